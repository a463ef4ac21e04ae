/*
 * The bridge's HTTP side, on libmicrohttpd driven from the bridge's own poll loop
 * (external epoll mode, one thread).
 *
 *   GET  /, /view.js, /view.css   the page (embedded in the binary; nothing fetched
 *                                 from elsewhere: the Content-Security-Policy says so)
 *   GET  /api/state               the snapshot as JSON
 *   GET  /events                  server-sent events: "scene", "state", "status",
 *                                 "events" (an array), "bridge" frames
 *   POST /api/control?request=pause|resume|step|reset[&count=N]   (header X-Lagsim: 1)
 *   POST /api/kick?joint=J&impulse=I[&duration=S]                  (header X-Lagsim: 1)
 *
 * Bounds: libmicrohttpd caps connections (all and per address), the memory of one
 * request (headers), and idle time (5 s; 20 s for a stream that accepts no bytes). A
 * flood that holds every connection slot (slowloris) delays new clients until its
 * connections close or idle out; it cannot make the bridge use more than the caps. A stream owns one VIEW_STREAM_BUF buffer; when it
 * has sent its frame it builds the next one from the newest snapshot, at most `hz` times
 * a second, or, when there is nothing new or it is too early, suspends itself: the loop
 * resumes it when the snapshot changes (and every few seconds for a keep-alive comment,
 * which is also how a vanished client is found out). A client that stops reading keeps
 * its one frame, no more, until the idle timeout closes it.
 *
 * Requests from other web pages: on loopback the Host header must name the bridge (a
 * rebound DNS name does not); a control request needs the X-Lagsim header, which a page
 * of another origin cannot send without a preflight the bridge never grants.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "view.h"

#define VIEW_KEEPALIVE_NS 5000000000LL   /* a comment on an idle stream */
#define VIEW_IDLE_TIMEOUT_S 5            /* libmicrohttpd closes connections idle this long */
#define VIEW_STREAM_TIMEOUT_S 20         /* ... and streams that accept no bytes this long */
#define VIEW_REQUEST_MEMORY (16 * 1024)  /* one request's headers and buffers */
#define VIEW_STATE_JSON (64 * 1024)

typedef struct stream {
    struct view_http *h;
    struct MHD_Connection *conn;
    struct stream *prev, *next;
    bool suspended;
    int64_t next_frame_ns;   /* not before */
    int64_t last_write_ns;
    int64_t state_seq, status_seq, scene_seq, event_seq; /* sent so far */
    bool hello_sent;
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
    int64_t woken_state, woken_status, woken_scene, woken_event;
    char host_ok[3][64];     /* accepted Host headers on loopback */
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

/* Builds the next frame from what is new since the last one. Returns its length (0:
 * nothing to send). */
static size_t build_frame(view_http *h, stream *s, int64_t now)
{
    view_bridge *vb = h->vb;
    jbuf b;
    jb_init(&b, s->buf, sizeof s->buf);
    size_t keep;
    if (!s->hello_sent) {
        jb_fmt(&b, "retry: 1000\nevent: bridge\ndata: {\"prefix\":");
        jb_str(&b, vb->prefix);
        jb_fmt(&b, ",\"hz\":%u}\n\n", h->o.hz);
        s->hello_sent = true;
    }
    /* each part whole or not at all: a part that does not fit waits for the next frame */
    if (s->scene_seq != vb->scene_seq && vb->scene_seq) {
        keep = b.len;
        jb_raw(&b, "event: scene\ndata: ");
        view_json_scene(&b, &vb->scene);
        jb_raw(&b, "\n\n");
        if (b.overflow) b.len = keep, b.overflow = false;
        else s->scene_seq = vb->scene_seq;
    }
    if (s->state_seq != vb->state_seq) {
        keep = b.len;
        jb_raw(&b, "event: state\ndata: ");
        view_json_state(&b, &vb->state);
        jb_raw(&b, "\n\n");
        if (b.overflow) b.len = keep, b.overflow = false;
        else s->state_seq = vb->state_seq;
    }
    if (s->status_seq != vb->status_seq) {
        keep = b.len;
        jb_raw(&b, "event: status\ndata: ");
        view_json_status(&b, &vb->status);
        jb_raw(&b, "\n\n");
        if (b.overflow) b.len = keep, b.overflow = false;
        else s->status_seq = vb->status_seq;
    }
    if (s->event_seq != vb->event_seq) {
        /* the ring keeps VIEW_EVENTS: older ones are gone, and the page is told */
        int64_t first = s->event_seq + 1, missed = 0;
        if (first < vb->event_seq - VIEW_EVENTS + 1) {
            missed = vb->event_seq - VIEW_EVENTS + 1 - first;
            first = vb->event_seq - VIEW_EVENTS + 1;
        }
        int64_t last = vb->event_seq;
        if (last - first + 1 > VIEW_EVENTS_PER_FRAME) last = first + VIEW_EVENTS_PER_FRAME - 1;
        keep = b.len;
        jb_fmt(&b, "event: events\ndata: {\"missed\":%lld,\"events\":[", (long long)missed);
        for (int64_t q = first; q <= last; q++) {
            if (q > first) jb_raw(&b, ",");
            view_json_event(&b, &vb->events[q % VIEW_EVENTS].ev, q);
        }
        jb_raw(&b, "]}\n\n");
        if (b.overflow) b.len = keep, b.overflow = false;
        else s->event_seq = last;
    }
    if (b.len == 0 && now - s->last_write_ns >= VIEW_KEEPALIVE_NS) jb_raw(&b, ": keep-alive\n\n");
    return b.len;
}

/* libmicrohttpd asks for the next bytes of a stream. */
static ssize_t stream_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    stream *s = cls;
    view_http *h = s->h;
    int64_t now = view_mono_ns();
    if (s->off >= s->len) {
        s->len = s->off = 0;
        if (now >= s->next_frame_ns) {
            s->len = build_frame(h, s, now);
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
    free(s);
}

static enum MHD_Result open_stream(view_http *h, struct MHD_Connection *c)
{
    if (h->n_streams >= h->o.max_streams)
        return reply_text(c, 503, "too many open views (see lagsim-view --max-views)\n");
    stream *s = calloc(1, sizeof *s);
    if (!s) return reply_text(c, 503, "out of memory\n");
    s->h = h;
    s->conn = c;
    s->last_write_ns = view_mono_ns();
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
    MHD_set_connection_option(c, MHD_CONNECTION_OPTION_TIMEOUT, (unsigned)VIEW_STREAM_TIMEOUT_S);
    MHD_add_response_header(r, "Content-Type", "text/event-stream");
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    enum MHD_Result ok = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r); /* stream_free runs when the connection lets go of it */
    return ok;
}

/* ---------------------------------------------------------------- requests */
static bool host_allowed(view_http *h, struct MHD_Connection *c)
{
    if (!h->o.check_host) return true;
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
    if (!host) return false;
    for (int i = 0; i < 3; i++)
        if (strcmp(host, h->host_ok[i]) == 0) return true;
    return false;
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
    if (!host_allowed(h, c)) return reply_text(c, 421, "unexpected Host header\n");
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
    if (strcmp(url, "/events") == 0) return open_stream(h, c);
    if (strcmp(url, "/api/state") == 0) {
        size_t n = view_json_snapshot(h->vb, h, h->json, sizeof h->json);
        if (n == 0) return reply_text(c, 500, "state too large\n");
        return reply(c, 200, "application/json", h->json, n, MHD_RESPMEM_MUST_COPY);
    }
    for (size_t i = 0; i < view_asset_count; i++)
        if (strcmp(url, view_assets[i].path) == 0)
            return reply(c, 200, view_assets[i].type, view_assets[i].data, view_assets[i].size,
                         MHD_RESPMEM_PERSISTENT);
    return reply_text(c, 404, "not found\n");
}

/* libmicrohttpd's own complaints (bad requests, limits): one line on stderr, bounded by
 * its own rate of connections. */
static void on_log(void *cls, const char *fmt, va_list ap)
{
    (void)cls;
    (void)fmt;
    (void)ap; /* silent: hostile clients must not fill the terminal */
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
    if (inet_pton(AF_INET, o->listen, &a4->sin_addr) == 1) {
        a4->sin_family = AF_INET;
        a4->sin_port = htons((uint16_t)o->port);
    } else if (inet_pton(AF_INET6, o->listen, &a6->sin6_addr) == 1) {
        a6->sin6_family = AF_INET6;
        a6->sin6_port = htons((uint16_t)o->port);
        flags |= MHD_USE_IPv6;
    } else {
        snprintf(err, errlen, "--listen '%s': a numeric IPv4 or IPv6 address", o->listen);
        free(h);
        return NULL;
    }
    h->d = MHD_start_daemon(flags, (uint16_t)o->port, NULL, NULL, on_request, h,
                            MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&ss,
                            MHD_OPTION_CONNECTION_LIMIT, (unsigned)o->max_connections,
                            MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)o->max_connections,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)VIEW_IDLE_TIMEOUT_S,
                            MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)VIEW_REQUEST_MEMORY,
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
    snprintf(h->host_ok[0], sizeof h->host_ok[0], "127.0.0.1:%u", h->port);
    snprintf(h->host_ok[1], sizeof h->host_ok[1], "localhost:%u", h->port);
    snprintf(h->host_ok[2], sizeof h->host_ok[2], "[::1]:%u", h->port);
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
    int64_t now = view_mono_ns();
    /* wake the suspended streams: when the snapshot changed (at most hz times a second)
     * and, for keep-alives, every VIEW_KEEPALIVE_NS */
    bool changed = h->woken_state != vb->state_seq || h->woken_status != vb->status_seq ||
                   h->woken_scene != vb->scene_seq || h->woken_event != vb->event_seq;
    if ((changed && now - h->last_wake_ns >= h->frame_ns) ||
        now - h->last_wake_ns >= VIEW_KEEPALIVE_NS) {
        h->last_wake_ns = now;
        h->woken_state = vb->state_seq;
        h->woken_status = vb->status_seq;
        h->woken_scene = vb->scene_seq;
        h->woken_event = vb->event_seq;
        for (stream *s = h->streams; s; s = s->next)
            if (s->suspended) {
                s->suspended = false;
                MHD_resume_connection(s->conn);
            }
    }
    MHD_run(h->d);
}

void view_http_stop(view_http *h)
{
    if (!h) return;
    for (stream *s = h->streams; s; s = s->next)
        if (s->suspended) {
            s->suspended = false;
            MHD_resume_connection(s->conn);
        }
    MHD_run(h->d);
    MHD_stop_daemon(h->d); /* frees every stream through stream_free */
    free(h);
}
