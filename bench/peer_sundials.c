/*
 * SUNDIALS peer (6.4): ARKODE and CVODE integrating lagsim's own right-hand side
 * y = (q, qd), ydot = (qd, qdd), qdd from lag_model_forward, on N_Vector serial.
 *  - ARKODE-DP5: ARKStep, explicit Dormand-Prince 5(4) (ARKODE_DORMAND_PRINCE_7_4_5),
 *    adaptive, rtol / atol = rtol * BENCH_ATOL_FACTOR; the state at each period end from
 *    ARKODE's interpolant (ARK_NORMAL) when the scene is unforced.
 *  - ARKODE-RK4: ARKStep with the classical RK4 Butcher table (ARKodeButcherTable_Create)
 *    and ARKStepSetFixedStep. Not ERKStep: 6.4's ERKStep treats this table as FSAL
 *    (wrong order, silently).
 *  - CVODE-Adams (fixed-point iteration) and CVODE-BDF (Newton, dense direct solver,
 *    difference-quotient Jacobian), adaptive order and step.
 * When the scene's input changes at a period start, the integrator is re-initialized
 * there (ARKStepReset / CVodeReInit, with a stop time at the period end): the documented
 * way to cross a discontinuity of f. ARKODE-DP5 restarts with the largest step of the
 * previous period (as lagsim's dopri5 keeps its step size); CVODE restarts at order 1
 * with its own initial step estimate.
 * RHS evaluations are counted in the RHS itself (including difference quotients).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_version.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "bench.h"

typedef struct rhs_data {
    const lag_model *m;
    int nq;
    double tau[LAG_MAX_DOF];
    int64_t nfe;
    int fail;
} rhs_data;

static SUNContext ctx;

const char *bench_sundials_version(void)
{
    static char buf[32];
    SUNDIALSGetVersion(buf, (int)sizeof buf);
    return buf;
}

/* f(t, y) = (qd, M^-1 (tau - C qd - g)). Returns 1 (recoverable) if M is singular. */
static int rhs(realtype t, N_Vector y, N_Vector ydot, void *user)
{
    (void)t;
    rhs_data *u = user;
    const double *Y = N_VGetArrayPointer(y);
    double *D = N_VGetArrayPointer(ydot);
    const int n = u->nq;
    u->nfe++;
    memcpy(D, Y + n, sizeof(double) * (size_t)n);
    if (lag_model_forward(u->m, Y, Y + n, u->tau, D + n) != LAG_OK) {
        u->fail++;
        return 1;
    }
    return 0;
}

/* Classical RK4 as an explicit Butcher table (4 stages, order 4, no embedding). */
static ARKodeButcherTable rk4_table(void)
{
    realtype c[4] = {0.0, 0.5, 0.5, 1.0};
    realtype A[16] = {0.0, 0.0, 0.0, 0.0,
                      0.5, 0.0, 0.0, 0.0,
                      0.0, 0.5, 0.0, 0.0,
                      0.0, 0.0, 1.0, 0.0};
    realtype b[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
    return ARKodeButcherTable_Create(4, 4, 0, c, A, b, NULL);
}

static int finite_state(const double *y, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(y[i]) || fabs(y[i]) > 1e6) return 0;
    return 1;
}

static void record(const bench_samples *out, int k, const double *y, int nq)
{
    memcpy(out->q + (size_t)k * LAG_MAX_DOF, y, sizeof(double) * (size_t)nq);
    memcpy(out->qd + (size_t)k * LAG_MAX_DOF, y + nq, sizeof(double) * (size_t)nq);
}

static int run_arkode(const bench_scene *sc, const bench_config *c, bench_samples *out,
                      rhs_data *u, N_Vector y, int64_t *steps)
{
    const int nq = sc->model.nq;
    const int np = bench_periods(sc);
    const bool fixed = (c->method == BENCH_SUN_ARK_RK4);
    const long per = lround(sc->period / c->dt);
    int status = 0;
    ARKodeButcherTable B = NULL;
    void *mem = ARKStepCreate(rhs, NULL, 0.0, y, ctx);
    if (!mem) return -10;
    ARKStepSetUserData(mem, u);
    ARKStepSetMaxNumSteps(mem, 1000000);
    if (fixed) {
        B = rk4_table();
        if (!B || ARKStepSetTables(mem, 4, 0, NULL, B) != ARK_SUCCESS ||
            ARKStepSetFixedStep(mem, c->dt) != ARK_SUCCESS)
            status = -11;
    } else {
        if (ARKStepSetTableNum(mem, ARKODE_DIRK_NONE, ARKODE_DORMAND_PRINCE_7_4_5) != ARK_SUCCESS ||
            ARKStepSStolerances(mem, c->rtol, c->rtol * BENCH_ATOL_FACTOR) != ARK_SUCCESS)
            status = -12;
    }
    double *Y = N_VGetArrayPointer(y);
    record(out, 0, Y, nq);
    realtype t = 0.0, hmax = 0.0;
    int64_t nst = 0;
    for (int k = 0; k < np && status == 0; k++) {
        realtype t0 = k * sc->period, tout = (k + 1) * sc->period;
        if (sc->input) {
            sc->input(&sc->model, t0, u->tau);
            if (k > 0) {
                ARKStepReset(mem, t, y);
                if (!fixed && hmax > 0) ARKStepSetInitStep(mem, hmax);
            }
            if (!fixed) ARKStepSetStopTime(mem, tout);
        }
        if (fixed) {
            /* Exactly `per` steps of dt per period (no interpolation, no tstop games). */
            for (long s = 0; s < per && status == 0; s++, nst++)
                if (ARKStepEvolve(mem, tout, y, &t, ARK_ONE_STEP) < 0) status = -13;
        } else if (sc->input) {
            /* Step by step to the stop time, noting the largest step for the restart. */
            hmax = 0.0;
            while (t < tout && status == 0) {
                int f = ARKStepEvolve(mem, tout, y, &t, ARK_ONE_STEP);
                if (f < 0) status = -14;
                realtype h = 0;
                ARKStepGetLastStep(mem, &h);
                if (h > hmax) hmax = h;
                nst++;
                if (f == ARK_TSTOP_RETURN) break;
            }
        } else {
            long n0 = 0, n1 = 0;
            ARKStepGetNumSteps(mem, &n0);
            if (ARKStepEvolve(mem, tout, y, &t, ARK_NORMAL) < 0) status = -14;
            ARKStepGetNumSteps(mem, &n1);
            nst += n1 - n0;
        }
        if (!finite_state(Y, 2 * nq)) status = -15;
        record(out, k + 1, Y, nq);
    }
    *steps = nst;
    ARKStepFree(&mem);
    if (B) ARKodeButcherTable_Free(B);
    return status;
}

static int run_cvode(const bench_scene *sc, const bench_config *c, bench_samples *out,
                     rhs_data *u, N_Vector y, int64_t *steps)
{
    const int nq = sc->model.nq;
    const int np = bench_periods(sc);
    const bool bdf = (c->method == BENCH_SUN_CV_BDF);
    int status = 0;
    SUNMatrix A = NULL;
    SUNLinearSolver LS = NULL;
    SUNNonlinearSolver NLS = NULL;
    void *mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx);
    if (!mem) return -20;
    if (CVodeInit(mem, rhs, 0.0, y) != CV_SUCCESS ||
        CVodeSStolerances(mem, c->rtol, c->rtol * BENCH_ATOL_FACTOR) != CV_SUCCESS)
        status = -21;
    CVodeSetUserData(mem, u);
    CVodeSetMaxNumSteps(mem, 1000000);
    if (bdf) {
        A = SUNDenseMatrix(2 * nq, 2 * nq, ctx);
        LS = SUNLinSol_Dense(y, A, ctx);
        if (!A || !LS || CVodeSetLinearSolver(mem, LS, A) != CV_SUCCESS) status = -22;
    } else {
        NLS = SUNNonlinSol_FixedPoint(y, 0, ctx);
        if (!NLS || CVodeSetNonlinearSolver(mem, NLS) != CV_SUCCESS) status = -23;
    }
    double *Y = N_VGetArrayPointer(y);
    record(out, 0, Y, nq);
    realtype t = 0.0;
    int64_t nst0 = 0;
    for (int k = 0; k < np && status == 0; k++) {
        realtype t0 = k * sc->period, tout = (k + 1) * sc->period;
        if (sc->input) {
            sc->input(&sc->model, t0, u->tau);
            if (k > 0) {
                long n = 0;
                CVodeGetNumSteps(mem, &n); /* ReInit zeroes the counters */
                nst0 += n;
                CVodeReInit(mem, t, y);
            }
            CVodeSetStopTime(mem, tout);
        }
        if (CVode(mem, tout, y, &t, CV_NORMAL) < 0) status = -24;
        if (!finite_state(Y, 2 * nq)) status = -25;
        record(out, k + 1, Y, nq);
    }
    long nst = 0;
    CVodeGetNumSteps(mem, &nst);
    *steps = nst0 + nst;
    CVodeFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (NLS) SUNNonlinSolFree(NLS);
    return status;
}

int bench_run_sundials(const bench_scene *sc, const bench_config *c, bench_samples *out,
                       int64_t *rhs_evals, int64_t *steps)
{
    *rhs_evals = 0;
    *steps = 0;
    if (!ctx && SUNContext_Create(NULL, &ctx) != 0) return -1;
    const int nq = sc->model.nq;
    rhs_data u = {&sc->model, nq, {0}, 0, 0};
    N_Vector y = N_VNew_Serial(2 * nq, ctx);
    if (!y) return -2;
    double *Y = N_VGetArrayPointer(y);
    memcpy(Y, sc->q0, sizeof(double) * (size_t)nq);
    memcpy(Y + nq, sc->qd0, sizeof(double) * (size_t)nq);
    int st = (c->method == BENCH_SUN_ARK_DP5 || c->method == BENCH_SUN_ARK_RK4)
                 ? run_arkode(sc, c, out, &u, y, steps)
                 : run_cvode(sc, c, out, &u, y, steps);
    N_VDestroy(y);
    *rhs_evals = u.nfe;
    return st;
}
