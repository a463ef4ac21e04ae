/*
 * Fuzz target: lagsim-sweep merge (server/tools/sweep_merge.c) on arbitrary bytes as a
 * shard file: its identity lines, its header and every row checked against it (lines of
 * any length, NUL bytes, numbers at and past 2^64). The input is merged alone with
 * --partial into a file of a private directory; merge's messages and summary go to
 * /dev/null. Corpus: a shard and a partial merge as lagsim-sweep writes them, and
 * malformed ones (tests/fuzz/sweep_merge/corpus).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

#include "sweep_merge.h"

static char dir[] = "/tmp/fuzz_sweep_merge.XXXXXX", out[64];

static void remove_dir(void)
{
    unlink(out);
    rmdir(dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static FILE *sink;
    if (!sink) {
        if (!mkdtemp(dir) || !(sink = fopen("/dev/null", "w"))) return 0;
        atexit(remove_dir);
        snprintf(out, sizeof out, "%s/out.csv", dir);
        sweep_merge_messages(sink);
        if (!freopen("/dev/null", "w", stdout)) return 0; /* the summary */
    }
    int fd = memfd_create("fuzz_sweep_merge", MFD_CLOEXEC);
    if (fd < 0) return 0;
    if (size > 0 && write(fd, data, size) != (ssize_t)size) {
        close(fd);
        return 0;
    }
    char in[64];
    snprintf(in, sizeof in, "/proc/self/fd/%d", fd);
    char *argv[] = {"merge", in, "--partial", "--force", "-o", out, NULL};
    (void)merge(6, argv, NULL);
    close(fd);
    unlink(out);
    return 0;
}
