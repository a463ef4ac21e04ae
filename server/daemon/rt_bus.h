/*
 * The real-time server's bus (rt_bus.c): its LCM instances, the subscriptions, the
 * channels, the encode buffer, and the plant watch (one plant per prefix).
 *
 * A part of the loop's (realtime.c holds one). What arrives is handed to the loop through
 * the handlers it gives at attach (rt_bus_handlers), never decoded here; a scene heard on
 * the prefix is judged here (rt_bus_foreign_scene) and what follows is the loop's.
 */
#ifndef LAGSIMD_RT_BUS_H
#define LAGSIMD_RT_BUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <lcm/lcm.h>
#include "lagsim_bus.h"
#include "lagsim_wire.h"
#include "rt_foreign.h"
#include "rt_pace.h"
#include "rt_rx.h"
#include "scene.h"

#define RT_CHANNEL_MAX LAG_BUS_CHANNEL_LEN /* prefix (< 64) + "_COMMAND" */
#define RT_BUF_SIZE LAG_WIRE_BUF_SIZE      /* encode buffer: holds any message */
/* The last scenes published, to tell them from another plant's when they are heard back on
 * the plant watch: enough for every scene the buckets let out in RT_SCENE_ECHO_S seconds
 * (a flood of SET and RESET publishes a new generation's scene for each within their
 * buckets, a burst of them in one pass; rt_control.c checks the bound), far longer than
 * a datagram looped back by this host takes to be read. */
#define RT_SCENES_KEPT 1024
#define RT_SCENE_ECHO_S 4

/* What the loop does with a message: a command, a control request, a scene heard on the
 * state URL (see rt_bus_foreign_scene). */
typedef struct rt_bus_handlers {
    void (*command)(void *ctx, const uint8_t *data, size_t len);
    void (*control)(void *ctx, const uint8_t *data, size_t len);
    void (*scene)(void *ctx, const uint8_t *data, size_t len);
    void *ctx;
} rt_bus_handlers;

typedef struct rt_bus {
    const lag_scene *sc;
    lag_bus urls;              /* the URLs and channels (lagsim_bus.h) */
    char ch_state[RT_CHANNEL_MAX], ch_command[RT_CHANNEL_MAX], ch_status[RT_CHANNEL_MAX],
        ch_event[RT_CHANNEL_MAX], ch_control[RT_CHANNEL_MAX], ch_scene[RT_CHANNEL_MAX],
        ch_reference[RT_CHANNEL_MAX];
    lcm_t *lcm;                /* publishes on the state URL */
    lcm_t *lcm_in;             /* udpm: publishes on the command URL (DESCRIBE at start, the
                                * sync marker); memq://: the same lcm_t as `lcm`, receiving
                                * _COMMAND and _CONTROL through LCM's subscriptions */
    rt_rx rx_in;               /* udpm: _COMMAND and _CONTROL, read by the loop (rt_rx.h) */
    rt_rx rx_watch;            /* udpm: the plant watch on the state URL: _SCENE, and
                                * _COMMAND sent to the wrong port */
    rt_rx rx_foreign;          /* udpm: other prefixes' _CONTROL on the command URL, apart
                                * from the plant's own input (read within a budget of its
                                * own) */
    long rcvbuf;               /* the URL's recv_buf_size (0: the system's) */
    lcm_subscription_t *sub_command, *sub_control;
    lcm_subscription_t *sub_scene; /* _SCENE on the state URL: another plant's (plant watch) */
    lcm_subscription_t *sub_wrong_port; /* _COMMAND on the state URL: counted, not applied */
    lcm_subscription_t *sub_foreign_in, *sub_foreign_out, *sub_foreign_scene; /* every
                                * <P>_CONTROL on the command URL and on the state URL, every
                                * <P>_SCENE on the state URL: requests not for this plant
                                * where it listens (rt_foreign.h) */
    rt_bus_handlers on;
    bool discard;              /* drop commands and control requests: before the start,
                                * LCM's queues may hold datagrams that came in before the
                                * filter */
    int64_t commands_wrong_port; /* joint_command_t heard on the state URL */
    rt_foreign foreign;        /* control requests for other prefixes, or on the state URL */
    rt_limit probes;           /* its DESCRIBEs to those prefixes (rt_foreign.h) */
    const int64_t *now;        /* the loop's clock (NULL: CLOCK_MONOTONIC) */
    bool quiet;                /* -q: rt_bus_open says where it listens only when the
                                * network can reach it (a warning) */
    /* one plant per prefix: the scenes this daemon published (FNV-1a of their bytes, which
     * include utime), and what was heard from another plant */
    uint64_t scene_sent[RT_SCENES_KEPT];
    int scene_next;
    char other_plant[160];     /* what gave it away, the last one heard ("" = nothing) */
    uint8_t buf[RT_BUF_SIZE];  /* the one encode buffer */
} rt_bus;

/* The URLs and channels of the scene's lcm section, by the rule every client follows
 * (lagsim_bus.h); no LCM yet. Returns 0, or -1 with a message in err. */
int rt_bus_init(rt_bus *b, const lag_scene *sc, char *err, size_t errlen);
/* Publishes on `out` and subscribes to _COMMAND and _CONTROL on `in` (the same lcm_t for
 * memq://; the caller owns both and destroys them after rt_bus_detach), and to _SCENE on
 * `out`; what arrives goes to `h`. Returns 0, or an exit code with a message in err. */
int rt_bus_attach(rt_bus *b, lcm_t *out, lcm_t *in, const rt_bus_handlers *h, char *err,
                  size_t errlen);
/* Unsubscribes (the caller destroys its lcm). */
void rt_bus_detach(rt_bus *b);
/* The daemon's bus: on udpm:// two LCM instances that only publish (state URL, command
 * URL) and two receive sockets of its own (rt_rx.h: no LCM thread, no select(2)); on
 * memq:// one lcm_t, attached with `h`; before anything is published,
 * the look for another plant on the prefix; and what the daemon says about them at start.
 * Leaves b->discard set (the loop clears it at the start). Returns 0, or an exit code with
 * a message in err; rt_bus_close detaches and destroys what rt_bus_open made.
 *
 * In two steps, for a loop that serves other plants during the look: rt_bus_open_start
 * makes the instances, filters the state URL's receive socket to the plant watch and asks
 * the prefix for its scene (DESCRIBE); the caller then handles b->lcm for RT_LOOK_MS
 * (another plant's scene is noted in b->other_plant); rt_bus_open_finish refuses the
 * start if one came, else filters the command URL and says where the plant listens. Each
 * closes what it made when it fails. rt_bus_open is the three in a row. */
#define RT_LOOK_MS 200 /* how long a starting daemon listens for another plant */
int rt_bus_open(rt_bus *b, const rt_bus_handlers *h, char *err, size_t errlen);
int rt_bus_open_start(rt_bus *b, const rt_bus_handlers *h, char *err, size_t errlen);
int rt_bus_open_finish(rt_bus *b, char *err, size_t errlen);
void rt_bus_close(rt_bus *b);
/* What the loop reads: the plant's own input (its commands and control requests), the
 * plant watch (the state URL), other prefixes' requests on the command URL. */
typedef enum rt_bus_input { RT_BUS_IN = 0, RT_BUS_WATCH, RT_BUS_FOREIGN } rt_bus_input;
/* What the loop waits on: the descriptor of `which` (-1: none: memq's watch and foreign). */
int rt_bus_fd(const rt_bus *b, rt_bus_input which);
/* Reads at most max messages of `which`, handing each to the handlers. Returns the number
 * read (0: nothing waiting). */
int rt_bus_read(rt_bus *b, rt_bus_input which, int max);

/* FNV-1a, 64 bits: how a published scene is remembered. */
uint64_t rt_bus_hash(const uint8_t *data, size_t len);
/* A scene this daemon published (encoded in data): remembered. */
void rt_bus_sent_scene(rt_bus *b, const uint8_t *data, size_t len);
/* A scene heard on this prefix: one that decodes, names this prefix and is not one this
 * daemon published is another plant's (or a forgery, or an old log played back), and is
 * noted in b->other_plant. At start (b->discard) that is all (rt_bus_open refuses to
 * start); returns true when one is heard while running (the loop says so). Anything else
 * on the channel is ignored. */
bool rt_bus_foreign_scene(rt_bus *b, const uint8_t *data, size_t len);

#endif
