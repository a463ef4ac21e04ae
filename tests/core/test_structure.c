/*
 * Structural properties of the equations, per model:
 *   - M(q) symmetric positive definite at random states (Cholesky pivots > 0);
 *   - M_dot - 2C skew-symmetric, with M_dot obtained by differencing the core's M along a
 *     trajectory simulated by the core (so M_dot is the true time derivative along a
 *     motion, not dM/dq qd from the same code);
 *   - dE/dt = qd^T tau along a driven trajectory: (a) our own RK4 over the core's forward
 *     dynamics with a smooth tau(t), E from our T + U; (b) lag_sim with the input held per
 *     tick, where the work of a constant tau over a tick is exactly tau . (q_end - q_start).
 */
#include "test_core.h"

static const char *kname(lag_model_kind k) { return lag_model_info_get(k)->name; }

/* ---------------------------------------------------------------- SPD */
static void check_spd(lag_model_kind kind)
{
    lt_rng rng = {0xabc0u + (uint64_t)kind};
    double worst_asym = 0, min_rel_pivot = INFINITY;
    for (int it = 0; it < 300; ++it) {
        lag_model md;
        tc_random_model(&rng, kind, &md);
        int n = md.nq;
        double q[3] = {0}, qd[3] = {0}, M[9];
        tc_random_state(&rng, &md, q, qd);
        /* and at special configurations: every angle at pi/2 (the stick upright, M_11 = I),
         * then at 0; positions at 0 (the manipulator's slider on the axis) */
        if (it < 2)
            for (int i = 0; i < n; ++i) q[i] = lag_model_info_get(kind)->angular[i] ? (1 - it) * TC_PI / 2 : 0.0;
        lag_model_mass(&md, q, M);
        double sM = tc_maxabs(n * n, M);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < i; ++j) {
                /* symmetric to rounding: both triangles are the same closed form */
                ENSURE_NEAR(M[i * n + j], M[j * n + i], 4 * TC_EPS * sM, "%s M symmetric (%d,%d) state %d",
                            kname(kind), i, j, it);
                worst_asym = fmax(worst_asym, fabs(M[i * n + j] - M[j * n + i]) / sM);
            }
        double piv = tc_min_pivot(n, M);
        /* positive definite: every Cholesky pivot > 0. The smallest pivot relative to |M|
         * is reported; T > 0 for qd != 0 needs it strictly positive. */
        ENSURE(piv > 0);
        if (piv > 0) min_rel_pivot = fmin(min_rel_pivot, piv / sM);
        /* and T = 1/2 qd^T M qd > 0 (our T, from the bodies) */
        ENSURE(tc_T(&md, q, qd) > 0);
    }
    printf("%-12s SPD: 300 states, worst |M - M^T|/|M| %.1e, smallest Cholesky pivot/|M| %.2e\n",
           kname(kind), worst_asym, min_rel_pivot);
}

/* ---------------------------------------------------------------- M_dot - 2C skew */
/* The core's rk4 at dt = 1e-4 s from a random state with rates in -2..2; at every tick k,
 * M_dot = (M_{k-2} - 8 M_{k-1} + 8 M_{k+1} - M_{k+2}) / (12 dt): truncation
 * dt^4/30 |M^(5)| ~ 3e-18 (rate)^5 |dM| (negligible), rounding ~ 1.5 eps |M| / dt ~ 3e-12 |M|;
 * the rk4 trajectory differs from the exact motion through (q_k, qd_k) by its local error
 * ~ (rate dt)^5 ~ 1e-17. So |N + N^T| <= 1e-9 (|M| + |dM| |qd|) has a margin of ~300. */
static void check_skew(lag_model_kind kind)
{
    lt_rng rng = {0x5e5eu + (uint64_t)kind};
    double worst = 0, biggest_N = 0;
    for (int run = 0; run < 10; ++run) {
        lag_model md;
        tc_random_model(&rng, kind, &md);
        int n = md.nq;
        double q0[3] = {0}, qd0[3] = {0};
        tc_random_state(&rng, &md, q0, qd0);
        for (int i = 0; i < n; ++i) qd0[i] = lt_uniform(&rng, -2, 2);
        tc_motion_start(&rng, &md, q0);
        const double dt = 1e-4;
        enum { NT = 200 };
        static double qs[NT][3], qds[NT][3];
        lag_sim_def def = tc_sim_def(&md, LAG_RK4, dt, q0, qd0);
        lag_sim s;
        if (tc_sim_init(&s, &def)) return;
        for (int k = 0; k < NT; ++k) {
            memcpy(qs[k], s.q, sizeof qs[k]);
            memcpy(qds[k], s.qd, sizeof qds[k]);
            if (tc_advance(&s, 1, false)) return;
        }
        for (int k = 2; k < NT - 2; ++k) {
            double Mm2[9], Mm1[9], Mp1[9], Mp2[9], Md[9], C[9], dM[27], N[9];
            lag_model_mass(&md, qs[k - 2], Mm2);
            lag_model_mass(&md, qs[k - 1], Mm1);
            lag_model_mass(&md, qs[k + 1], Mp1);
            lag_model_mass(&md, qs[k + 2], Mp2);
            lag_model_coriolis(&md, qs[k], qds[k], C);
            lag_model_mass_deriv(&md, qs[k], dM);
            for (int i = 0; i < n * n; ++i) {
                Md[i] = (Mm2[i] - 8 * Mm1[i] + 8 * Mp1[i] - Mp2[i]) / (12 * dt);
                N[i] = Md[i] - 2 * C[i];
            }
            double sc = tc_maxabs(n * n, Mp1) + tc_maxabs(n * n * n, dM) * tc_maxabs(n, qds[k]);
            for (int i = 0; i < n; ++i)
                for (int j = 0; j <= i; ++j) {
                    double a = N[i * n + j] + N[j * n + i];
                    ENSURE_NEAR(a, 0.0, 1e-9 * sc, "%s (M_dot - 2C) + (M_dot - 2C)^T entry (%d,%d) run %d tick %d",
                                kname(kind), i, j, run, k);
                    worst = fmax(worst, fabs(a) / sc);
                    biggest_N = fmax(biggest_N, fabs(N[i * n + j]) / sc);
                }
            /* the same M_dot equals sum_k dM/dq_k qd_k from the core's mass_deriv */
            for (int i = 0; i < n * n; ++i) {
                double md_ = 0;
                for (int kk = 0; kk < n; ++kk) md_ += dM[kk * n * n + i] * qds[k][kk];
                ENSURE_NEAR(Md[i], md_, 1e-9 * sc, "%s M_dot vs dM/dq qd entry %d run %d tick %d",
                            kname(kind), i, run, k);
            }
        }
    }
    printf("%-12s M_dot - 2C: worst |sym part|/scale %.1e (largest entry of M_dot - 2C: %.2f of scale)\n",
           kname(kind), worst, biggest_N);
}

/* ---------------------------------------------------------------- power balance */
/* A smooth input: tau_i(t) = a_i sin(w_i t + c_i), on every coordinate (a) or on the
 * actuated ones only (b). */
typedef struct { double a[3], w[3], c[3]; } input_fn;

static void input_at(const input_fn *u, int n, double t, double *tau)
{
    for (int i = 0; i < n; ++i) tau[i] = u->a[i] * sin(u->w[i] * t + u->c[i]);
}

/* y = (q, qd, W), W = work integral of qd . tau. */
static void aug_rhs(const lag_model *md, const input_fn *u, double t, const double *y, double *yd)
{
    int n = md->nq;
    double tau[3] = {0}, qdd[3] = {0};
    input_at(u, n, t, tau);
    if (lag_model_forward(md, y, y + n, tau, qdd) != LAG_OK) {
        lt_failures++;
        fprintf(stderr, "forward failed at t = %g\n", t);
        memset(qdd, 0, sizeof qdd);
    }
    double P = 0;
    for (int i = 0; i < n; ++i) {
        yd[i] = y[n + i];
        yd[n + i] = qdd[i];
        P += y[n + i] * tau[i];
    }
    yd[2 * n] = P;
}

/* Our own RK4 over the core's forward dynamics for duration T at step h; returns
 * E(T) - E(0) - W(T), E = our T + U. */
static double power_mismatch(const lag_model *md, const input_fn *u, const double *q0,
                             const double *qd0, double T, int steps, double *scale)
{
    int n = md->nq, ny = 2 * n + 1;
    double y[7] = {0}, k1[7] = {0}, k2[7] = {0}, k3[7] = {0}, k4[7] = {0}, yt[7] = {0};
    memcpy(y, q0, n * sizeof *y);
    memcpy(y + n, qd0, n * sizeof *y);
    double E0 = tc_T(md, y, y + n) + tc_U(md, y);
    double h = T / steps, sc = fabs(E0);
    for (int s = 0; s < steps; ++s) {
        double t = s * h;
        aug_rhs(md, u, t, y, k1);
        for (int i = 0; i < ny; ++i) yt[i] = y[i] + 0.5 * h * k1[i];
        aug_rhs(md, u, t + 0.5 * h, yt, k2);
        for (int i = 0; i < ny; ++i) yt[i] = y[i] + 0.5 * h * k2[i];
        aug_rhs(md, u, t + 0.5 * h, yt, k3);
        for (int i = 0; i < ny; ++i) yt[i] = y[i] + h * k3[i];
        aug_rhs(md, u, t + h, yt, k4);
        for (int i = 0; i < ny; ++i) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
        sc = fmax(sc, fmax(fabs(tc_T(md, y, y + n)), fabs(y[2 * n])));
    }
    *scale = sc;
    return tc_T(md, y, y + n) + tc_U(md, y) - E0 - y[2 * n];
}

static void check_power(lag_model_kind kind)
{
    lt_rng rng = {0x9090u + (uint64_t)kind};
    const lag_model_info *inf = lag_model_info_get(kind);
    double worst_a = 0, worst_b[LAG_METHOD_COUNT] = {0};
    for (int run = 0; run < 5; ++run) {
        lag_model md;
        tc_random_model(&rng, kind, &md);
        int n = md.nq;
        double q0[3] = {0}, qd0[3] = {0};
        tc_random_state(&rng, &md, q0, qd0);
        for (int i = 0; i < n; ++i) qd0[i] = lt_uniform(&rng, -1, 1);
        tc_motion_start(&rng, &md, q0);
        input_fn u;
        for (int i = 0; i < 3; ++i) {
            u.a[i] = lt_uniform(&rng, 0.5, 3);
            u.w[i] = lt_uniform(&rng, 1, 6);
            u.c[i] = lt_uniform(&rng, 0, 2 * TC_PI);
        }
        /* (a) RK4 of our own over 1 s at h = 1, 1/2, 1/4 ms. The mismatch
         * E(T) - E(0) - W(T) is RK4's global error, ~ T (rate h)^4 |E|, which for the fastest
         * random scenes (small sticks, rates ~ 25/s) is ~ 4e-7 |E| at 1 ms. So what is
         * asserted is the limit: two halvings of h divide the mismatch by >= 50 (order
         * >= 2.8; RK4 gives 256) unless at 1 ms it is already below 1e-10 |E| (rounding of
         * E and W over 4000 steps is ~ 1e-13 |E|, and a signed error may cross zero), and at
         * h = 1/4 ms it is below 1e-8 |E|. A wrong C or g leaves an O(1) mismatch that does
         * not shrink. */
        double sc[3], e[3];
        for (int r = 0; r < 3; ++r) e[r] = power_mismatch(&md, &u, q0, qd0, 1.0, 1000 << r, &sc[r]);
        if (fabs(e[0]) > 1e-10 * sc[0])
            ENSURE_NEAR(fabs(e[2]), 0.0, fabs(e[0]) / 50,
                        "%s dE/dt = qd.tau (own rk4): mismatch %.3g at 1 ms does not shrink (%.3g, %.3g "
                        "at 1/2, 1/4 ms), run %d", kname(kind), e[0], e[1], e[2], run);
        ENSURE_NEAR(e[2], 0.0, 1e-8 * sc[2], "%s dE/dt = qd.tau (own rk4, h = 0.25 ms) run %d", kname(kind), run);
        worst_a = fmax(worst_a, fabs(e[2]) / sc[2]);

        /* (b) lag_sim with the input held over each tick, every method, at dt = 1 ms and
         * 0.5 ms (the input is re-sampled each tick). The work of a constant tau over a tick
         * is exactly tau . (q_end - q_start) (actuated coordinates only: the core must
         * ignore the rest), so the mismatch is the method's energy error alone, O(dt^p).
         * Asserted: halving dt divides it by >= 2^(p - 1/2) (p = 1: 1.4, 2: 2.8, 4: 11),
         * unless it is already at the rounding floor (1e-11 |E|). dopri5 (rtol 1e-11) is
         * not a dt method: its mismatch must stay below 1e-7 |E| (tolerance x 1e4 steps). */
        for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) {
            lag_method meth = (lag_method)mi;
            double mis[2], scb[2];
            for (int r = 0; r < 2; ++r) {
                double dt = 1e-3 / (1 << r);
                int nt = 1000 << r;
                lag_sim_def def = tc_sim_def(&md, meth, dt, q0, qd0);
                def.integrator.rtol = 1e-11;
                def.integrator.atol = 1e-13;
                lag_sim s;
                if (tc_sim_init(&s, &def)) return;
                double E0 = lag_sim_energy(&s), W = 0, scale = fabs(E0);
                for (int k = 0; k < nt; ++k) {
                    double tau[3] = {0}, qprev[3];
                    input_at(&u, n, k * dt, tau);
                    lag_sim_set_input(&s, tau);
                    memcpy(qprev, s.q, sizeof qprev);
                    if (tc_advance(&s, 1, false)) break;
                    for (int i = 0; i < n; ++i)
                        if (inf->actuated[i]) W += tau[i] * (s.q[i] - qprev[i]);
                    scale = fmax(scale, fmax(fabs(lag_model_kinetic(&md, s.q, s.qd)), fabs(W)));
                }
                mis[r] = lag_sim_energy(&s) - E0 - W;
                scb[r] = scale;
            }
            if (tc_method(mi)->adaptive) {
                ENSURE_NEAR(mis[0], 0.0, 1e-7 * scb[0], "%s dopri5: E(1 s) - E(0) - work, run %d", kname(kind), run);
            } else if (fabs(mis[0]) > 1e-11 * scb[0]) {
                double need = pow(2.0, lag_method_order(meth) - 0.5);
                ENSURE_NEAR(fabs(mis[1]), 0.0, fabs(mis[0]) / need,
                            "%s %s: energy balance mismatch %.3g at 1 ms does not shrink at order %d "
                            "(0.5 ms: %.3g), run %d",
                            kname(kind), lag_method_name(meth), mis[0], lag_method_order(meth), mis[1], run);
            }
            worst_b[mi] = fmax(worst_b[mi], fabs(mis[0]) / scb[0]);
        }
    }
    printf("%-12s dE/dt = qd.tau: own rk4 (h 0.25 ms) worst %.1e of |E|; lag_sim at 1 ms:", kname(kind), worst_a);
    for (int mi = 0; mi < LAG_METHOD_COUNT; ++mi) printf(" %s %.1e", lag_method_name((lag_method)mi), worst_b[mi]);
    printf("\n");
}

static void case_model(int kind)
{
    check_spd((lag_model_kind)kind);
    check_skew((lag_model_kind)kind);
    check_power((lag_model_kind)kind);
}

/* One case per model of the core's table. */
int main(int argc, char **argv)
{
    lt_cases cs = {0};
    for (int k = 0; k < LAG_MODEL_COUNT; ++k)
        lt_add(&cs, lag_model_info_get((lag_model_kind)k)->name, case_model, k, 0);
    return lt_main(argc, argv, cs.c, cs.n);
}
