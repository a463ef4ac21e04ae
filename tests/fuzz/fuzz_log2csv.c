/*
 * Fuzz target: lagsim-log2csv's whole conversion (the shared bounded LCM log reader and
 * wire decoders, the CSV writers and the summary) on arbitrary bytes as a log file.
 * CSVs and the summary go to /dev/null. Corpus: tests/view/lcmlog.py --corpus.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/mman.h>
#include <unistd.h>

#include "log2csv.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[512];
    /* a regular file in memory (memfd): the reader fstat()s its stream, which fmemopen
     * streams cannot answer */
    int fd = memfd_create("fuzz_log2csv", MFD_CLOEXEC);
    if (fd < 0) return 0;
    if (size > 0 && write(fd, data, size) != (ssize_t)size) {
        close(fd);
        return 0;
    }
    lseek(fd, 0, SEEK_SET);
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        close(fd);
        return 0;
    }
    lag_log *lg = lag_log_open_stream(f, "fuzz", L2C_MAX_DATA, err, sizeof err);
    if (lg) {
        static FILE *sink;
        if (!sink) sink = fopen("/dev/null", "w");
        l2c_opts o = {.outdir = NULL, .n_select = 0, .listing = NULL};
        (void)l2c_convert(lg, &o, sink, err, sizeof err);
        lag_log_close(lg);
    }
    fclose(f);
    return 0;
}
