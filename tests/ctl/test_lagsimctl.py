#!/usr/bin/env python3
"""lagsimctl against a running lagsimd: every command, its output, its exit status.

    test_lagsimctl.py --lagsimctl BIN --lagsimd BIN --source DIR

A real-time daemon on config/dipc.yaml with a prefix of its own; then, in order:
  status      exit 0, for people: a block headed `status of <prefix>`, one field a line (name, value, unit:
              sim_time in s, energy in J), the names aligned, every non-zero field of
              status_t.lcm (read from the file) named, the zero counters on a `zero` line;
              --json: one JSON object with every field of status_t.lcm, run_state=running
  describe    exit 0, the scene: model=dipc, one `param` line per parameter (m0 = 1.5 as
              in the file), one `joint` line per joint
  pause       exit 0, `event pause`, then a status with run_state=paused
  step 3      exit 0, `event step ... value=3`, `event step_done`, and a status exactly
              3 control periods (30 ticks) after the paused one
  step 2 while running, after resume: exit 1, the daemon's reason on stderr
  reset-to    (paused) exit 0; the next state is the one asked for, bit for bit
  reset-to with 2 numbers for 3 joints: exit 1, the daemon's reason
  reset       exit 0, `event reset`, status at step 0
  set         parameters.m0=2.5: exit 0, `event set`, the scene with the new value; a value
              the loader refuses, or a key outside parameters and effects: exit 1, the reason
  usage       step 0, step abc, reset-to 1 2 3, an unknown command, kick without an
              impulse or with a duration of 0, reset --sceen: exit 2, nothing sent; an option
              after the command: the line to write instead, with its value
  no daemon   another prefix: exit 3 within the timeout
  watch       a daemon that runs 1 s and stops: states as lines, the stop event, exit 0
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, daemon, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def tokens(line):
    """key=value tokens of a line (values may be "quoted")."""
    return dict(re.findall(r'(\w+)=("(?:[^"\\]|\\.)*"|\S+)', line))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimctl", required=True)
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    cfg = os.path.join(a.source, "config", "dipc.yaml")
    prefix = "CTL_%d" % os.getpid()
    # a multicast port of this run's own (ttl=0: this host), through LCM_DEFAULT_URL, which
    # lagsimd and lagsimctl read: another run on the machine is not heard (nor floods these
    # sockets), nothing of this one is heard elsewhere
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")

    def ctl(*args, timeout=20):
        r = subprocess.run([a.lagsimctl, "--prefix", prefix] + list(args),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=timeout)
        print("$ lagsimctl %s   -> exit %d" % (" ".join(args), r.returncode))
        for line in r.stdout.splitlines()[:6]:
            print("  " + line[:160])
        if r.stderr.strip():
            print("  stderr: " + r.stderr.strip()[:200])
        return r

    def lines(r, word):
        return [l for l in r.stdout.splitlines() if l.split(" ", 1)[0] == word]

    def statuses(r):
        """the statuses of a --json answer, as dicts"""
        out = []
        for l in r.stdout.splitlines():
            if l.startswith("{"):
                m = json.loads(l)
                if m.get("type") == "status":
                    out.append(m)
        return out

    status_fields = []
    with open(os.path.join(a.source, "lcmtypes", "status_t.lcm")) as f:
        for line in f:
            m = re.match(r"\s*(?:int8_t|int16_t|int64_t|double|boolean|string)\s+(\w+)\s*;", line)
            if m:
                status_fields.append(m.group(1))

    with daemon(a.lagsimd, a.lagsimctl, cfg, prefix, "--set", "realtime.start=running", grace=5):
        r = ctl("status")
        rj = statuses(ctl("--json", "status"))
        out = r.stdout.splitlines()
        rows = {l.split()[0]: l for l in out[1:] if l.startswith("  ") and l.split()}
        named = set(rows) | set(w.strip(",") for w in rows.get("zero", "").split()[1:])
        missing = [f for f in status_fields if f != "utime" and f not in named and
                   not (rj and rj[0].get(f) == "")]  # an empty word is left out
        check(r.returncode == 0 and out and out[0] == "status of " + prefix and not missing,
              "status for people: exit 0, every field of status_t.lcm named (%d; missing %s)"
              % (len(status_fields), missing))
        cols = set(l.index(l.split()[1]) for l in out[1:] if len(l.split()) > 1)
        check(len(cols) == 1, "status for people: the values start in one column %s" % cols)
        check(rows.get("sim_time", "").endswith(" s") and rows.get("energy", "").endswith(" J")
              and rows.get("run_state", "").split()[-1] == "running",
              "status for people: sim_time in s, energy in J, run_state running")
        r = ctl("--json", "status")
        st = statuses(r)
        check(r.returncode == 0 and len(st) == 1, "status --json: exit 0, one JSON status")
        kv = st[0] if st else {}
        missing = [f for f in status_fields if f not in kv]
        check(status_fields and not missing,
              "status --json: every field of status_t.lcm (%d; missing %s)"
              % (len(status_fields), missing))
        check(kv.get("run_state") == "running" and kv.get("mode") == "realtime",
              "status --json: run_state=running mode=realtime")

        r = ctl("describe")
        sc = lines(r, "scene")
        params = dict(l.split(" ", 1)[1].split("=", 1) for l in lines(r, "param"))
        joints = [l.split()[1] for l in lines(r, "joint")]
        check(r.returncode == 0 and sc and tokens(sc[0]).get("model") == "dipc",
              "describe: exit 0, scene model=dipc")
        check(float(params.get("m0", "nan")) == 1.5 and len(params) >= 9,
              "describe: the parameters (%d, m0 = %s)" % (len(params), params.get("m0")))
        check(joints == ["theta0", "theta1", "theta2"], "describe: the joints %s" % joints)

        r = ctl("--json", "pause")
        ev, st = [json.loads(l) for l in r.stdout.splitlines() if '"type": "event"' in l], statuses(r)
        check(r.returncode == 0 and ev and ev[0]["kind"] == "pause" and st and
              st[0].get("run_state") == "paused",
              "pause --json: exit 0, event pause, status run_state=paused")
        step0 = st[0].get("step", -1) if st else -1

        r = ctl("step", "3")
        ev = lines(r, "event")
        check(r.returncode == 0 and len(ev) == 2 and ev[0].startswith("event step ") and
              float(tokens(ev[0]).get("value", 0)) == 3 and ev[1].startswith("event step_done"),
              "step 3: exit 0, event step value=3, event step_done")
        st = statuses(ctl("--json", "status"))
        step1 = st[0].get("step", -1) if st else -1
        check(st and step1 == step0 + 30 and st[0].get("run_state") == "paused",
              "step 3: the status after it is 30 ticks on (%d -> %d), paused" % (step0, step1))

        r = ctl("reset-to", "0", "0.1", "-0.05", "0", "0", "0")
        check(r.returncode == 0 and lines(r, "event") and
              lines(r, "event")[0].startswith("event reset "), "reset-to: exit 0, event reset")
        w = subprocess.Popen([a.lagsimctl, "--prefix", prefix, "watch"], stdout=subprocess.PIPE,
                             universal_newlines=True)
        first = None
        t_end = time.monotonic() + 5
        while time.monotonic() < t_end:
            line = w.stdout.readline()
            if line.startswith("state "):
                first = tokens(line)
                break
        w.terminate()
        w.wait()
        check(first is not None and float(first["theta1"]) == 0.1 and
              float(first["theta2"]) == -0.05 and float(first["t"]) == 0.0,
              "reset-to: the paused daemon publishes the state asked for (%s)"
              % ({k: first[k] for k in ("t", "theta1", "theta2")} if first else None))

        r = ctl("reset-to", "0", "0")
        check(r.returncode == 1 and "num_joints 1; accepted: 3" in r.stderr
              and "refused" in r.stderr,
              "reset-to with 1 joint of 3: exit 1, the daemon's reason on stderr")

        r = ctl("--json", "resume")
        st = statuses(r)
        check(r.returncode == 0 and st and st[0].get("run_state") == "running",
              "resume: exit 0, run_state=running")
        r = ctl("step", "2")
        check(r.returncode == 1 and "only while paused" in r.stderr,
              "step while running: exit 1, the daemon's reason on stderr")
        r = ctl("reset")
        ev, st = lines(r, "event"), lines(r, "status")
        check(r.returncode == 0 and ev and ev[0].startswith("event reset ") and st,
              "reset: exit 0, event reset, a status")

        r = ctl("set", "parameters.m0=2.5")
        ev, sc = lines(r, "event"), lines(r, "param")
        check(r.returncode == 0 and ev and ev[0].startswith("event set ") and
              'detail=parameters.m0=2.5' in ev[0].replace('"', '') and "param m0=2.5" in sc,
              "set parameters.m0=2.5: exit 0, event set, the scene with m0 = 2.5")
        r = ctl("set", "parameters.m0=-1")
        check(r.returncode == 1 and "expected a number > 0" in r.stderr,
              "set parameters.m0=-1: exit 1, the loader's reason on stderr")
        r = ctl("set", "integrator.dt=0.002")
        check(r.returncode == 1 and "only keys under parameters, effects and reference" in r.stderr,
              "set integrator.dt: exit 1, only parameters and effects change")

        for bad in (["step", "0"], ["step", "abc"], ["reset-to", "1", "2", "3"], ["spin"],
                    ["set", "m0"], ["set", "=1"], ["set", "parameters.m0="],
                    ["status", "extra"], ["--timeout", "-1", "status"], ["kick", "x"],
                    ["kick", "theta1", "abc"], ["kick", "theta1", "1", "--duration", "0"],
                    ["kick", "theta1", "1", "--during", "1"], ["reset", "--sceen"]):
            r = ctl(*bad)
            check(r.returncode == 2 and r.stderr.startswith("lagsimctl: "),
                  "usage error %s: exit 2 with a message" % bad)
        # an option after the command: the command line to write instead, its value kept
        r = subprocess.run([a.lagsimctl, "status", "--prefix", "OTHER"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True)
        check(r.returncode == 2 and "lagsimctl --prefix OTHER status)" in r.stderr,
              "status --prefix OTHER: exit 2, 'lagsimctl --prefix OTHER status' said (%s)"
              % r.stderr.strip())
        t0 = time.monotonic()
        r = subprocess.run([a.lagsimctl, "--prefix", prefix + "_NONE", "--timeout", "0.5",
                            "status"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True)
        dt = time.monotonic() - t0
        # it ends after the directory's look (1 s), its --timeout and the look for other
        # plants to name (1 s): at least the timeout, and well before a hang (the bound
        # leaves a busy machine room; the check is that it ends, not how fast)
        check(r.returncode == 3 and "no answer" in r.stderr and 0.5 <= dt < 15.0,
              "no daemon on the prefix: exit 3 after %.2f s with a message" % dt)

    # watch: a daemon that runs 1 s of sim time, then stops by itself
    w = subprocess.Popen([a.lagsimctl, "--prefix", prefix + "W", "watch"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, universal_newlines=True)
    time.sleep(0.3)
    subprocess.run([a.lagsimd, "--config", cfg, "--set", "lcm.prefix=" + prefix + "W", "-q",
                    "--set", "realtime.start=running", "--duration", "1"], timeout=30)
    try:
        out, err = w.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        w.kill()
        out, err = w.communicate()
    states = [l for l in out.splitlines() if l.startswith("state ")]
    stops = [l for l in out.splitlines() if l.startswith("event stop ")]
    check(w.returncode == 0 and stops, "watch: exit 0 after the daemon's stop event")
    check(len(states) >= 50 and all(len(tokens(s)) == 2 + 9 for s in states),
          "watch: %d state lines, each with t, step and 3 x (q, qd, effort)" % len(states))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
