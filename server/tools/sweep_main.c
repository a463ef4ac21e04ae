/*
 * lagsim-sweep: Monte Carlo and grid sweeps of an evaluation case over scene keys, each run
 * evaluated as lagsim-eval evaluates a case (eval_case.h); the CSV of the runs, a summary
 * (pass rate, percentiles of each metric), a PNG of a metric against each varied key;
 * shards (--shard K/N) and `lagsim-sweep merge` for sweeps spread over machines.
 *
 * Reproducible: run i's values come from (seed, i, the key's index) alone, never from
 * the worker or the shard that runs it, and rows are written in run order, so the same
 * seed gives the same CSV bit for bit whatever -j and however it is sharded and merged.
 */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "eval_case.h"
#include "lagsim_port.h"
#include "lagsim_url.h"
#include "scene.h"
#include "sweep_live.h"
#include "sweep_merge.h"
#include "lagsim_num.h"

static const char *prog = "lagsim-sweep";

#define VARY_MAX 16
#define ROW_MAX 8192 /* bytes of the CSV header and of a row at most (a row: < 4000) */

static void usage_end(FILE *f);

static void usage(FILE *f)
{
    fprintf(f,
"usage: lagsim-sweep --config SCENE --controller 'COMMAND' (--case NAME | --duration S)\n"
"                    --vary KEY=DIST ... [--runs N] [--seed S] [-j N] [--shard K/N]\n"
"                    [--only RUNS] [--restart | --plants-per-worker K] [--progress]\n"
"                    [--suite FILE] [--require EXPR] [--csv OUT.csv] [--plot OUT.png]\n"
"                    [--metric JOINT.METRIC] [--force] [--url URL] [--allow-lan]\n"
"                    [--lagsimd PATH] [--timeout S] [-v]\n"
"       lagsim-sweep merge A.csv B.csv ... -o OUT.csv [--partial] [--force]\n"
"\n"
"Runs an evaluation case (lagsim-eval's) over scene keys drawn at random or on a grid,\n"
"each run in lockstep against the controller, and writes one CSV row per run: the\n"
"values, the verdict and every joint's metrics; prints the pass rate and percentiles.\n"
"\n"
"options:\n"
"  -c, --config SCENE     the scene file (lagsimd's)\n"
"  -C, --controller CMD   the controller's shell command; {prefix} and {url} are\n"
"                         replaced as they are, no quotes added (as lagsim-eval)\n"
"      --case NAME        the case to vary (from the scene's or the suite's cases:)\n"
"      --suite FILE       take the cases from FILE\n"
"  -d, --duration S       without --case: a case of S sim seconds and no overrides\n"
"      --vary KEY=DIST    a scene key (as lagsimd --set; initial.q[i], initial.qd[i]\n"
"                         for one coordinate) and its values: uniform(A,B) (A < B),\n"
"                         normal(MEAN,SD) (SD > 0) or grid(A,B,N) (N values from A\n"
"                         up to B > A, N from 2 to 1e6), numbers as plain decimals;\n"
"                         repeatable, each key once: grids multiply, random keys are\n"
"                         drawn per run\n"
"  -n, --runs N           runs (per grid point when there are grids; default 1)\n"
"      --seed S           the random seed of every drawn value (default 1)\n"
"  -j, --jobs N           runs at once on this machine (default 1)\n"
"      --shard K/N        only runs i with i mod N = K - 1 (K = 1..N, N <= 1e7): one\n"
"                         machine's part; lagsim-sweep merge joins the parts\n"
"      --only RUNS        only these runs (of the shard's), as a CSV's held line writes\n"
"                         them: A-B,C (a sweep stopped before its end says which runs to\n"
"                         give it); merge joins its CSV with the others\n"
"      --restart          a daemon and a controller started for each run, with the\n"
"                         run's values (default: one of each per worker, started\n"
"                         with the scene's values; each run's values SET and its\n"
"                         initial state RESET_TO between runs)\n"
"      --plants-per-worker K  the workers' plants K to a lagsimd (a host, lagsimd\n"
"                         --plants), each worker driving its own plant of it; the same\n"
"                         CSV (default 1: a lagsimd per worker, the faster for\n"
"                         lockstep runs on this machine: docs/evaluation.md)\n"
"      --require EXPR     a run that misses EXPR does not pass (as lagsim-eval)\n"
"      --csv OUT.csv      the runs' CSV\n"
"      --plot OUT.png     --metric against each varied key (gnuplot); runs without\n"
"                         a value (never settled) on a line at the top\n"
"      --metric J.M       the metric drawn (default: --require's first, else the first\n"
"                         joint's iae)\n"
"  -f, --force            replace existing output files\n"
"      --url URL          the runs' multicast group and options (default:\n"
"                         LCM_DEFAULT_URL's, else udpm://239.255.76.67?ttl=0&\n"
"                         recv_buf_size=4194304); the ports are lagsim-sweep's: a pair\n"
"                         for each worker, held while it runs, that no other sweep or\n"
"                         evaluation of this host holds and no socket of it is bound to\n"
"      --allow-lan        accept a URL with ttl above 0 (the runs on the network)\n"
"      --lagsimd PATH     the daemon (default: the lagsimd beside this program)\n"
"      --timeout S        wall seconds a run may take (default 600); a new pair's\n"
"                         first answer is waited for at most 30 s, or S when shorter\n"
"      --progress         the progress line (runs done, failed, rate, ETA) on stderr when\n"
"                         it is no terminal too: a line every 10 s (on a terminal it is\n"
"                         drawn without it, up to 4 times a second, unless -v)\n"
"  -v, --verbose          pass the daemon's and the controller's output through, keep\n"
"                         the daemons' logs in the temporary directory and say where;\n"
"                         without it their stderr goes to files of the run, and the\n"
"                         first failed run of each worker shows their last lines\n"
"  -o, --output OUT.csv   merge: the joined CSV (the whole sweep's, byte for byte); every\n"
"                         shard's identity lines (# seed:, # scene-sha256:, # vary:, ...)\n"
"                         must be the first's, every row one of its header, every shard\n"
"                         and run there\n"
"      --partial          merge: join shards that leave shards or runs out\n"
"  -h, --help             this help\n"
"\n"
"keys lagsim-sweep sets on every run (a case's set: or a --vary naming one, or a\n"
"mapping above one, is refused):\n");
    eval_owned_usage(f);
    usage_end(f);
}

/* --help's end: the exit codes and the signals. */
static void usage_end(FILE *f)
{
    fprintf(f,
"\n"
"exit codes: 0 every run passed; 1 a run failed or missed --require; 2 usage, scene or\n"
"case error, an output that exists (checked before the first run), a controller that\n"
"cannot answer the first state of a worker's first lagsimd, or shard CSVs that do not\n"
"belong together, hold a malformed row or leave shards or runs out\n"
"\n"
"signals: SIGINT, SIGTERM, SIGHUP stop every process it started (SIGKILL after 2 s),\n"
"write the rows of the runs that ended to --csv in run order (its held line says\n"
"which, stderr how to run the others: --only) and end it by that signal; after\n"
"SIGKILL they end within about 2 s, and --csv holds the rows of the runs that had\n"
"ended (written as each ended; held: unknown). TMPDIR: where the workers' files go\n"
"(default /tmp)\n");
}

static int die(const char *fmt, const char *a)
{
    fprintf(stderr, "%s: ", prog);
    fprintf(stderr, fmt, a);
    fputc('\n', stderr);
    return 2;
}

/* ---------------------------------------------------------------- varied keys */
typedef enum { V_UNIFORM, V_NORMAL, V_GRID } vary_kind;

typedef struct vary {
    char text[EVAL_SET_LEN];  /* as given, the CSV column's name is its key */
    char key[EVAL_SET_LEN];   /* "parameters.m1", "initial.q" */
    int index;                /* initial.q[i]: i; else -1 */
    vary_kind kind;
    double a, b;
    long n;                   /* grid points */
} vary;

/* The numbers of "NAME(X1, ..., Xn)" at d into x: each a plain decimal as a scene writes
 * one (lag_scene_read_decimal: not inf, nan, 0x1p3 or 1e999), nothing after the ')'. */
static bool read_args(const char *d, const char *name, int n, double *x)
{
    size_t nl = strlen(name);
    if (strncmp(d, name, nl) || d[nl] != '(') return false;
    const char *p = d + nl + 1;
    for (int i = 0; i < n; i++) {
        size_t len = strcspn(p, i + 1 < n ? "," : ")");
        char num[64];
        if (!p[len] || len >= sizeof num) return false;
        /* blanks around a number are allowed, as in uniform(0.5, 2) */
        while (len && p[len - 1] == ' ') len--;
        size_t lead = strspn(p, " ");
        if (lead >= len) return false;
        memcpy(num, p + lead, len - lead);
        num[len - lead] = '\0';
        if (lag_scene_read_decimal(num, &x[i]) != LAG_OK) return false;
        p += strcspn(p, i + 1 < n ? "," : ")") + 1;
    }
    return p[0] == '\0' && p[-1] == ')';
}

/* KEY, and its index on initial.q[i] / initial.qd[i] */
static int parse_vary_key(const char *text, vary *v, char *why, size_t len)
{
    const char *eq = strchr(text, '=');
    if (!eq || eq == text || (size_t)(eq - text) >= sizeof v->key)
        return snprintf(why, len, "expected KEY=DIST"), -1;
    memcpy(v->key, text, (size_t)(eq - text));
    v->index = -1;
    char *br = strchr(v->key, '[');
    if (!br && (!strcmp(v->key, "initial.q") || !strcmp(v->key, "initial.qd")))
        return snprintf(why, len, "%s is a list: vary one coordinate, %s[i]", v->key,
                        v->key), -1;
    if (!br) return 0;
    char *end;
    long i = strtol(br + 1, &end, 10);
    if ((strncmp(v->key, "initial.q[", 10) && strncmp(v->key, "initial.qd[", 11)) ||
        end == br + 1 || strcmp(end, "]") || !(br[1] >= '0' && br[1] <= '9') || i < 0 ||
        i >= EVAL_JOINTS_MAX)
        return snprintf(why, len, "an index only on initial.q[i] or initial.qd[i], i from 0 "
                        "to %d", EVAL_JOINTS_MAX - 1), -1;
    *br = '\0';
    v->index = (int)i;
    return 0;
}

/* A --vary: KEY=uniform(A,B), normal(MEAN,SD) or grid(A,B,N). Every value a run can get is
 * a finite double: A < B (a grid ascends, as uniform's range), B - A finite, SD > 0 and
 * MEAN +- 9 SD finite (Box-Muller's draws stay within 8.7 SD), N an integer from 2 to
 * 1e6. -1 with what was expected in why. */
static int parse_vary(const char *text, vary *v, char *why, size_t len)
{
    memset(v, 0, sizeof *v);
    snprintf(v->text, sizeof v->text, "%s", text);
    if (parse_vary_key(text, v, why, len)) return -1;
    const char *d = strchr(text, '=') + 1;
    double x[3];
    if (read_args(d, "uniform", 2, x)) {
        v->kind = V_UNIFORM;
        if (!(x[0] < x[1]) || !isfinite(x[1] - x[0]))
            return snprintf(why, len, "uniform(A,B) needs A < B and B - A finite"), -1;
    } else if (read_args(d, "normal", 2, x)) {
        v->kind = V_NORMAL;
        if (!(x[1] > 0) || !isfinite(fabs(x[0]) + 9 * x[1]))
            return snprintf(why, len, "normal(MEAN,SD) needs SD > 0 and MEAN +- 9 SD finite "
                            "(the draws reach 8.7 SD)"), -1;
    } else if (read_args(d, "grid", 3, x)) {
        v->kind = V_GRID;
        if (!(x[0] < x[1]) || !isfinite(x[1] - x[0]))
            return snprintf(why, len, "grid(A,B,N) needs A < B (it goes from A up to B) and "
                            "B - A finite"), -1;
        if (!(x[2] >= 2 && x[2] <= 1e6 && x[2] == floor(x[2])))
            return snprintf(why, len, "grid(A,B,N) needs N, its number of points, an integer "
                            "from 2 to 1e6"), -1;
        v->n = (long)x[2];
    } else {
        return snprintf(why, len, "expected uniform(A,B), normal(MEAN,SD) or grid(A,B,N), "
                        "each number a plain decimal"), -1;
    }
    v->a = x[0], v->b = x[1];
    return 0;
}

/* -1 after saying so when v varies a key (or a coordinate) that an earlier --vary of vs
 * varies too, or holds or lies under it: a run could take only one of the values, and
 * the CSV would show both. */
static int vary_twice(const vary *vs, int nv, const vary *v)
{
    for (int k = 0; k < nv; k++) {
        const vary *o = &vs[k];
        if (!eval_key_overlap(o->key, strlen(o->key), v->key, strlen(v->key))) continue;
        /* two coordinates of one list are two keys */
        if (!strcmp(o->key, v->key) && o->index >= 0 && v->index >= 0 && o->index != v->index)
            continue;
        bool same = !strcmp(o->key, v->key) && o->index == v->index;
        fprintf(stderr, "%s: --vary %s: %s that of --vary %s: a run takes one value of a "
                "key (one of the two CSV columns would be false); vary each key once\n",
                prog, v->text, same ? "the same key as" : "its key holds or lies in",
                o->text);
        return -1;
    }
    return 0;
}

/* A varied key the tools own (eval_owned_keys) is refused: said, and -1. */
static int vary_owned(const vary *v)
{
    char why[512];
    if (!eval_owned_check(v->key, strlen(v->key), why, sizeof why)) return 0;
    fprintf(stderr, "%s: --vary %s: %s: a sweep cannot vary it\n", prog, v->text, why);
    return -1;
}

/* splitmix64: one 64-bit mix of (seed, run, key, draw), the only source of randomness */
static uint64_t mix(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double unit(uint64_t seed, long run, int key, int draw)
{
    uint64_t z = mix(mix(mix(seed) ^ (uint64_t)run) ^ ((uint64_t)key << 8 | (uint64_t)draw));
    return ((double)(z >> 11) + 0.5) * 0x1.0p-53; /* in (0, 1) */
}

/* The value of key k in run i: grids by the run's grid point, the others drawn. */
static double vary_value(const vary *vs, int nv, int k, long run, long runs_per_point,
                         uint64_t seed)
{
    const vary *v = &vs[k];
    if (v->kind == V_GRID) {
        long point = run / runs_per_point;
        for (int g = nv - 1; g > k; g--)
            if (vs[g].kind == V_GRID) point /= vs[g].n;
        long at = point % v->n;
        return v->n == 1 ? v->a : v->a + (v->b - v->a) * (double)at / (double)(v->n - 1);
    }
    double u1 = unit(seed, run, k, 0);
    if (v->kind == V_UNIFORM) return v->a + (v->b - v->a) * u1;
    double u2 = unit(seed, run, k, 1); /* Box-Muller */
    return v->a + v->b * sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

/* The --set strings of a run: keys as they are, coordinates joined into their list. */
static int run_sets(const vary *vs, int nv, const double *val, const eval_scene *sc,
                    char sets[][EVAL_SET_LEN])
{
    int n = 0;
    char num[LAG_NUM_LEN];
    double q[EVAL_JOINTS_MAX], qd[EVAL_JOINTS_MAX];
    bool has_q = false, has_qd = false;
    memcpy(q, sc->q0, sizeof q);
    memcpy(qd, sc->qd0, sizeof qd);
    for (int k = 0; k < nv; k++) {
        if (vs[k].index < 0) {
            snprintf(sets[n++], EVAL_SET_LEN, "%s=%s", vs[k].key, lag_num(val[k], num));
        } else if (!strcmp(vs[k].key, "initial.q")) {
            q[vs[k].index] = val[k], has_q = true;
        } else {
            qd[vs[k].index] = val[k], has_qd = true;
        }
    }
    for (int w = 0; w < 2; w++) {
        if (!(w ? has_qd : has_q)) continue;
        const double *x = w ? qd : q;
        size_t u = (size_t)snprintf(sets[n], EVAL_SET_LEN, "initial.%s=[", w ? "qd" : "q");
        for (int j = 0; j < sc->nj && u < EVAL_SET_LEN; j++)
            u += (size_t)snprintf(sets[n] + u, EVAL_SET_LEN - u, "%s%s", j ? ", " : "",
                                  lag_num(x[j], num));
        if (u < EVAL_SET_LEN) snprintf(sets[n] + u, EVAL_SET_LEN - u, "]");
        n++;
    }
    return n;
}

/* ---------------------------------------------------------------- plot */
/* The column of a metric in the CSV's header, or -1. */
static int header_column(const char *header, const char *name)
{
    char hb[ROW_MAX];
    snprintf(hb, sizeof hb, "%s", header);
    char *hf[512];
    int nh = split(hb, hf, 512);
    for (int i = 0; i < nh; i++)
        if (!strcmp(hf[i], name)) return i;
    return -1;
}

/* The PNG: the metric against each varied key, one point a run. A run where the metric
 * has no value (never settled: nan) is drawn too, as a red triangle on a line above the
 * others, so that every run appears. The data and the script go to dir (the sweep's
 * temporary directory); png was opened (and so checked) before the first run. */
static int plot(const char *png, const char *dir, const char *header, rows *r, int nv,
                const char *metric)
{
    char hb[ROW_MAX];
    snprintf(hb, sizeof hb, "%s", header);
    char *hf[512];
    int nh = split(hb, hf, 512), cf = header_column(header, "failed");
    int cm = header_column(header, metric);
    if (cm < 0 || cf < 0) return -1; /* checked before the runs */
    char dat[300], gp[300];
    snprintf(dat, sizeof dat, "%s/plot.dat", dir);
    snprintf(gp, sizeof gp, "%s/plot.gp", dir);
    FILE *f = fopen(dat, "w");
    if (!f) {
        fprintf(stderr, "%s: --plot: %s: %s\n", prog, dat, strerror(errno));
        return -1;
    }
    double lo = INFINITY, hi = -INFINITY;
    int none = 0;
    for (int i = 0; i < r->n; i++) {
        char lb[ROW_MAX];
        snprintf(lb, sizeof lb, "%s", r->line[i]);
        char *fl[512];
        if (split(lb, fl, 512) != nh) continue;
        for (int k = 0; k < nv; k++) fprintf(f, "%s ", fl[1 + k]);
        double v = strtod(fl[cm], NULL);
        bool has = isfinite(v);
        if (has) lo = fmin(lo, v), hi = fmax(hi, v);
        none += !has;
        /* the value (0 when none), passed (not failed and --require met), no value */
        fprintf(f, "%s %d %d\n", has ? fl[cm] : "0",
                !strcmp(fl[cf], "0") && !strcmp(fl[cf + 1], "1"), !has);
    }
    fclose(f);
    if (!(lo <= hi)) lo = 0, hi = 1;
    double span = hi > lo ? hi - lo : fmax(1, fabs(hi));
    double top = hi + 0.12 * span; /* the line of the runs without a value */
    f = fopen(gp, "w");
    if (!f) {
        fprintf(stderr, "%s: --plot: %s: %s\n", prog, gp, strerror(errno));
        unlink(dat);
        return -1;
    }
    fprintf(f, "set terminal pngcairo noenhanced size %d,440 font ',10'\n", 420 * nv + 80);
    fprintf(f, "set output '%s'\nset grid\n", png);
    fprintf(f, "set offsets graph 0.05, graph 0.05, 0, 0\n");
    fprintf(f, "set yrange [%.9g:%.9g]\n", lo - 0.06 * span, top + 0.06 * span);
    fprintf(f, "set key outside bottom center horizontal\n");
    fprintf(f, "set multiplot layout 1,%d title '%d runs: %s (red: did not pass; %d with no "
               "value, drawn at the top)'\n", nv, r->n, metric, none);
    int c_val = nv + 1, c_pass = nv + 2, c_none = nv + 3;
    for (int k = 0; k < nv; k++) {
        fprintf(f, "set xlabel '%s'\nset ylabel '%s'\n", hf[1 + k], metric);
        fprintf(f, "set arrow 1 from graph 0, first %.9g to graph 1, first %.9g nohead dt 3 "
                   "lc rgb '#d62728'\n", top, top);
        fprintf(f, "plot '%s' u %d:($%d == 0 && $%d == 1 ? $%d : 1/0) pt 7 ps 0.6 "
                   "lc rgb '#1f77b4' t 'passed', "
                   "'' u %d:($%d == 0 && $%d == 0 ? $%d : 1/0) pt 7 ps 0.6 lc rgb '#d62728' "
                   "t 'did not pass', "
                   "'' u %d:($%d == 1 ? %.9g : 1/0) pt 9 ps 0.9 lc rgb '#d62728' "
                   "t 'no value (e.g. never settled)'\n",
                dat, k + 1, c_none, c_pass, c_val, k + 1, c_none, c_pass, c_val, k + 1, c_none,
                top);
    }
    fprintf(f, "unset multiplot\n");
    fclose(f);
    int rc = eval_gnuplot(prog, gp);
    unlink(dat);
    unlink(gp);
    return rc;
}

/* ---------------------------------------------------------------- the sweep */
static double parse_pos(const char *opt, const char *s, double lo, double hi, int *bad)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !(v >= lo && v <= hi)) {
        fprintf(stderr, "%s: %s: expected a number from %g to %g, got '%s'\n", prog, opt, lo,
                hi, s);
        *bad = 1;
    }
    return v;
}

/* ---------------------------------------------------------------- the sweep */
/* What a sweep is, from the command line and the scene. */
typedef struct sweep {
    const char *config, *controller, *suite, *case_name, *require, *csv, *png, *metric;
    double duration, timeout;
    long runs, jobs, shard_k, shard_n, per_point, total;
    uint64_t seed;
    const char *url_opt;
    bool force, verbose, restart, allow_lan;
    eval_bus bus;                /* the runs' group and options */
    lag_port_lease lease[256];   /* a pair of ports for each worker, held while it runs */
    char url[256][160];          /* each worker's URL */
    /* --plants-per-worker K: the workers in groups of K, each group's plants in one
     * lagsimd (a host, --plants) started before the workers: its directory's pair, then
     * its plants' pairs, consecutive; each worker drives its own plant of it */
    long ppw;
    long ngroups;
    int ppid;                    /* the sweep's pid: the plants' prefixes */
    lag_port_lease dir_lease[256];
    char dir_url[256][160];
    pid_t host[256];
    char attach[256][320];       /* each worker's plant's --log in its host */
    vary vs[VARY_MAX];
    int nv;
    char lagsimd[4096];
    eval_case c;
    eval_scene sc;
    lag_require req;
    char header[ROW_MAX];
    char *identity;      /* the CSV's identity lines (sweep_merge.h) */
    char default_metric[160];
    char tmpdir[160]; /* eval_make_tmpdir: at most 128 + 21 */
    char cmd_files[EVAL_CMD_FILES_MAX][1024]; /* the files the controller command names */
    bool stopping;       /* the sweep stops before its end (a controller that cannot run) */
    const char *only;    /* --only RUNS */
    const char *self;    /* argv[0]: the command, as it was run */
    const char *duration_text, *timeout_text; /* as given: the command that finishes it */
    bool progress, lagsimd_given;
    unsigned char *shards, *want; /* shards[K - 1]: --shard's K (all: the whole sweep);
                                   * want[run]: this sweep runs it (its shard, --only) */
    long nwant;
    sweep_live live;     /* the rows as they come, the CSV, the progress */
    bool png_new;        /* --plot made by this sweep (empty until its end) */
} sweep;

/* An integer option: a plain decimal (as a scene writes a number) with no fraction; lo
 * when it is not one (so that the caller's conversion to an integer is defined). */
static double parse_int(const char *opt, const char *s, double lo, double hi, int *bad)
{
    double v = 0;
    if (lag_scene_read_decimal(s, &v) != LAG_OK || v != floor(v) || !(v >= lo && v <= hi)) {
        fprintf(stderr, "%s: %s: expected an integer from %.0f to %.0f, got '%s'\n", prog, opt,
                lo, hi, s);
        *bad = 1;
        return lo;
    }
    return v;
}

/* One --vary: read, not on a key the tools own, not on a key varied already. -1 after
 * saying why. */
static int add_vary(sweep *x, const char *text)
{
    char why[256];
    if (x->nv == VARY_MAX) return die("at most %s --vary", "16"), -1;
    vary *v = &x->vs[x->nv];
    if (parse_vary(text, v, why, sizeof why)) {
        fprintf(stderr, "%s: --vary %s: %s\n", prog, text, why);
        return -1;
    }
    if (vary_owned(v) || vary_twice(x->vs, x->nv, v)) return -1;
    x->nv++;
    return 0;
}

static int parse_options(sweep *x, int argc, char **argv)
{
    enum { O_CASE = 256, O_SUITE, O_VARY, O_SEED, O_SHARD, O_REQUIRE, O_CSV, O_PLOT, O_METRIC,
           O_LAGSIMD, O_TIMEOUT, O_RESTART, O_URL, O_ALLOW_LAN, O_ONLY, O_PROGRESS, O_PPW };
    static const struct option opts[] = {
        {"config", required_argument, 0, 'c'},      {"controller", required_argument, 0, 'C'},
        {"case", required_argument, 0, O_CASE},     {"suite", required_argument, 0, O_SUITE},
        {"duration", required_argument, 0, 'd'},    {"vary", required_argument, 0, O_VARY},
        {"runs", required_argument, 0, 'n'},        {"seed", required_argument, 0, O_SEED},
        {"jobs", required_argument, 0, 'j'},        {"shard", required_argument, 0, O_SHARD},
        {"require", required_argument, 0, O_REQUIRE}, {"csv", required_argument, 0, O_CSV},
        {"plot", required_argument, 0, O_PLOT},     {"metric", required_argument, 0, O_METRIC},
        {"force", no_argument, 0, 'f'},             {"lagsimd", required_argument, 0, O_LAGSIMD},
        {"timeout", required_argument, 0, O_TIMEOUT}, {"verbose", no_argument, 0, 'v'},
        {"restart", no_argument, 0, O_RESTART},     {"help", no_argument, 0, 'h'},
        {"url", required_argument, 0, O_URL},       {"allow-lan", no_argument, 0, O_ALLOW_LAN},
        {"only", required_argument, 0, O_ONLY},     {"progress", no_argument, 0, O_PROGRESS},
        {"plants-per-worker", required_argument, 0, O_PPW}, {0, 0, 0, 0}};
    int o, bad = 0;
    opterr = 0;
    while ((o = getopt_long(argc, argv, ":c:C:d:n:j:fvh", opts, NULL)) != -1) {
        switch (o) {
        case 'c': x->config = optarg; break;
        case 'C': x->controller = optarg; break;
        case O_CASE: x->case_name = optarg; break;
        case O_SUITE: x->suite = optarg; break;
        case 'd':
            x->duration = parse_pos("--duration", optarg, 1e-3, 1e6, &bad);
            x->duration_text = optarg;
            break;
        case O_VARY:
            if (add_vary(x, optarg)) return 2;
            break;
        case 'n': x->runs = (long)parse_int("--runs", optarg, 1, 1e7, &bad); break;
        case O_SEED: x->seed = (uint64_t)parse_int("--seed", optarg, 0, 9e15, &bad); break;
        case 'j': x->jobs = (long)parse_int("--jobs", optarg, 1, 256, &bad); break;
        case O_SHARD:
            if (sweep_shard_parse(optarg, &x->shard_k, &x->shard_n))
                return die("--shard: expected K/N, whole numbers with 1 <= K <= N <= 1e7, got "
                           "'%s'", optarg);
            break;
        case O_REQUIRE: x->require = optarg; break;
        case O_CSV: x->csv = optarg; break;
        case O_PLOT: x->png = optarg; break;
        case O_METRIC: x->metric = optarg; break;
        case 'f': x->force = true; break;
        case O_LAGSIMD:
            snprintf(x->lagsimd, sizeof x->lagsimd, "%s", optarg);
            x->lagsimd_given = true;
            break;
        case O_TIMEOUT:
            x->timeout = parse_pos("--timeout", optarg, 1, 1e6, &bad);
            x->timeout_text = optarg;
            break;
        case O_ONLY: x->only = optarg; break;
        case O_PROGRESS: x->progress = true; break;
        case 'v': x->verbose = true; break;
        case O_RESTART: x->restart = true; break;
        case O_URL: x->url_opt = optarg; break;
        case O_ALLOW_LAN: x->allow_lan = true; break;
        case O_PPW: x->ppw = (long)parse_int("--plants-per-worker", optarg, 1, 64, &bad); break;
        case 'h': usage(stdout); return 0;
        case ':': return die("%s needs a value (try --help)", argv[optind - 1]);
        default: return die("unknown option '%s' (try --help)", argv[optind - 1]);
        }
        if (bad) return 2;
    }
    return -1; /* go on */
}

static int check_options(sweep *x, int argc, char **argv)
{
    if (optind < argc) return die("unexpected argument '%s' (try --help)", argv[optind]);
    if (!x->config) return die("%s", "--config SCENE is required (try --help)");
    if (!x->controller) return die("%s", "--controller 'COMMAND' is required (try --help)");
    if (!x->nv) return die("%s", "at least one --vary KEY=DIST is required (try --help)");
    if (!x->case_name == !x->duration) return die("%s", "give either --case NAME or --duration S");
    if (x->ppw > 1 && x->restart)
        return die("%s", "--plants-per-worker shares kept daemons between runs: not with "
                   "--restart");
    char err[512];
    if (eval_bus_init(&x->bus, x->url_opt, x->allow_lan, err, sizeof err)) return die("%s", err);
    return -1;
}

/* The case: --case NAME from the scene's or the suite's cases, or --duration alone. */
static int load_case(sweep *x)
{
    char err[2048];
    if (!x->case_name) {
        snprintf(x->c.name, sizeof x->c.name, "sweep");
        x->c.duration = x->duration;
        return -1;
    }
    const char *from = x->suite ? x->suite : x->config;
    eval_case *cases = NULL;
    int ncases = 0, found = -1;
    if (eval_cases_load(from, &cases, &ncases, err, sizeof err)) return die("%s", err);
    for (int k = 0; k < ncases; k++)
        if (!strcmp(cases[k].name, x->case_name)) found = k;
    if (found >= 0) x->c = cases[found];
    free(cases);
    if (found >= 0) return -1;
    fprintf(stderr, "%s: --case %s: no such case in %s\n", prog, x->case_name, from);
    return 2;
}

/* The scene with the case's overrides, the requirement, and whether the varied keys can
 * change while one daemon runs (SET, RESET_TO) */
static int load_scene(sweep *x)
{
    char err[2048];
    if (eval_case_scene_load(x->config, x->suite ? x->suite : x->config, &x->c, NULL, 0, &x->sc,
                             err, sizeof err))
        return die("%s", err);
    for (int k = 0; k < x->nv; k++)
        if (x->vs[k].index >= x->sc.nj)
            return die("--vary %s: the scene's model has fewer coordinates", x->vs[k].text);
    if (x->require && (lag_require_parse(x->require, &x->req, err, sizeof err) ||
                       eval_require_check(&x->req, &x->sc, err, sizeof err)))
        return die("--require: %s", err);
    for (int k = 0; !x->restart && k < x->nv; k++) {
        const char *key = x->vs[k].key;
        if (lag_scene_key_live(key) || !strcmp(key, "initial.q") || !strcmp(key, "initial.qd"))
            continue;
        fprintf(stderr, "%s: %s cannot change while lagsimd runs (SET takes the keys under "
                        "parameters, effects and reference, RESET_TO initial.q and "
                        "initial.qd): a daemon and a controller are started for each run "
                        "(--restart)\n", prog, key);
        x->restart = true;
        if (x->ppw > 1)
            fprintf(stderr, "%s: --plants-per-worker %ld: each run has a daemon of its own "
                    "then: one plant per worker\n", prog, x->ppw);
        x->ppw = 1;
    }
    x->per_point = x->total = x->runs;
    for (int k = 0; k < x->nv; k++) /* each factor <= 1e7: checked before it can overflow */
        if (x->vs[k].kind == V_GRID && (x->total *= x->vs[k].n) > 10000000)
            return die("%s", "more than 1e7 runs (--runs times the grids' points)");
    return -1;
}

/* Every varied key as the scene loader takes it, before any run: the scene with the case's
 * overrides and one key set to its distribution's centre (uniform and grid: (A + B) / 2;
 * normal: MEAN), a key at a time, so that an unknown key, a key of another type or a centre
 * the scene refuses is said at once with the loader's words and exit 2, not found in every
 * run's row. A value the scene refuses for part of the range only (a negative mass drawn
 * by normal) stays a failed run of its own. -1 or the exit code. */
static int check_vary_keys(const sweep *x)
{
    char err[2048], sets[2][EVAL_SET_LEN];
    for (int k = 0; k < x->nv; k++) {
        const vary *v = &x->vs[k];
        double centre = v->kind == V_NORMAL ? v->a : v->a + 0.5 * (v->b - v->a);
        int n = run_sets(v, 1, &centre, &x->sc, sets);
        const char *extra[2] = {sets[0], sets[1]};
        eval_scene sc;
        if (eval_case_scene_load(x->config, x->suite ? x->suite : x->config, &x->c, extra, n,
                                 &sc, err, sizeof err) == 0)
            continue;
        fprintf(stderr, "%s: --vary %s: the scene refuses %s: %s\n", prog, v->text, sets[0], err);
        return 2;
    }
    return -1;
}

/* The CSV's header: run, the keys, the verdict, each joint's metrics; the metric to plot
 * among its columns. Returns -1 or the exit code. */
static int make_header(sweep *x)
{
    char *h = x->header;
    size_t hu = (size_t)snprintf(h, ROW_MAX, "run");
    for (int k = 0; k < x->nv && hu < ROW_MAX; k++) {
        if (x->vs[k].index < 0)
            hu += (size_t)snprintf(h + hu, ROW_MAX - hu, ",%s", x->vs[k].key);
        else
            hu += (size_t)snprintf(h + hu, ROW_MAX - hu, ",%s[%d]", x->vs[k].key,
                                   x->vs[k].index);
    }
    if (hu < ROW_MAX) hu += (size_t)snprintf(h + hu, ROW_MAX - hu, ",failed,required,reason");
    for (int j = 0; j < x->sc.nj && hu < ROW_MAX; j++)
        for (int m = 0; m < LAG_METRIC_COUNT && hu < ROW_MAX; m++)
            hu += (size_t)snprintf(h + hu, ROW_MAX - hu, ",%s.%s", x->sc.joint[j],
                                   lag_metric_table[m].name);
    if (hu >= ROW_MAX) return die("the CSV's header (the varied keys' names) would pass %s bytes",
                                  "8191");
    snprintf(x->default_metric, sizeof x->default_metric, "%s.%s",
             x->req.n ? x->req.term[0].joint : x->sc.joint[0],
             lag_metric_table[x->req.n ? x->req.term[0].metric : LAG_METRIC_IAE].name);
    if (!x->metric) x->metric = x->default_metric;
    if (x->png && header_column(x->header, x->metric) < 0)
        return die("--metric %s: no such column (JOINT.METRIC, e.g. theta.settle)", x->metric);
    return -1;
}

/* What every shard of the sweep shares, for the CSV's identity lines. -1 or the exit code. */
static int make_identity(sweep *x)
{
    char err[2048];
    const char *texts[VARY_MAX];
    for (int k = 0; k < x->nv; k++) texts[k] = x->vs[k].text;
    sweep_identity id = {.seed = x->seed, .scene = x->config, .c = &x->c, .vary = texts,
                         .nvary = x->nv, .runs = x->total, .controller = x->controller,
                         .restart = x->restart, .require = x->require,
                         .shard_k = x->shard_k, .shard_n = x->shard_n};
    if (!(x->identity = sweep_identity_text(&id, err, sizeof err))) return die("%s", err);
    return -1;
}

/* The runs this sweep runs: its shard's (--shard K/N: i mod N = K - 1), of those --only's
 * (ranges counted in the shard's runs, as a held line writes them). -1 or the exit code. */
static int make_want(sweep *x)
{
    if (!(x->shards = calloc((size_t)x->shard_n, 1)) || !(x->want = calloc((size_t)x->total, 1)))
        return die("%s", "out of memory");
    x->shards[x->shard_k - 1] = 1;
    if (x->only && sweep_runs_parse(x->only, x->total, x->want)) {
        fprintf(stderr, "%s: --only %s: expected runs as A-B,C (ascending, from 0 to %ld), as "
                "a CSV's held line writes them\n", prog, x->only, x->total - 1);
        return 2;
    }
    for (long i = 0; i < x->total; i++) {
        x->want[i] = (!x->only || x->want[i]) && i % x->shard_n == x->shard_k - 1;
        x->nwant += x->want[i];
    }
    if (x->nwant == 0)
        return die("--only %s: no run of this sweep (of its shard) in it", x->only);
    return -1;
}

/* ---------------------------------------------------------------- a worker */
#define KEEP_RUNS 200 /* a kept daemon is started again after this many runs (its log) */

typedef struct worker {
    const sweep *x;
    long w;          /* its number */
    eval_worker *kept; /* the daemon and the controller kept for its runs */
    FILE *rows;
    long pairs;      /* kept pairs that started (answered their first state) */
    int refused;     /* new pairs in a row whose controller could not answer */
    long ran;        /* --restart: runs started */
    bool said_output;  /* the output of a failed run said (once a worker) */
} worker;

#define PAIR_REFUSALS 3 /* new pairs in a row whose controller cannot answer: the sweep stops */
#define RUN_FATAL (-2)  /* the controller cannot run the sweep: it stops (exit 2) */
#define WORKER_FATAL 5  /* a worker's exit status for it; its words in tmpdir/W.fatal */

/* A run that did not run: failed, every metric none. */
static void fail_unrun(eval_result *res, int nj, const char *why)
{
    memset(res, 0, sizeof *res);
    res->nj = nj;
    for (int j = 0; j < nj; j++)
        for (int m = 0; m < LAG_METRIC_COUNT; m++) res->m[j].v[m] = NAN;
    eval_fail(res, "%s", why);
}

/* Worker w's plant of its group's host: prefix SWEEP<pid>_W<w> (w in three digits, so
 * that the files' names sort as the workers do and the host gives the plants their pairs
 * in that order); its file is the prefix in small letters (the host's rule). */
static void plant_prefix(const sweep *x, long w, char *out, size_t len)
{
    snprintf(out, len, "SWEEP%d_W%03ld", x->ppid, w);
}

static eval_env worker_env(const worker *wk, long run)
{
    const sweep *x = wk->x;
    eval_env env = {.lagsimd = x->lagsimd, .config = x->config, .controller = x->controller,
                    .workdir = x->tmpdir, .wall_timeout = x->timeout, .verbose = x->verbose,
                    .allow_lan = x->allow_lan};
    /* the worker's ports, for all its runs; a prefix of each run's own */
    snprintf(env.url, sizeof env.url, "%s", x->url[wk->w]);
    if (run < 0 && x->ppw > 1) { /* its plant of the group's host (start_hosts) */
        plant_prefix(x, wk->w, env.prefix, sizeof env.prefix);
        env.attach_log = x->attach[wk->w];
    } else if (run < 0) {
        snprintf(env.prefix, sizeof env.prefix, "SWEEP%d_W%ld", (int)getpid(), wk->w);
    } else {
        snprintf(env.prefix, sizeof env.prefix, "SWEEP%d_%ld", (int)getpid(), run);
    }
    return env;
}

/* A new kept pair for the worker: 1 when it runs. A controller that cannot answer its
 * first state (it ended, or listens elsewhere) in the worker's first pair, or in
 * PAIR_REFUSALS new pairs in a row, cannot run the sweep: RUN_FATAL, why in err. In a
 * later pair (it ran before) the run fails with that reason (0), and the next run tries
 * another pair. -1: the pair could not start for another reason. */
static int start_pair(worker *wk, eval_result *res, char *err, size_t errlen)
{
    const sweep *x = wk->x;
    bool controller;
    eval_env env = worker_env(wk, -1);
    if ((wk->kept = eval_worker_start(&env, &x->c, &x->sc, &controller, err, errlen))) {
        wk->pairs++, wk->refused = 0;
        return 1;
    }
    if (!controller) return -1;
    if (wk->pairs == 0 || ++wk->refused >= PAIR_REFUSALS) return RUN_FATAL;
    char why[sizeof res->reason];
    snprintf(why, sizeof why, "a new lagsimd and controller for this run: %.200s", err);
    fail_unrun(res, x->sc.nj, why);
    eval_say("%s: worker %ld: %s\n", prog, wk->w, why);
    return 0;
}

/* A run on the kept processes: started when there are none, started again after
 * KEEP_RUNS runs, after a run that stalled or whose controller ended, and once for a run
 * the kept ones lost. */
static int run_kept(worker *wk, const char *const *sets, int nsets, const eval_scene *rsc,
                    eval_result *res, char *err, size_t errlen)
{
    const sweep *x = wk->x;
    for (int attempt = 0; attempt < 2; attempt++) {
        if (wk->kept && eval_worker_runs(wk->kept) >= KEEP_RUNS) {
            eval_worker_stop(wk->kept);
            wk->kept = NULL;
        }
        int started = wk->kept ? 1 : start_pair(wk, res, err, errlen);
        if (started != 1) return started;
        int rc = eval_worker_run(wk->kept, &x->c, sets, nsets, rsc->q0, rsc->qd0, res, err,
                                 errlen);
        /* a stalled run, a controller that did not answer the run before's last state or
         * that ended: the run fails, and the next one gets a new worker pair (a stalled run
         * is run again on it first) */
        bool unanswered = rc == 0 && strstr(res->reason, "did not answer the paused state");
        bool lost = rc == 0 && eval_worker_lost(wk->kept);
        if (rc == 0 && !strstr(res->reason, "before the duration") && !unanswered && !lost)
            return 0;
        if (unanswered || lost) /* the run fails, and it is said: never a silent restart */
            eval_say("%s: worker %ld: a run failed: %s; a new lagsimd and controller for the "
                     "next run\n", prog, wk->w, res->reason);
        eval_worker_stop(wk->kept);
        wk->kept = NULL;
        if (rc == 0) return 0;
    }
    return -1;
}

static void write_row(const worker *wk, long i, const double *val, const eval_result *res)
{
    const sweep *x = wk->x;
    FILE *f = wk->rows;
    char why[2048] = "";
    bool met = !x->require || eval_require_holds(&x->req, &x->sc, res, why, sizeof why);
    /* one line per run: the run number first (the parent sorts by it) */
    fprintf(f, "%ld", i);
    char num[LAG_NUM_LEN];
    for (int k = 0; k < x->nv; k++) fprintf(f, ",%s", lag_num(val[k], num));
    const char *reason = res->failed ? res->reason : met ? "" : why;
    fprintf(f, ",%d,%d,", res->failed, met);
    sweep_write_reason(f, reason);
    for (int j = 0; j < x->sc.nj; j++)
        for (int m = 0; m < LAG_METRIC_COUNT; m++) {
            if (isnan(res->m[j].v[m])) fprintf(f, ",nan");
            else fprintf(f, ",%s", lag_num(res->m[j].v[m], num));
        }
    fputc('\n', f);
    fflush(f);
}

/* The controller cannot run the sweep (run i found it): its words for the parent, which
 * says them once and stops every worker. WORKER_FATAL. */
static int worker_fatal(const worker *wk, long i, const char *err)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%ld.fatal", wk->x->tmpdir, wk->w);
    FILE *f = fopen(path, "w");
    if (f) fprintf(f, "run %ld, worker %ld: %s", i, wk->w, err), fclose(f);
    else eval_say("%s: run %ld: %s\n", prog, i, err);
    return WORKER_FATAL;
}

/* Run i: its values, then a failed row for values the scene refuses (a negative mass),
 * else the run on the kept processes or on processes of its own. */
static int run_one(worker *wk, long i)
{
    const sweep *x = wk->x;
    char err[2048];
    double val[VARY_MAX];
    for (int k = 0; k < x->nv; k++)
        val[k] = vary_value(x->vs, x->nv, k, i, x->per_point, x->seed);
    char extra[VARY_MAX][EVAL_SET_LEN];
    int nx = run_sets(x->vs, x->nv, val, &x->sc, extra);
    const char *xp[VARY_MAX + EVAL_SETS_MAX];
    for (int k = 0; k < x->c.nsets; k++) xp[k] = x->c.set[k];
    for (int k = 0; k < nx; k++) xp[x->c.nsets + k] = extra[k];
    eval_result res;
    memset(&res, 0, sizeof res);
    eval_scene rsc;
    int rc = 0;
    if (eval_scene_load(x->config, xp, x->c.nsets + nx, &rsc, err, sizeof err)) {
        char why[sizeof res.reason];
        snprintf(why, sizeof why, "refused: %.240s", err);
        fail_unrun(&res, x->sc.nj, why);
    } else if (!x->restart) {
        rc = run_kept(wk, xp + x->c.nsets, nx, &rsc, &res, err, sizeof err);
    } else {
        eval_env env = worker_env(wk, i);
        if (!wk->ran++) /* its first run says a plant that waits for its first answer */
            snprintf(env.who, sizeof env.who, "%s: run %ld", prog, i);
        rc = eval_run(&env, &x->c, xp + x->c.nsets, nx, &rsc, &res, NULL, err, sizeof err);
    }
    if (rc == RUN_FATAL) return worker_fatal(wk, i, err);
    if (rc) {
        eval_say("%s: run %ld: %s\n", prog, i, err);
        return 4;
    }
    if (res.output[0] && !wk->said_output) { /* a worker's first failed run: what its
                                               * controller and lagsimd said last */
        wk->said_output = true;
        fprintf(stderr, "%s: run %ld failed: %s\n%s(the output of later runs that fail: "
                "-v passes every run's through)\n", prog, i, res.reason, res.output);
    }
    write_row(wk, i, val, &res);
    return 0;
}

/* Worker w runs the sweep's runs it wants (its shard's, --only's) number w, w + jobs, ...
 * of them; its rows go to a file of its own. Never returns. */
static void worker_main(const sweep *x, long w)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%ld.rows", x->tmpdir, w);
    worker wk = {.x = x, .w = w, .rows = fopen(path, "w")};
    if (!wk.rows) _exit(3);
    int rc = 0;
    for (long i = 0, k = 0; i < x->total && !rc; i++)
        if (x->want[i] && k++ % x->jobs == w) rc = run_one(&wk, i);
    eval_worker_stop(wk.kept);
    fclose(wk.rows);
    _exit(rc);
}

/* ---------------------------------------------------------------- the results */
/* A worker that found the controller cannot run the sweep: its words said once, the
 * other workers stopped. */
static void say_fatal(const sweep *x, long w)
{
    char path[256], text[4096] = "";
    snprintf(path, sizeof path, "%s/%ld.fatal", x->tmpdir, w);
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = '\0';
    if (f) fclose(f);
    unlink(path);
    eval_say("%s: %s\n%s: the sweep stops: a controller that cannot answer the first state "
             "of its lagsimd fails every run\n", prog, text, prog);
}

/* The workers' ends, as they come: one that stops the sweep stops the others. 0, or 2
 * when a worker failed. */
static int wait_workers(sweep *x, const pid_t *pids)
{
    bool alive[256];
    long left = x->jobs;
    int status = 0;
    for (long w = 0; w < x->jobs; w++) alive[w] = true;
    while (left) {
        sweep_live_poll(&x->live);
        if (eval_proc_pending()) { /* a signal: every worker stopped, what ended kept */
            eval_proc_stop_children();
            return 2;
        }
        for (long w = 0; w < x->jobs; w++) {
            int st = 0;
            if (!alive[w] || !eval_wait_until(pids[w], 0, &st)) continue;
            alive[w] = false, left--;
            if (WIFEXITED(st) && WEXITSTATUS(st) == 0) continue;
            bool fatal = WIFEXITED(st) && WEXITSTATUS(st) == WORKER_FATAL;
            if (fatal && !x->stopping) say_fatal(x, w);
            if (fatal) x->stopping = true;
            status = 2;
        }
        for (long w = 0; x->stopping && w < x->jobs; w++) /* the others end now */
            if (alive[w]) eval_stop_group(pids[w], &(int){0}), alive[w] = false, left--;
        if (left) eval_sleep(0.02);
    }
    return status;
}
/* The workers, forked (each dies with this process: eval_proc_fork), and their ends. */
static int run_workers(sweep *x)
{
    pid_t pids[256];
    for (long w = 0; w < x->jobs; w++) {
        pids[w] = eval_proc_fork();
        if (pids[w] < 0) {
            fprintf(stderr, "%s: fork: %s\n", prog, strerror(errno));
            for (long k = 0; k < w; k++) eval_stop_group(pids[k], &(int){0});
            return 2;
        }
        if (pids[w] == 0) worker_main(x, w);
    }
    return wait_workers(x, pids);
}

/* A word of the command, quoted for sh when it needs it. */
static void sh_word(FILE *f, const char *w)
{
    if (w[0] && strspn(w, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                          "_-./:=,+@%") == strlen(w)) {
        fputs(w, f);
        return;
    }
    fputc('\'', f);
    for (const char *p = w; *p; p++) {
        if (*p == '\'') fputs("'\\''", f);
        else fputc(*p, f);
    }
    fputc('\'', f);
}

static void sh_opt(FILE *f, const char *opt, const char *value)
{
    fprintf(f, " %s ", opt);
    sh_word(f, value);
}

/* The sweep's command again, for the runs `only` alone, to CSV rest: every option that
 * makes the runs what they are (the identity's), as given. */
static void finish_command(FILE *f, const sweep *x, const char *only, const char *rest)
{
    char num[32];
    fputs("  ", f);
    sh_word(f, x->self);
    sh_opt(f, "--config", x->config);
    sh_opt(f, "--controller", x->controller);
    if (x->suite) sh_opt(f, "--suite", x->suite);
    if (x->case_name) sh_opt(f, "--case", x->case_name);
    else sh_opt(f, "--duration", x->duration_text);
    for (int k = 0; k < x->nv; k++) sh_opt(f, "--vary", x->vs[k].text);
    snprintf(num, sizeof num, "%ld", x->runs), sh_opt(f, "--runs", num);
    snprintf(num, sizeof num, "%llu", (unsigned long long)x->seed), sh_opt(f, "--seed", num);
    snprintf(num, sizeof num, "%ld", x->jobs), sh_opt(f, "-j", num);
    if (x->shard_n > 1) fprintf(f, " --shard %ld/%ld", x->shard_k, x->shard_n);
    if (x->restart) fputs(" --restart", f); /* said, or forced by a key: the same either way */
    if (x->require) sh_opt(f, "--require", x->require);
    if (x->url_opt) sh_opt(f, "--url", x->url_opt);
    if (x->allow_lan) fputs(" --allow-lan", f);
    if (x->lagsimd_given) sh_opt(f, "--lagsimd", x->lagsimd);
    if (x->timeout_text) sh_opt(f, "--timeout", x->timeout_text);
    sh_opt(f, "--only", only);
    sh_opt(f, "--csv", rest);
    fputc('\n', f);
}

/* The CSV holds some of the runs (why: a signal, a worker that failed): which, and how to
 * run the others and merge them (--only), on stderr. */
static void say_held(const sweep *x, const char *why)
{
    const sweep_live *l = &x->live;
    char *held = sweep_live_held(l), *miss = sweep_live_missing(l);
    char of[64] = "";
    if (x->shard_n > 1) snprintf(of, sizeof of, " of shard %ld/%ld", x->shard_k, x->shard_n);
    if (!x->csv || !held || !miss) {
        eval_say("%s: %s: %ld of the %ld runs%s had ended; without --csv they are kept "
                 "nowhere%s\n", prog, why, l->done, x->nwant, of,
                 l->done > 0 ? " (their summary: above)" : "");
        free(held), free(miss);
        return;
    }
    char rest[1100], whole[1100];
    const char *dot = strrchr(x->csv, '.');
    int base = dot && !strchr(dot, '/') ? (int)(dot - x->csv) : (int)strlen(x->csv);
    snprintf(rest, sizeof rest, "%.*s-rest.csv", base, x->csv);
    snprintf(whole, sizeof whole, "%.*s-whole.csv", base, x->csv);
    bool all = l->done >= x->nwant; /* every run had ended: nothing to run, one file */
    if (all)
        eval_say("%s: %s: %s holds all %ld runs%s, in run order, with a held line; nothing is "
                 "missing. To make it the whole sweep's CSV:\n", prog, why, x->csv, x->nwant, of);
    else {
        eval_say("%s: %s: %s holds %ld of the %ld runs%s (held: %.200s%s), in run order; the "
                 "runs missing: %.200s%s. To finish the sweep, run them and merge:\n", prog,
                 why, x->csv, l->done, x->nwant, of, held, strlen(held) > 200 ? "..." : "",
                 miss, strlen(miss) > 200 ? "..." : "");
        finish_command(stderr, x, miss, rest);
    }
    fputs("  ", stderr);
    sh_word(stderr, x->self);
    /* a shard's or --only's runs made whole are still a part: --partial joins them */
    fputs(x->shard_n > 1 || x->only ? " merge --partial " : " merge ", stderr);
    sh_word(stderr, x->csv);
    if (!all) {
        fputc(' ', stderr);
        sh_word(stderr, rest);
    }
    fprintf(stderr, " -o ");
    sh_word(stderr, whole);
    fprintf(stderr, "\n");
    free(held), free(miss);
}

/* A signal stopped the sweep (its workers too, and the CSV holds the rows of the runs
 * that ended): their summary, which runs the CSV holds and how to run the others; a PNG
 * it made and never drew removed; then it ends by the signal. */
static void __attribute__((noreturn)) stop_by(sweep *x, int sig)
{
    if (x->live.r.n) summary(x->header, &x->live.r);
    fflush(stdout);
    char why[64];
    snprintf(why, sizeof why, "stopped by %s", sig == SIGINT ? "SIGINT" : sig == SIGTERM ?
             "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "a signal");
    say_held(x, why);
    if (x->png_new) unlink(x->png);
    eval_proc_end(sig);
}

static int count_passed(const sweep *x, const rows *r)
{
    int passed = 0;
    for (int i = 0; i < r->n; i++) {
        char lb[ROW_MAX];
        snprintf(lb, sizeof lb, "%s", r->line[i]);
        char *f[512];
        int n = split(lb, f, 512);
        passed += n > x->nv + 2 && !strcmp(f[x->nv + 1], "0") && !strcmp(f[x->nv + 2], "1");
    }
    return passed;
}

/* A URL of the runs' group and options on `port`. -1 when it cannot be one. */
static int url_on(const sweep *x, int port, char *url, size_t len)
{
    int n = lag_url_format(&x->bus.u, port, url, len);
    return n < 0 || (size_t)n >= len ? -1 : 0;
}

/* --plants-per-worker: for each group of K workers, K + 1 consecutive pairs: the host's
 * directory's, then each worker's plant's (the host gives its plants the pairs after its
 * directory's, in the order of their files' names). */
static int take_blocks(sweep *x)
{
    char err[512];
    x->ngroups = (x->jobs + x->ppw - 1) / x->ppw;
    for (long g = 0; g < x->ngroups; g++) {
        long first = g * x->ppw, n = x->jobs - first < x->ppw ? x->jobs - first : x->ppw;
        lag_port_lease l[65];
        if (lag_port_take_block((int)n + 1, l, err, sizeof err) != 0) {
            fprintf(stderr, "%s: the host of workers %ld to %ld: %s\n", prog, first + 1,
                    first + n, err);
            return -1;
        }
        x->dir_lease[g] = l[0];
        for (long k = 0; k < n; k++) x->lease[first + k] = l[k + 1];
        if (url_on(x, l[0].port, x->dir_url[g], sizeof x->dir_url[g]))
            return die("%s", "the runs' URL is too long"), -1;
        for (long k = 0; k < n; k++)
            if (url_on(x, l[k + 1].port, x->url[first + k], sizeof x->url[first + k]))
                return die("%s", "the runs' URL is too long"), -1;
    }
    return 0;
}

/* A pair of ports for each worker, held until the sweep ends (its workers, forked, share
 * the locks). Returns -1 after saying why when the host has too few free. */
static int take_ports(sweep *x)
{
    if (x->ppw > 1) return take_blocks(x);
    char err[512];
    for (long w = 0; w < x->jobs; w++)
        if (eval_bus_take(&x->bus, &x->lease[w], x->url[w], sizeof x->url[w], err, sizeof err)) {
            fprintf(stderr, "%s: worker %ld: %s\n", prog, w + 1, err);
            return -1;
        }
    return 0;
}

static void release_ports(sweep *x)
{
    for (long w = 0; w < x->jobs; w++) lag_port_release(&x->lease[w]);
    for (long g = 0; g < x->ngroups; g++) lag_port_release(&x->dir_lease[g]);
}

/* ---------------------------------------------------------------- shared hosts */
/* Group g's host: a directory of its workers' plants (copies of the scene file, named by
 * their prefixes), lagsimd --plants on it with the keys the tools own (but each plant's
 * URL and prefix: the host's rules give them) and the case's sets, --log per plant. */
static int start_host(sweep *x, long g, const char *text, size_t len)
{
    char dir[200], path[512], pre[64];
    snprintf(dir, sizeof dir, "%s/h%ld", x->tmpdir, g);
    snprintf(path, sizeof path, "%s/lab", dir);
    if (mkdir(dir, 0700) != 0 || mkdir(path, 0700) != 0) return -1;
    long first = g * x->ppw;
    for (long w = first; w < x->jobs && w < first + x->ppw; w++) {
        plant_prefix(x, w, pre, sizeof pre);
        for (char *c = pre; *c; c++) *c = (char)(*c >= 'A' && *c <= 'Z' ? *c - 'A' + 'a' : *c);
        snprintf(path, sizeof path, "%s/lab/%s.yaml", dir, pre);
        FILE *f = fopen(path, "w");
        if (!f || fwrite(text, 1, len, f) != len || fclose(f) != 0) return -1;
        snprintf(x->attach[w], sizeof x->attach[w], "%s/%s/run.lcm", dir, pre);
    }
    eval_env env = {.lagsimd = x->lagsimd, .config = x->config, .workdir = x->tmpdir,
                    .verbose = x->verbose, .allow_lan = x->allow_lan};
    snprintf(env.url, sizeof env.url, "%s", x->dir_url[g]); /* LCM_DEFAULT_URL: the directory */
    char owned[EVAL_OWN_COUNT][EVAL_SET_LEN], lab[512], log[512];
    eval_owned_sets(&env, true, owned);
    snprintf(lab, sizeof lab, "%s/lab", dir);
    snprintf(log, sizeof log, "%s/run.lcm", dir);
    char *argv[2 * (EVAL_SETS_MAX + EVAL_OWN_COUNT) + 16];
    int na = 0;
    argv[na++] = x->lagsimd;
    argv[na++] = "--plants";
    argv[na++] = lab;
    for (int i = 0; i < EVAL_OWN_COUNT; i++)
        if (i != EVAL_OWN_URL && i != EVAL_OWN_PREFIX) {
            argv[na++] = "--set";
            argv[na++] = owned[i];
        }
    for (int i = 0; i < x->c.nsets; i++) {
        argv[na++] = "--set";
        argv[na++] = (char *)x->c.set[i];
    }
    argv[na++] = "--log";
    argv[na++] = log;
    argv[na++] = "-q";
    argv[na] = NULL;
    x->host[g] = eval_spawn(argv, NULL, &env, NULL);
    return x->host[g] > 0 ? 0 : -1;
}

/* Every group's host (--plants-per-worker). -1 after saying why. */
static int start_hosts(sweep *x)
{
    char *text = NULL, err[1024];
    size_t len = 0;
    if (lag_scene_read(x->config, &text, &len, err, sizeof err) != LAG_OK)
        return die("%s", err), -1;
    int rc = 0;
    for (long g = 0; g < x->ngroups && !rc; g++)
        if ((rc = start_host(x, g, text, len)) != 0)
            fprintf(stderr, "%s: the host of group %ld cannot start in %s\n", prog, g + 1,
                    x->tmpdir);
    free(text);
    return rc;
}

/* The hosts stopped (SIGTERM: every plant's stop event), their files removed (kept with
 * -v, as the kept daemons' logs). */
static void stop_hosts(sweep *x)
{
    for (long g = 0; g < x->ngroups; g++) {
        int st;
        if (x->host[g] > 0) eval_stop_group(x->host[g], &st);
        x->host[g] = 0;
        if (x->verbose) continue;
        char path[512], pre[64];
        for (long w = g * x->ppw; w < x->jobs && w < (g + 1) * x->ppw; w++) {
            plant_prefix(x, w, pre, sizeof pre);
            for (char *c = pre; *c; c++) *c = (char)(*c >= 'A' && *c <= 'Z' ? *c - 'A' + 'a' : *c);
            unlink(x->attach[w]);
            snprintf(path, sizeof path, "%s/h%ld/%s", x->tmpdir, g, pre);
            rmdir(path);
            snprintf(path, sizeof path, "%s/h%ld/lab/%s.yaml", x->tmpdir, g, pre);
            unlink(path);
        }
        snprintf(path, sizeof path, "%s/h%ld/lab", x->tmpdir, g);
        rmdir(path);
        snprintf(path, sizeof path, "%s/h%ld", x->tmpdir, g);
        rmdir(path);
    }
}

/* A scene with a reference for some joints and not for others: the summary's note says
 * which are scored against r = 0 (as lagsim-eval's table says it). */
static void note_unreferenced(const eval_scene *sc)
{
    char names[EVAL_JOINTS_MAX * (EVAL_NAME_LEN + 6)];
    if (!eval_scene_unreferenced(sc, names, sizeof names)) return;
    bool one = !strchr(names, ' ');
    printf("note: %s %s no reference (the scene's reference: names the other joints): %s "
           "metrics measure %s against r = 0\n", names, one ? "has" : "have",
           one ? "its" : "their", one ? "it" : "them");
}

/* What sweep_live needs from the sweep. */
static void live_setup(sweep *x, FILE *fcsv)
{
    bool tty = isatty(STDERR_FILENO);
    x->live = (sweep_live){.tmpdir = x->tmpdir, .jobs = x->jobs, .csv = fcsv,
                           .identity = x->identity, .header = x->header, .runs = x->total,
                           .sn = x->shard_n, .shards = x->shards, .want = x->want,
                           .nwant = x->nwant, .nvary = x->nv, .tty = tty && !x->verbose,
                           .progress = x->progress || (tty && !x->verbose),
                           .require = x->require != NULL};
}

static void say_csv(const sweep *x, const char *why)
{
    eval_say("%s: --csv %s: %s\n", prog, x->csv, why);
}

static int sweep_run(sweep *x)
{
    char err[2048];
    FILE *fcsv = NULL, *fpng = NULL;
    /* what the sweep reads (the scene, the suite, the daemon) and its CSV: no output may
     * be one of them (compared by device and inode) */
    const char *in[4 + EVAL_CMD_FILES_MAX] = {x->config, x->lagsimd, x->suite ? x->suite : x->config};
    /* and what the controller command names (its script): read by every run */
    int nin = 3 + eval_command_files(x->controller, x->cmd_files, EVAL_CMD_FILES_MAX);
    for (int k = 3; k < nin; k++) in[k] = x->cmd_files[k - 3];
    in[nin] = x->csv;
    /* every output opened (and so refused, when it must be) before the first run: a sweep
     * never runs for hours to lose its results at the end */
    struct stat st;
    bool csv_new = x->csv && lstat(x->csv, &st) != 0;
    bool png_new = x->png && lstat(x->png, &st) != 0;
    if (x->csv && !(fcsv = eval_open_out(prog, "--csv", x->csv, x->force, in, nin))) return 2;
    if (x->png && !(fpng = eval_open_out(prog, "--plot", x->png, x->force, in, nin + 1))) {
        if (fcsv) fclose(fcsv);
        if (csv_new) unlink(x->csv); /* a CSV this sweep made, empty */
        return 2;
    }
    if (fpng) fclose(fpng); /* gnuplot writes it at the end */
    if (eval_make_tmpdir("lagsim-sweep", x->tmpdir, sizeof x->tmpdir) != 0) {
        fprintf(stderr, "%s: cannot make a temporary directory: %s\n", prog, strerror(errno));
        return 2;
    }
    if (x->verbose) { /* -v keeps the daemons' logs: said where, once */
        eval_proc_tmpdir_done();
        if (x->ppw > 1)
            fprintf(stderr, "%s: -v: the hosts' plants' logs (h<group>/sweep%d_w<worker>/run.lcm) "
                    "are kept in %s\n", prog, (int)getpid(), x->tmpdir);
        else
            fprintf(stderr, "%s: -v: the daemons' logs (SWEEP%d_W<worker>.lcm for a worker's "
                    "kept pair, SWEEP%d_<run>.lcm for a run's own) are kept in %s\n", prog,
                    (int)getpid(), (int)getpid(), x->tmpdir);
    }
    x->png_new = png_new;
    /* a signal from here on is the sweep's to act on: the rows of the runs that ended go
     * to the CSV before it ends (stop_by) */
    eval_proc_defer(true);
    live_setup(x, fcsv);
    if (sweep_live_start(&x->live, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", prog, err);
        eval_proc_defer(false);
        if (eval_proc_pending()) eval_proc_end(eval_proc_pending());
        return 2;
    }
    int status = x->ppw > 1 && start_hosts(x) ? 2 : run_workers(x);
    stop_hosts(x);
    if (sweep_live_finish(&x->live, err, sizeof err)) status = 2, say_csv(x, err);
    if (fcsv && fclose(fcsv) != 0) status = 2, say_csv(x, strerror(errno));
    eval_proc_defer(false);
    if (eval_proc_pending()) stop_by(x, eval_proc_pending());
    rows *r = &x->live.r;
    if (r->n || !x->stopping) { /* a sweep stopped before any run has nothing to sum */
        summary(x->header, r);
        note_unreferenced(&x->sc);
    }
    if (x->live.done < x->nwant) say_held(x, "not every run ended");
    bool all = count_passed(x, r) == r->n;
    if (x->png && plot(x->png, x->tmpdir, x->header, r, x->nv, x->metric)) status = 2;
    sweep_live_free(&x->live); /* the workers' row files closed, then removed with the rest */
    if (x->verbose) { /* -v keeps the daemons' logs (said where) */
        rmdir(x->tmpdir);
        eval_proc_tmpdir_done();
    } else {
        eval_proc_tmpdir_remove();
    }
    return status ? status : all ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "merge")) return merge(argc - 1, argv + 1, usage);
    eval_proc_init(); /* every process it starts ends when it ends (eval_proc.h) */
    static sweep x = {.timeout = 600, .runs = 1, .jobs = 1, .shard_k = 1, .shard_n = 1,
                      .seed = 1, .ppw = 1};
    x.ppid = (int)getpid();
    eval_default_lagsimd(x.lagsimd, sizeof x.lagsimd);
    x.self = argv[0];
    int rc;
    if ((rc = parse_options(&x, argc, argv)) >= 0 || (rc = check_options(&x, argc, argv)) >= 0 ||
        (rc = load_case(&x)) >= 0 || (rc = load_scene(&x)) >= 0 ||
        (rc = check_vary_keys(&x)) >= 0)
        return rc;
    if ((rc = make_header(&x)) >= 0 || (rc = make_identity(&x)) >= 0 ||
        (rc = make_want(&x)) >= 0)
        return rc;
    for (long w = 0; w < x.jobs; w++) x.lease[w] = (lag_port_lease){.port = 0, .fd = -1};
    rc = take_ports(&x) ? 2 : sweep_run(&x);
    release_ports(&x);
    free(x.identity), free(x.shards), free(x.want);
    return rc;
}
