/*
 * What the loop publishes, through one place each (rt_publish.c): events, each kind
 * limited by its own token bucket; states, the last one kept as sent (lockstep's copies);
 * the scene; statuses; and the answers control requests ask for (a state, the scene, a
 * status), coalesced into one for many requests and limited by their buckets.
 *
 * A part of the loop's: it stands on the bus (rt_bus.h), the log (rt_record.h), the
 * terminal (rt_term.h) and the encoders (rt_wire.h). Its state is the buckets, the
 * answers owed and the last state as sent; it reads the loop's clock and the sim (for the
 * sim time and tick of what it publishes) through the pointers rt_pub_init is given.
 */
#ifndef LAGSIMD_RT_PUBLISH_H
#define LAGSIMD_RT_PUBLISH_H

#include <stdbool.h>
#include <stdint.h>
#include "lagsim/lagsim.h"
#include "rt_bus.h"
#include "rt_pace.h"
#include "rt_record.h"
#include "rt_term.h"
#include "rt_wire.h"
#include "scene.h"

/* Events the daemon publishes in answer to what arrives or about its own pacing: each
 * kind has its own token bucket (rt_limit), so that no input, however fast, makes the
 * daemon publish more than a few of them per second. What a bucket suppressed is counted
 * and said by the next event of that kind that gets through. `start`, `stop` and the
 * effects' events (at most a fixed number per period, located by the core) are not
 * limited. */
typedef enum rt_ev {
    RT_EV_COMMAND_REJECTED = 0,
    RT_EV_CONTROL_REJECTED,
    RT_EV_PAUSE,
    RT_EV_RESUME,
    RT_EV_STEP,
    RT_EV_STEP_DONE,
    RT_EV_RESET,
    RT_EV_WATCHDOG_TRIP,
    RT_EV_WATCHDOG_CLEAR,
    RT_EV_LOCKSTEP_TIMEOUT,
    RT_EV_OVERRUN_BURST,
    RT_EV_NUMERIC_FAULT,
    RT_EV_EVENTS_DROPPED,
    RT_EV_PLANT_CONFLICT,     /* a scene of another plant heard on this prefix while running */
    RT_EV_ERROR_ESTIMATE,     /* the live error estimate over the scene's budget per period */
    RT_EV_INPUT_LIMITED,      /* a host's plant: more input than it can use, reading paused */
    RT_EV_FOREIGN_LIMITED,    /* other prefixes' requests on the command URL: budget spent */
    RT_EV_COUNT
} rt_ev;

#define RT_CONFLICT_EVERY_S 5     /* another plant's scenes: said at most once in 5 s */

/* Answers to control requests beyond events: per second and burst. */
#define RT_STATUS_PER_S 20
#define RT_STATUS_BURST 5
#define RT_SCENE_PER_S 5
#define RT_SCENE_BURST 2
#define RT_STATE_PER_S 20  /* states published because of a reset (not the periods' own) */
#define RT_STATE_BURST 5

typedef struct rt_pub {
    /* where it publishes and what it reads (rt_pub_init) */
    rt_bus *bus;
    rt_record *rec;
    rt_term *term;
    const int64_t *now;        /* the loop's clock */
    const lag_sim *sim;        /* sim time and tick of what is published */

    /* the generation of what is published: 1 at the start, one more at every reset and
     * every accepted SET or kick (rt_pub_new_generation); states, references and scenes
     * carry it, and a command carries the generation of the state it answers */
    int64_t generation;

    /* answers owed: published once per wake-up at most, when their bucket allows (a
     * flood of requests gets one answer, not one each) */
    bool want_state, want_scene, want_status;
    rt_limit lim_state, lim_scene, lim_status;
    rt_limit lim_event[RT_EV_COUNT];

    /* counters published in status */
    int64_t states_published;
    int64_t lockstep_retries;  /* states published again, no answer having come */

    uint8_t state_buf[RT_BUF_SIZE]; /* the last state published, as sent (lockstep retries) */
    rt_sent last_scene, last_status; /* the last of each, as sent (a host's directory) */
    rt_sent ref_sent;               /* its reference, as sent (lockstep retries) */
    unsigned state_len;
} rt_pub;

/* Where to publish and what to read; the buckets full at *now. */
void rt_pub_init(rt_pub *p, rt_bus *bus, rt_record *rec, rt_term *term, const int64_t *now,
                 const lag_sim *sim);
/* The name of an event kind ("command_rejected", ...). */
const char *rt_ev_kind(rt_ev ev);

/* Every event goes out through here: on the bus (and --log), and on the terminal;
 * `effect`: one of the effects' events, located in a tick at sim_time. */
void rt_pub_event_at(rt_pub *p, double sim_time, const char *kind, const char *joint,
                     double value, const char *detail, bool effect);
/* An event at the sim's time. */
void rt_pub_event(rt_pub *p, const char *kind, const char *joint, double value,
                  const char *detail);
/* An unlimited event (start, stop) with a formatted detail. */
void rt_pub_eventf(rt_pub *p, const char *kind, double value, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* A limited event: published if its kind's bucket has a token, else counted as
 * suppressed; the next one that gets through says how many were suppressed before it. */
void rt_pub_limited(rt_pub *p, rt_ev ev, const char *joint, double value, const char *fmt,
                    ...) __attribute__((format(printf, 5, 6)));

/* The state the sim holds (with its reference), kept as sent; true when it went out. */
bool rt_pub_state(rt_pub *p, const lag_model_info *info, const lag_scene_reference *ref);
/* The last state again, byte for byte, with its reference before it: a copy for the
 * network, which --log (the run's record, one state per period) does not keep. */
void rt_pub_state_again(rt_pub *p);
/* The scene as it is now. */
void rt_pub_scene(rt_pub *p, const lag_scene *sc, const lag_model_info *info);
/* The scene or the run changed (a reset, a SET, a kick): a new generation, whose scene
 * goes out now, before any state of it, not through the DESCRIBE bucket (what changes
 * the generation has its own bucket: RT_SET_PER_S, RT_RESET_PER_S). */
void rt_pub_new_generation(rt_pub *p, const lag_scene *sc, const lag_model_info *info);
/* The status m (the loop fills it). */
void rt_pub_status(rt_pub *p, lag_wire_status *m);

#endif
