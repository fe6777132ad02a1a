/* friction: C API of the dry-friction kernel (AFM scan lines, Girling brake).
 *
 * Every function returns an int status: FRICTION_OK (0) on success, else one
 * of the FRICTION_ERROR_* codes.  Functions that take a friction_error handle
 * also store the status and a message in it when the handle is not NULL; the
 * handle is owned by the caller (friction_error_new / friction_error_free).
 * The library never prints and never stops the process.
 *
 * Reentrant: the library keeps no mutable global state, so threads may call
 * it at once, each with its own arrays and its own error handle.
 *
 * Units are those of the namelist input (docs/input.md).
 */
#ifndef FRICTION_H
#define FRICTION_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
  FRICTION_OK = 0,
  FRICTION_ERROR_INPUT = 1,     /* bad argument: null, too small, unknown name, non-physical value */
  FRICTION_ERROR_NUMERICAL = 2, /* the integration failed */
  FRICTION_ERROR_IO = 3,
  FRICTION_ERROR_INTERNAL = 4,
  FRICTION_INTERRUPTED = 5      /* friction_run_job: a sweep stopped early; its file is valid, resumable */
};

/* Opaque error handle. */
typedef struct friction_error friction_error;

/* Library version ("major.minor.patch") into buf of len bytes, NUL-terminated.
 * FRICTION_ERROR_INPUT if buf is NULL or too small (then truncated). */
int friction_version(char *buf, size_t len);

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

/* One AFM scan line (the CLI's first line of a map with the same settings):
 * the lateral force fx[i], fy[i] (nN) with the support at
 * (x0, y0) + i length/(nx-1) (cos angle, sin angle), i = 0..nx-1.
 *   potential  "naf" (V0 eV, periods ax, ay Å) or "hopg" (V0 eV, lattice a Å)
 *   mass kg > 0; kx, ky N/m >= 0; cx, cy N s/m >= 0; velocity Å/s > 0
 *   x0, y0 Å; angle degrees; length Å > 0; nx >= 2
 *   forward    non-zero: trace (support from x0,y0 outwards); zero: retrace
 *              (from the far end back; still stored by position i)
 *   stepper    GSL step type: rk2 rk4 rkf45 rkck rk8pd rk1imp rk2imp rk4imp
 *              bsimp msadams msbdf, or "auto" (docs/speed.md);
 *              rtol, atol > 0
 *   fx, fy     caller arrays of nx doubles */
int friction_afm_line(const char *potential, double v0, double ax, double ay, double a,
                      double mass, double kx, double ky, double cx, double cy,
                      double velocity, double x0, double y0, double angle, double length,
                      int nx, int forward, const char *stepper, double rtol, double atol,
                      double *fx, double *fy, friction_error *err);

/* The Girling brake (Eq. 10, nondimensional parameters as in &brake) from the
 * state x = y = 0, x' = v_dr, y' = 0 on the grid t = 0, dt_out, ..., t_end (τ):
 * block displacement x, velocity v, crank arm displacement y and velocity w
 * into caller arrays of length n.
 *   model      "switched" or "regularized"
 *   needed     if not NULL, receives the number of grid points; when n is
 *              smaller the call fails with FRICTION_ERROR_INPUT and writes
 *              nothing else, so a caller may ask with n = 0 first. */
/* Checks as the namelist: xi, kappa, t_end, dt_out, rtol, atol > 0; mu, mu_s,
 * delta_prime >= 0; epsilon_prime > 0 for "regularized"; mu <= mu_s for
 * "switched"; all finite.  An initial normal force N' <= 0 is an input error. */
int friction_brake(const char *model, double xi, double kappa, double g_prime, double mu,
                   double mu_s, double epsilon_prime, double delta_prime, double v_dr,
                   double t_end, double dt_out, const char *stepper, double rtol, double atol,
                   double *t, double *x, double *v, double *y, double *w, size_t n,
                   size_t *needed, friction_error *err);

/* A whole job, as the command line runs it: the namelist files (later files
 * override earlier values variable by variable) are read, the scene or sweep
 * they describe is computed and `output` (HDF5) is written under a temporary
 * name and renamed when complete; nothing is written on an error.
 *   files, nfiles  the namelist files, as on the command line
 *   output         the HDF5 file to write
 *   flags          FRICTION_JOB_FORCE: overwrite an existing output;
 *                  FRICTION_JOB_RESUME: a sweep reuses the checkpoints of an
 *                  interrupted run (as --resume)
 *   report         if not NULL, called (on rank 0) with progress, message
 *                  "12 of 64 lines" and fraction in [0, 1], and with notes
 *                  (a verify result), fraction -1; user is passed through
 * MPI: collective over MPI_COMM_WORLD when the caller has initialised MPI
 * (every rank calls it with the same arguments); otherwise the library
 * initialises MPI once (MPI_THREAD_FUNNELED), runs on this process alone and
 * leaves MPI to the process's exit.  Unlike the other functions, call it from
 * one thread at a time.  Returns FRICTION_OK, an error code, or
 * FRICTION_INTERRUPTED. */
enum { FRICTION_JOB_FORCE = 1, FRICTION_JOB_RESUME = 2 };
typedef void (*friction_report_fn)(const char *message, double fraction, void *user);
int friction_run_job(const char *const *files, int nfiles, const char *output, int flags,
                     friction_report_fn report, void *user, friction_error *err);

#ifdef __cplusplus
}
#endif

#endif /* FRICTION_H */
