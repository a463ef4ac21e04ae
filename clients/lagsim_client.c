/*
 * lagsim client library: see lagsim_client.h.
 *
 * Subscriptions are raw lcm_subscribe() handlers that pass the payload to one dispatch
 * function (also behind lag_client_feed), which decodes it with the bounded wire module
 * into scratch structs on the handle, so that a message is kept only whole and valid.
 * Nothing is allocated after lag_client_create.
 */
#include "lagsim_client.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/lcm.h>

#include "lagsim/lagsim_control_t.h"
#include "lagsim_bus.h"

struct lag_client {
    lcm_t *lcm;                  /* the state URL: states, status, events, scene in */
    lcm_t *lcm_cmd;              /* the command URL: commands and control out (publishing
                                  * only: LCM opens no receive socket for it); the same
                                  * lcm_t for memq:// */
    lag_bus bus;
    char prefix[64];
    char ch_state[LAG_BUS_CHANNEL_LEN], ch_status[LAG_BUS_CHANNEL_LEN],
        ch_event[LAG_BUS_CHANNEL_LEN], ch_scene[LAG_BUS_CHANNEL_LEN],
        ch_command[LAG_BUS_CHANNEL_LEN], ch_control[LAG_BUS_CHANNEL_LEN];
    char errmsg[256];

    lag_client_state state;      /* latest state */
    bool have_state, new_state;  /* new: not yet returned by lag_client_wait_state */
    lag_client_scene scene;
    bool have_scene;
    lag_client_status status;
    bool have_status;
    lag_client_counters counters;
    /* the last command sent for the latest state, as encoded (a copy of that state gets
     * it again) */
    uint8_t answer[LAG_WIRE_BUF_SIZE];
    unsigned answer_len;         /* 0: none for the latest state */

    /* decoding scratch: a message is copied to the fields above only when valid */
    union {
        lag_wire_joint_state state;
        lag_wire_scene scene;
        lag_wire_status status;
        lag_wire_event event;
    } tmp;
    uint8_t buf[LAG_WIRE_BUF_SIZE]; /* encoding of outgoing messages */

    lag_client_state_fn on_state;
    void *on_state_user;
    lag_client_status_fn on_status;
    void *on_status_user;
    lag_client_event_fn on_event;
    void *on_event_user;
    lag_client_scene_fn on_scene;
    void *on_scene_user;
};

/* ---------------------------------------------------------------- helpers */

static void set_err(lag_client *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->errmsg, sizeof c->errmsg, fmt, ap);
    va_end(ap);
}

double lag_client_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int64_t wall_utime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* Copies src into dst[cap]; returns false (dst = truncated copy) if it does not fit. */
static bool copy_str(char *dst, size_t cap, const char *src)
{
    if (!src) src = "";
    size_t len = strlen(src);
    if (len >= cap) {
        memcpy(dst, src, cap - 1);
        dst[cap - 1] = '\0';
        return false;
    }
    memcpy(dst, src, len + 1);
    return true;
}

/* Writes src with every POSIX ERE metacharacter backslash-escaped (dst holds
 * 2 strlen(src) + 1). */
static void regex_escape(char *dst, size_t cap, const char *src)
{
    size_t j = 0;
    for (; *src && j + 2 < cap; src++) {
        if (strchr(".[]{}()\\*+?^$|", *src)) dst[j++] = '\\';
        dst[j++] = *src;
    }
    dst[j] = '\0';
}

/* ---------------------------------------------------------------- receiving */

/* Decodes a message of type t into c->tmp; false (counted as dropped) unless it decodes
 * whole, fits the structs and every number in it is finite. */
static bool decode(lag_client *c, lag_wire_type t, const void *data, size_t len)
{
    if (lag_wire_decode(t, data, len, LAG_WIRE_MAX_JOINTS, &c->tmp) == LAG_WIRE_OK &&
        lag_wire_all_finite(t, &c->tmp))
        return true;
    c->counters.dropped++;
    return false;
}

/* One message from `channel`: decoded, kept, passed to the callback. */
static int dispatch(lag_client *c, const char *channel, const void *data, size_t len)
{
    if (!strcmp(channel, c->ch_state)) {
        if (!decode(c, LAG_WIRE_JOINT_STATE, data, len)) return LAG_CLIENT_OK;
        /* Each state once: a copy of the latest state (the same utime, step and sim_time:
         * in lockstep the daemon publishes a state again until an answer to it arrives)
         * is neither returned nor passed to on_state, so the control law runs once per
         * state and a law slower than the copies never falls behind on them; a command
         * already sent for it goes out again at once (the first may have been lost). */
        const lag_wire_joint_state *m = &c->tmp.state;
        if (c->have_state && m->utime == c->state.utime && m->step == c->state.step &&
            m->sim_time == c->state.sim_time) {
            c->counters.states++; /* received and valid: kept, as the state it copies */
            c->counters.copies++;
            if (c->answer_len > 0 &&
                lcm_publish(c->lcm_cmd, c->ch_command, c->answer, c->answer_len) == 0)
                c->counters.repeats++;
            return LAG_CLIENT_OK;
        }
        c->answer_len = 0;
        c->state = c->tmp.state;
        c->have_state = c->new_state = true;
        c->counters.states++;
        if (c->on_state) c->on_state(&c->state, c->on_state_user);
    } else if (!strcmp(channel, c->ch_scene)) {
        if (!decode(c, LAG_WIRE_SCENE, data, len)) return LAG_CLIENT_OK;
        c->scene = c->tmp.scene;
        c->have_scene = true;
        c->counters.scenes++;
        if (c->on_scene) c->on_scene(&c->scene, c->on_scene_user);
    } else if (!strcmp(channel, c->ch_status)) {
        if (!decode(c, LAG_WIRE_STATUS, data, len)) return LAG_CLIENT_OK;
        c->status = c->tmp.status;
        c->have_status = true;
        c->counters.statuses++;
        if (c->on_status) c->on_status(&c->status, c->on_status_user);
    } else if (!strcmp(channel, c->ch_event)) {
        if (!decode(c, LAG_WIRE_EVENT, data, len)) return LAG_CLIENT_OK;
        c->counters.events++;
        if (c->on_event) c->on_event(&c->tmp.event, c->on_event_user);
    } else {
        set_err(c, "feed: %s is not one of this handle's channels (%s_*)", channel, c->prefix);
        return LAG_CLIENT_ERR_ARG;
    }
    return LAG_CLIENT_OK;
}

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    dispatch(user, channel, rbuf->data, rbuf->data_size);
}

int lag_client_feed(lag_client *c, const char *channel, const void *data, size_t len)
{
    if (!channel || (!data && len > 0)) {
        set_err(c, "feed: NULL channel or data");
        return LAG_CLIENT_ERR_ARG;
    }
    return dispatch(c, channel, data ? data : "", len);
}

/* ---------------------------------------------------------------- life cycle */

lag_client *lag_client_create(const char *url, const char *prefix, char *err, size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    if (!prefix || !prefix[0] || strlen(prefix) >= 64) {
        if (err) snprintf(err, errlen, "prefix must be 1 to 63 characters");
        return NULL;
    }
    lag_client *c = calloc(1, sizeof *c);
    if (!c) {
        if (err) snprintf(err, errlen, "out of memory");
        return NULL;
    }
    /* the plant's two URLs from url (NULL or "": LCM_DEFAULT_URL, else LCM's default) */
    char berr[256];
    if (lag_bus_init(&c->bus, url, prefix, berr, sizeof berr) != 0) {
        if (err) snprintf(err, errlen, "%s", berr);
        free(c);
        return NULL;
    }
    c->lcm = lcm_create(c->bus.state_url);
    c->lcm_cmd = !c->lcm ? NULL : c->bus.udpm ? lcm_create(c->bus.command_url) : c->lcm;
    if (!c->lcm || !c->lcm_cmd) {
        if (err)
            snprintf(err, errlen, "cannot create LCM for %s",
                     c->lcm ? c->bus.command_url : c->bus.state_url);
        if (c->lcm) lcm_destroy(c->lcm);
        free(c);
        return NULL;
    }
    copy_str(c->prefix, sizeof c->prefix, prefix);
    snprintf(c->ch_state, sizeof c->ch_state, "%s", c->bus.channel[LAG_BUS_STATE]);
    snprintf(c->ch_status, sizeof c->ch_status, "%s", c->bus.channel[LAG_BUS_STATUS]);
    snprintf(c->ch_event, sizeof c->ch_event, "%s", c->bus.channel[LAG_BUS_EVENT]);
    snprintf(c->ch_scene, sizeof c->ch_scene, "%s", c->bus.channel[LAG_BUS_SCENE]);
    snprintf(c->ch_command, sizeof c->ch_command, "%s", c->bus.channel[LAG_BUS_COMMAND]);
    snprintf(c->ch_control, sizeof c->ch_control, "%s", c->bus.channel[LAG_BUS_CONTROL]);
    /* lcm_subscribe takes a POSIX regular expression: escape the channel names so that
     * a prefix with regex characters still matches only itself. */
    char re[4][200];
    const char *chans[4] = {c->ch_state, c->ch_status, c->ch_event, c->ch_scene};
    for (int k = 0; k < 4; k++) regex_escape(re[k], sizeof re[k], chans[k]);
    lcm_subscription_t *s1 = lcm_subscribe(c->lcm, re[0], on_message, c);
    lcm_subscription_t *s2 = lcm_subscribe(c->lcm, re[1], on_message, c);
    lcm_subscription_t *s3 = lcm_subscribe(c->lcm, re[2], on_message, c);
    lcm_subscription_t *s4 = lcm_subscribe(c->lcm, re[3], on_message, c);
    if (!s1 || !s2 || !s3 || !s4) {
        if (err) snprintf(err, errlen, "cannot subscribe to %s_*", prefix);
        lag_client_destroy(c);
        return NULL;
    }
    /* The state subscription keeps a deeper queue: a slow controller still sees states
     * in order rather than losing them inside LCM. */
    lcm_subscription_set_queue_capacity(s1, 64);
    return c;
}

void lag_client_destroy(lag_client *c)
{
    if (!c) return;
    if (c->lcm_cmd && c->lcm_cmd != c->lcm) lcm_destroy(c->lcm_cmd);
    if (c->lcm) lcm_destroy(c->lcm);
    free(c);
}

const char *lag_client_errmsg(const lag_client *c) { return c ? c->errmsg : "no client"; }

int lag_client_fileno(const lag_client *c) { return lcm_get_fileno(c->lcm); }

void lag_client_on_state(lag_client *c, lag_client_state_fn fn, void *user)
{
    c->on_state = fn;
    c->on_state_user = user;
}
void lag_client_on_status(lag_client *c, lag_client_status_fn fn, void *user)
{
    c->on_status = fn;
    c->on_status_user = user;
}
void lag_client_on_event(lag_client *c, lag_client_event_fn fn, void *user)
{
    c->on_event = fn;
    c->on_event_user = user;
}

void lag_client_on_scene(lag_client *c, lag_client_scene_fn fn, void *user)
{
    c->on_scene = fn;
    c->on_scene_user = user;
}

void lag_client_get_counters(const lag_client *c, lag_client_counters *out)
{
    *out = c->counters;
}

/* ---------------------------------------------------------------- waiting */

int lag_client_handle(lag_client *c, int timeout_ms)
{
    if (timeout_ms < 0) timeout_ms = 0;
    errno = 0;
    int rc = lcm_handle_timeout(c->lcm, timeout_ms);
    if (rc < 0 && errno == EINTR) return LAG_CLIENT_TIMEOUT; /* a signal (e.g. SIGINT) */
    if (rc < 0) {
        set_err(c, "lcm_handle_timeout failed");
        return LAG_CLIENT_ERR_LCM;
    }
    return rc > 0 ? LAG_CLIENT_OK : LAG_CLIENT_TIMEOUT;
}

/* Handles messages until `flag` becomes true or the deadline (monotonic s) passes.
 * Returns LAG_CLIENT_OK if flag, LAG_CLIENT_TIMEOUT, or an error. */
static int handle_until(lag_client *c, const bool *flag, double deadline)
{
    while (!*flag) {
        double left = deadline - lag_client_now();
        if (!(left > 0.0)) return LAG_CLIENT_TIMEOUT;
        int ms = left < 0.1 ? (int)ceil(left * 1000.0) : 100;
        int rc = lag_client_handle(c, ms);
        if (rc < 0) return rc;
    }
    return LAG_CLIENT_OK;
}

int lag_client_wait_scene(lag_client *c, double timeout_s, lag_client_scene *sc)
{
    double t0 = lag_client_now(), deadline = t0 + timeout_s;
    while (!c->have_scene) {
        int rc = lag_client_request_describe(c);
        if (rc < 0) return rc;
        double next = lag_client_now() + 0.25;
        rc = handle_until(c, &c->have_scene, next < deadline ? next : deadline);
        if (rc < 0) return rc;
        if (!c->have_scene && lag_client_now() >= deadline) {
            set_err(c, "no scene description on %s within %.1f s (is lagsimd running with "
                       "lcm.prefix %s on the same LCM URL?)",
                    c->ch_scene, timeout_s, c->prefix);
            return LAG_CLIENT_TIMEOUT;
        }
    }
    if (sc) *sc = c->scene;
    return LAG_CLIENT_OK;
}

int lag_client_wait_state(lag_client *c, double timeout_s, lag_client_state *st)
{
    int rc = handle_until(c, &c->new_state, lag_client_now() + timeout_s);
    if (rc != LAG_CLIENT_OK) {
        if (rc == LAG_CLIENT_TIMEOUT)
            set_err(c, "no state on %s within %.3f s", c->ch_state, timeout_s);
        return rc;
    }
    /* drain what is already queued so that the newest state is returned */
    for (int i = 0; i < 1000; i++) {
        rc = lag_client_handle(c, 0);
        if (rc < 0) return rc;
        if (rc == LAG_CLIENT_TIMEOUT) break;
    }
    c->new_state = false;
    if (st) *st = c->state;
    return LAG_CLIENT_OK;
}

bool lag_client_latest_state(const lag_client *c, lag_client_state *st)
{
    if (c->have_state && st) *st = c->state;
    return c->have_state;
}

bool lag_client_latest_status(const lag_client *c, lag_client_status *st)
{
    if (c->have_status && st) *st = c->status;
    return c->have_status;
}

/* ---------------------------------------------------------------- sending */

/* Encodes message m of type t and publishes it on channel. */
static int publish(lag_client *c, const char *channel, lag_wire_type t, const void *m)
{
    int n = lag_wire_encode(t, m, c->buf, sizeof c->buf);
    if (n < 0) {
        set_err(c, "%s: %s", lag_wire_type_name(t), lag_wire_result_string(n));
        return LAG_CLIENT_ERR_ARG;
    }
    if (lcm_publish(c->lcm_cmd, channel, c->buf, (unsigned)n) != 0) {
        set_err(c, "publish on %s failed", channel);
        return LAG_CLIENT_ERR_LCM;
    }
    return LAG_CLIENT_OK;
}

int lag_client_send_command(lag_client *c, double sim_time, int n, const char *const *names,
                            const double *effort)
{
    if (n < 0 || n > LAG_CLIENT_MAX_JOINTS || (n > 0 && (!names || !effort))) {
        set_err(c, "send_command: %d joints (0 to %d, with names and efforts)", n,
                LAG_CLIENT_MAX_JOINTS);
        return LAG_CLIENT_ERR_ARG;
    }
    lag_wire_joint_command m;
    memset(&m, 0, sizeof m);
    m.utime = wall_utime();
    m.sim_time = sim_time;
    m.num_joints = (int16_t)n;
    for (int i = 0; i < n; i++) {
        if (!names[i] || !copy_str(m.name[i], sizeof m.name[i], names[i])) {
            set_err(c, "send_command: joint name %d is %s", i,
                    names[i] ? "64 bytes or longer" : "NULL");
            return LAG_CLIENT_ERR_ARG;
        }
        m.effort[i] = effort[i];
    }
    if (!lag_wire_all_finite(LAG_WIRE_JOINT_COMMAND, &m)) {
        set_err(c, "send_command: a NaN or infinite effort or sim_time is never sent");
        return LAG_CLIENT_ERR_ARG;
    }
    int rc = publish(c, c->ch_command, LAG_WIRE_JOINT_COMMAND, &m);
    if (rc != LAG_CLIENT_OK) return rc;
    c->counters.commands_sent++;
    if (c->have_state && sim_time == c->state.sim_time) { /* answers the latest state */
        int n_enc = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &m, c->answer, sizeof c->answer);
        c->answer_len = n_enc > 0 ? (unsigned)n_enc : 0;
    }
    return rc;
}

static int send_control(lag_client *c, int8_t request, int64_t count, int n, const double *q,
                        const double *qd)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    m.utime = wall_utime();
    m.request = request;
    m.count = count;
    m.num_joints = (int16_t)n;
    for (int i = 0; i < n; i++) {
        m.q[i] = q[i];
        m.qd[i] = qd[i];
    }
    if (!lag_wire_all_finite(LAG_WIRE_CONTROL, &m)) {
        set_err(c, "reset_to: a NaN or infinite q or qd is never sent");
        return LAG_CLIENT_ERR_ARG;
    }
    int rc = publish(c, c->ch_control, LAG_WIRE_CONTROL, &m);
    if (rc == LAG_CLIENT_OK) c->counters.controls_sent++;
    return rc;
}

int lag_client_pause(lag_client *c) { return send_control(c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL); }
int lag_client_resume(lag_client *c) { return send_control(c, LAGSIM_CONTROL_T_RESUME, 0, 0, NULL, NULL); }
int lag_client_reset(lag_client *c) { return send_control(c, LAGSIM_CONTROL_T_RESET, 0, 0, NULL, NULL); }
int lag_client_request_status(lag_client *c)
{
    return send_control(c, LAGSIM_CONTROL_T_STATUS, 0, 0, NULL, NULL);
}
int lag_client_request_describe(lag_client *c)
{
    return send_control(c, LAGSIM_CONTROL_T_DESCRIBE, 0, 0, NULL, NULL);
}

int lag_client_set(lag_client *c, const char *key, const char *value)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    if (!key || !value || !key[0] || !value[0] || strlen(key) >= sizeof m.key ||
        strlen(value) >= sizeof m.value) {
        set_err(c, "set: key and value must be 1 to %zu and 1 to %zu bytes", sizeof m.key - 1,
                sizeof m.value - 1);
        return LAG_CLIENT_ERR_ARG;
    }
    m.utime = wall_utime();
    m.request = LAGSIM_CONTROL_T_SET;
    memcpy(m.key, key, strlen(key) + 1);
    memcpy(m.value, value, strlen(value) + 1);
    int rc = publish(c, c->ch_control, LAG_WIRE_CONTROL, &m);
    if (rc == LAG_CLIENT_OK) c->counters.controls_sent++;
    return rc;
}

int lag_client_step(lag_client *c, int64_t count)
{
    if (count < 1) {
        set_err(c, "step: count must be >= 1, got %lld", (long long)count);
        return LAG_CLIENT_ERR_ARG;
    }
    return send_control(c, LAGSIM_CONTROL_T_STEP, count, 0, NULL, NULL);
}

int lag_client_reset_to(lag_client *c, int n, const double *q, const double *qd)
{
    if (n < 1 || n > LAG_CLIENT_MAX_JOINTS || !q || !qd) {
        set_err(c, "reset_to: %d joints (1 to %d, with q and qd)", n, LAG_CLIENT_MAX_JOINTS);
        return LAG_CLIENT_ERR_ARG;
    }
    return send_control(c, LAGSIM_CONTROL_T_RESET_TO, 0, n, q, qd);
}

/* ---------------------------------------------------------------- lookups */

int lag_client_scene_joint(const lag_client_scene *sc, const char *name)
{
    for (int i = 0; i < sc->num_joints; i++)
        if (strcmp(sc->joint_name[i], name) == 0) return i;
    return -1;
}

double lag_client_scene_param(const lag_client_scene *sc, const char *name)
{
    for (int i = 0; i < sc->num_params; i++)
        if (strcmp(sc->param_name[i], name) == 0) return sc->param_value[i];
    return NAN;
}

int lag_client_state_joint(const lag_client_state *st, const char *name)
{
    for (int i = 0; i < st->num_joints; i++)
        if (strcmp(st->name[i], name) == 0) return i;
    return -1;
}
