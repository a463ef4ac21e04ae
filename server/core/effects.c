/*
 * Effects a scene calls for (lag_effects_def): one table, lag_effect_rows, with one row
 * per effect. A row names its bit and its scene key and gives what the effect does, as
 * hooks; an effect that is off (its bit not in lag_effects_def.enabled) is never called
 * (MuJoCo's enable flags). What an effect takes part in follows from the hooks it has,
 * so it cannot be forgotten:
 *   validate   its settings (lag_effects_check)
 *   force      a generalized force added in the right-hand side (lag_effects_force, the
 *              one place that gathers them, as MuJoCo's mj_passive)
 *   potential  the energy it stores (lag_effects_potential: part of lag_sim_energy, as
 *              MuJoCo's mj_energyPos)
 *   pre_tick   per-tick work before each tick (actuator lag, scheduled disturbances):
 *              makes the effect per-tick (the sim stops at every tick boundary)
 *   watch      watchers located in time by the event engine (events.c), with `on_event`
 *              their maps and `value` the event function of custom ones: makes it a
 *              per-tick event effect
 *   observe    a change of the published state only (noise)
 * The rows' order is the order of their forces, per-tick work and watchers (ties between
 * events at one instant go to the earlier row): forces are added damping, friction,
 * disturbance, spring; per-tick work is the actuator's, then the disturbances'.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "core_internal.h"

lag_effects_def lag_default_effects_def(void)
{
    lag_effects_def e;
    memset(&e, 0, sizeof e);
    e.rest_velocity = 1e-3;
    for (int i = 0; i < LAG_MAX_DOF; i++) e.actuator_max[i] = INFINITY;
    e.noise_seed = 1;
    e.floor_flight = true;
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
    case LAG_EV_LANDING: return "landing";
    }
    return "unknown";
}

/* field = "effects.<effect>.<joint>[.<key>]" */
static const char *jfield(char *buf, const char *effect, const char *joint, const char *key)
{
    snprintf(buf, LAG_FIELD_MAX, "effects.%s.%s%s%s", effect, joint, key ? "." : "", key ? key : "");
    return buf;
}

static const char *jname(const lag_sim_def *def, int i)
{
    return lag_model_info_get(def->model.kind)->joint_names[i];
}

/* ================================================================== damping */
/* Q_i = -b_i qd_i */

static lag_result damping_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    for (int i = 0; i < def->model.nq; i++)
        if (!(isfinite(e->damping[i]) && e->damping[i] >= 0))
            return lag_diag_fail(d, jfield(f, "damping", jname(def, i), NULL),
                                 "expected a finite number >= 0, got %g", e->damping[i]);
    return LAG_OK;
}

static void damping_force(const lag_sim *s, const double *q, const double *qd, double *Q)
{
    (void)q;
    for (int i = 0; i < s->nq; i++) Q[i] -= s->def.effects.damping[i] * qd[i];
}

/* ================================================================== stops: limits, floor */
/* A stop at position `bound` on one side of a joint: a POSITION watcher; its map is an
 * impact with restitution e, or resting contact (a hold) when the impact is slower than
 * rest_velocity or the bounce would come back within one tick (the Zeno guard). */

static lag_result stop_event(lag_sim *s, const lag_watcher *w, double *y, double t,
                             lag_event_kind bounce, lag_event_kind rest_kind)
{
    const int n = s->nq, i = w->joint;
    lag_result r;
    double v = y[n + i];
    /* Zeno guard: rest if slower than rest_velocity, or if the bounce would come back
     * within one tick (e |v| < a dt, a the acceleration into the stop). */
    double Q[LAG_MAX_DOF], qdd[LAG_MAX_DOF];
    lag_effects_force(s, y, y + n, Q);
    if ((r = lag_forward_locked(s, y, y + n, Q, qdd, NULL)) != LAG_OK) return r;
    double a_in = qdd[i] * w->side;
    bool rest = fabs(v) < s->def.effects.rest_velocity ||
                (a_in > 0 && w->e * fabs(v) < a_in * s->def.integrator.dt);
    if (rest) {
        if ((r = lag_impulse_map(s, y, i, 0.0)) != LAG_OK) return r;
        y[n + i] = 0.0;
        s->mode.locked |= 1u << i;
        s->mode.lock_side[i] = (int8_t)w->side;
        s->mode.slip_dir[i] = 0;
        double lambda[LAG_MAX_DOF];
        if (rest_kind == LAG_EV_LANDING &&
            (r = lag_forward_locked(s, y, y + n, Q, qdd, lambda)) == LAG_OK &&
            -w->side * lambda[i] < 0) {
            /* the floor would have to pull: the end touches it and flies on */
            s->mode.locked &= ~(1u << i);
            s->mode.lock_side[i] = 0;
            lag_sim_record_event(s, bounce, i, t, v);
        } else {
            if (r != LAG_OK) return r;
            lag_sim_record_event(s, rest_kind, i, t, v);
        }
    } else {
        if ((r = lag_impulse_map(s, y, i, w->e)) != LAG_OK) return r;
        lag_sim_record_event(s, bounce, i, t, v);
    }
    lag_refresh_slip(s, y);
    return LAG_OK;
}

static lag_result rest_velocity_validate(const lag_sim_def *def, lag_diag *d, const char *field)
{
    double v = def->effects.rest_velocity;
    if (!(isfinite(v) && v >= 0)) return lag_diag_fail(d, field, "expected a finite number >= 0, got %g", v);
    return LAG_OK;
}

/* ---------------------------------------------------------------- limits: per-joint stops */

static lag_result limits_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    lag_result r = rest_velocity_validate(def, d, "effects.limits.rest_velocity");
    if (r != LAG_OK) return r;
    for (int i = 0; i < def->model.nq; i++) {
        if (!e->limit_on[i]) continue;
        const char *j = jname(def, i);
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
    return LAG_OK;
}

static bool limits_watch(const lag_sim *s, int joint, int self, lag_watch_set *ws)
{
    const lag_effects_def *e = &s->def.effects;
    if (joint < 0 || !e->limit_on[joint]) return true;
    lag_watcher w = {.kind = LAG_WATCH_POSITION, .owner = (uint8_t)self, .joint = (int8_t)joint,
                     .strict = true, .e = e->restitution[joint]};
    w.side = -1;
    w.bound = e->limit_lower[joint];
    if (!lag_watch_add(ws, w)) return false;
    w.side = +1;
    w.bound = e->limit_upper[joint];
    return lag_watch_add(ws, w);
}

static lag_result limits_event(lag_sim *s, const lag_watcher *w, double *y, double t)
{
    return stop_event(s, w, y, t, LAG_EV_LIMIT, LAG_EV_REST);
}

/* ---------------------------------------------------------------- floor: the stick's */
/* Stick only. Without flight (floor_flight false): its end on the floor, impacts of the
 * free end at phi = 0 and pi (reported as impacts), resting contact, and lift-off (the
 * normal force reaching zero, a CUSTOM watcher) is a fault.
 * With flight, the sim integrates the flying stick (x, phi, h), h the height of one end
 * (model_flying_stick.c), and the floor is a stop of h at 0 on the lower side:
 *   - in contact h is held (a resting stop): the stop's hold force is the normal force,
 *     and when it would pull the hold lets go (events.c: a `liftoff`, the stick flies);
 *     the free end's impacts are those of the stick without flight, at phi = k pi and
 *     (k + 1) pi around the contact's interval of phi;
 *   - in flight h's stop is watched (that end landing: a frictionless impact, the
 *     vertical impulse at the end being a generalized impulse on h alone, J = e_h), and
 *     the other end's height h + sigma l sin phi (a GAP watcher): when it reaches the
 *     floor, h is made that end's height (a change of coordinates: x, phi, the velocities
 *     and the energy unchanged) and it lands as h's end does;
 *   - a landing ends in sliding contact (`landing`, h held) when it is slower than
 *     rest_velocity or its bounce would come back within one tick (the Zeno guard), and
 *     the floor then pushes (else the end touches and the stick flies on: `impact`);
 *     otherwise the end bounces (`impact`), J qd+ = -e J qd-. */

static lag_result floor_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    if (def->model.kind != LAG_MODEL_STICK)
        return lag_diag_fail(d, "effects.floor", "the floor effect is for the stick model only");
    lag_result r = rest_velocity_validate(def, d, "effects.floor.rest_velocity");
    if (r != LAG_OK) return r;
    if (!(e->floor_restitution >= 0 && e->floor_restitution <= 1))
        return lag_diag_fail(d, "effects.floor.restitution", "expected a number in [0, 1], got %g",
                             e->floor_restitution);
    if (def->q0[1] < 0 || def->q0[1] > M_PI)
        return lag_diag_fail(d, "initial.q[1]", "initial phi = %g must be in [0, pi] with a floor",
                             def->q0[1]);
    if (e->floor_flight) {
        double h = def->q0[2], hd = def->qd0[2];
        if (!(isfinite(h) && h >= 0 && h <= def->explode_limit))
            return lag_diag_fail(d, "initial.q[2]",
                                 "the stick's lower end is at height h = %g: expected a number "
                                 "in [0, explode_limit]", h);
        if (!(isfinite(hd) && fabs(hd) <= def->explode_limit))
            return lag_diag_fail(d, "initial.qd[2]", "expected a finite number within "
                                 "explode_limit, got %g", hd);
    } else if (def->q0[2] != 0 || def->qd0[2] != 0) {
        return lag_diag_fail(d, "initial.q[2]", "a height needs a floor the stick may leave "
                             "(flight: true)");
    }
    return LAG_OK;
}

/* sigma of the flying stick: +1 when h is end A's height, -1 for end B's */
static double floor_sigma(const lag_sim *s)
{
    return s->model.p[LAG_FSTICK_END] != 0.0 ? -1.0 : 1.0;
}

/* In contact on h's end, the interval [k pi, (k + 1) pi] of phi in which the stick is
 * above the floor: k even for end A (sin phi >= 0), odd for end B; the one whose middle
 * is nearest phi (phi may lie a rounding outside it after a landing). */
static double floor_k(const lag_sim *s, double phi)
{
    double off = s->model.p[LAG_FSTICK_END] != 0.0 ? 1.0 : 0.0;
    return 2.0 * round((phi / M_PI - off - 0.5) / 2.0) + off;
}

static bool floor_watch(const lag_sim *s, int joint, int self, lag_watch_set *ws)
{
    const double e = s->def.effects.floor_restitution;
    if (s->model.kind == LAG_MODEL_FLYING_STICK) {
        const bool contact = s->mode.locked & (1u << 2);
        lag_watcher w = {.kind = LAG_WATCH_POSITION, .owner = (uint8_t)self, .strict = true,
                         .e = e, .side = -1};
        if (joint == 2) { /* h's end landing (h is free: a held joint has its hold only) */
            w.joint = 2;
            w.bound = 0.0;
            return lag_watch_add(ws, w);
        }
        if (joint == 1 && contact) { /* the free end reaching the floor */
            double k = floor_k(s, s->q[1]);
            w.joint = 1;
            w.bound = k * M_PI;
            if (!lag_watch_add(ws, w)) return false;
            w.side = +1;
            w.bound = (k + 1.0) * M_PI;
            return lag_watch_add(ws, w);
        }
        if (joint < 0 && !contact) /* the other end landing */
            return lag_watch_add(ws, (lag_watcher){.kind = LAG_WATCH_GAP, .owner = (uint8_t)self,
                                                   .joint = 2, .strict = true, .e = e});
        return true;
    }
    if (joint < 0) /* lift-off: the normal force, with the dynamics (value below) */
        return lag_watch_add(ws, (lag_watcher){.kind = LAG_WATCH_CUSTOM, .owner = (uint8_t)self,
                                               .joint = 1, .strict = false});
    if (joint != 1) return true;
    lag_watcher w = {.kind = LAG_WATCH_POSITION, .owner = (uint8_t)self, .joint = 1,
                     .strict = true, .e = e};
    w.side = -1;
    w.bound = 0.0;
    if (!lag_watch_add(ws, w)) return false;
    w.side = +1;
    w.bound = M_PI;
    return lag_watch_add(ws, w);
}

/* N = m (g + d2/dt2 ((l/2) sin phi)), divided by m */
static double floor_normal(lag_sim *s, const lag_watcher *w, const double *y, const double *qdd)
{
    (void)w;
    const double *p = s->def.model.p;
    const int n = s->nq;
    double ph = y[1], phd = y[n + 1];
    return p[LAG_STICK_G] + 0.5 * p[LAG_STICK_L] * (cos(ph) * qdd[1] - sin(ph) * phd * phd);
}

/* The other end's height h + sigma l sin phi, its rate and its second derivative. */
static double floor_gap(const lag_sim *s, const lag_watcher *w, const double *y,
                        const double *qdd, double *rate, double *accel)
{
    (void)w;
    const int n = s->nq;
    const double sl = floor_sigma(s) * s->model.p[LAG_STICK_L];
    double sn = sin(y[1]), c = cos(y[1]), phd = y[n + 1];
    if (rate) *rate = y[n + 2] + sl * c * phd;
    if (accel && qdd) *accel = qdd[2] + sl * (c * qdd[1] - sn * phd * phd);
    return y[2] + sl * sn;
}

static lag_result floor_event(lag_sim *s, const lag_watcher *w, double *y, double t)
{
    if (w->kind == LAG_WATCH_CUSTOM) {
        lag_sim_record_event(s, LAG_EV_LIFTOFF, 1, t, 0.0);
        return LAG_ERR_LIFTOFF;
    }
    if (w->kind == LAG_WATCH_GAP) {
        /* h becomes the landing end's height: y = h + sigma a s = h' - sigma a s */
        const int n = s->nq;
        double rate, gap = floor_gap(s, w, y, NULL, &rate, NULL);
        y[2] = gap;
        y[n + 2] = rate;
        s->model.p[LAG_FSTICK_END] = s->model.p[LAG_FSTICK_END] != 0.0 ? 0.0 : 1.0;
        s->dp.valid = false;
        lag_watcher h = {.kind = LAG_WATCH_POSITION, .owner = w->owner, .joint = 2, .side = -1,
                         .strict = true, .bound = 0.0, .e = w->e};
        return stop_event(s, &h, y, t, LAG_EV_IMPACT, LAG_EV_LANDING);
    }
    if (w->joint == 2) return stop_event(s, w, y, t, LAG_EV_IMPACT, LAG_EV_LANDING);
    return stop_event(s, w, y, t, LAG_EV_IMPACT, LAG_EV_REST);
}

void lag_floor_from_lower_end(lag_sim *s, double *q, double *qd)
{
    (void)q; (void)qd;
    /* h is the lower end's height: end B's when it is below the centre */
    s->model.p[LAG_FSTICK_END] = sin(q[1]) < 0 ? 1.0 : 0.0;
}

/* The published h: the lower end's height and vertical velocity (0 in contact). */
static void floor_publish(const lag_sim *s, double *q, double *qd)
{
    if (s->mode.locked & (1u << 2)) {
        q[2] = 0.0;
        qd[2] = 0.0;
        return;
    }
    double rate, other = floor_gap(s, NULL, (const double[]){s->q[0], s->q[1], s->q[2],
                                                             s->qd[0], s->qd[1], s->qd[2]},
                                   NULL, &rate, NULL);
    if (other < s->q[2]) {
        q[2] = other;
        qd[2] = rate;
    }
}

/* ================================================================== friction */
/* Coulomb per joint: a joint at rest is held while |force| <= mu_s (a hold); a sliding
 * one feels -mu_k sgn(qd) and is watched for qd crossing zero. */

static lag_result friction_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    for (int i = 0; i < def->model.nq; i++) {
        const char *j = jname(def, i);
        double ms = e->friction_static[i], mk = e->friction_kinetic[i];
        if (!(isfinite(mk) && mk >= 0))
            return lag_diag_fail(d, jfield(f, "friction", j, "kinetic"),
                                 "expected a finite number >= 0, got %g", mk);
        if (!(isfinite(ms) && ms >= mk))
            return lag_diag_fail(d, jfield(f, "friction", j, "static"),
                                 "expected a finite number >= the kinetic value %g, got %g", mk, ms);
    }
    return LAG_OK;
}

static void friction_force(const lag_sim *s, const double *q, const double *qd, double *Q)
{
    (void)q; (void)qd;
    for (int i = 0; i < s->nq; i++) Q[i] -= s->def.effects.friction_kinetic[i] * s->mode.slip_dir[i];
}

static bool friction_watch(const lag_sim *s, int joint, int self, lag_watch_set *ws)
{
    if (joint < 0 || !lag_has_friction(s, joint) || s->mode.slip_dir[joint] == 0) return true;
    return lag_watch_add(ws, (lag_watcher){.kind = LAG_WATCH_VELOCITY_ZERO, .owner = (uint8_t)self,
                                           .joint = (int8_t)joint, .strict = true});
}

/* The sliding joint stopped: held if static friction can, else it slides back. */
static lag_result friction_event(lag_sim *s, const lag_watcher *w, double *y, double t)
{
    const int i = w->joint;
    lag_result r;
    if ((r = lag_impulse_map(s, y, i, 0.0)) != LAG_OK) return r;
    lag_event_kind k = lag_friction_settle(s, y, i);
    lag_sim_record_event(s, k, i, t, s->mode.slip_dir[i]);
    lag_refresh_slip(s, y);
    return LAG_OK;
}

/* ================================================================== actuator */
/* Per input: a first-order lag (advanced exactly over each tick), then saturation. */

static lag_result actuator_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    for (int i = 0; i < def->model.nq; i++) {
        const char *j = jname(def, i);
        if (!(e->actuator_max[i] > 0))
            return lag_diag_fail(d, jfield(f, "actuator", j, "max"), "expected a number > 0, got %g",
                                 e->actuator_max[i]);
        if (!(isfinite(e->actuator_tau[i]) && e->actuator_tau[i] >= 0))
            return lag_diag_fail(d, jfield(f, "actuator", j, "lag"),
                                 "expected a finite number >= 0 (s), got %g", e->actuator_tau[i]);
    }
    return LAG_OK;
}

static void actuator_pre_tick(lag_sim *s)
{
    const lag_effects_def *e = &s->def.effects;
    const double dt = s->def.integrator.dt, t0 = lag_sim_time(s);
    for (int i = 0; i < s->nq; i++) {
        double cmd = s->tau[i], v = cmd;
        if (e->actuator_tau[i] > 0) {
            double a = exp(-dt / e->actuator_tau[i]);
            s->mode.act_state[i] = cmd + (s->mode.act_state[i] - cmd) * a;
            v = s->mode.act_state[i];
        }
        bool sat = fabs(v) > e->actuator_max[i];
        if (sat) v = copysign(e->actuator_max[i], v);
        if (sat && !s->mode.saturated[i]) lag_sim_record_event(s, LAG_EV_SATURATION, i, t0, cmd);
        s->mode.saturated[i] = sat;
        s->tau_applied[i] = v;
    }
}

/* ================================================================== disturbance */
/* Scheduled generalized impulses (at the first tick boundary at or after t) and forces
 * held over [t, t + duration). */

static lag_result disturbance_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    if (e->n_disturbances < 0 || e->n_disturbances > LAG_MAX_DISTURBANCES)
        return lag_diag_fail(d, "effects.disturbance", "expected at most %d disturbances, got %d",
                             LAG_MAX_DISTURBANCES, e->n_disturbances);
    for (int k = 0; k < e->n_disturbances; k++) {
        const lag_disturbance *dk = &e->disturbances[k];
        if (!(isfinite(dk->t) && dk->t >= 0)) {
            snprintf(f, sizeof f, "effects.disturbance[%d].t", k);
            return lag_diag_fail(d, f, "expected a finite time >= 0 (s), got %g", dk->t);
        }
        if (dk->joint < 0 || dk->joint >= def->model.nq) {
            snprintf(f, sizeof f, "effects.disturbance[%d].joint", k);
            return lag_diag_fail(d, f, "no joint %d in model %s", dk->joint,
                                 lag_model_info_get(def->model.kind)->name);
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
    return LAG_OK;
}

static void disturbance_pre_tick(lag_sim *s)
{
    const lag_effects_def *e = &s->def.effects;
    const int n = s->nq;
    const double dt = s->def.integrator.dt, t0 = lag_sim_time(s);
    bool impulse = false;
    double y[LAG_MAX_STATE];
    for (int i = 0; i < n; i++) { s->mode.dist_force[i] = 0.0; y[i] = s->q[i]; y[n + i] = s->qd[i]; }
    for (int k = 0; k < e->n_disturbances; k++) {
        const lag_disturbance *d = &e->disturbances[k];
        /* the first tick boundary at or after d->t (saturated: a time past the last tick
         * is never reached) */
        int64_t kd = lag_ticks_ceil(d->t, dt);
        if (d->impulse) {
            if (s->tick != kd) continue;
            double x[LAG_MAX_DOF];
            /* an impulse breaks any hold but the floor's of h (which then pushes, or lets go
             * at the tick's start); modes are re-settled */
            s->mode.locked &= lag_floor_h(s, 2) ? (1u << 2) : 0u;
            if (lag_minv_column(s, y, d->joint, x) != LAG_OK) continue;
            for (int i = 0; i < n; i++) y[n + i] += x[i] * d->value;
            impulse = true;
            lag_sim_record_event(s, LAG_EV_DISTURBANCE, d->joint, t0, d->value);
        } else {
            double tend = d->t + d->duration;
            if (s->tick >= kd && t0 < tend - 1e-9 * dt) {
                s->mode.dist_force[d->joint] += d->value;
                if (s->tick == kd) lag_sim_record_event(s, LAG_EV_DISTURBANCE, d->joint, t0, d->value);
            }
        }
    }
    if (impulse) {
        for (int i = 0; i < n; i++) {
            if (!(s->mode.locked & (1u << i))) s->mode.lock_side[i] = 0;
            s->mode.slip_dir[i] = 0;
        }
        lag_refresh_slip(s, y);
        for (int i = 0; i < n; i++) s->qd[i] = y[n + i];
    }
}

static void disturbance_force(const lag_sim *s, const double *q, const double *qd, double *Q)
{
    (void)q; (void)qd;
    for (int i = 0; i < s->nq; i++) Q[i] += s->mode.dist_force[i];
}

/* ================================================================== noise */
/* Gaussian noise on the published state only; deterministic in (seed, tick, index). */

static lag_result noise_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    for (int i = 0; i < def->model.nq; i++) {
        const char *j = jname(def, i);
        if (!(isfinite(e->noise_q[i]) && e->noise_q[i] >= 0))
            return lag_diag_fail(d, jfield(f, "noise.q", j, NULL), "expected a finite number >= 0, got %g",
                                 e->noise_q[i]);
        if (!(isfinite(e->noise_qd[i]) && e->noise_qd[i] >= 0))
            return lag_diag_fail(d, jfield(f, "noise.qd", j, NULL), "expected a finite number >= 0, got %g",
                                 e->noise_qd[i]);
    }
    return LAG_OK;
}

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

static void noise_observe(const lag_sim *s, double *q, double *qd)
{
    const lag_effects_def *e = &s->def.effects;
    for (int i = 0; i < s->nq; i++) {
        if (e->noise_q[i] > 0) q[i] += e->noise_q[i] * gauss_at(e->noise_seed, s->tick, i);
        if (e->noise_qd[i] > 0) qd[i] += e->noise_qd[i] * gauss_at(e->noise_seed, s->tick, LAG_MAX_DOF + i);
    }
}

/* ================================================================== spring */
/* A linear spring per joint towards a rest position: Q_i = -k_i (q_i - rest_i), storing
 * U_i = 1/2 k_i (q_i - rest_i)^2 (part of the energy). */

static lag_result spring_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    for (int i = 0; i < def->model.nq; i++) {
        const char *j = jname(def, i);
        if (!(isfinite(e->spring_k[i]) && e->spring_k[i] >= 0))
            return lag_diag_fail(d, jfield(f, "spring", j, "k"), "expected a finite number >= 0, got %g",
                                 e->spring_k[i]);
        if (!isfinite(e->spring_rest[i]))
            return lag_diag_fail(d, jfield(f, "spring", j, "rest"), "expected a finite number, got %g",
                                 e->spring_rest[i]);
    }
    return LAG_OK;
}

static void spring_force(const lag_sim *s, const double *q, const double *qd, double *Q)
{
    (void)qd;
    const lag_effects_def *e = &s->def.effects;
    for (int i = 0; i < s->nq; i++) Q[i] -= e->spring_k[i] * (q[i] - e->spring_rest[i]);
}

static double spring_potential(const lag_sim *s, const double *q)
{
    const lag_effects_def *e = &s->def.effects;
    double U = 0.0;
    for (int i = 0; i < s->nq; i++) {
        double x = q[i] - e->spring_rest[i];
        U += 0.5 * e->spring_k[i] * x * x;
    }
    return U;
}

/* ================================================================== the table */

const lag_effect_row lag_effect_rows[] = {
    {.bit = LAG_EFF_DAMPING, .name = "damping", .validate = damping_validate, .force = damping_force},
    {.bit = LAG_EFF_LIMITS, .name = "limits", .validate = limits_validate, .watch = limits_watch,
     .on_event = limits_event, .max_watch_joint = 2, .keeps_state = true},
    {.bit = LAG_EFF_FLOOR, .name = "floor", .validate = floor_validate, .watch = floor_watch,
     .value = floor_normal, .gap = floor_gap, .on_event = floor_event, .max_watch_joint = 2,
     .max_watch_global = 1, .keeps_state = true},
    {.bit = LAG_EFF_FRICTION, .name = "friction", .validate = friction_validate, .force = friction_force,
     .watch = friction_watch, .on_event = friction_event, .max_watch_joint = 1, .keeps_state = true},
    {.bit = LAG_EFF_ACTUATOR, .name = "actuator", .validate = actuator_validate,
     .pre_tick = actuator_pre_tick, .keeps_state = true},
    {.bit = LAG_EFF_DISTURBANCE, .name = "disturbance", .validate = disturbance_validate,
     .pre_tick = disturbance_pre_tick, .force = disturbance_force},
    {.bit = LAG_EFF_NOISE, .name = "noise", .validate = noise_validate, .observe = noise_observe},
    {.bit = LAG_EFF_SPRING, .name = "spring", .validate = spring_validate, .force = spring_force,
     .potential = spring_potential},
};
_Static_assert(sizeof lag_effect_rows / sizeof lag_effect_rows[0] == LAG_EFF_COUNT,
               "the effect table needs one row per LAG_EFF_* bit");

/* The public facts of a row, with its classes as its hooks make them. */
lag_effect_info lag_effect_info_get(int index)
{
    lag_effect_info inf = {0};
    if (index < 0 || index >= LAG_EFF_COUNT) return inf;
    const lag_effect_row *r = &lag_effect_rows[index];
    inf.bit = r->bit;
    inf.name = r->name;
    inf.force = r->force != NULL;
    inf.potential = r->potential != NULL;
    inf.per_tick = r->pre_tick != NULL || r->watch != NULL;
    inf.events = r->watch != NULL;
    inf.observe = r->observe != NULL;
    inf.keeps_state = r->keeps_state;
    return inf;
}

int lag_effect_from_name(const char *name)
{
    for (int k = 0; k < LAG_EFF_COUNT; k++)
        if (name && strcmp(name, lag_effect_rows[k].name) == 0) return k;
    return -1;
}

uint32_t lag_effects_known(void)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) m |= lag_effect_rows[k].bit;
    return m;
}

uint32_t lag_effects_per_tick(uint32_t enabled)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++)
        if (lag_effect_rows[k].pre_tick || lag_effect_rows[k].watch) m |= lag_effect_rows[k].bit;
    return enabled & m;
}

uint32_t lag_effects_with_events(uint32_t enabled)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++)
        if (lag_effect_rows[k].watch) m |= lag_effect_rows[k].bit;
    return enabled & m;
}

/* ------------------------------------------------------------------ dispatch */

lag_result lag_effects_check(const lag_sim_def *def, lag_diag *d)
{
    const uint32_t en = def->effects.enabled, known = lag_effects_known();
    if (en & ~known) return lag_diag_fail(d, "effects", "unknown effect bits 0x%x", (unsigned)(en & ~known));
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const lag_effect_row *r = &lag_effect_rows[k];
        lag_result res;
        if ((en & r->bit) && (res = r->validate(def, d)) != LAG_OK) return res;
    }
    return LAG_OK;
}

void lag_effects_prepare(lag_sim *s)
{
    memset(&s->fx, 0, sizeof s->fx);
    const uint32_t en = s->def.effects.enabled;
    s->fx.enabled = en;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const lag_effect_row *r = &lag_effect_rows[k];
        if (!(en & r->bit)) continue;
        if (r->force) s->fx.force[s->fx.n_force++] = (uint8_t)k;
        if (r->pre_tick) s->fx.pre_tick[s->fx.n_pre_tick++] = (uint8_t)k;
        if (r->watch) s->fx.watch[s->fx.n_watch++] = (uint8_t)k;
        if (r->potential) s->fx.potential[s->fx.n_potential++] = (uint8_t)k;
        if (r->observe) s->fx.observe[s->fx.n_observe++] = (uint8_t)k;
        if (r->pre_tick || r->watch) s->fx.per_tick |= r->bit;
    }
}

void lag_effects_force(const lag_sim *s, const double *q, const double *qd, double *Q)
{
    LAG_ASSERT(s->fx.enabled == s->def.effects.enabled); /* prepared for this definition */
    for (int i = 0; i < s->nq; i++) Q[i] = s->tau_applied[i];
    for (int k = 0; k < s->fx.n_force; k++) lag_effect_rows[s->fx.force[k]].force(s, q, qd, Q);
}

double lag_effects_potential(const lag_sim *s, const double *q)
{
    double U = 0.0;
    for (int k = 0; k < s->fx.n_potential; k++) U += lag_effect_rows[s->fx.potential[k]].potential(s, q);
    return U;
}

void lag_effects_pre_tick(lag_sim *s)
{
    for (int k = 0; k < s->fx.n_pre_tick; k++) lag_effect_rows[s->fx.pre_tick[k]].pre_tick(s);
}

bool lag_effects_watch(const lag_sim *s, int joint, lag_watch_set *ws)
{
    for (int k = 0; k < s->fx.n_watch; k++) {
        int row = s->fx.watch[k];
        if (!lag_effect_rows[row].watch(s, joint, row, ws)) return false;
    }
    return true;
}

void lag_sim_observe(const lag_sim *s, double *q, double *qd)
{
    for (int i = 0; i < s->nq; i++) { q[i] = s->q[i]; qd[i] = s->qd[i]; }
    if (lag_floor_h(s, 2)) floor_publish(s, q, qd);
    for (int k = 0; k < s->fx.n_observe; k++) lag_effect_rows[s->fx.observe[k]].observe(s, q, qd);
}
