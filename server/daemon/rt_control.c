/*
 * The control requests of control_t: see rt_control.h.
 */
#include "rt_control.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rt_command.h"
#include "lagsim/lagsim_control_t.h"

/* every scene the buckets let out in RT_SCENE_ECHO_S is remembered until heard back (a
 * new generation's: SET's and RESET's buckets; an answer to DESCRIBE: the scene bucket) */
_Static_assert(RT_SCENES_KEPT >= RT_SET_BURST + RT_RESET_BURST + RT_SCENE_BURST +
                                     RT_SCENE_ECHO_S * (RT_SET_PER_S + RT_RESET_PER_S +
                                                        RT_SCENE_PER_S),
               "the scenes published are remembered long enough to be known when heard back");

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

void rt_control_init(rt_control *c, const lag_scene *sc, const lagsimd_opts *o,
                     const lag_model_info *info, lag_sim *sim, rt_pub *pub, rt_record *rec,
                     int64_t now)
{
    c->sc = sc;
    c->opts = o;
    c->info = info;
    c->nq = sim->nq;
    c->sim = sim;
    c->pub = pub;
    c->rec = rec;
    c->ref = sc->reference;
    rt_limit_init(&c->lim_set, RT_SET_PER_S, RT_SET_BURST, now);
    rt_limit_init(&c->lim_reset, RT_RESET_PER_S, RT_RESET_BURST, now);
}

bool rt_actuator_lagged(const lag_effects_def *fx, int nq)
{
    for (int i = 0; (fx->enabled & LAG_EFF_ACTUATOR) && i < nq; i++)
        if (fx->actuator_tau[i] > 0) return true;
    return false;
}

void rt_control_rejected(rt_control *c, const char *why)
{
    c->controls_rejected++;
    rt_log_rx_fate(c->rec, *c->pub->now, RT_RX_REFUSED); /* --log: a sample of them */
    rt_pub_limited(c->pub, RT_EV_CONTROL_REJECTED, "", 0, "%s", why);
    c->pub->want_status = true;
}

/* A kick (SET key "kick.<joint>", value "<impulse>[,<duration>]"): a disturbance from
 * the current tick on, added to the scene's and to the kicks not over yet (live_set.c).
 * The answer: a `kick` event whose detail is exactly "kick.<joint>=<value>" and whose step
 * is the tick it starts at (what --replay re-applies), then a status. */
static void handle_kick(rt_control *c, const lag_wire_control *m)
{
    char kv[LIVE_SET_LEN], why[1024];
    if (snprintf(kv, sizeof kv, "%s=%s", m->key, m->value) >= (int)sizeof kv) {
        rt_control_rejected(c, "kick: key=value is too long");
        return;
    }
    if (!rt_limit_take(&c->lim_set, *c->pub->now)) {
        snprintf(why, sizeof why, "%s: more than %d changes a second; this one was not "
                                  "applied", kv, RT_SET_PER_S);
        rt_control_rejected(c, why);
        return;
    }
    live_kick k;
    if (live_kick_apply(&c->live, c->sim, kv, &k, why, sizeof why) != 0) {
        rt_control_rejected(c, why);
        return;
    }
    rt_pub_event(c->pub, "kick", lag_model_info_get(c->sim->def.model.kind)->joint_names[k.joint],
                 k.impulse, kv);
    rt_pub_new_generation(c->pub, c->sc, c->info);
    c->pub->want_status = true;
}

/* SET key=value: the change is validated by the scene loader itself, on the scene's own
 * bytes with its --set overrides, the changes already made and this one after them (so
 * every rule of a scene file holds, with its message: live_set.c), then by the core
 * against the state the run is in; it takes effect at once, at the current tick. Only
 * keys under parameters and effects change while running. The answer: a `set` event
 * whose detail is exactly "key=value" and whose step is the tick it took effect at (what
 * --replay re-applies), and the new scene. A refusal is a control_rejected whose detail
 * names the change and the reason. */
static void handle_set(rt_control *c, const lag_wire_control *m)
{
    char kv[LIVE_SET_LEN], err[512], why[1024];
    if (live_is_kick(m->key)) {
        handle_kick(c, m);
        return;
    }
    if (live_set_parse(m->key, m->value, kv, why, sizeof why) != 0) {
        rt_control_rejected(c, why);
        return;
    }
    if (!rt_limit_take(&c->lim_set, *c->pub->now)) {
        snprintf(why, sizeof why, "set %s: more than %d changes a second; this one was not "
                                  "applied", kv, RT_SET_PER_S);
        rt_control_rejected(c, why);
        return;
    }
    static lag_scene ns; /* large: not on the stack; used by this function only */
    if (live_set_load(c->opts, &c->live, kv, &ns, why, sizeof why) != 0) {
        rt_control_rejected(c, why);
        return;
    }
    /* A lag's actuator state lives within periods: --log records the commanded inputs
     * that let --replay run it only when the scene starts with a lag. */
    if (!rt_actuator_lagged(&c->sc->sim.effects, c->nq) &&
        rt_actuator_lagged(&ns.sim.effects, c->nq)) {
        snprintf(why, sizeof why, "set %s: an actuator lag cannot be switched on while "
                                  "running (a replay could not reproduce the run); give the "
                                  "scene's actuator a lag to start with", kv);
        rt_control_rejected(c, why);
        return;
    }
    if (lag_sim_redefine(c->sim, &ns.sim, err, sizeof err) != LAG_OK) {
        snprintf(why, sizeof why, "set %s: %s", kv, err);
        rt_control_rejected(c, why);
        return;
    }
    c->ref = ns.reference; /* SET reference.*: from the next state on */
    live_set_keep(&c->live, kv);
    rt_pub_event(c->pub, "set", "", 0, kv);
    rt_pub_new_generation(c->pub, c->sc, c->info); /* the new scene, before any state */
    c->pub->want_status = true;
}

/* The requests of control_t, by value (lcmtypes/control_t.lcm): what a rejection of an
 * unknown one offers. */
static const char *control_requests(void)
{
    static char list[160];
    if (!list[0]) {
        size_t k = 0;
        for (int i = 0; i < 128 && k < sizeof list; i++) {
            const char *name = lag_wire_request_name(i);
            if (!name) continue;
            int w = snprintf(list + k, sizeof list - k, "%s%s = %d", k ? ", " : "", name, i);
            if (w < 0) break;
            k += (size_t)w;
        }
    }
    return list;
}

/* A control request, decoded into m; one that does not decode is rejected (false). Any
 * count a message may carry decodes; reset_to checks it against the model's. */
static bool control_decode(rt_control *c, const uint8_t *data, size_t len, lag_wire_control *m)
{
    int d = lag_wire_decode_control(data, len, LAG_WIRE_MAX_JOINTS, m);
    if (d == LAG_WIRE_OK) return true;
    if (d != LAG_WIRE_ECOUNT) rt_log_rx_fate(c->rec, *c->pub->now, RT_RX_UNDECODABLE);
    char why[LAG_WIRE_TEXT_LEN];
    if (d == LAG_WIRE_ECOUNT)
        snprintf(why, sizeof why, "control: num_joints out of range; accepted: 0, or %d "
                 "for reset_to (the joints of %s)", c->nq, c->info->name);
    else
        snprintf(why, sizeof why, "control: %zu bytes that are no lagsim.control_t; "
                 "accepted: a control_t as lcm-gen encodes it (lcmtypes/control_t.lcm)", len);
    rt_control_rejected(c, why);
    return false;
}

/* The requests, one step each. PAUSE and RESUME: not in the fault state. */
static rt_act control_run(rt_control *c, rt_run run, rt_act_kind kind)
{
    if (run == RT_FAULT) {
        rt_control_rejected(c, kind == RT_ACT_PAUSE ? "pause: in fault state (reset first)"
                                                    : "resume: in fault state (reset first)");
        return (rt_act){.kind = RT_ACT_NONE};
    }
    return (rt_act){.kind = kind};
}

/* STEP N: only while paused or waiting. */
static rt_act control_step(rt_control *c, rt_run run, int64_t count)
{
    if (run != RT_PAUSED && run != RT_WAITING) {
        rt_control_rejected(c, run == RT_FAULT ? "step: in fault state (reset first)"
                                               : "step: only while paused or waiting "
                                                 "(pause first)");
        return (rt_act){.kind = RT_ACT_NONE};
    }
    if (count < 1) {
        char why[96];
        snprintf(why, sizeof why, "step: count %lld; accepted: a count >= 1", (long long)count);
        rt_control_rejected(c, why);
        return (rt_act){.kind = RT_ACT_NONE};
    }
    return (rt_act){.kind = RT_ACT_STEP, .count = count};
}

/* Resets within their bucket (RT_RESET_PER_S); false: refused. */
static bool reset_allowed(rt_control *c, const char *what)
{
    if (rt_limit_take(&c->lim_reset, *c->pub->now)) return true;
    char why[160];
    snprintf(why, sizeof why, "%s: more than %d resets a second; this one was not applied",
             what, RT_RESET_PER_S);
    rt_control_rejected(c, why);
    return false;
}

/* RESET and RESET_TO's count: a set of the bits `accepted` (LAG_WIRE_RESET_*); false:
 * refused, naming the values accepted. Checked before the reset bucket is drawn on. */
static bool reset_flags_ok(rt_control *c, const char *what, int64_t count, int64_t accepted)
{
    if (count >= 0 && (count & ~accepted) == 0) return true;
    char why[LAG_WIRE_TEXT_LEN];
    if (accepted & LAG_WIRE_RESET_SCENE)
        snprintf(why, sizeof why, "%s: count %lld; accepted: 0, %d (the scene file's values "
                 "too), %d (then wait for the first command) or %d (both)", what,
                 (long long)count, LAG_WIRE_RESET_SCENE, LAG_WIRE_RESET_WAIT,
                 LAG_WIRE_RESET_SCENE | LAG_WIRE_RESET_WAIT);
    else
        snprintf(why, sizeof why, "%s: count %lld; accepted: 0 or %d (then wait for the first "
                 "command)", what, (long long)count, LAG_WIRE_RESET_WAIT);
    rt_control_rejected(c, why);
    return false;
}

/* RESET; count bit LAG_WIRE_RESET_SCENE: the scene file's values too, after a `restore`
 * event (never suppressed: --replay undoes the changes where it says) before the reset's;
 * bit LAG_WIRE_RESET_WAIT: then wait for the first command. */
static rt_act control_reset(rt_control *c, int64_t count)
{
    if (!reset_flags_ok(c, "reset", count, LAG_WIRE_RESET_SCENE | LAG_WIRE_RESET_WAIT))
        return (rt_act){.kind = RT_ACT_NONE};
    if (!reset_allowed(c, "reset")) return (rt_act){.kind = RT_ACT_NONE};
    bool scene = (count & LAG_WIRE_RESET_SCENE) != 0;
    if (scene && (c->live.n > 0 || c->live.nk > 0)) {
        char err[512], why[700];
        if (lag_sim_redefine(c->sim, &c->sc->sim, err, sizeof err) != LAG_OK) {
            snprintf(why, sizeof why, "reset to the scene file's values: %s", err);
            rt_control_rejected(c, why);
            return (rt_act){.kind = RT_ACT_NONE};
        }
        char undone[180], detail[LAG_WIRE_TEXT_LEN];
        live_set_describe(&c->live, undone, sizeof undone);
        snprintf(detail, sizeof detail, "the scene file's values again: undone %s%s%d "
                 "kick(s)", undone, undone[0] ? ", " : "", c->live.nk);
        rt_pub_event(c->pub, "restore", "", (double)c->live.n, detail);
        memset(&c->live, 0, sizeof c->live);
        c->ref = c->sc->reference;
    }
    return (rt_act){.kind = RT_ACT_RESET,
                    .what = scene ? "reset to the scene file's initial state and values"
                                  : "reset to the scene's initial state",
                    .wait = (count & LAG_WIRE_RESET_WAIT) != 0};
}

/* RESET_TO: a state of the model's joints, finite, within explode_limit, where the mass
 * matrix is positive definite and the stick is not below the floor; count: 0 or
 * LAG_WIRE_RESET_WAIT. */
static rt_act control_reset_to(rt_control *c, const lag_wire_control *m)
{
    rt_act none = {.kind = RT_ACT_NONE};
    if (m->num_joints != c->nq) {
        char why[LAG_WIRE_TEXT_LEN], all[160];
        snprintf(why, sizeof why, "reset_to: num_joints %d; accepted: %d, the joints of %s "
                 "in this order: %s", m->num_joints, c->nq, c->info->name,
                 rt_joint_list(c->info, c->nq, false, all, sizeof all));
        rt_control_rejected(c, why);
        return none;
    }
    double lim = c->sc->sim.explode_limit;
    for (int i = 0; i < c->nq; i++)
        if (!isfinite(m->q[i]) || !isfinite(m->qd[i]) || fabs(m->q[i]) > lim ||
            fabs(m->qd[i]) > lim) {
            rt_control_rejected(c, "reset_to: q and qd must be finite and within explode_limit");
            return none;
        }
    double qdd[LAG_MAX_DOF];
    if (lag_model_forward(&c->sim->model, m->q, m->qd, NULL, qdd) != LAG_OK) {
        rt_control_rejected(c, "reset_to: mass matrix not positive definite at q");
        return none;
    }
    if (lag_sim_contact(c->sim)[0] && m->q[2] < 0) {
        rt_control_rejected(c, "reset_to: h, the stick's lower end, must not be below the "
                               "floor (h >= 0)");
        return none;
    }
    if (!reset_flags_ok(c, "reset_to", m->count, LAG_WIRE_RESET_WAIT)) return none;
    if (!reset_allowed(c, "reset_to")) return none;
    rt_act a = {.kind = RT_ACT_RESET, .to = true, .what = "reset to a given state",
                .wait = (m->count & LAG_WIRE_RESET_WAIT) != 0};
    for (int i = 0; i < c->nq; i++) {
        a.q[i] = m->q[i];
        a.qd[i] = m->qd[i];
    }
    return a;
}

/* STATUS and DESCRIBE change nothing (--log: a sample of them); their answer is a status
 * or the scene, through its bucket. */
static void control_query(rt_control *c, bool scene)
{
    rt_log_rx_fate(c->rec, *c->pub->now, RT_RX_QUERY);
    if (scene) c->pub->want_scene = true;
    else c->pub->want_status = true;
}

rt_act rt_control_handle(rt_control *c, rt_run run, const uint8_t *data, size_t len)
{
    rt_act none = {.kind = RT_ACT_NONE};
    lag_wire_control m;
    if (!control_decode(c, data, len, &m)) return none;
    switch (m.request) {
    case LAGSIM_CONTROL_T_PAUSE: return control_run(c, run, RT_ACT_PAUSE);
    case LAGSIM_CONTROL_T_RESUME: return control_run(c, run, RT_ACT_RESUME);
    case LAGSIM_CONTROL_T_STEP: return control_step(c, run, m.count);
    case LAGSIM_CONTROL_T_RESET: return control_reset(c, m.count);
    case LAGSIM_CONTROL_T_RESET_TO: return control_reset_to(c, &m);
    case LAGSIM_CONTROL_T_STATUS: control_query(c, false); return none;
    case LAGSIM_CONTROL_T_DESCRIBE: control_query(c, true); return none;
    case LAGSIM_CONTROL_T_SET: handle_set(c, &m); return none;
    default: {
        char why[LAG_WIRE_TEXT_LEN];
        snprintf(why, sizeof why, "control: unknown request %d; accepted: %s", m.request,
                 control_requests());
        rt_control_rejected(c, why);
        return none;
    }
    }
}
