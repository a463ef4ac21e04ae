/*
 * lagsim-sweep's CSV: one row a run (the run number first), the summary of the rows, and
 * `lagsim-sweep merge`, which joins the CSVs of a sweep's shards (--shard K/N) into the CSV
 * one machine writes.
 */
#ifndef LAGSIM_SWEEP_MERGE_H
#define LAGSIM_SWEEP_MERGE_H

#include <stddef.h>
#include <stdio.h>

#define ROW_MAX 8192

/* A CSV's rows, in the order added, each with its run number */
typedef struct rows {
    int n, cap;
    long *run;
    char **line;
} rows;

int rows_add(rows *r, long run, const char *line);
void rows_free(rows *r);
/* Writes the header and the rows in run order; -1 on two rows of one run (said in err). */
int rows_write(rows *r, FILE *f, const char *header, char *err, size_t errlen);
/* The CSV fields of a line (reason quoted, the others plain): pointers into buf. */
int split(char *buf, char **field, int max);
/* Pass rate and percentiles of every metric column, from the CSV's rows, on stdout. */
void summary(const char *header, rows *r);
/* lagsim-sweep merge A.csv B.csv ... -o OUT.csv: argv[0] is "merge"; usage prints --help.
 * Returns the exit status. */
int merge(int argc, char **argv, void (*usage)(FILE *));

#endif
