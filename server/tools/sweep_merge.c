/*
 * lagsim-sweep's CSV (the format: sweep_merge.h): its rows and their summary, the identity
 * lines, the check of a row against its header, and `lagsim-sweep merge`.
 *
 * Merge refuses (exit 2, naming the first difference) whatever would make its output other
 * than the CSV one machine writes for the sweep: a shard of another sweep (any identity
 * line other than the first file's), a line that is no row as lagsim-sweep writes one
 * (checked field by field against the header, lines of any length), a run outside the
 * sweep or outside its shard, a run found twice, and, unless --partial, a shard or a run
 * missing (the identity says how many runs the sweep has and in how many shards).
 */
#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <glib.h>

#include "eval_case.h"
#include "sweep_merge.h"
#include "lagsim_num.h"

#ifndef LAGSIM_VERSION
#error "LAGSIM_VERSION (the project's version) must be defined"
#endif

static const char *prog = "lagsim-sweep";
static FILE *messages; /* where merge says why it refuses (NULL: stderr) */
#define MSG (messages ? messages : stderr)

void sweep_merge_messages(FILE *f)
{
    messages = f;
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

static rows *sort_rows;
static int by_run(const void *a, const void *b)
{
    long x = sort_rows->run[*(const int *)a], y = sort_rows->run[*(const int *)b];
    return (x > y) - (x < y);
}

int rows_write(rows *r, FILE *f, const char *identity, const char *header, char *err,
               size_t errlen)
{
    int *ord = malloc((size_t)(r->n ? r->n : 1) * sizeof *ord);
    if (!ord) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (int i = 0; i < r->n; i++) ord[i] = i;
    sort_rows = r;
    qsort(ord, (size_t)r->n, sizeof *ord, by_run);
    for (int i = 1; i < r->n; i++)
        if (r->run[ord[i]] == r->run[ord[i - 1]]) {
            snprintf(err, errlen, "run %ld appears twice", r->run[ord[i]]);
            free(ord);
            return -1;
        }
    fprintf(f, "%s%s\n", identity, header);
    for (int i = 0; i < r->n; i++) fprintf(f, "%s\n", r->line[ord[i]]);
    free(ord);
    return 0;
}

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

/* Each metric's values over the rows (vals[c * r->n ...], nv[c] of them); the runs that
 * passed and failed. */
static void summary_collect(const rows *r, int nh, int c_failed, int c_req, int c_first,
                            double *vals, int *nv, int *pass, int *failed)
{
    char **f = malloc((size_t)(nh + 1) * sizeof *f);
    for (int i = 0; f && i < r->n; i++) {
        char *lb = strdup(r->line[i]);
        if (!lb) break;
        if (split(lb, f, nh + 1) == nh) {
            bool fl = !strcmp(f[c_failed], "1"), ok = !fl && !strcmp(f[c_req], "1");
            *pass += ok, *failed += fl;
            for (int c = c_first; c < nh; c++) {
                double x = strtod(f[c], NULL);
                if (isfinite(x)) vals[(size_t)c * (size_t)r->n + (size_t)nv[c]++] = x;
            }
        }
        free(lb);
    }
    free(f);
}

/* A failure's reason and how many runs failed with it. */
typedef struct reason_count {
    const char *text;
    long n;
} reason_count;

static int cmp_text(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int cmp_count(const void *a, const void *b)
{
    const reason_count *x = a, *y = b;
    if (x->n != y->n) return x->n < y->n ? 1 : -1;
    return strcmp(x->text, y->text);
}

#define REASONS_SHOWN 5 /* the commonest reasons printed; the others counted */

/* Why the runs failed: each distinct reason of the failed rows with its count, the
 * commonest first (REASONS_SHOWN of them, then how many more), so that a sweep whose runs
 * failed says why without its CSV. Reasons are compared as written ("" for a quote). */
static void summary_reasons(const rows *r, int nh, int c_failed, int c_reason)
{
    char **why = malloc((size_t)(r->n ? r->n : 1) * sizeof *why);
    char **f = malloc((size_t)(nh + 1) * sizeof *f);
    long nw = 0;
    for (int i = 0; why && f && i < r->n; i++) {
        char *lb = strdup(r->line[i]);
        if (lb && split(lb, f, nh + 1) == nh && !strcmp(f[c_failed], "1") &&
            (why[nw] = strdup(f[c_reason])))
            nw++;
        free(lb);
    }
    free(f);
    reason_count *d = why && nw ? malloc((size_t)nw * sizeof *d) : NULL;
    long nd = 0;
    if (d) {
        qsort(why, (size_t)nw, sizeof *why, cmp_text);
        for (long i = 0; i < nw; i++) {
            if (nd && !strcmp(d[nd - 1].text, why[i])) d[nd - 1].n++;
            else d[nd++] = (reason_count){why[i], 1};
        }
        qsort(d, (size_t)nd, sizeof *d, cmp_count);
        long rest = 0;
        for (long i = 0; i < nd; i++) {
            if (i < REASONS_SHOWN) printf("  %ld failed: %s\n", d[i].n, d[i].text);
            else rest += d[i].n;
        }
        if (nd > REASONS_SHOWN)
            printf("  ... and %ld other reason%s (%ld run%s)\n", nd - REASONS_SHOWN,
                   nd - REASONS_SHOWN > 1 ? "s" : "", rest, rest > 1 ? "s" : "");
    }
    for (long i = 0; why && i < nw; i++) free(why[i]);
    free(why);
    free(d);
}

void summary(const char *header, rows *r)
{
    char *hb = strdup(header);
    char *hf[512];
    int nh = hb ? split(hb, hf, 512) : 0;
    int c_failed = -1, c_req = -1, c_first = -1;
    for (int i = 0; i < nh; i++) {
        if (!strcmp(hf[i], "failed")) c_failed = i;
        if (!strcmp(hf[i], "required")) c_req = i;
        if (!strcmp(hf[i], "reason")) c_first = i + 1;
    }
    double *vals = NULL;
    int *nv = NULL;
    if (c_failed < 0 || c_req < 0 || c_first < 0 ||
        !(vals = malloc((size_t)(r->n ? r->n : 1) * (size_t)nh * sizeof *vals)) ||
        !(nv = calloc((size_t)nh, sizeof *nv))) {
        free(vals), free(hb);
        return;
    }
    int pass = 0, failed = 0;
    summary_collect(r, nh, c_failed, c_req, c_first, vals, nv, &pass, &failed);
    printf("%d runs: %d passed (%.1f %%), %d failed, %d missed --require\n", r->n, pass,
           r->n ? 100.0 * pass / r->n : 0.0, failed, r->n - pass - failed);
    if (failed) summary_reasons(r, nh, c_failed, c_first - 1);
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
    free(hb);
}

/* ---------------------------------------------------------------- what a row holds */
static bool is_control(unsigned char c)
{
    return c < 0x20 || c == 0x7f;
}

void sweep_write_reason(FILE *f, const char *reason)
{
    fputc('"', f);
    for (const char *p = reason; *p; p++) {
        if (*p == '"') fputc('"', f);
        fputc(is_control((unsigned char)*p) ? ' ' : *p, f);
    }
    fputc('"', f);
}

/* A number as lag_num (printf's %g) writes one: -?D+(.D+)?(e[+-]DD+)?, or inf, -inf. */
static bool is_number(const char *s, size_t n)
{
    size_t i = n && s[0] == '-', d;
    if (n - i == 3 && !memcmp(s + i, "inf", 3)) return true;
    for (d = i; i < n && isdigit((unsigned char)s[i]); i++) {}
    if (i == d) return false;
    if (i < n && s[i] == '.') {
        for (d = ++i; i < n && isdigit((unsigned char)s[i]); i++) {}
        if (i == d) return false;
    }
    if (i < n && s[i] == 'e') {
        if (++i == n || (s[i] != '+' && s[i] != '-')) return false;
        for (d = ++i; i < n && isdigit((unsigned char)s[i]); i++) {}
        if (i - d < 2) return false;
    }
    return i == n;
}

/* Fields of a row: where field i starts (its quotes included) and ends. The number of
 * fields, or -1 with why: a quote not closed, text after one, one inside a plain field. */
static int row_fields(const char *line, size_t len, size_t *start, size_t *end, int max,
                      char *why, size_t whylen)
{
    size_t p = 0;
    for (int n = 0;; n++) {
        size_t s = p;
        if (p < len && line[p] == '"') {
            for (p++; p < len && !(line[p] == '"' && (p + 1 == len || line[p + 1] != '"'));)
                p += line[p] == '"' ? 2 : 1;
            if (p >= len) {
                snprintf(why, whylen, "field %d: a quote not closed", n + 1);
                return -1;
            }
            p++;
        } else {
            while (p < len && line[p] != ',' && line[p] != '"') p++;
        }
        if (p < len && line[p] != ',') {
            snprintf(why, whylen, "field %d: a quote %s", n + 1,
                     line[s] == '"' ? "followed by more than a comma" : "inside a plain field");
            return -1;
        }
        if (n < max) start[n] = s, end[n] = p;
        if (p == len) return n + 1;
        p++;
    }
}

/* What is wrong with field col (text s, n bytes) of a row, or NULL; *run from field 0. */
static const char *field_fault(const sweep_columns *c, int col, const char *s, size_t n,
                               long runs, long *run)
{
    if (col == 0) {
        /* as %ld writes a run number: no sign, no leading zero */
        bool digits = n > 0 && (s[0] != '0' || n == 1);
        for (size_t i = 0; i < n; i++) digits = digits && isdigit((unsigned char)s[i]);
        if (!digits) return "expected a run number of the sweep";
        errno = 0;
        unsigned long long v = strtoull(s, NULL, 10); /* stops at the ',' */
        if (errno == ERANGE || v >= (unsigned long long)runs)
            return "expected a run number of the sweep";
        *run = (long)v;
        return NULL;
    }
    int failed = c->nvary + 1, reason = c->nvary + 3;
    if (col == reason)
        return n >= 2 && s[0] == '"' ? NULL : "expected the reason in quotes";
    if (n && s[0] == '"') return "a quoted field where a number belongs";
    if (col == failed || col == failed + 1)
        return n == 1 && (s[0] == '0' || s[0] == '1') ? NULL : "expected 0 or 1";
    if (col > reason && n == 3 && !memcmp(s, "nan", 3)) return NULL;
    if (!is_number(s, n))
        return col > reason ? "expected a number or nan" : "expected a number";
    return NULL;
}

int sweep_row_check(const sweep_columns *c, const char *line, size_t len, long runs,
                    long *run, char *why, size_t whylen)
{
    for (size_t i = 0; i < len; i++)
        if (is_control((unsigned char)line[i])) {
            snprintf(why, whylen, "%s at byte %zu", line[i] ? "a control byte" : "a NUL byte",
                     i + 1);
            return -1;
        }
    size_t *start = malloc(2 * (size_t)c->n * sizeof *start);
    if (!start) {
        snprintf(why, whylen, "out of memory");
        return -1;
    }
    size_t *end = start + c->n;
    int n = row_fields(line, len, start, end, c->n, why, whylen);
    if (n >= 0 && n != c->n)
        snprintf(why, whylen, "%d field%s where the header has %d (a row cut short, or "
                              "joined to another?)", n, n == 1 ? "" : "s", c->n);
    for (int k = 0; n == c->n && k < n; k++) {
        size_t w = end[k] - start[k];
        const char *fault = field_fault(c, k, line + start[k], w, runs, run);
        if (!fault) continue;
        char range[64] = "";
        if (!k) snprintf(range, sizeof range, " (0 to %ld)", runs - 1);
        snprintf(why, whylen, "field %d (%s): %s%s, found '%.*s%s'", k + 1, c->name[k], fault,
                 range, w > 40 ? 40 : (int)w, line + start[k], w > 40 ? "..." : "");
        n = -1;
    }
    free(start);
    return n == c->n ? 0 : -1;
}

void sweep_columns_free(sweep_columns *c)
{
    free(c->name);
    free(c->text);
    memset(c, 0, sizeof *c);
}

int sweep_columns_parse(const char *header, int nvary, sweep_columns *c, char *why,
                        size_t whylen)
{
    memset(c, 0, sizeof *c);
    c->nvary = nvary;
    c->text = strdup(header);
    size_t commas = 0;
    for (const char *p = header; *p; p++) commas += *p == ',';
    c->name = malloc((commas + 1) * sizeof *c->name);
    if (!c->text || !c->name) {
        snprintf(why, whylen, "out of memory");
        sweep_columns_free(c);
        return -1;
    }
    for (char *p = c->text, *s; (s = strsep(&p, ","));) c->name[c->n++] = s;
    static const char *const fixed[] = {"failed", "required", "reason"};
    const char *bad = NULL;
    if (strcmp(c->name[0], "run")) bad = "run";
    for (int k = 0; !bad && k < 3; k++)
        if (nvary + 1 + k >= c->n || strcmp(c->name[nvary + 1 + k], fixed[k])) bad = fixed[k];
    if (bad) {
        snprintf(why, whylen, "expected the header 'run', the %d varied key%s (its vary: "
                              "lines), 'failed,required,reason' and the metrics: no '%s' "
                              "where it belongs", nvary, nvary == 1 ? "" : "s", bad);
        sweep_columns_free(c);
        return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- shards */
/* digits only, no sign, no leading zero, from lo to hi; end: where it stopped */
static int parse_count(const char *s, const char **end, long lo, long hi, long *v)
{
    const char *p = s;
    while (isdigit((unsigned char)*p)) p++;
    *end = p;
    if (p == s || (*s == '0' && p > s + 1) || p - s > 9) return -1;
    *v = strtol(s, NULL, 10);
    return *v >= lo && *v <= hi ? 0 : -1;
}

int sweep_shard_parse(const char *text, long *k, long *n)
{
    const char *p;
    *k = *n = 0;
    if (parse_count(text, &p, 1, SWEEP_RUNS_MAX, k) || *p != '/' ||
        parse_count(p + 1, &p, 1, SWEEP_RUNS_MAX, n) || *p || *k > *n)
        return -1;
    return 0;
}

/* A shard line's value: "K/N" or, from a partial merge, "A-B,C/N" (ascending): *n and a
 * new array holds[K - 1] of the shards it names. 0, or -1. */
static int shard_set_parse(const char *text, long *n, unsigned char **holds)
{
    const char *slash = strrchr(text, '/'), *p;
    *holds = NULL;
    if (!slash || parse_count(slash + 1, &p, 1, SWEEP_RUNS_MAX, n) || *p) return -1;
    unsigned char *h = calloc((size_t)*n, 1);
    if (!h) return -1;
    long last = 0, a = 0, b = 0;
    bool ok = true;
    for (p = text; ok; p++) {
        ok = !parse_count(p, &p, last + 1, *n, &a);
        b = a;
        if (ok && *p == '-') ok = !parse_count(p + 1, &p, a + 1, *n, &b);
        if (!ok) break;
        memset(h + a - 1, 1, (size_t)(b - a + 1));
        last = b;
        if (p == slash) break;
        ok = *p == ',';
    }
    if (!ok) {
        free(h);
        return -1;
    }
    *holds = h;
    return 0;
}

/* The shards of N a set holds as "A-B,C/N" (its ranges). */
static void shard_set_write(FILE *f, const unsigned char *holds, long n)
{
    bool first = true;
    for (long a = 0; a < n; a++) {
        if (!holds[a]) continue;
        long b = a;
        while (b + 1 < n && holds[b + 1]) b++;
        fprintf(f, "%s%ld", first ? "" : ",", a + 1);
        if (b > a) fprintf(f, "-%ld", b + 1);
        first = false;
        a = b;
    }
    fprintf(f, "/%ld", n);
}

/* ---------------------------------------------------------------- sets of runs */
int sweep_runs_parse(const char *text, long runs, unsigned char *set)
{
    memset(set, 0, (size_t)runs);
    if (!strcmp(text, "none")) return 0;
    const char *p = text;
    long last = -1;
    for (;;) {
        long a, b;
        if (parse_count(p, &p, 0, runs - 1, &a) || a <= last) return -1;
        b = a;
        if (*p == '-' && parse_count(p + 1, &p, a + 1, runs - 1, &b)) return -1;
        memset(set + a, 1, (size_t)(b - a + 1));
        last = b;
        if (!*p) return 0;
        if (*p++ != ',') return -1;
    }
}

void sweep_runs_write(FILE *f, const unsigned char *set, long runs, long sn,
                      const unsigned char *shards)
{
    bool any = false;
    long a = -1, b = -1; /* the range being read: runs of the shards, each in the set */
    for (long r = 0; r <= runs; r++) {
        if (r < runs && !shards[r % sn]) continue;
        if (r < runs && set[r]) {
            if (a < 0) a = r;
            b = r;
            continue;
        }
        if (a < 0) continue;
        fprintf(f, "%s%ld", any ? "," : "", a);
        if (b > a) fprintf(f, "-%ld", b);
        any = true, a = -1;
    }
    if (!any) fputs("none", f);
}

char *sweep_runs_text(const unsigned char *set, long runs, long sn, const unsigned char *shards)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) return NULL;
    sweep_runs_write(f, set, runs, sn, shards);
    if (fclose(f) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

/* ---------------------------------------------------------------- the identity */
/* The identity's keys after the version line. The writer writes them in this order; merge
 * compares them in this order (the first that differs is named). */
typedef struct ident_key {
    const char *name;
    bool required, many;
} ident_key;

static const ident_key ident_keys[] = {
    {"seed", true, false},     {"scene-sha256", true, false}, {"case", true, false},
    {"duration", true, false}, {"set", false, true},          {"bound", false, true},
    {"vary", true, true},      {"runs", true, false},         {"controller", true, false},
    {"restart", true, false},  {"require", false, false},     {"shard", false, false},
    {"held", false, false},
};
#define IDENT_KEYS (int)(sizeof ident_keys / sizeof ident_keys[0])
#define IDENT_VERSION "# lagsim-sweep "

/* "# key: " and the value escaped: each value one line */
static void ident_line(FILE *f, const char *key, const char *value)
{
    fprintf(f, "# %s: ", key);
    for (const unsigned char *p = (const unsigned char *)value; *p; p++) {
        if (*p == '\\') fputs("\\\\", f);
        else if (*p == '\n') fputs("\\n", f);
        else if (*p == '\r') fputs("\\r", f);
        else if (*p == '\t') fputs("\\t", f);
        else if (is_control(*p)) fprintf(f, "\\x%02x", *p);
        else fputc(*p, f);
    }
    fputc('\n', f);
}

int sweep_sha256_file(const char *path, char hex[65], char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return -1;
    }
    GChecksum *cs = g_checksum_new(G_CHECKSUM_SHA256);
    unsigned char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) g_checksum_update(cs, buf, (gssize)n);
    int bad = ferror(f);
    fclose(f);
    if (!bad) snprintf(hex, 65, "%s", g_checksum_get_string(cs));
    else snprintf(err, errlen, "%s: a read error", path);
    g_checksum_free(cs);
    return bad ? -1 : 0;
}

char *sweep_identity_text(const sweep_identity *id, char *err, size_t errlen)
{
    char hex[65], num[64], n17[LAG_NUM_LEN];
    if (sweep_sha256_file(id->scene, hex, err, errlen)) return NULL;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    fprintf(f, IDENT_VERSION "%s\n# seed: %" PRIu64 "\n", LAGSIM_VERSION, id->seed);
    ident_line(f, "scene-sha256", hex);
    ident_line(f, "case", id->c->name);
    snprintf(num, sizeof num, "%s", lag_num(id->c->duration, n17));
    ident_line(f, "duration", num);
    for (int k = 0; k < id->c->nsets; k++) ident_line(f, "set", id->c->set[k]);
    for (int k = 0; k < id->c->nbounds; k++) {
        char b[EVAL_NAME_LEN + 40];
        snprintf(b, sizeof b, "%s=%s", id->c->bound_joint[k], lag_num(id->c->bound[k], n17));
        ident_line(f, "bound", b);
    }
    for (int k = 0; k < id->nvary; k++) ident_line(f, "vary", id->vary[k]);
    fprintf(f, "# runs: %ld\n", id->runs);
    ident_line(f, "controller", id->controller);
    ident_line(f, "restart", id->restart ? "yes" : "no");
    if (id->require) ident_line(f, "require", id->require);
    if (id->shard_n > 1) fprintf(f, "# shard: %ld/%ld\n", id->shard_k, id->shard_n);
    if (fclose(f) != 0) {
        free(buf);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    return buf;
}

/* ---------------------------------------------------------------- reading a shard */
typedef struct shard {
    const char *path;
    char *version;
    int nid;                /* identity lines after the version's */
    char **key, **val;      /* each line's key and value (as written: escaped) */
    char *text;             /* the identity lines but the shard line, as read */
    size_t textlen;
    FILE *tf;               /* text's stream while reading */
    long runs, sn;          /* the sweep's runs; the shards it is split in (1: whole) */
    unsigned char *holds;   /* holds[K - 1]: this file's runs are of shard K of sn */
    unsigned char *held;    /* its held line's runs, held[run] (NULL: no line, or unknown:
                             * every run of its shards) */
    bool unknown;           /* held: unknown (a sweep that did not end: its rows say) */
    char *header;
    sweep_columns cols;
} shard;

/* What merge holds: the shards read, the rows, which file holds each run. */
typedef struct merging {
    shard *sh;
    int nsh;
    rows r;
    int *claim;             /* claim[run]: 1 + the file whose identity holds it; 0: none */
    int *from;              /* from[run]: 1 + the file that has its row; 0: none */
    unsigned char *held;    /* held[K - 1]: a file holds runs of shard K */
} merging;

/* Whether shard file s holds run r (its shards, and its held line's runs). */
static bool file_holds(const shard *s, long r)
{
    return s->holds[r % s->sn] && (!s->held || s->held[r]);
}

static int say(const char *path, long ln, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int say(const char *path, long ln, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(MSG, "%s: merge: %s", prog, path);
    if (ln) fprintf(MSG, ":%ld", ln);
    fprintf(MSG, ": ");
    vfprintf(MSG, fmt, ap);
    fputc('\n', MSG);
    va_end(ap);
    return -1;
}

static void shard_free(shard *s)
{
    if (s->tf) fclose(s->tf); /* first: it writes s->text */
    for (int i = 0; i < s->nid; i++) free(s->key[i]), free(s->val[i]);
    free(s->key), free(s->val), free(s->version), free(s->text), free(s->holds);
    free(s->held);
    free(s->header);
    sweep_columns_free(&s->cols);
}

static int ident_find(const char *key)
{
    for (int i = 0; i < IDENT_KEYS; i++)
        if (!strcmp(ident_keys[i].name, key)) return i;
    return -1;
}

/* Line ln of the identity, "# key: value": kept, and written to the text but the shard's. */
static int ident_take(shard *s, long ln, const char *line)
{
    const char *colon = strstr(line, ": ");
    char key[32] = "";
    if (strncmp(line, "# ", 2) || !colon || colon - line - 2 >= (long)sizeof key)
        return say(s->path, ln, "expected an identity line '# KEY: VALUE' or the header");
    memcpy(key, line + 2, (size_t)(colon - line - 2));
    int i = ident_find(key);
    if (i < 0) return say(s->path, ln, "'%s' is no identity key of lagsim-sweep %s", key,
                          LAGSIM_VERSION);
    for (int j = 0; j < s->nid && !ident_keys[i].many; j++)
        if (!strcmp(s->key[j], key)) return say(s->path, ln, "a second '%s' line", key);
    char **k2 = realloc(s->key, (size_t)(s->nid + 1) * sizeof *k2);
    if (k2) s->key = k2;
    char **v2 = realloc(s->val, (size_t)(s->nid + 1) * sizeof *v2);
    if (v2) s->val = v2;
    if (!k2 || !v2 || !(s->key[s->nid] = strdup(key))) return say(s->path, ln, "out of memory");
    if (!(s->val[s->nid++] = strdup(colon + 2))) return say(s->path, ln, "out of memory");
    if (strcmp(key, "shard") && strcmp(key, "held")) fprintf(s->tf, "%s\n", line);
    return 0;
}

static const char *ident_get(const shard *s, const char *key, int nth)
{
    for (int j = 0; j < s->nid; j++)
        if (!strcmp(s->key[j], key) && nth-- == 0) return s->val[j];
    return NULL;
}

/* The header (line ln) ends the identity: every key it needs there, runs and the shard
 * line read, the columns made. */
static int ident_end(shard *s, long ln, const char *line)
{
    for (int i = 0; i < IDENT_KEYS; i++)
        if (ident_keys[i].required && !ident_get(s, ident_keys[i].name, 0))
            return say(s->path, ln, "no '# %s:' line before the header", ident_keys[i].name);
    const char *p, *runs = ident_get(s, "runs", 0), *sh = ident_get(s, "shard", 0);
    if (parse_count(runs, &p, 1, SWEEP_RUNS_MAX, &s->runs) || *p)
        return say(s->path, 0, "runs: expected a count from 1 to %ld, found '%s'",
                   SWEEP_RUNS_MAX, runs);
    s->sn = 1;
    if (!sh && !(s->holds = calloc(1, 1))) return say(s->path, ln, "out of memory");
    if (!sh) s->holds[0] = 1;
    else if (shard_set_parse(sh, &s->sn, &s->holds))
        return say(s->path, 0, "shard: expected K/N (1 <= K <= N) or shards of N as "
                               "A-B,C/N (ascending), found '%s'", sh);
    const char *held = ident_get(s, "held", 0);
    s->unknown = held && !strncmp(held, "unknown", 7);
    if (held && !s->unknown && !(s->held = malloc((size_t)s->runs)))
        return say(s->path, 0, "out of memory");
    if (s->held && sweep_runs_parse(held, s->runs, s->held))
        return say(s->path, 0, "held: expected the runs it holds as A-B,C (ascending, from 0 "
                   "to %ld), none or unknown, found '%.200s'", s->runs - 1, held);
    int nvary = 0;
    while (ident_get(s, "vary", nvary)) nvary++;
    char why[512];
    if (sweep_columns_parse(line, nvary, &s->cols, why, sizeof why))
        return say(s->path, ln, "%s", why);
    if (fclose(s->tf) != 0) free(s->text), s->text = NULL;
    s->tf = NULL;
    if (!s->text || !(s->header = strdup(line))) return say(s->path, ln, "out of memory");
    return 0;
}

/* How a CSV's sweep is split, in words: "the whole sweep (no --shard)" or "shards of N
 * (--shard K/N)". */
static void split_text(long sn, char *buf, size_t len)
{
    if (sn == 1) snprintf(buf, len, "the whole sweep (no --shard)");
    else snprintf(buf, len, "shards of %ld (--shard K/%ld)", sn, sn);
}

/* The first key (in the table's order) whose values differ between shards a and b: 0, or
 * -1 after naming it and both values. */
static int ident_compare(const shard *a, const shard *b)
{
    if (strcmp(a->version, b->version))
        return say(b->path, 0, "not a shard of %s's sweep: lagsim-sweep %s wrote %s, %s wrote "
                               "this one", a->path, a->version, a->path, b->version);
    for (int i = 0; i < IDENT_KEYS; i++) {
        const char *key = ident_keys[i].name;
        if (!strcmp(key, "shard") || !strcmp(key, "held")) continue; /* which runs: */
        for (int nth = 0;; nth++) {
            const char *va = ident_get(a, key, nth), *vb = ident_get(b, key, nth);
            if (!va && !vb) break;
            if (va && vb && !strcmp(va, vb)) continue;
            char qa[1040] = "none", qb[sizeof qa] = "none"; /* each value quoted */
            if (va) snprintf(qa, sizeof qa, "'%.1024s'", va);
            if (vb) snprintf(qb, sizeof qb, "'%.1024s'", vb);
            return say(b->path, 0, "not a shard of %s's sweep: %s%s %s in %s, %s here", a->path,
                       key, ident_keys[i].many ? " (a line of them)" : "", qa, a->path, qb);
        }
    }
    if (strcmp(a->header, b->header))
        return say(b->path, 0, "not a shard of %s's sweep: another header", a->path);
    if (a->sn != b->sn) {
        char sa[64], sb[64];
        split_text(a->sn, sa, sizeof sa);
        split_text(b->sn, sb, sizeof sb);
        return say(b->path, 0, "not a shard of %s's sweep: another split: %s holds %s, this "
                               "file %s", a->path, a->path, sa, sb);
    }
    return 0;
}

/* Shard k (read up to its header) against the first and the shards before it: the runs
 * its identity says it holds are its own (a run two files hold is refused). */
static int shard_admit(merging *m, int k)
{
    shard *s = &m->sh[k];
    if (k && ident_compare(&m->sh[0], s)) return -1;
    if (!k && (!(m->from = calloc((size_t)s->runs, sizeof *m->from)) ||
               !(m->claim = calloc((size_t)s->runs, sizeof *m->claim)) ||
               !(m->held = calloc((size_t)s->sn, 1))))
        return say(s->path, 0, "out of memory");
    for (long K = 0; K < s->sn; K++) m->held[K] |= s->holds[K];
    for (long r = 0; r < s->runs && !s->unknown; r++) { /* unknown: its rows, as they come */
        if (!file_holds(s, r)) continue;
        if (m->claim[r]) {
            const shard *o = &m->sh[m->claim[r] - 1];
            long K = r % s->sn;
            if (!s->held && !o->held) /* each holds the whole shard */
                return say(s->path, 0, "shard %ld/%ld again (%s holds it)", K + 1, s->sn,
                           o->path);
            return say(s->path, 0, "run %ld again (%s holds it too: its held line and "
                                   "this file's share it)", r, o->path);
        }
        m->claim[r] = k + 1;
    }
    return 0;
}

/* Row line ln of shard k: checked against its header, its sweep and its shard, kept. */
static int row_take(merging *m, int k, long ln, const char *line, size_t len)
{
    shard *s = &m->sh[k];
    char why[512];
    long run = -1;
    if (line[0] == '#') return say(s->path, ln, "a comment line among the rows");
    if (sweep_row_check(&s->cols, line, len, s->runs, &run, why, sizeof why))
        return say(s->path, ln, "%s", why);
    if (!s->holds[run % s->sn])
        return say(s->path, ln, "run %ld is shard %ld/%ld's (K = run mod N + 1), not one "
                                "of the shards this file holds", run, run % s->sn + 1, s->sn);
    if (!file_holds(s, run))
        return say(s->path, ln, "run %ld is not one of the runs this file holds (its held "
                                "line)", run);
    if (m->claim[run] && m->claim[run] != k + 1)
        return say(s->path, ln, "run %ld again (%s holds it)", run,
                   m->sh[m->claim[run] - 1].path);
    m->claim[run] = k + 1;
    if (m->from[run])
        return say(s->path, ln, "run %ld again (%s holds it)", run, m->sh[m->from[run] - 1].path);
    m->from[run] = k + 1;
    if (rows_add(&m->r, run, line)) return say(s->path, ln, "out of memory");
    return 0;
}

/* Line ln of shard k, whatever its part. */
static int shard_line(merging *m, int k, long ln, const char *line, size_t len, bool *rows_now)
{
    shard *s = &m->sh[k];
    if (*rows_now) return row_take(m, k, ln, line, len);
    for (size_t i = 0; i < len; i++)
        if (is_control((unsigned char)line[i]))
            return say(s->path, ln, "%s at byte %zu", line[i] ? "a control byte" : "a NUL byte",
                       i + 1);
    if (ln == 1) {
        if (strncmp(line, IDENT_VERSION, strlen(IDENT_VERSION)) ||
            !line[strlen(IDENT_VERSION)])
            return say(s->path, ln, "not a lagsim-sweep CSV: it starts with '%.40s', not with "
                                    "its identity '%sVERSION'", line, IDENT_VERSION);
        s->version = strdup(line + strlen(IDENT_VERSION));
        s->tf = open_memstream(&s->text, &s->textlen);
        if (!s->version || !s->tf) return say(s->path, ln, "out of memory");
        fprintf(s->tf, "%s\n", line);
        return 0;
    }
    if (line[0] == '#') return ident_take(s, ln, line);
    *rows_now = true;
    return ident_end(s, ln, line) || shard_admit(m, k) ? -1 : 0;
}

/* Shard number k's lines, each whole whatever its length. 0, or -1 after saying why. */
static int read_shard(merging *m, int k)
{
    shard *s = &m->sh[k];
    FILE *f = fopen(s->path, "r");
    if (!f) return say(s->path, 0, "%s", strerror(errno));
    char *line = NULL;
    size_t cap = 0;
    ssize_t got;
    long ln = 0;
    bool rows_now = false;
    int rc = 0;
    while (!rc && (got = getline(&line, &cap, f)) >= 0) {
        size_t len = (size_t)got;
        ln++;
        if (!len || line[len - 1] != '\n')
            rc = say(s->path, ln, "the file ends inside this line (no end of line): cut "
                                  "short?");
        else
            line[--len] = '\0', rc = shard_line(m, k, ln, line, len, &rows_now);
    }
    if (!rc && ferror(f)) rc = say(s->path, ln, "%s", strerror(errno));
    if (!rc && !rows_now)
        rc = say(s->path, 0, ln ? "no header line after the identity" : "an empty file");
    free(line);
    fclose(f);
    return rc;
}

/* ---------------------------------------------------------------- merge */
/* The runs from is 0 for, as numbers and ranges (at most 12 of them), in buf. */
static void missing_runs(const int *from, long runs, char *buf, size_t len)
{
    size_t u = 0;
    int gaps = 0;
    buf[0] = '\0';
    for (long a = 0; a < runs; a++) {
        if (from[a]) continue;
        long b = a;
        while (b + 1 < runs && !from[b + 1]) b++;
        if (gaps < 12 && u < len)
            u += (size_t)(b > a ? snprintf(buf + u, len - u, "%s%ld-%ld", gaps ? ", " : "", a, b)
                                : snprintf(buf + u, len - u, "%s%ld", gaps ? ", " : "", a));
        else if (gaps == 12 && u < len)
            u += (size_t)snprintf(buf + u, len - u, ", ...");
        gaps++;
        a = b;
    }
}

/* The runs of the sweep no row has, for each shard of N that has some: how to run them
 * (--shard K/N --only RUNS), then merge. */
static void merge_hint(const merging *m)
{
    const shard *s = &m->sh[0];
    unsigned char *has = malloc((size_t)s->runs), *one = calloc((size_t)s->sn, 1);
    int said = 0;
    for (long r = 0; has && r < s->runs; r++) has[r] = m->from[r] != 0;
    for (long K = 0; has && one && K < s->sn && said < 4; K++) {
        long r = K;
        while (r < s->runs && has[r]) r += s->sn;
        if (r >= s->runs) continue; /* every run of shard K is there */
        for (long q = 0; q < s->runs; q++) has[q] = !has[q]; /* the missing ones */
        one[K] = 1;
        char *text = sweep_runs_text(has, s->runs, s->sn, one);
        one[K] = 0;
        for (long q = 0; q < s->runs; q++) has[q] = !has[q];
        if (!said++)
            fprintf(MSG, "%s: merge: to finish the sweep, run its command again for the runs "
                         "missing (another --csv for each), then merge these with them:\n", prog);
        if (s->sn > 1) fprintf(MSG, "  --shard %ld/%ld --only %.300s%s\n", K + 1, s->sn,
                               text ? text : "?", text && strlen(text) > 300 ? "..." : "");
        else fprintf(MSG, "  --only %.300s%s\n", text ? text : "?",
                     text && strlen(text) > 300 ? "..." : "");
        free(text);
    }
    if (said == 4) fprintf(MSG, "  (and so on for the other shards that lack runs)\n");
    free(has), free(one);
}

/* Without --partial: every shard and every run there. 0, or -1 after naming what lacks. */
static int merge_whole(const merging *m)
{
    const shard *s = &m->sh[0];
    char buf[512];
    size_t u = 0;
    int lack = 0;
    for (long K = 0; K < s->sn; K++)
        if (!m->held[K] && lack++ < 8 && u < sizeof buf)
            u += (size_t)snprintf(buf + u, sizeof buf - u, "%s%ld/%ld", lack > 1 ? ", " : "",
                                  K + 1, s->sn);
    if (lack) {
        fprintf(MSG, "%s: merge: the shards do not make a whole sweep: missing shard%s %s%s "
                        "(of the sweep's %ld); give every shard, or --partial to merge only "
                        "these\n", prog, lack > 1 ? "s" : "", buf, lack > 8 ? ", ..." : "",
                s->sn);
        return -1;
    }
    missing_runs(m->from, s->runs, buf, sizeof buf);
    if (buf[0]) {
        fprintf(MSG, "%s: merge: the shards do not make a whole sweep: missing runs %s "
                        "(the sweep has runs 0 to %ld; a shard's sweep stopped early?); "
                        "--partial merges the runs there\n", prog, buf, s->runs - 1);
        merge_hint(m);
        return -1;
    }
    return 0;
}

/* The output: the first shard's identity (its shard line left out), the shards held when
 * they are not all, the header, the rows in run order. */
static int merge_write(merging *m, const char *out, bool force, const char *const *in)
{
    const shard *s = &m->sh[0];
    char *ident = NULL, err[256];
    size_t len = 0;
    FILE *t = open_memstream(&ident, &len);
    if (!t) return say(out, 0, "out of memory");
    fputs(s->text, t);
    if (memchr(m->held, 0, (size_t)s->sn)) {
        fputs("# shard: ", t);
        shard_set_write(t, m->held, s->sn);
        fputc('\n', t);
    }
    /* the runs of those shards that have a row, when not every one has */
    unsigned char *has = malloc((size_t)s->runs);
    bool all = true;
    for (long r = 0; has && r < s->runs; r++)
        all &= (has[r] = m->from[r] != 0) || !m->held[r % s->sn];
    if (has && !all) {
        fputs("# held: ", t);
        sweep_runs_write(t, has, s->runs, s->sn, m->held);
        fputc('\n', t);
    }
    free(has);
    if (fclose(t) != 0 || !has) {
        free(ident);
        return say(out, 0, "out of memory");
    }
    FILE *fo = eval_open_out(prog, "-o", out, force, in, m->nsh);
    if (!fo) {
        free(ident);
        return -1;
    }
    struct stat st; /* a half-written file is removed; a device (-o /dev/null) never */
    bool regular = fstat(fileno(fo), &st) == 0 && S_ISREG(st.st_mode);
    int rc = rows_write(&m->r, fo, ident, s->header, err, sizeof err);
    free(ident);
    if (fclose(fo) != 0 || rc) {
        say(out, 0, "%s", rc ? err : strerror(errno));
        if (regular) unlink(out);
        return -1;
    }
    return 0;
}

/* The command line: the inputs (in, nin), -o, --force, --partial. -1, or an exit status. */
static int merge_options(int argc, char **argv, const char **in, int *nin, const char **out,
                         bool *force, bool *partial, void (*usage)(FILE *))
{
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) {
            if (++i == argc) {
                fprintf(MSG, "%s: merge: %s needs a value\n", prog, argv[i - 1]);
                return 2;
            }
            *out = argv[i];
        } else if (!strcmp(argv[i], "-f") || !strcmp(argv[i], "--force")) {
            *force = true;
        } else if (!strcmp(argv[i], "--partial")) {
            *partial = true;
        } else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            usage(stdout);
            return 0;
        } else if (argv[i][0] == '-') {
            fprintf(MSG, "%s: merge: unknown option '%s' (try --help)\n", prog, argv[i]);
            return 2;
        } else {
            in[(*nin)++] = argv[i];
        }
    }
    if (!*nin) fprintf(MSG, "%s: merge: expected the shards' CSV files (try --help)\n", prog);
    else if (!*out) fprintf(MSG, "%s: merge: -o OUT.csv is required\n", prog);
    return *nin && *out ? -1 : 2;
}

int merge(int argc, char **argv, void (*usage)(FILE *))
{
    const char *out = NULL, **in = calloc((size_t)argc, sizeof *in);
    bool force = false, partial = false;
    merging m = {0};
    int rc = in ? merge_options(argc, argv, in, &m.nsh, &out, &force, &partial, usage) : 2;
    if (rc < 0 && !(m.sh = calloc((size_t)m.nsh, sizeof *m.sh))) rc = 2;
    for (int k = 0; rc < 0 && k < m.nsh; k++) {
        m.sh[k].path = in[k];
        if (read_shard(&m, k)) rc = 2;
    }
    if (rc < 0 && !partial && merge_whole(&m)) rc = 2;
    if (rc < 0 && merge_write(&m, out, force, in)) rc = 2;
    if (rc < 0) {
        summary(m.sh[0].header, &m.r);
        if (partial) merge_hint(&m); /* what the output lacks, and how to run it */
        rc = 0;
    }
    for (int k = 0; m.sh && k < m.nsh; k++) shard_free(&m.sh[k]);
    free(m.sh), free(m.from), free(m.claim), free(m.held), free(in);
    rows_free(&m.r);
    return rc;
}
