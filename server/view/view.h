/*
 * lagsim-view: a bridge from a daemon's LCM channels to browsers.
 *
 * One thread, one poll loop (view_main.c) over the LCM socket, libmicrohttpd's epoll
 * descriptor, a timerfd and a signalfd. LCM messages are decoded by the shared bounded
 * wire module into the latest snapshot (view_bridge.c); nothing queues: the newest state
 * replaces the previous one, events go into a fixed ring. Browsers read the page, the
 * snapshot as JSON (GET /api/state) and a stream of server-sent events (GET /events):
 * each stream holds one fixed buffer, refilled with the newest snapshot at most `hz`
 * times a second and only when the previous frame has left (view_http.c), so a slow or
 * vanished client never makes the bridge hold more than that buffer.
 */
#ifndef LAGSIM_VIEW_H
#define LAGSIM_VIEW_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <lcm/lcm.h>

#include "lagsim_clock.h"
#include "lagsim_wire.h"

#define VIEW_EVENTS 256            /* events kept for streams and /api/state */
#define VIEW_EVENTS_PER_FRAME 16   /* at most this many in one stream frame */
#define VIEW_EVENTS_IN_STATE 32    /* the newest ones in /api/state */
#define VIEW_STREAM_BUF 32768      /* one stream's frame buffer */
#define VIEW_CONTROLS_PER_S 10     /* control requests forwarded per second at most */
#define VIEW_CHANNEL_MAX 96
/* History for a page opened mid-run (GET /api/history): the newest states and energies,
 * 60 s at the shipped 100 Hz publish rate (less at a higher rate: the ring is capped). */
#define VIEW_HISTORY 6000
/* Budgets for text off the bus, in bytes of JSON (escapes included): a name (63 bytes on
 * the wire) or a detail (255) that needs more is cut and ends in "…[truncated N bytes]"
 * (N: the bytes of the original left out). Twice the wire's length: text as the daemon
 * writes it is never cut; only escapes (6 bytes for one control byte) can need more. */
#define VIEW_JSON_NAME_MAX (2 * LAG_WIRE_NAME_LEN)
#define VIEW_JSON_TEXT_MAX (2 * LAG_WIRE_TEXT_LEN)

/* ---------------------------------------------------------------- JSON (view_json.c) */
/* A bounded JSON builder: everything appended past cap is dropped and `overflow` set,
 * so the caller throws the piece away instead of sending half of it. */
typedef struct jbuf {
    char *p;
    size_t cap, len;
    bool overflow;
} jbuf;

void jb_init(jbuf *b, char *mem, size_t cap);
void jb_raw(jbuf *b, const char *s);
void jb_fmt(jbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* A JSON string from bytes off the bus: quotes, backslashes and control characters
 * escaped, invalid UTF-8 replaced by U+FFFD, at most `budget` bytes between the quotes
 * (cut with the marker above when it needs more). jb_str: VIEW_JSON_NAME_MAX. */
void jb_str_max(jbuf *b, const char *s, size_t budget);
void jb_str(jbuf *b, const char *s);
/* A number, or null when it is not finite (JSON has no NaN). */
void jb_num(jbuf *b, double x);
void jb_key(jbuf *b, const char *key, bool first); /* ,"key": */

/* A state, with "ref": {name, r, rdot} when ref holds its reference (ref may be NULL;
 * num_joints 0: none). */
void view_json_state(jbuf *b, const lag_wire_joint_state *m, const lag_wire_reference *ref);
void view_json_status(jbuf *b, const lag_wire_status *m);
void view_json_event(jbuf *b, const lag_wire_event *m, int64_t seq);
void view_json_scene(jbuf *b, const lag_wire_scene *m);

/* ---------------------------------------------------------------- bridge (view_bridge.c) */
/* One state of the history: sim time (s), q, qd, effort of n joints. */
typedef struct view_sample {
    double t;
    int n;
    double q[LAG_WIRE_MAX_JOINTS], qd[LAG_WIRE_MAX_JOINTS], effort[LAG_WIRE_MAX_JOINTS];
} view_sample;

/* A ring of the newest VIEW_HISTORY samples, numbered seq = 1, 2, ... (slot seq %
 * VIEW_HISTORY): it holds first..last (none while last < first). A sim time before the
 * newest one (a reset) starts it over; the newest one's time again (paused: the daemon
 * republishes) replaces that sample. */
typedef struct view_history {
    view_sample state[VIEW_HISTORY];
    int64_t state_first, state_last;
    double energy_t[VIEW_HISTORY], energy[VIEW_HISTORY]; /* from the status: s, J */
    int64_t energy_first, energy_last;
} view_history;

typedef struct view_event {
    int64_t seq;                   /* 1, 2, ... */
    lag_wire_event ev;
} view_event;

typedef struct view_bridge {
    lcm_t *lcm;      /* the plant's state URL: states, status, events, scene */
    lcm_t *lcm_cmd;  /* its command URL: control requests (lagsim_bus.h); = lcm for memq:// */
    char prefix[64];
    char url[256];
    char ch_state[VIEW_CHANNEL_MAX], ch_status[VIEW_CHANNEL_MAX], ch_event[VIEW_CHANNEL_MAX],
        ch_scene[VIEW_CHANNEL_MAX], ch_control[VIEW_CHANNEL_MAX], ch_reference[VIEW_CHANNEL_MAX];

    /* the latest of each, with a sequence number that grows on every update */
    lag_wire_joint_state state;
    int64_t state_seq;
    lag_wire_reference reference;   /* the latest <PREFIX>_REFERENCE */
    lag_wire_reference state_ref;   /* the state's own (same sim_time and step), or none */
    lag_wire_status status;
    int64_t status_seq;
    lag_wire_scene scene;
    int64_t scene_seq;
    view_event events[VIEW_EVENTS]; /* ring: events[seq % VIEW_EVENTS] */
    int64_t event_seq;              /* of the newest */
    view_history hist;              /* for a page opened mid-run */
    int64_t last_msg_ns;            /* CLOCK_MONOTONIC of the last decoded message */
    int64_t last_describe_ns;       /* when a DESCRIBE was last sent */
    bool discard;                   /* while the socket filter is put in place */

    /* counters for /api/state */
    int64_t n_state, n_status, n_event, n_scene, n_undecodable, n_reference;
    int64_t controls_sent, controls_refused;
    int64_t ctl_window_ns;
    int ctl_in_window;
} view_bridge;

/* Connects and subscribes; on udpm keeps only the plant's channels and, unless allow_lan,
 * only datagrams sent from this host. Returns false with a message in err. */
bool view_bridge_open(view_bridge *vb, const char *url, const char *prefix, bool allow_lan,
                      char *err, size_t errlen);
void view_bridge_close(view_bridge *vb);
/* Handles the LCM messages waiting (at most a bounded number); sends a DESCRIBE while
 * no scene is known (once a second). */
void view_bridge_poll(view_bridge *vb);
/* Sends a control request: "pause", "resume", "step" (count >= 1), "reset", "status",
 * "describe". Returns 0, or an HTTP status with a reason in why: 400 unknown request or
 * bad count, 429 over VIEW_CONTROLS_PER_S, 500 LCM refused it. */
int view_bridge_control(view_bridge *vb, const char *request, const char *count,
                        const char **why);
/* A kick (lagsimctl kick): impulse I (N s or N m s) on joint J now, or spread over S s as
 * a force; sent as SET "kick.J" = "I[,S]" under the same rate limit as the controls.
 * Returns 0 (sent) or an HTTP status with the reason in *why. */
int view_bridge_kick(view_bridge *vb, const char *joint, const char *impulse,
                     const char *duration, const char **why);

/* ---------------------------------------------------------------- HTTP (view_http.c) */
typedef struct view_http view_http;

typedef struct view_http_opts {
    const char *listen;            /* numeric IPv4 or IPv6 address */
    unsigned port;                 /* 0: any free port */
    unsigned hz;                   /* stream frames per second at most */
    unsigned max_streams;          /* concurrent /events streams */
    unsigned max_connections;      /* all connections */
    const char *const *allow_hosts;  /* more names accepted in the Host header (--allow-host) */
    int n_allow_hosts;
} view_http_opts;

#define VIEW_HOSTS_MAX 64           /* names on the Host allow-list */
#define VIEW_HOST_LEN 256

view_http *view_http_start(view_bridge *vb, const view_http_opts *o, char *err, size_t errlen);
/* Whether a Host header's value names this bridge: a name on the allow-list built from
 * --listen and --allow-host (see view_http.c), and the port bound. */
bool view_host_ok(const view_http *h, const char *host);
/* The port bound (useful with port 0). */
unsigned view_http_port(const view_http *h);
/* The descriptor to poll for readability (libmicrohttpd's epoll set). */
int view_http_fd(const view_http *h);
/* How long the loop may sleep, ms (-1: no limit from HTTP). */
int view_http_timeout_ms(view_http *h);
/* Runs libmicrohttpd once; wakes the streams that are due a frame. */
void view_http_run(view_http *h);
/* Streams open now. */
unsigned view_http_streams(const view_http *h);
/* Stops: every stream ends (its last chunk) and is resumed first, libmicrohttpd aborting in
 * MHD_stop_daemon while a connection is suspended; then closes. Within about 1 s. */
void view_http_stop(view_http *h);

/* What one stream has been sent. */
typedef struct view_cursor {
    int64_t state_seq, status_seq, scene_seq, event_seq;
    bool hello_sent;
} view_cursor;
/* A stream's next frame into buf[cap]: what is new since the cursor (which it advances),
 * each of scene, state and status whole or left for the next frame, the events that fit
 * (oldest first, at most VIEW_EVENTS_PER_FRAME). A part too big for an empty frame (the
 * budgets rule it out) is sent as {"truncated":true} and counted in *cut, so that a stream
 * never sticks. Returns the length (0: nothing new). */
size_t view_frame(const view_bridge *vb, unsigned hz, view_cursor *c, char *buf, size_t cap,
                  int64_t *cut);

/* GET /api/history?of=state|energy&from=SEQ: the ring's samples from seq `from` (or its
 * oldest) on, oldest first, as many as fit in cap: {"of":..,"first":F,"last":L,"next":N,
 * "samples":[[t,[q..],[qd..],[effort..]],..]} (energy: [t,E]); N is the seq to ask for
 * next (N > L: all sent). Returns the length, 0 for an unknown `of` or a bad `from`. */
size_t view_json_history(const view_bridge *vb, const char *of, const char *from, char *out,
                         size_t cap);
/* The snapshot as JSON (GET /api/state). A part that does not fit is null (counted in
 * parts_omitted); the newest events that fit are kept (the others counted in
 * events_omitted). Returns the length, 0 only if cap cannot hold the bridge's counters. */
size_t view_json_snapshot(const view_bridge *vb, const view_http *h, char *out, size_t cap);
/* Events first..last of the ring, comma-separated, as many as fit while `reserve` bytes
 * stay free; *sent: the last one written (first - 1: none). Returns how many. */
size_t view_json_events(jbuf *b, const view_bridge *vb, int64_t first, int64_t last,
                        size_t reserve, int64_t *sent);
/* The HTTP side's counters as ,"key":value pairs (for the bridge object). */
void view_http_counters(const view_http *h, jbuf *b);

/* ---------------------------------------------------------------- page (generated) */
typedef struct view_asset {
    const char *path;              /* "/", "/view.js", ... */
    const char *type;              /* Content-Type */
    const unsigned char *data;
    size_t size;
} view_asset;

extern const view_asset view_assets[];
extern const size_t view_asset_count;

#endif
