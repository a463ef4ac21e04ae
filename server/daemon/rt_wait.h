/*
 * The waits (rt_wait.c): whenever the run does not advance, what the plant waits for,
 * since when, and what came instead, in every status and in a line on stderr now and
 * then.
 *
 * A part of the loop's (realtime.c holds one): the loop says each wake-up what the plant
 * waits for (rt_wait_kind and the sim time an answer must carry) and what it counted
 * (rt_wait_seen); the wait keeps when it began and when its next line is due.
 */
#ifndef LAGSIMD_RT_WAIT_H
#define LAGSIMD_RT_WAIT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "lagsim_bus.h"
#include "rt_command.h"
#include "rt_foreign.h"
#include "rt_term.h"

/* What a plant that does not advance waits for. */
typedef enum rt_wait_kind {
    RT_WAIT_NONE = 0,
    RT_WAIT_FIRST,   /* the first command (start: first_command, or after a reset) */
    RT_WAIT_ANSWER,  /* lockstep: a command answering the state published */
    RT_WAIT_RESUME,  /* paused: RESUME or STEP */
    RT_WAIT_RESET,   /* the fault state: RESET or RESET_TO */
} rt_wait_kind;

/* What the plant waits for now, and what came so far (the loop's counters). */
typedef struct rt_wait_seen {
    rt_wait_kind kind;
    double t;                   /* the sim_time an answer must carry */
    const int64_t *rejected;    /* [RT_REJ_COUNT]: commands rejected, by reason */
    int64_t wrong_port;         /* commands heard on the state URL */
    const char *last_reject;    /* why the last command was rejected (not stale) */
    const rt_foreign *foreign;  /* control requests for other prefixes, or on the state URL
                                 * (NULL: none kept) */
    bool owed;                  /* RT_WAIT_RESUME in lockstep: the state waited on (at t)
                                 * has not been answered yet */
    const int64_t *stale;       /* [RT_STALE_COUNT]: the stale rejections, by kind */
} rt_wait_seen;

typedef struct rt_wait {
    const lag_bus *bus;         /* where commands and control requests go */
    const char *prefix;
    bool lockstep;
    rt_wait_kind kind;
    double t;                   /* the sim_time an answer must carry */
    int64_t since_ns;           /* when the wait began */
    int64_t next_line_ns;       /* its next line on stderr */
    int64_t rejected0[RT_REJ_COUNT]; /* the counters when it began */
    int64_t stale0[RT_STALE_COUNT];
    int64_t wrong_port0;
    rt_foreign foreign0;        /* the requests heard elsewhere when it began */
} rt_wait;

void rt_wait_init(rt_wait *w, const lag_bus *bus, const char *prefix, bool lockstep);
/* Each wake-up: notes when a wait begins and prints its line (through `term`) every few
 * seconds. */
void rt_wait_update(rt_wait *w, int64_t now, const rt_wait_seen *seen, rt_term *term);
/* When the line is due (INT64_MAX: no wait). */
int64_t rt_wait_next(const rt_wait *w);
/* Writes what the plant waits for and where ("" while it advances) and what came instead
 * ("" = nothing), and returns the wall s waited. */
double rt_wait_describe(const rt_wait *w, int64_t now, const rt_wait_seen *seen, char *what,
                        size_t whatlen, char *got, size_t gotlen);

#endif
