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

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
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

/* ---------------------------------------------------------------- a series of outputs */

/* path split into its directory (what opendir takes) and its last component. Returns
 * false when path names no file (empty, or ending in '/', or too long). OUT: dir, base */
static bool split_path(const char *path, char *dir, size_t dirlen, const char **base)
{
    const char *slash = strrchr(path, '/');
    *base = slash ? slash + 1 : path;
    if (!(*base)[0]) return false;
    if (!slash) return snprintf(dir, dirlen, ".") < (int)dirlen;
    size_t n = slash == path ? 1 : (size_t)(slash - path); /* "/x": the root */
    if (n >= dirlen) return false;
    memcpy(dir, path, n);
    dir[n] = '\0';
    return true;
}

/* The number of a member's name: base, '.', LAG_OUT_SERIES_DIGITS to
 * LAG_OUT_SERIES_MAX_DIGITS digits and nothing else, as lag_out_series_name writes them. OUT: number (true: a member's name) */
static bool member_number(const char *entry, const char *base, size_t baselen,
                          uint64_t *number)
{
    if (strncmp(entry, base, baselen) != 0 || entry[baselen] != '.') return false;
    const char *d = entry + baselen + 1;
    uint64_t v = 0;
    size_t k = 0;
    for (; d[k]; k++) {
        if (d[k] < '0' || d[k] > '9' || k >= LAG_OUT_SERIES_MAX_DIGITS) return false;
        v = v * 10 + (uint64_t)(d[k] - '0'); /* at most 18 digits: no overflow */
    }
    /* exactly as lag_out_series_name writes it: zero-padded to LAG_OUT_SERIES_DIGITS,
     * wider without a leading zero */
    if (k < LAG_OUT_SERIES_DIGITS || (k > LAG_OUT_SERIES_DIGITS && d[0] == '0')) return false;
    *number = v;
    return true;
}

int lag_out_series_name(const char *path, uint64_t number, char *name, size_t namelen)
{
    int w = snprintf(name, namelen, "%s.%0*llu", path, LAG_OUT_SERIES_DIGITS,
                     (unsigned long long)number);
    return w > 0 && (size_t)w < namelen ? 0 : -1;
}

/* One past the highest member number of the directory's entries (0: none). Returns 0, or
 * -1 with errno set when the directory cannot be read. OUT: next */
static int series_next(const char *dir, const char *base, uint64_t *next)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    size_t baselen = strlen(base);
    uint64_t n = 0;
    struct dirent *e;
    errno = 0;
    while ((e = readdir(d)) != NULL) {
        uint64_t v;
        if (member_number(e->d_name, base, baselen, &v) && v + 1 > n) n = v + 1;
    }
    int rc = errno ? -1 : 0;
    int saved = errno;
    closedir(d);
    errno = saved;
    *next = n;
    return rc;
}

int lag_out_series_open(const char *what, const char *path, int extra_flags, char *name,
                        size_t namelen, uint64_t *number, char *err, size_t errlen)
{
    char dir[4096];
    const char *base;
    if (!path || !split_path(path, dir, sizeof dir, &base))
        return refuse(-1, LAG_OUT_REFUSED, err, errlen, "%s %s: names no file (a series is "
                      "FILE.000000, FILE.000001, ...: give FILE)", what, path ? path : "");
    uint64_t n;
    if (series_next(dir, base, &n) != 0)
        return refuse(-1, LAG_OUT_ERROR, err, errlen, "%s %s: cannot read the directory %s: %s",
                      what, path, dir, strerror(errno));
    const int flags = O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | extra_flags;
    for (int tries = 0; tries < 1000; tries++, n++) {
        if (n >= 1000000000000000000ULL || lag_out_series_name(path, n, name, namelen) != 0)
            break;
        int fd = open(name, flags, 0644);
        if (fd >= 0) {
            *number = n;
            return fd;
        }
        if (errno != EEXIST) /* EEXIST: another process took it first: the next one */
            return refuse(-1, LAG_OUT_ERROR, err, errlen, "%s %s: cannot create %s: %s", what,
                          path, name, strerror(errno));
    }
    return refuse(-1, LAG_OUT_ERROR, err, errlen, "%s %s: no free number in its series (the "
                  "last tried: %llu)", what, path, (unsigned long long)n);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* The numbers of the directory's members that are regular files of the effective user
 * (not following symbolic links), sorted. Returns how many (in *out, malloc'd), or -1
 * with errno set. OUT: out */
static long own_members(DIR *d, const char *base, uint64_t **out)
{
    size_t baselen = strlen(base), cap = 0;
    long n = 0;
    uint64_t *v = NULL;
    struct dirent *e;
    errno = 0;
    while ((e = readdir(d)) != NULL) {
        uint64_t num;
        struct stat st;
        if (!member_number(e->d_name, base, baselen, &num)) continue;
        if (fstatat(dirfd(d), e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0) continue; /* gone */
        if (!S_ISREG(st.st_mode) || st.st_uid != geteuid()) continue;
        if ((size_t)n == cap) {
            cap = cap ? 2 * cap : 64;
            uint64_t *g = realloc(v, cap * sizeof *v);
            if (!g) {
                free(v);
                errno = ENOMEM;
                return -1;
            }
            v = g;
        }
        v[n++] = num;
        errno = 0;
    }
    if (errno) {
        free(v);
        return -1;
    }
    if (n > 1) qsort(v, (size_t)n, sizeof *v, cmp_u64);
    *out = v;
    return n;
}

int lag_out_series_prune(const char *what, const char *path, int keep, uint64_t current,
                         int64_t *freed, char *err, size_t errlen)
{
    char dir[4096], name[4096];
    const char *base;
    if (freed) *freed = 0;
    if (!path || keep < 1 || !split_path(path, dir, sizeof dir, &base))
        return refuse(-1, -1, err, errlen, "%s %s: no series to keep", what, path ? path : "");
    DIR *d = opendir(dir);
    uint64_t *v = NULL;
    long n = d ? own_members(d, base, &v) : -1;
    if (n < 0) {
        int e = errno;
        if (d) closedir(d);
        return refuse(-1, -1, err, errlen, "%s %s: cannot read the directory %s: %s", what,
                      path, dir, strerror(e));
    }
    int removed = 0, rc = 0;
    for (long i = 0; i + keep < n; i++) { /* the oldest: all but the newest `keep` */
        struct stat st;
        if (v[i] == current) continue;
        if (lag_out_series_name(base, v[i], name, sizeof name) != 0) continue;
        bool known = fstatat(dirfd(d), name, &st, AT_SYMLINK_NOFOLLOW) == 0;
        if (unlinkat(dirfd(d), name, 0) != 0) {
            if (errno == ENOENT) continue; /* removed meanwhile */
            rc = refuse(-1, -1, err, errlen, "%s %s: cannot remove %s/%s (--keep): %s", what,
                        path, dir, name, strerror(errno));
            break;
        }
        removed++;
        if (freed && known) *freed += (int64_t)st.st_size;
    }
    free(v);
    closedir(d);
    return rc < 0 ? rc : removed;
}
