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
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_client.h"
#include "lqr.h"

#define N 6 /* states */

static volatile sig_atomic_t stop_requested = 0;
static void on_signal(int sig) { (void)sig; stop_requested = 1; }

static void usage(FILE *f)
{
    fprintf(f,
            "usage: dipc_lqr [options]\n"
            "Balances the DIPC of a running lagsimd upright with LQR gains computed from its\n"
            "scene description. Answers every state (lockstep-safe).\n"
            "  --prefix P       channel prefix (default DIPC)\n"
            "  --url URL        LCM URL (default: LCM's default, honours LCM_DEFAULT_URL)\n"
            "  --duration S     stop after S s of sim time from the first state (default 0:\n"
            "                   until SIGINT/SIGTERM)\n"
            "  --gain G         discrete (default: DARE at the control period) or continuous\n"
            "  --q a,b,c,d,e,f  state weights (default 5,50,50,20,700,700, Bogdanov 2004)\n"
            "  --r R            input weight (default 1)\n"
            "  --timeout S      give up after S wall s without a scene or a state (default 5;\n"
            "                   with --duration 0 only the scene wait gives up)\n"
            "  -q               quiet: design and summary only, no progress lines\n"
            "  --help           this text\n"
            "Exit status: 0 done, 1 no daemon/scene/state or design failed, 2 bad usage.\n");
}

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

static int parse_list(const char *s, double *v, int n)
{
    char *end;
    for (int i = 0; i < n; i++) {
        v[i] = strtod(s, &end);
        if (end == s || !isfinite(v[i]) || v[i] < 0.0) return -1;
        s = end;
        if (i < n - 1) {
            if (*s != ',') return -1;
            s++;
        }
    }
    return *s == '\0' ? 0 : -1;
}

int main(int argc, char **argv)
{
    const char *prefix = "DIPC", *url = NULL;
    double duration = 0.0, timeout = 5.0, r_weight = 1.0;
    double qw[N] = {5, 50, 50, 20, 700, 700};
    int quiet = 0, continuous = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-q")) {
            quiet = 1;
        } else if (!strcmp(a, "--prefix") && v) {
            prefix = v; i++;
        } else if (!strcmp(a, "--url") && v) {
            url = v; i++;
        } else if (!strcmp(a, "--duration") && v) {
            duration = atof(v); i++;
        } else if (!strcmp(a, "--timeout") && v) {
            timeout = atof(v); i++;
        } else if (!strcmp(a, "--r") && v) {
            r_weight = atof(v); i++;
            if (!(r_weight > 0.0) || !isfinite(r_weight)) {
                fprintf(stderr, "dipc_lqr: --r must be > 0\n");
                return 2;
            }
        } else if (!strcmp(a, "--q") && v) {
            if (parse_list(v, qw, N)) {
                fprintf(stderr, "dipc_lqr: --q wants 6 comma-separated weights >= 0\n");
                return 2;
            }
            i++;
        } else if (!strcmp(a, "--gain") && v) {
            if (!strcmp(v, "continuous")) continuous = 1;
            else if (!strcmp(v, "discrete")) continuous = 0;
            else {
                fprintf(stderr, "dipc_lqr: --gain is discrete or continuous\n");
                return 2;
            }
            i++;
        } else {
            fprintf(stderr, "dipc_lqr: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return 2;
        }
    }
    if (!(timeout > 0.0) || !(duration >= 0.0)) {
        fprintf(stderr, "dipc_lqr: --timeout must be > 0 and --duration >= 0\n");
        return 2;
    }

    char err[256];
    lag_client *c = lag_client_create(url, prefix, err, sizeof err);
    if (!c) {
        fprintf(stderr, "dipc_lqr: %s\n", err);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    /* ---- scene -> model */
    /* subscribed: from here on no state is missed (test harnesses wait for this line) */
    printf("dipc_lqr: waiting for the scene description on %s_SCENE\n", prefix);
    fflush(stdout);
    lag_client_scene sc;
    if (lag_client_wait_scene(c, timeout, &sc) != LAG_CLIENT_OK) {
        fprintf(stderr, "dipc_lqr: %s\n", lag_client_errmsg(c));
        lag_client_destroy(c);
        return 1;
    }
    if (strcmp(sc.model, "dipc") != 0) {
        fprintf(stderr, "dipc_lqr: prefix %s runs model '%s', not dipc\n", prefix, sc.model);
        lag_client_destroy(c);
        return 1;
    }
    lag_model model;
    lag_model_default_unfinished(&model, LAG_MODEL_DIPC);
    for (int i = 0; i < sc.num_params; i++) {
        int k = lag_model_param_index(LAG_MODEL_DIPC, sc.param_name[i]);
        if (k >= 0) model.p[k] = sc.param_value[i];
        else fprintf(stderr, "dipc_lqr: ignoring unknown parameter %s\n", sc.param_name[i]);
    }
    lag_model_finish(&model);
    if (lag_model_validate(&model, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "dipc_lqr: scene parameters: %s\n", err);
        lag_client_destroy(c);
        return 1;
    }
    const char *jn[3] = {"theta0", "theta1", "theta2"};
    int in_scene = lag_client_scene_joint(&sc, "theta0");
    if (in_scene < 0 || !sc.actuated[in_scene]) {
        fprintf(stderr, "dipc_lqr: the scene has no actuated joint theta0\n");
        lag_client_destroy(c);
        return 1;
    }
    const double h = sc.control_period;
    printf("dipc_lqr: scene %s on %s_*: mode %s, dt %g s, control period %g s, integrator %s\n",
           sc.model, prefix, sc.mode, sc.dt, h, sc.integrator);
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
    int rc = lag_lqr_linearize(&model, q0, qd0, NULL, 1, &input, A, B);
    if (rc == LAG_LQR_OK) rc = lag_lqr_care(N, 1, A, B, Q, R, X, Kc);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "dipc_lqr: continuous LQR design failed (%d)\n", rc);
        lag_client_destroy(c);
        return 1;
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
        lag_client_destroy(c);
        return 1;
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
    const double *K = continuous ? Kc : Kd;
    double rho = continuous ? rho_c : rho_d;
    if (!(cmax < 0.0) || !(rho < 1.0)) {
        fprintf(stderr, "dipc_lqr: the %s design does not stabilize the sampled loop "
                        "(spectral radius %.6f)\n", continuous ? "continuous" : "discrete", rho);
        lag_client_destroy(c);
        return 1;
    }
    printf("applying the %s gain: u = -K x on theta0\n", continuous ? "continuous" : "discrete");
    fflush(stdout);

    /* ---- control loop: answer every state */
    lag_client_state st;
    int64_t states = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY;
    double max_th1 = 0, max_th2 = 0, max_x = 0, max_u = 0, end_th1 = NAN, end_th2 = NAN;
    double x_first[N] = {0};
    int idx[3] = {-1, -1, -1}, exit_code = 0;
    while (!stop_requested) {
        rc = lag_client_wait_state(c, duration > 0.0 ? timeout : 0.5, &st);
        if (rc < 0) {
            fprintf(stderr, "dipc_lqr: %s\n", lag_client_errmsg(c));
            exit_code = 1;
            break;
        }
        if (rc == 0) {
            if (duration > 0.0) {
                fprintf(stderr, "dipc_lqr: %s\n", lag_client_errmsg(c));
                exit_code = 1;
                break;
            }
            continue; /* running until stopped: keep waiting for the daemon */
        }
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
        if (!isfinite(u)) u = 0.0; /* a non-finite state: never send NaN */
        lag_client_send_command(c, st.sim_time, 1, jn, &u);

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
        if (!quiet && st.sim_time - t_report >= 1.0) {
            t_report = st.sim_time;
            printf("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f\n", st.sim_time, x[0],
                   x[1], x[2], u);
            fflush(stdout);
        }
        if (duration > 0.0 && st.sim_time - t_first >= duration - 0.5 * h) break;
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
    lag_client_counters cnt;
    lag_client_get_counters(c, &cnt);
    printf("dipc_lqr: summary states=%lld t_first=%.6f t_last=%.6f max_abs_theta0=%.6g "
           "max_abs_theta1=%.6g max_abs_theta2=%.6g max_abs_effort=%.6g end_theta1=%.3g "
           "end_theta2=%.3g pred_max_abs_theta0=%.6g pred_max_abs_theta1=%.6g "
           "pred_max_abs_theta2=%.6g dropped=%lld\n",
           (long long)states, t_first, t_last, max_x, max_th1, max_th2, max_u, end_th1,
           end_th2, pred_x, pred_th1, pred_th2, (long long)cnt.dropped);
    lag_client_destroy(c);
    return exit_code;
}
