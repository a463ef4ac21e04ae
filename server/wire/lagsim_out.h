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
#include <stdint.h>

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

/* ---------------------------------------------------------------- a series of outputs
 * lagsimd --log FILE --increment writes FILE.000000, FILE.000001, ...: a series. Its
 * members are the names FILE, a dot and LAG_OUT_SERIES_DIGITS to LAG_OUT_SERIES_MAX_DIGITS
 * decimal digits and nothing else, in FILE's directory. Numbers are zero-padded to
 * LAG_OUT_SERIES_DIGITS, so `ls` and a shell glob list a series in order up to
 * FILE.999999 (a restart every 5 s for 58 days); past it they widen (FILE.1000000: `ls -v`
 * and lag_out_series_prune order by the number). Numbering never runs out and never goes
 * back: the next member is one past the highest number taken in the directory, whatever
 * holds it (another user's file, a symbolic link, a directory), so a name is never reused
 * and a member removed by retention leaves no gap that a later start would fill.
 * Names of fewer digits (lcm-logger -i's FILE.00, ...) are not members: never touched. */
#define LAG_OUT_SERIES_DIGITS 6
#define LAG_OUT_SERIES_MAX_DIGITS 18 /* more is no name this code made: not a member */

/* Creates the next member of path's series (an exclusive create: nothing is replaced, and
 * a name another process takes first is passed over), O_NOFOLLOW and extra_flags added to
 * open(2)'s, mode 0644 before the umask. `name` gets the member's path, `number` its
 * number. Returns a file descriptor, or LAG_OUT_REFUSED (a path that names no file: empty,
 * or ending in '/') / LAG_OUT_ERROR (the directory cannot be read or written, the numbers
 * are used up) with a message in err that starts with `what`. OUT: name, number */
int lag_out_series_open(const char *what, const char *path, int extra_flags, char *name,
                        size_t namelen, uint64_t *number, char *err, size_t errlen);
/* The name of member `number` of path's series. OUT: name (0 on success, -1: too long) */
int lag_out_series_name(const char *path, uint64_t number, char *name, size_t namelen);

/* Retention: keeps the newest `keep` (>= 1) members of path's series that the series'
 * writer makes, and removes the older ones (lowest numbers first). Only regular files of
 * the effective user are members it counts or removes (fstatat without following: a
 * symbolic link is never followed nor removed, a directory or another user's file never
 * removed); `current` (the member being written) is never removed. Returns how many were
 * removed (and their bytes in *freed, may be NULL), or -1 with a message in err when the
 * directory cannot be read or a removal fails (those before it stay removed). OUT: freed */
int lag_out_series_prune(const char *what, const char *path, int keep, uint64_t current,
                         int64_t *freed, char *err, size_t errlen);

#endif
