/*
 * dipc_lqr: balances the double inverted pendulum on a cart upright with LQR.
 *
 * It waits for the daemon's scene description, builds the DIPC model from its
 * parameters with the core, linearizes about upright (q = 0, qd = 0), designs the gain
 * and answers every state with u = -K x on theta0, x = (theta0, theta1, theta2,
 * theta0_dot, theta1_dot, theta2_dot). Works in realtime, fast and lockstep modes
 * (every command carries the sim_time of the state it answers).
 *
 * Gain (default --gain discrete): the controller samples the state every control
 * period h and the daemon holds the effort over that period (zero-order hold), so the
 * exact design for this loop is the discrete LQR of the ZOH-discretized plant,
 * x+ = Ad x + Bd u, with the Riemann sum of the continuous cost (Q h, R h); it tends to
 * the continuous design as h -> 0 (tests/clients/test_lqr.c checks that). With
 * Bogdanov's weights the continuous closed loop has a pole near -43 rad/s, i.e.
 * |lambda| h = 0.43 at the default 100 Hz, where the continuous gain applied through a
 * ZOH is noticeably off (Kd differs from K by about 20 %). --gain continuous applies the
 * CARE gain instead; both designs and their closed-loop eigenvalues are printed.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_controller.h"
#include "lqr.h"

#define N 6 /* states */

static void print_eig(const char *what, int n, const double *M)
{
    double re[2 * N], im[2 * N];
    if (lag_lqr_eig(n, M, re, im)) {
        printf("%s: eigenvalues failed\n", what);
        return;
    }
    printf("%s:", what);
    for (int i = 0; i < n; i++) {
        if (im[i] == 0.0) printf(" %.4f", re[i]);
        else printf(" %.4f%+.4fi", re[i], im[i]);
    }
    printf("\n");
}

static double spectral_radius(int n, const double *M)
{
    double re[2 * N], im[2 * N], rho = 0.0;
    if (lag_lqr_eig(n, M, re, im)) return NAN;
    for (int i = 0; i < n; i++) rho = fmax(rho, hypot(re[i], im[i]));
    return rho;
}

static double max_real(int n, const double *M)
{
    double re[2 * N], im[2 * N], mx = -INFINITY;
    if (lag_lqr_eig(n, M, re, im)) return NAN;
    for (int i = 0; i < n; i++) mx = fmax(mx, re[i]);
    return mx;
}

/* --q: six weights >= 0 */
static int set_weights(const char *v, void *target, char *err, size_t errlen)
{
    double *w = target, x[N];
    if (lag_ctl_parse_list(v, x, N, err, errlen)) return -1;
    for (int i = 0; i < N; i++)
        if (x[i] < 0) {
            snprintf(err, errlen, "weights must be >= 0, got %g", x[i]);
            return -1;
        }
    memcpy(w, x, sizeof x);
    return 0;
}

/* --k: a given gain of six numbers */
static int set_k(const char *v, void *target, char *err, size_t errlen)
{
    double *k = target;
    if (lag_ctl_parse_list(v, k + 1, N, err, errlen)) return -1;
    k[0] = 1; /* given */
    return 0;
}

int main(int argc, char **argv)
{
    double r_weight = 1.0, qw[N] = {5, 50, 50, 20, 700, 700}, kgiven[1 + N] = {0};
    int continuous = 0;
    const lag_ctl_option mine[] = {
        {"gain", "G", "discrete (default: DARE at the control period) or continuous",
         lag_ctl_gain_kind, &continuous},
        {"q", "a,b,c,d,e,f", "state weights (default 5,50,50,20,700,700, Bogdanov 2004)",
         set_weights, qw},
        {"r", "R", "input weight (default 1)", lag_ctl_positive, &r_weight},
        {"k", "k0,...,k5", "apply this gain u = -K x instead of the design's (the design is "
                           "still printed)", set_k, kgiven},
    };
    lag_ctl ctl;
    lag_ctl_init(&ctl, "dipc_lqr", "DIPC");
    int rc = lag_ctl_parse(&ctl, argc, argv,
                           "Balances the DIPC of a running lagsimd upright with LQR gains "
                           "computed from its\nscene description. Answers every state "
                           "(lockstep-safe).",
                           mine, (int)(sizeof mine / sizeof mine[0]));
    if (rc >= 0) return rc;
    if (lag_ctl_start(&ctl, "dipc")) return lag_ctl_fail(&ctl);
    const lag_client_scene sc = ctl.scene;
    const lag_model model = ctl.model;
    const char *jn[3] = {"theta0", "theta1", "theta2"};
    int in_scene = lag_client_scene_joint(&sc, "theta0");
    if (in_scene < 0 || !sc.actuated[in_scene]) {
        fprintf(stderr, "dipc_lqr: the scene has no actuated joint theta0\n");
        return lag_ctl_fail(&ctl);
    }
    const double h = sc.control_period;
    printf("dipc_lqr: scene %s on %s_*: mode %s, dt %g s, control period %g s, integrator %s\n",
           sc.model, ctl.prefix, sc.mode, sc.dt, h, sc.integrator);
    printf("parameters:");
    for (int k = 0; k < LAG_DIPC_NP; k++)
        printf(" %s=%g", lag_model_info_get(LAG_MODEL_DIPC)->param_names[k], model.p[k]);
    printf("\n");

    /* ---- design */
    const int input = 0;
    double q0[3] = {0, 0, 0}, qd0[3] = {0, 0, 0};
    double A[N * N], B[N], Q[N * N] = {0}, R[1] = {r_weight};
    double X[N * N], Kc[N], Acl[N * N];
    for (int i = 0; i < N; i++) Q[i * N + i] = qw[i];
    rc = lag_lqr_linearize(&model, q0, qd0, NULL, 1, &input, A, B);
    if (rc == LAG_LQR_OK) rc = lag_lqr_care(N, 1, A, B, Q, R, X, Kc);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "dipc_lqr: continuous LQR design failed (%d)\n", rc);
        return lag_ctl_fail(&ctl);
    }
    print_eig("open-loop poles (1/s)", N, A);
    printf("continuous LQR: K = [%.4f %.4f %.4f %.4f %.4f %.4f], CARE residual %.2e\n",
           Kc[0], Kc[1], Kc[2], Kc[3], Kc[4], Kc[5], lag_lqr_care_residual(N, 1, A, B, Q, R, X));
    lag_lqr_closed_loop(N, 1, A, B, Kc, Acl);
    print_eig("continuous closed-loop poles (1/s)", N, Acl);
    double cmax = max_real(N, Acl);

    double Ad[N * N], Bd[N], Qd[N * N], Rd[1] = {r_weight * h}, Xd[N * N], Kd[N];
    for (int i = 0; i < N * N; i++) Qd[i] = Q[i] * h;
    rc = lag_lqr_c2d(N, 1, A, B, h, Ad, Bd);
    if (rc == LAG_LQR_OK) rc = lag_lqr_dare(N, 1, Ad, Bd, Qd, Rd, Xd, Kd);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "dipc_lqr: discrete LQR design failed (%d)\n", rc);
        return lag_ctl_fail(&ctl);
    }
    printf("discrete LQR (h = %g s): K = [%.4f %.4f %.4f %.4f %.4f %.4f], DARE residual %.2e\n",
           h, Kd[0], Kd[1], Kd[2], Kd[3], Kd[4], Kd[5],
           lag_lqr_dare_residual(N, 1, Ad, Bd, Qd, Rd, Xd));
    double Adcl[N * N];
    lag_lqr_closed_loop(N, 1, Ad, Bd, Kd, Adcl);
    print_eig("discrete closed-loop eigenvalues (z)", N, Adcl);
    double rho_d = spectral_radius(N, Adcl);
    lag_lqr_closed_loop(N, 1, Ad, Bd, Kc, Acl);
    double rho_c = spectral_radius(N, Acl);
    printf("sampled loop spectral radius: discrete gain %.6f, continuous gain %.6f\n", rho_d,
           rho_c);
    const double *K = kgiven[0] ? kgiven + 1 : continuous ? Kc : Kd;
    const char *which = kgiven[0] ? "given" : continuous ? "continuous" : "discrete";
    lag_lqr_closed_loop(N, 1, Ad, Bd, K, Acl);
    double rho = spectral_radius(N, Acl);
    if (!(cmax < 0.0) || !(rho < 1.0)) {
        fprintf(stderr, "dipc_lqr: the %s gain does not stabilize the sampled loop "
                        "(spectral radius %.6f)\n", which, rho);
        return lag_ctl_fail(&ctl);
    }
    printf("applying the %s gain: u = -K x on theta0, K = [%.17g %.17g %.17g %.17g %.17g "
           "%.17g]\n", which, K[0], K[1], K[2], K[3], K[4], K[5]);
    fflush(stdout);

    /* ---- control loop: answer every state until the run ends */
    lag_client_state st;
    int64_t states = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY;
    double max_th1 = 0, max_th2 = 0, max_x = 0, max_u = 0, end_th1 = NAN, end_th2 = NAN;
    double x_first[N] = {0};
    int idx[3] = {-1, -1, -1};
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        if (idx[0] < 0 || lag_client_state_joint(&st, jn[0]) != idx[0]) {
            for (int k = 0; k < 3; k++) idx[k] = lag_client_state_joint(&st, jn[k]);
            if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0) {
                fprintf(stderr, "dipc_lqr: state without theta0/theta1/theta2; ignored\n");
                idx[0] = -1;
                continue;
            }
        }
        double x[N];
        for (int k = 0; k < 3; k++) {
            x[k] = st.position[idx[k]];
            x[3 + k] = st.velocity[idx[k]];
        }
        double u = 0.0;
        for (int k = 0; k < N; k++) u -= K[k] * x[k];
        lag_ctl_command(&ctl, &st, 1, jn, &u); /* a non-finite u is sent as 0 */

        if (states == 0) {
            t_first = st.sim_time;
            memcpy(x_first, x, sizeof x_first);
        }
        states++;
        t_last = st.sim_time;
        max_x = fmax(max_x, fabs(x[0]));
        max_th1 = fmax(max_th1, fabs(x[1]));
        max_th2 = fmax(max_th2, fabs(x[2]));
        max_u = fmax(max_u, fabs(u));
        end_th1 = x[1];
        end_th2 = x[2];
        if (!ctl.quiet && st.sim_time - t_report >= 1.0) {
            t_report = st.sim_time;
            printf("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f\n", st.sim_time, x[0],
                   x[1], x[2], u);
            fflush(stdout);
        }
    }

    /* Linear prediction from the first state answered: the same sampled loop
     * x+ = (Ad - Bd K) x on the linearized plant, over the same number of periods.
     * For small angles the daemon's nonlinear run should come close to it. */
    double pred_th1 = 0, pred_th2 = 0, pred_x = 0, xl[N], xn[N];
    lag_lqr_closed_loop(N, 1, Ad, Bd, K, Acl);
    memcpy(xl, x_first, sizeof xl);
    for (int64_t k = 0; k < states; k++) {
        pred_x = fmax(pred_x, fabs(xl[0]));
        pred_th1 = fmax(pred_th1, fabs(xl[1]));
        pred_th2 = fmax(pred_th2, fabs(xl[2]));
        for (int i = 0; i < N; i++) {
            xn[i] = 0.0;
            for (int j = 0; j < N; j++) xn[i] += Acl[i * N + j] * xl[j];
        }
        memcpy(xl, xn, sizeof xl);
    }
    return lag_ctl_finish(&ctl,
                          "states=%lld t_first=%.6f t_last=%.6f max_abs_theta0=%.6g "
                          "max_abs_theta1=%.6g max_abs_theta2=%.6g max_abs_effort=%.6g "
                          "end_theta1=%.3g end_theta2=%.3g pred_max_abs_theta0=%.6g "
                          "pred_max_abs_theta1=%.6g pred_max_abs_theta2=%.6g",
                          (long long)states, t_first, t_last, max_x, max_th1, max_th2, max_u,
                          end_th1, end_th2, pred_x, pred_th1, pred_th2);
}
