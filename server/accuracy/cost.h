/*
 * What accuracy costs on one scene: the integrator settings a plant could run with, each
 * measured on the scene itself, and the cheapest one that meets an error asked for.
 *
 * "Error" means: over `horizon` seconds of sim time from the scene's initial state, with
 * no input (or the scene's held input), the largest difference between a setting's q and
 * a reference's q at the scene's publish times, in each joint's own unit (m or rad). The
 * reference is dopri5 at a tolerance far below the error asked for (with a floor or stops,
 * at a tick of period / 1024, the finest dt tried). Effects stay as the scene has them (a floor, stops
 * or friction are located and applied as in a run); a bounce shorter than one tick ends
 * in resting contact (the Zeno guard), so a coarse tick can end bouncing earlier than the
 * reference does, and shows as error.
 *
 * Settings tried: each fixed-step method at dt = period / k (k = 1, 2, 4, ...: a dt that
 * divides the period, as the daemon needs; down to period / 1024), and dopri5 at
 * rtol = atol = 1e-3, 1e-4, ... down to 100 times the reference's tolerance (tick = the
 * period). A method's refinement stops once it meets the error (finer costs
 * more), once it costs more than the cheapest setting that met it so far (it can no
 * longer be chosen), or when the calibration's budget of CPU time is spent.
 *
 * The cost of a setting is the CPU time one sim-second takes on this machine (the least
 * of a few timed batches; the clock is the caller's, so tests may make one up); its
 * real-time margin is period's wall time over its cost, 1 / cost.
 *
 * What cannot be known: a second reference runs beside the first, dopri5 at ten times its
 * tolerance (with a floor or stops, whose tick bounds dopri5's steps so that the tolerance
 * changes nothing, rk4 at the same tick). Where they differ by more than the error asked
 * for, the reference itself is not known to that error (a chaotic scene, or a motion that
 * passes near an unstable equilibrium, amplifies any difference, the arithmetic's too):
 * the pair is tried again a hundred times tighter, down to 1e-13; if even the tightest
 * pair differs by more than the error before the horizon's end, the scene is predictable
 * to that error only for the periods before (lag_cost_table.horizon), every setting is
 * measured over those alone, and the table says the horizon was cut. Without an error
 * asked for (from_current), the pair may differ by at most the current setting's error.
 */
#ifndef LAGSIM_COST_H
#define LAGSIM_COST_H

#include <stdbool.h>
#include <stdint.h>

#include "lagsim/lagsim.h"

#define LAG_COST_MAX_ROWS 128

typedef struct lag_cost_row {
    lag_method method;
    double dt;               /* s: the step of a fixed-step method; dopri5's tick */
    double tol;              /* dopri5: rtol (= atol unless atol is set); 0 for fixed-step methods */
    double atol;             /* dopri5: atol when it differs from tol (a scene's own); else 0 */
    double error;            /* max |q - q_ref| over the horizon (joint's unit); inf on a fault */
    double energy_error;     /* max |E - E_ref| over the horizon (J) */
    double cpu_per_sim_s;    /* CPU seconds per sim-second */
    lag_result fault;        /* LAG_OK, or what a tick of this setting ran into */
    bool meets;              /* error * safety <= target */
} lag_cost_row;

typedef struct lag_cost_opts {
    double target;      /* the error asked for (joint's unit) */
    double horizon;     /* s of sim time measured (1) */
    double period;      /* s: the scene's publish period; fixed dts divide it */
    double safety;      /* a setting meets the target when error * safety <= target (4) */
    double budget;      /* CPU seconds the whole calibration may take (3) */
    bool complete;      /* refine every method until it meets the target (or the budget
                           ends), not only while it could still be the cheapest: a whole
                           work-precision curve per method (lagsimd --cost) */
    const lag_integrator_def *current; /* the scene's own setting: measured as a row too
                                          and marked (lag_cost_table.current); NULL: none */
    bool from_current;  /* no error asked for: the target is the error `current` reaches
                           over the horizon, times safety (a setting meets it when it is at
                           least as accurate); `target` when that is not finite */
    double (*clock)(void *ctx); /* CPU seconds; NULL: the process's CPU clock */
    void *clock_ctx;
} lag_cost_opts;

/* target 1e-6, horizon 1 s, period 0.01 s, safety 4, budget 3 s, the process clock. */
lag_cost_opts lag_cost_opts_default(void);

typedef struct lag_cost_table {
    int n;
    lag_cost_row row[LAG_COST_MAX_ROWS];
    int chosen;            /* the cheapest row that meets the target; -1 if none does */
    int best;              /* the row of least error (what is offered when none meets) */
    int current;           /* the row of opts.current; -1 without one */
    double target;         /* the error the rows are marked at (opts.target, or the
                              current setting's error times safety with from_current) */
    bool target_from_current; /* target is the current setting's */
    double horizon;        /* s measured: opts.horizon, or the part of it the references
                              agree on within the target (horizon_cut) */
    bool horizon_cut;      /* the tightest references differ by more than the target
                              after `horizon` s: the scene is not predictable to the target
                              over opts.horizon; the rows are measured over `horizon` */
    double ref_tol;        /* the reference's dopri5 tolerance */
    lag_cost_row ref2;     /* the second reference's setting: dopri5 at 10 ref_tol, or with
                              a floor or stops (whose tick bounds dopri5's steps, so that its
                              tolerance changes nothing) rk4 at the reference's tick */
    double agree_tol;      /* how far the references may differ: the target, or with
                              from_current the current setting's error (the reference is then
                              known to about a tenth of the error it measures) */
    double ref_diff;       /* their largest difference over `horizon` (joint's unit) */
    double spent;          /* CPU seconds the calibration took */
    bool budget_hit;       /* it stopped early: rows are missing */
} lag_cost_table;

/*
 * Measures the settings for DEF (its integrator is ignored but as opts.current; its
 * model, effects, initial state and input held at zero are used) and chooses. Returns
 * LAG_OK, or LAG_ERR_ARG with a message when the options or the definition cannot be
 * measured, the reference itself faults, or the scene is not predictable to the target
 * over even one period (then nothing can be said of the error).
 */
lag_result lag_cost_measure(const lag_sim_def *def, const lag_cost_opts *o,
                            lag_cost_table *out /* OUT */, char *err, size_t errlen);

/* The integrator definition of ROW, from DEF's other settings. */
lag_integrator_def lag_cost_row_integrator(const lag_sim_def *def, const lag_cost_row *row);

/* "rk4 dt 0.0025 s" / "dopri5 tol 1e-08" for messages. */
void lag_cost_row_describe(const lag_cost_row *row, char *buf, size_t len);

#endif
