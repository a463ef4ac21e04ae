/*
 * The metrics library (server/eval/metrics.c) against closed forms: a first-order and a
 * second-order step response, a rejected disturbance, a held effort; and the --require
 * parser. The exact values come from the formulas of each response (or from bisection on
 * the exact response where a metric has no closed form), never from the library.
 *
 * Tolerances: the library interpolates crossings linearly between samples h apart, so a
 * crossing time is off by at most h^2 max|y''| / (8 |y'|) at the crossing; trapezoids are
 * off by at most (T - t0) h^2 max|f''| / 12. With h = 1e-3 and the responses below, both
 * are under 3e-6; the checks allow 1e-5.
 */
#include "lagsim_test.h"
#include "metrics.h"

#define H 1e-3
#define TOL 1e-5
#define NMAX 20001

static double t_[NMAX], y_[NMAX], r_[NMAX], u_[NMAX];

/* Samples f on [0, T] every H into t_, y_, with the reference rv. */
static size_t sample(double (*f)(double, const double *), const double *par, double T, double rv)
{
    size_t n = (size_t)(T / H + 0.5) + 1;
    for (size_t k = 0; k < n; k++) {
        t_[k] = (double)k * H;
        y_[k] = f(t_[k], par);
        r_[k] = rv;
        u_[k] = 0;
    }
    return n;
}

/* Solves f(t) = c for t in [a, b] by bisection, f(a) - c and f(b) - c of opposite signs. */
static double bisect(double (*f)(double, const double *), const double *par, double a, double b,
                     double c)
{
    double fa = f(a, par) - c;
    for (int i = 0; i < 200; i++) {
        double m = 0.5 * (a + b), fm = f(m, par) - c;
        if ((fm > 0) == (fa > 0)) a = m, fa = fm;
        else b = m;
    }
    return 0.5 * (a + b);
}

static lag_metrics compute(size_t n, const lag_metric_opts *o)
{
    lag_metrics m;
    char err[256];
    int rc = lag_metrics_compute(t_, y_, r_, u_, n, o, &m, err, sizeof err);
    if (rc != 0) LT_FAIL("lag_metrics_compute: %s", err);
    return m;
}

/* y = g (1 - exp(-t / tau)), par = {tau, g} */
static double first_order(double t, const double *p)
{
    return p[1] * (1 - exp(-t / p[0]));
}

static void case_first_order(int sign)
{
    const double tau = 0.5, T = 10, g = sign ? -1.0 : 1.0, par[2] = {tau, g};
    size_t n = sample(first_order, par, T, g);
    lag_metric_opts o = lag_metric_opts_default();
    lag_metrics m = compute(n, &o);
    ENSURE_NEAR(m.step, g, 0, "step");
    ENSURE_NEAR(m.v[LAG_METRIC_RISE], tau * log(9.0), TOL, "rise = tau ln 9");
    ENSURE_NEAR(m.v[LAG_METRIC_SETTLE], tau * log(50.0), TOL, "settle = tau ln 50");
    ENSURE_NEAR(m.v[LAG_METRIC_OVERSHOOT], 0, 0, "a first-order response never overshoots");
    ENSURE_NEAR(m.v[LAG_METRIC_IAE], tau * (1 - exp(-T / tau)), TOL, "IAE");
    ENSURE_NEAR(m.v[LAG_METRIC_ISE], 0.5 * tau * (1 - exp(-2 * T / tau)), TOL, "ISE");
    ENSURE_NEAR(m.v[LAG_METRIC_PEAK_ERROR], 1, 0, "peak error at t = 0");
    /* mean of e = g exp(-t/tau) over [0.9 T, T] */
    double sse = g * tau / (0.1 * T) * (exp(-0.9 * T / tau) - exp(-T / tau));
    ENSURE_NEAR(m.v[LAG_METRIC_SS_ERROR], sse, 1e-12, "steady-state error");
}

/* unit step of omega^2 / (s^2 + 2 zeta omega s + omega^2), par = {zeta, omega} */
static double second_order(double t, const double *p)
{
    double z = p[0], w = p[1], wd = w * sqrt(1 - z * z);
    return 1 - exp(-z * w * t) * (cos(wd * t) + z / sqrt(1 - z * z) * sin(wd * t));
}

static double second_order_err(double t, const double *p)
{
    return fabs(1 - second_order(t, p));
}

static void case_second_order(int arg)
{
    (void)arg;
    const double z = 0.3, w = 4, T = 10, par[2] = {z, w};
    const double wd = w * sqrt(1 - z * z), tp = M_PI / wd;
    size_t n = sample(second_order, par, T, 1);
    lag_metric_opts o = lag_metric_opts_default();
    lag_metrics m = compute(n, &o);
    /* y rises monotonically up to its first peak at tp: bisection there */
    double rise = bisect(second_order, par, 0, tp, 0.9) - bisect(second_order, par, 0, tp, 0.1);
    ENSURE_NEAR(m.v[LAG_METRIC_RISE], rise, TOL, "rise time");
    ENSURE_NEAR(m.v[LAG_METRIC_OVERSHOOT], exp(-M_PI * z / sqrt(1 - z * z)), TOL,
                "overshoot = exp(-pi zeta / sqrt(1 - zeta^2))");
    /* settling: |e| = 0.02 for the last time. The extrema of e lie at multiples of
     * pi / wd; the last one above 0.02 and the zero of e after it bracket the time. */
    int j = 1;
    while (second_order_err((j + 1) * M_PI / wd, par) > 0.02) j++;
    double a = j * M_PI / wd;
    double b = a + (M_PI - atan2(sqrt(1 - z * z), z)) / wd; /* next zero of e after a (< a + pi/wd) */
    double settle = bisect(second_order_err, par, a, b, 0.02);
    ENSURE(second_order_err(settle + 1e-9, par) <= 0.02 + 1e-12);
    ENSURE_NEAR(m.v[LAG_METRIC_SETTLE], settle, TOL, "settling time");
    ENSURE_NEAR(m.v[LAG_METRIC_ISE], (1 + 4 * z * z) / (4 * z * w), TOL,
                "ISE = (1 + 4 zeta^2) / (4 zeta omega)");
    /* no steady-state error: over the last second e stays inside its envelope */
    ENSURE_NEAR(m.v[LAG_METRIC_SS_ERROR], 0, exp(-z * w * 0.9 * T) / sqrt(1 - z * z),
                "steady-state error within the envelope");
}

/* A disturbance rejected: y = t exp(-t), r = 0 */
static double bump(double t, const double *p)
{
    (void)p;
    return t * exp(-t);
}

static void case_disturbance(int arg)
{
    (void)arg;
    const double T = 20;
    size_t n = sample(bump, NULL, T, 0);
    lag_metric_opts o = lag_metric_opts_default();
    lag_metrics m = compute(n, &o);
    ENSURE(m.step == 0);
    ENSURE(isnan(m.v[LAG_METRIC_RISE]));
    ENSURE(isnan(m.v[LAG_METRIC_OVERSHOOT]));
    ENSURE_NEAR(m.v[LAG_METRIC_PEAK_ERROR], exp(-1.0), 1e-6, "peak |e| = 1/e at t = 1");
    /* band: 2 % of the peak error; y falls through it after its peak */
    double settle = bisect(bump, NULL, 1, T, 0.02 * exp(-1.0));
    ENSURE_NEAR(m.v[LAG_METRIC_SETTLE], settle, 1e-4, "settling into 2 %% of the peak");
    ENSURE_NEAR(m.v[LAG_METRIC_IAE], 1 - (T + 1) * exp(-T), TOL, "IAE = 1 - (T + 1) e^-T");
    ENSURE_NEAR(m.v[LAG_METRIC_ISE], 0.25 * (1 - exp(-2 * T) * (2 * T * T + 2 * T + 1)), TOL, "ISE");
}

/* The case starts at t0 = 2: samples before are ignored, times count from t0. */
static double delayed(double t, const double *p)
{
    return t < 2 ? 0 : first_order(t - 2, p);
}

static void case_start_time(int arg)
{
    (void)arg;
    const double tau = 0.25, par[2] = {tau, 1};
    size_t n = sample(delayed, par, 8, 1);
    for (size_t k = 0; k < n; k++) r_[k] = t_[k] < 2 ? 0 : 1;
    lag_metric_opts o = lag_metric_opts_default();
    o.t0 = 2;
    lag_metrics m = compute(n, &o);
    ENSURE_NEAR(m.v[LAG_METRIC_RISE], tau * log(9.0), TOL, "rise");
    ENSURE_NEAR(m.v[LAG_METRIC_SETTLE], tau * log(50.0), TOL, "settle from t0");
    ENSURE_NEAR(m.v[LAG_METRIC_IAE], tau * (1 - exp(-6 / tau)), TOL, "IAE from t0");
}

/* Runs that end outside the band, never rise, or have nothing to measure. */
static void case_missing(int arg)
{
    (void)arg;
    const double par[2] = {0.5, 0.5}; /* reaches only half the step */
    size_t n = sample(first_order, par, 5, 1);
    lag_metric_opts o = lag_metric_opts_default();
    lag_metrics m = compute(n, &o);
    ENSURE(isnan(m.v[LAG_METRIC_SETTLE]));
    ENSURE(isnan(m.v[LAG_METRIC_RISE]));
    /* e = 0.5 + 0.5 exp(-t / 0.5): its mean over [4.5, 5] */
    ENSURE_NEAR(m.v[LAG_METRIC_SS_ERROR], 0.5 + 0.5 * (exp(-9.0) - exp(-10.0)), 1e-9,
                "half the step left");
    /* everything zero: settled at once, no step */
    n = sample(bump, NULL, 1, 0);
    for (size_t k = 0; k < n; k++) y_[k] = 0;
    m = compute(n, &o);
    ENSURE(m.v[LAG_METRIC_SETTLE] == 0);
    ENSURE(m.v[LAG_METRIC_IAE] == 0 && m.v[LAG_METRIC_PEAK_ERROR] == 0);
    /* no effort given: no effort metrics */
    lag_metrics m2;
    ENSURE(lag_metrics_compute(t_, y_, NULL, NULL, n, &o, &m2, NULL, 0) == 0);
    ENSURE(isnan(m2.v[LAG_METRIC_EFFORT_PEAK]) && isnan(m2.v[LAG_METRIC_EFFORT_RMS]));
}

/* A held effort: +3 for the first half, -1 for the second: peak 3, RMS sqrt(5). */
static void case_effort(int arg)
{
    (void)arg;
    size_t n = sample(bump, NULL, 2, 0);
    for (size_t k = 0; k < n; k++) u_[k] = t_[k] < 1 - H / 2 ? 3 : -1;
    lag_metric_opts o = lag_metric_opts_default();
    lag_metrics m = compute(n, &o);
    ENSURE_NEAR(m.v[LAG_METRIC_EFFORT_PEAK], 3, 0, "peak effort");
    ENSURE_NEAR(m.v[LAG_METRIC_EFFORT_RMS], sqrt(5.0), 1e-12, "RMS of the held effort");
}

static void case_bad_samples(int arg)
{
    (void)arg;
    lag_metric_opts o = lag_metric_opts_default();
    lag_metrics m;
    char err[256];
    double t[3] = {0, 1, 1}, y[3] = {0, 1, 2};
    ENSURE(lag_metrics_compute(t, y, NULL, NULL, 3, &o, &m, err, sizeof err) == -1);
    ENSURE(strstr(err, "does not increase") != NULL);
    t[2] = 2;
    y[1] = NAN;
    ENSURE(lag_metrics_compute(t, y, NULL, NULL, 3, &o, &m, err, sizeof err) == -1);
    ENSURE(strstr(err, "not finite") != NULL);
    y[1] = 1;
    o.t0 = 1.5;
    ENSURE(lag_metrics_compute(t, y, NULL, NULL, 3, &o, &m, err, sizeof err) == -1);
    ENSURE(strstr(err, "fewer than 2") != NULL);
    ENSURE(isnan(m.v[LAG_METRIC_IAE])); /* the outputs are valid (NaN) on error */
}

static void case_require(int arg)
{
    (void)arg;
    lag_require req;
    char err[512];
    ENSURE(lag_require_parse("theta1.settle<2 and theta1.overshoot<0.1", &req, err, sizeof err) == 0);
    ENSURE(req.n == 2);
    ENSURE(strcmp(req.term[0].joint, "theta1") == 0 && req.term[0].metric == LAG_METRIC_SETTLE);
    ENSURE(req.term[0].op == LAG_REQ_LT && req.term[0].value == 2);
    ENSURE(req.term[1].metric == LAG_METRIC_OVERSHOOT && req.term[1].value == 0.1);
    ENSURE(lag_require_parse("  x.iae <= 1e-3  and  x.effort_peak>=2 ", &req, err, sizeof err) == 0);
    ENSURE(req.n == 2 && req.term[0].op == LAG_REQ_LE && req.term[1].op == LAG_REQ_GE);

    lag_metrics m = {.step = 1};
    for (int i = 0; i < LAG_METRIC_COUNT; i++) m.v[i] = 1;
    lag_require_term lt = {.metric = LAG_METRIC_RISE, .op = LAG_REQ_LT, .value = 1};
    ENSURE(!lag_require_term_holds(&lt, &m));
    lt.op = LAG_REQ_LE;
    ENSURE(lag_require_term_holds(&lt, &m));
    lt.op = LAG_REQ_GE;
    ENSURE(lag_require_term_holds(&lt, &m));
    lt.op = LAG_REQ_GT;
    ENSURE(!lag_require_term_holds(&lt, &m));
    m.v[LAG_METRIC_RISE] = NAN; /* a metric the run does not have fails every term */
    for (int op = LAG_REQ_LT; op <= LAG_REQ_GE; op++) {
        lt.op = (lag_require_op)op;
        ENSURE(!lag_require_term_holds(&lt, &m));
    }
    char buf[128];
    lag_require_term_format(&req.term[0], buf, sizeof buf);
    ENSURE(strcmp(buf, "x.iae <= 0.001") == 0);

    /* errors say where and what was expected */
    ENSURE(lag_require_parse("theta1.settling<2", &req, err, sizeof err) == -1);
    ENSURE(strstr(err, "column 8") && strstr(err, "unknown metric 'settling'"));
    for (int i = 0; i < LAG_METRIC_COUNT; i++) ENSURE(strstr(err, lag_metric_table[i].name));
    ENSURE(lag_require_parse("theta1.settle = 2", &req, err, sizeof err) == -1);
    ENSURE(strstr(err, "column 15") && strstr(err, "expected <"));
    ENSURE(lag_require_parse("theta1.settle < two", &req, err, sizeof err) == -1);
    ENSURE(strstr(err, "column 17") && strstr(err, "number"));
    ENSURE(lag_require_parse("theta1.settle < 1e999", &req, err, sizeof err) == -1);
    ENSURE(lag_require_parse("theta1.settle < 2 or x.iae < 1", &req, err, sizeof err) == -1);
    ENSURE(strstr(err, "column 19") && strstr(err, "'and'"));
    ENSURE(lag_require_parse("", &req, err, sizeof err) == -1);
    ENSURE(strstr(err, "joint name"));
    ENSURE(lag_require_parse("theta1 < 2", &req, err, sizeof err) == -1);
    ENSURE(strstr(err, "expected '.'"));
}

/* docs/evaluation.md's table of metrics (its section "## The metrics") has a row for every
 * metric of the table, and no other. */
static void case_docs(int arg)
{
    (void)arg;
    FILE *f = fopen(LAGSIM_SOURCE_DIR "/docs/evaluation.md", "r");
    ENSURE(f != NULL);
    if (!f) return;
    char line[1024];
    int rows[LAG_METRIC_COUNT] = {0}, other = 0;
    bool in_section = false;
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "## ", 3)) in_section = !strcmp(line, "## The metrics\n");
        char name[64];
        if (!in_section || sscanf(line, "| `%63[a-z_]` |", name) != 1) continue;
        int m = lag_metric_find(name);
        if (m < 0) {
            LT_FAIL("docs/evaluation.md has a row for '%s', which is not a metric", name);
            other++;
        } else rows[m]++;
    }
    fclose(f);
    for (int i = 0; i < LAG_METRIC_COUNT; i++)
        if (rows[i] != 1)
            LT_FAIL("docs/evaluation.md has %d rows for metric '%s' (want 1)", rows[i],
                    lag_metric_table[i].name);
    ENSURE(other == 0);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"first_order", case_first_order, 0, 0},
        {"first_order_down", case_first_order, 1, 0},
        {"second_order", case_second_order, 0, 0},
        {"disturbance", case_disturbance, 0, 0},
        {"start_time", case_start_time, 0, 0},
        {"missing", case_missing, 0, 0},
        {"effort", case_effort, 0, 0},
        {"bad_samples", case_bad_samples, 0, 0},
        {"require", case_require, 0, 0},
        {"docs", case_docs, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
