/*
 * Fuzz target: lagsim-view's formatting of text off the bus and its HTTP side.
 *
 * The first byte chooses what the rest is:
 *   0  the bytes of a scene, a state and its reference, a status and 1 to 300 events (every string any
 *      bytes but NUL, up to its field's length; numbers any 64 bits): /api/state must
 *      be valid JSON that fits its buffer with every part and the newest 32 events; the
 *      stream frames a new browser is sent, one after the other, must each be valid
 *      server-sent events of valid JSON, never cut a part ({"truncated":true}), and
 *      carry every event of the ring (the others counted missed); /api/history, for
 *      up to VIEW_HISTORY states and energies of any numbers, answers valid JSON in
 *      pieces that fit its buffer and together carry every sample once, in order;
 *   1  a raw HTTP request (any bytes; "@P" is replaced by the port bound) sent to a
 *      running bridge (memq://, on 127.0.0.1) over TCP, answered until it closes;
 *   2  a Host header's value for the allow-list check: never accepted with a port that is
 *      not the bridge's, nor with a name off the list.
 */
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <unistd.h>
#include <fcntl.h>
#include <errno.h>

#include "view.h"

static void fail(const char *what, const char *doc, size_t len)
{
    fprintf(stderr, "fuzz_view: %s\n%.*s\n", what, (int)(len > 2000 ? 2000 : len), doc);
    abort();
}

/* ---------------------------------------------------------------- a strict JSON check */
typedef struct jp {
    const char *p, *end;
    int depth;
} jp;

static bool j_value(jp *j);
static void j_ws(jp *j)
{
    while (j->p < j->end && (*j->p == ' ' || *j->p == '\n' || *j->p == '\r' || *j->p == '\t')) j->p++;
}
static bool j_lit(jp *j, const char *s)
{
    size_t n = strlen(s);
    if ((size_t)(j->end - j->p) < n || memcmp(j->p, s, n) != 0) return false;
    j->p += n;
    return true;
}
static bool j_string(jp *j)
{
    if (j->p >= j->end || *j->p != '"') return false;
    j->p++;
    while (j->p < j->end) {
        unsigned char c = (unsigned char)*j->p;
        if (c == '"') {
            j->p++;
            return true;
        }
        if (c < 0x20) return false;
        if (c == '\\') {
            if (++j->p >= j->end) return false;
            char e = *j->p++;
            if (e == 'u') {
                for (int i = 0; i < 4; i++, j->p++)
                    if (j->p >= j->end || !strchr("0123456789abcdefABCDEF", *j->p) || !*j->p) return false;
            } else if (!strchr("\"\\/bfnrt", e) || !e) {
                return false;
            }
            continue;
        }
        if (c < 0x80) {
            j->p++;
            continue;
        }
        /* UTF-8: a lead byte and its continuation bytes, no overlong form, no surrogate */
        int n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
        if (!n || j->end - j->p < n) return false;
        unsigned cp = c & (0x7f >> n);
        for (int i = 1; i < n; i++) {
            unsigned char d = (unsigned char)j->p[i];
            if ((d & 0xc0) != 0x80) return false;
            cp = (cp << 6) | (d & 0x3f);
        }
        if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10ffff)) ||
            (cp >= 0xd800 && cp <= 0xdfff))
            return false;
        j->p += n;
    }
    return false;
}
static bool j_number(jp *j)
{
    const char *s = j->p;
    if (j->p < j->end && *j->p == '-') j->p++;
    if (j->p >= j->end) return false;
    if (*j->p == '0') j->p++;
    else if (*j->p >= '1' && *j->p <= '9') while (j->p < j->end && *j->p >= '0' && *j->p <= '9') j->p++;
    else return false;
    if (j->p < j->end && *j->p == '.') {
        j->p++;
        if (j->p >= j->end || *j->p < '0' || *j->p > '9') return false;
        while (j->p < j->end && *j->p >= '0' && *j->p <= '9') j->p++;
    }
    if (j->p < j->end && (*j->p == 'e' || *j->p == 'E')) {
        j->p++;
        if (j->p < j->end && (*j->p == '+' || *j->p == '-')) j->p++;
        if (j->p >= j->end || *j->p < '0' || *j->p > '9') return false;
        while (j->p < j->end && *j->p >= '0' && *j->p <= '9') j->p++;
    }
    return j->p > s;
}
static bool j_value(jp *j)
{
    j_ws(j);
    if (j->p >= j->end || ++j->depth > 32) return false;
    bool ok;
    char c = *j->p;
    if (c == '{' || c == '[') {
        char close = c == '{' ? '}' : ']';
        j->p++;
        j_ws(j);
        ok = true;
        if (j->p < j->end && *j->p == close) {
            j->p++;
        } else {
            for (;;) {
                if (c == '{') {
                    j_ws(j);
                    if (!j_string(j)) return false;
                    j_ws(j);
                    if (j->p >= j->end || *j->p++ != ':') return false;
                }
                if (!j_value(j)) return false;
                j_ws(j);
                if (j->p >= j->end) return false;
                if (*j->p == ',') {
                    j->p++;
                    continue;
                }
                if (*j->p++ != close) return false;
                break;
            }
        }
    } else if (c == '"') {
        ok = j_string(j);
    } else if (c == 't') {
        ok = j_lit(j, "true");
    } else if (c == 'f') {
        ok = j_lit(j, "false");
    } else if (c == 'n') {
        ok = j_lit(j, "null");
    } else {
        ok = j_number(j);
    }
    j->depth--;
    return ok;
}
static bool json_ok(const char *s, size_t n)
{
    jp j = {s, s + n, 0};
    if (!j_value(&j)) return false;
    j_ws(&j);
    return j.p == j.end;
}

/* ---------------------------------------------------------------- bytes into messages */
typedef struct src {
    const uint8_t *p;
    size_t n;
} src;

static uint8_t byte(src *s)
{
    if (!s->n) return 0;
    s->n--;
    return *s->p++;
}
static double num(src *s)
{
    uint64_t u = 0;
    for (int i = 0; i < 8; i++) u = u << 8 | byte(s);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}
/* Any bytes but NUL, up to cap - 1 of them; a first byte >= 0xf0 asks for the longest. */
static void text(src *s, char *dst, size_t cap)
{
    uint8_t l = byte(s);
    size_t n = l >= 0xf0 ? cap - 1 : l % cap;
    for (size_t i = 0; i < n; i++) {
        uint8_t c = byte(s);
        dst[i] = (char)(c ? c : (uint8_t)(i * 7 + 1)); /* no NUL: a string ends there */
    }
    dst[n] = '\0';
}

static view_bridge vb; /* large: static */

static void fill(src *s)
{
    memset(&vb, 0, sizeof vb);
    snprintf(vb.prefix, sizeof vb.prefix, "FUZZ");
    lag_wire_scene *sc = &vb.scene;
    text(s, sc->model, sizeof sc->model);
    text(s, sc->prefix, sizeof sc->prefix);
    sc->num_params = byte(s) % (LAG_WIRE_MAX_PARAMS + 1);
    for (int i = 0; i < LAG_WIRE_MAX_PARAMS; i++) {
        text(s, sc->param_name[i], sizeof sc->param_name[i]);
        sc->param_value[i] = num(s);
    }
    sc->num_joints = byte(s) % (LAG_WIRE_MAX_JOINTS + 1);
    for (int i = 0; i < LAG_WIRE_MAX_JOINTS; i++) {
        text(s, sc->joint_name[i], sizeof sc->joint_name[i]);
        sc->actuated[i] = byte(s) & 1;
        sc->limit_on[i] = byte(s) & 1;
        sc->initial_q[i] = num(s);
        sc->limit_lower[i] = num(s);
    }
    text(s, sc->integrator, sizeof sc->integrator);
    text(s, sc->mode, sizeof sc->mode);
    text(s, sc->effects, sizeof sc->effects);
    sc->dt = num(s);
    vb.scene_seq = byte(s) & 1;
    lag_wire_joint_state *st = &vb.state;
    st->num_joints = byte(s) % (LAG_WIRE_MAX_JOINTS + 1);
    for (int i = 0; i < LAG_WIRE_MAX_JOINTS; i++) {
        text(s, st->name[i], sizeof st->name[i]);
        st->position[i] = num(s);
        st->effort[i] = num(s);
    }
    st->sim_time = num(s);
    vb.state_seq = byte(s) & 1;
    lag_wire_reference *rf = &vb.state_ref; /* the state's reference, sent with it */
    rf->num_joints = byte(s) % (LAG_WIRE_MAX_JOINTS + 1);
    for (int i = 0; i < LAG_WIRE_MAX_JOINTS; i++) {
        text(s, rf->name[i], sizeof rf->name[i]);
        rf->r[i] = num(s);
        rf->rdot[i] = num(s);
    }
    rf->sim_time = num(s);
    lag_wire_status *su = &vb.status;
    text(s, su->integrator, sizeof su->integrator);
    text(s, su->mode, sizeof su->mode);
    text(s, su->run_state, sizeof su->run_state);
    text(s, su->contact, sizeof su->contact);
    su->rtf = num(s);
    vb.status_seq = byte(s) & 1;
    int n = 1 + (int)((byte(s) << 8 | byte(s)) % 300);
    int whole = 0; /* the last event made of the input's bytes alone */
    for (int q = 1; q <= n; q++) {
        lag_wire_event *e = &vb.events[q % VIEW_EVENTS].ev;
        if (s->n) { /* while bytes last; then copies of the last whole one */
            text(s, e->kind, sizeof e->kind);
            text(s, e->joint, sizeof e->joint);
            text(s, e->detail, sizeof e->detail);
            e->value = num(s);
            if (s->n) whole = q;
        } else if (whole) {
            *e = vb.events[whole % VIEW_EVENTS].ev;
        }
    }
    vb.event_seq = n;
    /* the history: a ring holding any span of seqs, of any numbers */
    view_history *h = &vb.hist;
    int64_t base = byte(s) << 16 | byte(s) << 8;
    int ns = (int)((byte(s) << 8 | byte(s)) % (VIEW_HISTORY + 1));
    int ne = (int)((byte(s) << 8 | byte(s)) % (VIEW_HISTORY + 1));
    h->state_first = base + 1, h->state_last = base + ns;
    h->energy_first = base + 1, h->energy_last = base + ne;
    for (int64_t q = h->state_first; q <= h->state_last; q++) {
        view_sample *x = &h->state[q % VIEW_HISTORY];
        x->n = byte(s) % (LAG_WIRE_MAX_JOINTS + 1);
        x->t = num(s);
        for (int i = 0; i < LAG_WIRE_MAX_JOINTS; i++)
            x->q[i] = num(s), x->qd[i] = num(s), x->effort[i] = num(s);
    }
    for (int64_t q = h->energy_first; q <= h->energy_last; q++) {
        h->energy_t[q % VIEW_HISTORY] = num(s);
        h->energy[q % VIEW_HISTORY] = num(s);
    }
}

/* /api/history of one kind asked for piece after piece, as the page does: each piece
 * valid JSON, the seqs first..last all sent once, in order. */
static void check_history(const char *of, int64_t first, int64_t last)
{
    static char out[64 * 1024]; /* view_http.c's VIEW_STATE_JSON */
    int64_t from = 0, got = 0;
    for (int k = 0; k <= VIEW_HISTORY + 1; k++) {
        char f[32];
        snprintf(f, sizeof f, "%lld", (long long)from);
        size_t n = view_json_history(&vb, of, f, out, sizeof out);
        if (n == 0) fail("/api/history did not answer", of, strlen(of));
        if (!json_ok(out, n - 1) || out[n - 1] != '\n') fail("/api/history is not valid JSON", out, n);
        long long a = 0, b = 0, next = 0;
        const char *t = strstr(out, "],\"next\":");
        if (sscanf(out, "{\"of\":\"%*[a-z]\",\"first\":%lld,\"last\":%lld", &a, &b) != 2 || !t ||
            sscanf(t, "],\"next\":%lld}", &next) != 1 || a != first || b != last)
            fail("/api/history without first, last, next", out, n);
        int64_t start = from < first ? first : from;
        got += next - start;
        if (next > last) break;
        if (next == start) fail("/api/history sent nothing and is not done", out, n);
        from = next;
    }
    if (got != (last >= first ? last - first + 1 : 0)) fail("/api/history lost samples", of, strlen(of));
}

static void check_json_side(void)
{
    static char out[64 * 1024]; /* view_http.c's VIEW_STATE_JSON */
    size_t n = view_json_snapshot(&vb, NULL, out, sizeof out);
    if (n == 0) fail("/api/state did not fit", "", 0);
    if (!json_ok(out, n - 1) || out[n - 1] != '\n') fail("/api/state is not valid JSON", out, n);
    if (!strstr(out, "\"events_omitted\":0,") || !strstr(out, "\"parts_omitted\":0}"))
        fail("/api/state left something out", out, n);

    view_cursor c = {0};
    int64_t cut = 0, events = 0, missed = 0;
    static char buf[VIEW_STREAM_BUF];
    for (int k = 0; k < 64; k++) {
        size_t len = view_frame(&vb, 60, &c, buf, sizeof buf, &cut);
        if (len == 0) break;
        /* event: NAME\ndata: JSON\n\n ... (the first frame starts with retry: 1000\n) */
        const char *p = buf, *end = buf + len;
        if (strncmp(p, "retry: 1000\n", 12) == 0) p += 12;
        while (p < end) {
            if (strncmp(p, "event: ", 7) != 0) fail("a frame without its event line", buf, len);
            const char *nl = memchr(p, '\n', (size_t)(end - p));
            if (!nl || strncmp(nl + 1, "data: ", 6) != 0) fail("an event without data", buf, len);
            const char *d = nl + 7, *de = memchr(d, '\n', (size_t)(end - d));
            if (!de || de + 1 >= end || de[1] != '\n') fail("data not ended by a blank line", buf, len);
            if (!json_ok(d, (size_t)(de - d))) fail("a frame's data is not valid JSON", buf, len);
            if (strncmp(p, "event: events\n", 14) == 0) {
                long long m;
                if (sscanf(d, "{\"missed\":%lld", &m) != 1) fail("events without missed", buf, len);
                missed += m;
                for (const char *q = d; (q = strstr(q, "{\"seq\":")) && q < de; q++) events++;
            }
            p = de + 2;
        }
    }
    if (cut) fail("a stream frame cut a part", buf, 0);
    check_history("state", vb.hist.state_first, vb.hist.state_last);
    check_history("energy", vb.hist.energy_first, vb.hist.energy_last);
    if (c.event_seq != vb.event_seq || events + missed != vb.event_seq)
        fail("a new stream was not sent every event", buf, 0);
}

/* ---------------------------------------------------------------- HTTP */
static view_http *http;
static view_bridge hvb;

static void run_once(int ms)
{
    struct pollfd pf = {view_http_fd(http), POLLIN, 0};
    poll(&pf, 1, ms);
    view_http_run(http);
}

static void check_http(const uint8_t *d, size_t n)
{
    if (!http) {
        char err[256];
        if (!view_bridge_open(&hvb, "memq://", "FUZZ", false, err, sizeof err)) fail(err, "", 0);
        view_http_opts o = {.listen = "127.0.0.1", .port = 0, .hz = 240, .max_streams = 4,
                            .max_connections = 16};
        http = view_http_start(&hvb, &o, err, sizeof err);
        if (!http) fail(err, "", 0);
    }
    /* the request, "@P" made the port */
    static char req[70000];
    char port[8];
    snprintf(port, sizeof port, "%u", view_http_port(http));
    size_t len = 0;
    for (size_t i = 0; i < n && len + 8 < sizeof req; i++) {
        if (d[i] == '@' && i + 1 < n && d[i + 1] == 'P') {
            memcpy(req + len, port, strlen(port));
            len += strlen(port);
            i++;
        } else {
            req[len++] = (char)d[i];
        }
    }
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)view_http_port(http))};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0) fail("connect", "", 0);
    fcntl(fd, F_SETFL, O_NONBLOCK);
    size_t off = 0;
    char sink[65536];
    /* until the bridge closes, or nothing moves for 20 rounds (a stream stays open) */
    for (int k = 0, quiet = 0; k < 400 && quiet < 20; k++) {
        bool moved = false;
        if (off < len) {
            ssize_t w = send(fd, req + off, len - off, MSG_NOSIGNAL);
            if (w > 0) off += (size_t)w, moved = true;
            else if (errno != EAGAIN) break;
            if (off == len) shutdown(fd, SHUT_WR);
        } else if (len == 0 && k == 0) {
            shutdown(fd, SHUT_WR);
        }
        run_once(1);
        ssize_t r = recv(fd, sink, sizeof sink, 0);
        if (r == 0 || (r < 0 && errno != EAGAIN)) break;
        if (r > 0) moved = true;
        quiet = moved ? 0 : quiet + 1;
    }
    close(fd);
    for (int k = 0; k < 20 && view_http_streams(http); k++) run_once(5);
    for (int k = 0; k < 3; k++) run_once(0);
}

/* ---------------------------------------------------------------- Host */
static void check_host(const uint8_t *d, size_t n)
{
    if (!http) check_http(NULL, 0);
    char h[512];
    if (n >= sizeof h) n = sizeof h - 1;
    memcpy(h, d, n);
    h[n] = '\0';
    if (!view_host_ok(http, h)) return;
    /* accepted: a name on the list (127.0.0.1 or localhost here), the bridge's port */
    char want[16];
    snprintf(want, sizeof want, ":%u", view_http_port(http));
    const char *colon = strrchr(h, ':');
    if (!colon || strcmp(colon, want) != 0) fail("a Host with another port accepted", h, strlen(h));
    size_t name = (size_t)(colon - h);
    if (name && h[name - 1] == '.') name--;
    if (!((name == 9 && strncmp(h, "127.0.0.1", 9) == 0) ||
          (name == 9 && strncasecmp(h, "localhost", 9) == 0)))
        fail("a Host off the allow-list accepted", h, strlen(h));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    src s = {data + 1, size - 1};
    switch (data[0] % 3) {
    case 0:
        fill(&s);
        check_json_side();
        break;
    case 1: check_http(data + 1, size - 1); break;
    default: check_host(data + 1, size - 1); break;
    }
    return 0;
}
