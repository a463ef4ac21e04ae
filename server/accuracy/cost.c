/* What accuracy costs on one scene (cost.h says what is measured and how). */
#include "cost.h"
#include "lagsim_clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TIMING_BATCH 1e-3   /* s of CPU a timed batch of runs takes at least */
#define TIMING_BATCHES 3    /* batches; the least per-run time counts */
#define MAX_REFINE 10       /* dt = period / 2^10 at the finest, the reference's tick */
#define MAX_PERIODS 1000000 /* publish periods in a horizon */

lag_cost_opts lag_cost_opts_default(void)
{
    return (lag_cost_opts){.target = 1e-6, .horizon = 1, .period = 0.01, .safety = 4,
                           .budget = 3, .complete = false, .clock = NULL, .clock_ctx = NULL};
}

static double thread_cpu(void *ctx)
{
    (void)ctx;
    return lag_clock_thread_cpu_s();
}

lag_integrator_def lag_cost_row_integrator(const lag_sim_def *def, const lag_cost_row *row)
{
    lag_integrator_def in = def->integrator;
    in.method = row->method;
    in.dt = row->dt;
    if (row->tol > 0) in.rtol = in.atol = row->tol;
    return in;
}

void lag_cost_row_describe(const lag_cost_row *row, char *buf, size_t len)
{
    if (row->tol > 0) snprintf(buf, len, "%s tol %.0e", lag_method_name(row->method), row->tol);
    else snprintf(buf, len, "%s dt %.6g s", lag_method_name(row->method), row->dt);
}

/* A calibration in progress: the reference's samples and the clock. */
typedef struct cost_run {
    const lag_sim_def *def;
    const lag_cost_opts *o;
    double (*clock)(void *);
    int64_t nper;     /* publish periods in the horizon */
    int nq;
    double *ref_q;    /* nper x nq: the reference's q at the end of each period */
    double *ref_e;    /* nper: its energy there */
    lag_sim *sim;     /* one sim, reused */
    double t_start;   /* the clock when the calibration began */
    double cheapest;  /* the cost of the cheapest row that meets so far */
} cost_run;

/* Runs the horizon with INTEG, from the initial state, period by period; with compare,
 * fills the row's errors against the reference. Returns the first fault or LAG_OK. */
static lag_result run_horizon(cost_run *c, const lag_integrator_def *integ, lag_cost_row *row,
                              bool compare, char *err, size_t errlen)
{
    lag_sim_def d = *c->def;
    d.integrator = *integ;
    if (lag_sim_init(c->sim, &d, err, errlen) != LAG_OK) return LAG_ERR_ARG;
    const int64_t tpp = (int64_t)llround(c->o->period / integ->dt);
    double emax = 0, eemax = 0;
    for (int64_t k = 0; k < c->nper; k++) {
        lag_result r = lag_sim_advance(c->sim, tpp, true);
        if (r != LAG_OK) return r;
        lag_event ev;
        while (lag_sim_poll_event(c->sim, &ev)) {}
        if (!compare) continue;
        for (int i = 0; i < c->nq; i++) {
            double e = fabs(c->sim->q[i] - c->ref_q[k * c->nq + i]);
            if (!(e <= emax)) emax = e; /* NaN propagates */
        }
        double ee = fabs(lag_sim_energy(c->sim) - c->ref_e[k]);
        if (!(ee <= eemax)) eemax = ee;
    }
    if (compare) {
        row->error = emax;
        row->energy_error = eemax;
    }
    return LAG_OK;
}

/* Measures one setting: its errors, then its cost (the least per-run CPU time of a few
 * batches, each at least TIMING_BATCH long). */
static void measure_row(cost_run *c, lag_cost_row *row)
{
    char err[256];
    lag_integrator_def in = lag_cost_row_integrator(c->def, row);
    row->error = INFINITY;
    row->energy_error = INFINITY;
    row->cpu_per_sim_s = INFINITY;
    double t0 = c->clock(c->o->clock_ctx);
    row->fault = run_horizon(c, &in, row, true, err, sizeof err);
    double once = c->clock(c->o->clock_ctx) - t0;
    if (row->fault != LAG_OK) return;
    double best = once;
    for (int b = 0; b < TIMING_BATCHES; b++) {
        int runs = once > 0 ? (int)ceil(TIMING_BATCH / once) : 1000;
        if (runs < 1) runs = 1;
        if (runs > 1000) runs = 1000;
        double tb = c->clock(c->o->clock_ctx);
        for (int i = 0; i < runs; i++) run_horizon(c, &in, row, false, err, sizeof err);
        double per = (c->clock(c->o->clock_ctx) - tb) / runs;
        if (per < best) best = per;
        if (once >= TIMING_BATCH) break; /* long runs: one more timing is enough */
    }
    row->cpu_per_sim_s = best / c->o->horizon;
    row->meets = row->error * c->o->safety <= c->o->target;
}

/* Methods from the highest order down (dopri5, rk4, gauss4, ...): the cheap accurate
 * ones first, so that the rest stop refining early. Fills order[], returns the count. */
static int method_order(lag_method *order)
{
    int n = 0;
    for (int m = 0; m < LAG_METHOD_COUNT; m++) order[n++] = (lag_method)m;
    for (int i = 1; i < n; i++) /* insertion sort, stable */
        for (int j = i; j > 0 && lag_method_order(order[j]) > lag_method_order(order[j - 1]); j--) {
            lag_method t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
    return n;
}

static lag_result fail(char *err, size_t errlen, const char *msg, lag_result r)
{
    if (err && errlen) snprintf(err, errlen, "%s", msg);
    return r;
}

/* The options' ranges; the publish periods in the horizon into *nper. */
static lag_result check_opts(const lag_cost_opts *o, int64_t *nper, char *err, size_t errlen)
{
    if (!(o->target > 0 && o->target < 1) || !(o->horizon > 0) || !(o->period > 0) ||
        !(o->safety >= 1) || !(o->budget > 0))
        return fail(err, errlen, "target in (0, 1), horizon > 0, period > 0, safety >= 1, "
                                 "budget > 0 expected", LAG_ERR_ARG);
    double nperd = floor(o->horizon / o->period * (1 + 1e-12) + 1e-9);
    if (!(nperd >= 1 && nperd <= MAX_PERIODS))
        return fail(err, errlen, "integrator.horizon holds no publish period, or more than 10^6",
                    LAG_ERR_ARG);
    *nper = (int64_t)nperd;
    return LAG_OK;
}

/* The reference: dopri5 far below the target; with a floor or stops at the finest
 * tick a setting may have (a bounce shorter than a tick ends in resting contact: their
 * Zeno guard depends on the tick, and the reference's must be the finest), else a
 * tick a period (dopri5 steps across ticks as it likes). Fills c->ref_q, c->ref_e. */
static lag_result run_reference(cost_run *c, lag_cost_table *out, char *err, size_t errlen)
{
    const lag_sim_def *def = c->def;
    const lag_cost_opts *o = c->o;
    out->ref_tol = fmax(1e-14, fmin(1e-10, o->target * 1e-4));
    const uint32_t zeno = LAG_EFF_FLOOR | LAG_EFF_LIMITS; /* effects whose rest depends on the tick */
    const int64_t ref_tpp = (def->effects.enabled & zeno) ? (int64_t)1 << MAX_REFINE : 1;
    lag_integrator_def in = def->integrator;
    in.method = LAG_DOPRI5;
    in.dt = o->period / (double)ref_tpp;
    in.rtol = in.atol = out->ref_tol;
    lag_sim_def d = *def;
    d.integrator = in;
    char why[256];
    if (lag_sim_init(c->sim, &d, why, sizeof why) != LAG_OK) {
        snprintf(err, errlen, "the scene cannot be measured: %s", why);
        return LAG_ERR_ARG;
    }
    c->nq = c->sim->nq;
    for (int64_t k = 0; k < c->nper; k++) {
        lag_result r = lag_sim_advance(c->sim, ref_tpp, true);
        if (r != LAG_OK) {
            snprintf(err, errlen, "the reference (dopri5 at tolerance %.0e) faulted at "
                     "t = %g s: %s; measure over a shorter horizon", out->ref_tol,
                     lag_sim_time(c->sim), lag_result_string(r));
            return LAG_ERR_ARG;
        }
        lag_event ev;
        while (lag_sim_poll_event(c->sim, &ev)) {}
        memcpy(&c->ref_q[k * c->nq], c->sim->q, sizeof(double) * (size_t)c->nq);
        c->ref_e[k] = lag_sim_energy(c->sim);
    }
    return LAG_OK;
}

/* Method m's rows, each setting finer than the last (dt halved, or the tolerance a
 * tenth), until one meets the target, can no longer be chosen, or the budget is spent. */
static void refine_method(cost_run *c, lag_cost_table *out, lag_method m)
{
    const lag_cost_opts *o = c->o;
    const bool adaptive = lag_method_info_get(m)->adaptive;
    double last_run = 0; /* CPU s of the last row's one run, to foresee the next */
    for (int j = 0; j <= MAX_REFINE; j++) {
        lag_cost_row row = {.method = m};
        if (adaptive) {
            row.tol = pow(10.0, -3 - j);
            row.dt = o->period;
            if (row.tol < 100 * out->ref_tol) break; /* no closer to the reference */
        } else {
            row.dt = o->period / (double)(1L << j);
        }
        /* a finer setting takes about twice as long, and is timed a few times */
        double spent = c->clock(o->clock_ctx) - c->t_start;
        if (j > 0 && spent + 2 * last_run * (TIMING_BATCHES + 2) + TIMING_BATCH * TIMING_BATCHES > o->budget) {
            out->budget_hit = true;
            break;
        }
        if (out->n == LAG_COST_MAX_ROWS) {
            out->budget_hit = true;
            break;
        }
        double t0 = c->clock(o->clock_ctx);
        measure_row(c, &row);
        last_run = (c->clock(o->clock_ctx) - t0) / (TIMING_BATCHES + 1);
        out->row[out->n++] = row;
        if (row.meets && row.cpu_per_sim_s < c->cheapest) c->cheapest = row.cpu_per_sim_s;
        if (row.meets) break;                          /* finer only costs more */
        if (!o->complete && row.fault == LAG_OK && row.cpu_per_sim_s > c->cheapest)
            break; /* can no longer be chosen */
    }
}

/* chosen: the cheapest row that meets the target; best: the most accurate one. */
static void pick_rows(lag_cost_table *out)
{
    for (int i = 0; i < out->n; i++) {
        const lag_cost_row *r = &out->row[i];
        if (r->meets && (out->chosen < 0 || r->cpu_per_sim_s < out->row[out->chosen].cpu_per_sim_s))
            out->chosen = i;
        if (r->fault == LAG_OK && (out->best < 0 || r->error < out->row[out->best].error))
            out->best = i;
    }
}

lag_result lag_cost_measure(const lag_sim_def *def, const lag_cost_opts *o,
                            lag_cost_table *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    out->chosen = out->best = -1;
    cost_run c = {.def = def, .o = o, .clock = o->clock ? o->clock : thread_cpu,
                  .cheapest = INFINITY};
    lag_result rc = check_opts(o, &c.nper, err, errlen);
    if (rc != LAG_OK) return rc;
    c.sim = malloc(sizeof *c.sim);
    c.ref_q = malloc(sizeof(double) * (size_t)c.nper * LAG_MAX_DOF);
    c.ref_e = malloc(sizeof(double) * (size_t)c.nper);
    if (!c.sim || !c.ref_q || !c.ref_e) {
        rc = fail(err, errlen, "out of memory", LAG_ERR_ARG);
    } else {
        c.t_start = c.clock(o->clock_ctx);
        rc = run_reference(&c, out, err, errlen);
    }
    if (rc == LAG_OK) {
        lag_method order[LAG_METHOD_COUNT];
        int nm = method_order(order);
        for (int mi = 0; mi < nm && !out->budget_hit; mi++) refine_method(&c, out, order[mi]);
        pick_rows(out);
    }
    out->spent = c.clock ? c.clock(o->clock_ctx) - c.t_start : 0;
    free(c.sim);
    free(c.ref_q);
    free(c.ref_e);
    return rc;
}
