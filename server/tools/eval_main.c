/*
 * lagsim-eval: runs a scene's cases in lockstep against a controller command and reports
 * each joint's metrics (the metrics library's, never recomputed here), whether a case
 * failed, and whether a requirement holds (controller CI). See docs/evaluation.md.
 */

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "eval_case.h"
#include "lagsim_num.h"

static const char *prog = "lagsim-eval";

static void usage(FILE *f)
{
    fprintf(f,
"usage: lagsim-eval --config SCENE --controller 'COMMAND' [--case NAME ...]\n"
"                   [--suite FILE] [--require EXPR] [--csv OUT.csv] [--report DIR]\n"
"                   [--force] [--url URL] [--allow-lan] [--lagsimd PATH] [--timeout S]\n"
"                   [-v]\n"
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
"                         prefix and LCM URL as they are, no quotes added (both are\n"
"                         letters, digits and _ - . : / ? = & only: the same inside\n"
"                         your own quotes; quote {url}, which has ? and &), and its\n"
"                         environment holds them (LAGSIM_PREFIX, LCM_DEFAULT_URL)\n"
"      --case NAME        run only this case (repeatable; default: every case)\n"
"      --suite FILE       take the cases from FILE's `cases:` instead of the scene's\n"
"      --require EXPR     exit 1 unless every case meets EXPR, e.g.\n"
"                         'theta.settle<2 and theta.overshoot<0.1'\n"
"      --csv OUT.csv      one row per case and joint: the metrics and the verdict\n"
"      --report DIR       a PNG per case in DIR (gnuplot): response, reference,\n"
"                         effort and the metrics, titled with the case's result\n"
"  -f, --force            replace existing output files\n"
"      --url URL          the runs' multicast group and options (default:\n"
"                         LCM_DEFAULT_URL's, else udpm://239.255.76.67?ttl=0&\n"
"                         recv_buf_size=4194304); the ports are lagsim-eval's: a pair\n"
"                         of its own, held while it runs, that no other evaluation or\n"
"                         sweep of this host holds and no socket of it is bound to\n"
"      --allow-lan        accept a URL with ttl above 0 (the runs on the network)\n"
"      --lagsimd PATH     the daemon (default: the lagsimd beside this program)\n"
"      --timeout S        wall seconds a case may take (default 600); a controller\n"
"                         not on {prefix} or LAGSIM_PREFIX never answers: its case\n"
"                         ends here (a plant still at t = 0 after 5 s is said on\n"
"                         stderr before, with what it waits for)\n"
"  -v, --verbose          pass the daemon's and the controller's output through, keep\n"
"                         each run's log in the report directory (or TMPDIR, /tmp)\n"
"                         and say where; without it their stderr goes to files of\n"
"                         the run, and a case that fails shows their last lines\n"
"                         under its note\n"
"  -h, --help             this help\n"
"\n"
"keys lagsim-eval sets on every run (a case's set: naming one, or a mapping above\n"
"one, is refused):\n");
    eval_owned_usage(f);
    fprintf(f,
"\n"
"exit codes: 0 every case ran, none failed and every case met --require; 1 a case\n"
"failed or missed the requirement; 2 usage, scene or case error (file:line:column)\n"
"\n"
"signals: SIGINT, SIGTERM, SIGHUP stop every process it started (SIGKILL after 2 s)\n"
"and end it by that signal; after SIGKILL they end within about 2 s. TMPDIR: where\n"
"the runs' logs go (default /tmp)\n");
}

static int die(const char *fmt, const char *a)
{
    fprintf(stderr, "%s: ", prog);
    fprintf(stderr, fmt, a);
    fputc('\n', stderr);
    return 2;
}

/* The files of a run that no output of it may be (lagsim_out.h compares them by device and
 * inode, so a hard link or another spelling of one is caught): those it reads (the scene,
 * the suite, the daemon), then every output it opened. */
typedef struct run_files {
    const char **path; /* [0, nin) the inputs; then the outputs (copies of their own) */
    const char **what; /* the option of each output ("--csv", "--report") */
    unsigned char *state; /* each output's: F_NEW (made by this run), F_DONE (written) */
    int nin, n, cap;
} run_files;
enum { F_NEW = 1, F_DONE = 2 };

static int files_add_now(run_files *rf, const char *path, const char *what, unsigned state);

/* files_add_now with SIGINT, SIGTERM and SIGHUP held off: remove_unfinished reads the list */
static int files_add(run_files *rf, const char *path, const char *what, unsigned state)
{
    sigset_t s, old;
    sigemptyset(&s);
    sigaddset(&s, SIGINT), sigaddset(&s, SIGTERM), sigaddset(&s, SIGHUP);
    sigprocmask(SIG_BLOCK, &s, &old);
    int rc = files_add_now(rf, path, what, state);
    sigprocmask(SIG_SETMASK, &old, NULL);
    return rc;
}

static int files_add_now(run_files *rf, const char *path, const char *what, unsigned state)
{
    if (rf->n == rf->cap) {
        int cap = rf->cap ? 2 * rf->cap : 16;
        const char **p = realloc(rf->path, (size_t)cap * sizeof *p);
        if (p) rf->path = p;
        const char **w = p ? realloc(rf->what, (size_t)cap * sizeof *w) : NULL;
        if (w) rf->what = w;
        unsigned char *st = w ? realloc(rf->state, (size_t)cap) : NULL;
        if (!st) return -1;
        rf->state = st, rf->cap = cap;
    }
    rf->path[rf->n] = what ? strdup(path) : path;
    rf->what[rf->n] = what;
    rf->state[rf->n] = (unsigned char)state;
    if (!rf->path[rf->n]) return -1;
    rf->n++;
    if (!what) rf->nin = rf->n;
    return 0;
}

/* The outputs a signal finds unfinished: those this run made and has not written (a
 * report of the case in progress or of one not run yet), removed before the tool ends by
 * the signal (eval_proc_at_stop; unlink only). The CSV stays: it holds the rows of the
 * cases that ended before, each written whole. */
static const run_files *stop_files;

static void remove_unfinished(void)
{
    const run_files *rf = stop_files;
    for (int i = rf ? rf->nin : 0; rf && i < rf->n; i++)
        if (rf->state[i] == F_NEW && strcmp(rf->what[i], "--csv") != 0) unlink(rf->path[i]);
}

/* The output `path` of option `what` is written: kept at the end. */
static void files_done(run_files *rf, const char *what, const char *path)
{
    for (int i = rf->nin; i < rf->n; i++)
        if (!strcmp(rf->what[i], what) && !strcmp(rf->path[i], path)) rf->state[i] |= F_DONE;
}

/* The end: an output this run made and never wrote (the report of a case that did not
 * run; a CSV of a run refused before its first case) is removed. */
static void files_end(run_files *rf)
{
    for (int i = rf->nin; i < rf->n; i++) {
        if (rf->state[i] == F_NEW) unlink(rf->path[i]);
        free((char *)rf->path[i]);
    }
    free(rf->path);
    free(rf->what);
    free(rf->state);
    memset(rf, 0, sizeof *rf);
}

/* An output of this run, by the rules of every lagsim output (eval_open_out): never one
 * of its inputs, nor another of its outputs; one opened before (a report file made before
 * the first run) is opened again as this run's own. NULL after saying why. */
static FILE *open_out(run_files *rf, const char *what, const char *path, bool force)
{
    const char **others = malloc((size_t)(rf->n + 1) * sizeof *others);
    if (!others) return NULL;
    int k = 0;
    bool again = false;
    for (int i = 0; i < rf->n; i++) {
        if (i >= rf->nin && !strcmp(rf->what[i], what) && !strcmp(rf->path[i], path))
            again = true;
        else
            others[k++] = rf->path[i];
    }
    struct stat st;
    bool existed = lstat(path, &st) == 0;
    FILE *f = eval_open_out(prog, what, path, force || again, others, k);
    free(others);
    if (f && !again && files_add(rf, path, what, existed ? 0 : F_NEW)) {
        fprintf(stderr, "%s: out of memory\n", prog);
        fclose(f);
        return NULL;
    }
    return f;
}

/* text in a double-quoted gnuplot string: '"' and '\\' escaped */
static void gp_text(FILE *f, const char *t)
{
    for (; *t; t++) {
        if (*t == '"' || *t == '\\') fputc('\\', f);
        fputc(*t == '\n' ? ' ' : *t, f);
    }
}

/* A title: as gp_text, each of the terms that fail ("; " between them) on a line of its
 * own. */
static void gp_title(FILE *f, const char *t)
{
    for (const char *semi; (semi = strstr(t, "; ")) != NULL; t = semi + 2) {
        char part[512];
        snprintf(part, sizeof part, "%.*s", (int)(semi - t), t);
        gp_text(f, part);
        fputs("\\n", f);
    }
    gp_text(f, t);
}

/* A CSV field (RFC 4180): in double quotes, a quote doubled, a control byte a space. */
static void csv_text(FILE *f, const char *t)
{
    fputc('"', f);
    for (; *t; t++) {
        if (*t == '"') fputc('"', f);
        fputc((unsigned char)*t < 0x20 || *t == 0x7f ? ' ' : *t, f);
    }
    fputc('"', f);
}

/* A y range that is never empty: [lo, hi] of the finite values of the nc columns (each
 * n long), widened by 1 each way when they are all equal (a plant that never moved);
 * gnuplot would otherwise warn of an empty range. */
static void y_range(FILE *f, const double *const *col, int nc, size_t n)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int c = 0; c < nc; c++)
        for (size_t k = 0; k < n; k++)
            if (isfinite(col[c][k])) lo = fmin(lo, col[c][k]), hi = fmax(hi, col[c][k]);
    if (!(lo <= hi)) lo = hi = 0;
    if (hi > lo) fprintf(f, "set yrange [*:*]\n");
    else fprintf(f, "set yrange [%.9g:%.9g]\n", lo - 1, hi + 1);
}

/* The metrics of each joint as labels, right of the report's first panel. */
static void report_labels(FILE *f, const eval_scene *sc, const eval_result *res)
{
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
                row, 0.66 + 0.33 * j / (sc->nj > 1 ? sc->nj : 1));
    }
}

/* The report's files of case c in dir: its data, its gnuplot script and its PNG. */
static void report_paths(const char *dir, const eval_case *c, char dat[1024], char gp[1024],
                         char png[1024])
{
    snprintf(dat, 1024, "%s/%s.dat", dir, c->name);
    snprintf(gp, 1024, "%s/%s.gp", dir, c->name);
    snprintf(png, 1024, "%s/%s.png", dir, c->name);
}

/* The PNG of one case: q (solid) and r (dashed) of each joint, the efforts, and the
 * metrics as text; its title says the verdict as the table does (FAIL and why, UNMET and
 * the term that fails, or ok); through gnuplot, from a data file beside it. */
static int report(run_files *rf, const char *dir, bool force, const eval_case *c,
                  const eval_scene *sc, const eval_series *s, const eval_result *res,
                  bool met, const char *why)
{
    char dat[1024], gp[1024], png[1024];
    report_paths(dir, c, dat, gp, png);
    FILE *f = open_out(rf, "--report", dat, force);
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
    f = open_out(rf, "--report", gp, force);
    if (!f) return -1;
    fprintf(f, "set terminal pngcairo noenhanced size 1200,640 font ',10'\n");
    fprintf(f, "set output '%s'\n", png);
    fprintf(f, "set multiplot layout 2,1 title \"%s: case %s: ", sc->model, c->name);
    if (res->failed) fprintf(f, "FAIL: ");
    else if (!met) fprintf(f, "UNMET --require: ");
    gp_title(f, res->failed ? res->reason : met ? "ok" : why);
    fprintf(f, "\"\n");
    fprintf(f, "set grid\nset key top right\nset xlabel 'sim time (s)'\n");
    /* the case's time, whatever the run reached: a run that never left t = 0 is no empty
     * range */
    double t_end = s->n ? s->t[s->n - 1] : 0;
    fprintf(f, "set xrange [0:%.9g]\n", t_end > c->duration ? t_end : c->duration);
    fprintf(f, "set lmargin 10\nset rmargin at screen 0.64\n");
    report_labels(f, sc, res);
    const double *cols[2 * EVAL_JOINTS_MAX];
    int nc = 0;
    for (int j = 0; j < sc->nj; j++) cols[nc++] = s->q[j], cols[nc++] = s->r[j];
    y_range(f, cols, nc, s->n);
    fprintf(f, "set ylabel 'q (m or rad)'\nplot ");
    /* a run without a state (gnuplot would warn of a file with no valid points) */
    if (!s->n) fprintf(f, "NaN t 'no state logged'");
    for (int j = 0; s->n && j < sc->nj; j++)
        fprintf(f, "%s'%s' u 1:%d w l lw 2 lc %d t '%s', '%s' u 1:%d w l dt 2 lc %d t '%s ref'",
                j ? ", " : "", dat, 2 + 3 * j, j + 1, sc->joint[j], dat, 3 + 3 * j, j + 1,
                sc->joint[j]);
    nc = 0;
    for (int j = 0; j < sc->nj; j++)
        if (sc->actuated[j]) cols[nc++] = s->u[j];
    fprintf(f, "\nunset label\n");
    y_range(f, cols, nc, s->n);
    fprintf(f, "set ylabel 'effort (N or N m)'\nplot ");
    int first = 1;
    for (int j = 0; s->n && j < sc->nj; j++) {
        if (!sc->actuated[j]) continue;
        fprintf(f, "%s'%s' u 1:%d w steps lw 1.5 lc %d t '%s effort'", first ? "" : ", ", dat,
                4 + 3 * j, j + 1, sc->joint[j]);
        first = 0;
    }
    if (first) fprintf(f, s->n ? "0 t 'no actuated joint'" : "NaN t 'no state logged'");
    fprintf(f, "\nunset multiplot\n");
    fclose(f);
    /* the PNG itself obeys the output rules too: opened (and refused) here first */
    f = open_out(rf, "--report", png, force);
    if (!f) return -1;
    fclose(f);
    /* the case's report is done once gnuplot has drawn it: a signal while gnuplot runs
     * finds all three unfinished (remove_unfinished) */
    int rc = eval_gnuplot(prog, gp);
    files_done(rf, "--report", dat);
    files_done(rf, "--report", gp);
    files_done(rf, "--report", png);
    return rc;
}

/* A run of lagsim-eval: the options, the scene and its cases, the outputs. */
typedef struct eval_cli {
    const char *config, *controller, *suite, *require, *csv, *report_dir, *url_opt;
    const char *only[EVAL_CASES_MAX];
    int nonly;
    bool force, verbose, allow_lan;
    double timeout;
    eval_bus bus;           /* the runs' group and options */
    lag_port_lease lease;   /* their ports, held while lagsim-eval runs */
    char url[160];          /* the runs' URL */
    char lagsimd[4096];
    char err[2048];
    eval_scene sc;
    lag_require req;
    eval_case *cases;
    int ncases;
    eval_scene csc[EVAL_CASES_MAX]; /* each case's scene, its overrides applied */
    FILE *fcsv;
    run_files files;
    char tmpdir[256];
    const char *workdir;
    int failures, status;
    char cmd_files[EVAL_CMD_FILES_MAX][1024]; /* the files the controller command names */
} eval_cli;

/* The options. Returns -1 to go on, or the exit code. */
static int parse_options(eval_cli *x, int argc, char **argv)
{
    enum { O_CASE = 256, O_SUITE, O_REQUIRE, O_CSV, O_REPORT, O_LAGSIMD, O_TIMEOUT, O_URL,
           O_ALLOW_LAN };
    static const struct option opts[] = {
        {"config", required_argument, 0, 'c'},   {"controller", required_argument, 0, 'C'},
        {"case", required_argument, 0, O_CASE},  {"suite", required_argument, 0, O_SUITE},
        {"require", required_argument, 0, O_REQUIRE}, {"csv", required_argument, 0, O_CSV},
        {"report", required_argument, 0, O_REPORT}, {"force", no_argument, 0, 'f'},
        {"lagsimd", required_argument, 0, O_LAGSIMD}, {"url", required_argument, 0, O_URL},
        {"allow-lan", no_argument, 0, O_ALLOW_LAN},
        {"timeout", required_argument, 0, O_TIMEOUT}, {"verbose", no_argument, 0, 'v'},
        {"help", no_argument, 0, 'h'},            {0, 0, 0, 0}};
    int o;
    opterr = 0;
    while ((o = getopt_long(argc, argv, ":c:C:fvh", opts, NULL)) != -1) {
        switch (o) {
        case 'c': x->config = optarg; break;
        case 'C': x->controller = optarg; break;
        case O_CASE:
            if (x->nonly == EVAL_CASES_MAX) return die("too many --case (at most %s)", "256");
            x->only[x->nonly++] = optarg;
            break;
        case O_SUITE: x->suite = optarg; break;
        case O_REQUIRE: x->require = optarg; break;
        case O_CSV: x->csv = optarg; break;
        case O_REPORT: x->report_dir = optarg; break;
        case 'f': x->force = true; break;
        case O_LAGSIMD: snprintf(x->lagsimd, sizeof x->lagsimd, "%s", optarg); break;
        case O_URL: x->url_opt = optarg; break;
        case O_ALLOW_LAN: x->allow_lan = true; break;
        case O_TIMEOUT: {
            char *end;
            errno = 0;
            x->timeout = strtod(optarg, &end);
            if (errno || *end || !(x->timeout >= 1 && x->timeout <= 1e6))
                return die("--timeout: expected wall seconds from 1 to 1e6, got '%s'", optarg);
            break;
        }
        case 'v': x->verbose = true; break;
        case 'h': usage(stdout); return 0;
        case ':': return die("%s needs a value (try --help)", argv[optind - 1]);
        default: return die("unknown option '%s' (try --help)", argv[optind - 1]);
        }
    }
    if (optind < argc) return die("unexpected argument '%s' (try --help)", argv[optind]);
    if (!x->config) return die("%s", "--config SCENE is required (try --help)");
    if (!x->controller) return die("%s", "--controller 'COMMAND' is required (try --help)");
    if (eval_bus_init(&x->bus, x->url_opt, x->allow_lan, x->err, sizeof x->err))
        return die("%s", x->err);
    return -1;
}

/* The scene, --require, the cases, and every --case among them. Returns -1 or the exit
 * code. */
static int load_cases(eval_cli *x)
{
    const char *from = x->suite ? x->suite : x->config;
    if (eval_scene_load(x->config, NULL, 0, &x->sc, x->err, sizeof x->err))
        return die("%s", x->err);
    if (x->require && (lag_require_parse(x->require, &x->req, x->err, sizeof x->err) ||
                       eval_require_check(&x->req, &x->sc, x->err, sizeof x->err)))
        return die("--require: %s", x->err);
    if (eval_cases_load(from, &x->cases, &x->ncases, x->err, sizeof x->err))
        return die("%s", x->err);
    if (!x->ncases) {
        fprintf(stderr, "%s: %s has no `cases:` (docs/evaluation.md)\n", prog, from);
        return 2;
    }
    for (int i = 0; i < x->nonly; i++) {
        int found = 0;
        for (int k = 0; k < x->ncases; k++) found |= !strcmp(x->cases[k].name, x->only[i]);
        if (!found) {
            fprintf(stderr, "%s: --case %s: no such case in %s (it has:", prog, x->only[i],
                    from);
            for (int k = 0; k < x->ncases; k++) fprintf(stderr, " %s", x->cases[k].name);
            fprintf(stderr, ")\n");
            return 2;
        }
    }
    return -1;
}

/* Whether case c runs: every case, or those --case names. */
static bool wanted(const eval_cli *x, const eval_case *c)
{
    bool yes = x->nonly == 0;
    for (int i = 0; i < x->nonly; i++) yes |= !strcmp(x->only[i], c->name);
    return yes;
}

/* Every case's overrides validated before anything runs; joint bounds named. Returns -1
 * or the exit code. */
static int check_cases(eval_cli *x)
{
    for (int k = 0; k < x->ncases; k++) {
        const eval_case *c = &x->cases[k];
        eval_scene *csc = &x->csc[k];
        if (eval_case_scene_load(x->config, x->suite ? x->suite : x->config, c, NULL, 0, csc,
                                 x->err, sizeof x->err)) {
            fprintf(stderr, "%s: %s\n", prog, x->err);
            return 2;
        }
        for (int b = 0; b < c->nbounds; b++) {
            int found = 0;
            for (int j = 0; j < csc->nj; j++) found |= !strcmp(csc->joint[j], c->bound_joint[b]);
            if (!found) {
                fprintf(stderr, "%s: case %s: bounds: the %s has no joint '%s'\n", prog,
                        c->name, csc->model, c->bound_joint[b]);
                return 2;
            }
        }
    }
    return -1;
}

/* The runs' bus: a pair of ports held for the whole evaluation (the group and options,
 * of --url or LCM_DEFAULT_URL, were read with the options). Returns -1 or the exit code. */
static int open_bus(eval_cli *x)
{
    if (eval_bus_take(&x->bus, &x->lease, x->url, sizeof x->url, x->err, sizeof x->err))
        return die("%s", x->err);
    return -1;
}

/* The report directory, the CSV (with its header) and the work directory. Returns -1 or
 * the exit code. */
static int open_outputs(eval_cli *x)
{
    stop_files = &x->files; /* a signal removes what this run made and did not finish */
    eval_proc_at_stop(remove_unfinished);
    if (files_add(&x->files, x->config, NULL, 0) || files_add(&x->files, x->lagsimd, NULL, 0) ||
        (x->suite && files_add(&x->files, x->suite, NULL, 0)))
        return die("%s", "out of memory");
    /* and what the controller command names (its script): read by every run */
    int ncf = eval_command_files(x->controller, x->cmd_files, EVAL_CMD_FILES_MAX);
    for (int k = 0; k < ncf; k++)
        if (files_add(&x->files, x->cmd_files[k], NULL, 0)) return die("%s", "out of memory");
    if (x->report_dir && mkdir(x->report_dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: --report %s: %s\n", prog, x->report_dir, strerror(errno));
        return 2;
    }
    if (x->csv && !(x->fcsv = open_out(&x->files, "--csv", x->csv, x->force))) return 2;
    /* the report's files too, before the first run: an evaluation that cannot write its
     * results refuses at once */
    for (int k = 0; x->report_dir && k < x->ncases; k++) {
        if (!wanted(x, &x->cases[k])) continue;
        char p[3][1024];
        report_paths(x->report_dir, &x->cases[k], p[0], p[1], p[2]);
        for (int i = 0; i < 3; i++) {
            FILE *f = open_out(&x->files, "--report", p[i], x->force);
            if (!f) return 2;
            fclose(f);
        }
    }
    if (x->fcsv) {
        fprintf(x->fcsv, "case,joint,failed,required,reason");
        for (int m = 0; m < LAG_METRIC_COUNT; m++)
            fprintf(x->fcsv, ",%s", lag_metric_table[m].name);
        fprintf(x->fcsv, ",max_abs_q,states,t_end\n");
    }
    x->workdir = x->report_dir && x->verbose ? x->report_dir
                 : eval_make_tmpdir("lagsim-eval", x->tmpdir, sizeof x->tmpdir) == 0 ? x->tmpdir
                                                                                    : NULL;
    if (x->verbose) eval_proc_tmpdir_done(); /* -v keeps the runs' logs, even on a signal */
    if (!x->workdir) {
        fprintf(stderr, "%s: cannot make a temporary directory: %s\n", prog, strerror(errno));
        return 2;
    }
    if (x->verbose) /* kept: said where, once */
        fprintf(stderr, "%s: -v: each case's log (EVAL%d_<case's index>.lcm) is kept in %s\n",
                prog, (int)getpid(), x->workdir);
    return -1;
}

/* The rows of one case and joint: the table on stdout and the CSV. */
static void write_rows(eval_cli *x, const eval_case *c, const eval_scene *csc,
                       const eval_result *res, bool met, const char *why)
{
    for (int j = 0; j < csc->nj; j++) {
        printf("%-14s %-8s %-6s", j ? "" : c->name, csc->joint[j],
               j ? "" : res->failed ? "FAIL" : met ? "ok" : "UNMET");
        for (int m = 0; m < LAG_METRIC_COUNT; m++) {
            char v[32];
            eval_fmt(res->m[j].v[m], v, sizeof v);
            printf(" %11s", v);
        }
        printf("\n");
        if (!x->fcsv) continue;
        char num[LAG_NUM_LEN];
        fprintf(x->fcsv, "%s,%s,%d,%d,", c->name, csc->joint[j], res->failed, met);
        csv_text(x->fcsv, res->failed ? res->reason : why);
        for (int m = 0; m < LAG_METRIC_COUNT; m++) {
            /* the CSV is read by programs: the double exactly (lagsim_num.h) */
            if (isnan(res->m[j].v[m])) fprintf(x->fcsv, ",nan");
            else fprintf(x->fcsv, ",%s", lag_num(res->m[j].v[m], num));
        }
        char t_end[LAG_NUM_LEN];
        fprintf(x->fcsv, ",%s,%zu,%s\n", lag_num(res->max_abs_q[j], num), res->states,
                lag_num(res->t_end, t_end));
    }
}

/* A case whose scene has a reference for some joints and not for others: the table's
 * notes say which are scored against r = 0 (an sse of -0.5 for a joint held at 0.5 by the
 * controller's own setpoint is that, not an error of the controller). */
static void note_unreferenced(const eval_case *c, const eval_scene *csc)
{
    char names[EVAL_JOINTS_MAX * (EVAL_NAME_LEN + 6)];
    if (!eval_scene_unreferenced(csc, names, sizeof names)) return;
    bool one = !strchr(names, ' ');
    printf("  %s: %s %s no reference (the scene's reference: names the other joints): %s "
           "metrics measure %s against r = 0\n", c->name, names, one ? "has" : "have",
           one ? "its" : "their", one ? "it" : "them");
}

/* Runs case k (if wanted) and reports it. Returns false when the run could not be made
 * (status 2: no further case runs). */
static bool run_case(eval_cli *x, int k)
{
    const eval_case *c = &x->cases[k];
    if (!wanted(x, c)) return true;
    eval_env env = {.lagsimd = x->lagsimd, .config = x->config, .controller = x->controller,
                    .workdir = x->workdir, .wall_timeout = x->timeout, .verbose = x->verbose,
                    .allow_lan = x->allow_lan};
    /* the ports of the whole evaluation; a prefix of each case's own */
    snprintf(env.url, sizeof env.url, "%s", x->url);
    snprintf(env.prefix, sizeof env.prefix, "EVAL%d_%d", (int)getpid(), k);
    snprintf(env.who, sizeof env.who, "%s: case %s", prog, c->name);
    eval_result res;
    eval_series s = {0};
    if (eval_run(&env, c, NULL, 0, &x->csc[k], &res, &s, x->err, sizeof x->err)) {
        fprintf(stderr, "%s: case %s: %s\n", prog, c->name, x->err);
        eval_series_free(&s);
        x->status = 2;
        return false;
    }
    char why[2048] = "";
    bool met = !x->require || eval_require_holds(&x->req, &x->csc[k], &res, why, sizeof why);
    if (res.failed || !met) x->failures++;
    write_rows(x, c, &x->csc[k], &res, met, why);
    if (res.failed) printf("  %s failed: %s\n", c->name, res.reason);
    else if (!met) printf("  %s: --require: %s\n", c->name, why);
    /* a failed run: what its controller and lagsimd said last (their stderr went to files
     * of the run; -v passes it through) */
    for (const char *l = res.output; *l;) {
        const char *nl = strchr(l, '\n');
        int len = nl ? (int)(nl - l) : (int)strlen(l);
        printf("    %.*s\n", len, l);
        l += len + (nl != NULL);
    }
    note_unreferenced(c, &x->csc[k]);
    fflush(stdout);
    if (x->report_dir &&
        report(&x->files, x->report_dir, x->force, c, &x->csc[k], &s, &res, met, why))
        x->status = 2;
    eval_series_free(&s);
    return true;
}

/* The table's header, every case, then the outputs closed. Returns the exit code. */
static int run_cases(eval_cli *x)
{
    printf("%-14s %-8s %-6s", "case", "joint", "result");
    for (int m = 0; m < LAG_METRIC_COUNT; m++) printf(" %11s", lag_metric_table[m].name);
    printf("\n");
    for (int k = 0; k < x->ncases && run_case(x, k); k++) {}
    if (x->fcsv && fclose(x->fcsv) != 0) {
        fprintf(stderr, "%s: --csv %s: %s\n", prog, x->csv, strerror(errno));
        x->status = 2;
    }
    x->fcsv = NULL;
    if (x->csv) files_done(&x->files, "--csv", x->csv);
    if (x->workdir == x->tmpdir) rmdir(x->tmpdir), eval_proc_tmpdir_done();
    if (x->status) return x->status;
    return x->failures ? 1 : 0;
}

int main(int argc, char **argv)
{
    static eval_cli x = {.timeout = 600, .lease = {.port = 0, .fd = -1}};
    eval_proc_init(); /* every process it starts ends when it ends (eval_proc.h) */
    eval_default_lagsimd(x.lagsimd, sizeof x.lagsimd);
    int rc;
    if ((rc = parse_options(&x, argc, argv)) < 0 && (rc = load_cases(&x)) < 0 &&
        (rc = check_cases(&x)) < 0 && (rc = open_bus(&x)) < 0 && (rc = open_outputs(&x)) < 0)
        rc = run_cases(&x);
    lag_port_release(&x.lease);
    free(x.cases);
    if (x.fcsv) fclose(x.fcsv); /* refused before its first case */
    eval_proc_at_stop(NULL);
    files_end(&x.files);
    return rc;
}
