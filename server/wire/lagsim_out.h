/*
 * Opening an output file without clobbering what is not meant to be written: the one
 * helper every program of lagsim uses for a file it creates (lagsimd --log and --csv,
 * lagsim-log2csv's CSVs, the controllers' --trace; lagsim-plot applies the same rules in
 * shell).
 *
 *   - a symbolic link is never followed (O_NOFOLLOW): writing through it would truncate
 *     its target, whatever that is;
 *   - a file that is one of the program's inputs (the same st_dev and st_ino: the scene
 *     file, the log being read, a hard link to either) is refused, even with force; so is
 *     one of its other outputs, when the program lists them among the inputs;
 *   - an existing regular file is refused unless force (lcm-logger's -f), and only then
 *     truncated;
 *   - a FIFO or a device (/dev/null, /dev/full, a pipe to another program) holds nothing
 *     that writing destroys: opened as it is.
 * The file is created 0644 (before the umask). A refusal is LAG_OUT_REFUSED with a
 * message that names the path, what it is, and what to do.
 */
#ifndef LAGSIM_OUT_H
#define LAGSIM_OUT_H

#include <stdbool.h>
#include <stddef.h>

enum {
    LAG_OUT_REFUSED = -2, /* the rules above: a usage error (exit 2) */
    LAG_OUT_ERROR = -1,   /* the system refused (no such directory, permission, ...) */
};

/* Opens path for writing. `inputs` (n of them, NULL entries skipped) are the files the
 * program reads; `what` names the option in messages ("--log"); `force` allows replacing
 * an existing regular file; `extra_flags` are added to open(2)'s (e.g. O_NONBLOCK).
 * Returns a file descriptor, or LAG_OUT_REFUSED / LAG_OUT_ERROR with a message in err
 * (which starts with `what` and the path). */
int lag_out_open(const char *what, const char *path, bool force, const char *const *inputs,
                 int n, int extra_flags, char *err, size_t errlen);

#endif
