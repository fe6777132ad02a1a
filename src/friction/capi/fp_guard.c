/* The host's floating-point environment around the C API's computing calls.
 *
 * The floating-point environment (exception flags and which exceptions
 * trap) is the calling thread's, and the host owns it.  A host that traps
 * overflow or invalid operations (a Fortran program built with -ffpe-trap,
 * a C program that called feenableexcept) was killed by SIGFPE inside the
 * library when an accepted extreme value overflowed (tip.kx = 1e308), where
 * the library would have reported the failure; and every call left its own
 * flags raised (inexact, underflow) in the host's environment.
 *
 * So each of these calls saves the host's environment and runs with no
 * exception trapping and clear flags (feholdexcept), and puts the host's
 * back on return (fesetenv), traps and flags as they were.  The library's
 * failures come back as statuses, as they do for any host.  A job's report
 * callback and a computation's progress callback run inside the call, in
 * the library's environment.
 *
 * The Fortran bodies are the functions of capi.f90 under the names
 * friction_*_body; these wrappers carry the header's names. */
#include <fenv.h>
#include <stddef.h>

#include "friction.h"

/* Declares NAME_body and defines NAME: the body inside the host's
 * environment held and restored. */
#define FP_GUARDED(type, name, params, args)  \
  type name##_body params;                    \
  type name params                            \
  {                                           \
    fenv_t host;                              \
    feholdexcept(&host);                      \
    type result = name##_body args;           \
    fesetenv(&host);                          \
    return result;                            \
  }

FP_GUARDED(friction_config *, friction_config_new, (const char *scene, friction_error *err), (scene, err))

FP_GUARDED(int, friction_config_read, (friction_config *cfg, const char *path, friction_error *err),
           (cfg, path, err))

FP_GUARDED(int, friction_config_set,
           (friction_config *cfg, const char *name, const char *value, friction_error *err),
           (cfg, name, value, err))

FP_GUARDED(int, friction_config_set_real, (friction_config *cfg, const char *name, double x, friction_error *err),
           (cfg, name, x, err))

FP_GUARDED(int, friction_config_get,
           (const friction_config *cfg, const char *name, char *buf, size_t len, friction_error *err),
           (cfg, name, buf, len, err))

FP_GUARDED(int, friction_config_text, (const friction_config *cfg, char *buf, size_t len, size_t *needed),
           (cfg, buf, len, needed))

FP_GUARDED(int, friction_config_check, (const friction_config *cfg, friction_error *err), (cfg, err))

FP_GUARDED(int, friction_config_warnings, (const friction_config *cfg, char *buf, size_t len, size_t *needed),
           (cfg, buf, len, needed))

FP_GUARDED(int, friction_afm_line,
           (friction_config *cfg, int line, int forward, double *fx, double *fy, size_t n,
            friction_error *err),
           (cfg, line, forward, fx, fy, n, err))

FP_GUARDED(int, friction_afm_line_progress,
           (friction_config *cfg, int line, int forward, double *fx, double *fy, size_t n,
            friction_progress_fn progress, void *user, friction_error *err),
           (cfg, line, forward, fx, fy, n, progress, user, err))

FP_GUARDED(friction_result *, friction_compute, (friction_config *cfg, friction_error *err), (cfg, err))

FP_GUARDED(friction_result *, friction_compute_progress,
           (friction_config *cfg, friction_progress_fn progress, void *user, friction_error *err),
           (cfg, progress, user, err))

FP_GUARDED(int, friction_run_job,
           (const char *const *files, int nfiles, const char *output, int flags, friction_report_fn report,
            void *user, friction_error *err),
           (files, nfiles, output, flags, report, user, err))

FP_GUARDED(int, friction_run_config,
           (const friction_config *cfg, const char *output, int flags, friction_report_fn report, void *user,
            friction_error *err),
           (cfg, output, flags, report, user, err))

/* The friction laws (capi/law.f90). */
FP_GUARDED(friction_law *, friction_law_new, (const char *model, friction_error *err), (model, err))

FP_GUARDED(int, friction_law_set, (friction_law *law, const char *name, const char *value, friction_error *err),
           (law, name, value, err))

FP_GUARDED(int, friction_law_set_real, (friction_law *law, const char *name, double x, friction_error *err),
           (law, name, x, err))

FP_GUARDED(int, friction_law_get,
           (const friction_law *law, const char *name, char *buf, size_t len, friction_error *err),
           (law, name, buf, len, err))

FP_GUARDED(int, friction_law_check, (const friction_law *law, friction_error *err), (law, err))

FP_GUARDED(int, friction_law_history,
           (const friction_law *law, double normal, const double *t, const double *u, size_t n, int displacement,
            double *force, double *states, size_t states_len, friction_error *err),
           (law, normal, t, u, n, displacement, force, states, states_len, err))
