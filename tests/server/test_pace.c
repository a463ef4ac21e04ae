/*
 * The real-time loop's arithmetic (server/daemon/rt_pace.c) with made-up clocks: no LCM,
 * no sleeping, exact integer expectations worked out by hand from the definitions
 * (deadline k = base + k * period; every due period but the last started late; a token
 * bucket of `burst` tokens refilled at one per interval).
 *
 *   test_pace CASE     CASE: convert ticks pace burst rebase skip limit (--list)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_test.h"
#include "rt_pace.h"

#define MS 1000000LL

/* Doubles to int64 nanoseconds and ticks: saturating at both ends, NaN to 0. */
static void case_convert(int arg)
{
    (void)arg;
    ENSURE(rt_sat_i64(1e300) == INT64_MAX && rt_sat_i64(-1e300) == INT64_MIN);
    ENSURE(rt_sat_i64(INFINITY) == INT64_MAX && rt_sat_i64(-INFINITY) == INT64_MIN);
    ENSURE(rt_sat_i64(NAN) == 0);
    ENSURE(rt_sat_i64(0x1p63) == INT64_MAX);              /* first double past INT64_MAX */
    ENSURE(rt_sat_i64(-0x1p63) == INT64_MIN);             /* exactly INT64_MIN */
    ENSURE(rt_sat_i64(0x1p62) == (1LL << 62));
    ENSURE(rt_sat_i64(-2.9) == -2 && rt_sat_i64(2.9) == 2);
    ENSURE(rt_sat_add(INT64_MAX, 1) == INT64_MAX && rt_sat_add(INT64_MIN, -1) == INT64_MIN);
    ENSURE(rt_sat_add(INT64_MAX, INT64_MIN) == -1 && rt_sat_add(5, -7) == -2);
    ENSURE(rt_sat_mul(1LL << 32, 1LL << 32) == INT64_MAX);
    ENSURE(rt_sat_mul(-(1LL << 32), 1LL << 32) == INT64_MIN);
    ENSURE(rt_sat_mul(INT64_MIN, -1) == INT64_MAX && rt_sat_mul(-3, 4) == -12);
    /* seconds to ns: lockstep_timeout 1e10 s and 1e300 s saturate instead of wrapping */
    ENSURE(rt_ns_from_s(0.05) == 50 * MS);
    ENSURE(rt_ns_from_s(1e10) == INT64_MAX && rt_ns_from_s(1e300) == INT64_MAX);
    ENSURE(rt_ns_from_s(-1e300) == INT64_MIN && rt_ns_from_s(NAN) == 0);
    ENSURE(rt_ns_from_s(9.2e9) == 9200000000LL * 1000000000LL);
    /* Hz to a clamped period: status_hz 1e-300 and 1e9 */
    ENSURE(rt_clamp_ns(1e9 / 1e-300, 10 * MS, INT64_MAX) == INT64_MAX);
    ENSURE(rt_clamp_ns(1e9 / 1e9, 10 * MS, INT64_MAX) == 10 * MS);
    ENSURE(rt_clamp_ns(1e9 / 5.0, 10 * MS, INT64_MAX) == 200 * MS);
    ENSURE(rt_clamp_ns(NAN, 1, 99) == 99);
    /* the wall period of a control period: rate 1e25 and rate 1e-300 are clamped, and
     * said so; 10 ms at rate 1 and 0.5 are exact */
    bool cl = true;
    ENSURE(rt_pace_period_ns(0.01, 1.0, &cl) == 10 * MS && !cl);
    ENSURE(rt_pace_period_ns(0.01, 0.5, &cl) == 20 * MS && !cl);
    ENSURE(rt_pace_period_ns(0.01, 1e25, &cl) == RT_PERIOD_NS_MIN && cl);
    ENSURE(rt_pace_period_ns(0.01, 1e6, &cl) == RT_PERIOD_NS_MIN && cl); /* 10 ns asked */
    ENSURE(rt_pace_period_ns(0.01, 1e-300, &cl) == RT_PERIOD_NS_MAX && cl);
    ENSURE(rt_pace_period_ns(1e9, 1.0, &cl) == RT_PERIOD_NS_MAX && cl);
    ENSURE(rt_pace_period_ns(0.01, NAN, &cl) == RT_PERIOD_NS_MAX && cl);
}

/* --duration to ticks: the count must fit 2^53 (sim time = tick * dt exact). */
static void case_ticks(int arg)
{
    (void)arg;
    int64_t t = -7;
    ENSURE(rt_ticks_for(2.0, 1e-3, &t) && t == 2000);
    ENSURE(rt_ticks_for(0.3, 1e-3, &t) && t == 300); /* 0.3/1e-3 = 299.99999999999994 */
    ENSURE(rt_ticks_for(1.0, 0.1, &t) && t == 10);   /* 1/0.1 = 10 exactly */
    ENSURE(rt_ticks_for(0.0105, 1e-3, &t) && t == 11); /* rounded up */
    ENSURE(rt_ticks_for(1e-9, 1e-3, &t) && t == 1);
    t = -7;
    ENSURE(!rt_ticks_for(1e300, 1e-3, &t) && t == -7);
    ENSURE(!rt_ticks_for(1e16, 1e-3, &t));            /* 1e19 ticks */
    ENSURE(!rt_ticks_for(INFINITY, 1e-3, &t) && !rt_ticks_for(NAN, 1e-3, &t));
    ENSURE(!rt_ticks_for(0.0, 1e-3, &t) && !rt_ticks_for(-1.0, 1e-3, &t));
    ENSURE(!rt_ticks_for(1.0, 0.0, &t) && !rt_ticks_for(1.0, -1e-3, &t));
    ENSURE(rt_ticks_for(0x1p52 * 1e-3, 1e-3, &t) && t <= RT_MAX_RUN_TICKS && t > (1LL << 51));
    ENSURE(!rt_ticks_for(0x1p54 * 1e-3, 1e-3, &t));
}

/* Deadlines on time: one period each, no overruns, no drift over a million periods. */
static void case_pace(int arg)
{
    (void)arg;
    rt_pace p;
    const int64_t t0 = 123456789, P = 10 * MS;
    rt_pace_start(&p, P, t0);
    ENSURE(rt_pace_next(&p) == t0 + P);
    rt_due d = rt_pace_due(&p, t0 + P - 1);
    ENSURE(d.due == 0 && d.run == 0 && d.overruns == 0 && !d.rebase);
    d = rt_pace_due(&p, t0 + P);
    ENSURE(d.due == 1 && d.run == 1 && d.overruns == 0 && !d.rebase);
    /* a clock before the base: nothing due */
    ENSURE(rt_pace_due(&p, t0 - 5 * P).due == 0);
    bool on_time = true; /* one check for the million periods */
    for (int64_t k = 1; k <= 1000000 && on_time; k++) {
        int64_t now = t0 + k * P + 37; /* woken 37 ns late each time */
        d = rt_pace_due(&p, now);
        on_time = d.due == 1 && d.run == 1 && d.overruns == 0;
        rt_pace_apply(&p, &d, now);
        rt_pace_ran(&p);
    }
    ENSUREF(on_time, "one period due, on time");
    ENSURE(rt_pace_next(&p) == t0 + 1000001 * P); /* exactly: no accumulated error */

    /* one wake-up 35 ms late with 10 ms periods: periods 2 and 3 due (2 started late) */
    rt_pace_start(&p, P, t0);
    d = rt_pace_due(&p, t0 + P);
    rt_pace_apply(&p, &d, t0 + P);
    rt_pace_ran(&p);
    d = rt_pace_due(&p, t0 + 35 * MS);
    ENSURE(d.due == 2 && d.run == 2 && d.overruns == 1 && !d.rebase);
    rt_pace_apply(&p, &d, t0 + 35 * MS);
    rt_pace_ran(&p);
    rt_pace_ran(&p);
    ENSURE(rt_pace_next(&p) == t0 + 4 * P);
    /* asked again at the same time: nothing more due, nothing counted twice */
    d = rt_pace_due(&p, t0 + 35 * MS);
    ENSURE(d.due == 0 && d.overruns == 0);
}

/* A wake-up 155 ms late: 15 due, 14 of them late; bursts of 10 then 5; each overrun
 * counted once although the second look sees the same late periods. */
static void case_burst(int arg)
{
    (void)arg;
    rt_pace p;
    const int64_t t0 = 1000, P = 10 * MS, now = t0 + 155 * MS;
    rt_pace_start(&p, P, t0);
    rt_due d = rt_pace_due(&p, now);
    ENSURE(d.due == 15 && d.run == RT_MAX_BURST && d.overruns == 14 && !d.rebase);
    int64_t overruns = d.overruns;
    rt_pace_apply(&p, &d, now);
    for (int k = 0; k < d.run; k++) rt_pace_ran(&p);
    d = rt_pace_due(&p, now);
    ENSURE(d.due == 5 && d.run == 5 && d.overruns == 0 && !d.rebase);
    overruns += d.overruns;
    rt_pace_apply(&p, &d, now);
    for (int k = 0; k < d.run; k++) rt_pace_ran(&p);
    ENSURE(overruns == 14 && rt_pace_next(&p) == t0 + 16 * P);
    /* the next deadline met on time: no overrun */
    d = rt_pace_due(&p, t0 + 16 * P);
    ENSURE(d.due == 1 && d.overruns == 0);
}

/* Too far behind (more than 100 periods, or more than 0.2 s): give up catching up, run
 * one period now and the next one period later. */
static void case_rebase(int arg)
{
    (void)arg;
    rt_pace p;
    const int64_t P = 1 * MS;
    rt_pace_start(&p, P, 0);
    int64_t now = 101 * P;                 /* 101 due */
    rt_due d = rt_pace_due(&p, now);
    ENSURE(d.due == 101 && d.rebase && d.run == 1 && d.overruns == 100);
    rt_pace_apply(&p, &d, now);
    rt_pace_ran(&p);
    ENSURE(rt_pace_next(&p) == now + P);
    ENSURE(rt_pace_due(&p, now).due == 0);
    rt_pace_start(&p, P, 0);
    d = rt_pace_due(&p, 100 * P);          /* exactly 100 (0.1 s): catch up */
    ENSURE(d.due == 100 && !d.rebase && d.run == RT_MAX_BURST);
    /* 0.2 s rule: 5 periods of 50 ms = 250 ms behind */
    rt_pace_start(&p, 50 * MS, 0);
    d = rt_pace_due(&p, 250 * MS);
    ENSURE(d.due == 5 && d.rebase && d.run == 1);
    d = rt_pace_due(&p, 200 * MS);         /* 4 periods = 200 ms: not more than 0.2 s */
    ENSURE(d.due == 4 && !d.rebase);
    /* a rate so high that the period is the 1 us floor, a wake-up 1 s late: one re-base,
     * never an overflow */
    rt_pace_start(&p, rt_pace_period_ns(0.01, 1e25, NULL), 0);
    d = rt_pace_due(&p, 1000 * MS);
    ENSURE(d.due == 1000000 && d.rebase && d.run == 1);
    /* the longest period, with a huge index: the next deadline saturates */
    rt_pace_start(&p, RT_PERIOD_NS_MAX, INT64_MAX / 2);
    p.done = INT64_MAX / 4;
    ENSURE(rt_pace_next(&p) == INT64_MAX);
}

/* Paused: every deadline slept through is skipped, the next one is in the future. */
static void case_skip(int arg)
{
    (void)arg;
    rt_pace p;
    const int64_t P = 10 * MS;
    rt_pace_start(&p, P, 0);
    rt_pace_skip(&p, 1003 * MS);           /* 100 deadlines passed */
    ENSURE(p.done == 100 && rt_pace_next(&p) == 1010 * MS);
    rt_due d = rt_pace_due(&p, 1003 * MS);
    ENSURE(d.due == 0);
    d = rt_pace_due(&p, 1010 * MS);        /* and resuming on time counts no overrun */
    ENSURE(d.due == 1 && d.overruns == 0);
    rt_pace_skip(&p, -5);                  /* a clock before the base changes nothing */
    ENSURE(p.done == 100);
}

/* Token buckets: a burst, then the rate; suppressed answers counted; a flood over 10 s
 * gets at most burst + 10 s * rate answers. */
static void case_limit(int arg)
{
    (void)arg;
    rt_limit l;
    const int64_t t0 = 5 * MS;
    rt_limit_init(&l, 10.0, 10, t0);
    for (int k = 0; k < 10; k++) ENSURE(rt_limit_take(&l, t0));
    ENSURE(!rt_limit_take(&l, t0) && l.suppressed == 1);
    ENSURE(rt_limit_ready(&l, t0) == t0 + 100 * MS);
    ENSURE(!rt_limit_take(&l, t0 + 99 * MS) && l.suppressed == 2);
    ENSURE(rt_limit_ready(&l, t0 + 99 * MS) == t0 + 100 * MS);
    ENSURE(rt_limit_take(&l, t0 + 100 * MS));
    ENSURE(!rt_limit_take(&l, t0 + 150 * MS));
    /* a clock that goes back counts as standing still: no tokens from it */
    ENSURE(!rt_limit_take(&l, t0));
    ENSURE(rt_limit_ready(&l, t0) == t0 + 200 * MS);
    /* after a long quiet time the bucket holds `burst` tokens, not more */
    int64_t later = t0 + 3600 * 1000 * MS;
    int n = 0;
    while (rt_limit_take(&l, later)) n++;
    ENSURE(n == 10);
    /* a flood: one try every 10 us for 10 s */
    rt_limit_init(&l, 10.0, 10, 0);
    int64_t got = 0, tries = 0;
    for (int64_t now = 0; now < 10000 * MS; now += 10000, tries++) got += rt_limit_take(&l, now);
    ENSURE(got == 10 + 100 - 1 || got == 10 + 100); /* the 100th refill lands at exactly 10 s */
    ENSURE(l.suppressed == tries - got);
    /* absurd rates: clamped intervals, no overflow */
    rt_limit_init(&l, 1e-300, 3, 0);
    ENSURE(l.interval_ns == RT_PERIOD_NS_MAX && rt_limit_take(&l, 0));
    rt_limit_init(&l, 1e300, 1000000, 0);
    ENSURE(l.interval_ns == 1 && rt_limit_take(&l, 0));
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"convert", case_convert, 0, 0}, {"ticks", case_ticks, 0, 0},
        {"pace", case_pace, 0, 0},       {"burst", case_burst, 0, 0},
        {"rebase", case_rebase, 0, 0},   {"skip", case_skip, 0, 0},
        {"limit", case_limit, 0, 0},
    };
    const lt_program p = {.cases = cases, .n = (int)(sizeof cases / sizeof cases[0]),
                          .stop_on_failure = true};
    return lt_run(argc, argv, &p);
}
