/*
 * The live error estimate (lag_sim_shadow_error: step doubling for the fixed-step methods,
 * a tighter tolerance for dopri5) against the truth it estimates: the error one control period of the
 * running integration adds. For each period of an unforced run of a shipped scene, the
 * true per-period error is max_i |q_i(method) - q_i(reference)| after one period, both
 * started from the same state (the method's own state at the period's start); the
 * reference is 2-stage Gauss-Legendre at period / 1024 (implicit, independent of both
 * estimators; its own error per period is below 1e-15 here). The claim checked: over the
 * periods whose true error stands above the reference's own (1e-12), the estimate is
 * within 10 times of the truth, in each period. On the chaotic DIPC (config/dipc.yaml,
 * released off upright: it falls and tumbles) and on the manipulator
 * (config/manipulator.yaml, released spinning: qd = (3 rad/s, 0.5 m/s)), with rk4,
 * gauss4 and dopri5 at two tolerances, over 4 s (400 periods; at least 50 must have a
 * true error above the floor). Also: the shadow never changes the run (bit-identical states with it on in
 * every period and off), and it refuses what it cannot estimate.
 *
 * Under the sanitizers (lt_span) the run still covers the 4 s and is estimated in every
 * period, but the reference, which costs most, is run for every 4th period only: the claim
 * is checked in those 100 periods, at least 12 of them above the floor.
 */
#include "lagsim_test.h"
#include "scene.h"

#define RUN_S 4.0
#define REF_SUB 1024
#define TRUTH_FLOOR 1e-12
#define FACTOR 10.0
#define MIN_COUNTED 50 /* periods above the floor, of the 400 compared */

typedef struct live_case {
    const char *name, *scene;
    lag_method method;
    double dt_per_period; /* the method's dt as a fraction of the period (0: the scene's) */
    double tol;           /* dopri5 */
    double qd0[2];        /* the manipulator: released with these velocities (rad/s, m/s) */
} live_case;

static const live_case cases[] = {
    {"dipc_rk4", "dipc.yaml", LAG_RK4, 0, 0},
    {"dipc_rk4_coarse", "dipc.yaml", LAG_RK4, 1.0, 0},
    {"dipc_dopri5_1e-6", "dipc.yaml", LAG_DOPRI5, 1.0, 1e-6},
    {"dipc_dopri5_1e-9", "dipc.yaml", LAG_DOPRI5, 1.0, 1e-9},
    {"dipc_gauss4", "dipc.yaml", LAG_GAUSS4, 0.25, 0},
    /* at the scene's dt (1 ms) rk4's error per period stays below 1e-12 here */
    {"manipulator_rk4", "manipulator.yaml", LAG_RK4, 1.0, 0, {3, 0.5}},
    {"manipulator_gauss4", "manipulator.yaml", LAG_GAUSS4, 0.5, 0, {3, 0.5}},
    {"manipulator_dopri5_1e-6", "manipulator.yaml", LAG_DOPRI5, 1.0, 1e-6, {3, 0.5}},
    {"manipulator_dopri5_1e-9", "manipulator.yaml", LAG_DOPRI5, 1.0, 1e-9, {3, 0.5}},
};
#define NCASES ((int)(sizeof cases / sizeof cases[0]))

static int load(const live_case *c, lag_scene *sc, lag_sim *s)
{
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/config/%s", LAGSIM_SOURCE_DIR, c->scene);
    if (lag_scene_load(path, NULL, 0, sc, err, sizeof err) != 0) {
        LT_FAIL("%s", err);
        return -1;
    }
    const double period = 1.0 / sc->publish_hz;
    sc->sim.integrator.method = c->method;
    if (c->dt_per_period > 0) sc->sim.integrator.dt = period * c->dt_per_period;
    if (c->tol > 0) sc->sim.integrator.rtol = sc->sim.integrator.atol = c->tol;
    if (c->qd0[0] != 0 || c->qd0[1] != 0)
        for (int i = 0; i < 2; i++) sc->sim.qd0[i] = c->qd0[i];
    if (lag_sim_init(s, &sc->sim, err, sizeof err) != LAG_OK) {
        LT_FAIL("%s", err);
        return -1;
    }
    return 0;
}

/* The reference's q after one period from START's state and input. OUT: q */
static int reference(const lag_sim *start, double period, double *q)
{
    static lag_sim r;
    r = *start;
    const double dt = period / REF_SUB;
    r.def.integrator.method = LAG_GAUSS4;
    r.def.integrator.dt = dt;
    r.def.integrator.newton_tol = 1e-15;
    r.tick = llround(lag_sim_time(start) / dt);
    r.dp.valid = false;
    if (lag_sim_advance(&r, REF_SUB, false) != LAG_OK) return -1;
    for (int i = 0; i < r.nq; i++) q[i] = r.q[i];
    return 0;
}

static void case_live(int arg)
{
    const live_case *c = &cases[arg];
    static lag_scene sc;
    static lag_sim s, start;
    if (load(c, &sc, &s) != 0) return;
    const double period = 1.0 / sc.publish_hz;
    const int64_t per = c->dt_per_period > 0 ? llround(1.0 / c->dt_per_period) : sc.ticks_per_period;
    const int nper = (int)llround(RUN_S / period);
    const int stride = (int)lt_span(1, 4); /* compare every stride-th period */
    int counted = 0, outside = 0, compared = 0;
    double worst_hi = 0, worst_lo = INFINITY, sum_log = 0;
    double est[LAG_MAX_DOF], qref[LAG_MAX_DOF];
    for (int k = 0; k < nper; k++) {
        start = s;
        if (lag_sim_advance_within(&s, per, s.tick + per) != LAG_OK) {
            LT_FAIL("%s: the run faulted at period %d", c->name, k);
            return;
        }
        ENSURE(lag_sim_shadow_error(&start, &s, est) == LAG_OK);
        for (int i = 0; i < s.nq; i++) ENSURE(isfinite(est[i]) && est[i] >= 0);
        if (k % stride != 0) continue;
        compared++;
        if (reference(&start, period, qref) != 0) {
            LT_FAIL("%s: the reference faulted at period %d", c->name, k);
            return;
        }
        double truth = 0, e = 0;
        for (int i = 0; i < s.nq; i++) {
            truth = fmax(truth, fabs(s.q[i] - qref[i]));
            e = fmax(e, est[i]);
        }
        if (truth < TRUTH_FLOOR) continue;
        counted++;
        double ratio = e / truth;
        sum_log += log10(ratio);
        worst_hi = fmax(worst_hi, ratio);
        worst_lo = fmin(worst_lo, ratio);
        if (ratio > FACTOR || ratio < 1.0 / FACTOR) {
            if (outside++ < 5)
                fprintf(stderr, "%s: t = %.2f s: estimate %.3g, true %.3g (ratio %.3g)\n",
                        c->name, lag_sim_time(&start), e, truth, ratio);
        }
    }
    printf("%s: %d of %d periods compared (of %d) above %g; estimate/true from %.3g to %.3g "
           "(geometric mean %.3g); %d outside [1/%g, %g]\n", c->name, counted, compared, nper,
           TRUTH_FLOOR, worst_lo, worst_hi, counted ? pow(10, sum_log / counted) : 0.0, outside,
           FACTOR, FACTOR);
    ENSURE(counted >= MIN_COUNTED / stride); /* the comparison says something */
    ENSURE(outside == 0);
}

/* The shadow leaves the run as it was: every state of a run estimated in every period is
 * bit-identical to that of a run never estimated; so is dopri5's with its sum read. */
static void case_unchanged(int arg)
{
    const live_case *c = &cases[arg];
    static lag_scene sc;
    static lag_sim a, b, start;
    if (load(c, &sc, &a) != 0) return;
    char err[256];
    ENSURE(lag_sim_init(&b, &sc.sim, err, sizeof err) == LAG_OK);
    const int64_t per = c->dt_per_period > 0 ? llround(1.0 / c->dt_per_period) : sc.ticks_per_period;
    double est[LAG_MAX_DOF];
    int same = 1;
    for (int k = 0; k < 300; k++) {
        start = a;
        ENSURE(lag_sim_advance_within(&a, per, a.tick + per) == LAG_OK);
        ENSURE(lag_sim_advance_within(&b, per, b.tick + per) == LAG_OK);
        ENSURE(lag_sim_shadow_error(&start, &a, est) == LAG_OK);
        if (memcmp(a.q, b.q, sizeof a.q) || memcmp(a.qd, b.qd, sizeof a.qd) || a.tick != b.tick)
            same = 0;
    }
    ENSURE(same);
}

/* What the shadow cannot estimate: an empty span, a span of other settings. */
static void case_refusals(int arg)
{
    (void)arg;
    static lag_scene sc;
    static lag_sim s, start;
    double est[LAG_MAX_DOF] = {1, 1, 1};
    for (int c = 0; c < 3; c += 2) { /* rk4, dopri5 */
        if (load(&cases[c], &sc, &s) != 0) return;
        start = s;
        ENSURE(lag_sim_shadow_error(&start, &s, est) == LAG_ERR_ARG); /* no span */
        ENSURE(est[0] == 0 && est[1] == 0 && est[2] == 0);
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        start.def.integrator.dt *= 2;
        start.def.integrator.rtol *= 2;
        est[0] = 1;
        ENSURE(lag_sim_shadow_error(&start, &s, est) == LAG_ERR_ARG);
        ENSURE(est[0] == 0);
    }
}

int main(int argc, char **argv)
{
    static lt_cases cs;
    static char names[2 * NCASES][96];
    for (int i = 0; i < NCASES; i++) {
        lt_add(&cs, cases[i].name, case_live, i, 0);
        snprintf(names[i], sizeof names[i], "unchanged_%s", cases[i].name);
        lt_add(&cs, names[i], case_unchanged, i, 0);
    }
    lt_add(&cs, "refusals", case_refusals, 0, 0);
    return lt_main(argc, argv, cs.c, cs.n);
}
