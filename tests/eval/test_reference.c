/*
 * Reference signals (server/eval/reference.c): each kind's values at points where the
 * formula gives them in closed form, its rate against a central difference of its values,
 * its second derivative in closed form and against a central difference of its rate,
 * continuity where the formula changes branch, and the checks of bad definitions.
 *
 * Tolerances: a central difference with step h of a signal whose third derivative is at
 * most D3 is off by h^2 D3 / 6 plus rounding eps |r| / h; with h = 1e-5 and the signals
 * below (|r| <= 3, D3 <= (2 pi 12)^3 * 2) that is under 2e-4 relative to the rate scale,
 * checked at 1e-3 of the largest rate. The same for r'' from r': h^2 D4 / 6 with
 * D4 <= (2 pi 12)^4 * 3 is under 4e-4 of the scale (2 pi 12)^2, plus eps |r'| / h ~ 2e-9:
 * checked at 1e-3 of the largest r''.
 */
#include "lagsim_test.h"
#include "reference.h"

static double value(const lag_reference *ref, double t)
{
    double r;
    lag_reference_eval(ref, t, &r, NULL, NULL);
    return r;
}

/* r' against a central difference at n times in [a, b], away from jumps (skip says). */
static void check_rate(const lag_reference *ref, double a, double b, double scale,
                       int (*skip)(const lag_reference *, double))
{
    lt_rng rng = {42};
    const double h = 1e-5;
    for (int i = 0; i < 400; i++) {
        double t = lt_uniform(&rng, a, b);
        if (skip && skip(ref, t)) continue;
        double rd;
        lag_reference_eval(ref, t, NULL, &rd, NULL);
        double fd = (value(ref, t + h) - value(ref, t - h)) / (2 * h);
        ENSURE_NEAR(rd, fd, 1e-3 * scale, "%s at t = %.9g", lag_ref_kind_table[ref->kind].name, t);
    }
}

/* r'' against a central difference of r' at n times in [a, b], away from jumps of r'. */
static void check_accel(const lag_reference *ref, double a, double b, double scale,
                        int (*skip)(const lag_reference *, double))
{
    lt_rng rng = {43};
    const double h = 1e-5;
    for (int i = 0; i < 400; i++) {
        double t = lt_uniform(&rng, a, b);
        if (skip && skip(ref, t)) continue;
        double rdd, rd0, rd1;
        lag_reference_eval(ref, t, NULL, NULL, &rdd);
        lag_reference_eval(ref, t - h, NULL, &rd0, NULL);
        lag_reference_eval(ref, t + h, NULL, &rd1, NULL);
        ENSURE_NEAR(rdd, (rd1 - rd0) / (2 * h), 1e-3 * scale, "r'' of %s at t = %.9g",
                    lag_ref_kind_table[ref->kind].name, t);
    }
}

/* r'' is exactly 0 at every time in [a, b]: r piecewise linear or constant. */
static void check_no_accel(const lag_reference *ref, double a, double b)
{
    lt_rng rng = {44};
    for (int i = 0; i < 400; i++) {
        double t = lt_uniform(&rng, a, b), rdd = 1;
        lag_reference_eval(ref, t, NULL, NULL, &rdd);
        ENSUREF(rdd == 0, "r'' of %s at t = %.9g: %.17g, not 0",
                lag_ref_kind_table[ref->kind].name, t, rdd);
    }
}

static int near_kink(const lag_reference *ref, double t)
{
    const double h = 2e-5;
    double tau = t - ref->start;
    if (fabs(tau) < h) return 1;
    if ((ref->kind == LAG_REF_RAMP || ref->kind == LAG_REF_CHIRP) && fabs(tau - ref->duration) < h) return 1;
    if (ref->kind == LAG_REF_WAYPOINTS)
        for (int i = 0; i < ref->n_points; i++)
            if (fabs(tau - ref->point_t[i]) < h) return 1;
    return 0;
}

static void case_step(int arg)
{
    (void)arg;
    lag_reference s = lag_reference_default(LAG_REF_STEP);
    s.start = 1, s.amplitude = 0.2, s.offset = -0.1;
    double r, rd;
    lag_reference_eval(&s, 0.999, &r, &rd, NULL);
    ENSURE(r == -0.1 && rd == 0);
    lag_reference_eval(&s, 1.0, &r, &rd, NULL);
    ENSURE_NEAR(r, 0.1, 1e-15, "step at its start");
    ENSURE(rd == 0);
    lag_reference_eval(&s, 1e6, &r, &rd, NULL);
    ENSURE_NEAR(r, 0.1, 1e-15, "step held");
    check_no_accel(&s, 0, 3);
}

static void case_ramp(int arg)
{
    (void)arg;
    lag_reference s = lag_reference_default(LAG_REF_RAMP);
    s.start = 0.5, s.amplitude = 2, s.offset = 1, s.duration = 4;
    ENSURE(value(&s, 0.5) == 1);
    ENSURE_NEAR(value(&s, 2.5), 2, 1e-15, "half way");
    ENSURE_NEAR(value(&s, 4.5), 3, 1e-15, "the end");
    ENSURE_NEAR(value(&s, 100), 3, 0, "held");
    double rd;
    lag_reference_eval(&s, 3, NULL, &rd, NULL);
    ENSURE_NEAR(rd, 0.5, 1e-15, "slope amplitude / duration");
    check_rate(&s, 0, 6, 0.5, near_kink);
    check_no_accel(&s, 0, 6);
}

static void case_sine(int arg)
{
    (void)arg;
    lag_reference s = lag_reference_default(LAG_REF_SINE);
    s.start = 1, s.amplitude = 3, s.offset = 0.5, s.frequency = 2;
    ENSURE_NEAR(value(&s, 1 + 0.125), 3.5, 1e-14, "a quarter period: offset + amplitude");
    ENSURE_NEAR(value(&s, 1 + 0.375), -2.5, 1e-14, "three quarters: offset - amplitude");
    ENSURE_NEAR(value(&s, 1 + 0.25 * 7), 0.5, 1e-13, "3.5 periods: offset");
    ENSURE(value(&s, 0.9) == 0.5);
    check_rate(&s, 0, 5, 2 * M_PI * 2 * 3, near_kink);
    /* r'' = -a w^2 sin(w tau): -a w^2 at a quarter period, +a w^2 at three quarters, 0
     * before the start */
    const double w2a = 3 * (2 * M_PI * 2) * (2 * M_PI * 2);
    double rdd;
    lag_reference_eval(&s, 1 + 0.125, NULL, NULL, &rdd);
    ENSURE_NEAR(rdd, -w2a, 1e-12 * w2a, "r'' a quarter period in");
    lag_reference_eval(&s, 1 + 0.375, NULL, NULL, &rdd);
    ENSURE_NEAR(rdd, w2a, 1e-12 * w2a, "r'' three quarters in");
    lag_reference_eval(&s, 0.9, NULL, NULL, &rdd);
    ENSURE(rdd == 0);
    check_accel(&s, 0, 5, w2a, near_kink);
}

static void case_chirp(int arg)
{
    (void)arg;
    lag_reference s = lag_reference_default(LAG_REF_CHIRP);
    s.start = 0, s.amplitude = 1, s.offset = 0, s.frequency = 1, s.frequency_end = 11, s.duration = 2;
    /* phi(tau) = 2 pi (tau + 2.5 tau^2): zero crossings where tau + 2.5 tau^2 = k / 2 */
    for (int k = 1; k <= 23; k++) {
        double tau = (-1 + sqrt(1 + 10.0 * k * 0.5)) / 5;
        ENSURE_NEAR(value(&s, tau), 0, 1e-12, "zero crossing %d at %.9g s", k, tau);
    }
    /* crests where phi = pi/2 + 2 pi k */
    for (int k = 0; k <= 10; k++) {
        double c = 0.25 + k, tau = (-1 + sqrt(1 + 10.0 * c)) / 5;
        ENSURE_NEAR(value(&s, tau), 1, 1e-12, "crest %d", k);
    }
    /* after the sweep: 11 Hz from phase 2 pi (1 + 11) / 2 * 2 = 2 pi 12 */
    ENSURE_NEAR(value(&s, 2 + 1.0 / 44), 1, 1e-12, "a quarter period of 11 Hz after the sweep");
    double r0, r1;
    lag_reference_eval(&s, 2 - 1e-12, &r0, NULL, NULL);
    lag_reference_eval(&s, 2 + 1e-12, &r1, NULL, NULL);
    ENSURE_NEAR(r0, r1, 1e-9, "continuous at the sweep's end");
    check_rate(&s, 0, 4, 2 * M_PI * 11, near_kink);
    /* r'' = phi'' cos(phi) - phi'^2 sin(phi), phi' = 2 pi (1 + 5 tau), phi'' = 10 pi in the
     * sweep: at a zero crossing of sin (phi = pi k) it is phi'' cos(phi) = +-10 pi; at a
     * crest (phi = pi/2 + 2 pi k), -phi'^2; after the sweep, -(2 pi 11)^2 sin(phi) */
    for (int k = 1; k <= 23; k++) {
        double tau = (-1 + sqrt(1 + 10.0 * k * 0.5)) / 5, rdd;
        lag_reference_eval(&s, tau, NULL, NULL, &rdd);
        ENSURE_NEAR(rdd, (k % 2 ? -1 : 1) * 10 * M_PI, 1e-9 * 5000, "r'' at zero crossing %d", k);
    }
    for (int k = 0; k <= 10; k++) {
        double c = 0.25 + k, tau = (-1 + sqrt(1 + 10.0 * c)) / 5, rdd;
        double w = 2 * M_PI * (1 + 5 * tau);
        lag_reference_eval(&s, tau, NULL, NULL, &rdd);
        ENSURE_NEAR(rdd, -w * w, 1e-9 * 5000, "r'' at crest %d", k);
    }
    double rdd, w11 = 2 * M_PI * 11;
    lag_reference_eval(&s, 2 + 1.0 / 44, NULL, NULL, &rdd);
    ENSURE_NEAR(rdd, -w11 * w11, 1e-9 * 5000, "r'' a quarter period of 11 Hz after the sweep");
    check_accel(&s, 0, 4, w11 * w11, near_kink);
}

static void case_square(int arg)
{
    (void)arg;
    lag_reference s = lag_reference_default(LAG_REF_SQUARE);
    s.start = 0.25, s.amplitude = 2, s.offset = 1, s.frequency = 0.5;
    ENSURE(value(&s, 0.2) == 1);
    ENSURE(value(&s, 0.25) == 3);
    ENSURE(value(&s, 1.2) == 3);
    ENSURE(value(&s, 1.3) == -1);
    ENSURE(value(&s, 2.2) == -1);
    ENSURE(value(&s, 2.3) == 3);
    double rd;
    lag_reference_eval(&s, 1.0, NULL, &rd, NULL);
    ENSURE(rd == 0);
    check_no_accel(&s, 0, 5);
}

static void case_waypoints(int arg)
{
    (void)arg;
    lag_reference s = lag_reference_default(LAG_REF_WAYPOINTS);
    s.start = 1, s.amplitude = 2, s.offset = 0.5;
    double pt[] = {0, 2, 3, 5}, pw[] = {0.1, 0.3, -0.2, -0.2};
    s.n_points = 4;
    memcpy(s.point_t, pt, sizeof pt);
    memcpy(s.point_w, pw, sizeof pw);
    ENSURE_NEAR(value(&s, 0), 0.5 + 2 * 0.1, 1e-15, "held before the first point");
    ENSURE_NEAR(value(&s, 2), 0.5 + 2 * 0.2, 1e-15, "half way to the second");
    ENSURE_NEAR(value(&s, 3.5), 0.5 + 2 * 0.05, 1e-15, "half way to the third");
    ENSURE_NEAR(value(&s, 10), 0.5 - 2 * 0.2, 1e-15, "held after the last");
    double rd;
    lag_reference_eval(&s, 3.5, NULL, &rd, NULL);
    ENSURE_NEAR(rd, 2 * -0.5, 1e-15, "slope");
    check_rate(&s, -1, 8, 1, near_kink);
    check_no_accel(&s, -1, 8);
}

static void case_check(int arg)
{
    (void)arg;
    char key[32], msg[128];
    for (int k = 0; k < LAG_REF_KIND_COUNT; k++) {
        lag_reference s = lag_reference_default((lag_ref_kind)k);
        if (k == LAG_REF_WAYPOINTS) s.n_points = 1;
        ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == 0);
        ENSURE(lag_ref_kind_from_name(lag_ref_kind_table[k].name) == k);
        /* a kind's name is a lowercase word, so that a name with a space (the scene
         * fixture's unknown kind) can never be one */
        const char *name = lag_ref_kind_table[k].name;
        ENSUREF(name && name[0] >= 'a' && name[0] <= 'z' &&
                strspn(name, "abcdefghijklmnopqrstuvwxyz0123456789-") == strlen(name),
                "reference kind '%s': not a lowercase word", name ? name : "(null)");
    }
    ENSURE(lag_ref_kind_from_name("no such type") == -1 && lag_ref_kind_from_name("") == -1);
    lag_reference s = lag_reference_default(LAG_REF_SINE);
    s.frequency = 0;
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == -1 && !strcmp(key, "frequency"));
    s = lag_reference_default(LAG_REF_STEP);
    s.frequency = 0; /* a key the kind does not take is not checked */
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == 0);
    s.amplitude = NAN;
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == -1 && !strcmp(key, "amplitude"));
    s = lag_reference_default(LAG_REF_CHIRP);
    s.duration = -1;
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == -1 && !strcmp(key, "duration"));
    s = lag_reference_default(LAG_REF_WAYPOINTS);
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == -1 && !strcmp(key, "points"));
    s.n_points = 3;
    s.point_t[0] = 0, s.point_t[1] = 1, s.point_t[2] = 1;
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == -1 && !strcmp(key, "points[2]"));
    s.start = INFINITY;
    ENSURE(lag_reference_check(&s, key, sizeof key, msg, sizeof msg) == -1 && !strcmp(key, "start"));
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"step", case_step, 0, 0},       {"ramp", case_ramp, 0, 0},
        {"sine", case_sine, 0, 0},       {"chirp", case_chirp, 0, 0},
        {"square", case_square, 0, 0},   {"waypoints", case_waypoints, 0, 0},
        {"check", case_check, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
