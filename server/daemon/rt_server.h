/*
 * The real-time LCM server's private state, shared by realtime.c (the loop, pacing,
 * commands and control requests, decoded by the wire module) and rt_wire.c (encoding and
 * publishing of outgoing messages).
 *
 * Everything the stepping path touches lives in this struct, allocated once (on the
 * stack of lagsimd_realtime): fixed-size arrays, one encode buffer, no malloc.
 */
#ifndef LAGSIMD_RT_SERVER_H
#define LAGSIMD_RT_SERVER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <lcm/lcm.h>
#include "daemon.h"
#include "lagsim_wire.h"

#define RT_CHANNEL_MAX 96     /* prefix (< 64) + "_COMMAND" */
#define RT_BUF_SIZE LAG_WIRE_BUF_SIZE /* encode buffer: holds any message */

typedef enum rt_run { RT_RUNNING = 0, RT_PAUSED, RT_FAULT } rt_run;

/* Why a command was rejected; indexes rt_server.rejected. */
typedef enum rt_reject {
    RT_REJ_UNKNOWN_JOINT = 0,
    RT_REJ_UNACTUATED,
    RT_REJ_NONFINITE,
    RT_REJ_BAD_LENGTH,
    RT_REJ_UNDECODABLE,
    RT_REJ_STALE,             /* lockstep: answers a state other than the one waited on */
    RT_REJ_COUNT
} rt_reject;

typedef struct rt_server {
    const lag_scene *sc;
    const lagsimd_opts *opts;
    const lag_model_info *info;
    lcm_t *lcm;
    lag_sim sim;
    int nq;
    char ch_state[RT_CHANNEL_MAX], ch_command[RT_CHANNEL_MAX], ch_status[RT_CHANNEL_MAX],
        ch_event[RT_CHANNEL_MAX], ch_control[RT_CHANNEL_MAX], ch_scene[RT_CHANNEL_MAX];

    /* run state */
    rt_run run;
    int64_t pending_steps;     /* STEP N: periods still to advance while paused */
    bool stop;                 /* signal or --duration reached */
    int64_t stop_tick;         /* --duration in ticks, 0 = none */

    /* commands: zero-order hold and watchdog */
    double held[LAG_MAX_DOF];  /* efforts the controller asked for */
    bool have_command;         /* a good command arrived since start/reset */
    int64_t command_tick;      /* sim tick at which it arrived */
    bool watchdog_tripped;

    /* lockstep */
    double waiting_time;       /* sim_time of the state being waited on */
    bool waiting;              /* a state was published and not yet answered */
    bool answered;
    int64_t wait_start_ns;     /* CLOCK_MONOTONIC when the wait began */

    /* realtime pacing: deadline j = base_ns + j * period_ns (absolute) */
    int64_t base_ns;
    int64_t periods_done;      /* since base */
    int64_t late_mark;         /* periods up to this index are already counted as overruns */
    double period_ns;

    /* counters published in status */
    int64_t overruns;
    int64_t overrun_bursts;
    int64_t accepted;
    int64_t rejected[RT_REJ_COUNT];
    int64_t controls_rejected;
    int64_t watchdog_trips;
    int64_t lockstep_timeouts;
    int64_t numeric_faults;
    int64_t states_published;
    int64_t effect_events_dropped; /* sim.events_dropped already reported */

    /* timing */
    int64_t start_ns;
    double step_us_max;
    double step_us_sum;        /* since the last status */
    int64_t step_us_n;
    int64_t ticks_since_status;/* ticks advanced since the last status (resets included) */
    int64_t last_status_ns;
    int64_t next_status_ns;
    int64_t next_line_ns;
    double rtf;                /* real-time factor of the last status period */
    bool live_line;            /* stderr is a terminal and not -q */

    /* rate limit of command_rejected events: at most RT_REJ_EVENTS_PER_S per second */
    int64_t rej_window_ns;
    int rej_events_in_window;
    int64_t rej_suppressed;

    uint8_t buf[RT_BUF_SIZE];
} rt_server;

/* Time helpers (ns). */
int64_t rt_mono_ns(void);
int64_t rt_wall_us(void);

/* rt_wire.c: publishing. Every double is checked; a non-finite one is never sent. */
void rt_publish_state(rt_server *s);
void rt_publish_status(rt_server *s);
void rt_publish_event(rt_server *s, const char *kind, const char *joint, double value,
                      const char *detail);
/* An event that happened at a given sim time (the effects' events, located in a tick). */
void rt_publish_event_at(rt_server *s, double sim_time, const char *kind, const char *joint,
                         double value, const char *detail);
void rt_publish_scene(rt_server *s);
const char *rt_run_name(rt_run r);

/* realtime.c: what the LCM handlers call. */
void rt_handle_command(rt_server *s, const uint8_t *data, size_t len);
void rt_handle_control(rt_server *s, const uint8_t *data, size_t len);

#endif
