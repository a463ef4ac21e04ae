/*
 * A refused tick names its cause.
 *
 * absurd_effort: an effort of 1e308 (or 1e200, 1e30) used to be reported as whatever the
 *   integrator then ran into ("mass matrix not positive definite" for rk4, Newton for the
 *   Gauss methods, a vanishing step for dopri5). For every model of the table and every
 *   method it must be LAG_ERR_FORCE, blaming an actuated joint, with the state left at
 *   the last good tick and a description naming the joint and explode_limit.
 * not_force: faults that are not the forces' keep their own code: a DIPC falling past a
 *   small explode_limit is LAG_ERR_EXPLODE; a moderate effort runs.
 * impulse: a scheduled impulse that leaves a velocity past explode_limit is LAG_ERR_FORCE
 *   and described as an impulse.
 * max_steps: dopri5's work per tick is bounded: a stick spinning at 8 rad/s with a tick
 *   of 640 s (several hundred thousand steps at rtol 1e-8) stops after max_steps steps
 *   with LAG_ERR_MAX_STEPS, the state left at the tick's start; with a budget that
 *   suffices the same tick completes.
 * singular: lag_model_forward tells a singular mass matrix at a finite state
 *   (LAG_ERR_SINGULAR) from a non-finite argument (LAG_ERR_NONFINITE).
 * event_map: a tick that ends on an event's map (an impulse, a landing) is checked as one
 *   that ends on a step. A stick on its floor with flight (explicit Euler), after 40
 *   ticks at a small effort, given 2.98e7 N m on phi: the tick after the first strong one
 *   bounces off the floor and lands and ends on the free end's impact at phi = 0, whose
 *   impulse leaves phi_dot = -1.57e6 rad/s, past explode_limit = 1e6 (the scene of a
 *   fuzz_sim input, tests/fuzz/sim/crash/floor-impact-ends-tick-past-explode-limit.bin,
 *   with its other effects left out). The tick must be LAG_ERR_EXPLODE, the state left at
 *   the last good tick; every tick reported good within explode_limit.
 */
#include "test_core.h"

static void check_absurd_effort(int arg)
{
    (void)arg;
    const double efforts[] = {1e308, 1e200, 1e30};
    int named = 0, total = 0;
    for (int k = 0; k < LAG_MODEL_COUNT; ++k) {
        const lag_model_info *inf = lag_model_info_get((lag_model_kind)k);
        for (int m = 0; m < LAG_METHOD_COUNT; ++m)
            for (size_t e = 0; e < sizeof efforts / sizeof efforts[0]; ++e) {
                lag_sim_def d = lag_default_sim_def((lag_model_kind)k);
                d.integrator.method = (lag_method)m;
                for (int i = 0; i < inf->nq; ++i) d.q0[i] = inf->angular[i] ? 0.5 : 0.3;
                lag_sim s;
                if (tc_sim_init(&s, &d)) continue;
                ENSURE(tc_advance(&s, 3, false) == 0);
                double q[LAG_MAX_DOF], qd[LAG_MAX_DOF], tau[LAG_MAX_DOF];
                memcpy(q, s.q, sizeof q);
                memcpy(qd, s.qd, sizeof qd);
                for (int i = 0; i < LAG_MAX_DOF; ++i) tau[i] = efforts[e];
                lag_sim_set_input(&s, tau);
                lag_result r = lag_sim_advance(&s, 1, false);
                char text[256];
                lag_sim_fault_describe(&s, text, sizeof text);
                total++;
                bool ok = r == LAG_ERR_FORCE && s.fault.code == LAG_ERR_FORCE &&
                          s.fault.joint >= 0 && s.fault.joint < inf->nq && s.fault.cause >= 0 &&
                          s.fault.cause < inf->nq && inf->actuated[s.fault.cause] &&
                          s.fault.force == efforts[e] &&
                          s.tick == 3 && s.fault.tick == 3 &&
                          memcmp(q, s.q, sizeof q) == 0 && memcmp(qd, s.qd, sizeof qd) == 0 &&
                          strstr(text, "applied force too large") &&
                          strstr(text, inf->joint_names[s.fault.cause]) &&
                          strstr(text, "explode_limit");
                if (!ok)
                    LT_FAIL("%s %s effort %g: %s (%s); tick %lld; '%s'", inf->name,
                            lag_method_name((lag_method)m), efforts[e], lag_result_string(r),
                            r == LAG_ERR_FORCE ? "as expected" : "expected: applied force too large",
                            (long long)s.tick, text);
                else
                    ENSURE(ok);
                named += ok;
            }
    }
    char text[256];
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
    lag_sim s;
    if (tc_sim_init(&s, &d) == 0) {
        double tau[3] = {1e308, 0, 0};
        lag_sim_set_input(&s, tau);
        lag_sim_advance(&s, 1, false);
        lag_sim_fault_describe(&s, text, sizeof text);
        printf("absurd_effort: %d of %d (model, method, effort) named as the applied force; e.g. \"%s\"\n",
               named, total, text);
    }
}

static void check_not_force(int arg)
{
    (void)arg;
    for (int m = 0; m < LAG_METHOD_COUNT; ++m) {
        /* the upright DIPC falls: theta1 passes 0.5 rad after a fraction of a second */
        lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
        d.integrator.method = (lag_method)m;
        d.q0[1] = 0.1;
        d.explode_limit = 0.5;
        lag_sim s;
        if (tc_sim_init(&s, &d)) continue;
        lag_result r = LAG_OK;
        for (int k = 0; k < 5000 && r == LAG_OK; ++k) r = lag_sim_advance(&s, 1, false);
        if (r != LAG_ERR_EXPLODE)
            LT_FAIL("dipc %s falling past explode_limit 0.5: %s, expected %s",
                    lag_method_name((lag_method)m), lag_result_string(r),
                    lag_result_string(LAG_ERR_EXPLODE));
        else
            ENSURE(s.fault.code == LAG_ERR_EXPLODE && s.fault.joint == -1);
        /* a moderate effort: runs */
        lag_sim_def d2 = lag_default_sim_def(LAG_MODEL_DIPC);
        d2.integrator.method = (lag_method)m;
        lag_sim s2;
        if (tc_sim_init(&s2, &d2)) continue;
        double tau[3] = {50, 0, 0};
        lag_sim_set_input(&s2, tau);
        ENSURE(lag_sim_advance(&s2, 100, false) == LAG_OK && s2.fault.code == LAG_OK);
    }
}

static void check_impulse(int arg)
{
    (void)arg;
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    d.q0[1] = 1.0;
    d.effects.enabled = LAG_EFF_DISTURBANCE;
    d.effects.n_disturbances = 1;
    d.effects.disturbances[0] = (lag_disturbance){0.005, 0, true, LAG_FORCE_MAX, 0};
    lag_sim s;
    if (tc_sim_init(&s, &d)) return;
    lag_result r = LAG_OK;
    int k = 0;
    for (; k < 20 && r == LAG_OK; ++k) r = lag_sim_advance(&s, 1, false);
    char text[256];
    lag_sim_fault_describe(&s, text, sizeof text);
    printf("impulse: %s after %d ticks: \"%s\"\n", lag_result_string(r), k, text);
    ENSURE(r == LAG_ERR_FORCE && s.tick == 5 && s.fault.joint == 0 && s.fault.cause == -1);
    ENSURE(strstr(text, "impulse") != NULL);
    ENSURE(isfinite(s.qd[0]) && isfinite(s.qd[1])); /* the last good tick, before the impulse */
}

static void check_singular(int arg)
{
    (void)arg;
    /* manipulator with l1 = I1 = I2 = 0 and the slider on the axis: M_00 = 0 */
    lag_model m;
    lag_model_default(&m, LAG_MODEL_MANIPULATOR);
    m.p[LAG_MANIP_L1] = 0;
    m.p[LAG_MANIP_I1] = 0;
    m.p[LAG_MANIP_I2] = 0;
    double q[2] = {0.3, 0.0}, qd[2] = {0.1, 0.2}, qdd[2];
    ENSURE(lag_model_forward(&m, q, qd, NULL, qdd) == LAG_ERR_SINGULAR);
    lag_model_default(&m, LAG_MODEL_DIPC);
    double q3[3] = {0, NAN, 0.1}, qd3[3] = {0}, qdd3[3];
    ENSURE(lag_model_forward(&m, q3, qd3, NULL, qdd3) == LAG_ERR_NONFINITE);
    q3[1] = INFINITY;
    ENSURE(lag_model_forward(&m, q3, qd3, NULL, qdd3) == LAG_ERR_NONFINITE);
    ENSURE(strcmp(lag_result_string(LAG_ERR_FORCE), lag_result_string(LAG_ERR_SINGULAR)) != 0);
}

static void check_max_steps(int arg)
{
    (void)arg;
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    d.integrator.method = LAG_DOPRI5;
    d.integrator.dt = 640;
    d.q0[0] = 8.2; d.q0[1] = 8.2; d.qd0[0] = 8.2; d.qd0[1] = 8.2;
    d.integrator.max_steps = 1000;
    for (int cont = 0; cont < 2; ++cont) {
        lag_sim s;
        if (tc_sim_init(&s, &d)) return;
        lag_result r = lag_sim_advance(&s, 1, cont);
        int64_t steps = s.stats.steps_accepted + s.stats.steps_rejected;
        printf("max_steps: dopri5 tick of 640 s (%s) with max_steps 1000: %s after %lld steps\n",
               cont ? "continuous" : "hard stop", lag_result_string(r), (long long)steps);
        ENSURE(r == LAG_ERR_MAX_STEPS && s.tick == 0 && s.q[1] == 8.2 && s.qd[1] == 8.2);
        ENSURE(steps <= 1000);
    }
    /* a tick of 6.4 s fits in the default budget */
    d.integrator.dt = 6.4;
    d.integrator.max_steps = lag_default_integrator_def().max_steps;
    lag_sim s;
    if (tc_sim_init(&s, &d)) return;
    ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
    printf("max_steps: a tick of 6.4 s took %lld steps (default max_steps %d)\n",
           (long long)(s.stats.steps_accepted + s.stats.steps_rejected), d.integrator.max_steps);
}
/* The state s holds (the one it publishes) finite and within explode_limit. */
static bool state_within_limit(const lag_sim *s)
{
    for (int i = 0; i < s->nq; ++i)
        if (!(fabs(s->q[i]) <= s->def.explode_limit && fabs(s->qd[i]) <= s->def.explode_limit))
            return false;
    return true;
}

static void check_event_map(int arg)
{
    (void)arg;
    const double a = 2.3644e-4;
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    d.integrator.method = LAG_EULER;
    d.effects.enabled = LAG_EFF_FLOOR;
    d.effects.floor_flight = true;
    d.effects.floor_restitution = 194.0 / 255.0;
    d.q0[0] = d.q0[1] = d.qd0[0] = d.qd0[1] = a;
    static lag_sim s;
    if (tc_sim_init(&s, &d)) return;
    ENSURE(s.nq == 3 && strcmp(lag_sim_contact(&s), "contact") == 0);
    lag_sim_set_input(&s, (const double[LAG_MAX_DOF]){a, a});
    if (tc_advance(&s, 40, false)) return;
    lag_sim_set_input(&s, (const double[LAG_MAX_DOF]){0.0, 2.9812e7});
    lag_result r = LAG_OK;
    double q[LAG_MAX_DOF] = {0}, qd[LAG_MAX_DOF] = {0};
    int k = 0;
    for (; k < 5 && r == LAG_OK; ++k) {
        memcpy(q, s.q, sizeof q);
        memcpy(qd, s.qd, sizeof qd);
        r = lag_sim_advance(&s, 1, false);
        /* good or refused, the state the sim holds is one it may publish */
        ENSUREF(state_within_limit(&s), "tick %lld (%s): q = (%g, %g, %g), qd = (%g, %g, %g) "
                "past explode_limit = %g", (long long)s.tick, lag_result_string(r), s.q[0],
                s.q[1], s.q[2], s.qd[0], s.qd[1], s.qd[2], s.def.explode_limit);
    }
    char text[256];
    lag_sim_fault_describe(&s, text, sizeof text);
    printf("event_map: %s after %d ticks: \"%s\"\n", lag_result_string(r), k, text);
    ENSUREF(r == LAG_ERR_EXPLODE && s.tick == 41 && s.fault.tick == 41,
            "expected state exceeded explode_limit at tick 41, got %s at tick %lld",
            lag_result_string(r), (long long)s.tick);
    ENSURE(memcmp(q, s.q, sizeof q) == 0 && memcmp(qd, s.qd, sizeof qd) == 0);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"absurd_effort", check_absurd_effort, 0, 0},
        {"not_force", check_not_force, 0, 0},
        {"impulse", check_impulse, 0, 0},
        {"max_steps", check_max_steps, 0, 0},
        {"singular", check_singular, 0, 0},
        {"event_map", check_event_map, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
