"""A multicast port pair of this process's own, for a test's LCM bus (ttl=0: this host).

    sys.path.insert(0, "<source>/tests/common")
    from lcm_port import lcm_url
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")

A plant uses two ports: its URL's (states, status, events, scenes) and the next one
(commands, control requests). On one port every socket gets every datagram, so two tests
on one port hear each other (a flood, a plant another test's lagsimctl would find). A
port pair is taken here by the one rule every test of the suite follows (and
tests/common/lagsim_test.h's lt_lcm_port, for the C tests):

  - an even port P in [20000, 60000), P and P + 1 (or the n ports a test asks for) free:
    a lock file of each, LOCK_DIR/P.lock, LOCK_DIR/P+1.lock, ... (LOCK_DIR:
    $LAGSIM_PORT_LOCK_DIR, else /tmp/lagsim-ports), held with flock(LOCK_EX | LOCK_NB) by
    this process until it ends (the lock goes with the process, however it ends), and no
    UDP socket of this host bound to any of them (/proc/net/udp, /proc/net/udp6: a plant
    someone runs by hand);
  - the search starts at a place drawn from the process id and goes up, wrapping around.

So tests run at once, by one ctest -j or by several people's suites on one machine, never
share a port, whatever their process ids.
"""
import errno
import fcntl
import os

LOCK_DIR = os.environ.get("LAGSIM_PORT_LOCK_DIR", "/tmp/lagsim-ports")
FIRST, END = 20000, 60000   # even ports P of [FIRST, END): pairs P, P + 1
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
    if not os.path.isdir(LOCK_DIR):
        os.makedirs(LOCK_DIR, exist_ok=True)
        try:
            os.chmod(LOCK_DIR, 0o1777)  # every user's tests take their ports here
        except OSError:
            pass
    path = os.path.join(LOCK_DIR, "%d.lock" % port)
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        os.close(fd)
        if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
            return None
        raise
    return fd


def lcm_port(n=2):
    """An even port P with P .. P + n - 1 this process's own (locked until it ends)."""
    blocks = (END - FIRST) // 2 - (n - 1) // 2
    start = (os.getpid() * 7919) % blocks
    for k in range(blocks):
        p = FIRST + 2 * ((start + k) % blocks)
        ports = range(p, p + n)
        if set(ports) & udp_ports_bound():
            continue
        fds = []
        for q in ports:
            fd = _lock(q)
            if fd is None:
                break
            fds.append(fd)
        if len(fds) == n and not set(ports) & udp_ports_bound():  # none bound meanwhile
            _held.extend(fds)
            return p
        for fd in fds:
            os.close(fd)
    raise RuntimeError("no %d free UDP ports in a row in [%d, %d)" % (n, FIRST, END))


def lcm_url(options=""):
    """udpm://239.255.76.67:P?ttl=0[&OPTIONS] on a port pair of this process's own."""
    return "udpm://%s:%d?ttl=0%s" % (GROUP, lcm_port(), "&" + options if options else "")


if __name__ == "__main__":
    import sys
    # a port for a shell: printed, and held by this process until its standard input closes
    print(lcm_port(), flush=True)
    if "--hold" in sys.argv[1:]:
        sys.stdin.read()
