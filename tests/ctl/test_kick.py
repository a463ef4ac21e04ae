#!/usr/bin/env python3
"""Kicks (lagsimctl kick) against the impulse-momentum theorem, and replayed exactly.

    test_kick.py --bin BUILD/bin --source SRC

The stick of config/stick.yaml (m = 1 kg, a frictionless floor) runs paused in real time
with --log; lagsimctl steps it and kicks it. Its x is cyclic and no force acts on it (no
command is sent, the floor pushes vertically), so its generalized momentum p_x = m x_dot
changes only by the impulses given on x (T = 1/2 m x_dot^2 + ...: docs/models.md):
  kick x 0.5 at t = 0                        -> after 5 periods  m x_dot = 0.5
  kick x 0.25 --duration 0.05 and kick x 0.125 --duration 0.05, both at t = 0.05 s (they
    act together: neither replaces the other) -> 10 periods on  m x_dot = 0.875
  kick cart 1                                 -> exit 1, the joints named
  set parameters.m=2, reset                   -> the reset's answer names the change it keeps;
    the kicks end (kicks_cleared): 10 periods on x_dot = 0 exactly
  kick x -0.5 at t = 0 after the reset        -> 5 periods on m x_dot = -0.5 (m = 2 now)
  reset --scene                               -> a restore event; the scene says m = 1 again
Then `lagsimd --replay` of the log applies every kick, the kicks_cleared and the restore
at their steps and must give a largest difference of exactly 0; the same log without its
events must not (the kicks mattered).

A kick obeys the rules of any disturbance, with the words of the scene loader: on a second
stick, kicks the scene loader would refuse as a disturbance (a force held shorter than a
tick, --duration 1e-6 and 1e-300; an impulse of 1e300; a force impulse/duration above
1e12 N) are refused with exit 1, and each message is the one `lagsimd` gives for the same
disturbance written in the scene file, and as a SET of effects.disturbance to that
disturbance says; none changes x_dot. A kick spread over 1.5 ticks
gives exactly its impulse (m x_dot = 0.5, not the 0.667 of a force 0.5/0.0015 held over two
whole ticks). A kick of 1e7 N s faults the plant (x_dot past explode_limit, as the same
impulse in a scene would); a kick in the fault is refused (a reset would end it unapplied:
"in fault state (reset first)", as resume and step), and after the reset one is accepted. The same for a run under control: the cart-pole of
config/cartpole.yaml balanced by lqr_balance in real time for 3 s, kicked on theta (an
impulse) and on x (a force over 0.3 s) while it runs, logged with --log.
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, daemon, replay, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_log import read_log, write_log  # noqa: E402
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)
import waits  # noqa: E402  (events waited on, bounded)


def decode_state(data):
    """joint_state_t (lcmtypes/joint_state_t.lcm): {step, t, names, q, qd}."""
    i = 8  # fingerprint
    _utime, t, step, n = struct.unpack_from(">qdqh", data, i)
    i += 8 + 8 + 8 + 2
    names = []
    for _ in range(n):
        (ln,) = struct.unpack_from(">i", data, i)
        names.append(data[i + 4:i + 4 + ln - 1].decode())
        i += 4 + ln
    q = struct.unpack_from(">%dd" % n, data, i)
    qd = struct.unpack_from(">%dd" % n, data, i + 8 * n)
    return {"step": step, "t": t, "names": names, "q": q, "qd": qd}


def scene_words(lagsimd, cfg, tmp, item):
    """What lagsimd says of the disturbance `item` (flow YAML) in cfg's scene file: the
    message after "effects.disturbance[0].", and the exit status."""
    path = os.path.join(tmp, "disturbance.yaml")
    with open(cfg) as f:
        text = f.read()
    assert text.rstrip().splitlines()[-1].startswith("    ") and "\neffects:\n" in text
    with open(path, "w") as f:
        f.write(text.rstrip() + "\n  disturbance:\n    - %s\n" % item)
    r = subprocess.run([lagsimd, "--config", path, "--offline", "--duration", "0.01"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                       timeout=60)
    at = "effects.disturbance[0]."
    err = r.stderr.strip()
    return r.returncode, err[err.find(at) + len(at):] if at in err else err


def rules(lagsimd, ctl_bin, cfg, prefix, tmp):
    """Kicks under the rules of a disturbance, on config/stick.yaml (m = 1 kg, dt 1 ms)."""
    log = os.path.join(tmp, "rules.lcm")

    def ctl(*args):
        r = subprocess.run([ctl_bin, "--prefix", prefix, "--timeout", "5"] + list(args),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=60)
        print("$ lagsimctl %s   -> exit %d %s" % (" ".join(args), r.returncode,
                                                    r.stderr.strip()[:300]))
        return r

    # (kick arguments, the same disturbance in a scene file)
    bad = [(["x", "0.5", "--duration", "1e-6"], "{t: 0, joint: x, force: 5e5, duration: 1e-6}"),
           (["x", "0.5", "--duration", "1e-300"],
            "{t: 0, joint: x, force: 5e299, duration: 1e-300}"),
           (["x", "1e300"], "{t: 0, joint: x, impulse: 1e300}"),
           (["x", "1e12", "--duration", "0.5"], "{t: 0, joint: x, force: 2e12, duration: 0.5}"),
           (["cart", "1"], "{t: 0, joint: cart, impulse: 1}")]
    with daemon(lagsimd, ctl_bin, cfg, prefix, "--set", "realtime.start=paused", "--log", log):
        for args, item in bad:
            r = ctl("kick", *args)
            rc, words = scene_words(lagsimd, cfg, tmp, item)
            rs = ctl("set", "effects.disturbance=[%s]" % item)
            at = "effects.disturbance[0]."
            by_set = rs.stderr.strip()
            by_set = by_set[by_set.find(at) + len(at):] if at in by_set else by_set
            check(rs.returncode == 1 and by_set == words,
                  "set effects.disturbance=[%s]: refused (exit %d) with the scene file's words"
                  % (item, rs.returncode))
            said = r.stderr.strip()
            kv = "kick.%s=" % args[0]
            said = said[said.find(kv):] if kv in said else said
            said = said[said.find(": ") + 2:].replace(" (impulse/duration)", "", 1)
            if words.startswith("joint: "):  # a kick names its joint in its key, kick.<joint>
                words = words[len("joint: "):]
            check(r.returncode == 1 and rc == 2 and said == words,
                  "kick %s: refused (exit %d) with the words of the scene file's %s (exit %d): "
                  "'%s' / '%s'" % (" ".join(args), r.returncode, item, rc, said, words))
        r = ctl("--json", "kick", "x", "0.5", "--duration", "0.0015")
        check(r.returncode == 0, "kick x 0.5 --duration 0.0015 (1.5 ticks): accepted")
        check(ctl("step", "5").returncode == 0, "step 5")
        check(ctl("kick", "x", "1e7").returncode == 0, "kick x 1e7: accepted (within 1e12)")
        ctl("step", "1")
        st = ctl("--json", "status")
        run_state = [json.loads(l).get("run_state") for l in st.stdout.splitlines()
                     if l.startswith("{")]
        check(run_state[-1:] == ["fault"], "the kick of 1e7 N s faults the plant "
              "(x_dot past explode_limit): run_state %s" % run_state[-1:])
        r = ctl("kick", "x", "0.5")
        check(r.returncode == 1 and "kick.x=0.5: in fault state (reset first)" in r.stderr,
              "kick x 0.5 in the fault: refused, 'in fault state (reset first)'")
        check(ctl("reset").returncode == 0, "reset")
        check(ctl("kick", "x", "0.5").returncode == 0, "kick x 0.5 after the reset: accepted")
    states = [decode_state(data) for _, ch, data in read_log(log) if ch == prefix + "_STATE"]
    v = [s["qd"][s["names"].index("x")] for s in states if s["step"] == 50]
    check(bool(v) and abs(1.0 * v[0] - 0.5) <= 1e-12,
          "m x_dot after the refused kicks and kick x 0.5 over 1.5 ticks: %r (exactly the "
          "impulse 0.5 N s)" % (v[0] if v else None))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    lagsimd, ctl_bin = (os.path.join(a.bin, p) for p in ("lagsimd", "lagsimctl"))
    cfg = os.path.join(a.source, "config", "stick.yaml")
    prefix = "KICK_%d" % os.getpid()
    # a multicast port of this run's own (ttl=0: this host)
    os.environ["LCM_DEFAULT_URL"] = lcm_url()
    tmp = tempfile.mkdtemp(prefix="lagsim_kick_")
    log = os.path.join(tmp, "kick.lcm")

    def ctl(*args):
        r = subprocess.run([ctl_bin, "--prefix", prefix, "--timeout", "5"] + list(args),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=60)
        print("$ lagsimctl %s   -> exit %d" % (" ".join(args), r.returncode))
        for line in r.stdout.splitlines()[:4]:
            print("  " + line[:200])
        if r.stderr.strip():
            print("  stderr: " + r.stderr.strip()[:300])
        return r

    def events(r):
        return [json.loads(l) for l in r.stdout.splitlines()
                if l.startswith("{") and json.loads(l)["type"] == "event"]

    with daemon(lagsimd, ctl_bin, cfg, prefix, "--set", "realtime.start=paused", "--log", log):
        r = ctl("--json", "kick", "x", "0.5")
        ev = events(r)
        check(r.returncode == 0 and ev and ev[0]["kind"] == "kick" and ev[0]["step"] == 0 and
              ev[0]["joint"] == "x" and ev[0]["value"] == 0.5,
              "kick x 0.5 while paused at t = 0: exit 0, a kick event at step 0 on x, value 0.5")
        check(ctl("step", "5").returncode == 0, "step 5")
        r1 = ctl("--json", "kick", "x", "0.25", "--duration", "0.05")
        r2 = ctl("--json", "kick", "x", "0.125", "--duration", "0.05")
        e1, e2 = events(r1), events(r2)
        check(r1.returncode == 0 and r2.returncode == 0 and e1 and e2 and
              e1[0]["step"] == 50 and e2[0]["step"] == 50,
              "two kicks with --duration 0.05 at step 50: exit 0 each")
        # the numbers as typed: the shortest decimal that reads back, not %.17g's
        # 0.050000000000000003 (lagsim_num.h)
        check(e1 and e1[0]["detail"] == "kick.x=0.25,0.05" and e2 and
              e2[0]["detail"] == "kick.x=0.125,0.05",
              "the kicks' details as typed: %r, %r" % (e1 and e1[0]["detail"], e2 and e2[0]["detail"]))
        check(ctl("step", "10").returncode == 0, "step 10")
        r = ctl("kick", "cart", "1")
        check(r.returncode == 1 and "unknown joint 'cart' for model stick; allowed: x, phi" in
              r.stderr, "kick cart 1: exit 1, the joints named")
        r = ctl("kick", "x")
        check(r.returncode == 2, "kick x (no impulse): exit 2")
        r = ctl("set", "parameters.m=2")
        check(r.returncode == 0, "set parameters.m=2")
        r = ctl("--json", "reset")
        ev = events(r)
        check(r.returncode == 0 and any(e["kind"] == "reset" and "parameters.m=2" in e["detail"]
                                        for e in ev),
              "reset: its answer names the change it keeps (parameters.m=2)")
        check(ctl("step", "10").returncode == 0, "step 10 after the reset")
        check(ctl("kick", "x", "-0.5").returncode == 0, "kick x -0.5 at t = 0 after the reset")
        check(ctl("step", "5").returncode == 0, "step 5")
        r = ctl("--json", "reset", "--scene")
        ev = events(r)
        check(r.returncode == 0 and [e["kind"] for e in ev][:2] == ["restore", "reset"] and
              "parameters.m=2" in ev[0]["detail"],
              "reset --scene: a restore event naming parameters.m=2, then the reset")
        r = ctl("--json", "describe")
        sc = [json.loads(l) for l in r.stdout.splitlines() if l.startswith("{")]
        m = dict(zip(sc[0]["param_name"], sc[0]["param_value"])).get("m") if sc else None
        check(m == 1.0, "describe after reset --scene: m = %s, the scene file's 1" % m)
        check(ctl("step", "3").returncode == 0, "step 3")

    recs = read_log(log)
    states = [decode_state(data) for _, ch, data in recs if ch == prefix + "_STATE"]
    print("%d records, %d states in the log" % (len(recs), len(states)))
    # the runs between resets: a step that goes back starts a new one
    runs, cur = [], []
    for s in states:
        if cur and s["step"] < cur[-1]["step"]:
            runs.append(cur)
            cur = []
        cur.append(s)
    runs.append(cur)

    def at(run, step):
        for s in run:
            if s["step"] == step:
                return s["qd"][s["names"].index("x")]
        return None

    check(len(runs) == 3, "three runs in the log (start, reset, reset --scene): %d" % len(runs))
    if len(runs) == 3:
        m = 1.0  # kg, config/stick.yaml
        v50, v150 = at(runs[0], 50), at(runs[0], 150)
        check(v50 is not None and abs(m * v50 - 0.5) <= 1e-12,
              "m x_dot after kick x 0.5: %r (impulse 0.5 N s)" % v50)
        check(v150 is not None and abs(m * v150 - 0.875) <= 1e-12,
              "m x_dot after two force kicks of 0.25 and 0.125 N s more: %r (0.875: they add)"
              % v150)
        v100 = at(runs[1], 100)
        check(v100 == 0.0, "after the reset the kicks of the run before are over: x_dot = %r "
              "at step 100 (exactly 0)" % v100)
        v150b = at(runs[1], 150)
        check(v150b is not None and abs(2.0 * v150b + 0.5) <= 1e-12,
              "m x_dot after kick x -0.5 with m = 2: %r" % (None if v150b is None else 2 * v150b))

    # a run under control: the cart-pole balanced by lqr_balance in real time, kicked
    # twice while it runs (mid-run, efforts held), logged, then replayed
    cfg_cp = os.path.join(a.source, "config", "cartpole.yaml")
    log_cp = os.path.join(tmp, "cartpole.lcm")
    pcp = prefix + "CP"
    # --timeout 30: the daemon starts once the controller is subscribed, and a loaded
    # machine's daemon may take more than the default 5 s to publish its scene; the kicks
    # come 1 s after the daemon answers (counted from its start, it was not up yet)
    c = subprocess.Popen([os.path.join(a.bin, "lqr_balance"), "--prefix", pcp, "-q",
                          "--timeout", "30"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    c.stdout.readline()  # "waiting for the scene description": subscribed
    d = subprocess.Popen([lagsimd, "--config", cfg_cp, "--set", "lcm.prefix=" + pcp, "-q",
                          "--set", "realtime.start=first_command", "--duration", "3",
                          "--log", log_cp], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        check(waits.daemon_answers(ctl_bin, pcp), "the cart-pole's daemon answers")
        time.sleep(1.0)
        r1 = subprocess.run([ctl_bin, "--prefix", pcp, "kick", "theta", "0.01"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        time.sleep(0.5)
        r2 = subprocess.run([ctl_bin, "--prefix", pcp, "kick", "x", "0.2", "--duration", "0.3"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        check(r1.returncode == 0 and r2.returncode == 0,
              "cart-pole under lqr_balance: kick theta 0.01 and kick x 0.2 --duration 0.3 while "
              "it runs: exit 0 (%s; %s)" % (r1.stdout.split("\n")[0], r2.stdout.split("\n")[0]))
        d.wait(30)
        out = c.communicate(timeout=30)[0]
        print("  " + out.strip().replace("\n", "\n  ")[-400:])
    finally:
        for p in (d, c):
            if p.poll() is None:
                p.kill()
                p.wait()
    r, diff = replay(lagsimd, cfg_cp, pcp, log_cp)
    check(r.returncode == 0 and diff == 0.0 and "2 change(s) made while running" in r.stdout,
          "--replay of the controlled, kicked cart-pole: 2 kicks applied, difference exactly 0 "
          "(%r)" % diff)
    recs_cp = read_log(log_cp)
    bare_cp = os.path.join(tmp, "cartpole_no_events.lcm")
    write_log(bare_cp, [x for x in recs_cp if x[1] != pcp + "_EVENT"])
    r, diff = replay(lagsimd, cfg_cp, pcp, bare_cp)
    check(r.returncode == 1 and diff is not None and diff > 0,
          "the same log without its events: difference %r, not 0" % diff)

    rules(lagsimd, ctl_bin, cfg, prefix + "R", tmp)

    r, diff = replay(lagsimd, cfg, prefix, log)
    check(r.returncode == 0 and diff == 0.0 and "7 change(s) made while running" in r.stdout,
          "--replay: 4 kicks, a set, a kicks_cleared and a restore applied (7), "
          "difference exactly 0 (%r)" % diff)
    bare = os.path.join(tmp, "no_events.lcm")
    write_log(bare, [x for x in recs if x[1] != prefix + "_EVENT"])
    r, diff = replay(lagsimd, cfg, prefix, bare)
    check(r.returncode == 1, "the same log without its events does not replay exactly "
          "(exit %d, difference %r)" % (r.returncode, diff))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
