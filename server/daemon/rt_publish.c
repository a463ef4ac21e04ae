/*
 * What the loop publishes, through one place each: see rt_publish.h.
 */
#include "rt_publish.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include <lcm/lcm.h>

/* The buckets of the limited events (rt_ev): name, answers per second, burst; and whether
 * the kind says the plant lost something (a command refused, its controller's silence,
 * periods, input, effects): -q's journal keeps those (rt_term.h). */
static const struct {
    const char *kind;
    double per_s;
    int burst;
    bool loss;
} ev_limits[RT_EV_COUNT] = {
    [RT_EV_COMMAND_REJECTED] = {"command_rejected", 10, 10, true},
    [RT_EV_CONTROL_REJECTED] = {"control_rejected", 10, 10, true},
    [RT_EV_PAUSE] = {"pause", 10, 10},
    [RT_EV_RESUME] = {"resume", 10, 10},
    [RT_EV_STEP] = {"step", 10, 10},
    [RT_EV_STEP_DONE] = {"step_done", 10, 10},
    [RT_EV_RESET] = {"reset", 10, 10},
    [RT_EV_WATCHDOG_TRIP] = {"watchdog_trip", 10, 10, true},
    [RT_EV_WATCHDOG_CLEAR] = {"watchdog_clear", 10, 10},
    [RT_EV_LOCKSTEP_TIMEOUT] = {"lockstep_timeout", 10, 10, true},
    [RT_EV_OVERRUN_BURST] = {"overrun_burst", 1, 3, true},
    [RT_EV_NUMERIC_FAULT] = {"numeric_fault", 10, 10, true},
    [RT_EV_EVENTS_DROPPED] = {"events_dropped", 1, 3, true},
    /* one in RT_CONFLICT_EVERY_S however many scenes a forger or a log player sends */
    [RT_EV_PLANT_CONFLICT] = {"plant_conflict", 1.0 / RT_CONFLICT_EVERY_S, 1},
    [RT_EV_ERROR_ESTIMATE] = {"error_estimate", 1, 3, true},
    [RT_EV_INPUT_LIMITED] = {"input_limited", 1, 3, true},
    [RT_EV_FOREIGN_LIMITED] = {"foreign_limited", 1, 3, true},
};
_Static_assert(sizeof ev_limits / sizeof ev_limits[0] == RT_EV_COUNT, "one bucket per rt_ev");
_Static_assert(RT_EV_COUNT <= RT_TERM_LOSS_KINDS, "a journal slot per limited kind");

/* The journal's slot of an event kind: its rt_ev when the table marks it a loss, else -1. */
static int loss_slot(const char *kind)
{
    for (int k = 0; k < RT_EV_COUNT; k++)
        if (ev_limits[k].loss && !strcmp(kind, ev_limits[k].kind)) return k;
    return -1;
}

void rt_pub_init(rt_pub *p, rt_bus *bus, rt_record *rec, rt_term *term, const int64_t *now,
                 const lag_sim *sim)
{
    p->bus = bus;
    p->rec = rec;
    p->term = term;
    p->now = now;
    p->sim = sim;
    p->generation = 1;
    for (int k = 0; k < RT_EV_COUNT; k++)
        rt_limit_init(&p->lim_event[k], ev_limits[k].per_s, ev_limits[k].burst, *now);
    rt_limit_init(&p->lim_status, RT_STATUS_PER_S, RT_STATUS_BURST, *now);
    rt_limit_init(&p->lim_scene, RT_SCENE_PER_S, RT_SCENE_BURST, *now);
    rt_limit_init(&p->lim_state, RT_STATE_PER_S, RT_STATE_BURST, *now);
}

const char *rt_ev_kind(rt_ev ev)
{
    return (unsigned)ev < RT_EV_COUNT ? ev_limits[ev].kind : "?";
}

/* Where what is published goes now: the bus and the log (rt_wire.h). */
static rt_out out(const rt_pub *p)
{
    return (rt_out){p->bus, p->rec, *p->now, p->generation};
}

void rt_pub_event_at(rt_pub *p, double sim_time, const char *kind, const char *joint,
                     double value, const char *detail, bool effect)
{
    lag_wire_event m;
    rt_out o = out(p);
    rt_publish_event(&o, sim_time, p->sim->tick, kind, joint, value, detail, &m);
    rt_term_event(p->term, *p->now, m.sim_time, m.kind, m.joint, m.value, m.detail, effect,
                  p->term->quiet ? loss_slot(m.kind) : -1);
}

void rt_pub_event(rt_pub *p, const char *kind, const char *joint, double value,
                  const char *detail)
{
    rt_pub_event_at(p, lag_sim_time(p->sim), kind, joint, value, detail, false);
}

void rt_pub_eventf(rt_pub *p, const char *kind, double value, const char *fmt, ...)
{
    char detail[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    rt_pub_event(p, kind, "", value, detail);
}

void rt_pub_limited(rt_pub *p, rt_ev ev, const char *joint, double value, const char *fmt, ...)
{
    rt_limit *l = &p->lim_event[ev];
    int64_t suppressed = l->suppressed;
    if (!rt_limit_take(l, *p->now)) return;
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
    rt_pub_event(p, ev_limits[ev].kind, joint, value, detail);
}

bool rt_pub_state(rt_pub *p, const lag_model_info *info, const lag_scene_reference *ref)
{
    rt_out o = out(p);
    int n = rt_publish_state(&o, p->sim, info, ref, &p->ref_sent);
    p->want_state = false;
    if (n <= 0) return false;
    p->states_published++;
    memcpy(p->state_buf, p->bus->buf, (size_t)n); /* as sent: a lockstep retry sends it again */
    p->state_len = (unsigned)n;
    return true;
}

void rt_pub_state_again(rt_pub *p)
{
    if (p->state_len == 0) return;
    /* straight to LCM, not through rt_wire's publish: --log keeps one state per period;
     * its reference just before it, as the first time (it may have been lost with it) */
    if (p->ref_sent.len > 0)
        lcm_publish(p->bus->lcm, p->bus->ch_reference, p->ref_sent.buf, p->ref_sent.len);
    lcm_publish(p->bus->lcm, p->bus->ch_state, p->state_buf, p->state_len);
    p->lockstep_retries++;
}

/* A message's bytes as sent (in the bus's buffer), kept. */
static void keep(rt_sent *k, const rt_bus *bus, int n)
{
    if (n <= 0 || (size_t)n > sizeof k->buf) return;
    memcpy(k->buf, bus->buf, (size_t)n);
    k->len = (unsigned)n;
}

void rt_pub_scene(rt_pub *p, const lag_scene *sc, const lag_model_info *info)
{
    rt_out o = out(p);
    keep(&p->last_scene, p->bus, rt_publish_scene(&o, sc, p->sim, info));
}

void rt_pub_new_generation(rt_pub *p, const lag_scene *sc, const lag_model_info *info)
{
    p->generation++;
    rt_pub_scene(p, sc, info);
    p->want_scene = false; /* a DESCRIBE waiting for its answer has it */
}

void rt_pub_status(rt_pub *p, lag_wire_status *m)
{
    rt_out o = out(p);
    keep(&p->last_status, p->bus, rt_publish_status(&o, m));
    p->want_status = false;
}
