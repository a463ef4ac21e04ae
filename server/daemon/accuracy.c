/*
 * Accuracy as a setting: a scene's integrator.error makes lagsimd choose the integrator
 * (method and dt, or dopri5's tolerance) at start, on this scene and this machine, and
 * `lagsimd --cost` prints what every setting it measured costs (server/accuracy/cost.h
 * says what is measured and how).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cost.h"
#include "daemon.h"
#include "lagsim_num.h"
#include "lagsim_out.h"

/* The real-time margin a chosen setting must keep at least: the daemon also serves LCM,
 * logs and publishes, and a loaded machine has less than one core for it. */
#define RT_MARGIN_MIN 4.0

#define DEFAULT_TARGET 1e-6 /* --cost on a scene that asks for no error */

static lag_cost_opts opts_for(const lag_scene *sc, double target)
{
    lag_cost_opts o = lag_cost_opts_default();
    o.target = target;
    o.horizon = sc->accuracy.horizon > 0 ? sc->accuracy.horizon : 1.0;
    o.period = 1.0 / sc->publish_hz;
    return o;
}

/* How many times faster than real time a row runs at the scene's rate. */
static double margin(const lag_scene *sc, const lag_cost_row *r)
{
    double rate = sc->realtime.mode == LAG_RT_REALTIME ? sc->realtime.rate : 1.0;
    return r->cpu_per_sim_s > 0 ? 1.0 / (r->cpu_per_sim_s * rate) : INFINITY;
}

static int measure(const lag_scene *sc, double target, bool complete, lag_cost_table *t)
{
    char err[512];
    lag_cost_opts o = opts_for(sc, target);
    o.complete = complete;
    if (lag_cost_measure(&sc->sim, &o, t, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: %s: integrator.error: %s\n", sc->path, err);
        return -1;
    }
    return 0;
}

/* The overrides that give the scene ROW's integrator: what the run then is, whatever
 * reloads its scene (a change made while running, a rerun, a replay given them). */
static void apply(lagsimd_choice *ch, const lag_cost_row *row)
{
    ch->n = 0;
    snprintf(ch->kv[ch->n++], sizeof ch->kv[0], "integrator.method=%s", lag_method_name(row->method));
    char num[LAG_NUM_LEN];
    snprintf(ch->kv[ch->n++], sizeof ch->kv[0], "integrator.dt=%s", lag_num(row->dt, num));
    if (row->tol > 0) {
        snprintf(ch->kv[ch->n++], sizeof ch->kv[0], "integrator.rtol=%s", lag_num(row->tol, num));
        snprintf(ch->kv[ch->n++], sizeof ch->kv[0], "integrator.atol=%s", lag_num(row->tol, num));
    }
}

static void say_overrides(const lagsimd_choice *ch)
{
    fputs("lagsimd: to run this setting again (or --replay a log of this run):", stderr);
    for (int i = 0; i < ch->n; i++) fprintf(stderr, " --set %s", ch->kv[i]);
    fputs("\n", stderr);
}

lag_result lagsimd_choose_integrator(const lag_scene *sc, bool offline, bool quiet,
                                      lagsimd_choice *ch)
{
    ch->n = 0;
    if (!(sc->accuracy.error > 0)) return LAGSIMD_EXIT_OK;
    static lag_cost_table t;
    if (measure(sc, sc->accuracy.error, false, &t) != 0) return LAGSIMD_EXIT_USAGE;
    const double e = sc->accuracy.error, horizon = opts_for(sc, e).horizon;
    const bool paced = !offline && sc->realtime.mode == LAG_RT_REALTIME;
    /* the cheapest that meets; in real time only one that keeps the margin */
    int pick = t.chosen;
    if (pick >= 0 && paced && margin(sc, &t.row[pick]) < RT_MARGIN_MIN) pick = -1;
    char d[96];
    if (pick >= 0) {
        lag_cost_row_describe(&t.row[pick], d, sizeof d);
        (void)quiet; /* said even with -q: a log of this run replays only with the overrides */
        fprintf(stderr, "lagsimd: integrator.error %g over %g s: %s, the cheapest of %d "
                    "settings measured on this scene that meets it %g times over (error %.2g; "
                    "%.2g s of CPU per sim-second, %.3g x real time); calibration took %.2f s "
                    "of CPU%s\n", e, horizon, d, t.n, lag_cost_opts_default().safety,
                    t.row[pick].error, t.row[pick].cpu_per_sim_s, margin(sc, &t.row[pick]),
                    t.spent, t.budget_hit ? " (its budget ran out: some settings unmeasured)" : "");
        apply(ch, &t.row[pick]);
        say_overrides(ch);
        return LAGSIMD_EXIT_OK;
    }
    /* none: the most accurate setting (that runs in real time, when paced) */
    int best = -1;
    for (int i = 0; i < t.n; i++) {
        const lag_cost_row *r = &t.row[i];
        if (r->fault != LAG_OK || (paced && margin(sc, r) < RT_MARGIN_MIN)) continue;
        if (best < 0 || r->error < t.row[best].error) best = i;
    }
    if (best < 0) {
        fprintf(stderr, "lagsimd: %s: integrator.error %g: no setting measured ran without a "
                "fault%s\n", sc->path, e, paced ? " at real time" : "");
        return LAGSIMD_EXIT_USAGE;
    }
    lag_cost_row_describe(&t.row[best], d, sizeof d);
    if (paced) {
        fprintf(stderr, "lagsimd: %s: integrator.error %g cannot be met at real time on this "
                "machine (a setting must be %g times below it and keep a %gx margin to real "
                "time): the best that keeps the margin is %s, error %.2g over %g s "
                "(lagsimd --cost shows every setting; a larger error, a lower publish_hz or "
                "realtime.rate, or lockstep mode would do)\n", sc->path, e,
                lag_cost_opts_default().safety, RT_MARGIN_MIN, d,
                t.row[best].error, horizon);
        return LAGSIMD_EXIT_USAGE;
    }
    fprintf(stderr, "lagsimd: warning: integrator.error %g is not met by any setting measured "
            "on this scene; running with the most accurate, %s, error %.2g over %g s\n", e, d,
            t.row[best].error, horizon);
    apply(ch, &t.row[best]);
    say_overrides(ch);
    return LAGSIMD_EXIT_OK;
}

/* Copies the file at path into the descriptor out (closed). Returns 0 or -1. */
static int copy_into(const char *path, int out)
{
    FILE *in = fopen(path, "rb");
    char buf[65536];
    size_t n;
    int rc = in ? 0 : -1;
    while (in && (n = fread(buf, 1, sizeof buf, in)) > 0)
        if (write(out, buf, n) != (ssize_t)n) rc = -1;
    if (in) fclose(in);
    if (close(out) != 0) rc = -1;
    return rc;
}

/* The work-precision diagram of the table, drawn by gnuplot into a temporary file and
 * copied to out (png, opened already by the rules of every output, lagsim_out.h). */
static int plot(const lag_scene *sc, const lag_cost_table *t, double target, const char *png,
                int out)
{
    char tmp_png[] = "/tmp/lagsimd-cost-XXXXXX.png";
    int tfd = mkstemps(tmp_png, 4);
    if (tfd < 0) {
        close(out);
        fprintf(stderr, "lagsimd: --plot: cannot make a temporary file: %s\n", strerror(errno));
        return LAGSIMD_EXIT_RUNTIME;
    }
    close(tfd);
    char data[] = "/tmp/lagsimd-cost-XXXXXX";
    int fd = mkstemp(data);
    if (fd < 0) {
        close(out);
        unlink(tmp_png);
        fprintf(stderr, "lagsimd: --plot: cannot make a temporary file: %s\n", strerror(errno));
        return LAGSIMD_EXIT_RUNTIME;
    }
    FILE *f = fdopen(fd, "w");
    for (int m = 0; f && m < LAG_METHOD_COUNT; m++) { /* one block per method */
        fprintf(f, "# %s\n", lag_method_name((lag_method)m));
        for (int i = 0; i < t->n; i++)
            if (t->row[i].method == (lag_method)m && t->row[i].fault == LAG_OK)
                fprintf(f, "%.6g %.6g\n", t->row[i].cpu_per_sim_s, fmax(t->row[i].error, 1e-17));
        fputs("\n\n", f);
    }
    if (!f || fclose(f) != 0) {
        close(out);
        unlink(data);
        unlink(tmp_png);
        fprintf(stderr, "lagsimd: --plot: cannot write %s\n", data);
        return LAGSIMD_EXIT_RUNTIME;
    }
    FILE *g = popen("gnuplot", "w");
    if (!g) {
        close(out);
        unlink(data);
        unlink(tmp_png);
        fprintf(stderr, "lagsimd: --plot: cannot run gnuplot\n");
        return LAGSIMD_EXIT_RUNTIME;
    }
    fprintf(g, "set terminal pngcairo size 900,600 enhanced font 'DejaVu Sans,11'\n"
               "set output '%s'\nset logscale xy\nset format x '10^{%%L}'\nset format y '10^{%%L}'\n"
               "set grid\nset key outside right top\n"
               "set xlabel 'CPU time per simulated second (s/s), this machine'\n"
               "set ylabel 'max |q - q_{ref}| over %g s (m or rad)'\n"
               "set title \"%s: what accuracy costs (lagsimd --cost)\" noenhanced\n"
               "set arrow from graph 0, first %g to graph 1, first %g nohead dt 2 lc rgb 'red'\n"
               "set label 'error asked for' at graph 0.02, first %g offset 0,0.6 tc rgb 'red'\n"
               "set arrow from graph 0, first %g to graph 1, first %g nohead dt 3 lc rgb 'gray40'\n"
               "set label 'what a setting must reach (/ %g)' at graph 0.02, first %g offset 0,-0.7 tc rgb 'gray40'\n",
            tmp_png, opts_for(sc, target).horizon, sc->path, target, target, target,
            target / opts_for(sc, target).safety, target / opts_for(sc, target).safety,
            opts_for(sc, target).safety, target / opts_for(sc, target).safety);
    fputs("plot ", g);
    for (int m = 0; m < LAG_METHOD_COUNT; m++)
        fprintf(g, "%s'%s' index %d using 1:2 with linespoints lw 2 pt 7 title '%s'", m ? ", " : "",
                data, m, lag_method_name((lag_method)m));
    fputs("\n", g);
    int rc = pclose(g);
    unlink(data);
    if (rc != 0) {
        close(out);
        unlink(tmp_png);
        fprintf(stderr, "lagsimd: --plot: gnuplot failed (exit %d)\n", rc);
        return LAGSIMD_EXIT_RUNTIME;
    }
    rc = copy_into(tmp_png, out);
    unlink(tmp_png);
    if (rc != 0) {
        fprintf(stderr, "lagsimd: --plot: cannot write %s\n", png);
        return LAGSIMD_EXIT_RUNTIME;
    }
    return LAGSIMD_EXIT_OK;
}

lag_result lagsimd_cost(const lag_scene *sc, const char *png, bool force)
{
    static lag_cost_table t;
    const bool asked = sc->accuracy.error > 0;
    const double target = asked ? sc->accuracy.error : DEFAULT_TARGET;
    int out = -1;
    if (png) { /* refused before anything is measured */
        char oerr[512];
        const char *inputs[1] = {sc->path};
        out = lag_out_open("--plot", png, force, inputs, 1, 0, oerr, sizeof oerr);
        if (out < 0) {
            fprintf(stderr, "lagsimd: %s\n", oerr);
            return out == LAG_OUT_REFUSED ? LAGSIMD_EXIT_USAGE : LAGSIMD_EXIT_RUNTIME;
        }
    }
    if (measure(sc, target, true, &t) != 0) {
        if (out >= 0) close(out);
        return LAGSIMD_EXIT_USAGE;
    }
    const lag_cost_opts o = opts_for(sc, target);
    const lag_model_info *info = lag_model_info_get(sc->sim.model.kind);
    printf("# %s: %s, error %s %g over %g s (a setting meets it with %g times to spare),\n"
           "# publish period %g s; reference dopri5 tolerance %.0e (with a floor or stops at a\n"
           "# tick of period/1024);\n"
           "# CPU measured on this machine: %.2f s for %d settings%s\n",
           sc->path, info ? info->name : "?",
           asked ? "asked for (integrator.error)" : "not asked for by the scene: rows marked at",
           target, o.horizon, o.safety, o.period, t.ref_tol,
           t.spent, t.n, t.budget_hit ? " (budget ran out: finer settings unmeasured)" : "");
    printf("%-34s %12s %14s %13s %13s  %s\n", "setting", "error", "energy error", "CPU s/sim-s",
           "x real time", "");
    for (int i = 0; i < t.n; i++) {
        const lag_cost_row *r = &t.row[i];
        char d[96];
        lag_cost_row_describe(r, d, sizeof d);
        if (r->fault != LAG_OK) {
            printf("%-34s %12s   fault: %s\n", d, "-", lag_result_string(r->fault));
            continue;
        }
        printf("%-34s %12.3g %14.3g %13.3g %13.3g  %s\n", d, r->error, r->energy_error,
               r->cpu_per_sim_s, margin(sc, r),
               i == t.chosen ? (asked ? "meets, chosen" : "meets, would be chosen")
                             : r->meets ? "meets" : "");
    }
    if (t.chosen < 0) printf("# no setting measured meets %g\n", target);
    return png ? plot(sc, &t, target, png, out) : LAGSIMD_EXIT_OK;
}
