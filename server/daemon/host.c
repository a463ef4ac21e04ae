/*
 * The loop of lagsimd's real-time server, for one plant or a host of many (host.h).
 *
 *     while a plant runs (or a directory is watched and no stop came):
 *         wake = the earliest of every plant's rt_next_wake (cached: a plant's is
 *                computed again only after it was processed), the looks of plants
 *                starting, a reading of the directory due
 *         rt_io_wait(io, wake)     epoll on every plant's receive sockets (rt_rx.h), the
 *                                  host's directory and inotify, one timerfd, one
 *                                  signalfd; a plant whose socket is ready reads at most
 *                                  HOST_DRAIN_MAX messages and is marked
 *         host_pass(h)             every plant due or marked: rt_process, its wake again;
 *                                  plants whose look is over start; stopped ones end
 *
 * A plant's input budget (a host's plants only; a daemon of one plant reads as before):
 * HOST_INPUT_PER_STATE messages for every state it publishes, HOST_INPUT_PER_S more a
 * second, HOST_INPUT_BURST at once. A controller needs one command per state (a copy of
 * a state, one more); a flood beyond the budget is left unread: the plant's socket is
 * parked until the budget allows again (the kernel drops what the socket's buffer cannot
 * hold), so that the flood costs the loop, and every other plant, nothing more. Lockstep
 * at any speed keeps its budget, which grows with the states it publishes.
 *
 * What is not for the plant (other prefixes' requests on its command URL: a student on a
 * copied URL, polling) comes on a socket of its own (rt_bus.h) with a budget of its own,
 * for a daemon of one plant too: HOST_FOREIGN_PER_S a second, HOST_FOREIGN_BURST at once,
 * counted and said (foreign_limited), the socket parked beyond (the kernel drops the rest,
 * and counts it). It never costs the plant's own controller a command.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host.h"
#include "lagsim_bus.h"
#include "lagsim_clock.h"
#include "lagsim_net.h"
#include "lagsim_url.h"
#include "lagsim_wire.h"
#include "lagsim/lagsim_control_t.h"
#include "realtime.h"
#include "rt_io.h"
#include "rt_pace.h"
#include "scene_run.h"

#define HOST_MAX_PLANTS 1024
#define HOST_DRAIN_MAX 256           /* messages a plant handles per wake-up at most */
#define HOST_WATCH_DRAIN_MAX 16      /* of the plant watch (scenes heard on the prefix) */
#define HOST_INPUT_PER_STATE 8
#define HOST_INPUT_PER_S 100.0
#define HOST_INPUT_BURST 256.0
#define HOST_FOREIGN_PER_S 20.0      /* other prefixes' requests read a second */
#define HOST_FOREIGN_BURST 20
#define HOST_RESCAN_NS 200000000LL   /* a quiet 0.2 s after inotify's last word */
#define HOST_LOG_RING_DEFAULT (1u << 20) /* a host's plant's --log ring: 1 MiB */
#define HOST_ANNOUNCE_NS 500000000LL /* each plant's `plant` event on the directory */
#define HOST_DIR_PER_S 5.0           /* directory answers per plant: 5 a second, 5 at once */

typedef enum plant_phase { PLANT_LOOKING, PLANT_RUNNING } plant_phase;

typedef struct host host;

/* One plant of the host: its file, its scene, its server and its place in the wait. */
typedef struct plant {
    host *h;
    char name[NAME_MAX + 1];    /* DIR's NAME of NAME.yaml; a --config's path */
    char file[PATH_MAX];
    bool from_dir;
    char *text;                 /* the file's bytes (the scene, and every SET, from them) */
    size_t len;
    const char **sets;          /* the host's --set, its own prefix and URL, the choice */
    int nsets;
    char set_prefix[96], set_url[LAG_BUS_URL_LEN + 16];
    lagsimd_choice choice;
    lag_scene sc;
    lagsimd_opts opts;
    char log_path[PATH_MAX];
    char who[80];               /* "ALICE: " */
    int port;                   /* the state port (0: memq://); commands on port + 1 */
    bool port_from_base;
    rt_server *s;
    plant_phase phase;
    int64_t look_end, wake;
    bool marked;                /* heard something since it was last processed */
    rt_io_src in, watch, foreign;
    rt_limit foreign_lim;       /* other prefixes' requests: their budget */
    /* the input budget */
    double tokens;
    int64_t tokens_ns, published;
    int64_t parked_times;
    /* the host's directory */
    int64_t announce_ns;        /* its next `plant` event */
    rt_limit dir_lim;           /* its answers there */
    char state_url[LAG_BUS_URL_LEN];
} plant;

/* A file that failed to start (DIR's by its NAME, a --config by its path), remembered so
 * that a reading of the files does not say it again until it changes or SIGHUP asks. */
typedef struct failed {
    char name[NAME_MAX + 1];
    uint64_t hash;
} failed;

struct host {
    const host_conf *c;
    bool one;                   /* a daemon of one plant: its failure is the daemon's */
    rt_io io;
    int64_t now;
    plant *p[HOST_MAX_PLANTS];
    int n;
    failed fail[HOST_MAX_PLANTS];
    int nfail;
    bool retry;                 /* SIGHUP: the next reading tries the failed files again */
    int notify_fd;
    rt_io_src notify;
    /* the directory: LCM_DEFAULT_URL's (or LCM's default) bus, where lagsimctl list
     * listens unless told otherwise */
    lag_bus dir;
    lcm_t *dir_out, *dir_in;
    rt_io_src dir_src;
    uint8_t dir_buf[LAG_WIRE_BUF_SIZE];
    int64_t rescan_at;          /* INT64_MAX: none due */
    bool stopping;              /* a stop signal came: no plant starts any more */
    lag_result rc;
    int port_base;              /* --port-base, or the directory's next pair (--plants) */
    int started;                /* plants started so far */
    int skipped;                /* files that could not start */
};

/* ---------------------------------------------------------------- small helpers */
static uint64_t hash_bytes(const char *data, size_t len)
{
    uint64_t hv = 14695981039346656037ULL;
    for (size_t i = 0; i < len; i++) hv = (hv ^ (uint8_t)data[i]) * 1099511628211ULL;
    return hv;
}

static int64_t min64(int64_t a, int64_t b) { return a < b ? a : b; }

/* The plant of file name `name` (DIR's), or NULL. */
static plant *plant_named(host *h, const char *name)
{
    for (int i = 0; i < h->n; i++)
        if (h->p[i]->from_dir && !strcmp(h->p[i]->name, name)) return h->p[i];
    return NULL;
}

static void say(const plant *p, const char *what)
{
    fprintf(stderr, "lagsimd: %s: %s\n", p->file, what);
}

/* ---------------------------------------------------------------- a plant's scene */
/* A DIR plant's prefix: its file's NAME in capitals (a class gives each student a file,
 * alice.yaml: ALICE). 0, or -1 when NAME cannot be a prefix (said). */
static int prefix_of_name(plant *p)
{
    size_t n = strlen(p->name);
    bool ok = n >= 1 && n <= LAG_SCENE_PREFIX_MAX;
    char up[LAG_SCENE_PREFIX_MAX + 1] = "";
    for (size_t i = 0; ok && i < n; i++) {
        char ch = p->name[i];
        ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
             ch == '_';
        up[i] = (char)(ch >= 'a' && ch <= 'z' ? ch - 'a' + 'A' : ch);
    }
    if (!ok) {
        fprintf(stderr, "lagsimd: %s: a plant of a directory takes its prefix from its file's "
                "name in capitals: '%s' is not a channel prefix (1 to %d of A-Z, a-z, 0-9, _); "
                "rename the file\n", p->file, p->name, LAG_SCENE_PREFIX_MAX);
        return -1;
    }
    up[n] = '\0';
    snprintf(p->set_prefix, sizeof p->set_prefix, "lcm.prefix=%s", up);
    return 0;
}

/* Whether a pair at `port` overlaps the host's directory or a plant's but `self`'s. */
static bool port_used(const host *h, const plant *self, int port)
{
    if (h->dir_in && port > h->dir.state_port - 2 && port < h->dir.state_port + 2) return true;
    for (int i = 0; i < h->n; i++) {
        const plant *q = h->p[i];
        if (q != self && q->port > 0 && port > q->port - 2 && port < q->port + 2) return true;
    }
    return false;
}

/* --port-base: the first free pair from the base (or `keep`, the plant's pair before a
 * reload), on the group and options of LCM_DEFAULT_URL (or LCM's default). 0, or -1
 * (said). */
static int port_from_base(host *h, plant *p, int keep)
{
    const char *env = getenv("LCM_DEFAULT_URL");
    lag_url u;
    char err[256];
    if (lag_url_parse(env && env[0] ? env : "udpm://", 0, &u, err, sizeof err) != 0 ||
        u.provider != LAG_URL_UDPM) {
        fprintf(stderr, "lagsimd: %s: --port-base needs a udpm:// LCM_DEFAULT_URL (or none): "
                "%s\n", p->file, env);
        return -1;
    }
    int port = keep;
    for (int k = 0; port == 0 && h->port_base + 2 * k + 1 <= 65535; k++)
        if (!port_used(h, p, h->port_base + 2 * k)) port = h->port_base + 2 * k;
    if (port == 0) {
        fprintf(stderr, "lagsimd: %s: no free port pair from --port-base %d up to 65535\n",
                p->file, h->port_base);
        return -1;
    }
    lag_url_format(&u, port, p->set_url + 8, sizeof p->set_url - 8);
    memcpy(p->set_url, "lcm.url=", 8);
    p->port_from_base = true;
    return 0;
}

/* Loads the plant's scene from its bytes: the host's --set, then its own prefix (a DIR
 * plant's), then (a scene with no lcm.url, --port-base) its own URL; the integrator
 * integrator.error chooses; LCM_DEFAULT_URL. `keep`: its port before a reload (0: none).
 * 0, or -1 (said). */
static int plant_scene(host *h, plant *p, int keep)
{
    const host_conf *c = h->c;
    p->nsets = 0;
    for (int i = 0; i < c->nsets; i++) p->sets[p->nsets++] = c->sets[i];
    if (p->from_dir) {
        if (prefix_of_name(p) != 0) return -1;
        p->sets[p->nsets++] = p->set_prefix;
    }
    /* as the file says first (nothing chosen yet): whether it names a URL */
    scene_run_how plain = {true, false, false, c->opts.quiet};
    if (scene_run_load(p->file, p->text, p->len, p->sets, &p->nsets, plain, &p->choice,
                       &p->sc) != LAG_OK)
        return -1;
    if (!p->sc.lcm.url[0] && h->port_base > 0) {
        if (port_from_base(h, p, keep) != 0) return -1;
        p->sets[p->nsets++] = p->set_url;
    }
    scene_run_how how = {false, false, false, c->opts.quiet};
    if (scene_run_load(p->file, p->text, p->len, p->sets, &p->nsets, how, &p->choice, &p->sc) != LAG_OK)
        return -1;
    return scene_run_default_url(&p->sc) == LAG_OK ? 0 : -1;
}

/* Another plant of the host with the plant's prefix, or a port pair that overlaps its
 * own: refused, both files named. 0, or -1 (said). */
static int plant_conflicts(host *h, plant *p)
{
    lag_bus b;
    char err[256];
    if (lag_bus_init(&b, p->sc.lcm.url, p->sc.lcm.prefix, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: %s: %s\n", p->file, err);
        return -1;
    }
    p->port = b.udpm ? b.state_port : 0;
    snprintf(p->state_url, sizeof p->state_url, "%s", b.state_url);
    if (h->dir_in && p->port > h->dir.state_port - 2 && p->port < h->dir.state_port + 2) {
        fprintf(stderr, "lagsimd: %s: ports %d and %d are the host's directory (%s, where "
                "lagsimctl list looks): give the plant another lcm.url, or --port-base "
                "(not started)\n", p->file, p->port, p->port + 1, h->dir.state_url);
        return -1;
    }
    for (int i = 0; i < h->n; i++) {
        const plant *q = h->p[i];
        if (q == p) continue;
        if (!strcmp(q->sc.lcm.prefix, p->sc.lcm.prefix)) {
            fprintf(stderr, "lagsimd: %s: prefix %s is already the plant of %s: one plant per "
                    "prefix (not started)\n", p->file, p->sc.lcm.prefix, q->file);
            return -1;
        }
        if (p->port > 0 && q->port > p->port - 2 && q->port < p->port + 2) {
            fprintf(stderr, "lagsimd: %s: ports %d and %d: the plant of %s has %d and %d; in "
                    "one lagsimd each plant has a port pair of its own (lcm.url, or "
                    "--port-base) (not started)\n", p->file, p->port, p->port + 1, q->file,
                    q->port, q->port + 1);
            return -1;
        }
    }
    return 0;
}

/* A host's plant with --log FILE writes DIR(FILE)/NAME/BASE(FILE), NAME its own, in a
 * directory made for it. 0, or -1 (said). */
static int plant_log(host *h, plant *p)
{
    const char *log = h->c->opts.log;
    if (!log || h->one) return 0;
    const char *slash = strrchr(log, '/');
    int dlen = slash ? (int)(slash - log) : 0;
    char dir[PATH_MAX];
    int n = snprintf(dir, sizeof dir, "%.*s%s%s", dlen, log, slash ? "/" : "", p->name);
    if (n < 0 || n >= (int)sizeof dir ||
        snprintf(p->log_path, sizeof p->log_path, "%s/%s", dir, slash ? slash + 1 : log) >=
            (int)sizeof p->log_path) {
        fprintf(stderr, "lagsimd: %s: --log: the plant's path is too long\n", p->file);
        return -1;
    }
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "lagsimd: %s: --log: cannot make the plant's directory %s: %s\n",
                p->file, dir, strerror(errno));
        return -1;
    }
    p->opts.log = p->log_path;
    return 0;
}

static void plant_free(plant *p)
{
    if (!p) return;
    if (p->s) rt_plant_free(p->s);
    free(p->text);
    free(p->sets);
    free(p);
}

/* A plant of file `file` (name: DIR's NAME, or NULL for a --config), its bytes read and its
 * scene loaded, not yet open; NULL when it cannot be (said). `keep`: its port pair before a
 * reload. */
static plant *plant_from_file(host *h, const char *file, const char *name, int keep)
{
    plant *p = calloc(1, sizeof *p);
    if (!p || !(p->sets = calloc((size_t)h->c->nsets + 2 + 4, sizeof *p->sets))) {
        fprintf(stderr, "lagsimd: %s: out of memory\n", file);
        plant_free(p);
        return NULL;
    }
    p->h = h;
    snprintf(p->file, sizeof p->file, "%s", file);
    p->from_dir = name != NULL;
    char err[1024];
    if (lag_scene_read(file, &p->text, &p->len, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "%s\n", err);
        plant_free(p);
        return NULL;
    }
    if (name) snprintf(p->name, sizeof p->name, "%s", name);
    if (plant_scene(h, p, keep) != 0) {
        plant_free(p);
        return NULL;
    }
    if (!name) snprintf(p->name, sizeof p->name, "%s", p->sc.lcm.prefix);
    return p;
}

/* ---------------------------------------------------------------- the input budget */
/* The budget brought up to date: HOST_INPUT_PER_S a second and HOST_INPUT_PER_STATE for
 * each state published since, at most HOST_INPUT_BURST. */
static void budget_refill(plant *p, int64_t now)
{
    int64_t pub = rt_plant_published(p->s);
    double dt = (double)(now - p->tokens_ns) * 1e-9;
    p->tokens += (dt > 0 ? dt * HOST_INPUT_PER_S : 0.0) +
                 (double)(pub - p->published) * HOST_INPUT_PER_STATE;
    if (p->tokens > HOST_INPUT_BURST) p->tokens = HOST_INPUT_BURST;
    if (now > p->tokens_ns) p->tokens_ns = now;
    p->published = pub;
}

/* When a parked plant's budget allows a message again (by the time alone). */
static int64_t budget_ready(const plant *p)
{
    if (p->tokens >= 1.0) return p->tokens_ns;
    return rt_sat_add(p->tokens_ns, (int64_t)((1.0 - p->tokens) / HOST_INPUT_PER_S * 1e9) + 1);
}

static void budget_park(plant *p)
{
    rt_io_park(&p->h->io, &p->in, true);
    rt_plant_input_limited(p->s, ++p->parked_times, "a budget of 8 messages a state "
                           "published, 100 a second more, 256 at once: reading paused until "
                           "it allows; the kernel drops what the socket cannot hold");
}

/* ---------------------------------------------------------------- sources */
/* The plant's command URL has messages: a bounded number handled (a host's plant: within
 * its budget, parked when spent). */
static void on_input(void *ctx)
{
    plant *p = ctx;
    host *h = p->h;
    int max = HOST_DRAIN_MAX;
    if (!h->one) {
        budget_refill(p, h->now);
        if (p->tokens < max) max = (int)p->tokens;
    }
    int n = max > 0 ? rt_plant_drain(p->s, RT_PLANT_IN, h->now, max) : 0;
    p->marked = true;
    if (h->one) return;
    p->tokens -= n;
    if (n == max && p->tokens < 1.0) budget_park(p);
}

/* Other prefixes' requests on the command URL: read within their budget; parked and said
 * when it is spent and more wait. */
static void on_foreign(void *ctx)
{
    plant *p = ctx;
    host *h = p->h;
    p->marked = true;
    for (int n = 0; n < HOST_FOREIGN_BURST; n++) {
        if (rt_limit_ready(&p->foreign_lim, h->now) > h->now) break;
        if (rt_plant_drain(p->s, RT_PLANT_FOREIGN, h->now, 1) == 0) return;
        rt_limit_take(&p->foreign_lim, h->now);
    }
    rt_io_park(&h->io, &p->foreign, true);
    struct pollfd pf = {p->foreign.fd, POLLIN, 0};
    if (poll(&pf, 1, 0) != 1) return;
    char why[96];
    snprintf(why, sizeof why, "%g a second read, apart from this plant's own input",
             HOST_FOREIGN_PER_S);
    rt_plant_foreign_limited(p->s, why);
}

/* The plant watch: a scene heard on the prefix. */
static void on_watch(void *ctx)
{
    plant *p = ctx;
    rt_plant_drain(p->s, RT_PLANT_WATCH, p->h->now, HOST_WATCH_DRAIN_MAX);
    p->marked = true;
}

static int add_source(host *h, rt_io_src *src, int fd, void (*ready)(void *), plant *p)
{
    if (fd < 0) return 0;
    src->fd = fd;
    src->ready = ready;
    src->ctx = p;
    return rt_io_add(&h->io, src);
}

/* ---------------------------------------------------------------- the directory */
/* A host of a directory's plants (--plants, --port-base) keeps a directory on the bus of
 * LCM_DEFAULT_URL (else LCM's default): where lagsimctl list, the view and the
 * controllers look for plants unless told a URL. Every HOST_ANNOUNCE_NS each plant sends
 * there a `plant` event on <PREFIX>_EVENT, its state URL in detail and its state port in
 * value (the clients' discovery takes the plant's URL from it); a STATUS or DESCRIBE
 * request there for one of the host's plants is answered there with the last status or
 * scene the plant published (HOST_DIR_PER_S a second for each). Nothing else is done
 * there: the plant's own URL takes its commands and the other requests. No plant runs on
 * the directory's port pair. */
static plant *plant_of_prefix(host *h, const char *pre, size_t len)
{
    for (int i = 0; i < h->n; i++)
        if (strlen(h->p[i]->sc.lcm.prefix) == len && !strncmp(h->p[i]->sc.lcm.prefix, pre, len))
            return h->p[i];
    return NULL;
}

/* A request on the directory: STATUS and DESCRIBE of a running plant answered. */
static void dir_control(const lcm_recv_buf_t *rb, const char *channel, void *user)
{
    host *h = user;
    static lag_wire_control m;
    const char *suffix = lag_bus_suffix(LAG_BUS_CONTROL);
    size_t cl = strlen(channel), sl = strlen(suffix);
    plant *p = cl > sl ? plant_of_prefix(h, channel, cl - sl) : NULL;
    if (!p || p->phase != PLANT_RUNNING ||
        lag_wire_decode(LAG_WIRE_CONTROL, rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m) !=
            LAG_WIRE_OK ||
        (m.request != LAGSIM_CONTROL_T_STATUS && m.request != LAGSIM_CONTROL_T_DESCRIBE) ||
        !rt_limit_take(&p->dir_lim, h->now))
        return;
    bool status = m.request == LAGSIM_CONTROL_T_STATUS;
    const uint8_t *data;
    unsigned len = rt_plant_last(p->s, status, &data);
    char ch[LAG_BUS_CHANNEL_LEN];
    lag_bus_channel_name(ch, sizeof ch, p->sc.lcm.prefix, status ? LAG_BUS_STATUS : LAG_BUS_SCENE);
    if (len > 0) lcm_publish(h->dir_out, ch, data, len);
}

static void on_directory(void *ctx)
{
    host *h = ctx;
    for (int k = 0; k < HOST_DRAIN_MAX && lcm_handle_timeout(h->dir_in, 0) > 0; k++) {}
}

/* Plant p's `plant` event on the directory. */
static void announce(host *h, plant *p)
{
    lag_wire_event m;
    memset(&m, 0, sizeof m);
    m.utime = lag_clock_wall_us();
    snprintf(m.kind, sizeof m.kind, "plant");
    m.value = p->port;
    memcpy(m.detail, p->state_url, strnlen(p->state_url, sizeof m.detail - 1)); /* < 256 */
    int n = lag_wire_encode(LAG_WIRE_EVENT, &m, h->dir_buf, sizeof h->dir_buf);
    char ch[LAG_BUS_CHANNEL_LEN];
    lag_bus_channel_name(ch, sizeof ch, p->sc.lcm.prefix, LAG_BUS_EVENT);
    if (n > 0) lcm_publish(h->dir_out, ch, h->dir_buf, (unsigned)n);
    p->announce_ns = rt_sat_add(h->now, HOST_ANNOUNCE_NS);
}

/* Opens the directory (said when it cannot: the host runs without one). */
static void dir_open(host *h)
{
    char err[256];
    if (lag_bus_init(&h->dir, NULL, "X", err, sizeof err) != 0 || !h->dir.udpm) {
        fprintf(stderr, "lagsimd: no directory of the host's plants (LCM_DEFAULT_URL: %s)\n",
                h->dir.udpm ? err : "not udpm://");
        return;
    }
    h->dir_out = lcm_create(h->dir.state_url);
    h->dir_in = h->dir_out ? lcm_create(h->dir.command_url) : NULL;
    lcm_subscription_t *sub = h->dir_in ? lcm_subscribe(h->dir_in, ".*_CONTROL", dir_control, h)
                                        : NULL;
    if (sub) lcm_subscription_set_queue_capacity(sub, 1000);
    h->dir_src = (rt_io_src){h->dir_in ? lcm_get_fileno(h->dir_in) : -1, on_directory, h,
                             false, false};
    err[0] = '\0';
    /* every prefix's _CONTROL, from this host (the marker: no other channel is needed) */
    const char *marker[] = {LAG_NET_MARKER_CHANNEL}, *requests[] = {lag_bus_suffix(LAG_BUS_CONTROL)};
    int nf = sub ? lag_net_filter_suffixes(h->dir.command_port, true, marker, 1, requests, 1, err,
                                           sizeof err)
                 : -1;
    if (nf == 0) snprintf(err, sizeof err, "LCM's receive socket was not found");
    if (nf < 1 || rt_io_add(&h->io, &h->dir_src) != 0) {
        fprintf(stderr, "lagsimd: no directory of the host's plants on %s: %s\n",
                h->dir.state_url, sub ? err : "cannot make LCM there");
        if (h->dir_in) lcm_destroy(h->dir_in);
        if (h->dir_out) lcm_destroy(h->dir_out);
        h->dir_in = h->dir_out = NULL;
        return;
    }
    fprintf(stderr, "lagsimd: the host's directory is on %s: lagsimctl list shows every plant "
            "with its URL\n", h->dir.state_url);
}

static void dir_close(host *h)
{
    rt_io_remove(&h->io, &h->dir_src);
    if (h->dir_in) lcm_destroy(h->dir_in);
    if (h->dir_out) lcm_destroy(h->dir_out);
    h->dir_in = h->dir_out = NULL;
}

/* ---------------------------------------------------------------- a plant's life */
/* Opens a loaded plant and adds it to the host: its server opened, the look for another
 * plant on its prefix begun. 0, or -1 (said; the plant freed; a daemon of one plant keeps
 * the exit code in h->rc). */
static int plant_open(host *h, plant *p)
{
    char err[1024];
    int rc = LAGSIMD_EXIT_RUNTIME;
    p->opts = h->c->opts; /* a daemon of one plant: the command line's, scene included */
    if (p->text) {
        p->opts.scene_name = p->file;
        p->opts.scene_text = p->text;
        p->opts.scene_len = p->len;
        p->opts.sets = p->sets;
        p->opts.nsets = p->nsets;
    }
    if (!h->one && !p->opts.log_ring) p->opts.log_ring = HOST_LOG_RING_DEFAULT;
    if (h->n >= HOST_MAX_PLANTS) {
        fprintf(stderr, "lagsimd: %s: a host runs at most %d plants (not started)\n", p->file,
                HOST_MAX_PLANTS);
    } else if (plant_conflicts(h, p) == 0 && plant_log(h, p) == 0) {
        snprintf(p->who, sizeof p->who, "%s%s", h->one ? "" : p->sc.lcm.prefix, h->one ? "" : ": ");
        if (!(p->s = rt_plant_new())) snprintf(err, sizeof err, "out of memory");
        else if ((rc = rt_plant_open(p->s, &p->sc, &p->opts, h->now, p->opts.quiet, p->who, err,
                                     sizeof err)) == LAGSIMD_EXIT_OK)
            goto opened;
        fprintf(stderr, "lagsimd: %s%s%s\n", h->one ? "" : p->file, h->one ? "" : ": ", err);
    }
    if (h->one) h->rc = rc;
    plant_free(p);
    return -1;
opened:
    h->p[h->n++] = p;
    p->phase = PLANT_LOOKING;
    p->look_end = rt_sat_add(h->now, rt_plant_look_ns(p->s));
    p->tokens = HOST_INPUT_BURST;
    p->tokens_ns = h->now;
    rt_limit_init(&p->dir_lim, HOST_DIR_PER_S, (int)HOST_DIR_PER_S, h->now);
    rt_limit_init(&p->foreign_lim, HOST_FOREIGN_PER_S, HOST_FOREIGN_BURST, h->now);
    p->announce_ns = rt_sat_add(h->now, (int64_t)(hash_bytes(p->sc.lcm.prefix,
                                                             strlen(p->sc.lcm.prefix)) %
                                                  (uint64_t)HOST_ANNOUNCE_NS));
    if (add_source(h, &p->in, rt_plant_fd(p->s, RT_PLANT_IN), on_input, p) != 0 ||
        add_source(h, &p->watch, rt_plant_fd(p->s, RT_PLANT_WATCH), on_watch, p) != 0)
        rt_plant_stop(p->s, RT_STOP_ERROR);
    return 0;
}

/* The look is over: the plant starts, or is refused (another plant answered on its
 * prefix: said, and ended by the pass). */
static void plant_start(host *h, plant *p)
{
    char err[1024];
    bool live = h->one && isatty(STDERR_FILENO) && !p->opts.quiet;
    int rc = rt_plant_start(p->s, h->now, live, err, sizeof err);
    if (rc != LAGSIMD_EXIT_OK) {
        fprintf(stderr, "lagsimd: %s%s%s\n", h->one ? "" : p->file, h->one ? "" : ": ", err);
        if (h->one) h->rc = rc;
        rt_plant_stop(p->s, RT_STOP_ERROR);
        return;
    }
    p->phase = PLANT_RUNNING;
    if (add_source(h, &p->foreign, rt_plant_fd(p->s, RT_PLANT_FOREIGN), on_foreign, p) != 0)
        rt_plant_stop(p->s, RT_STOP_ERROR);
    p->published = rt_plant_published(p->s);
    p->wake = h->now;
    h->started++;
}

/* Ends plant i (why: RT_STOP_NONE when it stopped by itself) and takes it out. */
static void plant_end(host *h, int i, rt_stop why)
{
    plant *p = h->p[i];
    if (why != RT_STOP_NONE) rt_plant_stop(p->s, why);
    rt_io_remove(&h->io, &p->in);
    rt_io_remove(&h->io, &p->watch);
    rt_io_remove(&h->io, &p->foreign);
    lag_result rc = rt_plant_end(p->s, p->phase == PLANT_RUNNING);
    if (rc != LAG_OK && h->rc == LAG_OK) h->rc = rc;
    if (!h->one && !p->opts.quiet)
        fprintf(stderr, "lagsimd: %s: plant %s stopped\n", p->file, p->sc.lcm.prefix);
    plant_free(p);
    memmove(&h->p[i], &h->p[i + 1], (size_t)(h->n - i - 1) * sizeof h->p[0]);
    h->n--;
}

/* A parked socket of the plant waited on again once its budget allows. */
static void unpark(host *h, plant *p)
{
    if (p->in.parked) {
        budget_refill(p, h->now);
        if (p->tokens >= 1.0) rt_io_park(&h->io, &p->in, false);
    }
    if (p->foreign.parked && rt_limit_ready(&p->foreign_lim, h->now) <= h->now)
        rt_io_park(&h->io, &p->foreign, false);
}

/* One pass over the plants at h->now: the due and the marked processed, the looks that
 * are over started, the stopped ended. */
static void host_pass(host *h)
{
    for (int i = 0; i < h->n;) {
        plant *p = h->p[i];
        if (p->phase == PLANT_LOOKING && !rt_plant_stopped(p->s) && h->now >= p->look_end)
            plant_start(h, p);
        else if (p->phase == PLANT_RUNNING && (p->marked || p->wake <= h->now ||
                                               rt_plant_stopped(p->s))) {
            rt_plant_set_now(p->s, h->now);
            rt_process(p->s); /* once more when stopped: the answers owed, as before */
            p->marked = false;
            p->wake = rt_next_wake(p->s);
        } else if (p->phase == PLANT_LOOKING) {
            /* what came during the look was read (its own DESCRIBE comes back to it): a
             * looking plant has nothing due before its look's end, so no mark is kept */
            p->marked = false;
        }
        if (p->phase == PLANT_RUNNING) unpark(h, p);
        if (rt_plant_stopped(p->s)) {
            plant_end(h, i, RT_STOP_NONE);
            continue;
        }
        if (h->dir_out && p->phase == PLANT_RUNNING && h->now >= p->announce_ns) announce(h, p);
        i++;
    }
}

/* The earliest thing due: a plant's wake, a look's end, a parked plant's budget, the
 * reading of the directory. */
static int64_t host_next_wake(const host *h)
{
    int64_t wake = h->rescan_at;
    for (int i = 0; i < h->n; i++) {
        const plant *p = h->p[i];
        if (rt_plant_stopped(p->s) || p->marked) return h->now;
        wake = min64(wake, p->phase == PLANT_LOOKING ? p->look_end : p->wake);
        if (p->in.parked) wake = min64(wake, budget_ready(p));
        if (p->foreign.parked) wake = min64(wake, rt_limit_ready(&p->foreign_lim, h->now));
        if (h->dir_out && p->phase == PLANT_RUNNING) wake = min64(wake, p->announce_ns);
    }
    return wake;
}

/* ---------------------------------------------------------------- signals */
static void on_signal(void *ctx, int signo)
{
    host *h = ctx;
    if (signo == SIGHUP && !h->one) { /* a host reads its files again, and tries again */
        h->rescan_at = h->now;       /* those that failed (a port taken meanwhile ...) */
        h->retry = true;
        return;
    }
    bool stops = signo != SIGUSR1 && signo != SIGUSR2;
    if (stops) h->stopping = true;
    for (int i = 0; i < h->n; i++) {
        plant *p = h->p[i];
        rt_plant_set_now(p->s, h->now);
        if (p->phase == PLANT_RUNNING) rt_signal(p->s, signo);
        else if (stops) rt_plant_stop(p->s, RT_STOP_SIGNAL); /* looking: ends unstarted */
        p->marked = true;
    }
}

/* ---------------------------------------------------------------- the directory */
/* inotify said something: the directory is read again after a quiet HOST_RESCAN_NS. */
static void on_notify(void *ctx)
{
    host *h = ctx;
    char buf[4096] __attribute__((aligned(__alignof__(struct inotify_event))));
    while (read(h->notify_fd, buf, sizeof buf) > 0) {}
    h->rescan_at = rt_sat_add(h->now, HOST_RESCAN_NS);
}

/* Whether a name of DIR is a plant's file: NAME.yaml, NAME not empty and not hidden. */
static bool plant_file(const char *dir, const char *fname, char *name, size_t cap)
{
    size_t n = strlen(fname);
    if (n <= 5 || fname[0] == '.' || strcmp(fname + n - 5, ".yaml") || n - 5 >= cap) return false;
    char path[PATH_MAX];
    struct stat st;
    if (snprintf(path, sizeof path, "%s/%s", dir, fname) >= (int)sizeof path ||
        stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return false;
    memcpy(name, fname, n - 5);
    name[n - 5] = '\0';
    return true;
}

/* A file that failed: remembered with its bytes' hash (one message per version). Returns
 * true when it was remembered already (nothing to say again), never in a reading SIGHUP
 * asked for (it is tried again). */
static bool failed_seen(host *h, const char *name, uint64_t hv, bool remember)
{
    for (int i = 0; i < h->nfail; i++)
        if (!strcmp(h->fail[i].name, name)) {
            bool seen = h->fail[i].hash == hv && !h->retry;
            if (remember) h->fail[i].hash = hv;
            return seen;
        }
    size_t n = strlen(name);
    if (remember && h->nfail < HOST_MAX_PLANTS && n < sizeof h->fail[0].name) {
        memcpy(h->fail[h->nfail].name, name, n + 1); /* a longer name is not remembered */
        h->fail[h->nfail++].hash = hv;
    }
    return false;
}

/* The bytes of a file, for comparing with a plant's (NULL: unreadable or gone). */
static char *file_bytes(const char *path, size_t *len)
{
    char *text = NULL, err[512];
    if (lag_scene_read(path, &text, len, err, sizeof err) != LAG_OK) return NULL;
    return text;
}

static bool failed_has(const host *h, const char *name)
{
    for (int i = 0; i < h->nfail; i++)
        if (!strcmp(h->fail[i].name, name)) return true;
    return false;
}

static void failed_forget(host *h, const char *name)
{
    for (int i = 0; i < h->nfail; i++)
        if (!strcmp(h->fail[i].name, name)) h->fail[i] = h->fail[--h->nfail];
}

/* A new plant from a file (name: DIR's NAME, NULL for a --config); a failure said once
 * for each version of the file. */
static void plant_add(host *h, const char *path, const char *name, int keep)
{
    size_t len = 0;
    char *text = file_bytes(path, &len);
    uint64_t hv = text ? hash_bytes(text, len) : 0;
    free(text);
    const char *key = name ? name : path;
    if (failed_seen(h, key, hv, false)) return;
    plant *p = plant_from_file(h, path, name, keep);
    if (!p || plant_open(h, p) != 0) {
        failed_seen(h, key, hv, true);
        h->skipped++;
        fprintf(stderr, "lagsimd: %s: skipped (the reason is above); the other plants run; "
                "it is tried again %son SIGHUP\n", path, name ? "when it changes and " : "");
        return;
    }
    failed_forget(h, key);
}

/* Plant *i's file read again: gone, the plant stops; changed, the plant stops and starts
 * again from the new bytes on its port pair; a new version that fails to load is said,
 * and the plant runs on. *i moves past the plant (or stays, when it ended). */
static void rescan_plant(host *h, int *i)
{
    plant *p = h->p[*i];
    size_t len = 0;
    char *text = file_bytes(p->file, &len);
    if (!text) {
        say(p, "removed: its plant stops");
        plant_end(h, *i, RT_STOP_REMOVED);
        return;
    }
    bool same = len == p->len && !memcmp(text, p->text, len);
    uint64_t hv = hash_bytes(text, len);
    free(text);
    const char *key = p->from_dir ? p->name : p->file;
    (*i)++;
    if (same || failed_seen(h, key, hv, false)) return;
    plant *q = plant_from_file(h, p->file, p->from_dir ? p->name : NULL,
                               p->port_from_base ? p->port : 0);
    if (!q) {
        failed_seen(h, key, hv, true);
        fprintf(stderr, "lagsimd: %s: changed, but its new scene cannot run (what is above): "
                "plant %s runs on with the scene before\n", p->file, p->sc.lcm.prefix);
        return;
    }
    say(p, "changed: its plant starts again from it");
    plant_end(h, --(*i), RT_STOP_CHANGED);
    if (plant_open(h, q) != 0) failed_seen(h, key, hv, true);
    else failed_forget(h, key);
}

/* DIR's files that are no plant yet: new ones, and those that failed. */
static void rescan_dir(host *h)
{
    struct dirent **list = NULL;
    int n = scandir(h->c->dir, &list, NULL, alphasort);
    if (n < 0) {
        fprintf(stderr, "lagsimd: --plants %s: %s\n", h->c->dir, strerror(errno));
        return;
    }
    for (int k = 0; k < n; k++) {
        char name[NAME_MAX + 1], path[PATH_MAX];
        if (plant_file(h->c->dir, list[k]->d_name, name, sizeof name) && !plant_named(h, name) &&
            snprintf(path, sizeof path, "%s/%s", h->c->dir, list[k]->d_name) < (int)sizeof path)
            plant_add(h, path, name, 0);
        free(list[k]);
    }
    free(list);
}

/* Every plant's file read again, then the --config files that failed (not watched: on
 * SIGHUP), then DIR's new files. */
static void host_rescan(host *h)
{
    h->rescan_at = INT64_MAX;
    if (!h->stopping) {
        for (int i = 0; i < h->n;) rescan_plant(h, &i);
        for (int i = 0; i < h->c->nconfigs; i++)
            if (failed_has(h, h->c->configs[i])) plant_add(h, h->c->configs[i], NULL, 0);
        if (h->c->dir) rescan_dir(h);
    }
    h->retry = false;
}

/* ---------------------------------------------------------------- the loop */
/* Whether the loop is over: no plant left, and none can come (a daemon of one plant, a
 * stop signal, --duration, or no directory to watch). */
static bool host_done(const host *h)
{
    return h->n == 0 && (h->one || h->stopping || !h->c->dir || h->c->opts.duration > 0);
}

static void host_loop(host *h)
{
    while (!host_done(h)) {
        if (rt_io_wait(&h->io, host_next_wake(h)) != 0) {
            for (int i = 0; i < h->n; i++) rt_plant_stop(h->p[i]->s, RT_STOP_ERROR);
            h->stopping = true;
            if (h->rc == LAG_OK) h->rc = LAGSIMD_EXIT_RUNTIME;
        }
        host_pass(h);
        if (h->now >= h->rescan_at) host_rescan(h);
    }
}

/* inotify on DIR: a file written, moved in or out, removed. 0, or -1 (said). */
static int watch_dir(host *h)
{
    h->notify_fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (h->notify_fd < 0 ||
        inotify_add_watch(h->notify_fd, h->c->dir, IN_CLOSE_WRITE | IN_MOVED_TO | IN_MOVED_FROM |
                          IN_DELETE | IN_ATTRIB) < 0) {
        fprintf(stderr, "lagsimd: --plants %s: cannot watch it (inotify): %s; SIGHUP reads it "
                "again\n", h->c->dir, strerror(errno));
        return -1;
    }
    h->notify = (rt_io_src){h->notify_fd, on_notify, h, false, false};
    return rt_io_add(&h->io, &h->notify);
}

static host *host_new(const host_conf *c, bool one)
{
    host *h = calloc(1, sizeof *h);
    if (!h) {
        fputs("lagsimd: out of memory\n", stderr);
        return NULL;
    }
    h->c = c;
    h->one = one;
    h->notify_fd = -1;
    h->rescan_at = INT64_MAX;
    h->rc = LAG_OK;
    return h;
}

/* Ends every plant still there (a failed start), closes the wait; the host's result. */
static lag_result host_close(host *h)
{
    while (h->n > 0) plant_end(h, h->n - 1, RT_STOP_ERROR);
    dir_close(h);
    rt_io_close(&h->io);
    if (h->notify_fd >= 0) close(h->notify_fd);
    lag_result rc = h->rc;
    if (!h->one && rc == LAG_OK && h->started == 0 && !h->stopping) rc = LAGSIMD_EXIT_USAGE;
    free(h);
    return rc;
}

lag_result lagsimd_host(const host_conf *c)
{
    host *h = host_new(c, false);
    if (!h) return LAG_ERR_NOMEM;
    if (rt_io_open(&h->io, &h->now, on_signal, h) != 0) {
        h->rc = LAGSIMD_EXIT_RUNTIME;
        return host_close(h);
    }
    h->now = lag_clock_mono_ns();
    lag_net_note_inherited(); /* before any LCM instance of the host's: a parent's sockets */
    if (c->dir || c->port_base) dir_open(h);
    /* --plants without --port-base: the pairs after the directory's */
    h->port_base = c->port_base ? c->port_base : c->dir && h->dir_in ? h->dir.state_port + 2 : 0;
    if (c->dir) watch_dir(h); /* else said: SIGHUP reads it again */
    for (int i = 0; i < c->nconfigs; i++) plant_add(h, c->configs[i], NULL, 0);
    host_rescan(h); /* DIR's files, in the order of their names */
    if (!c->opts.quiet)
        fprintf(stderr, "lagsimd: %d plant%s starting%s%s; %d skipped\n", h->n,
                h->n == 1 ? "" : "s", c->dir ? " from " : "", c->dir ? c->dir : "", h->skipped);
    host_loop(h);
    return host_close(h);
}

lag_result lagsimd_realtime(const lag_scene *sc, const lagsimd_opts *o)
{
    host_conf c = {.opts = *o};
    host *h = host_new(&c, true);
    plant *p = h ? calloc(1, sizeof *p) : NULL;
    if (!p) {
        if (h) free(h);
        return LAG_ERR_NOMEM;
    }
    p->h = h;
    p->sc = *sc;
    snprintf(p->file, sizeof p->file, "%s", o->scene_name ? o->scene_name : "");
    snprintf(p->name, sizeof p->name, "%s", sc->lcm.prefix);
    if (rt_io_open(&h->io, &h->now, on_signal, h) != 0) {
        plant_free(p);
        h->rc = LAGSIMD_EXIT_RUNTIME;
        return host_close(h);
    }
    h->now = lag_clock_mono_ns();
    if (plant_open(h, p) == 0) host_loop(h);
    return host_close(h);
}
