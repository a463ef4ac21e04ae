/*
 * lagsim-sweep while its workers run (sweep_live.h): their rows taken as they come, the
 * CSV written as runs end, the progress line.
 *
 * Each worker appends a row to a file of its own (tmpdir/W.rows) when a run ends. The
 * parent reads the complete lines of each (a line still being written waits for its end
 * of line), keeps them and, when --csv names a regular file, appends them to it at once
 * under identity lines whose held line says the rows are what it holds (SWEEP_HELD_UNKNOWN):
 * a sweep killed (SIGKILL, a crash, the OOM killer) leaves the rows of every run that had
 * ended, which `merge --partial` takes. At the end, and when a signal stops the sweep, the
 * CSV is written again in run order with its identity: a held line only when some of its
 * runs are missing, so a sweep that ends writes the same bytes as before.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sweep_live.h"

#define DRAW_GAP_S 0.25  /* the terminal's line: at most 4 drawings a second */
#define DRAW_TICK_S 1.0  /* ... and one a second while nothing ends (the times move) */
#define LINE_GAP_S 10.0  /* --progress to a file or a pipe: a line every 10 s */

int sweep_live_start(sweep_live *l, char *err, size_t errlen)
{
    l->has = calloc((size_t)l->runs, 1);
    if (!l->has) return snprintf(err, errlen, "out of memory"), -1;
    for (long w = 0; w < l->jobs; w++) {
        char path[300];
        snprintf(path, sizeof path, "%s/%ld.rows", l->tmpdir, w);
        FILE *f = fopen(path, "w"); /* made here, so that it can be read from the start */
        if (f) fclose(f);
        if (!f || !(l->in[w] = fopen(path, "r")))
            return snprintf(err, errlen, "%s: cannot be made", path), -1;
    }
    struct stat st;
    l->live = l->csv && fstat(fileno(l->csv), &st) == 0 && S_ISREG(st.st_mode);
    if (l->live) { /* the rows follow as their runs end */
        fprintf(l->csv, "%s# held: %s\n%s\n", l->identity, SWEEP_HELD_UNKNOWN, l->header);
        fflush(l->csv);
    }
    l->t0 = l->drawn = eval_now();
    l->drawn -= DRAW_TICK_S + LINE_GAP_S; /* the first drawing at once */
    return 0;
}

/* A row a worker wrote: kept, counted, in the CSV. */
static void take_row(sweep_live *l, const char *line)
{
    char *end;
    long run = strtol(line, &end, 10);
    if (end == line || run < 0 || run >= l->runs || l->has[run]) return; /* cannot be */
    if (rows_add(&l->r, run, line)) return;
    l->has[run] = 1;
    l->done++;
    /* failed and required: the fields after the run and its nvary values */
    const char *p = line;
    for (int k = 0; k <= l->nvary && p; k++) p = strchr(p + 1, ',');
    if (p && p[1] == '1') l->failed++;
    else if (p && p[1] == '0' && !strncmp(p + 2, ",0,", 3)) l->missed++;
    if (l->live) {
        fprintf(l->csv, "%s\n", line);
        fflush(l->csv);
    }
}

/* The complete lines worker w wrote since the last look. */
static void read_new(sweep_live *l, long w)
{
    FILE *f = l->in[w];
    char *line = NULL;
    size_t cap = 0;
    for (;;) {
        off_t at = ftello(f);
        ssize_t n = getline(&line, &cap, f);
        if (n > 0 && line[n - 1] != '\n') fseeko(f, at, SEEK_SET); /* its end comes later */
        if (n <= 0 || line[n - 1] != '\n') break;
        line[n - 1] = '\0';
        take_row(l, line);
    }
    clearerr(f);
    free(line);
}

/* "42 s", "3 min 02 s", "1 h 02 min" */
static void span_text(double s, char *buf, size_t len)
{
    long t = (long)(s + 0.5);
    if (t < 60) snprintf(buf, len, "%ld s", t);
    else if (t < 3600) snprintf(buf, len, "%ld min %02ld s", t / 60, t % 60);
    else snprintf(buf, len, "%ld h %02ld min", t / 3600, t / 60 % 60);
}

/* The progress: runs done of this sweep's (or shard's) runs, failures so far, the rate,
 * the time so far and the time left at that rate (the last line: the time it took). */
static void progress_text(const sweep_live *l, bool final, char *buf, size_t len)
{
    double took = eval_now() - l->t0, rate = took > 0 ? (double)l->done / took : 0;
    char so_far[32], left[48] = ", ETA -", missed[48] = "";
    span_text(took, so_far, sizeof so_far);
    if (l->done && rate > 0 && !final) {
        span_text((double)(l->nwant - l->done) / rate, left + 6, sizeof left - 6);
    }
    if (final) left[0] = '\0';
    if (l->require) snprintf(missed, sizeof missed, ", %ld missed --require", l->missed);
    snprintf(buf, len, "lagsim-sweep: %ld/%ld runs (%.0f %%), %ld failed%s, %.3g runs/s, %s%s%s",
             l->done, l->nwant, l->nwant ? 100.0 * (double)l->done / (double)l->nwant : 100.0,
             l->failed, missed, rate, final ? "in " : "", so_far, final ? "" : " so far");
    size_t n = strlen(buf);
    if (n + 1 < len) snprintf(buf + n, len - n, "%s", left);
}

static void draw(sweep_live *l, bool final)
{
    char line[512];
    progress_text(l, final, line, sizeof line);
    if (!l->tty) {
        fprintf(stderr, "%s\n", line);
    } else {
        struct winsize ws; /* never wider than the terminal: it would wrap */
        if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 1 &&
            ws.ws_col < sizeof line)
            line[ws.ws_col - 1] = '\0';
        fprintf(stderr, "\r\033[K%s%s", line, final ? "\n" : "");
    }
    fflush(stderr);
    l->drawn = eval_now();
    l->shown_done = l->done;
}

void sweep_live_poll(sweep_live *l)
{
    for (long w = 0; w < l->jobs; w++)
        if (l->in[w]) read_new(l, w);
    if (!l->progress) return;
    double since = eval_now() - l->drawn;
    if (l->tty ? (since >= DRAW_TICK_S || (l->done != l->shown_done && since >= DRAW_GAP_S))
               : since >= LINE_GAP_S)
        draw(l, false);
}

/* The identity, and a held line when a run of the file's shards has no row. */
static char *identity_now(const sweep_live *l)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) return NULL;
    fputs(l->identity, f);
    bool all = true;
    for (long r = 0; r < l->runs && all; r++) all = l->has[r] || !l->shards[r % l->sn];
    if (!all) {
        fputs("# held: ", f);
        sweep_runs_write(f, l->has, l->runs, l->sn, l->shards);
        fputc('\n', f);
    }
    if (fclose(f) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

int sweep_live_finish(sweep_live *l, char *err, size_t errlen)
{
    sweep_live_poll(l);
    if (l->progress) draw(l, true);
    if (!l->csv) return 0;
    char *ident = identity_now(l);
    if (!ident) return snprintf(err, errlen, "out of memory"), -1;
    /* in run order, from the start: the live file's rows were in the order runs ended */
    fflush(l->csv);
    if (l->live && (ftruncate(fileno(l->csv), 0) != 0 || fseeko(l->csv, 0, SEEK_SET) != 0)) {
        free(ident);
        return snprintf(err, errlen, "cannot write it again in run order"), -1;
    }
    int rc = rows_write(&l->r, l->csv, ident, l->header, err, errlen);
    free(ident);
    if (fflush(l->csv) != 0 && !rc) {
        snprintf(err, errlen, "a write failed");
        rc = -1;
    }
    return rc;
}

char *sweep_live_missing(const sweep_live *l)
{
    unsigned char *miss = malloc((size_t)l->runs);
    if (!miss) return NULL;
    for (long r = 0; r < l->runs; r++) miss[r] = l->want[r] && !l->has[r];
    char *text = sweep_runs_text(miss, l->runs, l->sn, l->shards);
    free(miss);
    return text;
}

char *sweep_live_held(const sweep_live *l)
{
    return sweep_runs_text(l->has, l->runs, l->sn, l->shards);
}

void sweep_live_free(sweep_live *l)
{
    for (long w = 0; w < l->jobs; w++)
        if (l->in[w]) fclose(l->in[w]);
    free(l->has);
    rows_free(&l->r);
}
