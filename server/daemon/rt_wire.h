/*
 * The real-time server's side of the wire (rt_wire.c): what it publishes, encoded into
 * the bus's one buffer and handed to LCM and to --log. Every double is checked; a
 * non-finite one is never sent.
 *
 * A part of the loop's: it stands on the bus (rt_bus.h) and the log (rt_record.h) and
 * keeps no state of its own; the loop says what to publish and where (rt_out).
 */
#ifndef LAGSIMD_RT_WIRE_H
#define LAGSIMD_RT_WIRE_H

#include <stdint.h>
#include "lagsim/lagsim.h"
#include "lagsim_wire.h"
#include "rt_bus.h"
#include "rt_record.h"
#include "scene.h"

/* Where a message goes: the bus, and the log at the loop's clock `now`. */
typedef struct rt_out {
    rt_bus *bus;
    rt_record *rec;
    int64_t now;
    int64_t generation;  /* stamped on states, references and scenes */
} rt_out;

/* The error a period may add (m or rad): integrator.error * period / integrator.horizon
 * (the horizon's periods each adding this much sum to the error asked for); 0 when the
 * scene asks for none. */
double rt_error_budget(const lag_scene *sc);

/* A message's bytes as sent, kept for sending again (a lockstep retry). */
typedef struct rt_sent {
    uint8_t buf[RT_BUF_SIZE];
    unsigned len; /* 0: none */
} rt_sent;

/* The reference at the state's sim time (when the scene has one: ref->n > 0; its bytes
 * to ref_sent when not NULL, len 0 without one), then the state as published
 * (lag_sim_observe). Returns the state's bytes, as sent, in o->bus->buf (0: not sent). */
int rt_publish_state(const rt_out *o, const lag_sim *sim, const lag_model_info *info,
                     const lag_scene_reference *ref, rt_sent *ref_sent);
/* The parts of a status the sim and the scene give (time, step, energy, contact, the
 * integrator, the mode, the error budget); the loop fills its counters. */
void rt_status_base(lag_wire_status *m, const lag_sim *sim, const lag_scene *sc);
/* Publishes the status m (its doubles made finite first). Returns its bytes, as sent, in
 * o->bus->buf (0: not sent). */
int rt_publish_status(const rt_out *o, lag_wire_status *m);
/* An event at sim_time, at tick `step`; m: the event as sent (what the terminal shows). */
void rt_publish_event(const rt_out *o, double sim_time, int64_t step, const char *kind,
                      const char *joint, double value, const char *detail, lag_wire_event *m);
/* The scene message of scene sc with definition d (nq joints): all but utime and the
 * generation (the replay compares it with the scene a log holds). */
void rt_scene_fill(lag_wire_scene *m, const lag_scene *sc, const lag_sim_def *d, int nq,
                   const lag_model_info *info);
/* The scene as it is now (SET changes the sim's definition), remembered by the plant
 * watch (rt_bus_sent_scene). Returns its bytes, as sent, in o->bus->buf (0: not sent). */
int rt_publish_scene(const rt_out *o, const lag_scene *sc, const lag_sim *sim,
                      const lag_model_info *info);

#endif
