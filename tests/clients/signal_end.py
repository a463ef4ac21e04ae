#!/usr/bin/env python3
"""How a run ends on a signal (docs/clients.md, "How a run ends"): a controller given
SIGINT or SIGTERM ends with `end=signal`, its summary line and exit status 0, both while
it waits for its scene (no daemon on its prefix) and in the middle of a run.

    signal_end.py --lagsimd BIN --config YAML [--set K=V ...] [--wait S] -- CLIENT ARGS...

"{prefix}" in the client's arguments is replaced by a prefix of this run's own, and
LCM_DEFAULT_URL gets a multicast port of its own (run_e2e.py's rule). For each of SIGINT
and SIGTERM, twice: the controller is started and, once it says it waits for the scene,
(1) signalled there, or (2) the daemon is started (lockstep, no end of its own) and the
controller signalled once the plant has published 20 states (each one answered: lockstep
advances only on answers). The controller must end within --wait wall s of the signal.
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_e2e import hostile_lcm, parse_summary  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import waits  # noqa: E402  (events waited on, bounded)
from lagsim_check import stop  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def one(a, client, sig, mid_run, n):
    prefix = "SIGEND%d_%d" % (os.getpid(), n)
    env = dict(os.environ)
    env["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")  # a pair of this run's own
    cmd = [c.replace("{prefix}", prefix) for c in client]
    what = "%s %s" % (signal.Signals(sig).name, "mid-run" if mid_run else "waiting for the scene")
    print("---- %s: %s" % (what, " ".join(cmd)), flush=True)
    cproc = dproc = None
    lines, states = [], []
    try:
        cproc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 universal_newlines=True, env=env)
        rd = waits.Reader(cproc, lines)
        ready, th = rd.ready, rd.thread
        if not ready.wait(30.0) or cproc.poll() is not None:
            return ["%s: the client did not get ready (%s)" % (what, "".join(lines)[-500:])]
        if mid_run:
            lc = hostile_lcm(env["LCM_DEFAULT_URL"])
            lc.subscribe(prefix + "_STATE", lambda ch, data: states.append(data))
            dproc = subprocess.Popen([a.lagsimd, "--config", a.config, "--set",
                                      "lcm.prefix=" + prefix, "--set", "realtime.mode=lockstep",
                                      "-q"] + [x for v in a.set for x in ("--set", v)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     env=env)
            deadline = time.monotonic() + 30
            while len(set(states)) < 20 and time.monotonic() < deadline:
                lc.handle_timeout(50)
            if len(set(states)) < 20:
                return ["%s: the run did not advance (%d states)" % (what, len(set(states)))]
        else:
            time.sleep(0.5)  # inside its wait
        cproc.send_signal(sig)
        t0 = time.monotonic()
        try:
            cproc.wait(timeout=a.wait)
        except subprocess.TimeoutExpired:
            return ["%s: still running %g s after the signal" % (what, a.wait)]
        wall = time.monotonic() - t0
        th.join(5.0)
        err = cproc.stderr.read()
    finally:
        stop(cproc, 3.0)
        stop(dproc, 3.0)
    out = "".join(lines)
    sys.stdout.write(out[-600:])
    if err.strip():
        sys.stdout.write("client stderr:\n" + err[-1500:])
    vals = parse_summary(out) or {}
    fails = []
    if cproc.returncode != 0:
        fails.append("%s: exit status %d, not 0" % (what, cproc.returncode))
    if vals.get("end") != "signal":
        fails.append("%s: summary end=%s, not signal" % (what, vals.get("end")))
    st = vals.get("states")
    if mid_run and not (isinstance(st, float) and st >= 1):
        fails.append("%s: states=%s in the summary, not >= 1" % (what, st))
    if not mid_run and st != 0:
        fails.append("%s: states=%s in the summary, not 0" % (what, st))
    if re.search(r"Traceback|Exception|stack traceback", err):
        fails.append("%s: a traceback on stderr" % what)
    print("%s: ended %.2f s after the signal, exit %d, summary end=%s states=%s"
          % (what, wall, cproc.returncode, vals.get("end"), st))
    return fails


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--wait", type=float, default=10.0)
    ap.add_argument("client", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    client = a.client[1:] if a.client and a.client[0] == "--" else a.client
    if not client:
        ap.error("no client command")
    fails, n = [], 0
    for sig in (signal.SIGINT, signal.SIGTERM):
        for mid_run in (False, True):
            n += 1
            fails += one(a, client, sig, mid_run, n)
    for f in fails:
        print("FAIL: " + f)
    print("%d passed, %d failed" % (4 - len({f.split(":")[0] for f in fails}),
                                     len({f.split(":")[0] for f in fails})))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
