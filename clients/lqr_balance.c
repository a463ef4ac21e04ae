/*
 * lqr_balance: holds any model of a running lagsimd at an equilibrium with LQR, the model
 * taken from the daemon's scene description (the cart-pole upright, the DIPC upright, ...).
 *
 * From the scene: the model and its parameters (the core's closed forms, as the daemon
 * runs them), the joints and which of them are actuated (the inputs), the control period
 * h. It linearizes about the equilibrium (q = --q0, default 0, qd = 0, no input; it refuses
 * a point that is not one), designs the discrete LQR of the zero-order-hold plant with the
 * Riemann sum of the continuous cost (Q h, R h; --gain continuous: the CARE gain), checks
 * that the sampled loop is stable, and answers every state with u = -K (q - q0, qd) on the
 * actuated joints. Works in realtime, fast and lockstep modes.
 *
 * Summary: per joint <j>, max_abs_<j>, end_<j> and pred_max_abs_<j> (the peak of the
 * linearized sampled loop x+ = (Ad - Bd K) x run from the first state answered, over as
 * many periods), and max_abs_effort.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_controller.h"
#include "lqr.h"

#define NS LAG_MAX_STATE
#define NI LAG_MAX_DOF

typedef struct {
    double v[NS];
    int n; /* 0: not given */
} weights;

/* a comma-separated list of 1 to NS numbers >= 0 (checked against the model later) */
static int set_list(const char *v, void *target, char *err, size_t errlen)
{
    weights *w = target;
    int n = 1;
    for (const char *c = v; *c; c++) n += *c == ',';
    if (n > NS) {
        snprintf(err, errlen, "at most %d numbers, got %d", NS, n);
        return -1;
    }
    if (lag_ctl_parse_list(v, w->v, n, err, errlen)) return -1;
    w->n = n;
    return 0;
}

static double eig_bound(int n, const double *M, int discrete)
{
    double re[2 * NS], im[2 * NS], b = -INFINITY;
    if (lag_lqr_eig(n, M, re, im)) return NAN;
    for (int i = 0; i < n; i++) b = fmax(b, discrete ? hypot(re[i], im[i]) : re[i]);
    return b;
}

static void print_eig(const char *what, int n, const double *M)
{
    double re[2 * NS], im[2 * NS];
    if (lag_lqr_eig(n, M, re, im)) return;
    printf("%s:", what);
    for (int i = 0; i < n; i++) {
        if (im[i] == 0.0) printf(" %.4f", re[i]);
        else printf(" %.4f%+.4fi", re[i], im[i]);
    }
    printf("\n");
}

int main(int argc, char **argv)
{
    double r_weight = 1.0;
    weights qw = {{0}, 0}, q0w = {{0}, 0};
    int continuous = 0;
    const lag_ctl_option mine[] = {
        {"q", "w,...", "state weights, 2 nq of them (positions, then velocities; default 1 "
                       "each)", set_list, &qw},
        {"r", "R", "weight of each input (default 1)", lag_ctl_positive, &r_weight},
        {"q0", "a,...", "the equilibrium's positions, nq of them (default 0 each)", set_list,
         &q0w},
        {"gain", "G", "discrete (default: DARE at the control period) or continuous",
         lag_ctl_gain_kind, &continuous},
    };
    lag_ctl ctl;
    lag_ctl_init(&ctl, "lqr_balance", NULL);
    int rc = lag_ctl_parse(&ctl, argc, argv,
                           "Holds the model of a running lagsimd (from its scene description) "
                           "at an equilibrium with\nLQR on its actuated joints. Answers every "
                           "state (lockstep-safe).",
                           mine, (int)(sizeof mine / sizeof mine[0]));
    if (rc >= 0) return rc;
    for (int i = 0; i < qw.n; i++)
        if (qw.v[i] < 0) {
            fprintf(stderr, "lqr_balance: --q: weights must be >= 0, got %g\n", qw.v[i]);
            return lag_result_exit(LAG_ERR_USAGE);
        }
    if (lag_ctl_start(&ctl, NULL)) return lag_ctl_fail(&ctl);
    const lag_client_scene sc = ctl.scene;
    const lag_model model = ctl.model;
    const lag_model_info *info = lag_model_info_get(ctl.kind);
    const int nq = info->nq, n = 2 * nq;
    if ((qw.n && qw.n != n) || (q0w.n && q0w.n != nq)) {
        fprintf(stderr, "lqr_balance: model %s has %d coordinates: --q takes %d weights, "
                        "--q0 %d positions\n", info->name, nq, n, nq);
        return lag_ctl_fail(&ctl);
    }
    int inputs[NI], m = 0;
    const char *in_names[NI];
    for (int i = 0; i < nq; i++)
        if (info->actuated[i]) {
            inputs[m] = i;
            in_names[m++] = info->joint_names[i];
        }
    const double h = sc.control_period;
    printf("lqr_balance: scene %s on %s_*: mode %s, dt %g s, control period %g s, integrator "
           "%s\n", sc.model, ctl.prefix, sc.mode, sc.dt, h, sc.integrator);
    printf("parameters:");
    for (int k = 0; k < info->np; k++) printf(" %s=%g", info->param_names[k], model.p[k]);
    printf("\ninputs:");
    for (int k = 0; k < m; k++) printf(" %s", in_names[k]);
    printf("\n");

    /* ---- the equilibrium: qdd(q0, 0, 0) = 0 */
    double q0[NI] = {0}, zero[NI] = {0}, qdd[NI];
    for (int i = 0; i < q0w.n; i++) q0[i] = q0w.v[i];
    if (lag_model_forward(&model, q0, zero, zero, qdd) != LAG_OK) {
        fprintf(stderr, "lqr_balance: the model's dynamics fail at q0\n");
        return lag_ctl_fail(&ctl);
    }
    for (int i = 0; i < nq; i++)
        if (!(fabs(qdd[i]) <= 1e-9)) { /* m/s^2 or rad/s^2 */
            fprintf(stderr, "lqr_balance: q0 is not an equilibrium without input (%s'' = %g)\n",
                    info->joint_names[i], qdd[i]);
            return lag_ctl_fail(&ctl);
        }

    /* ---- design */
    double A[NS * NS], B[NS * NI], Q[NS * NS] = {0}, R[NI * NI] = {0};
    double X[NS * NS], Kc[NI * NS], Acl[NS * NS];
    for (int i = 0; i < n; i++) Q[i * n + i] = qw.n ? qw.v[i] : 1.0;
    for (int k = 0; k < m; k++) R[k * m + k] = r_weight;
    rc = lag_lqr_linearize(&model, q0, zero, NULL, m, inputs, A, B);
    if (rc == LAG_LQR_OK) rc = lag_lqr_care(n, m, A, B, Q, R, X, Kc);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "lqr_balance: continuous LQR design failed (%d)\n", rc);
        return lag_ctl_fail(&ctl);
    }
    print_eig("open-loop poles (1/s)", n, A);
    lag_lqr_closed_loop(n, m, A, B, Kc, Acl);
    printf("continuous LQR: CARE residual %.2e\n", lag_lqr_care_residual(n, m, A, B, Q, R, X));
    print_eig("continuous closed-loop poles (1/s)", n, Acl);
    double Ad[NS * NS], Bd[NS * NI], Qd[NS * NS], Rd[NI * NI], Xd[NS * NS], Kd[NI * NS];
    for (int i = 0; i < n * n; i++) Qd[i] = Q[i] * h;
    for (int i = 0; i < m * m; i++) Rd[i] = R[i] * h;
    rc = lag_lqr_c2d(n, m, A, B, h, Ad, Bd);
    if (rc == LAG_LQR_OK) rc = lag_lqr_dare(n, m, Ad, Bd, Qd, Rd, Xd, Kd);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "lqr_balance: discrete LQR design failed (%d)\n", rc);
        return lag_ctl_fail(&ctl);
    }
    printf("discrete LQR (h = %g s): DARE residual %.2e\n", h,
           lag_lqr_dare_residual(n, m, Ad, Bd, Qd, Rd, Xd));
    const double *K = continuous ? Kc : Kd;
    double Adcl[NS * NS];
    lag_lqr_closed_loop(n, m, Ad, Bd, K, Adcl);
    print_eig("sampled closed-loop eigenvalues (z)", n, Adcl);
    double rho = eig_bound(n, Adcl, 1);
    if (!(rho < 1.0)) {
        fprintf(stderr, "lqr_balance: the %s gain does not stabilize the sampled loop "
                        "(spectral radius %.6f)\n", continuous ? "continuous" : "discrete", rho);
        return lag_ctl_fail(&ctl);
    }
    for (int k = 0; k < m; k++) {
        /* u, not the joint's name: a joint may be called x (the cart-pole's), the state's name */
        printf("applying the %s gain on %s: u = -K x, K =", continuous ? "continuous" : "discrete",
               in_names[k]);
        for (int j = 0; j < n; j++) printf(" %.17g", K[k * n + j]);
        printf("\n");
    }
    fflush(stdout);

    /* ---- control loop: answer every state until the run ends */
    lag_client_state st;
    int64_t states = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY, max_u = 0.0;
    double x_first[NS] = {0}, max_abs[NI] = {0}, end[NI] = {0};
    int idx[NI];
    for (int i = 0; i < nq; i++) idx[i] = -1;
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        bool have = true;
        for (int i = 0; i < nq; i++) {
            if (idx[i] < 0 || idx[i] >= st.num_joints ||
                strcmp(st.name[idx[i]], info->joint_names[i]) != 0)
                idx[i] = lag_client_state_joint(&st, info->joint_names[i]);
            have = have && idx[i] >= 0;
        }
        if (!have) {
            fprintf(stderr, "lqr_balance: a state without the model's joints; ignored\n");
            continue;
        }
        double x[NS], u[NI];
        for (int i = 0; i < nq; i++) {
            x[i] = st.position[idx[i]] - q0[i];
            x[nq + i] = st.velocity[idx[i]];
        }
        for (int k = 0; k < m; k++) {
            u[k] = 0.0;
            for (int j = 0; j < n; j++) u[k] -= K[k * n + j] * x[j];
            max_u = fmax(max_u, fabs(u[k]));
        }
        lag_ctl_command(&ctl, &st, m, in_names, u); /* a non-finite u is sent as 0 */
        if (states == 0) {
            t_first = st.sim_time;
            memcpy(x_first, x, sizeof x_first);
        }
        states++;
        t_last = st.sim_time;
        for (int i = 0; i < nq; i++) {
            max_abs[i] = fmax(max_abs[i], fabs(x[i]));
            end[i] = x[i];
        }
        if (!ctl.quiet && st.sim_time - t_report >= 1.0) {
            t_report = st.sim_time;
            printf("t=%8.3f", st.sim_time);
            for (int i = 0; i < nq; i++) printf("  %s=%+.6f", info->joint_names[i], x[i]);
            printf("\n");
            fflush(stdout);
        }
    }

    /* Linear prediction from the first state answered: the same sampled loop on the
     * linearized plant over the same number of periods (near the equilibrium, the
     * daemon's nonlinear run should come close to it). */
    double pred[NI] = {0}, xl[NS], xn[NS];
    memcpy(xl, x_first, sizeof xl);
    for (int64_t k = 0; k < states; k++) {
        for (int i = 0; i < nq; i++) pred[i] = fmax(pred[i], fabs(xl[i]));
        for (int i = 0; i < n; i++) {
            xn[i] = 0.0;
            for (int j = 0; j < n; j++) xn[i] += Adcl[i * n + j] * xl[j];
        }
        memcpy(xl, xn, sizeof xl);
    }
    char joints[1024] = "";
    size_t len = 0;
    for (int i = 0; i < nq && len < sizeof joints; i++)
        len += (size_t)snprintf(joints + len, sizeof joints - len,
                                " max_abs_%s=%.6g end_%s=%.3g pred_max_abs_%s=%.6g",
                                info->joint_names[i], max_abs[i], info->joint_names[i], end[i],
                                info->joint_names[i], pred[i]);
    return lag_ctl_finish(&ctl, "states=%lld t_first=%.6f t_last=%.6f max_abs_effort=%.6g%s",
                          (long long)states, t_first, t_last, max_u, joints);
}
