/*
 * The loop's wait (rt_io.c): one epoll_wait on the sources the loop registered (the LCM
 * instances of every plant, an inotify descriptor), a timerfd armed at the next thing due
 * and a signalfd (never a busy spin); then the signals and the sources that are ready.
 *
 * A part of the loop's (host.c holds one for all its plants): it owns the descriptors and
 * the signal mask, and tells the loop through what the loop gave it: its clock (set when
 * the wait ends, before anything is handled), a callback for each signal, and for each
 * source a callback called when the source has something to read (the callback reads a
 * bounded amount: a source still readable is reported again at the next wait). A source
 * can be parked (not waited on, its data left where it is) and resumed.
 *
 * The cost of a wait does not grow with the number of sources (epoll): a host of 200
 * plants registers 400 LCM instances, and a wake-up for one command looks at one.
 */
#ifndef LAGSIMD_RT_IO_H
#define LAGSIMD_RT_IO_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

/* A source: a descriptor and what to do when it is readable. The caller owns it (it must
 * stay where it is while registered). */
typedef struct rt_io_src {
    int fd;
    void (*ready)(void *ctx);
    void *ctx;
    bool parked;               /* not waited on (rt_io_park) */
    bool added;                /* registered */
} rt_io_src;

typedef struct rt_io {
    int ep, timer_fd, sig_fd;
    int64_t armed_ns;          /* what the timer is armed at (INT64_MAX: disarmed) */
    int64_t *now;              /* the loop's clock */
    void (*signal)(void *ctx, int signo);
    void *ctx;
    sigset_t old_mask;
    struct sigaction old_pipe;
} rt_io;

/* Blocks the signals the daemon handles (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1,
 * SIGUSR2: before LCM starts any thread), ignores SIGPIPE, makes the epoll descriptor,
 * the signalfd and the timerfd. Returns 0, or -1 (said on stderr); rt_io_close undoes it
 * either way. */
int rt_io_open(rt_io *io, int64_t *now, void (*on_signal)(void *, int), void *ctx);
/* Registers src (its fd, ready and ctx set). Returns 0, or -1 (said on stderr). */
int rt_io_add(rt_io *io, rt_io_src *src);
/* Unregisters src (before its descriptor is closed); a source not added is left alone. */
void rt_io_remove(rt_io *io, rt_io_src *src);
/* Stops waiting on src (its data stays unread), or waits on it again. */
void rt_io_park(rt_io *io, rt_io_src *src, bool parked);
/* Waits until `wake` (absolute CLOCK_MONOTONIC ns), a signal or a ready source, then
 * handles the signals and calls each ready source's callback. Returns 0, or -1 when the
 * wait failed (said on stderr). */
int rt_io_wait(rt_io *io, int64_t wake);
void rt_io_close(rt_io *io);

#endif
