/*
 * The real-time loop's arithmetic (see rt_pace.h): saturating conversions, which periods
 * are due, token buckets. Integer nanoseconds throughout; doubles only at the edges, where
 * every conversion saturates.
 */
#include <math.h>

#include "rt_pace.h"

/* ---------------------------------------------------------------- conversions */
int64_t rt_sat_i64(double x)
{
    if (isnan(x)) return 0;
    if (x >= 0x1p63) return INT64_MAX;   /* 2^63 is the first double above INT64_MAX */
    if (x <= -0x1p63) return INT64_MIN;
    return (int64_t)x;
}

int64_t rt_sat_add(int64_t a, int64_t b)
{
    int64_t r;
    if (__builtin_add_overflow(a, b, &r)) return b > 0 ? INT64_MAX : INT64_MIN;
    return r;
}

int64_t rt_sat_mul(int64_t a, int64_t b)
{
    int64_t r;
    if (__builtin_mul_overflow(a, b, &r)) return (a < 0) != (b < 0) ? INT64_MIN : INT64_MAX;
    return r;
}

int64_t rt_ns_from_s(double seconds)
{
    return rt_sat_i64(nearbyint(seconds * 1e9));
}

int64_t rt_clamp_ns(double ns, int64_t lo, int64_t hi)
{
    if (isnan(ns)) return hi;
    int64_t v = rt_sat_i64(nearbyint(ns));
    return v < lo ? lo : v > hi ? hi : v;
}

bool rt_ticks_for(double seconds, double dt, int64_t *ticks)
{
    double x = seconds / dt;
    if (!(x > 0.0) || !(dt > 0.0)) return false;            /* also NaN */
    x = ceil(x * (1.0 - 1e-12) - 1e-9);
    if (!(x <= (double)RT_MAX_RUN_TICKS)) return false;     /* also +inf */
    *ticks = x < 1.0 ? 1 : (int64_t)x;
    return true;
}

/* ---------------------------------------------------------------- pacing */
int64_t rt_pace_period_ns(double period_s, double rate, bool *clamped)
{
    double ns = period_s / rate * 1e9;
    int64_t v = rt_clamp_ns(ns, RT_PERIOD_NS_MIN, RT_PERIOD_NS_MAX);
    if (clamped) *clamped = !(fabs((double)v - ns) <= 0.5);
    return v;
}

void rt_pace_start(rt_pace *p, int64_t period_ns, int64_t now)
{
    p->period_ns = period_ns < RT_PERIOD_NS_MIN ? RT_PERIOD_NS_MIN
                   : period_ns > RT_PERIOD_NS_MAX ? RT_PERIOD_NS_MAX : period_ns;
    p->base_ns = now;
    p->done = 0;
    p->late_mark = 0;
}

rt_due rt_pace_due(const rt_pace *p, int64_t now)
{
    rt_due d = {0, 0, 0, false};
    if (now <= p->base_ns) return d;
    /* periods whose deadline base + k * period has passed: exact integer division */
    int64_t k = (now - p->base_ns) / p->period_ns;
    if (k <= p->done) return d;
    d.due = k - p->done;
    /* every due period but the last started late; each is counted once (a burst may leave
     * some for the next wake-up, which must not count them again) */
    int64_t last_late = p->done + d.due - 1;
    int64_t from = p->late_mark > p->done ? p->late_mark : p->done;
    if (last_late > from) d.overruns = last_late - from;
    if (d.due > RT_MAX_LAG_PERIODS ||
        (d.due > 1 && rt_sat_mul(d.due, p->period_ns) > RT_MAX_LAG_NS)) {
        d.rebase = true;
        d.run = 1;
    } else {
        d.run = d.due < RT_MAX_BURST ? d.due : RT_MAX_BURST;
    }
    return d;
}

void rt_pace_apply(rt_pace *p, const rt_due *d, int64_t now)
{
    if (d->rebase) {
        /* one period due now, the next one period from now */
        p->base_ns = now - p->period_ns;
        p->done = 0;
        p->late_mark = 0;
    } else if (d->overruns > 0) {
        p->late_mark = p->done + d->due - 1;
    }
}

void rt_pace_ran(rt_pace *p)
{
    p->done++;
}

void rt_pace_skip(rt_pace *p, int64_t now)
{
    if (now <= p->base_ns) return;
    int64_t k = (now - p->base_ns) / p->period_ns;
    if (k > p->done) p->done = k;
    if (p->late_mark < p->done) p->late_mark = p->done;
}

int64_t rt_pace_next(const rt_pace *p)
{
    return rt_sat_add(p->base_ns, rt_sat_mul(p->done + 1, p->period_ns));
}

/* ---------------------------------------------------------------- limiting */
void rt_limit_init(rt_limit *l, double per_s, int burst, int64_t now)
{
    l->interval_ns = rt_clamp_ns(1e9 / per_s, 1, RT_PERIOD_NS_MAX);
    l->cap_ns = rt_sat_mul(l->interval_ns, burst < 1 ? 1 : burst);
    l->credit_ns = l->cap_ns;
    l->last_ns = now;
    l->suppressed = 0;
}

/* Credit at `now`, without changing the bucket. */
static int64_t credit_at(const rt_limit *l, int64_t now)
{
    int64_t elapsed = now > l->last_ns ? now - l->last_ns : 0;
    int64_t c = rt_sat_add(l->credit_ns, elapsed);
    return c > l->cap_ns ? l->cap_ns : c;
}

bool rt_limit_take(rt_limit *l, int64_t now)
{
    l->credit_ns = credit_at(l, now);
    if (now > l->last_ns) l->last_ns = now;
    if (l->credit_ns < l->interval_ns) {
        l->suppressed++;
        return false;
    }
    l->credit_ns -= l->interval_ns;
    return true;
}

int64_t rt_limit_ready(const rt_limit *l, int64_t now)
{
    int64_t c = credit_at(l, now);
    int64_t t = now > l->last_ns ? now : l->last_ns;
    return c >= l->interval_ns ? now : rt_sat_add(t, l->interval_ns - c);
}
