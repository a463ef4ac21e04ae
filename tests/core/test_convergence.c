/*
 * Convergence order of every integrator (issue 2, tests 4).
 *
 * Smooth scenes: Bogdanov's DIPC hanging down and swinging (theta1 = pi + 0.3,
 * theta2 = pi - 0.2, at rest) over 1 s, and the manipulator swinging below the horizontal
 * with its slider moving, over 1 s. The reference trajectory is computed here, with no core
 * code at all: classical RK4 at h = 1e-4 s over our own forward dynamics from T and U
 * (tc_forward_own). Its error, ~ (rate h)^4 ~ 1e-13 for rates ~ 5/s, is checked by
 * comparing with the same run at h = 2e-4 (must agree to 1e-11) and is far below the
 * smallest error measured below (~1e-8).
 *
 * Error = max over (q, qd) components of |y(1 s) - y_ref(1 s)|. The fitted slope of
 * log(error) vs log(dt) over four dt must be within +-0.3 of the method's order: with the
 * dt ranges below the errors are in the asymptotic range (ratios per halving printed), and
 * +-0.3 leaves room for the next-order term over a factor-8 range of dt (a relative
 * contribution c dt changes the fitted slope by ~ c dt_max / ln 8) while still telling order
 * 1 from 2 and 4 from 5.
 *
 * dopri5: error against tolerance (rtol 1e-4 .. 1e-10): must decrease at every step and
 * at rtol 1e-10 agree with the reference to 1e-7, both with the last step shortened to
 * the tick and with dense (continuous) output on a 10 ms grid, checked at every grid point.
 *
 * Symplectic methods over a long run (DIPC hanging, 100 s): max energy error in the last
 * tenth at most twice that in the first tenth (no drift); rk4 at the same dt drifts,
 * which shows the check can tell (its last tenth must exceed its first by 3x).
 */
#include "test_core.h"

static double max_err(int n, const double *q, const double *qd, const double *yref)
{
    double e = 0;
    for (int i = 0; i < n; ++i) e = fmax(e, fmax(fabs(q[i] - yref[i]), fabs(qd[i] - yref[n + i])));
    return e;
}

/* One run of the core over 1 s with N ticks; returns the error at the end. */
static double run_err(const lag_model *md, lag_method meth, int N, const double *q0,
                      const double *qd0, const double *yref)
{
    lag_sim_def def = tc_sim_def(md, meth, 1.0 / N, q0, qd0);
    lag_sim s;
    if (tc_sim_init(&s, &def)) return NAN;
    if (tc_advance(&s, N, false)) return NAN;
    ENSURE(s.tick == N);
    return max_err(md->nq, s.q, s.qd, yref);
}

static void scene(int which, lag_model *md, double *q0, double *qd0)
{
    memset(q0, 0, 3 * sizeof *q0);
    memset(qd0, 0, 3 * sizeof *qd0);
    if (which == 0) {
        tc_dipc_hanging(md, q0, qd0);
    } else {
        lag_model_default(md, LAG_MODEL_MANIPULATOR);
        q0[0] = -TC_PI / 2 + 0.4;
        q0[1] = 0.5;
        qd0[1] = -0.3;
    }
}

static void check_orders(void)
{
    struct { lag_method meth; int N0; } cases[] = {
        {LAG_EULER, 1000}, {LAG_SEMI_IMPLICIT_EULER, 1000}, {LAG_RK4, 100},
        {LAG_IMPLICIT_MIDPOINT, 100}, {LAG_GAUSS4, 40},
    };
    for (int sc = 0; sc < 2; ++sc) {
        lag_model md;
        double q0[3], qd0[3], yref[6], ycheck[6];
        scene(sc, &md, q0, qd0);
        const char *name = lag_model_info_get(md.kind)->name;
        tc_reference_run(&md, q0, qd0, 1e-4, 10000, yref, NULL, 0);
        tc_reference_run(&md, q0, qd0, 2e-4, 5000, ycheck, NULL, 0);
        double refcheck = max_err(md.nq, ycheck, ycheck + md.nq, yref);
        ENSURE_NEAR(refcheck, 0.0, 1e-11, "%s reference at h = 1e-4 vs 2e-4", name);
        printf("%-12s reference (own RK4 from T and U) h 1e-4 vs 2e-4: %.1e\n", name, refcheck);
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
            double dts[4], err[4];
            for (int r = 0; r < 4; ++r) {
                int N = cases[c].N0 << r;
                dts[r] = 1.0 / N;
                err[r] = run_err(&md, cases[c].meth, N, q0, qd0, yref);
            }
            double slope = tc_slope(4, dts, err);
            int p = lag_method_order(cases[c].meth);
            printf("%-12s %-20s dt 1/%d..1/%d: err %.2e %.2e %.2e %.2e  slope %.2f (order %d)\n", name,
                   lag_method_name(cases[c].meth), cases[c].N0, cases[c].N0 << 3, err[0], err[1], err[2],
                   err[3], slope, p);
            ENSURE_NEAR(slope, (double)p, 0.3, "%s %s convergence order", name, lag_method_name(cases[c].meth));
        }

        /* dopri5 against tolerance; atol = rtol / 100. (a) one tick of 1 s, so that only
         * the tolerance limits the steps (with short ticks the tick caps the step and the
         * error stops depending on rtol); (b) continuous mode on a 10 ms grid, every grid
         * state compared with the reference recorded on the same grid. */
        static double rec[101][6];
        double yend[6];
        tc_reference_run(&md, q0, qd0, 1e-4, 10000, yend, rec, 100);
        double prev = INFINITY, prev_grid = INFINITY;
        printf("%-12s dopri5 err at rtol", name);
        for (int e = 4; e <= 10; e += 2) {
            double tol = pow(10.0, -e);
            lag_sim_def def = tc_sim_def(&md, LAG_DOPRI5, 1.0, q0, qd0);
            def.integrator.rtol = tol;
            def.integrator.atol = tol / 100;
            lag_sim s;
            if (tc_sim_init(&s, &def) || tc_advance(&s, 1, false)) return;
            double err = max_err(md.nq, s.q, s.qd, yref);
            lag_sim_stats st = s.stats;

            def.integrator.dt = 1e-2;
            if (tc_sim_init(&s, &def)) return;
            double worst_grid = 0;
            for (int k = 1; k <= 100; ++k) {
                if (tc_advance(&s, 1, true)) return;
                worst_grid = fmax(worst_grid, max_err(md.nq, s.q, s.qd, rec[k]));
            }
            printf(" 1e-%d: %.2e (%lld steps; dense 10 ms grid %.2e, %lld steps)", e, err,
                   (long long)st.steps_accepted, worst_grid, (long long)s.stats.steps_accepted);
            /* each 100x tighter tolerance must give a smaller error, in both modes */
            ENSURE_NEAR(err, 0.0, prev, "%s dopri5 error must decrease with rtol (rtol 1e-%d)", name, e);
            ENSURE_NEAR(worst_grid, 0.0, prev_grid, "%s dopri5 dense-output error must decrease with rtol (1e-%d)",
                        name, e);
            prev = err;
            prev_grid = worst_grid;
        }
        /* at rtol 1e-10 both agree with the reference to 1e-7 (global error ~ 1e2 x tol) */
        ENSURE_NEAR(prev, 0.0, 1e-7, "%s dopri5 at rtol 1e-10 vs reference", name);
        ENSURE_NEAR(prev_grid, 0.0, 1e-7, "%s dopri5 dense output at rtol 1e-10 vs reference", name);
        printf("\n");
    }
}

/* Max |E - E0| over the first and last tenth of a 100 s unforced run of the hanging DIPC. */
static void energy_tenths(lag_method meth, double dt, double *first, double *last)
{
    lag_model md;
    double q0[3], qd0[3];
    tc_dipc_hanging(&md, q0, qd0);
    lag_sim_def def = tc_sim_def(&md, meth, dt, q0, qd0);
    lag_sim s;
    *first = *last = NAN;
    if (tc_sim_init(&s, &def)) return;
    int N = (int)lround(100.0 / dt);
    double E0 = tc_T(&md, q0, qd0) + tc_U(&md, q0), f = 0, l = 0;
    for (int k = 1; k <= N; ++k) {
        if (tc_advance(&s, 1, false)) return;
        double e = fabs(tc_T(&md, s.q, s.qd) + tc_U(&md, s.q) - E0);
        if (k <= N / 10) f = fmax(f, e);
        if (k > N - N / 10) l = fmax(l, e);
    }
    *first = f;
    *last = l;
}

static void check_long_run(void)
{
    struct { lag_method meth; double dt; bool symplectic; } cases[] = {
        {LAG_IMPLICIT_MIDPOINT, 0.02, true}, {LAG_GAUSS4, 0.04, true}, {LAG_RK4, 0.04, false},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        double f, l;
        energy_tenths(cases[c].meth, cases[c].dt, &f, &l);
        printf("dipc 100 s %-18s dt %.2f: max|E-E0| first tenth %.2e, last tenth %.2e (ratio %.2f)\n",
               lag_method_name(cases[c].meth), cases[c].dt, f, l, l / f);
        if (cases[c].symplectic)
            ENSURE_NEAR(l, 0.0, 2 * f, "%s: energy error must stay bounded (last tenth <= 2x first)",
                        lag_method_name(cases[c].meth));
        else
            ENSURE(l > 3 * f); /* the check tells drift from no drift */
    }
}

static void case_orders(int arg) { (void)arg; check_orders(); }
static void case_long_run(int arg) { (void)arg; check_long_run(); }

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"orders", case_orders, 0, 0},
        {"long_run", case_long_run, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
