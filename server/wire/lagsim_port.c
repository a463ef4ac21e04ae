/*
 * A pair of UDP ports held by a lock file: see lagsim_port.h.
 */
#include "lagsim_port.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#define BOUND_BYTES (65536 / 8)

/* Marks in `bound` (a bit a port) every port a UDP socket of this host is bound to, from
 * /proc/net/udp and /proc/net/udp6 ("  12: 0100007F:FA00 00000000:0000 07 ...": the local
 * address, a colon, the port in hex). 0, or -1 when neither file can be read. */
static int read_bound(unsigned char bound[BOUND_BYTES])
{
    static const char *const files[] = {"/proc/net/udp", "/proc/net/udp6"};
    int read = 0;
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        FILE *f = fopen(files[i], "re");
        if (!f) continue;
        read++;
        char line[512];
        bool header = true;
        while (fgets(line, sizeof line, f)) {
            if (header) { /* the column titles */
                header = false;
                continue;
            }
            const char *sl = strchr(line, ':');              /* after the slot number */
            const char *pc = sl ? strchr(sl + 1, ':') : NULL; /* after the local address */
            unsigned port;
            if (pc && sscanf(pc + 1, "%4x", &port) == 1 && port < 65536)
                bound[port / 8] |= (unsigned char)(1u << (port % 8));
        }
        fclose(f);
    }
    return read ? 0 : -1;
}

static bool is_bound(const unsigned char bound[BOUND_BYTES], int port)
{
    return bound[port / 8] & (1u << (port % 8));
}

int lag_port_bound(int port)
{
    unsigned char bound[BOUND_BYTES] = {0};
    if (port < 0 || port > 65535 || read_bound(bound) != 0) return -1;
    return is_bound(bound, port);
}

/* The lock file of the pair at `port` in dir, opened (created when it is not there) and
 * locked without waiting: its descriptor, or -1 with *why 0 (another holds it) or an errno
 * (no lock file can be had there: a symbolic link, a FIFO, a file we may not read, a
 * directory we may not write). An existing file is opened without O_CREAT: in a sticky
 * directory with fs.protected_regular a creating open of another user's file is refused. */
static int lock_pair(const char *dir, int port, int *why)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, port);
    const int flags = O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC;
    int fd = open(path, flags);
    if (fd < 0 && errno == ENOENT) fd = open(path, flags | O_CREAT | O_EXCL, 0644);
    if (fd < 0 && errno == EEXIST) fd = open(path, flags); /* another made it meanwhile */
    if (fd < 0) return *why = errno, -1;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return *why = EINVAL, -1;
    }
    /* readable by every user, whatever the umask of the one who made it */
    if (st.st_uid == geteuid() && (st.st_mode & 0444) != 0444) (void)fchmod(fd, 0644);
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        close(fd);
        return *why = e == EWOULDBLOCK ? 0 : e, -1;
    }
    return fd;
}

/* What the search found when no pair was free. */
typedef struct search {
    int held, bound, unusable, last_errno;
} search;

/* The pair at `port`, locked and then found unbound (a socket bound since /proc was read
 * first counts too): its descriptor, or -1 with the reason counted in s. */
static int try_pair(const char *dir, int port, const unsigned char *bound, search *s)
{
    if (is_bound(bound, port) || is_bound(bound, port + 1)) return s->bound++, -1;
    int why = 0;
    int fd = lock_pair(dir, port, &why);
    if (fd < 0) {
        if (why) s->unusable++, s->last_errno = why;
        else s->held++;
        return -1;
    }
    if (lag_port_bound(port) == 1 || lag_port_bound(port + 1) == 1) {
        close(fd);
        return s->bound++, -1;
    }
    return fd;
}

int lag_port_take_in(const char *dir, int first, int last, unsigned start, lag_port_lease *l,
                     char *err, size_t errlen)
{
    l->port = 0;
    l->fd = -1;
    if (first < 2 || last > 65534 || first > last || first % 2 || last % 2) {
        snprintf(err, errlen, "lag_port_take_in: a range of even state ports from 2 to 65534 "
                 "expected, got %d..%d", first, last);
        return -1;
    }
    unsigned char bound[BOUND_BYTES] = {0};
    (void)read_bound(bound); /* unreadable: the locks alone */
    unsigned n = (unsigned)(last - first) / 2 + 1;
    search s = {0};
    for (unsigned i = 0; i < n; i++) {
        int port = first + 2 * (int)((start + i) % n);
        int fd = try_pair(dir, port, bound, &s);
        if (fd >= 0) {
            l->port = port;
            l->fd = fd;
            return 0;
        }
    }
    snprintf(err, errlen, "no free pair of UDP ports from %d to %d: %d held by other lagsim "
             "tools, %d bound by programs of this host, %d without a usable lock file in %s%s%s",
             first, last + 1, s.held, s.bound, s.unusable, dir, s.unusable ? ": " : "",
             s.unusable ? strerror(s.last_errno) : "");
    return -1;
}

/* The host's directory of lock files: the first of these that exists. */
static const char *lock_dir(void)
{
    static const char *const dirs[] = {LAG_PORT_LOCK_DIR, "/var/lock", "/tmp"};
    for (size_t i = 0; i < sizeof dirs / sizeof dirs[0]; i++) {
        struct stat st;
        if (stat(dirs[i], &st) == 0 && S_ISDIR(st.st_mode)) return dirs[i];
    }
    return dirs[sizeof dirs / sizeof dirs[0] - 1];
}

/* Knuth's multiplicative hash of the pid: holders started one after another start their
 * searches far apart */
static unsigned pid_start(void) { return (unsigned)getpid() * 2654435761u >> 16; }

int lag_port_take(lag_port_lease *l, char *err, size_t errlen)
{
    return lag_port_take_in(lock_dir(), LAG_PORT_FIRST, LAG_PORT_LAST, pid_start(), l, err,
                            errlen);
}

int lag_port_take_block(int n, lag_port_lease *l, char *err, size_t errlen)
{
    const char *dir = lock_dir();
    const unsigned pairs = (LAG_PORT_LAST - LAG_PORT_FIRST) / 2 + 1;
    unsigned start = pid_start();
    for (int k = 0; k < n; k++) l[k] = (lag_port_lease){0, -1};
    for (unsigned tries = 0; n >= 1 && tries < pairs; tries++) {
        if (lag_port_take_in(dir, LAG_PORT_FIRST, LAG_PORT_LAST, start, &l[0], err, errlen) != 0)
            return -1;
        int k = 1;
        for (; k < n; k++) {
            int p = l[0].port + 2 * k;
            if (p > LAG_PORT_LAST || lag_port_take_in(dir, p, p, 0, &l[k], err, errlen) != 0) break;
        }
        if (k == n) return 0;
        int first = l[0].port;
        for (int j = 0; j < k; j++) lag_port_release(&l[j]);
        /* on after the pair that was not free */
        start = (unsigned)((first - LAG_PORT_FIRST) / 2 + k + 1) % pairs;
    }
    snprintf(err, errlen, "no %d consecutive free port pairs in %d..%d", n, LAG_PORT_FIRST,
             LAG_PORT_LAST + 1);
    return -1;
}

void lag_port_release(lag_port_lease *l)
{
    if (l->fd >= 0) close(l->fd);
    l->fd = -1;
    l->port = 0;
}
