/*
 * The server's side of the wire: bounded decoding of commands and control requests, and
 * publication of states, status, events and the scene description.
 *
 * Incoming messages are decoded by hand, not with lcm-gen's decoders: those trust the
 * payload (a negative array length or string length goes straight to malloc/memcpy) and
 * allocate; these read at most `len` bytes into fixed-size structs and classify what is
 * wrong (undecodable vs bad length). The fingerprint is the generated type's, so a
 * change in the .lcm file cannot silently desynchronize them.
 *
 * Outgoing messages use lcm-gen's encoders into the server's one buffer (no allocation);
 * every double goes through fin() so NaN/Inf never reach the bus.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"

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
    case RT_FAULT: return "fault";
    }
    return "?";
}

/* A finite double, or 0: what goes on the bus. */
static double fin(double x) { return isfinite(x) ? x : 0.0; }

/* ---------------------------------------------------------------- bounded reader */
typedef struct rd {
    const uint8_t *p;
    size_t len, pos;
    bool bad;
} rd;

static uint64_t rd_u(rd *r, int nbytes)
{
    uint64_t v = 0;
    if (r->bad || r->len - r->pos < (size_t)nbytes) {
        r->bad = true;
        return 0;
    }
    for (int i = 0; i < nbytes; i++) v = (v << 8) | r->p[r->pos + (size_t)i];
    r->pos += (size_t)nbytes;
    return v;
}
static int64_t rd_i64(rd *r) { return (int64_t)rd_u(r, 8); }
static int32_t rd_i32(rd *r) { return (int32_t)(uint32_t)rd_u(r, 4); }
static int16_t rd_i16(rd *r) { return (int16_t)(uint16_t)rd_u(r, 2); }
static int8_t rd_i8(rd *r) { return (int8_t)(uint8_t)rd_u(r, 1); }
static double rd_f64(rd *r)
{
    uint64_t u = rd_u(r, 8);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/* An LCM string: int32 length including the NUL, bytes, NUL. Copies at most cap-1
 * characters; *too_long says it did not fit. An embedded NUL or a missing final NUL makes
 * the message undecodable (a name "x\0y" must not match joint "x"). */
static void rd_string(rd *r, char *out, size_t cap, bool *too_long)
{
    int32_t n = rd_i32(r);
    out[0] = '\0';
    *too_long = false;
    if (r->bad) return;
    if (n < 1 || (size_t)n > r->len - r->pos) {
        r->bad = true;
        return;
    }
    const uint8_t *b = r->p + r->pos;
    if (b[n - 1] != 0 || memchr(b, 0, (size_t)n - 1) != NULL) {
        r->bad = true;
        return;
    }
    if ((size_t)n > cap) {
        *too_long = true;
        memcpy(out, b, cap - 1);
        out[cap - 1] = '\0';
    } else {
        memcpy(out, b, (size_t)n);
    }
    r->pos += (size_t)n;
}

rt_decode_result rt_decode_command(const uint8_t *data, size_t len, int nq, rt_command *out)
{
    memset(out, 0, sizeof *out);
    rd r = {data, len, 0, false};
    int64_t hash = rd_i64(&r);
    if (r.bad || hash != __lagsim_joint_command_t_get_hash()) return RT_DEC_UNDECODABLE;
    (void)rd_i64(&r); /* utime: informational */
    out->sim_time = rd_f64(&r);
    int n = rd_i16(&r);
    if (r.bad) return RT_DEC_UNDECODABLE;
    out->num_joints = n;
    if (n < 0 || n > nq) return RT_DEC_BAD_LENGTH;
    for (int i = 0; i < n; i++) rd_string(&r, out->name[i], RT_NAME_MAX, &out->name_too_long[i]);
    for (int i = 0; i < n; i++) out->effort[i] = rd_f64(&r);
    return r.bad ? RT_DEC_UNDECODABLE : RT_DEC_OK;
}

rt_decode_result rt_decode_control(const uint8_t *data, size_t len, rt_control *out)
{
    memset(out, 0, sizeof *out);
    rd r = {data, len, 0, false};
    int64_t hash = rd_i64(&r);
    if (r.bad || hash != __lagsim_control_t_get_hash()) return RT_DEC_UNDECODABLE;
    (void)rd_i64(&r); /* utime */
    out->request = rd_i8(&r);
    out->count = rd_i64(&r);
    int n = rd_i16(&r);
    if (r.bad) return RT_DEC_UNDECODABLE;
    out->num_joints = n;
    if (n < 0 || n > LAG_MAX_DOF) return RT_DEC_BAD_LENGTH;
    for (int i = 0; i < n; i++) out->q[i] = rd_f64(&r);
    for (int i = 0; i < n; i++) out->qd[i] = rd_f64(&r);
    return r.bad ? RT_DEC_UNDECODABLE : RT_DEC_OK;
}

/* ---------------------------------------------------------------- publishing */
/* Joint names as lcm-gen's char** (the encoder only reads them). */
static void joint_names(const rt_server *s, char **names)
{
    for (int i = 0; i < s->nq; i++) names[i] = (char *)s->info->joint_names[i];
}

void rt_publish_state(rt_server *s)
{
    char *names[LAG_MAX_DOF];
    double pos[LAG_MAX_DOF], vel[LAG_MAX_DOF], eff[LAG_MAX_DOF];
    joint_names(s, names);
    /* the state as published: plus the noise effect when the scene turns it on */
    lag_sim_observe(&s->sim, pos, vel);
    for (int i = 0; i < s->nq; i++) {
        /* the caller checked finiteness (a non-finite state is a fault, never published);
         * fin() is the last line of defence */
        pos[i] = fin(pos[i]);
        vel[i] = fin(vel[i]);
        /* the effort applied over the last tick: the actuator's output (after its lag and
         * saturation), zero where unactuated; without the actuator effect it is exactly
         * the held command. Disturbance forces are external and not included. */
        eff[i] = fin(s->sim.tau_applied[i]);
    }
    lagsim_joint_state_t m = {
        .utime = rt_wall_us(),
        .sim_time = fin(lag_sim_time(&s->sim)),
        .step = s->sim.tick,
        .num_joints = (int16_t)s->nq,
        .name = names,
        .position = pos,
        .velocity = vel,
        .effort = eff,
    };
    int n = lagsim_joint_state_t_encode(s->buf, 0, RT_BUF_SIZE, &m);
    if (n > 0) lcm_publish(s->lcm, s->ch_state, s->buf, (unsigned)n);
    s->states_published++;
}

void rt_publish_status(rt_server *s)
{
    int64_t now = rt_mono_ns();
    double wall = (double)(now - s->last_status_ns) * 1e-9;
    double sim_adv = (double)s->ticks_since_status * s->sc->sim.integrator.dt;
    lagsim_status_t m = {
        .utime = rt_wall_us(),
        .sim_time = fin(lag_sim_time(&s->sim)),
        .step = s->sim.tick,
        .wall_time = fin((double)(now - s->start_ns) * 1e-9),
        /* a window shorter than 50 ms (a status on request, the final one) is too short
         * to measure: it repeats the last figure */
        .rtf = s->run != RT_RUNNING ? 0.0 : wall < 0.05 ? fin(s->rtf) : fin(sim_adv / wall),
        .overruns = s->overruns,
        .step_time_max_us = fin(s->step_us_max),
        .step_time_mean_us = s->step_us_n > 0 ? fin(s->step_us_sum / (double)s->step_us_n) : 0.0,
        .energy = fin(lag_sim_energy(&s->sim)),
        .integrator = (char *)lag_method_name(s->sc->sim.integrator.method),
        .mode = (char *)lag_rt_mode_name(s->sc->realtime.mode),
        .run_state = (char *)rt_run_name(s->run),
        .commands_accepted = s->accepted,
        .rejected_unknown_joint = s->rejected[RT_REJ_UNKNOWN_JOINT],
        .rejected_unactuated = s->rejected[RT_REJ_UNACTUATED],
        .rejected_nonfinite = s->rejected[RT_REJ_NONFINITE],
        .rejected_bad_length = s->rejected[RT_REJ_BAD_LENGTH],
        .rejected_undecodable = s->rejected[RT_REJ_UNDECODABLE],
        .controls_rejected = s->controls_rejected,
        .watchdog_tripped = s->watchdog_tripped,
        .watchdog_trips = s->watchdog_trips,
        .lockstep_timeouts = s->lockstep_timeouts,
        .numeric_faults = s->numeric_faults,
        .rejected_stale = s->rejected[RT_REJ_STALE],
        .overrun_bursts = s->overrun_bursts,
        .states_published = s->states_published,
    };
    int n = lagsim_status_t_encode(s->buf, 0, RT_BUF_SIZE, &m);
    if (n > 0) lcm_publish(s->lcm, s->ch_status, s->buf, (unsigned)n);
    s->rtf = m.rtf;
    if (wall < 0.05 && s->run == RT_RUNNING) return; /* the window goes on */
    s->last_status_ns = now;
    s->ticks_since_status = 0;
    s->step_us_sum = 0;
    s->step_us_n = 0;
}

void rt_publish_event(rt_server *s, const char *kind, const char *joint, double value,
                      const char *detail)
{
    rt_publish_event_at(s, lag_sim_time(&s->sim), kind, joint, value, detail);
}

void rt_publish_event_at(rt_server *s, double sim_time, const char *kind, const char *joint,
                         double value, const char *detail)
{
    lagsim_event_t m = {
        .utime = rt_wall_us(),
        .sim_time = fin(sim_time),
        .step = s->sim.tick,
        .kind = (char *)kind,
        .joint = (char *)(joint ? joint : ""),
        .value = fin(value),
        .detail = (char *)(detail ? detail : ""),
    };
    int n = lagsim_event_t_encode(s->buf, 0, RT_BUF_SIZE, &m);
    if (n > 0) lcm_publish(s->lcm, s->ch_event, s->buf, (unsigned)n);
}

void rt_publish_scene(rt_server *s)
{
    const lag_sim_def *d = &s->sc->sim;
    char *pnames[LAG_MAX_PARAMS], *jnames[LAG_MAX_DOF];
    double pvals[LAG_MAX_PARAMS], q0[LAG_MAX_DOF], qd0[LAG_MAX_DOF];
    int8_t act[LAG_MAX_DOF];
    int np = s->info->np;
    for (int i = 0; i < np; i++) {
        pnames[i] = (char *)s->info->param_names[i];
        pvals[i] = fin(d->model.p[i]);
    }
    joint_names(s, jnames);
    for (int i = 0; i < s->nq; i++) {
        act[i] = s->info->actuated[i] ? 1 : 0;
        q0[i] = fin(d->q0[i]);
        qd0[i] = fin(d->qd0[i]);
    }
    lagsim_scene_t m = {
        .utime = rt_wall_us(),
        .model = (char *)s->info->name,
        .prefix = (char *)s->sc->lcm.prefix,
        .num_params = (int16_t)np,
        .param_name = pnames,
        .param_value = pvals,
        .num_joints = (int16_t)s->nq,
        .joint_name = jnames,
        .actuated = act,
        .initial_q = q0,
        .initial_qd = qd0,
        .dt = fin(d->integrator.dt),
        .control_period = fin((double)s->sc->ticks_per_period * d->integrator.dt),
        .integrator = (char *)lag_method_name(d->integrator.method),
        .mode = (char *)lag_rt_mode_name(s->sc->realtime.mode),
        .rate = fin(s->sc->realtime.rate),
        .command_timeout = fin(s->sc->realtime.command_timeout),
    };
    int n = lagsim_scene_t_encode(s->buf, 0, RT_BUF_SIZE, &m);
    if (n > 0) lcm_publish(s->lcm, s->ch_scene, s->buf, (unsigned)n);
}
