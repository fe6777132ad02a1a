/* The Rosenbrock steppers (src/friction/ode/rosenbrock.c) as GSL step types,
 * on problems with exact solutions:
 *
 *   order        Prothero-Robinson y' = lambda (y - g(t)) + g'(t), y = g(t)
 *                (non-autonomous: g = sin t + cos 2t), lambda = -1, fixed
 *                steps halving: the observed order of the global error, and
 *                of the embedded error estimate over one step, within 0.2
 *                of the method's.  Linear systems of 1, 2 and 3 damped
 *                rotations, each 2 x 2 with its own frequency (y = exp(At) y0
 *                in closed form), the same way: dimensions 2, 4 and 6, so
 *                that the stepper's loops for general sizes and those it
 *                specialises (4 and 6) are all checked.
 *   stiff        one step of y' = -1e9 y with h = 1: L-stable and stiffly
 *                accurate, so |y| ends near 0 (not near 1 as for an A-stable
 *                method with R(-inf) = -1 or 1).
 *   df/dt        y' = -lambda (y - sin t) + cos t, lambda = 1e4, y = sin t:
 *                the error through GSL's evolve at rtol 1e-8; with df/dt
 *                withheld (set to 0) the same fixed steps are far worse.
 *   dense        rodas4's continuous extension: it meets both ends of the
 *                step bit for bit; one step from the exact solution, its
 *                error inside the step falls as h^4 (the local error of a
 *                cubic of order 3) on Prothero-Robinson with lambda = -1
 *                and the damped rotations, and as h^3 at least with
 *                lambda = -1e6 (the stiff limit, where y is the algebraic
 *                g(t)); through GSL's evolve at rtol 1e-8 the values inside
 *                the steps are as close to the closed form as the steps'
 *                ends.  rodas3 has none: asking is GSL_EINVAL.
 *   bad paths    a singular matrix I/(h gamma) - J fails the step with
 *                GSL_ESING and y unchanged, and evolve recovers by halving
 *                the step; a Jacobian of NaN fails every step and evolve
 *                gives up with that status (no hang, no abort: GSL's default
 *                handler, which aborts, stays installed); no Jacobian is
 *                GSL_EFAULT.
 *
 * Usage: test_rosenbrock_steppers (exit status 0 when every check passes). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

extern const gsl_odeiv2_step_type *friction_step_rodas3;
extern const gsl_odeiv2_step_type *friction_step_rodas4;
int friction_rosenbrock_has_dense(const gsl_odeiv2_step_type *type);
int friction_rosenbrock_dense(void *state, const gsl_odeiv2_step_type *type, double t, double y[]);

static int failures = 0;

#define CHECK(cond, ...)                                  \
    do {                                                  \
        if (!(cond)) {                                    \
            failures++;                                   \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__); \
            fprintf(stderr, __VA_ARGS__);                 \
            fputc('\n', stderr);                          \
        }                                                 \
    } while (0)

/* ---- Prothero-Robinson ---- */

struct pr {
    double lambda;
    int with_dfdt;   /* 0: the Jacobian withholds df/dt (wrong on purpose) */
};

static double g(double t) { return sin(t) + cos(2.0 * t); }
static double gp(double t) { return cos(t) - 2.0 * sin(2.0 * t); }
static double gpp(double t) { return -sin(t) - 4.0 * cos(2.0 * t); }

static int pr_f(double t, const double y[], double f[], void *params)
{
    const struct pr *p = params;
    f[0] = p->lambda * (y[0] - g(t)) + gp(t);
    return GSL_SUCCESS;
}

static int pr_jac(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    const struct pr *p = params;
    (void)y;
    dfdy[0] = p->lambda;
    dfdt[0] = p->with_dfdt ? -p->lambda * gp(t) + gpp(t) : 0.0;
    return GSL_SUCCESS;
}

/* ---- y' = A y, A block diagonal with lin_blocks blocks [[-a, w_b], [-w_b, -a]]:
 * y = exp(-a t) R(-w_b t) y0 in each ---- */

enum { max_blocks = 3 };
static const double lin_a = 0.5;
static int lin_blocks = 1;

static double lin_w(int block) { return 3.0 + block; }

static int lin_f(double t, const double y[], double f[], void *params)
{
    int b;
    (void)t;
    (void)params;
    for (b = 0; b < lin_blocks; b++) {
        f[2 * b] = -lin_a * y[2 * b] + lin_w(b) * y[2 * b + 1];
        f[2 * b + 1] = -lin_w(b) * y[2 * b] - lin_a * y[2 * b + 1];
    }
    return GSL_SUCCESS;
}

static int lin_jac(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    const int n = 2 * lin_blocks;
    int b;
    (void)t;
    (void)y;
    (void)params;
    memset(dfdy, 0, (size_t)(n * n) * sizeof *dfdy);
    for (b = 0; b < lin_blocks; b++) {
        dfdy[2 * b * n + 2 * b] = -lin_a;
        dfdy[2 * b * n + 2 * b + 1] = lin_w(b);
        dfdy[(2 * b + 1) * n + 2 * b] = -lin_w(b);
        dfdy[(2 * b + 1) * n + 2 * b + 1] = -lin_a;
        dfdt[2 * b] = dfdt[2 * b + 1] = 0.0;
    }
    return GSL_SUCCESS;
}

static void lin_exact(double t, double y[])
{
    double e = exp(-lin_a * t);
    int b;
    for (b = 0; b < lin_blocks; b++) {
        y[2 * b] = e * cos(lin_w(b) * t);   /* y0 = (1, 0) in each block */
        y[2 * b + 1] = -e * sin(lin_w(b) * t);
    }
}

/* Global error at t_end after n fixed steps (no error control). */
static double fixed_steps(const gsl_odeiv2_step_type *type, gsl_odeiv2_system *sys, const double y0[],
                          double t_end, int n, void (*exact)(double, double[]))
{
    size_t dim = sys->dimension, i;
    gsl_odeiv2_step *s = gsl_odeiv2_step_alloc(type, dim);
    double y[2 * max_blocks], yerr[2 * max_blocks], dydt_out[2 * max_blocks], want[2 * max_blocks];
    double h = t_end / n, t = 0.0, error = 0.0;
    int k, status = GSL_SUCCESS;

    memcpy(y, y0, dim * sizeof *y);
    for (k = 0; k < n && status == GSL_SUCCESS; k++) {
        status = gsl_odeiv2_step_apply(s, t, h, y, yerr, NULL, dydt_out, sys);
        t = (k + 1) * h;
    }
    gsl_odeiv2_step_free(s);
    if (status != GSL_SUCCESS) return NAN;
    exact(t_end, want);
    for (i = 0; i < dim; i++) error = fmax(error, fabs(y[i] - want[i]));
    return error;
}

static void pr_exact(double t, double y[]) { y[0] = g(t); }

/* |yerr| of one step of size h from the exact y(t0). */
static double one_step_estimate(const gsl_odeiv2_step_type *type, gsl_odeiv2_system *sys, double t0, double h)
{
    gsl_odeiv2_step *s = gsl_odeiv2_step_alloc(type, 1);
    double y = g(t0), yerr = 0.0, out;
    int status = gsl_odeiv2_step_apply(s, t0, h, &y, &yerr, NULL, &out, sys);
    gsl_odeiv2_step_free(s);
    return status == GSL_SUCCESS ? fabs(yerr) : NAN;
}

static void check_order(const char *name, const gsl_odeiv2_step_type *type, double order)
{
    struct pr p = {-1.0, 1};
    gsl_odeiv2_system pr_sys = {pr_f, pr_jac, 1, &p};
    gsl_odeiv2_system lin_sys = {lin_f, lin_jac, 2, NULL};
    double y0[2] = {g(0.0), 0.0}, y0_lin[2 * max_blocks] = {1.0, 0.0, 1.0, 0.0, 1.0, 0.0};
    int n;

    /* Global error over [0, 2] with 10 ... 80 steps: log2 of successive
     * ratios.  (The errors stay far above rounding: 1e-9 and more.) */
    for (n = 10; n <= 40; n *= 2) {
        double e1 = fixed_steps(type, &pr_sys, y0, 2.0, n, pr_exact);
        double e2 = fixed_steps(type, &pr_sys, y0, 2.0, 2 * n, pr_exact);
        double observed = log2(e1 / e2);
        CHECK(fabs(observed - order) <= 0.2, "%s: Prothero-Robinson order %.3f with %d -> %d steps (errors %.3e, %.3e)",
              name, observed, n, 2 * n, e1, e2);
        for (lin_blocks = 1; lin_blocks <= max_blocks; lin_blocks++) {
            lin_sys.dimension = (size_t)(2 * lin_blocks);
            e1 = fixed_steps(type, &lin_sys, y0_lin, 2.0, n, lin_exact);
            e2 = fixed_steps(type, &lin_sys, y0_lin, 2.0, 2 * n, lin_exact);
            observed = log2(e1 / e2);
            CHECK(fabs(observed - order) <= 0.2,
                  "%s: linear system of dimension %d, order %.3f with %d -> %d steps (errors %.3e, %.3e)", name,
                  2 * lin_blocks, observed, n, 2 * n, e1, e2);
        }
    }
    /* The embedded estimate is y_new minus a solution of order p - 1: the
     * local error of that one, O(h^p). */
    for (n = 0; n < 3; n++) {
        double h = 0.02 / (1 << n);
        double e1 = one_step_estimate(type, &pr_sys, 0.3, h), e2 = one_step_estimate(type, &pr_sys, 0.3, h / 2);
        double observed = log2(e1 / e2);
        CHECK(fabs(observed - order) <= 0.2, "%s: embedded estimate of order %.3f (h = %g: %.3e, %.3e)", name,
              observed, h, e1, e2);
    }
}

/* ---- dense output ---- */

static const double dense_thetas[] = {0.2, 0.5, 0.8};

/* Largest error of the continuous extension at dense_thetas within one step
 * of size h from the exact y(t0); *ends_exact is cleared unless theta = 0
 * and 1 give y0 and the step's y bit for bit. */
static double dense_step_error(gsl_odeiv2_system *sys, double t0, double h, void (*exact)(double, double[]),
                               int *ends_exact)
{
    const gsl_odeiv2_step_type *type = friction_step_rodas4;
    size_t dim = sys->dimension, i, k;
    gsl_odeiv2_step *s = gsl_odeiv2_step_alloc(type, dim);
    double y[2 * max_blocks], y0[2 * max_blocks], yerr[2 * max_blocks], out[2 * max_blocks];
    double value[2 * max_blocks], want[2 * max_blocks], error = 0.0;
    int status;

    exact(t0, y);
    memcpy(y0, y, dim * sizeof *y);
    status = gsl_odeiv2_step_apply(s, t0, h, y, yerr, NULL, out, sys);
    if (status == GSL_SUCCESS) status = friction_rosenbrock_dense(s->state, type, t0, value);
    if (status == GSL_SUCCESS && memcmp(value, y0, dim * sizeof *y) != 0) *ends_exact = 0;
    if (status == GSL_SUCCESS) status = friction_rosenbrock_dense(s->state, type, t0 + h, value);
    if (status == GSL_SUCCESS && memcmp(value, y, dim * sizeof *y) != 0) *ends_exact = 0;
    for (k = 0; k < sizeof dense_thetas / sizeof dense_thetas[0] && status == GSL_SUCCESS; k++) {
        status = friction_rosenbrock_dense(s->state, type, t0 + dense_thetas[k] * h, value);
        exact(t0 + dense_thetas[k] * h, want);
        for (i = 0; i < dim; i++) error = fmax(error, fabs(value[i] - want[i]));
    }
    gsl_odeiv2_step_free(s);
    return status == GSL_SUCCESS ? error : NAN;
}

static void check_dense(void)
{
    struct pr mild = {-1.0, 1}, stiff = {-1.0e6, 1};
    gsl_odeiv2_system pr_sys = {pr_f, pr_jac, 1, &mild};
    gsl_odeiv2_system lin_sys = {lin_f, lin_jac, 2, NULL};
    int ends_exact = 1, n;

    CHECK(friction_rosenbrock_has_dense(friction_step_rodas4) && !friction_rosenbrock_has_dense(friction_step_rodas3),
          "rodas4 has dense output, rodas3 not");
    /* Local error C h^4 of the extension (its own, not a step's h^5):
     * log2 of the ratio from h to h/2 is 4; a weight that breaks one of
     * the order-3 conditions leaves h^3 (3), one of order 2 h^2. */
    for (n = 0; n < 3; n++) {
        double h = 0.05 / (1 << n), e1, e2, observed;
        e1 = dense_step_error(&pr_sys, 0.3, h, pr_exact, &ends_exact);
        e2 = dense_step_error(&pr_sys, 0.3, h / 2, pr_exact, &ends_exact);
        observed = log2(e1 / e2);
        CHECK(fabs(observed - 4.0) <= 0.3, "rodas4 dense output, Prothero-Robinson: order %.3f (h = %g: %.3e, %.3e)",
              observed, h, e1, e2);
        for (lin_blocks = 1; lin_blocks <= max_blocks; lin_blocks++) {
            lin_sys.dimension = (size_t)(2 * lin_blocks);
            e1 = dense_step_error(&lin_sys, 0.3, h, lin_exact, &ends_exact);
            e2 = dense_step_error(&lin_sys, 0.3, h / 2, lin_exact, &ends_exact);
            observed = log2(e1 / e2);
            CHECK(fabs(observed - 4.0) <= 0.3,
                  "rodas4 dense output, linear system of dimension %d: order %.3f (h = %g: %.3e, %.3e)",
                  2 * lin_blocks, observed, h, e1, e2);
        }
    }
    CHECK(ends_exact, "rodas4 dense output: theta = 0 and 1 give the step's ends bit for bit");
    /* The stiff limit: h |lambda| = 1e5 ... 2.5e4, y = g(t) algebraic. */
    pr_sys.params = &stiff;
    for (n = 0; n < 2; n++) {
        double h = 0.1 / (1 << n), e1, e2, observed;
        e1 = dense_step_error(&pr_sys, 0.3, h, pr_exact, &ends_exact);
        e2 = dense_step_error(&pr_sys, 0.3, h / 2, pr_exact, &ends_exact);
        observed = log2(e1 / e2);
        CHECK(observed >= 2.8, "rodas4 dense output, Prothero-Robinson lambda = -1e6: order %.3f (h = %g: %.3e, %.3e)",
              observed, h, e1, e2);
    }
    /* Controlled steps: the extension adds an error of the order of the
     * one the control bounds (the embedded estimate's, O(h^4) too), so its
     * values between the ends stay within a few times the ends' error. */
    {
        gsl_odeiv2_evolve *e;
        gsl_odeiv2_control *c;
        gsl_odeiv2_step *s;
        double y[6] = {1.0, 0.0, 1.0, 0.0, 1.0, 0.0}, want[6], value[6], t = 0.0, h = 1e-3;
        double at_ends = 0.0, inside = 0.0;
        int status = GSL_SUCCESS, steps = 0, k;
        size_t i;

        lin_blocks = 3;
        lin_sys.dimension = 6;
        s = gsl_odeiv2_step_alloc(friction_step_rodas4, 6);
        c = gsl_odeiv2_control_y_new(1e-10, 1e-8);
        e = gsl_odeiv2_evolve_alloc(6);
        while (t < 5.0 && status == GSL_SUCCESS) {
            double t0 = t;
            status = gsl_odeiv2_evolve_apply(e, c, s, &lin_sys, &t, 5.0, &h, y);
            steps++;
            lin_exact(t, want);
            for (i = 0; i < 6; i++) at_ends = fmax(at_ends, fabs(y[i] - want[i]));
            for (k = 0; k < 3 && status == GSL_SUCCESS; k++) {
                double tk = t0 + dense_thetas[k] * (t - t0);
                status = friction_rosenbrock_dense(s->state, friction_step_rodas4, tk, value);
                lin_exact(tk, want);
                for (i = 0; i < 6; i++) inside = fmax(inside, fabs(value[i] - want[i]));
            }
        }
        CHECK(status == GSL_SUCCESS && inside <= 3.0 * at_ends,
              "rodas4 dense output under evolve: status %d, %d steps, error %.3e inside the steps, %.3e at their ends",
              status, steps, inside, at_ends);
        /* Outside the last step, and after a reset: no value. */
        CHECK(friction_rosenbrock_dense(s->state, friction_step_rodas4, t + 1.0, value) == GSL_EINVAL,
              "rodas4 dense output beyond the step");
        gsl_odeiv2_step_reset(s);
        CHECK(friction_rosenbrock_dense(s->state, friction_step_rodas4, t, value) == GSL_EINVAL,
              "rodas4 dense output after a reset");
        gsl_odeiv2_evolve_free(e);
        gsl_odeiv2_control_free(c);
        gsl_odeiv2_step_free(s);
    }
}

/* ---- stiff decay ---- */

static int decay_f(double t, const double y[], double f[], void *params)
{
    (void)t;
    f[0] = *(const double *)params * y[0];
    return GSL_SUCCESS;
}

static int decay_jac(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    (void)t;
    (void)y;
    dfdy[0] = *(const double *)params;
    dfdt[0] = 0.0;
    return GSL_SUCCESS;
}

static void check_stiff_decay(const char *name, const gsl_odeiv2_step_type *type)
{
    double rate = -1.0e9, y = 1.0, yerr, out;
    gsl_odeiv2_system sys = {decay_f, decay_jac, 1, &rate};
    gsl_odeiv2_step *s = gsl_odeiv2_step_alloc(type, 1);
    int status = gsl_odeiv2_step_apply(s, 0.0, 1.0, &y, &yerr, NULL, &out, &sys);

    gsl_odeiv2_step_free(s);
    /* R(z) of an L-stable method falls as 1/z: about 1e-9 here.  An A-stable
     * method without that (R(-inf) = +-1) would leave |y| near 1. */
    CHECK(status == GSL_SUCCESS && fabs(y) < 1.0e-6, "%s: one step of y' = -1e9 y, h = 1: y = %.3e (status %d)",
          name, y, status);
}

/* ---- df/dt ---- */

static double nonautonomous_error(const gsl_odeiv2_step_type *type, int with_dfdt, int fixed)
{
    struct pr p = {-1.0e4, with_dfdt};
    gsl_odeiv2_system sys = {pr_f, pr_jac, 1, &p};
    double t = 0.0, y = g(0.0), t_end = 3.0, h = 1.0e-3;

    if (fixed) {
        double y0[1] = {g(0.0)};
        return fixed_steps(type, &sys, y0, t_end, 100, pr_exact);
    }
    {
        gsl_odeiv2_driver *d = gsl_odeiv2_driver_alloc_y_new(&sys, type, h, 1.0e-8, 1.0e-8);
        int status = gsl_odeiv2_driver_apply(d, &t, t_end, &y);
        gsl_odeiv2_driver_free(d);
        return status == GSL_SUCCESS ? fabs(y - g(t_end)) : NAN;
    }
}

static void check_dfdt(const char *name, const gsl_odeiv2_step_type *type)
{
    double adaptive = nonautonomous_error(type, 1, 0);
    double right = nonautonomous_error(type, 1, 1), withheld = nonautonomous_error(type, 0, 1);

    /* A local tolerance of 1e-8 on a contracting problem (lambda = -1e4):
     * the global error stays of that order; 1e-7 leaves a factor 10. */
    CHECK(adaptive < 1.0e-7, "%s: y' = -1e4 (y - g) + g' through evolve at 1e-8: error %.3e", name, adaptive);
    /* 100 fixed steps (h lambda = -300): with df/dt the stiffly accurate
     * method follows g; without it each step misses a term of order h g'',
     * damped only by 1/(h lambda), so the error is far larger. */
    CHECK(right < 1.0e-4 && withheld > 10.0 * right,
          "%s: 100 fixed steps: error %.3e with df/dt, %.3e without", name, right, withheld);
}

/* ---- bad paths ---- */

static int nan_jac(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    (void)t;
    (void)y;
    (void)params;
    dfdy[0] = NAN;
    dfdt[0] = 0.0;
    return GSL_SUCCESS;
}

static void check_bad_paths(const char *name, const gsl_odeiv2_step_type *type, double gamma)
{
    /* y' = c y with c = 1/(h gamma): the matrix I/(h gamma) - J is zero. */
    double c = 2.0, h = 1.0 / (c * gamma), y = 1.0, yerr, out, t = 0.0;
    gsl_odeiv2_system sys = {decay_f, decay_jac, 1, &c};
    gsl_odeiv2_step *s = gsl_odeiv2_step_alloc(type, 1);
    int status = gsl_odeiv2_step_apply(s, 0.0, h, &y, &yerr, NULL, &out, &sys);

    CHECK(status == GSL_ESING && y == 1.0, "%s: singular matrix: status %d, y = %g", name, status, y);
    gsl_odeiv2_step_free(s);
    {
        /* Through evolve: the failed step is halved and the run goes on to
         * the right answer e^(c t). */
        gsl_odeiv2_driver *d = gsl_odeiv2_driver_alloc_y_new(&sys, type, h, 1.0e-10, 1.0e-10);
        y = 1.0;
        status = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, &sys, &t, 1.0, &d->h, &y);
        CHECK(status == GSL_SUCCESS && t > 0.0 && d->e->failed_steps >= 1,
              "%s: evolve after a singular matrix: status %d, t = %g, %lu failed", name, status, t,
              (unsigned long)d->e->failed_steps);
        status = gsl_odeiv2_driver_apply(d, &t, 1.0, &y);
        CHECK(status == GSL_SUCCESS && fabs(y / exp(c) - 1.0) < 1.0e-8, "%s: y' = 2y to t = 1: %.12g (status %d)",
              name, y, status);
        gsl_odeiv2_driver_free(d);
    }
    {
        /* A Jacobian of NaN: every try fails; evolve halves the step until it
         * no longer moves t, then returns the status with t and y as they were. */
        gsl_odeiv2_system bad = {decay_f, nan_jac, 1, &c};
        gsl_odeiv2_driver *d = gsl_odeiv2_driver_alloc_y_new(&bad, type, 0.1, 1.0e-6, 1.0e-6);
        t = 0.0;
        y = 1.0;
        status = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, &bad, &t, 1.0, &d->h, &y);
        CHECK(status == GSL_ESING && t == 0.0 && y == 1.0, "%s: NaN Jacobian: status %d, t = %g, y = %g", name,
              status, t, y);
        gsl_odeiv2_driver_free(d);
    }
    {
        gsl_error_handler_t *old = gsl_set_error_handler_off();
        gsl_odeiv2_system none = {decay_f, NULL, 1, &c};
        s = gsl_odeiv2_step_alloc(type, 1);
        y = 1.0;
        status = gsl_odeiv2_step_apply(s, 0.0, 0.1, &y, &yerr, NULL, &out, &none);
        CHECK(status == GSL_EFAULT && y == 1.0, "%s: no Jacobian: status %d", name, status);
        gsl_odeiv2_step_free(s);
        gsl_set_error_handler(old);
    }
}

int main(void)
{
    const struct {
        const char *name;
        const gsl_odeiv2_step_type *type;
        double order, gamma;
    } methods[] = {{"rodas3", NULL, 3.0, 0.5}, {"rodas4", NULL, 4.0, 0.25}};
    const gsl_odeiv2_step_type *types[] = {friction_step_rodas3, friction_step_rodas4};
    size_t m;

    for (m = 0; m < 2; m++) {
        const gsl_odeiv2_step_type *type = types[m];
        gsl_odeiv2_step *s = gsl_odeiv2_step_alloc(type, 1);
        CHECK(strcmp(gsl_odeiv2_step_name(s), methods[m].name) == 0, "name %s", gsl_odeiv2_step_name(s));
        /* GSL's control takes the order of the error estimate's local error. */
        CHECK(gsl_odeiv2_step_order(s) == (unsigned int)methods[m].order, "%s: order %u", methods[m].name,
              gsl_odeiv2_step_order(s));
        gsl_odeiv2_step_free(s);
        check_order(methods[m].name, type, methods[m].order);
        check_stiff_decay(methods[m].name, type);
        check_dfdt(methods[m].name, type);
        check_bad_paths(methods[m].name, type, methods[m].gamma);
    }
    check_dense();
    if (failures == 0) printf("test_rosenbrock_steppers: all checks passed\n");
    return failures == 0 ? 0 : 1;
}
