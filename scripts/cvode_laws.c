/* The machine scene's stiff friction laws integrated by SUNDIALS CVODE: the
 * peer of `friction` in scripts/benchmark_laws.py.
 *
 * The same two cases as the benchmark's SciPy runs (and as the program's
 * inputs/machine_lugre.nml and machine_rate_state.nml with the benchmark's
 * settings), in the state (x, v, z) of a block of mass m on a spring:
 *   lugre       LuGre (Table I of its paper: sigma0 = 1e5 N/m, sigma1 =
 *               sqrt(1e5) N s/m, sigma2 = 0.4 N s/m, F_c = 1 N, F_s = 1.5 N,
 *               v_s = 1e-3 m/s) on a belt at 0.1 m/s, m = 1 kg, k = 2 N/m,
 *               30 s; z the bristles' deflection
 *   rate_state  Dieterich-Ruina with the aging law and the regularized
 *               friction a asinh(v/(2 V0) e^(psi/a)), a spring-slider at
 *               k = 0.2 k_c pulled at 1e-6 m/s, 3000 s; z the state theta
 * CVODE as a C user sets it up for a stiff problem: BDF with a dense direct
 * linear solver and the analytic Jacobian (with CVODE's own difference
 * quotients the Newton iteration fails on the rate-and-state slips at every
 * tolerance from 1e-4 to 1e-8, flag -4), scalar tolerances
 * (atol = rtol x 1e-3, as the benchmark's other runs), CV_NORMAL output at
 * each grid point (CVODE interpolates there).
 *
 * Usage: cvode_laws CASE RTOL ATOL DT_OUT OUT [T_END]
 *   T_END  the span's end in s (default the case's: 30 s, 3000 s)
 *   OUT  x on the grid t = 0, DT_OUT, ..., t_end as raw doubles; built with
 *        -DCVODE_LAWS_HDF5 (and HDF5's C library), an HDF5 file instead with
 *        what the program's file holds of the run: group /machine with the
 *        datasets t, x, v, the third state (z for LuGre, theta for rate and
 *        state) and the friction force, each with its "units" attribute, as a
 *        C user who keeps their result writes it
 * Prints one line of JSON: steps, rhs_evaluations, jacobian_evaluations,
 * seconds and cpu_seconds (the integration alone, wall and CPU time: from its
 * state vector's creation to the last output point).
 * Exit 1 on bad arguments, 2 on a CVODE failure, 3 on an output failure. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#ifdef CVODE_LAWS_HDF5
#include <hdf5.h>
#endif

typedef struct {
    int rate_state;
    /* LuGre */
    double m, k, belt, fc, fs, vs, s0, s1, s2;
    /* rate and state */
    double normal, a, b, dc, v0, mu0, pull, stiffness;
} case_t;

static double stribeck(const case_t *p, double w)
{
    return p->fc + (p->fs - p->fc) * exp(-(w / p->vs) * (w / p->vs));
}

static int rhs(double t, N_Vector yv, N_Vector dv, void *data)
{
    const case_t *p = data;
    const double *y = N_VGetArrayPointer(yv);
    double *d = N_VGetArrayPointer(dv);
    if (!p->rate_state) {
        double w = y[1] - p->belt;
        double zdot = w - p->s0 * fabs(w) * y[2] / stribeck(p, w);
        d[0] = y[1];
        d[1] = (-p->k * y[0] - (p->s0 * y[2] + p->s1 * zdot + p->s2 * w)) / p->m;
        d[2] = zdot;
    } else {
        double theta = y[2] > 1e-300 ? y[2] : 1e-300;
        double speed = fabs(y[1]) > 1e-300 ? fabs(y[1]) : 1e-300;
        double psi = p->mu0 + p->b * log(p->v0 * theta / p->dc);
        double big = log(speed / (2.0 * p->v0)) + psi / p->a;
        double sign = (y[1] > 0) - (y[1] < 0);
        /* asinh(s e^big) for large big is s (big + ln 2): no overflow of the exponential */
        double mu = big > 18.0 ? sign * p->a * (big + log(2.0)) : p->a * asinh(sign * exp(big));
        d[0] = y[1];
        d[1] = (-p->stiffness * (y[0] - p->pull * t) - p->normal * mu) / p->m;
        d[2] = 1.0 - fabs(y[1]) * y[2] / p->dc;
    }
    return 0;
}

static int jacobian(double t, N_Vector yv, N_Vector fy, SUNMatrix jm, void *data, N_Vector t1, N_Vector t2,
                    N_Vector t3)
{
    (void)t; (void)fy; (void)t1; (void)t2; (void)t3;
    const case_t *p = data;
    const double *y = N_VGetArrayPointer(yv);
    SUNMatZero(jm);
    SM_ELEMENT_D(jm, 0, 1) = 1.0;
    if (!p->rate_state) {
        double w = y[1] - p->belt, g = stribeck(p, w);
        double dg = (p->fs - p->fc) * exp(-(w / p->vs) * (w / p->vs)) * (-2.0 * w / (p->vs * p->vs));
        double sign = (w > 0) - (w < 0);
        double dzdot_dv = 1.0 - p->s0 * y[2] * (sign * g - fabs(w) * dg) / (g * g);
        double dzdot_dz = -p->s0 * fabs(w) / g;
        SM_ELEMENT_D(jm, 1, 0) = -p->k / p->m;
        SM_ELEMENT_D(jm, 1, 1) = -(p->s1 * dzdot_dv + p->s2) / p->m;
        SM_ELEMENT_D(jm, 1, 2) = -(p->s0 + p->s1 * dzdot_dz) / p->m;
        SM_ELEMENT_D(jm, 2, 1) = dzdot_dv;
        SM_ELEMENT_D(jm, 2, 2) = dzdot_dz;
    } else {
        double theta = y[2] > 1e-300 ? y[2] : 1e-300;
        double speed = fabs(y[1]) > 1e-300 ? fabs(y[1]) : 1e-300;
        double psi = p->mu0 + p->b * log(p->v0 * theta / p->dc);
        double big = log(speed / (2.0 * p->v0)) + psi / p->a;
        double sign = (y[1] > 0) - (y[1] < 0);
        double dmu_dv, dmu_dtheta;
        if (big > 18.0) { /* mu = s a (big + ln 2) */
            dmu_dv = p->a / speed;
            dmu_dtheta = sign * p->b / theta;
        } else {
            double e = exp(psi / p->a) / (2.0 * p->v0), s = y[1] * e, root = sqrt(1.0 + s * s);
            dmu_dv = p->a * e / root;
            dmu_dtheta = p->b * s / (theta * root);
        }
        SM_ELEMENT_D(jm, 1, 0) = -p->stiffness / p->m;
        SM_ELEMENT_D(jm, 1, 1) = -p->normal * dmu_dv / p->m;
        SM_ELEMENT_D(jm, 1, 2) = -p->normal * dmu_dtheta / p->m;
        SM_ELEMENT_D(jm, 2, 1) = -sign * y[2] / p->dc;
        SM_ELEMENT_D(jm, 2, 2) = -fabs(y[1]) / p->dc;
    }
    return 0;
}

#ifdef CVODE_LAWS_HDF5
/* The friction force on the block at state y (as rhs computes it): LuGre's
 * sigma0 z + sigma1 dz/dt + sigma2 w, rate and state's N mu. */
static double friction_force(const case_t *p, const double *y)
{
    if (!p->rate_state) {
        double w = y[1] - p->belt;
        double zdot = w - p->s0 * fabs(w) * y[2] / stribeck(p, w);
        return p->s0 * y[2] + p->s1 * zdot + p->s2 * w;
    }
    double theta = y[2] > 1e-300 ? y[2] : 1e-300;
    double speed = fabs(y[1]) > 1e-300 ? fabs(y[1]) : 1e-300;
    double psi = p->mu0 + p->b * log(p->v0 * theta / p->dc);
    double big = log(speed / (2.0 * p->v0)) + psi / p->a;
    double sign = (y[1] > 0) - (y[1] < 0);
    double mu = big > 18.0 ? sign * p->a * (big + log(2.0)) : p->a * asinh(sign * exp(big));
    return p->normal * mu;
}

/* One dataset of n doubles with its units: 0 or -1. */
static int write_series(hid_t group, const char *name, const double *values, long n, const char *units)
{
    hsize_t size = (hsize_t)n;
    hid_t space = H5Screate_simple(1, &size, NULL);
    hid_t set = H5Dcreate2(group, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    herr_t status = set < 0 ? -1 : H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values);
    hid_t text = H5Tcopy(H5T_C_S1), scalar = H5Screate(H5S_SCALAR);
    H5Tset_size(text, strlen(units));
    H5Tset_cset(text, H5T_CSET_UTF8);
    hid_t attribute = set < 0 ? -1 : H5Acreate2(set, "units", text, scalar, H5P_DEFAULT, H5P_DEFAULT);
    if (attribute < 0 || H5Awrite(attribute, text, units) < 0) status = -1;
    if (attribute >= 0) H5Aclose(attribute);
    H5Sclose(scalar);
    H5Tclose(text);
    if (set >= 0) H5Dclose(set);
    H5Sclose(space);
    return status < 0 ? -1 : 0;
}

/* The run's file: /machine/{t, x, v, z or theta, force}; 0 or -1. */
static int write_file(const char *path, const case_t *p, const double *t, const double *states, long n)
{
    double *column = malloc(sizeof(double) * (size_t)n);
    hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t group = file < 0 ? -1 : H5Gcreate2(file, "machine", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int status = column == NULL || group < 0 ? -1 : write_series(group, "t", t, n, "s");
    static const char *names[2][3] = {{"x", "v", "z"}, {"x", "v", "theta"}};
    static const char *units[2][3] = {{"m", "m/s", "m"}, {"m", "m/s", "s"}};
    for (int j = 0; j < 3 && status == 0; ++j) {
        for (long i = 0; i < n; ++i) column[i] = states[3 * i + j];
        status = write_series(group, names[p->rate_state][j], column, n, units[p->rate_state][j]);
    }
    if (status == 0) {
        for (long i = 0; i < n; ++i) column[i] = friction_force(p, &states[3 * i]);
        status = write_series(group, "force", column, n, "N");
    }
    if (group >= 0 && H5Gclose(group) < 0) status = -1;
    if (file >= 0 && H5Fclose(file) < 0) status = -1;
    free(column);
    return file < 0 ? -1 : status;
}
#endif

int main(int argc, char **argv)
{
    if (argc != 6 && argc != 7) {
        fprintf(stderr, "usage: cvode_laws lugre|rate_state RTOL ATOL DT_OUT OUT.bin [T_END]\n");
        return 1;
    }
    case_t p = {0};
    double y0[3], t_end;
    if (strcmp(argv[1], "lugre") == 0) {
        p = (case_t){.m = 1.0, .k = 2.0, .belt = 0.1, .fc = 1.0, .fs = 1.5, .vs = 1e-3, .s0 = 1e5,
                     .s1 = sqrt(1e5), .s2 = 0.4};
        y0[0] = 0.0;
        y0[1] = 0.0;
        y0[2] = -stribeck(&p, -p.belt) / p.s0;
        t_end = 30.0;
    } else if (strcmp(argv[1], "rate_state") == 0) {
        p = (case_t){.rate_state = 1, .m = 1.0, .normal = 1.0, .a = 0.010, .b = 0.015, .dc = 1e-5, .v0 = 1e-6,
                     .mu0 = 0.6, .pull = 1e-6};
        p.stiffness = 0.2 * p.normal * (p.b - p.a) / p.dc;
        y0[0] = -p.mu0 * p.normal / p.stiffness;
        y0[1] = 1.01 * p.pull;
        y0[2] = p.dc / (1.01 * p.pull);
        t_end = 3000.0;
    } else {
        fprintf(stderr, "cvode_laws: unknown case %s (lugre or rate_state)\n", argv[1]);
        return 1;
    }
    char *end;
    double rtol = strtod(argv[2], &end), atol = strtod(argv[3], &end), dt = strtod(argv[4], &end);
    if (argc == 7) t_end = strtod(argv[6], &end);
    if (!(rtol > 0) || !(atol > 0) || !(dt > 0) || !(t_end > 0)) {
        fprintf(stderr, "cvode_laws: RTOL, ATOL, DT_OUT and T_END must be positive\n");
        return 1;
    }
    long n = lround(t_end / dt) + 1;
    double *x = malloc(sizeof(double) * (size_t)n);
#ifdef CVODE_LAWS_HDF5
    double *times = malloc(sizeof(double) * (size_t)n), *states = malloc(sizeof(double) * 3 * (size_t)n);
    if (times == NULL || states == NULL) return 2;
    times[0] = 0.0;
    for (int j = 0; j < 3; ++j) states[j] = y0[j];
#endif
    SUNContext context;
    if (x == NULL || SUNContext_Create(NULL, &context) != 0) return 2;
    struct timespec began, ended, cpu_began, cpu_ended;
    clock_gettime(CLOCK_MONOTONIC, &began);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_began);
    N_Vector y = N_VNew_Serial(3, context);
    for (int i = 0; i < 3; ++i) NV_Ith_S(y, i) = y0[i];
    void *mem = CVodeCreate(CV_BDF, context);
    SUNMatrix matrix = SUNDenseMatrix(3, 3, context);
    SUNLinearSolver solver = SUNLinSol_Dense(y, matrix, context);
    int status = CVodeInit(mem, rhs, 0.0, y);
    status = status ? status : CVodeSStolerances(mem, rtol, atol);
    status = status ? status : CVodeSetUserData(mem, &p);
    status = status ? status : CVodeSetLinearSolver(mem, solver, matrix);
    status = status ? status : CVodeSetJacFn(mem, jacobian);
    status = status ? status : CVodeSetMaxNumSteps(mem, 100000000L);
    x[0] = y0[0];
    double t = 0.0;
    for (long i = 1; i < n && status >= 0; ++i) {
        status = CVode(mem, (double)i * dt, y, &t, CV_NORMAL);
        x[i] = NV_Ith_S(y, 0);
#ifdef CVODE_LAWS_HDF5
        times[i] = (double)i * dt;
        for (int j = 0; j < 3; ++j) states[3 * i + j] = NV_Ith_S(y, j);
#endif
    }
    clock_gettime(CLOCK_MONOTONIC, &ended);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_ended);
    if (status < 0) {
        fprintf(stderr, "cvode_laws: CVODE failed at t = %g with flag %d\n", t, status);
        return 2;
    }
    long steps = 0, rhs_evaluations = 0, jacobians = 0, rhs_for_jacobian = 0;
    CVodeGetNumSteps(mem, &steps);
    CVodeGetNumRhsEvals(mem, &rhs_evaluations);
    CVodeGetNumJacEvals(mem, &jacobians);
    CVodeGetNumLinRhsEvals(mem, &rhs_for_jacobian);
#ifdef CVODE_LAWS_HDF5
    if (write_file(argv[5], &p, times, states, n) != 0) {
#else
    FILE *out = fopen(argv[5], "wb");
    if (out == NULL || fwrite(x, sizeof(double), (size_t)n, out) != (size_t)n || fclose(out) != 0) {
#endif
        fprintf(stderr, "cvode_laws: cannot write %s\n", argv[5]);
        return 3;
    }
    printf("{\"steps\": %ld, \"rhs_evaluations\": %ld, \"jacobian_evaluations\": %ld, \"seconds\": %.9g, "
           "\"cpu_seconds\": %.9g}\n", steps, rhs_evaluations + rhs_for_jacobian, jacobians,
           (double)(ended.tv_sec - began.tv_sec) + 1e-9 * (double)(ended.tv_nsec - began.tv_nsec),
           (double)(cpu_ended.tv_sec - cpu_began.tv_sec) + 1e-9 * (double)(cpu_ended.tv_nsec - cpu_began.tv_nsec));
    CVodeFree(&mem);
    SUNLinSolFree(solver);
    SUNMatDestroy(matrix);
    N_VDestroy(y);
    SUNContext_Free(&context);
    free(x);
#ifdef CVODE_LAWS_HDF5
    free(times);
    free(states);
#endif
    return 0;
}
