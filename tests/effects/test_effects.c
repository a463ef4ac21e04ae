/*
 * Each effect does what it says, checked against expectations of our own:
 * closed-form solutions, conservation laws, energy balances by quadrature.
 *
 *   test_effects damping|friction|limits|floor|actuator|disturbance|noise|off
 *
 * Every case prints the figure it reached.
 */
#include "effects_test.h"

/* ================================================================== damping */

/* DIPC with damping on every joint: dE/dt = -sum b_i qd_i^2 pointwise (central differences
 * of our own E along the run) and E(t) - E(0) = -int sum b_i qd_i^2 dt (Simpson). */
static double damping_power(double dt)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
    const double b[3] = {0.8, 0.05, 0.03};
    d.effects.enabled = LAG_EFF_DAMPING;
    for (int i = 0; i < 3; i++) d.effects.damping[i] = b[i];
    d.q0[1] = 0.6; d.q0[2] = -0.4; d.qd0[0] = 0.5; d.qd0[1] = 1.0;
    d.integrator.dt = dt;
    lag_sim s;
    te_init(&s, &d);
    enum { NMAX = 8000 };
    static double E[NMAX + 1], P[NMAX + 1];
    const int N = (int)lround(4.0 / dt);
    for (int k = 0; k <= N; k++) {
        if (k > 0) ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        E[k] = te_sim_energy(&s);
        P[k] = 0.0;
        for (int i = 0; i < 3; i++) P[k] -= b[i] * s.qd[i] * s.qd[i];
    }
    double maxerr = 0.0, maxP = 0.0;
    for (int k = 2; k < N - 1; k++) {
        /* fourth-order central difference: error dt^4/30 E^(5) */
        double dE = (-E[k + 2] + 8 * E[k + 1] - 8 * E[k - 1] + E[k - 2]) / (12 * dt);
        maxerr = fmax(maxerr, fabs(dE - P[k]));
        maxP = fmax(maxP, fabs(P[k]));
    }
    double simpson = 0.0;
    for (int k = 0; k < N; k += 2) simpson += dt / 3 * (P[k] + 4 * P[k + 1] + P[k + 2]);
    double balance = (E[N] - E[0]) - simpson;
    printf("damping: DIPC, dt %g: dE/dt vs -b qd^2: max |diff| %.2e (max |dE/dt| %.3f W, "
           "4th-order central differences); E(4 s) - E(0) = %.6f J, -int b qd^2 dt = %.6f J, "
           "balance %.2e J\n", dt, maxerr, maxP, E[N] - E[0], simpson, balance);
    ENSURE(maxerr < 1e-5 * maxP);
    ENSURE(fabs(balance) < 1e-9 * fabs(simpson));
    ENSURE(E[N] < E[0] - 0.1); /* it did dissipate */
    return maxerr;
}

/* The pointwise difference is the difference formula's truncation error: it must fall
 * like dt^4 (a factor 16 when dt halves); a wrong damping force would leave a floor. */
static void damping_power_converges(void)
{
    double e1 = damping_power(1e-3), e2 = damping_power(5e-4);
    printf("damping: dE/dt error ratio dt 1e-3 / 5e-4 = %.1f (dt^4: 16)\n", e1 / e2);
    ENSURE(e1 / e2 > 10);
}

/* Stick, damping b on x: x is decoupled (M diagonal, no C term), so
 * xd(t) = xd0 exp(-b t / m), x(t) = x0 + xd0 m/b (1 - exp(-b t / m)) exactly. */
static void damping_stick_x(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    const double b = 2.0, m = d.model.p[LAG_STICK_M];
    d.effects.enabled = LAG_EFF_DAMPING;
    d.effects.damping[0] = b;
    d.q0[1] = 1.0; d.qd0[0] = 1.5; d.qd0[1] = 0.0;
    lag_sim s;
    te_init(&s, &d);
    double maxe = 0.0;
    for (int k = 1; k <= 3000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double t = lag_sim_time(&s), a = exp(-b * t / m);
        maxe = fmax(maxe, fabs(s.qd[0] - 1.5 * a));
        maxe = fmax(maxe, fabs(s.q[0] - 1.5 * m / b * (1 - a)));
    }
    printf("damping: stick x vs xd0 exp(-b t/m) over 3 s (rk4, dt 1e-3): max error %.2e\n", maxe);
    ENSURE(maxe < 1e-11);
}

/* Manipulator hanging (q1 = -pi/2 + a) with q2 resting at its upper stop (gravity and the
 * centrifugal force push it outward): a physical pendulum with J = m1 l1^2 + m2 q2^2 + I1
 * + I2 and K = (m1 l1 + m2 q2) g. Linearized, J a'' + b a' + K a = 0, a(0) = A, a'(0) = 0:
 *   a(t) = A exp(-zeta wn t) (cos wd t + zeta wn / wd sin wd t). */
static void damping_pendulum(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_MANIPULATOR);
    const double *p = d.model.p;
    const double b = 0.3, A = 1e-3, q2 = 0.5;
    d.effects.enabled = LAG_EFF_DAMPING | LAG_EFF_LIMITS;
    d.effects.damping[0] = b;
    d.effects.limit_on[1] = true;
    d.effects.limit_lower[1] = 0.1;
    d.effects.limit_upper[1] = q2;
    d.effects.restitution[1] = 0.5;
    d.q0[0] = -TE_PI / 2 + A; d.q0[1] = q2;
    lag_sim s;
    te_init(&s, &d);
    double J = p[LAG_MANIP_M1] * p[LAG_MANIP_L1] * p[LAG_MANIP_L1] + p[LAG_MANIP_M2] * q2 * q2 +
               p[LAG_MANIP_I1] + p[LAG_MANIP_I2];
    double K = (p[LAG_MANIP_M1] * p[LAG_MANIP_L1] + p[LAG_MANIP_M2] * q2) * p[LAG_MANIP_G];
    double wn = sqrt(K / J), zeta = b / (2 * sqrt(K * J)), wd = wn * sqrt(1 - zeta * zeta);
    double maxe = 0.0, maxq2 = 0.0;
    for (int k = 1; k <= 5000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double t = lag_sim_time(&s);
        double a = A * exp(-zeta * wn * t) * (cos(wd * t) + zeta * wn / wd * sin(wd * t));
        maxe = fmax(maxe, fabs((s.q[0] + TE_PI / 2) - a));
        maxq2 = fmax(maxq2, fabs(s.q[1] - q2));
    }
    lag_event ev;
    int rest = 0;
    while (lag_sim_poll_event(&s, &ev)) rest += ev.kind == LAG_EV_REST;
    printf("damping: hanging pendulum (zeta %.4f, wn %.3f rad/s) vs closed form over 5 s: "
           "max |a - a_exact| %.2e rad (A = %g; nonlinearity ~A^3 wn t = %.1e), q2 held to %.1e\n",
           zeta, wn, maxe, A, A * A * A * wn * 5, maxq2);
    ENSURE(maxe < 2e-8);
    ENSURE(maxq2 == 0.0);
    ENSURE(rest == 1);
}

/* ================================================================== friction */

/* Manipulator with g = 0 and q1 at rest: q1 stays put (its equation has only the term
 * 2 m2 q2 q2d q1d), so q2 is a block of mass m2 on a Coulomb surface. */
static lag_sim_def block_def(double v0, double mus, double muk)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_MANIPULATOR);
    d.model.p[LAG_MANIP_G] = 0.0;
    d.effects.enabled = LAG_EFF_FRICTION;
    d.effects.friction_static[1] = mus;
    d.effects.friction_kinetic[1] = muk;
    d.q0[1] = 0.3;
    d.qd0[1] = v0;
    return d;
}

static void friction_block(void)
{
    const double v0 = 1.0, mus = 3.0, muk = 2.0;
    lag_sim_def d = block_def(v0, mus, muk);
    const double m2 = d.model.p[LAG_MANIP_M2];
    lag_sim s;
    te_init(&s, &d);
    /* phase 1: slides to a stop at t* = m2 v0 / mu_k, x* = x0 + m2 v0^2 / (2 mu_k) */
    double ts = m2 * v0 / muk, xs = 0.3 + m2 * v0 * v0 / (2 * muk);
    double maxe = 0.0, Eprev = te_sim_energy(&s), maxrise = 0.0;
    for (int k = 1; k <= 1000; k++) {
        (void)xs; /* = x at t >= ts, checked through the formula below */
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double t = lag_sim_time(&s), tt = fmin(t, ts);
        double x = 0.3 + v0 * tt - 0.5 * muk / m2 * tt * tt;
        maxe = fmax(maxe, fabs(s.q[1] - x));
        double E = te_sim_energy(&s);
        maxrise = fmax(maxrise, E - Eprev);
        Eprev = E;
    }
    lag_event ev;
    int nev = 0;
    double t_stick = -1;
    while (lag_sim_poll_event(&s, &ev)) {
        nev++;
        if (ev.kind == LAG_EV_STICK) t_stick = ev.t;
    }
    printf("friction: block slides to a stop: stick at t = %.15f s (exact %.15f), max |x - x_exact| "
           "%.2e m, %d event(s), largest energy rise per tick %.1e J\n",
           t_stick, ts, maxe, nev, maxrise);
    ENSURE_NEAR(t_stick, ts, 1e-12, "stick time");
    ENSURE(nev == 1);
    ENSURE(maxe < 1e-12);
    ENSURE(maxrise <= 0.0);
    ENSURE(s.q[0] == d.q0[0] && s.qd[0] == 0.0); /* q1 did not move */

    /* phase 2: a force below mu_s holds, with no motion and no events (no chattering) */
    double x_hold = s.q[1];
    double tau[2] = {0.0, 0.97 * mus};
    lag_sim_set_input(&s, tau);
    ENSURE(lag_sim_advance(&s, 5000, false) == LAG_OK);
    int nev2 = te_drain(&s, 0, NULL);
    printf("friction: force 0.97 mu_s held for 5 s: moved %.1e m, %d events\n",
           fabs(s.q[1] - x_hold), nev2);
    ENSURE(s.q[1] == x_hold && s.qd[1] == 0.0);
    ENSURE(nev2 == 0);
    tau[1] = -0.97 * mus;
    lag_sim_set_input(&s, tau);
    ENSURE(lag_sim_advance(&s, 1000, false) == LAG_OK);
    ENSURE(s.q[1] == x_hold && te_drain(&s, 0, NULL) == 0);

    /* phase 3: above mu_s it slips at once and accelerates at (F - mu_k) / m2 */
    const double F = 3.5;
    tau[1] = F;
    lag_sim_set_input(&s, tau);
    double t1 = lag_sim_time(&s);
    double maxe3 = 0.0;
    for (int k = 1; k <= 1000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double t = lag_sim_time(&s) - t1;
        maxe3 = fmax(maxe3, fabs(s.q[1] - (x_hold + 0.5 * (F - muk) / m2 * t * t)));
    }
    int slips = 0, nev3 = 0;
    double t_slip = -1;
    while (lag_sim_poll_event(&s, &ev)) {
        nev3++;
        if (ev.kind == LAG_EV_SLIP) { slips++; t_slip = ev.t; }
    }
    printf("friction: force %.1f > mu_s: slip at t = %.6f (force applied at %.6f), max |x - "
           "x_exact| %.2e m over 1 s\n", F, t_slip, t1, maxe3);
    ENSURE(slips == 1 && nev3 == 1);
    ENSURE_NEAR(t_slip, t1, 1e-12, "slip time");
    ENSURE(maxe3 < 1e-11);
}

/* DIPC with friction on every joint and no input: the energy never rises, and the energy
 * lost equals the friction work sum_i mu_k,i * (path length of q_i), path lengths summed
 * per tick as |q_i(k+1) - q_i(k)|. That sum is exact while q_i is monotone in a tick; a tick
 * in which q_i reverses (a stick event) undercounts by at most mu_k a dt^2: the bound. */
static void friction_dipc(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
    const double mus[3] = {1.0, 0.02, 0.015}, muk[3] = {0.7, 0.015, 0.01};
    d.effects.enabled = LAG_EFF_FRICTION;
    for (int i = 0; i < 3; i++) {
        d.effects.friction_static[i] = mus[i];
        d.effects.friction_kinetic[i] = muk[i];
    }
    d.q0[1] = TE_PI - 0.8; d.q0[2] = TE_PI + 0.5; d.qd0[0] = 0.8;
    lag_sim s;
    te_init(&s, &d);
    double E0 = te_sim_energy(&s), Eprev = E0, maxrise = -INFINITY, diss = 0.0;
    double qprev[3] = {s.q[0], s.q[1], s.q[2]};
    int nev = 0, sticks = 0;
    for (int k = 1; k <= 20000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double E = te_sim_energy(&s);
        maxrise = fmax(maxrise, E - Eprev);
        Eprev = E;
        for (int i = 0; i < 3; i++) { diss += muk[i] * fabs(s.q[i] - qprev[i]); qprev[i] = s.q[i]; }
        lag_event ev;
        while (lag_sim_poll_event(&s, &ev)) { nev++; sticks += ev.kind == LAG_EV_STICK; }
    }
    double E1 = te_sim_energy(&s);
    double balance = (E1 - E0) + diss;
    /* accelerations here are below 50 (rad or m)/s^2; see the bound above */
    double bound = (sticks + 1) * 0.7 * 50 * 1e-6 + 1e-9 * E0;
    printf("friction: DIPC 20 s, friction on all joints: E %.6f -> %.6f J, friction work %.6f J, "
           "balance %.2e J (bound %.1e), largest rise per tick %.1e J, %d events (%d stick)\n",
           E0, E1, diss, balance, bound, maxrise, nev, sticks);
    ENSURE(fabs(balance) < bound);
    ENSURE(maxrise < 1e-9 * fabs(E0));
    ENSURE(nev < 200);
}

/* ================================================================== limits */

/* Manipulator with g = 0, q1 at rest: q2 moves freely between stops [lo, hi] with speed
 * v0 e^k after k hits; hit times follow from the distances. */
static void limits_free(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_MANIPULATOR);
    const double lo = 0.1, hi = 0.8, e = 0.9, v0 = 1.0, x0 = 0.45;
    d.model.p[LAG_MANIP_G] = 0.0;
    d.effects.enabled = LAG_EFF_LIMITS;
    d.effects.limit_on[1] = true;
    d.effects.limit_lower[1] = lo;
    d.effects.limit_upper[1] = hi;
    d.effects.restitution[1] = e;
    d.q0[1] = x0; d.qd0[1] = v0;
    lag_sim s;
    te_init(&s, &d);
    double t_hit = (hi - x0) / v0, v = v0, maxdt = 0.0, maxdv = 0.0, over = 0.0;
    int hits = 0;
    for (int k = 0; k < 20000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        over = fmax(over, fmax(lo - s.q[1], s.q[1] - hi));
        lag_event ev;
        while (lag_sim_poll_event(&s, &ev)) {
            ENSURE(ev.kind == LAG_EV_LIMIT && ev.joint == 1);
            maxdt = fmax(maxdt, fabs(ev.t - t_hit));
            maxdv = fmax(maxdv, fabs(ev.value - v));
            hits++;
            v = -e * v;
            t_hit += (hi - lo) / fabs(v);
        }
    }
    printf("limits: free block between stops, e = %.1f, 20 s: %d hits, hit times within %.1e s, "
           "impact velocities within %.1e m/s of v0 e^k, deepest excursion past a stop %.1e m\n",
           e, hits, maxdt, maxdv, over);
    ENSURE(hits >= 10);
    ENSURE(maxdt < 1e-12 && maxdv < 1e-12);
    ENSURE(over <= 1e-12);
}

/* Spinning arm with g = 0: between hits E and p1 = (m1 l1^2 + m2 q2^2 + I1 + I2) q1d are
 * conserved; a hit changes q2d only (M is diagonal). At the stop (q2 = bound) the speed
 * follows from E and p1: m2 q2d^2 = 2E - p1^2 / J(bound). So from E before and after the
 * hit, |v+| / |v-| must be e, and e = 1 must keep E. */
static void limits_spin(double e)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_MANIPULATOR);
    const double *p = d.model.p;
    const double lo = 0.1, hi = 0.6;
    d.model.p[LAG_MANIP_G] = 0.0;
    d.effects.enabled = LAG_EFF_LIMITS;
    d.effects.limit_on[1] = true;
    d.effects.limit_lower[1] = lo;
    d.effects.limit_upper[1] = hi;
    d.effects.restitution[1] = e;
    d.effects.rest_velocity = 1e-6;
    d.q0[1] = 0.3; d.qd0[0] = 4.0; d.qd0[1] = -1.5;
    lag_sim s;
    te_init(&s, &d);
    double J0 = p[LAG_MANIP_M1] * p[LAG_MANIP_L1] * p[LAG_MANIP_L1] + p[LAG_MANIP_I1] + p[LAG_MANIP_I2];
    double m2 = p[LAG_MANIP_M2];
    double p1_0 = te_momentum(&d.model, s.q, s.qd, 0);
    double E0 = te_sim_energy(&s), Eprev = E0, maxdev_ratio = 0.0, maxrise = -INFINITY,
           maxdp = 0.0, over = 0.0, maxdE = 0.0;
    int hits = 0;
    for (int k = 0; k < 10000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        over = fmax(over, fmax(lo - s.q[1], s.q[1] - hi));
        double E = te_sim_energy(&s);
        maxdp = fmax(maxdp, fabs(te_momentum(&d.model, s.q, s.qd, 0) - p1_0));
        lag_event ev;
        int hit_here = 0;
        double bound = 0;
        while (lag_sim_poll_event(&s, &ev))
            if (ev.kind == LAG_EV_LIMIT) { hit_here++; bound = ev.value > 0 ? hi : lo; }
        if (hit_here == 1) {
            double Jb = J0 + m2 * bound * bound;
            double vm = sqrt((2 * Eprev - p1_0 * p1_0 / Jb) / m2);
            double vp = sqrt(fmax(0.0, 2 * E - p1_0 * p1_0 / Jb) / m2);
            maxdev_ratio = fmax(maxdev_ratio, fabs(vp / vm - e));
            maxrise = fmax(maxrise, E - Eprev);
            hits++;
        } else if (hit_here == 0) {
            maxdE = fmax(maxdE, fabs(E - Eprev));
        }
        Eprev = E;
    }
    printf("limits: spinning arm, e = %.2f, 10 s: %d hits, |v+/v- - e| <= %.1e, energy change "
           "at a hit <= %+.1e J (between hits per tick %.1e), p1 kept to %.1e, "
           "E %.9f -> %.9f J, past a stop %.1e m\n",
           e, hits, maxdev_ratio, maxrise, maxdE, maxdp, E0, te_sim_energy(&s), over);
    ENSURE(hits >= 3);
    ENSURE(maxdev_ratio < 1e-6);
    ENSURE(maxdp < 1e-9);
    ENSURE(over <= 1e-9);
    if (e == 1.0) ENSURE(fabs(te_sim_energy(&s) - E0) < 1e-9 * E0);
    else ENSURE(maxrise < 0);
}

/* ================================================================== floor */

/* Stick released at rest from phi0 < pi/2 falls to phi = 0. Its landing rate is
 * -sqrt(m g l sin phi0 / J(0)); each landing reverses phi_dot with factor e, so the k-th
 * impact rate is e^k times the first; finally it rests at phi = 0. x_dot never changes. */
static void floor_bounces(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    const double *p = d.model.p;
    const double phi0 = 1.2, e = 0.5, xd = 0.3;
    d.effects.enabled = LAG_EFF_FLOOR;
    d.effects.floor_restitution = e;
    d.effects.rest_velocity = 1e-3;
    d.q0[1] = phi0; d.qd0[0] = xd;
    lag_sim s;
    te_init(&s, &d);
    double v1 = -sqrt(te_stick_phid2(p, phi0, 0.0, 0.0));
    /* time of the first landing by quadrature of dt = dphi / |phid| (theta from vertical) */
    double tq = te_stick_fall_time(p, TE_PI / 2 - phi0, NULL);
    int impacts = 0, rests = 0, other = 0;
    double maxdv = 0.0, t_first = -1, Nmin = INFINITY;
    for (int k = 0; k < 5000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        if (!(s.mode.locked & 2u)) Nmin = fmin(Nmin, te_stick_normal(p, s.q[1], s.qd[1] * s.qd[1]));
        lag_event ev;
        while (lag_sim_poll_event(&s, &ev)) {
            if (ev.kind == LAG_EV_IMPACT) {
                if (impacts == 0) t_first = ev.t;
                double want = v1 * pow(e, impacts);
                maxdv = fmax(maxdv, fabs(ev.value - want) / fabs(want));
                impacts++;
            } else if (ev.kind == LAG_EV_REST) {
                rests++;
            } else {
                other++;
            }
        }
    }
    printf("floor: stick from phi0 = %.1f, e = %.1f: first landing at %.12f s (quadrature %.12f), "
           "%d impacts with rates e^k v1 to %.1e relative, %d rest; then phi = %g, phi_dot = %g, "
           "x_dot - x_dot0 = %.1e, min N/m in flight %.2f m/s^2\n",
           phi0, e, t_first, tq, impacts, maxdv, rests, s.q[1], s.qd[1], s.qd[0] - xd, Nmin);
    ENSURE_NEAR(t_first, tq, 1e-9, "first landing");
    ENSURE(impacts >= 3 && rests == 1 && other == 0);
    ENSURE(maxdv < 1e-6);
    ENSURE(fabs(s.q[1]) <= 1e-15 && s.qd[1] == 0.0);
    ENSURE(s.qd[0] == xd);
    ENSURE(Nmin > 0);
}

/* A stick spinning fast enough lifts off: the core reports LAG_EV_LIFTOFF at the instant
 * our own normal force N(phi) on the energy curve reaches zero (the time to get there by
 * quadrature), and then LAG_ERR_LIFTOFF (a fault: the model no longer holds) on a floor
 * that it may not leave (flight false); with flight the same event, and it flies on. */
typedef struct { const double *p; double phi0, phid0; } te_curve_ctx;
static double inv_rate(double phi, const void *vctx)
{
    const te_curve_ctx *c = (const te_curve_ctx *)vctx;
    return 1.0 / sqrt(te_stick_phid2(c->p, c->phi0, c->phid0, phi));
}
static void floor_liftoff(bool flight)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    const double *p = d.model.p;
    const double phi0 = 0.6, phid0 = 5.0; /* rising towards the vertical, fast */
    d.effects.enabled = LAG_EFF_FLOOR;
    d.effects.floor_flight = flight;
    d.q0[1] = phi0; d.qd0[1] = phid0;
    lag_sim s;
    te_init(&s, &d);
    /* N on the curve: root in phi by bisection (N > 0 at phi0, < 0 at the vertical) */
    double a = phi0, b = TE_PI / 2;
    ENSURE(te_stick_normal(p, a, phid0 * phid0) > 0 && te_stick_normal(p, b, te_stick_phid2(p, phi0, phid0, b)) < 0);
    for (int it = 0; it < 200; it++) {
        double c = 0.5 * (a + b);
        if (te_stick_normal(p, c, te_stick_phid2(p, phi0, phid0, c)) > 0) a = c; else b = c;
    }
    te_curve_ctx c = {p, phi0, phid0};
    double tq = te_gauss5(inv_rate, &c, phi0, a, 400);
    lag_result r = LAG_OK;
    int k;
    lag_event ev;
    double t_lift = -1;
    int n_lift = 0;
    for (k = 0; k < (flight ? 150 : 2000) && r == LAG_OK; k++) {
        r = lag_sim_advance(&s, 1, false);
        while (lag_sim_poll_event(&s, &ev))
            if (ev.kind == LAG_EV_LIFTOFF) { t_lift = ev.t; n_lift++; }
    }
    printf("floor: spinning stick (phi0 %.1f, phid0 %.1f, flight %d): %s at t = %.12f s, our "
           "N = 0 at phi = %.9f reached at %.12f s (quadrature); state finite: %d\n",
           phi0, phid0, flight, lag_result_string(r), t_lift, a, tq, te_finite_state(&s));
    ENSURE(r == (flight ? LAG_OK : LAG_ERR_LIFTOFF));
    ENSURE(n_lift == 1);
    ENSURE_NEAR(t_lift, tq, 1e-9, "lift-off time");
    ENSURE(te_finite_state(&s));
}

/* ================================================================== actuator */

/* Lag: a unit step command through a first-order lag of time constant T gives
 * 1 - exp(-t/T); the effort applied over a tick is the lag's value at the tick's end
 * (exact discretization), and the stick's x (decoupled, M_xx = m) integrates it exactly:
 * m xd(t_k) = sum_j dt * u(t_j). Saturation: a DIPC cart force beyond max is clamped, the
 * onset reported once, and the horizontal momentum p0 grows at exactly the clamped force. */
static void actuator(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    const double T = 0.05, dt = 1e-3, m = d.model.p[LAG_STICK_M];
    d.effects.enabled = LAG_EFF_ACTUATOR;
    d.effects.actuator_tau[0] = T;
    d.q0[1] = 0.3;
    lag_sim s;
    te_init(&s, &d);
    double u[2] = {1.0, 0.0}, maxe = 0.0, mom = 0.0, maxv = 0.0;
    lag_sim_set_input(&s, u);
    for (int k = 1; k <= 300; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double want = 1.0 - exp(-k * dt / T);
        maxe = fmax(maxe, fabs(s.tau_applied[0] - want));
        mom += dt * want;
        maxv = fmax(maxv, fabs(m * s.qd[0] - mom));
    }
    printf("actuator: lag T = %.2f s: applied effort vs 1 - exp(-t/T) within %.1e, x momentum vs "
           "its integral within %.1e, %d events\n", T, maxe, maxv, te_drain(&s, 0, NULL));
    ENSURE(maxe < 1e-14);
    ENSURE(maxv < 1e-13);

    lag_sim_def dd = lag_default_sim_def(LAG_MODEL_DIPC);
    const double fmax_ = 20.0;
    dd.effects.enabled = LAG_EFF_ACTUATOR;
    dd.effects.actuator_max[0] = fmax_;
    dd.q0[1] = 0.3; dd.q0[2] = -0.2;
    te_init(&s, &dd);
    double p00 = te_momentum(&dd.model, s.q, s.qd, 0);
    double cmd[3] = {50.0, 0, 0};
    lag_sim_set_input(&s, cmd);
    ENSURE(lag_sim_advance(&s, 500, false) == LAG_OK);
    ENSURE(s.tau_applied[0] == fmax_);
    double dp = te_momentum(&dd.model, s.q, s.qd, 0) - p00;
    cmd[0] = 10.0; lag_sim_set_input(&s, cmd);
    ENSURE(lag_sim_advance(&s, 100, false) == LAG_OK);
    ENSURE(s.tau_applied[0] == 10.0);
    cmd[0] = -50.0; lag_sim_set_input(&s, cmd);
    ENSURE(lag_sim_advance(&s, 100, false) == LAG_OK);
    ENSURE(s.tau_applied[0] == -fmax_);
    lag_event ev;
    int sat = 0, other = 0;
    double t_sat[2] = {-1, -1}, v_sat[2] = {0, 0};
    while (lag_sim_poll_event(&s, &ev)) {
        if (ev.kind == LAG_EV_SATURATION) { if (sat < 2) { t_sat[sat] = ev.t; v_sat[sat] = ev.value; } sat++; }
        else other++;
    }
    printf("actuator: cart force 50 N with max %.0f N: p0 grew by %.12f N s in 0.5 s (clamped "
           "force x time = %.12f), saturation events at t = %g (cmd %g) and %g (cmd %g)\n",
           fmax_, dp, fmax_ * 0.5, t_sat[0], v_sat[0], t_sat[1], v_sat[1]);
    /* rk4 on (q, qd) keeps p0's balance to its integration error (~1e-9 here) */
    ENSURE_NEAR(dp, fmax_ * 0.5, 1e-8, "p0 under saturation");
    ENSURE(sat == 2 && other == 0);
    ENSURE(t_sat[0] == 0.0 && v_sat[0] == 50.0);
    ENSURE_NEAR(t_sat[1], 0.6, 1e-12, "second onset");
    ENSURE(v_sat[1] == -50.0);
}

/* ================================================================== disturbance */

/* DIPC: no horizontal force but the disturbances on theta0, so the horizontal momentum
 * p0 = dT/d theta0_dot changes only by them: +J at an impulse, +F T for a force held T.
 * A generalized impulse on theta1 changes p1 by its value and leaves p0 alone. */
static void disturbance(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
    const lag_model *m = &d.model;
    d.effects.enabled = LAG_EFF_DISTURBANCE;
    d.effects.n_disturbances = 3;
    d.effects.disturbances[0] = (lag_disturbance){1.0, 0, true, 0.5, 0.0};
    d.effects.disturbances[1] = (lag_disturbance){2.0, 0, false, 0.2, 0.1};
    d.effects.disturbances[2] = (lag_disturbance){3.0, 1, true, 0.3, 0.0};
    d.q0[1] = TE_PI - 0.4; d.q0[2] = TE_PI + 0.3; d.qd0[1] = 0.5;
    lag_sim s;
    te_init(&s, &d);
    double p0[4001], p1[4001];
    for (int k = 0; k <= 4000; k++) {
        if (k) ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        p0[k] = te_momentum(m, s.q, s.qd, 0);
        p1[k] = te_momentum(m, s.q, s.qd, 1);
    }
    double jump = p0[1001] - p0[1000];
    double ramp = p0[2100] - p0[2000];
    double steady = 0.0;
    for (int k = 1; k <= 4000; k++)
        if (k != 1001 && !(k > 2000 && k <= 2100)) steady = fmax(steady, fabs(p0[k] - p0[k - 1]));
    /* p1 across its impulse: the tick's own change (with the velocities after the impulse)
     * extrapolated back from the next two ticks, error O(dt^3 p1''') */
    double p1jump = p1[3001] - p1[3000] - (2 * (p1[3002] - p1[3001]) - (p1[3003] - p1[3002]));
    lag_event ev;
    int n = 0;
    double te[3] = {-1, -1, -1};
    while (lag_sim_poll_event(&s, &ev))
        if (ev.kind == LAG_EV_DISTURBANCE && n < 3) te[n++] = ev.t;
    printf("disturbance: p0 jump %.15f (impulse 0.5), p0 gain over the force %.15f (F T = 0.02), "
           "p0 change elsewhere per tick <= %.1e, p1 jump %.9f (impulse 0.3), events at %g %g %g\n",
           jump, ramp, steady, p1jump, te[0], te[1], te[2]);
    ENSURE_NEAR(jump, 0.5, 1e-12, "impulse");
    /* rk4 on (q, qd) keeps p0 to its integration error: ~1e-12 per tick here */
    ENSURE_NEAR(ramp, 0.02, 1e-9, "force x duration");
    ENSURE(steady < 1e-11);
    ENSURE_NEAR(p1jump, 0.3, 1e-6, "impulse on theta1");
    ENSURE(n == 3 && te[0] == 1.0 && te[1] == 2.0 && te[2] == 3.0);
}

/* Disturbances scheduled beyond any reachable tick (t / dt past the range of a tick
 * count, or just far away) never act and never report: the run is bit-identical to one
 * without them. (A time converted to a tick count without saturating overflowed, and a
 * force at t = 1e300 acted from t = 0 without an event.) A time is at most LAG_TIME_MAX
 * (the check refuses more: core_validate_fields), so past the range of a tick count takes
 * a tick of 1e-11 s: 1e9 s is 1e20 ticks. */
static void disturbance_far(void)
{
    lag_sim_def bare = lag_default_sim_def(LAG_MODEL_DIPC);
    bare.q0[1] = 0.3; bare.q0[2] = -0.2; bare.qd0[0] = 0.1;
    bare.integrator.dt = 1e-11;
    bare.integrator.dt_min = 1e-15;
    lag_sim_def far = bare;
    far.effects.enabled = LAG_EFF_DISTURBANCE;
    const double times[] = {LAG_TIME_MAX, LAG_TIME_MAX, 1e8, 9.3e7, 5e8, 1e9, 1e3};
    const int nt = (int)(sizeof times / sizeof times[0]);
    far.effects.n_disturbances = nt;
    for (int k = 0; k < nt; k++)
        far.effects.disturbances[k] = (lag_disturbance){times[k], k % 3, k == 1, 5.0, k == 1 ? 0.0 : 1.0};
    lag_sim a, b;
    te_init(&a, &bare);
    te_init(&b, &far);
    int events = 0;
    bool same = true;
    for (int k = 0; k < 1000; k++) {
        ENSURE(lag_sim_advance(&a, 1, false) == LAG_OK);
        ENSURE(lag_sim_advance(&b, 1, false) == LAG_OK);
        events += te_drain(&b, 0, NULL);
        same = same && memcmp(a.q, b.q, sizeof a.q) == 0 && memcmp(a.qd, b.qd, sizeof a.qd) == 0;
    }
    printf("disturbance_far: %d disturbances at 1e3 to 1e9 s, 1000 ticks: %d events, trajectory %s\n",
           nt, events, same ? "bit-identical to none" : "DIFFERS from none");
    ENSURE(events == 0);
    ENSURE(same);
}

/* ================================================================== noise */

static void noise(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
    const double sq = 1e-3, sqd = 2e-3;
    d.q0[1] = 0.2; d.q0[2] = -0.1;
    lag_sim_def dn = d;
    dn.effects.enabled = LAG_EFF_NOISE;
    dn.effects.noise_seed = 7;
    dn.effects.noise_q[1] = sq;
    dn.effects.noise_qd[0] = sqd;
    lag_sim a, b, c, bare;
    te_init(&a, &dn);
    te_init(&b, &dn);
    dn.effects.noise_seed = 8;
    te_init(&c, &dn);
    te_init(&bare, &d);
    enum { N = 20000 };
    double s1 = 0, s2 = 0, t1 = 0, t2 = 0;
    int same_ab = 1, diff_ac = 0, exact_other = 1, true_same = 1;
    for (int k = 0; k < N; k++) {
        double qa[3], qda[3], qb[3], qdb[3], qc[3], qdc[3];
        lag_sim_observe(&a, qa, qda);
        lag_sim_observe(&b, qb, qdb);
        lag_sim_observe(&c, qc, qdc);
        if (memcmp(qa, qb, sizeof qa) || memcmp(qda, qdb, sizeof qda)) same_ab = 0;
        if (qc[1] != qa[1]) diff_ac++;
        double e1 = qa[1] - a.q[1], e2 = qda[0] - a.qd[0];
        s1 += e1; s2 += e1 * e1; t1 += e2; t2 += e2 * e2;
        if (qa[0] != a.q[0] || qa[2] != a.q[2] || qda[1] != a.qd[1] || qda[2] != a.qd[2])
            exact_other = 0;
        if (memcmp(a.q, bare.q, sizeof a.q) || memcmp(a.qd, bare.qd, sizeof a.qd)) true_same = 0;
        ENSURE(lag_sim_advance(&a, 1, false) == LAG_OK);
        ENSURE(lag_sim_advance(&b, 1, false) == LAG_OK);
        ENSURE(lag_sim_advance(&c, 1, false) == LAG_OK);
        ENSURE(lag_sim_advance(&bare, 1, false) == LAG_OK);
    }
    double m1 = s1 / N, sd1 = sqrt(s2 / N - m1 * m1), m2 = t1 / N, sd2 = sqrt(t2 / N - m2 * m2);
    /* 5 sigma bounds: mean ~ sigma / sqrt(N), sample std ~ sigma sqrt(1 / (2N)) */
    double mb = 5 / sqrt((double)N), sb = 5 * sqrt(0.5 / N);
    printf("noise: %d samples: theta1 noise mean %.2e std %.4e (want 0, %.0e), theta0_dot noise "
           "mean %.2e std %.4e (want 0, %.0e); 5-sigma bounds %.1e, %.1e relative; same seed "
           "identical: %d, other seed differs in %d/%d, true state bit-identical to no noise: %d\n",
           N, m1, sd1, sq, m2, sd2, sqd, mb, sb, same_ab, diff_ac, N, true_same);
    ENSURE(fabs(m1) < mb * sq && fabs(sd1 / sq - 1) < sb);
    ENSURE(fabs(m2) < mb * sqd && fabs(sd2 / sqd - 1) < sb);
    ENSURE(same_ab && exact_other);
    ENSURE(diff_ac > N - 10);
    ENSURE(true_same);
    /* a replay: reset and rerun gives the same observed sequence (deterministic in seed, tick) */
    double first[3], qd_[3], again[3];
    lag_sim_reset(&b, NULL, NULL);
    lag_sim_observe(&b, first, qd_);
    lag_sim_reset(&a, NULL, NULL);
    lag_sim_observe(&a, again, qd_);
    ENSURE(memcmp(first, again, sizeof first) == 0);
}

/* ================================================================== spring */

/* Stick with a spring on x: x is decoupled (M_00 = m, no bias), so m x'' = -k (x - r):
 *   x(t) = r + (x0 - r) cos w t + v0 / w sin w t,  w = sqrt(k / m),
 * with rk4 at 1 ms and with dopri5 (a force-only effect: no tick boundaries needed). */
static void spring_stick_x(void)
{
    for (int meth = 0; meth < 2; meth++) {
        lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
        const double k = 4.0, r = 0.3, m = d.model.p[LAG_STICK_M], w = sqrt(k / m);
        d.integrator.method = meth ? LAG_DOPRI5 : LAG_RK4;
        d.integrator.rtol = 1e-12;
        d.integrator.atol = 1e-14;
        d.effects.enabled = LAG_EFF_SPRING;
        d.effects.spring_k[0] = k;
        d.effects.spring_rest[0] = r;
        d.q0[0] = 1.0; d.q0[1] = 1.0; d.qd0[0] = -0.5;
        lag_sim s;
        te_init(&s, &d);
        double maxe = 0.0;
        for (int t = 1; t <= 3000; t++) {
            ENSURE(lag_sim_advance(&s, 1, meth == 1) == LAG_OK);
            double tt = lag_sim_time(&s);
            double x = r + (1.0 - r) * cos(w * tt) - 0.5 / w * sin(w * tt);
            maxe = fmax(maxe, fabs(s.q[0] - x));
        }
        printf("spring: stick x against r + (x0 - r) cos wt + v0/w sin wt over 3 s (%s): max error %.2e\n",
               te_method(d.integrator.method), maxe);
        ENSURE(maxe < 1e-10);
    }
}

/* DIPC with a spring on every joint, unforced, gauss4 (symplectic): the energy the core
 * reports (lag_sim_energy, what status and CSV print) is our own T + U plus the springs'
 * 1/2 k (q - r)^2, and it is conserved; T + U alone is not (the springs trade energy with
 * the motion), which is what a leak would look like without the springs' potential. */
static void spring_energy(void)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_DIPC);
    const double k[3] = {20.0, 3.0, 1.5}, r[3] = {0.1, 0.2, -0.3};
    d.integrator.method = LAG_GAUSS4;
    d.effects.enabled = LAG_EFF_SPRING;
    for (int i = 0; i < 3; i++) { d.effects.spring_k[i] = k[i]; d.effects.spring_rest[i] = r[i]; }
    d.q0[1] = TE_PI - 0.4; d.q0[2] = TE_PI + 0.3; d.qd0[0] = 0.5;
    lag_sim s;
    te_init(&s, &d);
    double E0 = 0, TU0 = 0, max_hook = 0, max_drift = 0, max_tu = 0;
    for (int t = 0; t <= 5000; t++) {
        if (t) ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        double Us = 0;
        for (int i = 0; i < 3; i++) Us += 0.5 * k[i] * (s.q[i] - r[i]) * (s.q[i] - r[i]);
        double TU = te_sim_energy(&s), E = TU + Us;
        if (t == 0) { E0 = E; TU0 = TU; }
        max_hook = fmax(max_hook, fabs(lag_sim_energy(&s) - E));
        max_drift = fmax(max_drift, fabs(E - E0));
        max_tu = fmax(max_tu, fabs(TU - TU0));
    }
    printf("spring: DIPC with springs, gauss4, 5 s: |lag_sim_energy - (T + U + springs)| <= %.1e J; "
           "T + U + springs varies by %.1e J, T + U alone by %.3f J\n", max_hook, max_drift, max_tu);
    ENSURE(max_hook < 1e-12 * fabs(E0) + 1e-12);
    ENSURE(max_drift < 1e-8 * fabs(E0));
    ENSURE(max_tu > 0.1);
}

/* ================================================================== off */

/* Every effect's settings, given values that make each effect act on the run started at
 * d's initial state (stops 0.01 around it, a disturbance at 10 ms, ...); enabled = 0. */
static void off_fill(lag_effects_def *e, const lag_sim_def *d)
{
    for (int i = 0; i < LAG_MAX_DOF; i++) {
        e->damping[i] = 3.0; e->friction_static[i] = 2.0; e->friction_kinetic[i] = 1.0;
        e->limit_on[i] = true; e->limit_lower[i] = d->q0[i] - 0.01; e->limit_upper[i] = d->q0[i] + 0.01;
        e->restitution[i] = 0.5; e->actuator_max[i] = 0.1; e->actuator_tau[i] = 0.3;
        e->noise_q[i] = 0.1; e->noise_qd[i] = 0.1;
        e->spring_k[i] = 4.0; e->spring_rest[i] = 0.1;
    }
    e->floor_restitution = 0.2;
    e->n_disturbances = 1;
    e->disturbances[0] = (lag_disturbance){0.01, 0, true, 5.0, 0.0};
    e->enabled = 0;
}

/* d's model at a moving state, with method meth. */
static lag_sim_def off_def(int kind, int meth)
{
    lag_sim_def d = lag_default_sim_def((lag_model_kind)kind);
    d.integrator.method = (lag_method)meth;
    d.q0[0] = 0.2; d.q0[1] = 0.7; d.qd0[0] = 0.3; d.qd0[1] = -0.4;
    if (kind == LAG_MODEL_DIPC) { d.q0[2] = -0.5; d.qd0[2] = 0.2; }
    return d;
}

/* Runs `ticks` ticks of def under a fixed input; false if the core refuses def. The
 * observed state goes to o (2 x 3 entries), the run's own to s. */
static bool off_run(lag_sim *s, const lag_sim_def *def, int64_t ticks, double o[6])
{
    char err[256];
    if (lag_sim_init(s, def, err, sizeof err) != LAG_OK) return false;
    double u[3] = {0.5, -0.3, 0.0};
    lag_sim_set_input(s, u);
    ENSURE(lag_sim_advance(s, ticks, true) == LAG_OK);
    for (int i = 0; i < 6; i++) o[i] = 0.0;
    lag_sim_observe(s, o, o + 3);
    return true;
}

static bool off_same(const lag_sim *s0, const double o0[6], const lag_sim *s1, const double o1[6])
{
    size_t nb = (size_t)s0->nq * sizeof(double); /* only the model's nq entries are defined */
    return s0->nq == s1->nq && memcmp(s0->q, s1->q, nb) == 0 && memcmp(s0->qd, s1->qd, nb) == 0 &&
           memcmp(o0, o1, 6 * sizeof(double)) == 0 && s1->n_events == s0->n_events &&
           s0->stats.rhs_evals == s1->stats.rhs_evals;
}

/* The fill above reaches every effect of the core's table: each one, switched on alone
 * with it, changes the run of some model (state, observed state, events or work), so an
 * effect whose settings the fill leaves out fails here by name, not by passing `off`
 * with nothing configured. */
static void off_fill_covers_table(void)
{
    int acting = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        lag_effect_info inf = lag_effect_info_get(k);
        bool accepted = false, acts = false;
        for (int kind = 0; kind < LAG_MODEL_COUNT && !acts; kind++) {
            lag_sim_def d = off_def(kind, LAG_RK4), x = d;
            off_fill(&x.effects, &d);
            x.effects.enabled = inf.bit;
            lag_sim s0, s1;
            double o0[6], o1[6];
            if (!off_run(&s1, &x, 200, o1)) continue;
            accepted = true;
            ENSURE(off_run(&s0, &d, 200, o0));
            acts = !off_same(&s0, o0, &s1, o1);
        }
        if (!accepted || !acts)
            LT_FAIL("off: effect '%s' of the core's table: the settings the test fills %s", inf.name,
                    accepted ? "change no model's run when it is on alone (fill them in off_fill)"
                             : "are refused by the core for every model");
        else
            ENSURE(acts);
        acting += acts;
    }
    printf("off: the filled settings make %d of the %d effects of the core's table act\n",
           acting, LAG_EFF_COUNT);
}

/* An effect that is off costs nothing: a definition carrying every effect's parameters but
 * enabled = 0 gives exactly the bare model's trajectory (memcmp), for every model and
 * method. */
static void off(void)
{
    off_fill_covers_table();
    int compared = 0, identical = 0;
    for (int kind = 0; kind < LAG_MODEL_COUNT; kind++)
        for (int meth = 0; meth < LAG_METHOD_COUNT; meth++) {
            lag_sim_def d = off_def(kind, meth), x = d;
            off_fill(&x.effects, &d);
            lag_sim s0, s1;
            double o0[6], o1[6];
            ENSURE(off_run(&s0, &d, 2000, o0));
            ENSURE(off_run(&s1, &x, 2000, o1));
            bool same = off_same(&s0, o0, &s1, o1) && s1.n_events == 0;
            compared++;
            identical += same;
            if (!same)
                fprintf(stderr, "off: %s %s differs from the bare model\n",
                        lag_model_info_get((lag_model_kind)kind)->name, lag_method_name((lag_method)meth));
        }
    printf("off: %d/%d model x method runs with every effect configured but disabled are "
           "bit-identical to the bare model (state, observed state, rhs evaluations)\n",
           identical, compared);
    ENSURE(identical == compared);
}


/* ------------------------------------------------------------------ keeps_state */
/* The table's keeps_state against what a restart does: a run of each effect that, under
 * its settings, keeps no state of its own (lag_effects_keeping_state) is restarted from
 * its (q, qd, tick) halfway and must go on bit for bit as the run itself (state and
 * observed state); the effects that keep state say so exactly for the settings that make
 * them (the actuator with a lag). Every row of the core's table must act under the
 * settings restart_settings gives it (restart_acts), so that a row left out there fails by
 * name instead of restarting exactly because it acts on nothing. */
static void restart_settings(lag_sim_def *d, uint32_t bit)
{
    lag_effects_def *e = &d->effects;
    e->enabled = bit;
    for (int i = 0; i < LAG_MAX_DOF; i++) {
        e->damping[i] = 0.7; e->spring_k[i] = 3.0; e->spring_rest[i] = 0.1;
        e->actuator_max[i] = 0.4; e->noise_q[i] = 0.05; e->noise_qd[i] = 0.05;
        e->friction_static[i] = 0.3; e->friction_kinetic[i] = 0.2;
        e->limit_on[i] = true; e->limit_lower[i] = -1.0; e->limit_upper[i] = 1.0;
        e->restitution[i] = 0.5;
    }
    e->n_disturbances = 2;
    e->disturbances[0] = (lag_disturbance){0.05, 0, false, 2.0, 0.2};
    e->disturbances[1] = (lag_disturbance){0.21, 1, true, 0.3, 0.0};
    if (bit == LAG_EFF_FLOOR) {
        *d = lag_default_sim_def(LAG_MODEL_STICK);
        d->effects.enabled = bit;
        d->q0[1] = 1.2;
    }
}

/* Whether the definition's effects change its run of `ticks` ticks under the restart's
 * input (state, observed state, events or work) against the same definition with every
 * effect off; false too when the core refuses the definition. */
static bool restart_acts(const lag_sim_def *d, int64_t ticks)
{
    lag_sim_def bare = *d;
    bare.effects.enabled = 0;
    lag_sim s0, s1;
    double o0[6], o1[6];
    if (!off_run(&s1, d, ticks, o1)) return false;
    ENSURE(off_run(&s0, &bare, ticks, o0));
    return !off_same(&s0, o0, &s1, o1);
}

static void restart(void)
{
    int checked = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const lag_effect_info inf = lag_effect_info_get(k);
        lag_sim_def d = lag_default_sim_def(LAG_MODEL_CARTPOLE);
        d.q0[1] = 0.4; d.qd0[0] = 0.3;
        restart_settings(&d, inf.bit);
        if (!restart_acts(&d, 300)) {
            LT_FAIL("keeps_state: effect '%s' of the core's table changes no run under the settings "
                    "the test gives it (give it settings in restart_settings)", inf.name);
            continue;
        }
        ENSURE(true);
        const uint32_t keeps = lag_effects_keeping_state(&d.effects);
        /* its own bit at most, and only if the table says it may keep state */
        ENSURE((keeps & ~inf.bit) == 0 && (inf.keeps_state || keeps == 0));
        if (inf.bit == LAG_EFF_ACTUATOR) { /* the lag is the actuator's state */
            d.effects.actuator_tau[0] = 0.1;
            ENSURE(lag_effects_keeping_state(&d.effects) == LAG_EFF_ACTUATOR);
            d.effects.actuator_tau[0] = 0.0;
            ENSURE(lag_effects_keeping_state(&d.effects) == 0);
        }
        if (lag_effects_keeping_state(&d.effects)) continue;
        lag_sim a, b;
        te_init(&a, &d);
        te_init(&b, &d);
        const double u[3] = {0.5, -0.3, 0.0};
        lag_sim_set_input(&a, u);
        ENSURE(lag_sim_advance(&a, 150, false) == LAG_OK);
        lag_sim_reset(&b, a.q, a.qd);
        b.tick = a.tick;
        lag_sim_set_input(&b, u);
        ENSURE(lag_sim_advance(&a, 150, false) == LAG_OK);
        ENSURE(lag_sim_advance(&b, 150, false) == LAG_OK);
        size_t nb = (size_t)a.nq * sizeof(double);
        double oa[6] = {0}, ob[6] = {0};
        lag_sim_observe(&a, oa, oa + 3);
        lag_sim_observe(&b, ob, ob + 3);
        bool same = memcmp(a.q, b.q, nb) == 0 && memcmp(a.qd, b.qd, nb) == 0 &&
                    memcmp(oa, ob, sizeof oa) == 0;
        if (!same) LT_FAIL("%s keeps no state by the table, but a restart at tick 150 differs", inf.name);
        else ENSURE(same);
        checked++;
    }
    ENSURE(checked >= 1);
}

static void case_damping(int a) { (void)a; damping_power_converges(); damping_stick_x(); damping_pendulum(); }
static void case_friction(int a) { (void)a; friction_block(); friction_dipc(); }
static void case_limits(int a) { (void)a; limits_free(); limits_spin(1.0); limits_spin(0.6); }
static void case_floor(int a) { (void)a; floor_bounces(); floor_liftoff(false); floor_liftoff(true); }
static void case_actuator(int a) { (void)a; actuator(); }
static void case_disturbance(int a) { (void)a; disturbance(); disturbance_far(); }
static void case_noise(int a) { (void)a; noise(); }
static void case_off(int a) { (void)a; off(); }
static void case_spring(int a) { (void)a; spring_stick_x(); spring_energy(); }
static void case_keeps_state(int a) { (void)a; restart(); }

static void case_coverage(int a);
static const lt_case cases[] = {
    {"damping", case_damping, 0, 0},         {"friction", case_friction, 0, 0},
    {"limits", case_limits, 0, 0},           {"floor", case_floor, 0, 0},
    {"actuator", case_actuator, 0, 0},       {"disturbance", case_disturbance, 0, 0},
    {"noise", case_noise, 0, 0},             {"off", case_off, 0, 0},
    {"spring", case_spring, 0, 0},           {"coverage", case_coverage, 0, 0},
    {"keeps_state", case_keeps_state, 0, 0},
};
#define NCASES ((int)(sizeof cases / sizeof cases[0]))

/* Every effect of the core's table has a case of its name here: an effect added to the
 * core without its test fails this. */
static void case_coverage(int a)
{
    (void)a;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const char *name = lag_effect_info_get(k).name;
        bool found = false;
        for (int c = 0; c < NCASES; c++) found |= name && strcmp(name, cases[c].name) == 0;
        if (!found) LT_FAIL("effect '%s' of the core's table has no case in test_effects", name ? name : "?");
        else ENSURE(found);
    }
}

int main(int argc, char **argv) { return lt_main(argc, argv, cases, NCASES); }
