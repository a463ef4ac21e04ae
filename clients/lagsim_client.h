/*
 * lagsim client library: talk to a lagsimd daemon over LCM from C.
 *
 *   char err[256];
 *   lag_client *c = lag_client_create(NULL, "DIPC", err, sizeof err); // LCM default URL
 *   lag_client_scene sc;
 *   lag_client_wait_scene(c, 5.0, &sc);          // sends DESCRIBE until the scene arrives
 *   lag_client_state st;
 *   while (lag_client_wait_state(c, 2.0, &st) == 1) {  // each new state, once
 *       double u = ...;
 *       const char *name = "theta0";
 *       lag_client_send_command(c, st.sim_time, 1, &name, &u); // answers this state
 *   }
 *   lag_client_destroy(c);
 *
 * Messages are copied into fixed-size structs (no LCM memory leaks into user code).
 * Odd messages (undecodable payloads, too many joints, over-long names) are dropped and
 * counted in lag_client_counters, never fatal. Like SQLite, functions return result codes
 * and the last error message is kept on the handle (lag_client_errmsg); the library
 * never prints and never exits. Not thread-safe: use one handle per thread.
 *
 * Lockstep contract (realtime.mode: lockstep): the daemon advances one control period
 * only when a command whose sim_time equals the last published state's sim_time arrives,
 * so answer every state with lag_client_send_command(c, state.sim_time, ...).
 */
#ifndef LAGSIM_CLIENT_H
#define LAGSIM_CLIENT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_CLIENT_MAX_JOINTS 8
#define LAG_CLIENT_MAX_PARAMS 16
#define LAG_CLIENT_NAME_LEN 32

/* Result codes. */
enum {
    LAG_CLIENT_OK = 0,
    LAG_CLIENT_TIMEOUT = 1,      /* nothing arrived in time (not an error of the bus) */
    LAG_CLIENT_ERR_ARG = -1,     /* bad argument (message says which) */
    LAG_CLIENT_ERR_LCM = -2,     /* LCM could not be created, publish or handle failed */
    LAG_CLIENT_ERR_NOMEM = -3
};

/* The daemon's scene description (lagsim_scene_t), copied. */
typedef struct lag_client_scene {
    int64_t utime;
    char model[LAG_CLIENT_NAME_LEN];       /* stick, manipulator or dipc */
    char prefix[64];
    int num_params;
    char param_name[LAG_CLIENT_MAX_PARAMS][LAG_CLIENT_NAME_LEN];
    double param_value[LAG_CLIENT_MAX_PARAMS];
    int num_joints;
    char joint_name[LAG_CLIENT_MAX_JOINTS][LAG_CLIENT_NAME_LEN];
    bool actuated[LAG_CLIENT_MAX_JOINTS];
    double initial_q[LAG_CLIENT_MAX_JOINTS];
    double initial_qd[LAG_CLIENT_MAX_JOINTS];
    double dt;                             /* integrator tick, s */
    double control_period;                 /* state period = lockstep period, s */
    char integrator[LAG_CLIENT_NAME_LEN];
    char mode[LAG_CLIENT_NAME_LEN];        /* realtime, fast or lockstep */
    double rate;
    double command_timeout;                /* s of sim time */
} lag_client_scene;

/* One joint state (lagsim_joint_state_t), copied. */
typedef struct lag_client_state {
    int64_t utime;     /* daemon's wall clock at publication, us */
    double sim_time;   /* s */
    int64_t step;      /* integrator ticks since the last reset */
    int num_joints;
    char name[LAG_CLIENT_MAX_JOINTS][LAG_CLIENT_NAME_LEN];
    double position[LAG_CLIENT_MAX_JOINTS];
    double velocity[LAG_CLIENT_MAX_JOINTS];
    double effort[LAG_CLIENT_MAX_JOINTS];
} lag_client_state;

/* The most useful fields of lagsim_status_t, copied. */
typedef struct lag_client_status {
    int64_t utime;
    double sim_time, wall_time, rtf, energy;
    int64_t step, overruns;
    double step_time_max_us, step_time_mean_us;
    char integrator[LAG_CLIENT_NAME_LEN], mode[LAG_CLIENT_NAME_LEN];
    char run_state[LAG_CLIENT_NAME_LEN];   /* running, paused or fault */
    int64_t commands_accepted;
    int64_t rejected_unknown_joint, rejected_unactuated, rejected_nonfinite;
    int64_t rejected_bad_length, rejected_undecodable, controls_rejected;
    bool watchdog_tripped;
    int64_t watchdog_trips, lockstep_timeouts, numeric_faults;
} lag_client_status;

/* One event (lagsim_event_t), copied; strings truncated to fit. */
typedef struct lag_client_event {
    int64_t utime;
    double sim_time;
    int64_t step;
    char kind[LAG_CLIENT_NAME_LEN];
    char joint[LAG_CLIENT_NAME_LEN];
    double value;
    char detail[256];
} lag_client_event;

/* What the handle has seen. */
typedef struct lag_client_counters {
    int64_t states, scenes, statuses, events;  /* messages received and kept */
    int64_t dropped;                           /* undecodable or out-of-range messages */
    int64_t commands_sent, controls_sent;
} lag_client_counters;

typedef struct lag_client lag_client;

typedef void (*lag_client_state_fn)(const lag_client_state *st, void *user);
typedef void (*lag_client_status_fn)(const lag_client_status *st, void *user);
typedef void (*lag_client_event_fn)(const lag_client_event *ev, void *user);

/* Connects to LCM at url (NULL or "": LCM's default, which honours LCM_DEFAULT_URL) and
 * subscribes to <prefix>_STATE, _STATUS, _EVENT, _SCENE. Returns NULL on failure with a
 * message in err (may be NULL). */
lag_client *lag_client_create(const char *url, const char *prefix, char *err, size_t errlen);
void lag_client_destroy(lag_client *c);
/* Message of the last failure on this handle ("" if none). */
const char *lag_client_errmsg(const lag_client *c);
/* The LCM file descriptor, for poll()/select() in the caller's loop: when readable, call
 * lag_client_handle(c, 0). */
int lag_client_fileno(const lag_client *c);

/* Handles at most one incoming message, waiting up to timeout_ms (0: do not wait).
 * Returns 1 if a message was handled, 0 on timeout, < 0 on error. Callbacks run from
 * inside this call. */
int lag_client_handle(lag_client *c, int timeout_ms);

/* Callbacks (NULL to remove), called for every kept message from lag_client_handle. */
void lag_client_on_state(lag_client *c, lag_client_state_fn fn, void *user);
void lag_client_on_status(lag_client *c, lag_client_status_fn fn, void *user);
void lag_client_on_event(lag_client *c, lag_client_event_fn fn, void *user);

/* Waits up to timeout_s (wall seconds) for the scene description, sending a DESCRIBE
 * request at once and every 0.25 s until it arrives (a scene already received counts).
 * Returns LAG_CLIENT_OK, LAG_CLIENT_TIMEOUT or an error. OUT: sc */
int lag_client_wait_scene(lag_client *c, double timeout_s, lag_client_scene *sc);

/* Waits up to timeout_s for a state not yet returned by this function (the newest one
 * if several arrived: a controller wants the latest). Returns 1 with *st filled,
 * 0 on timeout, < 0 on error. OUT: st */
int lag_client_wait_state(lag_client *c, double timeout_s, lag_client_state *st);

/* Polling: the latest state / status received, whether or not already returned.
 * Return false if none has arrived yet. OUT: st */
bool lag_client_latest_state(const lag_client *c, lag_client_state *st);
bool lag_client_latest_status(const lag_client *c, lag_client_status *st);

/* Publishes a command on <prefix>_COMMAND: efforts for n joints named in names (N or
 * N m), answering the state at sim_time (lockstep advances on it; pass the sim_time of
 * the state the effort was computed from). Joints not named keep their effort. */
int lag_client_send_command(lag_client *c, double sim_time, int n, const char *const *names,
                            const double *effort);

/* Control requests on <prefix>_CONTROL (lagsim_control_t). */
int lag_client_pause(lag_client *c);
int lag_client_resume(lag_client *c);
int lag_client_step(lag_client *c, int64_t count);           /* control periods, >= 1 */
int lag_client_reset(lag_client *c);                         /* scene's initial state */
int lag_client_reset_to(lag_client *c, int n, const double *q, const double *qd);
int lag_client_request_status(lag_client *c);
int lag_client_request_describe(lag_client *c);

void lag_client_get_counters(const lag_client *c, lag_client_counters *out);

/* Index of joint `name` in the scene (or -1); value of parameter `name` (or NaN). */
int lag_client_scene_joint(const lag_client_scene *sc, const char *name);
double lag_client_scene_param(const lag_client_scene *sc, const char *name);
/* Index of joint `name` in a state (or -1). */
int lag_client_state_joint(const lag_client_state *st, const char *name);

/* Wall clock (CLOCK_MONOTONIC) in seconds, for controllers' own timing. */
double lag_client_now(void);

#ifdef __cplusplus
}
#endif
#endif
