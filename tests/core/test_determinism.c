/*
 * Determinism.
 *
 * rerun: the same lag_sim run twice from a fresh init, and once more after lag_sim_reset,
 * gives bit-identical states (memcmp of q and qd) for every model and every method, with a
 * time-varying input set every tick; dopri5 in both modes. Sim time is tick * dt,
 * computed, so it must equal that product exactly.
 *
 * golden_<model>: across builds and machines (Box2D's test_determinism.c). For every
 * method, two fixed scenes of the model (bare, and with every effect that applies to it)
 * are run for 1 s with an input pattern made of integers (no libm in the test's own
 * numbers), and a 64-bit hash of every tick's state, published (noisy) state and events
 * is compared with the value in golden_hashes.h. What the hash depends on, and so what a
 * build must keep to reproduce it:
 *   - IEEE double arithmetic without contraction: the core is built with
 *     -ffp-contract=off (an FMA rounds once where a*b + c rounds twice; GCC contracts by
 *     default wherever the target has FMA, clang within expressions), and never with
 *     -ffast-math (reassociation);
 *   - the same results from libm's sin, cos, exp, log and pow. These are not correctly
 *     rounded, and glibc itself picks one of two implementations at run time on x86-64
 *     (with FMA and AVX2, or without): their last bits differ (seen with
 *     GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA). So the goldens are recorded per libm,
 *     identified by a fingerprint (a hash of those functions at fixed arguments). On a
 *     libm without recorded goldens the case says so and is skipped (exit 77), never
 *     passed; the rerun case still holds everywhere;
 *   - the hash reads values, not bytes (so byte order does not matter).
 * The goldens were recorded before the core's tables (models, integrators, effects) were
 * introduced, and pin that every later change of structure left every trajectory exactly
 * as it was. A change that means to alter trajectories must say so and record new values:
 *   LAGSIM_PRINT_GOLDEN=1 build/bin/test_core_determinism golden_<model>
 * prints the table rows. A model without its rows fails here (it prints them).
 */
#include "test_core.h"
#include "golden_hashes.h"

#define NT 500

typedef struct { double q[NT][3], qd[NT][3]; } trace;

static int run(const lag_sim_def *def, lag_sim *s, bool fresh, bool continuous, trace *tr)
{
    if (fresh) {
        if (tc_sim_init(s, def)) return -1;
    } else {
        lag_sim_reset(s, NULL, NULL);
    }
    for (int k = 0; k < NT; ++k) {
        double tau[3] = {sin(0.01 * k), cos(0.013 * k), 0.5 * sin(0.007 * k)};
        lag_sim_set_input(s, tau);
        if (tc_advance(s, 1, continuous)) return -1;
        memcpy(tr->q[k], s->q, sizeof tr->q[k]);
        memcpy(tr->qd[k], s->qd, sizeof tr->qd[k]);
        ENSURE(lag_sim_time(s) == (double)s->tick * def->integrator.dt);
    }
    return 0;
}

static void check_rerun(int arg)
{
    (void)arg;
    static trace a, b, c;
    lt_rng rng = {0xde7u};
    int identical = 0, total = 0;
    for (int kind = 0; kind < LAG_MODEL_COUNT; ++kind) {
        lag_model md;
        tc_random_model(&rng, (lag_model_kind)kind, &md);
        double q0[3] = {0}, qd0[3] = {0};
        tc_random_state(&rng, &md, q0, qd0);
        for (int i = 0; i < md.nq; ++i) qd0[i] = lt_uniform(&rng, -1, 1);
        tc_motion_start(&rng, &md, q0);
        for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
            for (int cont = 0; cont < (tc_method(mi)->adaptive ? 2 : 1); ++cont) {
                lag_sim_def def = tc_sim_def(&md, (lag_method)mi, 2e-3, q0, qd0);
                lag_sim s1, s2;
                if (run(&def, &s1, true, cont, &a) || run(&def, &s2, true, cont, &b) ||
                    run(&def, &s1, false, cont, &c))
                    continue;
                bool same_fresh = memcmp(&a, &b, sizeof a) == 0;
                bool same_reset = memcmp(&a, &c, sizeof a) == 0;
                ENSURE(same_fresh);
                ENSURE(same_reset);
                /* and the run did move: the check is not vacuous */
                ENSURE(memcmp(a.q[0], a.q[NT - 1], sizeof a.q[0]) != 0);
                if (!same_fresh || !same_reset)
                    fprintf(stderr, "  ^ %s %s%s: fresh rerun %s, after reset %s\n",
                            lag_model_info_get(md.kind)->name, lag_method_name(def.integrator.method),
                            cont ? " (continuous)" : "", same_fresh ? "identical" : "DIFFERS",
                            same_reset ? "identical" : "DIFFERS");
                identical += same_fresh && same_reset;
                total++;
            }
        }
    }
    printf("determinism: %d of %d (model, method, mode) runs bit-identical on rerun and after reset\n",
           identical, total);
}

/* ---------------------------------------------------------------- chunks */

/* A span of ticks advanced in chunks with lag_sim_advance_within (as the daemon runs a
 * long control period) is bit-identical to one hard-stop call for the span, for every model
 * and method, with the input changed between spans. dopri5 steps across the chunks' ends
 * and must take the steps of one call, landing on the span's end; two tolerances (one
 * loose enough that steps are rejected) and random spans and chunk lengths. The case fails
 * if no dopri5 step ever crossed a chunk's end or none was rejected (it would show
 * nothing). */
static void check_chunks(int arg)
{
    (void)arg;
    lt_rng rng = {0xc4u};
    int identical = 0, total = 0;
    int64_t crossed = 0, rejected = 0;
    for (int kind = 0; kind < LAG_MODEL_COUNT; ++kind) {
        lag_model md;
        tc_random_model(&rng, (lag_model_kind)kind, &md);
        double q0[3] = {0}, qd0[3] = {0};
        tc_random_state(&rng, &md, q0, qd0);
        tc_motion_start(&rng, &md, q0);
        for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
            const bool adaptive = tc_method(mi)->adaptive;
            for (int tol = 0; tol < (adaptive ? 2 : 1); ++tol) {
                lag_sim_def def = tc_sim_def(&md, (lag_method)mi, 1e-3, q0, qd0);
                if (tol) { def.integrator.rtol = 1e-3; def.integrator.atol = 1e-5; }
                static lag_sim one, chunked;
                if (tc_sim_init(&one, &def) || tc_sim_init(&chunked, &def)) continue;
                bool same = true;
                for (int p = 0; p < 12 && same; ++p) {
                    const int64_t span = 40 + (int64_t)(lt_next(&rng) % 200);
                    const int64_t stop = chunked.tick + span;
                    double tau[LAG_MAX_DOF] = {0};
                    for (int i = 0; i < md.nq; ++i) tau[i] = lt_uniform(&rng, -0.5, 0.5);
                    lag_sim_set_input(&one, tau);
                    lag_sim_set_input(&chunked, tau);
                    if (tc_advance(&one, span, false)) { same = false; break; }
                    while (chunked.tick < stop) {
                        int64_t n = 1 + (int64_t)(lt_next(&rng) % 70);
                        if (n > stop - chunked.tick) n = stop - chunked.tick;
                        lag_result r = lag_sim_advance_within(&chunked, n, stop);
                        if (r != LAG_OK) {
                            LT_FAIL("lag_sim_advance_within: %s", lag_result_string(r));
                            same = false;
                            break;
                        }
                        if (adaptive && chunked.tick < stop && chunked.dp.t > lag_sim_time(&chunked))
                            crossed++;
                    }
                    same = same && one.tick == chunked.tick &&
                           memcmp(one.q, chunked.q, sizeof one.q) == 0 &&
                           memcmp(one.qd, chunked.qd, sizeof one.qd) == 0;
                }
                if (adaptive) rejected += one.stats.steps_rejected;
                if (!same)
                    LT_FAIL("%s %s rtol %g: chunked span differs from one call at tick %lld: "
                            "q0 %.17g vs %.17g",
                            lag_model_info_get(md.kind)->name, lag_method_name(def.integrator.method),
                            def.integrator.rtol, (long long)one.tick, chunked.q[0], one.q[0]);
                else
                    ENSURE(same);
                identical += same;
                total++;
            }
        }
    }
    ENSURE(crossed > 0);  /* else no step crossed a chunk's end: the case shows nothing */
    ENSURE(rejected > 0); /* else the loose tolerance does not bite */
    printf("chunks: %d of %d (model, method, tolerance) runs bit-identical to one call; "
           "%lld chunks ended inside a dopri5 step, %lld steps rejected\n",
           identical, total, (long long)crossed, (long long)rejected);
}

/* ---------------------------------------------------------------- golden hashes */

/* FNV-1a over 64-bit words: hashes values, so the result does not depend on byte order. */
static uint64_t hash_u64(uint64_t h, uint64_t v)
{
    for (int b = 0; b < 8; ++b) {
        h ^= (v >> (8 * b)) & 0xffu;
        h *= 0x100000001b3ull;
    }
    return h;
}
static uint64_t hash_f64(uint64_t h, double x)
{
    uint64_t v;
    memcpy(&v, &x, sizeof v);
    return hash_u64(h, v);
}

/* The golden scenes of a model: initial state from the coordinates' kinds, and for
 * `effects` every effect the core accepts for this model (an effect whose validation
 * refuses the model, e.g. the stick's floor elsewhere, is left out). */
static lag_sim_def golden_def(lag_model_kind kind, lag_method meth, bool effects)
{
    const lag_model_info *inf = lag_model_info_get(kind);
    lag_sim_def d = lag_default_sim_def(kind);
    d.integrator.method = meth;
    d.integrator.dt = 2e-3;
    for (int i = 0; i < inf->nq; ++i) {
        d.q0[i] = inf->angular[i] ? 0.7 - 0.25 * i : 0.4 + 0.1 * i;
        d.qd0[i] = 0.3 - 0.2 * i;
    }
    if (!effects) return d;
    lag_effects_def *e = &d.effects;
    e->enabled = LAG_EFF_DAMPING | LAG_EFF_FRICTION | LAG_EFF_LIMITS | LAG_EFF_ACTUATOR |
                 LAG_EFF_DISTURBANCE | LAG_EFF_NOISE;
    for (int i = 0; i < inf->nq; ++i) {
        e->damping[i] = 0.05;
        e->noise_q[i] = 1e-3;
        e->noise_qd[i] = 2e-3;
        e->actuator_max[i] = 0.2;
        e->actuator_tau[i] = 0.002;
    }
    e->friction_static[0] = 0.3;
    e->friction_kinetic[0] = 0.2;
    e->limit_on[0] = true;
    e->limit_lower[0] = d.q0[0] - 0.05;
    e->limit_upper[0] = d.q0[0] + 0.08;
    e->restitution[0] = 0.5;
    e->noise_seed = 3;
    e->n_disturbances = 2;
    e->disturbances[0] = (lag_disturbance){0.1, 0, true, 0.2, 0.0};
    e->disturbances[1] = (lag_disturbance){0.2, inf->nq - 1, false, 0.5, 0.05};
    lag_sim_def f = d;
    f.effects.enabled |= LAG_EFF_FLOOR;
    f.effects.floor_restitution = 0.4;
    f.effects.floor_flight = false; /* the flight rows are the flying stick's, and the floor scenes of test_flight */
    char err[256];
    if (lag_sim_def_validate(&f, err, sizeof err) == LAG_OK) return f;
    return d;
}

/* 500 ticks of 2 ms with input u_i(k) = ((37 k + 11 i) mod 101 - 50) / 50 (exact doubles);
 * dopri5 in continuous mode for the bare scene. Hashes, every tick: the result code, q,
 * qd, the published state and each event. */
static uint64_t golden_run(const lag_sim_def *def, bool continuous)
{
    uint64_t h = 0xcbf29ce484222325ull;
    lag_sim s;
    if (tc_sim_init(&s, def)) return 0;
    const int n = s.nq;
    for (int k = 0; k < 500; ++k) {
        double tau[LAG_MAX_DOF] = {0};
        for (int i = 0; i < n; ++i) tau[i] = (double)((37 * k + 11 * i) % 101 - 50) / 50.0;
        lag_sim_set_input(&s, tau);
        lag_result r = lag_sim_advance(&s, 1, continuous);
        h = hash_u64(h, (uint64_t)r);
        double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
        lag_sim_observe(&s, q, qd);
        for (int i = 0; i < n; ++i) {
            h = hash_f64(h, s.q[i]);
            h = hash_f64(h, s.qd[i]);
            h = hash_f64(h, q[i]);
            h = hash_f64(h, qd[i]);
        }
        lag_event ev;
        while (lag_sim_poll_event(&s, &ev)) {
            h = hash_u64(h, (uint64_t)ev.kind);
            h = hash_u64(h, (uint64_t)(int64_t)ev.joint);
            h = hash_f64(h, ev.t);
            h = hash_f64(h, ev.value);
        }
        if (r != LAG_OK) break;
    }
    return h;
}

/* Which libm this is: a hash of the functions the core calls, at fixed arguments. */
static uint64_t libm_fingerprint(void)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (int k = 0; k < 4096; ++k) {
        double x = -12.0 + 0.0061728394 * k, s, c;
        sincos(x, &s, &c);
        h = hash_f64(h, sin(x));
        h = hash_f64(h, cos(x));
        h = hash_f64(h, s);
        h = hash_f64(h, c);
        h = hash_f64(h, exp(0.25 * x));
        h = hash_f64(h, log(fabs(x) + 1e-3));
        h = hash_f64(h, pow(fabs(x) + 0.5, -0.2));
    }
    return h;
}

static void check_golden(int kind)
{
    const char *model = lag_model_info_get((lag_model_kind)kind)->name;
    const bool print = getenv("LAGSIM_PRINT_GOLDEN") != NULL;
    const uint64_t libm = libm_fingerprint();
    bool known = false;
    for (size_t i = 0; i < sizeof golden_libms / sizeof golden_libms[0]; ++i)
        known |= golden_libms[i].fingerprint == libm;
    if (!known && !print) {
        lt_skip("golden %s: no goldens recorded for this libm (fingerprint 0x%016llx; see "
                "golden_hashes.h)", model, (unsigned long long)libm);
        return;
    }
    int matched = 0, total = 0;
    for (int m = 0; m < LAG_METHOD_COUNT; ++m) {
        const char *method = lag_method_name((lag_method)m);
        for (int fx = 0; fx < 2; ++fx) {
            const char *scene = fx ? "effects" : "bare";
            lag_sim_def def = golden_def((lag_model_kind)kind, (lag_method)m, fx);
            uint64_t h = golden_run(&def, !fx);
            const golden_hash *g = NULL;
            for (size_t i = 0; i < sizeof golden_hashes / sizeof golden_hashes[0]; ++i)
                if (golden_hashes[i].libm == libm && !strcmp(golden_hashes[i].model, model) &&
                    !strcmp(golden_hashes[i].method, method) && !strcmp(golden_hashes[i].scene, scene))
                    g = &golden_hashes[i];
            if (print)
                printf("    {0x%016llxull, \"%s\", \"%s\", \"%s\", 0x%016llxull},\n",
                       (unsigned long long)libm, model, method, scene, (unsigned long long)h);
            total++;
            if (!g) {
                LT_FAIL("no golden hash for (%s, %s, %s): computed 0x%016llx (see golden_hashes.h)",
                        model, method, scene, (unsigned long long)h);
                continue;
            }
            if (g->hash != h)
                LT_FAIL("(%s, %s, %s): hash 0x%016llx, golden 0x%016llx: the trajectory changed",
                        model, method, scene, (unsigned long long)h, (unsigned long long)g->hash);
            else
                ENSURE(g->hash == h);
            matched += g->hash == h;
        }
    }
    printf("golden %s: %d of %d (method, scene) hashes as recorded\n", model, matched, total);
}

/* Cases: rerun, chunks, and golden_<model> for each model of the core's table. */
int main(int argc, char **argv)
{
    static char names[LAG_MODEL_COUNT][64];
    lt_cases cs = {0};
    lt_add(&cs, "rerun", check_rerun, 0, 0);
    lt_add(&cs, "chunks", check_chunks, 0, 0);
    for (int k = 0; k < LAG_MODEL_COUNT; ++k) {
        snprintf(names[k], sizeof names[k], "golden_%s", lag_model_info_get((lag_model_kind)k)->name);
        lt_add(&cs, names[k], check_golden, k, 0);
    }
    return lt_main(argc, argv, cs.c, cs.n);
}
