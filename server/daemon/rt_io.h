/*
 * The loop's wait (rt_io.c): one ppoll on the LCM sockets, a timerfd armed at the next
 * thing due and a signalfd (never a busy spin), then the signals and the LCM messages
 * that arrived, a bounded number of each.
 *
 * A part of the loop's (lagsimd_realtime holds one): it owns the descriptors and the
 * signal mask, and tells the loop through what the loop gave it at open: its clock (set
 * when the wait ends, before anything is handled), its stop flag (no more messages once
 * set) and a callback for each signal.
 */
#ifndef LAGSIMD_RT_IO_H
#define LAGSIMD_RT_IO_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <lcm/lcm.h>

typedef struct rt_io {
    int in_fd, timer_fd, sig_fd;
    int watch_fd;              /* the state URL's receive socket (the plant watch); -1: none */
    int64_t armed_ns;          /* what the timer is armed at (INT64_MAX: disarmed) */
    lcm_t *in, *watch;         /* the command URL's lcm_t; the state URL's, or NULL */
    int64_t *now;              /* the loop's clock */
    const bool *stop;          /* the loop's stop flag */
    void (*signal)(void *ctx, int signo);
    void *ctx;
    sigset_t old_mask;
    struct sigaction old_pipe;
} rt_io;

/* Blocks the signals the daemon handles (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1,
 * SIGUSR2: before LCM starts any thread), ignores SIGPIPE, makes the signalfd and the
 * timerfd. Returns 0, or -1 (said on stderr); rt_io_close undoes it either way. */
int rt_io_open(rt_io *io, int64_t *now, const bool *stop, void (*on_signal)(void *, int),
               void *ctx);
/* The LCM instances to wait on: `in` (commands, control), `watch` (the plant watch; NULL
 * when it is `in`, as for memq://). */
void rt_io_watch(rt_io *io, lcm_t *in, lcm_t *watch);
/* Waits until `wake` (absolute CLOCK_MONOTONIC ns), a signal or an LCM message, then
 * handles the signals and the messages that arrived. Returns 0, or -1 when the wait
 * failed (said on stderr). */
int rt_io_wait(rt_io *io, int64_t wake);
void rt_io_close(rt_io *io);

#endif
