/*
 * lagsim client library: talk to a lagsimd daemon over LCM, from C, C++ (extern "C"; and
 * lagsim_client.hpp over it) or any language with a C foreign-function interface.
 *
 *   char err[256];
 *   lag_client *c = lag_client_create(NULL, "DIPC", err, sizeof err); // LCM default URL
 *   lag_client_scene *sc = lag_client_scene_new();
 *   lag_client_wait_scene(c, 5.0, sc);           // sends DESCRIBE until the scene arrives
 *   lag_client_state st;
 *   while (lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK) { // each state once
 *       double u = ...;
 *       const char *name = "theta0";
 *       lag_client_send_command(c, st.sim_time, 1, &name, &u); // answers this state
 *   }
 *   lag_client_scene_free(sc);
 *   lag_client_destroy(c);
 *
 * Link: liblagsim_client.so.LAGSIM_CLIENT_ABI (or liblagsim_client.a), through pkg-config's
 * lagsim-client (docs/clients.md).
 *
 * One return convention (SQLite's): every function returning lag_result (lagsim/result.h)
 * returns LAG_CLIENT_OK (0) on success, LAG_CLIENT_TIMEOUT (> 0) when nothing arrived in
 * time (not an error), or a negative error code, with a message kept on the handle
 * (lag_client_errmsg). The library never prints and never exits.
 *
 * Threads: a handle is used by one thread at a time (callbacks run in that thread, from
 * inside lag_client_handle and the waits); different handles, and lag_client_discover,
 * lag_client_pick_plant and the functions without a handle, may be used from several
 * threads at once.
 *
 * The ABI (docs/clients.md, "The ABI"): this header, lagsim/version.h and lagsim/result.h are
 * the library's interface, stable within one LAGSIM_CLIENT_ABI (the SONAME's number):
 *   - the client's types are its own, never the server's: fixed-layout structs for what
 *     arrives with every state (lag_client_state, lag_client_reference; events, counters,
 *     plants), whose capacities are part of the ABI (8 joints, 16 parameters, names of 64
 *     bytes with their NUL), and opaque handles with accessors for the scene and the status,
 *     which grow with the daemon;
 *   - a struct of this header only grows at its end, never moves a field; every function
 *     that fills one takes its size (sizeof as the caller compiled it) and fills that
 *     much, so a program built against an older header keeps working with a newer library;
 *     a field the daemon's messages gain later becomes an appended field or an accessor;
 *   - no varargs, no struct returned by value, callbacks take a `void *user`: any FFI.
 * The core's lagsim.h (lag_sim, lag_model) is not part of it: the core is a static library
 * for in-tree tools, whose structs change with the core.
 *
 * Messages are decoded by lagsim's bounded wire module (no length from the bus is
 * trusted, nothing is allocated per message). A message that does not decode (wrong type,
 * truncated, hostile), holds more joints or longer names than the capacities, or carries
 * a NaN or an infinity is dropped and counted in lag_client_counters, never returned.
 * Commands and control requests are encoded by the same module: a NaN or infinite effort,
 * or a name of 64 bytes or more, is refused (LAG_CLIENT_ERR_ARG), never sent.
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
#include "lagsim/version.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Capacities: part of the ABI. */
#define LAG_CLIENT_MAX_JOINTS 8    /* joints of any message */
#define LAG_CLIENT_MAX_PARAMS 16   /* a scene's parameters */
#define LAG_CLIENT_NAME_LEN 64     /* names, kinds, modes, prefixes: 63 bytes + NUL */
#define LAG_CLIENT_TEXT_LEN 256    /* an event's detail: 255 bytes + NUL */
#define LAG_CLIENT_URL_LEN 320     /* a plant's URL, with its NUL */
#define LAG_CLIENT_DESCRIBE_S 0.25 /* the pace of DESCRIBE while a scene is awaited */

/* Result codes: the one space of lagsim/result.h (lag_result). The client's names stay,
 * as aliases of its codes, with the values they always had. lag_result_name,
 * lag_result_string and lag_result_exit (lagsim/result.h) are in this library too. */
#define LAG_CLIENT_OK LAG_OK
#define LAG_CLIENT_TIMEOUT LAG_TIMEOUT             /* nothing arrived in time (not an error);
                                                    * positive, 2: never reads as "true" */
#define LAG_CLIENT_ERR_ARG LAG_ERR_ARG             /* bad argument (message says which) */
#define LAG_CLIENT_ERR_LCM LAG_ERR_LCM             /* LCM could not be created, publish or
                                                      handle failed */
#define LAG_CLIENT_ERR_NOMEM LAG_ERR_NOMEM
#define LAG_CLIENT_ERR_AMBIGUOUS LAG_ERR_AMBIGUOUS /* several plants could be meant (message
                                                      names them) */

/* ---------------------------------------------------------------- versions */

/* The library's lagsim version, LAGSIM_VERSION_NUMBER as it was built (a program compares
 * it with the LAGSIM_VERSION_NUMBER it was compiled with: equal, or newer within the same
 * ABI), and its ABI number (LAGSIM_CLIENT_ABI, the SONAME's: liblagsim_client.so.N). */
int lag_client_version(void);
int lag_client_abi(void);

/* The two LCM URLs of the plant whose lcm.url is url (NULL or "": LCM_DEFAULT_URL, else
 * LCM's default), by the rule lag_client_create follows (docs/network.md): the state URL
 * (the URL itself, its port made explicit) and the command URL (the same group and options
 * on the next port; memq:// is both). For bindings that open LCM themselves. Returns
 * LAG_CLIENT_OK, or LAG_CLIENT_ERR_ARG with the reason in err for a URL a plant cannot
 * have. state_len, command_len: LAG_CLIENT_URL_LEN is enough. OUT: state_url, command_url */
lag_result lag_client_plant_urls(const char *url, char *state_url, size_t state_len,
                                 char *command_url, size_t command_len, char *err, size_t errlen);

/* ---------------------------------------------------------------- messages */

/* <PREFIX>_STATE: one state of the simulated model (joint_state_t). */
typedef struct lag_client_state {
    int64_t utime;                                     /* wall clock at publication, us */
    double sim_time;                                   /* s */
    int64_t step;                                      /* integrator ticks since reset */
    int64_t generation;                                /* the run and scene it belongs to */
    int32_t num_joints;
    int32_t reserved_;                                 /* 0 */
    char name[LAG_CLIENT_MAX_JOINTS][LAG_CLIENT_NAME_LEN];
    double position[LAG_CLIENT_MAX_JOINTS];            /* q: m or rad */
    double velocity[LAG_CLIENT_MAX_JOINTS];            /* qd: m/s or rad/s */
    double effort[LAG_CLIENT_MAX_JOINTS];              /* applied, N or N m */
} lag_client_state;

/* <PREFIX>_REFERENCE: what the joints with a reference should follow at a state's time
 * (reference_t): published just before the state with the same generation and sim_time
 * (lag_client_reference_of). */
typedef struct lag_client_reference {
    int64_t utime;
    double sim_time;                                   /* the state's */
    int64_t step;                                      /* the state's */
    int64_t generation;                                /* the state's */
    int32_t num_joints;                                /* joints with a reference */
    int32_t reserved_;                                 /* 0 */
    char name[LAG_CLIENT_MAX_JOINTS][LAG_CLIENT_NAME_LEN];
    double r[LAG_CLIENT_MAX_JOINTS];                   /* m or rad */
    double rdot[LAG_CLIENT_MAX_JOINTS];                /* m/s or rad/s */
    double rddot[LAG_CLIENT_MAX_JOINTS];               /* m/s^2 or rad/s^2 */
} lag_client_reference;

/* <PREFIX>_EVENT: something happened (event_t; the kinds are in docs/server.md). */
typedef struct lag_client_event {
    int64_t utime;
    double sim_time;
    int64_t step;
    double value;
    char kind[LAG_CLIENT_NAME_LEN];
    char joint[LAG_CLIENT_NAME_LEN];
    char detail[LAG_CLIENT_TEXT_LEN];
} lag_client_event;

/* The scene (<PREFIX>_SCENE, scene_t) and the daemon's status (<PREFIX>_STATUS,
 * status_t): opaque, read through the accessors below. */
typedef struct lag_client_scene lag_client_scene;
typedef struct lag_client_status lag_client_status;

typedef struct lag_client_counters {
    int64_t states, scenes, statuses, events;  /* messages received and kept (events: the
                                                * plant's own; a host directory's `plant`
                                                * announcements are passed to the event
                                                * callback, not counted: a silence is the
                                                * plant's) */
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
typedef void (*lag_client_reference_fn)(const lag_client_reference *ref, void *user);
typedef void (*lag_client_status_fn)(const lag_client_status *st, void *user);
typedef void (*lag_client_event_fn)(const lag_client_event *ev, void *user);
typedef void (*lag_client_scene_fn)(const lag_client_scene *sc, void *user);

/* ---------------------------------------------------------------- a handle */

/* Connects to the plant whose LCM URL is url (the daemon's lcm.url; NULL or "": LCM's
 * default, which honours LCM_DEFAULT_URL) and prefix: subscribes to <prefix>_REFERENCE,
 * _SCENE, _STATUS, _EVENT and, last, _STATE on that (state) URL (a state is never kept
 * without what was published just before it), and sends commands and control
 * requests to the plant's command URL, the same group on the next port. Returns NULL on
 * failure with a message in err (may be NULL). */
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
 * <prefix>_STATE, _STATUS, _EVENT, _SCENE, _REFERENCE): decoding, counters, callbacks, as
 * for the bus. For messages read elsewhere (a log file) and for tests. Returns
 * LAG_CLIENT_OK (kept or dropped: the counters say which) or LAG_CLIENT_ERR_ARG for
 * another channel. */
lag_result lag_client_feed(lag_client *c, const char *channel, const void *data, size_t len);

/* Callbacks (NULL to remove), called for every kept message from lag_client_handle; the
 * pointer passed is valid during the call only. */
void lag_client_on_state(lag_client *c, lag_client_state_fn fn, void *user);
void lag_client_on_reference(lag_client *c, lag_client_reference_fn fn, void *user);
void lag_client_on_status(lag_client *c, lag_client_status_fn fn, void *user);
void lag_client_on_event(lag_client *c, lag_client_event_fn fn, void *user);
void lag_client_on_scene(lag_client *c, lag_client_scene_fn fn, void *user);

/* Waits up to timeout_s (wall seconds) for the scene description, sending a DESCRIBE
 * request at once and every 0.25 s until it arrives (a scene already received counts).
 * Returns LAG_CLIENT_OK, LAG_CLIENT_TIMEOUT or an error. OUT: sc (a scene from
 * lag_client_scene_new, or NULL) */
lag_result lag_client_wait_scene(lag_client *c, double timeout_s, lag_client_scene *sc);

/* Waits up to timeout_s for a state not yet returned by this function (the newest one
 * if several arrived: a controller wants the latest). Returns LAG_CLIENT_OK with *st
 * filled, LAG_CLIENT_TIMEOUT, or an error. size: sizeof *st. OUT: st */
lag_result lag_client_wait_state(lag_client *c, double timeout_s, lag_client_state *st,
                                 size_t size);

/* Polling: the latest state / reference / status received, whether or not already
 * returned. False if none has arrived yet (or a size below the first version's).
 * A reference is published just before each state with the same generation and
 * sim_time, so when a state arrives its reference has arrived already, unless UDP lost
 * it: a reference belongs to a state when both match (after a reset or a SET sim_time
 * may repeat: the generation tells them apart); lag_client_reference_of checks it. A
 * scene without a reference publishes none. OUT: st, ref, out */
bool lag_client_latest_state(const lag_client *c, lag_client_state *st, size_t size);
bool lag_client_latest_reference(const lag_client *c, lag_client_reference *ref, size_t size);
bool lag_client_latest_status(const lag_client *c, lag_client_status *out);
/* The reference of state st: the latest reference when its generation and sim_time are
 * st's; false when there is none (lost, or a scene without a reference). OUT: ref */
bool lag_client_reference_of(const lag_client *c, const lag_client_state *st,
                             lag_client_reference *ref, size_t size);
/* The scene of the latest state's generation (the scene rule above; a scene of a later
 * generation that came since waits for its own state); before any state, the latest scene
 * received. False if none has arrived. OUT: sc */
bool lag_client_latest_scene(const lag_client *c, lag_client_scene *sc);

/* Publishes a command on <prefix>_COMMAND: efforts for n joints named in names (N or
 * N m), answering the state at sim_time (lockstep advances on it; pass the sim_time of
 * the state the effort was computed from), stamped with the generation of the latest
 * state (0 before any: a command that answers no state, which lockstep never takes).
 * Joints not named keep their effort. A non-finite effort or sim_time, or a name of 64
 * bytes or more, is refused. */
lag_result lag_client_send_command(lag_client *c, double sim_time, int n, const char *const *names,
                                   const double *effort);

/* Control requests on <prefix>_CONTROL (control_t). */
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
/* RESET (n = 0, q and qd NULL) or RESET_TO (n joints at q, qd) with flags, an OR of:
 *   LAG_CLIENT_RESET_SCENE  the scene file's values too, as lag_client_reset_scene (RESET
 *                           only: with n > 0 it is refused here)
 *   LAG_CLIENT_RESET_WAIT   then wait at t = 0 for the first command (run_state waiting,
 *                           as realtime.start: first_command): the state is republished,
 *                           and the first valid command or a RESUME starts the run, its
 *                           real-time deadlines counted from then. In the fault state too.
 * Without LAG_CLIENT_RESET_WAIT a reset keeps the run state (running or paused). Other
 * bits: LAG_CLIENT_ERR_ARG (the daemon refuses them too, with control_rejected). */
#define LAG_CLIENT_RESET_SCENE 1
#define LAG_CLIENT_RESET_WAIT 2
lag_result lag_client_reset_with(lag_client *c, int flags, int n, const double *q, const double *qd);

/* When the last message from the daemon was kept (a state or a copy of one, a scene, a
 * status, an event, a reference), on lag_client_now()'s clock; the handle's creation
 * before any. A controller ends when lag_client_now() - lag_client_heard(c) exceeds its
 * silence timeout: the daemon died, hung or never came (a plant that waits or is paused
 * still publishes its status, at realtime.status_hz). */
double lag_client_heard(const lag_client *c);

/* size: sizeof *out. OUT: out */
void lag_client_get_counters(const lag_client *c, lag_client_counters *out, size_t size);

/* Index of joint `name` in a state, in a reference (or -1: none; a reference: the scene
 * gives it no reference). */
int lag_client_state_joint(const lag_client_state *st, const char *name);
int lag_client_reference_joint(const lag_client_reference *ref, const char *name);

/* ---------------------------------------------------------------- the scene */

/* A scene of one's own (empty: model "", no joints), for lag_client_wait_scene and
 * lag_client_latest_scene to fill; NULL when out of memory. */
lag_client_scene *lag_client_scene_new(void);
void lag_client_scene_free(lag_client_scene *sc);
void lag_client_scene_copy(lag_client_scene *dst, const lag_client_scene *src);

/* Its fields (lcmtypes/scene_t.lcm). Out of range indices: NULL, NaN, false. */
const char *lag_client_scene_model(const lag_client_scene *sc);
const char *lag_client_scene_prefix(const lag_client_scene *sc);
int64_t lag_client_scene_generation(const lag_client_scene *sc);
int64_t lag_client_scene_utime(const lag_client_scene *sc);
int lag_client_scene_num_params(const lag_client_scene *sc);
const char *lag_client_scene_param_name(const lag_client_scene *sc, int i);
double lag_client_scene_param_value(const lag_client_scene *sc, int i);
/* The value of parameter `name`, or NaN. */
double lag_client_scene_param(const lag_client_scene *sc, const char *name);
int lag_client_scene_num_joints(const lag_client_scene *sc);
const char *lag_client_scene_joint_name(const lag_client_scene *sc, int i);
/* The index of joint `name`, or -1. */
int lag_client_scene_joint(const lag_client_scene *sc, const char *name);
bool lag_client_scene_actuated(const lag_client_scene *sc, int i);
double lag_client_scene_initial_q(const lag_client_scene *sc, int i);
double lag_client_scene_initial_qd(const lag_client_scene *sc, int i);
bool lag_client_scene_limit_on(const lag_client_scene *sc, int i);
double lag_client_scene_limit_lower(const lag_client_scene *sc, int i);
double lag_client_scene_limit_upper(const lag_client_scene *sc, int i);
double lag_client_scene_dt(const lag_client_scene *sc);             /* s */
double lag_client_scene_control_period(const lag_client_scene *sc); /* s */
double lag_client_scene_rate(const lag_client_scene *sc);
double lag_client_scene_command_timeout(const lag_client_scene *sc);
const char *lag_client_scene_integrator(const lag_client_scene *sc);
const char *lag_client_scene_mode(const lag_client_scene *sc);
const char *lag_client_scene_effects(const lag_client_scene *sc);   /* comma-separated */

/* ---------------------------------------------------------------- the model's dynamics */

/* The scene's model with the scene's parameters, as the daemon integrates it
 * (docs/models.md):
 *
 *     M(q) qdd + h(q, qd) = tau + (the effects' forces),   h = C(q, qd) qd + g(q),
 *
 * M the mass matrix (T = 1/2 qd^T M qd), C qd the Coriolis and centrifugal forces, g = dU/dq
 * the gravity forces, tau the efforts commanded. Computed by the core's own closed forms
 * (the daemon's step, bit for bit), for computed torque, feedforward and observers. The
 * effects (docs/effects.md: damping, friction, springs, limits, the floor, actuator lag,
 * disturbances, noise) are not in M nor h: a controller that wants them models them.
 * q and qd are in the scene's joint order (a state's: lag_client_scene_joint_name), n is
 * their number, which must be the model's (lag_client_scene_num_joints). A stick whose
 * floor lets it fly (joints x, phi, h) is the flying stick, with h the height of end A
 * (after end B landed the daemon measures h from end B: docs/models.md).
 * Return LAG_CLIENT_OK, or LAG_CLIENT_ERR_ARG with a message in err (may be NULL): a model
 * this library does not know, n not the model's, a parameter missing or out of its range,
 * a non-finite q or qd. OUT: M (n*n, row-major: M[i*n + j]), h (n) */
lag_result lag_client_model_mass(const lag_client_scene *sc, int n, const double *q, double *M,
                                 char *err, size_t errlen);
lag_result lag_client_model_bias(const lag_client_scene *sc, int n, const double *q,
                                 const double *qd, double *h, char *err, size_t errlen);

/* ---------------------------------------------------------------- the status */

/* A status of one's own, for lag_client_latest_status; NULL when out of memory. */
lag_client_status *lag_client_status_new(void);
void lag_client_status_free(lag_client_status *st);
void lag_client_status_copy(lag_client_status *dst, const lag_client_status *src);

/* Its fields by their names in lcmtypes/status_t.lcm, so that a field the daemon adds is
 * read without a new function: numbers (integers exact up to 2^53, booleans 0 or 1; NaN
 * for a name that is no numeric field) and texts (NULL for a name that is no text field).
 * The fields, in their order: lag_client_status_fields() of them, each with its name and
 * whether it is a text. */
double lag_client_status_number(const lag_client_status *st, const char *field);
const char *lag_client_status_text(const lag_client_status *st, const char *field);
int lag_client_status_fields(void);
const char *lag_client_status_field_name(int i);
bool lag_client_status_field_is_text(int i);

/* ---------------------------------------------------------------- finding plants */

#define LAG_CLIENT_MAX_PLANTS 1024 /* a lab host's plants (lagsimd --plants) */

/* One plant heard on the bus. */
typedef struct lag_client_plant {
    double sim_time;                     /* s, from its status */
    char prefix[LAG_CLIENT_NAME_LEN];    /* its channel prefix (lcm.prefix) */
    char model[LAG_CLIENT_NAME_LEN];     /* from its scene ("" if none came) */
    char mode[LAG_CLIENT_NAME_LEN];      /* realtime, fast or lockstep */
    char run_state[LAG_CLIENT_NAME_LEN]; /* from its status: running, paused, waiting, fault */
    char host[LAG_CLIENT_NAME_LEN];      /* who sends its messages: this host's name, or
                                          * the sender's IPv4 address ("" if not seen) */
    char url[LAG_CLIENT_URL_LEN];        /* its state URL (commands: the next port): the
                                          * URL it was heard on, or the one a host's
                                          * directory names for it (a `plant` event) */
} lag_client_plant;

/* Lists the plants on the bus at url (NULL or "": LCM's default, honouring
 * LCM_DEFAULT_URL): every <PREFIX>_STATE, _STATUS, _EVENT or _SCENE heard on the state
 * URL names a plant, which is then asked for its scene (DESCRIBE) and status (STATUS)
 * until they come. Listens at most wait_s wall seconds, and stops settle_s after the
 * first plant was heard once every plant heard is described (settle_s < 0: the whole
 * wait_s). Plants are sorted by prefix; at most max (<= LAG_CLIENT_MAX_PLANTS) are kept
 * in plants[], an array of elements of `size` bytes (sizeof *plants), the number in *n
 * (a note in err if more were heard). Returns LAG_CLIENT_OK (also when none was heard:
 * *n = 0) or an error with a message in err. OUT: plants, n */
lag_result lag_client_discover(const char *url, double wait_s, double settle_s,
                               lag_client_plant *plants, int max, size_t size, int *n,
                               char *err, size_t errlen);

/* The plant a program talks to when the user named none: the only plant on the bus (of
 * `model`, unless NULL). Returns LAG_CLIENT_OK with *out (size: sizeof *out);
 * LAG_CLIENT_TIMEOUT when there is none within wait_s (err says so, naming the plants of
 * other models heard); LAG_CLIENT_ERR_AMBIGUOUS when several run (err names them: prefix,
 * model, run state); another error. OUT: out */
lag_result lag_client_pick_plant(const char *url, const char *model, double wait_s,
                                 lag_client_plant *out, size_t size, char *err, size_t errlen);

/* What the bus at url has instead of a plant on `prefix`, for the message of a program
 * that asked `prefix` and got no answer (a misspelt --prefix): listens up to wait_s
 * (lag_client_discover) and writes "no plant on prefix P; plants heard on URL: A
 * (model, mode, run state), B (...); did you mean A?" (the suggestion when a heard prefix
 * is P in other letter case, starts with P, or is at most 2 edits from it), or "no plant
 * heard on URL within S s (is lagsimd running on this LCM URL?)". Returns the number of
 * plants heard (>= 0), or an error with a message in out. OUT: out */
int lag_client_plants_instead(const char *url, const char *prefix, double wait_s, char *out,
                              size_t len);

/* Where the plant on `prefix` runs when a program was given its prefix and no URL: a host
 * of plants (lagsimd --plants) runs each plant on a URL of its own and keeps a directory on
 * LCM's default bus (LCM_DEFAULT_URL, else LCM's default), where every 0.5 s each plant's
 * `plant` event names its state URL (docs/protocol.md, "A host's directory"). Listens to
 * <prefix>_EVENT, _STATE, _STATUS and _SCENE on that bus until the first message that
 * decides, at most wait_s (LAG_CLIENT_LOCATE_WAIT_S: a directory's two announcements), and
 * asks nothing of any plant. Returns:
 *   LAG_CLIENT_LOCATE_HOST  a `plant` event of prefix names another URL (a URL a plant can
 *                           have, not the default bus's): url is that state URL;
 *   LAG_CLIENT_LOCATE_HERE  the plant is on the default bus itself (its state, status or
 *                           scene, or an event of another kind, came first);
 *   LAG_CLIENT_LOCATE_NONE  nothing of prefix within wait_s (no plant yet, no directory, or
 *                           a directory that did not announce in time: a busy machine);
 *                           err (when given) says so, for the program to print;
 *   for both, url is the default bus's state URL, where a program waits for it;
 * or a negative lag_result with a message in err (may be NULL): LAG_CLIENT_ERR_ARG (a prefix
 * that is not 1 to 53 of [A-Za-z0-9_], a bad wait_s, url too short: LAG_CLIENT_URL_LEN is
 * enough, a bad LCM_DEFAULT_URL), LAG_CLIENT_ERR_LCM, LAG_CLIENT_ERR_NOMEM. OUT: url */
#define LAG_CLIENT_LOCATE_NONE 0
#define LAG_CLIENT_LOCATE_HERE 1
#define LAG_CLIENT_LOCATE_HOST 2
#define LAG_CLIENT_LOCATE_WAIT_S 1.0
int lag_client_locate(const char *prefix, double wait_s, char *url, size_t len, char *err,
                      size_t errlen);

/* Wall clock (CLOCK_MONOTONIC) in seconds, for controllers' own timing. */
double lag_client_now(void);

#ifdef __cplusplus
}
#endif
#endif
