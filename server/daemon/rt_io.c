/*
 * The loop's wait (rt_io.h).
 */
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include "lagsim_clock.h"
#include "rt_io.h"
#include "rt_pace.h"

#define RT_DRAIN_MAX 256          /* LCM messages handled per wake-up at most */
#define RT_SIGNALS_PER_WAKE 16    /* signals read per wake-up at most */

/* Signals the daemon handles: these stop it cleanly (a stop event and a final status);
 * SIGUSR1/SIGUSR2 ask for a status and a line on stderr. SIGPIPE is ignored. */
static void handled_signals(sigset_t *set)
{
    sigemptyset(set);
    sigaddset(set, SIGINT);
    sigaddset(set, SIGTERM);
    sigaddset(set, SIGHUP);
    sigaddset(set, SIGQUIT);
    sigaddset(set, SIGUSR1);
    sigaddset(set, SIGUSR2);
}

int rt_io_open(rt_io *io, int64_t *now, const bool *stop, void (*on_signal)(void *, int),
               void *ctx)
{
    *io = (rt_io){-1, -1, -1, -1, INT64_MAX, NULL, NULL, now, stop, on_signal, ctx};
    /* signals through a signalfd: blocked before LCM starts any thread */
    sigset_t sigs;
    handled_signals(&sigs);
    sigprocmask(SIG_BLOCK, &sigs, &io->old_mask);
    struct sigaction ign = {.sa_handler = SIG_IGN};
    sigemptyset(&ign.sa_mask);
    sigaction(SIGPIPE, &ign, &io->old_pipe);
    io->sig_fd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    io->timer_fd = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
    if (io->sig_fd < 0 || io->timer_fd < 0) {
        perror("lagsimd: signalfd/timerfd");
        return -1;
    }
    return 0;
}

void rt_io_watch(rt_io *io, lcm_t *in, lcm_t *watch)
{
    io->in = in;
    io->in_fd = lcm_get_fileno(in);
    io->watch = watch;
    if (watch) io->watch_fd = lcm_get_fileno(watch);
}

/* The timeout of the wait for `wake`: none (the timerfd is armed at it), or zero (due,
 * or the timer could not be armed: do not sleep past the deadline). */
static struct timespec *arm(rt_io *io, int64_t wake)
{
    static struct timespec zero = {0, 0};
    if (wake <= lag_clock_mono_ns()) return &zero;
    if (wake == io->armed_ns) return NULL;
    struct itimerspec its = {{0, 0}, {0, 0}};
    if (wake != INT64_MAX) {
        its.it_value.tv_sec = (time_t)(wake / RT_NS_PER_S);
        its.it_value.tv_nsec = (long)(wake % RT_NS_PER_S);
    }
    if (timerfd_settime(io->timer_fd, TFD_TIMER_ABSTIME, &its, NULL) != 0) return &zero;
    io->armed_ns = wake;
    return NULL;
}

int rt_io_wait(rt_io *io, int64_t wake)
{
    struct timespec *tmo = arm(io, wake);
    struct pollfd pf[4] = {{io->in_fd, POLLIN, 0}, {io->timer_fd, POLLIN, 0},
                           {io->sig_fd, POLLIN, 0}, {io->watch_fd, POLLIN, 0}};
    int np = ppoll(pf, io->watch_fd >= 0 ? 4 : 3, tmo, NULL);
    *io->now = lag_clock_mono_ns();
    if (np < 0) {
        if (errno == EINTR) return 0;
        perror("lagsimd: poll");
        return -1;
    }
    if (pf[2].revents & POLLIN) {
        struct signalfd_siginfo si;
        for (int k = 0; k < RT_SIGNALS_PER_WAKE; k++) {
            if (read(io->sig_fd, &si, sizeof si) != (ssize_t)sizeof si) break;
            io->signal(io->ctx, (int)si.ssi_signo);
        }
    }
    if (pf[1].revents & POLLIN) {
        uint64_t expirations;
        if (read(io->timer_fd, &expirations, sizeof expirations) < 0) expirations = 0;
        io->armed_ns = INT64_MAX;
    }
    if (pf[0].revents & POLLIN) {
        for (int k = 0; k < RT_DRAIN_MAX && !*io->stop; k++)
            if (lcm_handle_timeout(io->in, 0) <= 0) break;
    }
    if (io->watch_fd >= 0 && (pf[3].revents & POLLIN)) {
        for (int k = 0; k < 16 && !*io->stop; k++)
            if (lcm_handle_timeout(io->watch, 0) <= 0) break;
    }
    *io->now = lag_clock_mono_ns();
    return 0;
}

void rt_io_close(rt_io *io)
{
    if (io->timer_fd >= 0) close(io->timer_fd);
    if (io->sig_fd >= 0) close(io->sig_fd);
    io->timer_fd = io->sig_fd = -1;
    sigaction(SIGPIPE, &io->old_pipe, NULL);
    sigprocmask(SIG_SETMASK, &io->old_mask, NULL);
}
