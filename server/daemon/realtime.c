/*
 * lagsimd's real-time LCM server. The loop is a few lines over three functions, as in
 * redis's ae.c:
 *
 *     while not stopped:
 *         wake = rt_next_wake(s)    the earliest thing due (a deadline, a status, an
 *                                   answer the rate limit holds back); now if busy
 *         wait(s, io, wake)         ppoll on the LCM socket, a signalfd and a timerfd
 *                                   armed at `wake` (never a busy spin); then the
 *                                   signals and LCM messages that arrived (bounded)
 *         rt_process(s)             what is due at s->now: the mode's periods, answers,
 *                                   the periodic status
 *
 *   control period  P = ticks_per_period * dt = 1 / publish_hz of sim time
 *   realtime        period j ends at wall deadline base + j * P / rate; at that deadline
 *                   the sim advances [t_j-1, t_j] with the efforts held then, and the
 *                   state at t_j is published. A command that answers state t_j within
 *                   one period is therefore applied over [t_j, t_j+1], as in lockstep.
 *                   Which periods are due (deadlines, overruns, bursts, re-basing) is the
 *                   pure arithmetic of rt_pace.c.
 *   fast            periods back to back, LCM served between every two.
 *   lockstep        publish t_j, wait for a command with sim_time == t_j (or for
 *                   lockstep_timeout wall seconds: event, and the step goes on under the
 *                   watchdog rule), advance one period.
 *
 * STEP N while paused runs N periods at the mode's pace (realtime: at its deadlines;
 * fast: back to back; lockstep: each waits for its answer). A period of many ticks runs
 * in chunks of at most tick_budget ticks per wake-up, so signals and LCM are served in
 * between however long a period is.
 *
 * Everything published in answer to what arrives is limited (rt_pace.h, rt_limit): each
 * event kind has a token bucket, and statuses, scene descriptions and states asked for by
 * control requests are coalesced (one answer for many requests) and limited too.
 *
 * The stepping path allocates nothing: the server struct holds every buffer.
 */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include "live_set.h"
#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"

#define RT_DRAIN_MAX 256          /* LCM messages handled per wake-up at most */
#define RT_TICK_BUDGET 4096       /* ticks advanced per wake-up at most */
#define RT_LINE_NS 250000000LL    /* live status line refresh */
#define RT_STATUS_NS_MIN 10000000LL /* periodic status at most every 10 ms (100 Hz) */
#define RT_SIGNALS_PER_WAKE 16    /* signals read per wake-up at most */
#define RT_RETRY_NS_MIN 1000000LL /* lockstep retries at most every millisecond */
#define RT_CONFLICT_EVERY_S 5     /* another plant's scenes: said at most once in 5 s */

/* The buckets of the limited events (rt_ev): name, answers per second, burst. */
static const struct {
    const char *kind;
    double per_s;
    int burst;
} ev_limits[RT_EV_COUNT] = {
    [RT_EV_COMMAND_REJECTED] = {"command_rejected", 10, 10},
    [RT_EV_CONTROL_REJECTED] = {"control_rejected", 10, 10},
    [RT_EV_PAUSE] = {"pause", 10, 10},
    [RT_EV_RESUME] = {"resume", 10, 10},
    [RT_EV_STEP] = {"step", 10, 10},
    [RT_EV_STEP_DONE] = {"step_done", 10, 10},
    [RT_EV_RESET] = {"reset", 10, 10},
    [RT_EV_WATCHDOG_TRIP] = {"watchdog_trip", 10, 10},
    [RT_EV_WATCHDOG_CLEAR] = {"watchdog_clear", 10, 10},
    [RT_EV_LOCKSTEP_TIMEOUT] = {"lockstep_timeout", 10, 10},
    [RT_EV_OVERRUN_BURST] = {"overrun_burst", 1, 3},
    [RT_EV_NUMERIC_FAULT] = {"numeric_fault", 10, 10},
    [RT_EV_EVENTS_DROPPED] = {"events_dropped", 1, 3},
    /* one in RT_CONFLICT_EVERY_S however many scenes a forger or a log player sends */
    [RT_EV_PLANT_CONFLICT] = {"plant_conflict", 1.0 / RT_CONFLICT_EVERY_S, 1},
    [RT_EV_ERROR_ESTIMATE] = {"error_estimate", 1, 3},
};
_Static_assert(sizeof ev_limits / sizeof ev_limits[0] == RT_EV_COUNT, "one bucket per rt_ev");

/* Answers to control requests beyond events: per second and burst. */
#define RT_STATUS_PER_S 20
#define RT_STATUS_BURST 5
#define RT_SCENE_PER_S 5
#define RT_SCENE_BURST 2
#define RT_STATE_PER_S 20  /* states published because of a reset (not the periods' own) */
#define RT_STATE_BURST 5

/* ---------------------------------------------------------------- small helpers */
static bool state_finite(const lag_sim *sim)
{
    for (int i = 0; i < sim->nq; i++)
        if (!isfinite(sim->q[i]) || !isfinite(sim->qd[i]) || !isfinite(sim->tau[i]))
            return false;
    return isfinite(lag_sim_time(sim));
}

static bool active(const rt_server *s)
{
    return s->run == RT_RUNNING || s->pending_steps > 0;
}

static int64_t min64(int64_t a, int64_t b) { return a < b ? a : b; }

/* A state asked for (by a reset, or a lockstep resume) can go out: not in the fault
 * state, and not in the middle of a period (whose end publishes one anyway). */
static bool state_wanted(const rt_server *s)
{
    return s->want_state && s->run != RT_FAULT && s->period_left == 0;
}

/* An unlimited event (start, stop). */
static void eventf(rt_server *s, const char *kind, double value, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void eventf(rt_server *s, const char *kind, double value, const char *fmt, ...)
{
    char detail[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    rt_publish_event(s, kind, "", value, detail);
}

/* A limited event: published if its kind's bucket has a token, else counted as
 * suppressed; the next one that gets through says how many were suppressed before it. */
static void limited_event(rt_server *s, rt_ev ev, const char *joint, double value,
                          const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static void limited_event(rt_server *s, rt_ev ev, const char *joint, double value,
                          const char *fmt, ...)
{
    rt_limit *l = &s->lim_event[ev];
    int64_t suppressed = l->suppressed;
    if (!rt_limit_take(l, s->now)) return;
    l->suppressed = 0;
    /* the note on what was suppressed always fits: the sentence is cut first */
    char note[96] = "", detail[LAG_WIRE_TEXT_LEN];
    if (suppressed > 0)
        snprintf(note, sizeof note, " (%lld more %s events suppressed before this one)",
                 (long long)suppressed, ev_limits[ev].kind);
    size_t room = sizeof detail - strlen(note);
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(detail, room, fmt, ap);
    va_end(ap);
    if (n < 0) detail[0] = '\0';
    strcat(detail, note);
    rt_publish_event(s, ev_limits[ev].kind, joint, value, detail);
}

/* Every state goes out through here: in lockstep a published state is waited on. */
static void publish_state(rt_server *s)
{
    rt_publish_state(s);
    s->want_state = false;
    if (s->sc->realtime.mode == LAG_RT_LOCKSTEP) {
        s->waiting = true;
        s->answered = false;
        s->waiting_time = lag_sim_time(&s->sim);
        s->wait_start_ns = s->now;
        s->answer_heard = false;
        s->retry_gap_ns = s->lockstep_retry_ns;
        s->next_retry_ns = rt_sat_add(s->now, s->retry_gap_ns);
    }
}

/* Lockstep, while a state is waited on and no answer to it has come: the same state goes
 * out again, byte for byte (utime included), lockstep_retry after it was published, then
 * at gaps that double up to retry_cap_ns (a sixteenth of lockstep_timeout: as many more
 * chances before it), so that a state or a command lost on the way costs a retry instead
 * of a timeout, and a controller that thinks long per state gets a copy every 62.5 ms at
 * most (default scene), not one per lockstep_retry. Once any command for that sim_time
 * arrived (applied or rejected) the controller has the state: no more copies. A
 * controller answers each state once and a copy of it with the same answer; a second
 * answer to a state already answered is ignored (commands_ignored), so the run does not
 * depend on how many copies arrived. */
static void lockstep_retry(rt_server *s)
{
    if (s->now < s->next_retry_ns || s->state_len == 0 || s->answer_heard) return;
    /* straight to LCM, not through rt_wire's publish: a copy for the network, which --log
     * (the run's record, one state per period) does not keep */
    lcm_publish(s->lcm, s->ch_state, s->state_buf, s->state_len);
    s->lockstep_retries++;
    int64_t cap = s->retry_cap_ns;
    s->retry_gap_ns = s->retry_gap_ns > cap / 2 ? cap : 2 * s->retry_gap_ns;
    s->next_retry_ns = rt_sat_add(s->now, s->retry_gap_ns);
}

static void publish_status(rt_server *s)
{
    rt_publish_status(s);
    s->want_status = false;
}

/* Numeric fault: pause in the fault state. The sim holds the last good tick (not a
 * period boundary); it is never published. Only reset leaves the fault state. The event
 * says what the core ran into (for a force too large, which joint and how large) and the
 * efforts that were held. */
static void enter_fault(rt_server *s, lag_result r)
{
    s->run = RT_FAULT;
    s->pending_steps = 0;
    s->period_left = 0;
    s->waiting = false;
    s->want_state = false;
    s->numeric_faults++;
    char why[LAG_WIRE_TEXT_LEN] = "";
    if (r != LAG_OK) lag_sim_fault_describe(&s->sim, why, sizeof why);
    if (!why[0])
        snprintf(why, sizeof why, "%s at t = %.9g s",
                 r == LAG_OK ? "non-finite state" : lag_result_string(r), lag_sim_time(&s->sim));
    char eff[128] = "";
    size_t n = 0;
    for (int i = 0; i < s->nq && n < sizeof eff; i++) {
        if (!s->info->actuated[i]) continue;
        int k = snprintf(eff + n, sizeof eff - n, "%s%s = %.6g", n ? ", " : "",
                         s->info->joint_names[i], s->held[i]);
        if (k < 0) break;
        n += (size_t)k;
    }
    limited_event(s, RT_EV_NUMERIC_FAULT, "", lag_sim_time(&s->sim),
                  "fault (efforts held: %s): %s; paused until reset or reset_to",
                  n ? eff : "none", why);
    s->want_status = true;
}

/* The effects' events of the last chunk (impact, limit, saturation, ...), with the sim
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
        int64_t lost = s->sim.events_dropped - s->effect_events_dropped;
        limited_event(s, RT_EV_EVENTS_DROPPED, "", (double)lost,
                      "%lld effect events dropped (more than the step records per period)",
                      (long long)lost);
        s->effect_events_dropped = s->sim.events_dropped;
    }
}

/* ---------------------------------------------------------------- one control period */
typedef enum rt_progress { RT_P_DONE, RT_P_MORE, RT_P_FAULT } rt_progress;

/* Starts a control period: watchdog, then the held efforts become the sim's input for
 * the whole period (zero-order hold). */
static void period_begin(rt_server *s, int64_t budget)
{
    const lag_scene *sc = s->sc;
    double dt = sc->sim.integrator.dt;
    /* watchdog: the last good command is older than command_timeout sim seconds */
    double age = (double)(s->sim.tick - s->command_tick) * dt;
    if (s->have_command && !s->watchdog_tripped && age > sc->realtime.command_timeout) {
        s->watchdog_tripped = true;
        s->watchdog_trips++;
        for (int i = 0; i < s->nq; i++) s->held[i] = 0.0;
        limited_event(s, RT_EV_WATCHDOG_TRIP, "", age,
                      "no command for %.6g s of sim time (command_timeout %.6g s): efforts zeroed",
                      age, sc->realtime.command_timeout);
    }
    lag_sim_set_input(&s->sim, s->held);
    rt_log_input(s); /* --log with an actuator lag: the input this period runs with */
    s->period_left = sc->ticks_per_period;
    s->period_us = 0;
    /* the live error estimate: a period run in one piece (nothing changes the sim between
     * its chunks then) is run again after it is published, from a copy of its start */
    const int every = lag_scene_estimate_every(sc);
    s->shadow_armed = every > 0 && s->periods_done % every == 0 && s->period_left <= budget;
    if (s->shadow_armed) s->shadow_start = s->sim;
}

/* The live error estimate of the period just published (docs/accuracy.md): its error,
 * largest over the joints, for status; over the scene's budget, an error_estimate event
 * naming the joint. A shadow that faults says nothing (the run itself did not). */
static void estimate_error(rt_server *s)
{
    s->shadow_armed = false;
    double err[LAG_MAX_DOF];
    if (lag_sim_shadow_error(&s->shadow_start, &s->sim, err) != LAG_OK) return;
    int j = 0;
    for (int i = 1; i < s->nq; i++)
        if (err[i] > err[j]) j = i;
    if (!isfinite(err[j])) return;
    s->err_estimate = err[j];
    s->err_joint = j;
    const double budget = rt_error_budget(s->sc);
    if (budget > 0 && err[j] > budget) {
        s->err_warnings++;
        limited_event(s, RT_EV_ERROR_ESTIMATE, s->info->joint_names[j], err[j],
                      "the integration added an estimated %.3g to %s over the period ending at "
                      "t = %.9g s, %.3g times its budget %.3g (integrator.error %g over %g s)",
                      err[j], s->info->joint_names[j], lag_sim_time(&s->sim), err[j] / budget,
                      budget, s->sc->accuracy.error, s->sc->accuracy.horizon);
    }
}

/* The period is complete: its state goes out; STEP and --duration are booked. */
static void period_end(rt_server *s)
{
    if (s->period_us > s->step_us_max) s->step_us_max = s->period_us;
    s->step_us_sum += s->period_us;
    s->step_us_n++;
    publish_state(s);
    if (s->pending_steps > 0 && --s->pending_steps == 0) {
        limited_event(s, RT_EV_STEP_DONE, "", 0, "step done: paused");
        s->want_status = true;
    }
    if (s->stop_tick > 0 && s->sim.tick >= s->stop_tick) {
        s->stop = true;
        s->stop_reason = RT_STOP_DURATION;
    }
}

/* Runs the current control period (starting one if none is in progress) for at most
 * *budget ticks (taken from it). No allocation. */
static rt_progress period_run(rt_server *s, int64_t *budget)
{
    if (s->period_left == 0) period_begin(s, *budget);
    int64_t n = s->period_left < *budget ? s->period_left : *budget;
    if (n < 1) return RT_P_MORE;
    *budget -= n;
    /* a chunk of the period, whose input holds to its end: dopri5 steps across the
     * chunk's end (dense output gives the state there) and lands on the period's, so the
     * period in chunks is bit-identical to one call for it */
    int64_t t0 = rt_mono_ns(), tick0 = s->sim.tick;
    lag_result r = lag_sim_advance_within(&s->sim, n, s->sim.tick + s->period_left);
    s->period_us += (double)(rt_mono_ns() - t0) * 1e-3;
    s->lg.ticks += s->sim.tick - tick0; /* the log's clock */
    s->period_left -= n;
    s->ticks_since_status += n;
    publish_effect_events(s);
    if (r != LAG_OK || !state_finite(&s->sim)) {
        s->shadow_armed = false;
        enter_fault(s, r);
        return RT_P_FAULT;
    }
    if (s->period_left > 0) return RT_P_MORE;
    period_end(s);
    s->periods_done++;
    if (s->shadow_armed) estimate_error(s); /* after the state went out */
    return RT_P_DONE;
}

/* ---------------------------------------------------------------- the modes */
/* Paused or waiting (realtime, fast): the held state is republished at each deadline,
 * once however many deadlines the loop slept through. */
static void paused_republish(rt_server *s)
{
    rt_due d = rt_pace_due(&s->pace, s->now);
    if (d.due == 0) return;
    if (s->run == RT_PAUSED || s->run == RT_WAITING) publish_state(s);
    rt_pace_skip(&s->pace, s->now);
}

/* Realtime: the periods whose deadline has passed, in bursts of at most RT_MAX_BURST; too
 * far behind, the clock re-bases (overrun_burst). */
static void mode_realtime(rt_server *s)
{
    if (!active(s)) {
        paused_republish(s);
        return;
    }
    rt_due d = rt_pace_due(&s->pace, s->now);
    if (d.due == 0) return;
    s->overruns += d.overruns;
    if (d.rebase) {
        s->overrun_bursts++;
        limited_event(s, RT_EV_OVERRUN_BURST, "", (double)d.due,
                      "%lld periods behind wall clock: cannot catch up, re-basing the clock "
                      "(sim time lags wall time by %.3g s more)",
                      (long long)d.due, (double)d.due * (double)s->pace.period_ns * 1e-9);
    }
    rt_pace_apply(&s->pace, &d, s->now);
    int64_t budget = s->tick_budget;
    for (int64_t k = 0; k < d.run && budget > 0 && active(s) && !s->stop; k++) {
        rt_pace_ran(&s->pace);
        if (period_run(s, &budget) != RT_P_DONE) break;
    }
}

/* --log in a mode without wall-clock deadlines (fast, lockstep): the next period waits
 * while the log's ring is more than half full, so the run slows to the disk's pace
 * instead of losing records (realtime never waits: rt_log.h). */
static bool log_holds(const rt_server *s)
{
    return s->lg.log && s->sc->realtime.mode != LAG_RT_REALTIME && !rt_log_room(s->lg.log);
}
#define RT_LOG_HOLD_NS 1000000LL /* a held period looks at the ring again 1 ms later */

/* Fast: one period per wake-up, LCM served between every two. */
static void mode_fast(rt_server *s)
{
    if (!active(s)) {
        paused_republish(s);
        return;
    }
    if (log_holds(s)) return;
    int64_t budget = s->tick_budget;
    period_run(s, &budget);
}

/* Lockstep: a period when the state waited on is answered; nothing else advances it.
 * A wait longer than lockstep_timeout means the controller is gone (or late): one
 * lockstep_timeout event, then the daemon waits (RT_WAITING) and republishes the state
 * every lockstep_timeout until a command answers it. It never steps without an answer, so
 * a run that lost its controller for a while ends exactly as one that did not. */
static void mode_lockstep(rt_server *s)
{
    if (s->run == RT_WAITING && s->pending_steps == 0) {
        if (s->waiting && s->now - s->wait_start_ns >= s->lockstep_wait_ns)
            s->want_state = true; /* the same state again, through the state bucket */
        return;
    }
    if (!active(s) || !s->waiting) return;
    if (!s->answered && s->now - s->wait_start_ns >= s->lockstep_wait_ns) {
        if (s->pending_steps > 0) { /* STEP N: a period without a command, as asked */
            s->answered = true;
        } else {
            s->lockstep_timeouts++;
            s->run = RT_WAITING;
            limited_event(s, RT_EV_LOCKSTEP_TIMEOUT, "", s->waiting_time,
                          "no command answered sim time %.9g s within %.6g s: waiting for one "
                          "(the state is published again every %.6g s)", s->waiting_time,
                          s->sc->realtime.lockstep_timeout, s->sc->realtime.lockstep_timeout);
            s->want_state = true;
            s->want_status = true;
            return;
        }
    }
    if (!s->answered) {
        lockstep_retry(s);
        return;
    }
    if (log_holds(s)) return;
    s->waiting = false;
    int64_t budget = s->tick_budget;
    period_run(s, &budget);
}

/* ---------------------------------------------------------------- commands */
static void lockstep_rewait(rt_server *s);

/* The model's joints, the actuated ones marked: "theta0 (actuated), theta1, theta2" (or
 * only the actuated ones), as the scene loader lists them; what a rejection offers. */
static const char *joint_list(const rt_server *s, bool actuated_only, char *buf, size_t n)
{
    size_t k = 0;
    buf[0] = '\0';
    for (int i = 0; i < s->nq && k < n; i++) {
        if (actuated_only && !s->info->actuated[i]) continue;
        int w = snprintf(buf + k, n - k, "%s%s%s", k ? ", " : "", s->info->joint_names[i],
                         !actuated_only && s->info->actuated[i] ? " (actuated)" : "");
        if (w < 0) break;
        k += (size_t)w;
    }
    if (!buf[0]) snprintf(buf, n, "none");
    return buf;
}

const char *const rt_reject_name[RT_REJ_COUNT] = {
    [RT_REJ_UNKNOWN_JOINT] = "unknown joint",
    [RT_REJ_UNACTUATED] = "unactuated joint",
    [RT_REJ_NONFINITE] = "non-finite effort",
    [RT_REJ_BAD_LENGTH] = "bad length",
    [RT_REJ_UNDECODABLE] = "undecodable payload",
    [RT_REJ_STALE] = "stale (lockstep: answers another state)",
    [RT_REJ_EFFORT_LIMIT] = "effort beyond realtime.effort_limit"};
_Static_assert(sizeof rt_reject_name / sizeof rt_reject_name[0] == RT_REJ_COUNT,
               "one name per reason");

/* A rejected command: counted by reason, and a command_rejected event (limited) whose
 * detail says what was wrong and what would be accepted. */
static void reject(rt_server *s, rt_reject why, const char *joint, double value,
                   const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static void reject(rt_server *s, rt_reject why, const char *joint, double value,
                   const char *fmt, ...)
{
    char what[192]; /* and the reason's name: within an event's detail */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    s->rejected[why]++;
    rt_log_rx_fate(s, why == RT_REJ_UNDECODABLE ? RT_RX_UNDECODABLE : RT_RX_REFUSED); /* --log */
    char detail[LAG_WIRE_TEXT_LEN];
    snprintf(detail, sizeof detail, "%s: %s", rt_reject_name[why], what);
    if (why != RT_REJ_STALE) memcpy(s->last_reject, detail, sizeof detail); /* waits say it */
    /* a flood is counted in status, not echoed one for one */
    limited_event(s, RT_EV_COMMAND_REJECTED, joint, value, "command rejected: %s", detail);
}

static void handle_command(rt_server *s, const uint8_t *data, size_t len);

/* --log: as received, once its fate is known (rt_log_rx_*) */
void rt_handle_command(rt_server *s, const uint8_t *data, size_t len)
{
    rt_log_rx_begin(s, s->ch_command, data, len);
    handle_command(s, data, len);
    rt_log_rx_end(s);
}

/* A command is applied whole or not at all: every name known, actuated, distinct; every
 * effort finite and within the scene's realtime.effort_limit. */
static void handle_command(rt_server *s, const uint8_t *data, size_t len)
{
    lag_wire_joint_command c;
    int d = lag_wire_decode_joint_command(data, len, s->nq, &c);
    if (d == LAG_WIRE_ECOUNT) {
        char all[160];
        reject(s, RT_REJ_BAD_LENGTH, "", c.num_joints,
               "num_joints %d (in value); accepted: 0 to %d, joints of %s: %s", c.num_joints,
               s->nq, s->info->name, joint_list(s, false, all, sizeof all));
        return;
    }
    if (d == LAG_WIRE_ETOOLONG) { /* a well-formed name longer than any joint's */
        char all[160];
        reject(s, RT_REJ_UNKNOWN_JOINT, "", 0, "a name of 64 bytes or more; joints of %s: %s",
               s->info->name, joint_list(s, false, all, sizeof all));
        return;
    }
    if (d != LAG_WIRE_OK) {
        reject(s, RT_REJ_UNDECODABLE, "", (double)len,
               "%zu bytes (in value) that are no lagsim.joint_command_t; accepted: a "
               "joint_command_t as lcm-gen encodes it (lcmtypes/joint_command_t.lcm)", len);
        return;
    }
    /* lockstep: an answer to the state waited on, good or not, came: it needs no copies */
    if (s->waiting && c.sim_time == s->waiting_time) s->answer_heard = true;
    int idx[LAG_MAX_DOF];
    for (int i = 0; i < c.num_joints; i++) {
        idx[i] = -1;
        for (int j = 0; j < s->nq; j++)
            if (strcmp(c.name[i], s->info->joint_names[j]) == 0) idx[i] = j;
        char all[160];
        if (idx[i] < 0) {
            reject(s, RT_REJ_UNKNOWN_JOINT, c.name[i], 0, "'%s'; joints of %s: %s", c.name[i],
                   s->info->name, joint_list(s, false, all, sizeof all));
            return;
        }
        for (int k = 0; k < i; k++)
            if (idx[k] == idx[i]) {
                reject(s, RT_REJ_BAD_LENGTH, c.name[i], c.num_joints,
                       "'%s' named twice; accepted: each joint at most once (%s)", c.name[i],
                       joint_list(s, false, all, sizeof all));
                return;
            }
        if (!s->info->actuated[idx[i]]) {
            reject(s, RT_REJ_UNACTUATED, c.name[i], 0,
                   "'%s' takes no input; actuated joints of %s: %s", c.name[i], s->info->name,
                   joint_list(s, true, all, sizeof all));
            return;
        }
        if (!isfinite(c.effort[i])) {
            reject(s, RT_REJ_NONFINITE, c.name[i], 0,
                   "%g for '%s'; accepted: a finite effort within +-%g", c.effort[i], c.name[i],
                   s->sc->realtime.effort_limit[idx[i]]);
            return;
        }
        /* a bound on what a command may ask, not the plant's saturation (that is the
         * actuator effect): an effort beyond it is a controller's bug, refused whole */
        double lim = s->sc->realtime.effort_limit[idx[i]];
        if (fabs(c.effort[i]) > lim) {
            reject(s, RT_REJ_EFFORT_LIMIT, c.name[i], c.effort[i],
                   "%g for '%s' (in value); accepted: |effort| <= %g", c.effort[i], c.name[i],
                   lim);
            return;
        }
    }
    if (s->sc->realtime.mode == LAG_RT_LOCKSTEP) {
        bool waited_on = s->waiting && c.sim_time == s->waiting_time;
        /* a second answer to a state already answered (the controller got it twice, a
         * retry crossing its first answer): not applied, counted, no event */
        if ((waited_on && s->answered) ||
            (!waited_on && s->have_answered && c.sim_time == s->answered_time)) {
            s->commands_ignored++;
            rt_log_rx_fate(s, RT_RX_REFUSED); /* --log: a sample of them */
            return;
        }
        if (!waited_on && !(s->run != RT_RUNNING && c.sim_time == lag_sim_time(&s->sim))) {
            if (s->waiting)
                reject(s, RT_REJ_STALE, "", c.sim_time,
                       "sim_time %.9g (in value); accepted: %.9g, the state waited on",
                       c.sim_time, s->waiting_time);
            else
                reject(s, RT_REJ_STALE, "", c.sim_time,
                       "sim_time %.9g (in value); no state is waited on (the next one's "
                       "sim_time will be)", c.sim_time);
            return;
        }
    }
    for (int i = 0; i < c.num_joints; i++) s->held[idx[i]] = c.effort[i];
    s->accepted++;
    s->have_command = true;
    s->command_tick = s->sim.tick;
    if (s->waiting && c.sim_time == s->waiting_time) {
        s->answered = true;
        s->answered_time = c.sim_time;
        s->have_answered = true;
    }
    if (s->run == RT_WAITING) {
        /* the command the run was waiting for: it goes on from here */
        s->run = RT_RUNNING;
        s->restart_pace = true; /* realtime: deadlines start now, not at the daemon's start */
        if (s->sc->realtime.mode == LAG_RT_LOCKSTEP && !s->answered) lockstep_rewait(s);
        limited_event(s, RT_EV_RESUME, "", lag_sim_time(&s->sim),
                      "a command arrived at sim time %.9g s: running", lag_sim_time(&s->sim));
        s->want_status = true;
    }
    if (s->watchdog_tripped) {
        s->watchdog_tripped = false;
        limited_event(s, RT_EV_WATCHDOG_CLEAR, "", 0, "a good command arrived: efforts held again");
    }
}

/* ---------------------------------------------------------------- control requests */
static void do_reset(rt_server *s, const double *q, const double *qd, const char *what)
{
    if (s->live.nk > 0) { /* sim time starts over: the kicks are the old run's */
        char detail[96];
        snprintf(detail, sizeof detail, "a reset ends the %d kick(s) of the run before it",
                 s->live.nk);
        live_kicks_clear(&s->live, &s->sim);
        rt_publish_event(s, "kicks_cleared", "", 0, detail); /* --replay applies it here */
    }
    lag_sim_reset(&s->sim, q, qd);
    s->effect_events_dropped = s->sim.events_dropped;
    for (int i = 0; i < s->nq; i++) s->held[i] = 0.0;
    s->have_command = false;
    s->watchdog_tripped = false;
    s->pending_steps = 0;
    s->period_left = 0;
    s->waiting = false; /* lockstep: the new state is waited on once it is published */
    s->have_answered = false;
    if (s->run == RT_FAULT) s->run = RT_PAUSED;
    char kept[200];
    live_set_describe(&s->live, kept, sizeof kept);
    /* which changes made while running the reset keeps (a reset with count 1 keeps none) */
    limited_event(s, RT_EV_RESET, "", 0, "%s: sim time 0, efforts zero, %s; %s%s%s", what,
                  s->run == RT_PAUSED    ? "paused (resume to run)"
                  : s->run == RT_WAITING ? "waiting for a command"
                                         : "running",
                  kept[0] ? "keeps the changes made while running: " : "the scene file's values",
                  kept, kept[0] ? " (lagsimctl reset --scene, RESET count 1: the scene file's "
                                  "values)" : "");
    s->want_scene = true;
    s->want_state = true;
    s->want_status = true;
}

static void control_rejected(rt_server *s, const char *why)
{
    s->controls_rejected++;
    rt_log_rx_fate(s, RT_RX_REFUSED); /* --log: a sample of them */
    limited_event(s, RT_EV_CONTROL_REJECTED, "", 0, "%s", why);
    s->want_status = true;
}

/* Does any joint's actuator have a lag? */
static bool actuator_lagged(const lag_effects_def *fx, int nq)
{
    for (int i = 0; (fx->enabled & LAG_EFF_ACTUATOR) && i < nq; i++)
        if (fx->actuator_tau[i] > 0) return true;
    return false;
}

/* A kick (SET key "kick.<joint>", value "<impulse>[,<duration>]"): a disturbance from
 * the current tick on, added to the scene's and to the kicks not over yet (live_set.c).
 * The answer: a `kick` event whose detail is exactly "kick.<joint>=<value>" and whose step
 * is the tick it starts at (what --replay re-applies), then a status. */
static void handle_kick(rt_server *s, const lag_wire_control *c)
{
    char kv[LIVE_SET_LEN], why[1024];
    if (snprintf(kv, sizeof kv, "%s=%s", c->key, c->value) >= (int)sizeof kv) {
        control_rejected(s, "kick: key=value is too long");
        return;
    }
    if (!rt_limit_take(&s->lim_set, s->now)) {
        snprintf(why, sizeof why, "%s: more than %d changes a second; this one was not "
                                  "applied", kv, RT_SET_PER_S);
        control_rejected(s, why);
        return;
    }
    live_kick k;
    if (live_kick_apply(&s->live, &s->sim, kv, &k, why, sizeof why) != 0) {
        control_rejected(s, why);
        return;
    }
    rt_publish_event(s, "kick", lag_model_info_get(s->sim.def.model.kind)->joint_names[k.joint],
                     k.impulse, kv);
    s->want_status = true;
}

/* SET key=value: the change is validated by the scene loader itself, on the scene's own
 * bytes with its --set overrides, the changes already made and this one after them (so
 * every rule of a scene file holds, with its message: live_set.c), then by the core
 * against the state the run is in; it takes effect at once, at the current tick. Only
 * keys under parameters and effects change while running. The answer: a `set` event
 * whose detail is exactly "key=value" and whose step is the tick it took effect at (what
 * --replay re-applies), and the new scene. A refusal is a control_rejected whose detail
 * names the change and the reason. */
static void handle_set(rt_server *s, const lag_wire_control *c)
{
    char kv[LIVE_SET_LEN], err[512], why[1024];
    if (live_is_kick(c->key)) {
        handle_kick(s, c);
        return;
    }
    if (live_set_parse(c->key, c->value, kv, why, sizeof why) != 0) {
        control_rejected(s, why);
        return;
    }
    if (!rt_limit_take(&s->lim_set, s->now)) {
        snprintf(why, sizeof why, "set %s: more than %d changes a second; this one was not "
                                  "applied", kv, RT_SET_PER_S);
        control_rejected(s, why);
        return;
    }
    static lag_scene ns; /* large: not on the stack; used by this function only */
    if (live_set_load(s->opts, &s->live, kv, &ns, why, sizeof why) != 0) {
        control_rejected(s, why);
        return;
    }
    /* A lag's actuator state lives within periods: --log records the commanded inputs
     * that let --replay run it only when the scene starts with a lag. */
    if (!actuator_lagged(&s->sc->sim.effects, s->nq) && actuator_lagged(&ns.sim.effects, s->nq)) {
        snprintf(why, sizeof why, "set %s: an actuator lag cannot be switched on while "
                                  "running (a replay could not reproduce the run); give the "
                                  "scene's actuator a lag to start with", kv);
        control_rejected(s, why);
        return;
    }
    if (lag_sim_redefine(&s->sim, &ns.sim, err, sizeof err) != LAG_OK) {
        snprintf(why, sizeof why, "set %s: %s", kv, err);
        control_rejected(s, why);
        return;
    }
    s->ref = ns.reference; /* SET reference.*: from the next state on */
    live_set_keep(&s->live, kv);
    rt_publish_event(s, "set", "", 0, kv);
    s->want_scene = true;
    s->want_status = true;
}

/* Lockstep, when the run goes on (resume, step): the state already published is waited
 * on afresh; if none is, it is published. */
static void lockstep_rewait(rt_server *s)
{
    if (s->sc->realtime.mode != LAG_RT_LOCKSTEP) return;
    if (s->waiting) s->wait_start_ns = s->now;
    else if (s->period_left == 0) s->want_state = true;
}

static void handle_control(rt_server *s, const uint8_t *data, size_t len);

/* --log: as received, once its fate is known (rt_log_rx_*) */

/* The requests of control_t, by value (lcmtypes/control_t.lcm): what a rejection of an
 * unknown one offers. */
static const char *control_requests(void)
{
    static const char *const names[] = {
        [LAGSIM_CONTROL_T_PAUSE] = "PAUSE", [LAGSIM_CONTROL_T_RESUME] = "RESUME",
        [LAGSIM_CONTROL_T_STEP] = "STEP", [LAGSIM_CONTROL_T_RESET] = "RESET",
        [LAGSIM_CONTROL_T_RESET_TO] = "RESET_TO", [LAGSIM_CONTROL_T_STATUS] = "STATUS",
        [LAGSIM_CONTROL_T_DESCRIBE] = "DESCRIBE", [LAGSIM_CONTROL_T_SET] = "SET"};
    static char list[160];
    if (!list[0]) {
        size_t k = 0;
        for (size_t i = 0; i < sizeof names / sizeof names[0] && k < sizeof list; i++) {
            if (!names[i]) continue;
            int w = snprintf(list + k, sizeof list - k, "%s%s = %zu", k ? ", " : "", names[i], i);
            if (w < 0) break;
            k += (size_t)w;
        }
    }
    return list;
}

void rt_handle_control(rt_server *s, const uint8_t *data, size_t len)
{
    rt_log_rx_begin(s, s->ch_control, data, len);
    handle_control(s, data, len);
    rt_log_rx_end(s);
}

static void handle_control(rt_server *s, const uint8_t *data, size_t len)
{
    lag_wire_control c;
    /* any count a message may carry decodes; reset_to checks it against the model's */
    int d = lag_wire_decode_control(data, len, LAG_WIRE_MAX_JOINTS, &c);
    if (d != LAG_WIRE_OK) {
        if (d != LAG_WIRE_ECOUNT) rt_log_rx_fate(s, RT_RX_UNDECODABLE);
        char why[LAG_WIRE_TEXT_LEN];
        if (d == LAG_WIRE_ECOUNT)
            snprintf(why, sizeof why, "control: num_joints out of range; accepted: 0, or %d "
                     "for reset_to (the joints of %s)", s->nq, s->info->name);
        else
            snprintf(why, sizeof why, "control: %zu bytes that are no lagsim.control_t; "
                     "accepted: a control_t as lcm-gen encodes it (lcmtypes/control_t.lcm)", len);
        control_rejected(s, why);
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
        s->restart_pace = true; /* the held state is republished from now on */
        limited_event(s, RT_EV_PAUSE, "", 0, "paused");
        break;
    case LAGSIM_CONTROL_T_RESUME:
        if (s->run == RT_FAULT) {
            control_rejected(s, "resume: in fault state (reset first)");
            return;
        }
        s->run = RT_RUNNING;
        s->pending_steps = 0;
        s->restart_pace = true; /* deadlines restart from now */
        lockstep_rewait(s);
        limited_event(s, RT_EV_RESUME, "", 0, "running");
        break;
    case LAGSIM_CONTROL_T_STEP:
        if (s->run != RT_PAUSED && s->run != RT_WAITING) {
            control_rejected(s, s->run == RT_FAULT ? "step: in fault state (reset first)"
                                                   : "step: only while paused or waiting "
                                                     "(pause first)");
            return;
        }
        if (c.count < 1) {
            char why[96];
            snprintf(why, sizeof why, "step: count %lld; accepted: a count >= 1",
                     (long long)c.count);
            control_rejected(s, why);
            return;
        }
        s->pending_steps = c.count;
        s->restart_pace = true; /* realtime: the first period ends one period from now */
        lockstep_rewait(s);
        limited_event(s, RT_EV_STEP, "", (double)c.count,
                      "stepping %lld control periods at the %s mode's pace", (long long)c.count,
                      lag_rt_mode_name(s->sc->realtime.mode));
        return; /* step_done (and its status) follow when the steps are done */
    case LAGSIM_CONTROL_T_RESET:
        if (c.count == 1 && (s->live.n > 0 || s->live.nk > 0)) {
            /* count 1: the scene file's values too. A `restore` event (never suppressed:
             * --replay undoes the changes where it says) before the reset's. */
            char err[512], why[700];
            if (lag_sim_redefine(&s->sim, &s->sc->sim, err, sizeof err) != LAG_OK) {
                snprintf(why, sizeof why, "reset to the scene file's values: %s", err);
                control_rejected(s, why);
                return;
            }
            char undone[180], detail[LAG_WIRE_TEXT_LEN];
            live_set_describe(&s->live, undone, sizeof undone);
            snprintf(detail, sizeof detail, "the scene file's values again: undone %s%s%d "
                     "kick(s)", undone, undone[0] ? ", " : "", s->live.nk);
            rt_publish_event(s, "restore", "", (double)s->live.n, detail);
            memset(&s->live, 0, sizeof s->live);
            s->ref = s->sc->reference;
        }
        do_reset(s, NULL, NULL, c.count == 1 ? "reset to the scene file's initial state and "
                                               "values" : "reset to the scene's initial state");
        return;
    case LAGSIM_CONTROL_T_RESET_TO: {
        if (c.num_joints != s->nq) {
            char why[LAG_WIRE_TEXT_LEN], all[160];
            snprintf(why, sizeof why, "reset_to: num_joints %d; accepted: %d, the joints of %s "
                     "in this order: %s", c.num_joints, s->nq, s->info->name,
                     joint_list(s, false, all, sizeof all));
            control_rejected(s, why);
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
        if (lag_model_forward(&s->sim.model, c.q, c.qd, NULL, qdd) != LAG_OK) {
            control_rejected(s, "reset_to: mass matrix not positive definite at q");
            return;
        }
        if (lag_sim_contact(&s->sim)[0] && c.q[2] < 0) {
            control_rejected(s, "reset_to: h, the stick's lower end, must not be below the "
                                "floor (h >= 0)");
            return;
        }
        do_reset(s, c.q, c.qd, "reset to a given state");
        return;
    }
    case LAGSIM_CONTROL_T_STATUS:
        rt_log_rx_fate(s, RT_RX_QUERY); /* --log: changes nothing; a sample of them */
        break; /* the status below is the answer */
    case LAGSIM_CONTROL_T_DESCRIBE:
        rt_log_rx_fate(s, RT_RX_QUERY);
        s->want_scene = true;
        return;
    case LAGSIM_CONTROL_T_SET:
        handle_set(s, &c);
        return;
    default: {
        char why[LAG_WIRE_TEXT_LEN];
        snprintf(why, sizeof why, "control: unknown request %d; accepted: %s", c.request,
                 control_requests());
        control_rejected(s, why);
        return;
    }
    }
    s->want_status = true;
}

/* ---------------------------------------------------------------- one plant per prefix */
uint64_t rt_hash(const uint8_t *data, size_t len)
{
    uint64_t h = 14695981039346656037ULL;
    for (size_t i = 0; i < len; i++) h = (h ^ data[i]) * 1099511628211ULL;
    return h;
}

void rt_handle_scene(rt_server *s, const uint8_t *data, size_t len)
{
    uint64_t h = rt_hash(data, len);
    for (int k = 0; k < RT_SCENES_KEPT; k++)
        if (s->scene_sent[k] == h) return; /* this daemon's own */
    if (s->discard && s->other_plant[0]) return; /* at start: said already */
    /* a plant's scene decodes and names its prefix; anything else on the channel is not a
     * plant (junk, a forgery of no consequence) and is ignored */
    static lag_wire_scene m; /* large: not on the stack of a handler */
    if (lag_wire_decode_scene(data, len, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK ||
        strcmp(m.prefix, s->sc->lcm.prefix) != 0)
        return;
    snprintf(s->other_plant, sizeof s->other_plant, "a scene this daemon did not send "
             "(model %.20s, mode %.10s, dt %g s)", m.model, m.mode, m.dt);
    if (s->discard) return; /* at start (rt_bus_open's look before publishing): refused there */
    /* running: one datagram from any process must not stop a plant that may be driving an
     * experiment; the conflict is counted and said, rate-limited, and the run goes on */
    s->plant_conflicts++;
    rt_limit *l = &s->lim_event[RT_EV_PLANT_CONFLICT];
    limited_event(s, RT_EV_PLANT_CONFLICT, "", (double)s->plant_conflicts,
                  "another plant publishes on prefix %s (%s): %lld such scenes so far (in "
                  "value); running on; one plant per prefix: stop the other, or give one "
                  "another lcm.prefix", s->sc->lcm.prefix, s->other_plant,
                  (long long)s->plant_conflicts);
    if (l->suppressed == 0) { /* the event went out: the terminal hears it too, even with -q */
        if (s->opts && s->opts->quiet)
            fprintf(stderr, "lagsimd: another plant publishes on prefix %s (%s): %lld such "
                    "scenes so far; running on\n", s->sc->lcm.prefix, s->other_plant,
                    (long long)s->plant_conflicts);
        s->want_status = true;
    }
}

/* ---------------------------------------------------------------- the server in pieces */
static void on_scene(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_handle_scene(user, rb->data, rb->data_size);
}

static void on_command(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_server *s = user;
    if (!s->discard) rt_handle_command(s, rb->data, rb->data_size);
}

/* A command on the state URL: the controller publishes on the wrong port. Counted (the
 * waits say so, rt_wait.c), never applied. */
static void on_wrong_port(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)rb;
    (void)ch;
    rt_server *s = user;
    if (!s->discard) s->commands_wrong_port++;
}

static void on_control(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_server *s = user;
    if (!s->discard) rt_handle_control(s, rb->data, rb->data_size);
}

static int open_error(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int open_error(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return LAGSIMD_EXIT_USAGE;
}

int rt_open(rt_server *s, const lag_scene *sc, const lagsimd_opts *o, int64_t now, bool quiet,
            char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    s->sc = sc;
    s->opts = o;
    s->now = now;
    s->info = lag_model_info_get(sc->sim.model.kind);

    /* everything that can fail on a bad scene fails before anything is published */
    char serr[256];
    if (!s->info) return open_error(err, errlen, "bad scene: unknown model");
    if (lag_sim_init(&s->sim, &sc->sim, serr, sizeof serr) != LAG_OK)
        return open_error(err, errlen, "bad scene: %s", serr);
    const double dt = sc->sim.integrator.dt;
    const double rate = sc->realtime.rate;
    if (!(sc->publish_hz > 0) || !isfinite(sc->publish_hz) || sc->ticks_per_period < 1 ||
        sc->ticks_per_period > RT_MAX_RUN_TICKS)
        return open_error(err, errlen, "bad scene: publish_hz must be > 0 and finite, "
                          "1/publish_hz a whole number of ticks (at most 2^53)");
    if (!(rate > 0) || !isfinite(rate))
        return open_error(err, errlen, "bad scene: realtime.rate must be > 0 and finite (got %g)", rate);
    if (!(sc->realtime.status_hz > 0) || !isfinite(sc->realtime.status_hz))
        return open_error(err, errlen, "bad scene: realtime.status_hz must be > 0 and finite (got %g)",
                          sc->realtime.status_hz);
    if (!(sc->realtime.lockstep_retry >= 0) || !isfinite(sc->realtime.lockstep_retry))
        return open_error(err, errlen, "bad scene: realtime.lockstep_retry must be >= 0 and "
                          "finite (got %g)", sc->realtime.lockstep_retry);
    if (!(sc->realtime.lockstep_timeout >= 0) || !isfinite(sc->realtime.lockstep_timeout))
        return open_error(err, errlen, "bad scene: realtime.lockstep_timeout must be >= 0 and "
                          "finite (got %g)", sc->realtime.lockstep_timeout);
    if (!(sc->realtime.command_timeout >= 0) || isnan(sc->realtime.command_timeout))
        return open_error(err, errlen, "bad scene: realtime.command_timeout must be >= 0 (got %g)",
                          sc->realtime.command_timeout);
    /* the loader bounds lcm.prefix (file:line:column); a scene built in code is checked here */
    _Static_assert(LAG_SCENE_PREFIX_MAX + 10 == LCM_MAX_CHANNEL_NAME_LENGTH,
                   "the loader's prefix bound leaves room for _REFERENCE in an LCM channel name");
    size_t plen = strnlen(sc->lcm.prefix, sizeof sc->lcm.prefix);
    if (plen == 0 || plen + 10 > LCM_MAX_CHANNEL_NAME_LENGTH)
        return open_error(err, errlen, "bad scene: lcm.prefix must have 1 to %d characters "
                          "(LCM channel names are at most %d, and the longest suffix is "
                          "_REFERENCE)", LCM_MAX_CHANNEL_NAME_LENGTH - 10,
                          LCM_MAX_CHANNEL_NAME_LENGTH);
    if (o && o->duration > 0 && !rt_ticks_for(o->duration, dt, &s->stop_tick))
        return open_error(err, errlen, "--duration %g s is more than 2^53 ticks of dt %g s "
                          "(the longest run whose sim time is exact)", o->duration, dt);

    /* settings the loop cannot honour as given are clamped, and said so */
    const double period_s = (double)sc->ticks_per_period * dt;
    bool clamped = false;
    s->period_ns = rt_pace_period_ns(period_s, rate, &clamped);
    if (clamped && !quiet)
        fprintf(stderr, "lagsimd: warning: a control period of %g s at realtime.rate %g is %g s of "
                "wall time; the loop paces periods %g s apart at the %s\n", period_s, rate,
                period_s / rate, (double)s->period_ns * 1e-9,
                s->period_ns == RT_PERIOD_NS_MIN ? "fastest (it runs as fast as it can and "
                "counts overruns)" : "slowest");
    double status_ns = 1e9 / sc->realtime.status_hz;
    s->status_period_ns = rt_clamp_ns(status_ns, RT_STATUS_NS_MIN, INT64_MAX);
    if ((double)s->status_period_ns > status_ns + 0.5 && !quiet)
        fprintf(stderr, "lagsimd: warning: realtime.status_hz %g: statuses go out at most "
                "every %g s\n", sc->realtime.status_hz, (double)RT_STATUS_NS_MIN * 1e-9);
    s->lockstep_wait_ns = rt_ns_from_s(sc->realtime.lockstep_timeout);
    /* a retry at most every millisecond (a scene built in code may say 0) */
    s->lockstep_retry_ns = sc->realtime.lockstep_retry > 0
                               ? rt_clamp_ns(sc->realtime.lockstep_retry * 1e9, RT_RETRY_NS_MIN,
                                             INT64_MAX)
                               : INT64_MAX;
    s->retry_cap_ns = s->lockstep_wait_ns / 16 > s->lockstep_retry_ns ? s->lockstep_wait_ns / 16
                                                                     : s->lockstep_retry_ns;

    s->nq = s->sim.nq;
    s->info = lag_sim_info(&s->sim); /* the joints published: a stick that may fly has h */
    s->err_joint = -1;      /* no live error estimate yet */
    /* the URLs and channels, by the rule every client follows (lagsim_bus.h) */
    char berr[256];
    if (lag_bus_init(&s->bus, sc->lcm.url, sc->lcm.prefix, berr, sizeof berr) != 0)
        return open_error(err, errlen, "bad scene: lcm.url: %s", berr);
    snprintf(s->ch_state, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_STATE]);
    snprintf(s->ch_command, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_COMMAND]);
    snprintf(s->ch_status, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_STATUS]);
    snprintf(s->ch_event, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_EVENT]);
    snprintf(s->ch_control, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_CONTROL]);
    snprintf(s->ch_scene, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_SCENE]);
    snprintf(s->ch_reference, RT_CHANNEL_MAX, "%s", s->bus.channel[LAG_BUS_REFERENCE]);
    s->ref = sc->reference;
    s->tick_budget = RT_TICK_BUDGET;
    for (int k = 0; k < RT_EV_COUNT; k++)
        rt_limit_init(&s->lim_event[k], ev_limits[k].per_s, ev_limits[k].burst, now);
    rt_limit_init(&s->lim_status, RT_STATUS_PER_S, RT_STATUS_BURST, now);
    rt_limit_init(&s->lim_scene, RT_SCENE_PER_S, RT_SCENE_BURST, now);
    rt_limit_init(&s->lim_state, RT_STATE_PER_S, RT_STATE_BURST, now);
    rt_limit_init(&s->lim_set, RT_SET_PER_S, RT_SET_BURST, now);
    rt_limit_init(&s->term.lim_print, 20, 20, now);
    rt_limit_init(&s->lg.lim_said, 1, 1, now);
    rt_limit_init(&s->lg.lim_sample_said, 1, 1, now);
    s->lg.sample_credit = RT_LOG_SAMPLE_BPS; /* a full bucket at start */
    s->lg.sample_ns = now;

    /* --log, last: nothing after it can fail */
    if (o && o->log) {
        s->lg.input = actuator_lagged(&sc->sim.effects, s->nq);
        snprintf(s->lg.ch_input, RT_CHANNEL_MAX, "%s_INPUT", sc->lcm.prefix);
        s->lg.log = rt_log_open(o->log, o->log_ring ? o->log_ring : RT_LOG_RING_DEFAULT,
                                o->force, o->scene_name, err, errlen);
        if (!s->lg.log) return LAGSIMD_EXIT_USAGE;
    }
    return LAGSIMD_EXIT_OK;
}

int rt_attach(rt_server *s, lcm_t *out, lcm_t *in, char *err, size_t errlen)
{
    s->lcm = out;
    s->lcm_in = in;
    s->sub_command = lcm_subscribe(in, s->ch_command, on_command, s);
    s->sub_control = lcm_subscribe(in, s->ch_control, on_control, s);
    if (!s->sub_command || !s->sub_control) {
        rt_close(s);
        snprintf(err, errlen, "cannot subscribe to %s and %s", s->ch_command, s->ch_control);
        return LAGSIMD_EXIT_RUNTIME;
    }
    /* a flood must not queue up without bound: LCM drops beyond this */
    lcm_subscription_set_queue_capacity(s->sub_command, 1000);
    lcm_subscription_set_queue_capacity(s->sub_control, 1000);
    /* the plant watch: another daemon's scene on this prefix. For udpm this gives the
     * state URL's lcm_t a receive socket, which rt_bus_open filters to _SCENE (the
     * daemon's own states are dropped by the kernel, never read back) */
    s->sub_scene = lcm_subscribe(out, s->ch_scene, on_scene, s);
    if (!s->sub_scene) {
        rt_close(s);
        snprintf(err, errlen, "cannot subscribe to %s", s->ch_scene);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lcm_subscription_set_queue_capacity(s->sub_scene, 16);
    if (out != in) { /* udpm: commands sent to the state URL's port are heard (rt_bus.c) */
        s->sub_wrong_port = lcm_subscribe(out, s->ch_command, on_wrong_port, s);
        if (s->sub_wrong_port) lcm_subscription_set_queue_capacity(s->sub_wrong_port, 16);
    }
    return LAGSIMD_EXIT_OK;
}

void rt_close(rt_server *s)
{
    rt_log_end(s); /* a no-op when lagsimd_realtime has closed it already */
    if (s->sub_command) lcm_unsubscribe(s->lcm_in, s->sub_command);
    if (s->sub_control) lcm_unsubscribe(s->lcm_in, s->sub_control);
    if (s->sub_scene) lcm_unsubscribe(s->lcm, s->sub_scene);
    if (s->sub_wrong_port) lcm_unsubscribe(s->lcm, s->sub_wrong_port);
    s->sub_wrong_port = NULL;
    s->sub_command = s->sub_control = NULL;
    s->sub_scene = NULL;
}

void rt_begin(rt_server *s)
{
    const lag_scene *sc = s->sc;
    s->start_ns = s->now;
    s->last_status_ns = s->now;
    s->next_status_ns = rt_sat_add(s->now, s->status_period_ns);
    s->next_line_ns = s->now;
    s->run = sc->realtime.start == LAG_RT_START_PAUSED          ? RT_PAUSED
             : sc->realtime.start == LAG_RT_START_FIRST_COMMAND ? RT_WAITING
                                                                : RT_RUNNING;
    rt_publish_scene(s);
    eventf(s, "start", 0, "%s, %s, dt %.6g s, control period %.6g s, mode %s, rate %.6g: %s",
           lag_model_info_get(sc->sim.model.kind)->name, lag_method_name(sc->sim.integrator.method), sc->sim.integrator.dt,
           (double)sc->ticks_per_period * sc->sim.integrator.dt,
           lag_rt_mode_name(sc->realtime.mode), sc->realtime.rate,
           s->run == RT_PAUSED    ? "paused at t = 0 (resume to run)"
           : s->run == RT_WAITING ? "waiting at t = 0 for the first command"
                                  : "running");
    publish_state(s); /* the initial state, t = 0 */
    rt_wait_update(s); /* a wait for the first command begins now */
    publish_status(s);
    rt_pace_start(&s->pace, s->period_ns, s->now);
}

int64_t rt_next_wake(const rt_server *s)
{
    const int64_t now = s->now;
    if (s->stop || s->restart_pace) return now;
    bool act = active(s);
    if (act && s->period_left > 0) return now; /* a long period goes on */
    int64_t wake = s->next_status_ns;
    switch (s->sc->realtime.mode) {
    case LAG_RT_FAST:
        if (act && !log_holds(s)) return now;
        if (act) wake = min64(wake, rt_sat_add(now, RT_LOG_HOLD_NS));
        if (s->run == RT_PAUSED || s->run == RT_WAITING) wake = min64(wake, rt_pace_next(&s->pace));
        break;
    case LAG_RT_REALTIME:
        if (act || s->run == RT_PAUSED || s->run == RT_WAITING)
            wake = min64(wake, rt_pace_next(&s->pace));
        break;
    case LAG_RT_LOCKSTEP:
        if ((act || s->run == RT_WAITING) && s->waiting && !s->want_state) {
            if (act && s->answered && !log_holds(s)) return now;
            if (act && s->answered) {
                wake = min64(wake, rt_sat_add(now, RT_LOG_HOLD_NS));
            } else {
                wake = min64(wake, rt_sat_add(s->wait_start_ns, s->lockstep_wait_ns));
                if ((s->run == RT_RUNNING || s->pending_steps > 0) && !s->answer_heard)
                    wake = min64(wake, s->next_retry_ns);
            }
        }
        break;
    }
    if (state_wanted(s)) wake = min64(wake, rt_limit_ready(&s->lim_state, now));
    if (s->want_scene) wake = min64(wake, rt_limit_ready(&s->lim_scene, now));
    if (s->want_status) wake = min64(wake, rt_limit_ready(&s->lim_status, now));
    if (s->live_line) wake = min64(wake, s->next_line_ns);
    wake = min64(wake, rt_wait_next(s));
    return wake;
}

/* Answers held back by their bucket go out when it allows, one for many requests. */
static void flush_answers(rt_server *s)
{
    if (state_wanted(s) && rt_limit_ready(&s->lim_state, s->now) <= s->now) {
        rt_limit_take(&s->lim_state, s->now);
        publish_state(s);
    }
    if (s->want_scene && rt_limit_ready(&s->lim_scene, s->now) <= s->now) {
        rt_limit_take(&s->lim_scene, s->now);
        rt_publish_scene(s);
        s->want_scene = false;
    }
    if (s->want_status && rt_limit_ready(&s->lim_status, s->now) <= s->now) {
        rt_limit_take(&s->lim_status, s->now);
        publish_status(s);
    }
}

void rt_process(rt_server *s)
{
    if (s->restart_pace) {
        rt_pace_start(&s->pace, s->period_ns, s->now);
        s->restart_pace = false;
    }
    if (!s->stop) {
        if (s->period_left > 0 && active(s)) {
            int64_t budget = s->tick_budget;
            period_run(s, &budget); /* a long period goes on, chunk by chunk */
        } else {
            switch (s->sc->realtime.mode) {
            case LAG_RT_REALTIME: mode_realtime(s); break;
            case LAG_RT_FAST: mode_fast(s); break;
            case LAG_RT_LOCKSTEP: mode_lockstep(s); break;
            }
        }
    }
    rt_wait_update(s); /* what the plant waits for: a line every few seconds (rt_wait.c) */
    flush_answers(s);
    if (s->now >= s->next_status_ns) {
        publish_status(s);
        s->next_status_ns = rt_sat_add(s->next_status_ns, s->status_period_ns);
        if (s->next_status_ns <= s->now) s->next_status_ns = rt_sat_add(s->now, s->status_period_ns);
    }
    if (s->live_line && s->now >= s->next_line_ns) {
        rt_term_line(s, false);
        s->next_line_ns = rt_sat_add(s->now, RT_LINE_NS);
    }
    /* the log's clock stops while paused or in the fault state, not while waiting for a
     * command (docs/server.md): a wake-up during the wait must not change the stamps */
    rt_log_check(s, active(s) || s->run == RT_WAITING);
    if (s->report_line) {
        s->report_line = false;
        if (s->opts && s->opts->quiet) return;
        fprintf(stderr, "lagsimd: %s t=%.3f s RTF %.3f overruns %lld states %lld commands %lld "
                "energy %+.6e J %s\n", s->sc->lcm.prefix, lag_sim_time(&s->sim), s->rtf,
                (long long)s->overruns, (long long)s->states_published, (long long)s->accepted,
                lag_sim_energy(&s->sim), rt_run_name(s->run));
    }
}

void rt_signal(rt_server *s, int signo)
{
    if (signo == SIGUSR1 || signo == SIGUSR2) {
        s->want_status = true;
        s->report_line = true;
        return;
    }
    if (!s->stop) {
        s->stop = true;
        s->stop_reason = RT_STOP_SIGNAL;
        s->stop_signal = signo;
    }
}

static const char *signal_name(int signo)
{
    switch (signo) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGQUIT: return "SIGQUIT";
    case SIGUSR1: return "SIGUSR1";
    case SIGUSR2: return "SIGUSR2";
    }
    return "signal";
}

void rt_finish(rt_server *s)
{
    switch (s->stop_reason) {
    case RT_STOP_SIGNAL:
        eventf(s, "stop", (double)s->stop_signal, "%s (%d): stopping", signal_name(s->stop_signal),
               s->stop_signal);
        break;
    case RT_STOP_DURATION:
        eventf(s, "stop", lag_sim_time(&s->sim), "duration reached");
        break;
    default:
        eventf(s, "stop", 0, "stopping");
        break;
    }
    publish_status(s);
    if (s->live_line) rt_term_line(s, true);
}

/* ---------------------------------------------------------------- the loop */
typedef struct rt_io {
    int in_fd, timer_fd, sig_fd;
    int watch_fd; /* the state URL's receive socket (the plant watch); -1 for memq:// */
    int64_t armed_ns; /* what the timer is armed at (INT64_MAX: disarmed) */
} rt_io;

/* Waits until `wake` (absolute), a signal or an LCM message, then handles the signals
 * and the messages that arrived (at most RT_DRAIN_MAX). */
static void wait_and_handle(rt_server *s, rt_io *io, int64_t wake)
{
    struct timespec zero = {0, 0}, *tmo = NULL;
    if (wake <= rt_mono_ns()) {
        tmo = &zero;
    } else if (wake != io->armed_ns) {
        struct itimerspec its = {{0, 0}, {0, 0}};
        if (wake != INT64_MAX) {
            its.it_value.tv_sec = (time_t)(wake / RT_NS_PER_S);
            its.it_value.tv_nsec = (long)(wake % RT_NS_PER_S);
        }
        if (timerfd_settime(io->timer_fd, TFD_TIMER_ABSTIME, &its, NULL) == 0) io->armed_ns = wake;
        else tmo = &zero; /* cannot arm: do not sleep past the deadline */
    }
    struct pollfd pf[4] = {{io->in_fd, POLLIN, 0}, {io->timer_fd, POLLIN, 0},
                           {io->sig_fd, POLLIN, 0}, {io->watch_fd, POLLIN, 0}};
    int np = ppoll(pf, io->watch_fd >= 0 ? 4 : 3, tmo, NULL);
    s->now = rt_mono_ns();
    if (np < 0) {
        if (errno == EINTR) return;
        perror("lagsimd: poll");
        s->stop = true;
        s->stop_reason = RT_STOP_ERROR;
        return;
    }
    if (pf[2].revents & POLLIN) {
        struct signalfd_siginfo si;
        for (int k = 0; k < RT_SIGNALS_PER_WAKE; k++) {
            if (read(io->sig_fd, &si, sizeof si) != (ssize_t)sizeof si) break;
            rt_signal(s, (int)si.ssi_signo);
        }
    }
    if (pf[1].revents & POLLIN) {
        uint64_t expirations;
        if (read(io->timer_fd, &expirations, sizeof expirations) < 0) expirations = 0;
        io->armed_ns = INT64_MAX;
    }
    if (pf[0].revents & POLLIN) {
        for (int k = 0; k < RT_DRAIN_MAX && !s->stop; k++)
            if (lcm_handle_timeout(s->lcm_in, 0) <= 0) break;
    }
    if (io->watch_fd >= 0 && (pf[3].revents & POLLIN)) {
        for (int k = 0; k < 16 && !s->stop; k++)
            if (lcm_handle_timeout(s->lcm, 0) <= 0) break;
    }
    s->now = rt_mono_ns();
}

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

lag_result lagsimd_realtime(const lag_scene *sc, const lagsimd_opts *o)
{
    static rt_server srv; /* large (encode buffer): static, one server per process */
    rt_server *s = &srv;
    bool quiet = o && o->quiet;
    char err[512];

    /* signals through a signalfd: blocked before LCM starts any thread */
    sigset_t sigs, old_mask;
    handled_signals(&sigs);
    sigprocmask(SIG_BLOCK, &sigs, &old_mask);
    struct sigaction ign = {.sa_handler = SIG_IGN}, old_pipe;
    sigemptyset(&ign.sa_mask);
    sigaction(SIGPIPE, &ign, &old_pipe);
    rt_io io = {-1, -1, -1, -1, INT64_MAX};
    int rc = LAGSIMD_EXIT_OK;
    bool opened = false;

    io.sig_fd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    io.timer_fd = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
    if (io.sig_fd < 0 || io.timer_fd < 0) {
        perror("lagsimd: signalfd/timerfd");
        rc = LAGSIMD_EXIT_RUNTIME;
        goto out;
    }
    /* everything that can fail on a bad scene fails before LCM is touched */
    rc = rt_open(s, sc, o, rt_mono_ns(), quiet, err, sizeof err);
    if (rc != LAGSIMD_EXIT_OK) {
        fprintf(stderr, "lagsimd: %s\n", err);
        goto out;
    }
    /* LCM: publishing on the state URL, receiving on the command URL */
    opened = true;
    rc = rt_bus_open(s, err, sizeof err);
    if (rc != LAGSIMD_EXIT_OK) {
        fprintf(stderr, "lagsimd: %s\n", err);
        goto out;
    }
    s->live_line = isatty(STDERR_FILENO) && !quiet;
    io.in_fd = lcm_get_fileno(s->lcm_in);
    if (s->lcm != s->lcm_in) io.watch_fd = lcm_get_fileno(s->lcm);

    s->now = rt_mono_ns();
    s->discard = false;
    rt_begin(s);
    while (!s->stop) {
        wait_and_handle(s, &io, rt_next_wake(s));
        rt_process(s);
    }
    rt_finish(s);
    if (rt_log_end(s) != 0 && rc == LAGSIMD_EXIT_OK) rc = LAGSIMD_EXIT_RUNTIME; /* --log lost records */
out:
    rt_log_end(s); /* --log opened, then the start failed */
    if (opened) rt_bus_close(s);
    if (io.timer_fd >= 0) close(io.timer_fd);
    if (io.sig_fd >= 0) close(io.sig_fd);
    sigaction(SIGPIPE, &old_pipe, NULL);
    sigprocmask(SIG_SETMASK, &old_mask, NULL);
    return rc;
}
