/*
 * lagsimd's real-time LCM server. The loop is a few lines over three functions, as in
 * redis's ae.c:
 *
 *     while not stopped:
 *         wake = rt_next_wake(s)    the earliest thing due (a deadline, a status, an
 *                                   answer the rate limit holds back); now if busy
 *         rt_io_wait(io, wake)      ppoll on the LCM socket, a signalfd and a timerfd
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
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lagsim_clock.h"
#include "live_set.h"
#include "rt_io.h"
#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"

#define RT_TICK_BUDGET 4096       /* ticks advanced per wake-up at most */
#define RT_LINE_NS 250000000LL    /* live status line refresh */
#define RT_STATUS_NS_MIN 10000000LL /* periodic status at most every 10 ms (100 Hz) */

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
    return s->pub.want_state && s->run != RT_FAULT && s->period_left == 0;
}

static void event(rt_server *s, const char *kind, const char *joint, double value,
                  const char *detail)
{
    rt_pub_event(&s->pub, kind, joint, value, detail);
}

static void publish_scene(rt_server *s)
{
    rt_pub_scene(&s->pub, s->sc, s->info);
}

/* Lockstep, paused: a state published and waited on (the last of a STEP, one after a
 * reset) still goes out again until an answer to it came, so that a lost state or answer
 * is not left unanswered while paused (lagsim-sweep waits for that answer between runs). */
static bool paused_copies(const rt_server *s)
{
    return s->run == RT_PAUSED && s->pending_steps == 0 && s->ls.waiting && !s->ls.answered;
}

/* What the plant waits for now (RT_WAIT_NONE: the run advances), with what came so far:
 * what the waits say (rt_wait.h). */
static rt_wait_seen wait_seen(const rt_server *s)
{
    rt_wait_seen w = {RT_WAIT_NONE, 0, s->rejected, s->bus.commands_wrong_port, s->last_reject,
                      &s->bus.foreign, false, s->stale};
    bool lockstep = s->sc->realtime.mode == LAG_RT_LOCKSTEP;
    if (s->run == RT_FAULT) w.kind = RT_WAIT_RESET;
    else if (s->run == RT_PAUSED && s->pending_steps == 0) {
        w.kind = RT_WAIT_RESUME;
        w.owed = paused_copies(s);
        w.t = w.owed ? s->ls.waiting_time : 0;
    }
    else if (s->run == RT_WAITING && s->pending_steps == 0 && !s->have_command) {
        w.kind = RT_WAIT_FIRST;
        w.t = lag_sim_time(&s->sim);
    } else if (lockstep && s->ls.waiting && !s->ls.answered &&
               (s->run == RT_RUNNING || s->run == RT_WAITING || s->pending_steps > 0)) {
        w.kind = RT_WAIT_ANSWER;
        w.t = s->ls.waiting_time;
    }
    return w;
}

static void wait_update(rt_server *s)
{
    rt_wait_seen w = wait_seen(s);
    rt_wait_update(&s->wait, s->now, &w, &s->term);
}

/* The live line's content (rt_term.h), asked when it is drawn. */
static void term_view(void *ctx, rt_term_view *v)
{
    const rt_server *s = ctx;
    *v = (rt_term_view){s->sc->lcm.prefix, lag_sim_time(&s->sim), s->rtf,
                        lag_sim_energy(&s->sim), s->sim.q, s->nq,
                        s->have_command && !s->watchdog_tripped, s->accepted, s->overruns,
                        rt_run_name(s->run)};
}

/* Every state goes out through here: in lockstep a published state is waited on. */
static void publish_state(rt_server *s)
{
    rt_pub_state(&s->pub, s->info, &s->ctl.ref);
    if (s->sc->realtime.mode == LAG_RT_LOCKSTEP)
        rt_lockstep_published(&s->ls, s->pub.generation, lag_sim_time(&s->sim), s->now);
}

/* Lockstep, while a state is waited on and no answer to it has come: the same state goes
 * out again, byte for byte, at the gaps rt_lockstep.c explains. */
static void lockstep_retry(rt_server *s)
{
    if (s->pub.state_len == 0 || !rt_lockstep_retry(&s->ls, s->now)) return;
    rt_pub_state_again(&s->pub);
}

/* The status: the sim's figures (rt_status_base), the loop's counters, what the plant
 * waits for; the RTF over the window since the last one. */
static void status_message(const rt_server *s, int64_t now, lag_wire_status *m)
{
    double wall = (double)(now - s->last_status_ns) * 1e-9;
    double sim_adv = (double)s->ticks_since_status * s->sc->sim.integrator.dt;
    rt_status_base(m, &s->sim, s->sc);
    m->wall_time = (double)(now - s->start_ns) * 1e-9;
    /* a window shorter than 50 ms (a status on request, the final one) is too short to
     * measure: it repeats the last figure */
    m->rtf = s->run != RT_RUNNING ? 0.0 : wall < 0.05 ? s->rtf : sim_adv / wall;
    m->overruns = s->overruns;
    m->step_time_max_us = s->step_us_max;
    m->step_time_mean_us = s->step_us_n > 0 ? s->step_us_sum / (double)s->step_us_n : 0.0;
    snprintf(m->run_state, sizeof m->run_state, "%s", rt_run_name(s->run));
    m->commands_accepted = s->accepted;
    m->rejected_unknown_joint = s->rejected[RT_REJ_UNKNOWN_JOINT];
    m->rejected_unactuated = s->rejected[RT_REJ_UNACTUATED];
    m->rejected_nonfinite = s->rejected[RT_REJ_NONFINITE];
    m->rejected_bad_length = s->rejected[RT_REJ_BAD_LENGTH];
    m->rejected_undecodable = s->rejected[RT_REJ_UNDECODABLE];
    m->rejected_stale = s->rejected[RT_REJ_STALE];
    m->rejected_effort_limit = s->rejected[RT_REJ_EFFORT_LIMIT];
    m->controls_rejected = s->ctl.controls_rejected;
    m->watchdog_tripped = s->watchdog_tripped;
    m->watchdog_trips = s->watchdog_trips;
    m->lockstep_timeouts = s->lockstep_timeouts;
    m->numeric_faults = s->numeric_faults;
    m->overrun_bursts = s->overrun_bursts;
    m->states_published = s->pub.states_published;
    m->lockstep_retries = s->pub.lockstep_retries;
    m->commands_ignored = s->commands_ignored;
    m->plant_conflicts = s->plant_conflicts;
    rt_wait_seen w = wait_seen(s);
    m->waiting_s = rt_wait_describe(&s->wait, s->now, &w, m->waiting_for, sizeof m->waiting_for,
                                    m->waiting_got, sizeof m->waiting_got);
    m->commands_wrong_port = s->bus.commands_wrong_port;
    const rt_estimate *e = &s->est;
    m->error_estimate = e->err;
    snprintf(m->error_joint, sizeof m->error_joint, "%s",
             e->joint >= 0 && e->joint < s->nq ? s->info->joint_names[e->joint] : "");
    m->error_warnings = e->warnings;
}

/* Every status goes out through here; the RTF's window starts again (unless it was too
 * short to measure while running). */
static void publish_status(rt_server *s)
{
    int64_t now = lag_clock_mono_ns();
    lag_wire_status m;
    status_message(s, now, &m);
    rt_pub_status(&s->pub, &m);
    s->rtf = m.rtf;
    if ((double)(now - s->last_status_ns) * 1e-9 < 0.05 && s->run == RT_RUNNING) return;
    s->last_status_ns = now;
    s->ticks_since_status = 0;
    s->step_us_sum = 0;
    s->step_us_n = 0;
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
    s->ls.waiting = false;
    s->pub.want_state = false;
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
    rt_pub_limited(&s->pub, RT_EV_NUMERIC_FAULT, "", lag_sim_time(&s->sim),
                  "fault (efforts held: %s): %s; paused until reset or reset_to",
                  n ? eff : "none", why);
    s->pub.want_status = true;
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
        rt_pub_event_at(&s->pub, ev.t, lag_event_kind_name(ev.kind), joint, ev.value, detail, true);
    }
    if (s->sim.events_dropped > s->effect_events_dropped) {
        int64_t lost = s->sim.events_dropped - s->effect_events_dropped;
        rt_pub_limited(&s->pub, RT_EV_EVENTS_DROPPED, "", (double)lost,
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
        rt_pub_limited(&s->pub, RT_EV_WATCHDOG_TRIP, "", age,
                      "no command for %.6g s of sim time (command_timeout %.6g s): efforts zeroed",
                      age, sc->realtime.command_timeout);
    }
    lag_sim_set_input(&s->sim, s->held);
    /* --log with an actuator lag: the input this period runs with */
    rt_log_input(&s->rec, s->now, &s->sim, s->info);
    s->period_left = sc->ticks_per_period;
    s->period_us = 0;
    /* the live error estimate: a period run in one piece (nothing changes the sim between
     * its chunks then) is run again after it is published, from a copy of its start */
    rt_estimate_arm(&s->est, &s->sim, s->period_left <= budget);
}

/* The live error estimate of the period just published (rt_estimate.h): its error,
 * largest over the joints, goes in status; over the scene's budget, an error_estimate
 * event naming the joint. */
static void estimate_error(rt_server *s)
{
    if (!rt_estimate_period(&s->est, &s->sim)) return;
    const int j = s->est.joint;
    const double err = s->est.err, budget = s->est.budget;
    rt_pub_limited(&s->pub, RT_EV_ERROR_ESTIMATE, s->info->joint_names[j], err,
                  "the integration added an estimated %.3g to %s over the period ending at "
                  "t = %.9g s, %.3g times its budget %.3g (integrator.error %g over %g s)",
                  err, s->info->joint_names[j], lag_sim_time(&s->sim), err / budget, budget,
                  s->sc->accuracy.error, s->sc->accuracy.horizon);
}

/* The period is complete: its state goes out; STEP and --duration are booked. */
static void period_end(rt_server *s)
{
    if (s->period_us > s->step_us_max) s->step_us_max = s->period_us;
    s->step_us_sum += s->period_us;
    s->step_us_n++;
    publish_state(s);
    if (s->pending_steps > 0 && --s->pending_steps == 0) {
        rt_pub_limited(&s->pub, RT_EV_STEP_DONE, "", 0, "step done: paused");
        s->pub.want_status = true;
    }
    /* --duration: the sim time this run has advanced, a reset's sim time starting over
     * or not (docs/server.md) */
    if (s->stop_tick > 0 && rt_sat_add(s->ticks_before_reset, s->sim.tick) >= s->stop_tick) {
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
    int64_t t0 = lag_clock_mono_ns(), tick0 = s->sim.tick;
    lag_result r = lag_sim_advance_within(&s->sim, n, s->sim.tick + s->period_left);
    s->period_us += (double)(lag_clock_mono_ns() - t0) * 1e-3;
    s->rec.ticks += s->sim.tick - tick0; /* the log's clock */
    s->period_left -= n;
    s->ticks_since_status += n;
    publish_effect_events(s);
    if (r != LAG_OK || !state_finite(&s->sim)) {
        rt_estimate_disarm(&s->est);
        enter_fault(s, r);
        return RT_P_FAULT;
    }
    if (s->period_left > 0) return RT_P_MORE;
    period_end(s);
    estimate_error(s); /* after the state went out */
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
        rt_pub_limited(&s->pub, RT_EV_OVERRUN_BURST, "", (double)d.due,
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
    return s->rec.log && s->sc->realtime.mode != LAG_RT_REALTIME && !rt_log_room(s->rec.log);
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
    if (paused_copies(s)) {
        lockstep_retry(s); /* paused: the state waited on, until an answer to it came */
        return;
    }
    if (s->run == RT_WAITING && s->pending_steps == 0) {
        if (s->ls.waiting && rt_lockstep_timed_out(&s->ls, s->now))
            s->pub.want_state = true; /* the same state again, through the state bucket */
        return;
    }
    if (!active(s) || !s->ls.waiting) return;
    if (!s->ls.answered && rt_lockstep_timed_out(&s->ls, s->now)) {
        if (s->pending_steps > 0) { /* STEP N: a period without a command, as asked */
            s->ls.answered = true;
        } else {
            s->lockstep_timeouts++;
            s->run = RT_WAITING;
            rt_pub_limited(&s->pub, RT_EV_LOCKSTEP_TIMEOUT, "", s->ls.waiting_time,
                          "no command answered sim time %.9g s within %.6g s: waiting for one "
                          "(the state is published again every %.6g s)", s->ls.waiting_time,
                          s->sc->realtime.lockstep_timeout, s->sc->realtime.lockstep_timeout);
            s->pub.want_state = true;
            s->pub.want_status = true;
            return;
        }
    }
    if (!s->ls.answered) {
        lockstep_retry(s);
        return;
    }
    if (log_holds(s)) return;
    s->ls.waiting = false;
    int64_t budget = s->tick_budget;
    period_run(s, &budget);
}

/* ---------------------------------------------------------------- commands */
static void lockstep_rewait(rt_server *s);

/* A rejected command (rt_command.h's verdict): counted by reason, and a command_rejected
 * event (limited) whose detail says what was wrong and what would be accepted. */
static void reject(rt_server *s, const rt_verdict *v)
{
    const rt_reject why = v->why;
    const char *what = v->what; /* and the reason's name: within an event's detail */
    s->rejected[why]++;
    /* --log */
    rt_log_rx_fate(&s->rec, s->now, why == RT_REJ_UNDECODABLE ? RT_RX_UNDECODABLE : RT_RX_REFUSED);
    char detail[LAG_WIRE_TEXT_LEN];
    snprintf(detail, sizeof detail, "%s: %s", rt_reject_name[why], what);
    if (why != RT_REJ_STALE) memcpy(s->last_reject, detail, sizeof detail); /* waits say it */
    /* a flood is counted in status, not echoed one for one */
    rt_pub_limited(&s->pub, RT_EV_COMMAND_REJECTED, v->joint, v->value, "command rejected: %s", detail);
}

static void handle_command(rt_server *s, const uint8_t *data, size_t len);

/* --log: as received, once its fate is known (rt_log_rx_*) */
void rt_handle_command(rt_server *s, const uint8_t *data, size_t len)
{
    rt_log_rx_begin(&s->rec, s->bus.ch_command, data, len);
    handle_command(s, data, len);
    rt_log_rx_end(&s->rec, s->now);
}

/* A command is applied whole or not at all: it decodes, every name is known, actuated,
 * distinct, every effort finite and within the scene's realtime.effort_limit
 * (rt_command.h), and in lockstep it answers the state waited on. Its steps: */

/* A command of a generation other than the current one answers a state of an earlier run
 * or scene: never applied, in any mode (stale). Generation 0 answers no particular state:
 * applied in the realtime and fast modes, stale in lockstep (which needs the state). */
static bool command_of_now(rt_server *s, const lag_wire_joint_command *c)
{
    const int64_t now_gen = s->pub.generation;
    bool lockstep = s->sc->realtime.mode == LAG_RT_LOCKSTEP;
    if (c->generation == now_gen || (c->generation == 0 && !lockstep)) return true;
    rt_verdict v = {RT_REJ_STALE, "", c->sim_time, ""};
    s->stale[c->generation == 0 ? RT_STALE_NO_GENERATION : RT_STALE_GENERATION]++;
    if (c->generation == 0)
        snprintf(v.what, sizeof v.what, "generation 0 answers no state; lockstep advances on "
                 "the generation and sim_time of the state waited on (generation %lld)",
                 (long long)now_gen);
    else
        snprintf(v.what, sizeof v.what, "generation %lld, sim_time %.9g (in value): a state "
                 "of an earlier run or scene; accepted: generation %lld", (long long)c->generation,
                 c->sim_time, (long long)now_gen);
    reject(s, &v);
    return false;
}

/* The copy rule (docs/protocol.md, Lockstep: run the law once per state; answer a copy,
 * the same generation and sim_time sent again until answered, at once with the command
 * already sent). A controller that runs its law on every copy answers the copies one law time
 * apart, long after the state's first answer (a controller that keeps the rule answers
 * the copies it got meanwhile at once, within a millisecond or so), and falls behind: its
 * answers to copies come late, and those to older states stale. Once they number 10 and
 * at least one for every two states answered, an event (and so a line on the terminal)
 * says so, once. */
#define RT_COPY_LATE_NS (20 * RT_NS_PER_S / 1000)
static void late_answer(rt_server *s)
{
    if (++s->late_answers < 10 || 2 * s->late_answers < s->accepted || s->copy_rule_said) return;
    s->copy_rule_said = true;
    rt_pub_eventf(&s->pub, "copy_rule", (double)s->late_answers, "the law seems to run again "
                  "on copies: %lld answers came 20 ms or more after their state was answered "
                  "(%lld states answered); answer a copy (same generation, sim_time) at once "
                  "with the command sent (docs/protocol.md: the copy rule)", (long long)s->late_answers,
                  (long long)s->accepted);
    s->pub.want_status = true;
}

/* Lockstep: the command answers the state waited on (or, not running, the state the sim
 * holds), known by its generation and sim time. A second answer to a state already
 * answered (the controller got it twice, a retry crossing its first answer) is not
 * applied: counted, no event. Else stale. */
static bool command_in_step(rt_server *s, const lag_wire_joint_command *c)
{
    if (!command_of_now(s, c)) return false;
    if (s->sc->realtime.mode != LAG_RT_LOCKSTEP) return true;
    if (rt_lockstep_repeated(&s->ls, c->generation, c->sim_time)) {
        s->commands_ignored++;
        rt_log_rx_fate(&s->rec, s->now, RT_RX_REFUSED); /* --log: a sample of them */
        if (s->now - s->ls.answered_ns >= RT_COPY_LATE_NS) late_answer(s);
        return false;
    }
    if (s->ls.have_answered && c->sim_time < s->ls.answered_time) late_answer(s);
    bool waited_on = rt_lockstep_is_waited(&s->ls, c->generation, c->sim_time);
    if (waited_on || (s->run != RT_RUNNING && c->sim_time == lag_sim_time(&s->sim))) return true;
    rt_verdict v = {RT_REJ_STALE, "", c->sim_time, ""};
    s->stale[RT_STALE_SIM_TIME]++;
    if (s->ls.waiting)
        snprintf(v.what, sizeof v.what, "sim_time %.9g (in value); accepted: %.9g, the state "
                 "waited on", c->sim_time, s->ls.waiting_time);
    else
        snprintf(v.what, sizeof v.what, "sim_time %.9g (in value); no state is waited on (the "
                 "next one's sim_time will be)", c->sim_time);
    reject(s, &v);
    return false;
}

/* The efforts are held from now on; a run waiting for a command goes on, a tripped
 * watchdog clears. */
static void command_apply(rt_server *s, const lag_wire_joint_command *c, const int *idx)
{
    for (int i = 0; i < c->num_joints; i++) s->held[idx[i]] = c->effort[i];
    s->accepted++;
    s->have_command = true;
    s->command_tick = s->sim.tick;
    rt_lockstep_answer(&s->ls, c->generation, c->sim_time, s->now);
    if (s->run == RT_WAITING) {
        /* the command the run was waiting for: it goes on from here */
        s->run = RT_RUNNING;
        s->restart_pace = true; /* realtime: deadlines start now, not at the daemon's start */
        if (s->sc->realtime.mode == LAG_RT_LOCKSTEP && !s->ls.answered) lockstep_rewait(s);
        rt_pub_limited(&s->pub, RT_EV_RESUME, "", lag_sim_time(&s->sim),
                      "a command arrived at sim time %.9g s: running", lag_sim_time(&s->sim));
        s->pub.want_status = true;
    }
    if (s->watchdog_tripped) {
        s->watchdog_tripped = false;
        rt_pub_limited(&s->pub, RT_EV_WATCHDOG_CLEAR, "", 0, "a good command arrived: efforts held again");
    }
}

static void handle_command(rt_server *s, const uint8_t *data, size_t len)
{
    lag_wire_joint_command c;
    rt_verdict v;
    if (!rt_command_decode(s->info, s->nq, data, len, &c, &v)) {
        reject(s, &v);
        return;
    }
    /* lockstep: an answer to the state waited on, good or not, came: it needs no copies */
    rt_lockstep_heard(&s->ls, c.generation, c.sim_time);
    int idx[LAG_MAX_DOF];
    if (!rt_command_entries(s->info, s->nq, s->sc->realtime.effort_limit, &c, idx, &v)) {
        reject(s, &v);
        return;
    }
    if (!command_in_step(s, &c)) return;
    command_apply(s, &c, idx);
}

/* ---------------------------------------------------------------- control requests */
/* What a control request asks of the run (rt_control.c checked it and made its changes
 * to the scene); a status follows where it says (want_status). */
static void do_reset(rt_server *s, const rt_act *a)
{
    if (s->ctl.live.nk > 0) { /* sim time starts over: the kicks are the old run's */
        char detail[96];
        snprintf(detail, sizeof detail, "a reset ends the %d kick(s) of the run before it",
                 s->ctl.live.nk);
        live_kicks_clear(&s->ctl.live, &s->sim);
        event(s, "kicks_cleared", "", 0, detail); /* --replay applies it here */
    }
    s->ticks_before_reset = rt_sat_add(s->ticks_before_reset, s->sim.tick); /* --duration */
    lag_sim_reset(&s->sim, a->to ? a->q : NULL, a->to ? a->qd : NULL);
    s->effect_events_dropped = s->sim.events_dropped;
    for (int i = 0; i < s->nq; i++) s->held[i] = 0.0;
    s->have_command = false;
    s->watchdog_tripped = false;
    s->pending_steps = 0;
    s->period_left = 0;
    s->ls.waiting = false; /* lockstep: the new state is waited on once it is published */
    s->ls.have_answered = false;
    if (a->wait) { /* as realtime.start: first_command: the next command starts the run */
        s->run = RT_WAITING;
        s->restart_pace = true; /* the state at t = 0 is republished from now on */
    } else if (s->run == RT_FAULT) {
        s->run = RT_PAUSED;
    }
    char kept[200];
    live_set_describe(&s->ctl.live, kept, sizeof kept);
    /* which changes made while running the reset keeps (a reset with count 1 keeps none) */
    rt_pub_limited(&s->pub, RT_EV_RESET, "", 0, "%s: sim time 0, efforts zero, %s; %s%s%s", a->what,
                  s->run == RT_PAUSED    ? "paused (resume to run)"
                  : s->run == RT_WAITING ? "waiting for the first command (it, or resume, "
                                           "starts the run)"
                                         : "running",
                  kept[0] ? "keeps the changes made while running: " : "the scene file's values",
                  kept, kept[0] ? " (lagsimctl reset --scene, RESET count 1: the scene file's "
                                  "values)" : "");
    rt_pub_new_generation(&s->pub, s->sc, s->info); /* the scene, before the new state */
    s->pub.want_state = true;
    s->pub.want_status = true;
    wait_update(s); /* a wait for the first command begins now */
}

/* Lockstep, when the run goes on (resume, step): the state already published is waited
 * on afresh; if none is, it is published. */
static void lockstep_rewait(rt_server *s)
{
    if (s->sc->realtime.mode != LAG_RT_LOCKSTEP) return;
    if (s->ls.waiting) s->ls.wait_start_ns = s->now;
    else if (s->period_left == 0) s->pub.want_state = true;
}

static void run_pause(rt_server *s)
{
    s->run = RT_PAUSED;
    s->pending_steps = 0;
    s->restart_pace = true; /* the held state is republished from now on */
    rt_pub_limited(&s->pub, RT_EV_PAUSE, "", 0, "paused");
    s->pub.want_status = true;
}

static void run_resume(rt_server *s)
{
    s->run = RT_RUNNING;
    s->pending_steps = 0;
    s->restart_pace = true; /* deadlines restart from now */
    lockstep_rewait(s);
    rt_pub_limited(&s->pub, RT_EV_RESUME, "", 0, "running");
    s->pub.want_status = true;
}

/* STEP N: step_done (and its status) follow when the steps are done. */
static void run_step(rt_server *s, int64_t count)
{
    s->pending_steps = count;
    s->restart_pace = true; /* realtime: the first period ends one period from now */
    lockstep_rewait(s);
    rt_pub_limited(&s->pub, RT_EV_STEP, "", (double)count,
                  "stepping %lld control periods at the %s mode's pace", (long long)count,
                  lag_rt_mode_name(s->sc->realtime.mode));
}

static void run_act(rt_server *s, const rt_act *a)
{
    switch (a->kind) {
    case RT_ACT_NONE: return;
    case RT_ACT_PAUSE: run_pause(s); return;
    case RT_ACT_RESUME: run_resume(s); return;
    case RT_ACT_STEP: run_step(s, a->count); return;
    case RT_ACT_RESET: do_reset(s, a); return;
    }
}

/* --log: as received, once its fate is known (rt_log_rx_*) */
void rt_handle_control(rt_server *s, const uint8_t *data, size_t len)
{
    rt_log_rx_begin(&s->rec, s->bus.ch_control, data, len);
    const int64_t gen = s->pub.generation;
    rt_act a = rt_control_handle(&s->ctl, s->run, data, len);
    run_act(s, &a);
    /* lockstep: a state waited on and not answered belongs to the generation before a
     * SET; it is published again in the new one (an answer to the old one is stale) */
    if (s->pub.generation != gen && s->sc->realtime.mode == LAG_RT_LOCKSTEP &&
        s->ls.waiting && !s->ls.answered) {
        s->ls.waiting = false;
        s->pub.want_state = true;
    }
    rt_log_rx_end(&s->rec, s->now);
}

/* ---------------------------------------------------------------- one plant per prefix */
void rt_handle_scene(rt_server *s, const uint8_t *data, size_t len)
{
    if (!rt_bus_foreign_scene(&s->bus, data, len)) return;
    /* running: one datagram from any process must not stop a plant that may be driving an
     * experiment; the conflict is counted and said, rate-limited, and the run goes on */
    s->plant_conflicts++;
    rt_limit *l = &s->pub.lim_event[RT_EV_PLANT_CONFLICT];
    rt_pub_limited(&s->pub, RT_EV_PLANT_CONFLICT, "", (double)s->plant_conflicts,
                  "another plant publishes on prefix %s (%s): %lld such scenes so far (in "
                  "value); running on; one plant per prefix: stop the other, or give one "
                  "another lcm.prefix", s->sc->lcm.prefix, s->bus.other_plant,
                  (long long)s->plant_conflicts);
    if (l->suppressed == 0) { /* the event went out: the terminal hears it too, even with -q */
        if (s->opts && s->opts->quiet)
            fprintf(stderr, "lagsimd: another plant publishes on prefix %s (%s): %lld such "
                    "scenes so far; running on\n", s->sc->lcm.prefix, s->bus.other_plant,
                    (long long)s->plant_conflicts);
        s->pub.want_status = true;
    }
}

/* ---------------------------------------------------------------- the server in pieces */
/* What arrives on the bus comes back here (rt_bus_handlers). */
static void on_command(void *ctx, const uint8_t *data, size_t len)
{
    rt_handle_command(ctx, data, len);
}

static void on_control(void *ctx, const uint8_t *data, size_t len)
{
    rt_handle_control(ctx, data, len);
}

static void on_scene(void *ctx, const uint8_t *data, size_t len)
{
    rt_handle_scene(ctx, data, len);
}

static rt_bus_handlers handlers(rt_server *s)
{
    return (rt_bus_handlers){on_command, on_control, on_scene, s};
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

/* rt_open's steps. Everything that can fail on a bad scene fails before anything is
 * published: the scene's real-time settings, checked (2, with a message in err). */
static int open_check(const lag_scene *sc, char *err, size_t errlen)
{
    _Static_assert(LAG_SCENE_PREFIX_MAX + 10 == LCM_MAX_CHANNEL_NAME_LENGTH,
                   "the scene's prefix bound leaves room for _REFERENCE in an LCM channel name");
    _Static_assert(LAG_SCENE_PERIOD_TICKS_MAX == RT_MAX_RUN_TICKS,
                   "a period is at most as long as the longest run");
    lag_diag d; /* the scene's rules, one place for the loader and a scene built in code */
    if (lag_scene_check(sc, &d) != LAG_OK)
        return open_error(err, errlen, "bad scene: %s: %s", d.field, d.message);
    return LAGSIMD_EXIT_OK;
}

/* The clocks of the loop: settings it cannot honour as given are clamped, and said so. */
static void open_clocks(rt_server *s, bool quiet)
{
    const lag_scene *sc = s->sc;
    const double rate = sc->realtime.rate;
    const double period_s = (double)sc->ticks_per_period * sc->sim.integrator.dt;
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
    rt_lockstep_init(&s->ls, sc->realtime.lockstep_timeout, sc->realtime.lockstep_retry);
}

/* The parts: the bus's URLs and channels (by the rule every client follows,
 * lagsim_bus.h), the terminal, the waits, the log's bookkeeping; then --log itself, last:
 * nothing after it can fail. */
static int open_parts(rt_server *s, const lagsimd_opts *o, char *err, size_t errlen)
{
    const lag_scene *sc = s->sc;
    char berr[256];
    if (rt_bus_init(&s->bus, sc, berr, sizeof berr) != 0)
        return open_error(err, errlen, "bad scene: lcm.url: %s", berr);
    s->bus.now = &s->now;
    bool quiet = o && o->quiet; /* the terminal's and the log's -q */
    rt_term_init(&s->term, quiet, s->bus.ch_event, s->now);
    s->term.view = term_view;
    s->term.ctx = s;
    rt_wait_init(&s->wait, &s->bus.urls, sc->lcm.prefix, sc->realtime.mode == LAG_RT_LOCKSTEP);
    rt_record_init(&s->rec, sc->sim.integrator.dt, quiet, s->now);
    if (o && o->log) {
        s->rec.input = rt_actuator_lagged(&sc->sim.effects, s->nq);
        lag_bus_channel_name(s->rec.ch_input, sizeof s->rec.ch_input, sc->lcm.prefix,
                             LAG_BUS_INPUT);
        if (rt_record_open(&s->rec, sc, o, err, errlen) != 0) return LAGSIMD_EXIT_USAGE;
    }
    return LAGSIMD_EXIT_OK;
}

int rt_open(rt_server *s, const lag_scene *sc, const lagsimd_opts *o, int64_t now, bool quiet,
            char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    s->bus.rx_in.fd = s->bus.rx_watch.fd = -1; /* no socket yet (rt_bus_close) */
    s->sc = sc;
    s->opts = o;
    s->now = now;
    s->info = lag_model_info_get(sc->sim.model.kind);
    char serr[256];
    if (!s->info) return open_error(err, errlen, "bad scene: unknown model");
    if (lag_sim_init(&s->sim, &sc->sim, serr, sizeof serr) != LAG_OK)
        return open_error(err, errlen, "bad scene: %s", serr);
    int rc = open_check(sc, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) return rc;
    const double dt = sc->sim.integrator.dt;
    if (o && o->duration > 0 && !rt_ticks_for(o->duration, dt, &s->stop_tick))
        return open_error(err, errlen, "--duration %g s is more than 2^53 ticks of dt %g s "
                          "(the longest run whose sim time is exact)", o->duration, dt);
    open_clocks(s, quiet);
    s->nq = s->sim.nq;
    s->info = lag_sim_info(&s->sim); /* the joints published: a stick that may fly has h */
    rt_estimate_init(&s->est, lag_scene_estimate_every(sc), rt_error_budget(sc));
    s->tick_budget = RT_TICK_BUDGET;
    /* the publisher and the control requests, full buckets at `now` */
    rt_pub_init(&s->pub, &s->bus, &s->rec, &s->term, &s->now, &s->sim);
    rt_control_init(&s->ctl, sc, o, s->info, &s->sim, &s->pub, &s->rec, now);
    return open_parts(s, o, err, errlen);
}

int rt_attach(rt_server *s, lcm_t *out, lcm_t *in, char *err, size_t errlen)
{
    rt_bus_handlers h = handlers(s);
    return rt_bus_attach(&s->bus, out, in, &h, err, errlen);
}

void rt_close(rt_server *s)
{
    rt_log_end(&s->rec); /* a no-op when rt_plant_end has closed it already */
    rt_bus_detach(&s->bus);
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
    publish_scene(s);
    rt_pub_eventf(&s->pub, "start", 0, "%s, %s, dt %.6g s, control period %.6g s, mode %s, rate %.6g: %s",
           lag_model_info_get(sc->sim.model.kind)->name, lag_method_name(sc->sim.integrator.method), sc->sim.integrator.dt,
           (double)sc->ticks_per_period * sc->sim.integrator.dt,
           lag_rt_mode_name(sc->realtime.mode), sc->realtime.rate,
           s->run == RT_PAUSED    ? "paused at t = 0 (resume to run)"
           : s->run == RT_WAITING ? "waiting at t = 0 for the first command"
                                  : "running");
    publish_state(s); /* the initial state, t = 0 */
    wait_update(s); /* a wait for the first command begins now */
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
        if (paused_copies(s) && !s->ls.answer_heard) wake = min64(wake, s->ls.next_retry_ns);
        if ((act || s->run == RT_WAITING) && s->ls.waiting && !s->pub.want_state) {
            if (act && s->ls.answered && !log_holds(s)) return now;
            if (act && s->ls.answered) {
                wake = min64(wake, rt_sat_add(now, RT_LOG_HOLD_NS));
            } else {
                wake = min64(wake, rt_sat_add(s->ls.wait_start_ns, s->ls.wait_ns));
                if ((s->run == RT_RUNNING || s->pending_steps > 0) && !s->ls.answer_heard)
                    wake = min64(wake, s->ls.next_retry_ns);
            }
        }
        break;
    }
    if (state_wanted(s)) wake = min64(wake, rt_limit_ready(&s->pub.lim_state, now));
    if (s->pub.want_scene) wake = min64(wake, rt_limit_ready(&s->pub.lim_scene, now));
    if (s->pub.want_status) wake = min64(wake, rt_limit_ready(&s->pub.lim_status, now));
    if (s->term.live_line) wake = min64(wake, s->next_line_ns);
    wake = min64(wake, rt_wait_next(&s->wait));
    return wake;
}

/* What --log has to say (rt_log_check's notes) goes out as events. */
static void log_check(rt_server *s, bool running)
{
    rt_record_note notes[RT_RECORD_NOTES];
    int n = rt_log_check(&s->rec, s->now, running, notes);
    for (int k = 0; k < n; k++) event(s, notes[k].kind, "", notes[k].value, notes[k].detail);
}

/* A DESCRIBE is how a controller starts (it asks for the scene until it has it), so one
 * may come from a controller that subscribed after the state it is to answer went out,
 * while that state's copies are far apart (they double up to lockstep_timeout / 16: 225 s
 * for a kept lagsim-sweep pair's 3600 s). While a state is owed an answer and none was
 * heard, the scene's answer is followed by a copy of it, as paced as the scene's. */
static void state_after_scene(rt_server *s)
{
    if (s->sc->realtime.mode != LAG_RT_LOCKSTEP || s->pub.state_len == 0 || s->run == RT_FAULT)
        return;
    if (!s->ls.waiting || s->ls.answered || s->ls.answer_heard) return;
    rt_pub_state_again(&s->pub);
}

/* Answers held back by their bucket go out when it allows, one for many requests. */
static void flush_answers(rt_server *s)
{
    if (state_wanted(s) && rt_limit_ready(&s->pub.lim_state, s->now) <= s->now) {
        rt_limit_take(&s->pub.lim_state, s->now);
        publish_state(s);
    }
    if (s->pub.want_scene && rt_limit_ready(&s->pub.lim_scene, s->now) <= s->now) {
        rt_limit_take(&s->pub.lim_scene, s->now);
        publish_scene(s);
        s->pub.want_scene = false;
        state_after_scene(s);
    }
    if (s->pub.want_status && rt_limit_ready(&s->pub.lim_status, s->now) <= s->now) {
        rt_limit_take(&s->pub.lim_status, s->now);
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
    wait_update(s); /* what the plant waits for: a line every few seconds (rt_wait.c) */
    flush_answers(s);
    if (s->now >= s->next_status_ns) {
        publish_status(s);
        s->next_status_ns = rt_sat_add(s->next_status_ns, s->status_period_ns);
        if (s->next_status_ns <= s->now) s->next_status_ns = rt_sat_add(s->now, s->status_period_ns);
    }
    rt_term_tick(&s->term, s->now); /* -q: the losses' journal */
    if (s->term.live_line && s->now >= s->next_line_ns) {
        rt_term_line(&s->term, s->now, false);
        s->next_line_ns = rt_sat_add(s->now, RT_LINE_NS);
    }
    /* the log's clock stops while paused or in the fault state, not while waiting for a
     * command (docs/server.md): a wake-up during the wait must not change the stamps */
    log_check(s, active(s) || s->run == RT_WAITING);
    if (s->report_line) {
        s->report_line = false;
        if (s->opts && s->opts->quiet) return;
        fprintf(stderr, "lagsimd: %s t=%.3f s RTF %.3f overruns %lld states %lld commands %lld "
                "energy %+.6e J %s\n", s->sc->lcm.prefix, lag_sim_time(&s->sim), s->rtf,
                (long long)s->overruns, (long long)s->pub.states_published, (long long)s->accepted,
                lag_sim_energy(&s->sim), rt_run_name(s->run));
    }
}

void rt_signal(rt_server *s, int signo)
{
    if (signo == SIGUSR1 || signo == SIGUSR2) {
        s->pub.want_status = true;
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
        rt_pub_eventf(&s->pub, "stop", (double)s->stop_signal, "%s (%d): stopping", signal_name(s->stop_signal),
               s->stop_signal);
        break;
    case RT_STOP_DURATION:
        rt_pub_eventf(&s->pub, "stop", lag_sim_time(&s->sim), "duration reached");
        break;
    case RT_STOP_REMOVED:
        rt_pub_eventf(&s->pub, "stop", 0, "its scene file was removed from the host's directory: "
                      "stopping");
        break;
    case RT_STOP_CHANGED:
        rt_pub_eventf(&s->pub, "stop", 0, "its scene file changed: stopping, to start again "
                      "from it");
        break;
    default:
        rt_pub_eventf(&s->pub, "stop", 0, "stopping");
        break;
    }
    publish_status(s);
    rt_term_flush(&s->term, s->now);
    if (s->term.live_line) rt_term_line(&s->term, s->now, true);
}

/* ---------------------------------------------------------------- one plant of a loop */
rt_server *rt_plant_new(void)
{
    return calloc(1, sizeof(rt_server));
}

void rt_plant_free(rt_server *s)
{
    free(s);
}

int rt_plant_open(rt_server *s, const lag_scene *sc, const lagsimd_opts *o, int64_t now,
                  bool quiet, const char *who, char *err, size_t errlen)
{
    /* everything that can fail on a bad scene fails before LCM is touched */
    int rc = rt_open(s, sc, o, now, quiet, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) {
        rt_log_end(&s->rec); /* --log opened, then the start failed */
        return rc;
    }
    s->term.who = who;
    /* LCM: publishing on the state URL, receiving on the command URL */
    rt_bus_handlers h = handlers(s);
    s->bus.quiet = quiet;
    rc = rt_bus_open_start(&s->bus, &h, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) rt_log_end(&s->rec);
    return rc;
}

int64_t rt_plant_look_ns(const rt_server *s)
{
    return s->bus.urls.udpm ? RT_LOOK_MS * 1000000LL : 0;
}

int rt_plant_fd(const rt_server *s, rt_plant_input which)
{
    return rt_bus_fd(&s->bus, (rt_bus_input)which);
}

int rt_plant_drain(rt_server *s, rt_plant_input which, int64_t now, int max)
{
    s->now = now;
    if (s->stop) return 0;
    return rt_bus_read(&s->bus, (rt_bus_input)which, max);
}

int rt_plant_start(rt_server *s, int64_t now, bool live_line, char *err, size_t errlen)
{
    int rc = rt_bus_open_finish(&s->bus, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) {
        rt_log_end(&s->rec);
        return rc;
    }
    s->term.live_line = live_line;
    s->now = now;
    s->bus.discard = false;
    rt_begin(s);
    return LAGSIMD_EXIT_OK;
}

bool rt_plant_stopped(const rt_server *s)
{
    return s->stop;
}

void rt_plant_stop(rt_server *s, rt_stop why)
{
    if (s->stop) return;
    s->stop = true;
    s->stop_reason = why;
}

void rt_plant_set_now(rt_server *s, int64_t now)
{
    s->now = now;
}

lag_result rt_plant_end(rt_server *s, bool started)
{
    lag_result rc = LAGSIMD_EXIT_OK;
    if (started) rt_finish(s);
    /* --log lost records */
    if (rt_log_end(&s->rec) != 0) rc = LAGSIMD_EXIT_RUNTIME;
    rt_bus_close(&s->bus);
    return rc;
}

int64_t rt_plant_published(const rt_server *s)
{
    return s->pub.states_published + s->pub.lockstep_retries;
}

void rt_plant_input_limited(rt_server *s, int64_t times, const char *why)
{
    rt_pub_limited(&s->pub, RT_EV_INPUT_LIMITED, "", (double)times,
                   "%s on %s and %s: %s (%lld times so far, in value)", "more messages than "
                   "the plant can use", s->bus.ch_command, s->bus.ch_control, why,
                   (long long)times);
}

void rt_plant_foreign_limited(rt_server *s, const char *why)
{
    const rt_foreign *f = &s->bus.foreign;
    const rt_foreign_prefix *last = NULL;
    int64_t heard = 0;
    for (int i = 0; i < RT_FOREIGN_MAX; i++) {
        const rt_foreign_prefix *e = &f->p[i];
        heard += e->total;
        if (e->prefix[0] && (!last || e->heard > last->heard)) last = e;
    }
    int64_t lost = s->bus.rx_foreign.lost;
    rt_pub_limited(&s->pub, RT_EV_FOREIGN_LIMITED, "", (double)(heard + lost),
                   "other prefixes' requests on %s's command URL (last: %s%s): %lld read, "
                   "%lld dropped by the kernel; %s", s->bus.sc->lcm.prefix,
                   last ? last->prefix : "?", last && last->has_plant ? ", a plant elsewhere" : "",
                   (long long)heard, (long long)lost, why);
}

unsigned rt_plant_last(const rt_server *s, bool status, const uint8_t **data)
{
    const rt_sent *k = status ? &s->pub.last_status : &s->pub.last_scene;
    *data = k->buf;
    return k->len;
}
