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
#include <stdio.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_controller.h"

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

int main(int argc, char **argv)
{
    double wn = 10.0, settle = 2.0;
    const lag_ctl_option mine[] = {
        {"wn", "W", "PD bandwidth, rad/s: Kp = W^2, Kd = 2 W (default 10)", lag_ctl_positive, &wn},
        {"settle", "S", "error statistics skip the first S s (default 2)", lag_ctl_nonnegative,
         &settle},
    };
    lag_ctl ctl;
    lag_ctl_init(&ctl, "manipulator_pd", "MANIPULATOR");
    int rc = lag_ctl_parse(&ctl, argc, argv,
                           "Tracks q1 = 0.3 sin(0.5 t), q2 = 0.5 + 0.1 sin(t) on a running "
                           "lagsimd manipulator\nwith PD + computed-torque feedforward from "
                           "its scene description.",
                           mine, (int)(sizeof mine / sizeof mine[0]));
    if (rc >= 0) return rc;
    const double kp = wn * wn, kd = 2.0 * wn;
    const traj tr = {0.3, 0.5, 0.5, 0.1, 1.0};

    if (lag_ctl_start(&ctl, "manipulator")) return lag_ctl_fail(&ctl);
    const lag_model model = ctl.model;
    const char *jn[2] = {"q1", "q2"};
    for (int k = 0; k < 2; k++) {
        int j = lag_client_scene_joint(&ctl.scene, jn[k]);
        if (j < 0 || !ctl.scene.actuated[j]) {
            fprintf(stderr, "manipulator_pd: joint %s is not actuated in this scene\n", jn[k]);
            return lag_ctl_fail(&ctl);
        }
    }
    printf("manipulator_pd: scene on %s_*: mode %s, control period %g s; Kp %g, Kd %g\n",
           ctl.prefix, ctl.scene.mode, ctl.scene.control_period, kp, kd);
    fflush(stdout);

    lag_client_state st;
    int64_t states = 0, n_settled = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY;
    double emax[2] = {0, 0}, esq[2] = {0, 0}, emax_all[2] = {0, 0};
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
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
        for (int k = 0; k < 2; k++) tau[k] = M[2 * k] * v[0] + M[2 * k + 1] * v[1] + hb[k];
        lag_ctl_command(&ctl, &st, 2, jn, tau); /* a non-finite tau is sent as 0 */

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
        if (!ctl.quiet && st.sim_time - t_report >= 1.0) {
            t_report = st.sim_time;
            printf("t=%8.3f  q1=%+.5f (e %+.2e)  q2=%+.5f (e %+.2e)  tau=%+.3f %+.3f\n",
                   st.sim_time, q[0], e[0], q[1], e[1], tau[0], tau[1]);
            fflush(stdout);
        }
    }
    double rms[2] = {0, 0};
    for (int k = 0; k < 2; k++) rms[k] = n_settled ? sqrt(esq[k] / (double)n_settled) : NAN;
    return lag_ctl_finish(&ctl,
                          "states=%lld t_first=%.6f t_last=%.6f settle=%g max_abs_e1=%.6g "
                          "max_abs_e2=%.6g rms_e1=%.6g rms_e2=%.6g max_abs_e1_all=%.6g "
                          "max_abs_e2_all=%.6g",
                          (long long)states, t_first, t_last, settle, emax[0], emax[1], rms[0],
                          rms[1], emax_all[0], emax_all[1]);
}
