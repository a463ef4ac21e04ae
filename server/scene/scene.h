/*
 * A scene: everything a YAML scene file says. The core part (lag_sim_def) plus the
 * daemon's settings (output rate, real-time pacing, LCM). Pure C: scene_load.c reads it
 * with libyaml (scene_yaml.c: the YAML tree; scene_schema.c: the keys, their ranges and
 * relations); nothing in this header depends on libyaml.
 */
#ifndef LAGSIM_SCENE_H
#define LAGSIM_SCENE_H

#include "lagsim/lagsim.h"
#include "reference.h"

typedef enum lag_rt_mode {
    LAG_RT_REALTIME = 0, /* paced against CLOCK_MONOTONIC at realtime.rate */
    LAG_RT_FAST,         /* as fast as possible, still serving LCM */
    LAG_RT_LOCKSTEP      /* one control period per answering command */
} lag_rt_mode;

/* How the real-time server starts (realtime.start). */
typedef enum lag_rt_start {
    LAG_RT_START_RUNNING = 0,   /* sim time advances from the start */
    LAG_RT_START_PAUSED,        /* paused at t = 0 until RESUME (or STEP) */
    LAG_RT_START_FIRST_COMMAND  /* waiting at t = 0 until the first valid command (or
                                   RESUME): the default in lockstep */
} lag_rt_start;

/* The longest lcm.prefix: LCM channel names have at most 63 bytes, and the longest
 * suffix of a plant's channels (_REFERENCE) has 10. */
#define LAG_SCENE_PREFIX_MAX 53

/* The scene's `reference:`: what each joint should follow (server/eval/reference.h),
 * published on <PREFIX>_REFERENCE beside every state. Not the core's business: the plant
 * does not see it. n = 0: no reference, nothing published. */
typedef struct lag_scene_reference {
    int n;                   /* joints with a reference */
    bool on[LAG_MAX_DOF];    /* joint i has one: joint[i] holds it (checked) */
    lag_reference joint[LAG_MAX_DOF];
} lag_scene_reference;

/* Every this many periods the daemon estimates the error the integration adds (a shadow
 * run of the period, lag_sim_shadow_error), when a scene asks for integrator.error and
 * does not say integrator.estimate_every: it then adds 3 to 5 % to a period's work
 * (docs/accuracy.md, bench/live_error_cost.sh). */
#define LAG_SCENE_ESTIMATE_EVERY 50

typedef struct lag_scene {
    char path[512];          /* file it was read from ("" if built in code) */
    lag_sim_def sim;         /* model, parameters, integrator, initial state */
    struct {
        double error;        /* integrator.error: 0, or the largest difference from the
                                exact q (m or rad) over `horizon` that the run may have:
                                lagsimd then chooses sim.integrator's method and dt (and
                                ticks_per_period) itself, measuring on this scene */
        double horizon;      /* integrator.horizon, s of sim time; default 1 */
        int estimate_every;  /* integrator.estimate_every: the live error estimate runs
                                every this many periods, 0: never; -1: not given (see
                                lag_scene_estimate_every) */
    } accuracy;
    double publish_hz;       /* state output rate = control rate, Hz; default 100 */
    int64_t ticks_per_period;/* (1/publish_hz) / dt, an integer (validated) */
    struct {
        lag_rt_mode mode;        /* default realtime */
        lag_rt_start start;      /* default: first_command in lockstep, else running */
        double rate;             /* sim seconds per wall second, default 1.0 */
        double command_timeout;  /* sim s; a command older than this is zeroed; default 0.5 */
        double lockstep_timeout; /* wall s; lockstep waits this long for a command; 1.0 */
        double lockstep_retry;   /* wall s; lockstep publishes the state waited on again
                                    this often until a command answers it (a lost state or
                                    command costs one retry, not a timeout); 0.02 */
        double status_hz;        /* status publication rate, Hz; default 5 */
        /* N or N m per coordinate: a command whose |effort| on an actuated joint exceeds
         * this is refused as a whole (counted like any bad command), never clamped:
         * saturation that belongs to the plant is effects.actuator.<joint>.max.
         * Default LAG_SCENE_EFFORT_LIMIT on actuated joints, 0 on the others. */
        double effort_limit[LAG_MAX_DOF];
    } realtime;
    struct {
        char url[256];           /* "" = LCM's default (honours LCM_DEFAULT_URL) */
        char prefix[64];         /* channel prefix, 1 to LAG_SCENE_PREFIX_MAX characters;
                                    default the model name in capitals */
        bool allow_lan;          /* the scene means its traffic to leave this host: a
                                    multicast ttl above 1 is accepted; default false */
        int ttl;                 /* the multicast ttl the URL asks for (0 for "", memq://
                                    or a URL without ttl=), checked by the loader */
    } lcm;
    lag_scene_reference reference; /* reference: per joint (none by default) */
} lag_scene;

/* What a scene may be, at most. A scene file is a few hundred bytes and about a hundred
 * nodes; these limits are far above that and keep a hostile file's cost small: it is
 * refused after at most LAG_SCENE_MAX_BYTES read and LAG_SCENE_MAX_NODES nodes built,
 * with an error that names the limit. */
#define LAG_SCENE_MAX_BYTES (1024 * 1024) /* file (or one --set value), bytes */
#define LAG_SCENE_MAX_NODES 10000         /* scalars, mappings and sequences in one source */
#define LAG_SCENE_MAX_ITEMS 1000          /* keys of one mapping, items of one sequence */
#define LAG_SCENE_MAX_DEPTH 32            /* nesting of mappings and sequences */
#define LAG_SCENE_MAX_SCALAR 4096         /* bytes of one scalar (key or value) */

/* The longest sim time a scene or the command line may name (a disturbance's t, a
 * force's duration, realtime.command_timeout, lagsimd --duration): the core's
 * (LAG_TIME_MAX, about 31.7 years). With integrator.dt >= 1e-6 s any such time is at most
 * 1e15 ticks: an exact integer in a double, far from int64's limit, so no conversion to
 * ticks can overflow. */
#define LAG_SCENE_MAX_TIME LAG_TIME_MAX

/* Default realtime.effort_limit, N or N m: far above what any controller of these models
 * commands, far below where the arithmetic of a step stops being finite. */
#define LAG_SCENE_EFFORT_LIMIT 1e6

/* Defaults for a model kind: lag_default_sim_def plus the daemon defaults above. */
void lag_scene_default(lag_scene *sc, lag_model_kind kind);

/* The most ticks a control period may take in a scene built in code (a scene file allows
 * far fewer): sim time tick * dt is exact up to 2^53. */
#define LAG_SCENE_PERIOD_TICKS_MAX (1LL << 53)
/* The scene-level rules, whoever built the scene (the loader, after it converted a file,
 * or code): publish_hz > 0 and finite with ticks_per_period 1 to
 * LAG_SCENE_PERIOD_TICKS_MAX; realtime.rate and realtime.status_hz > 0 and finite;
 * realtime.lockstep_retry and realtime.lockstep_timeout >= 0 and finite;
 * realtime.command_timeout >= 0 (inf: never); lcm.prefix of 1 to LAG_SCENE_PREFIX_MAX
 * characters. A scene file's keys have narrower ranges, checked first (what a file may
 * say); these are what lagsimd needs. Returns LAG_OK, or LAG_ERR_ARG with the first fault
 * in d (field: the scene key, e.g. "realtime.rate"). OUT: d */
lag_result lag_scene_check(const lag_scene *sc, lag_diag *d);
/* The rule on the length n of a channel prefix (lcm.prefix), alone: the loader applies it
 * to the prefix as the file gives it, before it is stored. OUT: d */
lag_result lag_scene_check_prefix_len(size_t n, lag_diag *d);

/* Loads a YAML scene file, then applies `nsets` overrides "dotted.key.path=yaml value"
 * (same validation as the file). Returns LAG_OK, or LAG_ERR_SCENE (LAG_ERR_ARG for a
 * NULL path or sc) and writes "file:line:column: what was expected" (or "--set key: ...")
 * into err. OUT: sc */
lag_result lag_scene_load(const char *path, const char *const *sets, int nsets, lag_scene *sc,
                          char *err, size_t errlen);

/* Reads a scene file as lag_scene_load does (at most LAG_SCENE_MAX_BYTES, the same
 * errors), so that a caller can keep the bytes a scene came from (lagsimd does, to
 * validate a change made while running against the same source). On success *text is a
 * new buffer of *len bytes (free it); else LAG_ERR_SCENE (LAG_ERR_ARG for NULL arguments)
 * with the message in err. OUT: text, len */
lag_result lag_scene_read(const char *path, char **text, size_t *len, char *err, size_t errlen);

/* The same for a scene already in memory: `name` stands for the file in messages, `text`
 * holds `len` bytes (not NUL-terminated; at most LAG_SCENE_MAX_BYTES). Returns what
 * lag_scene_load does. OUT: sc */
lag_result lag_scene_load_buffer(const char *name, const char *text, size_t len,
                                 const char *const *sets, int nsets, lag_scene *sc, char *err,
                                 size_t errlen);

/* The periods between two live error estimates of SC: integrator.estimate_every when
 * given, else LAG_SCENE_ESTIMATE_EVERY with integrator.error and 0 (none) without. */
int lag_scene_estimate_every(const lag_scene *sc);
const char *lag_rt_mode_name(lag_rt_mode m);
const char *lag_rt_start_name(lag_rt_start s);  /* "running", "paused", "first_command" */

/* Reads a number written as a plain decimal, the only way a scene (or lagsimd's command
 * line) writes one: [-+]? (digits [. digits?] | . digits) ([eE] [-+]? digits)?, finite.
 * Not "0x1p-10", "inf", "nan", "1_000" or "1e999", whatever strtod makes of them.
 * Returns LAG_OK, LAG_ERR_SYNTAX if s is not a plain decimal, LAG_ERR_RANGE if it is one
 * too large for a double (1e999). OUT: v */
lag_result lag_scene_read_decimal(const char *s, double *v);

/* Does `key` (a dotted path as --set takes it) change while lagsimd runs, by control SET?
 * The keys under parameters, effects and reference. */
bool lag_scene_key_live(const char *key);

/* Checks an LCM URL the way the loader does for lcm.url (and lagsimd for
 * LCM_DEFAULT_URL): "" (LCM's default), memq:// (in-process, for tests) or
 * udpm://GROUP[:PORT][?ttl=N&recv_buf_size=BYTES] with GROUP a dotted IPv4 multicast
 * address (224.0.0.0/4), PORT 1..65534 (a plant's commands go to PORT + 1), each
 * option at most once, ttl 0..255 and above 0 only with allow_lan, recv_buf_size
 * 4096..268435456. Every other provider (file://
 * writes files, tcpq:// opens connections) is refused. Returns LAG_OK, or LAG_ERR_SCENE
 * with what was expected in err. OUT: ttl (0 when the URL does not set it) */
lag_result lag_scene_check_url(const char *url, bool allow_lan, int *ttl, char *err, size_t errlen);

#endif
