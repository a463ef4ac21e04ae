/*
 * Conservation laws of the unforced models, integrated by the core: one case per model of
 * the core's table, every method of its table.
 *
 * Momenta of cyclic coordinates. A coordinate on which neither T nor U depends (found
 * here from our own T and U: dT/dq_i and dU/dq_i vanish exactly, by complex steps, at
 * random states) has a conserved momentum p_i = dT/dqd_i (the stick's x, the DIPC's and
 * the cart-pole's cart). What each method must do with it:
 *   - if row i of M is constant (the stick: p_x = m x_dot), p_i is a linear function of
 *     qd, and every Runge-Kutta method keeps linear invariants of its state exactly: to
 *     rounding (1e-12 of the momentum scale over 1000 steps), every method; and since
 *     then sum_j M_ij q_j has the constant derivative p_i, it must equal its start plus
 *     p_i t (the stick's x = x0 + x_dot0 t);
 *   - otherwise p_i = sum_j M_ij(q) qd_j is not linear in (q, qd). The canonical methods
 *     (implicit midpoint, gauss4: Gauss-Legendre in (q, p)) keep it, as a linear function
 *     of their state, to the Newton tolerance (1e-13 per step): 1e-10 of the scale over
 *     1000 steps. dopri5 at rtol 1e-12: 1e-9. The explicit fixed-step methods keep it
 *     only to their order p: two halvings of dt must divide the drift by >= 2^(2p - 1),
 *     unless it is already at the rounding floor (1e-11).
 *
 * Energy. Along the model's smooth reference motion (tests/common/ref_models.h) with its
 * default parameters, max |E(t) - E(0)| (E from our own T + U) over dt, dt/2, dt/4 must
 * fall with a fitted slope >= p - 0.3. For the canonical methods (E of a modified
 * Hamiltonian H + dt^p H_p is conserved) and the first-order ones (first-order drift) it
 * is exactly p, so also <= p + 0.3. An explicit method of higher order can do better on
 * energy than on the trajectory: on a harmonic oscillator RK4's |R(i w h)|^2 =
 * 1 - (w h)^6 / 72, an O(h^5) energy drift over a fixed horizon, so for explicit methods
 * of order >= 2 the upper bound is p + 1.3 (their trajectory order is checked in
 * test_convergence). dt ranges by order (1: 1e-3, 2: 1e-2, 4: 2e-2) keep the errors in
 * the asymptotic range and far above the rounding floor (~1e-13 |E|): figures printed.
 */
#include "test_core.h"

/* ---------------------------------------------------------------- cyclic coordinates */
typedef struct cyclic_info {
    bool cyclic[LAG_MAX_DOF];     /* dT/dq_i = dU/dq_i = 0 */
    bool row_const[LAG_MAX_DOF];  /* dM_ij/dq_k = 0 for all j, k */
} cyclic_info;

/* Exact zeros of complex-step derivatives at 20 random states and parameter sets. */
static cyclic_info find_cyclic(lag_model_kind kind)
{
    cyclic_info ci;
    const int n = tc_nq(kind);
    for (int i = 0; i < LAG_MAX_DOF; ++i) ci.cyclic[i] = ci.row_const[i] = i < n;
    lt_rng rng = {0xc7c1u + (uint64_t)kind};
    for (int it = 0; it < 20; ++it) {
        lag_model md;
        tc_random_model(&rng, kind, &md);
        double q[LAG_MAX_DOF] = {0}, qd[LAG_MAX_DOF] = {0}, dTq[LAG_MAX_DOF], dUq[LAG_MAX_DOF];
        double dM[LAG_MAX_DOF * LAG_MAX_DOF * LAG_MAX_DOF];
        tc_random_state(&rng, &md, q, qd);
        tc_dT_dq(&md, q, qd, dTq);
        tc_dU_dq(&md, q, dUq);
        tc_mass_deriv(&md, q, dM);
        for (int i = 0; i < n; ++i) {
            if (dTq[i] != 0.0 || dUq[i] != 0.0) ci.cyclic[i] = false;
            for (int k = 0; k < n; ++k)
                for (int j = 0; j < n; ++j)
                    if (dM[k * n * n + i * n + j] != 0.0) ci.row_const[i] = false;
        }
    }
    return ci;
}

/* One unforced run of 1 s at tick dt from (q0, qd0). Returns max |p_i(t) - p_i(0)|;
 * *scale = max sum_j |M_ij qd_j| seen; *lin = max |sum_j M_ij (q_j(t) - q_j(0)) - p_i(0) t|
 * (meaningful when row i of M is constant), *lin_scale its scale. */
static double momentum_drift(const lag_model *md, lag_method meth, double dt, int i,
                             const double *q0, const double *qd0, double *scale, double *lin,
                             double *lin_scale)
{
    const int n = md->nq;
    lag_sim_def def = tc_sim_def(md, meth, dt, q0, qd0);
    def.integrator.rtol = 1e-12;
    def.integrator.atol = 1e-14;
    lag_sim s;
    if (tc_sim_init(&s, &def)) return NAN;
    double M0[LAG_MAX_DOF * LAG_MAX_DOF];
    tc_mass(md, q0, M0);
    double P0 = tc_momentum(md, q0, qd0, i), worst = 0, sc = fabs(P0), lw = 0, ls = 1;
    int nt = (int)lround(1.0 / dt);
    for (int k = 0; k < nt; ++k) {
        if (tc_advance(&s, 1, false)) return NAN;
        worst = fmax(worst, fabs(tc_momentum(md, s.q, s.qd, i) - P0));
        double M[LAG_MAX_DOF * LAG_MAX_DOF], a = 0, x = 0, xs = 0;
        tc_mass(md, s.q, M);
        for (int j = 0; j < n; ++j) {
            a += fabs(M[i * n + j] * s.qd[j]);
            x += M0[i * n + j] * (s.q[j] - q0[j]);
            xs += fabs(M0[i * n + j]) * (fabs(s.q[j]) + fabs(q0[j]));
        }
        sc = fmax(sc, a);
        double t = lag_sim_time(&s);
        lw = fmax(lw, fabs(x - P0 * t));
        ls = fmax(ls, xs + fabs(P0) * t);
    }
    *scale = sc;
    *lin = lw;
    *lin_scale = ls;
    return worst;
}

static void check_momenta(lag_model_kind kind)
{
    const char *name = lag_model_info_get(kind)->name;
    const cyclic_info ci = find_cyclic(kind);
    const int n = tc_nq(kind);
    int ncyc = 0;
    lt_rng rng = {0x57d1u + (uint64_t)kind};
    for (int i = 0; i < n; ++i) {
        if (!ci.cyclic[i]) continue;
        ncyc++;
        double worst[LAG_METHOD_COUNT] = {0}, worst_lin = 0;
        for (int run = 0; run < 3; ++run) {
            lag_model md;
            tc_random_model(&rng, kind, &md);
            double q0[LAG_MAX_DOF] = {0}, qd0[LAG_MAX_DOF] = {0};
            tc_motion_start(&rng, &md, q0);
            for (int j = 0; j < n; ++j) qd0[j] = lt_uniform(&rng, -1, 1);
            for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
                const lag_method_info *inf = tc_method(mi);
                lag_method meth = (lag_method)mi;
                double sc, lin, ls;
                if (ci.row_const[i] || inf->canonical || inf->adaptive) {
                    double dt = inf->adaptive ? 1e-2 : 1e-3;
                    double d = momentum_drift(&md, meth, dt, i, q0, qd0, &sc, &lin, &ls);
                    double tol = ci.row_const[i] ? 1e-12 : inf->adaptive ? 1e-9 : 1e-10;
                    ENSURE_NEAR(d, 0.0, tol * sc, "%s %s: max |p_%d(t) - p_%d(0)| over 1 s, run %d", name,
                                inf->name, i, i, run);
                    if (ci.row_const[i]) {
                        ENSURE_NEAR(lin, 0.0, 1e-12 * ls, "%s %s: sum_j M_%dj q_j(t) - p_%d t, run %d", name,
                                    inf->name, i, i, run);
                        worst_lin = fmax(worst_lin, lin / ls);
                    }
                    worst[mi] = fmax(worst[mi], d / sc);
                } else {
                    double dt0 = inf->order >= 3 ? 1e-2 : 1e-3, d[3], scs[3];
                    for (int r = 0; r < 3; ++r)
                        d[r] = momentum_drift(&md, meth, dt0 / (1 << r), i, q0, qd0, &scs[r], &lin, &ls);
                    int p = inf->order;
                    if (d[0] > 1e-11 * scs[0])
                        ENSURE_NEAR(d[2], 0.0, d[0] / pow(2.0, 2 * p - 1),
                                    "%s %s: p_%d drift %.3g at dt %g does not shrink at order %d (%.3g, %.3g), run %d",
                                    name, inf->name, i, d[0], dt0, p, d[1], d[2], run);
                    else
                        ENSURE(d[2] <= 1e-11 * scs[2]);
                    worst[mi] = fmax(worst[mi], d[0] / scs[0]);
                }
            }
        }
        printf("%-12s p_%d = dT/d%s_dot (cyclic%s): worst max|p(t) - p(0)| / scale over 1 s:", name, i,
               lag_model_info_get(kind)->joint_names[i], ci.row_const[i] ? ", row of M constant" : "");
        for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) printf(" %s %.1e", tc_method(mi)->name, worst[mi]);
        if (ci.row_const[i]) printf("; |sum_j M_ij q_j - p t| %.1e", worst_lin);
        printf("\n");
    }
    if (ncyc == 0) {
        printf("%-12s no cyclic coordinate (T or U depends on every one)\n", name);
        ENSURE(ncyc == 0); /* the search ran and found none: nothing to conserve */
    }
}

/* ---------------------------------------------------------------- energy order */
/* Max |E(t) - E(0)| over duration T, E from our T + U, unforced. */
static double energy_drift(const lag_model *md, lag_method meth, double dt, double T,
                           const double *q0, const double *qd0)
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
    return worst;
}

static void check_energy_order(lag_model_kind kind)
{
    const tc_ref *ref = tc_ref_of(kind);
    lag_model md;
    lag_model_default(&md, kind);
    for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
        const lag_method_info *inf = tc_method(mi);
        if (inf->adaptive) continue; /* no dt order: see test_convergence */
        const int p = inf->order;
        const double dt0 = p <= 1 ? 1e-3 : p == 2 ? 1e-2 : 2e-2;
        double dts[3], err[3];
        for (int r = 0; r < 3; ++r) {
            dts[r] = dt0 / (1 << r);
            err[r] = energy_drift(&md, (lag_method)mi, dts[r], ref->T, ref->q0, ref->qd0);
        }
        double slope = tc_slope(3, dts, err);
        printf("%-12s energy %-20s dt %.4g..%.4g: max|E-E0| %.2e %.2e %.2e  slope %.2f (order %d)\n",
               lag_model_info_get(kind)->name, inf->name, dts[0], dts[2], err[0],
               err[1], err[2], slope, p);
        double hi = (inf->canonical || p <= 1) ? p + 0.3 : p + 1.3;
        if (!(slope >= p - 0.3 && slope <= hi))
            LT_FAIL("%s %s energy error slope %.2f outside [%.1f, %.1f]", lag_model_info_get(kind)->name,
                    inf->name, slope, p - 0.3, hi);
        else
            ENSURE(slope >= p - 0.3 && slope <= hi);
    }
}

static void case_model(int kind)
{
    check_momenta((lag_model_kind)kind);
    check_energy_order((lag_model_kind)kind);
}

/* One case per model of the core's table. */
int main(int argc, char **argv)
{
    lt_cases cs = {0};
    for (int k = 0; k < LAG_MODEL_COUNT; ++k)
        lt_add(&cs, lag_model_info_get((lag_model_kind)k)->name, case_model, k, 0);
    return lt_main(argc, argv, cs.c, cs.n);
}
