/*
 * What every C example controller shares: options, connect, wait for the scene, the
 * model from the scene, answering states until the run ends, a summary line. The same
 * contract as the Python, Lua and Java examples' controller setup.
 *
 *   lag_ctl ctl;
 *   lag_ctl_init(&ctl, "dipc_lqr", "DIPC");
 *   double r = 1.0;
 *   const lag_ctl_option mine[] = {{"r", "R", "input weight (default 1)", lag_ctl_positive, &r}};
 *   int rc = lag_ctl_parse(&ctl, argc, argv, "Balances the DIPC.", mine, 1);
 *   if (rc >= 0) return rc;                       // --help (0) or a usage error (2)
 *   if (lag_ctl_start(&ctl, "dipc")) return lag_ctl_fail(&ctl); // connect, scene, model
 *   lag_client_state st;
 *   while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK)   // each newest state once
 *       // ... the law, from st and ctl.scene / ctl.model ...
 *       lag_ctl_command(&ctl, &st, 1, names, &u);             // answers it
 *   return lag_ctl_finish(&ctl, "states=%lld", (long long)ctl.states);
 *
 * Options every controller takes (getopt_long; a value that is not a number where one
 * is expected, a number out of range, an unknown option or a stray argument is a usage
 * error: a message, exit 2):
 *   --prefix P      channel prefix (default: the only plant of the controller's model on
 *                   the bus; none yet: the model in capitals, waited for; several: they
 *                   are named, exit 2)
 *   --url URL       LCM URL (default: LCM's default, which honours LCM_DEFAULT_URL)
 *   --duration S    end after S s of sim time from the first state (default 0: until the
 *                   daemon stops)
 *   --timeout S     wall s without a scene, or without any message from the daemon once
 *                   running, before ending (default 5)
 *   --trace FILE    one line per answered state: sim time, positions, velocities,
 *                   efforts sent, each %.17g
 *   -q, --quiet     design and summary only
 *   -h, --help      usage
 * A run ends when the daemon publishes its `stop` event, when nothing came from it (no
 * state, status or event) for --timeout wall seconds, after --duration, or on SIGINT or
 * SIGTERM; ctl.end says which ("stop", "silence", "duration", "signal"). Exit status: 0
 * for all of these; 1 when no scene came, the scene is another model's, its parameters
 * are invalid, or the client failed; 2 bad usage.
 */
#ifndef LAGSIM_CONTROLLER_H
#define LAGSIM_CONTROLLER_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "lagsim/lagsim.h"
#include "lagsim_client.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Sets *target from an option's value (NULL for a flag); 0, or -1 with a message in err
 * (the option's name is added in front). */
typedef int (*lag_ctl_setter)(const char *value, void *target, char *err, size_t errlen);

/* A controller's own option. */
typedef struct lag_ctl_option {
    const char *name;      /* long name, without "--" */
    const char *metavar;   /* the value's name in the usage ("S"); NULL: a flag */
    const char *help;
    lag_ctl_setter set;
    void *target;
    char letter;           /* also -letter (0: long name only) */
} lag_ctl_option;

/* Ready-made setters: a finite double (> 0, >= 0, any) into a double; true into a bool. */
int lag_ctl_positive(const char *value, void *target, char *err, size_t errlen);
int lag_ctl_nonnegative(const char *value, void *target, char *err, size_t errlen);
int lag_ctl_number(const char *value, void *target, char *err, size_t errlen);
int lag_ctl_flag(const char *value, void *target, char *err, size_t errlen);
/* An LQR's gain: "discrete" (0) or "continuous" (1) into an int. */
int lag_ctl_gain_kind(const char *value, void *target, char *err, size_t errlen);
/* n comma-separated finite numbers into double[n]: used by setters of lists. */
int lag_ctl_parse_list(const char *value, double *out, int n, char *err, size_t errlen);

typedef struct lag_ctl {
    /* the common options (lag_ctl_init sets the defaults) */
    const char *name;          /* program name in messages */
    const char *prefix;        /* --prefix, or the plant found (lag_ctl_start) */
    const char *default_prefix; /* when no plant is found (NULL: one must be) */
    char found_prefix[64];
    char found_url[LAG_CLIENT_URL_LEN]; /* the URL a host's directory named (lag_client_locate) */
    int fail_code;              /* lag_ctl_fail's exit status (0: 1) */
    const char *url;           /* NULL: LCM's default */
    double duration;           /* sim s, 0: until the run ends otherwise */
    double timeout;            /* wall s */
    const char *trace_path;    /* NULL: no trace */
    bool quiet;

    /* after lag_ctl_start */
    lag_client *client;
    lag_client_scene *scene;   /* the scene of the state last returned (lag_client_scene_*) */
    lag_model_kind kind;
    lag_model model;           /* the scene's parameters, finished and validated */

    /* the run */
    const char *end;           /* why it ended: stop, silence, duration, signal; NULL */
    int64_t states;            /* states returned by lag_ctl_next_state */
    double t_first;            /* sim time of the first one */
    bool failed;               /* a client error ended the run */
    FILE *trace;
    double heard;              /* monotonic s of the last message from the daemon */
    bool stopped;              /* the daemon's stop event arrived */
    lag_client_state current;  /* the state last returned */

    /* optional, set before lag_ctl_start: called with every event from the daemon (from
     * inside lag_ctl_next_state), after the setup has looked at it */
    lag_client_event_fn on_event;
    void *event_user;
} lag_ctl;

/* Without --prefix, lag_ctl_start takes the only plant of the model on the bus
 * (lag_client_pick_plant); if there is none yet, default_prefix (NULL: a plant must show
 * up within --timeout). */
void lag_ctl_init(lag_ctl *ctl, const char *name, const char *default_prefix);

/* Parses argv: the common options and the controller's own (`what` is the usage's
 * description line). Returns -1 to go on, 0 after --help (usage printed on stdout), 2
 * after a usage error (message and usage on stderr). */
int lag_ctl_parse(lag_ctl *ctl, int argc, char **argv, const char *what,
                  const lag_ctl_option *extra, int nextra);

/* Connects, handles SIGINT and SIGTERM, prints "<name>: waiting for the scene description
 * on <prefix>_SCENE" once subscribed (test harnesses start the daemon on it), waits for
 * the scene, checks it runs `model` (NULL: any model of this build, the scene's) and builds
 * ctl->model from its parameters. Returns 0, or 1 with a message on stderr. */
int lag_ctl_start(lag_ctl *ctl, const char *model);

/* The newest state not yet returned: LAG_CLIENT_OK, or LAG_CLIENT_TIMEOUT when the run
 * has ended (ctl->end says why), or a negative error (message on stderr). A copy of the
 * state answered last (same generation, step and sim time: the daemon published it again
 * because no answer reached it) is answered at once with the same command and not
 * returned: every state received is answered, and the control law runs once per state.
 * A state of a new generation (a reset, a SET) comes with its scene: ctl->scene and
 * ctl->model are that scene's when it is returned. OUT: st */
int lag_ctl_next_state(lag_ctl *ctl, lag_client_state *st);

/* Answers state st with efforts for n named joints; a non-finite effort is sent as 0
 * (never NaN on the bus). Writes the trace line. Returns a client result code. */
int lag_ctl_command(lag_ctl *ctl, const lag_client_state *st, int n, const char *const *names,
                    const double *effort);

/* Prints "<name>: summary end=<end> <fmt...> dropped=<n> repeats=<n>" on stdout (repeats:
 * copies of a state answered again by the client, lagsim_client.h), closes the trace and
 * the client. Returns the exit status (lag_result_exit): 0, or 1 when a client error ended
 * the run. */
int lag_ctl_finish(lag_ctl *ctl, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Closes the trace and the client without a summary (a run that could not start).
 * Returns the exit status (lag_result_exit): 1, or 2 when several plants could be meant.
 * A start that SIGINT or SIGTERM ended while it waited for the scene is no failure: the
 * summary (end=signal states=0) as lag_ctl_finish prints it, and 0. */
int lag_ctl_fail(lag_ctl *ctl);

#ifdef __cplusplus
}
#endif
#endif
