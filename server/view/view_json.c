/*
 * JSON for the page and for scripts: a bounded builder, lagsim's messages as objects,
 * and the whole snapshot (GET /api/state). Strings come from the bus and may be hostile:
 * every one goes through jb_str, which escapes what JSON requires and replaces bytes
 * that are not UTF-8.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "view.h"

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

void jb_str(jbuf *b, const char *s)
{
    jb_put(b, "\"", 1);
    const unsigned char *u = (const unsigned char *)s;
    while (*u && !b->overflow) {
        unsigned c = *u;
        if (c == '"' || c == '\\') {
            char e[2] = {'\\', (char)c};
            jb_put(b, e, 2);
            u++;
        } else if (c < 0x20 || c == 0x7f) {
            char e[8];
            snprintf(e, sizeof e, "\\u%04x", c);
            jb_put(b, e, 6);
            u++;
        } else if (c < 0x80) {
            jb_put(b, (const char *)u, 1);
            u++;
        } else {
            int n = utf8_len(u);
            if (n == 0) {
                jb_put(b, "\\ufffd", 6);
                u++;
            } else {
                jb_put(b, (const char *)u, (size_t)n);
                u += n;
            }
        }
    }
    jb_put(b, "\"", 1);
}

void jb_num(jbuf *b, double x)
{
    if (!isfinite(x)) jb_raw(b, "null");
    else jb_fmt(b, "%.17g", x);
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

void view_json_state(jbuf *b, const lag_wire_joint_state *m)
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
    jb_s(b, "detail", m->detail);
    jb_raw(b, "}");
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

size_t view_json_snapshot(const view_bridge *vb, const view_http *h, char *out, size_t cap)
{
    jbuf b;
    jb_init(&b, out, cap);
    int64_t now = view_mono_ns();
    jb_raw(&b, "{\"bridge\":{");
    jb_key(&b, "prefix", true);
    jb_str(&b, vb->prefix);
    jb_s(&b, "url", vb->url[0] ? vb->url : "LCM default");
    jb_int(&b, "streams", h ? (int64_t)view_http_streams(h) : 0);
    jb_int(&b, "states", vb->n_state);
    jb_int(&b, "statuses", vb->n_status);
    jb_int(&b, "events", vb->n_event);
    jb_int(&b, "scenes", vb->n_scene);
    jb_int(&b, "undecodable", vb->n_undecodable);
    jb_int(&b, "controls_sent", vb->controls_sent);
    jb_int(&b, "controls_refused", vb->controls_refused);
    jb_dbl(&b, "last_message_age_s", vb->last_msg_ns ? (double)(now - vb->last_msg_ns) * 1e-9 : NAN);
    jb_raw(&b, "}");
    jb_key(&b, "scene", false);
    if (vb->scene_seq) view_json_scene(&b, &vb->scene);
    else jb_raw(&b, "null");
    jb_key(&b, "state", false);
    if (vb->state_seq) view_json_state(&b, &vb->state);
    else jb_raw(&b, "null");
    jb_key(&b, "status", false);
    if (vb->status_seq) view_json_status(&b, &vb->status);
    else jb_raw(&b, "null");
    jb_key(&b, "events", false);
    jb_raw(&b, "[");
    int64_t first = vb->event_seq - VIEW_EVENTS_IN_STATE + 1;
    if (first < 1) first = 1;
    for (int64_t s = first; s <= vb->event_seq; s++) {
        if (s > first) jb_raw(&b, ",");
        view_json_event(&b, &vb->events[s % VIEW_EVENTS].ev, s);
    }
    jb_raw(&b, "]}\n");
    return b.overflow ? 0 : b.len;
}
