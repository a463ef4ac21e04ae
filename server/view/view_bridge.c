/*
 * The bridge's LCM side: the daemon's STATE, STATUS, EVENT, SCENE and REFERENCE channels
 * (a state's reference goes out with it, in its JSON) decoded by
 * the shared bounded wire module into the latest snapshot, and control requests sent on
 * CONTROL. Nothing is queued: LCM's own queue per subscription is capped, each poll
 * handles a bounded number of messages, a newer state replaces the older one, events go
 * into a fixed ring.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "view.h"
#include "lagsim/lagsim_control_t.h"
#include "lagsim_bus.h"
#include "lagsim_net.h"
#include "lagsim_num.h"

#define VIEW_DRAIN_MAX 512        /* messages handled per poll at most */
#define VIEW_LCM_QUEUE 200        /* LCM's queue per subscription */
#define VIEW_DESCRIBE_NS 1000000000

/* The seq a sample at sim time t takes in a ring of VIEW_HISTORY holding first..last whose
 * newest sample is at newest_t (view_history); -1: not kept (t not finite). */
static int64_t ring_slot(int64_t *first, int64_t *last, double newest_t, double t)
{
    if (!isfinite(t)) return -1;
    bool any = *last >= *first;
    if (any && t == newest_t) return *last; /* paused: the same state again */
    if (any && t < newest_t) *first = *last + 1; /* a reset: start over */
    ++*last;
    if (*last - *first + 1 > VIEW_HISTORY) *first = *last - VIEW_HISTORY + 1;
    return *last;
}

static void history_state(view_history *h, const lag_wire_joint_state *m)
{
    double newest = h->state[h->state_last % VIEW_HISTORY].t;
    int64_t seq = ring_slot(&h->state_first, &h->state_last, newest, m->sim_time);
    if (seq < 0) return;
    view_sample *s = &h->state[seq % VIEW_HISTORY];
    int n = m->num_joints < 0 ? 0 : m->num_joints > LAG_WIRE_MAX_JOINTS ? LAG_WIRE_MAX_JOINTS
                                                                        : m->num_joints;
    s->t = m->sim_time;
    s->n = n;
    memcpy(s->q, m->position, sizeof s->q);
    memcpy(s->qd, m->velocity, sizeof s->qd);
    memcpy(s->effort, m->effort, sizeof s->effort);
}

static void history_energy(view_history *h, const lag_wire_status *m)
{
    double newest = h->energy_t[h->energy_last % VIEW_HISTORY];
    int64_t seq = ring_slot(&h->energy_first, &h->energy_last, newest, m->sim_time);
    if (seq < 0) return;
    h->energy_t[seq % VIEW_HISTORY] = m->sim_time;
    h->energy[seq % VIEW_HISTORY] = m->energy;
}

static void on_state(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    view_bridge *vb = user;
    if (vb->discard) return; /* came in before the socket filter */
    lag_wire_joint_state m;
    if (lag_wire_decode_any(LAG_WIRE_JOINT_STATE, rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS,
                            &m, NULL) != LAG_WIRE_OK) {
        vb->n_undecodable++;
        return;
    }
    vb->state = m;
    /* its reference, published just before it: the one with its sim_time and step */
    if (vb->reference.num_joints > 0 && vb->reference.sim_time == m.sim_time &&
        vb->reference.step == m.step)
        vb->state_ref = vb->reference;
    else
        vb->state_ref.num_joints = 0;
    vb->state_seq++;
    history_state(&vb->hist, &m);
    vb->n_state++;
    vb->last_msg_ns = lag_clock_mono_ns();
}

static void on_reference(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    view_bridge *vb = user;
    if (vb->discard) return; /* came in before the socket filter */
    lag_wire_reference m;
    if (lag_wire_decode_any(LAG_WIRE_REFERENCE, rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS,
                            &m, NULL) != LAG_WIRE_OK) {
        vb->n_undecodable++;
        return;
    }
    vb->reference = m;
    vb->n_reference++;
    vb->last_msg_ns = lag_clock_mono_ns();
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    view_bridge *vb = user;
    if (vb->discard) return; /* came in before the socket filter */
    lag_wire_status m;
    if (lag_wire_decode_status(rb->data, rb->data_size, &m) != LAG_WIRE_OK) {
        vb->n_undecodable++;
        return;
    }
    vb->status = m;
    vb->status_seq++;
    history_energy(&vb->hist, &m);
    vb->n_status++;
    vb->last_msg_ns = lag_clock_mono_ns();
}

static void on_event(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    view_bridge *vb = user;
    if (vb->discard) return; /* came in before the socket filter */
    lag_wire_event m;
    int r = lag_wire_decode_event(rb->data, rb->data_size, &m);
    /* an over-long detail is kept, cut; the rest of the event decoded */
    if (r != LAG_WIRE_OK && r != LAG_WIRE_ETOOLONG) {
        vb->n_undecodable++;
        return;
    }
    vb->event_seq++;
    vb->events[vb->event_seq % VIEW_EVENTS].seq = vb->event_seq;
    vb->events[vb->event_seq % VIEW_EVENTS].ev = m;
    vb->n_event++;
    vb->last_msg_ns = lag_clock_mono_ns();
}

static void on_scene(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    view_bridge *vb = user;
    if (vb->discard) return; /* came in before the socket filter */
    lag_wire_scene m;
    if (lag_wire_decode_any(LAG_WIRE_SCENE, rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m,
                            NULL) != LAG_WIRE_OK) {
        vb->n_undecodable++;
        return;
    }
    vb->scene = m;
    vb->scene_seq++;
    vb->n_scene++;
    vb->last_msg_ns = lag_clock_mono_ns();
}

/* Keeps only this plant's five channels on the state URL's receive socket and, unless
 * allow_lan, only datagrams from this host (lagsim_net.h, the daemon's filter); then reads
 * until a marker sent after the filter comes back, discarding what came before it. */
static bool filter_input(view_bridge *vb, const lag_bus *bus, bool allow_lan, char *err,
                         size_t errlen)
{
    const char *chans[] = {vb->ch_state, vb->ch_status, vb->ch_event, vb->ch_scene,
                           vb->ch_reference, LAG_NET_MARKER_CHANNEL};
    char ferr[256];
    int n = lag_net_filter(bus->state_port, !allow_lan, chans, 6, ferr, sizeof ferr);
    if (n > 0) {
        vb->discard = true;
        int synced = lag_net_sync(vb->lcm, 3000);
        vb->discard = false;
        if (synced != 0) {
            snprintf(err, errlen, "LCM on %s does not hear its own messages (is there a "
                     "multicast route? docs/network.md)", bus->state_url);
            return false;
        }
        n = lag_net_filter(bus->state_port, !allow_lan, chans, 5, ferr, sizeof ferr);
    }
    if (n <= 0) {
        snprintf(err, errlen, "%s: cannot restrict the state URL %s to %s", n < 0 ? ferr :
                 "LCM's receive socket was not found", bus->state_url,
                 allow_lan ? "this plant's channels" : "this host (--allow-lan opens it)");
        return false;
    }
    return true;
}

bool view_bridge_open(view_bridge *vb, const char *url, const char *prefix, bool allow_lan,
                      char *err, size_t errlen)
{
    memset(vb, 0, sizeof *vb);
    vb->hist.state_first = vb->hist.energy_first = 1; /* empty: last < first */
    size_t n = strlen(prefix);
    if (n == 0 || n >= sizeof vb->prefix) {
        snprintf(err, errlen, "--prefix: 1 to %zu characters", sizeof vb->prefix - 1);
        return false;
    }
    for (size_t i = 0; i < n; i++) {
        char c = prefix[i];
        if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '-')) {
            snprintf(err, errlen, "--prefix '%s': letters, digits, '_' and '-' only", prefix);
            return false;
        }
    }
    snprintf(vb->prefix, sizeof vb->prefix, "%s", prefix);
    snprintf(vb->url, sizeof vb->url, "%s", url ? url : "");
    lag_bus bus; /* the plant's URLs and channels, as the daemon derives them */
    char berr[256];
    if (lag_bus_init(&bus, url, prefix, berr, sizeof berr) != 0) {
        snprintf(err, errlen, "--url: %s", berr);
        return false;
    }
    snprintf(vb->ch_state, VIEW_CHANNEL_MAX, "%s", bus.channel[LAG_BUS_STATE]);
    snprintf(vb->ch_status, VIEW_CHANNEL_MAX, "%s", bus.channel[LAG_BUS_STATUS]);
    snprintf(vb->ch_event, VIEW_CHANNEL_MAX, "%s", bus.channel[LAG_BUS_EVENT]);
    snprintf(vb->ch_scene, VIEW_CHANNEL_MAX, "%s", bus.channel[LAG_BUS_SCENE]);
    snprintf(vb->ch_control, VIEW_CHANNEL_MAX, "%s", bus.channel[LAG_BUS_CONTROL]);
    snprintf(vb->ch_reference, VIEW_CHANNEL_MAX, "%s", bus.channel[LAG_BUS_REFERENCE]);
    lag_net_note_inherited(); /* a parent's sockets are not filtered */
    vb->lcm = lcm_create(bus.state_url);
    vb->lcm_cmd = !vb->lcm ? NULL : bus.udpm ? lcm_create(bus.command_url) : vb->lcm;
    if (!vb->lcm || !vb->lcm_cmd) {
        snprintf(err, errlen, "cannot create LCM (url '%s')",
                 vb->lcm ? bus.command_url : bus.state_url);
        view_bridge_close(vb);
        return false;
    }
    /* one at a time, the state's channel last: LCM drops a message that no subscription
     * takes when it arrives, and a state's reference (a generation's scene) is published
     * just before it: a state is drawn with its reference (the client library's rule) */
    lcm_subscription_t *subs[5];
    subs[0] = lcm_subscribe(vb->lcm, vb->ch_reference, on_reference, vb);
    subs[1] = lcm_subscribe(vb->lcm, vb->ch_scene, on_scene, vb);
    subs[2] = lcm_subscribe(vb->lcm, vb->ch_status, on_status, vb);
    subs[3] = lcm_subscribe(vb->lcm, vb->ch_event, on_event, vb);
    subs[4] = lcm_subscribe(vb->lcm, vb->ch_state, on_state, vb);
    for (int i = 0; i < 5; i++) {
        if (!subs[i]) {
            snprintf(err, errlen, "cannot subscribe to the %s channels", prefix);
            view_bridge_close(vb);
            return false;
        }
        lcm_subscription_set_queue_capacity(subs[i], VIEW_LCM_QUEUE);
    }
    if (bus.udpm && !filter_input(vb, &bus, allow_lan, err, errlen)) {
        view_bridge_close(vb);
        return false;
    }
    return true;
}

void view_bridge_close(view_bridge *vb)
{
    if (vb->lcm_cmd && vb->lcm_cmd != vb->lcm) lcm_destroy(vb->lcm_cmd);
    if (vb->lcm) lcm_destroy(vb->lcm);
    vb->lcm = vb->lcm_cmd = NULL;
}

static bool send_control(view_bridge *vb, int request, int64_t count)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    m.utime = lag_clock_wall_us();
    m.request = (int8_t)request;
    m.count = count;
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode_control(&m, buf, sizeof buf);
    return n > 0 && lcm_publish(vb->lcm_cmd, vb->ch_control, buf, (unsigned)n) == 0;
}

/* The window limit every control request of a page shares: false (counted) beyond it. */
static bool control_allowed(view_bridge *vb)
{
    int64_t now = lag_clock_mono_ns();
    if (now - vb->ctl_window_ns >= 1000000000) {
        vb->ctl_window_ns = now;
        vb->ctl_in_window = 0;
    }
    if (vb->ctl_in_window >= VIEW_CONTROLS_PER_S) return false;
    vb->ctl_in_window++;
    return true;
}

int view_bridge_kick(view_bridge *vb, const char *joint, const char *impulse,
                     const char *duration, const char **why)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    char *end = NULL;
    double j = impulse ? strtod(impulse, &end) : NAN;
    bool ok = impulse && end != impulse && !*end && isfinite(j);
    double d = 0;
    if (ok && duration && duration[0]) {
        d = strtod(duration, &end);
        ok = end != duration && !*end && isfinite(d) && d > 0 && d <= 1e9;
    }
    if (!ok || !joint || !joint[0] ||
        snprintf(m.key, sizeof m.key, "kick.%s", joint) >= (int)sizeof m.key) {
        vb->controls_refused++;
        *why = "kick: joint=NAME&impulse=N s[&duration=S s > 0], finite numbers";
        return 400;
    }
    if (!control_allowed(vb)) {
        vb->controls_refused++;
        *why = "too many control requests: at most 10 per second";
        return 429;
    }
    char a[LAG_NUM_LEN], b[LAG_NUM_LEN]; /* the kick event says 0.1, as typed */
    if (d > 0) snprintf(m.value, sizeof m.value, "%s,%s", lag_num(j, a), lag_num(d, b));
    else snprintf(m.value, sizeof m.value, "%s", lag_num(j, a));
    m.utime = lag_clock_wall_us();
    m.request = LAGSIM_CONTROL_T_SET;
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode_control(&m, buf, sizeof buf);
    if (n <= 0 || lcm_publish(vb->lcm_cmd, vb->ch_control, buf, (unsigned)n) != 0) {
        vb->controls_refused++;
        *why = "LCM publish failed";
        return 500;
    }
    vb->controls_sent++;
    *why = "sent (the daemon's kick event, or its reason, follows in the events)";
    return 0;
}

void view_bridge_poll(view_bridge *vb)
{
    for (int k = 0; k < VIEW_DRAIN_MAX; k++)
        if (lcm_handle_timeout(vb->lcm, 0) <= 0) break;
    int64_t now = lag_clock_mono_ns();
    if (!vb->scene_seq && now - vb->last_describe_ns >= VIEW_DESCRIBE_NS) {
        vb->last_describe_ns = now;
        send_control(vb, LAGSIM_CONTROL_T_DESCRIBE, 0);
    }
}

int view_bridge_control(view_bridge *vb, const char *request, const char *count,
                        const char **why)
{
    static const struct { const char *name; int request; } reqs[] = {
        {"pause", LAGSIM_CONTROL_T_PAUSE},   {"resume", LAGSIM_CONTROL_T_RESUME},
        {"step", LAGSIM_CONTROL_T_STEP},     {"reset", LAGSIM_CONTROL_T_RESET},
        {"status", LAGSIM_CONTROL_T_STATUS}, {"describe", LAGSIM_CONTROL_T_DESCRIBE},
    };
    int req = -1;
    for (size_t i = 0; request && i < sizeof reqs / sizeof reqs[0]; i++)
        if (strcmp(request, reqs[i].name) == 0) req = reqs[i].request;
    if (req < 0) {
        vb->controls_refused++;
        *why = "request must be pause, resume, step, reset, status or describe";
        return 400;
    }
    int64_t n = 0;
    if (req == LAGSIM_CONTROL_T_STEP) {
        char *end = NULL;
        long long v = count ? strtoll(count, &end, 10) : 1;
        if (count && (end == count || *end != '\0' || v < 1 || v > 1000000)) {
            vb->controls_refused++;
            *why = "step: count must be an integer from 1 to 1000000";
            return 400;
        }
        n = v;
    }
    /* a page (or a script) cannot make the bridge flood the daemon */
    if (!control_allowed(vb)) {
        vb->controls_refused++;
        *why = "too many control requests: at most 10 per second";
        return 429;
    }
    if (!send_control(vb, req, n)) {
        vb->controls_refused++;
        *why = "LCM publish failed";
        return 500;
    }
    vb->controls_sent++;
    *why = "sent";
    return 0;
}
