/*
 * Opening an output file without clobbering: see lagsim_out.h.
 *
 * The checks are made on the open file descriptor, not on the name before opening, so
 * that a file swapped in between cannot slip through: first an exclusive create (a new
 * file is nobody's input and replaces nothing); if the name exists, an open without
 * O_CREAT and without O_TRUNC, then fstat: only a regular file that is no input, with
 * force, is truncated. O_NOFOLLOW makes both opens fail (ELOOP) on a symbolic link.
 */
#include "lagsim_out.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int refuse(int fd, int rc, char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static int refuse(int fd, int rc, char *err, size_t errlen, const char *fmt, ...)
{
    if (fd >= 0) close(fd);
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return rc;
}

int lag_out_open(const char *what, const char *path, bool force, const char *const *inputs,
                 int n, int extra_flags, char *err, size_t errlen)
{
    const int base = O_WRONLY | O_NOFOLLOW | O_CLOEXEC | extra_flags;
    if (!path || !path[0])
        return refuse(-1, LAG_OUT_REFUSED, err, errlen, "%s: an empty path", what);
    int fd = open(path, base | O_CREAT | O_EXCL, 0644);
    if (fd >= 0) return fd; /* new: nothing replaced, nobody's input */
    if (errno != EEXIST)
        return refuse(-1, LAG_OUT_ERROR, err, errlen, "%s %s: cannot open for writing: %s",
                      what, path, strerror(errno));
    fd = open(path, base);
    if (fd < 0 && errno == ELOOP)
        return refuse(-1, LAG_OUT_REFUSED, err, errlen, "%s %s: a symbolic link: not followed "
                      "(writing through it would replace its target); give the target's own "
                      "path, or remove the link", what, path);
    if (fd < 0)
        return refuse(-1, LAG_OUT_ERROR, err, errlen, "%s %s: cannot open for writing: %s%s",
                      what, path, strerror(errno),
                      errno == ENXIO ? " (a FIFO that nobody reads)" : "");
    struct stat st;
    if (fstat(fd, &st) != 0)
        return refuse(fd, LAG_OUT_ERROR, err, errlen, "%s %s: %s", what, path, strerror(errno));
    for (int i = 0; i < n; i++) {
        struct stat in;
        if (!inputs[i] || stat(inputs[i], &in) != 0) continue;
        if (in.st_dev == st.st_dev && in.st_ino == st.st_ino)
            return refuse(fd, LAG_OUT_REFUSED, err, errlen, "%s %s: the same file as %s, "
                          "which this run reads or writes: refused, with --force too; write "
                          "elsewhere", what, path, inputs[i]);
    }
    if (!S_ISREG(st.st_mode)) return fd; /* a FIFO, a device: nothing stored is lost */
    if (!force)
        return refuse(fd, LAG_OUT_REFUSED, err, errlen, "%s %s: exists (%lld bytes): not "
                      "replaced; --force replaces it", what, path, (long long)st.st_size);
    if (ftruncate(fd, 0) != 0)
        return refuse(fd, LAG_OUT_ERROR, err, errlen, "%s %s: cannot truncate: %s", what, path,
                      strerror(errno));
    return fd;
}
