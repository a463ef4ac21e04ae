/*
 * The daemon's bus (lagsim_bus.h gives the URLs). On udpm://:
 *   b->lcm        publishes on the state URL;
 *   b->lcm_in     publishes on the command URL (DESCRIBE at start, the sync marker, the
 *                 probes of rt_foreign.h); neither subscribes, so LCM makes no thread,
 *                 pipe wait or select(2) for them;
 *   b->rx_in      the plant's own receive socket on the command URL (rt_rx.h), read by the
 *                 loop: this plant's _COMMAND and _CONTROL alone. Its socket filter
 *                 (lagsim_net.h) keeps only those, and unless lcm.allow_lan only datagrams
 *                 sent from this host;
 *   b->rx_foreign a second socket on the command URL: every other prefix's _CONTROL (below),
 *                 its filter dropping this plant's own. Apart, so that what is not for this
 *                 plant has a budget of its own (the loop's) and never costs the plant's
 *                 controller a command: a flood of it fills this socket's buffer, not the
 *                 plant's;
 *   b->rx_watch   the plant watch on the state URL: _SCENE (and _COMMAND sent to the wrong
 *                 port, counted), its filter dropping the daemon's own states in the kernel.
 * For memq:// (tests, one process) one lcm_t is both, with LCM's subscriptions.
 *
 * One plant per prefix: before it publishes anything, the daemon asks its prefix for a
 * scene (DESCRIBE) and listens RT_LOOK_MS (rt_bus_open); another plant's scene
 * (rt_bus_foreign_scene: one that decodes, names this prefix and is not one of the
 * daemon's own) makes it refuse to start, and later is counted and said. Whom it hears
 * follows the command URL's rule: this host only unless lcm.allow_lan.
 *
 * What is asked where the plant listens but not of it is heard too (rt_foreign.h): every
 * <P>_CONTROL on both ports (another prefix's: a misspelt one; this plant's on the state
 * port: the wrong port) and every <P>_SCENE on the state port (a prefix asked that has a
 * plant of its own). The filters keep them by their suffix; on the command URL they come
 * on a socket of their own (rx_foreign), read within a small budget of their own.
 */
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "lagsim_clock.h"
#include "lagsim_net.h"
#include "lagsim_url.h"
#include "daemon.h"
#include "rt_bus.h"
#include "rt_pace.h"
#include "lagsim/lagsim_control_t.h"

int rt_bus_init(rt_bus *b, const lag_scene *sc, char *err, size_t errlen)
{
    b->sc = sc;
    if (lag_bus_init(&b->urls, sc->lcm.url, sc->lcm.prefix, err, errlen) != 0) return -1;
    snprintf(b->ch_state, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_STATE]);
    snprintf(b->ch_command, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_COMMAND]);
    snprintf(b->ch_status, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_STATUS]);
    snprintf(b->ch_event, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_EVENT]);
    snprintf(b->ch_control, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_CONTROL]);
    snprintf(b->ch_scene, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_SCENE]);
    snprintf(b->ch_reference, RT_CHANNEL_MAX, "%s", b->urls.channel[LAG_BUS_REFERENCE]);
    return 0;
}

/* ---------------------------------------------------------------- subscriptions */
static void on_scene(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_bus *b = user;
    b->on.scene(b->on.ctx, rb->data, rb->data_size);
}

static void on_command(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_bus *b = user;
    if (!b->discard) b->on.command(b->on.ctx, rb->data, rb->data_size);
}

/* A command on the state URL: the controller publishes on the wrong port. Counted (the
 * waits say so, rt_wait.c), never applied. */
static void on_wrong_port(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)rb;
    (void)ch;
    rt_bus *b = user;
    if (!b->discard) b->commands_wrong_port++;
}

/* Every <P>_CONTROL on the command URL (this plant's own is on_control's) and on the
 * state URL, every <P>_SCENE on the state URL: rt_foreign.h. */
/* A control request heard on channel ch (state_port: on the state URL): counted; a prefix
 * heard for the first time is asked for its scene (the probe, within its bucket), so that
 * another plant's prefix is known as such (rt_foreign.h). */
static void foreign_request(rt_bus *b, const uint8_t *data, size_t size, const char *ch,
                            bool state_port)
{
    if (b->discard) return;
    rt_foreign_prefix *e =
        rt_foreign_request(&b->foreign, ch, b->ch_control, state_port, data, size);
    int64_t now = b->now ? *b->now : lag_clock_mono_ns();
    if (!e || !rt_limit_take(&b->probes, now)) return; /* asked again at its next request */
    lag_wire_control c;
    memset(&c, 0, sizeof c);
    c.utime = lag_clock_wall_us();
    c.request = LAGSIM_CONTROL_T_DESCRIBE;
    uint8_t buf[256];
    int len = lag_wire_encode(LAG_WIRE_CONTROL, &c, buf, sizeof buf);
    char channel[RT_CHANNEL_MAX];
    int w = lag_bus_channel_name(channel, sizeof channel, e->prefix, LAG_BUS_CONTROL);
    if (w < 0 || (size_t)w >= sizeof channel) return;
    if (len > 0 && lcm_publish(b->lcm_in, channel, buf, (unsigned)len) == 0)
        rt_foreign_probed(&b->foreign, e, now, c.utime);
}

static void on_foreign_in(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    foreign_request(user, rb->data, rb->data_size, ch, false);
}

static void on_foreign_out(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    foreign_request(user, rb->data, rb->data_size, ch, true);
}

static void on_foreign_scene(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)rb;
    rt_bus *b = user;
    if (!b->discard) rt_foreign_scene(&b->foreign, ch, b->ch_scene);
}

/* The three subscriptions of rt_foreign.h (none is needed to run: a failure is silent). */
static void subscribe_foreign(rt_bus *b, lcm_t *out, lcm_t *in)
{
    char control[32], scene[32]; /* every prefix's (LCM's channel patterns are regexes) */
    snprintf(control, sizeof control, ".*%s", lag_bus_suffix(LAG_BUS_CONTROL));
    snprintf(scene, sizeof scene, ".*%s", lag_bus_suffix(LAG_BUS_SCENE));
    b->sub_foreign_in = lcm_subscribe(in, control, on_foreign_in, b);
    b->sub_foreign_scene = lcm_subscribe(out, scene, on_foreign_scene, b);
    if (out != in) b->sub_foreign_out = lcm_subscribe(out, control, on_foreign_out, b);
    lcm_subscription_t *subs[] = {b->sub_foreign_in, b->sub_foreign_scene, b->sub_foreign_out};
    for (int i = 0; i < 3; i++)
        if (subs[i]) lcm_subscription_set_queue_capacity(subs[i], 16);
}

static void on_control(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    rt_bus *b = user;
    if (!b->discard) b->on.control(b->on.ctx, rb->data, rb->data_size);
}

int rt_bus_attach(rt_bus *b, lcm_t *out, lcm_t *in, const rt_bus_handlers *h, char *err,
                  size_t errlen)
{
    b->on = *h;
    b->lcm = out;
    b->lcm_in = in;
    b->sub_command = lcm_subscribe(in, b->ch_command, on_command, b);
    b->sub_control = lcm_subscribe(in, b->ch_control, on_control, b);
    if (!b->sub_command || !b->sub_control) {
        rt_bus_detach(b);
        snprintf(err, errlen, "cannot subscribe to %s and %s", b->ch_command, b->ch_control);
        return LAGSIMD_EXIT_RUNTIME;
    }
    /* a flood must not queue up without bound: LCM drops beyond this */
    lcm_subscription_set_queue_capacity(b->sub_command, 1000);
    lcm_subscription_set_queue_capacity(b->sub_control, 1000);
    /* the plant watch: another daemon's scene on this prefix. For udpm this gives the
     * state URL's lcm_t a receive socket, which rt_bus_open filters to _SCENE (the
     * daemon's own states are dropped by the kernel, never read back) */
    b->sub_scene = lcm_subscribe(out, b->ch_scene, on_scene, b);
    if (!b->sub_scene) {
        rt_bus_detach(b);
        snprintf(err, errlen, "cannot subscribe to %s", b->ch_scene);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lcm_subscription_set_queue_capacity(b->sub_scene, 16);
    if (out != in) { /* udpm: commands sent to the state URL's port are heard */
        b->sub_wrong_port = lcm_subscribe(out, b->ch_command, on_wrong_port, b);
        if (b->sub_wrong_port) lcm_subscription_set_queue_capacity(b->sub_wrong_port, 16);
    }
    subscribe_foreign(b, out, in);
    rt_limit_init(&b->probes, RT_FOREIGN_PROBES_PER_S, RT_FOREIGN_PROBES_PER_S,
                  b->now ? *b->now : lag_clock_mono_ns());
    return LAGSIMD_EXIT_OK;
}

void rt_bus_detach(rt_bus *b)
{
    if (b->sub_command) lcm_unsubscribe(b->lcm_in, b->sub_command);
    if (b->sub_control) lcm_unsubscribe(b->lcm_in, b->sub_control);
    if (b->sub_scene) lcm_unsubscribe(b->lcm, b->sub_scene);
    if (b->sub_wrong_port) lcm_unsubscribe(b->lcm, b->sub_wrong_port);
    if (b->sub_foreign_in) lcm_unsubscribe(b->lcm_in, b->sub_foreign_in);
    if (b->sub_foreign_out) lcm_unsubscribe(b->lcm, b->sub_foreign_out);
    if (b->sub_foreign_scene) lcm_unsubscribe(b->lcm, b->sub_foreign_scene);
    b->sub_wrong_port = b->sub_foreign_in = b->sub_foreign_out = b->sub_foreign_scene = NULL;
    b->sub_command = b->sub_control = NULL;
    b->sub_scene = NULL;
}

/* ---------------------------------------------------------------- one plant per prefix */
uint64_t rt_bus_hash(const uint8_t *data, size_t len)
{
    uint64_t h = 14695981039346656037ULL;
    for (size_t i = 0; i < len; i++) h = (h ^ data[i]) * 1099511628211ULL;
    return h;
}

void rt_bus_sent_scene(rt_bus *b, const uint8_t *data, size_t len)
{
    b->scene_sent[b->scene_next] = rt_bus_hash(data, len);
    b->scene_next = (b->scene_next + 1) % RT_SCENES_KEPT;
}

bool rt_bus_foreign_scene(rt_bus *b, const uint8_t *data, size_t len)
{
    uint64_t h = rt_bus_hash(data, len);
    for (int k = 0; k < RT_SCENES_KEPT; k++)
        if (b->scene_sent[k] == h) return false; /* this daemon's own */
    if (b->discard && b->other_plant[0]) return false; /* at start: said already */
    /* a plant's scene decodes and names its prefix; anything else on the channel is not a
     * plant (junk, a forgery of no consequence) and is ignored */
    static lag_wire_scene m; /* large: not on the stack of a handler */
    if (lag_wire_decode_scene(data, len, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK ||
        strcmp(m.prefix, b->sc->lcm.prefix) != 0)
        return false;
    snprintf(b->other_plant, sizeof b->other_plant, "a scene this daemon did not send "
             "(model %.20s, mode %.10s, dt %g s)", m.model, m.mode, m.dt);
    return !b->discard; /* at start (rt_bus_open's look before publishing): refused there */
}

/* ---------------------------------------------------------------- opening the bus */
/* The sync marker: sent on the command URL, read back by the plant's own socket. */
typedef struct sync_marker {
    rt_bus *b;
    char text[96];
} sync_marker;

static void send_marker(void *ctx)
{
    sync_marker *m = ctx;
    lcm_publish(m->b->lcm_in, LAG_NET_MARKER_CHANNEL, m->text, (unsigned)strlen(m->text));
}

/* The command URL's second socket: every prefix's _CONTROL but this plant's (rt_foreign.h),
 * filtered before anything reaches it but the few datagrams of the moment between its bind
 * and its filter, which its handler sorts as well (this plant's own are not its). */
static int open_foreign(rt_bus *b, char *err, size_t errlen)
{
    const lag_bus *u = &b->urls;
    const char *requests[] = {lag_bus_suffix(LAG_BUS_CONTROL)};
    const char *own[] = {b->ch_control};
    char ferr[256];
    if (rt_rx_open(&b->rx_foreign, u->group, u->command_port, b->rcvbuf, err, errlen) != 0)
        return LAGSIMD_EXIT_RUNTIME;
    if (lag_net_filter_fd(b->rx_foreign.fd, !b->sc->lcm.allow_lan, NULL, 0, requests, 1, own, 1,
                          ferr, sizeof ferr) != 0) {
        snprintf(err, errlen, "%s: cannot filter the command URL %s for other prefixes' "
                 "requests", ferr, u->command_url);
        return LAGSIMD_EXIT_RUNTIME;
    }
    return LAGSIMD_EXIT_OK;
}

/* Filters the plant's receive socket on the command URL, then reads until a marker sent
 * after the filter comes back, dropping whatever came before it (it may have come in
 * before the filter did). Returns 0, or an exit code with a message in err. */
static int filter_input(rt_bus *b, char *err, size_t errlen)
{
    const lag_bus *u = &b->urls;
    bool host_only = !b->sc->lcm.allow_lan;
    const char *with_marker[] = {b->ch_command, b->ch_control, LAG_NET_MARKER_CHANNEL};
    char ferr[256];
    if (lag_net_filter_fd(b->rx_in.fd, host_only, with_marker, 3, NULL, 0, NULL, 0, ferr,
                          sizeof ferr) != 0) {
        snprintf(err, errlen, "%s%s: cannot restrict the command URL %s to %s", ferr,
                 host_only ? "" : " (lcm.allow_lan: true)", u->command_url,
                 host_only ? "this host (lcm.allow_lan: false)" : "this plant's channels");
        return LAGSIMD_EXIT_RUNTIME;
    }
    static unsigned counter;
    sync_marker m = {b, ""};
    int64_t t = lag_clock_mono_ns();
    snprintf(m.text, sizeof m.text, "lagsimd %ld %s sync %u %lld", (long)getpid(),
             b->sc->lcm.prefix, ++counter, (long long)t);
    if (rt_rx_sync(&b->rx_in, LAG_NET_MARKER_CHANNEL, m.text, send_marker, &m, 3000) != 0) {
        snprintf(err, errlen, "LCM on %s does not hear its own messages (is there a multicast "
                 "route? docs/network.md)", u->command_url);
        return LAGSIMD_EXIT_RUNTIME;
    }
    if (lag_net_filter_fd(b->rx_in.fd, host_only, with_marker, 2, NULL, 0, NULL, 0, ferr,
                          sizeof ferr) != 0) {
        snprintf(err, errlen, "%s", ferr);
        return LAGSIMD_EXIT_RUNTIME;
    }
    return open_foreign(b, err, errlen);
}

/* Before the daemon publishes anything: filters the state URL's receive socket to _SCENE
 * (the plant watch) and asks the prefix for its scene (DESCRIBE on the command URL; a
 * daemon there answers on the state URL). Returns 0, or an exit code with a message. */
static int ask_for_other_plant(rt_bus *b, char *err, size_t errlen)
{
    const lag_bus *u = &b->urls;
    bool host_only = !b->sc->lcm.allow_lan;
    /* and _COMMAND: a command sent to the state port is counted (rt_wait.c says so); any
     * prefix's _CONTROL and _SCENE: rt_foreign.h */
    const char *out[] = {b->ch_scene, b->ch_command};
    const char *requests[] = {lag_bus_suffix(LAG_BUS_CONTROL), lag_bus_suffix(LAG_BUS_SCENE)};
    char ferr[256];
    int n = lag_net_filter_suffixes(u->state_port, host_only, out, 2, requests, 2, ferr,
                                    sizeof ferr);
    if (n <= 0) {
        snprintf(err, errlen, "%s: cannot filter the state URL %s for the plant watch",
                 n < 0 ? ferr : "the receive socket for the state port was not found",
                 u->state_url);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lag_wire_control c;
    memset(&c, 0, sizeof c);
    c.utime = lag_clock_wall_us();
    c.request = LAGSIM_CONTROL_T_DESCRIBE;
    int len = lag_wire_encode(LAG_WIRE_CONTROL, &c, b->buf, RT_BUF_SIZE);
    if (len > 0) lcm_publish(b->lcm_in, b->ch_control, b->buf, (unsigned)len);
    return LAGSIMD_EXIT_OK;
}

/* rt_rx's handlers: the plant's own sockets (udpm://). */
static void rx_command(void *ctx, const uint8_t *data, size_t len)
{
    rt_bus *b = ctx;
    if (!b->discard) b->on.command(b->on.ctx, data, len);
}

static void rx_control(void *ctx, const uint8_t *data, size_t len)
{
    rt_bus *b = ctx;
    if (!b->discard) b->on.control(b->on.ctx, data, len);
}

static void rx_scene(void *ctx, const uint8_t *data, size_t len)
{
    rt_bus *b = ctx;
    b->on.scene(b->on.ctx, data, len);
}

static void rx_wrong_port(void *ctx, const uint8_t *data, size_t len)
{
    (void)data, (void)len;
    rt_bus *b = ctx;
    if (!b->discard) b->commands_wrong_port++;
}

/* Whether channel ch ends in the suffix of `which` after a prefix. */
static bool ends_in(const char *ch, lag_bus_channel which)
{
    const char *suf = lag_bus_suffix(which);
    size_t n = strlen(ch), k = strlen(suf);
    return n > k && !strcmp(ch + n - k, suf);
}

/* Every datagram of the plant's sockets, as LCM's subscriptions to every prefix's
 * _CONTROL (both ports) and _SCENE (the state port) would hear them: rt_foreign.h. */
static void rx_foreign_in(void *ctx, const char *ch, const uint8_t *data, size_t len)
{
    if (ends_in(ch, LAG_BUS_CONTROL)) foreign_request(ctx, data, len, ch, false);
}

static void rx_foreign_out(void *ctx, const char *ch, const uint8_t *data, size_t len)
{
    rt_bus *b = ctx;
    if (ends_in(ch, LAG_BUS_CONTROL)) foreign_request(b, data, len, ch, true);
    else if (ends_in(ch, LAG_BUS_SCENE) && !b->discard) rt_foreign_scene(&b->foreign, ch, b->ch_scene);
}

/* udpm://: the plant's two receive sockets (rt_rx.h): _COMMAND and _CONTROL on the command
 * URL; the plant watch (_SCENE, and _COMMAND sent to the wrong port) on the state URL (the
 * third, other prefixes' requests on the command URL, comes with the start: open_foreign). */
static int open_receivers(rt_bus *b, char *err, size_t errlen)
{
    const lag_bus *u = &b->urls;
    lag_url url;
    long rcvbuf = lag_url_parse(u->state_url, LAG_URL_SCENE_RULES | LAG_URL_ALLOW_LAN, &url,
                                err, errlen) == 0 ? url.recv_buf_size : 0;
    b->rcvbuf = rcvbuf;
    b->rx_in = (rt_rx){-1, 2, {"", ""}, {rx_command, rx_control}, NULL, b, 0, 0};
    b->rx_watch = (rt_rx){-1, 2, {"", ""}, {rx_scene, rx_wrong_port}, rx_foreign_out, b, 0, 0};
    b->rx_foreign = (rt_rx){-1, 0, {"", ""}, {NULL, NULL}, rx_foreign_in, b, 0, 0};
    snprintf(b->rx_in.ch[0], sizeof b->rx_in.ch[0], "%s", b->ch_command);
    snprintf(b->rx_in.ch[1], sizeof b->rx_in.ch[1], "%s", b->ch_control);
    snprintf(b->rx_watch.ch[0], sizeof b->rx_watch.ch[0], "%s", b->ch_scene);
    snprintf(b->rx_watch.ch[1], sizeof b->rx_watch.ch[1], "%s", b->ch_command);
    if (rt_rx_open(&b->rx_in, u->group, u->command_port, rcvbuf, err, errlen) != 0 ||
        rt_rx_open(&b->rx_watch, u->group, u->state_port, rcvbuf, err, errlen) != 0)
        return LAGSIMD_EXIT_RUNTIME;
    return LAGSIMD_EXIT_OK;
}

int rt_bus_open_start(rt_bus *b, const rt_bus_handlers *h, char *err, size_t errlen)
{
    const lag_bus *u = &b->urls;
    lag_net_note_inherited(); /* a parent's sockets are not filtered */
    b->rx_in.fd = b->rx_watch.fd = b->rx_foreign.fd = -1;
    /* udpm: two publishers (no subscription: LCM makes no thread for them) and the plant's
     * own receive sockets; memq://: one lcm_t, LCM's subscriptions */
    lcm_t *out = lcm_create(u->state_url);
    lcm_t *in = !u->udpm ? out : out ? lcm_create(u->command_url) : NULL;
    if (!out || !in) {
        snprintf(err, errlen, "cannot create LCM on %s", out ? u->command_url : u->state_url);
        if (out) lcm_destroy(out);
        return LAGSIMD_EXIT_RUNTIME;
    }
    b->discard = true; /* until rt_begin: nothing that arrives before the start counts */
    int rc;
    if (u->udpm) {
        b->on = *h;
        b->lcm = out;
        b->lcm_in = in;
        rt_limit_init(&b->probes, RT_FOREIGN_PROBES_PER_S, RT_FOREIGN_PROBES_PER_S,
                      b->now ? *b->now : lag_clock_mono_ns());
        rc = open_receivers(b, err, errlen);
        if (rc == LAGSIMD_EXIT_OK) rc = ask_for_other_plant(b, err, errlen);
    } else {
        rc = rt_bus_attach(b, out, in, h, err, errlen);
        if (rc != LAGSIMD_EXIT_OK) {
            lcm_destroy(out);
            b->lcm = b->lcm_in = NULL;
            return rc;
        }
    }
    if (rc != LAGSIMD_EXIT_OK) rt_bus_close(b);
    return rc;
}

/* The socket of `which` (udpm://). */
static const rt_rx *rx_of(const rt_bus *b, rt_bus_input which)
{
    return which == RT_BUS_WATCH ? &b->rx_watch : which == RT_BUS_FOREIGN ? &b->rx_foreign
                                                                           : &b->rx_in;
}

int rt_bus_fd(const rt_bus *b, rt_bus_input which)
{
    if (b->urls.udpm) return rx_of(b, which)->fd;
    return which != RT_BUS_IN || !b->lcm_in ? -1 : lcm_get_fileno(b->lcm_in);
}

int rt_bus_read(rt_bus *b, rt_bus_input which, int max)
{
    if (b->urls.udpm) return rt_rx_read((rt_rx *)rx_of(b, which), max);
    int n = 0;
    while (which == RT_BUS_IN && b->lcm_in && n < max && lcm_handle_timeout(b->lcm_in, 0) > 0)
        n++;
    return n;
}

/* Where the daemon listens, and who can reach it (said at start). */
static void say_where(const rt_bus *b)
{
    const lag_bus *u = &b->urls;
    char ifname[64];
    if (lag_net_group_iface(u->group, ifname, sizeof ifname) != 0)
        snprintf(ifname, sizeof ifname, "no interface (no route to %s)", u->group);
    int ttl = b->sc->lcm.ttl; /* the loader's reading of the URL (LCM_DEFAULT_URL included) */
    if (ttl > 0)
        fprintf(stderr, "lagsimd: warning: LCM url '%s' has ttl=%d: states, status and events "
                "leave this host (multicast to the local network%s)\n", u->state_url, ttl,
                ttl > 1 ? " and beyond routers" : "");
    /* -q: only what warns (the network can reach the plant), as the ttl warning above */
    if (b->sc->lcm.allow_lan)
        fprintf(stderr, "lagsimd: %s: listening on %s for commands and control from the "
                "network (lcm.allow_lan: true: any host that reaches %s can command this "
                "plant) on %s; states on %s\n", b->sc->lcm.prefix, ifname, ifname,
                u->command_url, u->state_url);
    else if (!b->quiet)
        fprintf(stderr, "lagsimd: %s: listening on %s for commands and control from this "
                "host only (lcm.allow_lan: false) on %s; states on %s%s\n", b->sc->lcm.prefix,
                ifname, u->command_url, u->state_url,
                ttl == 0 ? ", which stay on this host (ttl=0)" : "");
}

int rt_bus_open_finish(rt_bus *b, char *err, size_t errlen)
{
    const lag_bus *u = &b->urls;
    if (!u->udpm) {
        if (!b->quiet)
            fprintf(stderr, "lagsimd: %s: on %s (this process only)\n", b->sc->lcm.prefix,
                    u->state_url);
        return LAGSIMD_EXIT_OK;
    }
    int rc = LAGSIMD_EXIT_OK;
    if (b->other_plant[0]) {
        snprintf(err, errlen, "another plant publishes on prefix %s (%s): refusing to start; "
                 "one plant per prefix (give this one another lcm.prefix, or stop the other)",
                 b->sc->lcm.prefix, b->other_plant);
        rc = LAGSIMD_EXIT_RUNTIME;
    }
    if (rc == LAGSIMD_EXIT_OK) rc = filter_input(b, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) {
        rt_bus_close(b);
        return rc;
    }
    say_where(b);
    return LAGSIMD_EXIT_OK;
}

int rt_bus_open(rt_bus *b, const rt_bus_handlers *h, char *err, size_t errlen)
{
    int rc = rt_bus_open_start(b, h, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) return rc;
    int64_t end = lag_clock_mono_ns() + RT_LOOK_MS * 1000000LL;
    for (int64_t left; b->urls.udpm && !b->other_plant[0] && (left = end - lag_clock_mono_ns()) > 0;) {
        struct pollfd pf = {b->rx_watch.fd, POLLIN, 0};
        poll(&pf, 1, (int)(left / 1000000) + 1);
        rt_rx_read(&b->rx_watch, 16);
    }
    return rt_bus_open_finish(b, err, errlen);
}

void rt_bus_close(rt_bus *b)
{
    rt_bus_detach(b);
    rt_rx_close(&b->rx_in);
    rt_rx_close(&b->rx_watch);
    rt_rx_close(&b->rx_foreign);
    if (b->lcm_in && b->lcm_in != b->lcm) lcm_destroy(b->lcm_in);
    if (b->lcm) lcm_destroy(b->lcm);
    b->lcm = b->lcm_in = NULL;
}
