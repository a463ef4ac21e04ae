/*
 * lagsim-log2csv's conversion: an LCM log (lagsimd --log or lcm-logger) into one CSV per
 * channel that carries lagsim's messages, and a summary. Separate from main() so that the
 * fuzz target runs exactly what the tool runs.
 */
#ifndef LAGSIM_LOG2CSV_H
#define LAGSIM_LOG2CSV_H

#include <stdbool.h>
#include <stdio.h>
#include "lagsim/result.h"
#include "lagsim_log.h"
#include "lagsim_wire.h"

#define L2C_MAX_SELECT 16
#define L2C_MAX_DATA 65536  /* records larger than this are not lagsim's: passed over */

typedef struct l2c_opts {
    const char *outdir;                 /* where CSVs go; NULL: convert but discard */
    int n_select;                       /* --channel: only these (0: every channel) */
    const char *select[L2C_MAX_SELECT];
    FILE *listing;                      /* one line per CSV written (NULL: none) */
    bool force;                         /* --force: an existing CSV may be replaced */
    const char *input;                  /* the log read: never written (lagsim_out.h) */
} l2c_opts;

/* Reads the whole log, writes the CSVs and the summary (to `summary`, may be NULL).
 * Returns LAG_OK, LAG_ERR_RUNTIME when the log ended in an error (the CSVs hold every
 * record before it; the message is in err), LAG_ERR_FILE when a CSV could not be written
 * (message in err). */
lag_result l2c_convert(lag_log *lg, const l2c_opts *o, FILE *summary, char *err, size_t errlen);

#endif
