/*
 * manipulator_pd: makes the rotary/prismatic manipulator track a smooth joint trajectory
 *   q1_d(t) = A1 sin(w1 t),  q2_d(t) = c2 + A2 sin(w2 t)   (t = sim time, s)
 * (defaults 0.3 rad, 0.5 rad/s; 0.5 m, 0.1 m, 1 rad/s) with PD plus model feedforward
 * (computed torque) built from the scene's parameters by the core:
 *   tau = M(q) (qdd_d + Kp (q_d - q) + Kd (qd_d - qd)) + C(q, qd) qd + g(q).
 * With the exact model the error obeys e'' + Kd e' + Kp e = 0 (Kp = wn^2, Kd = 2 wn,
 * critically damped), up to the zero-order hold of the effort over a control period.
 * Answers every state (lockstep-safe) and prints the tracking error.
 */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_client.h"

static volatile sig_atomic_t stop_requested = 0;
static void on_signal(int sig) { (void)sig; stop_requested = 1; }

typedef struct traj {
    double a1, w1, c2, a2, w2;
} traj;

/* Desired position, velocity, acceleration at sim time t. OUT: q, qd, qdd (2 each) */
static void traj_eval(const traj *tr, double t, double *q, double *qd, double *qdd)
{
    q[0] = tr->a1 * sin(tr->w1 * t);
    qd[0] = tr->a1 * tr->w1 * cos(tr->w1 * t);
    qdd[0] = -tr->a1 * tr->w1 * tr->w1 * sin(tr->w1 * t);
    q[1] = tr->c2 + tr->a2 * sin(tr->w2 * t);
    qd[1] = tr->a2 * tr->w2 * cos(tr->w2 * t);
    qdd[1] = -tr->a2 * tr->w2 * tr->w2 * sin(tr->w2 * t);
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: manipulator_pd [options]\n"
            "Tracks q1 = 0.3 sin(0.5 t), q2 = 0.5 + 0.1 sin(t) on a running lagsimd manipulator\n"
            "with PD + computed-torque feedforward from its scene description.\n"
            "  --prefix P     channel prefix (default MANIPULATOR)\n"
            "  --url URL      LCM URL (default: LCM's default, honours LCM_DEFAULT_URL)\n"
            "  --duration S   stop after S s of sim time from the first state (default 0:\n"
            "                 until SIGINT/SIGTERM)\n"
            "  --wn W         PD bandwidth, rad/s: Kp = W^2, Kd = 2 W (default 10)\n"
            "  --settle S     error statistics skip the first S s (default 2)\n"
            "  --timeout S    give up after S wall s without a scene or state (default 5)\n"
            "  -q             quiet: summary only\n"
            "  --help         this text\n");
}

int main(int argc, char **argv)
{
    const char *prefix = "MANIPULATOR", *url = NULL;
    double duration = 0.0, timeout = 5.0, wn = 10.0, settle = 2.0;
    int quiet = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        else if (!strcmp(a, "-q")) quiet = 1;
        else if (!strcmp(a, "--prefix") && v) { prefix = v; i++; }
        else if (!strcmp(a, "--url") && v) { url = v; i++; }
        else if (!strcmp(a, "--duration") && v) { duration = atof(v); i++; }
        else if (!strcmp(a, "--timeout") && v) { timeout = atof(v); i++; }
        else if (!strcmp(a, "--wn") && v) { wn = atof(v); i++; }
        else if (!strcmp(a, "--settle") && v) { settle = atof(v); i++; }
        else {
            fprintf(stderr, "manipulator_pd: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return 2;
        }
    }
    if (!(timeout > 0.0) || !(duration >= 0.0) || !(wn > 0.0) || !(settle >= 0.0)) {
        fprintf(stderr, "manipulator_pd: --timeout, --wn must be > 0; --duration, --settle >= 0\n");
        return 2;
    }
    const double kp = wn * wn, kd = 2.0 * wn;
    const traj tr = {0.3, 0.5, 0.5, 0.1, 1.0};

    char err[256];
    lag_client *c = lag_client_create(url, prefix, err, sizeof err);
    if (!c) {
        fprintf(stderr, "manipulator_pd: %s\n", err);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    /* subscribed: from here on no state is missed (test harnesses wait for this line) */
    printf("manipulator_pd: waiting for the scene description on %s_SCENE\n", prefix);
    fflush(stdout);
    lag_client_scene sc;
    if (lag_client_wait_scene(c, timeout, &sc) != LAG_CLIENT_OK) {
        fprintf(stderr, "manipulator_pd: %s\n", lag_client_errmsg(c));
        lag_client_destroy(c);
        return 1;
    }
    if (strcmp(sc.model, "manipulator") != 0) {
        fprintf(stderr, "manipulator_pd: prefix %s runs model '%s', not manipulator\n", prefix,
                sc.model);
        lag_client_destroy(c);
        return 1;
    }
    lag_model model;
    lag_model_default_unfinished(&model, LAG_MODEL_MANIPULATOR);
    for (int i = 0; i < sc.num_params; i++) {
        int k = lag_model_param_index(LAG_MODEL_MANIPULATOR, sc.param_name[i]);
        if (k >= 0) model.p[k] = sc.param_value[i];
    }
    lag_model_finish(&model);
    if (lag_model_validate(&model, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "manipulator_pd: scene parameters: %s\n", err);
        lag_client_destroy(c);
        return 1;
    }
    const char *jn[2] = {"q1", "q2"};
    for (int k = 0; k < 2; k++) {
        int j = lag_client_scene_joint(&sc, jn[k]);
        if (j < 0 || !sc.actuated[j]) {
            fprintf(stderr, "manipulator_pd: joint %s is not actuated in this scene\n", jn[k]);
            lag_client_destroy(c);
            return 1;
        }
    }
    printf("manipulator_pd: scene on %s_*: mode %s, control period %g s; Kp %g, Kd %g\n",
           prefix, sc.mode, sc.control_period, kp, kd);
    fflush(stdout);

    lag_client_state st;
    int64_t states = 0, n_settled = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY;
    double emax[2] = {0, 0}, esq[2] = {0, 0}, emax_all[2] = {0, 0};
    int exit_code = 0;
    while (!stop_requested) {
        int rc = lag_client_wait_state(c, duration > 0.0 ? timeout : 0.5, &st);
        if (rc < 0 || (rc == 0 && duration > 0.0)) {
            fprintf(stderr, "manipulator_pd: %s\n", lag_client_errmsg(c));
            exit_code = 1;
            break;
        }
        if (rc == 0) continue;
        int i1 = lag_client_state_joint(&st, "q1"), i2 = lag_client_state_joint(&st, "q2");
        if (i1 < 0 || i2 < 0) continue;
        double q[2] = {st.position[i1], st.position[i2]};
        double qd[2] = {st.velocity[i1], st.velocity[i2]};
        double q_d[2], qd_d[2], qdd_d[2], M[4], hb[2], v[2], tau[2];
        traj_eval(&tr, st.sim_time, q_d, qd_d, qdd_d);
        for (int k = 0; k < 2; k++)
            v[k] = qdd_d[k] + kp * (q_d[k] - q[k]) + kd * (qd_d[k] - qd[k]);
        lag_model_mass(&model, q, M);
        lag_model_bias(&model, q, qd, hb);
        for (int k = 0; k < 2; k++) {
            tau[k] = M[2 * k] * v[0] + M[2 * k + 1] * v[1] + hb[k];
            if (!isfinite(tau[k])) tau[k] = 0.0;
        }
        lag_client_send_command(c, st.sim_time, 2, jn, tau);

        if (states == 0) t_first = st.sim_time;
        states++;
        t_last = st.sim_time;
        double e[2] = {q_d[0] - q[0], q_d[1] - q[1]};
        for (int k = 0; k < 2; k++) emax_all[k] = fmax(emax_all[k], fabs(e[k]));
        if (st.sim_time - t_first >= settle) {
            n_settled++;
            for (int k = 0; k < 2; k++) {
                emax[k] = fmax(emax[k], fabs(e[k]));
                esq[k] += e[k] * e[k];
            }
        }
        if (!quiet && st.sim_time - t_report >= 1.0) {
            t_report = st.sim_time;
            printf("t=%8.3f  q1=%+.5f (e %+.2e)  q2=%+.5f (e %+.2e)  tau=%+.3f %+.3f\n",
                   st.sim_time, q[0], e[0], q[1], e[1], tau[0], tau[1]);
            fflush(stdout);
        }
        if (duration > 0.0 && st.sim_time - t_first >= duration - 0.5 * sc.control_period) break;
    }
    double rms[2] = {0, 0};
    for (int k = 0; k < 2; k++) rms[k] = n_settled ? sqrt(esq[k] / (double)n_settled) : NAN;
    printf("manipulator_pd: summary states=%lld t_first=%.6f t_last=%.6f settle=%g "
           "max_abs_e1=%.6g max_abs_e2=%.6g rms_e1=%.6g rms_e2=%.6g max_abs_e1_all=%.6g "
           "max_abs_e2_all=%.6g\n",
           (long long)states, t_first, t_last, settle, emax[0], emax[1], rms[0], rms[1],
           emax_all[0], emax_all[1]);
    lag_client_destroy(c);
    return exit_code;
}
