#!/usr/bin/env python3
"""The Python LCM binding (clients/python/lagsim_lcm.py) behaves as LCM's bindings do.

In-process (memq://), no network:
  - subscribe() takes LCM's regular expressions: "RX_.*" receives RX_A and RX_B, not QX_A;
    a plain name matches only itself (anchored: "RX_A" does not receive "RX_AB");
  - an exception in a handler is raised again by the handle_timeout() / handle() call
    that ran it (type and message intact), and the LCM works afterwards;
  - unsubscribe() stops delivery.
And on udpm:// (a port from the process id, ttl=0): a signal whose Python handler runs
while handle_timeout() waits ends the wait (False) and the handler runs, as the C client's
lag_client_handle; it raised LCMError, so a controller's SIGTERM handler ended in a
traceback instead of its summary.
usage: test_python_lcm.py CLIENTS_PYTHON_DIR
"""
import os
import signal
import sys
import threading
import time

sys.path.insert(0, sys.argv[1])
from lagsim_lcm import LCM  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def drain(lc):
    n = 0
    while lc.handle_timeout(0):
        n += 1
    return n


lc = LCM("memq://")
got = []
sub = lc.subscribe("RX_.*", lambda ch, data: got.append((ch, data)))
exact = []
lc.subscribe("RX_A", lambda ch, data: exact.append(ch))
for ch in ("RX_A", "RX_B", "QX_A", "RX_AB"):
    lc.publish(ch, ch.encode())
drain(lc)
check(sorted(c for c, _ in got) == ["RX_A", "RX_AB", "RX_B"],
      "'RX_.*' receives RX_A, RX_AB, RX_B and not QX_A (got %s)" % [c for c, _ in got])
check(got and all(d == c.encode() for c, d in got), "payloads arrive intact")
check(exact == ["RX_A"], "'RX_A' receives RX_A only (got %s)" % exact)


class Boom(Exception):
    pass


def bad(ch, data):
    raise Boom("handler failed on " + ch)


bad_sub = lc.subscribe("BAD", bad)
lc.publish("BAD", b"x")
try:
    lc.handle_timeout(100)
    check(False, "an exception in a handler reaches the caller of handle_timeout()")
except Boom as e:
    check(str(e) == "handler failed on BAD",
          "an exception in a handler reaches the caller of handle_timeout() (%s)" % e)
lc.publish("BAD", b"x")
try:
    lc.handle()
    check(False, "an exception in a handler reaches the caller of handle()")
except Boom:
    check(True, "an exception in a handler reaches the caller of handle()")
lc.unsubscribe(bad_sub)
got.clear()
lc.publish("RX_C", b"y")
lc.publish("BAD", b"x")
n = drain(lc)
check(got == [("RX_C", b"y")] and n >= 1, "after a failed handler the LCM keeps working")

lc.unsubscribe(sub)
got.clear()
lc.publish("RX_D", b"z")
drain(lc)
check(got == [], "unsubscribe() stops delivery")
lc.close()

# a signal during the wait: handle_timeout() returns False, the handler has run
seen = []
signal.signal(signal.SIGUSR1, lambda signum, frame: seen.append(signum))
udp = LCM(lcm_url())  # a port pair of this process's own
udp.subscribe("NOTHING_COMES", lambda ch, data: None)
main = threading.get_ident()
threading.Thread(target=lambda: (time.sleep(0.2), signal.pthread_kill(main, signal.SIGUSR1)),
                 daemon=True).start()
t0 = time.monotonic()
try:
    got_one = udp.handle_timeout(5000)
    check(not got_one and seen == [signal.SIGUSR1] and time.monotonic() - t0 < 4,
          "a signal ends handle_timeout()'s wait with False, its handler run (%s after %.2f s)"
          % (seen, time.monotonic() - t0))
except Exception as e:
    check(False, "a signal ends handle_timeout()'s wait with False, not %r" % e)
udp.close()
sys.exit(verdict())
