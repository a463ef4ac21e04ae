/*
 * manipulator_pd: makes the rotary/prismatic manipulator track the scene's reference
 * (its `reference:` key, which lagsimd publishes on <PREFIX>_REFERENCE just before each
 * state: q_d = r, qd_d = r', qdd_d = r'' at the state's sim time; config/manipulator.yaml
 * gives q1 = 0.3 sin(0.5 t), q2 = 0.5 + 0.1 sin(t)) with PD plus model feedforward
 * (computed torque) built from the scene's parameters by the core:
 *   tau = M(q) (qdd_d + Kp (q_d - q) + Kd (qd_d - qd)) + C(q, qd) qd + g(q).
 * r'' is the reference's exact second derivative (docs/evaluation.md), so the feedforward
 * needs no difference of r'. A joint the scene gives no reference holds its position at
 * the first state (qd_d = qdd_d = 0). A state whose reference was lost (none of its
 * generation and sim_time) keeps the last one, and is counted. clients/manipulator_ct.cpp
 * is the same law in C++ over the client library alone (M and C qd + g from
 * lag_client_model_mass and lag_client_model_bias), bit for bit the same numbers.
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
    int64_t stale;          /* states whose reference did not arrive (the last one kept) */
} desired;

/* Desired position, velocity, acceleration at state st (q1 at i[0], q2 at i[1]), from
 * the latest reference: r, r', r''. */
static void desired_at(desired *d, lag_ctl *ctl, const lag_client_state *st, const int i[2],
                       const char *const jn[2], bool first)
{
    lag_client_reference ref; /* st's own (its generation and sim_time), else the last kept */
    bool have = lag_client_reference_of(ctl->client, st, &ref, sizeof ref);
    if (!have && (have = lag_client_latest_reference(ctl->client, &ref, sizeof ref))) d->stale++;
    for (int k = 0; k < 2; k++) {
        int j = have ? lag_client_reference_joint(&ref, jn[k]) : -1;
        d->have[k] = j >= 0;
        if (first) d->hold[k] = st->position[i[k]];
        d->q[k] = j >= 0 ? ref.r[j] : d->hold[k];
        d->qd[k] = j >= 0 ? ref.rdot[j] : 0.0;
        d->qdd[k] = j >= 0 ? ref.rddot[j] : 0.0;
    }
}

/* The control law at one state: tau = M(q) (qdd_d + Kp e + Kd e_dot) + C(q, qd) qd + g(q). */
static void computed_torque(const lag_model *model, double kp, double kd, const desired *d,
                            const double q[2], const double qd[2], double tau[2])
{
    double v[2], M[4], hb[2];
    for (int k = 0; k < 2; k++)
        v[k] = d->qdd[k] + kp * (d->q[k] - q[k]) + kd * (d->qd[k] - qd[k]);
    lag_model_mass(model, q, M);
    lag_model_bias(model, q, qd, hb);
    for (int k = 0; k < 2; k++) tau[k] = M[2 * k] * v[0] + M[2 * k + 1] * v[1] + hb[k];
}

/* The tracking error over the run: its peaks, and after --settle its RMS. */
typedef struct tracking {
    int64_t states, n_settled;
    double t_first, t_last, t_report;
    double emax[2], esq[2], emax_all[2];
} tracking;

static void track(tracking *tr, const lag_ctl *ctl, double settle, const lag_client_state *st,
                  const double q[2], const desired *d, const double tau[2])
{
    if (tr->states == 0) tr->t_first = st->sim_time;
    tr->states++;
    tr->t_last = st->sim_time;
    double e[2] = {d->q[0] - q[0], d->q[1] - q[1]};
    for (int k = 0; k < 2; k++) tr->emax_all[k] = fmax(tr->emax_all[k], fabs(e[k]));
    if (st->sim_time - tr->t_first >= settle) {
        tr->n_settled++;
        for (int k = 0; k < 2; k++) {
            tr->emax[k] = fmax(tr->emax[k], fabs(e[k]));
            tr->esq[k] += e[k] * e[k];
        }
    }
    if (!ctl->quiet && st->sim_time - tr->t_report >= 1.0) {
        tr->t_report = st->sim_time;
        printf("t=%8.3f  q1=%+.5f (e %+.2e)  q2=%+.5f (e %+.2e)  tau=%+.3f %+.3f\n",
               st->sim_time, q[0], e[0], q[1], e[1], tau[0], tau[1]);
        fflush(stdout);
    }
}

static int finish(lag_ctl *ctl, const tracking *tr, double settle, const desired *d)
{
    double rms[2] = {0, 0};
    for (int k = 0; k < 2; k++)
        rms[k] = tr->n_settled ? sqrt(tr->esq[k] / (double)tr->n_settled) : NAN;
    return lag_ctl_finish(ctl,
                          "states=%lld t_first=%.6f t_last=%.6f settle=%g max_abs_e1=%.6g "
                          "max_abs_e2=%.6g rms_e1=%.6g rms_e2=%.6g max_abs_e1_all=%.6g "
                          "max_abs_e2_all=%.6g references_stale=%lld",
                          (long long)tr->states, tr->t_first, tr->t_last, settle, tr->emax[0],
                          tr->emax[1], rms[0], rms[1], tr->emax_all[0], tr->emax_all[1],
                          (long long)d->stale);
}

/* Both joints actuated, else a message and -1. */
static int check_joints(const lag_ctl *ctl, const char *const jn[2])
{
    for (int k = 0; k < 2; k++) {
        int j = lag_client_scene_joint(ctl->scene, jn[k]);
        if (!lag_client_scene_actuated(ctl->scene, j)) {
            fprintf(stderr, "manipulator_pd: joint %s is not actuated in this scene\n", jn[k]);
            return -1;
        }
    }
    return 0;
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
    const char *jn[2] = {"q1", "q2"};
    if (check_joints(&ctl, jn)) return lag_ctl_fail(&ctl);
    printf("manipulator_pd: scene on %s_*: mode %s, control period %g s; Kp %g, Kd %g\n",
           ctl.prefix, lag_client_scene_mode(ctl.scene),
           lag_client_scene_control_period(ctl.scene), kp, kd);
    fflush(stdout);

    /* ---- control loop: answer every state until the run ends */
    lag_client_state st;
    desired des = {0};
    tracking tr = {.t_first = NAN, .t_last = NAN, .t_report = -INFINITY};
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        const int idx[2] = {lag_client_state_joint(&st, "q1"), lag_client_state_joint(&st, "q2")};
        if (idx[0] < 0 || idx[1] < 0) continue;
        double q[2] = {st.position[idx[0]], st.position[idx[1]]};
        double qd[2] = {st.velocity[idx[0]], st.velocity[idx[1]]};
        desired_at(&des, &ctl, &st, idx, jn, tr.states == 0);
        if (tr.states == 0) {
            printf("manipulator_pd: tracking %s %s, %s %s\n", jn[0],
                   des.have[0] ? "its reference" : "its first position", jn[1],
                   des.have[1] ? "its reference" : "its first position");
            fflush(stdout);
        }
        double tau[2];
        computed_torque(&ctl.model, kp, kd, &des, q, qd, tau);
        lag_ctl_command(&ctl, &st, 2, jn, tau); /* a non-finite tau is sent as 0 */
        track(&tr, &ctl, settle, &st, q, &des, tau);
    }
    return finish(&ctl, &tr, settle, &des);
}
