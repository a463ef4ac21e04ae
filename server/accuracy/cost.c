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
#define REF_TOL_MIN 1e-13   /* the tightest reference: at 1e-14 dopri5 is no more accurate
                               (rounding rules), and a pair at 1e-14 and 1e-13 agrees long
                               after independent integrations part (on config/dipc.yaml to
                               1e-6 for 8.2 s, Gauss-Legendre against dopri5 6.8 s) */
#define REF2_FACTOR 10.0    /* the second reference's tolerance, times the first's */
#define TARGET_MIN 1e-12    /* the least error measured against the references (the
                               lower bound of integrator.error) */

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
    if (row->tol > 0) {
        in.rtol = row->tol;
        in.atol = row->atol > 0 ? row->atol : row->tol;
    }
    return in;
}

void lag_cost_row_describe(const lag_cost_row *row, char *buf, size_t len)
{
    const char *m = lag_method_name(row->method);
    if (row->tol > 0 && row->atol > 0)
        snprintf(buf, len, "%s rtol %.0e atol %.0e", m, row->tol, row->atol);
    else if (row->tol > 0)
        snprintf(buf, len, "%s tol %.0e", m, row->tol);
    else
        snprintf(buf, len, "%s dt %.6g s", m, row->dt);
}

/* A calibration in progress: the reference's samples and the clock. */
typedef struct cost_run {
    const lag_sim_def *def;
    const lag_cost_opts *o;
    double (*clock)(void *);
    int64_t nper;     /* publish periods measured (the horizon's, or the predictable ones) */
    int64_t nper_asked; /* publish periods in the horizon asked for */
    double target;    /* the error rows are marked at (lag_cost_table.target) */
    int nq;
    double *ref_q;    /* nper x nq: the reference's q at the end of each period */
    double *ref_e;    /* nper: its energy there */
    double *ref_diff; /* nper: the two references' largest difference there */
    double *per;      /* nper: a row's largest error in each period (the current one's) */
    lag_sim *sim;     /* one sim, reused */
    lag_sim *sim2;    /* the second reference */
    double t_start;   /* the clock when the calibration began */
    double cheapest;  /* the cost of the cheapest row that meets so far */
} cost_run;

/* Runs the horizon with INTEG, from the initial state, period by period; with compare,
 * fills the row's errors against the reference (and c->per, each period's, when the row
 * is the current one). Returns the first fault or LAG_OK. */
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
        double ek = 0;
        for (int i = 0; i < c->nq; i++) {
            double e = fabs(c->sim->q[i] - c->ref_q[k * c->nq + i]);
            if (!(e <= ek)) ek = e; /* NaN propagates */
        }
        if (!(ek <= emax)) emax = ek;
        if (row == NULL) c->per[k] = ek;
        double ee = fabs(lag_sim_energy(c->sim) - c->ref_e[k]);
        if (!(ee <= eemax)) eemax = ee;
    }
    if (compare && row) {
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
    row->cpu_per_sim_s = best / ((double)c->nper * c->o->period);
    row->meets = row->error * c->o->safety <= c->target;
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

/* Whether the scene has effects whose rest depends on the tick (a floor, stops): a bounce
 * shorter than a tick ends in resting contact, so their Zeno guard depends on the tick,
 * and the references' must be the finest a setting may have. */
static bool zeno(const cost_run *c)
{
    return (c->def->effects.enabled & (LAG_EFF_FLOOR | LAG_EFF_LIMITS)) != 0;
}

/* A reference's setting: the first, dopri5 at tol; the second, dopri5 at REF2_FACTOR tol
 * or, with a floor or stops, rk4 at the same tick (a tick of period / 1024 bounds
 * dopri5's steps, and its tolerance then changes nothing). Ticks: a period's (dopri5 steps
 * across ticks as it likes), or with a floor or stops period / 1024. */
static lag_cost_row ref_row(const cost_run *c, double tol, bool second)
{
    const int64_t tpp = zeno(c) ? (int64_t)1 << MAX_REFINE : 1;
    lag_cost_row r = {.method = LAG_DOPRI5, .dt = c->o->period / (double)tpp, .tol = tol};
    if (second && zeno(c)) r.method = LAG_RK4, r.tol = 0;
    else if (second) r.tol = tol * REF2_FACTOR;
    return r;
}

/* Starts s with setting r; returns its ticks per period, or 0 (err). */
static int64_t ref_init(cost_run *c, lag_sim *s, const lag_cost_row *r, char *err, size_t errlen)
{
    lag_sim_def d = *c->def;
    d.integrator = lag_cost_row_integrator(c->def, r);
    char why[256];
    if (lag_sim_init(s, &d, why, sizeof why) != LAG_OK) {
        snprintf(err, errlen, "the scene cannot be measured: %s", why);
        return 0;
    }
    return llround(c->o->period / r->dt);
}

/* The reference pair of tol (ref_row), side by side from the initial state: the first's q
 * and energy at each period end into ref_q and ref_e, their largest difference into
 * ref_diff (inf once the second faults). Stops after the first period whose difference is
 * above stop_above. Returns the periods run, or -1 (err) when the first faults: nothing
 * can then be said of the error. */
static int64_t run_pair(cost_run *c, double tol, double stop_above, char *err, size_t errlen)
{
    const lag_cost_row ra = ref_row(c, tol, false), rb = ref_row(c, tol, true);
    const int64_t tpp = ref_init(c, c->sim, &ra, err, errlen);
    if (!tpp || !ref_init(c, c->sim2, &rb, err, errlen)) return -1;
    c->nq = c->sim->nq;
    bool second = true;
    for (int64_t k = 0; k < c->nper_asked; k++) {
        lag_result r = lag_sim_advance(c->sim, tpp, true);
        if (r != LAG_OK) {
            snprintf(err, errlen, "the reference (dopri5 at tolerance %.0e) faulted at "
                     "t = %g s: %s; measure over a shorter horizon", tol,
                     lag_sim_time(c->sim), lag_result_string(r));
            return -1;
        }
        lag_event ev;
        while (lag_sim_poll_event(c->sim, &ev)) {}
        memcpy(&c->ref_q[k * c->nq], c->sim->q, sizeof(double) * (size_t)c->nq);
        c->ref_e[k] = lag_sim_energy(c->sim);
        second = second && lag_sim_advance(c->sim2, tpp, true) == LAG_OK;
        while (second && lag_sim_poll_event(c->sim2, &ev)) {}
        double d = second ? 0 : INFINITY;
        for (int i = 0; second && i < c->nq; i++) d = fmax(d, fabs(c->sim->q[i] - c->sim2->q[i]));
        c->ref_diff[k] = d;
        if (!(d <= stop_above)) return k + 1;
    }
    return c->nper_asked;
}

/* The periods from the start over which the references agree within thr. */
static int64_t agreeing(const cost_run *c, int64_t ran, double thr)
{
    int64_t k = 0;
    while (k < ran && c->ref_diff[k] <= thr) k++;
    return k;
}

/* The reference: the pair at a tolerance far below the target (1e-4 of it, at most 1e-10),
 * tightened a hundredfold (at most to REF_TOL_MIN) while it differs by more than the
 * target before the horizon's end. With from_current the target is not known yet: the
 * tightest pair, over the whole horizon. Returns the periods run. */
static int64_t run_reference(cost_run *c, lag_cost_table *out, char *err, size_t errlen)
{
    const lag_cost_opts *o = c->o;
    double tol = o->from_current ? REF_TOL_MIN : fmax(REF_TOL_MIN, fmin(1e-10, o->target * 1e-4));
    int64_t ran;
    for (;;) {
        ran = run_pair(c, tol, o->from_current ? INFINITY : o->target, err, errlen);
        if (ran < 0 || o->from_current || agreeing(c, ran, o->target) == c->nper_asked ||
            tol <= REF_TOL_MIN || zeno(c))
            break;
        tol = fmax(tol / 100, REF_TOL_MIN);
    }
    out->ref_tol = tol;
    out->ref2 = ref_row(c, tol, true);
    return ran;
}

/* from_current: the target is the error the current setting reaches, times safety, over
 * the periods before the first where the references differ by more than that error so
 * far: beyond, the first reference is not known to a tenth of the error it measures. A
 * difference within a hundred times the second's tolerance is its own error, not a parting
 * (a pair at 1e-13 and 1e-12 differs by 1e-12 to 5e-12 over 1 s of the shipped scenes),
 * and an error below the references' difference cannot be told from it: the target is
 * then safety times that difference (at least TARGET_MIN). Returns those periods; 0 if
 * the current setting's error is not finite (then the target is opts.target). */
static int64_t target_of_current(cost_run *c, lag_cost_table *out)
{
    const lag_cost_opts *o = c->o;
    char err[256];
    if (run_horizon(c, o->current, NULL, true, err, sizeof err) != LAG_OK) return 0;
    const double least = fmax(TARGET_MIN, 100 * out->ref2.tol);
    double m = 0, d = 0;
    int64_t k = 0;
    for (; k < c->nper; k++) {
        double mk = fmax(m, c->per[k]);
        if (!(c->ref_diff[k] <= fmax(mk, least))) break;
        m = mk;
        d = fmax(d, c->ref_diff[k]);
    }
    if (k == 0) { /* not one period: the references' own difference there is the least */
        k = 1;
        m = c->per[0];
        d = c->ref_diff[0];
    }
    if (!isfinite(m) || !isfinite(d)) return 0;
    c->target = fmax(o->safety * fmax(m, d), TARGET_MIN);
    out->agree_tol = fmax(m, least);
    out->target_from_current = true;
    return k;
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

/* Is row r setting x (the same method, dt and tolerances)? */
static bool same_setting(const lag_cost_row *r, const lag_cost_row *x)
{
    return r->method == x->method && fabs(r->dt - x->dt) <= 1e-12 * x->dt && r->tol == x->tol &&
           r->atol == x->atol;
}

/* opts.current's row: one measured already, or measured now and put among its method's
 * rows (coarse to fine). */
static void add_current(cost_run *c, lag_cost_table *out)
{
    const lag_integrator_def *in = c->o->current;
    lag_cost_row row = {.method = in->method, .dt = in->dt};
    if (lag_method_info_get(in->method)->adaptive) {
        row.tol = in->rtol;
        row.atol = in->atol != in->rtol ? in->atol : 0;
    }
    for (int i = 0; i < out->n; i++)
        if (same_setting(&out->row[i], &row)) {
            out->current = i;
            return;
        }
    if (out->n == LAG_COST_MAX_ROWS) return;
    measure_row(c, &row);
    int at = -1, last = -1;
    for (int i = 0; i < out->n; i++) {
        const lag_cost_row *r = &out->row[i];
        if (r->method != row.method) continue;
        last = i;
        if (at < 0 && (row.tol > 0 ? r->tol < row.tol : r->dt < row.dt)) at = i;
    }
    if (at < 0) at = last >= 0 ? last + 1 : out->n;
    memmove(&out->row[at + 1], &out->row[at], sizeof out->row[0] * (size_t)(out->n - at));
    out->row[at] = row;
    out->n++;
    out->current = at;
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

/* The references, the target, and the periods measured: those over which the references
 * agree within the target (all of the horizon's, unless it is cut). */
static lag_result prepare(cost_run *c, lag_cost_table *out, char *err, size_t errlen)
{
    const lag_cost_opts *o = c->o;
    int64_t ran = run_reference(c, out, err, errlen);
    if (ran < 0) return LAG_ERR_ARG;
    c->target = o->target;
    c->nper = ran;
    int64_t agree = 0;
    if (o->from_current && o->current) agree = target_of_current(c, out);
    if (agree == 0) {
        c->target = out->agree_tol = o->target;
        agree = agreeing(c, ran, o->target);
    }
    out->target = c->target;
    if (agree == 0) {
        char d[96];
        lag_cost_row_describe(&out->ref2, d, sizeof d);
        snprintf(err, errlen, "the scene is not predictable to %g over even one period (%g s): "
                 "two references, dopri5 tol %.0e and %s, differ by %.2g there",
                 c->target, o->period, out->ref_tol, d, c->ref_diff[0]);
        return LAG_ERR_ARG;
    }
    c->nper = agree;
    out->horizon = (double)agree * o->period;
    out->horizon_cut = agree < c->nper_asked;
    if (!out->horizon_cut) out->horizon = o->horizon;
    for (int64_t k = 0; k < agree; k++) out->ref_diff = fmax(out->ref_diff, c->ref_diff[k]);
    return LAG_OK;
}

lag_result lag_cost_measure(const lag_sim_def *def, const lag_cost_opts *o,
                            lag_cost_table *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    out->chosen = out->best = out->current = -1;
    cost_run c = {.def = def, .o = o, .clock = o->clock ? o->clock : thread_cpu,
                  .cheapest = INFINITY};
    lag_result rc = check_opts(o, &c.nper_asked, err, errlen);
    if (rc != LAG_OK) return rc;
    const size_t np = (size_t)c.nper_asked;
    c.sim = malloc(sizeof *c.sim);
    c.sim2 = malloc(sizeof *c.sim2);
    c.ref_q = malloc(sizeof(double) * np * LAG_MAX_DOF);
    c.ref_e = malloc(sizeof(double) * np);
    c.ref_diff = malloc(sizeof(double) * np);
    c.per = malloc(sizeof(double) * np);
    if (!c.sim || !c.sim2 || !c.ref_q || !c.ref_e || !c.ref_diff || !c.per) {
        rc = fail(err, errlen, "out of memory", LAG_ERR_ARG);
    } else {
        c.t_start = c.clock(o->clock_ctx);
        rc = prepare(&c, out, err, errlen);
    }
    if (rc == LAG_OK) {
        lag_method order[LAG_METHOD_COUNT];
        int nm = method_order(order);
        for (int mi = 0; mi < nm && !out->budget_hit; mi++) refine_method(&c, out, order[mi]);
        if (o->current) add_current(&c, out);
        pick_rows(out);
    }
    out->spent = c.clock ? c.clock(o->clock_ctx) - c.t_start : 0;
    free(c.sim);
    free(c.sim2);
    free(c.ref_q);
    free(c.ref_e);
    free(c.ref_diff);
    free(c.per);
    return rc;
}
