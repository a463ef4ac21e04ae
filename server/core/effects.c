/*
 * Effects a scene calls for (lag_effects_def): only what `enabled` names is ever called.
 *
 * Smooth forces (damping, sliding friction, disturbance forces) enter the right-hand side
 * through lag_applied_forces. Per-tick work (actuator lag and saturation, scheduled
 * disturbances) happens once before each tick. Non-smooth effects (stops, the stick's
 * floor, friction stick/slip, lift-off) are hybrid: each tick is integrated, event
 * functions are sampled along the cubic Hermite interpolant of the step (same order as
 * rk4; see shared/BRIEF.md), the earliest zero is found by the Illinois method, the step
 * is redone up to that instant, the event map is applied (an impulse or a mode change),
 * and the rest of the tick is integrated from there. Sim time stays tick * dt.
 *
 * Event maps (frictionless impact at a stop of joint i, J = e_i^T):
 *   P = -(1 + e) (J qd-) / (J M^-1 J^T),  qd+ = qd- + M^-1 J^T P
 * so J qd+ = -e J qd- and the kinetic energy never increases for e in [0, 1]. An impact
 * slower than rest_velocity ends in resting contact (e = 0, joint locked): the Zeno guard.
 * A locked joint (resting at a stop, or held by static friction) has qd_i = qdd_i = 0 and
 * the constraint force lambda_i it needs is watched: a stop releases when lambda_i would
 * have to pull, static friction lets go when |lambda_i| > mu_s.
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

#define MAX_EVENTS_PER_TICK 16
#define NSEG 4 /* samples of the interpolant per step for sign changes */

lag_effects_def lag_default_effects_def(void)
{
    lag_effects_def e;
    memset(&e, 0, sizeof e);
    e.rest_velocity = 1e-3;
    for (int i = 0; i < LAG_MAX_DOF; i++) e.actuator_max[i] = INFINITY;
    e.noise_seed = 1;
    return e;
}

const char *lag_event_kind_name(lag_event_kind k)
{
    switch (k) {
    case LAG_EV_LIMIT: return "limit";
    case LAG_EV_IMPACT: return "impact";
    case LAG_EV_REST: return "rest";
    case LAG_EV_RELEASE: return "release";
    case LAG_EV_STICK: return "stick";
    case LAG_EV_SLIP: return "slip";
    case LAG_EV_LIFTOFF: return "liftoff";
    case LAG_EV_SATURATION: return "saturation";
    case LAG_EV_DISTURBANCE: return "disturbance";
    case LAG_EV_EVENT_LIMIT: return "event_limit";
    }
    return "unknown";
}

void lag_sim_record_event(lag_sim *s, lag_event_kind kind, int joint, double t, double value)
{
    int cap = (int)(sizeof s->events / sizeof s->events[0]);
    if (s->n_events >= cap) {
        s->events_dropped++;
        return;
    }
    lag_event *ev = &s->events[s->n_events++];
    ev->kind = kind;
    ev->joint = joint;
    ev->t = t;
    ev->value = isfinite(value) ? value : 0.0;
}

bool lag_sim_poll_event(lag_sim *s, lag_event *ev)
{
    if (s->n_events == 0) return false;
    *ev = s->events[0];
    memmove(&s->events[0], &s->events[1], sizeof(lag_event) * (size_t)(s->n_events - 1));
    s->n_events--;
    return true;
}

/* ------------------------------------------------------------------ validation */
#include <stdio.h>

/* field = "effects.<effect>.<joint>[.<key>]" */
static const char *jfield(char *buf, const char *effect, const char *joint, const char *key)
{
    snprintf(buf, LAG_FIELD_MAX, "effects.%s.%s%s%s", effect, joint, key ? "." : "", key ? key : "");
    return buf;
}

lag_result lag_effects_check(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    const int n = def->model.nq;
    const uint32_t known = LAG_EFF_DAMPING | LAG_EFF_FRICTION | LAG_EFF_LIMITS | LAG_EFF_FLOOR |
                           LAG_EFF_ACTUATOR | LAG_EFF_DISTURBANCE | LAG_EFF_NOISE;
    const lag_model_info *info = lag_model_info_get(def->model.kind);
    char f[LAG_FIELD_MAX];
    if (e->enabled & ~known)
        return lag_diag_fail(d, "effects", "unknown effect bits 0x%x", (unsigned)(e->enabled & ~known));
    if (!(isfinite(e->rest_velocity) && e->rest_velocity >= 0))
        return lag_diag_fail(d, (e->enabled & LAG_EFF_LIMITS) || !(e->enabled & LAG_EFF_FLOOR)
                                    ? "effects.limits.rest_velocity" : "effects.floor.rest_velocity",
                             "expected a finite number >= 0, got %g", e->rest_velocity);
    for (int i = 0; i < n; i++) {
        const char *j = info->joint_names[i];
        if ((e->enabled & LAG_EFF_DAMPING) && !(isfinite(e->damping[i]) && e->damping[i] >= 0))
            return lag_diag_fail(d, jfield(f, "damping", j, NULL),
                                 "expected a finite number >= 0, got %g", e->damping[i]);
        if (e->enabled & LAG_EFF_FRICTION) {
            double ms = e->friction_static[i], mk = e->friction_kinetic[i];
            if (!(isfinite(mk) && mk >= 0))
                return lag_diag_fail(d, jfield(f, "friction", j, "kinetic"),
                                     "expected a finite number >= 0, got %g", mk);
            if (!(isfinite(ms) && ms >= mk))
                return lag_diag_fail(d, jfield(f, "friction", j, "static"),
                                     "expected a finite number >= the kinetic value %g, got %g", mk, ms);
        }
        if ((e->enabled & LAG_EFF_LIMITS) && e->limit_on[i]) {
            double lo = e->limit_lower[i], hi = e->limit_upper[i];
            if (!isfinite(lo))
                return lag_diag_fail(d, jfield(f, "limits", j, "lower"), "expected a finite number, got %g", lo);
            if (!(isfinite(hi) && lo < hi))
                return lag_diag_fail(d, jfield(f, "limits", j, "upper"),
                                     "expected a finite number > lower = %g, got %g", lo, hi);
            if (!(e->restitution[i] >= 0 && e->restitution[i] <= 1))
                return lag_diag_fail(d, jfield(f, "limits", j, "restitution"),
                                     "expected a number in [0, 1], got %g", e->restitution[i]);
            if (def->q0[i] < lo || def->q0[i] > hi) {
                snprintf(f, sizeof f, "initial.q[%d]", i);
                return lag_diag_fail(d, f, "initial %s = %g is outside its limits [%g, %g]", j,
                                     def->q0[i], lo, hi);
            }
        }
        if (e->enabled & LAG_EFF_ACTUATOR) {
            if (!(e->actuator_max[i] > 0))
                return lag_diag_fail(d, jfield(f, "actuator", j, "max"),
                                     "expected a number > 0, got %g", e->actuator_max[i]);
            if (!(isfinite(e->actuator_tau[i]) && e->actuator_tau[i] >= 0))
                return lag_diag_fail(d, jfield(f, "actuator", j, "lag"),
                                     "expected a finite number >= 0 (s), got %g", e->actuator_tau[i]);
        }
        if (e->enabled & LAG_EFF_NOISE) {
            if (!(isfinite(e->noise_q[i]) && e->noise_q[i] >= 0))
                return lag_diag_fail(d, jfield(f, "noise.q", j, NULL),
                                     "expected a finite number >= 0, got %g", e->noise_q[i]);
            if (!(isfinite(e->noise_qd[i]) && e->noise_qd[i] >= 0))
                return lag_diag_fail(d, jfield(f, "noise.qd", j, NULL),
                                     "expected a finite number >= 0, got %g", e->noise_qd[i]);
        }
    }
    if (e->enabled & LAG_EFF_FLOOR) {
        if (def->model.kind != LAG_MODEL_STICK)
            return lag_diag_fail(d, "effects.floor", "the floor effect is for the stick model only");
        if (!(e->floor_restitution >= 0 && e->floor_restitution <= 1))
            return lag_diag_fail(d, "effects.floor.restitution", "expected a number in [0, 1], got %g",
                                 e->floor_restitution);
        if (def->q0[1] < 0 || def->q0[1] > M_PI)
            return lag_diag_fail(d, "initial.q[1]", "initial phi = %g must be in [0, pi] with a floor",
                                 def->q0[1]);
    }
    if (e->enabled & LAG_EFF_DISTURBANCE) {
        if (e->n_disturbances < 0 || e->n_disturbances > LAG_MAX_DISTURBANCES)
            return lag_diag_fail(d, "effects.disturbance", "expected at most %d disturbances, got %d",
                                 LAG_MAX_DISTURBANCES, e->n_disturbances);
        for (int k = 0; k < e->n_disturbances; k++) {
            const lag_disturbance *dk = &e->disturbances[k];
            if (!(isfinite(dk->t) && dk->t >= 0)) {
                snprintf(f, sizeof f, "effects.disturbance[%d].t", k);
                return lag_diag_fail(d, f, "expected a finite time >= 0 (s), got %g", dk->t);
            }
            if (dk->joint < 0 || dk->joint >= n) {
                snprintf(f, sizeof f, "effects.disturbance[%d].joint", k);
                return lag_diag_fail(d, f, "no joint %d in model %s", dk->joint, info->name);
            }
            if (!isfinite(dk->value)) {
                snprintf(f, sizeof f, "effects.disturbance[%d].%s", k, dk->impulse ? "impulse" : "force");
                return lag_diag_fail(d, f, "expected a finite number, got %g", dk->value);
            }
            if (!dk->impulse && !(isfinite(dk->duration) && dk->duration > 0)) {
                snprintf(f, sizeof f, "effects.disturbance[%d].duration", k);
                return lag_diag_fail(d, f, "expected a finite number > 0 (s), got %g", dk->duration);
            }
        }
    }
    return LAG_OK;
}

/* ------------------------------------------------------------------ impulses, modes */

/* x = M^-1 e_i on the free joints (locked ones get no velocity). OUT: x */
static lag_result minv_column(const lag_sim *s, const double *q, int i, double *x)
{
    double p[LAG_MAX_DOF] = {0};
    p[i] = 1.0;
    return lag_qd_from_p(s, q, p, x);
}

/* Impulse at joint i that leaves J qd+ = -e J qd-. */
static lag_result joint_impulse(lag_sim *s, double *y, int i, double e)
{
    const int n = s->nq;
    double x[LAG_MAX_DOF];
    lag_result r = minv_column(s, y, i, x);
    if (r != LAG_OK) return r;
    if (!(x[i] > 0)) return LAG_ERR_SINGULAR;
    double P = -(1.0 + e) * y[n + i] / x[i];
    for (int k = 0; k < n; k++) y[n + k] += x[k] * P;
    y[n + i] = -e * (y[n + i] - x[i] * P) ; /* exact: avoid rounding leaving a residue */
    return LAG_OK;
}

static int sgn(double v) { return (v > 0) - (v < 0); }

/* Constraint forces with the current locks at state y. OUT: lambda */
static lag_result lock_forces(lag_sim *s, const double *y, double *lambda)
{
    const int n = s->nq;
    double Q[LAG_MAX_DOF], qdd[LAG_MAX_DOF];
    lag_applied_forces(s, y, y + n, Q);
    return lag_forward_locked(s, y, y + n, Q, qdd, lambda);
}

static bool has_friction(const lag_sim *s, int i)
{
    const lag_effects_def *e = &s->def.effects;
    return (e->enabled & LAG_EFF_FRICTION) &&
           (e->friction_static[i] > 0 || e->friction_kinetic[i] > 0);
}

/* Joint i is at rest (qd_i = 0): held by static friction if it can be, else slides in
 * the direction of the net force. Returns the event kind it produced. */
static lag_event_kind friction_settle(lag_sim *s, double *y, int i)
{
    const int n = s->nq;
    y[n + i] = 0.0;
    s->mode.slip_dir[i] = 0;
    s->mode.locked |= 1u << i;
    s->mode.lock_side[i] = 0;
    double lambda[LAG_MAX_DOF];
    if (lock_forces(s, y, lambda) == LAG_OK &&
        fabs(lambda[i]) <= s->def.effects.friction_static[i])
        return LAG_EV_STICK;
    s->mode.locked &= ~(1u << i);
    s->mode.slip_dir[i] = (int8_t)(-sgn(lambda[i]));
    return LAG_EV_SLIP;
}

/* After an impulse: sliding friction must oppose each joint's new velocity. */
static void refresh_slip(lag_sim *s, double *y)
{
    const int n = s->nq;
    for (int i = 0; i < n; i++) {
        if (!has_friction(s, i) || (s->mode.locked & (1u << i))) continue;
        double v = y[n + i];
        if (v != 0.0) s->mode.slip_dir[i] = (int8_t)sgn(v);
        else friction_settle(s, y, i);
    }
}

void lag_effects_init_modes(lag_sim *s)
{
    const int n = s->nq;
    double y[LAG_MAX_STATE];
    for (int i = 0; i < n; i++) { y[i] = s->q[i]; y[n + i] = s->qd[i]; }
    s->mode.locked = 0;
    for (int i = 0; i < n; i++) { s->mode.lock_side[i] = 0; s->mode.slip_dir[i] = 0; }
    refresh_slip(s, y);
    for (int i = 0; i < n; i++) s->qd[i] = y[n + i];
}

/* ------------------------------------------------------------------ per tick */
void lag_effects_pre_tick(lag_sim *s)
{
    const lag_effects_def *e = &s->def.effects;
    const int n = s->nq;
    const double dt = s->def.integrator.dt;
    const double t0 = lag_sim_time(s);
    if (e->enabled & LAG_EFF_ACTUATOR) {
        /* first-order lag advanced exactly over one tick, then saturation */
        for (int i = 0; i < n; i++) {
            double cmd = s->tau[i], v = cmd;
            if (e->actuator_tau[i] > 0) {
                double a = exp(-dt / e->actuator_tau[i]);
                s->mode.act_state[i] = cmd + (s->mode.act_state[i] - cmd) * a;
                v = s->mode.act_state[i];
            }
            bool sat = fabs(v) > e->actuator_max[i];
            if (sat) v = copysign(e->actuator_max[i], v);
            if (sat && !s->mode.saturated[i])
                lag_sim_record_event(s, LAG_EV_SATURATION, i, t0, cmd);
            s->mode.saturated[i] = sat;
            s->tau_applied[i] = v;
        }
    }
    if (e->enabled & LAG_EFF_DISTURBANCE) {
        bool impulse = false;
        double y[LAG_MAX_STATE];
        for (int i = 0; i < n; i++) { s->mode.dist_force[i] = 0.0; y[i] = s->q[i]; y[n + i] = s->qd[i]; }
        for (int k = 0; k < e->n_disturbances; k++) {
            const lag_disturbance *d = &e->disturbances[k];
            /* the first tick boundary at or after d->t (saturated: a time past the last
             * tick is never reached) */
            int64_t kd = lag_ticks_ceil(d->t, dt);
            if (d->impulse) {
                if (s->tick != kd) continue;
                double x[LAG_MAX_DOF];
                s->mode.locked = 0; /* an impulse breaks any hold; modes are re-settled */
                if (minv_column(s, y, d->joint, x) != LAG_OK) continue;
                for (int i = 0; i < n; i++) y[n + i] += x[i] * d->value;
                impulse = true;
                lag_sim_record_event(s, LAG_EV_DISTURBANCE, d->joint, t0, d->value);
            } else {
                double tend = d->t + d->duration;
                if (s->tick >= kd && t0 < tend - 1e-9 * dt) {
                    s->mode.dist_force[d->joint] += d->value;
                    if (s->tick == kd)
                        lag_sim_record_event(s, LAG_EV_DISTURBANCE, d->joint, t0, d->value);
                }
            }
        }
        if (impulse) {
            for (int i = 0; i < n; i++) { s->mode.lock_side[i] = 0; s->mode.slip_dir[i] = 0; }
            refresh_slip(s, y);
            for (int i = 0; i < n; i++) s->qd[i] = y[n + i];
        }
    }
}

/* ------------------------------------------------------------------ event location */
typedef enum { W_LIMIT, W_SLIPZERO, W_RELEASE, W_LIFTOFF } wkind;
typedef struct watcher {
    wkind kind;
    int joint;
    int side;      /* limits: -1 lower, +1 upper */
    double bound;  /* limits: the stop position */
    double e;      /* limits: restitution */
    bool floor;    /* the stick's floor (reported as impact) */
} watcher;

static int build_watchers(const lag_sim *s, watcher *w)
{
    const lag_effects_def *e = &s->def.effects;
    const int n = s->nq;
    int nw = 0;
    for (int i = 0; i < n; i++) {
        bool locked = s->mode.locked & (1u << i);
        if (locked) {
            w[nw++] = (watcher){W_RELEASE, i, 0, 0, 0, false};
            continue;
        }
        if ((e->enabled & LAG_EFF_LIMITS) && e->limit_on[i]) {
            w[nw++] = (watcher){W_LIMIT, i, -1, e->limit_lower[i], e->restitution[i], false};
            w[nw++] = (watcher){W_LIMIT, i, +1, e->limit_upper[i], e->restitution[i], false};
        }
        if ((e->enabled & LAG_EFF_FLOOR) && i == 1) {
            w[nw++] = (watcher){W_LIMIT, 1, -1, 0.0, e->floor_restitution, true};
            w[nw++] = (watcher){W_LIMIT, 1, +1, M_PI, e->floor_restitution, true};
        }
        if (has_friction(s, i) && s->mode.slip_dir[i] != 0)
            w[nw++] = (watcher){W_SLIPZERO, i, 0, 0, 0, false};
    }
    if (e->enabled & LAG_EFF_FLOOR) w[nw++] = (watcher){W_LIFTOFF, 1, 0, 0, 0, false};
    return nw;
}

static bool needs_dynamics(const watcher *w, int nw)
{
    for (int k = 0; k < nw; k++)
        if (w[k].kind == W_RELEASE || w[k].kind == W_LIFTOFF) return true;
    return false;
}

/* Event function values at y (positive = nothing happening). OUT: val, qdd (if dyn) */
static lag_result eval_watchers(lag_sim *s, const watcher *w, int nw, bool dyn, const double *y,
                                double *val, double *qdd)
{
    const int n = s->nq;
    double lambda[LAG_MAX_DOF] = {0};
    if (dyn) {
        double Q[LAG_MAX_DOF];
        lag_applied_forces(s, y, y + n, Q);
        lag_result r = lag_forward_locked(s, y, y + n, Q, qdd, lambda);
        if (r != LAG_OK) return r;
    }
    for (int k = 0; k < nw; k++) {
        int i = w[k].joint;
        switch (w[k].kind) {
        case W_LIMIT:
            val[k] = w[k].side < 0 ? y[i] - w[k].bound : w[k].bound - y[i];
            break;
        case W_SLIPZERO:
            val[k] = s->mode.slip_dir[i] * y[n + i];
            break;
        case W_RELEASE:
            val[k] = s->mode.lock_side[i] == 0
                         ? s->def.effects.friction_static[i] - fabs(lambda[i])
                         : -s->mode.lock_side[i] * lambda[i];
            break;
        case W_LIFTOFF: {
            /* N = m (g + d2/dt2 ((l/2) sin phi)), divided by m */
            const double *p = s->def.model.p;
            double ph = y[1], phd = y[n + 1];
            val[k] = p[LAG_STICK_G] + 0.5 * p[LAG_STICK_L] * (cos(ph) * qdd[1] - sin(ph) * phd * phd);
            break;
        }
        }
    }
    return LAG_OK;
}

/* Has watcher k fired between values a (earlier) and b (later)? */
static bool fired(wkind kind, double a, double b)
{
    if (kind == W_LIMIT || kind == W_SLIPZERO) return a > 0 && b <= 0;
    return a >= 0 && b < 0;
}

/* Cubic Hermite interpolant on [y0, y1] with slopes f0, f1 over h at theta. OUT: y */
static void hermite(int N, double h, const double *y0, const double *f0, const double *y1,
                    const double *f1, double th, double *y)
{
    double t2 = th * th, t3 = t2 * th;
    double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + th, h01 = -2 * t3 + 3 * t2,
           h11 = t3 - t2;
    for (int i = 0; i < N; i++) y[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
}

/* The event map for watcher w at state y (in place). Returns a fault for lift-off. */
static lag_result handle(lag_sim *s, const watcher *w, double *y, double t)
{
    const int n = s->nq, i = w->joint;
    lag_result r = LAG_OK;
    switch (w->kind) {
    case W_LIMIT: {
        double v = y[n + i];
        /* Zeno guard: rest if slower than rest_velocity, or if the bounce would come back
         * within one tick (e |v| < a dt, a the acceleration into the stop). */
        double Q[LAG_MAX_DOF], qdd[LAG_MAX_DOF];
        lag_applied_forces(s, y, y + n, Q);
        if ((r = lag_forward_locked(s, y, y + n, Q, qdd, NULL)) != LAG_OK) return r;
        double a_in = qdd[i] * w->side;
        bool rest = fabs(v) < s->def.effects.rest_velocity ||
                    (a_in > 0 && w->e * fabs(v) < a_in * s->def.integrator.dt);
        if (rest) {
            if ((r = joint_impulse(s, y, i, 0.0)) != LAG_OK) return r;
            y[n + i] = 0.0;
            s->mode.locked |= 1u << i;
            s->mode.lock_side[i] = (int8_t)w->side;
            s->mode.slip_dir[i] = 0;
            lag_sim_record_event(s, LAG_EV_REST, i, t, v);
        } else {
            if ((r = joint_impulse(s, y, i, w->e)) != LAG_OK) return r;
            lag_sim_record_event(s, w->floor ? LAG_EV_IMPACT : LAG_EV_LIMIT, i, t, v);
        }
        refresh_slip(s, y);
        break;
    }
    case W_SLIPZERO: {
        if ((r = joint_impulse(s, y, i, 0.0)) != LAG_OK) return r;
        lag_event_kind k = friction_settle(s, y, i);
        lag_sim_record_event(s, k, i, t, s->mode.slip_dir[i]);
        refresh_slip(s, y);
        break;
    }
    case W_RELEASE: {
        double lambda[LAG_MAX_DOF];
        if ((r = lock_forces(s, y, lambda)) != LAG_OK) return r;
        bool stop = s->mode.lock_side[i] != 0;
        s->mode.locked &= ~(1u << i);
        s->mode.lock_side[i] = 0;
        y[n + i] = 0.0;
        if (stop) {
            lag_sim_record_event(s, LAG_EV_RELEASE, i, t, lambda[i]);
            if (has_friction(s, i)) {
                lag_event_kind k = friction_settle(s, y, i);
                if (k == LAG_EV_STICK) lag_sim_record_event(s, k, i, t, 0.0);
            }
        } else {
            s->mode.slip_dir[i] = (int8_t)(-sgn(lambda[i]));
            lag_sim_record_event(s, LAG_EV_SLIP, i, t, s->mode.slip_dir[i]);
        }
        break;
    }
    case W_LIFTOFF:
        lag_sim_record_event(s, LAG_EV_LIFTOFF, 1, t, 0.0);
        return LAG_ERR_LIFTOFF;
    }
    return LAG_OK;
}

/* At the start of an interval: an event already due (at or past a stop and moving into
 * it, a hold that no longer holds, lift-off). Returns its index, -1 if none, or -2 with
 * *err set if the dynamics needed to judge a joint at rest on a stop failed. qdd is the
 * acceleration at y if `have_qdd`; otherwise it is computed here, and only for that case
 * (a joint exactly at rest at or past a stop), so that ticks away from the stops do not
 * pay for it. */
static int due_now(lag_sim *s, const watcher *w, int nw, const double *y, const double *val,
                   double *qdd, bool have_qdd, lag_result *err)
{
    const int n = s->nq;
    for (int k = 0; k < nw; k++) {
        int i = w[k].joint;
        if (w[k].kind == W_LIMIT && val[k] <= 0) {
            /* moving into the stop (qd toward it, or at rest and accelerating toward it) */
            double v = y[n + i] * w[k].side; /* > 0: moving into the stop */
            if (v > 0) return k;
            if (v == 0) {
                if (!have_qdd) {
                    double Q[LAG_MAX_DOF];
                    lag_applied_forces(s, y, y + n, Q);
                    if ((*err = lag_forward_locked(s, y, y + n, Q, qdd, NULL)) != LAG_OK)
                        return -2;
                    have_qdd = true;
                }
                if (qdd[i] * w[k].side > 0) return k;
            }
        } else if ((w[k].kind == W_RELEASE || w[k].kind == W_LIFTOFF) && val[k] < 0) {
            return k;
        }
    }
    return -1;
}

lag_result lag_effects_tick(lag_sim *s, double *y)
{
    const int n = s->nq, N = 2 * n;
    const double dt = s->def.integrator.dt;
    const double t_tick = lag_sim_time(s);
    double tloc = 0.0;
    int events = 0;
    lag_result r;

    while (tloc < dt) {
        watcher w[4 * LAG_MAX_DOF + 2];
        int nw = build_watchers(s, w);
        const double H = dt - tloc;
        double y1[LAG_MAX_STATE];
        if (nw == 0 || events >= MAX_EVENTS_PER_TICK) {
            if (events >= MAX_EVENTS_PER_TICK)
                lag_sim_record_event(s, LAG_EV_EVENT_LIMIT, -1, t_tick + tloc, events);
            if ((r = lag_step(s, H, y, y1)) != LAG_OK) return r;
            if (!lag_state_ok(N, y1, INFINITY)) return LAG_ERR_NONFINITE;
            if (!lag_state_ok(N, y1, s->def.explode_limit)) return LAG_ERR_EXPLODE;
            memcpy(y, y1, sizeof(double) * N);
            break;
        }
        bool dyn = needs_dynamics(w, nw);
        double v0[4 * LAG_MAX_DOF + 2], qdd0[LAG_MAX_DOF] = {0};
        if ((r = eval_watchers(s, w, nw, dyn, y, v0, qdd0)) != LAG_OK) return r;
        int k0 = due_now(s, w, nw, y, v0, qdd0, dyn, &r);
        if (k0 == -2) return r;
        if (k0 >= 0) {
            if ((r = handle(s, &w[k0], y, t_tick + tloc)) != LAG_OK) return r;
            events++;
            continue;
        }

        if ((r = lag_step(s, H, y, y1)) != LAG_OK) return r;
        if (!lag_state_ok(N, y1, INFINITY)) return LAG_ERR_NONFINITE;
        if (!lag_state_ok(N, y1, s->def.explode_limit)) return LAG_ERR_EXPLODE;
        double f0[LAG_MAX_STATE], f1[LAG_MAX_STATE];
        if ((r = lag_sim_rhs(s, y, f0)) != LAG_OK) return r;
        if ((r = lag_sim_rhs(s, y1, f1)) != LAG_OK) return r;

        /* first segment of the interpolant in which some watcher fires */
        double vprev[4 * LAG_MAX_DOF + 2], vcur[4 * LAG_MAX_DOF + 2], qdd[LAG_MAX_DOF];
        memcpy(vprev, v0, sizeof(double) * nw);
        int seg = -1;
        for (int k = 1; k <= NSEG && seg < 0; k++) {
            double yt[LAG_MAX_STATE];
            if (k == NSEG) memcpy(yt, y1, sizeof(double) * N);
            else hermite(N, H, y, f0, y1, f1, (double)k / NSEG, yt);
            if ((r = eval_watchers(s, w, nw, dyn, yt, vcur, qdd)) != LAG_OK) return r;
            for (int j = 0; j < nw; j++)
                if (fired(w[j].kind, vprev[j], vcur[j])) seg = k;
            if (seg < 0) memcpy(vprev, vcur, sizeof(double) * nw);
        }
        if (seg < 0) {
            memcpy(y, y1, sizeof(double) * N);
            break;
        }

        /* earliest zero among the watchers that fired in the segment (Illinois) */
        double th_best = 2.0;
        int k_best = -1;
        for (int j = 0; j < nw; j++) {
            if (!fired(w[j].kind, vprev[j], vcur[j])) continue;
            double a = (double)(seg - 1) / NSEG, b = (double)seg / NSEG;
            double fa = vprev[j], fb = vcur[j];
            int last = 0;
            for (int it = 0; it < 80 && (b - a) * H > 1e-15; it++) {
                double c = (fa != fb) ? (a * fb - b * fa) / (fb - fa) : 0.5 * (a + b);
                if (!(c > a && c < b)) c = 0.5 * (a + b);
                double yt[LAG_MAX_STATE], vals[4 * LAG_MAX_DOF + 2];
                hermite(N, H, y, f0, y1, f1, c, yt);
                if ((r = eval_watchers(s, w, nw, dyn, yt, vals, qdd)) != LAG_OK) return r;
                double fc = vals[j];
                if (fired(w[j].kind, fa, fc)) {
                    b = c; fb = fc;
                    if (last == -1) fa *= 0.5;
                    last = -1;
                } else {
                    a = c; fa = fc;
                    if (last == 1) fb *= 0.5;
                    last = 1;
                }
            }
            if (b < th_best) { th_best = b; k_best = j; }
        }

        /* redo the step up to the event, apply its map, go on with the rest of the tick */
        double hs = th_best * H;
        if (th_best >= 1.0) hs = H;
        double ys[LAG_MAX_STATE];
        if (hs > 0) {
            if ((r = lag_step(s, hs, y, ys)) != LAG_OK) return r;
            if (!lag_state_ok(N, ys, s->def.explode_limit))
                return lag_state_ok(N, ys, INFINITY) ? LAG_ERR_EXPLODE : LAG_ERR_NONFINITE;
        } else {
            memcpy(ys, y, sizeof(double) * N);
        }
        tloc = (th_best >= 1.0) ? dt : tloc + hs;
        if ((r = handle(s, &w[k_best], ys, t_tick + tloc)) != LAG_OK) return r;
        memcpy(y, ys, sizeof(double) * N);
        events++;
    }
    return LAG_OK;
}

/* ------------------------------------------------------------------ noise */
static uint64_t splitmix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* Standard normal from (seed, tick, index), Box-Muller on two counter-based uniforms. */
static double gauss_at(uint64_t seed, int64_t tick, int idx)
{
    uint64_t a = splitmix64(seed ^ splitmix64((uint64_t)tick * 64u + (uint64_t)idx * 2u));
    uint64_t b = splitmix64(a ^ 0xD1B54A32D192ED03ull);
    double u1 = ((double)(a >> 11) + 0.5) * 0x1.0p-53, u2 = (double)(b >> 11) * 0x1.0p-53;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

void lag_sim_observe(const lag_sim *s, double *q, double *qd)
{
    const int n = s->nq;
    const lag_effects_def *e = &s->def.effects;
    for (int i = 0; i < n; i++) { q[i] = s->q[i]; qd[i] = s->qd[i]; }
    if (!(e->enabled & LAG_EFF_NOISE)) return;
    for (int i = 0; i < n; i++) {
        if (e->noise_q[i] > 0) q[i] += e->noise_q[i] * gauss_at(e->noise_seed, s->tick, i);
        if (e->noise_qd[i] > 0) qd[i] += e->noise_qd[i] * gauss_at(e->noise_seed, s->tick, LAG_MAX_DOF + i);
    }
}
