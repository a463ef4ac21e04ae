/*
 * The stick off its floor: the floor effect with flight (lift-off, free flight, landing of
 * either end, impact with restitution, sliding contact and rest), against expectations
 * of our own: the free rigid body's closed form, the impact of a rigid rod at an end, and
 * conservation laws.
 *
 *   test_flight liftoff|free|pushed|landing|impact|thrown|random|redefine|noise
 *
 * The state is read as published (lag_sim_observe: x, phi and h, the height of the lower
 * end), and the centre of mass is found from it with our own geometry: the lower end is
 * a |sin phi| below the centre (a = l/2). Every case prints the figure it reached.
 */
#include "effects_test.h"

#define G_DT 1e-3

static lag_sim_def flight_def(lag_method m, double e)
{
    lag_sim_def d = lag_default_sim_def(LAG_MODEL_STICK);
    d.integrator.method = m;
    d.integrator.dt = G_DT;
    if (m == LAG_DOPRI5) { d.integrator.rtol = 1e-12; d.integrator.atol = 1e-14; }
    d.effects.enabled = LAG_EFF_FLOOR;
    d.effects.floor_restitution = e;
    return d;
}

/* Centre of mass and its velocity from the published state (our geometry). */
typedef struct { double x, y, phi, vx, vy, w, h, hd; } body;
static body observe(const lag_sim *s)
{
    double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
    lag_sim_observe(s, q, qd);
    const double a = 0.5 * s->def.model.p[LAG_STICK_L];
    double sn = sin(q[1]), sg = sn < 0 ? -1.0 : 1.0;
    body b = {q[0], q[2] + a * fabs(sn), q[1], qd[0], qd[2] + sg * a * cos(q[1]) * qd[1], qd[1],
              q[2], qd[2]};
    return b;
}

/* T + U of the free rod, from the centre's motion. */
static double body_energy(const double *p, body b)
{
    return 0.5 * p[LAG_STICK_M] * (b.vx * b.vx + b.vy * b.vy) + 0.5 * p[LAG_STICK_I] * b.w * b.w +
           p[LAG_STICK_M] * p[LAG_STICK_G] * b.y;
}

/* The closed form of flight with no input: the centre on its parabola, the angle turning
 * at a constant rate. */
typedef struct { double x0, y0, phi0, vx, vy, w, g, a; } flight;
static void flight_at(const flight *f, double t, double *x, double *y, double *phi)
{
    *x = f->x0 + f->vx * t;
    *y = f->y0 + f->vy * t - 0.5 * f->g * t * t;
    *phi = f->phi0 + f->w * t;
}
/* The lower end's height on the closed form. */
static double low_end(const flight *f, double t)
{
    double x, y, phi;
    flight_at(f, t, &x, &y, &phi);
    return y - f->a * fabs(sin(phi));
}
/* The first time the lower end reaches the floor: a scan at 1e-4 s for the sign change,
 * then bisection to the last bit. */
static double landing_time(const flight *f)
{
    double t0 = 0.0, t1 = 0.0;
    for (int k = 1; k < 1000000; k++) {
        t1 = k * 1e-4;
        if (low_end(f, t1) <= 0) break;
        t0 = t1;
    }
    for (int it = 0; it < 200 && t1 - t0 > 0; it++) {
        double c = 0.5 * (t0 + t1);
        if (c <= t0 || c >= t1) break;
        if (low_end(f, c) > 0) t0 = c; else t1 = c;
    }
    return t1;
}

/* A throw from the air: h0 = 1.2 m, spinning at 6 rad/s, rising. */
static lag_sim_def throw_def(lag_method m, double e, flight *f)
{
    lag_sim_def d = flight_def(m, e);
    const double *p = d.model.p;
    d.q0[0] = 0.1; d.q0[1] = 0.4; d.q0[2] = 1.2;
    d.qd0[0] = 0.7; d.qd0[1] = 6.0; d.qd0[2] = 3.0;
    double a = 0.5 * p[LAG_STICK_L];
    *f = (flight){d.q0[0], d.q0[2] + a * sin(d.q0[1]), d.q0[1], d.qd0[0],
                  d.qd0[2] + a * cos(d.q0[1]) * d.qd0[1], d.qd0[1], p[LAG_STICK_G], a};
    return d;
}

/* ================================================================== free flight */
/* Thrown in the air, no input: x, y of the centre and phi against the closed form until
 * just before the landing, and T + U kept. x and phi are exact for every method (their
 * accelerations are exactly zero in the model's closed form) but the implicit methods,
 * which iterate; y follows h, whose equation has the sin phi of the coordinates: exact to
 * the method's order. */
static void free_flight(int arg)
{
    (void)arg;
    for (int mi = 0; mi < LAG_METHOD_COUNT; mi++) {
        flight f;
        lag_sim_def d = throw_def((lag_method)mi, 0.5, &f);
        lag_sim s;
        te_init(&s, &d);
        double tl = landing_time(&f), E0 = body_energy(d.model.p, observe(&s));
        int64_t n = (int64_t)floor(tl / G_DT) - 1;
        double ex = 0, ey = 0, ephi = 0, eE = 0;
        int events = 0;
        lag_result r = LAG_OK;
        for (int64_t k = 1; k <= n && r == LAG_OK; k++) {
            r = lag_sim_advance(&s, 1, false);
            te_drain(&s, 0, &events);
            double x, y, phi, t = lag_sim_time(&s);
            flight_at(&f, t, &x, &y, &phi);
            body b = observe(&s);
            ex = fmax(ex, fabs(b.x - x));
            ey = fmax(ey, fabs(b.y - y));
            ephi = fmax(ephi, fabs(b.phi - phi));
            eE = fmax(eE, fabs(body_energy(d.model.p, b) - E0));
        }
        printf("free: %-19s %.3f s of flight (landing at %.6f s): |x - x(t)| %.1e m, |y - y(t)| "
               "%.1e m, |phi - phi(t)| %.1e rad, |E - E0| %.1e J of %.3f J, %d events\n",
               lag_method_name((lag_method)mi), n * G_DT, tl, ex, ey, ephi, eE, E0, events);
        ENSURE(r == LAG_OK && events == 0);
        /* x (every method: its momentum is m x_dot) and, for the explicit methods, phi:
         * sums of n exact increments, rounding only (n eps |value|); the implicit ones
         * iterate on the canonical momenta, whose map to phi_dot depends on phi */
        ENSURE(ex < 1e-12);
        if (!lag_method_info_get((lag_method)mi)->implicit) ENSURE(ephi < 1e-11);
        if (mi == LAG_DOPRI5) {
            /* round-off: rtol 1e-12 on a state of size ~10 */
            ENSURE(ey < 1e-11 && eE < 1e-10);
        } else if (lag_method_info_get((lag_method)mi)->order >= 4) {
            ENSURE(ey < 1e-9 && eE < 1e-8); /* (w dt)^4 a ~ 1e-10 per unit time */
        }
    }
}

/* The same throw pushed: F_x on x and tau on phi, held (the stick's inputs, the same in
 * flight): x = x0 + vx t + F t^2 / (2 m), phi = phi0 + w t + tau t^2 / (2 I), the centre's
 * height unchanged (the inputs do no vertical work), until just before the landing. */
static void pushed_flight(int arg)
{
    (void)arg;
    const double F = 1.5, tau = -0.4;
    for (int mi = 0; mi < LAG_METHOD_COUNT; mi++) {
        if (lag_method_info_get((lag_method)mi)->order < 4) continue;
        flight f;
        lag_sim_def d = throw_def((lag_method)mi, 0.5, &f);
        const double *p = d.model.p;
        lag_sim s;
        te_init(&s, &d);
        double u[LAG_MAX_DOF] = {F, tau, 0.0};
        lag_sim_set_input(&s, u);
        double ex = 0, ey = 0, ephi = 0;
        lag_result r = LAG_OK;
        int events = 0;
        for (int k = 1; k <= 600 && r == LAG_OK; k++) {
            r = lag_sim_advance(&s, 1, false);
            te_drain(&s, 0, &events);
            double t = lag_sim_time(&s), x, y, phi;
            flight_at(&f, t, &x, &y, &phi);
            x += F * t * t / (2 * p[LAG_STICK_M]);
            phi += tau * t * t / (2 * p[LAG_STICK_I]);
            body b = observe(&s);
            ex = fmax(ex, fabs(b.x - x));
            ey = fmax(ey, fabs(b.y - y));
            ephi = fmax(ephi, fabs(b.phi - phi));
        }
        printf("pushed: %-19s F_x %.1f N, tau %.1f N m, 0.6 s of flight: |x - x(t)| %.1e m, "
               "|y - y(t)| %.1e m, |phi - phi(t)| %.1e rad, %d events\n",
               lag_method_name((lag_method)mi), F, tau, ex, ey, ephi, events);
        ENSURE(r == LAG_OK && events == 0);
        /* quadratics in t: exact for these methods up to rounding, and the implicit
         * ones' Newton tolerance for phi; y as in free flight */
        ENSURE(ex < 1e-12 && ephi < 1e-9 && ey < 1e-9);
    }
}

/* ================================================================== lift-off */
/* A stick on its floor rising fast (phi0 0.6, phid0 5 rad/s) lifts off where our normal
 * force N(phi) on its energy curve reaches 0; the time to get there by quadrature of
 * dt = dphi / phid(phi). Every method of order >= 4 locates it to 1e-9 s (the others are
 * printed), and the stick then flies: the lower end rises. */
typedef struct { const double *p; double phi0, phid0; } curve;
static double inv_rate(double phi, const void *vc)
{
    const curve *c = (const curve *)vc;
    return 1.0 / sqrt(te_stick_phid2(c->p, c->phi0, c->phid0, phi));
}
static void liftoff(int arg)
{
    (void)arg;
    lag_sim_def d0 = flight_def(LAG_RK4, 0.0);
    const double *p = d0.model.p;
    const double phi0 = 0.6, phid0 = 5.0;
    double a = phi0, b = TE_PI / 2;
    for (int it = 0; it < 200; it++) {
        double c = 0.5 * (a + b);
        if (te_stick_normal(p, c, te_stick_phid2(p, phi0, phid0, c)) > 0) a = c; else b = c;
    }
    curve cv = {p, phi0, phid0};
    double tq = te_gauss5(inv_rate, &cv, phi0, a, 400);
    for (int mi = 0; mi < LAG_METHOD_COUNT; mi++) {
        lag_sim_def d = flight_def((lag_method)mi, 0.0);
        d.q0[1] = phi0;
        d.qd0[1] = phid0;
        lag_sim s;
        te_init(&s, &d);
        double t_lift = -1, hmax = 0;
        lag_result r = LAG_OK;
        for (int k = 0; k < 150 && r == LAG_OK; k++) {
            r = lag_sim_advance(&s, 1, false);
            lag_event ev;
            while (lag_sim_poll_event(&s, &ev))
                if (ev.kind == LAG_EV_LIFTOFF && t_lift < 0) t_lift = ev.t;
            hmax = fmax(hmax, observe(&s).h);
        }
        printf("liftoff: %-19s at %.12f s (quadrature %.12f, %+.1e), then h up to %.4f m\n",
               lag_method_name((lag_method)mi), t_lift, tq, t_lift - tq, hmax);
        ENSURE(r == LAG_OK && t_lift > 0 && hmax > 5e-4);
        if (lag_method_info_get((lag_method)mi)->order >= 4)
            ENSURE_NEAR(t_lift, tq, 1e-9, "lift-off time, %s", lag_method_name((lag_method)mi));
    }
}

/* ================================================================== landing */
/* The same throw: the first landing (the lower end at y = 0) against the root of the
 * closed form; the event's value is the end's vertical velocity there. */
static void landing(int arg)
{
    (void)arg;
    for (int mi = 0; mi < LAG_METHOD_COUNT; mi++) {
        flight f;
        lag_sim_def d = throw_def((lag_method)mi, 0.5, &f);
        lag_sim s;
        te_init(&s, &d);
        double tl = landing_time(&f), t_ev = -1, v_ev = 0;
        lag_result r = LAG_OK;
        for (int k = 0; k < 3000 && r == LAG_OK && t_ev < 0; k++) {
            r = lag_sim_advance(&s, 1, false);
            lag_event ev;
            while (lag_sim_poll_event(&s, &ev))
                if (t_ev < 0 && (ev.kind == LAG_EV_IMPACT || ev.kind == LAG_EV_LANDING)) {
                    t_ev = ev.t;
                    v_ev = ev.value;
                }
        }
        /* the lower end's velocity at tl on the closed form */
        double x, y, phi;
        flight_at(&f, tl, &x, &y, &phi);
        double sg = sin(phi) < 0 ? -1.0 : 1.0;
        double v = f.vy - f.g * tl - sg * f.a * cos(phi) * f.w;
        printf("landing: %-19s at %.12f s (closed form %.12f, %+.1e), end velocity %.9f m/s "
               "(closed form %.9f)\n",
               lag_method_name((lag_method)mi), t_ev, tl, t_ev - tl, v_ev, v);
        ENSURE(r == LAG_OK && t_ev > 0);
        if (lag_method_info_get((lag_method)mi)->order >= 4) {
            ENSURE_NEAR(t_ev, tl, 1e-9, "landing time, %s", lag_method_name((lag_method)mi));
            ENSURE_NEAR(v_ev, v, 1e-7, "landing velocity, %s", lag_method_name((lag_method)mi));
        }
    }
}

/* ================================================================== impact */
/* An end hitting the floor at vertical velocity v < 0 gets a vertical impulse P there;
 * for the free rod (mass m, inertia I, the end at horizontal offset d = a cos phi from the
 * centre) the end's velocity changes by P / m_eff, 1 / m_eff = 1 / m + d^2 / I, and with
 * restitution e it leaves at -e v: the kinetic energy falls by (1 - e^2) m_eff v^2 / 2.
 * The throw with dopri5 (energy kept in flight), e from 0 to 1: the energy after the first
 * landing against E0 minus that loss. */
static void impact(int arg)
{
    (void)arg;
    const double es[5] = {0.0, 0.3, 0.6, 0.9, 1.0};
    for (int j = 0; j < 5; j++) {
        flight f;
        lag_sim_def d = throw_def(LAG_DOPRI5, es[j], &f);
        const double *p = d.model.p;
        lag_sim s;
        te_init(&s, &d);
        double E0 = body_energy(p, observe(&s)), tl = landing_time(&f);
        lag_result r = LAG_OK;
        int kinds[16], ne = 0;
        while (r == LAG_OK && lag_sim_time(&s) < tl + 2 * G_DT) {
            r = lag_sim_advance(&s, 1, false);
            lag_event ev;
            while (lag_sim_poll_event(&s, &ev))
                if (ne < 16) kinds[ne++] = (int)ev.kind;
        }
        double x, y, phi;
        flight_at(&f, tl, &x, &y, &phi);
        double sg = sin(phi) < 0 ? -1.0 : 1.0, dd = f.a * cos(phi);
        double v = f.vy - f.g * tl - sg * dd * f.w;
        double meff = 1.0 / (1.0 / p[LAG_STICK_M] + dd * dd / p[LAG_STICK_I]);
        double want = E0 - 0.5 * (1 - es[j] * es[j]) * meff * v * v;
        double E = body_energy(p, observe(&s));
        printf("impact: e = %.1f, end at %.4f m/s: E %.12f J after (impact map %.12f, %+.1e), "
               "E0 %.6f; first event %s\n",
               es[j], v, E, want, E - want, E0, ne ? lag_event_kind_name((lag_event_kind)kinds[0]) : "-");
        ENSURE(r == LAG_OK && ne >= 1);
        /* dopri5 at rtol 1e-12 keeps E in flight to ~1e-11 J; the landing time's 1e-12 s
         * moves the loss by ~|dv/dt| 1e-12 */
        ENSURE_NEAR(E, want, 1e-9, "energy after the impact, e = %.1f", es[j]);
    }
}

/* ================================================================== thrown, every method */
/* Penetration: the lowest end's height below the floor, from the integrated state with
 * our own geometry (y of the centre from h and which end h measures). */
static double lowest_end(const lag_sim *s)
{
    const double a = 0.5 * s->def.model.p[LAG_STICK_L];
    double sig = s->mode.floor_end != 0 ? -1.0 : 1.0;
    double y = s->q[2] + sig * a * sin(s->q[1]);
    return y - a * fabs(sin(s->q[1]));
}

typedef struct {
    lag_result r;
    int liftoffs, landings, impacts, rests, limits, other;
    double min_end, max_rise, t_end, E_end;
    bool finite;
    const char *contact;
} run_stats;

/* Runs `seconds`; at each tick with an event, E(after) - E(before) enters max_rise. */
static run_stats run(lag_sim *s, double seconds)
{
    run_stats st = {LAG_OK, 0, 0, 0, 0, 0, 0, INFINITY, -INFINITY, 0, 0, true, ""};
    const int64_t n = (int64_t)llround(seconds / s->def.integrator.dt);
    double E = te_sim_energy(s);
    for (int64_t k = 0; k < n; k++) {
        st.r = lag_sim_advance(s, 1, false);
        if (st.r != LAG_OK) break;
        if (!te_finite_state(s)) { st.finite = false; break; }
        lag_event ev;
        bool any = false;
        while (lag_sim_poll_event(s, &ev)) {
            any = true;
            switch (ev.kind) {
            case LAG_EV_LIFTOFF: st.liftoffs++; break;
            case LAG_EV_LANDING: st.landings++; break;
            case LAG_EV_IMPACT: st.impacts++; break;
            case LAG_EV_REST: st.rests++; break;
            case LAG_EV_EVENT_LIMIT: st.limits++; break;
            default: st.other++; break;
            }
        }
        double E1 = te_sim_energy(s);
        if (any) st.max_rise = fmax(st.max_rise, E1 - E);
        E = E1;
        st.min_end = fmin(st.min_end, lowest_end(s));
    }
    st.t_end = lag_sim_time(s);
    st.E_end = E;
    st.contact = lag_sim_contact(s);
    return st;
}

/* Thrown up spinning from the floor: it lifts off, flies, lands, bounces, slides and comes
 * to rest lying on the floor, for every method: no fault, no NaN, no end below the floor
 * by more than 1e-12 m, no tick that runs out of events (a Zeno hang would). */
static void thrown(int arg)
{
    (void)arg;
    for (int mi = 0; mi < LAG_METHOD_COUNT; mi++) {
        lag_sim_def d = flight_def((lag_method)mi, 0.5);
        d.q0[1] = 0.5;
        d.qd0[0] = 0.4;
        d.qd0[1] = 12.0;
        lag_sim s;
        te_init(&s, &d);
        run_stats st = run(&s, 6.0);
        printf("thrown: %-19s %s, t = %.3f s: %d liftoffs, %d landings, %d impacts, %d rests, "
               "%d event limits; lowest end %+.1e m; ends %s, phi = %.6f, phi_dot = %g, "
               "E = %.3e J\n",
               lag_method_name((lag_method)mi), lag_result_string(st.r), st.t_end, st.liftoffs,
               st.landings, st.impacts, st.rests, st.limits, st.min_end, st.contact, s.q[1],
               s.qd[1], st.E_end - 0.5 * d.model.p[LAG_STICK_M] * s.qd[0] * s.qd[0]);
        ENSURE(st.r == LAG_OK && st.finite);
        ENSURE_NEAR(st.t_end, 6.0, 1e-12, "sim time");
        ENSURE(st.liftoffs >= 1 && st.landings + st.impacts >= 2);
        ENSURE(st.limits == 0 && st.other == 0);
        ENSURE(st.min_end > -1e-12);
        ENSURE(strcmp(st.contact, "flat") == 0 && s.qd[1] == 0.0 && s.qd[2] == 0.0);
    }
}

/* ================================================================== random throws */
/* Seeded random throws (from the floor or from the air, spin, restitution), 3 s each:
 * no fault, sim time reaches the end, no end below the floor, and the energy never rises
 * across a tick with an event beyond the integrator's own error: dopri5 at rtol 1e-12
 * keeps T + U in a tick to ~1e-12 of its scale, so 1e-9 of it is the bound. rk4 runs the
 * same throws for faults, penetration and time only. 300 throws; under the sanitizers
 * (lt_span) the first 76 of the same sequence, each as long, with the same checks. */
static uint64_t rng_next(uint64_t *st)
{
    uint64_t x = (*st += 0x9E3779B97F4A7C15ull);
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}
static double uni(uint64_t *st, double lo, double hi)
{
    return lo + (hi - lo) * ((double)(rng_next(st) >> 11) * 0x1.0p-53);
}

static void random_throws(int arg)
{
    (void)arg;
    const int N = (int)lt_span(300, 76);
    uint64_t seed = 20261123;
    int faults = 0, short_runs = 0, rises = 0, deep = 0, lifted = 0, landed = 0, limited = 0;
    double worst_rise = -INFINITY, worst_end = INFINITY;
    for (int k = 0; k < N; k++) {
        lag_method m = (k % 2) ? LAG_RK4 : LAG_DOPRI5;
        lag_sim_def d = flight_def(m, uni(&seed, 0.0, 1.0));
        d.q0[0] = uni(&seed, -1, 1);
        d.q0[1] = uni(&seed, 0.0, TE_PI);
        d.qd0[0] = uni(&seed, -2, 2);
        d.qd0[1] = uni(&seed, -25, 25);
        if (uni(&seed, 0, 1) < 0.5) {
            d.q0[2] = uni(&seed, 0.0, 1.5);
            d.qd0[2] = uni(&seed, -3, 5);
        }
        lag_sim s;
        te_init(&s, &d);
        double scale = fmax(fabs(te_sim_energy(&s)), d.model.p[LAG_STICK_M] * d.model.p[LAG_STICK_G] *
                                                         d.model.p[LAG_STICK_L]);
        run_stats st = run(&s, 3.0);
        faults += st.r != LAG_OK || !st.finite;
        short_runs += fabs(st.t_end - 3.0) > 1e-12;
        deep += !(st.min_end > -1e-12);
        limited += st.limits > 0;
        lifted += st.liftoffs > 0;
        landed += st.landings + st.impacts > 0;
        worst_end = fmin(worst_end, st.min_end);
        if (m == LAG_DOPRI5) {
            rises += st.max_rise > 1e-9 * scale;
            worst_rise = fmax(worst_rise, st.max_rise / scale);
        }
        if (st.r != LAG_OK || st.max_rise > 1e-9 * scale || !(st.min_end > -1e-12))
            fprintf(stderr, "  throw %d (%s): %s, rise %.2e of %.2e, lowest end %.1e\n", k,
                    lag_method_name(m), lag_result_string(st.r), st.max_rise, scale, st.min_end);
    }
    printf("random: %d throws (half dopri5, half rk4), 3 s each: %d faults, %d short of 3 s, "
           "%d with an event limit; %d lifted off, %d landed; lowest end %+.1e m; largest "
           "energy rise across an event tick (dopri5) %+.1e of the scale\n",
           N, faults, short_runs, limited, lifted, landed, worst_end, worst_rise);
    ENSURE(faults == 0 && short_runs == 0 && deep == 0 && rises == 0 && limited == 0);
    ENSURE(lifted > N / 4 && landed > N / 4); /* the throws did fly */
}

/* ================================================================== noise */
/* Noise on the published x and phi of a thrown stick: the simulated state is bit for bit
 * that of the run without noise (events included), the published h is the noiseless
 * lower end's, and x, phi carry noise of the configured size. */
static void noise(int arg)
{
    (void)arg;
    lag_sim_def d = flight_def(LAG_RK4, 0.5);
    d.q0[1] = 0.5;
    d.qd0[0] = 0.4;
    d.qd0[1] = 12.0;
    lag_sim_def dn = d;
    dn.effects.enabled |= LAG_EFF_NOISE;
    dn.effects.noise_seed = 5;
    dn.effects.noise_q[0] = dn.effects.noise_q[1] = 1e-3;
    lag_sim a, b;
    te_init(&a, &d);
    te_init(&b, &dn);
    int same = 1, h_same = 1, ea = 0, eb = 0;
    double sum2 = 0;
    const int n = 3000;
    for (int k = 0; k < n; k++) {
        ENSURE(lag_sim_advance(&a, 1, false) == LAG_OK && lag_sim_advance(&b, 1, false) == LAG_OK);
        te_drain(&a, 0, &ea);
        te_drain(&b, 0, &eb);
        same &= memcmp(a.q, b.q, sizeof a.q) == 0 && memcmp(a.qd, b.qd, sizeof a.qd) == 0;
        double qa[LAG_MAX_DOF], qda[LAG_MAX_DOF], qb[LAG_MAX_DOF], qdb[LAG_MAX_DOF];
        lag_sim_observe(&a, qa, qda);
        lag_sim_observe(&b, qb, qdb);
        h_same &= qa[2] == qb[2] && qda[2] == qdb[2];
        sum2 += (qb[1] - qa[1]) * (qb[1] - qa[1]);
    }
    double sd = sqrt(sum2 / n);
    printf("noise: thrown stick, 3 s: true state %s, %d and %d events, published h %s, phi "
           "noise std %.3e (want 1e-3)\n", same ? "bit-identical" : "DIFFERS", ea, eb,
           h_same ? "identical" : "DIFFERS", sd);
    ENSURE(same && h_same && ea == eb && ea > 5);
    ENSURE(fabs(sd - 1e-3) < 5 * 1e-3 / sqrt(2.0 * n)); /* 5 sigma of a std estimate */
}

/* ================================================================== redefine */
/* A running flying stick takes new parameters and a new restitution where it is (spun
 * past phi = 2 pi, in the air) and goes on from there; the floor's flight itself does
 * not change while running. */
static void redefine(int arg)
{
    (void)arg;
    flight f;
    lag_sim_def d = throw_def(LAG_RK4, 0.5, &f);
    lag_sim s;
    te_init(&s, &d);
    ENSURE(lag_sim_advance(&s, 1100, false) == LAG_OK);
    ENSURE(strcmp(lag_sim_contact(&s), "flight") == 0 && s.q[1] > 2 * TE_PI);
    lag_sim_def d2 = d;
    d2.model.p[LAG_STICK_M] = 2.0;
    d2.effects.floor_restitution = 0.9;
    char err[256] = "";
    lag_result r = lag_sim_redefine(&s, &d2, err, sizeof err);
    printf("redefine: in flight at phi = %.3f: %s %s; mass now %g\n", s.q[1], lag_result_string(r),
           err, s.model.p[LAG_STICK_M]);
    ENSURE(r == LAG_OK && s.model.p[LAG_STICK_M] == 2.0 && s.model.kind == LAG_MODEL_FLYING_STICK);
    ENSURE(lag_sim_advance(&s, 2000, false) == LAG_OK && te_finite_state(&s));
    d2.effects.floor_flight = false;
    r = lag_sim_redefine(&s, &d2, err, sizeof err);
    printf("redefine: flight off while running: %s (%s)\n", lag_result_string(r), err);
    ENSURE(r == LAG_ERR_ARG && strstr(err, "flight") != NULL);
}

/* ================================================================== the model is data */
/* A thrown stick lands on both of its ends (h measuring end A, then end B): the run's
 * model, its parameters included, stays bit for bit what lag_sim_init made it at every
 * tick; which end h measures is the sim's state, not a parameter. */
static void model_readonly(int arg)
{
    (void)arg;
    lag_sim_def d = flight_def(LAG_RK4, 0.5);
    d.q0[1] = 0.5;
    d.qd0[0] = 0.4;
    d.qd0[1] = 12.0;
    lag_sim s;
    te_init(&s, &d);
    const lag_model m0 = s.model;
    int changed = 0, lands[2] = {0, 0}; /* h's events with end A, end B the lower one */
    for (int k = 0; k < 6000 && s.tick < 6000; k++) {
        ENSURE(lag_sim_advance(&s, 1, false) == LAG_OK);
        changed += memcmp(&s.model, &m0, sizeof m0) != 0;
        lag_event ev;
        while (lag_sim_poll_event(&s, &ev))
            if (ev.joint == 2 && (ev.kind == LAG_EV_LANDING || ev.kind == LAG_EV_IMPACT))
                lands[sin(s.q[1]) < 0]++;
    }
    printf("model_readonly: %d ticks of 6000 with the model changed; landings on end A %d, "
           "end B %d\n", changed, lands[0], lands[1]);
    ENSURE(lands[0] >= 1 && lands[1] >= 1); /* both ends landed: h switched ends */
    ENSURE(changed == 0);
    for (int i = 0; i < LAG_STICK_NP; i++) ENSURE(memcmp(&s.model.p[i], &d.model.p[i], sizeof(double)) == 0);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"liftoff", liftoff, 0, 0},    {"free", free_flight, 0, 0},
        {"pushed", pushed_flight, 0, 0},
        {"landing", landing, 0, 0},    {"impact", impact, 0, 0},
        {"thrown", thrown, 0, 0},      {"random", random_throws, 0, 0},
        {"redefine", redefine, 0, 0}, {"noise", noise, 0, 0},
        {"model_readonly", model_readonly, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
