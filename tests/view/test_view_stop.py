#!/usr/bin/env python3
"""lagsim-view stops cleanly on SIGINT and SIGTERM while browsers hold its event streams.

usage: test_view_stop.py --view VIEW --lagsimd LAGSIMD --config SCENE --types DIR
                         [--tries N] sigint|sigterm

Beside a running lagsimd (a bus of this test's own), N times: a new lagsim-view, three
streams (GET /events) that read and one that never does; once every reading stream has
its first frames (a stream the view has nothing new for is suspended until the next
frame is due), the signal, at a different moment of the frame period each time. Each time
the view must exit 0 (its man page: stopped by a signal) within STOP_WAIT_S, not abort
(libmicrohttpd aborts in MHD_stop_daemon while a connection is suspended: SIGABRT, a core
dump), and end each reading stream properly: the chunked stream's last chunk, then the
connection closed.
"""
import argparse
import os
import select
import signal
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_view_attacks import View, lcm_port, start_daemon, stop, stream_request  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

STOP_WAIT_S = 10.0


def read_until(s, pred, timeout):
    """Reads s until pred(bytes so far) or EOF or the timeout: (bytes, eof)."""
    buf, deadline = b"", time.monotonic() + timeout
    while not pred(buf) and time.monotonic() < deadline:
        r, _, _ = select.select([s], [], [], max(0.0, deadline - time.monotonic()))
        if not r:
            break
        try:
            chunk = s.recv(65536)
        except (ConnectionResetError, socket.timeout):
            return buf, False
        if not chunk:
            return buf, True
        buf += chunk
    return buf, False


def one_try(a, k, sig, prefix, url):
    v = View(a, prefix, ["--url", url, "-q"])
    streams, sleeper = [], None
    try:
        for _ in range(3):
            s = stream_request(v.port, v.hosthdr)
            s.setblocking(False)
            got, _ = read_until(s, lambda b: b.count(b"event: state") >= 2, 15)
            if not check(b"200 OK" in got[:40] and b"event: state" in got,
                         "try %d: a stream has its first frames" % k):
                return
            streams.append(s)
        sleeper = stream_request(v.port, v.hosthdr, rcvbuf=4096)
        # a different moment of the frame period (60 Hz) each try
        time.sleep(0.003 * k)
        v.p.send_signal(sig)
        try:
            rc = v.p.wait(STOP_WAIT_S)
        except subprocess.TimeoutExpired:
            rc = None
        err = v.p.stderr.read()
        check(rc == 0, "try %d: %s: lagsim-view exited with %s (0 expected; -6 is SIGABRT)%s"
              % (k, signal.Signals(sig).name, rc, (": " + err.strip()[-300:]) if rc else ""))
        check("Fatal error" not in err, "try %d: no fatal error from libmicrohttpd" % k)
        for i, s in enumerate(streams):
            tail, eof = read_until(s, lambda b: False, 5)
            check(eof and tail.endswith(b"0\r\n\r\n"),
                  "try %d: stream %d ended with the last chunk and closed (%s, ends %r)"
                  % (k, i, "closed" if eof else "not closed", tail[-12:]))
    finally:
        for s in streams + ([sleeper] if sleeper else []):
            s.close()
        v.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--view", required=True)
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--types")
    ap.add_argument("--tries", type=int, default=6)
    ap.add_argument("case", choices=["sigint", "sigterm"])
    a = ap.parse_args()
    sig = {"sigint": signal.SIGINT, "sigterm": signal.SIGTERM}[a.case]
    prefix = "VIEWSTOP%d" % os.getpid()
    url = "udpm://239.255.76.67:%d?ttl=0" % lcm_port()
    d = start_daemon(a, prefix, url)
    try:
        for k in range(a.tries):
            one_try(a, k, sig, prefix, url)
    finally:
        stop(d)
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
