/* friction: C API of the dry-friction simulator (AFM tip over a surface,
 * Girling brake), API version 2.  Reference: docs/capi.md.
 *
 * Handles.  A friction_config is a scene's configuration: made with the
 * scene's defaults (friction_config_new), changed by namelist files
 * (friction_config_read) or by name ("tip.kx", friction_config_set), checked
 * by the scene's own checks, the very code that checks the program's input
 * (friction_config_check; every computation runs it first).  Computations on
 * the calling process (friction_afm_line, friction_afm_line_progress,
 * friction_compute, friction_compute_progress) need no MPI;
 * a friction_result holds a whole computation's arrays.  Jobs
 * (friction_run_job, friction_run_config) run the program's job and write
 * its HDF5 file.
 *
 * Errors.  Every function that can fail returns an int status: FRICTION_OK
 * (0) or one of the FRICTION_ERROR_* codes.  Functions that take a
 * friction_error handle also store the status and a message in it when the
 * handle is not NULL; the handle is owned by the caller (friction_error_new /
 * friction_error_free).  The messages are the program's: a value refused by
 * a check reads "&tip: mass = -1.000000E-8: must be > 0 (kg)", preceded by
 * "file:line: " when the value came from a file.  The library never prints
 * and never stops the process.  It leaves GSL's error handler and HDF5's
 * automatic error printing as the host set them: each call installs its own
 * for its duration and restores the host's.  Likewise the floating-point
 * environment: the calls that compute run with no exception trapping and
 * clear flags, and give the host back its traps and flags on return (a
 * host that traps overflow gets a status, not SIGFPE).
 *
 * Threads.  Handles are independent, and threads may work at once, each on
 * its own handles (configuration, result, error).  A handle must not be used
 * by two threads at once.  Functions that take a `const` handle only read it;
 * two threads may read one configuration at once only through those.  The
 * computing functions (friction_afm_line, friction_afm_line_progress,
 * friction_compute, friction_compute_progress) take a non-const configuration: they keep the
 * surface they built in it for the next call, so a configuration shared by
 * threads that compute needs the caller's lock, or one copy per thread
 * (friction_config_text and friction_config_read make one).  The state shared between calls is a
 * mutex-guarded count of the threads inside GSL, so that the host's GSL
 * handler is back when the last of them returns, and a lock that runs the
 * job functions one at a time: they use HDF5, FFTW's planner and MPI, which
 * are the whole process's, so a job called while another thread's runs
 * waits for it to end.  Jobs keep HDF5's Fortran interface open and the
 * last spectrum's FFT plan from one job to the next.  A job started from a job's own report callback (the
 * same thread) is refused with FRICTION_ERROR_INPUT.
 *
 * Freed handles.  The library keeps a table of the handles it gave out and
 * the host has not freed.  Freeing a handle twice, or passing one after
 * freeing it (or a pointer the library never gave out, or a handle of
 * another kind), is detected and harmless: the free functions ignore it,
 * the others return FRICTION_ERROR_INPUT with "... handle is not live"
 * (friction_error_status returns -1 for such an error handle, and an error
 * handle that is not live gets no message).  The one case it cannot tell:
 * a freed handle whose memory the allocator has given to a new handle of
 * the same kind is that new handle, so using it is undefined behaviour.
 *
 * Units are those of the namelist input (docs/input.md).
 */
#ifndef FRICTION_H
#define FRICTION_H

#include <stddef.h>

/* The library's version (CMake's project version; a test checks that it
 * matches friction_version()) and the version of this API: 2 is the API of
 * handles (version 1 had positional friction_afm_line and friction_brake). */
#define FRICTION_VERSION_MAJOR 0
#define FRICTION_VERSION_MINOR 1
#define FRICTION_VERSION_PATCH 0
#define FRICTION_API_VERSION 2

#ifdef __cplusplus
extern "C" {
#endif

enum {
  FRICTION_OK = 0,
  FRICTION_ERROR_INPUT = 1,     /* bad argument or value: null, too small, unknown name, refused by a check */
  FRICTION_ERROR_NUMERICAL = 2, /* the integration failed */
  FRICTION_ERROR_IO = 3,
  FRICTION_ERROR_INTERNAL = 4,
  FRICTION_INTERRUPTED = 5      /* stopped on request: a job (a sweep's file is valid, resumable) or a
                                   computation (friction_compute_progress: no result) */
};

typedef struct friction_error friction_error;   /* opaque: status and message of the last call */
typedef struct friction_config friction_config; /* opaque: a scene's configuration */
typedef struct friction_result friction_result; /* opaque: the arrays of a computation */
typedef struct friction_law friction_law;       /* opaque: a friction law with its parameters */

/* ---- versions and errors ---- */

/* Library version ("major.minor.patch") into buf of len bytes, NUL-terminated.
 * FRICTION_ERROR_INPUT if buf is NULL or too small (then truncated). */
int friction_version(char *buf, size_t len);
/* FRICTION_API_VERSION of the library (a program loaded at run time, e.g.
 * through Python's ctypes, compares it with the version it was written for). */
int friction_api_version(void);

/* A new error handle (status FRICTION_OK, empty message); NULL if out of memory. */
friction_error *friction_error_new(void);
/* Free a handle; NULL is ignored. */
void friction_error_free(friction_error *err);
/* Status of the last call that used the handle; -1 for a NULL handle. */
int friction_error_status(const friction_error *err);
/* Message of the last call that used the handle ("" after success) into buf,
 * NUL-terminated; FRICTION_ERROR_INPUT if err or buf is NULL or buf is too
 * small (then truncated). */
int friction_error_message(const friction_error *err, char *buf, size_t len);

/* ---- configurations ---- */

/* A configuration of scene "afm" (friction-force map) or "brake" (Girling
 * brake) with the scene's defaults: &job, the scene's groups and &sweep, as
 * the program's input has them.  NULL (and a message) for an unknown scene.
 * Free it with friction_config_free (NULL is ignored). */
friction_config *friction_config_new(const char *scene, friction_error *err);
void friction_config_free(friction_config *cfg);

/* Apply the namelist file `path` over the current values, as the program
 * reads a later file over an earlier one (same reader, same messages, with
 * file:line).  All or nothing: a file with a bad assignment changes nothing.
 * A file whose &job names another scene, or that has groups of another
 * scene, is refused.  Values are not checked here (friction_config_check). */
int friction_config_read(friction_config *cfg, const char *path, friction_error *err);

/* Set one variable.  `name` is "group.variable" ("tip.kx",
 * "surface.potential"), optionally with an element: "surface.sigma(2)" (the
 * value's items then fill from that element on).  `value` is namelist value
 * text: "5.0", "'hopg'", ".true.", "1, 2", "3*0.0".  An unknown group or
 * variable, or a value of the wrong kind, is FRICTION_ERROR_INPUT with the
 * reader's message ("&scan: nx = 'many': expected an integer"); the value is
 * then left as it was.  The scene itself (job.scene) cannot change.
 *   integrator.method  GSL step type: rk2 rk4 rkf45 rkck rk8pd rk1imp rk2imp
 *                      rk4imp bsimp msadams msbdf rodas3 rodas4, or "auto"
 *                      (docs/speed.md; rodas3 and rodas4 are the library's
 *                      own Rosenbrock steppers in GSL's stepper interface) */
int friction_config_set(friction_config *cfg, const char *name, const char *value, friction_error *err);
/* The same for a number, without text in between: a real variable, or an
 * integer one when x is whole; NaN and infinities are set (and refused by
 * friction_config_check). */
int friction_config_set_real(friction_config *cfg, const char *name, double x, friction_error *err);

/* The value of "group.variable" (or one element, "surface.sigma(2)") as
 * namelist text ("10.0", "'naf'", ".true.", "2*0.0") into buf of len bytes.
 * FRICTION_ERROR_INPUT for an unknown name or a NULL or too small buf (the
 * message says how many bytes are needed). */
int friction_config_get(const friction_config *cfg, const char *name, char *buf, size_t len,
                        friction_error *err);

/* The whole configuration as namelist text: &job, the scene's groups, and
 * &sweep when a sweep is set; reals with the digits that read back to the
 * same doubles, so friction_config_read of this text gives the same
 * configuration.  *needed (if not NULL) gets the bytes it takes, NUL
 * included.  Returns FRICTION_OK, or FRICTION_ERROR_INPUT if cfg is NULL or
 * buf is NULL or too small (truncated); buf = NULL with len = 0 and needed
 * not NULL is a size query and returns FRICTION_OK. */
int friction_config_text(const friction_config *cfg, char *buf, size_t len, size_t *needed);

/* Every variable, one line each: "group.variable<TAB>kind<TAB>elements<TAB>unit\n"
 * with kind "real", "integer", "logical" or "text"; buffer as friction_config_text. */
int friction_config_names(const friction_config *cfg, char *buf, size_t len, size_t *needed);

/* The scene's checks (and the sweep's): the first value refused, as the
 * program refuses it: "&tip: mass = -1.000000E-8: must be > 0 (kg)"
 * (preceded by "file:line: " when the value was read from a file). */
int friction_config_check(const friction_config *cfg, friction_error *err);

/* The warnings the program's input would give for the configuration's
 * values, one a line in the program's words, "" for none (the library
 * prints nothing: show them as you show its messages):
 *   - a value set (friction_config_set, _set_real, friction_config_read)
 *     that looks like a number in another unit than its variable's:
 *     "&scan: angle = 0.122: below 2 pi and not a whole or half degree: it
 *     looks like radians, and the unit is degrees (...)";
 *   - the scene's own ("&tip: kx = 10000.0: far outside the springs of AFM tips ...");
 *   - a sweep's values that look like another unit, once per swept variable:
 *     "&sweep: sweep_variable = 'scan.angle': 5 of its 5 values, from 0.1 to
 *     0.5, look like another unit than degree; the first: ...";
 * each preceded by "file:line: " when the value was read from a file.  The
 * checks run first: a configuration they refuse has no warnings
 * (friction_config_check gives its error).  Buffer as friction_config_text. */
int friction_config_warnings(const friction_config *cfg, char *buf, size_t len, size_t *needed);

/* ---- computations on the calling process (no MPI) ---- */

/* Line `line` (0-based, < scan.ny) of the map of an "afm" configuration:
 * trace (forward != 0) or retrace (still stored by position), the lateral
 * force fx[i], fy[i] (nN) at the nx = scan.nx support positions of the
 * line, exactly as the program's file holds line `line` of /afm/trace
 * (/afm/retrace).  Every tip model, surface and potential; at a temperature
 * (&thermal temperature > 0) the mean over the realizations, as the file
 * holds it.  n is the length of fx and fy: n < scan.nx is
 * FRICTION_ERROR_INPUT and nothing is written.  The configuration keeps
 * the surface it built (a Lennard-Jones net's table) for its next line or
 * computation while &surface and the scan's rectangle stay as they were:
 * a later line of the graphite map costs the line alone.  friction_config_free
 * releases it. */
int friction_afm_line(friction_config *cfg, int line, int forward, double *fx, double *fy, size_t n,
                      friction_error *err);

/* friction_afm_line with a progress function (friction_progress_fn, below),
 * polled as friction_compute_progress polls it within a line: every 0.1 s of
 * a line that takes longer, with the message "started" and fraction -1,
 * whose nonzero return stops the line within the trip's next look
 * (FRICTION_INTERRUPTED, nothing written, the configuration as it was); and
 * called once when the line is done ("1 of 1 lines", fraction 1; its return
 * is not a stop: the line is written).  With progress = NULL it is
 * friction_afm_line. */
typedef int (*friction_progress_fn)(const char *message, double fraction, void *user);
int friction_afm_line_progress(friction_config *cfg, int line, int forward, double *fx, double *fy, size_t n,
                               friction_progress_fn progress, void *user, friction_error *err);

/* The configuration's whole computation on the calling process, checked
 * first; NULL (and a message) on an error.  Free with friction_result_free.
 *   afm:   as /afm of the program's file: "support_x" (nx), "support_y" (ny);
 *          "trace/fx", "trace/fy", "trace/f_along", "trace/f_across",
 *          "trace/tip_x", "trace/tip_y" as (ny, nx) maps (also "trace/fz",
 *          "trace/tip_z" for a tip moving in z, "trace/jumps" for the
 *          quasistatic model); the same under "retrace/" and "friction",
 *          "mean_abs_force" and "peak_force" (ny, nN) when scan.retrace.
 *          At a temperature the means over the realizations, with their
 *          standard errors beside them as in the file: "trace/fx_sem", ...,
 *          "friction_sem".
 *   brake: as /brake: "t", "x", "v", "y", "w", "stick" (1 stick, 0 slip) on
 *          the output grid; the events "events/t", "events/kind", "events/x",
 *          "events/v", "events/y", "events/w".  (&analysis and &verify are
 *          for jobs: friction_run_config.)
 * A configuration with a &sweep is refused: run it with friction_run_config.
 * The afm surface is kept in the configuration as by friction_afm_line. */
friction_result *friction_compute(friction_config *cfg, friction_error *err);

/* friction_progress_fn (declared above friction_afm_line_progress): progress
 * of a computation on the calling process: "12 of 48 lines" or
 * "τ = 120.0 of 1000.0", fraction in [0, 1]; fraction -1 is a poll from
 * inside a map's line (below).  A nonzero return asks the computation to
 * stop there. */

/* friction_compute with progress, and a way to stop it: `progress` (if not
 * NULL) is called on the calling thread after each scan line of a map and
 * 200 times along a brake trajectory, with `user` passed through; within a
 * map's line it is also called every 0.1 s of a line at a temperature (and
 * of a line slower than that at T = 0) with the last message ("started"
 * before the first) and fraction -1: a poll, not progress, whose nonzero
 * return stops the line within the trip's next look (a Langevin tip's
 * 0.05 A of support travel or 1e5 steps, a reduced-model search: measured
 * within 1 ms of the return).  When it returns nonzero before the last
 * report, the computation stops there:
 * NULL, status FRICTION_INTERRUPTED ("the map stopped on request after 12
 * of 48 lines: no result"), and the configuration as it was (its kept
 * surface too).  The request is this call's own: computations on other
 * threads go on.  To stop from elsewhere (a signal handler, another thread,
 * a Cancel button) set a flag there and return it from `progress`.  With
 * progress = NULL it is friction_compute. */
friction_result *friction_compute_progress(friction_config *cfg, friction_progress_fn progress, void *user,
                                           friction_error *err);

/* Copy the array `name` into out[0..n-1] as doubles, maps row-major (ny, nx):
 * out[j * nx + i] is sample i of line j.  *needed (if not NULL) gets its
 * number of values.  n smaller than that is FRICTION_ERROR_INPUT and nothing
 * is written, except that out = NULL with n = 0 is a size query
 * (FRICTION_OK).  An unknown name is FRICTION_ERROR_INPUT (the message lists
 * the names). */
int friction_result_get(const friction_result *res, const char *name, double *out, size_t n, size_t *needed,
                        friction_error *err);
/* The shape of `name`: {rows, columns}; {ny, nx} for a map, {n, 1} for a series. */
int friction_result_shape(const friction_result *res, const char *name, size_t shape[2], friction_error *err);
/* The names of the result's arrays, separated by '\n', into buf of len
 * bytes; FRICTION_ERROR_INPUT if res or buf is NULL or buf is too small. */
int friction_result_names(const friction_result *res, char *buf, size_t len);
void friction_result_free(friction_result *res);

/* ---- jobs: the program's computation and HDF5 file ---- */

enum {
  FRICTION_JOB_FORCE = 1,   /* overwrite an existing output */
  FRICTION_JOB_RESUME = 2,  /* a sweep reuses the checkpoints of an interrupted run (as --resume) */
  FRICTION_JOB_INIT_MPI = 4 /* MPI not initialised: the library may initialise it (see below) */
};
/* Progress ("12 of 64 lines", fraction in [0, 1]) and notes (a verify
 * result; fraction -1), called on rank 0 only. */
typedef void (*friction_report_fn)(const char *message, double fraction, void *user);

/* A whole job, as the command line runs it: the namelist files (later files
 * override earlier values variable by variable) are read and checked, the
 * scene or sweep they describe is computed and `output` (HDF5) is written
 * under a temporary name and renamed when complete; nothing is written on an
 * error.
 *   files, nfiles  the namelist files, as on the command line
 *   flags          FRICTION_JOB_FORCE, FRICTION_JOB_RESUME, FRICTION_JOB_INIT_MPI
 *   report         if not NULL, gets progress and notes; user is passed through
 * MPI is the caller's choice:
 *   - the caller initialised MPI (MPI_Init or MPI_Init_thread): the job is
 *     collective over MPI_COMM_WORLD (every rank calls it with the same
 *     arguments), e.g. under mpirun -n 4 it spreads as the program does;
 *   - MPI is not initialised and flags has FRICTION_JOB_INIT_MPI: the
 *     library initialises MPI (MPI_THREAD_FUNNELED), runs the job on this
 *     process alone and leaves MPI initialised for the process's exit (MPI
 *     cannot be initialised twice: the caller must not call MPI_Init later);
 *   - MPI is not initialised and the flag is not given: the job runs
 *     serially on this process without any MPI call (MPI stays
 *     uninitialised); its file is the one a 1-rank MPI run writes;
 *   - after MPI_Finalize: FRICTION_ERROR_INPUT.
 * Returns FRICTION_OK, an error code, or FRICTION_INTERRUPTED. */
int friction_run_job(const char *const *files, int nfiles, const char *output, int flags,
                     friction_report_fn report, void *user, friction_error *err);

/* Ask the job running in this process (friction_run_job, friction_run_config)
 * to stop at its next safe point: between two scan lines of a map, or two
 * points of a sweep.  The job then returns FRICTION_INTERRUPTED: a sweep
 * writes its file with the points done, a map writes no file and keeps the
 * lines done beside the output; the same job with FRICTION_JOB_RESUME
 * computes only the rest.  A brake trajectory that is not a sweep stops
 * within a 200th of its τ range and writes nothing.  Callable from any thread, from the job's report callback and
 * from a signal handler (one atomic store); a request made while no job
 * runs is forgotten when the next job begins.  Under MPI the request is
 * rank 0's: the other ranks finish their share first. */
void friction_job_stop(void);

/* The job of a configuration handle, as friction_run_job runs one read from
 * files: checked, computed (every group: &analysis, &verify, &sweep), and
 * written to `output`, whose `input` attribute is the configuration's text
 * (friction_config_text).  MPI and flags as friction_run_job. */
int friction_run_config(const friction_config *cfg, const char *output, int flags, friction_report_fn report,
                        void *user, friction_error *err);

/* ---- friction laws on their own (docs/laws.md) ---- */

/* A friction law by name ("coulomb", "arctan", "stribeck", "karnopp", "dahl",
 * "lugre", "elastoplastic", "rate_state", "table") with the &law defaults and
 * the &integrator of its states' integration (rodas4, rtol 1e-9, atol 1e-11
 * in units of each state's scale); NULL (and a message) for an unknown name.
 * Free it with friction_law_free (NULL is ignored). */
friction_law *friction_law_new(const char *model, friction_error *err);
void friction_law_free(friction_law *law);
/* Set, get, check by "group.variable" ("law.sigma0", "law.table_file",
 * "integrator.rtol"), with namelist value text or a number, as
 * friction_config_set, friction_config_set_real, friction_config_get and
 * friction_config_check do for a configuration.  A relative table_file is
 * relative to the process's working directory. */
int friction_law_set(friction_law *law, const char *name, const char *value, friction_error *err);
int friction_law_set_real(friction_law *law, const char *name, double x, friction_error *err);
int friction_law_get(const friction_law *law, const char *name, char *buf, size_t len, friction_error *err);
int friction_law_check(const friction_law *law, friction_error *err);
/* The number of the law's internal states (0 for a static law; 1 for LuGre's,
 * Dahl's and the elasto-plastic law's deflection z in m and rate and state's
 * age theta in s; the element count for GMS, each element's deflection in m);
 * -1 on an error. */
int friction_law_state_count(const friction_law *law, friction_error *err);
/* The law along a prescribed history at the n times t[i] (s, increasing):
 * u[i] the sliding velocity (m/s; displacement = 0, linear between the
 * samples) or the displacement (m; displacement = 1, linear between the
 * samples, so the velocity is constant on each interval).  force[i] (N) gets
 * the friction force (it resists the motion: the sign of v), and states (if
 * not NULL, states_len >= n * count) the internal states, states[i * count +
 * j].  normal is the normal load (N, finite, >= 0), used by the coefficient laws (coulomb,
 * arctan, rate_state).  The states start in steady sliding at the first
 * velocity.  The law is checked first; FRICTION_ERROR_NUMERICAL if the
 * integration fails. */
int friction_law_history(const friction_law *law, double normal, const double *t, const double *u, size_t n,
                         int displacement, double *force, double *states, size_t states_len, friction_error *err);

#ifdef __cplusplus
}
#endif

#endif /* FRICTION_H */
