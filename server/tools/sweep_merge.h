/*
 * lagsim-sweep's CSV: the identity of the sweep, the header, one row a run; the summary of
 * the rows; and `lagsim-sweep merge`, which joins the CSVs of a sweep's shards (--shard
 * K/N) into the CSV one machine writes, after checking that every shard belongs.
 *
 * A CSV, whole sweep's, shard's or merge's, is, line by line:
 *
 *   # lagsim-sweep 0.1.0                        lagsim's version
 *   # seed: 7                                   --seed
 *   # scene-sha256: 3a7b...                     SHA-256 of the scene file's bytes
 *   # case: sweep                               the case's name (--duration alone: sweep)
 *   # duration: 8                               its sim seconds
 *   # set: parameters.m1=0.2                    each of its overrides, in order
 *   # bound: theta=0.5                          each of its bounds
 *   # vary: parameters.m0=uniform(0.5,2)        each --vary, as given, in order
 *   # runs: 8                                   the whole sweep's runs
 *   # controller: lqr_balance -q --prefix {prefix}
 *   # restart: no                               --restart: yes
 *   # require: theta.settle<6.5                 --require, when given
 *   # shard: 1/2                                a shard's (a partial merge's: 1-3,5/8)
 *   # held: 0-41,43                             the runs it holds, when not every run of
 *                                               its shards (a sweep stopped, --only, a
 *                                               partial merge); unknown: its rows say (a
 *                                               sweep that did not end)
 *   run,parameters.m0,...,failed,required,reason,x.rise,...
 *   0,1.4140917868522627,...,0,1,"",nan,6.7393795857533...
 *
 * Values are escaped (\\, \n, \r, \t, \xHH for other control bytes), so each is one line.
 * A whole sweep and the merge of its shards write the same bytes: the shard line is the
 * only one a shard adds, the held line the only one a CSV of some of its runs adds.
 *
 * One notion of a CSV that holds some of a sweep's runs: its shard line says of which
 * shards they are, its held line which of those runs (ranges of run numbers, each range
 * counted in those shards' runs: "0-40" under "shard: 1/2" is runs 0, 2, ..., 40). A
 * sweep stopped by a signal, a sweep of --only runs and a partial merge all write it;
 * merge takes them with the others, every run held by one file alone, and a whole set
 * of them makes the whole sweep's CSV, byte for byte. Comment lines are what pandas (comment='#'), gnuplot and R skip.
 */
#ifndef LAGSIM_SWEEP_MERGE_H
#define LAGSIM_SWEEP_MERGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "eval_case.h"

#define SWEEP_RUNS_MAX 10000000L /* runs of a sweep, and so shards of one */

/* A CSV's rows, in the order added, each with its run number */
typedef struct rows {
    int n, cap;
    long *run;
    char **line;
} rows;

int rows_add(rows *r, long run, const char *line);
void rows_free(rows *r);
/* Writes the identity lines (a string of whole lines), the header and the rows in run
 * order; -1 on two rows of one run (said in err). */
int rows_write(rows *r, FILE *f, const char *identity, const char *header, char *err,
               size_t errlen);
/* The CSV fields of a line (reason quoted, the others plain): pointers into buf. */
int split(char *buf, char **field, int max);
/* Pass rate, why runs failed (each reason with its count, the commonest first) and
 * percentiles of every metric column, from the CSV's rows, on stdout. */
void summary(const char *header, rows *r);

/* ---------------------------------------------------------------- what a row holds */
/* The reason field of a row: quoted, '"' doubled, every control byte a space. */
void sweep_write_reason(FILE *f, const char *reason);

/* A header's columns, as its rows are checked: run, the nvary varied keys' values,
 * failed, required, reason, then the metrics (each a number or nan). */
typedef struct sweep_columns {
    int n;                  /* fields a row has */
    int nvary;
    char **name;            /* each column's name (pointers into text) */
    char *text;
} sweep_columns;

/* The columns of a header line of nvary varied keys: 0, or -1 with what is wrong in why.
 * Free with sweep_columns_free. */
int sweep_columns_parse(const char *header, int nvary, sweep_columns *c /* OUT */, char *why,
                        size_t whylen);
void sweep_columns_free(sweep_columns *c);

/* Whether line (len bytes, its end of line removed) is a row of those columns in a sweep
 * of `runs` runs, as lagsim-sweep writes one: the run number an integer in [0, runs) as
 * %ld writes it, the values numbers as lag_num writes them (%g's form), failed and required 0 or 1, the
 * reason quoted, the metrics numbers or nan; no control byte. 0 with *run set, or -1 with
 * what is wrong (the field named) in why. */
int sweep_row_check(const sweep_columns *c, const char *line, size_t len, long runs,
                    long *run /* OUT */, char *why, size_t whylen);

/* --shard K/N: 1 <= K <= N <= SWEEP_RUNS_MAX, digits only. 0, or -1. OUT: k, n */
int sweep_shard_parse(const char *text, long *k, long *n);

/* ---------------------------------------------------------------- sets of runs */
/* A held line's value while the sweep writing it runs: its rows say which runs it holds. */
#define SWEEP_HELD_UNKNOWN "unknown (the rows below, each written as its run ended: the " \
                           "sweep writing this file did not end)"
/* "A-B,C" (ascending, each number digits only from 0 to runs - 1) or "none": set[r] = 1
 * for each run r it names (set has runs bytes). 0, or -1 when it is none of those. */
int sweep_runs_parse(const char *text, long runs, unsigned char *set);
/* The runs r of set[] of the shards shards[K - 1] of sn as ranges of those shards' runs
 * ("0-40" for 0, 2, ..., 40 of shard 1/2), or "none". */
void sweep_runs_write(FILE *f, const unsigned char *set, long runs, long sn,
                      const unsigned char *shards);
/* The same in a new string (NULL: out of memory). */
char *sweep_runs_text(const unsigned char *set, long runs, long sn, const unsigned char *shards);

/* ---------------------------------------------------------------- the identity */
/* What makes a sweep's runs what they are: every shard of one sweep has the same. */
typedef struct sweep_identity {
    uint64_t seed;
    const char *scene;            /* the scene file: the SHA-256 of its bytes is written */
    const eval_case *c;           /* name, duration, overrides, bounds */
    const char *const *vary;      /* each --vary KEY=DIST as given */
    int nvary;
    long runs;                    /* the whole sweep's */
    const char *controller;
    bool restart;
    const char *require;          /* NULL: none */
    long shard_k, shard_n;        /* 1/1: the whole sweep */
} sweep_identity;

/* The identity lines (each ending in '\n') in a new string; NULL with why in err (the
 * scene cannot be read). */
char *sweep_identity_text(const sweep_identity *id, char *err, size_t errlen);

/* The SHA-256 of a file's bytes in hex (65 bytes with the '\0'); 0, or -1 with why. */
int sweep_sha256_file(const char *path, char hex[65], char *err, size_t errlen);

/* lagsim-sweep merge A.csv B.csv ... -o OUT.csv: argv[0] is "merge"; usage prints --help.
 * Returns the exit status. */
int merge(int argc, char **argv, void (*usage)(FILE *));
/* Where merge says why it refuses: f, or stderr (NULL, the default). The fuzz target's. */
void sweep_merge_messages(FILE *f);

#endif
