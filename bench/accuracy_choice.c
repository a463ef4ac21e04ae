/*
 * What integrator.error's choice costs against the best the --cost table offers: for every
 * shipped scene (config/NAME.yaml) and E = 1e-4, 1e-6, 1e-9, in one run,
 *   1. the setting lagsimd chooses for E (lag_cost_measure as lagsimd calls it at start:
 *      refinement stops once a method meets E or can no longer be the cheapest);
 *   2. the scene's whole --cost table (complete: every method refined until it meets E)
 *      and its cheapest row that meets E;
 *   3. both timed again here, alternately (the least CPU time of REPS batches each, one
 *      batch being as many runs over the horizon as fill 20 ms of CPU), and the ratio
 *      chosen / cheapest: 1 when the choice is that row; above 1 when the calibration's
 *      own timings, noisier, picked another.
 * usage: accuracy_choice CONFIG_DIR [REPS]     (REPS default 7)
 */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lagsim_clock.h"

#include "cost.h"
#include "scene.h"

static double cpu_now(void)
{
    return lag_clock_thread_cpu_s();
}

/* One run of DEF with integrator IN over the horizon, period by period; false on a fault. */
static bool run_once(const lag_sim_def *def, const lag_integrator_def *in, double period,
                     double horizon)
{
    static lag_sim s;
    lag_sim_def d = *def;
    d.integrator = *in;
    char err[256];
    if (lag_sim_init(&s, &d, err, sizeof err) != LAG_OK) return false;
    const int64_t per = llround(period / in->dt);
    const int64_t nper = (int64_t)floor(horizon / period * (1 + 1e-12) + 1e-9);
    for (int64_t k = 0; k < nper; k++) {
        if (lag_sim_advance_within(&s, per, s.tick + per) != LAG_OK) return false;
        lag_event ev;
        while (lag_sim_poll_event(&s, &ev)) {}
    }
    return true;
}

/* CPU seconds per sim-second of one batch (runs filling about 20 ms of CPU). */
static double batch(const lag_sim_def *def, const lag_integrator_def *in, double period,
                    double horizon)
{
    int runs = 0;
    const double t0 = cpu_now();
    double t = t0;
    while (t - t0 < 0.02 || runs == 0) {
        if (!run_once(def, in, period, horizon)) return INFINITY;
        runs++;
        t = cpu_now();
    }
    return (t - t0) / (runs * horizon);
}

static int by_name(const void *a, const void *b) { return strcmp(a, b); }

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: accuracy_choice CONFIG_DIR [REPS]\n");
        return 2;
    }
    const int reps = argc > 2 ? atoi(argv[2]) : 7;
    static char names[32][64];
    int n = 0;
    DIR *d = opendir(argv[1]);
    if (!d) {
        fprintf(stderr, "accuracy_choice: cannot open %s\n", argv[1]);
        return 2;
    }
    struct dirent *e;
    while ((e = readdir(d)) && n < 32) {
        size_t len = strlen(e->d_name);
        if (len > 5 && len < sizeof names[0] && !strcmp(e->d_name + len - 5, ".yaml"))
            snprintf(names[n++], sizeof names[0], "%s", e->d_name);
    }
    closedir(d);
    qsort(names, (size_t)n, sizeof names[0], by_name);
    const double targets[] = {1e-4, 1e-6, 1e-9};
    printf("| scene | E | chosen | cheapest in --cost that meets E | CPU s/sim-s chosen | cheapest | ratio |\n");
    printf("|---|---|---|---|---|---|---|\n");
    double worst = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 3; j++) {
            char path[2400], err[512];
            snprintf(path, sizeof path, "%s/%s", argv[1], names[i]);
            static lag_scene sc;
            if (lag_scene_load(path, NULL, 0, &sc, err, sizeof err) != 0) {
                fprintf(stderr, "%s\n", err);
                return 1;
            }
            lag_cost_opts o = lag_cost_opts_default();
            o.target = targets[j];
            o.horizon = sc.accuracy.horizon > 0 ? sc.accuracy.horizon : 1.0;
            o.period = 1.0 / sc.publish_hz;
            static lag_cost_table choice, full;
            if (lag_cost_measure(&sc.sim, &o, &choice, err, sizeof err) != LAG_OK) {
                fprintf(stderr, "%s: %s\n", names[i], err);
                return 1;
            }
            o.complete = true;
            if (lag_cost_measure(&sc.sim, &o, &full, err, sizeof err) != LAG_OK) {
                fprintf(stderr, "%s: %s\n", names[i], err);
                return 1;
            }
            if (choice.chosen < 0 || full.chosen < 0) {
                printf("| %s | %g | none meets | | | | |\n", names[i], targets[j]);
                continue;
            }
            const lag_cost_row *rc = &choice.row[choice.chosen], *rf = &full.row[full.chosen];
            lag_integrator_def ic = lag_cost_row_integrator(&sc.sim, rc);
            lag_integrator_def jf = lag_cost_row_integrator(&sc.sim, rf);
            double bc = INFINITY, bf = INFINITY;
            for (int r = 0; r < reps; r++) {
                bc = fmin(bc, batch(&sc.sim, &ic, o.period, o.horizon));
                bf = fmin(bf, batch(&sc.sim, &jf, o.period, o.horizon));
            }
            char dc[96], df[96];
            lag_cost_row_describe(rc, dc, sizeof dc);
            lag_cost_row_describe(rf, df, sizeof df);
            const double ratio = bc / bf;
            worst = fmax(worst, ratio);
            printf("| %s | %g | %s | %s | %.3g | %.3g | %.2f |\n", names[i], targets[j], dc, df,
                   bc, bf, ratio);
            fflush(stdout);
        }
    printf("\nworst ratio %.2f\n", worst);
    return worst <= 2.0 ? 0 : 1;
}
