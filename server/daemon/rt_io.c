/*
 * The loop's wait (rt_io.h).
 */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include "lagsim_clock.h"
#include "rt_io.h"
#include "rt_pace.h"

#define RT_SIGNALS_PER_WAKE 16    /* signals read per wake-up at most */
#define RT_EVENTS_PER_WAKE 256    /* ready sources looked at per wake-up at most (the rest
                                   * are reported again at the next) */

/* The timer's and the signals' places in epoll's data (a source's is its rt_io_src). */
static char k_timer, k_signals;

/* Signals the daemon handles: these stop it cleanly (a stop event and a final status);
 * SIGUSR1/SIGUSR2 ask for a status and a line on stderr; a host reads its directory again
 * on SIGHUP. SIGPIPE is ignored. */
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

static int add_fd(int ep, int fd, void *ptr)
{
    struct epoll_event ev = {.events = EPOLLIN, .data.ptr = ptr};
    return epoll_ctl(ep, EPOLL_CTL_ADD, fd, &ev);
}

int rt_io_open(rt_io *io, int64_t *now, void (*on_signal)(void *, int), void *ctx)
{
    *io = (rt_io){-1, -1, -1, INT64_MAX, now, on_signal, ctx};
    /* signals through a signalfd: blocked before LCM starts any thread */
    sigset_t sigs;
    handled_signals(&sigs);
    sigprocmask(SIG_BLOCK, &sigs, &io->old_mask);
    struct sigaction ign = {.sa_handler = SIG_IGN};
    sigemptyset(&ign.sa_mask);
    sigaction(SIGPIPE, &ign, &io->old_pipe);
    io->sig_fd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    io->timer_fd = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
    io->ep = epoll_create1(EPOLL_CLOEXEC);
    if (io->sig_fd < 0 || io->timer_fd < 0 || io->ep < 0 ||
        add_fd(io->ep, io->timer_fd, &k_timer) != 0 || add_fd(io->ep, io->sig_fd, &k_signals) != 0) {
        perror("lagsimd: signalfd/timerfd/epoll");
        return -1;
    }
    return 0;
}

int rt_io_add(rt_io *io, rt_io_src *src)
{
    src->parked = false;
    if (add_fd(io->ep, src->fd, src) != 0) {
        perror("lagsimd: epoll_ctl");
        return -1;
    }
    src->added = true;
    return 0;
}

void rt_io_remove(rt_io *io, rt_io_src *src)
{
    if (!src->added) return;
    epoll_ctl(io->ep, EPOLL_CTL_DEL, src->fd, NULL);
    src->added = false;
}

void rt_io_park(rt_io *io, rt_io_src *src, bool parked)
{
    if (!src->added || src->parked == parked) return;
    struct epoll_event ev = {.events = parked ? 0 : EPOLLIN, .data.ptr = src};
    if (epoll_ctl(io->ep, EPOLL_CTL_MOD, src->fd, &ev) == 0) src->parked = parked;
}

/* Arms the timer at `wake`. Returns the wait's timeout in ms: -1 (the timer wakes the
 * wait), or 0 (due, or the timer could not be armed: do not sleep past the deadline). */
static int arm(rt_io *io, int64_t wake)
{
    if (wake <= lag_clock_mono_ns()) return 0;
    if (wake == io->armed_ns) return -1;
    struct itimerspec its = {{0, 0}, {0, 0}};
    if (wake != INT64_MAX) {
        its.it_value.tv_sec = (time_t)(wake / RT_NS_PER_S);
        its.it_value.tv_nsec = (long)(wake % RT_NS_PER_S);
    }
    if (timerfd_settime(io->timer_fd, TFD_TIMER_ABSTIME, &its, NULL) != 0) return 0;
    io->armed_ns = wake;
    return -1;
}

static void read_signals(rt_io *io)
{
    struct signalfd_siginfo si;
    for (int k = 0; k < RT_SIGNALS_PER_WAKE; k++) {
        if (read(io->sig_fd, &si, sizeof si) != (ssize_t)sizeof si) break;
        io->signal(io->ctx, (int)si.ssi_signo);
    }
}

int rt_io_wait(rt_io *io, int64_t wake)
{
    static struct epoll_event ev[RT_EVENTS_PER_WAKE];
    int n = epoll_wait(io->ep, ev, RT_EVENTS_PER_WAKE, arm(io, wake));
    *io->now = lag_clock_mono_ns();
    if (n < 0) {
        if (errno == EINTR) return 0;
        perror("lagsimd: epoll_wait");
        return -1;
    }
    /* signals first: a stop is known before any message is handled */
    for (int k = 0; k < n; k++)
        if (ev[k].data.ptr == &k_signals) read_signals(io);
    for (int k = 0; k < n; k++) {
        if (ev[k].data.ptr == &k_timer) {
            uint64_t expirations;
            if (read(io->timer_fd, &expirations, sizeof expirations) < 0) expirations = 0;
            io->armed_ns = INT64_MAX;
        } else if (ev[k].data.ptr != &k_signals) {
            rt_io_src *src = ev[k].data.ptr;
            src->ready(src->ctx);
        }
    }
    *io->now = lag_clock_mono_ns();
    return 0;
}

void rt_io_close(rt_io *io)
{
    if (io->ep >= 0) close(io->ep);
    if (io->timer_fd >= 0) close(io->timer_fd);
    if (io->sig_fd >= 0) close(io->sig_fd);
    io->ep = io->timer_fd = io->sig_fd = -1;
    sigaction(SIGPIPE, &io->old_pipe, NULL);
    sigprocmask(SIG_SETMASK, &io->old_mask, NULL);
}
