/*
 * lagsim-sweep's CSV rows, the summary made from them, and `lagsim-sweep merge`, which joins
 * the CSVs of a sweep's shards into the CSV of the whole sweep.
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "eval_case.h"
#include "sweep_merge.h"

static const char *prog = "lagsim-sweep";

static int die(const char *fmt, const char *a)
{
    fprintf(stderr, "%s: ", prog);
    fprintf(stderr, fmt, a);
    fputc('\n', stderr);
    return 2;
}

/* ---------------------------------------------------------------- CSV rows */

int rows_add(rows *r, long run, const char *line)
{
    if (r->n == r->cap) {
        int cap = r->cap ? 2 * r->cap : 256;
        long *ru = realloc(r->run, (size_t)cap * sizeof *ru);
        if (!ru) return -1;
        r->run = ru;
        char **li = realloc(r->line, (size_t)cap * sizeof *li);
        if (!li) return -1;
        r->line = li;
        r->cap = cap;
    }
    r->run[r->n] = run;
    r->line[r->n] = strdup(line);
    return r->line[r->n++] ? 0 : -1;
}

void rows_free(rows *r)
{
    for (int i = 0; i < r->n; i++) free(r->line[i]);
    free(r->run);
    free(r->line);
    memset(r, 0, sizeof *r);
}

static int cmp_long(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

static rows *sort_rows;
static int by_run(const void *a, const void *b)
{
    long x = sort_rows->run[*(const int *)a], y = sort_rows->run[*(const int *)b];
    return (x > y) - (x < y);
}

/* Writes the rows in run order; -1 on two rows of one run. */
int rows_write(rows *r, FILE *f, const char *header, char *err, size_t errlen)
{
    int *ord = malloc((size_t)(r->n ? r->n : 1) * sizeof *ord);
    if (!ord) return -1;
    for (int i = 0; i < r->n; i++) ord[i] = i;
    sort_rows = r;
    qsort(ord, (size_t)r->n, sizeof *ord, by_run);
    for (int i = 1; i < r->n; i++)
        if (r->run[ord[i]] == r->run[ord[i - 1]]) {
            snprintf(err, errlen, "run %ld appears twice", r->run[ord[i]]);
            free(ord);
            return -1;
        }
    fprintf(f, "%s\n", header);
    for (int i = 0; i < r->n; i++) fprintf(f, "%s\n", r->line[ord[i]]);
    free(ord);
    return 0;
}

/* The CSV fields of a line (reason quoted, the others plain): pointers into buf. */
int split(char *buf, char **field, int max)
{
    int n = 0;
    char *p = buf;
    while (n < max) {
        if (*p == '"') {
            field[n++] = ++p;
            while (*p && !(*p == '"' && p[1] != '"')) p += *p == '"' ? 2 : 1;
            if (*p) *p++ = '\0';
        } else {
            field[n++] = p;
            p += strcspn(p, ",");
        }
        if (*p != ',') {
            *p = '\0';
            break;
        }
        *p++ = '\0';
    }
    return n;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double pct(const double *v, int n, double p)
{
    double at = p * (n - 1);
    int lo = (int)floor(at);
    if (lo >= n - 1) return v[n - 1];
    return v[lo] + (v[lo + 1] - v[lo]) * (at - lo);
}

/* Pass rate and percentiles of every metric column, from the CSV's rows. */
void summary(const char *header, rows *r)
{
    char hb[ROW_MAX];
    snprintf(hb, sizeof hb, "%s", header);
    char *hf[512];
    int nh = split(hb, hf, 512);
    int c_failed = -1, c_req = -1, c_first = -1;
    for (int i = 0; i < nh; i++) {
        if (!strcmp(hf[i], "failed")) c_failed = i;
        if (!strcmp(hf[i], "required")) c_req = i;
        if (!strcmp(hf[i], "reason")) c_first = i + 1;
    }
    if (c_failed < 0 || c_req < 0 || c_first < 0) return;
    int pass = 0, failed = 0;
    double *vals = malloc((size_t)(r->n ? r->n : 1) * (size_t)nh * sizeof *vals);
    int *nv = calloc((size_t)nh, sizeof *nv);
    if (!vals || !nv) {
        free(vals), free(nv);
        return;
    }
    for (int i = 0; i < r->n; i++) {
        char lb[ROW_MAX];
        snprintf(lb, sizeof lb, "%s", r->line[i]);
        char *f[512];
        int n = split(lb, f, 512);
        if (n != nh) continue;
        bool fl = !strcmp(f[c_failed], "1"), ok = !fl && !strcmp(f[c_req], "1");
        pass += ok, failed += fl;
        for (int c = c_first; c < nh; c++) {
            double x = strtod(f[c], NULL);
            if (isfinite(x)) vals[(size_t)c * (size_t)r->n + (size_t)nv[c]++] = x;
        }
    }
    printf("%d runs: %d passed (%.1f %%), %d failed, %d missed --require\n", r->n, pass,
           r->n ? 100.0 * pass / r->n : 0.0, failed, r->n - pass - failed);
    printf("%-22s %6s %12s %12s %12s %12s %12s\n", "metric", "n", "min", "p5", "p50", "p95",
           "max");
    for (int c = c_first; c < nh; c++) {
        double *v = vals + (size_t)c * (size_t)r->n;
        if (!nv[c]) {
            printf("%-22s %6d %12s\n", hf[c], 0, "none");
            continue;
        }
        qsort(v, (size_t)nv[c], sizeof *v, cmp_double);
        printf("%-22s %6d %12.6g %12.6g %12.6g %12.6g %12.6g\n", hf[c], nv[c], v[0],
               pct(v, nv[c], 0.05), pct(v, nv[c], 0.5), pct(v, nv[c], 0.95), v[nv[c] - 1]);
    }
    free(vals);
    free(nv);
}

/* ---------------------------------------------------------------- merge */
/* Whether the rows' run numbers are exactly 0..max (runs found twice are rows_write's to
 * refuse); else the missing ones, as numbers and ranges, in buf. */
static bool rows_whole(const rows *r, char *buf, size_t len)
{
    long *run = malloc((size_t)(r->n ? r->n : 1) * sizeof *run);
    if (!run) {
        snprintf(buf, len, "out of memory");
        return false;
    }
    memcpy(run, r->run, (size_t)r->n * sizeof *run);
    qsort(run, (size_t)r->n, sizeof *run, cmp_long);
    size_t u = 0;
    int gaps = 0;
    long next = 0; /* the first run not yet seen */
    buf[0] = '\0';
    for (int i = 0; i <= r->n; i++) {
        long at = i < r->n ? run[i] : next; /* past the end: no gap after the last */
        if (at > next) {
            if (gaps < 12 && u < len)
                u += (size_t)(at - 1 > next
                                  ? snprintf(buf + u, len - u, "%s%ld-%ld", gaps ? ", " : "",
                                             next, at - 1)
                                  : snprintf(buf + u, len - u, "%s%ld", gaps ? ", " : "", next));
            else if (gaps == 12 && u < len)
                u += (size_t)snprintf(buf + u, len - u, ", ...");
            gaps++;
        }
        if (at + 1 > next) next = at + 1;
    }
    bool negative = r->n && run[0] < 0;
    if (negative) snprintf(buf, len, "(a negative run number, %ld)", run[0]);
    free(run);
    return gaps == 0 && !negative;
}

/* Shard number k's rows into r; its header must be the first's (kept in header). 0, or -1
 * after saying why. */
static int read_shard(const char *path, int k, char *header, rows *r)
{
    char line[ROW_MAX];
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "%s: %s: %s\n", prog, path, strerror(errno));
        return -1;
    }
    int ln = 0, bad = 0;
    while (!bad && fgets(line, sizeof line, f)) {
        ln++;
        size_t len = strlen(line);
        if (len && line[len - 1] == '\n') line[--len] = '\0';
        if (ln == 1) {
            if (strncmp(line, "run,", 4)) bad = 1;
            else if (k && strcmp(header, line)) bad = 2;
            else snprintf(header, ROW_MAX, "%s", line);
        } else {
            char *end;
            long run = strtol(line, &end, 10);
            if (end == line || *end != ',' || rows_add(r, run, line)) bad = 3;
        }
    }
    fclose(f);
    if (bad)
        fprintf(stderr, "%s: %s:%d: %s\n", prog, path, ln,
                bad == 1 ? "not a lagsim-sweep CSV (its header starts with 'run,')"
                : bad == 2 ? "another sweep's header than the first file's"
                           : "expected a row starting with its run number");
    return bad ? -1 : 0;
}

int merge(int argc, char **argv, void (*usage)(FILE *))
{
    const char *out = NULL;
    bool force = false, partial = false;
    const char *in[256];
    int nin = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) {
            if (++i == argc) return die("%s needs a value", argv[i - 1]);
            out = argv[i];
        } else if (!strcmp(argv[i], "-f") || !strcmp(argv[i], "--force")) {
            force = true;
        } else if (!strcmp(argv[i], "--partial")) {
            partial = true;
        } else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            usage(stdout);
            return 0;
        } else if (argv[i][0] == '-') {
            return die("merge: unknown option '%s' (try --help)", argv[i]);
        } else if (nin < 256) {
            in[nin++] = argv[i];
        }
    }
    if (!nin) return die("%s", "merge: expected the shards' CSV files (try --help)");
    if (!out) return die("%s", "merge: -o OUT.csv is required");
    rows r = {0};
    char header[ROW_MAX] = "";
    for (int k = 0; k < nin; k++)
        if (read_shard(in[k], k, header, &r)) {
            rows_free(&r);
            return 2;
        }
    /* a run number is all a row says of its sweep: shards that leave a run out (one
     * forgotten, one of another split) make no whole; the runs a sweep has are not in its
     * CSV, so a missing last shard's runs past the others' cannot be told */
    char missing[512];
    if (!partial && !rows_whole(&r, missing, sizeof missing)) {
        fprintf(stderr, "%s: merge: the shards do not make a whole sweep: missing runs %s "
                        "(a whole sweep has every run from 0 to its last); give every shard, "
                        "or --partial to merge only these\n", prog, missing);
        rows_free(&r);
        return 2;
    }
    FILE *fo = eval_open_out(prog, "-o", out, force, in, nin);
    if (!fo) {
        rows_free(&r);
        return 2;
    }
    char err[256];
    int rc = rows_write(&r, fo, header, err, sizeof err);
    if (fclose(fo) != 0 || rc) {
        fprintf(stderr, "%s: merge: %s\n", prog, rc ? err : strerror(errno));
        unlink(out);
        rows_free(&r);
        return 2;
    }
    summary(header, &r);
    rows_free(&r);
    return 0;
}
