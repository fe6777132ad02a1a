/* Linearly implicit Rosenbrock steppers with the analytic Jacobian, as GSL
 * odeiv2 step types: they plug into GSL's evolve, control and driver like
 * any GSL stepper (gsl_shim.c lists them in its table of step types).
 *
 * A step from (t, y) of size h with s stages, in the form of Hairer and
 * Wanner (the "transformed" Rosenbrock form without matrix-vector
 * products):
 *
 *   (I/(h gamma) - J) k_i = f(t + alpha_i h, y + sum_{j<i} a_ij k_j)
 *                           + sum_{j<i} (c_ij / h) k_j + gamma_i h df/dt
 *   y_new = y + sum_i m_i k_i,     error estimate  sum_i e_i k_i
 *
 * with J = df/dy and df/dt at (t, y) from the system's jacobian (the
 * systems here are non-autonomous: the AFM support moves with t).  One
 * Jacobian, one LU factorisation of the n x n matrix and s solves per
 * step (a step retried from the same point after a rejection keeps its
 * Jacobian and factorises again); no Newton iteration.  The order of the
 * method needs the exact Jacobian.
 *
 * Methods (coefficients from the papers, in the form above):
 *   rodas3  4 stages, order 3 with an embedded order 2, L-stable and
 *           stiffly accurate: A. Sandu, J. G. Verwer, J. G. Blom,
 *           E. J. Spee, G. R. Carmichael and F. A. Potra, "Benchmarking
 *           stiff ODE solvers for atmospheric chemistry problems II:
 *           Rosenbrock solvers", Atmospheric Environment 31 (1997)
 *           3459-3472 (method RODAS3).
 *   rodas4  6 stages, order 4 with an embedded order 3, L-stable and
 *           stiffly accurate: E. Hairer and G. Wanner, Solving Ordinary
 *           Differential Equations II, 2nd ed., Springer (1996),
 *           Sect. IV.7 (RODAS).
 * Both are stiffly accurate: y_new is the last stage's argument plus its
 * k, so for y' = lambda y the step's factor R(h lambda) tends to 0 as
 * h lambda -> -infinity.
 *
 * Failures: a singular matrix (a zero or non-finite pivot) or a
 * non-finite result returns GSL_ESING or GSL_FAILURE with y unchanged;
 * GSL's evolve then halves the step and tries again, and gives up (with
 * that status) once the step no longer changes t.  So does a right-hand
 * side that is not finite at a stage's trial state or at the step's end
 * (a step too long for a stiffness the Jacobian at its start did not
 * see).  A failing right-hand side at the step's start, or a failing
 * Jacobian, returns its own status (GSL_EBADFUNC: evolve stops).
 *
 * The right-hand side at the start of a step is the previous step's
 * dydt_out when the step starts where that one ended (same system, same t
 * and y bit for bit): evolve does not pass it (can_use_dydt_in = 0), and
 * a rejected step restarts from the same point, so both ends are kept.
 * reset forgets them. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "rosenbrock.h"

enum { max_stages = 6 };

struct rosenbrock_method {
    const char *name;
    int stages;
    unsigned int order;              /* of the error estimate's local error (GSL's "order") */
    double gamma;                    /* the diagonal: matrix I/(h gamma) - J */
    double a[max_stages][max_stages];  /* a_ij, j < i */
    double c[max_stages][max_stages];  /* c_ij, j < i */
    double alpha[max_stages];        /* stage times t + alpha_i h */
    double gamma_sum[max_stages];    /* gamma_i = sum_j gamma_ij, the df/dt weights */
    double m[max_stages];            /* solution weights */
    double e[max_stages];            /* error weights */
    int dense;                       /* has the continuous extension below */
    double d2[max_stages], d3[max_stages];  /* its weights (see friction_rosenbrock_dense) */
};

/* RODAS3 (Sandu et al. 1997). Stage 2 has the same
 * argument as stage 1 (a_21 = 0, alpha_2 = 0), so it reuses f. */
static const struct rosenbrock_method rodas3 = {
    "rodas3", 4, 3, 0.5,
    {{0}, {0.0}, {2.0, 0.0}, {2.0, 0.0, 1.0}},
    {{0}, {4.0}, {1.0, -1.0}, {1.0, -1.0, -8.0 / 3.0}},
    {0.0, 0.0, 1.0, 1.0},
    {0.5, 1.5, 0.0, 0.0},
    {2.0, 0.0, 1.0, 1.0},
    {0.0, 0.0, 0.0, 1.0},
    0, {0}, {0},
};

/* RODAS (Hairer and Wanner 1996, Sect. IV.7). */
static const struct rosenbrock_method rodas4 = {
    "rodas4", 6, 4, 0.25,
    {{0},
     {1.544},
     {0.9466785280815826, 0.2557011698983284},
     {3.314825187068521, 2.896124015972201, 0.9986419139977817},
     {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950},
     {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0}},
    {{0},
     {-5.6688},
     {-2.430093356833875, -0.2063599157091915},
     {-0.1073529058151375, -9.594562251023355, -20.47028614809616},
     {7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160},
     {8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136,
      -6.058818238834054}},
    {0.0, 0.386, 0.21, 0.63, 1.0, 1.0},
    {0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0},
    {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0, 1.0},
    {0.0, 0.0, 0.0, 0.0, 0.0, 1.0},
    /* The continuous extension of order 3 (docs/speed.md, "Dense output"):
     * the order conditions to order 3 for every theta and the index-1
     * condition of the algebraic components, solved with d_6 = 0. */
    1,
    {10.126235083445865, -7.487995877610194, -34.80091861555751, -7.992771707568842, 1.0251377232956649, 0.0},
    {-0.6762803392800684, 6.087714651680054, 16.430843208924582, 24.767225114183717, -6.594389125716781, 0.0},
};

/* A right-hand side value kept for reuse: f(t, y) of system sys. */
struct kept_rhs {
    int valid;
    const gsl_odeiv2_system *sys;
    double t;
    double *y, *f;
};

struct rosenbrock_state {
    const struct rosenbrock_method *method;
    int reuses_f[max_stages];        /* the stage's argument is the previous stage's: its f stands */
    size_t dim;
    double *y0, *ytmp, *f, *dfdt, *jac, *lu, *k;  /* k: stages x dim */
    double *inverse_pivot;           /* 1 / the factors' diagonal (lu_factor) */
    size_t *pivot;
    struct kept_rhs start, end;
    int jacobian_at_start;           /* jac and dfdt are those at `start` (a retried step reuses them) */
    /* The last accepted step, for its continuous extension: from (dense_t, y0)
     * to y1 over dense_h with the stages in k; dense_valid until the next try. */
    int dense_valid;
    double dense_t, dense_h, *y1;
    /* sum_i d2_i k_i and sum_i d3_i k_i of that step, once it is asked for a value */
    int dense_sums;
    double *d2k, *d3k;
};

static void kept_clear(struct kept_rhs *kept)
{
    kept->valid = 0;
}

static int kept_matches(const struct kept_rhs *kept, const gsl_odeiv2_system *sys, double t,
                        const double y[], size_t n)
{
    return kept->valid && kept->sys == sys && kept->t == t && memcmp(kept->y, y, n * sizeof *y) == 0;
}

static void kept_set(struct kept_rhs *kept, const gsl_odeiv2_system *sys, double t, const double y[],
                     const double f[], size_t n)
{
    kept->valid = 1;
    kept->sys = sys;
    kept->t = t;
    memcpy(kept->y, y, n * sizeof *y);
    memcpy(kept->f, f, n * sizeof *f);
}

static void *alloc_with(const struct rosenbrock_method *method, size_t dim)
{
    struct rosenbrock_state *s;
    double *block;
    size_t doubles;
    int stage, other;

    if (dim == 0) {
        GSL_ERROR_NULL("dimension of the system must be positive", GSL_EINVAL);
    }
    s = calloc(1, sizeof *s);
    /* y0, y1, ytmp, f, dfdt, 4 kept vectors, inverse_pivot, d2k, d3k: 12 n; jac, lu: 2 n^2; k: stages n */
    doubles = 12 * dim + 2 * dim * dim + (size_t)method->stages * dim;
    block = s != NULL ? malloc(doubles * sizeof *block) : NULL;
    if (block != NULL) s->pivot = malloc(dim * sizeof *s->pivot);
    if (s == NULL || block == NULL || s->pivot == NULL) {
        if (s != NULL) free(s->pivot);
        free(block);
        free(s);
        GSL_ERROR_NULL("failed to allocate space for the rosenbrock state", GSL_ENOMEM);
    }
    s->method = method;
    for (stage = 1; stage < method->stages; stage++) {
        int same = method->alpha[stage] == method->alpha[stage - 1] && method->a[stage][stage - 1] == 0.0;
        for (other = 0; other < stage - 1 && same; other++)
            if (method->a[stage][other] != method->a[stage - 1][other]) same = 0;
        s->reuses_f[stage] = same;
    }
    s->dim = dim;
    s->y0 = block;
    s->ytmp = s->y0 + dim;
    s->f = s->ytmp + dim;
    s->dfdt = s->f + dim;
    s->start.y = s->dfdt + dim;
    s->start.f = s->start.y + dim;
    s->end.y = s->start.f + dim;
    s->end.f = s->end.y + dim;
    s->jac = s->end.f + dim;
    s->lu = s->jac + dim * dim;
    s->k = s->lu + dim * dim;
    s->inverse_pivot = s->k + (size_t)method->stages * dim;
    s->y1 = s->inverse_pivot + dim;
    s->d2k = s->y1 + dim;
    s->d3k = s->d2k + dim;
    s->dense_valid = 0;
    kept_clear(&s->start);
    kept_clear(&s->end);
    s->jacobian_at_start = 0;
    return s;
}

static void *rodas3_alloc(size_t dim)
{
    return alloc_with(&rodas3, dim);
}

static void *rodas4_alloc(size_t dim)
{
    return alloc_with(&rodas4, dim);
}

/* LU factorisation with partial pivoting of the row-major n x n matrix a,
 * in place, and the reciprocals of U's diagonal (the solves multiply: a
 * division costs several multiplications' time and the stages' solves are
 * most of a step's own work); GSL_ESING for a zero or non-finite pivot. */
static inline __attribute__((always_inline)) int lu_factor(double *restrict a, double *restrict inverse_pivot, size_t *pivot, size_t n)
{
    size_t i, j, col, best;

    for (col = 0; col < n; col++) {
        double largest = fabs(a[col * n + col]);
        best = col;
        for (i = col + 1; i < n; i++)
            if (fabs(a[i * n + col]) > largest) {
                largest = fabs(a[i * n + col]);
                best = i;
            }
        pivot[col] = best;
        if (!(largest > 0.0) || !isfinite(largest)) return GSL_ESING;
        inverse_pivot[col] = 1.0 / a[best * n + col];
        if (best != col)
            for (j = 0; j < n; j++) {
                double swap = a[col * n + j];
                a[col * n + j] = a[best * n + j];
                a[best * n + j] = swap;
            }
        for (i = col + 1; i < n; i++) {
            double factor = a[i * n + col] * inverse_pivot[col];
            a[i * n + col] = factor;
            for (j = col + 1; j < n; j++) a[i * n + j] -= factor * a[col * n + j];
        }
    }
    return GSL_SUCCESS;
}

/* Solve with the factors of lu_factor: b is overwritten by x.  (Each row's
 * sum is kept in a register, not in b, which the compiler must otherwise
 * store and reload at every term.) */
static inline __attribute__((always_inline)) void lu_solve(const double *restrict lu, const double *restrict inverse_pivot,
                     const size_t *restrict pivot, size_t n, double *restrict b)
{
    size_t i, j;

    for (i = 0; i < n; i++) {
        if (pivot[i] != i) {
            double swap = b[i];
            b[i] = b[pivot[i]];
            b[pivot[i]] = swap;
        }
    }
    for (i = 1; i < n; i++) {
        double sum = b[i];
        for (j = 0; j < i; j++) sum -= lu[i * n + j] * b[j];
        b[i] = sum;
    }
    for (i = n; i-- > 0;) {
        double sum = b[i];
        for (j = i + 1; j < n; j++) sum -= lu[i * n + j] * b[j];
        b[i] = sum * inverse_pivot[i];
    }
}

/* The step, with y unchanged unless it succeeds; n = s->dim and stages =
 * s->method->stages, passed apart so that `step` can call it with
 * constants (below). */
static inline __attribute__((always_inline)) int step_sized(struct rosenbrock_state *s, double t, double h,
                                                            double y[], double yerr[], const double dydt_in[],
                                                            double dydt_out[], const gsl_odeiv2_system *sys,
                                                            const size_t n, const int stages)
{
    const struct rosenbrock_method *m = s->method;
    const double diagonal = 1.0 / (h * m->gamma), inverse_h = 1.0 / h;
    double c_over_h[max_stages][max_stages];
    size_t i, j;
    int stage, other, status;
    /* A retry from the same point (a rejected step) keeps f and the Jacobian. */
    const int retry = kept_matches(&s->start, sys, t, y, n);

    s->dense_valid = 0;
    if (!retry) s->jacobian_at_start = 0;
    /* f(t, y): given, kept from this point's previous try or from the last
     * step's end, or evaluated. */
    if (dydt_in != NULL) {
        memcpy(s->f, dydt_in, n * sizeof *s->f);
    } else if (retry) {
        memcpy(s->f, s->start.f, n * sizeof *s->f);
    } else if (kept_matches(&s->end, sys, t, y, n)) {
        memcpy(s->f, s->end.f, n * sizeof *s->f);
    } else {
        status = GSL_ODEIV_FN_EVAL(sys, t, y, s->f);
        if (status != GSL_SUCCESS) return status;
    }
    if (!retry || dydt_in != NULL) kept_set(&s->start, sys, t, y, s->f, n);

    if (!s->jacobian_at_start) {
        status = GSL_ODEIV_JA_EVAL(sys, t, y, s->jac, s->dfdt);
        if (status != GSL_SUCCESS) return status;
        s->jacobian_at_start = 1;
    }
    for (i = 0; i < n * n; i++) s->lu[i] = -s->jac[i];
    for (i = 0; i < n; i++) s->lu[i * n + i] += diagonal;
    status = lu_factor(s->lu, s->inverse_pivot, s->pivot, n);
    if (status != GSL_SUCCESS) return status;
    for (stage = 1; stage < stages; stage++)
        for (other = 0; other < stage; other++) c_over_h[stage][other] = m->c[stage][other] * inverse_h;

    for (stage = 0; stage < stages; stage++) {
        double *k = s->k + (size_t)stage * n;

        if (stage > 0 && !s->reuses_f[stage]) {
            for (i = 0; i < n; i++) {
                double sum = y[i];
                for (other = 0; other < stage; other++)
                    sum += m->a[stage][other] * s->k[(size_t)other * n + i];
                s->ytmp[i] = sum;
            }
            status = GSL_ODEIV_FN_EVAL(sys, t + m->alpha[stage] * h, s->ytmp, s->f);
            /* A stage's state is a trial, not the solution: where f is not finite there, the step
             * is too long for the stiffness the Jacobian at (t, y) did not see (Dahl's sigma0 |v| / F_c
             * at v = 0): rejected, evolve halves it. */
            if (status == GSL_EBADFUNC) return GSL_FAILURE;
            if (status != GSL_SUCCESS) return status;
        }
        for (i = 0; i < n; i++) {
            double sum = s->f[i] + m->gamma_sum[stage] * h * s->dfdt[i];
            for (other = 0; other < stage; other++)
                sum += c_over_h[stage][other] * s->k[(size_t)other * n + i];
            k[i] = sum;
        }
        lu_solve(s->lu, s->inverse_pivot, s->pivot, n, k);
    }

    for (i = 0; i < n; i++) {
        double sum = y[i], error = 0.0;
        for (stage = 0; stage < stages; stage++) {
            sum += m->m[stage] * s->k[(size_t)stage * n + i];
            error += m->e[stage] * s->k[(size_t)stage * n + i];
        }
        if (!isfinite(sum) || !isfinite(error)) return GSL_FAILURE;
        s->ytmp[i] = sum;
        yerr[i] = error;
    }

    if (dydt_out != NULL) {
        status = GSL_ODEIV_FN_EVAL(sys, t + h, s->ytmp, dydt_out);
        /* (The same at the step's end, whose error the control has not yet judged.) */
        if (status == GSL_EBADFUNC) return GSL_FAILURE;
        if (status != GSL_SUCCESS) return status;
        kept_set(&s->end, sys, t + h, s->ytmp, dydt_out, n);
    }
    if (m->dense) {
        memcpy(s->y0, y, n * sizeof *y);
        memcpy(s->y1, s->ytmp, n * sizeof *y);
        s->dense_t = t;
        s->dense_h = h;
        s->dense_valid = 1;
        s->dense_sums = 0;
    }
    for (j = 0; j < n; j++) y[j] = s->ytmp[j];
    return GSL_SUCCESS;
}

/* The step for the systems here, their sizes and the methods' stages as
 * constants: the compiler then unrolls the factorisation's, the solves' and
 * the stages' short loops, whose trip counts (1, 2, 3 ...) otherwise change
 * from loop to loop and cost a mispredicted branch each (the step's own
 * work was 210 ns, more than its right-hand sides, on the regularized
 * brake; size 3 is the machine with a law of one state).  Any other size
 * takes the general loops. */
static int step(struct rosenbrock_state *s, double t, double h, double y[], double yerr[],
                const double dydt_in[], double dydt_out[], const gsl_odeiv2_system *sys)
{
    const int stages = s->method->stages;

    if (s->dim == 3 && stages == 6) return step_sized(s, t, h, y, yerr, dydt_in, dydt_out, sys, 3, 6);
    if (s->dim == 4 && stages == 4) return step_sized(s, t, h, y, yerr, dydt_in, dydt_out, sys, 4, 4);
    if (s->dim == 4 && stages == 6) return step_sized(s, t, h, y, yerr, dydt_in, dydt_out, sys, 4, 6);
    if (s->dim == 6 && stages == 4) return step_sized(s, t, h, y, yerr, dydt_in, dydt_out, sys, 6, 4);
    if (s->dim == 6 && stages == 6) return step_sized(s, t, h, y, yerr, dydt_in, dydt_out, sys, 6, 6);
    return step_sized(s, t, h, y, yerr, dydt_in, dydt_out, sys, s->dim, stages);
}

static int rosenbrock_apply(void *vstate, size_t dim, double t, double h, double y[], double yerr[],
                            const double dydt_in[], double dydt_out[], const gsl_odeiv2_system *sys)
{
    struct rosenbrock_state *s = vstate;

    if (dim != s->dim) {
        GSL_ERROR("dimension of the system does not match the stepper", GSL_EINVAL);
    }
    if (sys->jacobian == NULL) {
        GSL_ERROR("no jacobian function given for the rosenbrock stepper", GSL_EFAULT);
    }
    if (!(h > 0.0 || h < 0.0)) {
        GSL_ERROR("step size must be non-zero", GSL_EINVAL);
    }
    /* (y itself is only written at the end of a successful step.) */
    return step(s, t, h, y, yerr, dydt_in, dydt_out, sys);
}

static int rosenbrock_set_driver(void *vstate, const gsl_odeiv2_driver *d)
{
    (void)vstate;
    (void)d;
    return GSL_SUCCESS;
}

static int rosenbrock_reset(void *vstate, size_t dim)
{
    struct rosenbrock_state *s = vstate;

    (void)dim;
    kept_clear(&s->start);
    kept_clear(&s->end);
    s->jacobian_at_start = 0;
    s->dense_valid = 0;
    return GSL_SUCCESS;
}

static unsigned int rosenbrock_order(void *vstate)
{
    const struct rosenbrock_state *s = vstate;

    return s->method->order;
}

static void rosenbrock_free(void *vstate)
{
    struct rosenbrock_state *s = vstate;

    if (s == NULL) return;
    free(s->y0);
    free(s->pivot);
    free(s);
}

int friction_rosenbrock_has_dense(const gsl_odeiv2_step_type *type)
{
    return type != NULL && type->alloc == rodas4_alloc;
}

/* The continuous extension of the last accepted step at t in [t0, t0 + h]:
 *
 *   y(t0 + theta h) = (1 - theta) y0 + theta y1
 *                     + theta (1 - theta) sum_i (d2_i + theta d3_i) k_i,
 *
 * a cubic in theta that meets both ends of the step exactly.  GSL_EINVAL
 * when there is no such step (none accepted since the last reset, a try
 * since, a method without the extension) or t is outside it. */
int friction_rosenbrock_dense(void *vstate, const gsl_odeiv2_step_type *type, double t, double y[])
{
    struct rosenbrock_state *s = vstate;
    const struct rosenbrock_method *m;
    double theta;
    size_t i, n;
    int stage;

    if (!friction_rosenbrock_has_dense(type) || s == NULL || !s->dense_valid) return GSL_EINVAL;
    m = s->method;
    n = s->dim;
    /* The step's end as evolve computes it is theta = 1 exactly: (t0 + h) - t0
     * rounded need not be h.  (Rounding may also put a time just before the
     * end a few ulps past 1.) */
    theta = t == s->dense_t + s->dense_h ? 1.0 : (t - s->dense_t) / s->dense_h;
    if (theta > 1.0 && theta <= 1.0 + 64.0 * DBL_EPSILON) theta = 1.0;
    if (!(theta >= 0.0 && theta <= 1.0)) return GSL_EINVAL;
    if (!s->dense_sums) {
        for (i = 0; i < n; i++) {
            double d2 = 0.0, d3 = 0.0;
            for (stage = 0; stage < m->stages; stage++) {
                d2 += m->d2[stage] * s->k[(size_t)stage * n + i];
                d3 += m->d3[stage] * s->k[(size_t)stage * n + i];
            }
            s->d2k[i] = d2;
            s->d3k[i] = d3;
        }
        s->dense_sums = 1;
    }
    for (i = 0; i < n; i++)
        y[i] = (1.0 - theta) * s->y0[i] + theta * (s->y1[i] + (1.0 - theta) * (s->d2k[i] + theta * s->d3k[i]));
    return GSL_SUCCESS;
}

static const gsl_odeiv2_step_type rodas3_type = {
    "rodas3", 0, 1, rodas3_alloc, rosenbrock_apply, rosenbrock_set_driver,
    rosenbrock_reset, rosenbrock_order, rosenbrock_free,
};

static const gsl_odeiv2_step_type rodas4_type = {
    "rodas4", 0, 1, rodas4_alloc, rosenbrock_apply, rosenbrock_set_driver,
    rosenbrock_reset, rosenbrock_order, rosenbrock_free,
};

const gsl_odeiv2_step_type *friction_step_rodas3 = &rodas3_type;
const gsl_odeiv2_step_type *friction_step_rodas4 = &rodas4_type;
