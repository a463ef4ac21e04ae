/*
 * The bridge's HTTP side, on libmicrohttpd driven from the bridge's own poll loop
 * (external epoll mode, one thread).
 *
 *   GET  /, /view.js, /view.css   the page (embedded in the binary; nothing fetched
 *                                 from elsewhere: the Content-Security-Policy says so)
 *   GET  /api/state               the snapshot as JSON
 *   GET  /api/history?of=state|energy[&from=SEQ]   the newest states or energies, in
 *                                 pieces of at most 64 kB (a page opened mid-run)
 *   GET  /events                  server-sent events: "scene", "state", "status",
 *                                 "events" (an array), "bridge" frames
 *   POST /api/control?request=pause|resume|step|reset[&count=N]   (header X-Lagsim: 1)
 *   POST /api/kick?joint=J&impulse=I[&duration=S]                  (header X-Lagsim: 1)
 *
 * Bounds: libmicrohttpd caps connections (all, and an eighth of them per address), the
 * memory of one request (headers), and idle time (5 s); the bridge adds deadlines
 * (headers complete within 3 s, a request that is not a stream done within 30 s), so a
 * slowloris from one address holds at most its share, and each of those for 3 s. A
 * stream owns one VIEW_STREAM_BUF buffer; when it has sent its frame it builds the next
 * one from the newest snapshot (view_frame), at most `hz` times a second, or, when there
 * is nothing new or it is too early, suspends itself: the loop resumes it when it is
 * behind the snapshot and due (and every few seconds for a keep-alive comment, which is
 * also how a vanished client is found out). A client that stops reading keeps its one
 * frame and a 32 kB socket send buffer, no more, until its TCP has acknowledged nothing
 * for 20 s while bytes wait for it (check_connections): then it is dropped.
 *
 * Requests from other web pages: the Host header must be one and name the bridge (an
 * allow-list from --listen and --allow-host: a rebound DNS name is not on it); a control
 * request needs the X-Lagsim header, which a page of another origin cannot send without a
 * preflight the bridge never grants.
 */
#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <ifaddrs.h>
#include <linux/sockios.h>
#include <linux/tcp.h> /* struct tcp_info with tcpi_bytes_acked */
#include <microhttpd.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include "view.h"

#define VIEW_KEEPALIVE_NS 5000000000LL   /* a comment on an idle stream */
#define VIEW_IDLE_TIMEOUT_S 5            /* libmicrohttpd closes connections idle this long */
#define VIEW_STREAM_TIMEOUT_S 20         /* a stream whose client takes no byte this long */
#define VIEW_HEADER_DEADLINE_S 3         /* a request's headers complete within this */
#define VIEW_REQUEST_DEADLINE_S 30       /* ... and a request that is not a stream, whole */
#define VIEW_STREAM_SNDBUF 32768         /* a stream's socket send buffer (the kernel doubles it) */
#define VIEW_CHECK_NS 250000000LL        /* deadlines and stalls looked at this often */
#define VIEW_REQUEST_MEMORY (16 * 1024)  /* one request's headers and buffers */
#define VIEW_STATE_JSON (64 * 1024)
#define VIEW_STOP_NS 1000000000LL        /* streams get this long to end when the view stops */

/* Every connection, from accept to close (libmicrohttpd's connection notifications): what
 * it waits for and until when. */
typedef struct conn {
    struct conn *prev, *next;
    int fd;
    int64_t deadline_ns;     /* closed if not done by then (0: none, a stream) */
    struct stream *stream;
    bool dropped;
} conn;

typedef struct stream {
    struct view_http *h;
    struct MHD_Connection *conn;
    struct conn *rec;
    uint64_t acked;          /* bytes the client's TCP has acknowledged */
    int64_t progress_ns;     /* when that last grew, or nothing was waiting for it */
    struct stream *prev, *next;
    bool suspended;
    int64_t next_frame_ns;   /* not before */
    int64_t last_write_ns;
    view_cursor cur;         /* what it has been sent */
    size_t len, off;
    char buf[VIEW_STREAM_BUF];
} stream;

struct view_http {
    view_bridge *vb;
    view_http_opts o;
    struct MHD_Daemon *d;
    unsigned port;
    int64_t frame_ns;
    stream *streams;         /* every open stream, suspended or not */
    unsigned n_streams;
    int64_t last_wake_ns;
    conn *conns;             /* every open connection */
    int64_t last_check_ns;
    int64_t n_header_timeouts, n_stalled, n_frames_cut, n_bad_host;
    bool stopping;           /* streams end instead of waiting: the view stops */
    /* Host header names accepted (lower case; IPv6 in brackets), the port apart */
    char hosts[VIEW_HOSTS_MAX][VIEW_HOST_LEN];
    int n_hosts;
    char json[VIEW_STATE_JSON];
};

/* ---------------------------------------------------------------- responses */
static enum MHD_Result reply(struct MHD_Connection *c, unsigned code, const char *type,
                             const void *data, size_t len, enum MHD_ResponseMemoryMode mode)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, (void *)(uintptr_t)data, mode);
    if (!r) return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(r, "Content-Security-Policy",
                            "default-src 'self'; img-src 'self' data:; base-uri 'none'; "
                            "frame-ancestors 'none'; form-action 'none'");
    enum MHD_Result ok = MHD_queue_response(c, code, r);
    MHD_destroy_response(r);
    return ok;
}

static enum MHD_Result reply_text(struct MHD_Connection *c, unsigned code, const char *msg)
{
    return reply(c, code, "text/plain; charset=utf-8", msg, strlen(msg), MHD_RESPMEM_MUST_COPY);
}

static enum MHD_Result reply_json_msg(struct MHD_Connection *c, unsigned code, bool ok,
                                      const char *msg)
{
    char out[512];
    jbuf b;
    jb_init(&b, out, sizeof out);
    jb_raw(&b, ok ? "{\"ok\":true,\"message\":" : "{\"ok\":false,\"message\":");
    jb_str(&b, msg);
    jb_raw(&b, "}\n");
    return reply(c, code, "application/json", out, b.len, MHD_RESPMEM_MUST_COPY);
}

/* ---------------------------------------------------------------- streams */
static void stream_unlink(view_http *h, stream *s)
{
    if (s->prev) s->prev->next = s->next;
    else h->streams = s->next;
    if (s->next) s->next->prev = s->prev;
    h->n_streams--;
}

/* A part that did not fit: it waits for the next frame, unless it was alone in this one
 * (it never fits, which the budgets rule out): then it is replaced by {"truncated":true}
 * and counted, so that the stream goes on. */
static void part_too_big(int64_t *cut, jbuf *b, size_t keep, const char *name, int64_t *seq,
                         int64_t now_seq)
{
    b->len = keep;
    b->overflow = false;
    if (keep != 0) return;
    jb_fmt(b, "event: %s\ndata: {\"truncated\":true}\n\n", name);
    *seq = now_seq;
    (*cut)++;
}

size_t view_frame(const view_bridge *vb, unsigned hz, view_cursor *s, char *buf, size_t cap,
                  int64_t *cut)
{
    jbuf b;
    jb_init(&b, buf, cap);
    size_t keep;
    if (!s->hello_sent) {
        jb_fmt(&b, "retry: 1000\nevent: bridge\ndata: {\"prefix\":");
        jb_str(&b, vb->prefix);
        jb_fmt(&b, ",\"hz\":%u}\n\n", hz);
        s->hello_sent = true;
    }
    /* each part whole or not at all: a part that does not fit waits for the next frame */
    if (s->scene_seq != vb->scene_seq && vb->scene_seq) {
        keep = b.len;
        jb_raw(&b, "event: scene\ndata: ");
        view_json_scene(&b, &vb->scene);
        jb_raw(&b, "\n\n");
        if (b.overflow) part_too_big(cut, &b, keep, "scene", &s->scene_seq, vb->scene_seq);
        else s->scene_seq = vb->scene_seq;
    }
    if (s->state_seq != vb->state_seq) {
        keep = b.len;
        jb_raw(&b, "event: state\ndata: ");
        view_json_state(&b, &vb->state, &vb->state_ref);
        jb_raw(&b, "\n\n");
        if (b.overflow) part_too_big(cut, &b, keep, "state", &s->state_seq, vb->state_seq);
        else s->state_seq = vb->state_seq;
    }
    if (s->status_seq != vb->status_seq) {
        keep = b.len;
        jb_raw(&b, "event: status\ndata: ");
        view_json_status(&b, &vb->status);
        jb_raw(&b, "\n\n");
        if (b.overflow) part_too_big(cut, &b, keep, "status", &s->status_seq, vb->status_seq);
        else s->status_seq = vb->status_seq;
    }
    if (s->event_seq != vb->event_seq) {
        /* the ring keeps VIEW_EVENTS: older ones are gone, and the page is told */
        int64_t first = s->event_seq + 1, missed = 0;
        if (first < vb->event_seq - VIEW_EVENTS + 1) {
            missed = vb->event_seq - VIEW_EVENTS + 1 - first;
            first = vb->event_seq - VIEW_EVENTS + 1;
        }
        int64_t last = vb->event_seq, sent;
        if (last - first + 1 > VIEW_EVENTS_PER_FRAME) last = first + VIEW_EVENTS_PER_FRAME - 1;
        /* as many as fit, oldest first: the rest go in the next frame, so a frame of big
         * events is cut, never stuck (one event always fits: VIEW_JSON_*_MAX) */
        keep = b.len;
        jb_fmt(&b, "event: events\ndata: {\"missed\":%lld,\"events\":[", (long long)missed);
        size_t n = view_json_events(&b, vb, first, last, 8, &sent);
        jb_raw(&b, "]}\n\n");
        if (b.overflow || n == 0) b.len = keep, b.overflow = false;
        else s->event_seq = sent;
        if (n == 0 && keep == 0) {
            /* alone in a frame and still too big (cannot happen with the budgets): said,
             * and skipped, so that the stream goes on */
            jb_fmt(&b, "event: events\ndata: {\"missed\":%lld,\"events\":[]}\n\n",
                   (long long)(missed + 1));
            s->event_seq = first;
            (*cut)++;
        }
    }
    return b.overflow ? 0 : b.len;
}

/* libmicrohttpd asks for the next bytes of a stream. */
static ssize_t stream_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    stream *s = cls;
    view_http *h = s->h;
    int64_t now = lag_clock_mono_ns();
    if (s->off >= s->len) {
        s->len = s->off = 0;
        /* the view stops: the stream ends (its last chunk) rather than waits */
        if (h->stopping) return MHD_CONTENT_READER_END_OF_STREAM;
        if (now >= s->next_frame_ns) {
            s->len = view_frame(h->vb, h->o.hz, &s->cur, s->buf, sizeof s->buf, &h->n_frames_cut);
            if (s->len == 0 && now - s->last_write_ns >= VIEW_KEEPALIVE_NS) {
                memcpy(s->buf, ": keep-alive\n\n", 15);
                s->len = 15;
            }
            if (s->len) s->next_frame_ns = now + h->frame_ns;
        }
        if (s->len == 0) {
            /* nothing now: sleep until the loop wakes the stream */
            MHD_suspend_connection(s->conn);
            s->suspended = true;
            return 0;
        }
    }
    size_t n = s->len - s->off < max ? s->len - s->off : max;
    memcpy(buf, s->buf + s->off, n);
    s->off += n;
    s->last_write_ns = now;
    return (ssize_t)n;
}

/* The stream's response is gone (client closed, error, bridge stopping). */
static void stream_free(void *cls)
{
    stream *s = cls;
    stream_unlink(s->h, s);
    if (s->rec) s->rec->stream = NULL;
    free(s);
}

static enum MHD_Result open_stream(view_http *h, struct MHD_Connection *c, conn *rec)
{
    if (h->stopping) return reply_text(c, 503, "the view is stopping\n");
    if (h->n_streams >= h->o.max_streams)
        return reply_text(c, 503, "too many open views (see lagsim-view --max-views)\n");
    stream *s = calloc(1, sizeof *s);
    if (!s) return reply_text(c, 503, "out of memory\n");
    s->h = h;
    s->conn = c;
    s->last_write_ns = s->progress_ns = lag_clock_mono_ns();
    struct MHD_Response *r =
        MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 16384, stream_read, s, stream_free);
    if (!r) {
        free(s);
        return MHD_NO;
    }
    s->next = h->streams;
    if (h->streams) h->streams->prev = s;
    h->streams = s;
    h->n_streams++;
    /* the stall is judged by what the client takes (stall_check), libmicrohttpd's idle
     * timeout stays as a backstop; a small send buffer keeps the kernel from queueing
     * megabytes for a client that does not read */
    MHD_set_connection_option(c, MHD_CONNECTION_OPTION_TIMEOUT, (unsigned)VIEW_STREAM_TIMEOUT_S);
    if (rec) {
        rec->stream = s;
        rec->deadline_ns = 0;
        s->rec = rec;
        int sndbuf = VIEW_STREAM_SNDBUF;
        setsockopt(rec->fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
    }
    MHD_add_response_header(r, "Content-Type", "text/event-stream");
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    enum MHD_Result ok = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r); /* stream_free runs when the connection lets go of it */
    return ok;
}

/* ---------------------------------------------------------------- requests */
/* Host: NAME[:PORT]. Accepted when NAME is on the allow-list (any case, one final dot
 * ignored) and PORT is the bridge's (absent: 80). */
bool view_host_ok(const view_http *h, const char *host)
{
    if (!host) return false;
    size_t n = strlen(host), name_len;
    const char *port = NULL;
    if (host[0] == '[') {
        const char *e = memchr(host, ']', n);
        if (!e) return false;
        name_len = (size_t)(e - host) + 1;
        if (e[1] == ':') port = e + 2;
        else if (e[1] != '\0') return false;
    } else {
        const char *colon = memchr(host, ':', n);
        name_len = colon ? (size_t)(colon - host) : n;
        if (colon) port = colon + 1;
    }
    if (name_len > 1 && host[name_len - 1] == '.') name_len--;
    if (name_len == 0 || name_len >= VIEW_HOST_LEN) return false;
    unsigned p = 80;
    if (port) {
        if (!*port || strlen(port) > 5) return false;
        p = 0;
        for (const char *c = port; *c; c++) {
            if (*c < '0' || *c > '9') return false;
            p = p * 10 + (unsigned)(*c - '0');
        }
    }
    if (p != h->port) return false;
    for (int i = 0; i < h->n_hosts; i++)
        if (strlen(h->hosts[i]) == name_len && strncasecmp(host, h->hosts[i], name_len) == 0)
            return true;
    return false;
}

static enum MHD_Result count_host(void *cls, enum MHD_ValueKind kind, const char *key,
                                  const char *value)
{
    (void)kind;
    (void)value;
    if (strcasecmp(key, "Host") == 0) ++*(int *)cls;
    return MHD_YES;
}

/* 0: fine; else the status to answer (400: no or several Host headers, 421: not ours) */
static unsigned host_check(view_http *h, struct MHD_Connection *c)
{
    int n = 0;
    MHD_get_connection_values(c, MHD_HEADER_KIND, count_host, &n);
    if (n > 1) return 400;
    if (!view_host_ok(h, MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host"))) return 421;
    return 0;
}

static conn *conn_of(struct MHD_Connection *c)
{
    const union MHD_ConnectionInfo *i =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    return i ? i->socket_context : NULL;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url,
                                  const char *method, const char *version,
                                  const char *upload_data, size_t *upload_data_size,
                                  void **con_cls)
{
    (void)version;
    (void)upload_data;
    view_http *h = cls;
    /* a body is never needed: whatever comes is dropped unread (the answer is queued
     * on the first call, and libmicrohttpd closes the connection after it) */
    if (*con_cls == NULL) {
        *con_cls = (void *)1;
    } else {
        *upload_data_size = 0;
        return MHD_YES;
    }
    conn *rec = conn_of(c);
    /* the headers are in: a request that is not a stream has VIEW_REQUEST_DEADLINE_S */
    if (rec) rec->deadline_ns = lag_clock_mono_ns() + VIEW_REQUEST_DEADLINE_S * 1000000000LL;
    unsigned bad = host_check(h, c);
    if (bad) {
        h->n_bad_host++;
        return reply_text(c, bad, bad == 400 ? "one Host header, please\n"
                                             : "unexpected Host header (see lagsim-view --allow-host)\n");
    }
    bool get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    bool post = strcmp(method, "POST") == 0;

    if (strcmp(url, "/api/control") == 0) {
        if (!post) return reply_json_msg(c, 405, false, "POST only");
        const char *tag = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Lagsim");
        if (!tag || strcmp(tag, "1") != 0)
            return reply_json_msg(c, 403, false, "control requests need the header X-Lagsim: 1");
        const char *why = "";
        int code = view_bridge_control(
            h->vb, MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "request"),
            MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "count"), &why);
        return reply_json_msg(c, code ? (unsigned)code : 202, code == 0, why);
    }
    if (strcmp(url, "/api/kick") == 0) { /* a kick: a control request of its own */
        if (!post) return reply_json_msg(c, 405, false, "POST only");
        const char *tag = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Lagsim");
        if (!tag || strcmp(tag, "1") != 0)
            return reply_json_msg(c, 403, false, "control requests need the header X-Lagsim: 1");
        const char *why = "";
        int code = view_bridge_kick(
            h->vb, MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "joint"),
            MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "impulse"),
            MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "duration"), &why);
        return reply_json_msg(c, code ? (unsigned)code : 202, code == 0, why);
    }
    if (!get) return reply_text(c, 405, "GET only\n");
    if (strcmp(url, "/events") == 0) return open_stream(h, c, rec);
    if (strcmp(url, "/api/history") == 0) {
        size_t n = view_json_history(h->vb, MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "of"),
                                     MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "from"),
                                     h->json, sizeof h->json);
        if (n == 0) return reply_text(c, 400, "history: of=state|energy[&from=SEQ >= 0]\n");
        return reply(c, 200, "application/json", h->json, n, MHD_RESPMEM_MUST_COPY);
    }
    if (strcmp(url, "/api/state") == 0) {
        size_t n = view_json_snapshot(h->vb, h, h->json, sizeof h->json);
        if (n == 0) return reply_text(c, 500, "state too large\n"); /* the budgets rule it out */
        return reply(c, 200, "application/json", h->json, n, MHD_RESPMEM_MUST_COPY);
    }
    for (size_t i = 0; i < view_asset_count; i++)
        if (strcmp(url, view_assets[i].path) == 0)
            return reply(c, 200, view_assets[i].type, view_assets[i].data, view_assets[i].size,
                         MHD_RESPMEM_PERSISTENT);
    return reply_text(c, 404, "not found\n");
}

/* ---------------------------------------------------------------- connections */
static void on_connection(void *cls, struct MHD_Connection *c, void **socket_context,
                          enum MHD_ConnectionNotificationCode code)
{
    view_http *h = cls;
    if (code == MHD_CONNECTION_NOTIFY_STARTED) {
        conn *r = calloc(1, sizeof *r);
        const union MHD_ConnectionInfo *i =
            MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
        if (!r || !i) { /* no record: no deadline; closed now rather than unguarded */
            free(r);
            if (i) shutdown(i->connect_fd, SHUT_RDWR);
            *socket_context = NULL;
            return;
        }
        r->fd = i->connect_fd;
        r->deadline_ns = lag_clock_mono_ns() + VIEW_HEADER_DEADLINE_S * 1000000000LL;
        r->next = h->conns;
        if (h->conns) h->conns->prev = r;
        h->conns = r;
        *socket_context = r;
    } else if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
        conn *r = *socket_context;
        if (!r) return;
        if (r->prev) r->prev->next = r->next;
        else h->conns = r->next;
        if (r->next) r->next->prev = r->prev;
        if (r->stream) r->stream->rec = NULL;
        free(r);
        *socket_context = NULL;
    }
}

/* A request answered on a connection kept alive: the next one's headers are due again
 * within VIEW_HEADER_DEADLINE_S. */
static void on_completed(void *cls, struct MHD_Connection *c, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    (void)cls;
    (void)con_cls;
    (void)toe;
    conn *r = conn_of(c);
    if (r && !r->stream) r->deadline_ns = lag_clock_mono_ns() + VIEW_HEADER_DEADLINE_S * 1000000000LL;
}

/* Ends a connection from outside libmicrohttpd's callbacks: the socket is shut down, the
 * loop sees it hang up and libmicrohttpd closes it (and frees its stream). */
static void drop(conn *r)
{
    if (r->dropped) return;
    r->dropped = true;
    shutdown(r->fd, SHUT_RDWR);
    if (r->stream && r->stream->suspended) {
        r->stream->suspended = false;
        MHD_resume_connection(r->stream->conn);
    }
}

/* Deadlines (headers, whole requests) and stalled streams. A stream is stalled when bytes
 * wait in its socket (SIOCOUTQ: sent or not, not yet acknowledged) and its client's TCP
 * has acknowledged nothing new (tcpi_bytes_acked) for VIEW_STREAM_TIMEOUT_S: what the
 * client has taken, not what the kernel accepted from the bridge. */
static void check_connections(view_http *h, int64_t now)
{
    for (conn *r = h->conns; r; r = r->next) {
        if (r->dropped) continue;
        if (r->deadline_ns && now >= r->deadline_ns) {
            h->n_header_timeouts++;
            drop(r);
            continue;
        }
        stream *s = r->stream;
        if (!s) continue;
        int outq = 0;
        struct tcp_info ti;
        socklen_t tl = sizeof ti;
        memset(&ti, 0, sizeof ti);
        if (ioctl(r->fd, SIOCOUTQ, &outq) != 0 ||
            getsockopt(r->fd, IPPROTO_TCP, TCP_INFO, &ti, &tl) != 0) {
            drop(r); /* not a TCP socket any more: gone */
            continue;
        }
        if (outq == 0 || ti.tcpi_bytes_acked != s->acked) {
            s->acked = ti.tcpi_bytes_acked;
            s->progress_ns = now;
        } else if (now - s->progress_ns >= VIEW_STREAM_TIMEOUT_S * 1000000000LL) {
            h->n_stalled++;
            drop(r);
        }
    }
}

void view_http_counters(const view_http *h, jbuf *b)
{
    jb_key(b, "streams_dropped_stalled", false);
    jb_fmt(b, "%lld", (long long)h->n_stalled);
    jb_key(b, "connections_timed_out", false);
    jb_fmt(b, "%lld", (long long)h->n_header_timeouts);
    jb_key(b, "bad_host", false);
    jb_fmt(b, "%lld", (long long)h->n_bad_host);
    jb_key(b, "frames_cut", false);
    jb_fmt(b, "%lld", (long long)h->n_frames_cut);
}

/* libmicrohttpd's own complaints (bad requests, limits): one line on stderr, bounded by
 * its own rate of connections. */
static void on_log(void *cls, const char *fmt, va_list ap)
{
    (void)cls;
    (void)fmt;
    (void)ap; /* silent: hostile clients must not fill the terminal */
}

/* ---------------------------------------------------------------- Host allow-list */
static void host_add(view_http *h, const char *name)
{
    char v[VIEW_HOST_LEN];
    size_t n = strlen(name);
    if (n == 0 || n >= sizeof v) return;
    for (size_t i = 0; i <= n; i++) v[i] = (char)tolower((unsigned char)name[i]);
    if (n > 1 && v[n - 1] == '.') v[n - 1] = '\0';
    for (int i = 0; i < h->n_hosts; i++)
        if (strcmp(h->hosts[i], v) == 0) return;
    if (h->n_hosts < VIEW_HOSTS_MAX) snprintf(h->hosts[h->n_hosts++], VIEW_HOST_LEN, "%s", v);
}

static void host_add_addr(view_http *h, int family, const void *addr)
{
    char a[INET6_ADDRSTRLEN], v[INET6_ADDRSTRLEN + 2];
    if (!inet_ntop(family, addr, a, sizeof a)) return;
    if (family == AF_INET6) snprintf(v, sizeof v, "[%s]", a);
    else snprintf(v, sizeof v, "%s", a);
    host_add(h, v);
}

/* The names a browser may put in Host: the address listened on; on a loopback address
 * also localhost; on a wildcard address every address of this host's interfaces; off
 * loopback this host's name; and every --allow-host. A rebound DNS name is none of them. */
static void hosts_build(view_http *h, int family, const void *addr, bool wildcard, bool loopback)
{
    host_add_addr(h, family, addr); /* the address printed, 0.0.0.0 included */
    if (loopback || wildcard) host_add(h, "localhost");
    if (wildcard) {
        struct ifaddrs *ifa = NULL;
        if (getifaddrs(&ifa) == 0) {
            for (struct ifaddrs *i = ifa; i; i = i->ifa_next) {
                if (!i->ifa_addr) continue;
                if (i->ifa_addr->sa_family == AF_INET)
                    host_add_addr(h, AF_INET, &((struct sockaddr_in *)i->ifa_addr)->sin_addr);
                else if (i->ifa_addr->sa_family == AF_INET6 && family == AF_INET6)
                    host_add_addr(h, AF_INET6, &((struct sockaddr_in6 *)i->ifa_addr)->sin6_addr);
            }
            freeifaddrs(ifa);
        }
    }
    if (!loopback) {
        char name[256];
        if (gethostname(name, sizeof name - 1) == 0) {
            name[sizeof name - 1] = '\0';
            host_add(h, name);
        }
    }
    for (int i = 0; i < h->o.n_allow_hosts; i++) {
        const char *n = h->o.allow_hosts[i];
        char v6[VIEW_HOST_LEN];
        if (strchr(n, ':') && n[0] != '[' && strlen(n) + 2 < sizeof v6) { /* an IPv6 literal */
            snprintf(v6, sizeof v6, "[%s]", n);
            n = v6;
        }
        host_add(h, n);
    }
}

/* ---------------------------------------------------------------- lifecycle */
view_http *view_http_start(view_bridge *vb, const view_http_opts *o, char *err, size_t errlen)
{
    view_http *h = calloc(1, sizeof *h);
    if (!h) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    h->vb = vb;
    h->o = *o;
    if (h->o.hz < 1) h->o.hz = 1;
    h->frame_ns = 1000000000LL / h->o.hz;
    struct sockaddr_storage ss;
    memset(&ss, 0, sizeof ss);
    struct sockaddr_in *a4 = (struct sockaddr_in *)&ss;
    struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)&ss;
    unsigned flags = MHD_USE_EPOLL | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG;
    int family;
    const void *addr;
    bool wildcard, loopback;
    if (inet_pton(AF_INET, o->listen, &a4->sin_addr) == 1) {
        a4->sin_family = AF_INET;
        a4->sin_port = htons((uint16_t)o->port);
        family = AF_INET;
        addr = &a4->sin_addr;
        wildcard = a4->sin_addr.s_addr == htonl(INADDR_ANY);
        loopback = (ntohl(a4->sin_addr.s_addr) >> 24) == 127;
    } else if (inet_pton(AF_INET6, o->listen, &a6->sin6_addr) == 1) {
        a6->sin6_family = AF_INET6;
        a6->sin6_port = htons((uint16_t)o->port);
        flags |= MHD_USE_IPv6;
        family = AF_INET6;
        addr = &a6->sin6_addr;
        wildcard = IN6_IS_ADDR_UNSPECIFIED(&a6->sin6_addr);
        loopback = IN6_IS_ADDR_LOOPBACK(&a6->sin6_addr);
    } else {
        snprintf(err, errlen, "--listen '%s': a numeric IPv4 or IPv6 address", o->listen);
        free(h);
        return NULL;
    }
    /* one address holds at most an eighth of the connections (a slowloris from one
     * address leaves the rest to others), and never fewer than a browser's needs */
    unsigned per_address = o->max_connections / 8;
    if (per_address < 32) per_address = 32;
    h->d = MHD_start_daemon(flags, (uint16_t)o->port, NULL, NULL, on_request, h,
                            MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&ss,
                            MHD_OPTION_CONNECTION_LIMIT, (unsigned)o->max_connections,
                            MHD_OPTION_PER_IP_CONNECTION_LIMIT, per_address,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)VIEW_IDLE_TIMEOUT_S,
                            MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)VIEW_REQUEST_MEMORY,
                            MHD_OPTION_NOTIFY_CONNECTION, on_connection, h,
                            MHD_OPTION_NOTIFY_COMPLETED, on_completed, h,
                            MHD_OPTION_EXTERNAL_LOGGER, on_log, NULL,
                            MHD_OPTION_END);
    if (!h->d) {
        snprintf(err, errlen, "cannot listen on %s port %u: %s", o->listen, o->port,
                 errno ? strerror(errno) : "libmicrohttpd refused");
        free(h);
        return NULL;
    }
    const union MHD_DaemonInfo *pi = MHD_get_daemon_info(h->d, MHD_DAEMON_INFO_BIND_PORT);
    h->port = pi ? pi->port : o->port;
    hosts_build(h, family, addr, wildcard, loopback);
    return h;
}

unsigned view_http_port(const view_http *h) { return h->port; }

int view_http_fd(const view_http *h)
{
    const union MHD_DaemonInfo *i = MHD_get_daemon_info(h->d, MHD_DAEMON_INFO_EPOLL_FD);
    return i ? i->epoll_fd : -1;
}

unsigned view_http_streams(const view_http *h) { return h->n_streams; }

int view_http_timeout_ms(view_http *h)
{
    MHD_UNSIGNED_LONG_LONG t;
    if (MHD_get_timeout(h->d, &t) != MHD_YES) return -1;
    return t > 60000 ? 60000 : (int)t;
}

void view_http_run(view_http *h)
{
    view_bridge *vb = h->vb;
    int64_t now = lag_clock_mono_ns();
    /* wake a suspended stream when it is behind the snapshot (something changed, or a
     * backlog of events remains) and its next frame is due, and every VIEW_KEEPALIVE_NS
     * for a keep-alive */
    bool keepalive = now - h->last_wake_ns >= VIEW_KEEPALIVE_NS;
    if (keepalive) h->last_wake_ns = now;
    for (stream *s = h->streams; s; s = s->next) {
        if (!s->suspended) continue;
        bool behind = s->cur.state_seq != vb->state_seq || s->cur.status_seq != vb->status_seq ||
                      s->cur.scene_seq != vb->scene_seq || s->cur.event_seq != vb->event_seq;
        if (keepalive || (behind && now >= s->next_frame_ns)) {
            s->suspended = false;
            MHD_resume_connection(s->conn);
        }
    }
    if (now - h->last_check_ns >= VIEW_CHECK_NS) {
        h->last_check_ns = now;
        check_connections(h, now);
    }
    MHD_run(h->d);
}

/* Resumes every suspended stream: each then ends (h->stopping) instead of suspending
 * again. Returns how many were suspended. */
static unsigned resume_all(view_http *h)
{
    unsigned n = 0;
    for (stream *s = h->streams; s; s = s->next)
        if (s->suspended) {
            s->suspended = false;
            MHD_resume_connection(s->conn);
            n++;
        }
    return n;
}

/* libmicrohttpd aborts the process in MHD_stop_daemon while a connection is suspended, and
 * a resumed stream asked for its next bytes suspends itself again when there is nothing
 * new: so every stream is first made to end (its last chunk sent) and resumed, and the
 * loop runs until the streams are gone, or for VIEW_STOP_NS (a client that does not read
 * keeps its stream, never suspended: MHD_stop_daemon closes it). The MHD_run after the
 * last resume is what takes the resumed connections off libmicrohttpd's suspended list. */
void view_http_stop(view_http *h)
{
    if (!h) return;
    h->stopping = true;
    int64_t until = lag_clock_mono_ns() + VIEW_STOP_NS;
    do {
        resume_all(h);
        MHD_run(h->d);
        if (!h->streams) break;
        struct pollfd pf = {view_http_fd(h), POLLIN, 0};
        poll(&pf, 1, 10);
    } while (lag_clock_mono_ns() < until);
    /* none is suspended now (the MHD_run after a resume takes it off the list, and a
     * stream no longer suspends itself); made sure of, as MHD_stop_daemon would abort */
    if (resume_all(h)) MHD_run(h->d);
    MHD_stop_daemon(h->d); /* frees every stream left through stream_free */
    free(h);
}
