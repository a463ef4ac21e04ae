/*
 * lagsim client library: see lagsim_client.h.
 *
 * Subscriptions are raw lcm_subscribe() handlers that pass the payload to one dispatch
 * function (also behind lag_client_feed), which decodes it with the bounded wire module
 * into scratch structs on the handle, so that a message is kept only whole and valid.
 * The handle keeps the wire module's structs; what a caller gets is the client's own
 * types (lagsim_client.h), copied out at the size the caller's header gave them.
 * Nothing is allocated after lag_client_create.
 */
#include "lagsim_client.h"
#include "lagsim_client_wire.h"

#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <ifaddrs.h>
#include <math.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <lcm/lcm.h>

#include "lagsim/lagsim_control_t.h"
#include "lagsim_bus.h"
#include "lagsim_clock.h"
#include "lagsim_num.h"

/* The capacities of the client's types are the wire module's: a message that fits one
 * fits the other. */
_Static_assert(LAG_CLIENT_MAX_JOINTS == LAG_WIRE_MAX_JOINTS, "joints");
_Static_assert(LAG_CLIENT_MAX_PARAMS == LAG_WIRE_MAX_PARAMS, "parameters");
_Static_assert(LAG_CLIENT_NAME_LEN == LAG_WIRE_NAME_LEN, "names");
_Static_assert(LAG_CLIENT_TEXT_LEN == LAG_WIRE_TEXT_LEN, "texts");
_Static_assert(LAG_CLIENT_URL_LEN == LAG_BUS_URL_LEN, "a plant's URL holds a state URL");

/* The sizes of the client's structs in the first version of the ABI: a caller's size
 * below these is a mistake (no header ever had a smaller struct). A field appended later
 * leaves these as they are. */
#define STATE_SIZE_1 sizeof(lag_client_state)
#define REFERENCE_SIZE_1 sizeof(lag_client_reference)
#define COUNTERS_SIZE_1 sizeof(lag_client_counters)
#define PLANT_SIZE_1 sizeof(lag_client_plant)

struct lag_client_scene {
    lag_wire_scene m;
};
struct lag_client_status {
    lag_wire_status m;
};

struct lag_client {
    lcm_t *lcm;                  /* the state URL: states, status, events, scene in */
    lcm_t *lcm_cmd;              /* the command URL: commands and control out (publishing
                                  * only: LCM opens no receive socket for it); the same
                                  * lcm_t for memq:// */
    lag_bus bus;
    char prefix[64];
    char ch_state[LAG_BUS_CHANNEL_LEN], ch_status[LAG_BUS_CHANNEL_LEN],
        ch_event[LAG_BUS_CHANNEL_LEN], ch_scene[LAG_BUS_CHANNEL_LEN],
        ch_command[LAG_BUS_CHANNEL_LEN], ch_control[LAG_BUS_CHANNEL_LEN],
        ch_reference[LAG_BUS_CHANNEL_LEN];
    char errmsg[256];

    lag_wire_joint_state state;  /* latest state */
    lag_client_state out_state;  /* the same, as the client's type (on_state, returns) */
    bool have_state, new_state;  /* new: not yet returned by lag_client_wait_state */
    lag_client_scene scene;
    bool have_scene;
    lag_client_scene state_scene; /* the scene of the latest state's generation */
    /* a state whose generation is not the scene's: held until the scene of its
     * generation came (asked for by DESCRIBE every LAG_CLIENT_DESCRIBE_S meanwhile) */
    lag_wire_joint_state held;
    bool have_held;
    double next_describe;        /* monotonic s: when a held state asks again */
    lag_client_status status;
    bool have_status;
    lag_client_reference reference; /* latest reference */
    bool have_reference;
    lag_client_counters counters;
    double heard;                /* monotonic s: the last message kept (creation before) */
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
        lag_wire_reference reference;
    } tmp;
    uint8_t buf[LAG_WIRE_BUF_SIZE]; /* encoding of outgoing messages */

    lag_client_state_fn on_state;
    void *on_state_user;
    lag_client_reference_fn on_reference;
    void *on_reference_user;
    lag_client_status_fn on_status;
    void *on_status_user;
    lag_client_event_fn on_event;
    void *on_event_user;
    lag_client_scene_fn on_scene;
    void *on_scene_user;
};

/* ---------------------------------------------------------------- helpers */

static void set_err(lag_client *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_err(lag_client *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->errmsg, sizeof c->errmsg, fmt, ap);
    va_end(ap);
}

double lag_client_now(void) { return lag_clock_mono_s(); }

int lag_client_version(void) { return LAGSIM_VERSION_NUMBER; }

lag_result lag_client_plant_urls(const char *url, char *state_url, size_t state_len,
                                 char *command_url, size_t command_len, char *err, size_t errlen)
{
    lag_bus b;
    char berr[256];
    if (err && errlen) err[0] = 0;
    if (!state_url || !command_url || state_len == 0 || command_len == 0) {
        if (err && errlen) snprintf(err, errlen, "lag_client_plant_urls: no room for the URLs");
        return LAG_CLIENT_ERR_ARG;
    }
    state_url[0] = command_url[0] = 0;
    if (lag_bus_init(&b, url, "P", berr, sizeof berr) != 0) { /* the prefix: any valid one */
        if (err && errlen) snprintf(err, errlen, "%s", berr);
        return LAG_CLIENT_ERR_ARG;
    }
    if (strlen(b.state_url) >= state_len || strlen(b.command_url) >= command_len) {
        if (err && errlen) snprintf(err, errlen, "lag_client_plant_urls: URL longer than the room given");
        return LAG_CLIENT_ERR_ARG;
    }
    snprintf(state_url, state_len, "%s", b.state_url);
    snprintf(command_url, command_len, "%s", b.command_url);
    return LAG_CLIENT_OK;
}

int lag_client_abi(void) { return LAGSIM_CLIENT_ABI; }

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

/* A struct of the client's, src (ours: src_size bytes), into the caller's dst of
 * dst_size bytes: what both know is copied, the caller's fields this library does not
 * know (a newer header's) are zeroed. False, nothing written, for a size below the
 * first version's (min). */
static bool copy_out(void *dst, size_t dst_size, const void *src, size_t src_size, size_t min)
{
    if (!dst || dst_size < min) return false;
    size_t n = dst_size < src_size ? dst_size : src_size;
    memcpy(dst, src, n);
    if (dst_size > n) memset((uint8_t *)dst + n, 0, dst_size - n);
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

/* ---------------------------------------------------------------- the client's types */

static void state_from_wire(lag_client_state *o, const lag_wire_joint_state *m)
{
    memset(o, 0, sizeof *o);
    o->utime = m->utime;
    o->sim_time = m->sim_time;
    o->step = m->step;
    o->generation = m->generation;
    o->num_joints = m->num_joints;
    memcpy(o->name, m->name, sizeof o->name);
    memcpy(o->position, m->position, sizeof o->position);
    memcpy(o->velocity, m->velocity, sizeof o->velocity);
    memcpy(o->effort, m->effort, sizeof o->effort);
}

static void reference_from_wire(lag_client_reference *o, const lag_wire_reference *m)
{
    memset(o, 0, sizeof *o);
    o->utime = m->utime;
    o->sim_time = m->sim_time;
    o->step = m->step;
    o->generation = m->generation;
    o->num_joints = m->num_joints;
    memcpy(o->name, m->name, sizeof o->name);
    memcpy(o->r, m->r, sizeof o->r);
    memcpy(o->rdot, m->rdot, sizeof o->rdot);
    memcpy(o->rddot, m->rddot, sizeof o->rddot);
}

static void event_from_wire(lag_client_event *o, const lag_wire_event *m)
{
    memset(o, 0, sizeof *o);
    o->utime = m->utime;
    o->sim_time = m->sim_time;
    o->step = m->step;
    o->value = m->value;
    memcpy(o->kind, m->kind, sizeof o->kind);
    memcpy(o->joint, m->joint, sizeof o->joint);
    memcpy(o->detail, m->detail, sizeof o->detail);
}

void lag_wire_of_state(const lag_client_state *st, lag_wire_joint_state *o)
{
    memset(o, 0, sizeof *o);
    o->utime = st->utime;
    o->sim_time = st->sim_time;
    o->step = st->step;
    o->generation = st->generation;
    o->num_joints = (int16_t)st->num_joints;
    memcpy(o->name, st->name, sizeof o->name);
    memcpy(o->position, st->position, sizeof o->position);
    memcpy(o->velocity, st->velocity, sizeof o->velocity);
    memcpy(o->effort, st->effort, sizeof o->effort);
}

void lag_wire_of_event(const lag_client_event *ev, lag_wire_event *o)
{
    memset(o, 0, sizeof *o);
    o->utime = ev->utime;
    o->sim_time = ev->sim_time;
    o->step = ev->step;
    o->value = ev->value;
    memcpy(o->kind, ev->kind, sizeof o->kind);
    memcpy(o->joint, ev->joint, sizeof o->joint);
    memcpy(o->detail, ev->detail, sizeof o->detail);
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

/* A state becomes the latest: returned once (wait_state), passed to on_state. A state
 * held for its scene is older: it is dropped, and asks for nothing more. */
static void take_state(lag_client *c, const lag_wire_joint_state *m)
{
    c->have_held = false;
    c->answer_len = 0;
    c->state = *m;
    state_from_wire(&c->out_state, m);
    c->state_scene = c->scene; /* its generation's (the scene rule) */
    c->have_state = c->new_state = true;
    if (c->on_state) c->on_state(&c->out_state, c->on_state_user);
}

/* A held state asks for its scene: DESCRIBE now and every LAG_CLIENT_DESCRIBE_S (the
 * scene comes with the first state of a generation; this is for when UDP lost it). */
static void ask_scene(lag_client *c, bool now)
{
    double t = lag_client_now();
    if (!now && t < c->next_describe) return;
    c->next_describe = t + LAG_CLIENT_DESCRIBE_S;
    if (lag_client_request_describe(c) == LAG_CLIENT_OK) c->counters.describes++;
}

/* A state, decoded into c->tmp.state. Each state once: a copy of the latest state (the
 * same generation, step and sim_time, whatever its utime: in lockstep the daemon publishes
 * a state again until an answer to it arrives, a paused real-time plant its state at
 * publish_hz) is neither returned nor passed to on_state, so the control law runs once per
 * state (a law with an integrator does not wind up while the plant is paused) and a law
 * slower than the copies never falls behind on them; a command already sent for it goes
 * out again at once (the first may have been lost). A state of a generation other than the scene's is held until that scene came:
 * a control law never answers a state with the parameters of another run or scene. */
static void on_state_msg(lag_client *c)
{
    const lag_wire_joint_state *m = &c->tmp.state;
    c->counters.states++; /* received and valid: kept (or held) */
    if (c->have_state && m->generation == c->state.generation && m->step == c->state.step &&
        m->sim_time == c->state.sim_time) {
        c->counters.copies++;
        if (c->answer_len > 0 &&
            lcm_publish(c->lcm_cmd, c->ch_command, c->answer, c->answer_len) == 0)
            c->counters.repeats++;
        return;
    }
    if (!c->have_scene || m->generation != c->scene.m.generation) {
        bool first = !c->have_held || c->held.generation != m->generation;
        c->held = *m; /* the newest of its generation */
        c->have_held = true;
        c->counters.held++;
        ask_scene(c, first && c->have_scene); /* the scene may be just behind the state */
        return;
    }
    take_state(c, m);
}

/* A scene, decoded into c->tmp.scene: kept, passed on; a state held for it goes on. */
static void on_scene_msg(lag_client *c)
{
    c->scene.m = c->tmp.scene;
    c->have_scene = true;
    c->counters.scenes++;
    if (c->on_scene) c->on_scene(&c->scene, c->on_scene_user);
    if (c->have_held && c->held.generation == c->scene.m.generation) {
        c->have_held = false; /* its scene came: it goes on */
        lag_wire_joint_state h = c->held;
        take_state(c, &h);
    }
}

/* One message from `channel`: decoded, kept, passed to the callback. */
static lag_result dispatch(lag_client *c, const char *channel, const void *data, size_t len)
{
    if (!strcmp(channel, c->ch_state)) {
        if (decode(c, LAG_WIRE_JOINT_STATE, data, len)) on_state_msg(c);
    } else if (!strcmp(channel, c->ch_scene)) {
        if (decode(c, LAG_WIRE_SCENE, data, len)) on_scene_msg(c);
    } else if (!strcmp(channel, c->ch_status)) {
        if (!decode(c, LAG_WIRE_STATUS, data, len)) return LAG_CLIENT_OK;
        c->status.m = c->tmp.status;
        c->have_status = true;
        c->counters.statuses++;
        if (c->on_status) c->on_status(&c->status, c->on_status_user);
    } else if (!strcmp(channel, c->ch_reference)) {
        if (!decode(c, LAG_WIRE_REFERENCE, data, len)) return LAG_CLIENT_OK;
        reference_from_wire(&c->reference, &c->tmp.reference);
        c->have_reference = true;
        c->counters.references++;
        if (c->on_reference) c->on_reference(&c->reference, c->on_reference_user);
    } else if (!strcmp(channel, c->ch_event)) {
        if (!decode(c, LAG_WIRE_EVENT, data, len)) return LAG_CLIENT_OK;
        if (strcmp(c->tmp.event.kind, "plant") != 0) c->counters.events++;
        lag_client_event ev;
        event_from_wire(&ev, &c->tmp.event);
        if (c->on_event) c->on_event(&ev, c->on_event_user);
    } else {
        set_err(c, "feed: %s is not one of this handle's channels (%s_*)", channel, c->prefix);
        return LAG_CLIENT_ERR_ARG;
    }
    return LAG_CLIENT_OK;
}

/* Messages kept from the daemon: states (copies too), scenes, statuses, events, references. */
static int64_t kept(const lag_client *c)
{
    const lag_client_counters *k = &c->counters;
    return k->states + k->scenes + k->statuses + k->events + k->references;
}

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    lag_client *c = user;
    int64_t before = kept(c);
    dispatch(c, channel, rbuf->data, rbuf->data_size);
    if (kept(c) != before) c->heard = lag_client_now();
}

lag_result lag_client_feed(lag_client *c, const char *channel, const void *data, size_t len)
{
    if (!channel || (!data && len > 0)) {
        set_err(c, "feed: NULL channel or data");
        return LAG_CLIENT_ERR_ARG;
    }
    int64_t before = kept(c);
    lag_result rc = dispatch(c, channel, data ? data : "", len);
    if (kept(c) != before) c->heard = lag_client_now();
    return rc;
}

/* ---------------------------------------------------------------- life cycle */

/* The handle's channels, from its bus, and its subscriptions on the state URL. */
static bool subscribe_all(lag_client *c)
{
    snprintf(c->ch_state, sizeof c->ch_state, "%s", c->bus.channel[LAG_BUS_STATE]);
    snprintf(c->ch_status, sizeof c->ch_status, "%s", c->bus.channel[LAG_BUS_STATUS]);
    snprintf(c->ch_event, sizeof c->ch_event, "%s", c->bus.channel[LAG_BUS_EVENT]);
    snprintf(c->ch_scene, sizeof c->ch_scene, "%s", c->bus.channel[LAG_BUS_SCENE]);
    snprintf(c->ch_command, sizeof c->ch_command, "%s", c->bus.channel[LAG_BUS_COMMAND]);
    snprintf(c->ch_control, sizeof c->ch_control, "%s", c->bus.channel[LAG_BUS_CONTROL]);
    snprintf(c->ch_reference, sizeof c->ch_reference, "%s", c->bus.channel[LAG_BUS_REFERENCE]);
    /* lcm_subscribe takes a POSIX regular expression: escape the channel names so that
     * a prefix with regex characters still matches only itself. The state's channel
     * last: LCM drops a message that no subscription takes when it arrives, and the
     * daemon publishes a state's reference (and a generation's scene) just before the
     * state, so a state subscribed first could be kept while its reference, come a moment
     * earlier, was not: a law would answer it without its reference. */
    const char *chans[5] = {c->ch_reference, c->ch_scene, c->ch_status, c->ch_event,
                            c->ch_state};
    lcm_subscription_t *s[5];
    for (int k = 0; k < 5; k++) {
        char re[200];
        regex_escape(re, sizeof re, chans[k]);
        if (!(s[k] = lcm_subscribe(c->lcm, re, on_message, c))) return false;
    }
    /* The state subscription keeps a deeper queue: a slow controller still sees states
     * in order rather than losing them inside LCM; each state's reference with it. */
    lcm_subscription_set_queue_capacity(s[4], 64);
    lcm_subscription_set_queue_capacity(s[0], 64);
    return true;
}

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
    c->heard = lag_client_now();
    if (!subscribe_all(c)) {
        if (err) snprintf(err, errlen, "cannot subscribe to %s_*", prefix);
        lag_client_destroy(c);
        return NULL;
    }
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

double lag_client_heard(const lag_client *c) { return c ? c->heard : NAN; }

int lag_client_fileno(const lag_client *c) { return lcm_get_fileno(c->lcm); }

void lag_client_on_state(lag_client *c, lag_client_state_fn fn, void *user)
{
    c->on_state = fn;
    c->on_state_user = user;
}

void lag_client_on_reference(lag_client *c, lag_client_reference_fn fn, void *user)
{
    c->on_reference = fn;
    c->on_reference_user = user;
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

void lag_client_get_counters(const lag_client *c, lag_client_counters *out, size_t size)
{
    copy_out(out, size, &c->counters, sizeof c->counters, COUNTERS_SIZE_1);
}

/* ---------------------------------------------------------------- waiting */

lag_result lag_client_handle(lag_client *c, int timeout_ms)
{
    if (timeout_ms < 0) timeout_ms = 0;
    errno = 0;
    int rc = lcm_handle_timeout(c->lcm, timeout_ms);
    if (c->have_held) ask_scene(c, false); /* a held state's scene, at the describe pace */
    if (rc < 0 && errno == EINTR) return LAG_CLIENT_TIMEOUT; /* a signal (e.g. SIGINT) */
    if (rc < 0) {
        set_err(c, "lcm_handle_timeout failed");
        return LAG_CLIENT_ERR_LCM;
    }
    return rc > 0 ? LAG_CLIENT_OK : LAG_CLIENT_TIMEOUT;
}

/* Reads what is already queued, without waiting, until `flag` (NULL: never) or nothing
 * is left: a process stalled past its deadline (a busy machine) still takes the answers
 * that came meanwhile before it says none came. LAG_CLIENT_OK, or an error. */
static lag_result handle_queued(lag_client *c, const bool *flag)
{
    for (int i = 0; i < 1000 && !(flag && *flag); i++) {
        lag_result rc = lag_client_handle(c, 0);
        if (rc < 0) return rc;
        if (rc == LAG_CLIENT_TIMEOUT) break;
    }
    return LAG_CLIENT_OK;
}

/* Handles messages until `flag` becomes true or the deadline (monotonic s) passes (what
 * was queued by then read first). Returns LAG_CLIENT_OK if flag, LAG_CLIENT_TIMEOUT, or
 * an error. */
static lag_result handle_until(lag_client *c, const bool *flag, double deadline)
{
    while (!*flag) {
        double left = deadline - lag_client_now();
        if (!(left > 0.0)) {
            lag_result rc = handle_queued(c, flag);
            if (rc < 0) return rc;
            return *flag ? LAG_CLIENT_OK : LAG_CLIENT_TIMEOUT;
        }
        int ms = left < 0.1 ? (int)ceil(left * 1000.0) : 100;
        lag_result rc = lag_client_handle(c, ms);
        if (rc < 0) return rc;
    }
    return LAG_CLIENT_OK;
}

lag_result lag_client_wait_scene(lag_client *c, double timeout_s, lag_client_scene *sc)
{
    double t0 = lag_client_now(), deadline = t0 + timeout_s;
    while (!c->have_scene) {
        lag_result rc = lag_client_request_describe(c);
        if (rc < 0) return rc;
        double next = lag_client_now() + LAG_CLIENT_DESCRIBE_S;
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

lag_result lag_client_wait_state(lag_client *c, double timeout_s, lag_client_state *st,
                                 size_t size)
{
    if (st && size < STATE_SIZE_1) {
        set_err(c, "wait_state: a state of %zu bytes (sizeof lag_client_state: %zu)", size,
                STATE_SIZE_1);
        return LAG_CLIENT_ERR_ARG;
    }
    lag_result rc = handle_until(c, &c->new_state, lag_client_now() + timeout_s);
    if (rc != LAG_CLIENT_OK) {
        if (rc == LAG_CLIENT_TIMEOUT)
            set_err(c, "no state on %s within %.3f s", c->ch_state, timeout_s);
        return rc;
    }
    /* drain what is already queued so that the newest state is returned */
    if ((rc = handle_queued(c, NULL)) < 0) return rc;
    c->new_state = false;
    if (st) copy_out(st, size, &c->out_state, sizeof c->out_state, STATE_SIZE_1);
    return LAG_CLIENT_OK;
}

bool lag_client_latest_state(const lag_client *c, lag_client_state *st, size_t size)
{
    if (!c->have_state) return false;
    return !st || copy_out(st, size, &c->out_state, sizeof c->out_state, STATE_SIZE_1);
}

bool lag_client_latest_scene(const lag_client *c, lag_client_scene *sc)
{
    if (c->have_scene && sc) *sc = c->have_state ? c->state_scene : c->scene;
    return c->have_scene;
}

bool lag_client_latest_status(const lag_client *c, lag_client_status *out)
{
    if (c->have_status && out) *out = c->status;
    return c->have_status;
}

bool lag_client_latest_reference(const lag_client *c, lag_client_reference *ref, size_t size)
{
    if (!c->have_reference) return false;
    return !ref || copy_out(ref, size, &c->reference, sizeof c->reference, REFERENCE_SIZE_1);
}

bool lag_client_reference_of(const lag_client *c, const lag_client_state *st,
                             lag_client_reference *ref, size_t size)
{
    if (!c->have_reference || !st || c->reference.generation != st->generation ||
        c->reference.sim_time != st->sim_time)
        return false;
    return !ref || copy_out(ref, size, &c->reference, sizeof c->reference, REFERENCE_SIZE_1);
}

/* ---------------------------------------------------------------- sending */

/* Encodes message m of type t and publishes it on channel. */
static lag_result publish(lag_client *c, const char *channel, lag_wire_type t, const void *m)
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

lag_result lag_client_send_command(lag_client *c, double sim_time, int n, const char *const *names,
                                   const double *effort)
{
    if (n < 0 || n > LAG_CLIENT_MAX_JOINTS || (n > 0 && (!names || !effort))) {
        set_err(c, "send_command: %d joints (0 to %d, with names and efforts)", n,
                LAG_CLIENT_MAX_JOINTS);
        return LAG_CLIENT_ERR_ARG;
    }
    lag_wire_joint_command m;
    memset(&m, 0, sizeof m);
    m.utime = lag_clock_wall_us();
    m.sim_time = sim_time;
    /* the generation of the state it answers: the latest state's (the only one a command
     * can answer in lockstep; 0 before any state: "no particular state") */
    m.generation = c->have_state ? c->state.generation : 0;
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
    lag_result rc = publish(c, c->ch_command, LAG_WIRE_JOINT_COMMAND, &m);
    if (rc != LAG_CLIENT_OK) return rc;
    c->counters.commands_sent++;
    if (c->have_state && sim_time == c->state.sim_time) { /* answers the latest state */
        int n_enc = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &m, c->answer, sizeof c->answer);
        c->answer_len = n_enc > 0 ? (unsigned)n_enc : 0;
    }
    return rc;
}
static lag_result send_control(lag_client *c, int8_t request, int64_t count, int n, const double *q,
                               const double *qd)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    m.utime = lag_clock_wall_us();
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

lag_result lag_client_pause(lag_client *c) { return send_control(c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL); }
lag_result lag_client_resume(lag_client *c) { return send_control(c, LAGSIM_CONTROL_T_RESUME, 0, 0, NULL, NULL); }
lag_result lag_client_reset(lag_client *c) { return send_control(c, LAGSIM_CONTROL_T_RESET, 0, 0, NULL, NULL); }
lag_result lag_client_request_status(lag_client *c)
{
    return send_control(c, LAGSIM_CONTROL_T_STATUS, 0, 0, NULL, NULL);
}
lag_result lag_client_request_describe(lag_client *c)
{
    return send_control(c, LAGSIM_CONTROL_T_DESCRIBE, 0, 0, NULL, NULL);
}

lag_result lag_client_set(lag_client *c, const char *key, const char *value)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    if (!key || !value || !key[0] || !value[0] || strlen(key) >= sizeof m.key ||
        strlen(value) >= sizeof m.value) {
        set_err(c, "set: key and value must be 1 to %zu and 1 to %zu bytes", sizeof m.key - 1,
                sizeof m.value - 1);
        return LAG_CLIENT_ERR_ARG;
    }
    m.utime = lag_clock_wall_us();
    m.request = LAGSIM_CONTROL_T_SET;
    memcpy(m.key, key, strlen(key) + 1);
    memcpy(m.value, value, strlen(value) + 1);
    int rc = publish(c, c->ch_control, LAG_WIRE_CONTROL, &m);
    if (rc == LAG_CLIENT_OK) c->counters.controls_sent++;
    return rc;
}

lag_result lag_client_kick(lag_client *c, const char *joint, double impulse, double duration)
{
    char key[LAG_WIRE_NAME_LEN], value[64];
    if (!joint || !joint[0] || snprintf(key, sizeof key, "kick.%s", joint) >= (int)sizeof key ||
        !isfinite(impulse) || !isfinite(duration) || duration < 0) {
        set_err(c, "kick: a joint name, a finite impulse and a duration >= 0 (s)");
        return LAG_CLIENT_ERR_ARG;
    }
    /* the shortest decimals the daemon reads back to the same doubles: the kick event's
     * detail says 0.1, as the user wrote it (lagsim_num.h) */
    char a[LAG_NUM_LEN], b[LAG_NUM_LEN];
    if (duration > 0) snprintf(value, sizeof value, "%s,%s", lag_num(impulse, a), lag_num(duration, b));
    else snprintf(value, sizeof value, "%s", lag_num(impulse, a));
    return lag_client_set(c, key, value);
}

lag_result lag_client_reset_scene(lag_client *c)
{
    return send_control(c, LAGSIM_CONTROL_T_RESET, 1, 0, NULL, NULL);
}

lag_result lag_client_step(lag_client *c, int64_t count)
{
    if (count < 1) {
        set_err(c, "step: count must be >= 1, got %lld", (long long)count);
        return LAG_CLIENT_ERR_ARG;
    }
    return send_control(c, LAGSIM_CONTROL_T_STEP, count, 0, NULL, NULL);
}

lag_result lag_client_reset_to(lag_client *c, int n, const double *q, const double *qd)
{
    return lag_client_reset_with(c, 0, n, q, qd);
}

/* The flags are control_t's count bits as the daemon reads them (lagsim_wire.h). */
_Static_assert(LAG_CLIENT_RESET_SCENE == LAG_WIRE_RESET_SCENE &&
                   LAG_CLIENT_RESET_WAIT == LAG_WIRE_RESET_WAIT,
               "LAG_CLIENT_RESET_* are control_t's RESET count bits");

lag_result lag_client_reset_with(lag_client *c, int flags, int n, const double *q, const double *qd)
{
    const int all = LAG_CLIENT_RESET_SCENE | LAG_CLIENT_RESET_WAIT;
    if (n == 0 && !q && !qd && flags >= 0 && (flags & ~all) == 0)
        return send_control(c, LAGSIM_CONTROL_T_RESET, flags, 0, NULL, NULL);
    if (flags != 0 && flags != LAG_CLIENT_RESET_WAIT) {
        set_err(c, "reset: flags %d; accepted: an OR of LAG_CLIENT_RESET_SCENE (%d, without "
                   "joints) and LAG_CLIENT_RESET_WAIT (%d)", flags, LAG_CLIENT_RESET_SCENE,
                LAG_CLIENT_RESET_WAIT);
        return LAG_CLIENT_ERR_ARG;
    }
    if (n < 1 || n > LAG_CLIENT_MAX_JOINTS || !q || !qd) {
        set_err(c, "reset_to: %d joints (1 to %d, with q and qd)", n, LAG_CLIENT_MAX_JOINTS);
        return LAG_CLIENT_ERR_ARG;
    }
    return send_control(c, LAGSIM_CONTROL_T_RESET_TO, flags, n, q, qd);
}

/* ---------------------------------------------------------------- lookups */

int lag_client_state_joint(const lag_client_state *st, const char *name)
{
    for (int i = 0; st && name && i < st->num_joints && i < LAG_CLIENT_MAX_JOINTS; i++)
        if (strcmp(st->name[i], name) == 0) return i;
    return -1;
}

int lag_client_reference_joint(const lag_client_reference *ref, const char *name)
{
    for (int i = 0; ref && name && i < ref->num_joints && i < LAG_CLIENT_MAX_JOINTS; i++)
        if (strcmp(ref->name[i], name) == 0) return i;
    return -1;
}

/* ---------------------------------------------------------------- the scene */

lag_client_scene *lag_client_scene_new(void) { return calloc(1, sizeof(lag_client_scene)); }

void lag_client_scene_free(lag_client_scene *sc) { free(sc); }

void lag_client_scene_copy(lag_client_scene *dst, const lag_client_scene *src)
{
    if (dst && src && dst != src) *dst = *src;
}

const lag_wire_scene *lag_wire_of_scene(const lag_client_scene *sc) { return &sc->m; }

/* Index i of a scene's joints / parameters: valid? */
static bool joint_ok(const lag_client_scene *sc, int i)
{
    return sc && i >= 0 && i < sc->m.num_joints && i < LAG_CLIENT_MAX_JOINTS;
}
static bool param_ok(const lag_client_scene *sc, int i)
{
    return sc && i >= 0 && i < sc->m.num_params && i < LAG_CLIENT_MAX_PARAMS;
}

const char *lag_client_scene_model(const lag_client_scene *sc) { return sc->m.model; }
const char *lag_client_scene_prefix(const lag_client_scene *sc) { return sc->m.prefix; }
int64_t lag_client_scene_generation(const lag_client_scene *sc) { return sc->m.generation; }
int64_t lag_client_scene_utime(const lag_client_scene *sc) { return sc->m.utime; }
int lag_client_scene_num_params(const lag_client_scene *sc) { return sc->m.num_params; }
int lag_client_scene_num_joints(const lag_client_scene *sc) { return sc->m.num_joints; }
double lag_client_scene_dt(const lag_client_scene *sc) { return sc->m.dt; }
double lag_client_scene_control_period(const lag_client_scene *sc) { return sc->m.control_period; }
double lag_client_scene_rate(const lag_client_scene *sc) { return sc->m.rate; }
double lag_client_scene_command_timeout(const lag_client_scene *sc) { return sc->m.command_timeout; }
const char *lag_client_scene_integrator(const lag_client_scene *sc) { return sc->m.integrator; }
const char *lag_client_scene_mode(const lag_client_scene *sc) { return sc->m.mode; }
const char *lag_client_scene_effects(const lag_client_scene *sc) { return sc->m.effects; }

const char *lag_client_scene_param_name(const lag_client_scene *sc, int i)
{
    return param_ok(sc, i) ? sc->m.param_name[i] : NULL;
}

double lag_client_scene_param_value(const lag_client_scene *sc, int i)
{
    return param_ok(sc, i) ? sc->m.param_value[i] : NAN;
}

double lag_client_scene_param(const lag_client_scene *sc, const char *name)
{
    for (int i = 0; name && param_ok(sc, i); i++)
        if (strcmp(sc->m.param_name[i], name) == 0) return sc->m.param_value[i];
    return NAN;
}

const char *lag_client_scene_joint_name(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) ? sc->m.joint_name[i] : NULL;
}

int lag_client_scene_joint(const lag_client_scene *sc, const char *name)
{
    for (int i = 0; name && joint_ok(sc, i); i++)
        if (strcmp(sc->m.joint_name[i], name) == 0) return i;
    return -1;
}

bool lag_client_scene_actuated(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) && sc->m.actuated[i];
}

double lag_client_scene_initial_q(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) ? sc->m.initial_q[i] : NAN;
}

double lag_client_scene_initial_qd(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) ? sc->m.initial_qd[i] : NAN;
}

bool lag_client_scene_limit_on(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) && sc->m.limit_on[i];
}

double lag_client_scene_limit_lower(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) ? sc->m.limit_lower[i] : NAN;
}

double lag_client_scene_limit_upper(const lag_client_scene *sc, int i)
{
    return joint_ok(sc, i) ? sc->m.limit_upper[i] : NAN;
}

/* ---------------------------------------------------------------- the status */

lag_client_status *lag_client_status_new(void) { return calloc(1, sizeof(lag_client_status)); }

void lag_client_status_free(lag_client_status *st) { free(st); }

void lag_client_status_copy(lag_client_status *dst, const lag_client_status *src)
{
    if (dst && src && dst != src) *dst = *src;
}

const lag_wire_status *lag_wire_of_status(const lag_client_status *st) { return &st->m; }

/* status_t's field `name` in the wire module's table (the .lcm file's fields), or NULL. */
static const lag_wire_field *status_field(const char *name)
{
    int n;
    const lag_wire_field *f = lag_wire_fields(LAG_WIRE_STATUS, &n);
    for (int i = 0; name && i < n; i++)
        if (!strcmp(f[i].name, name)) return &f[i];
    return NULL;
}

double lag_client_status_number(const lag_client_status *st, const char *field)
{
    const lag_wire_field *f = status_field(field);
    if (!st || !f || f->count_field >= 0) return NAN;
    const uint8_t *p = (const uint8_t *)&st->m + f->offset;
    switch (f->kind) {
    case LAG_WIRE_DOUBLE: {
        double x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case LAG_WIRE_INT64: {
        int64_t x;
        memcpy(&x, p, sizeof x);
        return (double)x;
    }
    case LAG_WIRE_BOOLEAN: return *(const bool *)p ? 1.0 : 0.0;
    case LAG_WIRE_INT8: return (double)*(const int8_t *)p;
    case LAG_WIRE_INT16: {
        int16_t x;
        memcpy(&x, p, sizeof x);
        return (double)x;
    }
    case LAG_WIRE_STRING: break;
    }
    return NAN;
}

const char *lag_client_status_text(const lag_client_status *st, const char *field)
{
    const lag_wire_field *f = status_field(field);
    if (!st || !f || f->kind != LAG_WIRE_STRING || f->count_field >= 0) return NULL;
    return (const char *)&st->m + f->offset;
}

int lag_client_status_fields(void)
{
    int n;
    lag_wire_fields(LAG_WIRE_STATUS, &n);
    return n;
}

const char *lag_client_status_field_name(int i)
{
    int n;
    const lag_wire_field *f = lag_wire_fields(LAG_WIRE_STATUS, &n);
    return i >= 0 && i < n ? f[i].name : NULL;
}

bool lag_client_status_field_is_text(int i)
{
    int n;
    const lag_wire_field *f = lag_wire_fields(LAG_WIRE_STATUS, &n);
    return i >= 0 && i < n && f[i].kind == LAG_WIRE_STRING;
}

/* ---------------------------------------------------------------- discovery */

/* What the discovery has heard so far. */
typedef struct disc {
    lag_client_plant p[LAG_CLIENT_MAX_PLANTS];
    int max, n, more;            /* more: plants heard beyond max */
    bool scene[LAG_CLIENT_MAX_PLANTS], status[LAG_CLIENT_MAX_PLANTS];
    double asked[LAG_CLIENT_MAX_PLANTS]; /* monotonic s of the last DESCRIBE + STATUS sent */
    double first;                /* monotonic s when the first plant was heard (0: none) */
    const char *url;
    uint8_t buf[LAG_WIRE_BUF_SIZE]; /* DESCRIBE, STATUS as encoded */
    union {
        lag_wire_scene scene;
        lag_wire_status status;
        lag_wire_event event;
    } tmp;
} disc;

/* The plant of prefix `pre` (len bytes), added if new; NULL if there is no room. */
static lag_client_plant *disc_plant(disc *d, const char *pre, size_t len)
{
    for (int i = 0; i < d->n; i++)
        if (strlen(d->p[i].prefix) == len && !strncmp(d->p[i].prefix, pre, len)) return &d->p[i];
    if (len == 0 || len >= sizeof d->p[0].prefix) return NULL;
    if (d->n >= d->max) {
        d->more++;
        return NULL;
    }
    lag_client_plant *p = &d->p[d->n++];
    memset(p, 0, sizeof *p);
    memcpy(p->prefix, pre, len);
    p->prefix[len] = '\0';
    snprintf(p->url, sizeof p->url, "%s", d->url);
    if (d->first == 0.0) d->first = lag_client_now();
    return p;
}

/* Any message of a plant (<PREFIX>_STATE, _STATUS, _EVENT, _SCENE on the state URL)
 * names its prefix; its scene and status say the rest. */
static void on_disc(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    disc *d = user;
    static const lag_bus_channel outs[] = {LAG_BUS_STATE, LAG_BUS_STATUS, LAG_BUS_EVENT,
                                           LAG_BUS_SCENE};
    size_t clen = strlen(channel);
    for (size_t k = 0; k < sizeof outs / sizeof outs[0]; k++) {
        const char *suf = lag_bus_suffix(outs[k]);
        size_t slen = strlen(suf);
        if (clen <= slen || strcmp(channel + clen - slen, suf)) continue;
        lag_client_plant *p = disc_plant(d, channel, clen - slen);
        if (!p) return;
        int i = (int)(p - d->p);
        if (outs[k] == LAG_BUS_SCENE &&
            lag_wire_decode(LAG_WIRE_SCENE, rbuf->data, rbuf->data_size, LAG_WIRE_MAX_JOINTS,
                            &d->tmp) == LAG_WIRE_OK &&
            !strcmp(d->tmp.scene.prefix, p->prefix)) {
            copy_str(p->model, sizeof p->model, d->tmp.scene.model);
            copy_str(p->mode, sizeof p->mode, d->tmp.scene.mode);
            d->scene[i] = true;
        } else if (outs[k] == LAG_BUS_EVENT &&
                   lag_wire_decode(LAG_WIRE_EVENT, rbuf->data, rbuf->data_size,
                                   LAG_WIRE_MAX_JOINTS, &d->tmp) == LAG_WIRE_OK &&
                   !strcmp(d->tmp.event.kind, "plant")) {
            /* a host's directory: the plant runs on the state URL its `plant` event names */
            lag_bus b;
            char berr[8];
            if (lag_bus_init(&b, d->tmp.event.detail, p->prefix, berr, sizeof berr) == 0)
                copy_str(p->url, sizeof p->url, b.state_url);
        } else if (outs[k] == LAG_BUS_STATUS &&
                   lag_wire_decode(LAG_WIRE_STATUS, rbuf->data, rbuf->data_size,
                                   LAG_WIRE_MAX_JOINTS, &d->tmp) == LAG_WIRE_OK &&
                   lag_wire_all_finite(LAG_WIRE_STATUS, &d->tmp)) {
            copy_str(p->run_state, sizeof p->run_state, d->tmp.status.run_state);
            if (!p->mode[0]) copy_str(p->mode, sizeof p->mode, d->tmp.status.mode);
            p->sim_time = d->tmp.status.sim_time;
            d->status[i] = true;
        }
        return;
    }
}

/* Where a plant's messages come from, from a plain UDP socket beside LCM's on the state
 * port (LCM does not say who sent a message): LCM's short-message header ("LC02", a
 * sequence number, the channel) names the channel, recvfrom the sender. Best effort: a
 * socket that cannot be opened leaves the hosts empty. */
static int host_socket(const lag_bus *b)
{
    if (!b->udpm) return -1;
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
#ifdef SO_REUSEPORT
    setsockopt(fd, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one);
#endif
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)b->state_port);
    a.sin_addr.s_addr = htonl(INADDR_ANY);
    struct ip_mreq mr;
    memset(&mr, 0, sizeof mr);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        inet_pton(AF_INET, b->group, &mr.imr_multiaddr) != 1 ||
        setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* Is a one of this host's IPv4 addresses? */
static bool address_is_local(struct in_addr a)
{
    if ((ntohl(a.s_addr) >> 24) == 127) return true;
    struct ifaddrs *ifs;
    if (getifaddrs(&ifs) != 0) return false;
    bool local = false;
    for (struct ifaddrs *i = ifs; i && !local; i = i->ifa_next)
        if (i->ifa_addr && i->ifa_addr->sa_family == AF_INET &&
            ((struct sockaddr_in *)i->ifa_addr)->sin_addr.s_addr == a.s_addr)
            local = true;
    freeifaddrs(ifs);
    return local;
}

/* Reads what the host socket has: each short message's sender becomes its plant's host
 * (this host's name, or the sender's IPv4 address). */
static void read_hosts(disc *d, int fd)
{
    uint8_t pkt[2048];
    for (int k = 0; fd >= 0 && k < 4096; k++) {
        struct sockaddr_in from;
        socklen_t fl = sizeof from;
        ssize_t n = recvfrom(fd, pkt, sizeof pkt - 1, 0, (struct sockaddr *)&from, &fl);
        if (n < 0) return;
        if (n < 9 || memcmp(pkt, "LC02", 4)) continue; /* fragments' first part has it too,
                                                        * but a plant's states are short */
        pkt[n] = '\0';
        const char *ch = (const char *)pkt + 8;
        size_t clen = strnlen(ch, (size_t)n - 8);
        for (int i = 0; i < d->n; i++) {
            size_t plen = strlen(d->p[i].prefix);
            if (d->p[i].host[0] || clen <= plen || strncmp(ch, d->p[i].prefix, plen) ||
                ch[plen] != '_')
                continue;
            if (address_is_local(from.sin_addr)) {
                if (gethostname(d->p[i].host, sizeof d->p[i].host) != 0) d->p[i].host[0] = '\0';
                d->p[i].host[sizeof d->p[i].host - 1] = '\0';
            }
            if (!d->p[i].host[0])
                inet_ntop(AF_INET, &from.sin_addr, d->p[i].host, sizeof d->p[i].host);
        }
    }
}

/* Sends DESCRIBE and STATUS to plant i on the command URL. */
static void disc_ask(disc *d, lcm_t *cmd, int i, uint8_t *buf, size_t cap)
{
    char ch[LAG_BUS_CHANNEL_LEN];
    snprintf(ch, sizeof ch, "%s%s", d->p[i].prefix, lag_bus_suffix(LAG_BUS_CONTROL));
    static const int8_t req[2] = {LAGSIM_CONTROL_T_DESCRIBE, LAGSIM_CONTROL_T_STATUS};
    for (int k = 0; k < 2; k++) {
        if ((k == 0 && d->scene[i]) || (k == 1 && d->status[i])) continue;
        lag_wire_control m;
        memset(&m, 0, sizeof m);
        m.utime = lag_clock_wall_us();
        m.request = req[k];
        int len = lag_wire_encode(LAG_WIRE_CONTROL, &m, buf, cap);
        if (len > 0) lcm_publish(cmd, ch, buf, (unsigned)len);
    }
    d->asked[i] = lag_client_now();
}

/* Reads what `in` already has queued, without waiting: a process stalled past its time
 * (a busy machine) still takes what came meanwhile. */
static void read_queued(lcm_t *in)
{
    for (int i = 0; i < 1000; i++)
        if (lcm_handle_timeout(in, 0) <= 0) break;
}

/* Listens on `in` up to wait_s, asking each plant heard for its scene and status on
 * `cmd` until they come; ends settle_s after the first plant was heard once every plant
 * heard is described (settle_s < 0: at wait_s). */
static void disc_listen(disc *d, lcm_t *in, lcm_t *cmd, const lag_bus *b, int max, double wait_s,
                        double settle_s)
{
    d->max = max;
    d->url = b->state_url;
    int hfd = host_socket(b);
    double t0 = lag_client_now(), end = t0 + wait_s;
    for (;;) {
        double now = lag_client_now();
        bool all = d->n > 0;
        for (int i = 0; i < d->n; i++) {
            if (!d->scene[i] || !d->status[i]) all = false;
            if ((!d->scene[i] || !d->status[i]) && now - d->asked[i] >= 0.25)
                disc_ask(d, cmd, i, d->buf, sizeof d->buf);
        }
        /* done: the time is up; or, once a plant was heard, settle_s later (every plant
         * heard so far described) */
        if (now >= end || (d->first > 0 && settle_s >= 0 && now >= d->first + settle_s && all))
            break;
        double left = end - now;
        int ms = left < 0.05 ? (int)ceil(left * 1000.0) : 50;
        errno = 0;
        if (lcm_handle_timeout(in, ms) < 0 && errno != EINTR) break;
        read_hosts(d, hfd);
    }
    read_queued(in);
    read_hosts(d, hfd);
    if (hfd >= 0) close(hfd);
}

/* The plants heard, sorted by prefix (so that a listing does not depend on who spoke
 * first), into the caller's array of elements of `size` bytes. */
static void disc_out(disc *d, lag_client_plant *plants, size_t size)
{
    lag_client_plant *p = d->p;
    for (int i = 1; i < d->n; i++)
        for (int j = i; j > 0 && strcmp(p[j - 1].prefix, p[j].prefix) > 0; j--) {
            lag_client_plant t = p[j];
            p[j] = p[j - 1];
            p[j - 1] = t;
        }
    for (int i = 0; i < d->n; i++)
        copy_out((uint8_t *)plants + (size_t)i * size, size, &p[i], sizeof p[i], PLANT_SIZE_1);
}

lag_result lag_client_discover(const char *url, double wait_s, double settle_s,
                               lag_client_plant *plants, int max, size_t size, int *n,
                               char *err, size_t errlen)
{
    if (n) *n = 0;
    if (err && errlen) err[0] = '\0';
    if (!plants || max < 1 || max > LAG_CLIENT_MAX_PLANTS || size < PLANT_SIZE_1 || !n ||
        !(wait_s >= 0) || !isfinite(wait_s) || !isfinite(settle_s)) {
        if (err) snprintf(err, errlen, "discover: bad arguments");
        return LAG_CLIENT_ERR_ARG;
    }
    lag_bus b;
    char berr[256];
    if (lag_bus_init(&b, url, "X", berr, sizeof berr) != 0) {
        if (err) snprintf(err, errlen, "%s", berr);
        return LAG_CLIENT_ERR_ARG;
    }
    lcm_t *in = lcm_create(b.state_url);
    lcm_t *cmd = !in ? NULL : b.udpm ? lcm_create(b.command_url) : in;
    if (!in || !cmd) {
        if (err) snprintf(err, errlen, "cannot create LCM for %s", in ? b.command_url : b.state_url);
        if (in) lcm_destroy(in);
        return LAG_CLIENT_ERR_LCM;
    }
    /* large: not on the stack; one per call, so that discoveries may run in several
     * threads at once */
    disc *dp = calloc(1, sizeof *dp);
    lcm_subscription_t *sub = dp ? lcm_subscribe(in, ".*", on_disc, dp) : NULL;
    if (!sub) {
        lag_result rc = dp ? LAG_CLIENT_ERR_LCM : LAG_CLIENT_ERR_NOMEM;
        if (err) snprintf(err, errlen, "%s on %s", dp ? "cannot subscribe" : "out of memory",
                          b.state_url);
        if (cmd != in) lcm_destroy(cmd);
        lcm_destroy(in);
        free(dp);
        return rc;
    }
    /* a host's directory names a plant every 0.5 s and answers for each: LCM's default
     * queue (30 messages) would drop most of a class of plants between two reads */
    lcm_subscription_set_queue_capacity(sub, 4 * LAG_CLIENT_MAX_PLANTS);
    disc_listen(dp, in, cmd, &b, max, wait_s, settle_s);
    lcm_unsubscribe(in, sub);
    if (cmd != in) lcm_destroy(cmd);
    lcm_destroy(in);
    disc_out(dp, plants, size);
    *n = dp->n;
    if (dp->more && err)
        snprintf(err, errlen, "%d more plants on %s than the %d listed", dp->more, b.state_url,
                 max);
    free(dp);
    return LAG_CLIENT_OK;
}

/* "PREFIX (model, run state)" for each plant, comma-separated. */
static void plant_names(const lag_client_plant *p, int n, char *out, size_t cap)
{
    size_t o = 0;
    out[0] = '\0';
    for (int i = 0; i < n && o + 1 < cap; i++) {
        int w = snprintf(out + o, cap - o, "%s%s (%s%s%s)", i ? ", " : "", p[i].prefix,
                         p[i].model[0] ? p[i].model : "model unknown",
                         p[i].run_state[0] ? ", " : "", p[i].run_state);
        if (w < 0) break;
        o += (size_t)w;
    }
}

/* The plants of `model` (any: NULL) that answered with a scene, among all[n]: how many,
 * the last one's index in *match. */
static int plants_of(const lag_client_plant *all, int n, const char *model, int *match)
{
    /* a plant is what answers DESCRIBE with a scene: a channel that only looks like a
     * plant's (another program's FOO_STATE) is not one to pick */
    int k = 0;
    for (int i = 0; i < n; i++)
        if (all[i].model[0] && (!model || !strcmp(all[i].model, model))) {
            k++;
            *match = i;
        }
    return k;
}

/* pick_plant's message when k != 1 plants of `model` are among all[n]. */
static void pick_message(const lag_client_plant *all, int n, int k, const char *model,
                         const char *where, double wait_s, char *err, size_t errlen)
{
    char names[1024];
    if (k == 0) {
        bool any = false;
        for (int i = 0; i < n; i++) any |= all[i].model[0] != '\0';
        plant_names(all, n, names, sizeof names);
        if (!any)
            snprintf(err, errlen, "no plant on %s within %.1f s (is lagsimd running on this "
                     "LCM URL?)", where, wait_s);
        else
            snprintf(err, errlen, "no %s plant on %s (heard: %s)", model, where, names);
        return;
    }
    lag_client_plant *sel = calloc((size_t)(n > 0 ? n : 1), sizeof *sel); /* not on a thread's
                                                                           * stack: 1024 plants */
    int m = 0;
    for (int i = 0; sel && i < n; i++)
        if (all[i].model[0] && (!model || !strcmp(all[i].model, model))) sel[m++] = all[i];
    plant_names(sel ? sel : all, sel ? m : n, names, sizeof names);
    free(sel);
    snprintf(err, errlen, "%d %s%splants on %s: %s; choose one with --prefix", k,
             model ? model : "", model ? " " : "", where, names);
}

lag_result lag_client_pick_plant(const char *url, const char *model, double wait_s,
                                 lag_client_plant *out, size_t size, char *err, size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    if (!out || size < PLANT_SIZE_1) {
        if (err) snprintf(err, errlen, "pick_plant: NULL out or a size below sizeof plant");
        return LAG_CLIENT_ERR_ARG;
    }
    memset(out, 0, size);
    lag_client_plant *all = calloc(LAG_CLIENT_MAX_PLANTS, sizeof *all);
    if (!all) {
        if (err) snprintf(err, errlen, "out of memory");
        return LAG_CLIENT_ERR_NOMEM;
    }
    int n = 0, match = -1;
    /* 0.5 s after the first plant is heard: longer than a plant's state period at any
     * publish_hz the shipped scenes use, so that a second plant is heard too */
    lag_result rc = lag_client_discover(url, wait_s, 0.5, all, LAG_CLIENT_MAX_PLANTS,
                                        sizeof *all, &n, err, errlen);
    int k = rc == LAG_CLIENT_OK ? plants_of(all, n, model, &match) : 0;
    if (rc == LAG_CLIENT_OK && k == 1) {
        copy_out(out, size, &all[match], sizeof all[match], PLANT_SIZE_1);
    } else if (rc == LAG_CLIENT_OK) {
        lag_bus b;
        char berr[8];
        const char *where = lag_bus_init(&b, url, "X", berr, sizeof berr) == 0 ? b.state_url : "?";
        if (err) pick_message(all, n, k, model, where, wait_s, err, errlen);
        rc = k == 0 ? LAG_CLIENT_TIMEOUT : LAG_CLIENT_ERR_AMBIGUOUS;
    }
    free(all);
    return rc;
}

/* ---------------------------------------------------------------- a prefix nobody has */
/* Edits (insert, delete, substitute) between a and b, capped at 3 (more: 3). */
static int edits(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > LAG_CLIENT_NAME_LEN || lb > LAG_CLIENT_NAME_LEN) return 3;
    int row[LAG_CLIENT_NAME_LEN + 1];
    for (size_t j = 0; j <= lb; j++) row[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int up = row[j];
            int best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best) best = up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb] < 3 ? row[lb] : 3;
}

/* How near a heard prefix is to the one asked: 0 the same but for letter case, 1 it
 * starts with it, 2 + edits; -1 not near. */
static int nearness(const char *heard, const char *asked)
{
    if (!strcasecmp(heard, asked)) return 0;
    if (asked[0] && !strncasecmp(heard, asked, strlen(asked))) return 1;
    int e = edits(heard, asked);
    return e <= 2 ? 2 + e : -1;
}

int lag_client_plants_instead(const char *url, const char *prefix, double wait_s, char *out,
                              size_t len)
{
    int n = 0;
    char err[256] = "";
    if (!out || len == 0 || !prefix) return LAG_CLIENT_ERR_ARG;
    /* one array per call (any thread may ask), not on its stack (1024 plants: 730 kB) */
    lag_client_plant *p = calloc(LAG_CLIENT_MAX_PLANTS, sizeof *p);
    if (!p) {
        snprintf(out, len, "out of memory");
        return LAG_CLIENT_ERR_NOMEM;
    }
    lag_result rc = lag_client_discover(url, wait_s, 0.5, p, LAG_CLIENT_MAX_PLANTS, sizeof p[0],
                                        &n, err, sizeof err);
    if (rc != LAG_CLIENT_OK) {
        snprintf(out, len, "%s", err);
        free(p);
        return rc;
    }
    lag_bus b;
    char berr[8];
    const char *where = lag_bus_init(&b, url, "X", berr, sizeof berr) == 0 ? b.state_url : "?";
    if (n == 0) {
        snprintf(out, len, "no plant heard on %s within %.3g s (is lagsimd running on this "
                 "LCM URL?)", where, wait_s);
        free(p);
        return 0;
    }
    size_t o = (size_t)snprintf(out, len, "no plant on prefix %s; plants heard on %s: ", prefix,
                                where);
    int best = -1, near = -1;
    for (int i = 0; i < n && o < len; i++) {
        o += (size_t)snprintf(out + o, len - o, "%s%s (%s%s%s%s%s)", i ? ", " : "", p[i].prefix,
                              p[i].model[0] ? p[i].model : "model unknown",
                              p[i].mode[0] ? ", " : "", p[i].mode,
                              p[i].run_state[0] ? ", " : "", p[i].run_state);
        int k = nearness(p[i].prefix, prefix);
        if (k >= 0 && (near < 0 || k < near)) near = k, best = i;
    }
    if (best >= 0 && o < len) snprintf(out + o, len - o, "; did you mean %s?", p[best].prefix);
    free(p);
    return n;
}

/* ---------------------------------------------------------------- a host's directory */

/* What lag_client_locate heard: the first message that decides. */
typedef struct locate {
    size_t plen;                /* the prefix's length */
    const char *default_url;    /* the state URL of LCM's default bus */
    char url[LAG_CLIENT_URL_LEN];
    int where;                  /* LAG_CLIENT_LOCATE_*, -1 while undecided */
    lag_wire_event ev;          /* decoded here: not on the stack */
} locate;

/* The rule (docs/protocol.md, "A host's directory"): on the default bus, the prefix's
 * state, status or scene, or an event of any other kind than `plant`, is the plant itself
 * (HERE); a `plant` event whose detail is a URL a plant can have, other than the default
 * bus's, names where it runs (HOST). Anything else (an event that does not decode, a
 * `plant` event naming no such URL or the default bus itself) decides nothing. */
static void on_locate(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    locate *l = user;
    if (l->where >= 0) return;
    if (strcmp(channel + l->plen, lag_bus_suffix(LAG_BUS_EVENT)) != 0) {
        l->where = LAG_CLIENT_LOCATE_HERE;
        return;
    }
    if (lag_wire_decode(LAG_WIRE_EVENT, rbuf->data, rbuf->data_size, LAG_WIRE_MAX_JOINTS,
                        &l->ev) != LAG_WIRE_OK)
        return;
    if (strcmp(l->ev.kind, "plant") != 0) {
        l->where = LAG_CLIENT_LOCATE_HERE;
        return;
    }
    lag_bus b;
    char berr[8];
    if (lag_bus_init(&b, l->ev.detail, "X", berr, sizeof berr) == 0 &&
        strcmp(b.state_url, l->default_url) != 0) {
        copy_str(l->url, sizeof l->url, b.state_url);
        l->where = LAG_CLIENT_LOCATE_HOST;
    }
}

/* Whether prefix can be a plant's: 1 to LAG_BUS_PREFIX_MAX of [A-Za-z0-9_]. */
static bool prefix_ok(const char *prefix)
{
    size_t n = prefix ? strlen(prefix) : 0;
    if (n == 0 || n > LAG_BUS_PREFIX_MAX) return false;
    for (size_t i = 0; i < n; i++)
        if (!isalnum((unsigned char)prefix[i]) && prefix[i] != '_') return false;
    return true;
}

/* Listens on `in` until the rule decides or wait_s passed; then reads what is already
 * queued (a process stalled past its window still takes the announcements that came). */
static void locate_listen(lcm_t *in, locate *l, double wait_s)
{
    double end = lag_client_now() + wait_s;
    for (double left; l->where < 0 && (left = end - lag_client_now()) > 0;)
        if (lcm_handle_timeout(in, (int)(left * 1000.0) + 1) < 0) return;
    if (l->where < 0) read_queued(in); /* on_locate keeps the first that decides */
}

int lag_client_locate(const char *prefix, double wait_s, char *url, size_t len, char *err,
                      size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    if (url && len) url[0] = '\0';
    lag_bus b;
    char berr[256];
    if (!prefix_ok(prefix) || !url || len == 0 || !(wait_s >= 0) || !isfinite(wait_s)) {
        if (err) snprintf(err, errlen, "locate: a prefix of 1 to %d letters, digits or _, a "
                          "finite wait >= 0 and a URL buffer", LAG_BUS_PREFIX_MAX);
        return LAG_CLIENT_ERR_ARG;
    }
    if (lag_bus_init(&b, NULL, prefix, berr, sizeof berr) != 0) { /* LCM_DEFAULT_URL */
        if (err) snprintf(err, errlen, "LCM_DEFAULT_URL: %s", berr);
        return LAG_CLIENT_ERR_ARG;
    }
    locate *l = calloc(1, sizeof *l);
    lcm_t *in = l ? lcm_create(b.state_url) : NULL;
    char pattern[LAG_BUS_CHANNEL_LEN + 32];
    snprintf(pattern, sizeof pattern, "%s_(EVENT|STATE|STATUS|SCENE)", prefix);
    lcm_subscription_t *sub = in ? lcm_subscribe(in, pattern, on_locate, l) : NULL;
    if (!sub) {
        if (err) snprintf(err, errlen, "%s %s", !l ? "out of memory on" : "cannot listen on",
                          b.state_url);
        if (in) lcm_destroy(in);
        free(l);
        return !l ? LAG_CLIENT_ERR_NOMEM : LAG_CLIENT_ERR_LCM;
    }
    lcm_subscription_set_queue_capacity(sub, 64);
    l->plen = strlen(prefix);
    l->default_url = b.state_url;
    l->where = -1;
    locate_listen(in, l, wait_s);
    lcm_unsubscribe(in, sub);
    lcm_destroy(in);
    int where = l->where < 0 ? LAG_CLIENT_LOCATE_NONE : l->where;
    if (where == LAG_CLIENT_LOCATE_NONE && err)
        snprintf(err, errlen, "nothing of prefix %s heard on %s within %.3g s and no host's "
                 "directory named it: waiting for it there", prefix, b.state_url, wait_s);
    if (!copy_str(url, len, where == LAG_CLIENT_LOCATE_HOST ? l->url : b.state_url)) {
        if (err) snprintf(err, errlen, "locate: a URL buffer of %zu bytes is too short", len);
        url[0] = '\0';
        where = LAG_CLIENT_ERR_ARG;
    }
    free(l);
    return where;
}
