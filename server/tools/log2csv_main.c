/*
 * lagsim-log2csv LOG [--channel CH ...] [-o DIR] [--force] [-q]
 *
 * Turns an LCM log (written by lagsimd --log or by lcm-logger) into one CSV per channel
 * that carries lagsim's messages, and prints a summary. Exit codes (lag_result_exit): 0 ok,
 * 1 the log ends in an error (truncated, corrupt: the CSVs hold every record before it),
 * 2 usage, or the log cannot be opened, or a CSV cannot be written.
 */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "log2csv.h"

static void usage(FILE *f)
{
    fputs("usage: lagsim-log2csv LOG [--channel CHANNEL ...] [-o DIR] [--force] [-q]\n"
          "\n"
          "Writes one CSV per channel of lagsim's messages found in LOG (an LCM log from\n"
          "lagsimd --log or lcm-logger) into DIR, named after the channel (DIPC_STATE.csv,\n"
          "...), and prints a summary: channels, counts, rates, gaps in the states,\n"
          "rejected commands, events.\n"
          "\n"
          "  -c, --channel CH   only this channel (repeatable)\n"
          "  -o, --output DIR   directory for the CSVs (default: the current one; created)\n"
          "  -f, --force        replace CSVs that exist (else refused, exit 2); a symbolic\n"
          "                     link is never written through, nor the LOG itself\n"
          "  -q, --quiet        no summary, no list of files\n"
          "  -h, --help         this help\n"
          "\n"
          "Columns: states  t (sim time, s), wall_time (publication, s since the epoch),\n"
          "log_time (as the log stored it), step, generation, each joint's position,\n"
          "<joint>_dot, <joint>_effort; references (<PREFIX>_REFERENCE) t, wall_time,\n"
          "log_time, step, generation,\n"
          "each joint's r under its name, r' as <joint>_dot, r'' as <joint>_ddot; status,\n"
          "events, scenes,\n"
          "commands and control requests: every\n"
          "field (see docs/view.md). Text from the log is quoted (RFC 4180), and text that\n"
          "would start a spreadsheet formula (=, +, -, @) gets a leading '.\n"
          "exit codes: 0 ok, 1 the log ends in an error (CSVs hold what came before),\n"
          "2 usage, unreadable log or unwritable CSV\n",
          f);
}

static lag_result log2csv_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"channel", required_argument, NULL, 'c'}, {"output", required_argument, NULL, 'o'},
        {"quiet", no_argument, NULL, 'q'},         {"help", no_argument, NULL, 'h'},
        {"force", no_argument, NULL, 'f'},
        {NULL, 0, NULL, 0},
    };
    l2c_opts o = {.outdir = ".", .n_select = 0, .listing = stdout};
    bool quiet = false;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":c:o:qhf", longopts, NULL)) != -1) {
        switch (c) {
        case 'c':
            if (o.n_select >= L2C_MAX_SELECT) {
                fprintf(stderr, "lagsim-log2csv: at most %d --channel options\n", L2C_MAX_SELECT);
                return LAG_ERR_USAGE;
            }
            o.select[o.n_select++] = optarg;
            break;
        case 'o':
            o.outdir = optarg;
            break;
        case 'q':
            quiet = true;
            break;
        case 'f':
            o.force = true;
            break;
        case 'h':
            usage(stdout);
            return LAG_OK;
        case ':':
            fprintf(stderr, "lagsim-log2csv: option %s needs a value\n", argv[optind - 1]);
            return LAG_ERR_USAGE;
        default:
            fprintf(stderr, "lagsim-log2csv: unknown option '%s' (try --help)\n", argv[optind - 1]);
            return LAG_ERR_USAGE;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "lagsim-log2csv: expected one LOG file (try --help)\n");
        return LAG_ERR_USAGE;
    }
    const char *path = argv[optind];
    o.input = path;
    if (mkdir(o.outdir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "lagsim-log2csv: cannot create %s: %s\n", o.outdir, strerror(errno));
        return LAG_ERR_FILE;
    }
    if (quiet) o.listing = NULL;
    char err[512] = "";
    lag_log *lg = lag_log_open(path, L2C_MAX_DATA, err, sizeof err);
    if (!lg) {
        fprintf(stderr, "lagsim-log2csv: %s\n", err);
        return LAG_ERR_FILE;
    }
    lag_result rc = l2c_convert(lg, &o, quiet ? NULL : stdout, err, sizeof err);
    lag_log_stats ls;
    lag_log_get_stats(lg, &ls);
    lag_log_close(lg);
    /* damage the reader got past: said on stderr even with -q */
    if (ls.damaged > 0)
        fprintf(stderr, "lagsim-log2csv: warning: %s is damaged in %lld place(s): %lld bytes "
                        "passed over to find the next record\n",
                path, (long long)ls.damaged, (long long)ls.bytes_skipped);
    if (ls.truncated_bytes > 0)
        fprintf(stderr, "lagsim-log2csv: warning: %s ends inside a record (%lld bytes cut "
                        "short: a logger stopped while writing?)\n",
                path, (long long)ls.truncated_bytes);
    if (rc == LAG_ERR_RUNTIME)
        fprintf(stderr, "lagsim-log2csv: %s: %s (the CSVs hold every record before it)\n",
                path, err);
    else if (rc != LAG_OK)
        fprintf(stderr, "lagsim-log2csv: %s\n", err);
    return rc;
}

int main(int argc, char **argv)
{
    return lag_result_exit(log2csv_main(argc, argv));
}
