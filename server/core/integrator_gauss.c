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

lag_result lag_step_gauss(lag_sim *s, int stages, double h, const double *yin, double *yout)
{
    LAG_ASSERT(stages >= 1 && stages <= MAX_STAGES);
    const int n = s->nq, N = 2 * n, S = stages * N;
    const lag_integrator_def *in = &s->def.integrator;
    double A[MAX_STAGES][MAX_STAGES], b[MAX_STAGES];
    tableau(stages, A, b);

    /* y0 = (q0, M(q0) qd0) */
    double y0[LAG_MAX_STATE], M[LAG_MAX_DOF * LAG_MAX_DOF];
    s->dyn->mass(s->model.p, yin, M);
    for (int i = 0; i < n; i++) {
        y0[i] = yin[i];
        double p = 0.0;
        for (int j = 0; j < n; j++) p += M[i * n + j] * yin[n + j];
        y0[n + i] = p;
    }

    /* f0 and the Jacobian J = df/dy at y0 by forward differences. */
    double f0[LAG_MAX_STATE], J[LAG_MAX_STATE * LAG_MAX_STATE];
    lag_result r = lag_sim_rhs_qp(s, y0, f0);
    if (r != LAG_OK) return r;
    for (int j = 0; j < N; j++) {
        double yp[LAG_MAX_STATE], fp[LAG_MAX_STATE];
        memcpy(yp, y0, sizeof(double) * N);
        double d = 1.4901161193847656e-08 * fmax(1.0, fabs(y0[j])); /* sqrt(eps) */
        yp[j] += d;
        d = yp[j] - y0[j]; /* the step actually represented */
        if ((r = lag_sim_rhs_qp(s, yp, fp)) != LAG_OK) return r;
        for (int i = 0; i < N; i++) J[i * N + j] = (fp[i] - f0[i]) / d;
    }

    /* Newton matrix I - h (A kron J), factored once per step (LU, in place each solve:
     * at most 12 x 12, cheaper to refactor than to keep pivots). */
    double W[MAX_SYS * MAX_SYS];
    for (int bi = 0; bi < stages; bi++)
        for (int bj = 0; bj < stages; bj++)
            for (int i = 0; i < N; i++)
                for (int j = 0; j < N; j++)
                    W[(bi * N + i) * S + bj * N + j] =
                        (bi == bj && i == j ? 1.0 : 0.0) - h * A[bi][bj] * J[i * N + j];

    /* Initial guess Z_i = h sum_j a_ij f0 */
    double Z[MAX_SYS], F[MAX_SYS];
    for (int bi = 0; bi < stages; bi++) {
        double ci = 0.0;
        for (int bj = 0; bj < stages; bj++) ci += A[bi][bj];
        for (int i = 0; i < N; i++) Z[bi * N + i] = h * ci * f0[i];
    }

    double scale[LAG_MAX_STATE];
    for (int i = 0; i < N; i++) scale[i] = 1.0 / (1.0 + fabs(y0[i]));
    double dn_prev = 0.0;
    bool converged = false;
    for (int it = 0; it < in->max_iter && !converged; it++) {
        /* F_i = f(y0 + Z_i); residual G_i = Z_i - h sum_j a_ij F_j */
        for (int bi = 0; bi < stages; bi++) {
            double y[LAG_MAX_STATE];
            for (int i = 0; i < N; i++) y[i] = y0[i] + Z[bi * N + i];
            if ((r = lag_sim_rhs_qp(s, y, F + bi * N)) != LAG_OK) return r;
        }
        double G[MAX_SYS], Wc[MAX_SYS * MAX_SYS];
        for (int bi = 0; bi < stages; bi++)
            for (int i = 0; i < N; i++) {
                double acc = Z[bi * N + i];
                for (int bj = 0; bj < stages; bj++) acc -= h * A[bi][bj] * F[bj * N + i];
                G[bi * N + i] = -acc;
            }
        memcpy(Wc, W, sizeof(double) * S * S);
        if (lag_lu_solve_inplace(S, Wc, G) != LAG_OK) return LAG_ERR_NEWTON;
        double dn = 0.0;
        for (int k = 0; k < S; k++) {
            Z[k] += G[k];
            double e = fabs(G[k]) * scale[k % N];
            if (!(e <= dn)) dn = e; /* NaN propagates into dn */
        }
        s->stats.newton_iters++;
        if (!isfinite(dn)) return LAG_ERR_NEWTON;
        if (dn <= in->newton_tol) {
            converged = true;
        } else if (it > 0) {
            double theta = dn / dn_prev;
            if (theta < 1.0 && theta / (1.0 - theta) * dn <= in->newton_tol) converged = true;
            else if (theta >= 1.0 && it > 2) return LAG_ERR_NEWTON; /* diverging */
        }
        dn_prev = dn;
    }
    if (!converged) return LAG_ERR_NEWTON;

    /* y1 = y0 + h sum_i b_i f(y0 + Z_i) at the converged stages */
    double y1[LAG_MAX_STATE];
    memcpy(y1, y0, sizeof(double) * N);
    for (int bi = 0; bi < stages; bi++) {
        double y[LAG_MAX_STATE];
        for (int i = 0; i < N; i++) y[i] = y0[i] + Z[bi * N + i];
        if ((r = lag_sim_rhs_qp(s, y, F + bi * N)) != LAG_OK) return r;
        for (int i = 0; i < N; i++) y1[i] += h * b[bi] * F[bi * N + i];
    }
    /* back to (q, qd): qd1 = M(q1)^-1 p1 (on the free joints when some are locked) */
    memcpy(yout, y1, sizeof(double) * n);
    return lag_qd_from_p(s, yout, y1 + n, yout + n);
}
