#!/usr/bin/env python3
"""Tools find the plant: lagsimctl list, and every program without --prefix.

    test_discover.py --bin BUILD/bin --source SRC

On a multicast port of this run's own, three daemons: a cart-pole waiting for its first
command (prefix CP_<pid>), a paused stick (ST_<pid>) and a DIPC waiting for its first
command (DP_<pid>). Then:
  lagsimctl list            exit 0, a table with all three: prefix, model, mode, run
                            state, host (this host's name), URL (the state URL)
  lagsimctl --json list     the same as JSON: cartpole waiting, stick paused, realtime
  lagsimctl status          (no --prefix, three plants) exit 2, all named, "--prefix"
  lqr_balance               (no --prefix, three plants) exit 2, all named
  dipc_lqr --duration 0.2   (no --prefix) takes the only DIPC, exit 0
  dipc_balance.py           (Python, no --prefix) the same
  manipulator_pd --timeout 1  (no --prefix, no manipulator) says there is none, names
                            the plants heard, waits on MANIPULATOR, exit 1 (no scene)
The stick and the DIPC are stopped; then, one plant on the bus, and junk published on
NOTAPLANT_<pid>_STATE (a channel that looks like a plant's):
  lagsimctl status          exit 0: the cart-pole's status (run_state waiting)
  lagsimctl list            NOTAPLANT_<pid> listed without a model ('?')
  lqr_balance --duration 1  exit 0: it took the cart-pole (its design line names CP_<pid>)
  lagsim-view --port 0      serves the cart-pole: its address line names CP_<pid>
and on a port with no plant, lagsimctl list exits 3 saying so.
"""
import argparse
import json
import os
import socket
import subprocess
import sys
import threading
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def run(args, timeout=60):
    r = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    print("$ %s %s   -> exit %d" % (os.path.basename(args[0]), " ".join(args[1:]), r.returncode))
    for line in r.stdout.splitlines()[:6]:
        print("  " + line[:200])
    if r.stderr.strip():
        print("  stderr: " + r.stderr.strip()[:400])
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    b = lambda p: os.path.join(a.bin, p)
    pid = os.getpid()
    cp, st, dp = "CP_%d" % pid, "ST_%d" % pid, "DP_%d" % pid
    url = lcm_url()
    os.environ["LCM_DEFAULT_URL"] = url
    daemons = {}
    for prefix, cfg, start in ((cp, "cartpole.yaml", "first_command"), (st, "stick.yaml", "paused"),
                               (dp, "dipc.yaml", "first_command")):
        daemons[prefix] = subprocess.Popen(
            [b("lagsimd"), "--config", os.path.join(a.source, "config", cfg), "-q",
             "--set", "lcm.prefix=" + prefix, "--set", "realtime.start=" + start],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for prefix in daemons:  # each answers (waited on, bounded), then all are listed
            check(waits.daemon_answers(b("lagsimctl"), prefix), "lagsimd %s answers" % prefix)
        r = run([b("lagsimctl"), "list"])
        rows = {l.split()[0]: l.split() for l in r.stdout.splitlines()[1:] if l.split()}
        check(r.returncode == 0 and r.stdout.split()[:4] == ["PREFIX", "MODEL", "MODE", "RUN"]
              and cp in rows and st in rows and dp in rows,
              "list: exit 0, a table with the three plants")
        r = run([b("lagsimctl"), "--json", "list"])
        try:
            plants = {p["prefix"]: p for p in json.loads(r.stdout)}
        except ValueError:
            plants = {}
        host = socket.gethostname()
        want = {cp: ("cartpole", "waiting"), st: ("stick", "paused"), dp: ("dipc", "waiting")}
        for prefix, (model, state) in want.items():
            p = plants.get(prefix, {})
            check(p.get("model") == model and p.get("run_state") == state and
                  p.get("mode") == "realtime" and p.get("host") == host and p.get("url") == url,
                  "list --json: %s is a %s, %s, realtime, on %s, at %s (%s)"
                  % (prefix, model, state, host, url, p))
        check(len(plants) == 3, "list --json: exactly the three plants (%d)" % len(plants))

        r = run([b("lagsimctl"), "status"])
        check(r.returncode == 2 and all(p in r.stderr for p in (cp, st, dp)) and
              "--prefix" in r.stderr,
              "status without --prefix, three plants: exit 2, all named, --prefix suggested")
        r = run([b("lqr_balance"), "--duration", "0.5"])
        check(r.returncode == 2 and all(p in r.stderr for p in (cp, st, dp)),
              "lqr_balance without --prefix, three plants: exit 2, all named")
        r = run([b("dipc_lqr"), "--duration", "0.2", "-q"])
        check(r.returncode == 0 and ("prefix %s" % dp) in r.stdout and "end=duration" in r.stdout,
              "dipc_lqr without --prefix: takes the only DIPC, %s" % dp)
        py = os.path.join(a.source, "clients", "python", "dipc_balance.py")
        r = run([sys.executable, py, "--types", os.path.join(os.path.dirname(a.bin), "python"),
                 "--duration", "0.2", "-q"])
        check(r.returncode == 0 and ("prefix %s" % dp) in r.stdout and "end=duration" in r.stdout,
              "dipc_balance.py (Python) without --prefix: takes the only DIPC, %s" % dp)
        r = run([b("manipulator_pd"), "--timeout", "1"])
        check(r.returncode == 1 and "no manipulator plant" in r.stdout and cp in r.stdout and
              "waiting for prefix MANIPULATOR" in r.stdout,
              "manipulator_pd without --prefix, no manipulator: says so, names the plants "
              "heard, waits on MANIPULATOR")

        for p in (st, dp):
            daemons[p].terminate()
            daemons[p].wait(10)
        time.sleep(0.3)
        # another program's channel that looks like a plant's, junk on it: not a plant
        sys.path.insert(0, os.path.join(os.path.dirname(a.bin), "python"))
        from lagsim_lcm import LCM
        junk_stop = threading.Event()

        def junk():
            lc = LCM(url)
            while not junk_stop.wait(0.05):
                lc.publish("NOTAPLANT_%d_STATE" % pid, b"\x00" * 40)
            lc.close()

        jt = threading.Thread(target=junk)
        jt.start()
        try:
            r = run([b("lagsimctl"), "status"])
            check(r.returncode == 0 and any(l.split() == ["run_state", "waiting"]
                                            for l in r.stdout.splitlines()),
                  "status without --prefix, one plant (and junk on NOTAPLANT_STATE): exit 0, "
                  "its status (waiting)")
            r = run([b("lagsimctl"), "list"])
            rows = {l.split()[0]: l.split() for l in r.stdout.splitlines()[1:] if l.split()}
            check(rows.get("NOTAPLANT_%d" % pid, [None, None])[1] == "?" and cp in rows,
                  "list: a channel that only looks like a plant's has no model ('?')")
        finally:
            junk_stop.set()
            jt.join()
        r = run([b("lqr_balance"), "--duration", "1", "-q"])
        check(r.returncode == 0 and ("prefix %s" % cp) in r.stdout and "summary" in r.stdout,
              "lqr_balance without --prefix, one plant: balances the cart-pole %s" % cp)
        v = subprocess.Popen([b("lagsim-view"), "--port", "0", "-q"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, universal_newlines=True)
        line = v.stdout.readline()
        v.terminate()
        v.wait(10)
        print("  lagsim-view: " + line.strip())
        check("(prefix %s)" % cp in line, "lagsim-view without --prefix: serves %s" % cp)
    finally:
        for d in daemons.values():
            if d.poll() is None:
                d.terminate()
                d.wait(10)
    os.environ["LCM_DEFAULT_URL"] = lcm_url()  # another port of its own: a bus with no plant
    r = run([b("lagsimctl"), "--timeout", "0.5", "list"])
    check(r.returncode == 3 and "no plant heard" in r.stderr,
          "list with no plant on the bus: exit 3, said")
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
