/*
 * The server's side of the wire: publication of states, status, events and the scene
 * description.
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

#include "rt_server.h"

int64_t rt_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

int64_t rt_wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

const char *rt_run_name(rt_run r)
{
    switch (r) {
    case RT_RUNNING: return "running";
    case RT_PAUSED: return "paused";
    case RT_WAITING: return "waiting";
    case RT_FAULT: return "fault";
    }
    return "?";
}

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
static int publish(rt_server *s, const char *channel, lag_wire_type t, const void *m)
{
    int n = lag_wire_encode(t, m, s->buf, RT_BUF_SIZE);
    if (n <= 0) return 0;
    lcm_publish(s->lcm, channel, s->buf, (unsigned)n);
    rt_log_record(s, RT_LOG_OUT, channel, s->buf, (size_t)n); /* --log */
    return n;
}

/* ---------------------------------------------------------------- publishing */
/* <PREFIX>_REFERENCE at the state's sim time, just before the state: a controller that
 * reads both has the reference of a state when the state arrives. Nothing (no cost)
 * when the scene has no reference. */
static void publish_reference(rt_server *s)
{
    if (s->ref.n == 0) return;
    lag_wire_reference m;
    lagsimd_reference_at(&s->ref, s->sim.def.model.kind, lag_sim_time(&s->sim), s->sim.tick,
                         &m);
    m.utime = rt_wall_us();
    publish(s, s->ch_reference, LAG_WIRE_REFERENCE, &m);
}

void rt_publish_state(rt_server *s)
{
    publish_reference(s);
    lag_wire_joint_state m;
    memset(&m, 0, sizeof m);
    double pos[LAG_MAX_DOF], vel[LAG_MAX_DOF];
    /* the state as published: plus the noise effect when the scene turns it on */
    lag_sim_observe(&s->sim, pos, vel);
    m.utime = rt_wall_us();
    m.sim_time = fin(lag_sim_time(&s->sim));
    m.step = s->sim.tick;
    m.num_joints = (int16_t)s->nq;
    for (int i = 0; i < s->nq; i++) {
        PUT(m.name[i], s->info->joint_names[i]);
        /* the caller checked finiteness (a non-finite state is a fault, never published);
         * fin() is the last line of defence */
        m.position[i] = fin(pos[i]);
        m.velocity[i] = fin(vel[i]);
        /* the effort applied over the last tick: the actuator's output (after its lag and
         * saturation), zero where unactuated; without the actuator effect it is exactly
         * the held command. Disturbance forces are external and not included. */
        m.effort[i] = fin(s->sim.tau_applied[i]);
    }
    int n = publish(s, s->ch_state, LAG_WIRE_JOINT_STATE, &m);
    if (n > 0) {
        s->states_published++;
        memcpy(s->state_buf, s->buf, (size_t)n); /* as sent: a lockstep retry sends it again */
        s->state_len = (unsigned)n;
    }
}

double rt_error_budget(const lag_scene *sc)
{
    const double e = sc->accuracy.error, h = sc->accuracy.horizon;
    return e > 0 && h > 0 ? e / (sc->publish_hz * h) : 0.0;
}

void rt_publish_status(rt_server *s)
{
    int64_t now = rt_mono_ns();
    double wall = (double)(now - s->last_status_ns) * 1e-9;
    double sim_adv = (double)s->ticks_since_status * s->sc->sim.integrator.dt;
    lag_wire_status m;
    memset(&m, 0, sizeof m);
    m.utime = rt_wall_us();
    m.sim_time = fin(lag_sim_time(&s->sim));
    m.step = s->sim.tick;
    m.wall_time = fin((double)(now - s->start_ns) * 1e-9);
    /* a window shorter than 50 ms (a status on request, the final one) is too short to
     * measure: it repeats the last figure */
    m.rtf = s->run != RT_RUNNING ? 0.0 : wall < 0.05 ? fin(s->rtf) : fin(sim_adv / wall);
    m.overruns = s->overruns;
    m.step_time_max_us = fin(s->step_us_max);
    m.step_time_mean_us = s->step_us_n > 0 ? fin(s->step_us_sum / (double)s->step_us_n) : 0.0;
    m.energy = fin(lag_sim_energy(&s->sim));
    PUT(m.integrator, lag_method_name(s->sc->sim.integrator.method));
    PUT(m.mode, lag_rt_mode_name(s->sc->realtime.mode));
    PUT(m.run_state, rt_run_name(s->run));
    m.commands_accepted = s->accepted;
    m.rejected_unknown_joint = s->rejected[RT_REJ_UNKNOWN_JOINT];
    m.rejected_unactuated = s->rejected[RT_REJ_UNACTUATED];
    m.rejected_nonfinite = s->rejected[RT_REJ_NONFINITE];
    m.rejected_bad_length = s->rejected[RT_REJ_BAD_LENGTH];
    m.rejected_undecodable = s->rejected[RT_REJ_UNDECODABLE];
    m.controls_rejected = s->controls_rejected;
    m.watchdog_tripped = s->watchdog_tripped;
    m.watchdog_trips = s->watchdog_trips;
    m.lockstep_timeouts = s->lockstep_timeouts;
    m.numeric_faults = s->numeric_faults;
    m.rejected_stale = s->rejected[RT_REJ_STALE];
    m.overrun_bursts = s->overrun_bursts;
    m.states_published = s->states_published;
    m.rejected_effort_limit = s->rejected[RT_REJ_EFFORT_LIMIT];
    m.lockstep_retries = s->lockstep_retries;
    m.commands_ignored = s->commands_ignored;
    PUT(m.contact, lag_sim_contact(&s->sim));
    m.plant_conflicts = s->plant_conflicts;
    m.waiting_s = fin(rt_wait_describe(s, m.waiting_for, sizeof m.waiting_for, m.waiting_got,
                                       sizeof m.waiting_got));
    m.commands_wrong_port = s->commands_wrong_port;
    m.error_estimate = fin(s->err_estimate);
    PUT(m.error_joint, s->err_joint >= 0 && s->err_joint < s->nq ? s->info->joint_names[s->err_joint] : "");
    m.error_budget = fin(rt_error_budget(s->sc));
    m.error_warnings = s->err_warnings;
    publish(s, s->ch_status, LAG_WIRE_STATUS, &m);
    s->rtf = m.rtf;
    if (wall < 0.05 && s->run == RT_RUNNING) return; /* the window goes on */
    s->last_status_ns = now;
    s->ticks_since_status = 0;
    s->step_us_sum = 0;
    s->step_us_n = 0;
}

static void publish_event(rt_server *s, double sim_time, const char *kind, const char *joint,
                          double value, const char *detail, bool effect)
{
    lag_wire_event m;
    memset(&m, 0, sizeof m);
    m.utime = rt_wall_us();
    m.sim_time = fin(sim_time);
    m.step = s->sim.tick;
    PUT(m.kind, kind);
    PUT(m.joint, joint);
    m.value = fin(value);
    PUT(m.detail, detail); /* cut to 255 bytes if longer */
    publish(s, s->ch_event, LAG_WIRE_EVENT, &m);
    rt_term_event(s, m.sim_time, m.kind, m.joint, m.value, m.detail, effect);
}

void rt_publish_event(rt_server *s, const char *kind, const char *joint, double value,
                      const char *detail)
{
    publish_event(s, lag_sim_time(&s->sim), kind, joint, value, detail, false);
}

void rt_publish_event_at(rt_server *s, double sim_time, const char *kind, const char *joint,
                         double value, const char *detail)
{
    publish_event(s, sim_time, kind, joint, value, detail, true);
}

void rt_publish_scene(rt_server *s)
{
    const lag_sim_def *d = &s->sim.def; /* the parameters and effects now (SET changes them) */
    lag_wire_scene m;
    memset(&m, 0, sizeof m);
    m.utime = rt_wall_us();
    PUT(m.model, lag_model_info_get(s->sc->sim.model.kind)->name); /* the scene's model; its joints are s->info's */
    PUT(m.prefix, s->sc->lcm.prefix);
    m.num_params = (int16_t)s->info->np;
    for (int i = 0; i < s->info->np; i++) {
        PUT(m.param_name[i], s->info->param_names[i]);
        m.param_value[i] = fin(d->model.p[i]);
    }
    m.num_joints = (int16_t)s->nq;
    for (int i = 0; i < s->nq; i++) {
        PUT(m.joint_name[i], s->info->joint_names[i]);
        m.actuated[i] = s->info->actuated[i];
        m.initial_q[i] = fin(d->q0[i]);
        m.initial_qd[i] = fin(d->qd0[i]);
        m.limit_on[i] = (d->effects.enabled & LAG_EFF_LIMITS) && d->effects.limit_on[i];
        m.limit_lower[i] = m.limit_on[i] ? fin(d->effects.limit_lower[i]) : 0.0;
        m.limit_upper[i] = m.limit_on[i] ? fin(d->effects.limit_upper[i]) : 0.0;
    }
    /* the effects that are on, by their scene-file names from the core's table, in the
     * order of their bits */
    size_t ne = 0;
    for (int b = 0; b < 32; b++)
        for (int k = 0; k < LAG_EFF_COUNT; k++) {
            lag_effect_info e = lag_effect_info_get(k);
            if (e.bit == (1u << b) && (d->effects.enabled & e.bit) && ne < sizeof m.effects)
                ne += (size_t)snprintf(m.effects + ne, sizeof m.effects - ne, "%s%s",
                                       ne ? "," : "", e.name);
        }
    m.dt = fin(d->integrator.dt);
    m.control_period = fin((double)s->sc->ticks_per_period * d->integrator.dt);
    PUT(m.integrator, lag_method_name(d->integrator.method));
    PUT(m.mode, lag_rt_mode_name(s->sc->realtime.mode));
    m.rate = fin(s->sc->realtime.rate);
    m.command_timeout = fin(s->sc->realtime.command_timeout);
    int n = publish(s, s->ch_scene, LAG_WIRE_SCENE, &m);
    /* remembered, so that the plant watch knows it when it comes back (rt_handle_scene) */
    if (n > 0) {
        s->scene_sent[s->scene_next] = rt_hash(s->buf, (size_t)n);
        s->scene_next = (s->scene_next + 1) % RT_SCENES_KEPT;
    }
}
