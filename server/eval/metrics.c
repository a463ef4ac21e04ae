/*
 * Step-response and tracking metrics of one joint's run, and requirements on them
 * (metrics.h says what each metric is; docs/evaluation.md gives the formulas).
 */
#include "metrics.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const lag_metric_info lag_metric_table[LAG_METRIC_COUNT] = {
    [LAG_METRIC_RISE] = {"rise", "s", "rise time, 10 % to 90 % of the step"},
    [LAG_METRIC_SETTLE] = {"settle", "s", "settling time into the 2 % band, from the case's start"},
    [LAG_METRIC_OVERSHOOT] = {"overshoot", "", "overshoot past the final reference, a fraction of the step"},
    [LAG_METRIC_SS_ERROR] = {"sse", "unit", "steady-state error: mean r - q over the last 10 %"},
    [LAG_METRIC_IAE] = {"iae", "unit s", "integral of |r - q| dt"},
    [LAG_METRIC_ISE] = {"ise", "unit^2 s", "integral of (r - q)^2 dt"},
    [LAG_METRIC_PEAK_ERROR] = {"peak_error", "unit", "largest |r - q|"},
    [LAG_METRIC_EFFORT_PEAK] = {"effort_peak", "effort", "largest |effort|"},
    [LAG_METRIC_EFFORT_RMS] = {"effort_rms", "effort", "root mean square of the held effort"},
};

lag_metric_opts lag_metric_opts_default(void)
{
    return (lag_metric_opts){.t0 = 0, .rise_lo = 0.1, .rise_hi = 0.9, .settle_band = 0.02,
                             .ss_window = 0.1};
}

int lag_metric_find(const char *name)
{
    for (int i = 0; i < LAG_METRIC_COUNT; i++)
        if (strcmp(lag_metric_table[i].name, name) == 0) return i;
    return -1;
}

static int fail(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* Where a linear interpolant from (ta, fa) to (tb, fb) reaches level c (fa != fb). */
static double crossing(double ta, double fa, double tb, double fb, double c)
{
    return ta + (c - fa) / (fb - fa) * (tb - ta);
}

/* The first time at or after sample `from` where s (as given by s_at) reaches c from
 * below, or NaN. */
static double first_reach(const double *t, const double *y, double y0, double a, size_t from,
                          size_t n, double c, size_t *at /* OUT */)
{
    *at = n;
    for (size_t k = from; k < n; k++) {
        double s = (y[k] - y0) / a;
        if (s >= c) {
            *at = k;
            if (k == from) return t[k];
            double sp = (y[k - 1] - y0) / a;
            return crossing(t[k - 1], sp, t[k], s, c);
        }
    }
    return NAN;
}

/* Integral of |f| over one interval of the linear interpolant: exact, split where f
 * changes sign. */
static double abs_trapezoid(double h, double fa, double fb)
{
    if ((fa >= 0) == (fb >= 0)) return 0.5 * h * fabs(fa + fb);
    double c = fa / (fa - fb); /* fraction of the interval where f = 0 */
    return 0.5 * h * (c * fabs(fa) + (1 - c) * fabs(fb));
}

/* One joint's run as the metrics see it: the samples from k0 on (t >= t0). */
typedef struct metric_run {
    const double *t, *y, *r, *u; /* r, u may be NULL: zero reference, no effort */
    size_t n, k0;
    double tend, y0, rT, a;      /* the last time, y(t0), r(T), the step A = r(T) - y(t0) */
    const lag_metric_opts *o;
} metric_run;

/* The error r - q at sample k. */
static double error_at(const metric_run *m, size_t k)
{
    return (m->r ? m->r[k] : 0.0) - m->y[k];
}

/* Every sample finite, t increasing. */
static int check_samples(const double *t, const double *y, const double *r, const double *u,
                         size_t n, char *err, size_t errlen)
{
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(t[k]) || !isfinite(y[k]) || (r && !isfinite(r[k])) || (u && !isfinite(u[k])))
            return fail(err, errlen, "sample %zu (t = %g) is not finite", k, t[k]);
        if (k > 0 && !(t[k] > t[k - 1]))
            return fail(err, errlen, "sim time does not increase at sample %zu (%.17g after %.17g)",
                        k, t[k], t[k - 1]);
    }
    return 0;
}

/* Integrals of |e| and e^2, and the peak |e|. */
static void error_integrals(const metric_run *m, lag_metrics *out)
{
    const double *t = m->t;
    double iae = 0, ise = 0, peak = fabs(error_at(m, m->k0));
    for (size_t k = m->k0 + 1; k < m->n; k++) {
        double h = t[k] - t[k - 1], ea = error_at(m, k - 1), eb = error_at(m, k);
        iae += abs_trapezoid(h, ea, eb);
        ise += 0.5 * h * (ea * ea + eb * eb);
        if (fabs(eb) > peak) peak = fabs(eb);
    }
    out->v[LAG_METRIC_IAE] = iae;
    out->v[LAG_METRIC_ISE] = ise;
    out->v[LAG_METRIC_PEAK_ERROR] = peak;
}

/* The steady state: the mean of e over the last ss_window of [t0, T]. */
static void steady_state(const metric_run *m, lag_metrics *out)
{
    const double *t = m->t;
    double tw = m->tend - m->o->ss_window * (m->tend - m->o->t0);
    double area = 0;
    for (size_t k = m->k0 + 1; k < m->n; k++) {
        if (t[k] <= tw) continue;
        double ta = t[k - 1], ea = error_at(m, k - 1), eb = error_at(m, k);
        if (ta < tw) { /* the interval the window starts in: from tw on */
            ea = ea + (eb - ea) * (tw - ta) / (t[k] - ta);
            ta = tw;
        }
        area += 0.5 * (t[k] - ta) * (ea + eb);
    }
    out->v[LAG_METRIC_SS_ERROR] = m->tend > tw ? area / (m->tend - tw) : error_at(m, m->n - 1);
}

/* Settling: the last time |e| leaves the band, interpolated; NaN if it ends outside. */
static void settling(const metric_run *m, lag_metrics *out)
{
    const double *t = m->t;
    const size_t n = m->n;
    double band = m->o->settle_band * (m->a != 0 ? fabs(m->a) : out->v[LAG_METRIC_PEAK_ERROR]);
    size_t last_out = n; /* none */
    for (size_t k = m->k0; k < n; k++)
        if (fabs(error_at(m, k)) > band) last_out = k;
    if (last_out == n)
        out->v[LAG_METRIC_SETTLE] = t[m->k0] - m->o->t0;
    else if (last_out + 1 < n) {
        double fa = fabs(error_at(m, last_out)), fb = fabs(error_at(m, last_out + 1));
        out->v[LAG_METRIC_SETTLE] =
            crossing(t[last_out], fa, t[last_out + 1], fb, band) - m->o->t0;
    }
}

/* A step (A != 0): rise from rise_lo to rise_hi, and the overshoot past r(T). */
static void step_shape(const metric_run *m, lag_metrics *out)
{
    const double *t = m->t, *y = m->y, a = m->a;
    const size_t n = m->n;
    /* rise: first reach of rise_lo, then of rise_hi after it */
    size_t at_lo, at_hi;
    double t_lo = first_reach(t, y, m->y0, a, m->k0, n, m->o->rise_lo, &at_lo);
    double t_hi = at_lo < n ? first_reach(t, y, m->y0, a, at_lo, n, m->o->rise_hi, &at_hi) : NAN;
    out->v[LAG_METRIC_RISE] = t_hi - t_lo;
    /* overshoot: how far y passes r(T), as a fraction of the step */
    double os = 0;
    for (size_t k = m->k0; k < n; k++) {
        double s = (y[k] - m->rT) / a;
        if (s > os) os = s;
    }
    out->v[LAG_METRIC_OVERSHOOT] = os;
}

/* The effort's peak and RMS, each effort held until the next sample. */
static void effort(const metric_run *m, lag_metrics *out)
{
    const double *t = m->t, *u = m->u;
    double upeak = 0, u2 = 0;
    for (size_t k = m->k0; k < m->n; k++) {
        if (fabs(u[k]) > upeak) upeak = fabs(u[k]);
        if (k + 1 < m->n) u2 += u[k] * u[k] * (t[k + 1] - t[k]); /* held until t[k+1] */
    }
    out->v[LAG_METRIC_EFFORT_PEAK] = upeak;
    out->v[LAG_METRIC_EFFORT_RMS] = sqrt(u2 / (m->tend - t[m->k0]));
}

int lag_metrics_compute(const double *t, const double *y, const double *r, const double *u,
                        size_t n, const lag_metric_opts *o, lag_metrics *out, char *err,
                        size_t errlen)
{
    out->step = NAN;
    for (int i = 0; i < LAG_METRIC_COUNT; i++) out->v[i] = NAN;
    if (!t || !y || !o) return fail(err, errlen, "no samples");
    if (check_samples(t, y, r, u, n, err, errlen)) return -1;
    size_t k0 = 0;
    while (k0 < n && t[k0] < o->t0) k0++;
    if (n - k0 < 2)
        return fail(err, errlen, "fewer than 2 samples at or after t0 = %g s (%zu in all)", o->t0, n);

    metric_run m = {.t = t, .y = y, .r = r, .u = u, .n = n, .k0 = k0, .o = o,
                    .tend = t[n - 1], .y0 = y[k0], .rT = r ? r[n - 1] : 0.0};
    m.a = m.rT - m.y0;
    out->step = m.a;
    error_integrals(&m, out);
    steady_state(&m, out);
    settling(&m, out);
    if (m.a != 0) step_shape(&m, out);
    if (u) effort(&m, out);
    return 0;
}

/* ------------------------------------------------------------------ requirements */

static const char *const op_text[] = {[LAG_REQ_LT] = "<", [LAG_REQ_LE] = "<=",
                                      [LAG_REQ_GT] = ">", [LAG_REQ_GE] = ">="};

static void metric_list(char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < LAG_METRIC_COUNT && used < len; i++) {
        int w = snprintf(buf + used, len - used, "%s%s", i ? ", " : "", lag_metric_table[i].name);
        if (w < 0) break;
        used += (size_t)w;
    }
}

static const char *skip_space(const char *p)
{
    while (*p == ' ' || *p == '\t') p++;
    return p;
}

static int is_name_char(char c)
{
    return isalnum((unsigned char)c) || c == '_';
}

int lag_require_parse(const char *text, lag_require *req, char *err, size_t errlen)
{
    req->n = 0;
    if (!text) return fail(err, errlen, "no requirement");
    const char *p = skip_space(text);
    char metrics[256];
    metric_list(metrics, sizeof metrics);
#define COL ((int)(p - text) + 1)
    for (;;) {
        if (req->n == LAG_REQUIRE_MAX)
            return fail(err, errlen, "column %d: more than %d terms", COL, LAG_REQUIRE_MAX);
        lag_require_term *term = &req->term[req->n];
        const char *s = p;
        while (is_name_char(*p)) p++;
        if (p == s)
            return fail(err, errlen, "column %d: expected a joint name (as in JOINT.METRIC < NUMBER)", COL);
        if ((size_t)(p - s) >= sizeof term->joint)
            return fail(err, errlen, "column %d: a joint name of at most %d characters",
                        (int)(s - text) + 1, LAG_REQUIRE_NAME - 1);
        memcpy(term->joint, s, (size_t)(p - s));
        term->joint[p - s] = '\0';
        if (*p != '.')
            return fail(err, errlen, "column %d: expected '.' and a metric after '%s'", COL, term->joint);
        s = ++p;
        while (is_name_char(*p)) p++;
        char name[64];
        size_t len = (size_t)(p - s);
        if (len >= sizeof name) len = sizeof name - 1;
        memcpy(name, s, len);
        name[len] = '\0';
        int m = lag_metric_find(name);
        if (m < 0)
            return fail(err, errlen, "column %d: unknown metric '%s' (expected one of: %s)",
                        (int)(s - text) + 1, name, metrics);
        term->metric = (lag_metric)m;
        p = skip_space(p);
        if (p[0] == '<' && p[1] == '=') term->op = LAG_REQ_LE, p += 2;
        else if (p[0] == '>' && p[1] == '=') term->op = LAG_REQ_GE, p += 2;
        else if (p[0] == '<') term->op = LAG_REQ_LT, p += 1;
        else if (p[0] == '>') term->op = LAG_REQ_GT, p += 1;
        else return fail(err, errlen, "column %d: expected <, <=, > or >= after '%s.%s'", COL,
                         term->joint, name);
        p = skip_space(p);
        char *endp;
        errno = 0;
        double v = strtod(p, &endp);
        if (endp == p || errno == ERANGE || !isfinite(v))
            return fail(err, errlen, "column %d: expected a finite number", COL);
        term->value = v;
        p = skip_space(endp);
        req->n++;
        if (*p == '\0') return 0;
        if (strncmp(p, "and", 3) == 0 && !is_name_char(p[3])) {
            p = skip_space(p + 3);
            continue;
        }
        return fail(err, errlen, "column %d: expected 'and' or the end of the requirement", COL);
    }
#undef COL
}

int lag_require_term_holds(const lag_require_term *term, const lag_metrics *metrics)
{
    double x = metrics->v[term->metric];
    if (isnan(x)) return 0;
    switch (term->op) {
    case LAG_REQ_LT: return x < term->value;
    case LAG_REQ_LE: return x <= term->value;
    case LAG_REQ_GT: return x > term->value;
    case LAG_REQ_GE: return x >= term->value;
    }
    return 0;
}

void lag_require_term_format(const lag_require_term *term, char *buf, size_t len)
{
    snprintf(buf, len, "%s.%s %s %g", term->joint, lag_metric_table[term->metric].name,
             op_text[term->op], term->value);
}
