/*
 * manipulator_pd: makes the rotary/prismatic manipulator track the scene's reference
 * (its `reference:` key, which lagsimd publishes on <PREFIX>_REFERENCE just before each
 * state: q_d = r, qd_d = r' at the state's sim time; config/manipulator.yaml gives
 * q1 = 0.3 sin(0.5 t), q2 = 0.5 + 0.1 sin(t)) with PD plus model feedforward (computed
 * torque) built from the scene's parameters by the core:
 *   tau = M(q) (qdd_d + Kp (q_d - q) + Kd (qd_d - qd)) + C(q, qd) qd + g(q).
 * qdd_d is the backward difference of r' over the last control period (0 at the first
 * state and after a gap): an error of about h/2 |d3r/dt3| in the acceleration. A joint
 * the scene gives no reference holds its position at the first state (qd_d = 0). A state
 * whose reference was lost (another sim_time) keeps the last one, and is counted.
 * With the exact model the error obeys e'' + Kd e' + Kp e = 0 (Kp = wn^2, Kd = 2 wn,
 * critically damped), up to the zero-order hold of the effort over a control period.
 * Answers every state (lockstep-safe) and prints the tracking error.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_controller.h"

/* What the joints should do at a state: from the scene's reference. */
typedef struct desired {
    bool have[2];           /* the joint has a reference (else: hold) */
    double hold[2];         /* a joint without one: its position at the first state */
    double q[2], qd[2], qdd[2];
    double prev_t, prev_qd[2];
    bool have_prev;
    int64_t stale;          /* states whose reference did not arrive (the last one kept) */
} desired;

/* Desired position, velocity, acceleration at state st (q1 at i[0], q2 at i[1]), from
 * the latest reference. */
static void desired_at(desired *d, lag_ctl *ctl, const lag_client_state *st, const int i[2],
                       double period, const char *const jn[2], bool first)
{
    lag_client_reference ref;
    bool have = lag_client_latest_reference(ctl->client, &ref);
    if (have && ref.sim_time != st->sim_time) d->stale++;
    for (int k = 0; k < 2; k++) {
        int j = have ? lag_client_reference_joint(&ref, jn[k]) : -1;
        d->have[k] = j >= 0;
        if (first) d->hold[k] = st->position[i[k]];
        d->q[k] = j >= 0 ? ref.r[j] : d->hold[k];
        d->qd[k] = j >= 0 ? ref.rdot[j] : 0.0;
    }
    /* the acceleration: r' one control period ago and now */
    bool next = d->have_prev && fabs(st->sim_time - d->prev_t - period) <= 1e-9 * period;
    for (int k = 0; k < 2; k++) {
        d->qdd[k] = next ? (d->qd[k] - d->prev_qd[k]) / period : 0.0;
        d->prev_qd[k] = d->qd[k];
    }
    d->prev_t = st->sim_time;
    d->have_prev = true;
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
                           "Tracks the scene's reference (<PREFIX>_REFERENCE) on a running "
                           "lagsimd manipulator\nwith PD + computed-torque feedforward from "
                           "its scene description; a joint\nwithout a reference holds its "
                           "first position.",
                           mine, (int)(sizeof mine / sizeof mine[0]));
    if (rc >= 0) return rc;
    const double kp = wn * wn, kd = 2.0 * wn;

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
    desired des;
    memset(&des, 0, sizeof des);
    int64_t states = 0, n_settled = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY;
    double emax[2] = {0, 0}, esq[2] = {0, 0}, emax_all[2] = {0, 0};
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        int i1 = lag_client_state_joint(&st, "q1"), i2 = lag_client_state_joint(&st, "q2");
        if (i1 < 0 || i2 < 0) continue;
        double q[2] = {st.position[i1], st.position[i2]};
        double qd[2] = {st.velocity[i1], st.velocity[i2]};
        double q_d[2], qd_d[2], qdd_d[2], M[4], hb[2], v[2], tau[2];
        const int idx[2] = {i1, i2};
        desired_at(&des, &ctl, &st, idx, ctl.scene.control_period, jn, states == 0);
        if (states == 0) {
            printf("manipulator_pd: tracking %s %s, %s %s\n", jn[0],
                   des.have[0] ? "its reference" : "its first position", jn[1],
                   des.have[1] ? "its reference" : "its first position");
            fflush(stdout);
        }
        for (int k = 0; k < 2; k++) {
            q_d[k] = des.q[k];
            qd_d[k] = des.qd[k];
            qdd_d[k] = des.qdd[k];
        }
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
                          "max_abs_e2_all=%.6g references_stale=%lld",
                          (long long)states, t_first, t_last, settle, emax[0], emax[1], rms[0],
                          rms[1], emax_all[0], emax_all[1], (long long)des.stale);
}
