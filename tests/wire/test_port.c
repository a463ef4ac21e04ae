/*
 * Pairs of UDP ports held by lock files (server/wire/lagsim_port.c), the buses of
 * lagsim-eval and lagsim-sweep: never two holders on one pair, across processes and users,
 * never a pair a socket of this host is bound to, never a hang on a lock file that cannot
 * be one.
 *
 * The cases work in a directory of their own (a lock directory is a parameter) on the
 * ports 61000..61767, 128 a case: above this host's ephemeral ports (32768..60999: an
 * unbound socket that sends is given one), below the tools' 64000..65535, apart from the
 * ranges the other tests draw theirs from (20000..49998). A case whose ports another
 * program binds at the time skips.
 *
 *   test_port [--list | CASE]
 */
#include "lagsim_test.h"

#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lagsim_port.h"

/* Each case its ports: 61000 + 128 k to 61127 + 128 k for the case of arg k, so that cases
 * run at once (ctest -j) do not bind or take each other's. */
static int base = 61000;
#define FIRST base
#define LAST (base + 14) /* 8 pairs */

static char dir[64];

/* A lock directory of the case's own, writable by every user (as /run/lock is). */
static void make_dir(void)
{
    snprintf(dir, sizeof dir, "/tmp/lagsim_test_port.XXXXXX");
    ENSURE(mkdtemp(dir) != NULL);
    ENSURE(chmod(dir, 01777) == 0);
}

static void remove_dir(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ENSURE(system(cmd) == 0);
}

/* Whether no socket of this host is bound to a port of first..last + 1; skipped if not. */
static bool ports_free(int first, int last)
{
    for (int p = first; p <= last + 1; p++)
        if (lag_port_bound(p) != 0) {
            lt_skip("port %d is bound by another program of this host (or /proc/net/udp "
                    "cannot be read)", p);
            return false;
        }
    return true;
}

static int take(unsigned start, lag_port_lease *l)
{
    char err[512];
    int rc = lag_port_take_in(dir, FIRST, LAST, start, l, err, sizeof err);
    if (rc) printf("take: %s\n", err);
    return rc ? -1 : l->port;
}

/* A UDP socket bound to port (IPv6 when v6); its descriptor. */
static int bind_udp(int port, bool v6)
{
    int fd = socket(v6 ? AF_INET6 : AF_INET, SOCK_DGRAM, 0);
    ENSURE(fd >= 0);
    int rc;
    if (v6) {
        struct sockaddr_in6 a = {.sin6_family = AF_INET6, .sin6_port = htons((uint16_t)port),
                                 .sin6_addr = IN6ADDR_LOOPBACK_INIT};
        rc = bind(fd, (struct sockaddr *)&a, sizeof a);
    } else {
        struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port),
                                .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
        rc = bind(fd, (struct sockaddr *)&a, sizeof a);
    }
    ENSUREF(rc == 0, "bind %d: %s", port, strerror(errno));
    return fd;
}

/* The first pair, then the next; a pair let go is taken again; the lock file a regular
 * file every user can open, and it stays. */
static void case_take(int arg)
{
    base = 61000 + 128 * arg;
    if (!ports_free(FIRST, LAST)) return;
    make_dir();
    lag_port_lease a, b, c;
    ENSURE(take(0, &a) == FIRST);
    ENSURE(take(0, &b) == FIRST + 2);  /* this process holds the first: not shared */
    ENSURE(take(3, &c) == FIRST + 6);  /* the search starts at pair 3 */
    lag_port_release(&c);
    ENSURE(take(7, &c) == LAST);       /* pair 7, the last */
    lag_port_release(&c);
    ENSURE(take(8, &c) == FIRST + 4);  /* 8 pairs: pair 8 is pair 0, held, and 1, held */
    lag_port_release(&a);
    ENSURE(a.port == 0 && a.fd == -1);
    lag_port_lease d;
    ENSURE(take(0, &d) == FIRST);      /* let go: free again */
    char path[128];
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, FIRST);
    struct stat st;
    ENSURE(lstat(path, &st) == 0 && S_ISREG(st.st_mode) && (st.st_mode & 0777) == 0644);
    ENSURE(fcntl(d.fd, F_GETFD) & FD_CLOEXEC); /* the programs it starts do not hold it */
    lag_port_release(&b);
    lag_port_release(&c);
    lag_port_release(&d);
    ENSURE(lstat(path, &st) == 0); /* never removed (a second holder could lock a new one) */
    remove_dir();
}

/* A pair another process holds is skipped, and taken once that process ended. */
static void case_held(int arg)
{
    base = 61000 + 128 * arg;
    if (!ports_free(FIRST, LAST)) return;
    make_dir();
    int up[2], down[2];
    ENSURE(pipe(up) == 0 && pipe(down) == 0);
    pid_t pid = fork();
    if (pid == 0) {
        close(down[1]);
        lag_port_lease l;
        char c = take(0, &l) == FIRST ? 'y' : 'n';
        if (write(up[1], &c, 1) != 1) _exit(1);
        if (read(down[0], &c, 1) < 0) _exit(1); /* holds until the parent closes the pipe */
        _exit(0);
    }
    close(down[0]);
    char c = 0;
    ENSURE(read(up[0], &c, 1) == 1 && c == 'y');
    lag_port_lease l;
    ENSURE(take(0, &l) == FIRST + 2);
    close(down[1]);
    int st;
    ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st) && WEXITSTATUS(st) == 0);
    lag_port_lease m;
    ENSURE(take(0, &m) == FIRST);
    lag_port_release(&l);
    lag_port_release(&m);
    remove_dir();
}

/* A pair with a socket bound to either port is skipped (IPv4 and IPv6 sockets). */
static void case_bound(int arg)
{
    base = 61000 + 128 * arg;
    if (!ports_free(FIRST, LAST)) return;
    make_dir();
    int s1 = bind_udp(FIRST, false);         /* the first pair's state port */
    int s2 = bind_udp(FIRST + 3, false);     /* the second pair's command port */
    int s3 = bind_udp(FIRST + 4, true);      /* the third pair's state port, IPv6 */
    ENSURE(lag_port_bound(FIRST) == 1 && lag_port_bound(FIRST + 3) == 1);
    ENSURE(lag_port_bound(FIRST + 4) == 1 && lag_port_bound(FIRST + 1) == 0);
    lag_port_lease l;
    ENSURE(take(0, &l) == FIRST + 6);
    lag_port_release(&l);
    close(s1);
    close(s2);
    close(s3);
    ENSURE(take(0, &l) == FIRST);
    lag_port_release(&l);
    remove_dir();
}

/* Lock files that cannot be one (a symbolic link, a FIFO, a directory) make their pair
 * unusable, never the search hang; none free: an error that says why. */
static void case_unusable(int arg)
{
    base = 61000 + 128 * arg;
    if (!ports_free(FIRST, LAST)) return;
    make_dir();
    char path[128];
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, FIRST);
    ENSURE(symlink("/etc/passwd", path) == 0);
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, FIRST + 2);
    ENSURE(mkfifo(path, 0666) == 0); /* opening it for reading would wait for a writer */
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, FIRST + 4);
    ENSURE(mkdir(path, 0777) == 0);
    alarm(20); /* a hang ends the case, failed */
    lag_port_lease l;
    ENSURE(take(0, &l) == FIRST + 6);
    lag_port_lease more[4];
    for (int i = 0; i < 4; i++) ENSURE(take(0, &more[i]) == FIRST + 8 + 2 * i);
    char err[512];
    lag_port_lease none;
    ENSURE(lag_port_take_in(dir, FIRST, LAST, 0, &none, err, sizeof err) == -1);
    ENSUREF(strstr(err, "5 held") && strstr(err, "3 without a usable lock file"), "%s", err);
    ENSURE(none.port == 0 && none.fd == -1);
    alarm(0);
    lag_port_release(&l);
    for (int i = 0; i < 4; i++) lag_port_release(&more[i]);
    remove_dir();
}

/* n processes (the first half as uid, gid `as` when as > 0) each take k pairs at once,
 * all starting their search at the same pair, and hold them until every one has; the
 * ports they took, through a pipe, into got (n * k of them). */
static void race(int n, int k, uid_t as, int *got)
{
    int up[2], go[2], hold[2];
    ENSURE(pipe(up) == 0 && pipe(go) == 0 && pipe(hold) == 0);
    pid_t pid[16];
    for (int i = 0; i < n; i++) {
        pid[i] = fork();
        if (pid[i] != 0) continue;
        close(go[1]);
        close(hold[1]);
        close(up[0]);
        if (as > 0 && i < n / 2 && (setgid(as) != 0 || setuid(as) != 0)) _exit(3);
        char c;
        if (read(go[0], &c, 1) < 0) _exit(1); /* all start together: at the end of go */
        lag_port_lease l[16];
        int ports[16];
        for (int j = 0; j < k; j++) {
            char err[512];
            ports[j] = lag_port_take_in(dir, FIRST, FIRST + 126, 0, &l[j], err, sizeof err)
                           ? -1 : l[j].port;
        }
        if (write(up[1], ports, (size_t)k * sizeof *ports) != (ssize_t)(k * sizeof *ports))
            _exit(1);
        if (read(hold[0], &c, 1) < 0) _exit(1); /* held until the parent has every port */
        _exit(0);
    }
    close(go[0]);
    close(up[1]);
    close(hold[0]);
    close(go[1]); /* go */
    size_t want = (size_t)(n * k) * sizeof *got, have = 0;
    while (have < want) {
        ssize_t r = read(up[0], (char *)got + have, want - have);
        if (r <= 0) break;
        have += (size_t)r;
    }
    ENSUREF(have == want, "%zu of %zu bytes of ports", have, want);
    close(up[0]);
    close(hold[1]); /* let go */
    for (int i = 0; i < n; i++) {
        int st;
        ENSURE(waitpid(pid[i], &st, 0) == pid[i] && WIFEXITED(st) && WEXITSTATUS(st) == 0);
    }
}

/* Concurrent takers never share a pair: 8 processes taking 6 pairs each at once from one
 * starting pair, 20 times. */
static void check_race(uid_t as)
{
    for (int round = 0; round < 20; round++) {
        int got[8 * 6];
        for (int i = 0; i < 8 * 6; i++) got[i] = -1;
        race(8, 6, as, got);
        int dup = 0, bad = 0;
        for (int i = 0; i < 8 * 6; i++) {
            bad += got[i] < FIRST || got[i] > FIRST + 126 || got[i] % 2;
            for (int j = 0; j < i; j++) dup += got[i] == got[j];
        }
        ENSUREF(!dup && !bad, "round %d: %d pairs taken twice, %d not a pair of the range",
                round, dup, bad);
    }
}

static void case_concurrent(int arg)
{
    base = 61000 + 128 * arg;
    if (!ports_free(FIRST, FIRST + 126)) return;
    make_dir();
    check_race(0);
    remove_dir();
}

/* The same across users: half the processes as nobody (65534), in a directory of every
 * user's; a lock file one user made is locked by the other once it is free. Needs root. */
static void case_users(int arg)
{
    base = 61000 + 128 * arg;
    if (geteuid() != 0) {
        lt_skip("needs root to run processes as another user");
        return;
    }
    if (!ports_free(FIRST, FIRST + 126)) return;
    make_dir();
    check_race(65534);
    /* every pair's lock file was made by one user or the other; all free now: root takes
     * them all, opening nobody's files too */
    int mine = 0;
    lag_port_lease l[64];
    char err[512];
    for (int i = 0; i < 64; i++)
        mine += lag_port_take_in(dir, FIRST, FIRST + 126, 0, &l[i], err, sizeof err) == 0;
    ENSUREF(mine == 64, "root took %d of 64 pairs", mine);
    int others = 0;
    for (int p = FIRST; p <= FIRST + 126; p += 2) {
        char path[128];
        struct stat st;
        snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, p);
        others += stat(path, &st) == 0 && st.st_uid == 65534;
    }
    ENSUREF(others > 0, "no lock file made by nobody (the race had root make them all)");
    for (int i = 0; i < 64; i++) lag_port_release(&l[i]);
    remove_dir();
}

/* The host's own: an even state port of the tools' range, its lock file in the host's
 * lock directory. */
static void case_host(int arg)
{
    (void)arg;
    lag_port_lease l;
    char err[512];
    ENSUREF(lag_port_take(&l, err, sizeof err) == 0, "%s", err);
    ENSURE(l.port >= LAG_PORT_FIRST && l.port <= LAG_PORT_LAST && l.port % 2 == 0);
    char path[128];
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", LAG_PORT_LOCK_DIR, l.port);
    struct stat st;
    ENSURE(access(LAG_PORT_LOCK_DIR, W_OK) != 0 || lstat(path, &st) == 0);
    lag_port_release(&l);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"take", case_take, 0, 0},       {"held", case_held, 1, 0},
        {"bound", case_bound, 2, 0},     {"unusable", case_unusable, 3, 0},
        {"concurrent", case_concurrent, 4, 0}, {"users", case_users, 5, 0},
        {"host", case_host, 0, 0},
    };
    return lt_main(argc, argv, cases, sizeof cases / sizeof cases[0]);
}
