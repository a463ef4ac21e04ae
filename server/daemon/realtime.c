/*
 * lagsimd's real-time LCM server: one loop that waits on the LCM socket, a timerfd armed
 * at absolute CLOCK_MONOTONIC deadlines and a signalfd together (poll, never a busy
 * spin), and advances the simulation one control period at a time.
 *
 *   control period  P = ticks_per_period * dt = 1 / publish_hz of sim time
 *   realtime        period j ends at wall deadline base + j * P / rate; at that deadline
 *                   the sim advances [t_j-1, t_j] with the efforts held then, and the
 *                   state at t_j is published. A command that answers state t_j within
 *                   one period is therefore applied over [t_j, t_j+1], as in lockstep.
 *   fast            periods back to back, LCM served between every two.
 *   lockstep        publish t_j, wait for a command with sim_time == t_j (or for
 *                   lockstep_timeout wall seconds: event, and the step goes on under the
 *                   watchdog rule), advance one period.
 *
 * The stepping path (rt_period) allocates nothing: the server struct holds every buffer.
 */
#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"

#define RT_MAX_BURST 10           /* periods run back to back when catching up */
#define RT_MAX_LAG_PERIODS 100    /* behind by more than this: re-base the clock, event */
#define RT_MAX_LAG_NS 200000000   /* ... or by more than 0.2 s of wall time */
#define RT_DRAIN_MAX 256          /* LCM messages handled per loop iteration at most */
#define RT_REJ_EVENTS_PER_S 10    /* command_rejected events per second at most */
#define RT_LINE_NS 250000000      /* live status line refresh */

/* ---------------------------------------------------------------- small helpers */
static bool state_finite(const lag_sim *sim)
{
    for (int i = 0; i < sim->nq; i++)
        if (!isfinite(sim->q[i]) || !isfinite(sim->qd[i]) || !isfinite(sim->tau[i]))
            return false;
    return isfinite(lag_sim_time(sim));
}

static void eventf(rt_server *s, const char *kind, const char *joint, double value,
                   const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static void eventf(rt_server *s, const char *kind, const char *joint, double value,
                   const char *fmt, ...)
{
    char detail[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    rt_publish_event(s, kind, joint, value, detail);
}

/* Restart realtime deadlines from now (after start, resume, reset, or a lost race). */
static void rebase_clock(rt_server *s, int timer_fd)
{
    s->base_ns = rt_mono_ns();
    s->periods_done = 0;
    s->late_mark = 0;
    int64_t next = s->base_ns + (int64_t)s->period_ns;
    struct itimerspec its = {{0, 0}, {next / 1000000000, next % 1000000000}};
    timerfd_settime(timer_fd, TFD_TIMER_ABSTIME, &its, NULL);
}

/* Arms the timer for the end of the next period: base + (done + 1) * period. */
static void arm_next(rt_server *s, int timer_fd)
{
    int64_t next = s->base_ns + (int64_t)((double)(s->periods_done + 1) * s->period_ns);
    struct itimerspec its = {{0, 0}, {next / 1000000000, next % 1000000000}};
    timerfd_settime(timer_fd, TFD_TIMER_ABSTIME, &its, NULL);
}

/* Lockstep: a state was just published; wait for its answer from now on. */
static void begin_wait(rt_server *s)
{
    s->waiting = true;
    s->answered = false;
    s->waiting_time = lag_sim_time(&s->sim);
    s->wait_start_ns = rt_mono_ns();
}

static void publish_state(rt_server *s)
{
    rt_publish_state(s);
    if (s->sc->realtime.mode == LAG_RT_LOCKSTEP) begin_wait(s);
}

/* Numeric fault: pause in the fault state. The sim holds the last good tick (not a
 * period boundary); it is never published. Only reset leaves the fault state. */
static void enter_fault(rt_server *s, lag_result r)
{
    s->run = RT_FAULT;
    s->pending_steps = 0;
    s->waiting = false;
    s->numeric_faults++;
    eventf(s, "numeric_fault", "", lag_sim_time(&s->sim),
           "%s at sim time %.9g s (tick %lld): paused in fault state; send reset or reset_to",
           r == LAG_OK ? "non-finite state" : lag_result_string(r), lag_sim_time(&s->sim),
           (long long)s->sim.tick);
    rt_publish_status(s);
}

/* The effects' events of the last period (impact, limit, saturation, ...), with the sim
 * time the step located them at. */
static void publish_effect_events(rt_server *s)
{
    lag_event ev;
    while (lag_sim_poll_event(&s->sim, &ev)) {
        const char *joint = ev.joint >= 0 && ev.joint < s->nq ? s->info->joint_names[ev.joint] : "";
        char detail[96];
        snprintf(detail, sizeof detail, "%s at t = %.9g s", lag_event_kind_name(ev.kind), ev.t);
        rt_publish_event_at(s, ev.t, lag_event_kind_name(ev.kind), joint, ev.value, detail);
    }
    if (s->sim.events_dropped > s->effect_events_dropped) {
        eventf(s, "events_dropped", "", (double)(s->sim.events_dropped - s->effect_events_dropped),
               "%lld effect events dropped (more than the step records per period)",
               (long long)(s->sim.events_dropped - s->effect_events_dropped));
        s->effect_events_dropped = s->sim.events_dropped;
    }
}

/* ---------------------------------------------------------------- one control period */
/* Watchdog, held input, ticks_per_period ticks, checks, state publication.
 * Returns false on a numeric fault (state not published). No allocation. */
static bool rt_period(rt_server *s)
{
    const lag_scene *sc = s->sc;
    double dt = sc->sim.integrator.dt;

    /* watchdog: the last good command is older than command_timeout sim seconds */
    if (s->have_command && !s->watchdog_tripped &&
        (double)(s->sim.tick - s->command_tick) * dt > sc->realtime.command_timeout) {
        s->watchdog_tripped = true;
        s->watchdog_trips++;
        for (int i = 0; i < s->nq; i++) s->held[i] = 0.0;
        eventf(s, "watchdog_trip", "", (double)(s->sim.tick - s->command_tick) * dt,
               "no command for %.6g s of sim time (command_timeout %.6g s): efforts zeroed",
               (double)(s->sim.tick - s->command_tick) * dt, sc->realtime.command_timeout);
    }
    lag_sim_set_input(&s->sim, s->held);

    int64_t t0 = rt_mono_ns();
    lag_result r = lag_sim_advance(&s->sim, sc->ticks_per_period, false);
    double us = (double)(rt_mono_ns() - t0) * 1e-3;
    if (us > s->step_us_max) s->step_us_max = us;
    s->step_us_sum += us;
    s->step_us_n++;
    s->ticks_since_status += sc->ticks_per_period;

    publish_effect_events(s);
    if (r != LAG_OK || !state_finite(&s->sim)) {
        enter_fault(s, r);
        return false;
    }
    publish_state(s);
    if (s->stop_tick > 0 && s->sim.tick >= s->stop_tick) s->stop = true;
    return true;
}

/* ---------------------------------------------------------------- commands */
static void reject(rt_server *s, rt_reject why, const char *joint, double value,
                   const char *what)
{
    static const char *const why_name[RT_REJ_COUNT] = {
        "unknown joint", "unactuated joint", "non-finite effort", "bad length",
        "undecodable payload", "stale (lockstep: answers another state)"};
    s->rejected[why]++;
    /* events are rate limited: a flood is counted in status, not echoed one for one */
    int64_t now = rt_mono_ns();
    if (now - s->rej_window_ns > 1000000000) {
        s->rej_window_ns = now;
        s->rej_events_in_window = 0;
    }
    if (s->rej_events_in_window >= RT_REJ_EVENTS_PER_S) {
        s->rej_suppressed++;
        return;
    }
    s->rej_events_in_window++;
    eventf(s, "command_rejected", joint, value, "command rejected: %s%s%s%s (%lld similar events suppressed before)",
           why_name[why], what ? " (" : "", what ? what : "", what ? ")" : "",
           (long long)s->rej_suppressed);
    s->rej_suppressed = 0;
}

/* A command is applied whole or not at all: every name known, actuated, distinct; every
 * effort finite. */
void rt_handle_command(rt_server *s, const uint8_t *data, size_t len)
{
    lag_wire_joint_command c;
    int d = lag_wire_decode_joint_command(data, len, s->nq, &c);
    if (d == LAG_WIRE_ECOUNT) {
        reject(s, RT_REJ_BAD_LENGTH, "", c.num_joints, "num_joints in value");
        return;
    }
    if (d == LAG_WIRE_ETOOLONG) { /* a well-formed name longer than any joint's */
        reject(s, RT_REJ_UNKNOWN_JOINT, "", 0, "a name of 64 bytes or more");
        return;
    }
    if (d != LAG_WIRE_OK) {
        reject(s, RT_REJ_UNDECODABLE, "", (double)len, "payload bytes in value");
        return;
    }
    int idx[LAG_MAX_DOF];
    for (int i = 0; i < c.num_joints; i++) {
        idx[i] = -1;
        for (int j = 0; j < s->nq; j++)
            if (strcmp(c.name[i], s->info->joint_names[j]) == 0) idx[i] = j;
        if (idx[i] < 0) {
            reject(s, RT_REJ_UNKNOWN_JOINT, c.name[i], 0, NULL);
            return;
        }
        for (int k = 0; k < i; k++)
            if (idx[k] == idx[i]) {
                reject(s, RT_REJ_BAD_LENGTH, c.name[i], c.num_joints, "duplicate name");
                return;
            }
        if (!s->info->actuated[idx[i]]) {
            reject(s, RT_REJ_UNACTUATED, c.name[i], 0, NULL);
            return;
        }
        if (!isfinite(c.effort[i])) {
            reject(s, RT_REJ_NONFINITE, c.name[i], 0, NULL);
            return;
        }
    }
    if (s->sc->realtime.mode == LAG_RT_LOCKSTEP &&
        !(s->waiting && c.sim_time == s->waiting_time) &&
        !(s->run != RT_RUNNING && c.sim_time == lag_sim_time(&s->sim))) {
        reject(s, RT_REJ_STALE, "", c.sim_time, "its sim_time in value");
        return;
    }
    for (int i = 0; i < c.num_joints; i++) s->held[idx[i]] = c.effort[i];
    s->accepted++;
    s->have_command = true;
    s->command_tick = s->sim.tick;
    if (s->waiting && c.sim_time == s->waiting_time) s->answered = true;
    if (s->watchdog_tripped) {
        s->watchdog_tripped = false;
        eventf(s, "watchdog_clear", "", 0, "a good command arrived: efforts held again");
    }
}

/* ---------------------------------------------------------------- control requests */
static void do_reset(rt_server *s, const double *q, const double *qd, const char *what)
{
    lag_sim_reset(&s->sim, q, qd);
    s->effect_events_dropped = s->sim.events_dropped;
    for (int i = 0; i < s->nq; i++) s->held[i] = 0.0;
    s->have_command = false;
    s->watchdog_tripped = false;
    s->pending_steps = 0;
    if (s->run == RT_FAULT) s->run = RT_PAUSED;
    eventf(s, "reset", "", 0, "%s: sim time 0, efforts zero, %s", what,
           s->run == RT_PAUSED ? "paused (resume to run)" : "running");
    rt_publish_scene(s);
    publish_state(s);
    rt_publish_status(s);
}

static void control_rejected(rt_server *s, const char *why)
{
    s->controls_rejected++;
    rt_publish_event(s, "control_rejected", "", 0, why);
    rt_publish_status(s);
}

void rt_handle_control(rt_server *s, const uint8_t *data, size_t len)
{
    lag_wire_control c;
    int d = lag_wire_decode_control(data, len, LAG_MAX_DOF, &c);
    if (d != LAG_WIRE_OK) {
        control_rejected(s, d == LAG_WIRE_ECOUNT ? "control: num_joints out of range"
                                                 : "control: undecodable payload");
        return;
    }
    switch (c.request) {
    case LAGSIM_CONTROL_T_PAUSE:
        if (s->run == RT_FAULT) {
            control_rejected(s, "pause: in fault state (reset first)");
            return;
        }
        s->run = RT_PAUSED;
        s->pending_steps = 0;
        s->base_ns = 0; /* the loop re-arms the timer: the state is republished */
        rt_publish_event(s, "pause", "", 0, "paused");
        break;
    case LAGSIM_CONTROL_T_RESUME:
        if (s->run == RT_FAULT) {
            control_rejected(s, "resume: in fault state (reset first)");
            return;
        }
        s->run = RT_RUNNING;
        s->pending_steps = 0;
        s->base_ns = 0; /* the loop re-bases the clock */
        if (s->sc->realtime.mode == LAG_RT_LOCKSTEP && s->waiting) {
            /* wait afresh for the state already published */
            s->wait_start_ns = rt_mono_ns();
        } else if (s->sc->realtime.mode == LAG_RT_LOCKSTEP) {
            publish_state(s);
        }
        rt_publish_event(s, "resume", "", 0, "running");
        break;
    case LAGSIM_CONTROL_T_STEP:
        if (s->run != RT_PAUSED) {
            control_rejected(s, s->run == RT_FAULT ? "step: in fault state (reset first)"
                                                   : "step: only while paused");
            return;
        }
        if (c.count < 1) {
            control_rejected(s, "step: count must be >= 1");
            return;
        }
        s->pending_steps = c.count;
        eventf(s, "step", "", (double)c.count, "stepping %lld control periods",
               (long long)c.count);
        return; /* step_done (and its status) follow when the steps are done */
    case LAGSIM_CONTROL_T_RESET:
        do_reset(s, NULL, NULL, "reset to the scene's initial state");
        return;
    case LAGSIM_CONTROL_T_RESET_TO: {
        if (c.num_joints != s->nq) {
            control_rejected(s, "reset_to: num_joints must equal the model's joint count");
            return;
        }
        double lim = s->sc->sim.explode_limit;
        for (int i = 0; i < s->nq; i++)
            if (!isfinite(c.q[i]) || !isfinite(c.qd[i]) || fabs(c.q[i]) > lim ||
                fabs(c.qd[i]) > lim) {
                control_rejected(s, "reset_to: q and qd must be finite and within explode_limit");
                return;
            }
        double qdd[LAG_MAX_DOF];
        if (lag_model_forward(&s->sim.def.model, c.q, c.qd, NULL, qdd) != LAG_OK) {
            control_rejected(s, "reset_to: mass matrix not positive definite at q");
            return;
        }
        do_reset(s, c.q, c.qd, "reset to a given state");
        return;
    }
    case LAGSIM_CONTROL_T_STATUS:
        break; /* the status below is the answer */
    case LAGSIM_CONTROL_T_DESCRIBE:
        rt_publish_scene(s);
        return;
    default:
        control_rejected(s, "control: unknown request");
        return;
    }
    rt_publish_status(s);
}

/* ---------------------------------------------------------------- LCM glue */
static void on_command(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_handle_command(user, rb->data, rb->data_size);
}

static void on_control(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_handle_control(user, rb->data, rb->data_size);
}

/* The one-line live status on a terminal: sim time, RTF, overruns, energy. */
static void live_line(rt_server *s, bool final)
{
    fprintf(stderr, "\r%s  t=%10.3f s  RTF %6.3f  overruns %-6lld  E=%+.6e J  %-7s%s",
            s->sc->lcm.prefix, lag_sim_time(&s->sim), s->rtf, (long long)s->overruns,
            lag_sim_energy(&s->sim), rt_run_name(s->run), final ? "\n" : "");
    fflush(stderr);
}

/* ---------------------------------------------------------------- the server */
int lagsimd_realtime(const lag_scene *sc, const lagsimd_opts *o)
{
    static rt_server srv; /* large (encode buffer): static, one server per process */
    rt_server *s = &srv;
    memset(s, 0, sizeof *s);
    s->sc = sc;
    s->opts = o;
    s->info = lag_model_info_get(sc->sim.model.kind);

    /* everything that can fail on a bad scene fails before LCM is touched */
    char err[256];
    if (!s->info || lag_sim_init(&s->sim, &sc->sim, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: bad scene: %s\n", s->info ? err : "unknown model");
        return LAGSIMD_EXIT_USAGE;
    }
    if (sc->publish_hz <= 0 || sc->ticks_per_period < 1 || !(sc->realtime.rate > 0) ||
        !(sc->realtime.status_hz > 0) || strlen(sc->lcm.prefix) == 0 ||
        strlen(sc->lcm.prefix) + 9 > RT_CHANNEL_MAX) {
        fprintf(stderr, "lagsimd: bad scene: publish_hz, realtime.rate, realtime.status_hz "
                        "must be > 0 and lcm.prefix non-empty\n");
        return LAGSIMD_EXIT_USAGE;
    }
    s->nq = s->sim.nq;
    snprintf(s->ch_state, RT_CHANNEL_MAX, "%s_STATE", sc->lcm.prefix);
    snprintf(s->ch_command, RT_CHANNEL_MAX, "%s_COMMAND", sc->lcm.prefix);
    snprintf(s->ch_status, RT_CHANNEL_MAX, "%s_STATUS", sc->lcm.prefix);
    snprintf(s->ch_event, RT_CHANNEL_MAX, "%s_EVENT", sc->lcm.prefix);
    snprintf(s->ch_control, RT_CHANNEL_MAX, "%s_CONTROL", sc->lcm.prefix);
    snprintf(s->ch_scene, RT_CHANNEL_MAX, "%s_SCENE", sc->lcm.prefix);
    double dt = sc->sim.integrator.dt;
    double period_s = (double)sc->ticks_per_period * dt;
    s->period_ns = period_s / sc->realtime.rate * 1e9;
    if (o && o->duration > 0) {
        s->stop_tick = (int64_t)ceil(o->duration / dt - 1e-9);
        if (s->stop_tick < 1) s->stop_tick = 1;
    }
    s->live_line = isatty(STDERR_FILENO) && !(o && o->quiet);

    /* signals through a signalfd: blocked before LCM starts any thread */
    sigset_t sigs, old_mask;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    sigprocmask(SIG_BLOCK, &sigs, &old_mask);
    int sig_fd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    int timer_fd = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
    if (sig_fd < 0 || timer_fd < 0) {
        perror("lagsimd: signalfd/timerfd");
        sigprocmask(SIG_SETMASK, &old_mask, NULL);
        return LAGSIMD_EXIT_RUNTIME;
    }

    s->lcm = lcm_create(sc->lcm.url[0] ? sc->lcm.url : NULL);
    if (!s->lcm) {
        fprintf(stderr, "lagsimd: cannot create LCM (url '%s')\n",
                sc->lcm.url[0] ? sc->lcm.url : "default");
        close(sig_fd);
        close(timer_fd);
        sigprocmask(SIG_SETMASK, &old_mask, NULL);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lcm_subscription_t *sub_cmd = lcm_subscribe(s->lcm, s->ch_command, on_command, s);
    lcm_subscription_t *sub_ctl = lcm_subscribe(s->lcm, s->ch_control, on_control, s);
    /* a flood must not queue up without bound: LCM drops beyond this */
    lcm_subscription_set_queue_capacity(sub_cmd, 1000);
    int lcm_fd = lcm_get_fileno(s->lcm);

    s->start_ns = rt_mono_ns();
    s->last_status_ns = s->start_ns;
    int64_t status_ns = (int64_t)(1e9 / sc->realtime.status_hz);
    s->next_status_ns = s->start_ns + status_ns;
    s->next_line_ns = s->start_ns;
    s->run = RT_RUNNING;
    lag_rt_mode mode = sc->realtime.mode;

    rt_publish_scene(s);
    eventf(s, "start", "", 0, "%s, %s, dt %.6g s, control period %.6g s, mode %s, rate %.6g",
           s->info->name, lag_method_name(sc->sim.integrator.method), dt, period_s,
           lag_rt_mode_name(mode), sc->realtime.rate);
    publish_state(s); /* the initial state, t = 0 */
    rt_publish_status(s);
    rebase_clock(s, timer_fd);

    while (!s->stop) {
        int64_t now = rt_mono_ns();
        /* how long poll may sleep: until the next status, live line, lockstep timeout;
         * zero when there is work to do now (fast mode, STEP N) */
        int64_t wake = s->next_status_ns;
        if (s->live_line && s->next_line_ns < wake) wake = s->next_line_ns;
        bool busy = s->pending_steps > 0 || (s->run == RT_RUNNING && mode == LAG_RT_FAST);
        if (mode == LAG_RT_LOCKSTEP && s->run == RT_RUNNING && s->waiting) {
            if (s->answered) busy = true;
            int64_t lw = s->wait_start_ns + (int64_t)(sc->realtime.lockstep_timeout * 1e9);
            if (lw < wake) wake = lw;
        }
        int64_t wait_ns = busy ? 0 : (wake > now ? wake - now : 0);
        struct timespec ts = {wait_ns / 1000000000, wait_ns % 1000000000};
        struct pollfd pf[3] = {{lcm_fd, POLLIN, 0}, {timer_fd, POLLIN, 0}, {sig_fd, POLLIN, 0}};
        int np = ppoll(pf, 3, &ts, NULL);
        if (np < 0 && errno != EINTR) {
            perror("lagsimd: poll");
            break;
        }
        if (np > 0 && (pf[2].revents & POLLIN)) {
            struct signalfd_siginfo si;
            if (read(sig_fd, &si, sizeof si) > 0) {
                eventf(s, "stop", "", (double)si.ssi_signo, "signal %u: stopping",
                       si.ssi_signo);
                s->stop = true;
                break;
            }
        }
        if (np > 0 && (pf[0].revents & POLLIN)) {
            for (int k = 0; k < RT_DRAIN_MAX; k++)
                if (lcm_handle_timeout(s->lcm, 0) <= 0) break;
        }
        uint64_t expirations = 0;
        if (np > 0 && (pf[1].revents & POLLIN)) {
            if (read(timer_fd, &expirations, sizeof expirations) < 0) expirations = 0;
        }
        if (s->stop) break;
        if (s->base_ns == 0) rebase_clock(s, timer_fd); /* after resume */
        now = rt_mono_ns();

        if (s->pending_steps > 0) {
            /* STEP N while paused: one period per iteration, LCM served between */
            if (rt_period(s) && --s->pending_steps == 0) {
                rt_publish_event(s, "step_done", "", 0, "step done: paused");
                rt_publish_status(s);
            }
        } else if (s->run == RT_RUNNING) {
            switch (mode) {
            case LAG_RT_FAST:
                rt_period(s);
                break;
            case LAG_RT_LOCKSTEP:
                if (s->waiting && !s->answered &&
                    now - s->wait_start_ns >= (int64_t)(sc->realtime.lockstep_timeout * 1e9)) {
                    s->lockstep_timeouts++;
                    eventf(s, "lockstep_timeout", "", s->waiting_time,
                           "no command answered sim time %.9g s within %.6g s: stepping "
                           "on under the watchdog rule", s->waiting_time,
                           sc->realtime.lockstep_timeout);
                    s->answered = true;
                }
                if (s->waiting && s->answered) {
                    s->waiting = false;
                    rt_period(s);
                }
                break;
            case LAG_RT_REALTIME:
                if (expirations > 0) {
                    /* periods whose deadline has passed */
                    int64_t due = (int64_t)((double)(now - s->base_ns) / s->period_ns) -
                                  s->periods_done;
                    /* every due period but the last started late; count each once
                     * (a burst may leave some for the next iteration) */
                    int64_t last_late = s->periods_done + due - 1;
                    if (last_late > s->late_mark) {
                        s->overruns += last_late - (s->late_mark > s->periods_done
                                                        ? s->late_mark : s->periods_done);
                        s->late_mark = last_late;
                    }
                    if (due > RT_MAX_LAG_PERIODS ||
                        (due > 1 && (double)due * s->period_ns > RT_MAX_LAG_NS)) {
                        s->overrun_bursts++;
                        eventf(s, "overrun_burst", "", (double)due,
                               "%lld periods behind wall clock: cannot catch up, "
                               "re-basing the clock (sim time lags wall time by %.3g s more)",
                               (long long)due, (double)due * s->period_ns * 1e-9);
                        due = 1;
                        s->base_ns = now - (int64_t)s->period_ns;
                        s->periods_done = 0;
                        s->late_mark = 0;
                    }
                    int64_t burst = due < RT_MAX_BURST ? due : RT_MAX_BURST;
                    for (int64_t k = 0; k < burst && s->run == RT_RUNNING && !s->stop; k++) {
                        s->periods_done++;
                        if (!rt_period(s)) break;
                    }
                    arm_next(s, timer_fd); /* if already past, fires at once: next burst */
                }
                break;
            }
        } else if (s->run == RT_PAUSED && mode != LAG_RT_LOCKSTEP && expirations > 0) {
            /* paused: the current state keeps being published at publish_hz */
            s->periods_done = (int64_t)((double)(now - s->base_ns) / s->period_ns);
            rt_publish_state(s);
            arm_next(s, timer_fd);
        }

        now = rt_mono_ns();
        if (now >= s->next_status_ns) {
            rt_publish_status(s);
            s->next_status_ns += status_ns;
            if (s->next_status_ns < now) s->next_status_ns = now + status_ns;
        }
        if (s->live_line && now >= s->next_line_ns) {
            live_line(s, false);
            s->next_line_ns = now + RT_LINE_NS;
        }
    }

    if (!s->stop) eventf(s, "stop", "", 0, "stopping");
    else if (s->stop_tick > 0 && s->sim.tick >= s->stop_tick)
        eventf(s, "stop", "", lag_sim_time(&s->sim), "duration reached");
    rt_publish_status(s);
    if (s->live_line) live_line(s, true);
    lcm_unsubscribe(s->lcm, sub_cmd);
    lcm_unsubscribe(s->lcm, sub_ctl);
    lcm_destroy(s->lcm);
    close(timer_fd);
    close(sig_fd);
    sigprocmask(SIG_SETMASK, &old_mask, NULL);
    return LAGSIMD_EXIT_OK;
}
