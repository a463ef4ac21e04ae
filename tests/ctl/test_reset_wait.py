#!/usr/bin/env python3
"""A reset that puts a plant back to waiting for its first command (lagsimctl reset --wait,
control_t RESET/RESET_TO count bit 2), as a lab host's TA hands a plant to the next student.

    test_reset_wait.py --bin BUILD/bin --source SRC --types BUILD/python

The DIPC of config/dipc.yaml (realtime, start: first_command) with --log:
  dipc_lqr balances it until its sim time passes 0.5 s; then it is stopped and
  `lagsimctl reset --wait` sent     -> exit 0, the reset event says it waits for the first
                                       command, the status says run_state waiting
  listening to its states for 1 s    -> states keep coming (republished), every one at step 0
                                       and sim time 0; the status still says waiting, sim
                                       time 0 (a plain reset would run free: the pendulum
                                       falls while no controller is there)
  a second dipc_lqr                  -> its commands are accepted and the run starts: sim
                                       time passes 0.5 s again, run_state running
  pause, then reset --scene --wait   -> waiting (not paused)
  kick theta0 1e7 (a numeric fault), reset --scene --wait -> waiting (a plain reset in the
                                       fault leaves the plant paused)
  reset-to Q QD --wait               -> waiting, the state published at Q
  RESET count 4, RESET_TO count 1 (raw control_t): refused with control_rejected naming the
    values accepted; nothing reset (sim time stays where it was)
  lagsimctl reset --bogus, reset-to ... --scene: exit 2
Then `lagsimd --replay` of the log: exit 0, largest difference exactly 0 (the resets
restart the comparison; a run that waited is the same trajectory).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_port  # noqa: E402  (a port pair of this process's own)
from lagsim_check import check, replay, stop, verdict  # noqa: E402  (tests/common: the one harness)

WITHIN = 30.0  # s: what a loaded 2-core machine may take (tests/common/waits.py)


class Plant:
    def __init__(self, a, prefix, lagsim):
        self.a, self.prefix, self.t = a, prefix, lagsim
        self.ctl_bin = os.path.join(a.bin, "lagsimctl")

    def ctl(self, *args):
        r = subprocess.run([self.ctl_bin, "--prefix", self.prefix, "--timeout", "5"] +
                           list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=60)
        print("$ lagsimctl %s   -> exit %d %s" % (" ".join(args), r.returncode,
                                                    r.stderr.strip()[:300]))
        return r

    def json_lines(self, r, kind):
        return [json.loads(l) for l in r.stdout.splitlines()
                if l.startswith("{") and json.loads(l)["type"] == kind]

    def status(self):
        st = self.json_lines(self.ctl("--json", "status"), "status")
        return st[-1] if st else {}

    def wait_status(self, what, ok):
        """Polls the status until ok(status) (bounded by WITHIN s): the last one seen."""
        deadline, st = time.monotonic() + WITHIN, {}
        while time.monotonic() < deadline:
            st = self.status()
            if st and ok(st):
                return st
        print("  gave up waiting for %s: %s" % (what, {k: st.get(k) for k in
                                                         ("run_state", "sim_time")}))
        return st

    def controller(self):
        p = subprocess.Popen([os.path.join(self.a.bin, "dipc_lqr"), "--prefix", self.prefix,
                              "-q", "--timeout", "60"], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, universal_newlines=True)
        return p


def states_for(lc, prefix, lagsim, seconds):
    """The states heard on prefix_STATE over `seconds` wall s: (step, sim_time, q)."""
    got = []

    def on(_chan, data):
        m = lagsim.joint_state_t.decode(data)
        got.append((m.step, m.sim_time, list(m.position)))

    sub = lc.subscribe(prefix + "_STATE", on)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        lc.handle_timeout(50)
    lc.unsubscribe(sub)
    return got


def handover(pl, lc, lagsim):
    """A controller runs the plant; it stops; reset --wait; the next controller starts it."""
    p = pl.controller()
    try:
        st = pl.wait_status("the first controller to run the plant past 0.5 s",
                            lambda s: s["run_state"] == "running" and s["sim_time"] > 0.5)
        check(st.get("run_state") == "running" and st.get("sim_time", 0) > 0.5,
              "dipc_lqr started the run: sim time %s s, running" % st.get("sim_time"))
    finally:
        stop(p)
    r = pl.ctl("--json", "reset", "--wait")
    ev = [e for e in pl.json_lines(r, "event") if e["kind"] == "reset"]
    st = pl.json_lines(r, "status")
    check(r.returncode == 0 and ev and "waiting for the first command" in ev[0]["detail"],
          "reset --wait: exit 0, the reset event says it waits for the first command (%r)"
          % (ev[0]["detail"] if ev else None))
    check(st and st[-1]["run_state"] == "waiting" and st[-1]["sim_time"] == 0,
          "reset --wait: status run_state %s, sim time %s (waiting, 0)" %
          (st and st[-1]["run_state"], st and st[-1]["sim_time"]))
    got = states_for(lc, pl.prefix, lagsim, 1.0)
    check(len(got) >= 2 and all(s[0] == 0 and s[1] == 0.0 for s in got),
          "over 1 s after reset --wait: %d states heard, steps %s (republished, all at step "
          "0, sim time 0)" % (len(got), sorted(set(s[0] for s in got))[:5]))
    st = pl.status()
    check(st.get("run_state") == "waiting" and st.get("sim_time") == 0,
          "1 s later: still waiting at sim time %s" % st.get("sim_time"))
    accepted = st.get("commands_accepted", 0)
    p = pl.controller()
    try:
        st = pl.wait_status("the next controller to start the run",
                            lambda s: s["run_state"] == "running" and s["sim_time"] > 0.5)
        check(st.get("run_state") == "running" and st.get("sim_time", 0) > 0.5 and
              st.get("commands_accepted", 0) > accepted,
              "the next dipc_lqr started the run: sim time %s s, running, %s commands "
              "accepted (%s before)" % (st.get("sim_time"), st.get("commands_accepted"),
                                        accepted))
    finally:
        stop(p)


def run_states(pl):
    """reset --scene --wait while paused and in the fault; reset-to --wait."""
    check(pl.ctl("pause").returncode == 0, "pause")
    r = pl.ctl("--json", "reset", "--scene", "--wait")
    st = pl.json_lines(r, "status")
    check(r.returncode == 0 and st and st[-1]["run_state"] == "waiting",
          "reset --scene --wait while paused: %s (waiting)" % (st and st[-1]["run_state"]))
    check(pl.ctl("resume").returncode == 0, "resume: the run starts")
    check(pl.ctl("kick", "theta0", "1e7").returncode == 0, "kick theta0 1e7")
    st = pl.wait_status("the numeric fault", lambda s: s["run_state"] == "fault")
    check(st.get("run_state") == "fault", "the kick faults the plant: %s" % st.get("run_state"))
    r = pl.ctl("--json", "reset", "--scene", "--wait")
    st = pl.json_lines(r, "status")
    check(r.returncode == 0 and st and st[-1]["run_state"] == "waiting",
          "reset --scene --wait in the fault: %s (waiting, not paused)" %
          (st and st[-1]["run_state"]))
    r = pl.ctl("--json", "reset-to", "0.1", "0.05", "-0.05", "0", "0", "0", "--wait")
    st = pl.json_lines(r, "status")
    check(r.returncode == 0 and st and st[-1]["run_state"] == "waiting",
          "reset-to ... --wait: %s (waiting)" % (st and st[-1]["run_state"]))
    r = pl.ctl("--json", "reset", "--bogus")
    check(r.returncode == 2 and "--scene, --wait" in r.stderr, "reset --bogus: exit 2")
    r = pl.ctl("reset-to", "0", "0", "0", "0", "0", "0", "--scene")
    check(r.returncode == 2, "reset-to ... --scene: exit 2 (the scene's values: reset only)")


def bad_counts(pl, lc, lc_control, lagsim):
    """RESET count 4 and RESET_TO count 1 on the wire: refused, naming what is accepted."""
    check(pl.ctl("step", "5").returncode == 0, "step 5 (from waiting at t = 0)")
    before = pl.status()
    events = []

    def on(_chan, data):
        events.append(lagsim.event_t.decode(data))

    sub = lc.subscribe(pl.prefix + "_EVENT", on)
    C = lagsim.control_t
    for req, count, n in ((C.RESET, 4, 0), (C.RESET_TO, 1, 3)):
        m = C()
        m.utime, m.request, m.count, m.key, m.value = 0, req, count, "", ""
        m.num_joints, m.q, m.qd = n, [0.0] * n, [0.0] * n
        lc_control.publish(pl.prefix + "_CONTROL", m.encode())
    deadline = time.monotonic() + WITHIN
    while time.monotonic() < deadline and \
            sum(e.kind == "control_rejected" for e in events) < 2:
        lc.handle_timeout(100)
    lc.unsubscribe(sub)
    why = [e.detail for e in events if e.kind == "control_rejected"]
    print("  control_rejected: %s" % why)
    check(any(w.startswith("reset: count 4; accepted: 0, 1 ") and "2 (then wait" in w
              for w in why), "RESET count 4: control_rejected naming 0, 1, 2 and 3")
    check(any(w.startswith("reset_to: count 1; accepted: 0 or 2") for w in why),
          "RESET_TO count 1: control_rejected naming 0 and 2")
    check(not any(e.kind == "reset" for e in events), "no reset event: nothing was reset")
    after = pl.status()
    check(after.get("sim_time") == before.get("sim_time") and before.get("sim_time", 0) > 0 and
          after.get("controls_rejected") == before.get("controls_rejected", 0) + 2,
          "sim time %s before, %s after (unchanged), 2 more controls rejected" %
          (before.get("sim_time"), after.get("sim_time")))


def replay_exact(a, cfg, prefix, log):
    r, diff = replay(os.path.join(a.bin, "lagsimd"), cfg, prefix, log, timeout=120)
    check(r.returncode == 0 and diff == 0.0,
          "--replay of the run with its resets that wait: difference exactly 0 (%r)" % diff)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--types", required=True)
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    import lagsim
    from lagsim_lcm import LCM
    port = lcm_port()  # states and events on port, commands and control on port + 1
    os.environ["LCM_DEFAULT_URL"] = "udpm://239.255.76.67:%d?ttl=0" % port
    prefix = "RWAIT_%d" % os.getpid()
    cfg = os.path.join(a.source, "config", "dipc.yaml")
    tmp = tempfile.mkdtemp(prefix="lagsim_rwait_")
    log = os.path.join(tmp, "run.lcm")
    pl = Plant(a, prefix, lagsim)
    d = subprocess.Popen([os.path.join(a.bin, "lagsimd"), "--config", cfg, "--set",
                          "lcm.prefix=" + prefix, "-q", "--log", log],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    lc = LCM(os.environ["LCM_DEFAULT_URL"])
    lc_control = LCM("udpm://239.255.76.67:%d?ttl=0" % (port + 1))
    try:
        check(waits.daemon_answers(pl.ctl_bin, prefix), "lagsimd answers (waited on)")
        st = pl.status()
        check(st.get("run_state") == "waiting", "the shipped scene starts waiting: %s" %
              st.get("run_state"))
        handover(pl, lc, lagsim)
        run_states(pl)
        bad_counts(pl, lc, lc_control, lagsim)
    finally:
        lc.close()
        lc_control.close()
        stop(d)
    replay_exact(a, cfg, prefix, log)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
