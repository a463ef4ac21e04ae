/*
 * lagsim-eval's and lagsim-sweep's common part: the cases of an evaluation, one run of a
 * case against a controller, and what a run is reported as.
 *
 * A case is a list of scene overrides (the --set strings lagsimd takes), a duration and
 * optional bounds, read from the `cases:` key of a scene file or of a suite file:
 *
 *   cases:
 *     - name: tilt
 *       duration: 5
 *       set: ["initial.q=[0, 0.1]", "parameters.m1=0.2"]
 *       bounds: {theta: 0.5}          # the case fails once |theta| > 0.5
 *
 * A run: lagsimd on the scene and the case's overrides in lockstep, with --log to a file
 * of the run's own, on an LCM URL and a channel prefix of the run's own (no crosstalk),
 * against the controller command (a shell command; {prefix} and {url} in it are replaced
 * by the run's prefix and URL as they are, and LCM_DEFAULT_URL and LAGSIM_PREFIX are set
 * in its environment). The log is then read
 * with the bounded log reader and each joint's series handed to the metrics library
 * (metrics.h): nothing here computes a metric.
 */
#ifndef LAGSIM_EVAL_CASE_H
#define LAGSIM_EVAL_CASE_H

#include <stdio.h>
#include <stdbool.h>
#include <stddef.h>

#include <sys/types.h>

#include "eval_proc.h"
#include "lagsim_log.h"
#include "lagsim_port.h"
#include "lagsim_url.h"
#include "metrics.h"
#include "eval_watch.h"

#define EVAL_NAME_LEN 64
#define EVAL_SETS_MAX 32
#define EVAL_SET_LEN 512
#define EVAL_JOINTS_MAX 8
#define EVAL_CASES_MAX 256

typedef struct eval_case {
    char name[EVAL_NAME_LEN];
    double duration;                       /* sim s */
    int nsets;
    char set[EVAL_SETS_MAX][EVAL_SET_LEN]; /* "key=value", applied after the scene's file */
    int index;                             /* its place in the file's cases: */
    int set_line[EVAL_SETS_MAX], set_col[EVAL_SETS_MAX]; /* where each set string is */
    int nbounds;
    char bound_joint[EVAL_JOINTS_MAX][EVAL_NAME_LEN];
    double bound[EVAL_JOINTS_MAX];         /* |q| above it fails the case */
} eval_case;

/* Reads the `cases:` of a YAML file (a scene or a suite) into a new array of *n cases.
 * Returns 0 (with *n = 0 when the file has no `cases:`), or -1 with "file:line:column:
 * what was expected" in err. OUT: cases, n */
int eval_cases_load(const char *path, eval_case **cases, int *n, char *err, size_t errlen);

/* The scene's facts a run needs, from the scene file and the case's overrides, validated
 * as lagsimd validates them (so a bad override is reported before anything runs). */
typedef struct eval_scene {
    char model[EVAL_NAME_LEN];
    int nj;
    char joint[EVAL_JOINTS_MAX][EVAL_NAME_LEN];
    bool angular[EVAL_JOINTS_MAX];
    bool actuated[EVAL_JOINTS_MAX];
    double period;                          /* s, 1 / publish_hz */
    double q0[EVAL_JOINTS_MAX], qd0[EVAL_JOINTS_MAX]; /* initial state */
    bool has_reference;                     /* publishes <PREFIX>_REFERENCE */
    bool reference[EVAL_JOINTS_MAX];        /* joint j has one (the others: r = 0) */
} eval_scene;

/* The joints of a scene that has a reference for some but not all (those are scored
 * against r = 0), as "q2" or "theta1 and theta2" in buf; false (buf "") when every joint
 * or none has one. */
bool eval_scene_unreferenced(const eval_scene *sc, char *buf, size_t len);

/* Loads CONFIG with the overrides (nsets of them); -1 and the loader's message in err. */
int eval_scene_load(const char *config, const char *const *sets, int nsets,
                    eval_scene *sc /* OUT */, char *err, size_t errlen);

/* eval_scene_load with a case's overrides (and `extra` ones after them), read from the
 * case file `from`: an override the loader refuses is reported at its place in that file,
 * "FILE:LINE:COL: cases[i].set[j]: the loader's message". */
int eval_case_scene_load(const char *config, const char *from, const eval_case *c,
                         const char *const *extra, int nextra, eval_scene *sc /* OUT */,
                         char *err, size_t errlen);

/* ---------------------------------------------------------------- the keys the tools own */
/* The scene keys lagsim-eval and lagsim-sweep set on every daemon they start, each for a
 * guarantee of theirs (lockstep: numbers that do not depend on the machine's load; a bus
 * and channels of the run's own; nothing from or to the LAN unless --allow-lan). One
 * table: the daemons' --set strings (eval_owned_sets), the refusal of a case's set: or a
 * --vary that names one of them or a mapping above one (eval_owned_find), --help and
 * docs/evaluation.md (eval_lagsim_eval_owned) all come from it. The run's log is the
 * tools' too: lagsimd's --log, an option no scene key sets. */
typedef enum eval_owned_row {
    EVAL_OWN_MODE = 0,
    EVAL_OWN_START,
    EVAL_OWN_LOCKSTEP_TIMEOUT,
    EVAL_OWN_URL,
    EVAL_OWN_PREFIX,
    EVAL_OWN_ALLOW_LAN,
    EVAL_OWN_COUNT
} eval_owned_row;

typedef struct eval_owned_key {
    const char *key; /* the dotted path, as lagsimd --set names it */
    const char *why; /* what the tools set it to, and for what */
} eval_owned_key;

extern const eval_owned_key eval_owned_keys[EVAL_OWN_COUNT];

/* Whether the dotted key paths a[0, alen) and b[0, blen) (as --set names them) are one
 * key or one holds the other ("initial" holds "initial.q"), compared a segment at a time
 * as the loader grafts them: setting both, the later one overrides (part of) the other. */
bool eval_key_overlap(const char *a, size_t alen, const char *b, size_t blen);

/* The owned key that the dotted key path key[0, len) (as --set names it, without its
 * "=value" or "[i]") is, lies under, or holds (a mapping above it: "realtime", "lcm"),
 * compared a path segment at a time as the loader grafts it; -1 when none. */
int eval_owned_find(const char *key, size_t len);

/* 0 when the key path key[0, len) leaves every owned key alone; else -1 with why the
 * tools refuse it in why ("realtime holds realtime.mode, which lagsim-eval and
 * lagsim-sweep set themselves (lockstep: ...)"). */
int eval_owned_check(const char *key, size_t len, char *why, size_t n);

/* The owned keys' rows for --help: "  KEY  WHY" a line. */
void eval_owned_usage(FILE *f);

typedef struct eval_env {
    const char *lagsimd;     /* the daemon's path */
    const char *config;      /* the scene file */
    const char *controller;  /* shell command */
    const char *workdir;     /* where the run's log goes */
    char url[160];           /* the run's LCM URL */
    char prefix[64];         /* the run's channel prefix */
    bool allow_lan;          /* --allow-lan: the URL's ttl may be above 0 */
    double wall_timeout;     /* s a run may take before it is stopped (and failed) */
    bool verbose;            /* pass the daemon's and the controller's output through */
    const char *attach_log;  /* kept processes on a plant of a host already running
                              * (lagsim-sweep --plants-per-worker): its --log; NULL: the
                              * worker starts a daemon of its own */
    char who[96];            /* "lagsim-eval: case tilt": the start of a line saying that
                              * the plant still waits for its first answer (eval_watch);
                              * "": said nothing */
} eval_env;

/* ---------------------------------------------------------------- watching a run */
/* eval_watch.h: a client on a run's URL and prefix, and eval_say. */

/* The bus of the tools' runs: the multicast group and the options of --url, else of
 * LCM_DEFAULT_URL, else EVAL_DEFAULT_URL's; the ports a pair of the runs' own
 * (lag_port_take: no two evaluations or sweeps of this host share one, and none joins a
 * port a program of this host is bound to). */
#define EVAL_DEFAULT_URL "udpm://239.255.76.67?ttl=0&recv_buf_size=4194304"
typedef struct eval_bus {
    char base[256];   /* the URL the group and the options come from */
    const char *from; /* which: "--url", "LCM_DEFAULT_URL" or "the default URL" */
    lag_url u;        /* base, read under a scene's rules (u.query points into base) */
} eval_bus;

/* Reads the base URL (url: --url's, or NULL): udpm:// with only ttl and recv_buf_size
 * (a scene's rules), ttl above 0 only with allow_lan (--allow-lan). -1 with why, naming
 * where the URL came from, in err. OUT: b */
int eval_bus_init(eval_bus *b, const char *url, bool allow_lan, char *err, size_t errlen);

/* Takes a pair of ports of b's own, held in *l until lag_port_release (the caller's
 * lifetime), and writes its URL to url: checked to hold only characters that mean the
 * same inside any quotes ({url} is replaced by it as written, docs/evaluation.md). -1 with
 * why in err. OUT: l, url */
int eval_bus_take(const eval_bus *b, lag_port_lease *l, char *url, size_t len, char *err,
                  size_t errlen);

/* Whether s holds only characters that mean themselves inside '...' or "..." in a shell
 * and in the strings of Octave, MATLAB and Python: letters, digits and _ - . : / ? = &. */
bool eval_text_plain(const char *s);

/* Why a controller that ended before its run did may have been cut by the shell: when the
 * command has {url} outside quotes and the run's URL holds a character the shell reads
 * there ('&' ends the command, '?' is a pattern), a sentence saying so and to write
 * '{url}' into buf (starting "; "); else "". */
void eval_url_hint(const char *cmd, const char *url, char *buf, size_t len);

/* The --set strings a daemon of the tools gets for the owned keys, one a row in the
 * table's order: a daemon of one run (starts on the controller's first command), or one
 * kept for many runs (kept: starts paused, waits for a STEP's answer as long as it takes).
 * OUT: out */
void eval_owned_sets(const eval_env *env, bool kept, char out[EVAL_OWN_COUNT][EVAL_SET_LEN]);

/* A joint's samples as logged: t, q, r (0 without a reference channel) and u (the
 * effort held from t[k] to t[k+1]: the next state's effort). */
typedef struct eval_series {
    size_t n, cap;
    double *t;
    double *q[EVAL_JOINTS_MAX];
    double *r[EVAL_JOINTS_MAX];
    double *u[EVAL_JOINTS_MAX];
    bool has_reference;      /* the log had <PREFIX>_REFERENCE states */
} eval_series;

void eval_series_free(eval_series *s);

#define EVAL_OUTPUT_LEN 2048

typedef struct eval_result {
    bool failed;
    char reason[256];        /* why it failed ("" if it did not) */
    char output[EVAL_OUTPUT_LEN]; /* a failed run's last lines of the controller's and
                              * lagsimd's stderr, "| " before each, under a line naming
                              * whose ("" if none, or with -v: they passed through) */
    int nj;
    lag_metrics m[EVAL_JOINTS_MAX];
    double max_abs_q[EVAL_JOINTS_MAX];
    double t_end;            /* last state's sim time */
    size_t states;
} eval_result;

/* The stderr files of a run's (or a kept pair's) controller and lagsimd, without -v:
 * <workdir>/<prefix>.controller.stderr, .lagsimd.stderr. */
void eval_stderr_paths(const eval_env *env, char *controller, char *daemon, size_t len);
/* Appends to out (cap bytes, NUL-terminated) the last lines (at most 8) of file `path`,
 * written by `who`: "<who>'s stderr, its last N lines:\n| ...\n"; nothing when the file
 * is empty or absent. Control bytes become spaces, a line is cut at 200 bytes. */
void eval_stderr_tail(const char *path, const char *who, char *out, size_t cap);

/* Runs a case (its overrides and `extra` ones after them) and fills res and, when s is
 * not NULL, the series. Without -v the controller's and lagsimd's stderr go to files of
 * the run (eval_stderr_paths), whose last lines res->output holds when the run failed; the
 * files are removed. Returns 0 when the run could be evaluated (failed or not), -1
 * with a message in err when it could not be run at all. */
int eval_run(const eval_env *env, const eval_case *c, const char *const *extra, int nextra,
             const eval_scene *sc, eval_result *res /* OUT */, eval_series *s /* OUT */,
             char *err, size_t errlen);

/* Reads a run's log (path) for a scene: each joint's series, and whether a fault or an
 * early stop happened (res->failed, res->reason). OUT: s, res */
int eval_read_log(const char *path, const char *prefix, const eval_scene *sc, double duration,
                  eval_series *s, eval_result *res, char *err, size_t errlen);

/* Metrics of each joint and the bounds of the case: fills res->m, res->max_abs_q, and
 * fails res on a bound passed. Returns -1 with a message when a series is no run. */
int eval_score(const eval_series *s, const eval_case *c, const eval_scene *sc,
               eval_result *res, char *err, size_t errlen);

/* Whether a requirement holds for a result; every term that fails written to why, each
 * with its value ("theta.settle < 2 fails (5.5); x.settle < 2 fails (5.85)"): as many as
 * fit in len bytes, then how many more fail. */
bool eval_require_holds(const lag_require *req, const eval_scene *sc, const eval_result *res,
                        char *why, size_t len);

/* -1 and a message when a requirement names a joint the scene does not have (the caller
 * says it is --require's). */
int eval_require_check(const lag_require *req, const eval_scene *sc, char *err, size_t len);

/* A number for tables and CSVs: %.6g, "nan" for none. */
void eval_fmt(double v, char *buf, size_t len);

/* Runs gnuplot on the script gp; 0, or -1 after saying it failed (prefixed with prog). */
int eval_gnuplot(const char *prog, const char *gp);

/* The lagsimd beside the running program (/proc/self/exe), else "lagsimd" on PATH. */
void eval_default_lagsimd(char *buf, size_t len);

/* An output file opened by the rules of every lagsim output (lagsim_out.h: no symbolic
 * link, never one of the nin inputs, an existing file only with force); NULL after saying
 * why on stderr, prefixed with prog. */
FILE *eval_open_out(const char *prog, const char *what, const char *path, bool force,
                    const char *const *in, int nin);

/* The words of a controller command, split as sh would (blanks and ; & | < > ( ) end a
 * word; '...', "..." and \ quote), that name an existing regular file: the files the
 * command reads (a script, its data), which no output may be, with --force either. At
 * most max, into out; returns how many. */
#define EVAL_CMD_FILES_MAX 16
int eval_command_files(const char *cmd, char (*out)[1024], int max);

/* ---------------------------------------------------------------- a run's records */
/* What a run's log records make: each joint's series, and why the run failed. Fed the
 * records of a run's own log (eval_read_log) or, from a daemon kept for many runs, those
 * after its run's RESET_TO (eval_worker.c): one reading of the records for both. */
typedef struct eval_take {
    char ch_state[96], ch_event[96], ch_ref[96], ch_control[96];
    const eval_scene *sc;
    eval_series *s;
    eval_result *res;
    double ref_time, ref_r[EVAL_JOINTS_MAX]; /* the last reference and its sim time */
    double t_stop;           /* states after this sim time are not the run's */
    bool per_reset;          /* the run starts again at each RESET_TO */
    bool started;            /* the records are the run's */
    bool fault;              /* a numeric_fault event was taken */
    bool stopped_at_duration;
    bool oom;
} eval_take;

void eval_take_init(eval_take *tk, const char *prefix, const eval_scene *sc, eval_series *s,
                    eval_result *res);
/* A daemon kept for many runs: the run is what follows the last RESET_TO taken. */
void eval_take_from_last_reset(eval_take *tk);
void eval_take_record(eval_take *tk, const lag_log_record *rec);

/* ---------------------------------------------------------------- for eval_worker.c */
double eval_now(void);
double eval_now_wall(void); /* s since the epoch */
void eval_sleep(double s);
/* starting, waiting for and stopping processes: eval_proc.h */
/* cmd with {prefix} and {url} replaced by env's, as they are; -1 with why in err */
int eval_expand(const char *cmd, const eval_env *env, char *out, size_t len, char *err,
                size_t errlen);
int eval_series_grow(eval_series *s, int nj);
void eval_fail(eval_result *res, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* ---------------------------------------------------------------- reused processes */
/* One daemon and one controller kept for many runs (lagsim-sweep without --restart): the
 * daemon starts paused in lockstep with the scene and the case's overrides, logging to a
 * file of the worker's own, and the controller designs itself against that scene once. A
 * run is then SET of each varied key under parameters, effects or reference, RESET_TO its
 * initial state and STEP of its periods; its states are taken from the bus, and read from
 * the log instead whenever the bus lost any of them (or the run faulted or stalled), so a
 * run's numbers are those of a daemon started for it with the same values set live. */
typedef struct eval_worker eval_worker;

/* NULL with why in err when the pair cannot run: *controller says that the controller is
 * why (it ended before it answered its first state, or never answered it: the daemon's
 * status says what it waits for), which no later pair would do otherwise. */
eval_worker *eval_worker_start(const eval_env *env, const eval_case *c, const eval_scene *sc,
                               bool *controller, char *err, size_t errlen);
/* One run: sets are "key=value" (initial.* ones skipped: q0/qd0 carry them), q0 and qd0
 * the run's initial state. Returns 0 when the run could be evaluated (failed or not), -1
 * with a message when the worker is lost (stop it and start another). OUT: res */
int eval_worker_run(eval_worker *w, const eval_case *c, const char *const *sets, int nsets,
                    const double *q0, const double *qd0, eval_result *res, char *err,
                    size_t errlen);
/* Runs since the worker started (its log grows with them). */
long eval_worker_runs(const eval_worker *w);
/* Whether its controller has ended (a run failed saying so): the pair cannot go on. */
bool eval_worker_lost(const eval_worker *w);
void eval_worker_stop(eval_worker *w);

#endif
