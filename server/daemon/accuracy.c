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

/* Measures the scene's settings for target; without an error asked for (from_current),
 * for the error its own integrator reaches, target being what is used if that cannot be
 * measured. */
static int measure(const lag_scene *sc, double target, bool complete, bool from_current,
                   lag_cost_table *t)
{
    char err[512];
    lag_cost_opts o = opts_for(sc, target);
    o.complete = complete;
    o.from_current = from_current;
    o.current = from_current ? &sc->sim.integrator : NULL;
    if (lag_cost_measure(&sc->sim, &o, t, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: %s: integrator.error: %s\n", sc->path, err);
        return -1;
    }
    return 0;
}

/* "the scene is predictable to E for about H s (...)" when the references' horizon was
 * cut; "" else. */
static void unpredictable(const lag_cost_table *t, char *buf, size_t len)
{
    buf[0] = '\0';
    char d[96];
    lag_cost_row_describe(&t->ref2, d, sizeof d);
    if (t->horizon_cut)
        snprintf(buf, len, "the scene is predictable to %.3g for about %.6g s: after it two "
                 "references, dopri5 tol %.0e and %s, differ by more than that (its motion "
                 "amplifies any difference, the arithmetic's too)", t->agree_tol, t->horizon,
                 t->ref_tol, d);
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
        snprintf(ch->kv[ch->n++], sizeof ch->kv[0], "integrator.atol=%s",
                 lag_num(row->atol > 0 ? row->atol : row->tol, num));
    }
}

static void say_overrides(const lagsimd_choice *ch)
{
    fputs("lagsimd: to run this setting again (or --replay a log of this run):", stderr);
    for (int i = 0; i < ch->n; i++) fprintf(stderr, " --set %s", ch->kv[i]);
    fputs("\n", stderr);
}

/* None meets E: the most accurate setting (that keeps the margin, when paced), run with
 * a warning, or refused when paced. */
static lag_result choose_best(const lag_scene *sc, const lag_cost_table *t, bool paced,
                              lagsimd_choice *ch)
{
    const double e = sc->accuracy.error;
    int best = -1;
    for (int i = 0; i < t->n; i++) {
        const lag_cost_row *r = &t->row[i];
        if (r->fault != LAG_OK || (paced && margin(sc, r) < RT_MARGIN_MIN)) continue;
        if (best < 0 || r->error < t->row[best].error) best = i;
    }
    if (best < 0) {
        fprintf(stderr, "lagsimd: %s: integrator.error %g: no setting measured ran without a "
                "fault%s\n", sc->path, e, paced ? " at real time" : "");
        return LAGSIMD_EXIT_USAGE;
    }
    char d[96];
    lag_cost_row_describe(&t->row[best], d, sizeof d);
    if (paced) {
        fprintf(stderr, "lagsimd: %s: integrator.error %g cannot be met at real time on this "
                "machine (a setting must be %g times below it and keep a %gx margin to real "
                "time): the best that keeps the margin is %s, error %.2g over %g s "
                "(lagsimd --cost shows every setting; a larger error, a lower publish_hz or "
                "realtime.rate, or lockstep mode would do)\n", sc->path, e,
                lag_cost_opts_default().safety, RT_MARGIN_MIN, d, t->row[best].error, t->horizon);
        return LAGSIMD_EXIT_USAGE;
    }
    fprintf(stderr, "lagsimd: warning: integrator.error %g is not met by any setting measured "
            "on this scene; running with the most accurate, %s, error %.2g over %g s\n", e, d,
            t->row[best].error, t->horizon);
    apply(ch, &t->row[best]);
    say_overrides(ch);
    return LAGSIMD_EXIT_OK;
}

lag_result lagsimd_choose_integrator(const lag_scene *sc, bool offline, bool quiet,
                                      lagsimd_choice *ch)
{
    ch->n = 0;
    if (!(sc->accuracy.error > 0)) return LAGSIMD_EXIT_OK;
    static lag_cost_table t;
    if (measure(sc, sc->accuracy.error, false, false, &t) != 0) return LAGSIMD_EXIT_USAGE;
    const double e = sc->accuracy.error, asked = opts_for(sc, e).horizon;
    const bool paced = !offline && sc->realtime.mode == LAG_RT_REALTIME;
    char why[400];
    unpredictable(&t, why, sizeof why);
    if (why[0] && paced) { /* a promise it cannot keep: refused, as an error no setting meets */
        fprintf(stderr, "lagsimd: %s: integrator.horizon %g s cannot be honoured: %s; ask for "
                "a horizon of at most %.6g s, or a larger error (lagsimd --cost shows the "
                "settings over the horizon it can honour)\n", sc->path, asked, why, t.horizon);
        return LAGSIMD_EXIT_USAGE;
    }
    if (why[0])
        fprintf(stderr, "lagsimd: warning: integrator.horizon %g s cannot be honoured: %s; the "
                "setting is chosen for the %.6g s it can honour\n", asked, why, t.horizon);
    /* the cheapest that meets; in real time only one that keeps the margin */
    int pick = t.chosen;
    if (pick >= 0 && paced && margin(sc, &t.row[pick]) < RT_MARGIN_MIN) pick = -1;
    if (pick < 0) return choose_best(sc, &t, paced, ch);
    char d[96];
    lag_cost_row_describe(&t.row[pick], d, sizeof d);
    (void)quiet; /* said even with -q: a log of this run replays only with the overrides */
    fprintf(stderr, "lagsimd: integrator.error %g over %g s: %s, the cheapest of %d "
                "settings measured on this scene that meets it %g times over (error %.2g; "
                "%.2g s of CPU per sim-second, %.3g x real time); calibration took %.2f s "
                "of CPU%s\n", e, t.horizon, d, t.n, lag_cost_opts_default().safety,
                t.row[pick].error, t.row[pick].cpu_per_sim_s, margin(sc, &t.row[pick]),
                t.spent, t.budget_hit ? " (its budget ran out: some settings unmeasured)" : "");
    apply(ch, &t.row[pick]);
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

/* The rows of method m (or, for m = LAG_METHOD_COUNT and + 1, the scene's own
 * integrator's and the chosen one) that ran, as gnuplot data (CPU s per sim-s, error).
 * Returns how many. */
static int data_block(FILE *f, const lag_cost_table *t, int m)
{
    int n = 0;
    for (int i = 0; i < t->n; i++) {
        const lag_cost_row *r = &t->row[i];
        bool in = m < LAG_METHOD_COUNT ? r->method == (lag_method)m
                                       : i == (m == LAG_METHOD_COUNT ? t->current : t->chosen);
        if (!in || r->fault != LAG_OK) continue;
        if (f) fprintf(f, "%.6g %.6g\n", r->cpu_per_sim_s, fmax(r->error, 1e-17));
        n++;
    }
    return n;
}

/* The table as gnuplot's datablock $cost: a block per method with rows, then the scene's
 * own integrator's row and the chosen row (those there are). */
static void write_data(FILE *f, const lag_cost_table *t)
{
    fputs("$cost << EOD\n", f);
    for (int m = 0; m <= LAG_METHOD_COUNT + 1; m++)
        if (data_block(NULL, t, m) > 0) {
            data_block(f, t, m);
            fputs("\n\n", f);
        }
    fputs("EOD\n", f);
}

/* The x axis's range (CPU s per sim-s, the rows', widened) and on top the real-time
 * factor's tics, 1 / (cost x realtime.rate), at each power of ten within it. */
static void real_time_axis(FILE *g, const lag_scene *sc, const lag_cost_table *t)
{
    /* factor f = 1 / (x realtime.rate) = inv / x: the tic of f is at x = inv / f */
    double lo = INFINITY, hi = 0, inv = margin(sc, &(lag_cost_row){.cpu_per_sim_s = 1});
    for (int i = 0; i < t->n; i++)
        if (t->row[i].fault == LAG_OK && t->row[i].cpu_per_sim_s > 0) {
            lo = fmin(lo, t->row[i].cpu_per_sim_s);
            hi = fmax(hi, t->row[i].cpu_per_sim_s);
        }
    if (!(lo <= hi)) return;
    lo /= 2, hi *= 2;
    fprintf(g, "set xrange [%g:%g]\nset x2range [%g:%g]\nset logscale x2\n"
               "set x2label 'times faster than real time: 1 / (CPU s per sim-s x realtime.rate)'\n"
               "set x2tics (", lo, hi, lo, hi);
    int n = 0;
    for (int k = (int)floor(log10(inv / hi)); k <= (int)ceil(log10(inv / lo)); k++) {
        double x = inv / pow(10.0, k);
        if (x >= lo && x <= hi) fprintf(g, "%s'10^{%d}' %g", n++ ? ", " : "", k, x);
    }
    fputs(")\nset xtics nomirror\n", g);
}

/* The lines across: the error asked for and what a setting must reach, or without an
 * error asked for the error of the scene's own integrator. */
static void target_lines(FILE *g, const lag_scene *sc, const lag_cost_table *t)
{
    const double safety = lag_cost_opts_default().safety, reach = t->target / safety;
    if (sc->accuracy.error > 0)
        fprintf(g, "set arrow from graph 0, first %g to graph 1, first %g nohead dt 2 lc rgb 'red'\n"
                   "set label 'error asked for' at graph 0.02, first %g offset 0,0.6 tc rgb 'red'\n",
                t->target, t->target, t->target);
    fprintf(g, "set arrow from graph 0, first %g to graph 1, first %g nohead dt 3 lc rgb 'gray40'\n"
               "set label \"%s\" at graph 0.02, first %g offset 0,-0.7 tc rgb 'gray40'\n",
            reach, reach,
            sc->accuracy.error > 0 ? "what a setting must reach (/ 4)"
            : t->target_from_current ? "as accurate as the scene's integrator"
                                     : "1e-6 / 4 (the scene's integrator not measured)",
            reach);
}

/* A marked row's title: "the scene's integrator: rk4 dt 0.001 s, 2.9e+03 x real time". */
static void mark_title(const lag_scene *sc, const lag_cost_table *t, int row, const char *what,
                       char *buf, size_t len)
{
    char d[96];
    lag_cost_row_describe(&t->row[row], d, sizeof d);
    snprintf(buf, len, "%s: %s, %.2g x real time", what, d, margin(sc, &t->row[row]));
}

/* The gnuplot script that draws the table into png, its data inline. */
static void script(FILE *g, const lag_scene *sc, const lag_cost_table *t, const char *png)
{
    fprintf(g, "# lagsimd --cost of %s: gnuplot draws it into %s\n", sc->path, png);
    write_data(g, t);
    fprintf(g, "set terminal pngcairo size 1000,760 enhanced font 'DejaVu Sans,11'\n"
               "set output '%s'\nset logscale xy\nset format x '10^{%%L}'\nset format y '10^{%%L}'\n"
               "set grid\nset key outside below left Left reverse width -8\n"
               "set tmargin 6\nset title offset 0,1.5\n"
               "set xlabel 'CPU time per simulated second (s/s), this machine'\n"
               "set ylabel 'max |q - q_{ref}| over %g s (m or rad)'\n"
               "set title \"%s: what accuracy costs (lagsimd --cost)%s\" noenhanced\n",
            png, t->horizon, sc->path, t->horizon_cut ? ", over the horizon it can honour" : "");
    real_time_axis(g, sc, t);
    target_lines(g, sc, t);
    fputs("plot ", g);
    int n = 0; /* the blocks of $cost, in order */
    char title[200];
    for (int m = 0; m <= LAG_METHOD_COUNT + 1; m++) {
        if (data_block(NULL, t, m) == 0) continue;
        if (m < LAG_METHOD_COUNT)
            snprintf(title, sizeof title, "%s", lag_method_name((lag_method)m));
        else
            mark_title(sc, t, m == LAG_METHOD_COUNT ? t->current : t->chosen,
                       m == LAG_METHOD_COUNT  ? "the scene's integrator"
                       : sc->accuracy.error > 0 ? "chosen"
                                                : "would be chosen",
                       title, sizeof title);
        char style[64]; /* a method's colour is its own, whichever methods have rows */
        snprintf(style, sizeof style, "with linespoints lw 2 pt 7 lc %d", m + 1);
        fprintf(g, "%s$cost index %d using 1:2 %s title \"%s\" noenhanced", n ? ", " : "", n,
                m < LAG_METHOD_COUNT        ? style
                : m == LAG_METHOD_COUNT     ? "with points pt 6 ps 3.5 lw 2 lc rgb 'black'"
                                            : "with points pt 4 ps 3.5 lw 2 lc rgb 'red'",
                title);
        n++;
    }
    fputs(n ? "\n" : "NaN notitle\n", g); /* no row ran: the axes alone */
}

/* The work-precision diagram of the table into out (opened already by the rules of every
 * output, lagsim_out.h): a path ending in .gp gets the gnuplot script that draws it
 * (into the same name in .png), any other the PNG, drawn by gnuplot into a temporary
 * file first. */
static int plot(const lag_scene *sc, const lag_cost_table *t, const char *path, int out)
{
    size_t len = strlen(path);
    if (len > 3 && !strcmp(path + len - 3, ".gp")) {
        FILE *f = fdopen(out, "w");
        char png[1024];
        snprintf(png, sizeof png, "%.*s.png", (int)(len - 3), path);
        if (f) script(f, sc, t, png);
        if (!f || fclose(f) != 0) {
            fprintf(stderr, "lagsimd: --plot: cannot write %s\n", path);
            return LAGSIMD_EXIT_RUNTIME;
        }
        return LAGSIMD_EXIT_OK;
    }
    char tmp_png[] = "/tmp/lagsimd-cost-XXXXXX.png";
    int tfd = mkstemps(tmp_png, 4);
    if (tfd >= 0) close(tfd);
    FILE *g = tfd >= 0 ? popen("gnuplot", "w") : NULL;
    const char *fail = tfd < 0 ? "cannot make a temporary file" : !g ? "cannot run gnuplot" : NULL;
    if (g) {
        script(g, sc, t, tmp_png);
        if (pclose(g) != 0) fail = "gnuplot failed";
    }
    int rc = fail ? (close(out), -1) : copy_into(tmp_png, out);
    if (tfd >= 0) unlink(tmp_png);
    if (rc != 0) {
        if (fail) fprintf(stderr, "lagsimd: --plot: %s\n", fail);
        else fprintf(stderr, "lagsimd: --plot: cannot write %s\n", path);
        return LAGSIMD_EXIT_RUNTIME;
    }
    return LAGSIMD_EXIT_OK;
}

/* --cost's header: what the rows are marked at, over which horizon, against what. */
static void cost_header(const lag_scene *sc, const lag_cost_table *t)
{
    const lag_cost_opts o = opts_for(sc, t->target);
    const lag_model_info *info = lag_model_info_get(sc->sim.model.kind);
    printf("# %s: %s, ", sc->path, info ? info->name : "?");
    if (sc->accuracy.error > 0)
        printf("error asked for (integrator.error) %g over %g s (a setting meets it with %g "
               "times to spare),\n", t->target, t->horizon, o.safety);
    else if (t->target_from_current) {
        char d[96] = "?";
        double e = t->target / o.safety;
        if (t->current >= 0) {
            lag_cost_row_describe(&t->row[t->current], d, sizeof d);
            e = t->row[t->current].error;
        }
        char why[120] = "";
        if (e * o.safety < t->target * (1 - 1e-9))
            snprintf(why, sizeof why, ": %g times the references' own difference, below "
                     "which no error is told", o.safety);
        printf("no error asked for: a setting meets when it is as accurate as\n# the scene's "
               "integrator, %s, error %.3g over %g s (as if integrator.error were %.3g%s),\n",
               d, e, t->horizon, t->target, why);
    }
    else
        printf("no error asked for, and its integrator's error not measured: rows marked at "
               "%g over %g s,\n", t->target, t->horizon);
    char why[400];
    unpredictable(t, why, sizeof why);
    if (why[0])
        printf("# integrator.horizon %g s cannot be honoured: %s; every error below is over "
               "%.6g s;\n", o.horizon, why, t->horizon);
    char d[96];
    lag_cost_row_describe(&t->ref2, d, sizeof d);
    printf("# publish period %g s; reference dopri5 tolerance %.0e (with a floor or stops at a\n"
           "# tick of period/1024), a second, %s, within %.2g of it;\n"
           "# CPU measured on this machine: %.2f s for %d settings%s\n",
           o.period, t->ref_tol, d, t->ref_diff, t->spent, t->n,
           t->budget_hit ? " (budget ran out: finer settings unmeasured)" : "");
}

lag_result lagsimd_cost(const lag_scene *sc, const char *png, bool force)
{
    static lag_cost_table t;
    const bool asked = sc->accuracy.error > 0;
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
    if (measure(sc, asked ? sc->accuracy.error : DEFAULT_TARGET, true, !asked, &t) != 0) {
        if (out >= 0) close(out);
        return LAGSIMD_EXIT_USAGE;
    }
    cost_header(sc, &t);
    printf("%-34s %12s %14s %13s %13s  %s\n", "setting", "error", "energy error", "CPU s/sim-s",
           "x real time", "");
    for (int i = 0; i < t.n; i++) {
        const lag_cost_row *r = &t.row[i];
        char d[96];
        lag_cost_row_describe(r, d, sizeof d);
        const char *own = i == t.current ? "the scene's integrator" : "";
        if (r->fault != LAG_OK) {
            printf("%-34s %12s   fault: %s%s%s\n", d, "-", lag_result_string(r->fault),
                   own[0] ? ", " : "", own);
            continue;
        }
        const char *tag = i == t.chosen ? (asked ? "meets, chosen" : "meets, would be chosen")
                          : r->meets    ? "meets"
                                        : "";
        printf("%-34s %12.3g %14.3g %13.3g %13.3g  %s%s%s\n", d, r->error, r->energy_error,
               r->cpu_per_sim_s, margin(sc, r), tag, tag[0] && own[0] ? ", " : "", own);
    }
    if (t.chosen < 0) printf("# no setting measured meets %g\n", t.target);
    return png ? plot(sc, &t, png, out) : LAGSIMD_EXIT_OK;
}
