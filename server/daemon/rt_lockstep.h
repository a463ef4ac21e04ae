/*
 * Lockstep's bookkeeping (rt_lockstep.c): the state waited on, whether it was answered,
 * when the wait times out and when the state goes out again.
 *
 * A part of the loop's (realtime.c holds one): it decides nothing about the run; the loop
 * asks it what is due (a timeout, a copy of the state) and tells it what happened (a
 * state published, an answer heard).
 */
#ifndef LAGSIMD_RT_LOCKSTEP_H
#define LAGSIMD_RT_LOCKSTEP_H

#include <stdbool.h>
#include <stdint.h>

#define RT_RETRY_NS_MIN 1000000LL /* lockstep retries at most every millisecond */

typedef struct rt_lockstep {
    double waiting_time;       /* sim_time of the state being waited on */
    int64_t waiting_gen;       /* its generation: a state is known by both */
    bool waiting;              /* a state was published and not yet answered */
    bool answered;
    int64_t wait_start_ns;     /* when the wait began */
    int64_t wait_ns;           /* realtime.lockstep_timeout, saturated */
    int64_t retry_ns;          /* realtime.lockstep_retry, saturated */
    int64_t next_retry_ns;     /* when the state waited on goes out again */
    int64_t retry_gap_ns;      /* the gap before that copy: doubles after each, up to */
    int64_t retry_cap_ns;      /* lockstep_timeout / 16, at least lockstep_retry */
    bool answer_heard;         /* a command for the state waited on came (applied or not):
                                * no more copies of it */
    double answered_time;      /* sim_time of the last state a command answered */
    int64_t answered_gen;      /* and its generation */
    bool have_answered;        /* answered_time holds one (since start or reset) */
    int64_t answered_ns;       /* when it was answered (the copy rule's hint: realtime.c) */
} rt_lockstep;

/* realtime.lockstep_timeout and lockstep_retry (s; a retry of 0: none). */
void rt_lockstep_init(rt_lockstep *l, double timeout_s, double retry_s);
/* A state of generation gen at sim time t went out at `now`: it is waited on. States
 * are told apart by (generation, sim time): every run starts again at sim time 0, and a
 * SET changes the scene without changing the sim time. */
void rt_lockstep_published(rt_lockstep *l, int64_t gen, double t, int64_t now);
/* The wait began lockstep_timeout ago or more. */
bool rt_lockstep_timed_out(const rt_lockstep *l, int64_t now);
/* Whether a copy of the state waited on is due at `now` (none once an answer was heard);
 * when it is, the next copy is booked (the gap doubles up to retry_cap_ns). */
bool rt_lockstep_retry(rt_lockstep *l, int64_t now);
/* Is (gen, t) the state waited on? */
bool rt_lockstep_is_waited(const rt_lockstep *l, int64_t gen, double t);
/* A command for the state (gen, t) heard (good or not): the state waited on, if it was
 * that one, needs no copies. */
void rt_lockstep_heard(rt_lockstep *l, int64_t gen, double t);
/* A command for the state (gen, t) applied: the state waited on, if it was that one, is
 * answered. */
void rt_lockstep_answer(rt_lockstep *l, int64_t gen, double t, int64_t now);
/* A second answer to a state already answered (not applied). */
bool rt_lockstep_repeated(const rt_lockstep *l, int64_t gen, double t);

#endif
