/*
 * The server's side of the wire (rt_wire.h): publication of states, status, events and
 * the scene description.
 *
 * Incoming messages are decoded by the bounded decoders of the wire module
 * (server/wire/lagsim_wire.h: fixed-size structs, no allocation, every length checked);
 * realtime.c classifies what they report. Outgoing messages are filled into the same
 * fixed-size structs on the stack and encoded into the server's one buffer (no
 * allocation); every double goes through fin() so NaN/Inf never reach the bus.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "daemon.h"
#include "lagsim_clock.h"
#include "rt_wire.h"

/* A finite double, or 0: what goes on the bus. */
static double fin(double x) { return isfinite(x) ? x : 0.0; }

/* Copies a name into a wire field (every name the daemon sends is shorter). */
static void put(char *dst, size_t cap, const char *src)
{
    snprintf(dst, cap, "%s", src ? src : "");
}
#define PUT(field, src) put(field, sizeof field, src)

_Static_assert(LAG_MAX_DOF <= LAG_WIRE_MAX_JOINTS && LAG_MAX_PARAMS <= LAG_WIRE_MAX_PARAMS,
               "the wire structs hold every model");

/* Encodes message m of type t into the server's buffer and hands it to LCM. Returns the
 * bytes sent, 0 if it could not be encoded (never: every double went through fin(),
 * every name fits). */
static int publish(const rt_out *o, const char *channel, lag_wire_type t, const void *m)
{
    rt_bus *b = o->bus;
    int n = lag_wire_encode(t, m, b->buf, RT_BUF_SIZE);
    if (n <= 0) return 0;
    lcm_publish(b->lcm, channel, b->buf, (unsigned)n);
    rt_log_record(o->rec, o->now, RT_LOG_OUT, channel, b->buf, (size_t)n); /* --log */
    return n;
}

/* ---------------------------------------------------------------- publishing */
/* <PREFIX>_REFERENCE at the state's sim time, just before the state: a controller that
 * reads both has the reference of a state when the state arrives. Nothing (no cost)
 * when the scene has no reference. */
static void publish_reference(const rt_out *o, const lag_sim *sim,
                              const lag_scene_reference *ref, rt_sent *sent)
{
    if (sent) sent->len = 0;
    if (ref->n == 0) return;
    lag_wire_reference m;
    lagsimd_reference_at(ref, sim->def.model.kind, lag_sim_time(sim), sim->tick, &m);
    m.utime = lag_clock_wall_us();
    m.generation = o->generation;
    int n = publish(o, o->bus->ch_reference, LAG_WIRE_REFERENCE, &m);
    if (sent && n > 0) {
        memcpy(sent->buf, o->bus->buf, (size_t)n);
        sent->len = (unsigned)n;
    }
}

int rt_publish_state(const rt_out *o, const lag_sim *sim, const lag_model_info *info,
                     const lag_scene_reference *ref, rt_sent *ref_sent)
{
    publish_reference(o, sim, ref, ref_sent);
    lag_wire_joint_state m;
    memset(&m, 0, sizeof m);
    double pos[LAG_MAX_DOF], vel[LAG_MAX_DOF];
    /* the state as published: plus the noise effect when the scene turns it on */
    lag_sim_observe(sim, pos, vel);
    m.utime = lag_clock_wall_us();
    m.sim_time = fin(lag_sim_time(sim));
    m.step = sim->tick;
    m.generation = o->generation;
    m.num_joints = (int16_t)sim->nq;
    for (int i = 0; i < sim->nq; i++) {
        PUT(m.name[i], info->joint_names[i]);
        /* the caller checked finiteness (a non-finite state is a fault, never published);
         * fin() is the last line of defence */
        m.position[i] = fin(pos[i]);
        m.velocity[i] = fin(vel[i]);
        /* the effort applied over the last tick: the actuator's output (after its lag and
         * saturation), zero where unactuated; without the actuator effect it is exactly
         * the held command. Disturbance forces are external and not included. */
        m.effort[i] = fin(sim->tau_applied[i]);
    }
    return publish(o, o->bus->ch_state, LAG_WIRE_JOINT_STATE, &m);
}

double rt_error_budget(const lag_scene *sc)
{
    const double e = sc->accuracy.error, h = sc->accuracy.horizon;
    return e > 0 && h > 0 ? e / (sc->publish_hz * h) : 0.0;
}

void rt_status_base(lag_wire_status *m, const lag_sim *sim, const lag_scene *sc)
{
    memset(m, 0, sizeof *m);
    m->utime = lag_clock_wall_us();
    m->sim_time = lag_sim_time(sim);
    m->step = sim->tick;
    m->energy = lag_sim_energy(sim);
    PUT(m->integrator, lag_method_name(sc->sim.integrator.method));
    PUT(m->mode, lag_rt_mode_name(sc->realtime.mode));
    PUT(m->contact, lag_sim_contact(sim));
    m->error_budget = rt_error_budget(sc);
}

int rt_publish_status(const rt_out *o, lag_wire_status *m)
{
    m->sim_time = fin(m->sim_time);
    m->wall_time = fin(m->wall_time);
    m->rtf = fin(m->rtf);
    m->step_time_max_us = fin(m->step_time_max_us);
    m->step_time_mean_us = fin(m->step_time_mean_us);
    m->energy = fin(m->energy);
    m->waiting_s = fin(m->waiting_s);
    m->error_estimate = fin(m->error_estimate);
    m->error_budget = fin(m->error_budget);
    return publish(o, o->bus->ch_status, LAG_WIRE_STATUS, m);
}

void rt_publish_event(const rt_out *o, double sim_time, int64_t step, const char *kind,
                      const char *joint, double value, const char *detail, lag_wire_event *m)
{
    memset(m, 0, sizeof *m);
    m->utime = lag_clock_wall_us();
    m->sim_time = fin(sim_time);
    m->step = step;
    PUT(m->kind, kind);
    PUT(m->joint, joint);
    m->value = fin(value);
    PUT(m->detail, detail); /* cut to 255 bytes if longer */
    publish(o, o->bus->ch_event, LAG_WIRE_EVENT, m);
}

void rt_scene_fill(lag_wire_scene *mp, const lag_scene *sc, const lag_sim_def *d, int nq,
                   const lag_model_info *info)
{
    memset(mp, 0, sizeof *mp);
    PUT(mp->model, lag_model_info_get(sc->sim.model.kind)->name); /* the scene's model; its joints are info's */
    PUT(mp->prefix, sc->lcm.prefix);
    mp->num_params = (int16_t)info->np;
    for (int i = 0; i < info->np; i++) {
        PUT(mp->param_name[i], info->param_names[i]);
        mp->param_value[i] = fin(d->model.p[i]);
    }
    mp->num_joints = (int16_t)nq;
    for (int i = 0; i < nq; i++) {
        PUT(mp->joint_name[i], info->joint_names[i]);
        mp->actuated[i] = info->actuated[i];
        mp->initial_q[i] = fin(d->q0[i]);
        mp->initial_qd[i] = fin(d->qd0[i]);
        mp->limit_on[i] = (d->effects.enabled & LAG_EFF_LIMITS) && d->effects.limit_on[i];
        mp->limit_lower[i] = mp->limit_on[i] ? fin(d->effects.limit_lower[i]) : 0.0;
        mp->limit_upper[i] = mp->limit_on[i] ? fin(d->effects.limit_upper[i]) : 0.0;
    }
    /* the effects that are on, by their scene-file names from the core's table, in the
     * order of their bits */
    size_t ne = 0;
    for (int b = 0; b < 32; b++)
        for (int k = 0; k < LAG_EFF_COUNT; k++) {
            lag_effect_info e = lag_effect_info_get(k);
            if (e.bit == (1u << b) && (d->effects.enabled & e.bit) && ne < sizeof mp->effects)
                ne += (size_t)snprintf(mp->effects + ne, sizeof mp->effects - ne, "%s%s",
                                       ne ? "," : "", e.name);
        }
    mp->dt = fin(d->integrator.dt);
    mp->control_period = fin((double)sc->ticks_per_period * d->integrator.dt);
    PUT(mp->integrator, lag_method_name(d->integrator.method));
    PUT(mp->mode, lag_rt_mode_name(sc->realtime.mode));
    mp->rate = fin(sc->realtime.rate);
    mp->command_timeout = fin(sc->realtime.command_timeout);
}

int rt_publish_scene(const rt_out *o, const lag_scene *sc, const lag_sim *sim,
                      const lag_model_info *info)
{
    lag_wire_scene m;
    /* the parameters and effects now (SET changes them) */
    rt_scene_fill(&m, sc, &sim->def, sim->nq, info);
    m.utime = lag_clock_wall_us();
    m.generation = o->generation;
    int n = publish(o, o->bus->ch_scene, LAG_WIRE_SCENE, &m);
    /* remembered, so that the plant watch knows it when it comes back */
    if (n > 0) rt_bus_sent_scene(o->bus, o->bus->buf, (size_t)n);
    return n;
}
