/* Tests of the C API (include/friction.h), one mode per CTest test:
 *
 *   test_capi checks    version, error handle, bad input of every kind
 *   test_capi threads   two scan lines in two threads == one after another, bitwise
 *   test_capi afm       prints the scene of capi_test.py (trace then retrace): i fx fy
 *   test_capi brake     prints the brake of capi_test.py: t x v y w
 *   test_capi job OUT FILE...   friction_run_job(FILE..., OUT); progress reports counted on stderr
 *
 * The last three are compared with the CLI's HDF5 output by capi_test.py.
 */
#include <friction.h>

#include <math.h>
#include <pthread.h>
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

/* The scene of capi_test.py: inputs/naf.nml with nx = 16, angle = 10,
 * origin (0.7, 0.3) Å; the CLI's first line. */
enum { NX = 16 };
static int naf_line(double x0, double y0, int forward, double *fx, double *fy, friction_error *err) {
  return friction_afm_line("naf", 1.0, 4.62, 4.62, 2.46, 1.0e-8, 10.0, 10.0, 1.0e-3, 1.0e-3, 400.0,
                           x0, y0, 10.0, 20.0, NX, forward, "rkf45", 1.0e-3, 1.0e-4, fx, fy, err);
}

static int brake(double *t, double *x, double *v, double *y, double *w, size_t n, size_t *needed,
                 friction_error *err) {
  return friction_brake("switched", 0.412, 1.5, 0.01778, 0.59, 0.59, 3.5121e7, 3.5121, -0.002788,
                        40.0, 0.5, "rk8pd", 1.0e-10, 1.0e-12, t, x, v, y, w, n, needed, err);
}

/* The call must fail with status FRICTION_ERROR_INPUT, the handle must hold
 * it, and the message must contain `word`. */
static void expect_input_error(int status, friction_error *err, const char *word, const char *what) {
  char message[512];
  CHECK(status == FRICTION_ERROR_INPUT, "%s: status %d, expected %d", what, status, FRICTION_ERROR_INPUT);
  CHECK(friction_error_status(err) == status, "%s: handle status %d, returned %d", what,
        friction_error_status(err), status);
  CHECK(friction_error_message(err, message, sizeof message) == FRICTION_OK, "%s: message", what);
  CHECK(strstr(message, word) != NULL, "%s: message '%s' lacks '%s'", what, message, word);
}

static int checks(void) {
  char buf[64];
  double fx[NX], fy[NX];
  friction_error *err = friction_error_new();
  CHECK(err != NULL, "friction_error_new returned NULL");

  /* version */
  CHECK(friction_version(buf, sizeof buf) == FRICTION_OK, "version");
  CHECK(strlen(buf) >= 5 && strchr(buf, '.') != NULL, "version '%s'", buf);
  CHECK(friction_version(buf, 2) == FRICTION_ERROR_INPUT && strlen(buf) == 1, "version into 2 bytes");
  CHECK(friction_version(NULL, 10) == FRICTION_ERROR_INPUT, "version into NULL");

  /* a fresh handle, a NULL handle */
  CHECK(friction_error_status(err) == FRICTION_OK, "fresh handle status");
  CHECK(friction_error_message(err, buf, sizeof buf) == FRICTION_OK && buf[0] == '\0', "fresh message");
  CHECK(friction_error_status(NULL) == -1, "status of NULL");
  CHECK(friction_error_message(NULL, buf, sizeof buf) != FRICTION_OK, "message of NULL");
  friction_error_free(NULL);

  /* success clears the handle; a NULL handle is allowed */
  CHECK(naf_line(0.7, 0.3, 1, fx, fy, NULL) == FRICTION_OK, "line without a handle");
  CHECK(naf_line(0.7, 0.3, 1, fx, fy, err) == FRICTION_OK, "line");
  CHECK(friction_error_status(err) == FRICTION_OK, "status after success");

  /* bad AFM input */
  expect_input_error(friction_afm_line(NULL, 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "null", "null potential");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, NULL, 1e-3, 1e-4, fx, fy, err), err, "null", "null stepper");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, NULL, fy, err), err, "null", "null fx");
  expect_input_error(friction_afm_line("gold", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "gold", "unknown potential");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "euler", 1e-3, 1e-4, fx, fy, err), err, "euler", "unknown stepper");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 0.0, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "mass", "zero mass");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, -1, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "kx", "negative kx");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, -1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "cy", "negative cy");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 0, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "velocity", "zero velocity");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       1, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "nx", "nx = 1");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 0.0, 1e-4, fx, fy, err), err, "rtol", "zero rtol");
  expect_input_error(friction_afm_line("naf", 1, 4.62, 4.62, 2.46, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, NAN, fx, fy, err), err, "atol", "NaN atol");
  expect_input_error(friction_afm_line("hopg", 1, 4.62, 4.62, 0.0, 1e-8, 10, 10, 1e-3, 1e-3, 400, 0, 0, 0, 20,
                                       NX, 1, "rkf45", 1e-3, 1e-4, fx, fy, err), err, "a = ", "zero hopg a");

  /* the brake: ask for the length, too small arrays, bad names and values */
  size_t needed = 0;
  double small[4], times[4];
  expect_input_error(brake(NULL, NULL, NULL, NULL, NULL, 0, &needed, err), err, "too small", "length query");
  CHECK(needed == 81, "needed %zu points, expected 81", needed);
  expect_input_error(brake(small, small, small, small, small, 4, &needed, err), err, "81", "arrays of 4");
  expect_input_error(friction_brake("smooth", 0.412, 1.5, 0.01778, 0.59, 0.59, 3.5e7, 3.5, -0.0028, 40, 0.5,
                                    "rk8pd", 1e-10, 1e-12, small, small, small, small, small, 4, NULL, err),
                     err, "smooth", "unknown model");
  expect_input_error(friction_brake("switched", 0.412, 1.5, 0.01778, 0.59, 0.5, 3.5e7, 3.5, -0.0028, 40, 0.5,
                                    "rk8pd", 1e-10, 1e-12, small, small, small, small, small, 4, NULL, err),
                     err, "mu_s", "mu_s below mu");
  expect_input_error(friction_brake("switched", 0.0, 1.5, 0.01778, 0.59, 0.59, 3.5e7, 3.5, -0.0028, 40, 0.5,
                                    "rk8pd", 1e-10, 1e-12, small, small, small, small, small, 4, NULL, err),
                     err, "xi", "zero xi");
  expect_input_error(friction_brake(NULL, 0.412, 1.5, 0.01778, 0.59, 0.59, 3.5e7, 3.5, -0.0028, 40, 0.5,
                                    "rk8pd", 1e-10, 1e-12, small, small, small, small, small, 4, NULL, err),
                     err, "null", "null model");
  expect_input_error(friction_brake("switched", 0.412, 1.5, 0.01778, 0.59, 0.59, 3.5e7, 3.5, -0.0028, 1, 0.5,
                                    "rk8pd", 1e-10, 1e-12, small, NULL, small, small, small, 4, NULL, err),
                     err, "null", "null x");

  expect_input_error(friction_brake("switched", 0.412, 1.5, -0.01, 0.59, 0.59, 3.5e7, 3.5, -0.0028, 1, 0.5,
                                    "rk8pd", 1e-10, 1e-12, small, small, small, small, small, 4, NULL, err),
                     err, "N'", "lift-off at the start");
  /* the regularized model runs (mu > mu_s allowed there, as in the namelist) */
  CHECK(friction_brake("regularized", 0.412, 1.5, 0.01778, 0.6, 0.59, 3.5121e7, 3.5121, -0.002788, 1, 0.5,
                       "rk4imp", 1e-8, 1e-10, times, small, small, small, small, 4, &needed, err) == FRICTION_OK,
        "regularized brake: status %d", friction_error_status(err));
  CHECK(needed == 3 && times[2] == 1.0, "regularized brake: %zu points, last t = %g", needed, times[2]);

  /* a message truncated into a small buffer */
  char tiny[8];
  friction_brake(NULL, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, NULL, 0, 0, NULL, NULL, NULL, NULL, NULL, 0, NULL, err);
  CHECK(friction_error_message(err, tiny, sizeof tiny) == FRICTION_ERROR_INPUT && strlen(tiny) == 7,
        "truncated message '%s'", tiny);

  /* friction_run_job: bad arguments, then a file that is not there. */
  {
    const char *none[] = {NULL};
    const char *missing[] = {"no-such-dir/missing.nml"};
    expect_input_error(friction_run_job(NULL, 1, "out.h5", 0, NULL, NULL, err), err, "files", "run_job files NULL");
    expect_input_error(friction_run_job(missing, 0, "out.h5", 0, NULL, NULL, err), err, "nfiles", "run_job nfiles 0");
    expect_input_error(friction_run_job(missing, 1, NULL, 0, NULL, NULL, err), err, "output", "run_job output NULL");
    expect_input_error(friction_run_job(none, 1, "out.h5", 0, NULL, NULL, err), err, "files[0]",
                       "run_job files[0] NULL");
    expect_input_error(friction_run_job(missing, 1, "out.h5", 8, NULL, NULL, err), err, "flags", "run_job flags");
    expect_input_error(friction_run_job(missing, 1, "out.h5", 0, NULL, NULL, err), err, "missing.nml",
                       "run_job missing file");
  }
  friction_error_free(err);
  if (failures == 0) printf("checks: all passed\n");
  return failures != 0;
}

/* ---- two threads ---- */
struct line_job {
  double y0;
  double fx[NX], fy[NX];
  int status;
};

static void *run_line(void *arg) {
  struct line_job *job = arg;
  friction_error *err = friction_error_new();
  for (int repeat = 0; repeat < 3 && job->status == 0; repeat++)
    job->status = naf_line(0.7, job->y0, 1, job->fx, job->fy, err);
  friction_error_free(err);
  return NULL;
}

static int threads(void) {
  struct line_job serial[2] = {{.y0 = 0.3}, {.y0 = 2.1}}, parallel[2] = {{.y0 = 0.3}, {.y0 = 2.1}};
  pthread_t id[2];
  for (int k = 0; k < 2; k++) run_line(&serial[k]);
  for (int k = 0; k < 2; k++) pthread_create(&id[k], NULL, run_line, &parallel[k]);
  for (int k = 0; k < 2; k++) pthread_join(id[k], NULL);
  for (int k = 0; k < 2; k++) {
    CHECK(serial[k].status == 0 && parallel[k].status == 0, "line %d: status %d / %d", k, serial[k].status,
          parallel[k].status);
    CHECK(memcmp(serial[k].fx, parallel[k].fx, sizeof serial[k].fx) == 0, "line %d: fx differs", k);
    CHECK(memcmp(serial[k].fy, parallel[k].fy, sizeof serial[k].fy) == 0, "line %d: fy differs", k);
  }
  CHECK(memcmp(serial[0].fx, serial[1].fx, sizeof serial[0].fx) != 0, "the two lines should differ");
  if (failures == 0) printf("threads: two lines in two threads equal them one after another, bitwise\n");
  return failures != 0;
}

static int print_afm(void) {
  double fx[NX], fy[NX];
  friction_error *err = friction_error_new();
  char message[512];
  for (int forward = 1; forward >= 0; forward--) {
    if (naf_line(0.7, 0.3, forward, fx, fy, err) != FRICTION_OK) {
      friction_error_message(err, message, sizeof message);
      fprintf(stderr, "friction_afm_line: %s\n", message);
      return 1;
    }
    for (int i = 0; i < NX; i++) printf("%d %d %.17g %.17g\n", forward, i, fx[i], fy[i]);
  }
  friction_error_free(err);
  return 0;
}

static int print_brake(void) {
  size_t n = 0;
  friction_error *err = friction_error_new();
  char message[512];
  brake(NULL, NULL, NULL, NULL, NULL, 0, &n, err);
  double *t = malloc(5 * n * sizeof *t);
  if (t == NULL) return 1;
  double *x = t + n, *v = x + n, *y = v + n, *w = y + n;
  if (brake(t, x, v, y, w, n, NULL, err) != FRICTION_OK) {
    friction_error_message(err, message, sizeof message);
    fprintf(stderr, "friction_brake: %s\n", message);
    return 1;
  }
  for (size_t i = 0; i < n; i++) printf("%.17g %.17g %.17g %.17g %.17g\n", t[i], x[i], v[i], y[i], w[i]);
  free(t);
  friction_error_free(err);
  return 0;
}

struct reports {
  int progress, notes;
  double last_fraction;
  int backwards;
};

static void count_report(const char *message, double fraction, void *user) {
  struct reports *seen = user;
  if (message == NULL) return;
  if (fraction < 0.0) {
    seen->notes++;
    fprintf(stderr, "note: %s\n", message);
    return;
  }
  if (fraction < seen->last_fraction) seen->backwards++;
  seen->last_fraction = fraction;
  seen->progress++;
}

/* friction_run_job on files argv[1..] writing argv[0]; the progress must
 * reach 1 without going backwards. */
static int run_job(int argc, char **argv) {
  struct reports seen = {0, 0, 0.0, 0};
  char message[512];
  friction_error *err = friction_error_new();
  if (argc < 2) return 2;
  int status = friction_run_job((const char *const *)(argv + 1), argc - 1, argv[0], FRICTION_JOB_FORCE,
                                count_report, &seen, err);
  if (status != FRICTION_OK) {
    friction_error_message(err, message, sizeof message);
    fprintf(stderr, "friction_run_job: status %d: %s\n", status, message);
    return 1;
  }
  CHECK(seen.progress > 0, "no progress reported");
  CHECK(seen.backwards == 0, "progress went backwards %d times", seen.backwards);
  CHECK(seen.last_fraction == 1.0, "progress ended at %g, not 1", seen.last_fraction);
  fprintf(stderr, "job: %d progress reports, %d notes\n", seen.progress, seen.notes);
  friction_error_free(err);
  return failures != 0;
}

int main(int argc, char **argv) {
  const char *mode = argc > 1 ? argv[1] : "checks";
  if (strcmp(mode, "checks") == 0) return checks();
  if (strcmp(mode, "threads") == 0) return threads();
  if (strcmp(mode, "afm") == 0) return print_afm();
  if (strcmp(mode, "brake") == 0) return print_brake();
  if (strcmp(mode, "job") == 0) return run_job(argc - 2, argv + 2);
  fprintf(stderr, "usage: test_capi checks|threads|afm|brake|job OUT FILE...\n");
  return 2;
}
