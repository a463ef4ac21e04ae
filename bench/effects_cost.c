/*
 * Cost of effects: ns per tick of each model with no effects and with each
 * effect on alone, measured in one run, printed as a Markdown table.
 *
 *   effects_cost [reps]      (default 9: the fastest of 9 repetitions is kept, the
 *                             repetitions interleaved over all rows)
 *
 * A tick is what the daemon does per sim step: lag_sim_advance(s, 1) then lag_sim_observe
 * (the published state). Each repetition runs 20 scenes of 2 s (2000 ticks of rk4 at
 * dt = 1e-3) from the scene's initial state, so rows with hybrid effects (a stick bouncing
 * to rest on the floor, friction sticking) contain their events in proportion.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lagsim_clock.h"

#include "lagsim/lagsim.h"

/* Rows: the bare model, then each effect of the core's table in its order (row k + 1 is
 * lag_effect_info_get(k)); an effect this file gives no settings makes the program fail
 * by name (bench_effects_cost_rows), so a new effect is not left out of the table. */
enum { ROW_NONE, ROW_COUNT = 1 + LAG_EFF_COUNT };

static const char *row_name(int row)
{
    return row == ROW_NONE ? "none (bare model)" : lag_effect_info_get(row - 1).name;
}

static double now_s(void)
{
    return lag_clock_mono_s();
}

/* The settings of effect `bit` on a model of n joints (d's initial state set). Returns
 * 1, 0 when the effect does not apply to the model (floor: stick only), -1 when this file
 * has no settings for it. */
static int effect_settings(uint32_t bit, lag_model_kind kind, int n, lag_sim_def *d)
{
    lag_effects_def *e = &d->effects;
    e->enabled = bit;
    switch (bit) {
    case LAG_EFF_DAMPING:
        for (int i = 0; i < n; i++) e->damping[i] = 0.05;
        return 1;
    case LAG_EFF_FRICTION:
        for (int i = 0; i < n; i++) { e->friction_static[i] = 0.2; e->friction_kinetic[i] = 0.1; }
        return 1;
    case LAG_EFF_LIMITS: /* stops on every joint; the manipulator's q2 hits its stops */
        for (int i = 0; i < n; i++) {
            e->limit_on[i] = true;
            e->limit_lower[i] = d->q0[i] - 20.0;
            e->limit_upper[i] = d->q0[i] + 20.0;
            e->restitution[i] = 0.5;
        }
        if (kind == LAG_MODEL_MANIPULATOR) { e->limit_lower[1] = 0.1; e->limit_upper[1] = 0.8; }
        return 1;
    case LAG_EFF_FLOOR:
        e->floor_restitution = 0.3;
        return kind == LAG_MODEL_STICK;
    case LAG_EFF_ACTUATOR:
        for (int i = 0; i < n; i++) { e->actuator_max[i] = 100.0; e->actuator_tau[i] = 0.02; }
        return 1;
    case LAG_EFF_DISTURBANCE:
        e->n_disturbances = 2;
        e->disturbances[0] = (lag_disturbance){0.5, 0, true, 0.1, 0.0};
        e->disturbances[1] = (lag_disturbance){1.0, 0, false, 0.2, 0.5};
        return 1;
    case LAG_EFF_NOISE:
        e->noise_seed = 7;
        for (int i = 0; i < n; i++) { e->noise_q[i] = 1e-3; e->noise_qd[i] = 1e-3; }
        return 1;
    case LAG_EFF_SPRING: /* about each joint's initial position */
        for (int i = 0; i < n; i++) { e->spring_k[i] = 1.0; e->spring_rest[i] = d->q0[i]; }
        return 1;
    }
    return -1;
}

/* The scene of one row: the model's moving initial state plus that one effect. Returns
 * effect_settings' answer (1 for the bare model). */
static int scene(lag_model_kind kind, int row, lag_sim_def *d)
{
    *d = lag_default_sim_def(kind);
    switch (kind) {
    case LAG_MODEL_STICK: d->q0[1] = 1.2; d->qd0[0] = 0.3; break;
    case LAG_MODEL_MANIPULATOR: d->q0[0] = 0.3; d->q0[1] = 0.3; d->qd0[0] = 1.0; d->qd0[1] = 0.5; break;
    default: d->q0[1] = 0.3; d->q0[2] = -0.2; break;
    }
    if (row == ROW_NONE) return 1;
    return effect_settings(lag_effect_info_get(row - 1).bit, kind, d->model.nq, d);
}

/* ns per tick of one repetition; NAN if the scene faulted. */
static double measure(const lag_sim_def *d, int reps, double *sink)
{
    enum { SCENES = 20, TICKS = 2000 };
    static lag_sim s;
    char err[256];
    if (lag_sim_init(&s, d, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "effects_cost: %s\n", err);
        return NAN;
    }
    const double u[LAG_MAX_DOF] = {0.5, 0.2, 0.0};
    double best = INFINITY;
    for (int r = 0; r < reps; r++) {
        double t0 = now_s();
        for (int c = 0; c < SCENES; c++) {
            lag_sim_reset(&s, NULL, NULL);
            lag_sim_set_input(&s, u);
            for (int k = 0; k < TICKS; k++) {
                if (lag_sim_advance(&s, 1, true) != LAG_OK) return NAN;
                double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
                lag_sim_observe(&s, q, qd);
                *sink += q[0] + qd[0];
                lag_event ev;
                while (lag_sim_poll_event(&s, &ev)) *sink += ev.t;
            }
        }
        double ns = (now_s() - t0) * 1e9 / (SCENES * TICKS);
        if (ns < best) best = ns;
    }
    return best;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? atoi(argv[1]) : 9;
    if (reps < 1) reps = 1;
    /* repetitions outermost, so that every row sees the same machine load; min per cell */
    double ns[ROW_COUNT][LAG_MODEL_COUNT], sink = 0.0;
    for (int row = 0; row < ROW_COUNT; row++)
        for (int kind = 0; kind < LAG_MODEL_COUNT; kind++) ns[row][kind] = INFINITY;
    for (int r = 0; r < reps; r++)
        for (int row = 0; row < ROW_COUNT; row++)
            for (int kind = 0; kind < LAG_MODEL_COUNT; kind++) {
                lag_sim_def d;
                int has = scene((lag_model_kind)kind, row, &d);
                if (has < 0) {
                    fprintf(stderr, "effects_cost: effect '%s' of the core's table has no "
                                    "settings here (effect_settings)\n", row_name(row));
                    return 1;
                }
                if (!has) { ns[row][kind] = -1.0; continue; }
                double v = measure(&d, 1, &sink);
                if (isnan(v) || isnan(ns[row][kind])) ns[row][kind] = NAN;
                else if (v < ns[row][kind]) ns[row][kind] = v;
            }
    printf("ns per tick (lag_sim_advance of one tick + lag_sim_observe), rk4 at dt = 1 ms, "
           "fastest of %d repetitions of 20 x 2000 ticks; in parentheses the ratio to the bare "
           "model\n\n", reps);
    printf("| effect on alone |");
    for (int kind = 0; kind < LAG_MODEL_COUNT; kind++)
        printf(" %s |", lag_model_info_get((lag_model_kind)kind)->name);
    printf("\n|---|");
    for (int kind = 0; kind < LAG_MODEL_COUNT; kind++) printf("---:|");
    printf("\n");
    for (int row = 0; row < ROW_COUNT; row++) {
        printf("| %s |", row_name(row));
        for (int kind = 0; kind < LAG_MODEL_COUNT; kind++) {
            double v = ns[row][kind];
            if (v < 0) printf(" n/a |");
            else if (isnan(v)) printf(" fault |");
            else if (row == ROW_NONE) printf(" %.0f |", v);
            else printf(" %.0f (%.2f) |", v, v / ns[ROW_NONE][kind]);
        }
        printf("\n");
    }
    fprintf(stderr, "(checksum %g)\n", sink);
    return 0;
}
