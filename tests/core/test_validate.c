/*
 * Validation: every refusal of lag_sim_def_check names the field at fault (lag_diag.field,
 * the scene file's key path) and says what was expected, so a loader can attach the
 * file:line:column of that key; lag_sim_def_validate and lag_sim_init write
 * "field: message". Each row below breaks one value of a valid definition and names the
 * field that must be blamed.
 */
#include "test_core.h"

typedef struct bad_case {
    lag_model_kind kind;
    const char *field;            /* expected lag_diag.field */
    const char *says;             /* a piece of the expected message */
    void (*brk)(lag_sim_def *d);  /* breaks one value */
} bad_case;

static void neg_m1(lag_sim_def *d) { d->model.p[LAG_DIPC_M1] = -1; }
static void nan_l(lag_sim_def *d) { d->model.p[LAG_STICK_L] = NAN; }
static void neg_g(lag_sim_def *d) { d->model.p[LAG_MANIP_G] = -9.81; }
static void zero_dt(lag_sim_def *d) { d->integrator.dt = 0; }
static void bad_method(lag_sim_def *d) { d->integrator.method = LAG_METHOD_COUNT; }
static void big_dtmin(lag_sim_def *d) { d->integrator.dt_min = 1.0; }
static void bad_iter(lag_sim_def *d) { d->integrator.max_iter = 0; }
static void bad_ntol(lag_sim_def *d) { d->integrator.newton_tol = 1; }
static void bad_steps(lag_sim_def *d) { d->integrator.max_steps = 0; }
static void bad_rtol(lag_sim_def *d) { d->integrator.rtol = -1; }
static void bad_explode(lag_sim_def *d) { d->explode_limit = INFINITY; }
static void nan_q1(lag_sim_def *d) { d->q0[1] = NAN; }
static void big_qd0(lag_sim_def *d) { d->qd0[0] = 2e6; }
static void bad_nq(lag_sim_def *d) { d->model.nq = 3; }
static void bad_bits(lag_sim_def *d) { d->effects.enabled = 1u << 30; }
static void neg_damping(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DAMPING;
    d->effects.damping[2] = -0.1;
}
static void friction_static(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FRICTION;
    d->effects.friction_kinetic[0] = 2;
    d->effects.friction_static[0] = 1;
}
static void limits_lower(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_LIMITS;
    d->effects.limit_on[1] = true;
    d->effects.limit_lower[1] = -INFINITY;
    d->effects.limit_upper[1] = 1;
}
static void limits_upper(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_LIMITS;
    d->effects.limit_on[0] = true;
    d->effects.limit_lower[0] = 1;
    d->effects.limit_upper[0] = 0.5;
}
static void limits_e(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_LIMITS;
    d->effects.limit_on[0] = true;
    d->effects.limit_lower[0] = -1;
    d->effects.limit_upper[0] = 1;
    d->effects.restitution[0] = 1.5;
}
static void limits_q0(lag_sim_def *d)
{
    limits_e(d);
    d->effects.restitution[0] = 0.5;
    d->q0[0] = 2;
}
static void rest_velocity(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FLOOR;
    d->q0[1] = 1;
    d->effects.rest_velocity = -1;
}
static void floor_e(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FLOOR;
    d->q0[1] = 1;
    d->effects.floor_restitution = NAN;
}
static void floor_model(lag_sim_def *d) { d->effects.enabled = LAG_EFF_FLOOR; }
static void actuator_max(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_ACTUATOR;
    d->effects.actuator_max[0] = 0;
}
static void actuator_lag(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_ACTUATOR;
    d->effects.actuator_tau[1] = -1;
}
static void dist_time(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DISTURBANCE;
    d->effects.n_disturbances = 2;
    d->effects.disturbances[0] = (lag_disturbance){0.5, 0, true, 1, 0};
    d->effects.disturbances[1] = (lag_disturbance){-1, 0, true, 1, 0};
}
static void dist_force(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DISTURBANCE;
    d->effects.n_disturbances = 1;
    d->effects.disturbances[0] = (lag_disturbance){0.5, 0, false, NAN, 1};
}
static void dist_duration(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DISTURBANCE;
    d->effects.n_disturbances = 1;
    d->effects.disturbances[0] = (lag_disturbance){0.5, 1, false, 1, 0};
}
static void dist_joint(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DISTURBANCE;
    d->effects.n_disturbances = 1;
    d->effects.disturbances[0] = (lag_disturbance){0.5, 7, true, 1, 0};
}
static void noise_qd(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_NOISE;
    d->effects.noise_qd[1] = -1;
}

static void inf_damping(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DAMPING;
    d->effects.damping[0] = INFINITY;
}
static void friction_kinetic(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FRICTION;
    d->effects.friction_kinetic[1] = -0.5;
    d->effects.friction_static[1] = 1;
}
static void limits_rest_velocity(lag_sim_def *d)
{
    limits_e(d);
    d->effects.restitution[0] = 0.5;
    d->effects.rest_velocity = NAN;
}
static void floor_phi(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FLOOR;
    d->q0[1] = -0.2;
}
static void floor_h(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FLOOR;
    d->q0[1] = 1;
    d->q0[2] = -0.1;
}
static void floor_hd(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FLOOR;
    d->q0[1] = 1;
    d->qd0[2] = NAN;
}
static void floor_no_flight_h(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_FLOOR;
    d->effects.floor_flight = false;
    d->q0[1] = 1;
    d->q0[2] = 0.5;
}
static void dist_count(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DISTURBANCE;
    d->effects.n_disturbances = LAG_MAX_DISTURBANCES + 1;
}
static void dist_impulse(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_DISTURBANCE;
    d->effects.n_disturbances = 1;
    d->effects.disturbances[0] = (lag_disturbance){0.5, 0, true, INFINITY, 0};
}
static void noise_q(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_NOISE;
    d->effects.noise_q[0] = -0.01;
}
static void spring_k(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_SPRING;
    d->effects.spring_k[1] = -2;
}
static void spring_rest(lag_sim_def *d)
{
    d->effects.enabled = LAG_EFF_SPRING;
    d->effects.spring_rest[0] = NAN;
}

static const bad_case bad_cases[] = {
    {LAG_MODEL_DIPC, "parameters.m1", "> 0 (kg)", neg_m1},
    {LAG_MODEL_STICK, "parameters.l", "finite", nan_l},
    {LAG_MODEL_MANIPULATOR, "parameters.g", ">= 0", neg_g},
    {LAG_MODEL_STICK, "model", "coordinates", bad_nq},
    {LAG_MODEL_DIPC, "integrator.dt", "> 0", zero_dt},
    {LAG_MODEL_DIPC, "integrator.method", "unknown", bad_method},
    {LAG_MODEL_DIPC, "integrator.dt_min", "<= dt", big_dtmin},
    {LAG_MODEL_DIPC, "integrator.max_iter", "1..1000", bad_iter},
    {LAG_MODEL_DIPC, "integrator.newton_tol", "(0, 1)", bad_ntol},
    {LAG_MODEL_DIPC, "integrator.max_steps", "1..1e8", bad_steps},
    {LAG_MODEL_DIPC, "integrator.rtol", "> 0", bad_rtol},
    {LAG_MODEL_DIPC, "explode_limit", "finite", bad_explode},
    {LAG_MODEL_DIPC, "initial.q[1]", "finite", nan_q1},
    {LAG_MODEL_STICK, "initial.qd[0]", "explode_limit", big_qd0},
    {LAG_MODEL_DIPC, "effects", "unknown effect", bad_bits},
    {LAG_MODEL_DIPC, "effects.damping.theta2", ">= 0", neg_damping},
    {LAG_MODEL_DIPC, "effects.friction.theta0.static", "kinetic", friction_static},
    {LAG_MODEL_STICK, "effects.limits.phi.lower", "finite", limits_lower},
    {LAG_MODEL_MANIPULATOR, "effects.limits.q1.upper", "> lower", limits_upper},
    {LAG_MODEL_MANIPULATOR, "effects.limits.q1.restitution", "[0, 1]", limits_e},
    {LAG_MODEL_MANIPULATOR, "initial.q[0]", "outside its limits", limits_q0},
    {LAG_MODEL_STICK, "effects.floor.rest_velocity", ">= 0", rest_velocity},
    {LAG_MODEL_STICK, "effects.floor.restitution", "[0, 1]", floor_e},
    {LAG_MODEL_DIPC, "effects.floor", "stick", floor_model},
    {LAG_MODEL_DIPC, "effects.actuator.theta0.max", "> 0", actuator_max},
    {LAG_MODEL_STICK, "effects.actuator.phi.lag", ">= 0", actuator_lag},
    {LAG_MODEL_DIPC, "effects.disturbance[1].t", "a time from 0", dist_time},
    {LAG_MODEL_DIPC, "effects.disturbance[0].force", "a number from -1e+12", dist_force},
    {LAG_MODEL_STICK, "effects.disturbance[0].duration", "a duration from 0.001 s", dist_duration},
    {LAG_MODEL_STICK, "effects.disturbance[0].joint", "no joint", dist_joint},
    {LAG_MODEL_MANIPULATOR, "effects.noise.qd.q2", ">= 0", noise_qd},
    /* every other rule of the effects' settings (the core's check is the truth: a loader's
     * ranges only bound what its syntax can say) */
    {LAG_MODEL_CARTPOLE, "effects.damping.x", "finite", inf_damping},
    {LAG_MODEL_CARTPOLE, "effects.friction.theta.kinetic", ">= 0", friction_kinetic},
    {LAG_MODEL_MANIPULATOR, "effects.limits.rest_velocity", ">= 0", limits_rest_velocity},
    {LAG_MODEL_STICK, "initial.q[1]", "[0, pi]", floor_phi},
    {LAG_MODEL_STICK, "initial.q[2]", "explode_limit", floor_h},
    {LAG_MODEL_STICK, "initial.qd[2]", "finite", floor_hd},
    {LAG_MODEL_STICK, "initial.q[2]", "flight", floor_no_flight_h},
    {LAG_MODEL_STICK, "effects.disturbance", "at most", dist_count},
    {LAG_MODEL_STICK, "effects.disturbance[0].impulse", "a number from -1e+12", dist_impulse},
    {LAG_MODEL_CARTPOLE, "effects.noise.q.x", ">= 0", noise_q},
    {LAG_MODEL_CARTPOLE, "effects.spring.theta.k", ">= 0", spring_k},
    {LAG_MODEL_DIPC, "effects.spring.theta0.rest", "finite", spring_rest},
};

static void check_fields(int arg)
{
    (void)arg;
    int named = 0;
    for (size_t c = 0; c < sizeof bad_cases / sizeof bad_cases[0]; ++c) {
        const bad_case *bc = &bad_cases[c];
        lag_sim_def d = lag_default_sim_def(bc->kind);
        if (bc->kind == LAG_MODEL_STICK) d.q0[1] = 1.0; /* valid before breaking */
        lag_diag g;
        ENSURE(lag_sim_def_check(&d, &g) == LAG_OK);
        bc->brk(&d);
        memset(&g, 0x55, sizeof g); /* the check must write both strings */
        lag_result r = lag_sim_def_check(&d, &g);
        ENSURE(r == LAG_ERR_ARG);
        if (r != LAG_ERR_ARG) continue;
        ENSURE(memchr(g.field, 0, sizeof g.field) && memchr(g.message, 0, sizeof g.message));
        bool ok_field = strcmp(g.field, bc->field) == 0;
        bool ok_msg = strstr(g.message, bc->says) != NULL;
        if (!ok_field || !ok_msg)
            LT_FAIL("case %zu: got field '%s' message '%s'; expected field '%s', message with '%s'",
                    c, g.field, g.message, bc->field, bc->says);
        else
            ENSURE(ok_field && ok_msg);
        named += ok_field;
        /* the message does not repeat the path; the char* form is "field: message" */
        ENSURE(strncmp(g.message, g.field, strlen(g.field)) != 0);
        char err[LAG_FIELD_MAX + LAG_MESSAGE_MAX + 2], want[LAG_FIELD_MAX + LAG_MESSAGE_MAX + 2];
        ENSURE(lag_sim_def_validate(&d, err, sizeof err) == LAG_ERR_ARG);
        snprintf(want, sizeof want, "%s: %s", g.field, g.message);
        ENSURE(strcmp(err, want) == 0);
        lag_sim s;
        ENSURE(lag_sim_init(&s, &d, err, sizeof err) == LAG_ERR_ARG && strcmp(err, want) == 0);
    }
    printf("validate: %d of %zu broken definitions blamed on the expected field\n", named,
           sizeof bad_cases / sizeof bad_cases[0]);
    /* every effect of the core's table has a refusal above, blamed on one of its keys */
    for (int k = 0; k < LAG_EFF_COUNT; ++k) {
        const char *name = lag_effect_info_get(k).name;
        char key[LAG_FIELD_MAX];
        snprintf(key, sizeof key, "effects.%s", name);
        bool found = false;
        for (size_t c = 0; c < sizeof bad_cases / sizeof bad_cases[0]; ++c)
            found |= strncmp(bad_cases[c].field, key, strlen(key)) == 0;
        if (!found) LT_FAIL("effect '%s' has no refused setting in test_validate's cases", name);
        else ENSURE(found);
    }
}

/* lag_model_check blames parameters.<name> with the parameter's unit. */
static void check_model_fields(int arg)
{
    (void)arg;
    for (int k = 0; k < LAG_MODEL_COUNT; ++k) {
        const lag_model_info *inf = lag_model_info_get((lag_model_kind)k);
        for (int i = 0; i < inf->np; ++i) {
            lag_model m;
            lag_model_default(&m, (lag_model_kind)k);
            m.p[i] = NAN;
            lag_diag g;
            char want[LAG_FIELD_MAX];
            snprintf(want, sizeof want, "parameters.%s", inf->param_names[i]);
            ENSURE(lag_model_check(&m, &g) == LAG_ERR_ARG);
            if (strcmp(g.field, want) != 0)
                LT_FAIL("%s: a NaN %s was blamed on '%s'", inf->name, inf->param_names[i], g.field);
            char err[128];
            ENSURE(lag_model_validate(&m, err, sizeof err) == LAG_ERR_ARG &&
                   strncmp(err, want, strlen(want)) == 0);
        }
    }
}

/* Times to tick counts: ceil(t / dt) within 1e-9 dt, saturated at both ends. */
static void check_ticks_ceil(int arg)
{
    (void)arg;
    struct { double t, dt; int64_t want; } c[] = {
        {0.0, 1e-3, 0},
        {-5.0, 1e-3, 0},
        {-INFINITY, 1e-3, 0},
        {1.0, 1e-3, 1000},
        {1.0 + 1e-13, 1e-3, 1000},     /* 1e-10 dt above: counted as on the boundary */
        {1.0 + 1e-11, 1e-3, 1001},     /* 1e-8 dt above: the next one */
        {0.0015, 1e-3, 2},
        {9.2e15, 1e-3, 9200000000000000000},
        {9.3e15, 1e-3, INT64_MAX},     /* 9.3e18 ticks: past INT64_MAX */
        {1e300, 1e-3, INT64_MAX},
        {DBL_MAX, 1e-6, INT64_MAX},
        {INFINITY, 1e-3, INT64_MAX},
        {NAN, 1e-3, INT64_MAX},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; ++i) {
        int64_t got = lag_ticks_ceil(c[i].t, c[i].dt);
        if (got != c[i].want)
            LT_FAIL("lag_ticks_ceil(%g, %g) = %lld, expected %lld", c[i].t, c[i].dt, (long long)got,
                    (long long)c[i].want);
        else
            ENSURE(got == c[i].want);
    }
}

/* The last boundary at or before t, with the same tolerance (1e-9 dt) and saturation. */
static void check_ticks_floor(int arg)
{
    (void)arg;
    struct { double t, dt; int64_t want; } c[] = {
        {0.0, 1e-3, 0},
        {-5.0, 1e-3, 0},
        {1.0, 1e-3, 1000},
        {1.0 - 1e-13, 1e-3, 1000},     /* 1e-10 dt below: counted as on the boundary */
        {1.0 - 1e-11, 1e-3, 999},      /* 1e-8 dt below: the one before */
        {0.0015, 1e-3, 1},
        {0.3, 0.1, 3},                 /* 0.3 / 0.1 = 2.9999999999999996 */
        {9.3e15, 1e-3, INT64_MAX},
        {INFINITY, 1e-3, INT64_MAX},
        {NAN, 1e-3, INT64_MAX},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; ++i) {
        int64_t got = lag_ticks_floor(c[i].t, c[i].dt);
        if (got != c[i].want)
            LT_FAIL("lag_ticks_floor(%g, %g) = %lld, expected %lld", c[i].t, c[i].dt, (long long)got,
                    (long long)c[i].want);
        else
            ENSURE(got == c[i].want);
    }
}

/* A whole number of ticks, within 1e-9 of one; not for a negative, non-finite or
 * unrepresentable count. */
static void check_ticks_exact(int arg)
{
    (void)arg;
    struct { double t, dt; bool ok; int64_t want; } c[] = {
        {0.02, 1e-3, true, 20},
        {0.3, 0.1, true, 3},           /* 2.9999999999999996 ticks */
        {1.0 / 60.0, 1.0 / 600.0, true, 10},
        {0.0, 1e-3, true, 0},
        {0.0025, 1e-3, false, 0},      /* 2.5 ticks */
        {1.0 + 1e-11, 1e-3, false, 0}, /* 1e-8 of a tick off */
        {1.0 + 1e-13, 1e-3, true, 1000},
        {-0.002, 1e-3, false, 0},
        {1e300, 1e-3, false, 0},
        {INFINITY, 1e-3, false, 0},
        {NAN, 1e-3, false, 0},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; ++i) {
        int64_t n = -1;
        bool ok = lag_ticks_exact(c[i].t, c[i].dt, &n);
        if (ok != c[i].ok || (ok && n != c[i].want))
            LT_FAIL("lag_ticks_exact(%g, %g) = %d (%lld), expected %d (%lld)", c[i].t, c[i].dt, ok,
                    (long long)n, c[i].ok, (long long)c[i].want);
        else
            ENSURE(ok == c[i].ok);
    }
}

/* lag_sim_redefine: a definition equal in all but the model's parameters is accepted
 * whatever the bytes of its padding (a copy need not keep them); one that changes the
 * integrator or explode_limit is refused; a stop that leaves out where the run is now is
 * refused in words that say so (not "initial"), and nothing changes. */
static void check_redefine(int arg)
{
    (void)arg;
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_MANIPULATOR);
    char err[LAG_FIELD_MAX + LAG_MESSAGE_MAX + 2];
    static lag_sim s;
    ENSURE(lag_sim_init(&s, &d, err, sizeof err) == LAG_OK);
    ENSURE(lag_sim_advance(&s, 100, false) == LAG_OK);
    static lag_sim_def n;
    memset(&n, 0xA5, sizeof n); /* padding that differs from d's */
    n.model = d.model;
    memset(&n.integrator, 0x5A, sizeof n.integrator);
    n.integrator.method = d.integrator.method;
    n.integrator.dt = d.integrator.dt;
    n.integrator.rtol = d.integrator.rtol;
    n.integrator.atol = d.integrator.atol;
    n.integrator.dt_min = d.integrator.dt_min;
    n.integrator.max_iter = d.integrator.max_iter;
    n.integrator.max_steps = d.integrator.max_steps;
    n.integrator.newton_tol = d.integrator.newton_tol;
    n.explode_limit = d.explode_limit;
    n.effects = d.effects;
    memcpy(n.q0, d.q0, sizeof n.q0);
    memcpy(n.qd0, d.qd0, sizeof n.qd0);
    n.model.p[LAG_MANIP_M2] = 2.5;
    if (lag_sim_redefine(&s, &n, err, sizeof err) != LAG_OK)
        LT_FAIL("a change of m2 alone was refused: %s", err);
    ENSURE(s.def.model.p[LAG_MANIP_M2] == 2.5 && s.tick == 100);
    lag_sim_def m = s.def;
    m.integrator.dt *= 2;
    ENSURE(lag_sim_redefine(&s, &m, err, sizeof err) == LAG_ERR_ARG && strstr(err, "integrator"));
    m = s.def;
    m.explode_limit = 10;
    ENSURE(lag_sim_redefine(&s, &m, err, sizeof err) == LAG_ERR_ARG);
    m = s.def;
    m.effects.enabled |= LAG_EFF_LIMITS;
    double q2 = s.q[1];
    m.effects.limit_lower[1] = q2 + 1.0;
    m.effects.limit_upper[1] = q2 + 2.0;
    m.effects.limit_on[1] = true;
    m.effects.restitution[1] = 0.5;
    ENSURE(lag_sim_redefine(&s, &m, err, sizeof err) == LAG_ERR_ARG);
    if (strncmp(err, "where the run is now, q2 = ", 27) != 0 || strstr(err, "initial"))
        LT_FAIL("a stop that leaves out where q2 is now: '%s'", err);
    ENSURE(!(s.def.effects.enabled & LAG_EFF_LIMITS) && s.q[1] == q2);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"fields", check_fields, 0, 0},
        {"model_fields", check_model_fields, 0, 0},
        {"ticks_ceil", check_ticks_ceil, 0, 0},
        {"ticks_floor", check_ticks_floor, 0, 0},
        {"ticks_exact", check_ticks_exact, 0, 0},
        {"redefine", check_redefine, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
