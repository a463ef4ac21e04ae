/*
 * JSON for the page and for scripts: a bounded builder, lagsim's messages as objects,
 * and the whole snapshot (GET /api/state). Strings come from the bus and may be hostile:
 * every one goes through jb_str, which escapes what JSON requires and replaces bytes
 * that are not UTF-8.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "view.h"
#include "lagsim_num.h"

void jb_init(jbuf *b, char *mem, size_t cap)
{
    b->p = mem;
    b->cap = cap;
    b->len = 0;
    b->overflow = cap == 0;
    if (cap) mem[0] = '\0';
}

static void jb_put(jbuf *b, const char *s, size_t n)
{
    if (b->overflow) return;
    if (n >= b->cap - b->len) {
        b->overflow = true;
        return;
    }
    memcpy(b->p + b->len, s, n);
    b->len += n;
    b->p[b->len] = '\0';
}

void jb_raw(jbuf *b, const char *s) { jb_put(b, s, strlen(s)); }

void jb_fmt(jbuf *b, const char *fmt, ...)
{
    char tmp[256];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof tmp) {
        b->overflow = true;
        return;
    }
    jb_put(b, tmp, (size_t)n);
}

/* Length of the valid UTF-8 sequence at s (1..4), or 0 if it is not one. */
static int utf8_len(const unsigned char *s)
{
    unsigned c = s[0];
    int n;
    unsigned min;
    if (c < 0x80) return 1;
    if (c >= 0xc2 && c <= 0xdf) n = 2, min = 0x80;
    else if (c >= 0xe0 && c <= 0xef) n = 3, min = 0x800;
    else if (c >= 0xf0 && c <= 0xf4) n = 4, min = 0x10000;
    else return 0;
    unsigned cp = c & (0x7f >> n);
    for (int i = 1; i < n; i++) {
        if ((s[i] & 0xc0) != 0x80) return 0; /* also stops at the NUL */
        cp = (cp << 6) | (s[i] & 0x3f);
    }
    if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
    return n;
}

/* The escaped form of the character at u: its bytes into e (up to 6), how many input
 * bytes it takes in *used. */
static size_t escape_one(const unsigned char *u, char e[8], size_t *used)
{
    unsigned c = *u;
    *used = 1;
    if (c == '"' || c == '\\') {
        e[0] = '\\';
        e[1] = (char)c;
        return 2;
    }
    if (c < 0x20 || c == 0x7f) {
        snprintf(e, 8, "\\u%04x", c);
        return 6;
    }
    if (c < 0x80) {
        e[0] = (char)c;
        return 1;
    }
    int n = utf8_len(u);
    if (n == 0) {
        memcpy(e, "\\ufffd", 6);
        return 6;
    }
    memcpy(e, u, (size_t)n);
    *used = (size_t)n;
    return (size_t)n;
}

/* room kept for the marker "…[truncated N bytes]" */
#define JB_MARK_MAX 48

void jb_str_max(jbuf *b, const char *s, size_t budget)
{
    if (budget < 2 * JB_MARK_MAX) budget = 2 * JB_MARK_MAX;
    const unsigned char *u = (const unsigned char *)s;
    size_t out = 0, used;
    char e[8];
    /* does it fit whole? */
    for (const unsigned char *v = u; *v && out <= budget; v += used) out += escape_one(v, e, &used);
    bool whole = out <= budget;
    jb_put(b, "\"", 1);
    out = 0;
    while (*u && !b->overflow) {
        size_t n = escape_one(u, e, &used);
        if (!whole && out + n > budget - JB_MARK_MAX) break;
        jb_put(b, e, n);
        out += n;
        u += used;
    }
    if (*u && !b->overflow) {
        char m[JB_MARK_MAX + 1];
        snprintf(m, sizeof m, "\xe2\x80\xa6[truncated %zu bytes]", strlen((const char *)u));
        jb_raw(b, m);
    }
    jb_put(b, "\"", 1);
}

void jb_str(jbuf *b, const char *s) { jb_str_max(b, s, VIEW_JSON_NAME_MAX); }

void jb_num(jbuf *b, double x)
{
    if (!isfinite(x)) jb_raw(b, "null");
    else {
        char s[LAG_NUM_LEN];
        jb_raw(b, lag_num(x, s));
    }
}

void jb_key(jbuf *b, const char *key, bool first)
{
    if (!first) jb_put(b, ",", 1);
    jb_str(b, key);
    jb_put(b, ":", 1);
}

static void jb_int(jbuf *b, const char *key, int64_t v) { jb_key(b, key, false); jb_fmt(b, "%lld", (long long)v); }
static void jb_dbl(jbuf *b, const char *key, double v) { jb_key(b, key, false); jb_num(b, v); }
static void jb_s(jbuf *b, const char *key, const char *v) { jb_key(b, key, false); jb_str(b, v); }

static void jb_num_array(jbuf *b, const char *key, const double *v, int n)
{
    jb_key(b, key, false);
    jb_raw(b, "[");
    for (int i = 0; i < n; i++) {
        if (i) jb_raw(b, ",");
        jb_num(b, v[i]);
    }
    jb_raw(b, "]");
}

static void jb_str_array(jbuf *b, const char *key, const char (*v)[LAG_WIRE_NAME_LEN], int n)
{
    jb_key(b, key, false);
    jb_raw(b, "[");
    for (int i = 0; i < n; i++) {
        if (i) jb_raw(b, ",");
        jb_str(b, v[i]);
    }
    jb_raw(b, "]");
}

static int joints(int n) { return n < 0 ? 0 : n > LAG_WIRE_MAX_JOINTS ? LAG_WIRE_MAX_JOINTS : n; }

void view_json_state(jbuf *b, const lag_wire_joint_state *m, const lag_wire_reference *ref)
{
    int n = joints(m->num_joints);
    jb_raw(b, "{");
    jb_key(b, "sim_time", true);
    jb_num(b, m->sim_time);
    jb_int(b, "utime", m->utime);
    jb_int(b, "step", m->step);
    jb_str_array(b, "name", m->name, n);
    jb_num_array(b, "q", m->position, n);
    jb_num_array(b, "qd", m->velocity, n);
    jb_num_array(b, "effort", m->effort, n);
    int nr = ref ? joints(ref->num_joints) : 0;
    if (nr > 0) { /* the scene's reference at this state's time */
        jb_key(b, "ref", false);
        jb_raw(b, "{");
        jb_key(b, "sim_time", true);
        jb_num(b, ref->sim_time);
        jb_str_array(b, "name", ref->name, nr);
        jb_num_array(b, "r", ref->r, nr);
        jb_num_array(b, "rdot", ref->rdot, nr);
        jb_raw(b, "}");
    }
    jb_raw(b, "}");
}

void view_json_status(jbuf *b, const lag_wire_status *m)
{
    jb_raw(b, "{");
    jb_key(b, "sim_time", true);
    jb_num(b, m->sim_time);
    jb_int(b, "utime", m->utime);
    jb_int(b, "step", m->step);
    jb_dbl(b, "wall_time", m->wall_time);
    jb_dbl(b, "rtf", m->rtf);
    jb_int(b, "overruns", m->overruns);
    jb_dbl(b, "step_time_max_us", m->step_time_max_us);
    jb_dbl(b, "step_time_mean_us", m->step_time_mean_us);
    jb_dbl(b, "energy", m->energy);
    jb_s(b, "integrator", m->integrator);
    jb_s(b, "mode", m->mode);
    jb_s(b, "run_state", m->run_state);
    jb_int(b, "commands_accepted", m->commands_accepted);
    jb_int(b, "rejected_unknown_joint", m->rejected_unknown_joint);
    jb_int(b, "rejected_unactuated", m->rejected_unactuated);
    jb_int(b, "rejected_nonfinite", m->rejected_nonfinite);
    jb_int(b, "rejected_bad_length", m->rejected_bad_length);
    jb_int(b, "rejected_undecodable", m->rejected_undecodable);
    jb_int(b, "rejected_stale", m->rejected_stale);
    jb_int(b, "controls_rejected", m->controls_rejected);
    jb_key(b, "watchdog_tripped", false);
    jb_raw(b, m->watchdog_tripped ? "true" : "false");
    jb_int(b, "watchdog_trips", m->watchdog_trips);
    jb_int(b, "lockstep_timeouts", m->lockstep_timeouts);
    jb_int(b, "numeric_faults", m->numeric_faults);
    jb_int(b, "overrun_bursts", m->overrun_bursts);
    jb_int(b, "states_published", m->states_published);
    jb_int(b, "plant_conflicts", m->plant_conflicts);
    jb_dbl(b, "error_estimate", m->error_estimate);
    jb_s(b, "error_joint", m->error_joint);
    jb_dbl(b, "error_budget", m->error_budget);
    jb_int(b, "error_warnings", m->error_warnings);
    jb_raw(b, "}");
}

void view_json_event(jbuf *b, const lag_wire_event *m, int64_t seq)
{
    jb_raw(b, "{");
    jb_key(b, "seq", true);
    jb_fmt(b, "%lld", (long long)seq);
    jb_dbl(b, "sim_time", m->sim_time);
    jb_int(b, "utime", m->utime);
    jb_int(b, "step", m->step);
    jb_s(b, "kind", m->kind);
    jb_s(b, "joint", m->joint);
    jb_dbl(b, "value", m->value);
    jb_key(b, "detail", false);
    jb_str_max(b, m->detail, VIEW_JSON_TEXT_MAX);
    jb_raw(b, "}");
}

/* The core's model whose joints are the scene's (lag_model_info_by_joints), or NULL: where
 * a joint's unit (m or rad) comes from. */
static const lag_model_info *scene_model(const lag_wire_scene *m, int n)
{
    const char *names[LAG_WIRE_MAX_JOINTS];
    for (int i = 0; i < n; i++) names[i] = m->joint_name[i];
    return lag_model_info_by_joints(names, n);
}

void view_json_scene(jbuf *b, const lag_wire_scene *m)
{
    int n = joints(m->num_joints);
    int np = m->num_params < 0 ? 0 : m->num_params > LAG_WIRE_MAX_PARAMS ? LAG_WIRE_MAX_PARAMS
                                                                          : m->num_params;
    jb_raw(b, "{");
    jb_key(b, "model", true);
    jb_str(b, m->model);
    jb_s(b, "prefix", m->prefix);
    jb_int(b, "utime", m->utime);
    jb_key(b, "params", false);
    jb_raw(b, "{");
    for (int i = 0; i < np; i++) {
        jb_key(b, m->param_name[i], i == 0);
        jb_num(b, m->param_value[i]);
    }
    jb_raw(b, "}");
    jb_str_array(b, "joints", m->joint_name, n);
    jb_key(b, "actuated", false);
    jb_raw(b, "[");
    for (int i = 0; i < n; i++) jb_raw(b, i ? (m->actuated[i] ? ",true" : ",false") : (m->actuated[i] ? "true" : "false"));
    jb_raw(b, "]");
    /* "m" or "rad" per joint from the core's table (null: a model it does not know) */
    const lag_model_info *info = scene_model(m, n);
    jb_key(b, "units", false);
    jb_raw(b, "[");
    for (int i = 0; i < n; i++) {
        if (i) jb_raw(b, ",");
        jb_raw(b, !info ? "null" : info->angular[i] ? "\"rad\"" : "\"m\"");
    }
    jb_raw(b, "]");
    jb_num_array(b, "initial_q", m->initial_q, n);
    jb_num_array(b, "initial_qd", m->initial_qd, n);
    jb_dbl(b, "dt", m->dt);
    jb_dbl(b, "control_period", m->control_period);
    jb_s(b, "integrator", m->integrator);
    jb_s(b, "mode", m->mode);
    jb_dbl(b, "rate", m->rate);
    jb_dbl(b, "command_timeout", m->command_timeout);
    jb_s(b, "effects", m->effects);
    jb_key(b, "limits", false);
    jb_raw(b, "[");
    for (int i = 0; i < n; i++) {
        if (i) jb_raw(b, ",");
        if (!m->limit_on[i]) {
            jb_raw(b, "null");
            continue;
        }
        jb_raw(b, "[");
        jb_num(b, m->limit_lower[i]);
        jb_raw(b, ",");
        jb_num(b, m->limit_upper[i]);
        jb_raw(b, "]");
    }
    jb_raw(b, "]}");
}

/* One part of a document: whole, or (when it does not fit in what is left) `null`, counted
 * in *cut, so that one oversized part never costs the others. */
typedef void (*part_fn)(jbuf *b, const void *m);
static void part(jbuf *b, const char *key, part_fn fn, const void *m, bool present, int *cut)
{
    jb_key(b, key, false);
    size_t keep = b->len;
    if (present) fn(b, m);
    else jb_raw(b, "null");
    if (b->overflow) {
        b->len = keep;
        b->overflow = false;
        jb_raw(b, "null");
        (*cut)++;
    }
}
static void scene_part(jbuf *b, const void *m) { view_json_scene(b, m); }
static void state_part(jbuf *b, const void *vb)
{
    view_json_state(b, &((const view_bridge *)vb)->state, &((const view_bridge *)vb)->state_ref);
}
static void status_part(jbuf *b, const void *m) { view_json_status(b, m); }

size_t view_json_events(jbuf *b, const view_bridge *vb, int64_t first, int64_t last,
                        size_t reserve, int64_t *sent)
{
    size_t n = 0;
    *sent = first - 1;
    if (b->overflow || reserve >= b->cap - b->len) return 0;
    size_t cap = b->cap;
    b->cap -= reserve; /* what must follow still fits */
    for (int64_t q = first; q <= last; q++) {
        size_t keep = b->len;
        if (q > first) jb_raw(b, ",");
        view_json_event(b, &vb->events[q % VIEW_EVENTS].ev, q);
        if (b->overflow) {
            b->len = keep;
            b->overflow = false;
            break;
        }
        *sent = q;
        n++;
    }
    b->cap = cap;
    return n;
}

static void jb_nums(jbuf *b, const double *v, int n)
{
    jb_raw(b, "[");
    for (int i = 0; i < n; i++) {
        if (i) jb_raw(b, ",");
        jb_num(b, v[i]);
    }
    jb_raw(b, "]");
}

size_t view_json_history(const view_bridge *vb, const char *of, const char *from, char *out,
                         size_t cap)
{
    const view_history *h = &vb->hist;
    bool states = of && strcmp(of, "state") == 0;
    if (!states && !(of && strcmp(of, "energy") == 0)) return 0;
    int64_t first = states ? h->state_first : h->energy_first;
    int64_t last = states ? h->state_last : h->energy_last;
    long long f = first;
    if (from) {
        char *end = NULL;
        f = strtoll(from, &end, 10);
        if (end == from || *end || f < 0) return 0;
    }
    if (f < first) f = first;
    jbuf b;
    jb_init(&b, out, cap);
    jb_fmt(&b, "{\"of\":\"%s\",\"first\":%lld,\"last\":%lld,\"samples\":[",
           states ? "state" : "energy", (long long)first, (long long)last);
    if (b.overflow) return 0;
    size_t room = b.cap;
    b.cap -= 48; /* the tail: ],"next":N} */
    int64_t q = f;
    for (; q <= last; q++) {
        size_t keep = b.len;
        if (q > f) jb_raw(&b, ",");
        jb_raw(&b, "[");
        if (states) {
            const view_sample *s = &h->state[q % VIEW_HISTORY];
            jb_num(&b, s->t);
            jb_raw(&b, ",");
            jb_nums(&b, s->q, s->n);
            jb_raw(&b, ",");
            jb_nums(&b, s->qd, s->n);
            jb_raw(&b, ",");
            jb_nums(&b, s->effort, s->n);
        } else {
            jb_num(&b, h->energy_t[q % VIEW_HISTORY]);
            jb_raw(&b, ",");
            jb_num(&b, h->energy[q % VIEW_HISTORY]);
        }
        jb_raw(&b, "]");
        if (b.overflow) {
            b.len = keep;
            b.overflow = false;
            break;
        }
    }
    b.cap = room;
    jb_fmt(&b, "],\"next\":%lld}\n", (long long)q);
    return b.overflow ? 0 : b.len;
}

size_t view_json_snapshot(const view_bridge *vb, const view_http *h, char *out, size_t cap)
{
    jbuf b;
    jb_init(&b, out, cap);
    int64_t now = lag_clock_mono_ns();
    int cut = 0;
    jb_raw(&b, "{\"bridge\":{");
    jb_key(&b, "prefix", true);
    jb_str(&b, vb->prefix);
    jb_key(&b, "url", false);
    jb_str_max(&b, vb->url[0] ? vb->url : "LCM default", VIEW_JSON_TEXT_MAX);
    jb_int(&b, "streams", h ? (int64_t)view_http_streams(h) : 0);
    if (h) view_http_counters(h, &b);
    jb_int(&b, "states", vb->n_state);
    jb_int(&b, "statuses", vb->n_status);
    jb_int(&b, "events", vb->n_event);
    jb_int(&b, "scenes", vb->n_scene);
    jb_int(&b, "undecodable", vb->n_undecodable);
    jb_int(&b, "controls_sent", vb->controls_sent);
    jb_int(&b, "controls_refused", vb->controls_refused);
    jb_dbl(&b, "last_message_age_s", vb->last_msg_ns ? (double)(now - vb->last_msg_ns) * 1e-9 : NAN);
    jb_raw(&b, "}");
    part(&b, "scene", scene_part, &vb->scene, vb->scene_seq != 0, &cut);
    part(&b, "state", state_part, vb, vb->state_seq != 0, &cut);
    part(&b, "status", status_part, &vb->status, vb->status_seq != 0, &cut);
    /* the newest events that fit: from the newest back, what the rest of the buffer holds */
    int64_t first = vb->event_seq - VIEW_EVENTS_IN_STATE + 1;
    if (first < 1) first = 1;
    int64_t omitted = 0;
    if (!b.overflow) {
        static char tmp[VIEW_STREAM_BUF]; /* one thread */
        size_t room = b.cap - b.len, need = 96; /* the keys, brackets and counts after them */
        for (int64_t q = vb->event_seq; q >= first; q--) {
            jbuf t;
            jb_init(&t, tmp, sizeof tmp);
            view_json_event(&t, &vb->events[q % VIEW_EVENTS].ev, q);
            need += t.len + 1;
            if (t.overflow || need > room) {
                omitted = q - first + 1;
                first = q + 1;
                break;
            }
        }
    }
    jb_key(&b, "events", false);
    jb_raw(&b, "[");
    int64_t sent;
    view_json_events(&b, vb, first, vb->event_seq, 96, &sent); /* the tail: < 70 bytes */
    jb_raw(&b, "]");
    jb_int(&b, "events_omitted", omitted + (vb->event_seq - sent));
    jb_int(&b, "parts_omitted", cut);
    jb_raw(&b, "}\n");
    return b.overflow ? 0 : b.len;
}
