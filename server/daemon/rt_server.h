/*
 * The real-time LCM server's private state, shared by realtime.c (the loop, pacing,
 * commands and control requests, decoded by the wire module) and rt_wire.c (encoding and
 * publishing of outgoing messages).
 *
 * Everything the stepping path touches lives in this struct, allocated once (on the
 * stack of lagsimd_realtime): fixed-size arrays, one encode buffer, no malloc.
 */
#ifndef LAGSIMD_RT_SERVER_H
#define LAGSIMD_RT_SERVER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <lcm/lcm.h>
#include "daemon.h"
#include "live_set.h"
#include "lagsim_bus.h"
#include "lagsim_wire.h"
#include "rt_log.h"
#include "rt_pace.h"

#define RT_CHANNEL_MAX LAG_BUS_CHANNEL_LEN /* prefix (< 64) + "_COMMAND" */
#define RT_BUF_SIZE LAG_WIRE_BUF_SIZE /* encode buffer: holds any message */
/* SET requests validated per second and burst (each parses the scene): a SET is either
 * applied and announced by its `set` event, which is never suppressed (replay re-applies
 * it), or refused; so `set` events stay within this bucket */
#define RT_SET_PER_S 10
#define RT_SET_BURST 10

/* RT_WAITING: not advancing, waiting for a command that starts the run (realtime.start:
 * first_command) or, in lockstep, for one that answers the state whose wait timed out; the
 * state is republished meanwhile, and such a command (or RESUME) makes it RT_RUNNING. */
typedef enum rt_run { RT_RUNNING = 0, RT_PAUSED, RT_FAULT, RT_WAITING } rt_run;

/* Why a command was rejected; indexes rt_server.rejected. */
typedef enum rt_reject {
    RT_REJ_UNKNOWN_JOINT = 0,
    RT_REJ_UNACTUATED,
    RT_REJ_NONFINITE,
    RT_REJ_BAD_LENGTH,
    RT_REJ_UNDECODABLE,
    RT_REJ_STALE,             /* lockstep: answers a state other than the one waited on */
    RT_REJ_EFFORT_LIMIT,      /* an |effort| beyond the scene's realtime.effort_limit */
    RT_REJ_COUNT
} rt_reject;

/* Events the daemon publishes in answer to what arrives or about its own pacing: each
 * kind has its own token bucket (rt_limit), so that no input, however fast, makes the
 * daemon publish more than a few of them per second. What a bucket suppressed is counted
 * and said by the next event of that kind that gets through. `start`, `stop` and the
 * effects' events (at most a fixed number per period, located by the core) are not
 * limited. */
/* The error a period may add (m or rad): integrator.error * period / integrator.horizon
 * (the horizon's periods each adding this much sum to the error asked for); 0 when the
 * scene asks for none. */
double rt_error_budget(const lag_scene *sc);

typedef enum rt_ev {
    RT_EV_COMMAND_REJECTED = 0,
    RT_EV_CONTROL_REJECTED,
    RT_EV_PAUSE,
    RT_EV_RESUME,
    RT_EV_STEP,
    RT_EV_STEP_DONE,
    RT_EV_RESET,
    RT_EV_WATCHDOG_TRIP,
    RT_EV_WATCHDOG_CLEAR,
    RT_EV_LOCKSTEP_TIMEOUT,
    RT_EV_OVERRUN_BURST,
    RT_EV_NUMERIC_FAULT,
    RT_EV_EVENTS_DROPPED,
    RT_EV_PLANT_CONFLICT,     /* a scene of another plant heard on this prefix while running */
    RT_EV_ERROR_ESTIMATE,     /* the live error estimate over the scene's budget per period */
    RT_EV_COUNT
} rt_ev;

/* Why the server stopped. */
typedef enum rt_stop {
    RT_STOP_NONE = 0,
    RT_STOP_SIGNAL,
    RT_STOP_DURATION,
    RT_STOP_ERROR,
} rt_stop;

/* What a plant that does not advance waits for (rt_wait.c). */
typedef enum rt_wait_kind {
    RT_WAIT_NONE = 0,
    RT_WAIT_FIRST,   /* the first command (start: first_command, or after a reset) */
    RT_WAIT_ANSWER,  /* lockstep: a command answering the state published */
    RT_WAIT_RESUME,  /* paused: RESUME or STEP */
    RT_WAIT_RESET,   /* the fault state: RESET or RESET_TO */
} rt_wait_kind;

#define RT_SCENES_KEPT 8 /* the last scenes published, to tell them from another plant's */

typedef struct rt_server {
    const lag_scene *sc;
    const lagsimd_opts *opts;
    const lag_model_info *info;
    lcm_t *lcm;                /* publishes on the state URL (never receives) */
    lcm_t *lcm_in;             /* receives _COMMAND and _CONTROL on the command URL (the
                                * same lcm_t as `lcm` for memq://) */
    lcm_subscription_t *sub_command, *sub_control;
    lcm_subscription_t *sub_scene; /* _SCENE on the state URL: another plant's (plant watch) */
    lcm_subscription_t *sub_wrong_port; /* _COMMAND on the state URL: counted, not applied */
    lag_bus bus;               /* the URLs and channels (lagsim_bus.h) */
    bool discard;              /* drop what arrives: before the start, LCM's queues may
                                * hold datagrams that came in before the filter */
    lag_sim sim;
    int nq;
    char ch_state[RT_CHANNEL_MAX], ch_command[RT_CHANNEL_MAX], ch_status[RT_CHANNEL_MAX],
        ch_event[RT_CHANNEL_MAX], ch_control[RT_CHANNEL_MAX], ch_scene[RT_CHANNEL_MAX],
        ch_reference[RT_CHANNEL_MAX];
    /* the scene's reference with the changes made while running (SET reference.*):
     * published on ch_reference before each state when ref.n > 0 */
    lag_scene_reference ref;

    /* the loop's clock: CLOCK_MONOTONIC ns, read once per wake-up (tests set it by hand);
     * every decision of the loop and the handlers uses it */
    int64_t now;

    /* run state */
    rt_run run;
    int64_t pending_steps;     /* STEP N: periods still to advance while paused */
    bool stop;                 /* signal, --duration reached, or a fatal error */
    rt_stop stop_reason;
    int stop_signal;
    int64_t stop_tick;         /* --duration in ticks, 0 = none */

    /* the control period in progress: a period of many ticks runs in chunks of at most
     * tick_budget ticks per wake-up, so that signals and LCM are served in between */
    int64_t period_left;       /* ticks of it still to run; 0 = between periods */
    int64_t tick_budget;       /* ticks one wake-up may advance */
    double period_us;          /* compute time of the period so far */

    /* commands: zero-order hold and watchdog */
    double held[LAG_MAX_DOF];  /* efforts the controller asked for */
    bool have_command;         /* a good command arrived since start/reset */
    int64_t command_tick;      /* sim tick at which it arrived */
    bool watchdog_tripped;

    /* lockstep */
    double waiting_time;       /* sim_time of the state being waited on */
    bool waiting;              /* a state was published and not yet answered */
    bool answered;
    int64_t wait_start_ns;     /* when the wait began */
    int64_t lockstep_wait_ns;  /* realtime.lockstep_timeout, saturated */
    int64_t lockstep_retry_ns; /* realtime.lockstep_retry, saturated */
    int64_t next_retry_ns;     /* when the state waited on goes out again */
    int64_t retry_gap_ns;      /* the gap before that copy: doubles after each, up to */
    int64_t retry_cap_ns;      /* lockstep_timeout / 16, at least lockstep_retry */
    bool answer_heard;         /* a command for the state waited on came (applied or not):
                                * no more copies of it */
    double answered_time;      /* sim_time of the last state a command answered */
    bool have_answered;        /* answered_time holds one (since start or reset) */

    /* pacing of periods (realtime mode) and of the paused republication (realtime, fast) */
    rt_pace pace;
    int64_t period_ns;         /* wall ns per control period */
    bool restart_pace;         /* deadlines restart from now at the next wake-up */

    /* answers: published once per wake-up at most, when their bucket allows (a flood of
     * requests gets one answer, not one each) */
    bool want_state, want_scene, want_status;
    rt_limit lim_state, lim_scene, lim_status;
    rt_limit lim_set;          /* SET requests validated per second */

    /* changes made while running (control_t SET), in the order they were applied */
    live_sets live;
    rt_limit lim_event[RT_EV_COUNT];

    /* counters published in status */
    int64_t overruns;
    int64_t overrun_bursts;
    int64_t accepted;
    int64_t rejected[RT_REJ_COUNT];
    int64_t controls_rejected;
    int64_t watchdog_trips;
    int64_t lockstep_timeouts;
    int64_t lockstep_retries;  /* states published again, no answer having come */
    int64_t commands_ignored;  /* answers to a state already answered */
    int64_t numeric_faults;
    int64_t states_published;
    int64_t effect_events_dropped; /* sim.events_dropped already reported */
    int64_t plant_conflicts;   /* scenes of another plant heard on this prefix while running */

    /* the live error estimate (docs/accuracy.md): every estimate_every-th period is run
     * again from a copy of its start, after its state is published */
    lag_sim shadow_start;      /* the sim at the start of the period to estimate */
    bool shadow_armed;         /* the period in progress is to be estimated */
    int64_t periods_done;      /* control periods completed since start */
    double err_estimate;       /* the last estimate, largest over the joints (m or rad) */
    int err_joint;             /* its joint, -1 before the first */
    int64_t err_warnings;      /* estimates over the budget (rt_error_budget) */

    /* timing */
    int64_t start_ns;
    double step_us_max;
    double step_us_sum;        /* since the last status */
    int64_t step_us_n;
    int64_t ticks_since_status;/* ticks advanced since the last status (resets included) */
    int64_t last_status_ns;
    int64_t status_period_ns;
    int64_t next_status_ns;
    int64_t next_line_ns;
    double rtf;                /* real-time factor of the last status period */
    bool live_line;            /* stderr is a terminal and not -q */
    bool report_line;          /* SIGUSR1/SIGUSR2: one status line on stderr */

    /* --log: every message published and received, in order (rt_log.h), on a clock of
     * its own: the wall clock at start, plus the sim time advanced since (across resets),
     * plus the wall time spent paused or in the fault state; so lcm-logplayer plays any
     * run, lockstep and fast included, at the pace of its sim time */
    struct {
        rt_log *log;           /* NULL: not logging */
        bool input;            /* the scene has an actuator lag: <PREFIX>_INPUT records */
        char ch_input[RT_CHANNEL_MAX];
        int64_t base_us;       /* wall clock at rt_begin */
        int64_t ticks;         /* ticks advanced since rt_begin */
        int64_t idle_ns;       /* wall time while not running */
        int64_t prev_ns;       /* s->now at the last rt_process */
        bool was_idle;         /* not running at the last rt_process */
        int64_t last_us;       /* the last timestamp written: they never go back */
        rt_log_stats seen;     /* counters already reported */
        rt_limit lim_said;     /* lost records are said at most once a second */
        bool error_said;
        /* the command or control request being handled (rt_log_rx_*), written when its
         * fate is known: accepted ones always, refused and undecodable ones as a sample
         * of at most RT_LOG_SAMPLE_BPS bytes a second (a byte bucket), the rest counted */
        const char *rx_channel;
        const void *rx_data;
        size_t rx_len;
        bool rx_pending;
        double sample_credit;  /* bytes the sample may still take */
        int64_t sample_ns;     /* when the credit was last brought up to date */
        int64_t rx_refused;    /* refused (rejected, ignored) or undecodable, received */
        int64_t rx_undecodable;/* of which undecodable */
        int64_t rx_queries;    /* status and describe requests received */
        int64_t rx_sampled;    /* refused and queries written (the sample) */
        int64_t rx_sampled_bytes;
        int64_t unsampled_said;/* refused ones not written, as last said by an event */
        rt_limit lim_sample_said; /* the log_sampled event: at most once a second */
    } lg;

    /* the terminal (rt_term.c): commands per second and printed events */
    struct {
        int64_t snap_ns[8];    /* the commands-per-second window: (time, s->accepted) at */
        int64_t snap_n[8];     /* the last redraws of the live line, a ring */
        int nsnap, next_snap;
        rt_limit lim_print;    /* event lines printed */
        bool line_shown;       /* the live line is on screen (cleared before a print) */
    } term;

    /* one plant per prefix: the scenes this daemon published (FNV-1a of their bytes, which
     * include utime), and what was heard from another plant */
    uint64_t scene_sent[RT_SCENES_KEPT];
    int scene_next;
    char other_plant[160];     /* what gave it away, the last one heard ("" = nothing) */

    /* the waits (rt_wait.c): what the plant waits for, since when, what came instead */
    struct {
        rt_wait_kind kind;
        double t;              /* the sim_time an answer must carry */
        int64_t since_ns;      /* when the wait began */
        int64_t next_line_ns;  /* its next line on stderr */
        int64_t rejected0[RT_REJ_COUNT]; /* the counters when it began */
        int64_t wrong_port0;
    } wt;
    int64_t commands_wrong_port;          /* joint_command_t heard on the state URL */
    char last_reject[LAG_WIRE_TEXT_LEN];  /* why the last command was rejected (not stale) */

    uint8_t buf[RT_BUF_SIZE];
    uint8_t state_buf[RT_BUF_SIZE]; /* the last state published, as sent (lockstep retries) */
    unsigned state_len;
} rt_server;

/* Time helpers (ns). */
int64_t rt_mono_ns(void);
int64_t rt_wall_us(void);

/* rt_wire.c: publishing. Every double is checked; a non-finite one is never sent. */
void rt_publish_state(rt_server *s);
void rt_publish_status(rt_server *s);
void rt_publish_event(rt_server *s, const char *kind, const char *joint, double value,
                      const char *detail);
/* An event that happened at a given sim time (the effects' events, located in a tick). */
void rt_publish_event_at(rt_server *s, double sim_time, const char *kind, const char *joint,
                         double value, const char *detail);
void rt_publish_scene(rt_server *s);
const char *rt_run_name(rt_run r);

/* rt_record.c: --log (no-ops without it). A record of what was published (RT_LOG_OUT)
 * or received (RT_LOG_IN) on `channel`, at the log's clock. */
void rt_log_record(rt_server *s, rt_log_dir dir, const char *channel, const void *data,
                   size_t len);
/* The fate of a received message in the log: accepted ones are all written; refused
 * (rejected, or ignored as a second answer), undecodable ones and queries (status,
 * describe: they change nothing a replay needs) are counted and written
 * only while the sample's byte bucket allows (RT_LOG_SAMPLE_BPS bytes a second, as much in
 * a burst), so a flood cannot fill the disk. The handlers call rt_log_rx_begin with what
 * arrived, rt_log_rx_fate once its fate is known (before publishing anything in answer:
 * the log keeps the order), rt_log_rx_end at their end (still pending: accepted). A message
 * the daemon publishes while one is pending was published in answer to an accepted one.
 * No-ops without --log. */
#define RT_LOG_SAMPLE_BPS (64 * 1024)
typedef enum rt_rx_fate {
    RT_RX_ACCEPTED = 0, /* a command applied, a control request that changes the run */
    RT_RX_REFUSED,      /* rejected, or ignored (a second answer to a lockstep state) */
    RT_RX_UNDECODABLE,  /* refused: not a message of its channel's type */
    RT_RX_QUERY,        /* status and describe requests: they change nothing */
} rt_rx_fate;
void rt_log_rx_begin(rt_server *s, const char *channel, const void *data, size_t len);
void rt_log_rx_fate(rt_server *s, rt_rx_fate fate);
void rt_log_rx_end(rt_server *s);
/* The commanded input of the period that starts (with an actuator lag only), on
 * <PREFIX>_INPUT as a joint_command_t: in the log, never on the bus. */
void rt_log_input(rt_server *s);
/* Once per wake-up, at its end: books the log's clock (running: the run advances sim
 * time until the next wake-up) and checks the writer: records lost, a failed write (an
 * event and a line on stderr, even with -q; lost records at most once a second). */
void rt_log_check(rt_server *s, bool running);
/* Closes the log once the writer has written everything (or made no progress for 5 s)
 * and says so on stderr: a summary unless -q; what was lost, always. Returns 0 when the
 * log is complete, -1 otherwise. */
int rt_log_end(rt_server *s);

/* rt_term.c: the terminal. Without -q every event goes to stderr on its own line (at most
 * 20 a second, the rest counted); on a terminal one live line below them: sim time, RTF,
 * q, commands per second or "no controller", energy, overruns, run state. */
void rt_term_event(rt_server *s, double sim_time, const char *kind, const char *joint,
                   double value, const char *detail, bool effect);
void rt_term_line(rt_server *s, bool final);
/* One line of the daemon's own (not an event) on stderr, the live line kept below it;
 * nothing with -q. */
void rt_term_say(rt_server *s, const char *line);

/* rt_wait.c: the waits. rt_wait_update (each wake-up) notes when a wait begins and
 * prints its line every few seconds; rt_wait_next is when that line is due (INT64_MAX:
 * no wait). rt_wait_describe writes what the plant waits for and where ("" while it
 * advances) and what came instead ("" = nothing) and returns the wall s waited. */
void rt_wait_update(rt_server *s);
int64_t rt_wait_next(const rt_server *s);
double rt_wait_describe(const rt_server *s, char *what, size_t whatlen, char *got, size_t gotlen);
/* The reasons of rt_reject, by index (realtime.c). */
extern const char *const rt_reject_name[RT_REJ_COUNT];

/* realtime.c: the server in pieces (lagsimd_realtime strings them together; tests and
 * the fuzz target drive them with their own clock and LCM, e.g. memq://). */
/* Checks the scene's real-time settings and initializes the sim, at clock `now`; no LCM
 * yet. Settings the loop clamps are said on stderr unless quiet. Returns 0, or an exit
 * code (2: bad scene or --duration) with a message in err. */
int rt_open(rt_server *s, const lag_scene *sc, const lagsimd_opts *o, int64_t now, bool quiet,
            char *err, size_t errlen);
/* Publishes on `out` and subscribes to _COMMAND and _CONTROL on `in` (the same lcm_t for
 * memq://; the caller owns both and destroys them after rt_close). Returns 0, or an exit
 * code with a message in err. */
int rt_attach(rt_server *s, lcm_t *out, lcm_t *in, char *err, size_t errlen);
/* Publishes the scene, a start event, the initial state and a status; deadlines start. */
void rt_begin(rt_server *s);
/* When the loop must next wake up (absolute ns; <= s->now: at once). Pure. */
int64_t rt_next_wake(const rt_server *s);
/* Everything due at s->now: the mode's periods, pending answers, the periodic status. */
void rt_process(rt_server *s);
/* A signal arrived: SIGUSR1/SIGUSR2 ask for a status, any other stops the server. */
void rt_signal(rt_server *s, int signo);
/* A stop event and the final status. */
void rt_finish(rt_server *s);
/* Unsubscribes (the caller destroys its lcm). */
void rt_close(rt_server *s);

/* The LCM handlers' work: a command or a control request, at s->now. */
void rt_handle_command(rt_server *s, const uint8_t *data, size_t len);
void rt_handle_control(rt_server *s, const uint8_t *data, size_t len);
/* A scene heard on this prefix: one that decodes, names this prefix and is not one this
 * daemon published is another plant's (or a forgery, or an old log played back). At start
 * (s->discard) it makes rt_bus_open refuse to start; while running the daemon runs on and
 * reports the conflict: counted (status plant_conflicts), a plant_conflict event and a
 * line on stderr (even with -q), both at most once per RT_CONFLICT_EVERY_S. Anything
 * else on the channel is ignored. */
void rt_handle_scene(rt_server *s, const uint8_t *data, size_t len);
/* FNV-1a, 64 bits: how a published scene is remembered. */
uint64_t rt_hash(const uint8_t *data, size_t len);

/* rt_bus.c: the daemon's LCM instances: one publishing on the state URL, one receiving
 * on the command URL (one lcm_t for memq://), and what the daemon says about them at
 * start. Returns 0, or an exit code with a message in err; rt_bus_close destroys what
 * rt_bus_open made. */
int rt_bus_open(rt_server *s, char *err, size_t errlen);
void rt_bus_close(rt_server *s);


#endif
