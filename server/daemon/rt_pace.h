/*
 * The arithmetic of the real-time loop, pure: no clock reads, no I/O, no LCM. Times are
 * CLOCK_MONOTONIC nanoseconds (int64_t) handed in by the caller, so every function here
 * can be tested with made-up clocks (tests/server/test_pace.c).
 *
 *   conversions   double seconds/Hz/rates to int64 nanoseconds and ticks, saturating:
 *                 no scene value, however absurd (1e300, 1e-300, inf, NaN), can overflow
 *   pacing        which control periods are due at a given time: deadlines, overruns,
 *                 bursts, re-basing when the loop cannot catch up
 *   limiting      token buckets for everything the daemon publishes in answer to what
 *                 arrives, so that a flood in is never a flood out
 */
#ifndef LAGSIMD_RT_PACE_H
#define LAGSIMD_RT_PACE_H

#include <stdbool.h>
#include <stdint.h>

#define RT_NS_PER_S 1000000000LL

/* ---------------------------------------------------------------- conversions */
/* x truncated toward zero, clamped to [INT64_MIN, INT64_MAX]; NaN gives 0. */
int64_t rt_sat_i64(double x);
/* a + b and a * b, clamped to [INT64_MIN, INT64_MAX] instead of overflowing. */
int64_t rt_sat_add(int64_t a, int64_t b);
int64_t rt_sat_mul(int64_t a, int64_t b);
/* seconds * 1e9, rounded to nearest, saturating; NaN gives 0. */
int64_t rt_ns_from_s(double seconds);
/* ns clamped to [lo, hi] (NaN gives hi). */
int64_t rt_clamp_ns(double ns, int64_t lo, int64_t hi);

/* The longest run in ticks: sim time is tick * dt, exact while the tick fits a double's
 * 53-bit significand. */
#define RT_MAX_RUN_TICKS (1LL << 53)
/* Ticks in `seconds` of sim time at tick dt, rounded up (with a relative guard, so that
 * 1 s at dt 1 ms is 1000 ticks, not 1001). Returns false (ticks untouched) when the count
 * is not a positive number of at most RT_MAX_RUN_TICKS ticks. OUT: ticks */
bool rt_ticks_for(double seconds, double dt, int64_t *ticks);

/* ---------------------------------------------------------------- pacing */
#define RT_MAX_BURST 10             /* periods run back to back when catching up */
#define RT_MAX_LAG_PERIODS 100      /* behind by more than this: re-base the clock */
#define RT_MAX_LAG_NS 200000000LL   /* ... or by more than 0.2 s of wall time */
#define RT_PERIOD_NS_MIN 1000LL     /* shortest wall period paced: 1 us */
#define RT_PERIOD_NS_MAX (100000LL * RT_NS_PER_S) /* longest: about 28 hours */

/* Realtime deadlines: period k (k = 1, 2, ...) since the base ends at base_ns + k * period_ns.
 * Deadlines come from the index, never from accumulated sums, so they do not drift. */
typedef struct rt_pace {
    int64_t period_ns;  /* wall ns per control period, in [RT_PERIOD_NS_MIN, RT_PERIOD_NS_MAX] */
    int64_t base_ns;
    int64_t done;       /* periods started since the base */
    int64_t late_mark;  /* periods up to this index are already counted as overruns */
} rt_pace;

/* What is due at a given time (rt_pace_due). */
typedef struct rt_due {
    int64_t due;        /* periods whose deadline has passed and that have not started */
    int64_t run;        /* how many to run now: 0 .. RT_MAX_BURST */
    int64_t overruns;   /* periods newly found to have started late (every due one but the last) */
    bool rebase;        /* too far behind to catch up: the clock re-bases, `due` are skipped */
} rt_due;

/* The wall period of one control period: period_s sim seconds at `rate` sim seconds per
 * wall second, clamped to [RT_PERIOD_NS_MIN, RT_PERIOD_NS_MAX]. *clamped (may be NULL)
 * says the clamp changed it. */
int64_t rt_pace_period_ns(double period_s, double rate, bool *clamped);
/* Deadlines restart from now: the first one is now + period. */
void rt_pace_start(rt_pace *p, int64_t period_ns, int64_t now);
/* Which periods are due at `now` (pure). */
rt_due rt_pace_due(const rt_pace *p, int64_t now);
/* Books what rt_pace_due found: overruns marked, and on a re-base the clock restarts so
 * that one period is due now and the next one period later. */
void rt_pace_apply(rt_pace *p, const rt_due *d, int64_t now);
/* A period starts (call once per period run). */
void rt_pace_ran(rt_pace *p);
/* Every period due at `now` is skipped without running (paused: the loop republishes the
 * held state once, however many deadlines it slept through). */
void rt_pace_skip(rt_pace *p, int64_t now);
/* Deadline of the next period to start: base + (done + 1) * period (saturating). */
int64_t rt_pace_next(const rt_pace *p);

/* ---------------------------------------------------------------- limiting */
/* A token bucket: `burst` answers at once, then one per interval. */
typedef struct rt_limit {
    int64_t interval_ns;  /* one token per interval */
    int64_t cap_ns;       /* bucket size: burst * interval */
    int64_t credit_ns;    /* tokens in the bucket, as time */
    int64_t last_ns;      /* when credit_ns was last brought up to date */
    int64_t suppressed;   /* refused since the last answer that got through */
} rt_limit;

/* per_s answers per second (> 0), bursts of `burst` (>= 1); the bucket starts full at now. */
void rt_limit_init(rt_limit *l, double per_s, int burst, int64_t now);
/* Takes a token if there is one (true); otherwise counts one more suppressed (false).
 * A clock that goes back is taken as standing still. */
bool rt_limit_take(rt_limit *l, int64_t now);
/* When rt_limit_take would next succeed (now if it would now). Pure. */
int64_t rt_limit_ready(const rt_limit *l, int64_t now);

#endif
