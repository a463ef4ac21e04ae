#!/usr/bin/env python3
"""Every client library knows a state by its generation: the copy rule and the scene rule
in each language, bit for bit alike with C.

    generation_rule.py --types BUILD/python --run NAME "COMMAND ... {prefix} ..." ...

The test plays the daemon (a DIPC in lockstep) on a multicast port of its own, for each
--run's controller in turn (the first is the reference, C):
  1. its scene (generation 1) once it asks (DESCRIBE), then a state (generation 1, sim
     time 0): answered, the command carrying generation 1;
  2. the same state again, byte for byte (a lockstep copy): the same command again;
  3. the scene of generation 2, then a state of generation 2 at the same step, sim time
     and utime but another position (a run after a RESET_TO): answered anew from its own
     position, with generation 2, never taken for a copy of the state of step 1;
  4. a state of generation 3 without its scene (UDP lost it): no answer while its scene
     has not come, DESCRIBE asked for it (twice: at once and at the 0.25 s pace); then the
     scene: answered, with generation 3;
  5. a stop event: the controller ends.
Every run's efforts must equal the first run's bit for bit.
"""
import argparse
import os
import shlex
import struct
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "clients", "python"))
from lagsim_lcm import LCM  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_port  # noqa: E402  (a port pair of this process's own)


# config/dipc.yaml's DIPC
PARAMS = [("m0", 1.5), ("m1", 0.5), ("m2", 0.75), ("l1", 0.5), ("l2", 0.75),
          ("I1", 0.010416666666666666), ("I2", 0.03515625), ("g", 9.81), ("h0", 0.0)]
JOINTS = ["theta0", "theta1", "theta2"]


class Daemon:
    def __init__(self, t, state_url, command_url, prefix):
        self.t, self.prefix = t, prefix
        self.out, self.inp = LCM(state_url), LCM(command_url)
        self.commands, self.describes = [], 0
        self.inp.subscribe(prefix + "_COMMAND", self.on_command)
        self.inp.subscribe(prefix + "_CONTROL", self.on_control)

    def on_command(self, ch, data):
        try:
            c = self.t.joint_command_t.decode(data)
        except Exception:
            return
        self.commands.append((c.generation, c.sim_time, list(c.effort)))

    def on_control(self, ch, data):
        try:
            c = self.t.control_t.decode(data)
        except Exception:
            return
        if c.request == self.t.control_t.DESCRIBE:
            self.describes += 1

    def pump(self, seconds, until=None):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.inp.handle_timeout(10)
            if until and until():
                return True
        return bool(until and until())

    def scene(self, gen):
        s = self.t.scene_t()
        s.utime, s.model, s.prefix = 1, "dipc", self.prefix
        s.num_params = len(PARAMS)
        s.param_name = [k for k, _ in PARAMS]
        s.param_value = [v for _, v in PARAMS]
        s.num_joints = 3
        s.joint_name = JOINTS
        s.actuated = [True, False, False]
        s.initial_q, s.initial_qd = [0.0, 0.05, -0.03], [0.0] * 3
        s.dt, s.control_period, s.integrator, s.mode = 0.001, 0.01, "rk4", "lockstep"
        s.rate, s.command_timeout, s.effects = 1.0, 0.5, ""
        s.limit_on, s.limit_lower, s.limit_upper = [False] * 3, [0.0] * 3, [0.0] * 3
        s.generation = gen
        self.out.publish(self.prefix + "_SCENE", s.encode())

    def state(self, gen, q):
        m = self.t.joint_state_t()
        m.utime, m.sim_time, m.step, m.num_joints = 42, 0.0, 0, 3
        m.name, m.position, m.velocity, m.effort = JOINTS, q, [0.01, -0.02, 0.03], [0.0] * 3
        m.generation = gen
        return m.encode()

    def stop(self):
        e = self.t.event_t()
        e.utime, e.sim_time, e.step, e.kind, e.joint, e.value, e.detail = 1, 0.0, 0, "stop", "", 0.0, "stopping"
        self.out.publish(self.prefix + "_EVENT", e.encode())


def play(t, name, command, k):
    prefix = "GEN%s_%d" % (name.upper(), os.getpid())
    port = lcm_port()  # a pair of this run's own
    url = "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=4194304" % port
    d = Daemon(t, url, url.replace(":%d?" % port, ":%d?" % (port + 1)), prefix)
    env = dict(os.environ, LCM_DEFAULT_URL=url)
    cmd = [c.replace("{prefix}", prefix) for c in shlex.split(command)]
    print("---- %s: %s" % (name, " ".join(cmd)), flush=True)
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         universal_newlines=True)
    got = []
    try:
        # 1. the scene once it asks, then a state of generation 1
        ok = d.pump(60, lambda: d.describes > 0)
        check(ok, "%s: asks for the scene" % name)
        if not ok:
            return None
        d.scene(1)
        d.pump(0.5)
        d.scene(1)
        d.pump(1.0)
        s1 = d.state(1, [0.0, 0.05, -0.03])
        d.out.publish(prefix + "_STATE", s1)
        ok = d.pump(30, lambda: len(d.commands) >= 1)
        check(ok and d.commands[0][:2] == (1, 0.0),
              "%s: the state of generation 1 answered with generation 1: %s" % (name, d.commands[:1]))
        if not ok:
            return None
        # 2. a copy: the same answer
        d.out.publish(prefix + "_STATE", s1)
        ok = d.pump(10, lambda: len(d.commands) >= 2)
        check(ok and d.commands[1] == d.commands[0],
              "%s: a copy answered with the same command" % name)
        # 3. generation 2, same step, sim time and utime, another position
        d.scene(2)
        d.pump(0.3)
        n = len(d.commands)
        d.out.publish(prefix + "_STATE", d.state(2, [0.0, 0.06, -0.02]))
        ok = d.pump(10, lambda: any(c[0] == 2 for c in d.commands[n:]))
        new = [c for c in d.commands[n:]]
        check(ok and new and new[0][0] == 2 and new[0][2] != d.commands[0][2],
              "%s: the state of generation 2 answered anew, with generation 2 (not taken for a "
              "copy): %s" % (name, new[:2]))
        # 4. generation 3 without its scene: held, DESCRIBE, then answered
        d.pump(0.3)
        n, asked = len(d.commands), d.describes
        d.out.publish(prefix + "_STATE", d.state(3, [0.0, 0.04, -0.01]))
        d.pump(10, lambda: d.describes >= asked + 2)  # at once and 0.25 s later
        check(len(d.commands) == n and d.describes >= asked + 2,
              "%s: a state whose scene has not come is not answered (%d answers), its scene "
              "asked for (%d DESCRIBE)" % (name, len(d.commands) - n, d.describes - asked))
        d.scene(3)
        ok = d.pump(10, lambda: any(c[0] == 3 for c in d.commands[n:]))
        check(ok, "%s: answered once the scene of generation 3 came" % name)
        got = [c for c in d.commands]
    finally:
        d.stop()
        try:
            out, _ = p.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            p.kill()
            out, _ = p.communicate()
        print(out[-1500:])
    firsts = {}
    for c in got:
        firsts.setdefault(c[0], c)
    return [firsts.get(g) for g in (1, 2, 3)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--types", required=True)
    ap.add_argument("--run", nargs=2, action="append", metavar=("NAME", "COMMAND"), required=True)
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    import lagsim as t
    ref = None
    for k, (name, command) in enumerate(a.run):
        got = play(t, name, command, k)
        if got is None:
            continue
        if ref is None:
            ref = (name, got)
            continue
        same = all(x is not None and y is not None and
                   [struct.pack(">d", v) for v in x[2]] == [struct.pack(">d", v) for v in y[2]]
                   for x, y in zip(ref[1], got))
        check(same, "%s: the answers of generations 1, 2, 3 equal %s's bit for bit" % (name, ref[0]))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
