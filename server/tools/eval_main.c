/*
 * lagsim-eval: runs a scene's cases in lockstep against a controller command and reports
 * each joint's metrics (the metrics library's, never recomputed here), whether a case
 * failed, and whether a requirement holds (controller CI). See docs/evaluation.md.
 */

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "eval_case.h"

static const char *prog = "lagsim-eval";

static void usage(FILE *f)
{
    fprintf(f,
"usage: lagsim-eval --config SCENE --controller 'COMMAND' [--case NAME ...]\n"
"                   [--suite FILE] [--require EXPR] [--csv OUT.csv] [--report DIR]\n"
"                   [--force] [--lagsimd PATH] [--timeout S] [-v]\n"
"\n"
"Runs each case of a scene (its `cases:` key, or those of a suite file) in lockstep\n"
"against a controller and reports per joint: rise, settle, overshoot, sse, iae, ise,\n"
"peak_error, effort_peak, effort_rms (docs/evaluation.md), and whether the case failed\n"
"(a fault, an early stop, a joint past its bound).\n"
"\n"
"options:\n"
"  -c, --config SCENE     the scene file (lagsimd's)\n"
"  -C, --controller CMD   shell command of the controller, started for each case;\n"
"                         {prefix} and {url} in it are replaced by the run's channel\n"
"                         prefix and LCM URL, which its environment also holds\n"
"                         (LAGSIM_PREFIX, LCM_DEFAULT_URL)\n"
"      --case NAME        run only this case (repeatable; default: every case)\n"
"      --suite FILE       take the cases from FILE's `cases:` instead of the scene's\n"
"      --require EXPR     exit 1 unless every case meets EXPR, e.g.\n"
"                         'theta.settle<2 and theta.overshoot<0.1'\n"
"      --csv OUT.csv      one row per case and joint: the metrics and the verdict\n"
"      --report DIR       a PNG per case in DIR (gnuplot): response, reference,\n"
"                         effort and the metrics\n"
"  -f, --force            replace existing output files\n"
"      --lagsimd PATH     the daemon (default: the lagsimd beside this program)\n"
"      --timeout S        wall seconds a case may take (default 600)\n"
"  -v, --verbose          pass the daemon's and the controller's output through, keep\n"
"                         each run's log in the report directory (or /tmp)\n"
"  -h, --help             this help\n"
"\n"
"exit codes: 0 every case ran, none failed and every case met --require; 1 a case\n"
"failed or missed the requirement; 2 usage, scene or case error (file:line:column)\n");
}

static int die(const char *fmt, const char *a)
{
    fprintf(stderr, "%s: ", prog);
    fprintf(stderr, fmt, a);
    fputc('\n', stderr);
    return 2;
}

/* An output of this run: never the scene file it reads (eval_open_out). */
static FILE *open_out(const char *what, const char *path, bool force, const char *config)
{
    const char *inputs[1] = {config};
    return eval_open_out(prog, what, path, force, inputs, 1);
}

/* The PNG of one case: q (solid) and r (dashed) of each joint, the efforts, and the
 * metrics as text; through gnuplot, from a data file beside it. */
static int report(const char *dir, bool force, const char *config, const eval_case *c,
                  const eval_scene *sc, const eval_series *s, const eval_result *res)
{
    char dat[1024], gp[1024], png[1024];
    snprintf(dat, sizeof dat, "%s/%s.dat", dir, c->name);
    snprintf(gp, sizeof gp, "%s/%s.gp", dir, c->name);
    snprintf(png, sizeof png, "%s/%s.png", dir, c->name);
    FILE *f = open_out("--report", dat, force, config);
    if (!f) return -1;
    fprintf(f, "# t");
    for (int j = 0; j < sc->nj; j++)
        fprintf(f, " %s %s_ref %s_effort", sc->joint[j], sc->joint[j], sc->joint[j]);
    fputc('\n', f);
    for (size_t k = 0; k < s->n; k++) {
        fprintf(f, "%.9g", s->t[k]);
        for (int j = 0; j < sc->nj; j++)
            fprintf(f, " %.9g %.9g %.9g", s->q[j][k], s->r[j][k], s->u[j][k]);
        fputc('\n', f);
    }
    fclose(f);
    f = open_out("--report", gp, force, config);
    if (!f) return -1;
    fprintf(f, "set terminal pngcairo noenhanced size 1200,640 font ',10'\n");
    fprintf(f, "set output '%s'\n", png);
    fprintf(f, "set multiplot layout 2,1 title \"%s: case %s%s%s\"\n", sc->model, c->name,
            res->failed ? " FAILED: " : " (passed)", res->failed ? res->reason : "");
    fprintf(f, "set grid\nset key top right\nset xlabel 'sim time (s)'\n");
    fprintf(f, "set lmargin 10\nset rmargin at screen 0.64\n");
    /* metrics as labels, right of the first panel */
    int line = 0;
    for (int j = 0; j < sc->nj; j++) {
        char row[512];
        size_t u = 0;
        u += (size_t)snprintf(row + u, sizeof row - u, "%s:", sc->joint[j]);
        for (int m = 0; m < LAG_METRIC_COUNT && u < sizeof row; m++) {
            if (m == LAG_METRIC_EFFORT_PEAK && !sc->actuated[j]) break;
            char v[32];
            eval_fmt(res->m[j].v[m], v, sizeof v);
            u += (size_t)snprintf(row + u, sizeof row - u, "\\n  %s %s", lag_metric_table[m].name,
                                  v);
        }
        fprintf(f, "set label %d \"%s\" at screen %.3f, screen 0.9 left font ',9'\n", j + 1,
                row, 0.66 + 0.33 * line / (sc->nj > 1 ? sc->nj : 1));
        line++;
    }
    fprintf(f, "set ylabel 'q (m or rad)'\nplot ");
    for (int j = 0; j < sc->nj; j++)
        fprintf(f, "%s'%s' u 1:%d w l lw 2 lc %d t '%s', '%s' u 1:%d w l dt 2 lc %d t '%s ref'",
                j ? ", " : "", dat, 2 + 3 * j, j + 1, sc->joint[j], dat, 3 + 3 * j, j + 1,
                sc->joint[j]);
    fprintf(f, "\nunset label\nset ylabel 'effort (N or N m)'\nplot ");
    int first = 1;
    for (int j = 0; j < sc->nj; j++) {
        if (!sc->actuated[j]) continue;
        fprintf(f, "%s'%s' u 1:%d w steps lw 1.5 lc %d t '%s effort'", first ? "" : ", ", dat,
                4 + 3 * j, j + 1, sc->joint[j]);
        first = 0;
    }
    if (first) fprintf(f, "0 t 'no actuated joint'");
    fprintf(f, "\nunset multiplot\n");
    fclose(f);
    /* the PNG itself obeys the output rules too: opened (and refused) here first */
    f = open_out("--report", png, force, config);
    if (!f) return -1;
    fclose(f);
    return eval_gnuplot(prog, gp);
}

int main(int argc, char **argv)
{
    const char *config = NULL, *controller = NULL, *suite = NULL, *require = NULL;
    const char *csv = NULL, *report_dir = NULL;
    const char *only[EVAL_CASES_MAX];
    int nonly = 0;
    bool force = false, verbose = false;
    double timeout = 600;
    char lagsimd[4096];
    eval_default_lagsimd(lagsimd, sizeof lagsimd);
    enum { O_CASE = 256, O_SUITE, O_REQUIRE, O_CSV, O_REPORT, O_LAGSIMD, O_TIMEOUT };
    static const struct option opts[] = {
        {"config", required_argument, 0, 'c'},   {"controller", required_argument, 0, 'C'},
        {"case", required_argument, 0, O_CASE},  {"suite", required_argument, 0, O_SUITE},
        {"require", required_argument, 0, O_REQUIRE}, {"csv", required_argument, 0, O_CSV},
        {"report", required_argument, 0, O_REPORT}, {"force", no_argument, 0, 'f'},
        {"lagsimd", required_argument, 0, O_LAGSIMD},
        {"timeout", required_argument, 0, O_TIMEOUT}, {"verbose", no_argument, 0, 'v'},
        {"help", no_argument, 0, 'h'},            {0, 0, 0, 0}};
    int o;
    opterr = 0;
    while ((o = getopt_long(argc, argv, ":c:C:fvh", opts, NULL)) != -1) {
        switch (o) {
        case 'c': config = optarg; break;
        case 'C': controller = optarg; break;
        case O_CASE:
            if (nonly == EVAL_CASES_MAX) return die("too many --case (at most %s)", "256");
            only[nonly++] = optarg;
            break;
        case O_SUITE: suite = optarg; break;
        case O_REQUIRE: require = optarg; break;
        case O_CSV: csv = optarg; break;
        case O_REPORT: report_dir = optarg; break;
        case 'f': force = true; break;
        case O_LAGSIMD: snprintf(lagsimd, sizeof lagsimd, "%s", optarg); break;
        case O_TIMEOUT: {
            char *end;
            errno = 0;
            timeout = strtod(optarg, &end);
            if (errno || *end || !(timeout >= 1 && timeout <= 1e6))
                return die("--timeout: expected wall seconds from 1 to 1e6, got '%s'", optarg);
            break;
        }
        case 'v': verbose = true; break;
        case 'h': usage(stdout); return 0;
        case ':': return die("%s needs a value (try --help)", argv[optind - 1]);
        default: return die("unknown option '%s' (try --help)", argv[optind - 1]);
        }
    }
    if (optind < argc) return die("unexpected argument '%s' (try --help)", argv[optind]);
    if (!config) return die("%s", "--config SCENE is required (try --help)");
    if (!controller) return die("%s", "--controller 'COMMAND' is required (try --help)");

    char err[2048];
    eval_scene sc;
    if (eval_scene_load(config, NULL, 0, &sc, err, sizeof err)) return die("%s", err);
    lag_require req = {0};
    if (require && (lag_require_parse(require, &req, err, sizeof err) ||
                    eval_require_check(&req, &sc, err, sizeof err)))
        return die("--require: %s", err);

    eval_case *cases = NULL;
    int ncases = 0;
    if (eval_cases_load(suite ? suite : config, &cases, &ncases, err, sizeof err))
        return die("%s", err);
    if (!ncases) {
        fprintf(stderr, "%s: %s has no `cases:` (docs/evaluation.md)\n", prog,
                suite ? suite : config);
        return 2;
    }
    for (int i = 0; i < nonly; i++) {
        int found = 0;
        for (int k = 0; k < ncases; k++) found |= !strcmp(cases[k].name, only[i]);
        if (!found) {
            fprintf(stderr, "%s: --case %s: no such case in %s (it has:", prog, only[i],
                    suite ? suite : config);
            for (int k = 0; k < ncases; k++) fprintf(stderr, " %s", cases[k].name);
            fprintf(stderr, ")\n");
            free(cases);
            return 2;
        }
    }
    /* every case's overrides validated before anything runs; joint bounds named */
    eval_scene csc[EVAL_CASES_MAX];
    for (int k = 0; k < ncases; k++) {
        const char *sets[EVAL_SETS_MAX];
        for (int i = 0; i < cases[k].nsets; i++) sets[i] = cases[k].set[i];
        if (eval_scene_load(config, sets, cases[k].nsets, &csc[k], err, sizeof err)) {
            fprintf(stderr, "%s: case %s: %s\n", prog, cases[k].name, err);
            free(cases);
            return 2;
        }
        for (int b = 0; b < cases[k].nbounds; b++) {
            int found = 0;
            for (int j = 0; j < csc[k].nj; j++)
                found |= !strcmp(csc[k].joint[j], cases[k].bound_joint[b]);
            if (!found) {
                fprintf(stderr, "%s: case %s: bounds: the %s has no joint '%s'\n", prog,
                        cases[k].name, csc[k].model, cases[k].bound_joint[b]);
                free(cases);
                return 2;
            }
        }
    }
    if (report_dir && mkdir(report_dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: --report %s: %s\n", prog, report_dir, strerror(errno));
        free(cases);
        return 2;
    }
    FILE *fcsv = NULL;
    if (csv && !(fcsv = open_out("--csv", csv, force, config))) {
        free(cases);
        return 2;
    }
    if (fcsv) {
        fprintf(fcsv, "case,joint,failed,required,reason");
        for (int m = 0; m < LAG_METRIC_COUNT; m++) fprintf(fcsv, ",%s", lag_metric_table[m].name);
        fprintf(fcsv, ",max_abs_q,states,t_end\n");
    }
    char tmpdir[] = "/tmp/lagsim-eval.XXXXXX";
    const char *workdir = report_dir && verbose ? report_dir : mkdtemp(tmpdir);
    if (!workdir) {
        fprintf(stderr, "%s: cannot make a temporary directory: %s\n", prog, strerror(errno));
        free(cases);
        return 2;
    }

    /* the table's header */
    printf("%-14s %-8s %-6s", "case", "joint", "result");
    for (int m = 0; m < LAG_METRIC_COUNT; m++) printf(" %11s", lag_metric_table[m].name);
    printf("\n");
    int failures = 0, status = 0;
    for (int k = 0; k < ncases; k++) {
        const eval_case *c = &cases[k];
        int wanted = nonly == 0;
        for (int i = 0; i < nonly; i++) wanted |= !strcmp(only[i], c->name);
        if (!wanted) continue;
        eval_env env = {.lagsimd = lagsimd, .config = config, .controller = controller,
                        .workdir = workdir, .wall_timeout = timeout, .verbose = verbose};
        eval_url(k, env.url, sizeof env.url);
        snprintf(env.prefix, sizeof env.prefix, "EVAL%d_%d", (int)getpid(), k);
        eval_result res;
        eval_series s = {0};
        if (eval_run(&env, c, NULL, 0, &csc[k], &res, &s, err, sizeof err)) {
            fprintf(stderr, "%s: case %s: %s\n", prog, c->name, err);
            eval_series_free(&s);
            status = 2;
            break;
        }
        char why[256] = "";
        bool met = !require || eval_require_holds(&req, &csc[k], &res, why, sizeof why);
        if (res.failed || !met) failures++;
        for (int j = 0; j < csc[k].nj; j++) {
            printf("%-14s %-8s %-6s", j ? "" : c->name, csc[k].joint[j],
                   j ? "" : res.failed ? "FAIL" : met ? "ok" : "UNMET");
            for (int m = 0; m < LAG_METRIC_COUNT; m++) {
                char v[32];
                eval_fmt(res.m[j].v[m], v, sizeof v);
                printf(" %11s", v);
            }
            printf("\n");
            if (fcsv) {
                fprintf(fcsv, "%s,%s,%d,%d,\"%s\"", c->name, csc[k].joint[j], res.failed,
                        met, res.failed ? res.reason : why);
                for (int m = 0; m < LAG_METRIC_COUNT; m++) {
                    /* the CSV is read by programs: every digit of the double */
                    if (isnan(res.m[j].v[m])) fprintf(fcsv, ",nan");
                    else fprintf(fcsv, ",%.17g", res.m[j].v[m]);
                }
                fprintf(fcsv, ",%.17g,%zu,%.17g\n", res.max_abs_q[j], res.states, res.t_end);
            }
        }
        if (res.failed) printf("  %s failed: %s\n", c->name, res.reason);
        else if (!met) printf("  %s: --require: %s\n", c->name, why);
        fflush(stdout);
        if (report_dir && report(report_dir, force, config, c, &csc[k], &s, &res)) status = 2;
        eval_series_free(&s);
    }
    if (fcsv && fclose(fcsv) != 0) {
        fprintf(stderr, "%s: --csv %s: %s\n", prog, csv, strerror(errno));
        status = 2;
    }
    if (workdir == tmpdir) rmdir(tmpdir);
    free(cases);
    if (status) return status;
    return failures ? 1 : 0;
}
