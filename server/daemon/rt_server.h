/*
 * One plant of the real-time LCM server (realtime.c) and the state it keeps itself: the run,
 * the control period in progress, the commands held, the answers owed, the counters that
 * status publishes. Everything else is a part the loop holds and passes what it needs,
 * each with its own header and struct, none of which includes this one:
 *
 *   rt_bus.h       LCM, subscriptions, channels, the encode buffer, the plant watch
 *   rt_publish.h   what is published, through one place each: events and their
 *                  buckets, states (the last as sent), the scene, statuses, the answers
 *                  owed
 *   rt_control.h   the control requests: checked, their changes to the scene made
 *   rt_wire.h      the encoders of what is published (on the bus and the log)
 *   rt_record.h    --log: its clock, the sample of refused messages, its notes
 *   rt_term.h      the terminal: event lines and the live line
 *   rt_wait.h      what the plant waits for, and its lines
 *   rt_lockstep.h  the state waited on, its timeout and its copies
 *   rt_command.h   what a command must be to be applied (no state)
 *   rt_estimate.h  the live error estimate
 *   rt_io.h        the wait (the loop's, host.c's): signalfd, timerfd, epoll
 *   rt_pace.h      deadlines and token buckets (pure arithmetic)
 *   live_set.h     the changes made while running (SET, kicks)
 *
 * Everything the stepping path touches lives in this struct, allocated once per plant
 * (rt_plant_new): fixed-size arrays, one encode buffer, no malloc.
 */
#ifndef LAGSIMD_RT_SERVER_H
#define LAGSIMD_RT_SERVER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <lcm/lcm.h>
#include "daemon.h"
#include "live_set.h"
#include "realtime.h"
#include "lagsim_bus.h"
#include "lagsim_wire.h"
#include "rt_bus.h"
#include "rt_command.h"
#include "rt_control.h"
#include "rt_estimate.h"
#include "rt_lockstep.h"
#include "rt_pace.h"
#include "rt_publish.h"
#include "rt_record.h"
#include "rt_term.h"
#include "rt_wait.h"
#include "rt_wire.h"

typedef struct rt_server {
    const lag_scene *sc;
    const lagsimd_opts *opts;
    const lag_model_info *info;
    lag_sim sim;
    int nq;

    /* the loop's clock: CLOCK_MONOTONIC ns, read once per wake-up (tests set it by hand);
     * every decision of the loop, the handlers and the parts uses it */
    int64_t now;

    /* the parts */
    rt_bus bus;                /* LCM, channels, the plant watch (rt_bus.h) */
    rt_record rec;             /* --log (rt_record.h) */
    rt_term term;              /* stderr (rt_term.h) */
    rt_wait wait;              /* what the plant waits for (rt_wait.h) */
    rt_lockstep ls;            /* lockstep's wait for an answer (rt_lockstep.h) */
    rt_estimate est;           /* the live error estimate (rt_estimate.h) */
    rt_pace pace;              /* pacing of periods (realtime) and of the paused
                                * republication (realtime, fast) */
    rt_pub pub;                /* what is published, the answers owed (rt_publish.h) */
    rt_control ctl;            /* control requests, the changes made while running and
                                * the reference they give (rt_control.h) */

    /* run state */
    rt_run run;
    int64_t pending_steps;     /* STEP N: periods still to advance while paused */
    bool stop;                 /* signal, --duration reached, or a fatal error */
    rt_stop stop_reason;
    int stop_signal;
    int64_t stop_tick;         /* --duration in ticks, 0 = none: of the whole run, resets
                                * included (ticks_before_reset + sim.tick) */
    int64_t ticks_before_reset; /* ticks run before the last reset (RESET, RESET_TO) */

    /* the control period in progress: a period of many ticks runs in chunks of at most
     * tick_budget ticks per wake-up, so that signals and LCM are served in between */
    int64_t period_left;       /* ticks of it still to run; 0 = between periods */
    int64_t tick_budget;       /* ticks one wake-up may advance */
    double period_us;          /* compute time of the period so far */
    int64_t period_ns;         /* wall ns per control period */
    bool restart_pace;         /* deadlines restart from now at the next wake-up */

    /* commands: zero-order hold and watchdog */
    double held[LAG_MAX_DOF];  /* efforts the controller asked for */
    bool have_command;         /* a good command arrived since start/reset */
    int64_t command_tick;      /* sim tick at which it arrived */
    bool watchdog_tripped;
    char last_reject[LAG_WIRE_TEXT_LEN];  /* why the last command was rejected (not stale) */

    /* counters published in status */
    int64_t overruns;
    int64_t overrun_bursts;
    int64_t accepted;
    int64_t rejected[RT_REJ_COUNT];
    int64_t stale[RT_STALE_COUNT]; /* rejected[RT_REJ_STALE] by kind (the waits say them) */
    int64_t watchdog_trips;
    int64_t lockstep_timeouts;
    int64_t commands_ignored;  /* answers to a state already answered */
    int64_t late_answers;      /* lockstep: answers to a state already answered that came
                                * RT_COPY_LATE_NS or more after its first, or to a state
                                * older than the last answered (the law run again on each
                                * copy: the copy rule's hint, said once) */
    bool copy_rule_said;
    int64_t numeric_faults;
    int64_t effect_events_dropped; /* sim.events_dropped already reported */
    int64_t plant_conflicts;   /* scenes of another plant heard on this prefix while running */

    /* timing */
    int64_t start_ns;
    double step_us_max;
    double step_us_sum;        /* since the last status */
    int64_t step_us_n;
    int64_t ticks_since_status;/* ticks advanced since the last status (resets included) */
    int64_t last_status_ns;
    int64_t status_period_ns;
    int64_t next_status_ns;
    int64_t next_line_ns;
    double rtf;                /* real-time factor of the last status period */
    bool report_line;          /* SIGUSR1/SIGUSR2: one status line on stderr */
} rt_server;

/* realtime.c: the server in pieces (rt_plant_* in realtime.h string them together for
 * the loop of host.c; tests and the fuzz target drive them with their own clock and LCM,
 * e.g. memq://). rt_next_wake, rt_process and rt_signal: realtime.h. */
/* Checks the scene's real-time settings and initializes the sim, at clock `now`; no LCM
 * yet. Settings the loop clamps are said on stderr unless quiet. Returns 0, or an exit
 * code (2: bad scene or --duration) with a message in err. */
int rt_open(rt_server *s, const lag_scene *sc, const lagsimd_opts *o, int64_t now, bool quiet,
            char *err, size_t errlen);
/* Publishes on `out` and subscribes to _COMMAND and _CONTROL on `in` (the same lcm_t for
 * memq://; the caller owns both and destroys them after rt_close). Returns 0, or an exit
 * code with a message in err. */
int rt_attach(rt_server *s, lcm_t *out, lcm_t *in, char *err, size_t errlen);
/* Publishes the scene, a start event, the initial state and a status; deadlines start. */
void rt_begin(rt_server *s);
/* A stop event and the final status. */
void rt_finish(rt_server *s);
/* Closes --log (if still open) and unsubscribes (the caller destroys its lcm). */
void rt_close(rt_server *s);

/* The LCM handlers' work: a command or a control request, at s->now. */
void rt_handle_command(rt_server *s, const uint8_t *data, size_t len);
void rt_handle_control(rt_server *s, const uint8_t *data, size_t len);
/* A scene heard on this prefix (rt_bus_foreign_scene judges it). Another plant's, while
 * running: the daemon runs on and reports the conflict: counted (status
 * plant_conflicts), a plant_conflict event and a line on stderr (even with -q), both at
 * most once per RT_CONFLICT_EVERY_S. */
void rt_handle_scene(rt_server *s, const uint8_t *data, size_t len);

#endif
