/*
 * The real-time server's terminal (stderr): event lines and the live line (rt_term.c).
 *
 * A part of the loop's (realtime.c holds one): it owns what the terminal shows and how
 * often, and knows nothing of the run. What the live line shows is asked of the loop
 * through `view` (a callback it sets), when the line is drawn.
 */
#ifndef LAGSIMD_RT_TERM_H
#define LAGSIMD_RT_TERM_H

#include <stdbool.h>
#include <stdint.h>
#include "lagsim/lagsim.h"
#include "rt_pace.h"

/* What the live line shows, filled by the loop (rt_term.view). */
typedef struct rt_term_view {
    const char *prefix;
    double t, rtf, energy;
    const double *q;
    int nq;
    bool controller;        /* a command is held (none yet, or the watchdog tripped: not) */
    int64_t accepted;       /* commands accepted so far: the rate is taken from it */
    int64_t overruns;
    const char *run;        /* the run state's name */
} rt_term_view;

/* -q's journal: the kinds of event that say the plant lost something (rt_publish.c's
 * table marks them), a line per kind at most every RT_TERM_JOURNAL_S with the count. */
#define RT_TERM_LOSS_KINDS 24
#define RT_TERM_JOURNAL_S 10

typedef struct rt_term_loss {
    int64_t pending;        /* events since the last line */
    int64_t total;
    int64_t line_ns;        /* when its last line was printed (0: never) */
    double t;               /* the last one's sim time */
    char kind[32];
    char detail[256];       /* the last one's */
} rt_term_loss;

typedef struct rt_term {
    bool quiet;             /* -q: no event lines, no live line; the losses' journal */
    const char *who;        /* what the event lines begin with after "lagsimd: ": "" for a
                             * daemon of one plant, "ALICE: " for a host's plant */
    bool live_line;         /* stderr is a terminal and not -q */
    const char *ch_event;   /* where every event is (said when lines were not shown) */
    void (*view)(void *ctx, rt_term_view *v); /* the live line's content, from the loop */
    void *ctx;
    int64_t snap_ns[8];     /* the commands-per-second window: (time, accepted) at */
    int64_t snap_n[8];      /* the last redraws of the live line, a ring */
    int nsnap, next_snap;
    rt_limit lim_print;     /* event lines printed */
    bool line_shown;        /* the live line is on screen (cleared before a print) */
    rt_term_loss loss[RT_TERM_LOSS_KINDS];
} rt_term;

/* At the loop's clock `now`: at most 20 event lines a second. */
void rt_term_init(rt_term *t, bool quiet, const char *ch_event, int64_t now);
/* Without -q every event goes to stderr on its own line (at most 20 a second, the rest
 * counted); on a terminal one live line below them: sim time, RTF, q, commands per second
 * or "no controller", energy, overruns, run state. With -q an event that says the plant
 * lost something (`loss`: its kind's slot, below RT_TERM_LOSS_KINDS; -1: not such an
 * event) still goes to the journal: the first of its kind at once, then one line per
 * RT_TERM_JOURNAL_S with how many came (rt_term_tick, rt_term_flush). */
void rt_term_event(rt_term *t, int64_t now, double sim_time, const char *kind,
                   const char *joint, double value, const char *detail, bool effect, int loss);
/* -q: the journal's lines due at `now` (a kind whose interval is over with events
 * pending). */
void rt_term_tick(rt_term *t, int64_t now);
/* -q: every pending count said (the plant ends). */
void rt_term_flush(rt_term *t, int64_t now);
void rt_term_line(rt_term *t, int64_t now, bool final);
/* One line of the daemon's own (not an event) on stderr, the live line kept below it;
 * nothing with -q. */
void rt_term_say(rt_term *t, int64_t now, const char *line);

#endif
