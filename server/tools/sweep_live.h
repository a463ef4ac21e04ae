/*
 * lagsim-sweep while its workers run: the rows taken as they come (each worker writes
 * tmpdir/W.rows), the CSV written as runs end (a crash leaves the finished rows), then
 * again in run order; the progress line on stderr. sweep_live.c says how.
 */
#ifndef LAGSIM_SWEEP_LIVE_H
#define LAGSIM_SWEEP_LIVE_H

#include <stdbool.h>
#include <stdio.h>

#include "sweep_merge.h"

typedef struct sweep_live {
    /* the caller's */
    const char *tmpdir;
    long jobs;                 /* workers: tmpdir/0.rows ... */
    FILE *csv;                 /* --csv, or NULL */
    const char *identity;      /* the CSV's identity lines (whole lines) */
    const char *header;
    long runs, sn;             /* the sweep's runs; its shards */
    const unsigned char *shards; /* shards[K - 1]: this CSV's runs are of shard K */
    const unsigned char *want; /* want[run]: this sweep runs it */
    long nwant;
    int nvary;                 /* the varied keys: the row's failed field after them */
    bool progress, tty;        /* the progress line; on a terminal (else a line each 10 s) */
    bool require;              /* count the runs that missed --require */
    /* what came */
    rows r;
    unsigned char *has;        /* has[run]: its row came */
    long done, failed, missed;
    FILE *in[256];
    bool live;                 /* the CSV is a regular file: rows written as they come */
    double t0, drawn;
    long shown_done;
} sweep_live;

/* The workers' row files made (before they start) and opened; the live CSV's identity
 * (held: unknown) and header. 0, or -1 with why. */
int sweep_live_start(sweep_live *l, char *err, size_t errlen);
/* The rows written since, taken (and in the live CSV); the progress line when due. */
void sweep_live_poll(sweep_live *l);
/* The last rows taken, the last progress line, and the CSV written again from its start:
 * the identity (a held line when a run of its shards has no row), the header, the rows in
 * run order. 0, or -1 with why. */
int sweep_live_finish(sweep_live *l, char *err, size_t errlen);
/* The runs wanted that have no row, and the runs that have one, as a held line writes
 * them (new strings; NULL: out of memory). */
char *sweep_live_missing(const sweep_live *l);
char *sweep_live_held(const sweep_live *l);
void sweep_live_free(sweep_live *l);

#endif
