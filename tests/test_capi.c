/* Tests of the C API (include/friction.h), one mode per CTest test:
 *
 *   test_capi checks            versions, error handles, configurations, results and
 *                               jobs: every refusal (NULL handles, unknown scene, group
 *                               or variable, wrong kind, too short arrays, bad values)
 *   test_capi threads           two threads on two handles == the same one after the
 *                               other, bitwise
 *   test_capi thermal-stop      a stop request from the progress function inside a
 *                               single-line thermal computation (Langevin, Kramers) ends it,
 *                               through friction_compute_progress and friction_afm_line_progress
 *   test_capi afm FILE...       friction_config_read(FILE...), friction_compute and
 *                               friction_afm_line of every line: prints every array
 *   test_capi brake FILE...     friction_config_read(FILE...), friction_compute: prints
 *   test_capi job OUT FILE...   friction_run_job(FILE..., OUT); progress reports checked
 *   test_capi serial-job OUT FILE...   the same without FRICTION_JOB_INIT_MPI: a serial
 *                               job, after which MPI is still not initialised
 *   test_capi config-job SCENE OUT FILE...   the same through friction_config_new(SCENE),
 *                               friction_config_read and friction_run_config
 *
 * The printing modes write each array as "# name rows columns" and its values,
 * one per line (%.17g, which reads back to the same double); capi_test.py
 * compares them and the job files with the program's output.  No mode but
 * the job modes initialises MPI: `checks` tests that a job without MPI and
 * without FRICTION_JOB_INIT_MPI runs serially and leaves MPI alone.
 */
#include <friction.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* From the MPI library the friction library links (callable before MPI_Init):
 * whether a job initialised MPI. */
extern int MPI_Initialized(int *flag);

static int mpi_initialized(void) {
  int flag = 0;
  MPI_Initialized(&flag);
  return flag;
}

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

static char last_message[2048];

/* The call must fail with FRICTION_ERROR_INPUT, the handle must hold it,
 * and the message must contain `word`. */
static void expect_input_error(int status, friction_error *err, const char *word, const char *what) {
  CHECK(status == FRICTION_ERROR_INPUT, "%s: status %d, expected %d", what, status, FRICTION_ERROR_INPUT);
  CHECK(friction_error_status(err) == status, "%s: handle status %d, returned %d", what,
        friction_error_status(err), status);
  CHECK(friction_error_message(err, last_message, sizeof last_message) == FRICTION_OK, "%s: message", what);
  CHECK(strstr(last_message, word) != NULL, "%s: message '%s' lacks '%s'", what, last_message, word);
}

/* The call must succeed; on failure show the handle's message. */
static void expect_ok(int status, friction_error *err, const char *what) {
  if (status != FRICTION_OK) {
    friction_error_message(err, last_message, sizeof last_message);
    CHECK(status == FRICTION_OK, "%s: status %d: %s", what, status, last_message);
  }
}

/* A small NaF map: 3 lines of 16 samples, 10 degrees, origin (0.7, 0.3) Å. */
static friction_config *small_naf(friction_error *err) {
  friction_config *cfg = friction_config_new("afm", err);
  if (cfg == NULL) return NULL;
  expect_ok(friction_config_set(cfg, "scan.nx", "16", err), err, "nx");
  expect_ok(friction_config_set(cfg, "scan.ny", "3", err), err, "ny");
  expect_ok(friction_config_set_real(cfg, "scan.angle", 10.0, err), err, "angle");
  expect_ok(friction_config_set_real(cfg, "scan.origin_x", 0.7, err), err, "origin_x");
  expect_ok(friction_config_set_real(cfg, "scan.origin_y", 0.3, err), err, "origin_y");
  return cfg;
}

/* A short brake run: 81 points to τ = 40. */
static friction_config *short_brake(friction_error *err) {
  friction_config *cfg = friction_config_new("brake", err);
  if (cfg == NULL) return NULL;
  expect_ok(friction_config_set(cfg, "brake.t_end", "40.0", err), err, "t_end");
  expect_ok(friction_config_set(cfg, "brake.dt_out", "0.5", err), err, "dt_out");
  return cfg;
}

static int write_file(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  if (f == NULL) return 1;
  fputs(text, f);
  return fclose(f) != 0;
}

static void check_versions(void) {
  char buf[64], macros[64];
  CHECK(friction_version(buf, sizeof buf) == FRICTION_OK, "version");
  snprintf(macros, sizeof macros, "%d.%d.%d", FRICTION_VERSION_MAJOR, FRICTION_VERSION_MINOR,
           FRICTION_VERSION_PATCH);
  CHECK(strcmp(buf, macros) == 0, "friction_version() '%s' but the header's macros say '%s'", buf, macros);
  CHECK(strcmp(buf, FRICTION_PROJECT_VERSION) == 0, "friction_version() '%s' but CMake's project version is '%s'",
        buf, FRICTION_PROJECT_VERSION);
  CHECK(friction_api_version() == FRICTION_API_VERSION && FRICTION_API_VERSION == 2, "API version %d, header %d",
        friction_api_version(), FRICTION_API_VERSION);
  CHECK(friction_version(buf, 2) == FRICTION_ERROR_INPUT && strlen(buf) == 1, "version into 2 bytes");
  CHECK(friction_version(NULL, 10) == FRICTION_ERROR_INPUT, "version into NULL");
}

static void check_error_handles(void) {
  char buf[64];
  friction_error *err = friction_error_new();
  CHECK(err != NULL, "friction_error_new returned NULL");
  CHECK(friction_error_status(err) == FRICTION_OK, "fresh handle status");
  CHECK(friction_error_message(err, buf, sizeof buf) == FRICTION_OK && buf[0] == '\0', "fresh message");
  CHECK(friction_error_status(NULL) == -1, "status of NULL");
  CHECK(friction_error_message(NULL, buf, sizeof buf) != FRICTION_OK, "message of NULL");
  friction_error_free(NULL);
  /* a message truncated into a small buffer */
  char tiny[8];
  friction_config_new("gold", err);
  CHECK(friction_error_message(err, tiny, sizeof tiny) == FRICTION_ERROR_INPUT && strlen(tiny) == 7,
        "truncated message '%s'", tiny);
  /* success clears the handle */
  friction_config *cfg = friction_config_new("afm", err);
  CHECK(cfg != NULL && friction_error_status(err) == FRICTION_OK, "status after success");
  CHECK(friction_error_message(err, buf, sizeof buf) == FRICTION_OK && buf[0] == '\0', "message after success");
  /* a NULL error handle is allowed, for success and failure */
  CHECK(friction_config_set(cfg, "tip.kx", "5.0", NULL) == FRICTION_OK, "set without a handle");
  CHECK(friction_config_set(cfg, "tip.kx", "'five'", NULL) == FRICTION_ERROR_INPUT, "bad set without a handle");
  friction_config_free(cfg);
  friction_error_free(err);
}

/* NULL handles and arguments: refused, never a crash. */
static void check_null_handles(friction_error *err) {
  char buf[256];
  double x[16];
  size_t shape[2], needed;
  friction_config *cfg = friction_config_new("afm", err);
  expect_input_error(friction_config_new(NULL, err) == NULL ? friction_error_status(err) : 0, err, "null",
                     "new(NULL)");
  expect_input_error(friction_config_read(NULL, "x.nml", err), err, "null", "read(NULL cfg)");
  expect_input_error(friction_config_read(cfg, NULL, err), err, "null", "read(NULL path)");
  expect_input_error(friction_config_set(NULL, "tip.kx", "1.0", err), err, "null", "set(NULL cfg)");
  expect_input_error(friction_config_set(cfg, NULL, "1.0", err), err, "null", "set(NULL name)");
  expect_input_error(friction_config_set(cfg, "tip.kx", NULL, err), err, "null", "set(NULL value)");
  expect_input_error(friction_config_set_real(NULL, "tip.kx", 1.0, err), err, "null", "set_real(NULL cfg)");
  expect_input_error(friction_config_set_real(cfg, NULL, 1.0, err), err, "null", "set_real(NULL name)");
  expect_input_error(friction_config_get(NULL, "tip.kx", buf, sizeof buf, err), err, "null", "get(NULL cfg)");
  expect_input_error(friction_config_get(cfg, NULL, buf, sizeof buf, err), err, "null", "get(NULL name)");
  expect_input_error(friction_config_get(cfg, "tip.kx", NULL, 10, err), err, "null", "get(NULL buf)");
  expect_input_error(friction_config_check(NULL, err), err, "null", "check(NULL)");
  CHECK(friction_config_text(NULL, buf, sizeof buf, &needed) == FRICTION_ERROR_INPUT, "text(NULL)");
  CHECK(friction_config_names(NULL, buf, sizeof buf, &needed) == FRICTION_ERROR_INPUT, "names(NULL)");
  expect_input_error(friction_afm_line(NULL, 0, 1, x, x, 16, err), err, "null", "afm_line(NULL cfg)");
  expect_input_error(friction_afm_line(cfg, 0, 1, NULL, x, 16, err), err, "null", "afm_line(NULL fx)");
  expect_input_error(friction_afm_line(cfg, 0, 1, x, NULL, 16, err), err, "null", "afm_line(NULL fy)");
  CHECK(friction_compute(NULL, err) == NULL, "compute(NULL)");
  expect_input_error(friction_error_status(err), err, "null", "compute(NULL)");
  expect_input_error(friction_result_get(NULL, "t", x, 16, &needed, err), err, "null", "result_get(NULL)");
  expect_input_error(friction_result_shape(NULL, "t", shape, err), err, "null", "result_shape(NULL)");
  CHECK(friction_result_names(NULL, buf, sizeof buf) == FRICTION_ERROR_INPUT, "result_names(NULL)");
  expect_input_error(friction_run_config(NULL, "out.h5", 0, NULL, NULL, err), err, "null", "run_config(NULL)");
  expect_input_error(friction_run_config(cfg, NULL, 0, NULL, NULL, err), err, "null", "run_config(NULL output)");
  friction_config_free(NULL);
  friction_result_free(NULL);
  friction_config_free(cfg);
}

/* A host that frees a handle twice or uses one after freeing it (issue 40):
 * the frees ignore it and the other calls refuse it, without touching the
 * freed memory (under valgrind or ASan this runs clean). */
static void check_freed_handles(friction_error *err) {
  char buf[256];
  double x[16];
  size_t shape[2], needed;
  friction_config *cfg = small_naf(err);
  friction_result *res = friction_compute(cfg, err);
  CHECK(res != NULL, "compute for the freed-handle checks");
  friction_config_free(cfg);
  friction_config_free(cfg); /* a double free */
  expect_input_error(friction_config_set(cfg, "tip.kx", "1.0", err), err, "not live", "set(freed cfg)");
  expect_input_error(friction_config_get(cfg, "tip.kx", buf, sizeof buf, err), err, "not live", "get(freed cfg)");
  expect_input_error(friction_config_check(cfg, err), err, "not live", "check(freed cfg)");
  CHECK(friction_config_text(cfg, buf, sizeof buf, &needed) == FRICTION_ERROR_INPUT, "text(freed cfg)");
  CHECK(friction_config_names(cfg, buf, sizeof buf, &needed) == FRICTION_ERROR_INPUT, "names(freed cfg)");
  CHECK(friction_compute(cfg, err) == NULL, "compute(freed cfg)");
  expect_input_error(friction_error_status(err), err, "not live", "compute(freed cfg)");
  friction_result_free(res);
  friction_result_free(res);
  expect_input_error(friction_result_get(res, "fx", x, 16, &needed, err), err, "not live", "result_get(freed)");
  expect_input_error(friction_result_shape(res, "fx", shape, err), err, "not live", "result_shape(freed)");
  CHECK(friction_result_names(res, buf, sizeof buf) == FRICTION_ERROR_INPUT, "result_names(freed)");
  /* A handle of another kind is not taken for this one. */
  expect_input_error(friction_config_check((friction_config *)err, err), err, "not live", "check(error as cfg)");
  friction_error *gone = friction_error_new();
  friction_error_free(gone);
  friction_error_free(gone);
  CHECK(friction_error_status(gone) == -1, "status of a freed error handle");
  CHECK(friction_error_message(gone, buf, sizeof buf) != FRICTION_OK && strstr(buf, "not live") != NULL,
        "message of a freed error handle: '%s'", buf);
  cfg = small_naf(err);
  CHECK(friction_config_set(cfg, "tip.kx", "1.0", gone) == FRICTION_OK, "a call with a freed error handle");
  friction_config_free(cfg);
}

/* Names, kinds and values through set, set_real and get. */
static void check_set_get(friction_error *err) {
  char buf[512];
  friction_config *cfg = friction_config_new("afm", err);

  /* unknown scenes, groups and variables; names that are not group.variable */
  CHECK(friction_config_new("gold", err) == NULL, "unknown scene");
  expect_input_error(friction_error_status(err), err, "unknown scene 'gold' (known: 'afm', 'brake', 'machine')", "scene");
  expect_input_error(friction_config_set(cfg, "tip.mas", "1e-8", err), err, "&tip: unknown variable 'mas' (known:",
                     "unknown variable");
  expect_input_error(friction_config_set(cfg, "tips.mass", "1e-8", err), err, "unknown namelist group &tips",
                     "unknown group");
  expect_input_error(friction_config_set(cfg, "brake.xi", "1.0", err), err, "group &brake is not part of scene 'afm'",
                     "another scene's group");
  expect_input_error(friction_config_set(cfg, "mass", "1e-8", err), err, "'group.variable'", "no group");
  expect_input_error(friction_config_set(cfg, "surface.sigma(0)", "1.0", err), err, "whole number >= 1", "index 0");
  expect_input_error(friction_config_set(cfg, "surface.sigma(x)", "1.0", err), err, "whole number >= 1", "index x");

  /* the wrong kind, as the reader says it; the value stays */
  expect_input_error(friction_config_set(cfg, "scan.nx", "'many'", err), err,
                     "&scan: nx = 'many': expected an integer", "text for an integer");
  expect_input_error(friction_config_set(cfg, "scan.nx", "2.5", err), err, "expected an integer", "real for int");
  expect_input_error(friction_config_set(cfg, "scan.retrace", "maybe", err), err, "expected .true. or .false.",
                     "bad logical");
  expect_input_error(friction_config_set(cfg, "integrator.method", "rkf45", err), err, "expected quoted text",
                     "unquoted text");
  expect_input_error(friction_config_set(cfg, "tip.kx", "'stiff'", err), err, "expected a number", "text for real");
  expect_input_error(friction_config_set(cfg, "tip.kx", "1, 2", err), err, "more values than the 1 elements",
                     "two values for a scalar");
  expect_input_error(friction_config_set(cfg, "surface.sigma(9)", "1.0", err), err, "sigma(9) = 1.0: more values",
                     "element beyond the array");
  expect_input_error(friction_config_set_real(cfg, "scan.nx", 2.5, err), err, "&scan: nx = 2.50000: expected an integer",
                     "set_real non-whole integer");
  expect_input_error(friction_config_set_real(cfg, "surface.potential", 1.0, err), err, "expected quoted text",
                     "set_real on text");
  expect_input_error(friction_config_set_real(cfg, "surface.sigma(9)", 1.0, err), err, "more values than the 8",
                     "set_real beyond the array");
  expect_input_error(friction_config_set(cfg, "job.scene", "'brake'", err), err,
                     "the configuration is of scene 'afm'", "change the scene");
  expect_ok(friction_config_get(cfg, "scan.nx", buf, sizeof buf, err), err, "get nx");
  CHECK(strcmp(buf, "128") == 0, "nx after refused sets: '%s'", buf);
  expect_ok(friction_config_get(cfg, "job.scene", buf, sizeof buf, err), err, "get scene");
  CHECK(strcmp(buf, "'afm'") == 0, "job.scene '%s'", buf);
  expect_ok(friction_config_set(cfg, "job.scene", "'afm'", err), err, "the same scene");

  /* values round trip */
  expect_ok(friction_config_set(cfg, "surface.potential", "'HOPG'", err), err, "potential");
  expect_ok(friction_config_get(cfg, "surface.potential", buf, sizeof buf, err), err, "get potential");
  CHECK(strcmp(buf, "'hopg'") == 0, "potential folded to lower case: '%s'", buf);
  expect_ok(friction_config_set_real(cfg, "tip.kx", 0.1, err), err, "kx");
  expect_ok(friction_config_get(cfg, "tip.kx", buf, sizeof buf, err), err, "get kx");
  CHECK(strcmp(buf, "0.1") == 0, "kx '%s'", buf);
  expect_ok(friction_config_set_real(cfg, "scan.nx", 24.0, err), err, "set_real integer");
  expect_ok(friction_config_get(cfg, "scan.nx", buf, sizeof buf, err), err, "get nx");
  CHECK(strcmp(buf, "24") == 0, "nx '%s'", buf);
  expect_ok(friction_config_set(cfg, "scan.retrace", ".false.", err), err, "retrace");
  expect_ok(friction_config_get(cfg, "scan.retrace", buf, sizeof buf, err), err, "get retrace");
  CHECK(strcmp(buf, ".false.") == 0, "retrace '%s'", buf);
  expect_ok(friction_config_set(cfg, "surface.sigma(2)", "3.0, 4.5", err), err, "sigma(2:3)");
  expect_ok(friction_config_get(cfg, "surface.sigma", buf, sizeof buf, err), err, "get sigma");
  CHECK(strcmp(buf, "2.4945, 3.0, 4.5, 5*0.0") == 0, "sigma '%s'", buf);
  expect_ok(friction_config_get(cfg, "surface.sigma(3)", buf, sizeof buf, err), err, "get sigma(3)");
  CHECK(strcmp(buf, "4.5") == 0, "sigma(3) '%s'", buf);
  expect_ok(friction_config_set_real(cfg, "surface.epsilon(4)", 0.25, err), err, "epsilon(4)");
  expect_ok(friction_config_get(cfg, "surface.epsilon(4)", buf, sizeof buf, err), err, "get epsilon(4)");
  CHECK(strcmp(buf, "0.25") == 0, "epsilon(4) '%s'", buf);
  expect_input_error(friction_config_get(cfg, "surface.sigma(9)", buf, sizeof buf, err), err,
                     "index 9 is outside the 8 elements", "get beyond the array");
  char small[4];
  expect_input_error(friction_config_get(cfg, "surface.potential", small, sizeof small, err), err,
                     "7 bytes needed", "get into 4 bytes");
  friction_config_free(cfg);
}

/* The scene's checks: values refused as the namelist refuses them. */
static void check_checks(friction_error *err) {
  friction_config *cfg = friction_config_new("afm", err);
  expect_ok(friction_config_check(cfg, err), err, "the defaults pass");
  struct {
    const char *name;
    double value;
    const char *message;
  } bad[] = {
      {"tip.mass", -1e-8, "&tip: mass = -1.000000E-8: must be > 0 (kg)"},
      {"tip.mass", NAN, "&tip: mass = NaN: must be > 0 (kg)"},
      {"tip.kx", -1.0, "&tip: kx = -1.00000: must be >= 0 (N/m)"},
      {"scan.velocity", 0.0, "&scan: velocity = 0.00000: must be > 0 (Å/s; the direction is set by angle)"},
      {"scan.angle", INFINITY, "&scan: angle = Inf: must be a finite number"},
      {"scan.nx", 1.0, "&scan: nx = 1: must be >= 2 (sample points per line)"},
      {"integrator.rtol", 0.0, "&integrator: rtol = 0.00000: must be > 0 (relative tolerance)"},
      {"surface.v0", -HUGE_VAL, "&surface: v0 = -Inf: must be >= 0 (eV)"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    friction_config *one = friction_config_new("afm", err);
    expect_ok(friction_config_set_real(one, bad[k].name, bad[k].value, err), err, bad[k].name);
    expect_input_error(friction_config_check(one, err), err, bad[k].message, bad[k].name);
    CHECK(strcmp(last_message, bad[k].message) == 0, "%s: message '%s', expected '%s' exactly", bad[k].name,
          last_message, bad[k].message);
    friction_config_free(one);
  }
  /* text values: an unknown potential, an overdamped tip without damping */
  expect_ok(friction_config_set(cfg, "surface.potential", "'gold'", err), err, "gold");
  expect_input_error(friction_config_check(cfg, err), err, "&surface: potential = 'gold': unknown potential", "gold");
  expect_ok(friction_config_set(cfg, "surface.potential", "'naf'", err), err, "naf");
  expect_ok(friction_config_set(cfg, "tip.model", "'overdamped'", err), err, "overdamped");
  expect_ok(friction_config_set(cfg, "tip.cy", "0.0", err), err, "cy");
  expect_input_error(friction_config_check(cfg, err), err, "&tip: cy = 0.00000: must be > 0 (N s/m) for model = "
                     "'overdamped'", "overdamped without damping");
  /* every computation checks first */
  double fx[128], fy[128];
  expect_input_error(friction_afm_line(cfg, 0, 1, fx, fy, 128, err), err, "&tip: cy", "afm_line checks");
  CHECK(friction_compute(cfg, err) == NULL, "compute of a bad configuration");
  expect_input_error(friction_error_status(err), err, "&tip: cy", "compute checks");
  friction_config_free(cfg);

  /* the brake: the switched model's mu <= mu_s, the initial normal force */
  cfg = friction_config_new("brake", err);
  expect_ok(friction_config_check(cfg, err), err, "brake defaults");
  expect_ok(friction_config_set(cfg, "brake.mu", "0.7", err), err, "mu");
  expect_input_error(friction_config_check(cfg, err), err, "&brake: mu = 0.700000: the switched model needs mu <= "
                     "mu_s", "mu above mu_s");
  expect_ok(friction_config_set(cfg, "brake.model", "'regularized'", err), err, "regularized");
  expect_ok(friction_config_check(cfg, err), err, "mu above mu_s is fine for the regularized model");
  expect_ok(friction_config_set_real(cfg, "brake.g_prime", -0.01, err), err, "g_prime");
  expect_input_error(friction_config_check(cfg, err), err, "initial normal force N'", "lift-off at the start");
  CHECK(friction_compute(cfg, err) == NULL, "compute with N' < 0");
  /* y0 = 0 is the default, refused against the g_prime set (by name: no place) */
  expect_input_error(friction_error_status(err), err,
                     "&brake: g_prime, with the default &brake: y0 = 0.00000: the initial normal force N'",
                     "compute checks N'");
  friction_config_free(cfg);
}

/* Files: read with the reader's messages; text that reads back. */
static void check_files(friction_error *err) {
  char *text, *again;
  size_t needed = 0, needed_again = 0;
  friction_config *cfg = small_naf(err), *copy = friction_config_new("afm", err);

  /* a size query, a buffer too small, the text, and the text read back */
  CHECK(friction_config_text(cfg, NULL, 0, &needed) == FRICTION_OK && needed > 100, "size query: %zu", needed);
  char small[16];
  CHECK(friction_config_text(cfg, small, sizeof small, NULL) == FRICTION_ERROR_INPUT && strlen(small) == 15,
        "text into 16 bytes");
  text = malloc(needed);
  CHECK(friction_config_text(cfg, text, needed, NULL) == FRICTION_OK, "text");
  CHECK(strstr(text, "&job\n  scene = 'afm'\n/\n&surface\n") == text, "text begins '%.40s'", text);
  CHECK(strstr(text, "  angle = 10.0\n") != NULL && strstr(text, "  origin_x = 0.7\n") != NULL, "text values");
  CHECK(write_file("capi-text.nml", text) == 0, "write capi-text.nml");
  expect_ok(friction_config_read(copy, "capi-text.nml", err), err, "read the text back");
  friction_config_text(copy, NULL, 0, &needed_again);
  again = malloc(needed_again);
  friction_config_text(copy, again, needed_again, NULL);
  CHECK(strcmp(text, again) == 0, "the text read back differs:\n%s\n---\n%s", text, again);
  free(again);
  free(text);

  /* the reader's errors, with file and line; a refused file changes nothing */
  expect_input_error(friction_config_read(copy, "no-such-dir/missing.nml", err), err, "missing.nml", "missing file");
  write_file("capi-bad.nml", "&scan\n  nx = 12\n  retrace = maybe\n/\n");
  expect_input_error(friction_config_read(copy, "capi-bad.nml", err), err,
                     "capi-bad.nml:3: &scan: retrace = maybe: expected .true. or .false.", "bad logical in a file");
  char buf[64];
  friction_config_get(copy, "scan.nx", buf, sizeof buf, err);
  CHECK(strcmp(buf, "16") == 0, "a refused file changed nx to %s", buf);
  write_file("capi-bad.nml", "&tip mas = 1e-8 /\n");
  expect_input_error(friction_config_read(copy, "capi-bad.nml", err), err, "capi-bad.nml:1: &tip: unknown variable "
                     "'mas'", "unknown variable in a file");
  write_file("capi-bad.nml", "&tip mass = 1e-8\n");
  expect_input_error(friction_config_read(copy, "capi-bad.nml", err), err, "not closed", "unclosed group");
  write_file("capi-bad.nml", "&job scene = 'brake' /\n&brake xi = 0.5 /\n");
  expect_input_error(friction_config_read(copy, "capi-bad.nml", err), err, "capi-bad.nml:1: &job: scene = 'brake': "
                     "the configuration is of scene 'afm'", "another scene in &job");
  write_file("capi-bad.nml", "&brake xi = 0.5 /\n");
  expect_input_error(friction_config_read(copy, "capi-bad.nml", err), err, "capi-bad.nml:1: group &brake is not "
                     "part of scene 'afm'", "another scene's group");
  /* a value from a file is checked with its file and line */
  write_file("capi-bad.nml", "! a comment\n&tip\n  mass = -1e-8\n/\n");
  expect_ok(friction_config_read(copy, "capi-bad.nml", err), err, "a bad value reads");
  expect_input_error(friction_config_check(copy, err), err, "capi-bad.nml:3: &tip: mass = -1.000000E-8: must be > 0",
                     "the value's file and line");
  /* ... until it is set in memory again, where the message has no place */
  friction_config_set_real(copy, "tip.mass", -2e-8, err);
  expect_input_error(friction_config_check(copy, err), err, "&tip: mass", "set in memory");
  CHECK(strncmp(last_message, "&tip: mass = -2.000000E-8: must be > 0", 38) == 0, "message '%s'", last_message);

  /* names: every variable with its kind */
  friction_config_names(cfg, NULL, 0, &needed);
  text = malloc(needed);
  CHECK(friction_config_names(cfg, text, needed, NULL) == FRICTION_OK, "names");
  CHECK(strstr(text, "tip.mass\treal\t1\tkg\n") != NULL, "names lack tip.mass");
  CHECK(strstr(text, "scan.nx\tinteger\t1\t\n") != NULL, "names lack scan.nx");
  CHECK(strstr(text, "surface.sigma\treal\t8\t") != NULL, "names lack surface.sigma");
  CHECK(strstr(text, "job.scene\ttext\t1\t\n") != NULL, "names lack job.scene");
  CHECK(strstr(text, "brake.") == NULL, "an AFM configuration lists brake variables");
  free(text);
  friction_config_free(copy);
  friction_config_free(cfg);
}

/* Lines and results: arguments, names, shapes, sizes. */
static void check_results(friction_error *err) {
  double fx[16], fy[16], big[200];
  char names[1024];
  size_t shape[2], needed = 0;
  friction_config *cfg = small_naf(err), *brake = short_brake(err);

  expect_input_error(friction_afm_line(cfg, 0, 1, fx, fy, 15, err), err, "n = 15: fx and fy must hold scan.nx = 16",
                     "arrays too short");
  expect_input_error(friction_afm_line(cfg, 3, 1, fx, fy, 16, err), err, "line = 3: the map has lines 0 to 2",
                     "line beyond the map");
  expect_input_error(friction_afm_line(cfg, -1, 1, fx, fy, 16, err), err, "line = -1", "negative line");
  expect_input_error(friction_afm_line(brake, 0, 1, fx, fy, 16, err), err, "scene 'brake' is not made of scan lines",
                     "afm_line of the brake");
  fx[0] = 12345.0;
  CHECK(friction_afm_line(cfg, 0, 1, fx, fy, 15, err) != FRICTION_OK && fx[0] == 12345.0, "a refused line wrote");

  /* The library's own Rosenbrock steppers by name: a line with rodas3 and
   * rodas4 at rtol = atol = 1e-8 against rk8pd at 1e-11.  On the full NaF
   * map rodas4 at 1e-7 is off by 1.3e-9 nN and rodas3 at 1e-7 by 2e-8 nN
   * (docs/speed.md); 1e-6 nN leaves a factor of 50 and more, and is far below
   * the 1e-3 nN that a wrong stepper (or a wrong Jacobian) gives. */
  {
    friction_config *tight = small_naf(err);
    double rx[16], ry[16], ox[16], oy[16];
    const char *own[] = {"'rodas3'", "'rodas4'"};
    int k, i;
    expect_ok(friction_config_set(tight, "integrator.method", "'rk8pd'", err), err, "rk8pd");
    expect_ok(friction_config_set_real(tight, "integrator.rtol", 1e-11, err), err, "rtol");
    expect_ok(friction_config_set_real(tight, "integrator.atol", 1e-11, err), err, "atol");
    expect_ok(friction_afm_line(tight, 1, 1, rx, ry, 16, err), err, "rk8pd line");
    for (k = 0; k < 2; k++) {
      double worst = 0.0;
      expect_ok(friction_config_set(tight, "integrator.method", own[k], err), err, own[k]);
      expect_ok(friction_config_set_real(tight, "integrator.rtol", 1e-8, err), err, "rtol");
      expect_ok(friction_config_set_real(tight, "integrator.atol", 1e-8, err), err, "atol");
      expect_ok(friction_config_check(tight, err), err, own[k]);
      expect_ok(friction_afm_line(tight, 1, 1, ox, oy, 16, err), err, own[k]);
      for (i = 0; i < 16; i++) worst = fmax(worst, fmax(fabs(ox[i] - rx[i]), fabs(oy[i] - ry[i])));
      CHECK(worst < 1e-6, "%s line against rk8pd: %.3e nN", own[k], worst);
    }
    friction_config_free(tight);
  }
  expect_ok(friction_afm_line(cfg, 2, 0, fx, fy, 16, err), err, "retrace of line 2");

  friction_result *res = friction_compute(cfg, err);
  CHECK(res != NULL, "compute the small map");
  if (res != NULL) {
    CHECK(friction_result_names(res, names, sizeof names) == FRICTION_OK, "result names");
    CHECK(strcmp(names, "support_x\nsupport_y\ntrace/fx\ntrace/fy\ntrace/f_along\ntrace/f_across\ntrace/tip_x\n"
                        "trace/tip_y\nretrace/fx\nretrace/fy\nretrace/f_along\nretrace/f_across\nretrace/tip_x\n"
                        "retrace/tip_y\nfriction\nmean_abs_force\npeak_force") == 0, "names:\n%s", names);
    CHECK(friction_result_names(res, names, 10) == FRICTION_ERROR_INPUT, "names into 10 bytes");
    expect_ok(friction_result_shape(res, "trace/fx", shape, err), err, "shape");
    CHECK(shape[0] == 3 && shape[1] == 16, "trace/fx shape %zu x %zu", shape[0], shape[1]);
    expect_ok(friction_result_shape(res, "friction", shape, err), err, "shape");
    CHECK(shape[0] == 3 && shape[1] == 1, "friction shape %zu x %zu", shape[0], shape[1]);
    expect_ok(friction_result_get(res, "retrace/fx", NULL, 0, &needed, err), err, "size query");
    CHECK(needed == 48, "retrace/fx needs %zu", needed);
    big[0] = 12345.0;
    expect_input_error(friction_result_get(res, "retrace/fx", big, 47, &needed, err), err,
                       "n = 47: retrace/fx has 48 values", "too short");
    CHECK(big[0] == 12345.0, "a refused get wrote");
    expect_ok(friction_result_get(res, "retrace/fx", big, 200, &needed, err), err, "get");
    CHECK(memcmp(big + 32, fx, sizeof fx) == 0, "line 2 of retrace/fx differs from friction_afm_line");
    expect_input_error(friction_result_get(res, "trace/fz", big, 200, NULL, err), err,
                       "no result named 'trace/fz' (known: support_x, ", "unknown name");
    expect_input_error(friction_result_get(res, NULL, big, 200, NULL, err), err, "null", "NULL name");
    expect_input_error(friction_result_shape(res, "friction", NULL, err), err, "null", "NULL shape");
    friction_result_free(res);
  }
  res = friction_compute(brake, err);
  CHECK(res != NULL, "compute the brake");
  if (res != NULL) {
    CHECK(friction_result_names(res, names, sizeof names) == FRICTION_OK &&
              strcmp(names, "t\nx\nv\ny\nw\nstick\nevents/t\nevents/kind\nevents/x\nevents/v\nevents/y\n"
                            "events/w") == 0,
          "brake names:\n%s", names);
    expect_ok(friction_result_get(res, "t", big, 200, &needed, err), err, "t");
    CHECK(needed == 81 && big[80] == 40.0, "t: %zu points, last %g", needed, big[80]);
    expect_ok(friction_result_shape(res, "events/t", shape, err), err, "events shape");
    CHECK(shape[0] > 0 && shape[1] == 1, "events: %zu x %zu", shape[0], shape[1]);
    friction_result_free(res);
  }
  /* a sweep is for jobs */
  expect_ok(friction_config_set(brake, "sweep.sweep_variable", "'brake.mu'", err), err, "sweep");
  expect_ok(friction_config_set(brake, "sweep.sweep_values", "0.5, 0.55", err), err, "sweep values");
  expect_ok(friction_config_check(brake, err), err, "the sweep checks");
  CHECK(friction_compute(brake, err) == NULL, "compute of a sweep");
  expect_input_error(friction_error_status(err), err, "friction_compute computes one scene", "compute of a sweep");
  /* and so is a check: friction_compute would skip it without a word */
  expect_ok(friction_config_set(cfg, "verify.check", ".true.", err), err, "verify");
  expect_ok(friction_config_check(cfg, err), err, "the check checks");
  CHECK(friction_compute(cfg, err) == NULL, "compute with a check");
  expect_input_error(friction_error_status(err), err, "friction_compute runs no check", "compute with a check");
  expect_ok(friction_config_set(cfg, "verify.check", ".false.", err), err, "verify off");
  friction_config_free(brake);
  friction_config_free(cfg);
}

/* friction_compute_progress: its reports, and a stop asked for by one. */
struct progress_log {
  int calls, stop_at;
  double last;
  char first[64];
};

static int log_progress(const char *message, double fraction, void *user) {
  struct progress_log *log = user;
  log->calls++;
  if (log->calls == 1) snprintf(log->first, sizeof log->first, "%s", message);
  log->last = fraction;
  return log->calls == log->stop_at;
}

/* The small map's result `res` (freed here) holds `plain` as its retrace/fx. */
static void expect_map(friction_result *res, const double plain[48], const char *what, friction_error *err) {
  double got[48];
  CHECK(res != NULL, "%s: no result", what);
  if (res == NULL) return;
  expect_ok(friction_result_get(res, "retrace/fx", got, 48, NULL, err), err, what);
  CHECK(memcmp(plain, got, sizeof got) == 0, "%s: the map differs from friction_compute's", what);
  friction_result_free(res);
}

static void check_progress(friction_error *err) {
  friction_config *cfg = small_naf(err), *brake = short_brake(err);
  struct progress_log log = {0, 0, -1.0, ""};
  double plain[48];
  friction_result *res = friction_compute(cfg, err);

  CHECK(res != NULL, "compute the small map");
  if (res == NULL) return;
  expect_ok(friction_result_get(res, "retrace/fx", plain, 48, NULL, err), err, "plain retrace/fx");
  friction_result_free(res);
  /* a report per line, and the same numbers as without */
  expect_map(friction_compute_progress(cfg, log_progress, &log, err), plain, "compute with progress", err);
  CHECK(log.calls == 3 && log.last == 1.0 && strcmp(log.first, "1 of 3 lines") == 0,
        "progress: %d calls, last fraction %g, first '%s'", log.calls, log.last, log.first);
  /* NULL progress is friction_compute */
  expect_map(friction_compute_progress(cfg, NULL, NULL, err), plain, "compute with NULL progress", err);
  /* a nonzero return stops the map after that line: no result, status 5 */
  log = (struct progress_log){0, 1, -1.0, ""};
  CHECK(friction_compute_progress(cfg, log_progress, &log, err) == NULL, "a stopped map gave a result");
  CHECK(friction_error_status(err) == FRICTION_INTERRUPTED, "stopped map: status %d", friction_error_status(err));
  friction_error_message(err, last_message, sizeof last_message);
  CHECK(strstr(last_message, "the map stopped on request after 1 of 3 lines: no result") != NULL, "message: %s",
        last_message);
  CHECK(log.calls == 1, "the map went on after the stop: %d reports", log.calls);
  /* ... and the configuration computes as before */
  expect_map(friction_compute(cfg, err), plain, "compute after a stop", err);
  /* a line with progress: the line of friction_afm_line, one report when it is done (a line this
   * short is never polled), and NULL progress is friction_afm_line */
  {
    double fx[16], fy[16], px[16], py[16];
    expect_ok(friction_afm_line(cfg, 2, 0, fx, fy, 16, err), err, "line without progress");
    log = (struct progress_log){0, 1, -1.0, ""};
    expect_ok(friction_afm_line_progress(cfg, 2, 0, px, py, 16, log_progress, &log, err), err, "line with progress");
    CHECK(memcmp(fx, px, sizeof fx) == 0 && memcmp(fy, py, sizeof fy) == 0, "the line with progress differs");
    CHECK(log.calls == 1 && log.last == 1.0 && strcmp(log.first, "1 of 1 lines") == 0,
          "line progress: %d calls, last fraction %g, first '%s'", log.calls, log.last, log.first);
    memset(px, 0, sizeof px);
    expect_ok(friction_afm_line_progress(cfg, 2, 0, px, py, 16, NULL, NULL, err), err, "line with NULL progress");
    CHECK(memcmp(fx, px, sizeof fx) == 0, "the line with NULL progress differs");
  }
  /* the brake reports along τ and stops at the request */
  log = (struct progress_log){0, 5, -1.0, ""};
  CHECK(friction_compute_progress(brake, log_progress, &log, err) == NULL, "a stopped brake gave a result");
  CHECK(friction_error_status(err) == FRICTION_INTERRUPTED, "stopped brake: status %d", friction_error_status(err));
  friction_error_message(err, last_message, sizeof last_message);
  CHECK(strstr(last_message, "brake run stopped on request at τ = ") != NULL &&
            strstr(last_message, "no result") != NULL,
        "message: %s", last_message);
  CHECK(log.calls == 5 && strncmp(log.first, "τ = ", strlen("τ = ")) == 0, "brake: %d reports, first '%s'",
        log.calls, log.first);
  friction_config_free(brake);
  friction_config_free(cfg);
}

/* Jobs: bad arguments; MPI must be initialised by the caller or by request. */
static void check_jobs(friction_error *err) {
  const char *none[] = {NULL};
  const char *missing[] = {"no-such-dir/missing.nml"};
  expect_input_error(friction_run_job(NULL, 1, "out.h5", 0, NULL, NULL, err), err, "files", "run_job files NULL");
  expect_input_error(friction_run_job(missing, 0, "out.h5", 0, NULL, NULL, err), err, "nfiles", "run_job nfiles 0");
  expect_input_error(friction_run_job(missing, 1, NULL, 0, NULL, NULL, err), err, "output", "run_job output NULL");
  expect_input_error(friction_run_job(none, 1, "out.h5", 0, NULL, NULL, err), err, "files[0]",
                     "run_job files[0] NULL");
  expect_input_error(friction_run_job(missing, 1, "out.h5", 8, NULL, NULL, err), err, "flags", "run_job flags");
  /* this process has not initialised MPI and does not ask for it: the jobs run
   * serially (here up to their input errors) and leave MPI uninitialised */
  expect_input_error(friction_run_job(missing, 1, "out.h5", FRICTION_JOB_FORCE, NULL, NULL, err), err,
                     "no-such-dir/missing.nml", "serial run_job of a missing file");
  CHECK(!mpi_initialized(), "a serial run_job initialised MPI");
  friction_config *cfg = friction_config_new("brake", err);
  friction_config_set(cfg, "brake.xi", "0.0", err);
  expect_input_error(friction_run_config(cfg, "out.h5", 0, NULL, NULL, err), err, "&brake: xi = 0.00000: must be > 0",
                     "serial run_config of a bad configuration");
  CHECK(!mpi_initialized(), "a serial run_config initialised MPI");
  /* with the flag the library initialises MPI (for the rest of this process) */
  expect_input_error(friction_run_job(missing, 1, "out.h5", FRICTION_JOB_INIT_MPI, NULL, NULL, err), err,
                     "no-such-dir/missing.nml", "run_job missing file");
  CHECK(mpi_initialized(), "FRICTION_JOB_INIT_MPI did not initialise MPI");
  /* ... after which no flag is needed; a bad configuration is refused by its checks */
  expect_input_error(friction_run_job(missing, 1, "out.h5", 0, NULL, NULL, err), err, "missing.nml",
                     "run_job with MPI initialised");
  friction_config_set(cfg, "brake.xi", "0.0", err);
  expect_input_error(friction_run_config(cfg, "out.h5", FRICTION_JOB_INIT_MPI, NULL, NULL, err), err,
                     "&brake: xi = 0.00000: must be > 0", "run_config of a bad configuration");
  CHECK(fopen("out.h5", "r") == NULL, "a refused job wrote out.h5");
  /* an existing output needs FRICTION_JOB_FORCE */
  write_file("exists.h5", "");
  friction_config_set(cfg, "brake.xi", "0.412", err);
  expect_input_error(friction_run_config(cfg, "exists.h5", 0, NULL, NULL, err), err,
                     "exists.h5: the output file exists", "run_config over an existing file");
  friction_config_free(cfg);
}

/* friction_config_warnings: the warnings the program's input would give for the values
 * (docs/input.md, Units), returned, never printed. */
static void check_warnings(friction_error *err) {
  char buf[4096];
  size_t needed = 0;
  friction_config *cfg = friction_config_new("afm", err);
  expect_ok(friction_config_warnings(cfg, buf, sizeof buf, &needed), err, "warnings of the defaults");
  CHECK(strcmp(buf, "") == 0 && needed == 1, "the defaults warn: '%s' (%zu bytes)", buf, needed);
  /* an angle in radians, an energy in joules: the program's words, one a line */
  expect_ok(friction_config_set_real(cfg, "scan.angle", 0.122, err), err, "angle");
  expect_ok(friction_config_set(cfg, "surface.v0", "1.6e-19", err), err, "v0");
  expect_ok(friction_config_warnings(cfg, NULL, 0, &needed), err, "size query");
  CHECK(needed > 1 && needed <= sizeof buf, "size query: %zu bytes", needed);
  expect_ok(friction_config_warnings(cfg, buf, sizeof buf, NULL), err, "warnings");
  /* (in the order of the groups, as the program's) */
  CHECK(strstr(buf, "&surface: v0 = 1.6e-19: below 1e-10 eV: it looks like joules, and the unit is eV") == buf,
        "v0 warning: '%s'", buf);
  CHECK(strstr(buf, "\n&scan: angle = 0.122: below 2 pi and not a whole or half degree: it looks like radians, and "
                    "the unit is degrees (0.122") != NULL,
        "angle warning: '%s'", buf);
  CHECK(buf[strlen(buf) - 1] == '\n' && strchr(strchr(buf, '\n') + 1, '\n') == buf + strlen(buf) - 1,
        "two lines: '%s'", buf);
  CHECK(friction_config_warnings(cfg, buf, 10, &needed) == FRICTION_ERROR_INPUT, "a short buffer is refused");
  /* the scene's own warning (a spring in another unit), and none once the values are plausible */
  expect_ok(friction_config_set_real(cfg, "scan.angle", 7.0, err), err, "angle 7");
  expect_ok(friction_config_set_real(cfg, "surface.v0", 1.0, err), err, "v0 1");
  expect_ok(friction_config_set_real(cfg, "tip.kx", 10000.0, err), err, "kx");
  expect_ok(friction_config_warnings(cfg, buf, sizeof buf, NULL), err, "kx warnings");
  CHECK(strncmp(buf, "&tip: kx = 10000", 16) == 0 && strstr(buf, "far outside the springs of AFM tips") != NULL,
        "kx warning: '%s'", buf);
  expect_ok(friction_config_set_real(cfg, "tip.kx", 5.0, err), err, "kx 5");
  expect_ok(friction_config_warnings(cfg, buf, sizeof buf, NULL), err, "plausible");
  CHECK(strcmp(buf, "") == 0, "plausible values warn: '%s'", buf);
  /* a sweep's values: once for the variable, with their range */
  expect_ok(friction_config_set(cfg, "sweep.sweep_variable", "'scan.angle'", err), err, "sweep variable");
  expect_ok(friction_config_set(cfg, "sweep.sweep_values", "0.1, 0.3, 45.0, 0.5", err), err, "sweep values");
  expect_ok(friction_config_warnings(cfg, buf, sizeof buf, NULL), err, "sweep warnings");
  /* (0.5 is a half degree, 45 a whole one: the rule's two exceptions) */
  CHECK(strcmp(buf, "&sweep: sweep_variable = 'scan.angle': 2 of its 4 values, from 0.100000 to 0.300000, look like "
                    "another unit than degree; the first: below 2 pi and not a whole or half degree: it looks like "
                    "radians, and the unit is degrees (0.100000 rad = 5.72958 degrees)\n") == 0,
        "sweep warning: '%s'", buf);
  /* a configuration the checks refuse has no warnings: its error is friction_config_check's */
  expect_ok(friction_config_set_real(cfg, "tip.mass", -1.0, err), err, "mass");
  expect_ok(friction_config_warnings(cfg, buf, sizeof buf, NULL), err, "refused");
  CHECK(strcmp(buf, "") == 0, "a refused configuration warns: '%s'", buf);
  CHECK(friction_config_warnings(NULL, buf, sizeof buf, NULL) == FRICTION_ERROR_INPUT, "a NULL configuration");
  friction_config_free(cfg);
}

static int checks(void) {
  friction_error *err = friction_error_new();
  check_versions();
  check_error_handles();
  check_null_handles(err);
  check_freed_handles(err);
  check_set_get(err);
  check_checks(err);
  check_warnings(err);
  check_files(err);
  check_results(err);
  check_progress(err);
  check_jobs(err); /* last: it initialises MPI */
  friction_error_free(err);
  if (failures == 0) printf("checks: all passed\n");
  return failures != 0;
}

/* ---- two threads, two handles ---- */
enum { NX = 24 };
struct work {
  const char *potential;
  double fx[NX], fy[NX];   /* line 1, retrace */
  double map[3 * NX];      /* trace/f_along of the whole map */
  int status;
};

static void *compute(void *arg) {
  struct work *w = arg;
  friction_error *err = friction_error_new();
  friction_config *cfg = friction_config_new("afm", err);
  char value[32];
  snprintf(value, sizeof value, "'%s'", w->potential);
  w->status = cfg == NULL;
  if (!w->status) w->status = friction_config_set(cfg, "surface.potential", value, err);
  if (!w->status) w->status = friction_config_set(cfg, "scan.nx", "24", err);
  if (!w->status) w->status = friction_config_set(cfg, "scan.ny", "3", err);
  if (!w->status) w->status = friction_config_set(cfg, "scan.angle", "7.0", err);
  for (int repeat = 0; repeat < 2 && !w->status; repeat++) {
    w->status = friction_afm_line(cfg, 1, 0, w->fx, w->fy, NX, err);
    friction_result *res = w->status ? NULL : friction_compute(cfg, err);
    if (res == NULL) w->status = w->status ? w->status : friction_error_status(err);
    if (!w->status) w->status = friction_result_get(res, "trace/f_along", w->map, 3 * NX, NULL, err);
    friction_result_free(res);
  }
  friction_config_free(cfg);
  friction_error_free(err);
  return NULL;
}

static int threads(void) {
  struct work serial[2] = {{.potential = "naf"}, {.potential = "hopg"}};
  struct work parallel[2] = {{.potential = "naf"}, {.potential = "hopg"}};
  pthread_t id[2];
  for (int k = 0; k < 2; k++) compute(&serial[k]);
  for (int k = 0; k < 2; k++) pthread_create(&id[k], NULL, compute, &parallel[k]);
  for (int k = 0; k < 2; k++) pthread_join(id[k], NULL);
  for (int k = 0; k < 2; k++) {
    CHECK(serial[k].status == 0 && parallel[k].status == 0, "%s: status %d / %d", serial[k].potential,
          serial[k].status, parallel[k].status);
    CHECK(memcmp(serial[k].fx, parallel[k].fx, sizeof serial[k].fx) == 0, "%s: fx differs", serial[k].potential);
    CHECK(memcmp(serial[k].fy, parallel[k].fy, sizeof serial[k].fy) == 0, "%s: fy differs", serial[k].potential);
    CHECK(memcmp(serial[k].map, parallel[k].map, sizeof serial[k].map) == 0, "%s: map differs",
          serial[k].potential);
  }
  CHECK(memcmp(serial[0].fx, serial[1].fx, sizeof serial[0].fx) != 0, "the two potentials should differ");
  if (failures == 0) printf("threads: NaF and HOPG in two threads equal them one after another, bitwise\n");
  return failures != 0;
}

/* ---- the numbers, for capi_test.py ---- */

static void print_array(const char *name, size_t rows, size_t columns, const double *values) {
  printf("# %s %zu %zu\n", name, rows, columns);
  for (size_t k = 0; k < rows * columns; k++) printf("%.17g\n", values[k]);
}

static friction_config *read_config(const char *scene, int nfiles, char **files, friction_error *err) {
  friction_config *cfg = friction_config_new(scene, err);
  for (int k = 0; k < nfiles && cfg != NULL; k++) {
    if (friction_config_read(cfg, files[k], err) != FRICTION_OK) {
      friction_config_free(cfg);
      cfg = NULL;
    }
  }
  return cfg;
}

static int fail_with(friction_error *err, const char *what) {
  friction_error_message(err, last_message, sizeof last_message);
  fprintf(stderr, "%s: status %d: %s\n", what, friction_error_status(err), last_message);
  return 1;
}

/* Every array of friction_compute; for the AFM also friction_afm_line of
 * every line and direction, as "line/<j>/<trace|retrace>/<fx|fy>". */
static int print_scene(const char *scene, int nfiles, char **files) {
  friction_error *err = friction_error_new();
  friction_config *cfg = read_config(scene, nfiles, files, err);
  if (cfg == NULL) return fail_with(err, "friction_config_read");
  friction_result *res = friction_compute(cfg, err);
  if (res == NULL) return fail_with(err, "friction_compute");
  char names[4096];
  if (friction_result_names(res, names, sizeof names) != FRICTION_OK) return fail_with(err, "names");
  for (char *name = strtok(names, "\n"); name != NULL; name = strtok(NULL, "\n")) {
    size_t shape[2], n;
    if (friction_result_shape(res, name, shape, err) != FRICTION_OK) return fail_with(err, name);
    n = shape[0] * shape[1];
    double *values = malloc((n > 0 ? n : 1) * sizeof *values);
    if (values == NULL || friction_result_get(res, name, values, n, NULL, err) != FRICTION_OK)
      return fail_with(err, name);
    print_array(name, shape[0], shape[1], values);
    free(values);
  }
  friction_result_free(res);
  if (strcmp(scene, "afm") == 0) {
    char text[64];
    int nx, ny;
    friction_config_get(cfg, "scan.nx", text, sizeof text, err);
    nx = atoi(text);
    friction_config_get(cfg, "scan.ny", text, sizeof text, err);
    ny = atoi(text);
    friction_config_get(cfg, "scan.retrace", text, sizeof text, err);
    int directions = strcmp(text, ".true.") == 0 ? 2 : 1;
    double *fx = malloc(2 * nx * sizeof *fx), *fy = fx + nx;
    for (int j = 0; j < ny; j++) {
      for (int d = 0; d < directions; d++) {
        char name[64];
        if (friction_afm_line(cfg, j, d == 0, fx, fy, nx, err) != FRICTION_OK) return fail_with(err, "line");
        snprintf(name, sizeof name, "line/%d/%s/fx", j, d == 0 ? "trace" : "retrace");
        print_array(name, 1, nx, fx);
        snprintf(name, sizeof name, "line/%d/%s/fy", j, d == 0 ? "trace" : "retrace");
        print_array(name, 1, nx, fy);
      }
    }
    free(fx);
  }
  friction_config_free(cfg);
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

/* friction_run_job (or, with a scene, friction_config_read +
 * friction_run_config) on the files argv[1..] writing argv[0]; the library
 * initialises MPI.  The progress must reach 1 without going backwards. */
static int run_job(int argc, char **argv, const char *scene, int init_mpi) {
  struct reports seen = {0, 0, 0.0, 0};
  friction_error *err = friction_error_new();
  int status, flags = FRICTION_JOB_FORCE | (init_mpi ? FRICTION_JOB_INIT_MPI : 0);
  if (argc < 2) return 2;
  if (scene != NULL) {
    friction_config *cfg = read_config(scene, argc - 1, argv + 1, err);
    if (cfg == NULL) return fail_with(err, "friction_config_read");
    status = friction_run_config(cfg, argv[0], flags, count_report, &seen, err);
    friction_config_free(cfg);
  } else {
    status = friction_run_job((const char *const *)(argv + 1), argc - 1, argv[0], flags, count_report, &seen, err);
  }
  if (status != FRICTION_OK) return fail_with(err, scene != NULL ? "friction_run_config" : "friction_run_job");
  CHECK(seen.progress > 0, "no progress reported");
  CHECK(seen.backwards == 0, "progress went backwards %d times", seen.backwards);
  CHECK(seen.last_fraction == 1.0, "progress ended at %g, not 1", seen.last_fraction);
  CHECK(mpi_initialized() == init_mpi, "after the job MPI is %sinitialised", mpi_initialized() ? "" : "not ");
  fprintf(stderr, "job: %d progress reports, %d notes\n", seen.progress, seen.notes);
  friction_error_free(err);
  return failures != 0;
}

/* ---- a stop request inside a thermal line ---- */
static double seconds_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

struct stop_log {
  double start, asked;   /* when the computation began; when a poll got the request (0: none yet) */
  int reports, polls;
};

/* Reports (fraction in [0, 1]) and polls (fraction -1, inside a line): the first poll
 * 0.5 s after the start gets the request. */
static int stop_in_line(const char *message, double fraction, void *user) {
  struct stop_log *log = user;
  (void)message;
  if (fraction >= 0.0) {
    log->reports++;
    return 0;
  }
  log->polls++;
  if (log->asked == 0.0 && seconds_now() - log->start > 0.5) log->asked = seconds_now();
  return log->asked != 0.0;
}

/* A single-line thermal map that takes tens of seconds, stopped by its progress
 * function from inside the line: no result, FRICTION_INTERRUPTED, within a second of
 * the request (the trip looks every 0.1 s of wall time; the bound allows a loaded
 * machine ten times that), and the configuration computes again afterwards. */
static int thermal_stop(void) {
  friction_error *err = friction_error_new();
  /* the Langevin tip at 0.1 A/s over 20 A (some 4e7 steps: half a minute), and the
   * reduced model in its thermolubric regime (1e-6 A/s: jumps back and forth, 30 s) */
  const char *cases[2][8] = {
      {"thermal.model", "'langevin'", "scan.velocity", "0.1", "tip.model", "'inertial'", "thermal.realizations",
       "1"},
      {"thermal.model", "'kramers'", "scan.velocity", "1e-6", "tip.model", "'overdamped'", "thermal.realizations",
       "2"}};
  for (int c = 0; c < 2; c++) {
    friction_config *cfg = friction_config_new("afm", err);
    expect_ok(friction_config_set(cfg, "scan.ny", "1", err), err, "ny");
    expect_ok(friction_config_set(cfg, "scan.length", "9.24", err), err, "length");
    expect_ok(friction_config_set(cfg, "thermal.temperature", "300.0", err), err, "temperature");
    for (int k = 0; k < 8; k += 2) expect_ok(friction_config_set(cfg, cases[c][k], cases[c][k + 1], err), err, cases[c][k]);
    struct stop_log log = {seconds_now(), 0.0, 0, 0};
    friction_result *res = friction_compute_progress(cfg, stop_in_line, &log, err);
    double ended = seconds_now();
    CHECK(res == NULL, "%s: the stopped line gave a result", cases[c][1]);
    CHECK(friction_error_status(err) == FRICTION_INTERRUPTED, "%s: status %d", cases[c][1], friction_error_status(err));
    friction_error_message(err, last_message, sizeof last_message);
    CHECK(strstr(last_message, "stopped on request") != NULL, "%s: message %s", cases[c][1], last_message);
    CHECK(log.asked > 0.0 && ended - log.asked < 1.0, "%s: ended %.3f s after the request (%d polls)", cases[c][1],
          log.asked > 0.0 ? ended - log.asked : -1.0, log.polls);
    CHECK(log.reports == 0, "%s: %d line reports before the line ended", cases[c][1], log.reports);
    printf("%s: stopped %.3f s after the request, %.2f s into the line, %d polls: %s\n", cases[c][1],
           ended - log.asked, ended - log.start, log.polls, last_message);
    /* the same line through friction_afm_line_progress: stopped inside, nothing written */
    {
      double fx[128], fy[128];
      fx[0] = 12345.0;
      struct stop_log line_log = {seconds_now(), 0.0, 0, 0};
      int status = friction_afm_line_progress(cfg, 0, 1, fx, fy, 128, stop_in_line, &line_log, err);
      double line_ended = seconds_now();
      CHECK(status == FRICTION_INTERRUPTED, "%s: afm_line_progress status %d", cases[c][1], status);
      CHECK(line_log.asked > 0.0 && line_ended - line_log.asked < 1.0 && line_log.reports == 0,
            "%s: the line ended %.3f s after the request, %d reports", cases[c][1],
            line_log.asked > 0.0 ? line_ended - line_log.asked : -1.0, line_log.reports);
      CHECK(fx[0] == 12345.0, "%s: a stopped line wrote", cases[c][1]);
      printf("%s: friction_afm_line_progress stopped %.3f s after the request, %d polls\n", cases[c][1],
             line_ended - line_log.asked, line_log.polls);
    }
    /* the configuration as it was: a short line computes */
    expect_ok(friction_config_set(cfg, "scan.length", "0.5", err), err, "length");
    expect_ok(friction_config_set(cfg, "scan.nx", "2", err), err, "nx");
    expect_ok(friction_config_set(cfg, "scan.velocity", "1e4", err), err, "velocity");
    res = friction_compute(cfg, err);
    CHECK(res != NULL, "%s: no result after the stop", cases[c][1]);
    friction_result_free(res);
    friction_config_free(cfg);
  }
  friction_error_free(err);
  if (failures == 0) printf("thermal-stop: all passed\n");
  return failures != 0;
}

int main(int argc, char **argv) {
  const char *mode = argc > 1 ? argv[1] : "checks";
  if (strcmp(mode, "checks") == 0) return checks();
  if (strcmp(mode, "threads") == 0) return threads();
  if (strcmp(mode, "thermal-stop") == 0) return thermal_stop();
  if (strcmp(mode, "afm") == 0 || strcmp(mode, "brake") == 0) return print_scene(mode, argc - 2, argv + 2);
  if (strcmp(mode, "job") == 0) return run_job(argc - 2, argv + 2, NULL, 1);
  if (strcmp(mode, "serial-job") == 0) return run_job(argc - 2, argv + 2, NULL, 0);
  if (strcmp(mode, "config-job") == 0 && argc > 2) return run_job(argc - 3, argv + 3, argv[2], 1);
  fprintf(stderr, "usage: test_capi checks|threads|thermal-stop|afm FILE...|brake FILE...|job OUT FILE...|"
                  "serial-job OUT FILE...|config-job SCENE OUT FILE...\n");
  return 2;
}
