/*
 * lagsimd --log: what the real-time server puts in its log, and on its own clock
 * (rt_record.c); the writer itself is rt_log.c.
 *
 * A part of the loop's (realtime.c holds one): it owns the log's clock, the sample of
 * refused messages and what was already said about losses. It publishes nothing: what it
 * has to say on the bus comes back to the loop as notes (rt_log_check).
 */
#ifndef LAGSIMD_RT_RECORD_H
#define LAGSIMD_RT_RECORD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "lagsim/lagsim.h"
#include "lagsim_bus.h"
#include "scene.h"
#include "rt_log.h"
#include "rt_pace.h"

/* What received messages may add to the log, in bytes per second of the log's own clock
 * (sim time while running, wall time while not: rt_record's clock) or of the wall clock,
 * whichever ran more (so in real time at rate <= 1, per wall second), each a byte bucket
 * that holds one second's worth at most:
 *   - refused, undecodable ones and queries (status, describe): a sample of
 *     RT_LOG_SAMPLE_BPS;
 *   - accepted ones (commands applied, control requests that change the run): room for
 *     RT_LOG_ACCEPTED_PER_PERIOD full commands (every actuated joint named) per control
 *     period, and at least RT_LOG_ACCEPTED_MIN_BPS (control requests on a slow scene).
 * A controller's one command a period is all written; a flood beyond is counted. Nothing
 * --replay reads comes from these records (it reads states, events, references and the
 * inputs the daemon writes itself), so a replay stays exact. */
#define RT_LOG_SAMPLE_BPS (8 * 1024)
#define RT_LOG_ACCEPTED_PER_PERIOD 2
#define RT_LOG_ACCEPTED_MIN_BPS (8 * 1024)

/* A byte bucket on the log's clock. */
typedef struct rt_log_bucket {
    double rate;           /* bytes per second of the log's clock; burst: as much */
    double credit;         /* bytes it may still take */
    int64_t start_us;      /* the log's clock at the first take, 0: none yet */
    int64_t start_ns;      /* the loop's clock then */
    double t;              /* seconds since, on the clock that ran more, at the last take */
} rt_log_bucket;

/* Every message published and received, in order (rt_log.h), on a clock of its own: the
 * wall clock at start, plus the sim time advanced since (across resets), plus the wall
 * time spent paused or in the fault state; so lcm-logplayer plays any run, lockstep and
 * fast included, at the pace of its sim time. */
typedef struct rt_record {
    rt_log *log;           /* NULL: not logging */
    bool quiet;            /* -q: only losses are said on stderr */
    double dt;             /* the scene's tick: the clock advances ticks * dt */
    bool input;            /* the scene has an actuator lag: <PREFIX>_INPUT records */
    char ch_input[LAG_BUS_CHANNEL_LEN];
    int64_t base_us;       /* wall clock at the first record */
    int64_t ticks;         /* ticks advanced since (the loop adds them) */
    int64_t idle_ns;       /* wall time while not running */
    int64_t prev_ns;       /* the loop's clock at the last rt_log_check */
    bool was_idle;         /* not running at the last rt_log_check */
    int64_t last_us;       /* the last timestamp written: they never go back */
    rt_log_stats seen;     /* counters already reported */
    int64_t files_said;    /* files of a series already said (log_split) */
    int prune_said;        /* the --keep failure already said */
    rt_limit lim_said;     /* lost records are said at most once a second */
    bool error_said;
    /* the command or control request being handled (rt_log_rx_*), written when its fate
     * is known, each kind while its bucket allows (above), the rest counted */
    const char *rx_channel;
    const void *rx_data;
    size_t rx_len;
    bool rx_pending;
    rt_log_bucket sample;  /* refused, undecodable and queries */
    rt_log_bucket accepted;/* accepted */
    int64_t rx_refused;    /* refused (rejected, ignored) or undecodable, received */
    int64_t rx_undecodable;/* of which undecodable */
    int64_t rx_queries;    /* status and describe requests received */
    int64_t rx_sampled;    /* refused and queries written (the sample) */
    int64_t rx_sampled_bytes;
    int64_t rx_accepted;   /* accepted, received */
    int64_t rx_accepted_written;
    int64_t rx_accepted_bytes;
    int64_t unsampled_said;/* received ones not written, as last said by an event */
    rt_limit lim_sample_said; /* the log_sampled event: at most once a second */
} rt_record;

/* Without --log (log NULL) every call below is a no-op but the clock's booking. */
void rt_record_init(rt_record *r, double dt, bool quiet, int64_t now);
/* --log as the options ask (--force, --increment, --keep, --split-mb, --log-buffer; the
 * scene file never written): opens r->log and says on stderr which file of a series it
 * writes and what --keep removed. Returns 0, or -1 with a message in err. */
struct lagsimd_opts;
int rt_record_open(rt_record *r, const lag_scene *sc, const struct lagsimd_opts *o,
                   char *err, size_t errlen);

/* A record of what was published (RT_LOG_OUT) or received (RT_LOG_IN) on `channel`, at
 * the log's clock. */
void rt_log_record(rt_record *r, int64_t now, rt_log_dir dir, const char *channel,
                   const void *data, size_t len);
/* The fate of a received message in the log: each is counted, and written while its
 * kind's byte bucket allows (accepted; refused, undecodable and queries: above), so that
 * no flood of any kind can fill the disk. The handlers call rt_log_rx_begin with what arrived,
 * rt_log_rx_fate once its fate is known (before publishing anything in answer: the log
 * keeps the order), rt_log_rx_end at their end (still pending: accepted). A message the
 * daemon publishes while one is pending was published in answer to an accepted one. */
typedef enum rt_rx_fate {
    RT_RX_ACCEPTED = 0, /* a command applied, a control request that changes the run */
    RT_RX_REFUSED,      /* rejected, or ignored (a second answer to a lockstep state) */
    RT_RX_UNDECODABLE,  /* refused: not a message of its channel's type */
    RT_RX_QUERY,        /* status and describe requests: they change nothing */
} rt_rx_fate;
void rt_log_rx_begin(rt_record *r, const char *channel, const void *data, size_t len);
void rt_log_rx_fate(rt_record *r, int64_t now, rt_rx_fate fate);
void rt_log_rx_end(rt_record *r, int64_t now);
/* The commanded input of the period that starts (with an actuator lag only), on
 * <PREFIX>_INPUT as a joint_command_t: in the log, never on the bus. */
void rt_log_input(rt_record *r, int64_t now, const lag_sim *sim, const lag_model_info *info);

/* What the log has to say on the bus: an event the loop publishes. */
typedef struct rt_record_note {
    const char *kind;      /* log_error, log_sampled, log_dropped, log_split */
    double value;
    char detail[320];
} rt_record_note;
#define RT_RECORD_NOTES 4
/* Once per wake-up, at its end: books the log's clock (running: the run advances sim
 * time until the next wake-up) and checks the writer: records lost, a failed write, a
 * flood of refused messages (said on stderr too with -q where it matters; lost records at
 * most once a second). Returns the number of notes written to `notes` (at most
 * RT_RECORD_NOTES). */
int rt_log_check(rt_record *r, int64_t now, bool running, rt_record_note *notes);
/* Closes the log once the writer has written everything (or made no progress for 5 s)
 * and says so on stderr: a summary unless -q; what was lost, always. Returns 0 when the
 * log is complete (or there is none), -1 otherwise. */
int rt_log_end(rt_record *r);

#endif
