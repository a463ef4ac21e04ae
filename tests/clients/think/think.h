/*
 * A slow control law for a C controller built as written: cc -include think.h ...
 * Every lag_client_send_command the program calls takes LAGSIM_THINK_S wall seconds
 * first (the program's law runs before each call; think.py says why) and appends a line
 * to the file LAGSIM_THINK_LOG (if set). The client's own
 * re-sends of an answer (lagsim_client.c) do not go through this macro.
 */
#ifndef LAGSIM_TEST_THINK_H
#define LAGSIM_TEST_THINK_H
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "lagsim_client.h"

static inline lag_result lag_test_think_send(lag_client *c, double sim_time, int n,
                                      const char *const *names, const double *effort)
{
    const char *log = getenv("LAGSIM_THINK_LOG");
    FILE *f = log ? fopen(log, "a") : NULL;
    if (f) {
        fputs("law\n", f);
        fclose(f);
    }
    const char *s = getenv("LAGSIM_THINK_S");
    double think = s ? atof(s) : 0.0;
    if (think > 0) {
        struct timespec ts = {(time_t)think, (long)((think - (double)(time_t)think) * 1e9)};
        while (nanosleep(&ts, &ts) != 0) {
        }
    }
    return lag_client_send_command(c, sim_time, n, names, effort);
}
#define lag_client_send_command(c, t, n, names, effort) \
    lag_test_think_send((c), (t), (n), (names), (effort))
#endif
