/*
 * The live error estimate (rt_estimate.h).
 */
#include <math.h>

#include "rt_estimate.h"

void rt_estimate_init(rt_estimate *e, int every, double budget)
{
    e->every = every;
    e->budget = budget;
    e->joint = -1; /* no live error estimate yet */
}

void rt_estimate_arm(rt_estimate *e, const lag_sim *sim, bool whole)
{
    e->armed = e->every > 0 && e->periods_done % e->every == 0 && whole;
    if (e->armed) e->shadow_start = *sim;
}

void rt_estimate_disarm(rt_estimate *e) { e->armed = false; }

bool rt_estimate_period(rt_estimate *e, const lag_sim *sim)
{
    e->periods_done++;
    if (!e->armed) return false;
    e->armed = false;
    double err[LAG_MAX_DOF];
    if (lag_sim_shadow_error(&e->shadow_start, sim, err) != LAG_OK) return false;
    int j = 0;
    for (int i = 1; i < sim->nq; i++)
        if (err[i] > err[j]) j = i;
    if (!isfinite(err[j])) return false;
    e->err = err[j];
    e->joint = j;
    if (!(e->budget > 0 && err[j] > e->budget)) return false;
    e->warnings++;
    return true;
}
