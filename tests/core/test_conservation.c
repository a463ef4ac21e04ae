/*
 * Conservation laws of the unforced models, integrated by the core (issue 2, tests 3):
 *   - stick: nothing depends on x, no input => x_dot constant, x = x0 + x_dot0 t;
 *   - DIPC: nothing depends on theta0, no cart force => the horizontal momentum
 *     p0 = dL/dtheta0_dot = (m0+m1+m2) th0d + (m1/2 + m2) l1 cos th1 th1d + m2 l2/2 cos th2 th2d
 *     is constant (computed here from our T by a complex step, not from the core);
 *   - energy of unforced runs: max |E(t) - E(0)| shrinks like dt^p (p = the method's order),
 *     measured at dt, dt/2, dt/4 with E from our own T + U.
 */
#include "test_core.h"

/* ---------------------------------------------------------------- stick x_dot */
/* Every method: x_dot must not move at all beyond rounding. The x equation is m x_ddot = 0
 * exactly (M is diagonal, bias_x = 0); an integrator adds at most a few rounding errors of
 * size eps |qd| per step, so over 1000 steps 1e-12 (|x_dot0| + |phi_dot|max) is a bound
 * with margin; x(t) = x0 + x_dot0 t to 1e-12 (|x0| + |x_dot0| t + 1). */
static void check_stick_momentum(void)
{
    lt_rng rng = {0x57u};
    double worst_v = 0, worst_x = 0;
    for (int run = 0; run < 4; ++run) {
        lag_model md;
        tc_random_model(&rng, LAG_MODEL_STICK, &md);
        double q0[3] = {lt_uniform(&rng, -2, 2), lt_uniform(&rng, 0.4, 1.2), 0};
        double qd0[3] = {lt_uniform(&rng, -3, 3), lt_uniform(&rng, -1, 1), 0};
        for (int mi = 0; mi < TC_NMETHODS; ++mi) {
            lag_method meth = tc_all_methods[mi];
            lag_sim_def def = tc_sim_def(&md, meth, meth == LAG_DOPRI5 ? 1e-2 : 1e-3, q0, qd0);
            lag_sim s;
            if (tc_sim_init(&s, &def)) return;
            double vmax = fabs(qd0[0]) + fabs(qd0[1]);
            int nt = meth == LAG_DOPRI5 ? 100 : 1000;
            for (int k = 0; k < nt; ++k) {
                if (tc_advance(&s, 1, false)) break;
                vmax = fmax(vmax, fabs(s.qd[0]) + fabs(s.qd[1]));
                ENSURE_NEAR(s.qd[0], qd0[0], 1e-12 * vmax, "stick %s x_dot at tick %lld, run %d",
                            lag_method_name(meth), (long long)s.tick, run);
                worst_v = fmax(worst_v, fabs(s.qd[0] - qd0[0]) / vmax);
            }
            double t = lag_sim_time(&s);
            double xs = fabs(q0[0]) + fabs(qd0[0]) * t + 1;
            ENSURE_NEAR(s.q[0], q0[0] + qd0[0] * t, 1e-12 * xs, "stick %s x(1 s), run %d", lag_method_name(meth), run);
            worst_x = fmax(worst_x, fabs(s.q[0] - (q0[0] + qd0[0] * t)) / xs);
        }
    }
    printf("stick x_dot: all methods, worst |x_dot - x_dot0| %.1e of the velocity scale; |x - x0 - x_dot0 t| %.1e\n",
           worst_v, worst_x);
}

/* ---------------------------------------------------------------- DIPC p0 */
static double p0_of(const lag_model *md, const double *q, const double *qd)
{
    double p[3];
    tc_dT_dqd(md, q, qd, p);
    return p[0];
}

/* Max |p0(t) - p0(0)| over 1 s of an unforced DIPC (random parameters, rods swinging
 * from a random state), at tick dt. OUT: *scale = max |m_total th0d| + |p_rods| seen. */
static double p0_drift(const lag_model *md, lag_method meth, double dt, const double *q0,
                       const double *qd0, double *scale)
{
    lag_sim_def def = tc_sim_def(md, meth, dt, q0, qd0);
    def.integrator.rtol = 1e-12;
    def.integrator.atol = 1e-14;
    lag_sim s;
    if (tc_sim_init(&s, &def)) return NAN;
    double P0 = p0_of(md, q0, qd0), worst = 0, sc = 0;
    int nt = (int)lround(1.0 / dt);
    for (int k = 0; k < nt; ++k) {
        if (tc_advance(&s, 1, false)) return NAN;
        worst = fmax(worst, fabs(p0_of(md, s.q, s.qd) - P0));
        double M[9];
        lag_model_mass(md, s.q, M);
        sc = fmax(sc, fabs(M[0] * s.qd[0]) + fabs(M[1] * s.qd[1]) + fabs(M[2] * s.qd[2]));
    }
    *scale = sc;
    return worst;
}

/* Implicit midpoint and gauss4 are Gauss-Legendre methods applied (header) in (q, p):
 * p0 is a linear function of that state, and every Runge-Kutta method conserves linear
 * invariants exactly up to the Newton tolerance (1e-13 per step) and rounding: over 1000
 * steps 1e-10 of the momentum scale. The explicit methods step y = (q, qd), in which p0 is
 * not linear (cos th_i qd_i), so they conserve it only to their order: the drift must
 * shrink like dt^p (two halvings: >= 2^(2p - 1)). dopri5 at rtol 1e-12: below 1e-9. */
static void check_dipc_momentum(void)
{
    lt_rng rng = {0xd1bcu};
    double worst[TC_NMETHODS] = {0};
    for (int run = 0; run < 3; ++run) {
        lag_model md;
        tc_random_model(&rng, LAG_MODEL_DIPC, &md);
        double q0[3] = {lt_uniform(&rng, -1, 1), lt_uniform(&rng, -TC_PI, TC_PI), lt_uniform(&rng, -TC_PI, TC_PI)};
        double qd0[3] = {lt_uniform(&rng, -1, 1), lt_uniform(&rng, -2, 2), lt_uniform(&rng, -2, 2)};
        for (int mi = 0; mi < TC_NMETHODS; ++mi) {
            lag_method meth = tc_all_methods[mi];
            double sc;
            if (meth == LAG_IMPLICIT_MIDPOINT || meth == LAG_GAUSS4 || meth == LAG_DOPRI5) {
                double d = p0_drift(&md, meth, meth == LAG_DOPRI5 ? 1e-2 : 1e-3, q0, qd0, &sc);
                double tol = meth == LAG_DOPRI5 ? 1e-9 : 1e-10;
                ENSURE_NEAR(d, 0.0, tol * sc, "dipc %s: max |p0(t) - p0(0)| over 1 s, run %d", lag_method_name(meth), run);
                worst[mi] = fmax(worst[mi], d / sc);
            } else {
                double dt0 = meth == LAG_RK4 ? 1e-2 : 1e-3, d[3], scs[3];
                for (int r = 0; r < 3; ++r) d[r] = p0_drift(&md, meth, dt0 / (1 << r), q0, qd0, &scs[r]);
                int p = lag_method_order(meth);
                if (d[0] > 1e-11 * scs[0])
                    ENSURE_NEAR(d[2], 0.0, d[0] / pow(2.0, 2 * p - 1),
                                "dipc %s: p0 drift %.3g at dt %g does not shrink at order %d (%.3g, %.3g), run %d",
                                lag_method_name(meth), d[0], dt0, p, d[1], d[2], run);
                worst[mi] = fmax(worst[mi], d[0] / scs[0]);
            }
        }
    }
    printf("dipc p0 = dL/dth0_dot: worst max|p0(t) - p0(0)| / scale over 1 s:");
    for (int mi = 0; mi < TC_NMETHODS; ++mi) printf(" %s %.1e", lag_method_name(tc_all_methods[mi]), worst[mi]);
    printf("\n  (implicit-midpoint, gauss4 at 1 ms and dopri5 at rtol 1e-12: conserved; euler, semi-implicit-euler at 1 ms, rk4 at 10 ms: O(dt^p))\n");
}

/* ---------------------------------------------------------------- energy order */
/* Max |E(t) - E(0)| over duration T, E from our T + U, unforced. */
static double energy_drift(const lag_model *md, lag_method meth, double dt, double T,
                           const double *q0, const double *qd0, double *E0out)
{
    lag_sim_def def = tc_sim_def(md, meth, dt, q0, qd0);
    lag_sim s;
    if (tc_sim_init(&s, &def)) return NAN;
    double E0 = tc_T(md, q0, qd0) + tc_U(md, q0), worst = 0;
    int nt = (int)lround(T / dt);
    for (int k = 0; k < nt; ++k) {
        if (tc_advance(&s, 1, false)) return NAN;
        worst = fmax(worst, fabs(tc_T(md, s.q, s.qd) + tc_U(md, s.q) - E0));
    }
    *E0out = E0;
    return worst;
}

/* The scene: Bogdanov's DIPC hanging and swinging (theta1 = pi + 0.3, theta2 = pi - 0.2),
 * 2 s, and the manipulator swinging about q1 = -pi/2 with the slider moving (1 s).
 * Energy error of an order-p method over a fixed horizon is at most C dt^p; the fitted
 * slope of log(err) vs log(dt) over dt, dt/2, dt/4 must be >= p - 0.3. For the symplectic
 * methods (implicit midpoint, gauss4: E of a modified Hamiltonian H + dt^p H_p is
 * conserved) and for euler / semi-implicit euler (first-order drift) it is exactly p, so
 * also <= p + 0.3. RK4's energy error can be of higher order than its trajectory error:
 * on a harmonic oscillator |R(i w h)|^2 = 1 - (w h)^6 / 72, an O(h^5) energy drift over a
 * fixed horizon; near-harmonic swinging shows a slope between 4 and 5, so for RK4 the
 * upper bound is p + 1.3 (its trajectory order is checked in test_convergence).
 * The dt ranges are chosen so the errors sit in the asymptotic range and far above the
 * rounding floor (~1e-13 |E|): measured values are printed. */
static void check_energy_order(void)
{
    struct { lag_method meth; double dt0; } cases[] = {
        {LAG_EULER, 1e-3}, {LAG_SEMI_IMPLICIT_EULER, 1e-3}, {LAG_RK4, 2e-2},
        {LAG_IMPLICIT_MIDPOINT, 1e-2}, {LAG_GAUSS4, 4e-2},
    };
    for (int sc = 0; sc < 2; ++sc) {
        lag_model md;
        double q0[3] = {0}, qd0[3] = {0}, T;
        if (sc == 0) {
            tc_dipc_hanging(&md, q0, qd0);
            T = 2.0;
        } else {
            lag_model_default(&md, LAG_MODEL_MANIPULATOR);
            q0[0] = -TC_PI / 2 + 0.4;
            q0[1] = 0.5;
            qd0[1] = -0.3;
            T = 1.0;
        }
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
            double dts[3], err[3], E0 = 0;
            for (int r = 0; r < 3; ++r) {
                dts[r] = cases[c].dt0 / (1 << r);
                err[r] = energy_drift(&md, cases[c].meth, dts[r], T, q0, qd0, &E0);
            }
            double slope = tc_slope(3, dts, err);
            int p = lag_method_order(cases[c].meth);
            printf("%-12s energy %-20s dt %.4g..%.4g: max|E-E0| %.2e %.2e %.2e  slope %.2f (order %d)\n",
                   lag_model_info_get(md.kind)->name, lag_method_name(cases[c].meth), dts[0], dts[2],
                   err[0], err[1], err[2], slope, p);
            double hi = cases[c].meth == LAG_RK4 ? p + 1.3 : p + 0.3;
            ENSURE(slope >= p - 0.3 && slope <= hi);
            if (!(slope >= p - 0.3 && slope <= hi))
                fprintf(stderr, "  ^ %s %s energy error slope %.2f outside [%.1f, %.1f]\n",
                        lag_model_info_get(md.kind)->name, lag_method_name(cases[c].meth), slope, p - 0.3, hi);
        }
    }
}

static void case_stick_momentum(int arg) { (void)arg; check_stick_momentum(); }
static void case_dipc_momentum(int arg) { (void)arg; check_dipc_momentum(); }
static void case_energy_order(int arg) { (void)arg; check_energy_order(); }

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"stick_momentum", case_stick_momentum, 0, 0},
        {"dipc_momentum", case_dipc_momentum, 0, 0},
        {"energy_order", case_energy_order, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
