/* The C API's friction laws (include/friction.h, "friction laws on their own")
 * from C: Dahl's law along a triangle wave of displacement against its closed
 * form, LuGre's state count and steady force, and every refusal (an unknown
 * law or variable, a bad value, short or NULL arrays, a NULL handle, a freed
 * one). */
#include <friction.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define CHECK(cond, ...)                                              \
  do {                                                                \
    if (!(cond)) {                                                    \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                   \
      fprintf(stderr, "\n");                                          \
      failures++;                                                     \
    }                                                                 \
  } while (0)

static void expect_refusal(int status, friction_error *err, const char *word) {
  char message[1024];
  friction_error_message(err, message, sizeof message);
  CHECK(status == FRICTION_ERROR_INPUT, "status %d for '%s'", status, word);
  CHECK(strstr(message, word) != NULL, "message '%s' lacks '%s'", message, word);
}

int main(void) {
  friction_error *err = friction_error_new();

  /* Dahl, sigma0 = 1e5 N/m, F_c = 1 N: at rest for the first interval (the states start in
   * steady sliding at its velocity, 0: F = 0), then x up to A = 2e-5 m and down to -A.  Each
   * branch from a reversal (x_r, F_r) is F = s F_c - s (F_c - s F_r) exp(-sigma0 |x - x_r|/F_c)
   * exactly (the law depends on the path only); bound: the integration (rtol 1e-9). */
  friction_law *dahl = friction_law_new("dahl", err);
  CHECK(dahl != NULL, "friction_law_new(dahl)");
  CHECK(friction_law_state_count(dahl, err) == 1, "one state");
  enum { n = 302 };
  double t[n], x[n], force[n], states[n];
  for (int i = 0; i < n; i++) {
    int k = i == 0 ? 0 : i - 1;
    t[i] = 0.01 * i;
    x[i] = k <= 100 ? 2e-5 * k / 100.0 : 2e-5 - 4e-5 * (k - 100) / 200.0;
  }
  CHECK(friction_law_history(dahl, 1.0, t, x, n, 1, force, states, n, err) == FRICTION_OK, "history");
  double worst = 0.0, tip = 1.0 - exp(-2.0);
  for (int i = 1; i < n; i++) {
    double exact = i <= 101 ? 1.0 - exp(-1e5 * x[i]) : -1.0 + (1.0 + tip) * exp(-1e5 * (2e-5 - x[i]));
    worst = fmax(worst, fabs(force[i] - exact));
    CHECK(fabs(states[i] - force[i] / 1e5) < 1e-15, "F = sigma0 z at %d", i);
  }
  CHECK(worst < 1e-8, "Dahl's branches: worst %g N", worst);

  /* Refusals: a value, a name, short arrays, NULLs; the handle unchanged by a refused set. */
  expect_refusal(friction_law_set_real(dahl, "law.sigma9", 1.0, err), err, "unknown variable 'sigma9'");
  expect_refusal(friction_law_set(dahl, "law.alpha", "'two'", err), err, "&law: alpha = 'two'");
  CHECK(friction_law_set_real(dahl, "law.alpha", 0.5, err) == FRICTION_OK, "set alpha");
  expect_refusal(friction_law_check(dahl, err), err, "&law: alpha = ");
  expect_refusal(friction_law_history(dahl, 1.0, t, x, n, 1, force, states, n, err), err, "&law: alpha = ");
  CHECK(friction_law_set_real(dahl, "law.alpha", 1.0, err) == FRICTION_OK, "set alpha back");
  expect_refusal(friction_law_history(dahl, 1.0, t, x, n, 1, force, states, n - 1, err), err, "states_len");
  expect_refusal(friction_law_history(dahl, 1.0, NULL, x, n, 1, force, NULL, 0, err), err, "null pointers");
  expect_refusal(friction_law_history(dahl, 1.0, t, x, n, 2, force, NULL, 0, err), err, "displacement = 2");
  /* A negative normal load was taken (and coulomb's force came out pulling); found by the fuzzing suite's law-capi. */
  double kept = force[0] = 12345.0;
  expect_refusal(friction_law_history(dahl, -1.0, t, x, n, 1, force, NULL, 0, err), err, "normal = -1");
  CHECK(force[0] == kept, "a refused history writes nothing");
  expect_refusal(friction_law_history(dahl, NAN, t, x, n, 1, force, NULL, 0, err), err, "must be a finite number >= 0");
  expect_refusal(friction_law_check(NULL, err), err, "null pointer");
  CHECK(friction_law_new("bristles", err) == NULL, "unknown law");
  expect_refusal(friction_error_status(err), err, "unknown friction law 'bristles'");
  char value[64];
  CHECK(friction_law_get(dahl, "law.sigma0", value, sizeof value, err) == FRICTION_OK && atof(value) == 1e5,
        "get sigma0: %s", value);
  friction_law_free(dahl);

  /* LuGre, Table I with sigma2 = 0.4: steady at 2e-3 m/s from the start, F = g(v) + sigma2 v. */
  friction_law *lugre = friction_law_new("lugre", err);
  CHECK(friction_law_set_real(lugre, "law.sigma2", 0.4, err) == FRICTION_OK, "sigma2");
  double tt[2] = {0.0, 1.0}, v[2] = {2e-3, 2e-3}, f[2];
  CHECK(friction_law_history(lugre, 1.0, tt, v, 2, 0, f, NULL, 0, err) == FRICTION_OK, "lugre history");
  double steady = 1.0 + 0.5 * exp(-4.0) + 0.4 * 2e-3;
  CHECK(fabs(f[1] - steady) < 1e-12, "LuGre steady %.17g vs %.17g", f[1], steady);
  friction_law_free(lugre);
  friction_law_free(NULL);

  /* A host that frees a law twice or uses it after its free (issue 40): the free ignores it and
   * every call refuses it with FRICTION_ERROR_INPUT, without touching the freed memory; so is a
   * handle of another kind passed as a law. */
  friction_law *gone = friction_law_new("coulomb", err);
  CHECK(gone != NULL, "friction_law_new(coulomb)");
  friction_law_free(gone);
  friction_law_free(gone);
  expect_refusal(friction_law_set(gone, "law.mu", "0.2", err), err, "law handle is not live");
  expect_refusal(friction_law_set_real(gone, "law.mu", 0.2, err), err, "law handle is not live");
  expect_refusal(friction_law_get(gone, "law.mu", value, sizeof value, err), err, "law handle is not live");
  expect_refusal(friction_law_check(gone, err), err, "law handle is not live");
  CHECK(friction_law_state_count(gone, err) == -1, "state count of a freed law");
  expect_refusal(friction_error_status(err), err, "law handle is not live");
  expect_refusal(friction_law_history(gone, 1.0, tt, v, 2, 0, f, NULL, 0, err), err, "law handle is not live");
  expect_refusal(friction_law_check((friction_law *)err, err), err, "law handle is not live");
  friction_law_free((friction_law *)err); /* not a law: ignored, the error handle stays */
  CHECK(friction_error_status(err) == FRICTION_ERROR_INPUT, "the error handle survives a law free of it");

  friction_error_free(err);
  if (failures) fprintf(stderr, "%d failures\n", failures);
  else printf("capi-law: all checks passed (Dahl's branches within %.1e N)\n", worst);
  return failures ? 1 : 0;
}
