/*
 * The live error estimate (rt_estimate.c, docs/accuracy.md): every estimate_every-th
 * control period run in one piece is run again from a copy of its start, after its state
 * is published, and the difference is the error the integration added over it.
 *
 * A part of the loop's (realtime.c holds one): it keeps the copy and the last estimate;
 * the loop arms it when a period begins and asks it when the period is done, and says an
 * estimate over the budget as an event.
 */
#ifndef LAGSIMD_RT_ESTIMATE_H
#define LAGSIMD_RT_ESTIMATE_H

#include <stdbool.h>
#include <stdint.h>
#include "lagsim/lagsim.h"

typedef struct rt_estimate {
    int every;                 /* estimate every this many periods; 0: never */
    double budget;             /* the error a period may add (rt_error_budget); 0: none */
    lag_sim shadow_start;      /* the sim at the start of the period to estimate */
    bool armed;                /* the period in progress is to be estimated */
    int64_t periods_done;      /* control periods completed since start */
    double err;                /* the last estimate, largest over the joints (m or rad) */
    int joint;                 /* its joint, -1 before the first */
    int64_t warnings;          /* estimates over the budget */
} rt_estimate;

void rt_estimate_init(rt_estimate *e, int every, double budget);
/* A period begins with the sim `sim`; `whole`: it runs in one piece (nothing changes the
 * sim between its chunks then). Arms the estimate when this period is one to estimate. */
void rt_estimate_arm(rt_estimate *e, const lag_sim *sim, bool whole);
/* The period in progress will not be estimated (a fault). */
void rt_estimate_disarm(rt_estimate *e);
/* The period is done and its state published (sim: at its end). Returns true when it
 * was estimated over the budget (e->err, e->joint say by how much, where). A shadow
 * that faults says nothing (the run itself did not). */
bool rt_estimate_period(rt_estimate *e, const lag_sim *sim);

#endif
