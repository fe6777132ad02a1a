/* The NaF tip of inputs/naf.nml integrated by SUNDIALS CVODE: the peer of
 * `friction` in scripts/benchmark_stiff.py.
 *
 * The same equations as the program (src/friction/afm/tip.f90, Eq. 4 in the
 * state y = (u, r'), u = r - r_M the tip's displacement from the support,
 * internal units Å, eV, s), the same scan (src/friction/afm/trip.f90: lines
 * along x at angle 0, every trip started at rest at the support, trace and
 * retrace) and the same samples, so the forces can be set side by side
 * with the program's.  CVODE runs as a C user would set it up for a stiff
 * problem: BDF (or Adams) with a dense direct linear solver and the
 * analytic Jacobian (the potential's Hessian), scalar tolerances, one
 * CVodeReInit per trip, CV_NORMAL output at each sample (CVODE interpolates
 * there rather than stopping on it).
 *
 * Usage: cvode_naf METHOD RTOL ATOL NX NY OUT.bin [DAMPING]
 *   METHOD  bdf or adams (adams uses functional iteration, no Jacobian)
 *   DAMPING cx = cy in N s/m (default 1e-3, the input file's)
 *   OUT.bin the lateral forces in nN as raw doubles: trace fx, trace fy,
 *           retrace fx, retrace fy, each NY lines of NX samples
 * Prints one line of JSON: compute_time (s, the integration and the
 * sampling, from the parameters set to the forces in memory), steps,
 * rhs_evaluations, jacobian_evaluations.  Exit 1 on bad arguments, 2 on a
 * CVODE failure. */
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
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

/* Unit conversions of src/friction/core/kinds.f90. */
#define ELEMENTARY_CHARGE 1.602176634e-19
#define SI_TO_INTERNAL (1.0 / ELEMENTARY_CHARGE / 1.0e20) /* kg, N/m, N s/m */
#define EV_PER_ANGSTROM_TO_NN (ELEMENTARY_CHARGE / 1.0e-10 * 1.0e9)

/* inputs/naf.nml */
static const double v0 = 1.0, ax = 4.62, ay = 4.62;           /* eV, Å */
static const double mass_si = 1.0e-8, k_si = 10.0; /* kg, N/m */
static const double velocity = 400.0, length = 20.0, width = 20.0; /* Å/s, Å */

typedef struct {
    double qx, qy, m, k, c;
    double start[2], vel[2]; /* support r_M(t) = start + vel t */
} tip_t;

static int rhs(double t, N_Vector yv, N_Vector dv, void *data)
{
    const tip_t *p = data;
    const double *y = N_VGetArrayPointer(yv);
    double *d = N_VGetArrayPointer(dv);
    double x = p->start[0] + p->vel[0] * t + y[0];
    double yy = p->start[1] + p->vel[1] * t + y[1];
    double sx = sin(p->qx * x), cx = cos(p->qx * x), sy = sin(p->qy * yy), cy = cos(p->qy * yy);
    double gx = v0 * p->qx * sx * cy, gy = v0 * p->qy * cx * sy;

    d[0] = y[2] - p->vel[0];
    d[1] = y[3] - p->vel[1];
    d[2] = (-p->k * y[0] - gx - p->c * y[2]) / p->m;
    d[3] = (-p->k * y[1] - gy - p->c * y[3]) / p->m;
    return 0;
}

static int jac(double t, N_Vector yv, N_Vector fy, SUNMatrix J, void *data, N_Vector t1, N_Vector t2,
               N_Vector t3)
{
    const tip_t *p = data;
    const double *y = N_VGetArrayPointer(yv);
    double x = p->start[0] + p->vel[0] * t + y[0];
    double yy = p->start[1] + p->vel[1] * t + y[1];
    double sx = sin(p->qx * x), cx = cos(p->qx * x), sy = sin(p->qy * yy), cy = cos(p->qy * yy);
    double hxx = v0 * p->qx * p->qx * cx * cy, hyy = v0 * p->qy * p->qy * cx * cy;
    double hxy = -v0 * p->qx * p->qy * sx * sy;
    int i, j;
    (void)fy; (void)t1; (void)t2; (void)t3;

    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++) SM_ELEMENT_D(J, i, j) = 0.0;
    SM_ELEMENT_D(J, 0, 2) = 1.0;
    SM_ELEMENT_D(J, 1, 3) = 1.0;
    SM_ELEMENT_D(J, 2, 0) = -(p->k + hxx) / p->m;
    SM_ELEMENT_D(J, 2, 1) = -hxy / p->m;
    SM_ELEMENT_D(J, 3, 0) = -hxy / p->m;
    SM_ELEMENT_D(J, 3, 1) = -(p->k + hyy) / p->m;
    SM_ELEMENT_D(J, 2, 2) = -p->c / p->m;
    SM_ELEMENT_D(J, 3, 3) = -p->c / p->m;
    return 0;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv)
{
    SUNContext ctx;
    SUNMatrix A = NULL;
    SUNLinearSolver LS = NULL;
    SUNNonlinearSolver NLS = NULL;
    N_Vector y;
    void *mem;
    tip_t p;
    double rtol, atol, *out, t0, c_si = 1.0e-3; /* N s/m */
    long nsteps = 0, nrhs = 0, njac = 0;
    int nx, ny, bdf, line, dir, k, status = 0;
    FILE *f;

    if ((argc != 7 && argc != 8) || (strcmp(argv[1], "bdf") != 0 && strcmp(argv[1], "adams") != 0)) {
        fprintf(stderr, "usage: cvode_naf bdf|adams RTOL ATOL NX NY OUT.bin [DAMPING]\n");
        return 1;
    }
    bdf = strcmp(argv[1], "bdf") == 0;
    rtol = atof(argv[2]);
    atol = atof(argv[3]);
    nx = atoi(argv[4]);
    ny = atoi(argv[5]);
    if (argc == 8) c_si = atof(argv[7]);
    if (!(rtol > 0.0) || !(atol > 0.0) || nx < 2 || ny < 1 || !(c_si >= 0.0)) {
        fprintf(stderr, "cvode_naf: bad tolerances or sizes\n");
        return 1;
    }
    out = calloc((size_t)4 * nx * ny, sizeof *out);
    if (out == NULL) return 2;

    t0 = now();
    p.qx = 2.0 * M_PI / ax;
    p.qy = 2.0 * M_PI / ay;
    p.m = mass_si * SI_TO_INTERNAL;
    p.k = k_si * SI_TO_INTERNAL;
    p.c = c_si * SI_TO_INTERNAL;
    if (SUNContext_Create(NULL, &ctx) != 0) return 2;
    y = N_VNew_Serial(4, ctx);
    N_VConst(0.0, y);
    mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx);
    if (mem == NULL || CVodeInit(mem, rhs, 0.0, y) != CV_SUCCESS) return 2;
    CVodeSStolerances(mem, rtol, atol);
    CVodeSetUserData(mem, &p);
    CVodeSetMaxNumSteps(mem, 10000000L);
    if (bdf) {
        A = SUNDenseMatrix(4, 4, ctx);
        LS = SUNLinSol_Dense(y, A, ctx);
        CVodeSetLinearSolver(mem, LS, A);
        CVodeSetJacFn(mem, jac);
    } else {
        NLS = SUNNonlinSol_FixedPoint(y, 0, ctx);
        CVodeSetNonlinearSolver(mem, NLS);
    }
    for (dir = 0; dir < 2 && status == 0; dir++) {
        for (line = 0; line < ny && status == 0; line++) {
            double across = ny > 1 ? width * line / (ny - 1) : 0.0;
            double s_start = dir == 0 ? 0.0 : length;
            double *fx = out + (size_t)(2 * dir) * nx * ny + (size_t)line * nx;
            double *fyy = out + (size_t)(2 * dir + 1) * nx * ny + (size_t)line * nx;
            double t = 0.0;
            p.start[0] = s_start;
            p.start[1] = across;
            p.vel[0] = dir == 0 ? velocity : -velocity;
            p.vel[1] = 0.0;
            N_VConst(0.0, y); /* at the support and at rest */
            if (CVodeReInit(mem, 0.0, y) != CV_SUCCESS) { status = 2; break; }
            for (k = 0; k < nx; k++) {
                int i = dir == 0 ? k : nx - 1 - k;
                double s = length * i / (nx - 1);
                double ts = fabs(s - s_start) / velocity;
                double *yd;
                if (ts > t && CVode(mem, ts, y, &t, CV_NORMAL) < 0) { status = 2; break; }
                yd = N_VGetArrayPointer(y);
                fx[i] = -p.k * yd[0] * EV_PER_ANGSTROM_TO_NN;
                fyy[i] = -p.k * yd[1] * EV_PER_ANGSTROM_TO_NN;
            }
            {
                long n;
                CVodeGetNumSteps(mem, &n); nsteps += n;
                CVodeGetNumRhsEvals(mem, &n); nrhs += n;
                if (bdf) { CVodeGetNumJacEvals(mem, &n); njac += n; }
            }
        }
    }
    t0 = now() - t0;
    if (status != 0) {
        fprintf(stderr, "cvode_naf: CVODE failed\n");
        return 2;
    }
    f = fopen(argv[6], "wb");
    if (f == NULL || fwrite(out, sizeof *out, (size_t)4 * nx * ny, f) != (size_t)4 * nx * ny) return 2;
    fclose(f);
    printf("{\"compute_time\": %.9g, \"steps\": %ld, \"rhs_evaluations\": %ld, \"jacobian_evaluations\": %ld}\n",
           t0, nsteps, nrhs, njac);
    CVodeFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (NLS) SUNNonlinSolFree(NLS);
    N_VDestroy(y);
    SUNContext_Free(&ctx);
    free(out);
    return 0;
}
