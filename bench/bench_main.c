/*
 * lagsim_bench: work-precision benchmark of lagsim's integrators beside MuJoCo and
 * SUNDIALS (when built with them).
 *
 *   lagsim_bench [--out DIR] [--reps N] [--quick]
 *
 * For every scene (bench_common.c): a reference (dopri5 at rtol 1e-13, checked against
 * gauss4 at a tiny step), then every method over a range of dt (or rtol): max position
 * error over the horizon, max energy error, RHS evaluations and CPU time per simulated
 * second (minimum of --reps runs). Prints Markdown tables (the numbers in
 * docs/benchmarks.md), the cross-checks against the peers, the cost ratios and the
 * real-time budget table; with --out writes DIR/bench_wp.csv and
 * DIR/bench_energy_long.csv (100 s chaotic DIPC, energy error vs time).
 *
 * --quick (the ctest): short horizons, one coarse point per method, and checks that fail
 * the run: the reference's two methods agree to 1e-10; at the same dt a higher-order
 * method is more accurate on every scene; dopri5's error falls with its tolerance; our
 * rk4 and semi-implicit Euler agree with MuJoCo's RK4 and Euler and with ARKODE's RK4 to
 * far below their own integration error. Exit status 1 if a check fails.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"

typedef struct row {
    int scene;
    bench_config c;
    bench_result r;
    double pos_err;
    double energy_err;
} row;

#define MAX_ROWS 1024
static row rows[MAX_ROWS];
static int nrows;
static int failures;

static void check(bool ok, const char *what, double got, double bound)
{
    printf("- check %s: %.3e %s %.3e ... %s\n", what, got, ok ? "ok vs" : "VIOLATES", bound,
           ok ? "PASS" : "FAIL");
    if (!ok) failures++;
}

static const double dts_low[] = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5};
static const double dts_high[] = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4};
static const double rtols[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

static bool peer_applies(bench_impl impl, const bench_scene *sc)
{
    if (impl == BENCH_MUJOCO)
        return sc->model.kind == LAG_MODEL_DIPC || sc->model.kind == LAG_MODEL_MANIPULATOR;
    return true;
}

/* Appends the configs of the sweep for one scene. OUT: out; returns the count */
static int sweep_configs(const bench_scene *sc, bool quick, bench_config *out)
{
    int n = 0;
    const double qdt = 5e-3;  /* the quick test's coarse point */
    const double tick = 1e-3; /* adaptive methods deliver the state every 1 ms (the daemon's
                               * default tick); the sweep varies their tolerance */
    (void)sc;
    for (int m = 0; m < LAG_METHOD_COUNT; m++) {
        bool low = (lag_method_order((lag_method)m) <= 2);
        if (m == LAG_DOPRI5) {
            if (quick) {
                out[n++] = (bench_config){BENCH_LAGSIM, m, tick, 1e-5};
                out[n++] = (bench_config){BENCH_LAGSIM, m, tick, 1e-9};
            } else {
                for (int i = 0; i < COUNT(rtols); i++)
                    out[n++] = (bench_config){BENCH_LAGSIM, m, tick, rtols[i]};
                for (int i = 0; i < COUNT(rtols); i++)
                    out[n++] = (bench_config){BENCH_LAGSIM, m, tick, rtols[i], true};
            }
            continue;
        }
        if (quick) {
            out[n++] = (bench_config){BENCH_LAGSIM, m, qdt, 0};
            continue;
        }
        const double *dts = low ? dts_low : dts_high;
        int nd = low ? COUNT(dts_low) : COUNT(dts_high);
        for (int i = 0; i < nd; i++) out[n++] = (bench_config){BENCH_LAGSIM, m, dts[i], 0};
    }
#ifdef LAGSIM_HAVE_MUJOCO
    if (peer_applies(BENCH_MUJOCO, sc))
        for (int m = 0; m < BENCH_MJ_COUNT; m++) {
            if (quick) {
                out[n++] = (bench_config){BENCH_MUJOCO, m, qdt, 0};
                continue;
            }
            const double *dts = m == BENCH_MJ_RK4 ? dts_high : dts_low;
            int nd = m == BENCH_MJ_RK4 ? COUNT(dts_high) : COUNT(dts_low);
            for (int i = 0; i < nd; i++) out[n++] = (bench_config){BENCH_MUJOCO, m, dts[i], 0};
        }
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
    for (int m = 0; m < BENCH_SUN_COUNT; m++) {
        if (m == BENCH_SUN_ARK_RK4) {
            if (quick) {
                out[n++] = (bench_config){BENCH_SUNDIALS, m, qdt, 0};
                continue;
            }
            for (int i = 0; i < COUNT(dts_high); i++)
                out[n++] = (bench_config){BENCH_SUNDIALS, m, dts_high[i], 0};
            continue;
        }
        if (quick) {
            out[n++] = (bench_config){BENCH_SUNDIALS, m, tick, 1e-6};
            continue;
        }
        for (int i = 0; i < COUNT(rtols); i++)
            out[n++] = (bench_config){BENCH_SUNDIALS, m, tick, rtols[i]};
    }
#endif
    return n;
}

static const char *label(const bench_config *c)
{
    static char buf[4][64];
    static int k;
    char m[48];
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s %s", bench_impl_name(c->impl),
             bench_method_label(c, m, sizeof m));
    return buf[k];
}

/* "dt=1e-03" or "rtol=1e-08". */
static const char *setting(const bench_config *c)
{
    static char buf[4][32];
    static int k;
    k = (k + 1) % 4;
    if (bench_config_adaptive(c)) snprintf(buf[k], sizeof buf[k], "rtol=%.0e", c->rtol);
    else snprintf(buf[k], sizeof buf[k], "dt=%.0e", c->dt);
    return buf[k];
}

static const row *find_row(int scene, bench_impl impl, int method, double dt)
{
    for (int i = 0; i < nrows; i++)
        if (rows[i].scene == scene && rows[i].c.impl == impl && rows[i].c.method == method &&
            fabs(rows[i].c.dt - dt) < 1e-15 && rows[i].r.status == 0)
            return &rows[i];
    return NULL;
}

/* log-log interpolation of CPU time per simulated second at error `e` along one
 * method's curve (points sorted by error); NaN outside the measured range. */
static double cpu_at_error(int scene, bench_impl impl, int method, bool cont, double e)
{
    double best = NAN;
    for (int i = 0; i < nrows; i++) {
        const row *a = &rows[i];
        if (a->scene != scene || a->c.impl != impl || a->c.method != method || a->r.status ||
            a->c.continuous != cont)
            continue;
        for (int j = 0; j < nrows; j++) {
            const row *b = &rows[j];
            if (b->scene != scene || b->c.impl != impl || b->c.method != method || b->r.status ||
                b->c.continuous != cont)
                continue;
            if (!(a->pos_err >= e && b->pos_err <= e && a->pos_err > b->pos_err)) continue;
            double la = log(a->pos_err), lb = log(b->pos_err), le = log(e);
            double w = (le - la) / (lb - la);
            double lc = (1 - w) * log(a->r.cpu) + w * log(b->r.cpu);
            double v = exp(lc);
            /* several brackets (noisy curves): the cheapest */
            if (isnan(best) || v < best) best = v;
        }
    }
    return best;
}

static void print_env(void)
{
    char model[256] = "unknown";
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f) {
        char line[512];
        while (fgets(line, sizeof line, f))
            if (strncmp(line, "model name", 10) == 0) {
                char *p = strchr(line, ':');
                if (p) {
                    snprintf(model, sizeof model, "%s", p + 2);
                    model[strcspn(model, "\n")] = 0;
                }
                break;
            }
        fclose(f);
    }
    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now));
    printf("Run %s on %s.\n", date, model);
#ifdef LAGSIM_HAVE_MUJOCO
    printf("Peers: MuJoCo %s", bench_mujoco_version());
#else
    printf("Peers: MuJoCo not built");
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
    printf(", SUNDIALS %s.\n", bench_sundials_version());
#else
    printf(", SUNDIALS not built.\n");
#endif
}

/* Max |q| difference between two configs' trajectories on a scene (untimed runs). */
static double agreement(const bench_scene *sc, const bench_config *a, const bench_config *b)
{
    bench_samples sa, sb;
    if (bench_samples_alloc(&sa, sc) || bench_samples_alloc(&sb, sc)) return NAN;
    bench_result ra = bench_measure(sc, a, 1, &sa);
    bench_result rb = bench_measure(sc, b, 1, &sb);
    double e = (ra.status || rb.status) ? NAN : bench_max_pos_err(&sa, &sb);
    bench_samples_free(&sa);
    bench_samples_free(&sb);
    return e;
}

/* CPU microseconds per step, minimum of 7 runs over the scene's horizon. */
static double step_us(const bench_scene *sc, const bench_config *c)
{
    bench_samples smp;
    if (bench_samples_alloc(&smp, sc)) return NAN;
    bench_result r = bench_measure(sc, c, 7, &smp);
    bench_samples_free(&smp);
    return (r.status || r.steps == 0) ? NAN : 1e6 * r.cpu / (double)r.steps;
}

/* ---------------------------------------------------------------- long energy run */
static void energy_long(const char *outdir, int reps)
{
    bench_scene sc[BENCH_SCENE_COUNT];
    bench_scenes(sc, false);
    bench_scene s = sc[3];
    s.horizon = 100.0;
    bench_config cfg[16];
    int n = 0;
    const double dt = 1e-3;
    cfg[n++] = (bench_config){BENCH_LAGSIM, LAG_EULER, dt, 0};
    cfg[n++] = (bench_config){BENCH_LAGSIM, LAG_SEMI_IMPLICIT_EULER, dt, 0};
    cfg[n++] = (bench_config){BENCH_LAGSIM, LAG_IMPLICIT_MIDPOINT, dt, 0};
    cfg[n++] = (bench_config){BENCH_LAGSIM, LAG_RK4, dt, 0};
    cfg[n++] = (bench_config){BENCH_LAGSIM, LAG_GAUSS4, dt, 0};
    cfg[n++] = (bench_config){BENCH_LAGSIM, LAG_DOPRI5, dt, 1e-8};
#ifdef LAGSIM_HAVE_MUJOCO
    cfg[n++] = (bench_config){BENCH_MUJOCO, BENCH_MJ_EULER, dt, 0};
    cfg[n++] = (bench_config){BENCH_MUJOCO, BENCH_MJ_RK4, dt, 0};
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
    cfg[n++] = (bench_config){BENCH_SUNDIALS, BENCH_SUN_ARK_DP5, dt, 1e-8};
#endif
    bench_samples smp[16];
    printf("\n## Long chaotic run: DIPC near upright, 100 s, energy error\n\n");
    printf("| method | setting | max abs(E - E0) over 100 s (J) | at t = 1 s | at t = 10 s | CPU s per sim s |\n");
    printf("|---|---|---|---|---|---|\n");
    const double E0 = bench_energy(&s.model, s.q0, s.qd0);
    for (int i = 0; i < n; i++) {
        bench_samples_alloc(&smp[i], &s);
        for (int k = 0; k < smp[i].n * LAG_MAX_DOF; k++) smp[i].q[k] = smp[i].qd[k] = NAN;
        bench_result r = bench_measure(&s, &cfg[i], reps < 2 ? reps : 2, &smp[i]);
        double emax = 0, e1 = NAN, e10 = NAN;
        for (int k = 0; k < smp[i].n; k++) {
            double e = fabs(bench_energy(&s.model, smp[i].q + k * LAG_MAX_DOF,
                                         smp[i].qd + k * LAG_MAX_DOF) - E0);
            if (isnan(e)) { emax = INFINITY; break; }
            if (e > emax) emax = e;
            if (k == 100) e1 = emax;
            if (k == 1000) e10 = emax;
        }
        printf("| %s | %s | %.2e%s | %.2e | %.2e | %.3g |\n", label(&cfg[i]), setting(&cfg[i]),
               emax, r.status ? " (failed: blew up)" : "", e1, e10,
               r.status ? NAN : r.cpu / s.horizon);
    }
    if (outdir) {
        char path[1024];
        snprintf(path, sizeof path, "%s/bench_energy_long.csv", outdir);
        FILE *f = fopen(path, "w");
        if (f) {
            fprintf(f, "t");
            for (int i = 0; i < n; i++) fprintf(f, ",%s %s", label(&cfg[i]), setting(&cfg[i]));
            fprintf(f, "\n");
            for (int k = 0; k < smp[0].n; k += 10) {
                fprintf(f, "%.2f", k * s.period);
                for (int i = 0; i < n; i++) {
                    double e = fabs(bench_energy(&s.model, smp[i].q + k * LAG_MAX_DOF,
                                                 smp[i].qd + k * LAG_MAX_DOF) - E0);
                    if (isfinite(e)) fprintf(f, ",%.6e", e);
                    else fprintf(f, ",NaN");
                }
                fprintf(f, "\n");
            }
            fclose(f);
        }
    }
    for (int i = 0; i < n; i++) bench_samples_free(&smp[i]);
}

/* ---------------------------------------------------------------- main */
/* One run of the benchmark: its options, the scenes and their references, the CSV. */
typedef struct bench_run {
    const char *outdir;   /* NULL: no CSV files */
    int reps;             /* runs per measurement, the least CPU time counts */
    bool quick;           /* the ctest: short horizons, coarse points, checks */
    bench_scene scenes[BENCH_SCENE_COUNT];
    bench_reference refs[BENCH_SCENE_COUNT];
    FILE *csv;            /* outdir/bench_wp.csv */
} bench_run;

static int parse_args(bench_run *b, int argc, char **argv)
{
    b->reps = 3;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) b->outdir = argv[++i];
        else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) b->reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--quick") == 0) b->quick = true;
        else {
            fprintf(stderr, "usage: %s [--out DIR] [--reps N] [--quick]\n", argv[0]);
            return 2;
        }
    }
    if (b->reps < 1) b->reps = 1;
    if (b->quick) b->reps = 1;
    return -1;
}

static int open_csv(bench_run *b)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/bench_wp.csv", b->outdir);
    b->csv = fopen(path, "w");
    if (!b->csv) {
        perror(path);
        return 2;
    }
    fprintf(b->csv, "scene,impl,method,dt,rtol,pos_err,energy_err,rhs_per_s,steps_per_s,"
                    "cpu_per_s,us_per_step,status\n");
    return 0;
}

/* References: dopri5 at rtol 1e-13, checked against gauss4 at period/200. */
static int build_references(bench_run *b)
{
    printf("\n## References (dopri5 rtol 1e-13 vs gauss4 at period/200)\n\n");
    printf("| scene | horizon (s) | gauss4 dt | max abs(q_dopri5 - q_gauss4) |\n|---|---|---|---|\n");
    for (int s = 0; s < BENCH_SCENE_COUNT; s++) {
        const bench_scene *sc = &b->scenes[s];
        bench_reference *ref = &b->refs[s];
        if (bench_reference_build(sc, ref) != 0) {
            fprintf(stderr, "bench: no reference for %s\n", sc->name);
            return 2;
        }
        printf("| %s | %g | %.0e | %.2e |\n", sc->name, sc->horizon, ref->gauss_dt,
               ref->agreement);
        if (b->quick) check(ref->agreement < 1e-10, "reference agreement", ref->agreement, 1e-10);
    }
    return 0;
}

/* One measured setting: its table line and CSV line. */
static void print_row(const bench_run *b, const bench_scene *sc, const row *w)
{
    const bench_config *c = &w->c;
    double T = sc->horizon;
    double us_step = w->r.steps ? 1e6 * w->r.cpu / (double)w->r.steps : NAN;
    if (w->r.status)
        printf("| %s | %s | failed (%d) | | | | |\n", label(c), setting(c), w->r.status);
    else
        printf("| %s | %s | %.2e | %.2e | %.0f | %.2e | %.3f |\n", label(c), setting(c),
               w->pos_err, w->energy_err, (double)w->r.rhs / T, w->r.cpu / T, us_step);
    if (b->csv) {
        char m[48];
        fprintf(b->csv, "%s,%s,%s,%.3g,%.3g,%.6e,%.6e,%.6g,%.6g,%.6e,%.6g,%d\n", sc->name,
                bench_impl_name(c->impl), bench_method_label(c, m, sizeof m), c->dt, c->rtol,
                w->pos_err, w->energy_err, (double)w->r.rhs / T, (double)w->r.steps / T,
                w->r.cpu / T, us_step, w->r.status);
    }
    fflush(stdout);
}

/* Every setting of scene s, measured into rows[]. */
static void sweep_scene(const bench_run *b, int s)
{
    const bench_scene *sc = &b->scenes[s];
    bench_config cfg[256];
    int nc = sweep_configs(sc, b->quick, cfg);
    printf("\n## %s: %s, %g s\n\n", sc->name, sc->title, sc->horizon);
    printf("| method | setting | max pos err | max energy err (J) | RHS/sim s | CPU s/sim s | us/step |\n");
    printf("|---|---|---|---|---|---|---|\n");
    bench_samples smp;
    bench_samples_alloc(&smp, sc);
    for (int i = 0; i < nc && nrows < MAX_ROWS; i++) {
        row *w = &rows[nrows++];
        w->scene = s;
        w->c = cfg[i];
        w->r = bench_measure(sc, &cfg[i], b->reps, &smp);
        w->pos_err = w->r.status ? NAN : bench_max_pos_err(&smp, &b->refs[s].ref);
        w->energy_err = w->r.status ? NAN : bench_max_energy_err(sc, &smp, &b->refs[s].ref);
        print_row(b, sc, w);
    }
    bench_samples_free(&smp);
}

/* With a forced input dopri5 restarts every period and its steps are capped by the
 * period: its error there hardly depends on rtol. Checked on unforced scenes. */
static void check_dopri5(int s)
{
    const row *d5 = NULL, *d9 = NULL;
    for (int i = 0; i < nrows; i++)
        if (rows[i].scene == s && rows[i].c.impl == BENCH_LAGSIM &&
            rows[i].c.method == LAG_DOPRI5 && rows[i].r.status == 0 && !rows[i].c.continuous) {
            if (rows[i].c.rtol == 1e-5) d5 = &rows[i];
            if (rows[i].c.rtol == 1e-9) d9 = &rows[i];
        }
    check(d5 && d9 && d5->pos_err > d9->pos_err, "dopri5 error rtol 1e-5 > rtol 1e-9",
          d5 ? d5->pos_err : NAN, d9 ? d9->pos_err : NAN);
    check(d9 && d9->pos_err < 1e-6, "dopri5 rtol 1e-9 error", d9 ? d9->pos_err : NAN, 1e-6);
}

/* Error ordering at the same dt (quick: the coarse point, full: dt = 5e-3). */
static void error_ordering(const bench_run *b, int s)
{
    const row *eu = find_row(s, BENCH_LAGSIM, LAG_EULER, 5e-3);
    const row *se = find_row(s, BENCH_LAGSIM, LAG_SEMI_IMPLICIT_EULER, 5e-3);
    const row *mp = find_row(s, BENCH_LAGSIM, LAG_IMPLICIT_MIDPOINT, 5e-3);
    const row *rk = find_row(s, BENCH_LAGSIM, LAG_RK4, 5e-3);
    const row *g4 = find_row(s, BENCH_LAGSIM, LAG_GAUSS4, 5e-3);
    printf("%s: euler %.2e, semi-implicit-euler %.2e, implicit-midpoint %.2e, rk4 %.2e, "
           "gauss4 %.2e\n", b->scenes[s].name, eu ? eu->pos_err : NAN, se ? se->pos_err : NAN,
           mp ? mp->pos_err : NAN, rk ? rk->pos_err : NAN, g4 ? g4->pos_err : NAN);
    if (!b->quick) return;
    /* An explicit Euler that blew up counts as "least accurate". */
    double e_eu = eu ? eu->pos_err : INFINITY;
    double e_se = se ? se->pos_err : INFINITY;
    check(mp && e_eu > mp->pos_err, "euler error > implicit-midpoint error", e_eu,
          mp ? mp->pos_err : NAN);
    check(mp && e_se > mp->pos_err, "semi-implicit-euler error > implicit-midpoint error",
          e_se, mp ? mp->pos_err : NAN);
    check(mp && rk && mp->pos_err > rk->pos_err, "implicit-midpoint error > rk4 error",
          mp ? mp->pos_err : NAN, rk ? rk->pos_err : NAN);
    check(mp && g4 && mp->pos_err > g4->pos_err, "implicit-midpoint error > gauss4 error",
          mp ? mp->pos_err : NAN, g4 ? g4->pos_err : NAN);
    if (!b->scenes[s].input) check_dopri5(s);
}

/* Cross-checks at one dt: same method, same dt, same ODE => same trajectory up to
 * rounding; chk: checked (the coarse dt, where the integration error is far above
 * rounding). */
static void cross_check(const bench_scene *sc, const bench_reference *ref, double dt, bool chk)
{
    bench_config ours_rk4 = {BENCH_LAGSIM, LAG_RK4, dt, 0};
    bench_config ours_se = {BENCH_LAGSIM, LAG_SEMI_IMPLICIT_EULER, dt, 0};
    bench_samples so;
    bench_samples_alloc(&so, sc);
    bench_measure(sc, &ours_rk4, 1, &so);
    double err_rk4 = bench_max_pos_err(&so, &ref->ref);
    bench_measure(sc, &ours_se, 1, &so);
    double err_se = bench_max_pos_err(&so, &ref->ref);
    bench_samples_free(&so);
    (void)err_rk4;
    (void)err_se;
    (void)chk;
#ifdef LAGSIM_HAVE_MUJOCO
    if (peer_applies(BENCH_MUJOCO, sc)) {
        bench_config mj_rk4 = {BENCH_MUJOCO, BENCH_MJ_RK4, dt, 0};
        bench_config mj_eu = {BENCH_MUJOCO, BENCH_MJ_EULER, dt, 0};
        double a = agreement(sc, &ours_rk4, &mj_rk4);
        double b = agreement(sc, &ours_se, &mj_eu);
        printf("| %s | lagsim rk4 vs mujoco RK4 | %.0e | %.2e | %.2e |\n", sc->name, dt, a,
               err_rk4);
        printf("| %s | lagsim semi-implicit-euler vs mujoco Euler | %.0e | %.2e | %.2e |\n",
               sc->name, dt, b, err_se);
        if (chk) {
            check(a < 1e-9 && a < 1e-2 * err_rk4, "rk4 vs MuJoCo RK4 agreement", a,
                  fmin(1e-9, 1e-2 * err_rk4));
            check(b < 1e-9 && b < 1e-2 * err_se, "semi-implicit Euler vs MuJoCo Euler agreement",
                  b, fmin(1e-9, 1e-2 * err_se));
        }
    }
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
    {
        bench_config ark_rk4 = {BENCH_SUNDIALS, BENCH_SUN_ARK_RK4, dt, 0};
        double a = agreement(sc, &ours_rk4, &ark_rk4);
        printf("| %s | lagsim rk4 vs ARKODE RK4 | %.0e | %.2e | %.2e |\n", sc->name, dt, a,
               err_rk4);
        if (chk)
            check(a < 1e-9 && a < 1e-2 * err_rk4, "rk4 vs ARKODE RK4 agreement", a,
                  fmin(1e-9, 1e-2 * err_rk4));
    }
#endif
}

static void cross_checks(const bench_run *b)
{
    printf("\n## Cross-checks against the peers (same method, same dt)\n\n");
    printf("| scene | pair | dt | max abs(q_ours - q_peer) | our error vs reference |\n|---|---|---|---|---|\n");
    static const double xdts[] = {5e-3, 1e-3};
    for (int s = 0; s < BENCH_SCENE_COUNT; s++) {
        if (b->scenes[s].chaotic) continue;
        for (int x = 0; x < COUNT(xdts); x++)
            cross_check(&b->scenes[s], &b->refs[s], xdts[x], b->quick && x == 0);
    }
}

/* Step costs re-measured on their own, minimum of 7 runs of the whole horizon at
 * dt = 1 ms (same method and dt for both sides: the trajectories agree, see above). */
static void step_cost_ratios(const bench_scene *sc)
{
    bench_config o = {BENCH_LAGSIM, LAG_RK4, 1e-3, 0};
    double uo = step_us(sc, &o);
    (void)uo;
#ifdef LAGSIM_HAVE_MUJOCO
    if (peer_applies(BENCH_MUJOCO, sc)) {
        bench_config p = {BENCH_MUJOCO, BENCH_MJ_RK4, 1e-3, 0};
        bench_config oe = {BENCH_LAGSIM, LAG_SEMI_IMPLICIT_EULER, 1e-3, 0};
        bench_config pe = {BENCH_MUJOCO, BENCH_MJ_EULER, 1e-3, 0};
        double up = step_us(sc, &p), uoe = step_us(sc, &oe), upe = step_us(sc, &pe);
        printf("- %s: lagsim rk4 %.3f us vs MuJoCo RK4 %.3f us: ratio %.3f (target <= 0.1)\n",
               sc->name, uo, up, uo / up);
        printf("- %s: lagsim semi-implicit-euler %.3f us vs MuJoCo Euler %.3f us: ratio %.3f\n",
               sc->name, uoe, upe, uoe / upe);
    }
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
    {
        bench_config p = {BENCH_SUNDIALS, BENCH_SUN_ARK_RK4, 1e-3, 0};
        double up = step_us(sc, &p);
        printf("- %s: lagsim rk4 %.3f us vs ARKODE RK4 (ARKStep, fixed step) %.3f us: "
               "ratio %.3f\n", sc->name, uo, up, uo / up);
    }
#endif
}

static void cost_ratios(const bench_run *b)
{
    printf("\n## Cost ratios\n\n");
    printf("Step cost at dt = 1e-3, minimum of 7 runs over the horizon (us per step):\n\n");
    for (int s = 0; s < BENCH_SCENE_COUNT; s++) step_cost_ratios(&b->scenes[s]);
    printf("\n");
#ifdef LAGSIM_HAVE_SUNDIALS
    static const double targets[] = {1e-4, 1e-6, 1e-8, 1e-10};
    for (int cont = 0; cont < 2; cont++)
        for (int s = 0; s < BENCH_SCENE_COUNT; s++) {
            printf("- %s: lagsim %s / ARKODE DP5 CPU at equal error (target <= 0.5):",
                   b->scenes[s].name, cont ? "dopri5-continuous" : "dopri5");
            for (int i = 0; i < COUNT(targets); i++) {
                double x = cpu_at_error(s, BENCH_LAGSIM, LAG_DOPRI5, cont, targets[i]);
                double y = cpu_at_error(s, BENCH_SUNDIALS, BENCH_SUN_ARK_DP5, false, targets[i]);
                printf(" %.0e: %.2f;", targets[i], x / y);
            }
            printf("\n");
        }
#endif
}

/* One line of the real-time budget: scene s's cheapest setting of ours and of the peers
 * within the error bound. */
static void budget_line(const bench_run *b, int s, double bound)
{
    const row *bo = NULL, *bp = NULL;
    for (int i = 0; i < nrows; i++) {
        const row *w = &rows[i];
        /* the real-time daemon lands on period ends: no continuous dopri5 */
        if (w->scene != s || w->r.status || !(w->pos_err <= bound) || w->c.continuous)
            continue;
        const row **best = w->c.impl == BENCH_LAGSIM ? &bo : &bp;
        if (!*best || w->r.cpu < (*best)->r.cpu) *best = w;
    }
    double T = b->scenes[s].horizon;
    printf("| %s | %.0e ", b->scenes[s].name, bound);
    if (bo) printf("| %s | %s | %.1e | %.2e ", label(&bo->c), setting(&bo->c), bo->pos_err,
                   bo->r.cpu / T);
    else printf("| none in sweep | | | ");
    if (bp) printf("| %s | %s | %.1e | %.2e |\n", label(&bp->c), setting(&bp->c), bp->pos_err,
                   bp->r.cpu / T);
    else printf("| none in sweep | | | |\n");
}

static void realtime_budget(const bench_run *b)
{
    printf("\n## Real-time budget: cheapest setting reaching a max position error\n\n");
    printf("CPU = fraction of one core to run the scene in real time (CPU s per simulated s).\n\n");
    printf("| scene | target | cheapest lagsim method | setting | error | CPU (core fraction) "
           "| cheapest peer | setting | error | CPU |\n|---|---|---|---|---|---|---|---|---|---|\n");
    static const double budget[] = {1e-3, 1e-6, 1e-9};
    for (int s = 0; s < BENCH_SCENE_COUNT; s++)
        for (int t = 0; t < COUNT(budget); t++) budget_line(b, s, budget[t]);
}

int main(int argc, char **argv)
{
    static bench_run b; /* the references are large: static */
    int code = parse_args(&b, argc, argv);
    if (code >= 0) return code;
    bench_scenes(b.scenes, b.quick);
    printf("# lagsim work-precision benchmark%s\n\n", b.quick ? " (quick check)" : "");
    print_env();
    if (b.outdir && (code = open_csv(&b))) return code;
    if ((code = build_references(&b))) return code;

    for (int s = 0; s < BENCH_SCENE_COUNT; s++) sweep_scene(&b, s);
    if (b.csv) fclose(b.csv);
    printf("\n## Error ordering at dt = 5e-3 (higher order => smaller error)\n\n");
    for (int s = 0; s < BENCH_SCENE_COUNT; s++) error_ordering(&b, s);
    cross_checks(&b);
    if (!b.quick) {
        cost_ratios(&b);
        realtime_budget(&b);
        energy_long(b.outdir, b.reps);
    }

    for (int s = 0; s < BENCH_SCENE_COUNT; s++) bench_reference_free(&b.refs[s]);
    if (b.quick) printf("\n%d check(s) failed\n", failures);
    return failures ? 1 : 0;
}
