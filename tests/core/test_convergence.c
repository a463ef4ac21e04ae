/*
 * Convergence order of every integrator, on every model: one case per model of the core's
 * table, plus long_run.
 *
 * The scene is the model's smooth reference motion (tests/common/ref_models.h: e.g. the
 * DIPC hanging down and swinging, the manipulator swinging below the horizontal with its
 * slider moving) with its default parameters, over its horizon T (0.4 .. 1 s). The
 * reference trajectory is
 * computed here, with no core code at all: classical RK4 at h = 1e-4 s over our own
 * forward dynamics from T and U (tc_forward_own). Its error, ~ (rate h)^4 ~ 1e-13 for
 * rates ~ 5/s, is checked by comparing with the same run at h = 2e-4 (must agree to 1e-11)
 * and is far below the smallest error measured below (~1e-8).
 *
 * Error = max over (q, qd) components and over t = T/10, 2T/10, ..., T of |y - y_ref| (a
 * maximum over times: at a single instant the leading error term may happen to pass near
 * zero and fake a higher order). For each fixed-step
 * method the fitted slope of log(error) vs log(dt) over four dt must be within +-0.3 of
 * its order: the dt ranges (first N = 1000 ticks per T for order 1, 100 for order 2, 40
 * for higher orders, then doubled three times) put the errors in the asymptotic range
 * (ratios per halving printed), and +-0.3 leaves room for the next-order term over a
 * factor-8 range of dt (a relative contribution c dt changes the fitted slope by
 * ~ c dt_max / ln 8) while still telling order 1 from 2 and 4 from 5.
 *
 * Adaptive methods: error against tolerance (rtol 1e-4 .. 1e-10): must decrease at every
 * step and at rtol 1e-10 agree with the reference to 1e-7, both with the last step
 * shortened to the tick (one tick of T) and with dense (continuous) output on a grid of
 * T/100, checked at every grid point.
 *
 * long_run: canonical methods over a long run (DIPC hanging, 100 s): max energy error in
 * the last tenth at most twice that in the first tenth (no drift); rk4 at the same dt
 * drifts, which shows the check can tell (its last tenth must exceed its first by 3x).
 */
#include "test_core.h"

static double max_err(int n, const double *q, const double *qd, const double *yref)
{
    double e = 0;
    for (int i = 0; i < n; ++i) e = fmax(e, fmax(fabs(q[i] - yref[i]), fabs(qd[i] - yref[n + i])));
    return e;
}

/* The reference motion recorded every T/100 (rec[k] at t = k T / 100). */
static double rec[101][6];

/* One run of the core over T with N ticks (N a multiple of 10); returns the largest
 * error at t = T/10, 2T/10, ..., T (a maximum over times, so that an error that happens
 * to pass near zero at one instant does not fake a higher order). */
static double run_err(const lag_model *md, lag_method meth, double T, int N, const double *q0,
                      const double *qd0)
{
    lag_sim_def def = tc_sim_def(md, meth, T / N, q0, qd0);
    lag_sim s;
    if (tc_sim_init(&s, &def)) return NAN;
    double e = 0;
    for (int j = 1; j <= 10; ++j) {
        if (tc_advance(&s, N / 10, false)) return NAN;
        e = fmax(e, max_err(md->nq, s.q, s.qd, rec[10 * j]));
    }
    ENSURE(s.tick == N);
    return e;
}

static void check_orders(lag_model_kind kind)
{
    const tc_ref *ref = tc_ref_of(kind);
    lag_model md;
    lag_model_default(&md, kind);
    const double *q0 = ref->q0, *qd0 = ref->qd0;
    double yref[6], ycheck[6];
    const char *name = lag_model_info_get(kind)->name;
    const double T = ref->T;
    const int nref = (int)lround(T / 1e-4);
    tc_reference_run(&md, q0, qd0, T / nref, nref, yref, rec, nref / 100);
    tc_reference_run(&md, q0, qd0, 2 * T / nref, nref / 2, ycheck, NULL, 0);
    double refcheck = max_err(md.nq, ycheck, ycheck + md.nq, yref);
    ENSURE_NEAR(refcheck, 0.0, 1e-11, "%s reference at h = 1e-4 vs 2e-4", name);
    printf("%-12s reference (own RK4 from T and U) h 1e-4 vs 2e-4: %.1e\n", name, refcheck);
    for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
        const lag_method_info *inf = tc_method(mi);
        if (inf->adaptive) continue;
        const int p = inf->order, N0 = p <= 1 ? 1000 : p == 2 ? 100 : 40;
        double dts[4], err[4];
        for (int r = 0; r < 4; ++r) {
            int N = N0 << r;
            dts[r] = T / N;
            err[r] = run_err(&md, (lag_method)mi, T, N, q0, qd0);
        }
        double slope = tc_slope(4, dts, err);
        printf("%-12s %-20s dt %.3g..%.3g: err %.2e %.2e %.2e %.2e  slope %.2f (order %d)\n", name,
               inf->name, dts[0], dts[3], err[0], err[1], err[2], err[3], slope, p);
        ENSURE_NEAR(slope, (double)p, 0.3, "%s %s convergence order", name, inf->name);
    }

    /* adaptive methods against tolerance; atol = rtol / 100. (a) one tick of T, so that
     * only the tolerance limits the steps (with short ticks the tick caps the step and the
     * error stops depending on rtol); (b) continuous mode on a T/100 grid, every grid
     * state compared with the reference recorded on the same grid. */
    for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
        const lag_method_info *inf = tc_method(mi);
        if (!inf->adaptive) continue;
        double prev = INFINITY, prev_grid = INFINITY;
        printf("%-12s %s err at rtol", name, inf->name);
        for (int e = 4; e <= 10; e += 2) {
            double tol = pow(10.0, -e);
            lag_sim_def def = tc_sim_def(&md, (lag_method)mi, T, q0, qd0);
            def.integrator.rtol = tol;
            def.integrator.atol = tol / 100;
            lag_sim s;
            if (tc_sim_init(&s, &def) || tc_advance(&s, 1, false)) return;
            double err = max_err(md.nq, s.q, s.qd, yref);
            lag_sim_stats st = s.stats;

            def.integrator.dt = T / 100;
            if (tc_sim_init(&s, &def)) return;
            double worst_grid = 0;
            for (int k = 1; k <= 100; ++k) {
                if (tc_advance(&s, 1, true)) return;
                worst_grid = fmax(worst_grid, max_err(md.nq, s.q, s.qd, rec[k]));
            }
            printf(" 1e-%d: %.2e (%lld steps; dense T/100 grid %.2e, %lld steps)", e, err,
                   (long long)st.steps_accepted, worst_grid, (long long)s.stats.steps_accepted);
            /* each 100x tighter tolerance must give a smaller error, in both modes */
            ENSURE_NEAR(err, 0.0, prev, "%s %s error must decrease with rtol (rtol 1e-%d)", name, inf->name, e);
            ENSURE_NEAR(worst_grid, 0.0, prev_grid, "%s %s dense-output error must decrease with rtol (1e-%d)",
                        name, inf->name, e);
            prev = err;
            prev_grid = worst_grid;
        }
        /* at rtol 1e-10 both agree with the reference to 1e-7 (global error ~ 1e2 x tol) */
        ENSURE_NEAR(prev, 0.0, 1e-7, "%s %s at rtol 1e-10 vs reference", name, inf->name);
        ENSURE_NEAR(prev_grid, 0.0, 1e-7, "%s %s dense output at rtol 1e-10 vs reference", name, inf->name);
        printf("\n");
    }
}

/* Max |E - E0| over the first and last tenth of a 100 s unforced run of the hanging DIPC
 * (its reference motion). */
static void energy_tenths(lag_method meth, double dt, double *first, double *last)
{
    const lag_model_kind kind = (lag_model_kind)lag_model_kind_from_name("dipc");
    const tc_ref *ref = tc_ref_of(kind);
    lag_model md;
    lag_model_default(&md, kind);
    lag_sim_def def = tc_sim_def(&md, meth, dt, ref->q0, ref->qd0);
    lag_sim s;
    *first = *last = NAN;
    if (tc_sim_init(&s, &def)) return;
    int N = (int)lround(100.0 / dt);
    double E0 = tc_T(&md, ref->q0, ref->qd0) + tc_U(&md, ref->q0), f = 0, l = 0;
    for (int k = 1; k <= N; ++k) {
        if (tc_advance(&s, 1, false)) return;
        double e = fabs(tc_T(&md, s.q, s.qd) + tc_U(&md, s.q) - E0);
        if (k <= N / 10) f = fmax(f, e);
        if (k > N - N / 10) l = fmax(l, e);
    }
    *first = f;
    *last = l;
}

/* Every canonical method (dt 0.02 at order 2, 0.04 above), and as the control the first
 * explicit fixed-step method of order >= 4 (rk4) at 0.04. */
static void check_long_run(int arg)
{
    (void)arg;
    bool control = false;
    for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
        const lag_method_info *inf = tc_method(mi);
        bool is_control = !control && !inf->canonical && !inf->adaptive && !inf->implicit && inf->order >= 4;
        if (!inf->canonical && !is_control) continue;
        control |= is_control;
        double dt = inf->order <= 2 ? 0.02 : 0.04, f, l;
        energy_tenths((lag_method)mi, dt, &f, &l);
        printf("dipc 100 s %-18s dt %.2f: max|E-E0| first tenth %.2e, last tenth %.2e (ratio %.2f)%s\n",
               inf->name, dt, f, l, l / f, is_control ? " [control: must drift]" : "");
        if (inf->canonical)
            ENSURE_NEAR(l, 0.0, 2 * f, "%s: energy error must stay bounded (last tenth <= 2x first)", inf->name);
        else
            ENSURE(l > 3 * f); /* the check tells drift from no drift */
    }
    ENSURE(control);
}

static void case_orders(int kind) { check_orders((lag_model_kind)kind); }

/* Cases: one per model of the core's table (orders), and long_run. */
int main(int argc, char **argv)
{
    lt_cases cs = {0};
    for (int k = 0; k < LAG_MODEL_COUNT; ++k)
        lt_add(&cs, lag_model_info_get((lag_model_kind)k)->name, case_orders, k, 0);
    lt_add(&cs, "long_run", check_long_run, 0, 0);
    return lt_main(argc, argv, cs.c, cs.n);
}
