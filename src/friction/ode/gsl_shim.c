/* The few things of GSL odeiv2 that Fortran cannot reach directly.
 *
 * GSL exposes its step types as global pointer variables; gfortran cannot
 * import those through bind(c) (it defines a zero copy of its own), so they
 * are handed out here by index.  The driver's counters live in structs whose
 * layout Fortran should not mirror, so they are read here too. */
#include <math.h>
#include <stddef.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

/* Keep this order in step with step_type_names in solver.f90. */
const gsl_odeiv2_step_type *friction_gsl_step_type(int index)
{
    switch (index) {
    case 1: return gsl_odeiv2_step_rk2;
    case 2: return gsl_odeiv2_step_rk4;
    case 3: return gsl_odeiv2_step_rkf45;
    case 4: return gsl_odeiv2_step_rkck;
    case 5: return gsl_odeiv2_step_rk8pd;
    case 6: return gsl_odeiv2_step_rk1imp;
    case 7: return gsl_odeiv2_step_rk2imp;
    case 8: return gsl_odeiv2_step_rk4imp;
    case 9: return gsl_odeiv2_step_bsimp;
    case 10: return gsl_odeiv2_step_msadams;
    case 11: return gsl_odeiv2_step_msbdf;
    default: return NULL;
    }
}

/* A driver with GSL's abort-on-error handler switched off: every failure
 * then comes back as a status code.  The handler is process-wide; setting it
 * off again is harmless, so every driver does it. */
gsl_odeiv2_driver *friction_gsl_driver_new(const gsl_odeiv2_system *sys, int index,
                                           double hstart, double epsabs, double epsrel)
{
    const gsl_odeiv2_step_type *type = friction_gsl_step_type(index);
    gsl_set_error_handler_off();
    if (type == NULL) return NULL;
    return gsl_odeiv2_driver_alloc_y_new(sys, type, hstart, epsabs, epsrel);
}

/* Accepted steps and rejected (failed) steps since the last reset. */
void friction_gsl_driver_counts(const gsl_odeiv2_driver *d, long *steps, long *failed)
{
    *steps = (long)d->e->count;
    *failed = (long)d->e->failed_steps;
}

/* The current step size the driver will try next. */
double friction_gsl_driver_step(const gsl_odeiv2_driver *d)
{
    return d->h;
}

/* One accepted step from *t towards t1 (never past it), with the checks of
 * gsl_odeiv2_driver_apply (h_max, h_min) but without its step budget, which
 * a caller that looks at every step counts itself.  h_min applies to the
 * step just taken as well as to the next one proposed: evolve shrinks a
 * rejected step internally and may accept one far below h_min, then
 * propose a larger one, which the driver's check alone would let through.
 * A final step clamped to t1 is exempt (GSL's evolve does not shrink the
 * suggested step after it, so stepping onto output times is harmless). */
int friction_gsl_driver_step_once(gsl_odeiv2_driver *d, double *t, double t1, double y[])
{
    double t0 = *t;
    int status = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, d->sys, t, t1, &d->h, y);
    if (status != GSL_SUCCESS) return status;
    if (fabs(d->h) > d->hmax) d->h = copysign(d->hmax, d->h);
    if (*t != t1 && (fabs(d->h) < d->hmin || fabs(*t - t0) < d->hmin)) return GSL_ENOPROG;
    return GSL_SUCCESS;
}
