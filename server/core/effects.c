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
 *   keeps_state  whether, under its settings, it keeps state of its own from tick to tick
 *              that q, qd, tick and the definition do not hold (contact and stick/slip
 *              modes, a lag's state): a restart from a logged (q, qd, tick) is then not
 *              exact (lag_effect_info.keeps_state, lag_effects_keeping_state)
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

/* keeps_state of the effects whose modes are state of their own whatever their settings */
static bool always(const lag_effects_def *e)
{
    (void)e;
    return true;
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

/* ================================================================== limits: per-joint stops */
/* A stop of each side of a joint (lag_stop_event, contact.c). */

static lag_result limits_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    char f[LAG_FIELD_MAX];
    lag_result r = lag_rest_velocity_validate(def, d, "effects.limits.rest_velocity");
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
    return lag_stop_event(s, w, y, t, LAG_EV_LIMIT, LAG_EV_REST);
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

/* The lag's state (mode.act_state) is the actuator's own, while some input has a lag. */
static bool actuator_lagged(const lag_effects_def *e)
{
    for (int i = 0; i < LAG_MAX_DOF; i++)
        if (e->actuator_tau[i] > 0) return true;
    return false;
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

/* field = "<at>.<key>", or the key alone */
static const char *dfield(char *buf, const char *at, const char *key)
{
    int n = snprintf(buf, LAG_FIELD_MAX, "%s%s%s", at && at[0] ? at : "", at && at[0] ? "." : "",
                     key);
    if (n >= LAG_FIELD_MAX) /* a path longer than a field name: cut, and said to be */
        memcpy(buf + LAG_FIELD_MAX - 4, "...", 4);
    return buf;
}

lag_result lag_disturbance_check(const lag_sim_def *def, const lag_disturbance *dist,
                                 const char *at, lag_diag *d)
{
    char f[LAG_FIELD_MAX];
    const double dt = def->integrator.dt;
    if (!(dist->t >= 0 && dist->t <= LAG_TIME_MAX))
        return lag_diag_fail(d, dfield(f, at, "t"), "expected a time from 0 to %g s, got %g",
                             LAG_TIME_MAX, dist->t);
    if (dist->joint < 0 || dist->joint >= def->model.nq)
        return lag_diag_fail(d, dfield(f, at, "joint"), "no joint %d in model %s", dist->joint,
                             lag_model_info_get(def->model.kind)->name);
    if (dist->impulse && dist->duration != 0)
        return lag_diag_fail(d, dfield(f, at, "duration"), "an impulse takes no duration, got "
                             "%g s", dist->duration);
    /* held over the ticks that start in [t, t + duration): shorter than a tick, it would
     * be held over one whole tick, and give more than the impulse it stands for */
    if (!dist->impulse && !(dist->duration >= dt && dist->duration <= LAG_TIME_MAX))
        return lag_diag_fail(d, dfield(f, at, "duration"), "expected a duration from %g s "
                             "(integrator.dt: a force acts for whole ticks; a shorter push is "
                             "an impulse) to %g s, got %g", dt, LAG_TIME_MAX, dist->duration);
    if (!(fabs(dist->value) <= LAG_FORCE_MAX))
        return lag_diag_fail(d, dfield(f, at, dist->impulse ? "impulse" : "force"),
                             "expected a number from %g to %g (%s), got %g", -LAG_FORCE_MAX,
                             LAG_FORCE_MAX, dist->impulse ? "N s or N m s" : "N or N m",
                             dist->value);
    return LAG_OK;
}

lag_result lag_disturbance_joint(const lag_sim_def *def, const char *name, const char *at,
                                 int *joint, lag_diag *d)
{
    const lag_model_info *mi = lag_model_info_get(def->model.kind);
    char f[LAG_FIELD_MAX], names[128] = "";
    for (int i = 0; i < mi->nq; i++) {
        if (name && strcmp(name, mi->joint_names[i]) == 0) {
            *joint = i;
            return LAG_OK;
        }
        size_t u = strlen(names);
        snprintf(names + u, sizeof names - u, "%s%s", i ? ", " : "", mi->joint_names[i]);
    }
    *joint = -1;
    return lag_diag_fail(d, dfield(f, at, "joint"), "unknown joint '%.40s' for model %s; "
                         "allowed: %s", name ? name : "", mi->name, names);
}

static lag_result disturbance_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    if (e->n_disturbances < 0 || e->n_disturbances > LAG_MAX_DISTURBANCES)
        return lag_diag_fail(d, "effects.disturbance", "expected at most %d disturbances, got %d",
                             LAG_MAX_DISTURBANCES, e->n_disturbances);
    for (int k = 0; k < e->n_disturbances; k++) {
        char at[LAG_FIELD_MAX];
        snprintf(at, sizeof at, "effects.disturbance[%d]", k);
        lag_result r = lag_disturbance_check(def, &e->disturbances[k], at, d);
        if (r != LAG_OK) return r;
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
            /* an impulse breaks any hold but a firm one (the floor's of h, which then
             * pushes, or lets go at the tick's start); modes are re-settled */
            s->mode.locked &= lag_effects_firm_holds(s);
            if (lag_minv_column(s, y, d->joint, x) != LAG_OK) continue;
            for (int i = 0; i < n; i++) y[n + i] += x[i] * d->value;
            impulse = true;
            lag_sim_record_event(s, LAG_EV_DISTURBANCE, d->joint, t0, d->value);
        } else {
            /* held over the ticks that start before t + duration */
            if (s->tick >= kd && s->tick < lag_ticks_ceil(d->t + d->duration, dt)) {
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

static const lag_effect_row damping_row = {
    .bit = LAG_EFF_DAMPING, .name = "damping", .validate = damping_validate, .force = damping_force};
static const lag_effect_row limits_row = {
    .bit = LAG_EFF_LIMITS, .name = "limits", .validate = limits_validate, .watch = limits_watch,
    .on_event = limits_event, .max_watch_joint = 2, .keeps_state = always};
static const lag_effect_row friction_row = {
    .bit = LAG_EFF_FRICTION, .name = "friction", .validate = friction_validate,
    .force = friction_force, .watch = friction_watch, .on_event = friction_event,
    .max_watch_joint = 1, .keeps_state = always};
static const lag_effect_row actuator_row = {
    .bit = LAG_EFF_ACTUATOR, .name = "actuator", .validate = actuator_validate,
    .pre_tick = actuator_pre_tick, .keeps_state = actuator_lagged};
static const lag_effect_row disturbance_row = {
    .bit = LAG_EFF_DISTURBANCE, .name = "disturbance", .validate = disturbance_validate,
    .pre_tick = disturbance_pre_tick, .force = disturbance_force};
static const lag_effect_row noise_row = {
    .bit = LAG_EFF_NOISE, .name = "noise", .validate = noise_validate, .observe = noise_observe};
static const lag_effect_row spring_row = {
    .bit = LAG_EFF_SPRING, .name = "spring", .validate = spring_validate, .force = spring_force,
    .potential = spring_potential};

/* The table, in dispatch order; a row may live in a unit of its own (the floor's). */
const lag_effect_row *const lag_effect_rows[] = {
    &damping_row, &limits_row, &lag_effect_floor, &friction_row,
    &actuator_row, &disturbance_row, &noise_row, &spring_row,
};
_Static_assert(sizeof lag_effect_rows / sizeof lag_effect_rows[0] == LAG_EFF_COUNT,
               "the effect table needs one row per LAG_EFF_* bit");

/* The public facts of a row, with its classes as its hooks make them. */
lag_effect_info lag_effect_info_get(int index)
{
    lag_effect_info inf = {0};
    if (index < 0 || index >= LAG_EFF_COUNT) return inf;
    const lag_effect_row *r = lag_effect_rows[index];
    inf.bit = r->bit;
    inf.name = r->name;
    inf.force = r->force != NULL;
    inf.potential = r->potential != NULL;
    inf.per_tick = r->pre_tick != NULL || r->watch != NULL;
    inf.events = r->watch != NULL;
    inf.observe = r->observe != NULL;
    inf.keeps_state = r->keeps_state != NULL;
    return inf;
}

uint32_t lag_effects_keeping_state(const lag_effects_def *e)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const lag_effect_row *r = lag_effect_rows[k];
        if ((e->enabled & r->bit) && r->keeps_state && r->keeps_state(e)) m |= r->bit;
    }
    return m;
}

int lag_effect_from_name(const char *name)
{
    for (int k = 0; k < LAG_EFF_COUNT; k++)
        if (name && strcmp(name, lag_effect_rows[k]->name) == 0) return k;
    return -1;
}

uint32_t lag_effects_known(void)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) m |= lag_effect_rows[k]->bit;
    return m;
}

uint32_t lag_effects_per_tick(uint32_t enabled)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++)
        if (lag_effect_rows[k]->pre_tick || lag_effect_rows[k]->watch) m |= lag_effect_rows[k]->bit;
    return enabled & m;
}

uint32_t lag_effects_with_events(uint32_t enabled)
{
    uint32_t m = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++)
        if (lag_effect_rows[k]->watch) m |= lag_effect_rows[k]->bit;
    return enabled & m;
}

/* ------------------------------------------------------------------ dispatch */

lag_result lag_effects_check(const lag_sim_def *def, lag_diag *d)
{
    const uint32_t en = def->effects.enabled, known = lag_effects_known();
    if (en & ~known) return lag_diag_fail(d, "effects", "unknown effect bits 0x%x", (unsigned)(en & ~known));
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const lag_effect_row *r = lag_effect_rows[k];
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
        const lag_effect_row *r = lag_effect_rows[k];
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
    for (int k = 0; k < s->fx.n_force; k++) lag_effect_rows[s->fx.force[k]]->force(s, q, qd, Q);
}

double lag_effects_potential(const lag_sim *s, const double *q)
{
    double U = 0.0;
    for (int k = 0; k < s->fx.n_potential; k++) U += lag_effect_rows[s->fx.potential[k]]->potential(s, q);
    return U;
}

void lag_effects_pre_tick(lag_sim *s)
{
    for (int k = 0; k < s->fx.n_pre_tick; k++) lag_effect_rows[s->fx.pre_tick[k]]->pre_tick(s);
}

bool lag_effects_watch(const lag_sim *s, int joint, lag_watch_set *ws)
{
    for (int k = 0; k < s->fx.n_watch; k++) {
        int row = s->fx.watch[k];
        if (!lag_effect_rows[row]->watch(s, joint, row, ws)) return false;
    }
    return true;
}

void lag_sim_observe(const lag_sim *s, double *q, double *qd)
{
    for (int i = 0; i < s->nq; i++) { q[i] = s->q[i]; qd[i] = s->qd[i]; }
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const lag_effect_row *r = lag_effect_rows[k];
        if ((s->def.effects.enabled & r->bit) && r->publish) r->publish(s, q, qd);
    }
    for (int k = 0; k < s->fx.n_observe; k++) lag_effect_rows[s->fx.observe[k]]->observe(s, q, qd);
}

/* ------------------------------------------------------------------ the run-state hooks */
/* Rare (a reset, a redefinition, an impulse, a release): over the enabled rows. */
#define FOR_ENABLED_WITH(en, hook) \
    for (int k_ = 0; k_ < LAG_EFF_COUNT; k_++) \
        if (((en) & lag_effect_rows[k_]->bit) && lag_effect_rows[k_]->hook)

int lag_effects_sim_model(const lag_sim_def *def, lag_model *m)
{
    int row = -1;
    *m = def->model;
    FOR_ENABLED_WITH(def->effects.enabled, sim_model) {
        lag_model before = *m;
        lag_effect_rows[k_]->sim_model(def, m);
        if (memcmp(&before, m, sizeof *m) != 0) row = k_;
    }
    return row;
}

void lag_effects_reset(lag_sim *s)
{
    FOR_ENABLED_WITH(s->def.effects.enabled, reset) lag_effect_rows[k_]->reset(s);
}

void lag_effects_init_holds(lag_sim *s)
{
    FOR_ENABLED_WITH(s->def.effects.enabled, init_holds) lag_effect_rows[k_]->init_holds(s);
}

uint32_t lag_effects_firm_holds(const lag_sim *s)
{
    uint32_t m = 0;
    FOR_ENABLED_WITH(s->def.effects.enabled, firm_holds) m |= lag_effect_rows[k_]->firm_holds(s);
    return m;
}

bool lag_effects_release(lag_sim *s, int i, double *y, double t, const double *lambda)
{
    FOR_ENABLED_WITH(s->def.effects.enabled, release)
        if (lag_effect_rows[k_]->release(s, i, y, t, lambda)) return true;
    return false;
}

void lag_effects_as_initial(const lag_sim *s, lag_sim_def *at)
{
    FOR_ENABLED_WITH(s->def.effects.enabled, as_initial) lag_effect_rows[k_]->as_initial(s, at);
}

/* The modes of the effects with events derived from the state (a reset, a
 * redefinition): friction's slip or stick, then the holds an effect starts with. */
void lag_effects_init_modes(lag_sim *s)
{
    const int n = s->nq;
    double y[LAG_MAX_STATE];
    for (int i = 0; i < n; i++) { y[i] = s->q[i]; y[n + i] = s->qd[i]; }
    s->mode.locked = 0;
    for (int i = 0; i < n; i++) { s->mode.lock_side[i] = 0; s->mode.slip_dir[i] = 0; }
    lag_refresh_slip(s, y);
    for (int i = 0; i < n; i++) s->qd[i] = y[n + i];
    lag_effects_init_holds(s); /* the holds an effect starts with (the floor's of h) */
}
