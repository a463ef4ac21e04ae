"""A multicast port pair of this process's own, for a test's LCM bus (ttl=0: this host).

    sys.path.insert(0, "<source>/tests/common")
    from lcm_port import lcm_url
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")

A plant uses two ports: its URL's (states, status, events, scenes) and the next one
(commands, control requests). On one port every socket gets every datagram, so two tests
on one port hear each other (a flood, a plant another test's lagsimctl would find). The
pairs are held as lagsim-eval and lagsim-sweep hold theirs (server/wire/lagsim_port.h),
with the same lock files, so that no test and no tool ever share a pair; tests take theirs
from another range (tests/common/lagsim_test.h's lt_lcm_ports does the same in C):

  - a pair P, P + 1 (P even, in [20000, 60000) below the kernel's ephemeral ports, from
    32768 by default; the tools use 64000 and up), or the n
    ports P .. P + n - 1 a test asks for, pair by pair;
  - held by an exclusive flock on the pair's lock file LOCK_DIR/lagsim-udp-P.lock
    (LOCK_DIR: the first of /run/lock, /var/lock, /tmp that exists), opened read-only
    (every user can lock a file another made) and created if missing, never removed; the
    lock goes with the process, however it ends (close-on-exec: not with its children);
  - no UDP socket of this host bound to any of the ports (/proc/net/udp, /proc/net/udp6: a
    plant someone runs by hand);
  - the search starts at a place drawn from the process id and goes up, wrapping around.

So tests run at once, by one ctest -j or by several people's suites on one machine, never
share a port, whatever their process ids.
"""
import errno
import os
import stat

LOCK_DIR = next((d for d in ("/run/lock", "/var/lock", "/tmp") if os.path.isdir(d)), "/tmp")
FIRST, END = 20000, 60000   # even ports P of [FIRST, END): pairs P, P + 1 ...


def _ephemeral_low():
    """The first port the kernel hands out to sockets bound to none (a sender's socket):
    a port taken that way is bound without SO_REUSEADDR, and a bus on it fails to bind
    (seen: "bind: Address already in use" on 50091). The range ends below it."""
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
            return int(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        return 32768


END = max(FIRST + 2000, min(END, _ephemeral_low()))
GROUP = "239.255.76.67"     # LCM's default multicast group

_held = []  # the lock files of the pairs this process took: open until it ends


def udp_ports_bound():
    """The local UDP ports of this host's sockets (every network namespace's view is its
    own: this one's)."""
    ports = set()
    for path in ("/proc/net/udp", "/proc/net/udp6"):
        try:
            with open(path) as f:
                next(f, None)
                for line in f:
                    local = line.split()[1]           # ADDR:PORT, hexadecimal
                    ports.add(int(local.rsplit(":", 1)[1], 16))
        except OSError:
            pass
    return ports


def _lock(port):
    """The pair at `port` (even) held: its lock file's descriptor, or None when another
    holds it or no lock file can be had."""
    import fcntl
    path = os.path.join(LOCK_DIR, "lagsim-udp-%d.lock" % port)
    flags = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
    try:
        try:
            fd = os.open(path, flags)
        except FileNotFoundError:
            try:
                fd = os.open(path, flags | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                fd = os.open(path, flags)  # another made it meanwhile
    except OSError:
        return None  # a symbolic link, a file we may not read: this pair is not usable
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise OSError(errno.EINVAL, "not a regular file")
        if st.st_uid == os.geteuid() and st.st_mode & 0o444 != 0o444:
            os.fchmod(fd, 0o644)  # readable by every user, whatever the umask
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def lcm_port(n=2):
    """An even port P with P .. P + n - 1 this process's own (held until it ends)."""
    pairs = (n + 1) // 2
    blocks = (END - FIRST) // 2 - (pairs - 1)
    start = (os.getpid() * 7919) % blocks
    for k in range(blocks):
        p = FIRST + 2 * ((start + k) % blocks)
        ports = set(range(p, p + 2 * pairs))
        if ports & udp_ports_bound():
            continue
        fds = []
        for q in range(p, p + 2 * pairs, 2):
            fd = _lock(q)
            if fd is None:
                break
            fds.append(fd)
        if len(fds) == pairs and not ports & udp_ports_bound():  # none bound meanwhile
            _held.extend(fds)
            return p
        for fd in fds:
            os.close(fd)
    raise RuntimeError("no %d free UDP ports in a row in [%d, %d)" % (n, FIRST, END))


def lcm_url(options=""):
    """udpm://239.255.76.67:P?ttl=0[&OPTIONS] on a port pair of this process's own."""
    return "udpm://%s:%d?ttl=0%s" % (GROUP, lcm_port(), "&" + options if options else "")


def lcm_urls(options=""):
    """lcm_url's pair as a plant whose lcm.url is the first uses it: (state URL, command
    URL), the command URL the same group and options on the next port, for a test that
    listens to both: the client library's rule (lag_client_plant_urls), written here for
    run_e2e.py, which also runs against installed and packaged trees where this build's
    library cannot be loaded; net_plant_urls_python fails when the two disagree."""
    port, opts = lcm_port(), "&" + options if options else ""
    return tuple("udpm://%s:%d?ttl=0%s" % (GROUP, p, opts) for p in (port, port + 1))


if __name__ == "__main__":
    import sys
    # a port for a shell: printed, and held by this process until its standard input closes
    print(lcm_port(), flush=True)
    if "--hold" in sys.argv[1:]:
        sys.stdin.read()
