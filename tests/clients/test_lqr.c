/*
 * Unit test of the LQR design used by dipc_lqr (clients/lqr.c), against figures that do
 * not come from this code:
 *  - double integrator, Q = I, R = 1: X = [[sqrt3, 1], [1, sqrt3]], K = [1, sqrt3]
 *    (closed form of the 2 x 2 CARE);
 *  - scalar DARE x+ = a x + b u: X solves b^2 X^2 + (r (1 - a^2) - q b^2) X - q r = 0;
 *  - eigenvalues of a companion matrix of (s+1)(s+2)(s^2+2s+5): -2, -1, -1 +- 2i;
 *  - DIPC with Bogdanov's (2004) parameters linearized about upright by the core:
 *    open-loop poles 0, 0, +-4.10, +-10.39 (published); with his
 *    Q = diag(5, 50, 50, 20, 700, 700), R = 1 the closed loop is stable and the
 *    Riccati residual is at round-off; the discrete design at the control period is
 *    stable and tends to the continuous one as the period goes to zero;
 *  - what any stabilizing Riccati solution satisfies, computed here with plain products:
 *    the closed loop's eigenvalues are the stable half of the Hamiltonian's
 *    [[A, -B R^-1 B^T], [-Q, -A^T]] (continuous), and X is the closed loop's cost,
 *    Acl^T X + X Acl = -(Q + K^T R K) (continuous) and X = Acl^T X Acl + Q + K^T R K
 *    (discrete); for the DIPC with one input and the manipulator with two;
 *  - the cart-pole (a uniform pole on a cart) linearized upright: open-loop poles 0, 0
 *    and +-sqrt(m1 g a (m0 + m1) / ((m0 + m1)(I1 + m1 a^2) - (m1 a)^2)), a = l1 / 2;
 *  - eigenvalues of a badly scaled, non-normal matrix S diag(1, 2, 3, 4) S^-1, and of a
 *    rotation block (a +- b i).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_test.h"
#include "lqr.h"

static void test_double_integrator(void)
{
    double A[4] = {0, 1, 0, 0}, B[2] = {0, 1}, Q[4] = {1, 0, 0, 1}, R[1] = {1};
    double X[4], K[2];
    ENSURE(lag_lqr_care(2, 1, A, B, Q, R, X, K) == LAG_LQR_OK);
    ENSURE_NEAR(X[0], sqrt(3.0), 1e-12, "%s", __func__);
    ENSURE_NEAR(X[1], 1.0, 1e-12, "%s", __func__);
    ENSURE_NEAR(X[2], 1.0, 1e-12, "%s", __func__);
    ENSURE_NEAR(X[3], sqrt(3.0), 1e-12, "%s", __func__);
    ENSURE_NEAR(K[0], 1.0, 1e-12, "%s", __func__);
    ENSURE_NEAR(K[1], sqrt(3.0), 1e-12, "%s", __func__);
    ENSURE(lag_lqr_care_residual(2, 1, A, B, Q, R, X) < 1e-13);
    /* ZOH of the double integrator: Ad = [[1, h], [0, 1]], Bd = [h^2/2, h] */
    double Ad[4], Bd[2], h = 0.1;
    ENSURE(lag_lqr_c2d(2, 1, A, B, h, Ad, Bd) == LAG_LQR_OK);
    ENSURE_NEAR(Ad[0], 1.0, 1e-15, "%s", __func__);
    ENSURE_NEAR(Ad[1], h, 1e-15, "%s", __func__);
    ENSURE_NEAR(Ad[2], 0.0, 1e-15, "%s", __func__);
    ENSURE_NEAR(Ad[3], 1.0, 1e-15, "%s", __func__);
    ENSURE_NEAR(Bd[0], 0.5 * h * h, 1e-15, "%s", __func__);
    ENSURE_NEAR(Bd[1], h, 1e-15, "%s", __func__);
}

static void test_scalar_dare(void)
{
    double a = 1.2, b = 0.5, q = 2.0, r = 0.3;
    double X, K;
    ENSURE(lag_lqr_dare(1, 1, &a, &b, &q, &r, &X, &K) == LAG_LQR_OK);
    double qa = b * b, qb = r * (1 - a * a) - q * b * b, qc = -q * r;
    double Xref = (-qb + sqrt(qb * qb - 4 * qa * qc)) / (2 * qa);
    ENSURE_NEAR(X, Xref, 1e-12 * Xref, "%s", __func__);
    ENSURE_NEAR(K, b * Xref * a / (r + b * b * Xref), 1e-12, "%s", __func__);
    ENSURE(fabs(a - b * K) < 1.0);
}

static void test_eig(void)
{
    /* (s+1)(s+2)(s^2+2s+5) = s^4 + 5 s^3 + 13 s^2 + 19 s + 10 */
    double C[16] = {-5, -13, -19, -10, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    double re[4], im[4];
    ENSURE(lag_lqr_eig(4, C, re, im) == LAG_LQR_OK);
    ENSURE_NEAR(re[0], -2.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(im[0], 0.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(re[1], -1.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(im[1], -2.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(re[2], -1.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(im[2], 0.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(re[3], -1.0, 1e-10, "%s", __func__);
    ENSURE_NEAR(im[3], 2.0, 1e-10, "%s", __func__);
}

static void print_eig(const char *what, int n, const double *re, const double *im);

/* C = A B (n x n) */
static void mul(int n, const double *A, const double *B, double *C)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double t = 0.0;
            for (int k = 0; k < n; k++) t += A[i * n + k] * B[k * n + j];
            C[i * n + j] = t;
        }
}

static double fro(int n, const double *A)
{
    double t = 0.0;
    for (int i = 0; i < n * n; i++) t += A[i] * A[i];
    return sqrt(t);
}

/* The properties of a stabilizing CARE and DARE solution (see the header), for the
 * system (A, B) with weights Q, R (R diagonal) and the discrete design at h. */
static void check_riccati(const char *what, int n, int m, const double *A, const double *B,
                          const double *Q, const double *R, double h)
{
    double X[36], K[18], Acl[36], KtRK[36] = {0}, T1[36], T2[36], At[36];
    ENSURE(lag_lqr_care(n, m, A, B, Q, R, X, K) == LAG_LQR_OK);
    lag_lqr_closed_loop(n, m, A, B, K, Acl);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int a = 0; a < m; a++)
                for (int b = 0; b < m; b++) KtRK[i * n + j] += K[a * n + i] * R[a * m + b] * K[b * n + j];
    /* Lyapunov identity of the cost */
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) At[i * n + j] = Acl[j * n + i];
    mul(n, At, X, T1);
    mul(n, X, Acl, T2);
    double lyap = 0.0, scale = 0.0;
    for (int i = 0; i < n * n; i++) {
        double r = T1[i] + T2[i] + Q[i] + KtRK[i];
        lyap += r * r;
        scale = fmax(scale, fabs(Q[i] + KtRK[i]));
    }
    lyap = sqrt(lyap) / (scale * n);
    /* Hamiltonian: its n stable eigenvalues are the closed loop's */
    double H[144] = {0}, hre[12], him[12], cre[6], cim[6];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double g = 0.0; /* (B R^-1 B^T)_ij, R diagonal here */
            for (int a = 0; a < m; a++) g += B[i * m + a] * B[j * m + a] / R[a * m + a];
            H[i * 2 * n + j] = A[i * n + j];
            H[i * 2 * n + n + j] = -g;
            H[(n + i) * 2 * n + j] = -Q[i * n + j];
            H[(n + i) * 2 * n + n + j] = -A[j * n + i];
        }
    ENSURE(lag_lqr_eig(2 * n, H, hre, him) == LAG_LQR_OK);
    ENSURE(lag_lqr_eig(n, Acl, cre, cim) == LAG_LQR_OK);
    double ham = 0.0, big = 0.0;
    for (int i = 0; i < n; i++) { /* sorted by real part: the first n are the stable ones */
        ham = fmax(ham, hypot(hre[i] - cre[i], him[i] - cim[i]));
        big = fmax(big, hypot(cre[i], cim[i]));
        ENSURE(cre[i] < 0.0);
    }
    ham /= big;
    /* discrete design at h: X = Acl^T X Acl + Q h + K^T (R h) K */
    double Ad[36], Bd[18], Qd[36], Rd[9], Xd[36], Kd[18];
    ENSURE(lag_lqr_c2d(n, m, A, B, h, Ad, Bd) == LAG_LQR_OK);
    for (int i = 0; i < n * n; i++) Qd[i] = Q[i] * h;
    for (int i = 0; i < m * m; i++) Rd[i] = R[i] * h;
    ENSURE(lag_lqr_dare(n, m, Ad, Bd, Qd, Rd, Xd, Kd) == LAG_LQR_OK);
    lag_lqr_closed_loop(n, m, Ad, Bd, Kd, Acl);
    memset(KtRK, 0, sizeof KtRK);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int a = 0; a < m; a++)
                for (int b = 0; b < m; b++)
                    KtRK[i * n + j] += Kd[a * n + i] * Rd[a * m + b] * Kd[b * n + j];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) At[i * n + j] = Acl[j * n + i];
    mul(n, At, Xd, T1);
    mul(n, T1, Acl, T2);
    double dlyap = 0.0;
    for (int i = 0; i < n * n; i++) {
        double r = Xd[i] - (T2[i] + Qd[i] + KtRK[i]);
        dlyap += r * r;
    }
    dlyap = sqrt(dlyap) / fro(n, Xd);
    ENSURE(lag_lqr_eig(n, Acl, cre, cim) == LAG_LQR_OK);
    double rho = 0.0;
    for (int i = 0; i < n; i++) rho = fmax(rho, hypot(cre[i], cim[i]));
    printf("%s: continuous cost identity %.2g, closed loop vs Hamiltonian %.2g; discrete cost "
           "identity %.2g, spectral radius %.6f\n", what, lyap, ham, dlyap, rho);
    ENSURE(lyap < 1e-12);
    ENSURE(ham < 1e-10);
    ENSURE(dlyap < 1e-12);
    ENSURE(rho < 1.0);
}

static void test_riccati_properties(void)
{
    lag_model model;
    lag_model_default_unfinished(&model, LAG_MODEL_DIPC);
    lag_model_finish(&model);
    double q0[3] = {0}, qd0[3] = {0}, A[36], B[18], Q[36] = {0}, R[9] = {0};
    const int in1 = 0;
    ENSURE(lag_lqr_linearize(&model, q0, qd0, NULL, 1, &in1, A, B) == LAG_LQR_OK);
    const double qw[6] = {5, 50, 50, 20, 700, 700};
    for (int i = 0; i < 6; i++) Q[i * 6 + i] = qw[i];
    R[0] = 1.0;
    check_riccati("dipc, 1 input", 6, 1, A, B, Q, R, 0.01);

    /* the manipulator about q = (0.3, 0.5): with both joints actuated, any point is an
     * equilibrium under its holding input tau0 = h(q, 0) = -M qdd(q, 0, no input) */
    lag_model_default_unfinished(&model, LAG_MODEL_MANIPULATOR);
    lag_model_finish(&model);
    const int in2[2] = {0, 1};
    double mq[2] = {0.3, 0.5}, mqd[2] = {0}, tau0[2], qdd[2], zero[2] = {0};
    ENSURE(lag_model_forward(&model, mq, mqd, zero, qdd) == LAG_OK);
    {   /* the holding input tau0 = -M qdd(0 input), i.e. the bias: M qdd0 + h = 0 */
        double M[9];
        lag_model_mass(&model, mq, M);
        for (int i = 0; i < 2; i++) tau0[i] = -(M[i * 2] * qdd[0] + M[i * 2 + 1] * qdd[1]);
    }
    ENSURE(lag_lqr_linearize(&model, mq, mqd, tau0, 2, in2, A, B) == LAG_LQR_OK);
    double Q4[16] = {0}, R2[4] = {2.0, 0, 0, 0.5};
    const double qw4[4] = {10, 20, 1, 2};
    for (int i = 0; i < 4; i++) Q4[i * 4 + i] = qw4[i];
    check_riccati("manipulator, 2 inputs", 4, 2, A, B, Q4, R2, 0.01);
}

static void test_cartpole(void)
{
    lag_model model;
    lag_model_default_unfinished(&model, LAG_MODEL_CARTPOLE);
    const double m0 = 1.3, m1 = 0.2, l1 = 0.8, g = 9.81, a = 0.5 * l1;
    model.p[lag_model_param_index(LAG_MODEL_CARTPOLE, "m0")] = m0;
    model.p[lag_model_param_index(LAG_MODEL_CARTPOLE, "m1")] = m1;
    model.p[lag_model_param_index(LAG_MODEL_CARTPOLE, "l1")] = l1;
    model.p[lag_model_param_index(LAG_MODEL_CARTPOLE, "g")] = g;
    lag_model_finish(&model);
    const double I1 = m1 * l1 * l1 / 12.0;
    double q0[2] = {0}, qd0[2] = {0}, A[16], B[4], re[4], im[4];
    const int input = 0;
    ENSURE(lag_lqr_linearize(&model, q0, qd0, NULL, 1, &input, A, B) == LAG_LQR_OK);
    ENSURE(lag_lqr_eig(4, A, re, im) == LAG_LQR_OK);
    double lam = sqrt(m1 * g * a * (m0 + m1) / ((m0 + m1) * (I1 + m1 * a * a) - m1 * a * m1 * a));
    print_eig("cart-pole open-loop poles", 4, re, im);
    printf("closed form: 0, 0, +-%.6f\n", lam);
    ENSURE_NEAR(re[0], -lam, 1e-7 * lam, "%s", __func__);
    ENSURE_NEAR(re[1], 0.0, 1e-7, "%s", __func__);
    ENSURE_NEAR(re[2], 0.0, 1e-7, "%s", __func__);
    ENSURE_NEAR(re[3], lam, 1e-7 * lam, "%s", __func__);
    for (int i = 0; i < 4; i++) ENSURE_NEAR(im[i], 0.0, 1e-7, "%s", __func__);
    double Q[16] = {0}, R[1] = {1.0};
    for (int i = 0; i < 4; i++) Q[i * 4 + i] = 1.0;
    check_riccati("cart-pole, 1 input", 4, 1, A, B, Q, R, 0.01);
}

static void test_eig_hard(void)
{
    /* S diag(1, 2, 3, 4) S^-1 with S badly scaled: S = D P, D = diag(1, 1e4, 1e-4, 1),
     * P = I + N (N strictly upper triangular, so P^-1 = I - N + N^2 - N^3) */
    double P[16] = {1, 2, -1, 3, 0, 1, 4, -2, 0, 0, 1, 5, 0, 0, 0, 1}, Nm[16], N2[16], N3[16];
    double Pi[16], D[4] = {1, 1e4, 1e-4, 1}, Lm[16] = {0}, T[16], Mx[16], re[4], im[4];
    for (int i = 0; i < 16; i++) Nm[i] = P[i] - (i % 5 == 0 ? 1.0 : 0.0);
    mul(4, Nm, Nm, N2);
    mul(4, N2, Nm, N3);
    for (int i = 0; i < 16; i++) Pi[i] = (i % 5 == 0 ? 1.0 : 0.0) - Nm[i] + N2[i] - N3[i];
    for (int i = 0; i < 4; i++) Lm[i * 5] = i + 1;
    mul(4, P, Lm, T);
    mul(4, T, Pi, Mx); /* P L P^-1, then D (.) D^-1 */
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) Mx[i * 4 + j] *= D[i] / D[j];
    ENSURE(lag_lqr_eig(4, Mx, re, im) == LAG_LQR_OK);
    for (int i = 0; i < 4; i++) {
        ENSURE_NEAR(re[i], i + 1.0, 1e-9, "%s", __func__);
        ENSURE_NEAR(im[i], 0.0, 1e-9, "%s", __func__);
    }
    double Rb[4] = {0.5, 2.0, -2.0, 0.5};
    ENSURE(lag_lqr_eig(2, Rb, re, im) == LAG_LQR_OK);
    ENSURE_NEAR(re[0], 0.5, 1e-15, "%s", __func__);
    ENSURE_NEAR(im[0], -2.0, 1e-15, "%s", __func__);
    ENSURE_NEAR(re[1], 0.5, 1e-15, "%s", __func__);
    ENSURE_NEAR(im[1], 2.0, 1e-15, "%s", __func__);
}

static void print_eig(const char *what, int n, const double *re, const double *im)
{
    printf("%s:", what);
    for (int i = 0; i < n; i++) printf(" %.4f%+.4fi", re[i], im[i]);
    printf("\n");
}

static void test_dipc(void)
{
    lag_model model;
    lag_model_default_unfinished(&model, LAG_MODEL_DIPC);
    model.p[LAG_DIPC_M0] = 1.5;
    model.p[LAG_DIPC_M1] = 0.5;
    model.p[LAG_DIPC_M2] = 0.75;
    model.p[LAG_DIPC_L1] = 0.5;
    model.p[LAG_DIPC_L2] = 0.75;
    model.p[LAG_DIPC_G] = 9.81;
    lag_model_finish(&model); /* uniform rods: I = m l^2 / 12 */
    ENSURE_NEAR(model.p[LAG_DIPC_I1], 0.5 * 0.25 / 12.0, 1e-15, "%s", __func__);

    const int n = 6, m = 1, input = 0;
    double q0[3] = {0}, qd0[3] = {0}, A[36], B[6];
    ENSURE(lag_lqr_linearize(&model, q0, qd0, NULL, m, &input, A, B) == LAG_LQR_OK);
    double re[12], im[12];
    ENSURE(lag_lqr_eig(n, A, re, im) == LAG_LQR_OK);
    print_eig("open-loop poles", n, re, im);
    /* published to two decimals: 0, 0, +-4.10, +-10.39 */
    const double want[6] = {-10.39, -4.10, 0.0, 0.0, 4.10, 10.39};
    for (int i = 0; i < n; i++) {
        ENSURE_NEAR(re[i], want[i], 0.006, "%s", __func__);
        ENSURE_NEAR(im[i], 0.0, 1e-6, "%s", __func__);
    }

    double Q[36] = {0}, R[1] = {1.0}, X[36], K[6], Acl[36];
    const double qd[6] = {5, 50, 50, 20, 700, 700};
    for (int i = 0; i < n; i++) Q[i * n + i] = qd[i];
    ENSURE(lag_lqr_care(n, m, A, B, Q, R, X, K) == LAG_LQR_OK);
    double res = lag_lqr_care_residual(n, m, A, B, Q, R, X);
    printf("CARE relative residual %.3g\nK =", res);
    for (int i = 0; i < n; i++) printf(" %.4f", K[i]);
    printf("\n");
    ENSURE(res < 1e-12); /* the sign function alone leaves 2.7e-11: Newton-Kleinman must run */
    for (int i = 0; i < n; i++) /* X symmetric positive definite: diagonal > 0 */
        ENSURE(X[i * n + i] > 0.0);
    lag_lqr_closed_loop(n, m, A, B, K, Acl);
    ENSURE(lag_lqr_eig(n, Acl, re, im) == LAG_LQR_OK);
    print_eig("closed-loop poles", n, re, im);
    for (int i = 0; i < n; i++) ENSURE(re[i] < -0.1);

    /* Discrete design at the default control period (10 ms) and its closed loop. */
    double Ad[36], Bd[6], Xd[36], Kd[6], Qd[36], Rd[1];
    double h = 0.01;
    ENSURE(lag_lqr_c2d(n, m, A, B, h, Ad, Bd) == LAG_LQR_OK);
    for (int i = 0; i < 36; i++) Qd[i] = Q[i] * h;
    Rd[0] = R[0] * h;
    ENSURE(lag_lqr_dare(n, m, Ad, Bd, Qd, Rd, Xd, Kd) == LAG_LQR_OK);
    double resd = lag_lqr_dare_residual(n, m, Ad, Bd, Qd, Rd, Xd);
    printf("DARE (h = %g) relative residual %.3g\nKd =", h, resd);
    for (int i = 0; i < n; i++) printf(" %.4f", Kd[i]);
    printf("\n");
    ENSURE(resd < 1e-9);
    lag_lqr_closed_loop(n, m, Ad, Bd, Kd, Acl);
    ENSURE(lag_lqr_eig(n, Acl, re, im) == LAG_LQR_OK);
    double rho = 0.0;
    for (int i = 0; i < n; i++) rho = fmax(rho, hypot(re[i], im[i]));
    printf("discrete closed loop spectral radius %.6f\n", rho);
    ENSURE(rho < 1.0);

    /* As h -> 0 the discrete gain tends to the continuous one (error O(h)). */
    double err_prev = INFINITY;
    for (h = 1e-2; h >= 1e-4; h *= 0.1) {
        ENSURE(lag_lqr_c2d(n, m, A, B, h, Ad, Bd) == LAG_LQR_OK);
        for (int i = 0; i < 36; i++) Qd[i] = Q[i] * h;
        Rd[0] = R[0] * h;
        ENSURE(lag_lqr_dare(n, m, Ad, Bd, Qd, Rd, Xd, Kd) == LAG_LQR_OK);
        double err = 0.0, nk = 0.0;
        for (int i = 0; i < n; i++) {
            err = fmax(err, fabs(Kd[i] - K[i]));
            nk = fmax(nk, fabs(K[i]));
        }
        err /= nk;
        printf("h = %g: max |Kd - K| / max |K| = %.3g\n", h, err);
        ENSURE(err < err_prev * 0.2); /* first order: about 10x smaller per decade */
        err_prev = err;
    }
    ENSURE(err_prev < 5e-3);
}

static void case_lqr(int arg)
{
    (void)arg;
    test_double_integrator();
    test_scalar_dare();
    test_eig();
    test_dipc();
    test_riccati_properties();
    test_cartpole();
    test_eig_hard();
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"lqr", case_lqr, 0, 0}};
    return lt_main(argc, argv, cases, 1);
}
