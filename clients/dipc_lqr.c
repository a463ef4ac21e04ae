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

/* The design: the plant linearized about upright, the continuous and discrete gains, and
 * the gain applied (K points at one of them, or at --k's). */
typedef struct design {
    double h;                         /* control period, s */
    double A[N * N], B[N], Q[N * N];  /* x' = A x + B u, cost weights */
    double Kc[N];                     /* continuous LQR (CARE) */
    double Ad[N * N], Bd[N], Kd[N];   /* zero-order-hold plant, discrete LQR (DARE) */
    double cmax;                      /* largest real part of the continuous loop's poles */
    const double *K;                  /* the gain applied */
    const char *which;                /* "given", "continuous" or "discrete" */
} design;

/* Continuous LQR of the plant linearized about upright; prints its poles. */
static int design_continuous(design *d, const lag_model *model, const double qw[N], double r)
{
    const int input = 0;
    double q0[3] = {0, 0, 0}, qd0[3] = {0, 0, 0}, R[1] = {r}, X[N * N], Acl[N * N];
    memset(d->Q, 0, sizeof d->Q);
    for (int i = 0; i < N; i++) d->Q[i * N + i] = qw[i];
    int rc = lag_lqr_linearize(model, q0, qd0, NULL, 1, &input, d->A, d->B);
    if (rc == LAG_LQR_OK) rc = lag_lqr_care(N, 1, d->A, d->B, d->Q, R, X, d->Kc);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "dipc_lqr: continuous LQR design failed (%d)\n", rc);
        return -1;
    }
    print_eig("open-loop poles (1/s)", N, d->A);
    printf("continuous LQR: K = [%.4f %.4f %.4f %.4f %.4f %.4f], CARE residual %.2e\n",
           d->Kc[0], d->Kc[1], d->Kc[2], d->Kc[3], d->Kc[4], d->Kc[5],
           lag_lqr_care_residual(N, 1, d->A, d->B, d->Q, R, X));
    lag_lqr_closed_loop(N, 1, d->A, d->B, d->Kc, Acl);
    print_eig("continuous closed-loop poles (1/s)", N, Acl);
    d->cmax = max_real(N, Acl);
    return 0;
}

/* Discrete LQR of the zero-order-hold plant at the control period, cost (Q h, R h); prints
 * both gains' sampled loops. */
static int design_discrete(design *d, double r)
{
    const double h = d->h;
    double Qd[N * N], Rd[1] = {r * h}, Xd[N * N], Acl[N * N];
    for (int i = 0; i < N * N; i++) Qd[i] = d->Q[i] * h;
    int rc = lag_lqr_c2d(N, 1, d->A, d->B, h, d->Ad, d->Bd);
    if (rc == LAG_LQR_OK) rc = lag_lqr_dare(N, 1, d->Ad, d->Bd, Qd, Rd, Xd, d->Kd);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "dipc_lqr: discrete LQR design failed (%d)\n", rc);
        return -1;
    }
    printf("discrete LQR (h = %g s): K = [%.4f %.4f %.4f %.4f %.4f %.4f], DARE residual %.2e\n",
           h, d->Kd[0], d->Kd[1], d->Kd[2], d->Kd[3], d->Kd[4], d->Kd[5],
           lag_lqr_dare_residual(N, 1, d->Ad, d->Bd, Qd, Rd, Xd));
    lag_lqr_closed_loop(N, 1, d->Ad, d->Bd, d->Kd, Acl);
    print_eig("discrete closed-loop eigenvalues (z)", N, Acl);
    double rho_d = spectral_radius(N, Acl);
    lag_lqr_closed_loop(N, 1, d->Ad, d->Bd, d->Kc, Acl);
    double rho_c = spectral_radius(N, Acl);
    printf("sampled loop spectral radius: discrete gain %.6f, continuous gain %.6f\n", rho_d,
           rho_c);
    return 0;
}

/* The gain to apply (--k's, or the design --gain names), refused unless it stabilizes the
 * sampled loop. */
static int choose_gain(design *d, const double kgiven[1 + N], int continuous)
{
    double Acl[N * N];
    d->K = kgiven[0] ? kgiven + 1 : continuous ? d->Kc : d->Kd;
    d->which = kgiven[0] ? "given" : continuous ? "continuous" : "discrete";
    lag_lqr_closed_loop(N, 1, d->Ad, d->Bd, d->K, Acl);
    double rho = spectral_radius(N, Acl);
    if (!(d->cmax < 0.0) || !(rho < 1.0)) {
        fprintf(stderr, "dipc_lqr: the %s gain does not stabilize the sampled loop "
                        "(spectral radius %.6f)\n", d->which, rho);
        return -1;
    }
    const double *K = d->K;
    printf("applying the %s gain: u = -K x on theta0, K = [%.17g %.17g %.17g %.17g %.17g "
           "%.17g]\n", d->which, K[0], K[1], K[2], K[3], K[4], K[5]);
    fflush(stdout);
    return 0;
}

/* What the run did: its states, peaks and end angles for the summary. */
typedef struct balance {
    int idx[3];                       /* theta0..2 in the state's joints (-1: look up) */
    int64_t states;
    double t_first, t_last, t_report;
    double max_x, max_th1, max_th2, max_u, end_th1, end_th2;
    double x_first[N];                /* the first state answered: the prediction's start */
} balance;

/* x = (theta0, theta1, theta2, their rates) from a state; -1 if it lacks a joint. */
static int state_vector(balance *b, const lag_client_state *st, const char *const jn[3],
                        double x[N])
{
    if (b->idx[0] < 0 || lag_client_state_joint(st, jn[0]) != b->idx[0]) {
        for (int k = 0; k < 3; k++) b->idx[k] = lag_client_state_joint(st, jn[k]);
        if (b->idx[0] < 0 || b->idx[1] < 0 || b->idx[2] < 0) {
            fprintf(stderr, "dipc_lqr: state without theta0/theta1/theta2; ignored\n");
            b->idx[0] = -1;
            return -1;
        }
    }
    for (int k = 0; k < 3; k++) {
        x[k] = st->position[b->idx[k]];
        x[3 + k] = st->velocity[b->idx[k]];
    }
    return 0;
}

static void record(balance *b, const lag_ctl *ctl, double t, const double x[N], double u)
{
    if (b->states == 0) {
        b->t_first = t;
        memcpy(b->x_first, x, sizeof b->x_first);
    }
    b->states++;
    b->t_last = t;
    b->max_x = fmax(b->max_x, fabs(x[0]));
    b->max_th1 = fmax(b->max_th1, fabs(x[1]));
    b->max_th2 = fmax(b->max_th2, fabs(x[2]));
    b->max_u = fmax(b->max_u, fabs(u));
    b->end_th1 = x[1];
    b->end_th2 = x[2];
    if (!ctl->quiet && t - b->t_report >= 1.0) {
        b->t_report = t;
        printf("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f\n", t, x[0], x[1], x[2], u);
        fflush(stdout);
    }
}

/* Linear prediction from the first state answered: the same sampled loop
 * x+ = (Ad - Bd K) x on the linearized plant, over the same number of periods.
 * For small angles the daemon's nonlinear run should come close to it. */
static void predict(const design *d, const balance *b, double pred[3])
{
    double Acl[N * N], xl[N], xn[N];
    pred[0] = pred[1] = pred[2] = 0;
    lag_lqr_closed_loop(N, 1, d->Ad, d->Bd, d->K, Acl);
    memcpy(xl, b->x_first, sizeof xl);
    for (int64_t k = 0; k < b->states; k++) {
        for (int i = 0; i < 3; i++) pred[i] = fmax(pred[i], fabs(xl[i]));
        for (int i = 0; i < N; i++) {
            xn[i] = 0.0;
            for (int j = 0; j < N; j++) xn[i] += Acl[i * N + j] * xl[j];
        }
        memcpy(xl, xn, sizeof xl);
    }
}

static int finish(lag_ctl *ctl, const design *d, const balance *b)
{
    double pred[3];
    predict(d, b, pred);
    return lag_ctl_finish(ctl,
                          "states=%lld t_first=%.6f t_last=%.6f max_abs_theta0=%.6g "
                          "max_abs_theta1=%.6g max_abs_theta2=%.6g max_abs_effort=%.6g "
                          "end_theta1=%.3g end_theta2=%.3g pred_max_abs_theta0=%.6g "
                          "pred_max_abs_theta1=%.6g pred_max_abs_theta2=%.6g",
                          (long long)b->states, b->t_first, b->t_last, b->max_x, b->max_th1,
                          b->max_th2, b->max_u, b->end_th1, b->end_th2, pred[0], pred[1],
                          pred[2]);
}

static void print_scene(const lag_ctl *ctl)
{
    const lag_client_scene *sc = ctl->scene;
    printf("dipc_lqr: scene %s on %s_*: mode %s, dt %g s, control period %g s, integrator %s\n",
           lag_client_scene_model(sc), ctl->prefix, lag_client_scene_mode(sc),
           lag_client_scene_dt(sc), lag_client_scene_control_period(sc),
           lag_client_scene_integrator(sc));
    printf("parameters:");
    for (int k = 0; k < LAG_DIPC_NP; k++)
        printf(" %s=%g", lag_model_info_get(LAG_MODEL_DIPC)->param_names[k], ctl->model.p[k]);
    printf("\n");
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
    const char *jn[3] = {"theta0", "theta1", "theta2"};
    int in_scene = lag_client_scene_joint(ctl.scene, "theta0");
    if (!lag_client_scene_actuated(ctl.scene, in_scene)) {
        fprintf(stderr, "dipc_lqr: the scene has no actuated joint theta0\n");
        return lag_ctl_fail(&ctl);
    }
    print_scene(&ctl);

    /* ---- design */
    design d = {.h = lag_client_scene_control_period(ctl.scene)};
    if (design_continuous(&d, &ctl.model, qw, r_weight) || design_discrete(&d, r_weight) ||
        choose_gain(&d, kgiven, continuous))
        return lag_ctl_fail(&ctl);

    /* ---- control loop: answer every state until the run ends */
    lag_client_state st;
    balance b = {.idx = {-1, -1, -1}, .t_first = NAN, .t_last = NAN, .t_report = -INFINITY,
                 .end_th1 = NAN, .end_th2 = NAN};
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        double x[N], u = 0.0;
        if (state_vector(&b, &st, jn, x)) continue;
        for (int k = 0; k < N; k++) u -= d.K[k] * x[k];
        lag_ctl_command(&ctl, &st, 1, jn, &u); /* a non-finite u is sent as 0 */
        record(&b, &ctl, st.sim_time, x, u);
    }
    return finish(&ctl, &d, &b);
}
