/*
 * lagsim client library: talk to a lagsimd daemon over LCM from C.
 *
 *   char err[256];
 *   lag_client *c = lag_client_create(NULL, "DIPC", err, sizeof err); // LCM default URL
 *   lag_client_scene sc;
 *   lag_client_wait_scene(c, 5.0, &sc);          // sends DESCRIBE until the scene arrives
 *   lag_client_state st;
 *   while (lag_client_wait_state(c, 2.0, &st) == LAG_CLIENT_OK) { // each new state, once
 *       double u = ...;
 *       const char *name = "theta0";
 *       lag_client_send_command(c, st.sim_time, 1, &name, &u); // answers this state
 *   }
 *   lag_client_destroy(c);
 *
 * One return convention (SQLite's): every function returning lag_result (lagsim/result.h)
 * returns LAG_CLIENT_OK (0) on success, LAG_CLIENT_TIMEOUT (> 0) when nothing arrived in
 * time (not an error), or a negative error code, with a message kept on the handle
 * (lag_client_errmsg). The library never prints and never exits. Not thread-safe: use one handle per thread.
 *
 * Messages are decoded by lagsim's bounded wire module (lagsim_wire.h) into its
 * fixed-size structs, which are this library's message types: every field of every
 * message reaches the caller, no length from the bus is trusted, nothing is allocated
 * per message. A message that does not decode (wrong type, truncated, hostile), holds
 * more joints or longer names than the structs, or carries a NaN or an infinity is
 * dropped and counted in lag_client_counters, never returned. Commands and control
 * requests are encoded by the same module: a NaN or infinite effort, or a name of 64
 * bytes or more, is refused (LAG_CLIENT_ERR_ARG), never sent.
 *
 * Lockstep contract (realtime.mode: lockstep): the daemon advances one control period
 * only when a command answering the last published state arrives: a state is known by
 * its generation (one more at every reset and every accepted SET: docs/server.md) and its
 * sim_time, so answer every state with lag_client_send_command(c, state.sim_time, ...),
 * which stamps the state's generation. The daemon sends the state again until an answer
 * arrives; the client returns each state once and answers a copy (same generation,
 * step, sim_time) with the command already sent for it (counters: copies, repeats), so a
 * slow control law never falls behind on copies.
 *
 * Scene rule: a state whose generation is not the generation of the scene the client
 * holds is held (counters: held), not returned nor passed to on_state, until the scene of
 * that generation arrived; the daemon publishes it just before the first state of a
 * generation, and while a state is held the client asks for it (DESCRIBE) at once and
 * every LAG_CLIENT_DESCRIBE_S, for when UDP lost it. So a controller that reads its
 * parameters from the scene (lag_client_latest_scene, on_scene) always answers a state
 * with the scene that state belongs to.
 */
#ifndef LAGSIM_CLIENT_H
#define LAGSIM_CLIENT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "lagsim/result.h"
#include "lagsim_wire.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_CLIENT_MAX_JOINTS LAG_WIRE_MAX_JOINTS   /* 8 */
#define LAG_CLIENT_MAX_PARAMS LAG_WIRE_MAX_PARAMS   /* 16 */
#define LAG_CLIENT_NAME_LEN LAG_WIRE_NAME_LEN       /* 64: 63 bytes + NUL */
#define LAG_CLIENT_DESCRIBE_S 0.25  /* the pace of DESCRIBE while a scene is awaited */

/* Result codes: the one space of lagsim/result.h (lag_result). The client's names stay,
 * as aliases of its codes, with the values they always had. */
#define LAG_CLIENT_OK LAG_OK
#define LAG_CLIENT_TIMEOUT LAG_TIMEOUT             /* nothing arrived in time (not an error);
                                                    * positive, 2: never reads as "true" */
#define LAG_CLIENT_ERR_ARG LAG_ERR_ARG             /* bad argument (message says which) */
#define LAG_CLIENT_ERR_LCM LAG_ERR_LCM             /* LCM could not be created, publish or
                                                      handle failed */
#define LAG_CLIENT_ERR_NOMEM LAG_ERR_NOMEM
#define LAG_CLIENT_ERR_AMBIGUOUS LAG_ERR_AMBIGUOUS /* several plants could be meant (message
                                                      names them) */

/* The messages, as the wire module decodes them (every field of the .lcm types; the
 * field meanings are in lcmtypes/<type>.lcm and docs/server.md, "Messages"). */
typedef lag_wire_scene lag_client_scene;        /* scene_t */
typedef lag_wire_joint_state lag_client_state;  /* joint_state_t */
typedef lag_wire_status lag_client_status;      /* status_t */
typedef lag_wire_event lag_client_event;        /* event_t */
typedef lag_wire_reference lag_client_reference; /* reference_t */

typedef struct lag_client_counters {
    int64_t states, scenes, statuses, events;  /* messages received and kept */
    int64_t dropped;                           /* undecodable or out-of-range messages */
    int64_t commands_sent, controls_sent;
    int64_t copies;   /* of states, copies of the latest state (lockstep re-sends): not
                       * returned again, not passed to on_state */
    int64_t repeats;  /* of them, answered again with the command sent for that state */
    int64_t references;                        /* references received and kept */
    int64_t held;     /* states held until the scene of their generation came */
    int64_t describes; /* DESCRIBE requests sent for a held state's scene */
} lag_client_counters;

typedef struct lag_client lag_client;

typedef void (*lag_client_state_fn)(const lag_client_state *st, void *user);
typedef void (*lag_client_status_fn)(const lag_client_status *st, void *user);
typedef void (*lag_client_event_fn)(const lag_client_event *ev, void *user);
typedef void (*lag_client_scene_fn)(const lag_client_scene *sc, void *user);

/* Connects to the plant whose LCM URL is url (the daemon's lcm.url; NULL or "": LCM's
 * default, which honours LCM_DEFAULT_URL) and prefix: subscribes to <prefix>_STATE,
 * _STATUS, _EVENT, _SCENE, _REFERENCE on that (state) URL, and sends commands and control requests
 * to the plant's command URL, the same group on the next port (lagsim_bus.h). Returns
 * NULL on failure with a message in err (may be NULL). */
lag_client *lag_client_create(const char *url, const char *prefix, char *err, size_t errlen);
void lag_client_destroy(lag_client *c);
/* Message of the last failure on this handle ("" if none). */
const char *lag_client_errmsg(const lag_client *c);
/* The LCM file descriptor, for poll()/select() in the caller's loop: when readable, call
 * lag_client_handle(c, 0). */
int lag_client_fileno(const lag_client *c);

/* Handles at most one incoming message, waiting up to timeout_ms (0: do not wait).
 * Returns LAG_CLIENT_OK if a message was handled (kept or dropped), LAG_CLIENT_TIMEOUT if
 * none arrived (or a signal interrupted the wait), < 0 on error. Callbacks run from
 * inside this call. */
lag_result lag_client_handle(lag_client *c, int timeout_ms);

/* Handles one message as if it had arrived on `channel` (one of this handle's
 * <prefix>_STATE, _STATUS, _EVENT, _SCENE, _REFERENCE): decoding, counters, callbacks, as for the
 * bus. For messages read elsewhere (a log file) and for tests. Returns LAG_CLIENT_OK
 * (kept or dropped: the counters say which) or LAG_CLIENT_ERR_ARG for another channel. */
lag_result lag_client_feed(lag_client *c, const char *channel, const void *data, size_t len);

/* Callbacks (NULL to remove), called for every kept message from lag_client_handle. */
void lag_client_on_state(lag_client *c, lag_client_state_fn fn, void *user);
void lag_client_on_status(lag_client *c, lag_client_status_fn fn, void *user);
void lag_client_on_event(lag_client *c, lag_client_event_fn fn, void *user);
void lag_client_on_scene(lag_client *c, lag_client_scene_fn fn, void *user);

/* Waits up to timeout_s (wall seconds) for the scene description, sending a DESCRIBE
 * request at once and every 0.25 s until it arrives (a scene already received counts).
 * Returns LAG_CLIENT_OK, LAG_CLIENT_TIMEOUT or an error. OUT: sc */
lag_result lag_client_wait_scene(lag_client *c, double timeout_s, lag_client_scene *sc);

/* Waits up to timeout_s for a state not yet returned by this function (the newest one
 * if several arrived: a controller wants the latest). Returns LAG_CLIENT_OK with *st
 * filled, LAG_CLIENT_TIMEOUT, or an error. OUT: st */
lag_result lag_client_wait_state(lag_client *c, double timeout_s, lag_client_state *st);

/* Polling: the latest state / status received, whether or not already returned.
 * Return false if none has arrived yet. OUT: st */
bool lag_client_latest_state(const lag_client *c, lag_client_state *st);
bool lag_client_latest_status(const lag_client *c, lag_client_status *st);
/* The scene of the latest state's generation (the scene rule above; a scene of a later
 * generation that came since waits for its own state); before any state, the latest scene
 * received. False if none has arrived. OUT: sc */
bool lag_client_latest_scene(const lag_client *c, lag_client_scene *sc);
/* The latest reference (<prefix>_REFERENCE: the scene's `reference:`, r and r' of the
 * joints that have one, which the daemon publishes just before each state with the same
 * sim_time; so when a state arrives its reference has arrived already, unless UDP lost
 * it: compare the sim_times). False if none has arrived: a scene without a reference
 * publishes none. OUT: ref */
bool lag_client_latest_reference(const lag_client *c, lag_client_reference *ref);

/* Publishes a command on <prefix>_COMMAND: efforts for n joints named in names (N or
 * N m), answering the state at sim_time (lockstep advances on it; pass the sim_time of
 * the state the effort was computed from), stamped with the generation of the latest
 * state (0 before any: a command that answers no state, which lockstep never takes).
 * Joints not named keep their effort. A non-finite effort or sim_time, or a name of 64
 * bytes or more, is refused. */
lag_result lag_client_send_command(lag_client *c, double sim_time, int n, const char *const *names,
                                   const double *effort);

/* Control requests on <prefix>_CONTROL (lagsim_control_t). */
lag_result lag_client_pause(lag_client *c);
lag_result lag_client_resume(lag_client *c);
lag_result lag_client_step(lag_client *c, int64_t count);           /* control periods, >= 1 */
lag_result lag_client_reset(lag_client *c);                         /* scene's initial state */
lag_result lag_client_reset_to(lag_client *c, int n, const double *q, const double *qd); /* finite */
lag_result lag_client_request_status(lag_client *c);
lag_result lag_client_request_describe(lag_client *c);
/* SET: changes a scene key under parameters or effects while running, e.g. ("parameters.m2",
 * "1.25"), value in YAML; the daemon validates it as the scene file and answers with a
 * `set` event (and the new scene) or `control_rejected` with the reason. */
lag_result lag_client_set(lag_client *c, const char *key, const char *value);

/* A kick: a disturbance on joint `joint` from the current sim time on, adding to the
 * scene's disturbances and to earlier kicks: impulse N s (N m s on an angle) at once
 * (duration 0), or spread as a force impulse/duration over duration s. Sent as SET
 * "kick.<joint>" = "<impulse>[,<duration>]"; answered by a `kick` event (replayed exactly
 * from a log) or control_rejected with the reason. */
lag_result lag_client_kick(lag_client *c, const char *joint, double impulse, double duration);
/* RESET to the scene file's initial state and values: the changes made by SET and the
 * kicks are undone (a `restore` event says which), then the `reset` event. */
lag_result lag_client_reset_scene(lag_client *c);

void lag_client_get_counters(const lag_client *c, lag_client_counters *out);

/* Index of joint `name` in the scene (or -1); value of parameter `name` (or NaN). */
int lag_client_scene_joint(const lag_client_scene *sc, const char *name);
double lag_client_scene_param(const lag_client_scene *sc, const char *name);
/* Index of joint `name` in a state (or -1). */
int lag_client_state_joint(const lag_client_state *st, const char *name);
/* Index of joint `name` in a reference (or -1: the scene gives it no reference). */
int lag_client_reference_joint(const lag_client_reference *ref, const char *name);

/* ---------------------------------------------------------------- finding plants */

#define LAG_CLIENT_MAX_PLANTS 1024 /* a lab host's plants (lagsimd --plants) */

/* One plant heard on the bus. */
typedef struct lag_client_plant {
    char prefix[LAG_CLIENT_NAME_LEN];    /* its channel prefix (lcm.prefix) */
    char model[LAG_CLIENT_NAME_LEN];     /* from its scene ("" if none came) */
    char mode[LAG_CLIENT_NAME_LEN];      /* realtime, fast or lockstep */
    char run_state[LAG_CLIENT_NAME_LEN]; /* from its status: running, paused, waiting, fault */
    char host[LAG_CLIENT_NAME_LEN];      /* who sends its messages: this host's name, or
                                          * the sender's IPv4 address ("" if not seen) */
    char url[320];                       /* its state URL (commands: the next port): the
                                          * URL it was heard on, or the one a host's
                                          * directory names for it (a `plant` event) */
    double sim_time;                     /* s, from its status */
} lag_client_plant;

/* Lists the plants on the bus at url (NULL or "": LCM's default, honouring
 * LCM_DEFAULT_URL): every <PREFIX>_STATE, _STATUS, _EVENT or _SCENE heard on the state
 * URL names a plant, which is then asked for its scene (DESCRIBE) and status (STATUS)
 * until they come. Listens at most wait_s wall seconds, and stops settle_s after the
 * first plant was heard once every plant heard is described (settle_s < 0: the whole
 * wait_s). Plants are sorted by prefix; at most max (<= LAG_CLIENT_MAX_PLANTS) are kept,
 * the number in *n (a note in err if more were heard). Returns LAG_CLIENT_OK (also when
 * none was heard: *n = 0) or an error with a message in err. OUT: plants, n */
lag_result lag_client_discover(const char *url, double wait_s, double settle_s,
                               lag_client_plant *plants, int max, int *n, char *err, size_t errlen);

/* The plant a program talks to when the user named none: the only plant on the bus (of
 * `model`, unless NULL). Returns LAG_CLIENT_OK with *out; LAG_CLIENT_TIMEOUT when there is
 * none within wait_s (err says so, naming the plants of other models heard);
 * LAG_CLIENT_ERR_AMBIGUOUS when several run (err names them: prefix, model, run state);
 * another error. OUT: out */
lag_result lag_client_pick_plant(const char *url, const char *model, double wait_s,
                                 lag_client_plant *out, char *err, size_t errlen);

/* What the bus at url has instead of a plant on `prefix`, for the message of a program
 * that asked `prefix` and got no answer (a misspelt --prefix): listens up to wait_s
 * (lag_client_discover) and writes "no plant on prefix P; plants heard on URL: A
 * (model, mode, run state), B (...); did you mean A?" (the suggestion when a heard prefix
 * is P in other letter case, starts with P, or is at most 2 edits from it), or "no plant
 * heard on URL within S s (is lagsimd running on this LCM URL?)". Returns the number of
 * plants heard (>= 0), or an error with a message in out. OUT: out */
int lag_client_plants_instead(const char *url, const char *prefix, double wait_s, char *out,
                              size_t len);

/* Wall clock (CLOCK_MONOTONIC) in seconds, for controllers' own timing. */
double lag_client_now(void);

#ifdef __cplusplus
}
#endif
#endif
