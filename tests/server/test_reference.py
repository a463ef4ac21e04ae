#!/usr/bin/env python3
"""The scene's reference on <PREFIX>_REFERENCE, end to end, read from lagsimd --log (every
message the daemon published, in order) with lcm-gen's Python types.

    test_reference.py --bin BUILD/bin --types BUILD/python --source SRC CASE

The reference is checked against its closed form written here (a sine's
offset + A sin(2 pi f (t - start)) and its derivative; waypoints as straight lines), not
against the reference library.

Cases:
  fast       fast mode: a reference just before each state, same sim_time and step, r and
             r-dot, r-ddot equal to the closed form; only the joints with a reference; a scene
             without one publishes none
  realtime   the same paced in real time
  lockstep   the same in lockstep with dipc_lqr answering; --replay: difference 0 with the
             references compared, and a log whose reference was changed by one ulp fails;
             lagsim-log2csv writes <PREFIX>_REFERENCE.csv with every reference as sent
  set        SET reference.theta0.amplitude while running (lagsimctl, a paced run with
             dipc_lqr): references logged
             before the `set` event have the old amplitude, those after it the new one,
             from the tick it took effect at; --replay re-applies it, difference 0
  manipulator  manipulator_pd (C) tracks a reference set on the command line, not its own:
             the logged q within bounds of the reference's closed form after 2 s
  retry      lockstep, paused, STEP 1 with no controller: the daemon sends the waited-on
             state again (lockstep_retry) until lockstep_timeout, and each copy goes out with
             its reference just before it, as the first (lcm-logger records the bus: --log keeps one state per period)
  offline    --offline --csv: <joint>_ref, _ref_dot, _ref_ddot columns after energy, equal to
             the closed form; without a reference the header is unchanged; lagsim-plot
             draws them dashed over q and q dot (also from <PREFIX>_REFERENCE.csv, lockstep)
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_log import records  # noqa: E402  (tests/common: LCM's log format)
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)

SINE = dict(start=0.205, amplitude=0.1, offset=0.05, frequency=2.0)
POINTS = [(0.0, 0.0), (0.503, 0.02), (1.007, -0.01)]
WP_START = 0.1
REFERENCE = ("reference={theta0: {type: sine, start: %g, amplitude: %g, offset: %g, "
             "frequency: %g}, theta1: {type: waypoints, start: %g, points: [%s]}}" %
             (SINE["start"], SINE["amplitude"], SINE["offset"], SINE["frequency"], WP_START,
              ", ".join("[%g, %g]" % p for p in POINTS)))


def sine(t, amplitude=SINE["amplitude"]):
    s, o, f = SINE["start"], SINE["offset"], SINE["frequency"]
    if t < s:
        return o, 0.0, 0.0
    w = 2 * math.pi * f
    return (o + amplitude * math.sin(w * (t - s)), amplitude * w * math.cos(w * (t - s)),
            -amplitude * w * w * math.sin(w * (t - s)))


def waypoints(t):
    u = t - WP_START
    if u <= POINTS[0][0]:
        return POINTS[0][1], 0.0, 0.0
    for (t0, w0), (t1, w1) in zip(POINTS, POINTS[1:]):
        if u < t1:
            k = (w1 - w0) / (t1 - t0)
            return w0 + k * (u - t0), k, 0.0  # straight lines: r'' = 0
    return POINTS[-1][1], 0.0, 0.0


def read_log(path):
    """[(channel, data, offset of the data in the file)] of a whole log (raises otherwise)."""
    return [(ch, data, at) for _, _, ch, data, at in records(path, whole=True)]


class T:
    def __init__(self, a):
        self.a = a
        sys.path.insert(0, a.types)
        import lagsim
        self.t = lagsim
        self.dipc = os.path.join(a.source, "config", "dipc.yaml")

    def logged(self, path, prefix, probe):
        """lcm-logger has written probe, sent on <prefix>_PROBE, to path (waits.py)"""
        check(waits.logger_wrote(path, prefix + "_PROBE", probe),
              f"lcm-logger wrote {probe!r} to its file within {waits.WITHIN} s")

    def answers(self, prefix):
        check(waits.daemon_answers(os.path.join(self.a.bin, "lagsimctl"), prefix),
              f"lagsimd {prefix} answered lagsimctl status within {waits.WITHIN} s")

    def started(self, proc):
        check(waits.subscribed(proc) is not None,
              f"the controller subscribed within {waits.WITHIN} s")

    def run(self, prog, *args, timeout=120):
        p = subprocess.run([os.path.join(self.a.bin, prog), *args], capture_output=True,
                           text=True, timeout=timeout)
        print(f"$ {prog} {' '.join(args)}\n  exit {p.returncode}\n" +
              "".join("  | " + l + "\n" for l in (p.stdout + p.stderr).splitlines()[-8:]), flush=True)
        return p

    def check_log(self, log, prefix, amplitude_after=None):
        """Every state has its reference just before it, equal to the closed form (with the
        sine's amplitude amplitude_after from the first `set` event on). Returns the number
        of states."""
        recs = read_log(log)
        amp, n_states, bad, worst = SINE["amplitude"], 0, [], 0.0
        set_step, first_after = None, None
        prev = None
        for ch, data, _ in recs:
            if ch == prefix + "_EVENT":
                ev = self.t.event_t.decode(data)
                if ev.kind == "set":
                    amp, set_step = amplitude_after, ev.step
            elif ch == prefix + "_STATE":
                st = self.t.joint_state_t.decode(data)
                n_states += 1
                if prev is None or prev[0] != prefix + "_REFERENCE":
                    bad.append(f"state at t = {st.sim_time}: no reference just before it")
                else:
                    r = self.t.reference_t.decode(prev[1])
                    if (r.sim_time, r.step) != (st.sim_time, st.step):
                        bad.append(f"reference at {r.sim_time} (step {r.step}) before the state "
                                   f"at {st.sim_time} (step {st.step})")
                    if list(r.name) != ["theta0", "theta1"]:
                        bad.append(f"joints {list(r.name)}")
                        continue
                    if set_step is not None and first_after is None:
                        first_after = r.step
                    want = [sine(r.sim_time, amp), waypoints(r.sim_time)]
                    for k in range(2):
                        d = max(abs(r.r[k] - want[k][0]), abs(r.rdot[k] - want[k][1]),
                                abs(r.rddot[k] - want[k][2]) / 16.0)  # r'' scale: (2 pi 2)^2 A
                        worst = max(worst, d)
                        if d > 1e-12:
                            bad.append(f"{r.name[k]} at t = {r.sim_time}: r {r.r[k]}, rdot "
                                       f"{r.rdot[k]}, rddot {r.rddot[k]}; closed form {want[k]}")
            prev = (ch, data)
        check(n_states > 10 and not bad,
              f"{n_states} states, each with its reference just before it (same sim_time, step), "
              f"equal to the closed form (largest difference {worst:.3g}): {bad[:3]}")
        if amplitude_after is not None:
            check(set_step is not None and first_after is not None and first_after >= set_step,
                  f"the set event took effect at step {set_step}; the first reference after it "
                  f"is at step {first_after}, with the new amplitude")
        return n_states, recs

    def none_without(self, prefix, *mode):
        log = os.path.join(self.tmp, "none.lcm")
        p = self.run("lagsimd", "--config", self.dipc, "--set", "lcm.url=memq://", "--set",
                     f"lcm.prefix={prefix}N", *mode, "--duration", "0.3", "-q", "--log", log)
        recs = read_log(log)
        check(p.returncode == 0 and any(ch.endswith("_STATE") for ch, _, _ in recs) and
              not any(ch.endswith("_REFERENCE") for ch, _, _ in recs),
              "a scene without a reference publishes no reference")

    def memq(self, mode, duration):
        prefix = "REF" + mode.upper()[:4] + str(os.getpid())
        log = os.path.join(self.tmp, mode + ".lcm")
        sets = ["--set", f"realtime.mode={mode}", "--set", "realtime.start=running"]
        p = self.run("lagsimd", "--config", self.dipc, "--set", "lcm.url=memq://", "--set",
                     f"lcm.prefix={prefix}", *sets, "--set", REFERENCE, "--duration",
                     str(duration), "-q", "--log", log)
        check(p.returncode == 0, f"{mode}: lagsimd ran")
        self.check_log(log, prefix)
        self.none_without(prefix, *sets)

    def lockstep(self, prefix, log, extra=(), during=None, mode="lockstep", duration=3):
        # --timeout 30: the daemon starts once the controller is subscribed, and a loaded
        # machine's may take more than the default 5 s to publish its scene
        lqr = subprocess.Popen([os.path.join(self.a.bin, "dipc_lqr"), "--prefix", prefix, "-q",
                                "--timeout", "30"],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            self.started(lqr)
            d = subprocess.Popen([os.path.join(self.a.bin, "lagsimd"), "--config", self.dipc,
                                  "--set", f"lcm.prefix={prefix}", "--set", f"realtime.mode={mode}",
                                  "--set", REFERENCE, *extra, "--duration", str(duration), "-q", "--log", log])
            if during:
                during()
            d.wait(timeout=120)
            lqr.communicate(timeout=30)
        finally:
            for p in (lqr,):
                if p.poll() is None:
                    p.kill()
        check(d.returncode == 0, f"{mode} run with dipc_lqr logged (exit {d.returncode})")

    def replay(self, log, prefix, *extra):
        p = self.run("lagsimd", "--config", self.dipc, "--set", f"lcm.prefix={prefix}", "--set",
                     REFERENCE, *extra, "--replay", log)
        m = re.search(r"(\d+) references compared", p.stdout)
        d = re.search(r"^max difference = (\S+)$", p.stdout, re.M)
        return p.returncode, int(m.group(1)) if m else -1, float(d.group(1)) if d else None


def plot_has_reference(t, csv, rcsv, want):
    """lagsim-plot draws each reference column of rcsv dashed (dt 2), in its joint's colour
    (the lt of the joint's own line), with the title in want (title: column)."""
    gp = os.path.join(t.tmp, "plot.gp")
    p = t.run("lagsim-plot", csv, "-o", os.path.join(t.tmp, "plot.png"), "--force", "--gnuplot", gp)
    script = open(gp).read() if os.path.exists(gp) else ""
    found = {}
    for m in re.finditer(r'"([^"]*)" using 1:(\d+) axes \S+ with lines lt (\d+) (dt 2 )?lw 1.5 title "([^"]*)"', script):
        found[m.group(5)] = (os.path.basename(m.group(1)), int(m.group(2)), int(m.group(3)), bool(m.group(4)))
    ok = p.returncode == 0
    for title, col in want.items():
        joint = found.get(title.replace(" ref", ""))
        ok &= title in found and found[title][:2] == (rcsv, col) and found[title][3] and \
            joint is not None and joint[2] == found[title][2] and not joint[3]
    check(ok, f"lagsim-plot draws {sorted(want)} dashed from {rcsv} in their joints' colours")


def case_fast(t):
    t.memq("fast", 2.0)


def case_realtime(t):
    t.memq("realtime", 0.6)


def case_lockstep(t):
    prefix = "REFL" + str(os.getpid())
    log = os.path.join(t.tmp, "lockstep.lcm")
    t.lockstep(prefix, log)
    n, recs = t.check_log(log, prefix)
    rc, compared, diff = t.replay(log, prefix)
    check(rc == 0 and compared == n and diff == 0.0,
          f"--replay: {compared} references compared ({n} logged), difference {diff}, exit {rc}")
    # lagsim-log2csv: <PREFIX>_REFERENCE.csv, a row per reference, the numbers as sent
    out = os.path.join(t.tmp, "csv")
    p = t.run("lagsim-log2csv", log, "-o", out, "-q")
    rows = open(os.path.join(out, prefix + "_REFERENCE.csv")).read().splitlines()
    sent = [t.t.reference_t.decode(d) for ch, d, _ in recs if ch == prefix + "_REFERENCE"]
    same = len(rows) == len(sent) + 1 and all(
        [float(x) for x in row.split(",")[5:]] == list(m.r) + list(m.rdot) + list(m.rddot) and
        int(row.split(",")[4]) == m.generation and
        float(row.split(",")[0]) == m.sim_time for row, m in zip(rows[1:], sent))
    check(p.returncode == 0 and rows[0] == 't,wall_time,log_time,step,generation,theta0,theta1,'
          'theta0_dot,theta1_dot,theta0_ddot,theta1_ddot' and same,
          f"lagsim-log2csv: {prefix}_REFERENCE.csv, {len(rows) - 1} rows equal to the "
          f"{len(sent)} references logged: {rows[0]}")
    plot_has_reference(t, os.path.join(out, prefix + "_STATE.csv"), prefix + "_REFERENCE.csv",
                       {"theta0 ref": 6, "theta1 ref (right)": 7, "theta0_dot ref": 8,
                        "theta1_dot ref (right)": 9})
    # one ulp more in the 100th reference's r of theta0: the replay fails
    refs = [k for k, (ch, _, _) in enumerate(recs) if ch == prefix + "_REFERENCE"]
    b = bytearray(open(log, "rb").read())
    ch, data, off = recs[refs[100]]
    r = t.t.reference_t.decode(data)
    r.r = [math.nextafter(r.r[0], math.inf)] + list(r.r[1:])
    new = r.encode()
    assert len(new) == len(data)
    b[off:off + len(data)] = new
    changed = os.path.join(t.tmp, "changed.lcm")
    open(changed, "wb").write(bytes(b))
    rc, compared, diff = t.replay(changed, prefix)
    check(rc == 1 and diff is not None and diff > 0,
          f"a reference changed by one ulp: --replay exit {rc}, difference {diff}")


def case_set(t):
    prefix = "REFS" + str(os.getpid())
    log = os.path.join(t.tmp, "set.lcm")

    def during():  # 1 s into the run: after the daemon answers (from its start, it may not be up)
        check(waits.daemon_answers(os.path.join(t.a.bin, "lagsimctl"), prefix),
              "the daemon answers")
        time.sleep(1.0)
        p = t.run("lagsimctl", "--prefix", prefix, "set", "reference.theta0.amplitude=0.3")
        check(p.returncode == 0, "lagsimctl set reference.theta0.amplitude=0.3 accepted")
        p = t.run("lagsimctl", "--prefix", prefix, "set", "reference.theta0.frequency_end=3")
        check(p.returncode == 1 and "a sine reference takes no frequency_end" in p.stderr,
              "a key the kind does not take is refused with the loader's message")

    # paced: 5 wall s, the change 1 s after the start, its answer waited for 2 s at most
    t.lockstep(prefix, log, during=during, mode="realtime", duration=5)
    t.check_log(log, prefix, amplitude_after=0.3)
    rc, compared, diff = t.replay(log, prefix)
    check(rc == 0 and compared > 100 and diff == 0.0,
          f"--replay re-applies the change: {compared} references, difference {diff}, exit {rc}")


def case_offline(t):
    p = t.run("lagsimd", "--config", t.dipc, "--set", REFERENCE, "--offline", "--duration", "1.5",
              "--csv", "-")
    lines = p.stdout.splitlines()
    head = lines[0].split(",")
    check(head[-7:] == ["energy", "theta0_ref", "theta0_ref_dot", "theta0_ref_ddot", "theta1_ref",
                        "theta1_ref_dot", "theta1_ref_ddot"],
          f"header: {head}")
    worst = 0.0
    for line in lines[1:]:
        v = [float(x) for x in line.split(",")]
        want = sine(v[0]) + waypoints(v[0])
        scale = [1, 1, 16, 1, 1, 16]  # r'' of the sine: up to (2 pi 2)^2 0.1 = 15.8
        worst = max(worst, max(abs(a - b) / s for a, b, s in zip(v[-6:], want, scale)))
    check(len(lines) == 152 and worst <= 1e-12,
          f"{len(lines) - 1} rows, r, r-dot and r-ddot equal to the closed form (largest "
          f"difference {worst:.3g})")
    csv = os.path.join(t.tmp, "run.csv")
    open(csv, "w").write(p.stdout)
    plot_has_reference(t, csv, "run.csv", {"theta0 ref": 9, "theta1 ref": 12,  # one axis: no
                                           "theta0_dot ref": 10, "theta1_dot ref": 13})  # scene
    p = t.run("lagsimd", "--config", t.dipc, "--offline", "--duration", "0.1", "--csv", "-")
    check(p.stdout.splitlines()[0] == "t,theta0,theta1,theta2,theta0_dot,theta1_dot,theta2_dot,energy",
          "without a reference the header is what it was")


MAN_SINE = dict(start=0.0, amplitude=0.2, offset=0.1, frequency=0.2)
MAN_POINTS = [(0.0, 0.0), (4.003, 0.1), (8.007, 0.0)]
MAN_REFERENCE = ("reference={q1: {type: sine, amplitude: 0.2, offset: 0.1, frequency: 0.2}, "
                 "q2: {type: waypoints, offset: 0.5, points: [%s]}}"
                 % ", ".join("[%g, %g]" % p for p in MAN_POINTS))


def man_reference(t):
    """q1's and q2's r at t, closed form."""
    w = 2 * math.pi * MAN_SINE["frequency"]
    r1 = MAN_SINE["offset"] + MAN_SINE["amplitude"] * math.sin(w * t)
    r2 = 0.5 + MAN_POINTS[-1][1]
    for (t0, w0), (t1, w1) in zip(MAN_POINTS, MAN_POINTS[1:]):
        if t0 <= t < t1:
            r2 = 0.5 + w0 + (w1 - w0) / (t1 - t0) * (t - t0)
    return r1, r2


def case_manipulator(t):
    """manipulator_pd tracks the scene's reference, not a trajectory of its own: a
    reference other than config/manipulator.yaml's (a sine and waypoints), the error of the
    logged q from its closed form after 2 s: computed torque with wn = 10 leaves the
    initial error (0.1 rad, 0.25 rad/s) below 1e-7 after 2 s (e ~ (1 + wn t) e^(-wn t));
    what remains is the effort held over a period (5e-5, see tests/clients.cmake) and, at
    a waypoint corner, r' jumping by 0.05 m/s one period before the backward difference
    feeds it forward: about 0.05 m/s x 10 ms = 5e-4 m. Bounds 1e-3 rad, 2e-3 m."""
    prefix = "REFM" + str(os.getpid())
    log = os.path.join(t.tmp, "man.lcm")
    man = os.path.join(t.a.source, "config", "manipulator.yaml")
    pd = subprocess.Popen([os.path.join(t.a.bin, "manipulator_pd"), "--prefix", prefix,
                           "--timeout", "30"],  # the daemon starts after it (as lockstep() says)
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        t.started(pd)
        d = t.run("lagsimd", "--config", man, "--set", f"lcm.prefix={prefix}", "--set",
                  "realtime.mode=lockstep", "--set", MAN_REFERENCE, "--duration", "10", "-q",
                  "--log", log)
        out, _ = pd.communicate(timeout=30)
    finally:
        if pd.poll() is None:
            pd.kill()
    print("  manipulator_pd: " + "\n  ".join(out.strip().splitlines()[-3:]))
    check(d.returncode == 0 and pd.returncode == 0 and "tracking q1 its reference, q2 its reference" in out,
          "manipulator_pd ran against a lockstep lagsimd and says it tracks both references")
    worst, n = [0.0, 0.0], 0
    for ch, data, _ in read_log(log):
        if ch != prefix + "_STATE":
            continue
        st = t.t.joint_state_t.decode(data)
        if st.sim_time < 2.0:
            continue
        n += 1
        r = man_reference(st.sim_time)
        for k in range(2):
            worst[k] = max(worst[k], abs(st.position[k] - r[k]))
    check(n == 801 and worst[0] <= 1e-3 and worst[1] <= 2e-3,
          f"{n} states after 2 s: |q1 - r1| <= {worst[0]:.3g} rad (bound 1e-3), "
          f"|q2 - r2| <= {worst[1]:.3g} m (bound 2e-3), r from the closed form")


def case_retry(t):
    prefix = "REFR" + str(os.getpid())
    bus = os.path.join(t.tmp, "bus.lcm")
    logger = subprocess.Popen(["lcm-logger", "-q", "--channel", prefix + "_.*", bus],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t.logged(bus, prefix, b"logger-up")  # it records
    # paused, then STEP 1: the state at 0 is waited on with retries until lockstep_timeout
    # (nothing answers), then the period runs without a command, as a STEP does
    d = subprocess.Popen([os.path.join(t.a.bin, "lagsimd"), "--config",
                          os.path.join(t.a.source, "config", "manipulator.yaml"),
                          "--set", "realtime.mode=lockstep", "--set", "lcm.prefix=" + prefix,
                          "--set", "realtime.start=paused",
                          "--set", "realtime.lockstep_timeout=1", "-q"])
    t.answers(prefix)
    # lagsimctl step returns on the step_done event: the copies went out, then the period
    # ran at lockstep_timeout
    p = t.run("lagsimctl", "--prefix", prefix, "step", "1", timeout=30)
    check(p.returncode == 0 and "step_done" in p.stdout, "lagsimctl step 1: step done")
    d.terminate()
    d.wait(timeout=10)
    t.logged(bus, prefix, b"run-over")  # the logger has written what it heard
    logger.terminate()
    logger.wait(timeout=10)
    recs = [(ch, d) for ch, d, _ in read_log(bus)]
    states = [k for k, (ch, _) in enumerate(recs) if ch == prefix + "_STATE"]
    bad = 0
    for k in states:
        st = t.t.joint_state_t.decode(recs[k][1])
        r = t.t.reference_t.decode(recs[k - 1][1]) if k and recs[k - 1][0] == prefix + "_REFERENCE" else None
        bad += r is None or (r.sim_time, r.step) != (st.sim_time, st.step)
    check(len(states) >= 5 and bad == 0,
          f"{len(states)} copies of the waited-on state on the bus (no controller), "
          f"{len(states) - bad} with their reference just before them")


CASES = {"fast": case_fast, "retry": case_retry, "manipulator": case_manipulator, "realtime": case_realtime, "lockstep": case_lockstep,
         "set": case_set, "offline": case_offline}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--types", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("case", choices=sorted(CASES))
    a = ap.parse_args()
    # a multicast port of this test's own (ttl=0: this host), and the next one for commands
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")
    t = T(a)
    with tempfile.TemporaryDirectory() as tmp:
        t.tmp = tmp
        CASES[a.case](t)
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
