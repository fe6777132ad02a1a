/* The C API leaves the process's GSL and HDF5 error settings as the program
 * set them, one mode per CTest test:
 *
 *   test_process_state gsl FILE      the program's GSL handler (counting) stays in place and is
 *                                    never called by the library: a scan line, a failing one
 *                                    (NaN), a job GSL refuses inside the library (h_min above
 *                                    h_start over the namelist FILE); the program's own GSL
 *                                    errors still reach it
 *   test_process_state threads       two threads computing (and failing) at once while the main
 *                                    thread makes GSL errors of its own: every one of those, and
 *                                    none of the library's, reaches the handler, which is the
 *                                    program's afterwards; the lines equal serial ones bitwise
 *   test_process_state hdf5 FILE     jobs over the namelist FILE write HDF5 files and leave the
 *                                    automatic error printing as it was: the default, then a
 *                                    function of the program's, which the library never calls
 *   test_process_state fpe FILE      a program that traps overflow, invalid operations and
 *                                    division by zero (as -ffpe-trap does): values that overflow
 *                                    (1e400 as text, 1e308 as a spring) are refused or fail with a
 *                                    status, not SIGFPE; a map, a brake run and a job over FILE
 *                                    succeed; after each call the traps and the exception flags
 *                                    are the program's, as they were before it
 *   test_process_state memory FILE   jobs over FILE in a loop keep no memory: the heap in use
 *                                    (mallinfo2) after 300 jobs is within 100 kB of that after
 *                                    100 (HDF5's free lists fill up to their bounds, some 70 kB
 *                                    here; HDF5's Fortran interface, opened and closed around
 *                                    every file, kept 2.6 kB a job: 520 kB over these 200)
 */
#define _GNU_SOURCE /* feenableexcept, fegetexcept */
#include <friction.h>

#include <fenv.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_vector.h>
#include <malloc.h>
#include <stddef.h>
#include <hdf5.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
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

/* ---- GSL: a handler that counts ---- */

static atomic_int gsl_calls = 0;

static void counting_handler(const char *reason, const char *file, int line, int gsl_errno) {
  (void)reason, (void)file, (void)line, (void)gsl_errno;
  atomic_fetch_add(&gsl_calls, 1);
}

/* Whether the handler in place is counting_handler (which stays installed). */
static int handler_is_ours(void) {
  return gsl_set_error_handler(&counting_handler) == &counting_handler;
}

/* A GSL error of the program's own: copying vectors of different lengths. */
static void own_gsl_error(void) {
  gsl_vector *a = gsl_vector_calloc(1), *b = gsl_vector_calloc(2);
  CHECK(gsl_vector_memcpy(a, b) == GSL_EBADLEN, "copied a vector of 2 into one of 1");
  gsl_vector_free(a);
  gsl_vector_free(b);
}

enum { NX = 16 };

/* A NaF line of NX samples from origin (x0, y0) at 10 degrees over `length`
 * Å at `velocity` Å/s, the rest the defaults (rkf45 at rtol 1e-3). */
static int line(double x0, double y0, double velocity, double length, double *fx, double *fy,
                friction_error *err) {
  friction_config *cfg = friction_config_new("afm", err);
  if (cfg == NULL) return friction_error_status(err);
  int status = FRICTION_OK;
  if (status == FRICTION_OK) status = friction_config_set(cfg, "scan.nx", "16", err);
  if (status == FRICTION_OK) status = friction_config_set(cfg, "scan.ny", "1", err);
  if (status == FRICTION_OK) status = friction_config_set(cfg, "scan.angle", "10.0", err);
  if (status == FRICTION_OK) status = friction_config_set_real(cfg, "scan.origin_x", x0, err);
  if (status == FRICTION_OK) status = friction_config_set_real(cfg, "scan.origin_y", y0, err);
  if (status == FRICTION_OK) status = friction_config_set_real(cfg, "scan.velocity", velocity, err);
  if (status == FRICTION_OK) status = friction_config_set_real(cfg, "scan.length", length, err);
  if (status == FRICTION_OK) status = friction_afm_line(cfg, 0, 1, fx, fy, NX, err);
  friction_config_free(cfg);
  return status;
}

static int naf_line(double x0, double y0, double *fx, double *fy, friction_error *err) {
  return line(x0, y0, 400.0, 20.0, fx, fy, err);
}

/* A line whose right-hand side overflows at once (the support races at
 * 1e308 Å/s over 1e-10 Å): a numerical failure inside the integration. */
static int failing_line(double *fx, double *fy, friction_error *err) {
  return line(0.7, 0.3, 1.0e308, 1.0e-10, fx, fy, err);
}

static void message_of(friction_error *err, char *buf, size_t len) {
  if (friction_error_message(err, buf, len) != FRICTION_OK) buf[0] = '\0';
}

static int gsl_mode(const char *namelist) {
  double fx[NX], fy[NX];
  char message[1024];
  friction_error *err = friction_error_new();
  gsl_error_handler_t *previous = gsl_set_error_handler(&counting_handler);

  CHECK(naf_line(0.7, 0.3, fx, fy, err) == FRICTION_OK, "scan line: status %d", friction_error_status(err));
  CHECK(handler_is_ours(), "the handler is not the program's after a scan line");

  CHECK(failing_line(fx, fy, err) == FRICTION_ERROR_NUMERICAL, "failing line: status %d",
        friction_error_status(err));
  message_of(err, message, sizeof message);
  CHECK(strstr(message, "NaN or Inf") != NULL, "failing line: message '%s'", message);
  CHECK(handler_is_ours(), "the handler is not the program's after a failing line");

  /* h_min above the first step: the configuration's own check refuses it
   * before GSL sees it (GSL's words for the same refusal, reported inside
   * the library, are the unit case library_state.gsl_reports_stay_inside). */
  {
    const char *override = "process_state_h_min.nml";
    const char *output = "process_state_h_min.h5";
    const char *files[] = {namelist, override};
    FILE *f = fopen(override, "w");
    CHECK(f != NULL, "cannot write %s", override);
    if (f == NULL) return 1;
    fputs("&integrator h_start = 1e-12, h_min = 1e-9 /\n", f);
    fclose(f);
    remove(output);
    int status = friction_run_job(files, 2, output, FRICTION_JOB_FORCE | FRICTION_JOB_INIT_MPI, NULL, NULL, err);
    message_of(err, message, sizeof message);
    CHECK(status == FRICTION_ERROR_INPUT, "h_min job: status %d (%s)", status, message);
    CHECK(strstr(message, "h_min") != NULL && strstr(message, "h_start") != NULL,
          "h_min job: message '%s'", message);
    f = fopen(output, "r");
    CHECK(f == NULL, "h_min job: %s written", output);
    if (f != NULL) fclose(f);
    CHECK(handler_is_ours(), "the handler is not the program's after a job GSL refused");
    remove(override);
  }

  CHECK(atomic_load(&gsl_calls) == 0, "the library called the program's handler %d times",
        atomic_load(&gsl_calls));
  own_gsl_error();
  CHECK(atomic_load(&gsl_calls) == 1, "the program's own GSL error reached its handler %d times, not once",
        atomic_load(&gsl_calls));
  gsl_set_error_handler(previous);
  friction_error_free(err);
  return failures != 0;
}

/* ---- threads ---- */

enum { ROUNDS = 6 };
static atomic_int workers_running = 0;
static atomic_int go = 0;   /* the main thread is making errors of its own */

struct worker {
  double x0, y0;
  const double *fx_ref, *fy_ref;
  int mismatches, failures;
};

static void *worker_run(void *arg) {
  struct worker *w = arg;
  double fx[NX], fy[NX];
  friction_error *err = friction_error_new();
  while (!atomic_load(&go)) sched_yield();
  for (int r = 0; r < ROUNDS; r++) {
    if (naf_line(w->x0, w->y0, fx, fy, err) != FRICTION_OK ||
        memcmp(fx, w->fx_ref, sizeof fx) != 0 || memcmp(fy, w->fy_ref, sizeof fy) != 0)
      w->mismatches++;
    if (failing_line(fx, fy, err) != FRICTION_ERROR_NUMERICAL) w->failures++;
  }
  friction_error_free(err);
  atomic_fetch_sub(&workers_running, 1);
  return NULL;
}

static int threads_mode(void) {
  double ref[2][2][NX];
  struct worker w[2] = {{0.7, 0.3, ref[0][0], ref[0][1], 0, 0}, {2.1, 1.4, ref[1][0], ref[1][1], 0, 0}};
  pthread_t thread[2];
  int own = 0;
  gsl_error_handler_t *previous = gsl_set_error_handler(&counting_handler);

  for (int k = 0; k < 2; k++)
    CHECK(naf_line(w[k].x0, w[k].y0, ref[k][0], ref[k][1], NULL) == FRICTION_OK, "reference line %d", k);
  atomic_store(&workers_running, 2);
  for (int k = 0; k < 2; k++) CHECK(pthread_create(&thread[k], NULL, worker_run, &w[k]) == 0, "thread %d", k);
  /* GSL errors of the program's own while the library runs in the others. */
  do {
    own_gsl_error();
    own++;
    atomic_store(&go, 1);
  } while (atomic_load(&workers_running) > 0);
  for (int k = 0; k < 2; k++) pthread_join(thread[k], NULL);

  for (int k = 0; k < 2; k++) {
    CHECK(w[k].mismatches == 0, "thread %d: %d of %d lines differ from the serial one", k, w[k].mismatches,
          ROUNDS);
    CHECK(w[k].failures == 0, "thread %d: %d failing lines did not fail", k, w[k].failures);
  }
  CHECK(handler_is_ours(), "the handler is not the program's after two threads");
  printf("%d GSL errors of the program's own during the threads' calls\n", own);
  CHECK(atomic_load(&gsl_calls) == own,
        "the handler was called %d times for the program's %d own errors", atomic_load(&gsl_calls), own);
  gsl_set_error_handler(previous);
  return failures != 0;
}

/* ---- HDF5 ---- */

static herr_t counting_printer(hid_t stack, void *data) {
  (void)stack;
  (*(int *)data)++;
  return 0;
}

/* A job over namelist into output, which must then exist. */
static void job(const char *namelist, const char *output) {
  friction_error *err = friction_error_new();
  const char *files[] = {namelist};
  char message[1024];
  int status;
  FILE *f;

  remove(output);
  status = friction_run_job(files, 1, output, FRICTION_JOB_FORCE | FRICTION_JOB_INIT_MPI, NULL, NULL, err);
  message_of(err, message, sizeof message);
  CHECK(status == FRICTION_OK, "job into %s: status %d (%s)", output, status, message);
  f = fopen(output, "rb");
  CHECK(f != NULL, "%s not written", output);
  if (f != NULL) fclose(f);
  remove(output);
  friction_error_free(err);
}

static int hdf5_mode(const char *namelist) {
  H5E_auto2_t initial_func, func;
  void *initial_data, *data;
  int calls = 0;

  CHECK(H5Eget_auto2(H5E_DEFAULT, &initial_func, &initial_data) >= 0, "H5Eget_auto2");
  CHECK(initial_func != NULL, "printing is off before the test");

  job(namelist, "process_state_default.h5");
  CHECK(H5Eget_auto2(H5E_DEFAULT, &func, &data) >= 0 && func == initial_func && data == initial_data,
        "the default printing changed by a job");

  CHECK(H5Eset_auto2(H5E_DEFAULT, counting_printer, &calls) >= 0, "H5Eset_auto2");
  job(namelist, "process_state_own.h5");
  CHECK(H5Eget_auto2(H5E_DEFAULT, &func, &data) >= 0 && func == counting_printer && data == &calls,
        "the program's error function replaced by a job");
  CHECK(calls == 0, "the library called the program's error function %d times", calls);
  /* The program's own failing HDF5 call still reaches it. */
  CHECK(H5Fopen("no-such-dir/missing.h5", H5F_ACC_RDONLY, H5P_DEFAULT) < 0, "opened a missing file");
  CHECK(calls == 1, "the program's own HDF5 error reached its function %d times, not once", calls);
  H5Eset_auto2(H5E_DEFAULT, initial_func, initial_data);
  return failures != 0;
}

/* ---- the floating-point environment ---- */

enum { TRAPPED = FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW };

/* The traps and flags are the program's: TRAPPED trapping, and only the
 * inexact flag it raised itself before the call. */
static void environment_kept(const char *call) {
  CHECK(fegetexcept() == TRAPPED, "after %s the traps are %#x, not %#x", call, fegetexcept(), TRAPPED);
  CHECK(fetestexcept(FE_ALL_EXCEPT) == FE_INEXACT, "after %s the flags are %#x, not only inexact (%#x)", call,
        fetestexcept(FE_ALL_EXCEPT), FE_INEXACT);
}

static void program_flags(void) {
  feclearexcept(FE_ALL_EXCEPT);
  feraiseexcept(FE_INEXACT);
}

static int fpe_mode(const char *namelist) {
  friction_error *err = friction_error_new();
  friction_config *cfg;
  friction_result *res;
  char message[1024];
  int status;

  feenableexcept(TRAPPED);
  program_flags();
  cfg = friction_config_new("afm", err);
  environment_kept("friction_config_new");
  status = friction_config_read(cfg, namelist, err);
  CHECK(status == FRICTION_OK, "read %s: status %d", namelist, status);
  environment_kept("friction_config_read");

  /* 1e400 overflows when read as a double: refused as out of range. */
  status = friction_config_set(cfg, "tip.kx", "1e400", err);
  message_of(err, message, sizeof message);
  CHECK(status == FRICTION_ERROR_INPUT && strstr(message, "out of range") != NULL, "1e400: status %d (%s)",
        status, message);
  environment_kept("friction_config_set of 1e400");

  /* A map with the paper's tip, then one whose spring (1e308 N/m) overflows the step. */
  program_flags();
  res = friction_compute(cfg, err);
  message_of(err, message, sizeof message);
  CHECK(res != NULL, "the map failed: %s", message);
  friction_result_free(res);
  environment_kept("friction_compute");
  status = friction_config_set_real(cfg, "tip.kx", 1e308, err);
  environment_kept("friction_config_set_real");
  res = status == FRICTION_OK ? friction_compute(cfg, err) : NULL;
  message_of(err, message, sizeof message);
  CHECK(res == NULL && friction_error_status(err) != FRICTION_OK, "kx = 1e308 gave a map (%s)", message);
  printf("kx = 1e308: status %d: %s\n", friction_error_status(err), message);
  friction_result_free(res);
  environment_kept("friction_compute with kx = 1e308");
  friction_config_free(cfg);

  /* A brake run, and a job writing its file. */
  program_flags();
  cfg = friction_config_new("brake", err);
  CHECK(friction_config_set_real(cfg, "brake.t_end", 100.0, err) == FRICTION_OK, "brake.t_end");
  res = friction_compute(cfg, err);
  message_of(err, message, sizeof message);
  CHECK(res != NULL, "the brake run failed: %s", message);
  friction_result_free(res);
  environment_kept("friction_compute of the brake");
  friction_config_free(cfg);
  program_flags();
  job(namelist, "process_state_fpe.h5");
  environment_kept("friction_run_job");
  friction_error_free(err);
  return failures != 0;
}

/* ---- memory kept from job to job ---- */

static int memory_mode(const char *namelist) {
  friction_error *err = friction_error_new();
  const char *files[] = {namelist};
  size_t after[2] = {0, 0};
  char message[1024];

  for (int k = 1; k <= 300; k++) {
    int status = friction_run_job(files, 1, "process_state_memory.h5", FRICTION_JOB_FORCE, NULL, NULL, err);
    message_of(err, message, sizeof message);
    CHECK(status == FRICTION_OK, "job %d: status %d (%s)", k, status, message);
    if (status != FRICTION_OK) break;
    if (k == 100) after[0] = mallinfo2().uordblks;
    if (k == 300) after[1] = mallinfo2().uordblks;
  }
  remove("process_state_memory.h5");
  printf("heap in use after 100 jobs %zu bytes, after 300 %zu\n", after[0], after[1]);
  CHECK(after[1] <= after[0] + 100000, "200 jobs kept %td bytes", (ptrdiff_t)(after[1] - after[0]));
  friction_error_free(err);
  return failures != 0;
}

int main(int argc, char **argv) {
  if (argc >= 3 && strcmp(argv[1], "gsl") == 0) return gsl_mode(argv[2]);
  if (argc >= 2 && strcmp(argv[1], "threads") == 0) return threads_mode();
  if (argc >= 3 && strcmp(argv[1], "hdf5") == 0) return hdf5_mode(argv[2]);
  if (argc >= 3 && strcmp(argv[1], "fpe") == 0) return fpe_mode(argv[2]);
  if (argc >= 3 && strcmp(argv[1], "memory") == 0) return memory_mode(argv[2]);
  fprintf(stderr, "usage: %s gsl NAMELIST | threads | hdf5 NAMELIST | fpe NAMELIST | memory NAMELIST\n", argv[0]);
  return 2;
}
