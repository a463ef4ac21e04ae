/*
 * The scene's `effects:` section: one row per effect in k_effects (gravity, the model's
 * parameter g, and the core's effects by their scene keys), each with the handler that
 * reads its settings into lag_effects_def and switches its bit on. The machinery (the
 * conversion state, the readers that report a bad value at its node) is scene_schema.c's
 * (scene_keys.h); the effects' own checks are the core's (lag_effects_check), whose
 * diagnosis the loader reports at the key's file:line:column.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene_keys.h"

static const range R_DAMPING = {0.0, F_MAX, false, "N s/m or N m s/rad"};
static const range R_FRICTION = {0.0, F_MAX, false, "N or N m"};
static const range R_STIFFNESS = {0.0, F_MAX, false, "N/m or N m/rad"};
static const range R_TIME = {0.0, T_MAX, false, "s"};
static const range R_GRAVITY = {0.0, 1e3, false, "m/s^2"}; /* 100 g; 0 switches gravity off */

/* Each section present switches its effect on (lag_effects_def.enabled); per-joint
 * sections are mappings from joint names to values. Values are checked where they are
 * read, so errors point at the offending node. */

static lag_effects_def *fx(conv *cv) { return &cv->sc->sim.effects; }

/* gravity: {enabled: bool, g: m/s^2} -- applied after parameters (see the end) */
static int key_gravity_enabled(conv *cv, const ynode *nd, const char *path)
{
    bool b = true;
    if (sch_get_bool(cv, nd, path, &b) < 0)
        return -1;
    cv->gravity_enabled = b ? 1 : 0;
    return 0;
}

static int key_gravity_g(conv *cv, const ynode *nd, const char *path)
{
    if (sch_get_range(cv, nd, path, &R_GRAVITY, &cv->gravity_g) < 0)
        return -1;
    cv->gravity_g_node = nd;
    return 0;
}

static const keyrow k_gravity_keys[] = {
    {"enabled", key_gravity_enabled, K_OTHER}, /* false: g = 0 */
    {"g", key_gravity_g, K_NUMBER},             /* m/s^2, replaces parameters.g */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_effect_gravity(conv *cv, const ynode *nd, const char *path)
{
    if (nd->kind == YN_SCALAR && !ynode_is_null(nd))
        return key_gravity_enabled(cv, nd, path); /* gravity: false */
    return sch_convert_map(cv, nd, path, k_gravity_keys, "key");
}

/* damping: {joint: b}, N s/m or N m s/rad */
static int damping_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_DAMPING, &fx(cv)->damping[j]);
}

static int key_effect_damping(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_DAMPING;
    return sch_per_joint(cv, nd, path, damping_joint);
}

/* friction: {joint: {static: mu_s, kinetic: mu_k}}, N or N m */
static int fr_static(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_FRICTION, &fx(cv)->friction_static[cv->cur_joint]);
}

static int fr_kinetic(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_FRICTION, &fx(cv)->friction_kinetic[cv->cur_joint]);
}

static const keyrow k_friction_keys[] = {
    {"static", fr_static, K_NUMBER},   /* largest holding force, N or N m */
    {"kinetic", fr_kinetic, K_NUMBER}, /* sliding force, N or N m */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int friction_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    cv->cur_joint = j;
    fx(cv)->friction_static[j] = NAN; /* "not given": defaults to kinetic below */
    if (sch_convert_map(cv, nd, path, k_friction_keys, "key") < 0)
        return -1;
    lag_effects_def *e = fx(cv);
    if (isnan(e->friction_static[j])) e->friction_static[j] = e->friction_kinetic[j];
    return 0; /* static >= kinetic: the core's check */
}

static int key_effect_friction(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_FRICTION;
    return sch_per_joint(cv, nd, path, friction_joint);
}

/* limits: {joint: {lower, upper, restitution}}, plus rest_velocity for all */
static int lim_lower(conv *cv, const ynode *nd, const char *path)
{
    cv->limit_seen |= 1;
    return sch_get_within_explode(cv, nd, path, &fx(cv)->limit_lower[cv->cur_joint]);
}

static int lim_upper(conv *cv, const ynode *nd, const char *path)
{
    cv->limit_seen |= 2;
    return sch_get_within_explode(cv, nd, path, &fx(cv)->limit_upper[cv->cur_joint]);
}

/* in [0, 1]: the core's check */
static int lim_restitution(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_number(cv, nd, path, &fx(cv)->restitution[cv->cur_joint]);
}

static const keyrow k_limit_keys[] = {
    {"lower", lim_lower, K_NUMBER},             /* m or rad, within explode_limit */
    {"upper", lim_upper, K_NUMBER},             /* m or rad, within explode_limit */
    {"restitution", lim_restitution, K_NUMBER}, /* [0, 1], default 0 */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

/* m/s or rad/s: an impact slower than this ends in resting contact */
static int key_rest_velocity(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_within_explode(cv, nd, path, &fx(cv)->rest_velocity);
}

/* the key of the limits section beside the joints */
static const keyrow k_limits_extra[] = {
    {"rest_velocity", key_rest_velocity, K_NUMBER, NULL, NULL},
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_effect_limits(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_LIMITS;
    if (sch_need_map(cv, nd, path, "a mapping of joints and rest_velocity") < 0)
        return -1;
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        char sub[256];
        sch_join(sub, sizeof sub, path, en->key);
        if (strcmp(en->key, k_limits_extra[0].name) == 0) {
            if (k_limits_extra[0].fn(cv, en->val, sub) < 0) return -1;
            continue;
        }
        int j = sch_joint_index(cv, en->key);
        if (j < 0) {
            char names[128];
            sch_joint_list(cv, names, sizeof names);
            return yfail_key(cv->err, en, "unknown joint '%s' in %s for model %s; allowed: %s, "
                             "rest_velocity", en->key, path, cv->info->name, names);
        }
        cv->cur_joint = j;
        cv->limit_seen = 0;
        if (sch_convert_map(cv, en->val, sub, k_limit_keys, "key") < 0)
            return -1;
        if (cv->limit_seen != 3)
            return yfail(cv->err, en->val, sub, "expected both lower and upper");
        fx(cv)->limit_on[j] = true; /* lower < upper: the core's check */
    }
    return 0;
}

/* floor (stick): {restitution, rest_velocity, flight} */
static int floor_restitution(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_number(cv, nd, path, &fx(cv)->floor_restitution);
}

static int floor_flight(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_bool(cv, nd, path, &fx(cv)->floor_flight);
}

static const keyrow k_floor_keys[] = {
    {"restitution", floor_restitution, K_NUMBER}, /* [0, 1], default 0 */
    {"rest_velocity", key_rest_velocity, K_NUMBER}, /* rad/s, default 1e-3 */
    {"flight", floor_flight, K_OTHER}, /* bool, default true: lift-off flies (else a fault) */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

/* which models have a floor, and where the initial state must then be: the core's check */
static int key_effect_floor(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_FLOOR;
    if (ynode_is_null(nd))
        return 0; /* floor: with defaults */
    return sch_convert_map(cv, nd, path, k_floor_keys, "key");
}

/* actuator: {joint: {max, lag}} on actuated joints */
static int act_max(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_EFFORT, &fx(cv)->actuator_max[cv->cur_joint]);
}

/* The lag is advanced exactly (exp(-dt/lag)) and is stable for any value. */
static int act_lag(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_TIME, &fx(cv)->actuator_tau[cv->cur_joint]);
}

static const keyrow k_actuator_keys[] = {
    {"max", act_max, K_NUMBER}, /* |effort| bound, N or N m */
    {"lag", act_lag, K_NUMBER}, /* first-order time constant, s */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int actuator_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    if (sch_need_actuated(cv, j, nd, path) < 0)
        return -1;
    cv->cur_joint = j;
    return sch_convert_map(cv, nd, path, k_actuator_keys, "key");
}

static int key_effect_actuator(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_ACTUATOR;
    return sch_per_joint(cv, nd, path, actuator_joint);
}

/* disturbance: [{t, joint, impulse | force + duration}, ...]. The values' rules (t's
 * bounds, the joint, the impulse's and force's bounds, a force's duration against dt) are
 * the core's one check of a disturbance (lag_disturbance_check, also a kick's), reported
 * at the key; the loader reads the numbers and the joint's name, and checks the shape. */
static int dist_t(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_number(cv, nd, path, &cv->cur_dist->t);
}

static int dist_joint(conv *cv, const ynode *nd, const char *path)
{
    const char *name;
    char names[128];
    sch_joint_list(cv, names, sizeof names);
    char what[160];
    snprintf(what, sizeof what, "a joint name (%s)", names);
    if (sch_get_string(cv, nd, path, what, &name) < 0)
        return -1;
    lag_diag d;
    if (lag_disturbance_joint(&cv->sc->sim, name, NULL, &cv->cur_dist->joint, &d) != LAG_OK)
        return yfail(cv->err, nd, path, "%s", d.message);
    return 0;
}

static int dist_impulse(conv *cv, const ynode *nd, const char *path)
{
    cv->cur_dist_kind |= 1;
    cv->cur_dist->impulse = true;
    return sch_get_number(cv, nd, path, &cv->cur_dist->value);
}

static int dist_force(conv *cv, const ynode *nd, const char *path)
{
    cv->cur_dist_kind |= 2;
    cv->cur_dist->impulse = false;
    return sch_get_number(cv, nd, path, &cv->cur_dist->value);
}

static int dist_duration(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_number(cv, nd, path, &cv->cur_dist->duration);
}

static const keyrow k_dist_keys[] = {
    {"t", dist_t, K_NUMBER},               /* s */
    {"joint", dist_joint, K_OTHER},       /* joint name */
    {"impulse", dist_impulse, K_NUMBER},   /* N s or N m s */
    {"force", dist_force, K_NUMBER},       /* N or N m */
    {"duration", dist_duration, K_NUMBER}, /* s, with force */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_effect_disturbance(conv *cv, const ynode *nd, const char *path)
{
    lag_effects_def *e = fx(cv);
    e->enabled |= LAG_EFF_DISTURBANCE;
    if (nd->kind != YN_SEQ)
        return yfail(cv->err, nd, path,
                     "expected a sequence of {t, joint, impulse} or {t, joint, force, duration}");
    if (nd->n > LAG_MAX_DISTURBANCES)
        return yfail(cv->err, nd, path, "at most %d disturbances, got %d",
                     LAG_MAX_DISTURBANCES, nd->n);
    e->n_disturbances = nd->n;
    for (int k = 0; k < nd->n; k++) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s[%d]", path, k);
        cv->cur_dist = &e->disturbances[k];
        memset(cv->cur_dist, 0, sizeof *cv->cur_dist);
        cv->cur_dist->joint = -1;
        cv->cur_dist->t = NAN;
        cv->cur_dist_kind = 0;
        if (sch_convert_map(cv, nd->items[k], sub, k_dist_keys, "key") < 0)
            return -1;
        const ynode *it = nd->items[k];
        if (isnan(cv->cur_dist->t) || cv->cur_dist->joint < 0)
            return yfail(cv->err, it, sub, "expected both t and joint");
        if (cv->cur_dist_kind != 1 && cv->cur_dist_kind != 2)
            return yfail(cv->err, it, sub, "expected exactly one of impulse or force");
        if (cv->cur_dist_kind == 2 && cv->cur_dist->duration == 0)
            return yfail(cv->err, it, sub, "a force needs a duration (s)");
        if (cv->cur_dist_kind == 1 && cv->cur_dist->duration != 0)
            return yfail(cv->err, it, sub, "an impulse takes no duration");
        lag_diag d; /* the core's check, at once: at this disturbance's key */
        if (lag_disturbance_check(&cv->sc->sim, cv->cur_dist, NULL, &d) != LAG_OK) {
            char key[sizeof sub + LAG_FIELD_MAX + 1];
            snprintf(key, sizeof key, "%s.%s", sub, d.field);
            return yfail(cv->err, ytree_lookup(it, d.field), key, "%s", d.message);
        }
    }
    return 0;
}

/* noise: {seed, q: {joint: std}, qd: {joint: std}}; the published state stays within a
 * few explode_limits (the normal deviates are bounded by about 8.6). */
static int noise_q_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    return sch_get_within_explode(cv, nd, path, &fx(cv)->noise_q[j]);
}

static int noise_qd_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    return sch_get_within_explode(cv, nd, path, &fx(cv)->noise_qd[j]);
}

static int noise_q(conv *cv, const ynode *nd, const char *path)
{
    return sch_per_joint(cv, nd, path, noise_q_joint);
}

static int noise_qd(conv *cv, const ynode *nd, const char *path)
{
    return sch_per_joint(cv, nd, path, noise_qd_joint);
}

static int noise_seed(conv *cv, const ynode *nd, const char *path)
{
    long long v = 0;
    if (sch_get_int(cv, nd, path, 0, 9007199254740991LL, &v) < 0) /* 2^53 - 1: exact in JSON */
        return -1;
    fx(cv)->noise_seed = (uint64_t)v;
    return 0;
}

static const keyrow k_noise_keys[] = {
    {"seed", noise_seed, K_INTEGER}, /* integer, default 1 */
    {"q", noise_q, K_JOINTS},       /* std dev per joint, m or rad */
    {"qd", noise_qd, K_JOINTS},     /* std dev per joint, m/s or rad/s */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_effect_noise(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_NOISE;
    return sch_convert_map(cv, nd, path, k_noise_keys, "key");
}

/* spring: {joint: {k, rest}}: Q = -k (q - rest), N/m or N m/rad; rest in m or rad */
static int spring_k(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_STIFFNESS, &fx(cv)->spring_k[cv->cur_joint]);
}

static int spring_rest(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_within_explode(cv, nd, path, &fx(cv)->spring_rest[cv->cur_joint]);
}

static const keyrow k_spring_keys[] = {
    {"k", spring_k, K_NUMBER},       /* stiffness, N/m or N m/rad */
    {"rest", spring_rest, K_NUMBER}, /* m or rad, within explode_limit; default 0 */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int spring_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    cv->cur_joint = j;
    return sch_convert_map(cv, nd, path, k_spring_keys, "key");
}

static int key_effect_spring(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_SPRING;
    return sch_per_joint(cv, nd, path, spring_joint);
}

const keyrow k_effects[] = {
    {"gravity", key_effect_gravity, K_MAP, k_gravity_keys},
    {"damping", key_effect_damping, K_JOINTS},
    {"friction", key_effect_friction, K_JOINTS, k_friction_keys},
    {"limits", key_effect_limits, K_JOINTS, k_limit_keys, k_limits_extra},
    {"floor", key_effect_floor, K_MAP, k_floor_keys},
    {"actuator", key_effect_actuator, K_JOINTS, k_actuator_keys},
    {"disturbance", key_effect_disturbance, K_LIST, k_dist_keys},
    {"noise", key_effect_noise, K_MAP, k_noise_keys},
    {"spring", key_effect_spring, K_JOINTS, k_spring_keys},
    {NULL, NULL, K_OTHER, NULL, NULL},
};

int key_effects(conv *cv, const ynode *nd, const char *path)
{
    /* `effects:` with nothing = no effects */
    if (ynode_is_null(nd))
        return 0;
    return sch_convert_map(cv, nd, path, k_effects, "effect");
}
