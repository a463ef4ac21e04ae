/*
 * The event-location engine and the effect table, on their own (server/core/events.c,
 * effects.c; the tests read core_internal.h).
 *
 * hermite: the cubic Hermite interpolant reproduces any cubic exactly (to rounding) and
 *   matches the end values and slopes.
 * capacity: a watcher set holds LAG_MAX_WATCHERS and refuses the next one without writing
 *   past its end; the effect rows' declared maxima fit it (every effect on, a model with
 *   LAG_MAX_DOF coordinates), and a sim with every watcher-making effect on every joint
 *   stays within what its rows declare.
 * locate: on steps whose interpolant is an exact cubic, the crossing of a bound is found
 *   to 1e-13 of the step, at or after the true root (the event has happened there); the
 *   earliest of two is chosen; nothing fires when nothing crosses; a strict watcher
 *   fires when it reaches 0, a non-strict one only below it.
 * impulse: the impact map at joint i leaves J qd+ = -e J qd-, changes the momenta by
 *   J^T P only (the other momenta of our own T unchanged) and never raises the kinetic
 *   energy, for e in [0, 1] and every model of the table.
 * table: one row per bit, bits distinct single bits, names unique, a validate
 *   for each, the classes that follow from the hooks (per-tick = per-tick work or
 *   watchers; events = watchers), watchers with their maps.
 */
#include "test_core.h"
#include "core_internal.h"

/* ---------------------------------------------------------------- hermite */
/* Step of H over x_i(t) = a + b t + c t^2 + d t^3 (two components). */
static void cubic_step(double H, const double co[2][4], double *y0, double *f0, double *y1, double *f1)
{
    for (int i = 0; i < 2; ++i) {
        const double *c = co[i];
        y0[i] = c[0];
        f0[i] = c[1];
        y1[i] = c[0] + c[1] * H + c[2] * H * H + c[3] * H * H * H;
        f1[i] = c[1] + 2 * c[2] * H + 3 * c[3] * H * H;
    }
}

static double cubic_at(const double *c, double t) { return c[0] + c[1] * t + c[2] * t * t + c[3] * t * t * t; }

static void check_hermite(int arg)
{
    (void)arg;
    /* y(t) = a + b t + c t^2 + d t^3 per component over [0, h] */
    const double h = 0.37, co[2][4] = {{1.5, -2.0, 0.7, 3.1}, {-0.2, 0.9, -4.0, 1.25}};
    double y0[2], f0[2], y1[2], f1[2];
    cubic_step(h, co, y0, f0, y1, f1);
    double worst = 0;
    for (int k = 0; k <= 100; ++k) {
        double th = k / 100.0, t = th * h, y[2];
        lag_hermite(2, h, y0, f0, y1, f1, th, y);
        for (int i = 0; i < 2; ++i) worst = fmax(worst, fabs(y[i] - cubic_at(co[i], t)));
    }
    printf("hermite: cubic reproduced to %.1e over 101 points\n", worst);
    ENSURE(worst < 1e-14);
    double ya[2], yb[2];
    lag_hermite(2, h, y0, f0, y1, f1, 0.0, ya);
    lag_hermite(2, h, y0, f0, y1, f1, 1.0, yb);
    ENSURE(ya[0] == y0[0] && ya[1] == y0[1] && yb[0] == y1[0] && yb[1] == y1[1]);
}

/* ---------------------------------------------------------------- capacity */
static void check_capacity(int arg)
{
    (void)arg;
    lag_watch_set ws;
    ws.n = 0;
    lag_watcher canary = {.kind = LAG_WATCH_POSITION, .joint = 7, .bound = 42.0};
    int added = 0;
    for (int k = 0; k < LAG_MAX_WATCHERS + 5; ++k) {
        lag_watcher w = {.kind = LAG_WATCH_POSITION, .joint = (int8_t)(k % 3), .bound = k};
        added += lag_watch_add(&ws, w);
    }
    ENSURE(added == LAG_MAX_WATCHERS && ws.n == LAG_MAX_WATCHERS);
    ENSURE(!lag_watch_add(&ws, canary) && ws.n == LAG_MAX_WATCHERS);
    ENSURE(ws.w[LAG_MAX_WATCHERS - 1].bound == LAG_MAX_WATCHERS - 1);

    /* the rows' declared maxima fit: every joint free with all its watchers, or held
     * (one hold watcher, fewer), plus the global ones */
    int per_joint = 0, global = 0;
    for (int k = 0; k < LAG_EFF_COUNT; ++k) {
        per_joint += lag_effect_rows[k]->max_watch_joint;
        global += lag_effect_rows[k]->max_watch_global;
    }
    int need = LAG_MAX_DOF * (per_joint > 1 ? per_joint : 1) + global;
    printf("capacity: rows declare at most %d watchers per joint and %d global: %d for %d "
           "joints, capacity %d\n", per_joint, global, need, LAG_MAX_DOF, LAG_MAX_WATCHERS);
    ENSURE(need <= LAG_MAX_WATCHERS);

    /* a stick with stops and friction on both joints and the floor: each row adds no more
     * than it declares */
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    d.q0[1] = 1.0;
    d.qd0[0] = 0.5;
    d.qd0[1] = 0.3;
    d.effects.enabled = LAG_EFF_LIMITS | LAG_EFF_FRICTION | LAG_EFF_FLOOR;
    d.effects.floor_flight = false;
    for (int i = 0; i < 2; ++i) {
        d.effects.limit_on[i] = true;
        d.effects.limit_lower[i] = d.q0[i] - 1;
        d.effects.limit_upper[i] = d.q0[i] + 1;
        d.effects.friction_kinetic[i] = d.effects.friction_static[i] = 0.1;
    }
    lag_sim s;
    if (tc_sim_init(&s, &d)) return;
    for (int j = -1; j < 2; ++j)
        for (int k = 0; k < LAG_EFF_COUNT; ++k) {
            const lag_effect_row *r = lag_effect_rows[k];
            if (!r->watch || !(d.effects.enabled & r->bit)) continue;
            ws.n = 0;
            ENSURE(r->watch(&s, j, k, &ws));
            ENSURE(ws.n <= (j < 0 ? r->max_watch_global : r->max_watch_joint));
            for (int w = 0; w < ws.n; ++w) ENSURE(ws.w[w].owner == k);
        }
    ws.n = 0;
    for (int j = 0; j < 2; ++j) ENSURE(lag_effects_watch(&s, j, &ws));
    ENSURE(lag_effects_watch(&s, -1, &ws));
    printf("capacity: a stick with stops, friction and the floor has %d watchers\n", ws.n);
    ENSURE(ws.n == 2 * 2 + 2 + 2 * 1 + 1);

    /* the floor with flight, the stick in the air: stops and friction on x and phi, the
     * floor's stop of h and the other end's gap; on the floor, h's hold replaces both and
     * the free end's two stops come back */
    d.effects.floor_flight = true;
    d.q0[2] = 0.5;
    if (tc_sim_init(&s, &d)) return;
    for (int j = -1; j < 3; ++j)
        for (int k = 0; k < LAG_EFF_COUNT; ++k) {
            const lag_effect_row *r = lag_effect_rows[k];
            if (!r->watch || !(d.effects.enabled & r->bit)) continue;
            ws.n = 0;
            ENSURE(r->watch(&s, j, k, &ws));
            ENSURE(ws.n <= (j < 0 ? r->max_watch_global : r->max_watch_joint));
        }
    ws.n = 0;
    for (int j = 0; j < 3; ++j) ENSURE(lag_effects_watch(&s, j, &ws));
    ENSURE(lag_effects_watch(&s, -1, &ws));
    printf("capacity: the same stick in flight has %d watchers\n", ws.n);
    ENSURE(ws.n == 2 * 2 + 2 + 1 + 1);
    ENSURE(s.nq == 3 && !(s.mode.locked & 4u) && strcmp(lag_sim_contact(&s), "flight") == 0);
    d.q0[2] = 0.0;
    if (tc_sim_init(&s, &d)) return;
    ENSURE((s.mode.locked & 4u) && strcmp(lag_sim_contact(&s), "contact") == 0);
}

/* ---------------------------------------------------------------- locate */
/* The state is a cubic x(t) per component; a watcher on component i against `bound`. */
typedef struct cubic_ctx {
    const lag_watch_set *ws;
    int evals;
} cubic_ctx;

static lag_result eval_cubic(void *vctx, const double *y, double *vals)
{
    cubic_ctx *c = (cubic_ctx *)vctx;
    c->evals++;
    for (int k = 0; k < c->ws->n; ++k) {
        const lag_watcher *w = &c->ws->w[k];
        vals[k] = w->side < 0 ? y[w->joint] - w->bound : w->bound - y[w->joint];
    }
    return LAG_OK;
}

/* The root of c(t) = bound in [a, b] by bisection to the last bit (our own reference). */
static double cubic_root(const double *c, double bound, double a, double b)
{
    double fa = cubic_at(c, a) - bound;
    for (int it = 0; it < 200; ++it) {
        double m = 0.5 * (a + b), fm = cubic_at(c, m) - bound;
        if (m <= a || m >= b) break;
        if ((fa > 0) == (fm > 0)) { a = m; fa = fm; } else b = m;
    }
    return 0.5 * (a + b);
}

static void check_locate(int arg)
{
    (void)arg;
    const double H = 0.01;
    /* x0 rises through 0.3 (upper bound) at some t in (0, H); x1 falls through -0.197
     * (lower bound) later; a third watcher on x1 is never reached */
    const double co[2][4] = {{0.29, 1.5, -20.0, 300.0}, {-0.19, -0.4, -50.0, 100.0}};
    double y0[2], f0[2], y1[2], f1[2];
    cubic_step(H, co, y0, f0, y1, f1);
    lag_watch_set ws = {0};
    lag_watch_add(&ws, (lag_watcher){.kind = LAG_WATCH_POSITION, .joint = 1, .side = -1, .bound = -5.0, .strict = true});
    lag_watch_add(&ws, (lag_watcher){.kind = LAG_WATCH_POSITION, .joint = 1, .side = -1, .bound = -0.197, .strict = true});
    lag_watch_add(&ws, (lag_watcher){.kind = LAG_WATCH_POSITION, .joint = 0, .side = +1, .bound = 0.3, .strict = true});
    cubic_ctx ctx = {&ws, 0};
    double v0[LAG_MAX_WATCHERS];
    eval_cubic(&ctx, y0, v0);
    int which;
    double theta;
    ENSURE(lag_event_locate(2, H, y0, f0, y1, f1, &ws, v0, eval_cubic, &ctx, &which, &theta) == LAG_OK);
    double t0 = cubic_root(co[0], 0.3, 0, H), t1 = cubic_root(co[1], -0.197, 0, H);
    printf("locate: roots at %.17g and %.17g of a step of %g; found watcher %d at theta H = %.17g "
           "(error %.1e, %d evaluations)\n", t0, t1, H, which, theta * H, theta * H - fmin(t0, t1), ctx.evals);
    ENSURE(t0 < t1 && t1 < 0.95 * H && which == 2);
    ENSURE(theta * H >= t0 - 1e-15 && theta * H - t0 <= 1e-13 * H);
    /* the event has happened at theta: the watcher is at or past its bound there */
    double yt[2], vt[LAG_MAX_WATCHERS];
    lag_hermite(2, H, y0, f0, y1, f1, theta, yt);
    eval_cubic(&ctx, yt, vt);
    ENSURE(vt[2] <= 0);

    /* without the first one the other is found */
    lag_watch_set ws2 = {0};
    lag_watch_add(&ws2, ws.w[1]);
    cubic_ctx ctx2 = {&ws2, 0};
    eval_cubic(&ctx2, y0, v0);
    ENSURE(lag_event_locate(2, H, y0, f0, y1, f1, &ws2, v0, eval_cubic, &ctx2, &which, &theta) == LAG_OK);
    ENSURE(which == 0 && theta * H >= t1 - 1e-15 && theta * H - t1 <= 1e-13 * H);

    /* nothing crosses */
    lag_watch_set ws3 = {0};
    lag_watch_add(&ws3, ws.w[0]);
    cubic_ctx ctx3 = {&ws3, 0};
    eval_cubic(&ctx3, y0, v0);
    ENSURE(lag_event_locate(2, H, y0, f0, y1, f1, &ws3, v0, eval_cubic, &ctx3, &which, &theta) == LAG_OK);
    ENSURE(which == -1 && theta == 1.0);

    /* strict: reaching 0 fires; non-strict: only going below it */
    lag_watcher st = {.strict = true}, ns = {.strict = false};
    ENSURE(lag_watch_fired(&st, 1.0, 0.0) && !lag_watch_fired(&st, 0.0, -1.0));
    ENSURE(!lag_watch_fired(&ns, 1.0, 0.0) && lag_watch_fired(&ns, 0.0, -1.0));
}

/* ---------------------------------------------------------------- impulse */
static void check_impulse(int arg)
{
    (void)arg;
    lt_rng rng = {0x1a9u};
    double worst_rel = 0, worst_mom = 0;
    int count = 0;
    for (int kind = 0; kind < LAG_MODEL_COUNT; ++kind)
        for (int it = 0; it < 50; ++it) {
            lag_model md;
            tc_random_model(&rng, (lag_model_kind)kind, &md);
            lag_sim_def d = lag_default_sim_def((lag_model_kind)kind);
            d.model = md;
            tc_random_state(&rng, &md, d.q0, d.qd0);
            lag_sim s;
            if (tc_sim_init(&s, &d)) return;
            const int n = md.nq;
            int i = (int)(lt_next(&rng) % (uint64_t)n);
            double e = lt_uniform(&rng, 0, 1), y[LAG_MAX_STATE];
            for (int k = 0; k < n; ++k) { y[k] = s.q[k]; y[n + k] = s.qd[k]; }
            double T0 = tc_T(&md, y, y + n), v0 = y[n + i], p0[LAG_MAX_DOF];
            for (int k = 0; k < n; ++k) p0[k] = tc_momentum(&md, y, y + n, k);
            ENSURE(lag_impulse_map(&s, y, i, e) == LAG_OK);
            double T1 = tc_T(&md, y, y + n);
            ENSURE_NEAR(y[n + i], -e * v0, 1e-12 * (fabs(v0) + 1), "%s joint %d e %g", lag_model_info_get(md.kind)->name, i, e);
            ENSURE(T1 <= T0 * (1 + 1e-12) + 1e-300);
            /* p+ - p- = J^T P: only momentum i changes */
            for (int k = 0; k < n; ++k) {
                if (k == i) continue;
                double dp = tc_momentum(&md, y, y + n, k) - p0[k], sc = fabs(p0[k]) + T0 + 1;
                ENSURE_NEAR(dp, 0.0, 1e-12 * sc, "momentum %d after an impulse at %d", k, i);
                worst_mom = fmax(worst_mom, fabs(dp) / sc);
            }
            /* energy lost = (1 - e^2) / 2 * v^2 / (M^-1)_ii (our T, exact for the map) */
            double x[LAG_MAX_DOF];
            ENSURE(lag_minv_column(&s, y, i, x) == LAG_OK);
            double lost = 0.5 * (1 - e * e) * v0 * v0 / x[i];
            ENSURE_NEAR(T0 - T1, lost, 1e-11 * (T0 + 1), "energy lost by an impact at %d", i);
            worst_rel = fmax(worst_rel, fabs(T0 - T1 - lost) / (T0 + 1));
            count++;
        }
    printf("impulse: %d impacts on every model: energy lost vs (1 - e^2) v^2 / (2 (M^-1)_ii): %.1e; "
           "other momenta unchanged to %.1e\n", count, worst_rel, worst_mom);
}

/* ---------------------------------------------------------------- table */
static void check_table(int arg)
{
    (void)arg;
    uint32_t all = 0;
    for (int k = 0; k < LAG_EFF_COUNT; ++k) {
        const lag_effect_row *r = lag_effect_rows[k];
        lag_effect_info inf = lag_effect_info_get(k);
        /* one bit each, distinct (the rows' order is the dispatch order, not the bits') */
        ENSURE(r->bit != 0 && (r->bit & (r->bit - 1)) == 0 && !(all & r->bit) && inf.bit == r->bit);
        ENSURE(r->name && r->name[0] && inf.name == r->name && lag_effect_from_name(r->name) == k);
        /* a name: [a-z][a-z0-9-]*, a key under a scene's effects: that is not gravity's (the
         * model's g) and fits the scene message's comma-separated list; a name with a
         * space (the scene fixture's unknown effect) can never be one */
        ENSUREF(r->name && r->name[0] >= 'a' && r->name[0] <= 'z' &&
                strspn(r->name, "abcdefghijklmnopqrstuvwxyz0123456789-") == strlen(r->name) &&
                strcmp(r->name, "gravity") != 0,
                "effect '%s': not a lowercase word that hyphens may join, or gravity's key",
                r->name ? r->name : "(null)");
        ENSURE(r->validate != NULL);
        ENSURE(inf.per_tick == (r->pre_tick != NULL || r->watch != NULL));
        ENSURE(inf.events == (r->watch != NULL) && inf.force == (r->force != NULL) &&
               inf.potential == (r->potential != NULL) && inf.observe == (r->observe != NULL));
        ENSURE(inf.keeps_state == (r->keeps_state != NULL));
        ENSURE((r->watch != NULL) == (r->on_event != NULL));
        ENSURE((r->watch != NULL) == (r->max_watch_joint + r->max_watch_global > 0));
        all |= r->bit;
    }
    ENSURE(all == (1u << LAG_EFF_COUNT) - 1 && lag_effects_known() == all);
    ENSURE(lag_effect_info_get(LAG_EFF_COUNT).name == NULL && lag_effect_from_name("no such effect") == -1);
    /* the classes of the effects known when these were written by hand */
    ENSURE(lag_effects_per_tick(all) == (LAG_EFF_FRICTION | LAG_EFF_LIMITS | LAG_EFF_FLOOR |
                                         LAG_EFF_ACTUATOR | LAG_EFF_DISTURBANCE));
    ENSURE(lag_effects_with_events(all) == (LAG_EFF_FRICTION | LAG_EFF_LIMITS | LAG_EFF_FLOOR));
    ENSURE(lag_effects_per_tick(LAG_EFF_DAMPING | LAG_EFF_NOISE | LAG_EFF_SPRING) == 0);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"hermite", check_hermite, 0, 0},   {"capacity", check_capacity, 0, 0},
        {"locate", check_locate, 0, 0},     {"impulse", check_impulse, 0, 0},
        {"table", check_table, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
