/* Every call of the library into GSL odeiv2 goes through here.
 *
 * 1. The table of step types (names, GSL types, whether they use the
 *    Jacobian): the only list of them.  Fortran reads it through
 *    friction_gsl_step_type_count / _name / _index / _uses_jacobian;
 *    include/friction.h documents the same names (a test compares).
 *    GSL exposes its step types as global pointer variables, which
 *    gfortran cannot import through bind(c) (it defines a zero copy of its
 *    own), so the table holds their addresses.  The Rosenbrock steppers of
 *    rosenbrock.c are step types of the same kind, the library's own.
 * 2. GSL's error handler: a process-wide variable that belongs to the
 *    program.  The library neither leaves it changed nor lets GSL abort
 *    (the default handler) or call the program's handler for an error of
 *    the library's own calls: see quiet_begin / quiet_end below.
 * 3. The driver's counters live in structs whose layout Fortran should not
 *    mirror, so they are read here too.
 *
 * Every function that calls GSL returns a GSL status, never GSL_SUCCESS when
 * GSL reported an error, even where GSL itself returns 0 after reporting
 * one (its GSL_ERROR_NULL in an int function: set_hmin, reset_hstart,
 * driver_apply).  friction_gsl_error_reason gives GSL's own words for the
 * last such error of the calling thread. */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_odeiv2.h>

#include "rosenbrock.h"

/* ---- the step types ---- */

static const struct step_type_entry {
    const char *name;                          /* as the input and the C API spell it */
    const gsl_odeiv2_step_type *const *type;   /* GSL's global pointer to the type */
    int uses_jacobian;                         /* implicit and BDF methods */
} step_types[] = {
    {"rk2", &gsl_odeiv2_step_rk2, 0},
    {"rk4", &gsl_odeiv2_step_rk4, 0},
    {"rkf45", &gsl_odeiv2_step_rkf45, 0},
    {"rkck", &gsl_odeiv2_step_rkck, 0},
    {"rk8pd", &gsl_odeiv2_step_rk8pd, 0},
    {"rk1imp", &gsl_odeiv2_step_rk1imp, 1},
    {"rk2imp", &gsl_odeiv2_step_rk2imp, 1},
    {"rk4imp", &gsl_odeiv2_step_rk4imp, 1},
    {"bsimp", &gsl_odeiv2_step_bsimp, 1},
    {"msadams", &gsl_odeiv2_step_msadams, 0},
    {"msbdf", &gsl_odeiv2_step_msbdf, 1},
    /* the library's own (rosenbrock.c) */
    {"rodas3", &friction_step_rodas3, 1},
    {"rodas4", &friction_step_rodas4, 1},
};
enum { step_type_count = (int)(sizeof step_types / sizeof step_types[0]) };

/* Number of step types; they are numbered 1..count. */
int friction_gsl_step_type_count(void)
{
    return step_type_count;
}

/* Name of step type index (1-based), NUL-terminated; NULL outside 1..count. */
const char *friction_gsl_step_type_name(int index)
{
    if (index < 1 || index > step_type_count) return NULL;
    return step_types[index - 1].name;
}

/* The same for Fortran: copies at most len characters of the name (no NUL)
 * into buffer, leaving the rest of it alone; nothing outside 1..count. */
void friction_gsl_step_type_name_copy(int index, char *buffer, size_t len)
{
    const char *name = friction_gsl_step_type_name(index);
    size_t n;
    if (name == NULL) return;
    n = strlen(name);
    memcpy(buffer, name, n < len ? n : len);
}

/* Index (1-based) of the step type called name[0..len-1] (exact, case
 * sensitive); 0 if there is none. */
int friction_gsl_step_type_index(const char *name, size_t len)
{
    int i;
    if (name == NULL) return 0;
    for (i = 0; i < step_type_count; i++)
        if (strlen(step_types[i].name) == len && memcmp(step_types[i].name, name, len) == 0)
            return i + 1;
    return 0;
}

/* 1 if step type index uses the Jacobian, 0 if not or unknown. */
int friction_gsl_step_type_uses_jacobian(int index)
{
    if (index < 1 || index > step_type_count) return 0;
    return step_types[index - 1].uses_jacobian;
}

/* ---- GSL's error handler, per call ----
 *
 * For the duration of each call into GSL the library installs its own
 * handler, `record`, which keeps the first error of the calling thread's
 * call (a thread-local slot) instead of aborting; afterwards the handler
 * that was in place before is put back.  The handler is one process-wide
 * variable while the C API lets threads call the library at once, so a
 * plain save/set/restore per call would race: thread A saves the
 * program's handler and installs `record`, thread B then saves `record`
 * as "the caller's", A restores the program's, B restores `record` -- and
 * the process is left with the library's handler.  Hence a count of the
 * calls in progress under a mutex: the first call to begin saves the
 * program's handler and installs `record`, later ones only count, and the
 * last to end restores the saved handler.  While any library call is in
 * progress the variable is not written at all, so GSL, reading it from
 * several library threads, always finds `record`.
 *
 * Other threads of the program may use GSL while a library call is in
 * progress and then meet `record` too: an error there (no library call in
 * progress on that thread) is passed on to the program's saved handler,
 * or to GSL's default behaviour (report and abort) when it had none, as if
 * the library were not there.  If the program installs a handler of its
 * own while a library call is in progress, that one stays when the last
 * call ends.  (Only GSL's reading of its variable while a program thread
 * writes it cannot be guarded from here.) */

static pthread_mutex_t quiet_lock = PTHREAD_MUTEX_INITIALIZER;
static int quiet_calls = 0;                        /* library calls in progress, all threads */
static gsl_error_handler_t *program_handler = NULL; /* in place before the first of them */

static _Thread_local int quiet_depth = 0;          /* this thread is in a library call */
static _Thread_local int recorded_errno = 0;       /* first GSL error of this thread's call */
static _Thread_local const char *recorded_reason = NULL;

static void record(const char *reason, const char *file, int line, int gsl_errno)
{
    gsl_error_handler_t *handler;

    if (quiet_depth > 0) {
        if (recorded_errno == 0) {
            recorded_errno = gsl_errno != GSL_SUCCESS ? gsl_errno : GSL_FAILURE;
            recorded_reason = reason;
        }
        return;
    }
    /* Not ours: the program's own GSL call on another thread. */
    pthread_mutex_lock(&quiet_lock);
    handler = program_handler;
    pthread_mutex_unlock(&quiet_lock);
    if (handler != NULL) {
        handler(reason, file, line, gsl_errno);
        return;
    }
    gsl_stream_printf("ERROR", file, line, reason);
    fflush(stdout);
    fprintf(stderr, "Default GSL error handler invoked.\n");
    fflush(stderr);
    abort();
}

static void quiet_begin(void)
{
    if (quiet_depth++ == 0) {
        recorded_errno = 0;
        recorded_reason = NULL;
    }
    pthread_mutex_lock(&quiet_lock);
    if (quiet_calls++ == 0) program_handler = gsl_set_error_handler(&record);
    pthread_mutex_unlock(&quiet_lock);
}

/* Ends a quiet section: status, or the error GSL reported if it returned
 * success all the same. */
static int quiet_end(int status)
{
    pthread_mutex_lock(&quiet_lock);
    if (--quiet_calls == 0) {
        gsl_error_handler_t *current = gsl_set_error_handler(program_handler);
        if (current != &record) gsl_set_error_handler(current);   /* the program's newer choice */
        /* program_handler stays: a program thread that read `record` just
         * before this restore still reaches the program's handler. */
    }
    pthread_mutex_unlock(&quiet_lock);
    quiet_depth--;
    if (status == GSL_SUCCESS && recorded_errno != 0) status = recorded_errno;
    return status;
}

/* GSL's words for the error it reported during this thread's last call
 * into it, or "" if it reported none (a status returned without a report). */
const char *friction_gsl_error_reason(void)
{
    return recorded_reason != NULL ? recorded_reason : "";
}

/* ---- the error control with a relative component ---- */

/* GSL's scaled control (a_y = 1, a_dydt = 0: the y_new control with an
 * absolute scale per component), and on one component, the slip rate of a
 * law that takes its logarithm, the further bound
 *
 *   D = min(eps_abs scale + eps_rel |y|, max(relative_fraction |y - reference|, floor)):
 *
 * an eps_abs above the slip rate would leave its error unmeasured, and a
 * Rosenbrock step whose stages carry the slip rate across 0 (the force
 * reverses) is then accepted (docs/speed.md, "Dense output").  The rest,
 * the step's adjustment included, is GSL's standard control to the bit, so
 * a run the bound never touches steps as before. */
static const double relative_fraction = 0.1;

struct relative_control {
    double eps_abs, eps_rel, reference, floor;
    size_t component, n;
    double *scale;
};

static void *relative_control_alloc(void)
{
    return calloc(1, sizeof(struct relative_control));
}

static int relative_control_init(void *vstate, double eps_abs, double eps_rel, double a_y, double a_dydt)
{
    struct relative_control *s = vstate;

    if (eps_abs < 0.0 || eps_rel < 0.0 || a_y != 1.0 || a_dydt != 0.0) return GSL_EINVAL;
    s->eps_abs = eps_abs;
    s->eps_rel = eps_rel;
    return GSL_SUCCESS;
}

static double relative_control_level(const struct relative_control *s, double y, size_t i)
{
    double level = s->eps_rel * fabs(y) + s->eps_abs * s->scale[i];

    if (i == s->component) {
        double bound = relative_fraction * fabs(y - s->reference);
        if (bound < s->floor) bound = s->floor;
        if (bound < level) level = bound;
    }
    return level;
}

/* As GSL's std_control_hadjust (control/cstd.c of GSL 2). */
static int relative_control_hadjust(void *vstate, size_t dim, unsigned int ord, const double y[],
                                    const double yerr[], const double yp[], double *h)
{
    const struct relative_control *s = vstate;
    const double safety = 0.9, h_old = *h;
    double rmax = DBL_MIN;
    size_t i;

    (void)yp;
    for (i = 0; i < dim && i < s->n; i++) {
        const double r = fabs(yerr[i]) / fabs(relative_control_level(s, y[i], i));
        rmax = GSL_MAX_DBL(r, rmax);
    }
    if (rmax > 1.1) {
        double r = safety / pow(rmax, 1.0 / ord);
        if (r < 0.2) r = 0.2;
        *h = r * h_old;
        return GSL_ODEIV_HADJ_DEC;
    }
    if (rmax < 0.5) {
        double r = safety / pow(rmax, 1.0 / (ord + 1.0));
        if (r > 5.0) r = 5.0;
        if (r < 1.0) r = 1.0;
        *h = r * h_old;
        return GSL_ODEIV_HADJ_INC;
    }
    return GSL_ODEIV_HADJ_NIL;
}

static int relative_control_errlevel(void *vstate, const double y, const double dydt, const double h,
                                     const size_t ind, double *errlev)
{
    const struct relative_control *s = vstate;

    (void)dydt;
    (void)h;
    if (ind >= s->n) return GSL_EINVAL;
    *errlev = relative_control_level(s, y, ind);
    return GSL_SUCCESS;
}

static int relative_control_set_driver(void *vstate, const gsl_odeiv2_driver *d)
{
    (void)vstate;
    (void)d;
    return GSL_SUCCESS;
}

static void relative_control_free(void *vstate)
{
    struct relative_control *s = vstate;

    if (s == NULL) return;
    free(s->scale);
    free(s);
}

static const gsl_odeiv2_control_type relative_control_type = {
    "relative", relative_control_alloc, relative_control_init, relative_control_hadjust,
    relative_control_errlevel, relative_control_set_driver, relative_control_free,
};

/* The control above for n components with these absolute scales (copied),
 * or NULL. */
static gsl_odeiv2_control *relative_control_new(double eps_abs, double eps_rel, const double scale[], size_t n,
                                                size_t component, double reference, double floor)
{
    gsl_odeiv2_control *c = gsl_odeiv2_control_alloc(&relative_control_type);
    struct relative_control *s;

    if (c == NULL) return NULL;
    s = c->state;
    s->scale = malloc(n * sizeof *s->scale);
    if (s->scale == NULL || gsl_odeiv2_control_init(c, eps_abs, eps_rel, 1.0, 0.0) != GSL_SUCCESS) {
        gsl_odeiv2_control_free(c);
        return NULL;
    }
    memcpy(s->scale, scale, n * sizeof *scale);
    s->n = n;
    s->component = component;
    s->reference = reference;
    s->floor = floor;
    return c;
}

/* ---- the driver ---- */

/* A driver for system sys with step type index (1-based), first step
 * hstart (non-zero) and the y_new error control on the first `controlled`
 * components (all of them when controlled >= the dimension); *driver is
 * NULL unless GSL_SUCCESS is returned.  The others are given an absolute
 * scale so large that their error never limits the step: GSL's scaled
 * control with a_y = 1, a_dydt = 0 and scale 1 is the y_new control.
 * relative (1-based, 0 for none) is a component whose error is further
 * held within a tenth of |y - reference|, down to floor (the control
 * above). */
int friction_gsl_driver_new(gsl_odeiv2_driver **driver, const gsl_odeiv2_system *sys, int index,
                            double hstart, double epsabs, double epsrel, int controlled, int relative,
                            double reference, double floor)
{
    gsl_odeiv2_driver *d;
    gsl_odeiv2_control *c = NULL;
    double *scale;
    size_t i, n = sys->dimension;
    int status, own_control;

    *driver = NULL;
    if (index < 1 || index > step_type_count) return GSL_EINVAL;
    if (controlled < 1) return GSL_EINVAL;
    if (relative < 0 || (size_t)relative > n || (relative > 0 && relative > controlled)) return GSL_EINVAL;
    if (relative > 0 && !(floor > 0.0 && isfinite(reference))) return GSL_EINVAL;
    /* GSL's own check of hstart (non-zero) comes after its allocations and
     * leaks them. */
    if (!(hstart > 0.0 || hstart < 0.0)) return GSL_EINVAL;
    own_control = (size_t)controlled < n || relative > 0;
    quiet_begin();
    d = gsl_odeiv2_driver_alloc_y_new(sys, *step_types[index - 1].type, hstart, epsabs, epsrel);
    if (d != NULL && own_control && (scale = malloc(n * sizeof *scale)) != NULL) {
        for (i = 0; i < n; i++) scale[i] = i < (size_t)controlled ? 1.0 : 1.0e200;
        /* (GSL copies the scales; so does relative_control_new.) */
        if (relative > 0)
            c = relative_control_new(epsabs, epsrel, scale, n, (size_t)relative - 1, reference, floor);
        else
            c = gsl_odeiv2_control_scaled_new(epsabs, epsrel, 1.0, 0.0, scale, n);
        free(scale);
        if (c != NULL) {
            gsl_odeiv2_control_free(d->c);
            d->c = c;
            gsl_odeiv2_control_set_driver(c, d);
        }
    }
    status = quiet_end(GSL_SUCCESS);
    if (d == NULL) return status != GSL_SUCCESS ? status : GSL_ENOMEM;
    if (status == GSL_SUCCESS && own_control && c == NULL) status = GSL_ENOMEM;
    if (status != GSL_SUCCESS) {
        quiet_begin();
        gsl_odeiv2_driver_free(d);
        quiet_end(GSL_SUCCESS);
        return status;
    }
    *driver = d;
    return GSL_SUCCESS;
}

/* The step budget per apply (0: none) and, if hmin > 0, the smallest step.
 * GSL refuses an hmin above the current step (reporting an error but
 * returning success): that comes back as GSL_EINVAL. */
int friction_gsl_driver_set_limits(gsl_odeiv2_driver *d, long nmax, double hmin)
{
    int status;

    quiet_begin();
    status = gsl_odeiv2_driver_set_nmax(d, (unsigned long)nmax);
    if (status == GSL_SUCCESS && hmin > 0.0) status = gsl_odeiv2_driver_set_hmin(d, hmin);
    return quiet_end(status);
}

/* Forget the history (multistep methods) and the counters; the next step
 * tried is hstart, which GSL requires within [hmin, hmax] and non-zero. */
int friction_gsl_driver_reset(gsl_odeiv2_driver *d, double hstart)
{
    int status;

    quiet_begin();
    status = gsl_odeiv2_driver_reset(d);
    /* reset_hstart resets again (harmlessly) but drops that status. */
    if (status == GSL_SUCCESS) status = gsl_odeiv2_driver_reset_hstart(d, hstart);
    return quiet_end(status);
}

/* gsl_odeiv2_driver_apply: from *t to t1. */
int friction_gsl_driver_apply(gsl_odeiv2_driver *d, double *t, double t1, double y[])
{
    quiet_begin();
    return quiet_end(gsl_odeiv2_driver_apply(d, t, t1, y));
}

/* gsl_odeiv2_driver_apply in parts: from *t towards t1 for at most `steps`
 * steps, with the same checks in the same order (the step budget of the
 * trip, h_max, h_min), so that the steps are the same, bit for bit, as one
 * apply; `first` starts the trip (its step count at 0).  *done is 1 once t1
 * is reached.  Between parts the caller may look at the clock or a stop
 * request: one apply gives it no chance until t1. */
int friction_gsl_driver_apply_part(gsl_odeiv2_driver *d, double *t, double t1, double y[], long steps,
                                   int first, int *done)
{
    int status = GSL_SUCCESS;
    long taken;

    *done = 0;
    if (first) d->n = 0;
    quiet_begin();
    if (first && !(t1 >= *t)) status = GSL_EINVAL;   /* (as apply: a step forwards, t1 behind) */
    for (taken = 0; status == GSL_SUCCESS && *t < t1 && taken < steps; taken++) {
        status = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, d->sys, t, t1, &d->h, y);
        if (status != GSL_SUCCESS) break;
        if (d->nmax > 0 && d->n > d->nmax) status = GSL_EMAXITER;
        else if (fabs(d->h) > d->hmax) d->h = copysign(d->hmax, d->h);
        if (status == GSL_SUCCESS && fabs(d->h) < d->hmin) status = GSL_ENOPROG;
        if (status == GSL_SUCCESS) d->n++;
    }
    status = quiet_end(status);
    if (status == GSL_SUCCESS && !(*t < t1)) *done = 1;
    return status;
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
    int status;

    quiet_begin();
    status = quiet_end(gsl_odeiv2_evolve_apply(d->e, d->c, d->s, d->sys, t, t1, &d->h, y));
    if (status != GSL_SUCCESS) return status;
    if (fabs(d->h) > d->hmax) d->h = copysign(d->hmax, d->h);
    if (*t != t1 && (fabs(d->h) < d->hmin || fabs(*t - t0) < d->hmin)) return GSL_ENOPROG;
    return GSL_SUCCESS;
}

void friction_gsl_driver_free(gsl_odeiv2_driver *d)
{
    if (d == NULL) return;
    quiet_begin();
    gsl_odeiv2_driver_free(d);
    quiet_end(GSL_SUCCESS);
}

/* Accepted steps and rejected (failed) steps since the last reset. */
void friction_gsl_driver_counts(const gsl_odeiv2_driver *d, long *steps, long *failed)
{
    *steps = (long)d->e->count;
    *failed = (long)d->e->failed_steps;
}

/* 1 if the driver's stepper has a continuous extension (dense output). */
int friction_gsl_driver_has_dense(const gsl_odeiv2_driver *d)
{
    return friction_rosenbrock_has_dense(d->s->type);
}

/* y at time t within the step the driver took last, from the stepper's
 * continuous extension; GSL_EINVAL without one or outside that step. */
int friction_gsl_driver_dense(const gsl_odeiv2_driver *d, double t, double y[])
{
    return friction_rosenbrock_dense(d->s->state, d->s->type, t, y);
}

/* The current step size the driver will try next. */
double friction_gsl_driver_step(const gsl_odeiv2_driver *d)
{
    return d->h;
}
