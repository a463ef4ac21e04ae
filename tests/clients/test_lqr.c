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
 *    stable and tends to the continuous one as the period goes to zero.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lqr.h"

static int failures = 0;
#define ENSURE(cond)                                                                   \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: ENSURE(%s) failed\n", __FILE__, __LINE__, #cond);  \
            failures++;                                                                \
        }                                                                              \
    } while (0)
#define ENSURE_NEAR(a, b, tol)                                                         \
    do {                                                                               \
        double a_ = (a), b_ = (b);                                                     \
        if (!(fabs(a_ - b_) <= (tol))) {                                               \
            fprintf(stderr, "%s:%d: %s = %.12g, expected %.12g +- %g\n", __FILE__,     \
                    __LINE__, #a, a_, b_, (double)(tol));                              \
            failures++;                                                                \
        }                                                                              \
    } while (0)

static void test_double_integrator(void)
{
    double A[4] = {0, 1, 0, 0}, B[2] = {0, 1}, Q[4] = {1, 0, 0, 1}, R[1] = {1};
    double X[4], K[2];
    ENSURE(lag_lqr_care(2, 1, A, B, Q, R, X, K) == LAG_LQR_OK);
    ENSURE_NEAR(X[0], sqrt(3.0), 1e-12);
    ENSURE_NEAR(X[1], 1.0, 1e-12);
    ENSURE_NEAR(X[2], 1.0, 1e-12);
    ENSURE_NEAR(X[3], sqrt(3.0), 1e-12);
    ENSURE_NEAR(K[0], 1.0, 1e-12);
    ENSURE_NEAR(K[1], sqrt(3.0), 1e-12);
    ENSURE(lag_lqr_care_residual(2, 1, A, B, Q, R, X) < 1e-13);
    /* ZOH of the double integrator: Ad = [[1, h], [0, 1]], Bd = [h^2/2, h] */
    double Ad[4], Bd[2], h = 0.1;
    ENSURE(lag_lqr_c2d(2, 1, A, B, h, Ad, Bd) == LAG_LQR_OK);
    ENSURE_NEAR(Ad[0], 1.0, 1e-15);
    ENSURE_NEAR(Ad[1], h, 1e-15);
    ENSURE_NEAR(Ad[2], 0.0, 1e-15);
    ENSURE_NEAR(Ad[3], 1.0, 1e-15);
    ENSURE_NEAR(Bd[0], 0.5 * h * h, 1e-15);
    ENSURE_NEAR(Bd[1], h, 1e-15);
}

static void test_scalar_dare(void)
{
    double a = 1.2, b = 0.5, q = 2.0, r = 0.3;
    double X, K;
    ENSURE(lag_lqr_dare(1, 1, &a, &b, &q, &r, &X, &K) == LAG_LQR_OK);
    double qa = b * b, qb = r * (1 - a * a) - q * b * b, qc = -q * r;
    double Xref = (-qb + sqrt(qb * qb - 4 * qa * qc)) / (2 * qa);
    ENSURE_NEAR(X, Xref, 1e-12 * Xref);
    ENSURE_NEAR(K, b * Xref * a / (r + b * b * Xref), 1e-12);
    ENSURE(fabs(a - b * K) < 1.0);
}

static void test_eig(void)
{
    /* (s+1)(s+2)(s^2+2s+5) = s^4 + 5 s^3 + 13 s^2 + 19 s + 10 */
    double C[16] = {-5, -13, -19, -10, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    double re[4], im[4];
    ENSURE(lag_lqr_eig(4, C, re, im) == LAG_LQR_OK);
    ENSURE_NEAR(re[0], -2.0, 1e-10);
    ENSURE_NEAR(im[0], 0.0, 1e-10);
    ENSURE_NEAR(re[1], -1.0, 1e-10);
    ENSURE_NEAR(im[1], -2.0, 1e-10);
    ENSURE_NEAR(re[2], -1.0, 1e-10);
    ENSURE_NEAR(im[2], 0.0, 1e-10);
    ENSURE_NEAR(re[3], -1.0, 1e-10);
    ENSURE_NEAR(im[3], 2.0, 1e-10);
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
    ENSURE_NEAR(model.p[LAG_DIPC_I1], 0.5 * 0.25 / 12.0, 1e-15);

    const int n = 6, m = 1, input = 0;
    double q0[3] = {0}, qd0[3] = {0}, A[36], B[6];
    ENSURE(lag_lqr_linearize(&model, q0, qd0, NULL, m, &input, A, B) == LAG_LQR_OK);
    double re[12], im[12];
    ENSURE(lag_lqr_eig(n, A, re, im) == LAG_LQR_OK);
    print_eig("open-loop poles", n, re, im);
    /* published to two decimals: 0, 0, +-4.10, +-10.39 */
    const double want[6] = {-10.39, -4.10, 0.0, 0.0, 4.10, 10.39};
    for (int i = 0; i < n; i++) {
        ENSURE_NEAR(re[i], want[i], 0.006);
        ENSURE_NEAR(im[i], 0.0, 1e-6);
    }

    double Q[36] = {0}, R[1] = {1.0}, X[36], K[6], Acl[36];
    const double qd[6] = {5, 50, 50, 20, 700, 700};
    for (int i = 0; i < n; i++) Q[i * n + i] = qd[i];
    ENSURE(lag_lqr_care(n, m, A, B, Q, R, X, K) == LAG_LQR_OK);
    double res = lag_lqr_care_residual(n, m, A, B, Q, R, X);
    printf("CARE relative residual %.3g\nK =", res);
    for (int i = 0; i < n; i++) printf(" %.4f", K[i]);
    printf("\n");
    ENSURE(res < 1e-10);
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

int main(void)
{
    test_double_integrator();
    test_scalar_dare();
    test_eig();
    test_dipc();
    if (failures) {
        fprintf(stderr, "test_lqr: %d failure(s)\n", failures);
        return 1;
    }
    printf("test_lqr: all passed\n");
    return 0;
}
