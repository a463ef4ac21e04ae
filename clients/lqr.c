/*
 * LQR design for the example controllers: see lqr.h.
 *
 * Why these algorithms. The systems are at most 6 states, so robustness and short code
 * matter more than flops:
 *  - CARE: the matrix sign function of the Hamiltonian (Roberts 1971, Byers 1987) needs
 *    only matrix inverses, converges quadratically and needs no stabilizing initial
 *    guess (the DIPC is open-loop unstable, which rules out plain Newton-Kleinman from
 *    K = 0). Its result is then polished by Newton-Kleinman steps (each one a Lyapunov
 *    equation solved as an n^2 linear system), which are stable from a stabilizing X and
 *    bring the residual to round-off.
 *  - DARE: the structure-preserving doubling algorithm (Chu, Fan, Lin, Wang 2004):
 *    three matrix products and one inverse per step, quadratic convergence.
 * The dense kernels are LAPACK's (through LAPACKE): LU solves and inverses (dgesv), the
 * least-squares step of the sign method (dgels), the Lyapunov equation of each
 * Newton-Kleinman step by Bartels-Stewart (real Schur form, dgees, then the triangular
 * Sylvester equation, dtrsyl), eigenvalues (dgeev, with balancing).
 */
#include "lqr.h"

#include <lapacke.h>
#include <math.h>
#include <string.h>

#define NMAX (2 * LAG_LQR_MAX_N)              /* Hamiltonian size */

/* ---------------------------------------------------------------- small helpers */

/* C (r x c) = A (r x k) * B (k x c). C must not alias A or B. */
static void mat_mul(int r, int k, int c, const double *A, const double *B, double *C)
{
    for (int i = 0; i < r; i++)
        for (int j = 0; j < c; j++) {
            double s = 0.0;
            for (int l = 0; l < k; l++) s += A[i * k + l] * B[l * c + j];
            C[i * c + j] = s;
        }
}

/* T (c x r) = A^T for A (r x c). */
static void mat_transpose(int r, int c, const double *A, double *T)
{
    for (int i = 0; i < r; i++)
        for (int j = 0; j < c; j++) T[j * r + i] = A[i * c + j];
}

static double mat_norm_fro(int r, int c, const double *A)
{
    double s = 0.0;
    for (int i = 0; i < r * c; i++) s += A[i] * A[i];
    return sqrt(s);
}

static double mat_norm_1(int n, const double *A)
{
    double best = 0.0;
    for (int j = 0; j < n; j++) {
        double s = 0.0;
        for (int i = 0; i < n; i++) s += fabs(A[i * n + j]);
        if (s > best) best = s;
    }
    return best;
}

static void mat_symmetrize(int n, double *X)
{
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++) {
            double s = 0.5 * (X[i * n + j] + X[j * n + i]);
            X[i * n + j] = X[j * n + i] = s;
        }
}

/* Solves A X = B for X (A: n x n, B: n x c, overwritten by X) by LU with partial
 * pivoting (LAPACK dgesv). A is destroyed (its LU factors). If logabsdet is not NULL, it
 * receives log|det A|. n <= NMAX. */
static int mat_solve(int n, double *A, int c, double *B, double *logabsdet)
{
    lapack_int ipiv[NMAX];
    if (n < 1 || n > NMAX) return LAG_LQR_ERR_ARG;
    if (LAPACKE_dgesv(LAPACK_ROW_MAJOR, n, c, A, n, ipiv, B, c) != 0)
        return LAG_LQR_ERR_SINGULAR;
    double ld = 0.0;
    for (int k = 0; k < n; k++) {
        double piv = A[k * n + k];
        if (piv == 0.0 || !isfinite(piv)) return LAG_LQR_ERR_SINGULAR;
        ld += log(fabs(piv));
    }
    for (int i = 0; i < n * c; i++)
        if (!isfinite(B[i])) return LAG_LQR_ERR_SINGULAR;
    if (logabsdet) *logabsdet = ld;
    return LAG_LQR_OK;
}

/* Ainv = A^-1 (n x n, n <= NMAX); logabsdet optional. */
static int mat_inverse(int n, const double *A, double *Ainv, double *logabsdet)
{
    double W[NMAX * NMAX];
    memcpy(W, A, sizeof(double) * (size_t)(n * n));
    for (int i = 0; i < n * n; i++) Ainv[i] = 0.0;
    for (int i = 0; i < n; i++) Ainv[i * n + i] = 1.0;
    return mat_solve(n, W, n, Ainv, logabsdet);
}

static int sizes_ok(int n, int m)
{
    return n >= 1 && n <= LAG_LQR_MAX_N && m >= 1 && m <= LAG_LQR_MAX_M;
}

/* ---------------------------------------------------------------- linearization */

/* ydot = (qd, qdd) of the model at y = (q, qd) with input tau. */
static int model_rhs(const lag_model *model, const double *y, const double *tau, double *ydot)
{
    int nq = model->nq;
    for (int i = 0; i < nq; i++) ydot[i] = y[nq + i];
    return lag_model_forward(model, y, y + nq, tau, ydot + nq) == LAG_OK ? 0 : -1;
}

int lag_lqr_linearize(const lag_model *model, const double *q0, const double *qd0,
                      const double *tau0, int m, const int *inputs, double *A, double *B)
{
    int nq = model->nq, n = 2 * nq;
    if (!sizes_ok(n, m)) return LAG_LQR_ERR_ARG;
    for (int k = 0; k < m; k++)
        if (inputs[k] < 0 || inputs[k] >= nq) return LAG_LQR_ERR_ARG;
    double y0[LAG_MAX_STATE], tau[LAG_MAX_DOF] = {0};
    for (int i = 0; i < nq; i++) {
        y0[i] = q0[i];
        y0[nq + i] = qd0[i];
        if (tau0) tau[i] = tau0[i];
    }
    double yp[LAG_MAX_STATE], fp[LAG_MAX_STATE], fm[LAG_MAX_STATE];
    /* Central differences: truncation O(e^2 f''') ~ 1e-12, round-off O(eps/e) ~ 1e-10. */
    for (int j = 0; j < n; j++) {
        double e = 1e-6 * fmax(1.0, fabs(y0[j]));
        memcpy(yp, y0, sizeof yp);
        yp[j] = y0[j] + e;
        if (model_rhs(model, yp, tau, fp)) return LAG_LQR_ERR_MODEL;
        yp[j] = y0[j] - e;
        if (model_rhs(model, yp, tau, fm)) return LAG_LQR_ERR_MODEL;
        for (int i = 0; i < n; i++) A[i * n + j] = (fp[i] - fm[i]) / (2.0 * e);
    }
    for (int k = 0; k < m; k++) {
        int c = inputs[k];
        double t0 = tau[c], e = 1e-6 * fmax(1.0, fabs(t0));
        tau[c] = t0 + e;
        if (model_rhs(model, y0, tau, fp)) return LAG_LQR_ERR_MODEL;
        tau[c] = t0 - e;
        if (model_rhs(model, y0, tau, fm)) return LAG_LQR_ERR_MODEL;
        tau[c] = t0;
        for (int i = 0; i < n; i++) B[i * m + k] = (fp[i] - fm[i]) / (2.0 * e);
    }
    return LAG_LQR_OK;
}

/* ---------------------------------------------------------------- CARE */

/* G = B R^-1 B^T (n x n). */
static int gain_matrix(int n, int m, const double *B, const double *R, double *G)
{
    double Rinv[LAG_LQR_MAX_M * LAG_LQR_MAX_M], Bt[LAG_LQR_MAX_M * LAG_LQR_MAX_N];
    double RBt[LAG_LQR_MAX_M * LAG_LQR_MAX_N];
    if (mat_inverse(m, R, Rinv, NULL)) return LAG_LQR_ERR_SINGULAR;
    mat_transpose(n, m, B, Bt);
    mat_mul(m, m, n, Rinv, Bt, RBt);
    mat_mul(n, m, n, B, RBt, G);
    return LAG_LQR_OK;
}

/* Res = A^T X + X A - X G X + Q, G = B R^-1 B^T. */
static int care_residual_matrix(int n, int m, const double *A, const double *B,
                                const double *Q, const double *R, const double *X, double *Res)
{
    double G[LAG_LQR_MAX_N * LAG_LQR_MAX_N], At[LAG_LQR_MAX_N * LAG_LQR_MAX_N] = {0};
    double T1[LAG_LQR_MAX_N * LAG_LQR_MAX_N], T2[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    if (gain_matrix(n, m, B, R, G)) return LAG_LQR_ERR_SINGULAR;
    mat_transpose(n, n, A, At);
    mat_mul(n, n, n, At, X, T1);
    for (int i = 0; i < n * n; i++) Res[i] = T1[i] + Q[i];
    mat_mul(n, n, n, X, A, T1);
    for (int i = 0; i < n * n; i++) Res[i] += T1[i];
    mat_mul(n, n, n, X, G, T1);
    mat_mul(n, n, n, T1, X, T2);
    for (int i = 0; i < n * n; i++) Res[i] -= T2[i];
    return LAG_LQR_OK;
}

double lag_lqr_care_residual(int n, int m, const double *A, const double *B, const double *Q,
                             const double *R, const double *X)
{
    double Res[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    if (!sizes_ok(n, m) || care_residual_matrix(n, m, A, B, Q, R, X, Res)) return NAN;
    return mat_norm_fro(n, n, Res) / mat_norm_fro(n, n, Q);
}

/* K = R^-1 B^T X (m x n). */
static int care_gain(int n, int m, const double *B, const double *R, const double *X, double *K)
{
    double Rinv[LAG_LQR_MAX_M * LAG_LQR_MAX_M], Bt[LAG_LQR_MAX_M * LAG_LQR_MAX_N];
    double BtX[LAG_LQR_MAX_M * LAG_LQR_MAX_N];
    if (mat_inverse(m, R, Rinv, NULL)) return LAG_LQR_ERR_SINGULAR;
    mat_transpose(n, m, B, Bt);
    mat_mul(m, n, n, Bt, X, BtX);
    mat_mul(m, m, n, Rinv, BtX, K);
    return LAG_LQR_OK;
}

/* Solves the Lyapunov equation Ac^T X + X Ac = -W for X (n x n) by Bartels-Stewart:
 * Ac = U T U^T (real Schur form, dgees), then T^T Y + Y T = -U^T W U (dtrsyl: T is quasi
 * upper triangular) and X = U Y U^T. */
static int lyapunov(int n, const double *Ac, const double *W, double *X)
{
    double T[LAG_LQR_MAX_N * LAG_LQR_MAX_N], U[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    double C[LAG_LQR_MAX_N * LAG_LQR_MAX_N], Tmp[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    double Ut[LAG_LQR_MAX_N * LAG_LQR_MAX_N], wr[LAG_LQR_MAX_N], wi[LAG_LQR_MAX_N], scale;
    lapack_int sdim;
    memcpy(T, Ac, sizeof(double) * (size_t)(n * n));
    if (LAPACKE_dgees(LAPACK_ROW_MAJOR, 'V', 'N', NULL, n, T, n, &sdim, wr, wi, U, n) != 0)
        return LAG_LQR_ERR_NOCONV;
    mat_transpose(n, n, U, Ut);
    mat_mul(n, n, n, Ut, W, Tmp);
    mat_mul(n, n, n, Tmp, U, C);
    for (int i = 0; i < n * n; i++) C[i] = -C[i];
    /* op(A) Y + isgn Y op(B) = scale C with op(A) = T^T, op(B) = T, isgn = +1; info 1
     * means eigenvalues of T^T and -T (nearly) shared: the equation is singular */
    if (LAPACKE_dtrsyl(LAPACK_ROW_MAJOR, 'T', 'N', 1, n, n, T, n, T, n, C, n, &scale) != 0 ||
        !(scale > 0.0))
        return LAG_LQR_ERR_SINGULAR;
    for (int i = 0; i < n * n; i++) C[i] /= scale;
    mat_mul(n, n, n, U, C, Tmp);
    mat_mul(n, n, n, Tmp, Ut, X);
    for (int i = 0; i < n * n; i++)
        if (!isfinite(X[i])) return LAG_LQR_ERR_SINGULAR;
    return LAG_LQR_OK;
}

int lag_lqr_care(int n, int m, const double *A, const double *B, const double *Q,
                 const double *R, double *X, double *K)
{
    if (!sizes_ok(n, m)) return LAG_LQR_ERR_ARG;
    const int N = 2 * n;
    double G[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    if (gain_matrix(n, m, B, R, G)) return LAG_LQR_ERR_SINGULAR;

    /* Hamiltonian H = [[A, -G], [-Q, -A^T]]; its stable invariant subspace is
     * span [I; X] with X the stabilizing solution. */
    double Z[NMAX * NMAX], Zi[NMAX * NMAX];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            Z[i * N + j] = A[i * n + j];
            Z[i * N + n + j] = -G[i * n + j];
            Z[(n + i) * N + j] = -Q[i * n + j];
            Z[(n + i) * N + n + j] = -A[j * n + i];
        }
    /* Sign iteration Z <- (Z / c + c Z^-1) / 2, c = |det Z|^(1/N) (determinant scaling
     * speeds up the early steps; c -> 1 near convergence). */
    int converged = 0;
    for (int it = 0; it < 100 && !converged; it++) {
        double logdet;
        if (mat_inverse(N, Z, Zi, &logdet)) return LAG_LQR_ERR_SINGULAR;
        double c = exp(logdet / N), diff = 0.0;
        for (int i = 0; i < N * N; i++) {
            double zn = 0.5 * (Z[i] / c + c * Zi[i]);
            diff += fabs(zn - Z[i]);
            Z[i] = zn;
        }
        if (diff <= 1e-13 * mat_norm_1(N, Z) * N) converged = 1;
    }
    if (!converged) return LAG_LQR_ERR_NOCONV;

    /* (sign H + I) [I; X] = 0  =>  [W12; W22 + I] X = -[W11 + I; W21], a 2n x n system
     * solved in the least-squares sense (QR, dgels; refined below). */
    double Mx[NMAX * LAG_LQR_MAX_N], rhs[NMAX * LAG_LQR_MAX_N];
    for (int i = 0; i < N; i++)
        for (int j = 0; j < n; j++) {
            Mx[i * n + j] = Z[i * N + n + j] + (i == n + j ? 1.0 : 0.0);
            rhs[i * n + j] = -(Z[i * N + j] + (i == j ? 1.0 : 0.0));
        }
    if (LAPACKE_dgels(LAPACK_ROW_MAJOR, 'N', N, n, n, Mx, n, rhs, n) != 0)
        return LAG_LQR_ERR_SINGULAR;
    memcpy(X, rhs, sizeof(double) * (size_t)(n * n)); /* the solution: rhs's first n rows */
    for (int i = 0; i < n * n; i++)
        if (!isfinite(X[i])) return LAG_LQR_ERR_SINGULAR;
    mat_symmetrize(n, X);

    /* Newton-Kleinman refinement: K = R^-1 B^T X, X+ = X + D with
     * (A - B K)^T D + D (A - B K) = -Res(X), the Riccati residual (the same step as
     * solving for X+ with right-hand side Q + K^T R K, but D is small, so the Lyapunov
     * solve's round-off is relative to the correction, not to X). Keep a step only if it
     * lowers the residual (it does from a stabilizing X; the guard makes round-off
     * harmless). */
    double res = lag_lqr_care_residual(n, m, A, B, Q, R, X);
    for (int it = 0; it < 8 && res > 1e-15; it++) {
        double Kt[LAG_LQR_MAX_M * LAG_LQR_MAX_N], Ac[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        double W[LAG_LQR_MAX_N * LAG_LQR_MAX_N], D[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        double Xn[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        if (care_gain(n, m, B, R, X, Kt)) return LAG_LQR_ERR_SINGULAR;
        lag_lqr_closed_loop(n, m, A, B, Kt, Ac);
        if (care_residual_matrix(n, m, A, B, Q, R, X, W)) return LAG_LQR_ERR_SINGULAR;
        if (lyapunov(n, Ac, W, D)) break;
        for (int i = 0; i < n * n; i++) Xn[i] = X[i] + D[i];
        mat_symmetrize(n, Xn);
        double rn = lag_lqr_care_residual(n, m, A, B, Q, R, Xn);
        if (!(rn < res)) break;
        memcpy(X, Xn, sizeof(double) * (size_t)(n * n));
        res = rn;
    }
    return care_gain(n, m, B, R, X, K);
}

void lag_lqr_closed_loop(int n, int m, const double *A, const double *B, const double *K,
                         double *Acl)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double s = A[i * n + j];
            for (int k = 0; k < m; k++) s -= B[i * m + k] * K[k * n + j];
            Acl[i * n + j] = s;
        }
}

/* ---------------------------------------------------------------- ZOH discretization */

int lag_lqr_c2d(int n, int m, const double *A, const double *B, double h, double *Ad,
                double *Bd)
{
    if (!sizes_ok(n, m) || !(h > 0.0) || !isfinite(h)) return LAG_LQR_ERR_ARG;
    const int p = n + m;
    double Mx[NMAX * NMAX] = {0}, E[NMAX * NMAX], T[NMAX * NMAX], T2[NMAX * NMAX];
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) Mx[i * p + j] = A[i * n + j] * h;
        for (int k = 0; k < m; k++) Mx[i * p + n + k] = B[i * m + k] * h;
    }
    /* Scale so that ||M / 2^s||_1 <= 1/2, Taylor series to round-off, square s times. */
    int s = 0;
    double nrm = mat_norm_1(p, Mx);
    while (nrm > 0.5 && s < 60) { nrm *= 0.5; s++; }
    double scale = ldexp(1.0, -s);
    for (int i = 0; i < p * p; i++) Mx[i] *= scale;
    for (int i = 0; i < p * p; i++) E[i] = T[i] = (i % (p + 1) == 0) ? 1.0 : 0.0;
    for (int k = 1; k <= 30; k++) {
        mat_mul(p, p, p, T, Mx, T2);
        for (int i = 0; i < p * p; i++) T[i] = T2[i] / k;
        double tn = mat_norm_1(p, T);
        for (int i = 0; i < p * p; i++) E[i] += T[i];
        if (tn < 1e-18 * mat_norm_1(p, E)) break;
    }
    for (int k = 0; k < s; k++) {
        mat_mul(p, p, p, E, E, T);
        memcpy(E, T, sizeof(double) * (size_t)(p * p));
    }
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) Ad[i * n + j] = E[i * p + j];
        for (int k = 0; k < m; k++) Bd[i * m + k] = E[i * p + n + k];
    }
    return LAG_LQR_OK;
}

/* ---------------------------------------------------------------- DARE */

/* K = (R + Bd^T X Bd)^-1 Bd^T X Ad. */
static int dare_gain(int n, int m, const double *Ad, const double *Bd, const double *R,
                     const double *X, double *K)
{
    double Bt[LAG_LQR_MAX_M * LAG_LQR_MAX_N], BtX[LAG_LQR_MAX_M * LAG_LQR_MAX_N];
    double S[LAG_LQR_MAX_M * LAG_LQR_MAX_M];
    mat_transpose(n, m, Bd, Bt);
    mat_mul(m, n, n, Bt, X, BtX);
    mat_mul(m, n, m, BtX, Bd, S);
    for (int i = 0; i < m * m; i++) S[i] += R[i];
    mat_mul(m, n, n, BtX, Ad, K);
    return mat_solve(m, S, n, K, NULL);
}

double lag_lqr_dare_residual(int n, int m, const double *Ad, const double *Bd,
                             const double *Q, const double *R, const double *X)
{
    double K[LAG_LQR_MAX_M * LAG_LQR_MAX_N], Acl[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    double T1[LAG_LQR_MAX_N * LAG_LQR_MAX_N], T2[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    double At[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    if (!sizes_ok(n, m) || dare_gain(n, m, Ad, Bd, R, X, K)) return NAN;
    /* rhs = Ad^T X (Ad - Bd K) + Q (the DARE's right-hand side with the optimal K). */
    lag_lqr_closed_loop(n, m, Ad, Bd, K, Acl);
    mat_transpose(n, n, Ad, At);
    mat_mul(n, n, n, At, X, T1);
    mat_mul(n, n, n, T1, Acl, T2);
    for (int i = 0; i < n * n; i++) T2[i] = X[i] - (T2[i] + Q[i]);
    return mat_norm_fro(n, n, T2) / mat_norm_fro(n, n, Q);
}

int lag_lqr_dare(int n, int m, const double *Ad, const double *Bd, const double *Q,
                 const double *R, double *X, double *K)
{
    if (!sizes_ok(n, m)) return LAG_LQR_ERR_ARG;
    double Ak[LAG_LQR_MAX_N * LAG_LQR_MAX_N], Gk[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    double Hk[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
    if (gain_matrix(n, m, Bd, R, Gk)) return LAG_LQR_ERR_SINGULAR;
    memcpy(Ak, Ad, sizeof(double) * (size_t)(n * n));
    memcpy(Hk, Q, sizeof(double) * (size_t)(n * n));
    int converged = 0;
    for (int it = 0; it < 100 && !converged; it++) {
        /* W = (I + G H)^-1; A+ = A W A; G+ = G + A W G A^T; H+ = H + A^T H W A. */
        double W[LAG_LQR_MAX_N * LAG_LQR_MAX_N], Wi[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        double AW[LAG_LQR_MAX_N * LAG_LQR_MAX_N], T1[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        double T2[LAG_LQR_MAX_N * LAG_LQR_MAX_N], At[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        double An[LAG_LQR_MAX_N * LAG_LQR_MAX_N], Gn[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        double Hn[LAG_LQR_MAX_N * LAG_LQR_MAX_N];
        mat_mul(n, n, n, Gk, Hk, W);
        for (int i = 0; i < n; i++) W[i * n + i] += 1.0;
        if (mat_inverse(n, W, Wi, NULL)) return LAG_LQR_ERR_SINGULAR;
        mat_transpose(n, n, Ak, At);
        mat_mul(n, n, n, Ak, Wi, AW);
        mat_mul(n, n, n, AW, Ak, An);
        mat_mul(n, n, n, AW, Gk, T1);
        mat_mul(n, n, n, T1, At, T2);
        for (int i = 0; i < n * n; i++) Gn[i] = Gk[i] + T2[i];
        mat_mul(n, n, n, At, Hk, T1);
        mat_mul(n, n, n, T1, Wi, T2);
        mat_mul(n, n, n, T2, Ak, T1);
        double diff = 0.0;
        for (int i = 0; i < n * n; i++) {
            Hn[i] = Hk[i] + T1[i];
            diff += (Hn[i] - Hk[i]) * (Hn[i] - Hk[i]);
        }
        memcpy(Ak, An, sizeof Ak);
        memcpy(Gk, Gn, sizeof Gk);
        memcpy(Hk, Hn, sizeof Hk);
        mat_symmetrize(n, Gk);
        mat_symmetrize(n, Hk);
        if (!isfinite(diff)) return LAG_LQR_ERR_NOCONV;
        if (sqrt(diff) <= 1e-14 * mat_norm_fro(n, n, Hk)) converged = 1;
    }
    if (!converged) return LAG_LQR_ERR_NOCONV;
    memcpy(X, Hk, sizeof(double) * (size_t)(n * n));
    return dare_gain(n, m, Ad, Bd, R, X, K) ? LAG_LQR_ERR_SINGULAR : LAG_LQR_OK;
}

/* ---------------------------------------------------------------- eigenvalues */

int lag_lqr_eig(int n, const double *A, double *re, double *im)
{
    if (n < 1 || n > NMAX) return LAG_LQR_ERR_ARG;
    double a[NMAX * NMAX];
    memcpy(a, A, sizeof(double) * (size_t)(n * n));
    for (int i = 0; i < n * n; i++)
        if (!isfinite(a[i])) return LAG_LQR_ERR_ARG;
    /* balancing, Hessenberg reduction and the shifted QR iteration (dgeev) */
    double vdummy[1];
    if (LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'N', n, a, n, re, im, vdummy, 1, vdummy, 1) != 0)
        return LAG_LQR_ERR_NOCONV;
    /* insertion sort by (re, im) */
    for (int i = 1; i < n; i++) {
        double r0 = re[i], i0 = im[i];
        int j = i - 1;
        while (j >= 0 && (re[j] > r0 || (re[j] == r0 && im[j] > i0))) {
            re[j + 1] = re[j];
            im[j + 1] = im[j];
            j--;
        }
        re[j + 1] = r0;
        im[j + 1] = i0;
    }
    return LAG_LQR_OK;
}
