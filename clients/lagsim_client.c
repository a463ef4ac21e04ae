/*
 * lagsim client library: see lagsim_client.h.
 *
 * Subscriptions are raw lcm_subscribe() handlers that decode the payload themselves, so
 * that a payload which does not decode (wrong type on the channel, truncated, hostile)
 * is counted and dropped silently instead of making the generated code print.
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
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"

struct lag_client {
    lcm_t *lcm;
    char prefix[64];
    char ch_state[96], ch_status[96], ch_event[96], ch_scene[96], ch_command[96],
        ch_control[96];
    char errmsg[256];

    lag_client_state state;      /* latest state */
    bool have_state, new_state;  /* new: not yet returned by lag_client_wait_state */
    lag_client_scene scene;
    bool have_scene;
    lag_client_status status;
    bool have_status;
    lag_client_counters counters;

    lag_client_state_fn on_state;
    void *on_state_user;
    lag_client_status_fn on_status;
    void *on_status_user;
    lag_client_event_fn on_event;
    void *on_event_user;
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

/* ---------------------------------------------------------------- handlers */

static void handle_state(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    lag_client *c = user;
    lagsim_joint_state_t m;
    if (lagsim_joint_state_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) {
        c->counters.dropped++;
        return;
    }
    lag_client_state st;
    bool ok = m.num_joints >= 0 && m.num_joints <= LAG_CLIENT_MAX_JOINTS;
    if (ok) {
        st.utime = m.utime;
        st.sim_time = m.sim_time;
        st.step = m.step;
        st.num_joints = m.num_joints;
        for (int i = 0; i < m.num_joints && ok; i++) {
            ok = copy_str(st.name[i], sizeof st.name[i], m.name[i]);
            st.position[i] = m.position[i];
            st.velocity[i] = m.velocity[i];
            st.effort[i] = m.effort[i];
        }
    }
    lagsim_joint_state_t_decode_cleanup(&m);
    if (!ok) {
        c->counters.dropped++;
        return;
    }
    c->state = st;
    c->have_state = c->new_state = true;
    c->counters.states++;
    if (c->on_state) c->on_state(&c->state, c->on_state_user);
}

static void handle_scene(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    lag_client *c = user;
    lagsim_scene_t m;
    if (lagsim_scene_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) {
        c->counters.dropped++;
        return;
    }
    lag_client_scene *sc = malloc(sizeof *sc); /* ~2.5 kB: keep it off small stacks */
    bool ok = sc != NULL && m.num_params >= 0 && m.num_params <= LAG_CLIENT_MAX_PARAMS &&
              m.num_joints >= 0 && m.num_joints <= LAG_CLIENT_MAX_JOINTS;
    if (ok) {
        memset(sc, 0, sizeof *sc);
        sc->utime = m.utime;
        ok = copy_str(sc->model, sizeof sc->model, m.model) &&
             copy_str(sc->prefix, sizeof sc->prefix, m.prefix) &&
             copy_str(sc->integrator, sizeof sc->integrator, m.integrator) &&
             copy_str(sc->mode, sizeof sc->mode, m.mode);
        sc->num_params = m.num_params;
        for (int i = 0; i < m.num_params && ok; i++) {
            ok = copy_str(sc->param_name[i], sizeof sc->param_name[i], m.param_name[i]);
            sc->param_value[i] = m.param_value[i];
        }
        sc->num_joints = m.num_joints;
        for (int i = 0; i < m.num_joints && ok; i++) {
            ok = copy_str(sc->joint_name[i], sizeof sc->joint_name[i], m.joint_name[i]);
            sc->actuated[i] = m.actuated[i] != 0;
            sc->initial_q[i] = m.initial_q[i];
            sc->initial_qd[i] = m.initial_qd[i];
        }
        sc->dt = m.dt;
        sc->control_period = m.control_period;
        sc->rate = m.rate;
        sc->command_timeout = m.command_timeout;
    }
    lagsim_scene_t_decode_cleanup(&m);
    if (ok) {
        c->scene = *sc;
        c->have_scene = true;
        c->counters.scenes++;
    } else {
        c->counters.dropped++;
    }
    free(sc);
}

static void handle_status(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    lag_client *c = user;
    lagsim_status_t m;
    if (lagsim_status_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) {
        c->counters.dropped++;
        return;
    }
    lag_client_status *s = &c->status;
    s->utime = m.utime;
    s->sim_time = m.sim_time;
    s->step = m.step;
    s->wall_time = m.wall_time;
    s->rtf = m.rtf;
    s->overruns = m.overruns;
    s->step_time_max_us = m.step_time_max_us;
    s->step_time_mean_us = m.step_time_mean_us;
    s->energy = m.energy;
    copy_str(s->integrator, sizeof s->integrator, m.integrator);
    copy_str(s->mode, sizeof s->mode, m.mode);
    copy_str(s->run_state, sizeof s->run_state, m.run_state);
    s->commands_accepted = m.commands_accepted;
    s->rejected_unknown_joint = m.rejected_unknown_joint;
    s->rejected_unactuated = m.rejected_unactuated;
    s->rejected_nonfinite = m.rejected_nonfinite;
    s->rejected_bad_length = m.rejected_bad_length;
    s->rejected_undecodable = m.rejected_undecodable;
    s->controls_rejected = m.controls_rejected;
    s->watchdog_tripped = m.watchdog_tripped != 0;
    s->watchdog_trips = m.watchdog_trips;
    s->lockstep_timeouts = m.lockstep_timeouts;
    s->numeric_faults = m.numeric_faults;
    lagsim_status_t_decode_cleanup(&m);
    c->have_status = true;
    c->counters.statuses++;
    if (c->on_status) c->on_status(s, c->on_status_user);
}

static void handle_event(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    lag_client *c = user;
    lagsim_event_t m;
    if (lagsim_event_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) {
        c->counters.dropped++;
        return;
    }
    lag_client_event ev;
    ev.utime = m.utime;
    ev.sim_time = m.sim_time;
    ev.step = m.step;
    copy_str(ev.kind, sizeof ev.kind, m.kind);
    copy_str(ev.joint, sizeof ev.joint, m.joint);
    ev.value = m.value;
    copy_str(ev.detail, sizeof ev.detail, m.detail);
    lagsim_event_t_decode_cleanup(&m);
    c->counters.events++;
    if (c->on_event) c->on_event(&ev, c->on_event_user);
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
    /* lcm_create(NULL) uses LCM_DEFAULT_URL if set, else udpm://239.255.76.67:7667?ttl=0 */
    c->lcm = lcm_create(url && url[0] ? url : NULL);
    if (!c->lcm) {
        if (err)
            snprintf(err, errlen, "cannot create LCM for %s",
                     url && url[0] ? url : "the default URL (LCM_DEFAULT_URL or udpm)");
        free(c);
        return NULL;
    }
    copy_str(c->prefix, sizeof c->prefix, prefix);
    snprintf(c->ch_state, sizeof c->ch_state, "%s_STATE", prefix);
    snprintf(c->ch_status, sizeof c->ch_status, "%s_STATUS", prefix);
    snprintf(c->ch_event, sizeof c->ch_event, "%s_EVENT", prefix);
    snprintf(c->ch_scene, sizeof c->ch_scene, "%s_SCENE", prefix);
    snprintf(c->ch_command, sizeof c->ch_command, "%s_COMMAND", prefix);
    snprintf(c->ch_control, sizeof c->ch_control, "%s_CONTROL", prefix);
    /* lcm_subscribe takes a POSIX regular expression: escape the channel names so that
     * a prefix with regex characters still matches only itself. */
    char re[4][200];
    const char *chans[4] = {c->ch_state, c->ch_status, c->ch_event, c->ch_scene};
    for (int k = 0; k < 4; k++) regex_escape(re[k], sizeof re[k], chans[k]);
    lcm_subscription_t *s1 = lcm_subscribe(c->lcm, re[0], handle_state, c);
    lcm_subscription_t *s2 = lcm_subscribe(c->lcm, re[1], handle_status, c);
    lcm_subscription_t *s3 = lcm_subscribe(c->lcm, re[2], handle_event, c);
    lcm_subscription_t *s4 = lcm_subscribe(c->lcm, re[3], handle_scene, c);
    if (!s1 || !s2 || !s3 || !s4) {
        if (err) snprintf(err, errlen, "cannot subscribe to %s_*", prefix);
        lcm_destroy(c->lcm);
        free(c);
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

void lag_client_get_counters(const lag_client *c, lag_client_counters *out)
{
    *out = c->counters;
}

/* ---------------------------------------------------------------- receiving */

int lag_client_handle(lag_client *c, int timeout_ms)
{
    if (timeout_ms < 0) timeout_ms = 0;
    errno = 0;
    int rc = lcm_handle_timeout(c->lcm, timeout_ms);
    if (rc < 0 && errno == EINTR) return 0; /* a signal (e.g. SIGINT): like a timeout */
    if (rc < 0) {
        set_err(c, "lcm_handle_timeout failed");
        return LAG_CLIENT_ERR_LCM;
    }
    return rc > 0 ? 1 : 0;
}

/* Handles messages until `flag` becomes true or the deadline (monotonic s) passes.
 * Returns 1 if flag, 0 on timeout, < 0 on error. */
static int handle_until(lag_client *c, const bool *flag, double deadline)
{
    while (!*flag) {
        double left = deadline - lag_client_now();
        if (left <= 0.0) return 0;
        int ms = (int)ceil(left * 1000.0);
        if (ms > 100) ms = 100;
        int rc = lag_client_handle(c, ms);
        if (rc < 0) return rc;
    }
    return 1;
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
    if (rc <= 0) {
        if (rc == 0) set_err(c, "no state on %s within %.3f s", c->ch_state, timeout_s);
        return rc;
    }
    /* drain what is already queued so that the newest state is returned */
    for (int i = 0; i < 1000; i++) {
        rc = lag_client_handle(c, 0);
        if (rc < 0) return rc;
        if (rc == 0) break;
    }
    c->new_state = false;
    if (st) *st = c->state;
    return 1;
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

int lag_client_send_command(lag_client *c, double sim_time, int n, const char *const *names,
                            const double *effort)
{
    if (n < 0 || n > LAG_CLIENT_MAX_JOINTS || (n > 0 && (!names || !effort))) {
        set_err(c, "send_command: %d joints (0 to %d, with names and efforts)", n,
                LAG_CLIENT_MAX_JOINTS);
        return LAG_CLIENT_ERR_ARG;
    }
    for (int i = 0; i < n; i++)
        if (!names[i]) {
            set_err(c, "send_command: joint name %d is NULL", i);
            return LAG_CLIENT_ERR_ARG;
        }
    lagsim_joint_command_t m;
    m.utime = wall_utime();
    m.sim_time = sim_time;
    m.num_joints = (int16_t)n;
    m.name = (char **)names;       /* encode only reads through these */
    m.effort = (double *)effort;
    if (lagsim_joint_command_t_publish(c->lcm, c->ch_command, &m) != 0) {
        set_err(c, "publish on %s failed", c->ch_command);
        return LAG_CLIENT_ERR_LCM;
    }
    c->counters.commands_sent++;
    return LAG_CLIENT_OK;
}

static int send_control(lag_client *c, int8_t request, int64_t count, int n, const double *q,
                        const double *qd)
{
    lagsim_control_t m;
    m.utime = wall_utime();
    m.request = request;
    m.count = count;
    m.num_joints = (int16_t)n;
    m.q = (double *)q;
    m.qd = (double *)qd;
    if (lagsim_control_t_publish(c->lcm, c->ch_control, &m) != 0) {
        set_err(c, "publish on %s failed", c->ch_control);
        return LAG_CLIENT_ERR_LCM;
    }
    c->counters.controls_sent++;
    return LAG_CLIENT_OK;
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
