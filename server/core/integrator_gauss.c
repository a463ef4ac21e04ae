/*
 * Gauss-Legendre collocation (implicit midpoint = 1 stage, order 2; gauss4 = 2 stages,
 * order 4) applied in canonical coordinates y = (q, p), p = M(q) qd, where the methods
 * are symplectic: energy errors stay bounded at O(h^order) without drift. (Applied to
 * (q, qd) they would not be: the map qd -> p is not linear in q.)
 *
 * The stage equations Z_i = h sum_j a_ij f(y0 + Z_j) are solved by simplified Newton with
 * the Jacobian of f at y0 (forward differences), at most max_iter iterations; the
 * convergence test is Hairer & Wanner's eta * ||dZ|| <= newton_tol (Solving ODEs II,
 * IV.8) on ||.|| scaled by 1 + |y0_k|. Failure is LAG_ERR_NEWTON, never a silent step.
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

#define MAX_STAGES 2
#define MAX_SYS (MAX_STAGES * LAG_MAX_STATE)

/* Butcher tableaux */
static const double SQ3_6 = 0.28867513459481288225; /* sqrt(3)/6 */

static void tableau(int stages, double A[MAX_STAGES][MAX_STAGES], double *b)
{
    if (stages == 1) {
        A[0][0] = 0.5;
        b[0] = 1.0;
    } else {
        A[0][0] = 0.25;         A[0][1] = 0.25 - SQ3_6;
        A[1][0] = 0.25 + SQ3_6; A[1][1] = 0.25;
        b[0] = b[1] = 0.5;
    }
}

/* One step's state: the tableau, the start in (q, p), the Newton matrix, the stages. */
typedef struct gauss_step {
    lag_sim *s;
    int stages, n, N, S; /* stages, coordinates, state size 2n, system size stages * N */
    double h;
    double A[MAX_STAGES][MAX_STAGES], b[MAX_STAGES];
    double y0[LAG_MAX_STATE], f0[LAG_MAX_STATE];
    double W[MAX_SYS * MAX_SYS]; /* I - h (A kron J) */
    double Z[MAX_SYS], F[MAX_SYS];
} gauss_step;

/* y0 = (q0, M(q0) qd0) and f0 = f(y0). */
static lag_result gauss_start(gauss_step *g, const double *yin)
{
    const int n = g->n;
    double M[LAG_MAX_DOF * LAG_MAX_DOF];
    g->s->dyn->mass(g->s->model.p, yin, M);
    for (int i = 0; i < n; i++) {
        g->y0[i] = yin[i];
        double p = 0.0;
        for (int j = 0; j < n; j++) p += M[i * n + j] * yin[n + j];
        g->y0[n + i] = p;
    }
    return lag_sim_rhs_qp(g->s, g->y0, g->f0);
}

/* The Jacobian J = df/dy at y0 by forward differences, and the Newton matrix
 * I - h (A kron J), factored once per step (LU, in place each solve: at most 12 x 12,
 * cheaper to refactor than to keep pivots). */
static lag_result gauss_newton_matrix(gauss_step *g)
{
    const int N = g->N, S = g->S;
    double J[LAG_MAX_STATE * LAG_MAX_STATE];
    lag_result r;
    for (int j = 0; j < N; j++) {
        double yp[LAG_MAX_STATE], fp[LAG_MAX_STATE];
        memcpy(yp, g->y0, sizeof(double) * N);
        double d = 1.4901161193847656e-08 * fmax(1.0, fabs(g->y0[j])); /* sqrt(eps) */
        yp[j] += d;
        d = yp[j] - g->y0[j]; /* the step actually represented */
        if ((r = lag_sim_rhs_qp(g->s, yp, fp)) != LAG_OK) return r;
        for (int i = 0; i < N; i++) J[i * N + j] = (fp[i] - g->f0[i]) / d;
    }
    for (int bi = 0; bi < g->stages; bi++)
        for (int bj = 0; bj < g->stages; bj++)
            for (int i = 0; i < N; i++)
                for (int j = 0; j < N; j++)
                    g->W[(bi * N + i) * S + bj * N + j] =
                        (bi == bj && i == j ? 1.0 : 0.0) - g->h * g->A[bi][bj] * J[i * N + j];
    return LAG_OK;
}

/* Initial guess Z_i = h sum_j a_ij f0. */
static void gauss_guess(gauss_step *g)
{
    for (int bi = 0; bi < g->stages; bi++) {
        double ci = 0.0;
        for (int bj = 0; bj < g->stages; bj++) ci += g->A[bi][bj];
        for (int i = 0; i < g->N; i++) g->Z[bi * g->N + i] = g->h * ci * g->f0[i];
    }
}

/* F_i = f(y0 + Z_i), each stage. */
static lag_result gauss_stage_rhs(gauss_step *g)
{
    lag_result r;
    for (int bi = 0; bi < g->stages; bi++) {
        double y[LAG_MAX_STATE];
        for (int i = 0; i < g->N; i++) y[i] = g->y0[i] + g->Z[bi * g->N + i];
        if ((r = lag_sim_rhs_qp(g->s, y, g->F + bi * g->N)) != LAG_OK) return r;
    }
    return LAG_OK;
}

/* One simplified-Newton update of Z; *dn = its scaled size (NaN propagates). */
static lag_result gauss_newton_update(gauss_step *g, const double *scale, double *dn)
{
    const int N = g->N, S = g->S;
    lag_result r = gauss_stage_rhs(g);
    if (r != LAG_OK) return r;
    /* residual G_i = Z_i - h sum_j a_ij F_j, solved with the Newton matrix */
    double G[MAX_SYS], Wc[MAX_SYS * MAX_SYS];
    for (int bi = 0; bi < g->stages; bi++)
        for (int i = 0; i < N; i++) {
            double acc = g->Z[bi * N + i];
            for (int bj = 0; bj < g->stages; bj++) acc -= g->h * g->A[bi][bj] * g->F[bj * N + i];
            G[bi * N + i] = -acc;
        }
    memcpy(Wc, g->W, sizeof(double) * S * S);
    if (lag_lu_solve_inplace(S, Wc, G) != LAG_OK) return LAG_ERR_NEWTON;
    *dn = 0.0;
    for (int k = 0; k < S; k++) {
        g->Z[k] += G[k];
        double e = fabs(G[k]) * scale[k % N];
        if (!(e <= *dn)) *dn = e; /* NaN propagates into dn */
    }
    g->s->stats.newton_iters++;
    return LAG_OK;
}

/* Newton on the stage equations until Hairer & Wanner's test holds (LAG_ERR_NEWTON when
 * it diverges, fails or runs out of iterations). */
static lag_result gauss_solve(gauss_step *g)
{
    const lag_integrator_def *in = &g->s->def.integrator;
    double scale[LAG_MAX_STATE];
    for (int i = 0; i < g->N; i++) scale[i] = 1.0 / (1.0 + fabs(g->y0[i]));
    double dn_prev = 0.0;
    for (int it = 0; it < in->max_iter; it++) {
        double dn;
        lag_result r = gauss_newton_update(g, scale, &dn);
        if (r != LAG_OK) return r;
        if (!isfinite(dn)) return LAG_ERR_NEWTON;
        if (dn <= in->newton_tol) return LAG_OK;
        if (it > 0) {
            double theta = dn / dn_prev;
            if (theta < 1.0 && theta / (1.0 - theta) * dn <= in->newton_tol) return LAG_OK;
            if (theta >= 1.0 && it > 2) return LAG_ERR_NEWTON; /* diverging */
        }
        dn_prev = dn;
    }
    return LAG_ERR_NEWTON;
}

/* y1 = y0 + h sum_i b_i f(y0 + Z_i) at the converged stages, back in (q, qd): qd1 =
 * M(q1)^-1 p1 (on the free joints when some are locked). */
static lag_result gauss_finish(gauss_step *g, double *yout)
{
    const int N = g->N;
    double y1[LAG_MAX_STATE];
    memcpy(y1, g->y0, sizeof(double) * N);
    for (int bi = 0; bi < g->stages; bi++) {
        double y[LAG_MAX_STATE];
        for (int i = 0; i < N; i++) y[i] = g->y0[i] + g->Z[bi * N + i];
        lag_result r = lag_sim_rhs_qp(g->s, y, g->F + bi * N);
        if (r != LAG_OK) return r;
        for (int i = 0; i < N; i++) y1[i] += g->h * g->b[bi] * g->F[bi * N + i];
    }
    memcpy(yout, y1, sizeof(double) * g->n);
    return lag_qd_from_p(g->s, yout, y1 + g->n, yout + g->n);
}

lag_result lag_step_gauss(lag_sim *s, int stages, double h, const double *yin, double *yout)
{
    LAG_ASSERT(stages >= 1 && stages <= MAX_STAGES);
    gauss_step g = {.s = s, .stages = stages, .n = s->nq, .N = 2 * s->nq,
                    .S = stages * 2 * s->nq, .h = h};
    tableau(stages, g.A, g.b);
    lag_result r;
    if ((r = gauss_start(&g, yin)) != LAG_OK) return r;
    if ((r = gauss_newton_matrix(&g)) != LAG_OK) return r;
    gauss_guess(&g);
    if ((r = gauss_solve(&g)) != LAG_OK) return r;
    return gauss_finish(&g, yout);
}
