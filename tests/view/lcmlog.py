#!/usr/bin/env python3
"""LCM log files and lagsim messages for the tools' tests, written independently of the C
code under test: records in the stock LCM log format (lcm/eventlog.h), payloads encoded
by lcm-gen's Python types (--types DIR, the build's python/ directory) or forged byte by
byte where a test needs a hostile one.

    python3 lcmlog.py --types build/python --corpus DIR   # (re)writes the fuzz corpus
"""
import argparse
import os
import struct
import sys

SYNC = 0xEDA1DA01


def record(eventnum, timestamp, channel, data, clen=None, dlen=None, sync=SYNC):
    ch = channel.encode()
    return (struct.pack(">IqqII", sync, eventnum, timestamp,
                        len(ch) if clen is None else clen & 0xffffffff,
                        len(data) if dlen is None else dlen & 0xffffffff) + ch + data)


def log(records, t0=1_700_000_000_000_000, dt=10_000):
    """records: list of (channel, payload); event numbers and timestamps in order."""
    return b"".join(record(i, t0 + i * dt, ch, data) for i, (ch, data) in enumerate(records))


class Types:
    def __init__(self, types_dir):
        sys.path.insert(0, types_dir)
        import lagsim  # noqa: E402  (lcm-gen's Python output for lagsim's .lcm files)
        self.m = lagsim

    def state(self, sim_time, step, names, q, qd, eff, utime=1_700_000_000_000_000):
        s = self.m.joint_state_t()
        s.utime, s.sim_time, s.step = utime, sim_time, step
        s.num_joints, s.name = len(names), list(names)
        s.position, s.velocity, s.effort = list(q), list(qd), list(eff)
        return s.encode()

    def scene(self, model="dipc", prefix="T", dt=0.001, period=0.01, joints=("theta0", "theta1", "theta2"),
              params=(("m0", 1.5), ("g", 9.81)), effects="", limits=None):
        s = self.m.scene_t()
        s.utime, s.model, s.prefix = 1_700_000_000_000_000, model, prefix
        s.num_params = len(params)
        s.param_name = [p[0] for p in params]
        s.param_value = [p[1] for p in params]
        s.num_joints = len(joints)
        s.joint_name = list(joints)
        s.actuated = [i == 0 for i in range(len(joints))]
        s.initial_q = [0.0] * len(joints)
        s.initial_qd = [0.0] * len(joints)
        s.dt, s.control_period = dt, period
        s.integrator, s.mode, s.rate, s.command_timeout = "rk4", "lockstep", 1.0, 0.5
        s.effects = effects
        lim = limits or {}
        s.limit_on = [j in lim for j in joints]
        s.limit_lower = [lim.get(j, (0.0, 0.0))[0] for j in joints]
        s.limit_upper = [lim.get(j, (0.0, 0.0))[1] for j in joints]
        return s.encode()

    def status(self, sim_time=1.0, step=1000, run_state="running", **counters):
        s = self.m.status_t()
        s.utime, s.sim_time, s.step = 1_700_000_000_000_000, sim_time, step
        s.wall_time, s.rtf, s.overruns = 1.5, 1.0, 0
        s.step_time_max_us, s.step_time_mean_us, s.energy = 10.0, 5.0, 7.25
        s.integrator, s.mode, s.run_state = "rk4", "lockstep", run_state
        for k in ("commands_accepted", "rejected_unknown_joint", "rejected_unactuated",
                  "rejected_nonfinite", "rejected_bad_length", "rejected_undecodable",
                  "controls_rejected", "watchdog_trips", "lockstep_timeouts", "numeric_faults",
                  "rejected_stale", "overrun_bursts", "states_published"):
            setattr(s, k, counters.get(k, 0))
        s.watchdog_tripped = bool(counters.get("watchdog_tripped", False))
        s.error_estimate = counters.get("error_estimate", 0.0)
        s.error_joint = counters.get("error_joint", "")
        s.error_budget = counters.get("error_budget", 0.0)
        s.error_warnings = counters.get("error_warnings", 0)
        return s.encode()

    def event(self, sim_time, step, kind, joint="", value=0.0, detail=""):
        e = self.m.event_t()
        e.utime, e.sim_time, e.step = 1_700_000_000_000_000, sim_time, step
        e.kind, e.joint, e.value, e.detail = kind, joint, value, detail
        return e.encode()

    def command(self, sim_time, names, efforts):
        c = self.m.joint_command_t()
        c.utime, c.sim_time = 1_700_000_000_000_000, sim_time
        c.num_joints, c.name, c.effort = len(names), list(names), list(efforts)
        return c.encode()

    def control(self, request, count=0, q=(), qd=(), key="", value=""):
        c = self.m.control_t()
        c.utime, c.request, c.count = 1_700_000_000_000_000, request, count
        c.num_joints, c.q, c.qd = len(q), list(q), list(qd)
        c.key, c.value = key, value
        return c.encode()

    def state_fp(self):
        return self.m.joint_state_t._get_packed_fingerprint()


J3 = ("theta0", "theta1", "theta2")


def forged_state(t, name_len, name=b"theta0", num_joints=1, tail=b""):
    """A joint_state_t whose first name's length field says name_len (hostile)."""
    return (t.state_fp() + struct.pack(">qdqh", 0, 0.0, 0, num_joints) +
            struct.pack(">i", name_len) + name + tail)


def sample_run(t, prefix="T"):
    """A small valid run: scene, states (with one missing state, a reset, a repeat),
    status, events, commands, control requests."""
    recs = [(prefix + "_SCENE", t.scene(prefix=prefix, limits={"theta0": (-1.0, 1.0)},
                                       effects="limits"))]
    for k in (0, 1, 2, 4):  # step 30 missing: one gap, one state missing
        recs.append((prefix + "_STATE", t.state(k * 0.01, k * 10, J3, [k * 0.1, -k * 0.2, 1e-300],
                                                [k * 1.5, 0.0, -2.5], [k * 0.25, 0.0, 0.0])))
        recs.append((prefix + "_COMMAND", t.command(k * 0.01, ["theta0"], [k * 0.25])))
    recs.append((prefix + "_CONTROL", t.control(5, 0, [0.0, 0.1, 0.2], [0.0, 0.0, 0.0])))
    recs.append((prefix + "_STATE", t.state(0.0, 0, J3, [0.0, 0.1, 0.2], [0, 0, 0], [0, 0, 0])))
    recs.append((prefix + "_STATE", t.state(0.0, 0, J3, [0.0, 0.1, 0.2], [0, 0, 0], [0, 0, 0])))
    recs.append((prefix + "_COMMAND", t.command(0.0, [], [])))
    recs.append((prefix + "_EVENT", t.event(0.0, 0, "start", detail='say "hi",\nnewline')))
    recs.append((prefix + "_EVENT", t.event(0.015, 15, "limit", "theta0", -0.5, "limit at t")))
    recs.append((prefix + "_EVENT", t.event(0.02, 20, "limit", "theta0", 0.5, "again")))
    recs.append((prefix + "_STATUS", t.status(0.04, 40, commands_accepted=5,
                                              rejected_unknown_joint=2, rejected_stale=1,
                                              error_estimate=2.5e-7, error_joint="theta1",
                                              error_budget=1e-8, error_warnings=3)))
    recs.append(("OTHER_CHANNEL", b"not lagsim"))
    return recs


def corpus_cases(t, d):
    os.makedirs(d, exist_ok=True)
    good = log(sample_run(t))
    cases = {
        "valid-run.lcm": good,
        "empty.lcm": b"",
        "truncated-mid-record.lcm": good[:len(good) - 7],
        "huge-data-length.lcm": record(0, 0, "T_STATE", b"\0" * 8, dlen=0x7fffffff),
        "negative-data-length.lcm": record(0, 0, "T_STATE", b"", dlen=-5),
        "huge-channel-length.lcm": record(0, 0, "T_STATE", b"", clen=0x7fffffff),
        "zeros.lcm": b"\0" * 256,
        "bad-sync-then-record.lcm": log(sample_run(t)[:2]) + b"\x01\x02\x03junk" + log(sample_run(t)[2:4]),
        "state-negative-name-length.lcm": log([("T_STATE", forged_state(t, -1))]),
        "state-name-without-nul.lcm": log([("T_STATE", forged_state(t, 6))]),
        "state-huge-num-joints.lcm": log([("T_STATE", forged_state(t, 7, b"theta0\0", 32767))]),
        "step-jump-2e62.lcm": log([("T_STATE", t.state(0.0, 0, J3, [0] * 3, [0] * 3, [0] * 3)),
                                   ("T_STATE", t.state(0.01, 10, J3, [0] * 3, [0] * 3, [0] * 3)),
                                   ("T_STATE", t.state(1.0, 1 << 62, J3, [0] * 3, [0] * 3, [0] * 3)),
                                   ("T_STATE", t.state(1.0, -(1 << 63), J3, [0] * 3, [0] * 3, [0] * 3)),
                                   ("T_STATE", t.state(1.0, (1 << 63) - 1, J3, [0] * 3, [0] * 3, [0] * 3))]),
        # every string a formula or a record breaker (the CSVs quote and neutralise them)
        "strings-formulas.lcm": log([("T_STATE", t.state(0.0, 0, ('a,b\n=HYPERLINK("x")', "=1+1", '"\t-2'),
                                                         [-0.5] * 3, [0] * 3, [0] * 3)),
                                     ("T_EVENT", t.event(0.0, 0, "@kind", "+j", -0.5, "\r=d,\"\""))]),
    }
    for name, data in cases.items():
        with open(os.path.join(d, name), "wb") as f:
            f.write(data)
    return cases


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--types", required=True)
    ap.add_argument("--corpus", required=True)
    a = ap.parse_args()
    cases = corpus_cases(Types(a.types), a.corpus)
    print(f"{len(cases)} inputs in {a.corpus}")


if __name__ == "__main__":
    main()
