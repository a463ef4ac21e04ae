/*
 * One plant of the real-time server, as the loop that runs it sees it (host.c: one loop
 * for one plant, or for the many plants of a host). The plant is opaque here: its struct
 * and its parts are realtime.c's (rt_server.h, which no other file includes).
 *
 * A plant's life, each step at the loop's clock `now`:
 *
 *     s = rt_plant_new()
 *     rt_plant_open(s, scene, opts, now, ...)   scene checked, sim made, --log opened,
 *                                               the bus made, the prefix asked for its
 *                                               scene
 *     ... the loop reads rt_plant_fd(s, RT_PLANT_WATCH) for rt_plant_look_ns ...
 *     rt_plant_start(s, now, ...)               refused if another plant answered; else
 *                                               the command URL filtered, the start
 *                                               published
 *     loop: rt_next_wake(s), the plant's LCM drained (rt_plant_drain), rt_process(s)
 *     rt_plant_end(s)                           the stop event and final status, --log
 *                                               closed, LCM closed: the plant's result
 *     rt_plant_free(s)
 */
#ifndef LAGSIMD_REALTIME_H
#define LAGSIMD_REALTIME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <lcm/lcm.h>
#include "daemon.h"

typedef struct rt_server rt_server;

/* Why a plant stopped. */
typedef enum rt_stop {
    RT_STOP_NONE = 0,
    RT_STOP_SIGNAL,
    RT_STOP_DURATION,
    RT_STOP_ERROR,
    RT_STOP_REMOVED,   /* a host: its scene file was removed */
    RT_STOP_CHANGED,   /* a host: its scene file changed (the plant starts again from it) */
} rt_stop;

/* What a plant reads: its input on the command URL (its commands and control requests),
 * the plant watch on the state URL (another plant's scene on the prefix), and other
 * prefixes' control requests on the command URL (a budget of their own: rt_bus.h). */
typedef enum rt_plant_input { RT_PLANT_IN = 0, RT_PLANT_WATCH, RT_PLANT_FOREIGN } rt_plant_input;

/* A plant's struct, zeroed (large: allocated once per plant, never in the stepping path);
 * NULL when out of memory. */
rt_server *rt_plant_new(void);
void rt_plant_free(rt_server *s);
/* rt_open, then LCM: the instances made and attached, the state URL's filtered, DESCRIBE
 * sent (rt_bus_open_start). `who`: what the plant's terminal lines begin with ("" for a
 * daemon of one plant, "ALICE: " in a host). Returns 0, or an exit code with a message in
 * err (2: the scene or --duration, nothing made; 1: LCM), everything made closed again. */
int rt_plant_open(rt_server *s, const lag_scene *sc, const lagsimd_opts *o, int64_t now,
                  bool quiet, const char *who, char *err, size_t errlen);
/* How long the loop listens for another plant on the prefix before rt_plant_start (ns;
 * 0: nothing to look for, memq://). */
int64_t rt_plant_look_ns(const rt_server *s);
/* The descriptor the loop waits on for `which` (-1: none, e.g. memq://'s plant watch). */
int rt_plant_fd(const rt_server *s, rt_plant_input which);
/* Handles what `which` holds, at most `max` messages, at the loop's clock `now`; none once
 * the plant stopped. Returns the number read. */
int rt_plant_drain(rt_server *s, rt_plant_input which, int64_t now, int max);
/* After the look: refused (1, message in err, LCM closed) when another plant answered on
 * the prefix; else the command URL filtered and the plant started at `now`: its scene, a
 * start event, its first state (rt_begin). live_line: the live status line on stderr. */
int rt_plant_start(rt_server *s, int64_t now, bool live_line, char *err, size_t errlen);
/* Whether the plant stopped (a signal, --duration, rt_plant_stop, an error of the wait). */
bool rt_plant_stopped(const rt_server *s);
/* Stops the plant (the next rt_plant_end says why in its stop event). */
void rt_plant_stop(rt_server *s, rt_stop why);
/* The end: a started plant publishes its stop event and final status; --log closed, LCM
 * closed. Returns the plant's result: LAGSIMD_EXIT_RUNTIME when --log lost records. */
lag_result rt_plant_end(rt_server *s, bool started);
/* The loop's clock of the plant (set before rt_process and rt_signal). */
void rt_plant_set_now(rt_server *s, int64_t now);

/* States published so far, copies included (a host's input budget grows with them). */
int64_t rt_plant_published(const rt_server *s);
/* A host paused reading the plant's input (its budget spent; `why` says the budget): an
 * input_limited event (limited: 3, then 1 a second), `times` in its value. */
void rt_plant_input_limited(rt_server *s, int64_t times, const char *why);

/* The loop paused reading other prefixes' requests on the plant's command URL (their
 * budget, `why`, spent): a foreign_limited event (3, then 1 a second) naming what was
 * heard and dropped, the requests heard so far (read and dropped) in its value. */
void rt_plant_foreign_limited(rt_server *s, const char *why);

/* The last scene (status false) or status the plant published, as sent: its length (0:
 * none yet), the bytes in *data (valid until the plant publishes the next). OUT: data */
unsigned rt_plant_last(const rt_server *s, bool status, const uint8_t **data);

/* When the loop must next wake up for this plant (absolute ns; <= now: at once). Pure. */
int64_t rt_next_wake(const rt_server *s);
/* Everything due at the plant's clock: the mode's periods, pending answers, the periodic
 * status. */
void rt_process(rt_server *s);
/* A signal arrived: SIGUSR1/SIGUSR2 ask for a status, any other stops the plant. */
void rt_signal(rt_server *s, int signo);

#endif
