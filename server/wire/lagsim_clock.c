/*
 * The clocks lagsim reads: see lagsim_clock.h.
 */
#include "lagsim_clock.h"

static struct timespec clock_read(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return ts;
}

static double seconds(struct timespec ts) { return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec; }

int64_t lag_clock_mono_ns(void)
{
    struct timespec ts = clock_read(CLOCK_MONOTONIC);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

double lag_clock_mono_s(void) { return seconds(clock_read(CLOCK_MONOTONIC)); }

int64_t lag_clock_wall_us(void)
{
    struct timespec ts = clock_read(CLOCK_REALTIME);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

void lag_clock_wall_timespec(struct timespec *ts) { *ts = clock_read(CLOCK_REALTIME); }

double lag_clock_process_cpu_s(void) { return seconds(clock_read(CLOCK_PROCESS_CPUTIME_ID)); }

double lag_clock_thread_cpu_s(void) { return seconds(clock_read(CLOCK_THREAD_CPUTIME_ID)); }
