#!/usr/bin/env python3
"""A language's controller given --prefix alone finds its plant on a lab host.

    host_prefix.py --bin BUILD/bin --source SRC --scene config/dipc.yaml LANG -- CONTROLLER ARGS...

A host of two plants (lagsimd --plants: alice.yaml and bob.yaml, both SCENE in lockstep,
each on a port pair of its own from --port-base) keeps its directory on LCM_DEFAULT_URL's
bus, a pair of this test's own. The controller (CONTROLLER ARGS..., given --prefix ALICE
and no --url; LCM_DEFAULT_URL the directory's bus, as on the host) must ask the directory
where ALICE runs (lag_client_locate, or Java's Locate for Java and MATLAB/Octave), say so
("prefix ALICE runs on URL (the host's directory)"), and drive ALICE there: it ends its
--duration with exit 0, ALICE took its commands and advanced (lockstep advances only on
them), BOB took none and stayed at t = 0. A controller that does not ask the directory
gets ALICE's scene there (the directory answers DESCRIBE with it) and then waits for
states that never come there: ALICE takes no command.

Exit 0 when every check held, 1 otherwise.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_port  # noqa: E402


def url(port):
    return "udpm://239.255.76.67:%d?ttl=0" % port


def status(a, env, prefix, port):
    """The plant's status (lagsimctl --json status on its own URL), or {}."""
    p = subprocess.run([os.path.join(a.bin, "lagsimctl"), "--json", "--url", url(port),
                        "--prefix", prefix, "--timeout", "10", "status"], capture_output=True,
                       text=True,
                       timeout=60, env=env)
    for line in p.stdout.splitlines():
        try:
            m = json.loads(line)
        except ValueError:
            continue
        if m.get("type") == "status":
            return m
    print("lagsimctl status %s: exit %d\n%s%s" % (prefix, p.returncode, p.stdout, p.stderr))
    return {}


def started(host, err, prefixes, seconds):
    """Waits until the host said every plant started (its stderr), or it ended."""
    end = time.monotonic() + seconds
    while time.monotonic() < end and host.poll() is None:
        err.seek(0)
        text = err.read()
        if all(("%s: event start" % p) in text for p in prefixes):
            return True
        time.sleep(0.1)
    return False


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--timeout", type=float, default=120.0, help="the controller's wall s")
    ap.add_argument("lang")
    ap.add_argument("controller", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    if a.controller[:1] == ["--"]:
        a.controller = a.controller[1:]
    base = lcm_port(6)  # the directory's pair, then ALICE's and BOB's
    directory, alice, bob = base, base + 2, base + 4
    env = dict(os.environ, LCM_DEFAULT_URL=url(directory))
    scene = open(a.scene).read()
    with tempfile.TemporaryDirectory() as d:
        lab = os.path.join(d, "lab")
        os.mkdir(lab)
        for name in ("alice", "bob"):
            open(os.path.join(lab, name + ".yaml"), "w").write(scene)
        err = tempfile.TemporaryFile(mode="w+")
        host = subprocess.Popen([os.path.join(a.bin, "lagsimd"), "--plants", lab, "--port-base",
                                 str(alice), "--set", "realtime.mode=lockstep"],
                                stdout=subprocess.DEVNULL, stderr=err, env=env)
        try:
            check(started(host, err, ("ALICE", "BOB"), 30), "the host started ALICE and BOB")
            print("$ %s" % " ".join(a.controller), flush=True)
            try:
                p = subprocess.run(a.controller, capture_output=True, text=True, env=env,
                                   timeout=a.timeout)
                out, rc = p.stdout + p.stderr, p.returncode
            except subprocess.TimeoutExpired as e:
                out = (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
                rc = None
            print("".join("  | %s\n" % ln for ln in out.splitlines()[-15:]), flush=True)
            said = "prefix ALICE runs on %s (the host's directory)" % url(alice)
            check(said in out, "%s says where ALICE runs: '%s'" % (a.lang, said))
            check(rc == 0 and "end=duration" in out,
                  "%s ran its --duration on ALICE and exited 0 (exit %s)" % (a.lang, rc))
            sa, sb = status(a, env, "ALICE", alice), status(a, env, "BOB", bob)
            check(sa.get("commands_accepted", 0) > 0 and sa.get("sim_time", 0) >= 1.0,
                  "ALICE took the controller's commands and advanced (%s commands, sim time "
                  "%s s)" % (sa.get("commands_accepted"), sa.get("sim_time")))
            check(sb.get("commands_accepted", -1) == 0 and sb.get("sim_time", -1) == 0,
                  "BOB took none and waits at t = 0 (%s commands, sim time %s s)"
                  % (sb.get("commands_accepted"), sb.get("sim_time")))
        finally:
            host.terminate()
            try:
                host.wait(timeout=20)
            except subprocess.TimeoutExpired:
                host.kill()
                host.wait()
            err.seek(0)
            tail = err.read().splitlines()[-8:]
            print("host: exit %s\n%s" % (host.returncode, "".join("  | %s\n" % ln for ln in tail)))
    return verdict(a.lang)


if __name__ == "__main__":
    sys.exit(main())
