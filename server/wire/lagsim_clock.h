/*
 * The clocks lagsim reads, in one place: every program and library of the project
 * (daemon, view, client library, tools, benchmarks) reads time through these functions,
 * and only server/wire/lagsim_clock.c calls clock_gettime (tests/structure checks it).
 *
 *   - monotonic: CLOCK_MONOTONIC, for pacing, deadlines, timeouts and rates (never jumps);
 *   - wall: CLOCK_REALTIME, for the utime of every message (microseconds since the epoch,
 *     as LCM's own tools and lcm-logger's receive times);
 *   - CPU: CLOCK_PROCESS_CPUTIME_ID / CLOCK_THREAD_CPUTIME_ID, for what a computation
 *     costs (benchmarks, the accuracy cost table).
 */
#ifndef LAGSIM_CLOCK_H
#define LAGSIM_CLOCK_H

#include <stdint.h>
#include <time.h>

#ifdef __cplusplus
extern "C" {
#endif

/* CLOCK_MONOTONIC in nanoseconds. */
int64_t lag_clock_mono_ns(void);
/* CLOCK_MONOTONIC in seconds. */
double lag_clock_mono_s(void);
/* CLOCK_REALTIME in microseconds since the epoch: a message's utime. */
int64_t lag_clock_wall_us(void);
/* CLOCK_REALTIME as a timespec (an absolute deadline for sem_timedwait). OUT: ts */
void lag_clock_wall_timespec(struct timespec *ts);
/* CPU time of the process, s. */
double lag_clock_process_cpu_s(void);
/* CPU time of the calling thread, s. */
double lag_clock_thread_cpu_s(void);

#ifdef __cplusplus
}
#endif
#endif
