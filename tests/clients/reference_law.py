#!/usr/bin/env python3
"""A controller's law handed the scene's reference, checked from the daemon's log:

    reference_law.py --lagsimd BIN --config YAML --types DIR [--set K=V ...]
                     [--duration S] [--lose-every N] [--hostile] [--name NAME]
                     [--check EXPR ...] [--timeout S] -- CLIENT ARGS...

The client is a controller whose law answers each joint with the r of the reference its
library handed it for that state (0 for a joint without one): tests/clients/reference/.
It is started first ("{prefix}" in its arguments is this run's channel prefix); once it
is subscribed, lagsimd runs the scene in lockstep for --duration s of sim time with
--log, then stops (the client ends on its stop event). The check reads the log
(tests/common/lcm_log.py): every command the daemon received must carry, for every joint
of the state it answers (its sim_time), exactly the r of the reference the client should
have been handed: the one published with that state, or, where it did not reach the
client, the last one that did before it; 0 for a joint that reference does not name, or
before any reached it. The client's summary must count the states answered with an older
reference in references_stale, exactly.

--lose-every N: the daemon and the client are on two buses (ports of their own) joined by
a relay here, which passes every message both ways but loses the references of every Nth
state (sim times 1, N + 1, 2 N + 1, ... periods in: the first reaches the client), copies
included: a deterministic UDP loss. Without it they share one bus.

--hostile: forged references (bad sizes, a string length of -1, 10^9 or 2^31-1, a name
without its NUL, 32767 and -1 joints, NaN and infinite numbers, each the bytes of a
reference whose r would otherwise be answered) are published on the client's
<PREFIX>_REFERENCE three times once it is subscribed, before the daemon starts, then every
20 ms while it runs. It must drop and count every one (dropped >= three times their
number) and answer as if none had come: the log check above.

--check EXPR: Python over the summary's key=value pairs (also `expected_stale`, `lost`,
`hostile`, `commands`), as in run_e2e.py. Exit 0 when all holds.
"""
import argparse
import math
import os
import struct
import subprocess
import sys
import tempfile
import threading
import select
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
sys.path.insert(0, os.path.join(HERE, "..", "..", "clients", "python"))
from lcm_log import read_log  # noqa: E402
from lagsim_lcm import LCM  # noqa: E402
from run_e2e import parse_summary  # noqa: E402
from lagsim_check import check_expressions, stop  # noqa: E402  (tests/common: the one harness)
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_port  # noqa: E402  (a port pair of this process's own)


def url(port):
    return "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=4194304" % port


def forged_references(t):
    """[(what, bytes)]: references that must not decode whole, each built from a valid one
    whose r (1e3 on every joint) a law would answer if it were kept."""
    def valid(names, r, rdot, sim_time=0.5):
        m = t.reference_t()
        m.utime, m.sim_time, m.step = 1, sim_time, 500
        m.num_joints, m.name, m.r, m.rdot = len(names), list(names), list(r), list(rdot)
        m.rddot = [0.0] * len(names)
        return m.encode()

    good = valid(["q1", "q2"], [1e3, 1e3], [0.0, 0.0])
    # layout: fingerprint (8), utime (8), sim_time (8), step (8), num_joints (2) at 32,
    # then the first name's int32 length (with its NUL) at 34, its bytes, its NUL
    n_at, len_at = 32, 34
    q1_nul = len_at + 4 + 2

    def patch(b, at, fmt, v):
        b = bytearray(b)
        struct.pack_into(fmt, b, at, v)
        return bytes(b)

    return [
        ("truncated by 4 bytes", good[:-4]),
        ("3 bytes too many", good + b"\0\0\0"),
        ("num_joints 32767", patch(good, n_at, ">h", 32767)),
        ("num_joints -1", patch(good, n_at, ">h", -1)),
        ("num_joints 3 with 2 joints' bytes", patch(good, n_at, ">h", 3)),
        ("name length -1", patch(good, len_at, ">i", -1)),
        ("name length 10^9", patch(good, len_at, ">i", 10**9)),
        ("name length 2^31-1", patch(good, len_at, ">i", 2**31 - 1)),
        ("name without its NUL", good[:q1_nul] + b"x" + good[q1_nul + 1:]),
        ("NaN r", valid(["q1", "q2"], [float("nan"), 1e3], [0.0, 0.0])),
        ("infinite rdot", valid(["q1", "q2"], [1e3, 1e3], [0.0, float("inf")])),
        ("NaN sim_time", valid(["q1", "q2"], [1e3, 1e3], [0.0, 0.0], float("nan"))),
    ]


def whole(t, data):
    """True if `data` is a reference that decodes whole, every number finite: it encodes
    back to the same bytes (the rule of the Python controller library, _decode)."""
    try:
        m = t.reference_t.decode(data)
        return m.encode() == data and all(math.isfinite(x) for x in
                                          [m.sim_time] + list(m.r) + list(m.rdot) + list(m.rddot))
    except Exception:
        return False


class Relay(object):
    """Passes the daemon's messages (bus A) to the client (bus B) and the client's commands
    and control requests back, losing the references of every `every`th state."""

    def __init__(self, t, prefix, port_a, port_b, every):
        self.t, self.prefix, self.every = t, prefix, every
        self.a_state, self.a_cmd = LCM(url(port_a)), LCM(url(port_a + 1))
        self.b_state, self.b_cmd = LCM(url(port_b)), LCM(url(port_b + 1))
        self.times = {}       # sim_time of a reference -> lost
        self.done = threading.Event()
        p = prefix + "_"
        self.a_state.subscribe(p + "REFERENCE", self.on_reference)  # before its state's
        self.a_state.subscribe(p + "(STATE|STATUS|EVENT|SCENE)",
                               lambda ch, d: self.b_state.publish(ch, d))
        self.b_cmd.subscribe(p + "(COMMAND|CONTROL)", lambda ch, d: self.a_cmd.publish(ch, d))
        self.th = threading.Thread(target=self.run, daemon=True)
        self.th.start()

    def on_reference(self, ch, data):
        r = self.t.reference_t.decode(data)
        if r.sim_time not in self.times:
            self.times[r.sim_time] = len(self.times) % self.every == 1
        if not self.times[r.sim_time]:
            self.b_state.publish(ch, data)

    def run(self):
        while not self.done.is_set():
            ready, _, _ = select.select([self.a_state, self.b_cmd], [], [], 0.05)
            for lc in ready:
                lc.handle_timeout(0)

    def close(self):
        self.done.set()
        self.th.join(5.0)

    def lost(self):
        return {s for s, gone in self.times.items() if gone}


def check_log(t, log, prefix, lost):
    """(commands checked, expected references_stale, failures) from the daemon's log."""
    refs, states, cmds = {}, set(), []
    for _, ch, data in read_log(log):
        if ch == prefix + "_REFERENCE":
            r = t.reference_t.decode(data)
            refs[r.sim_time] = r
        elif ch == prefix + "_STATE":
            states.add(t.joint_state_t.decode(data).sim_time)
        elif ch == prefix + "_COMMAND":
            cmds.append(t.joint_command_t.decode(data))
    fails, stale, answered = [], 0, set()
    for c in cmds:
        if c.sim_time not in states:
            fails.append("a command at t = %r answers no state" % c.sim_time)
            continue
        # the reference the client was handed: the last one it received up to this state
        got = [s for s in refs if s <= c.sim_time and s not in lost]
        ref = refs[max(got)] if got else None
        if c.sim_time not in answered:
            answered.add(c.sim_time)
            stale += ref is not None and ref.sim_time != c.sim_time
        for name, effort in zip(c.name, c.effort):
            want = ref.r[ref.name.index(name)] if ref is not None and name in ref.name else 0.0
            if effort != want:
                fails.append("t = %r, %s: effort %r, its reference's r %r (reference of t = %r)"
                             % (c.sim_time, name, effort, want, ref.sim_time if ref else None))
    if not refs:
        fails.append("no reference in the log")
    if len(answered) < len(states) - 1:
        fails.append("%d states answered of %d" % (len(answered), len(states)))
    return len(cmds), stale, fails


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--types", required=True, help="the lcm-gen Python types (<build>/python)")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--lose-every", type=int, default=0)
    ap.add_argument("--hostile", action="store_true")
    ap.add_argument("--name", default="REFLAW")
    ap.add_argument("--check", action="append", default=[])
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("client", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    client = a.client[1:] if a.client and a.client[0] == "--" else a.client
    if not client:
        ap.error("no client command")
    sys.path.insert(0, a.types)
    import lagsim as t

    prefix = "%s_%d" % (a.name.upper(), os.getpid())
    client = [c.replace("{prefix}", prefix) for c in client]
    tmp = tempfile.mkdtemp(prefix="lagsim_reflaw_")
    log = os.path.join(tmp, "run.lcm")
    # the client's bus: a multicast port of this run's own (run_e2e.py says why); the
    # daemon's, with a relay, another of its own
    port_b = lcm_port()
    env = dict(os.environ, LCM_DEFAULT_URL=url(port_b))
    print("client:", " ".join(client), flush=True)
    cproc = dproc = relay = fth = None
    done = threading.Event()
    lines, n_hostile = [], [0]
    try:
        cproc = subprocess.Popen(client, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 universal_newlines=True, env=env)
        rd = waits.Reader(cproc, lines)
        ready, th = rd.ready, rd.thread
        if not ready.wait(20.0) or cproc.poll() is not None:
            print("".join(lines) + "FAIL: the client did not get ready")
            return 1
        port_a = port_b
        if a.lose_every:
            port_a = lcm_port()
            relay = Relay(t, prefix, port_a, port_b, a.lose_every)
        if a.hostile:
            forged = forged_references(t)
            hlc = LCM(url(port_b))
            for what, data in forged:  # each is damaged by the rule every client keeps
                if whole(t, data):
                    print("FAIL: the forged reference '%s' decodes whole" % what)
                    return 1
            for _ in range(3):
                for _, data in forged:
                    hlc.publish(prefix + "_REFERENCE", data)
                    n_hostile[0] += 1
            time.sleep(0.5)

            def flood():
                while cproc.poll() is None and not done.is_set():
                    for _, data in forged:
                        hlc.publish(prefix + "_REFERENCE", data)
                        n_hostile[0] += 1
                    done.wait(0.02)

            fth = threading.Thread(target=flood, daemon=True)
            fth.start()
        dcmd = [a.lagsimd, "--config", a.config, "--set", "lcm.prefix=" + prefix,
                "--set", "realtime.mode=lockstep", "-q", "--duration", repr(a.duration),
                "--log", log]
        for s in a.set:
            dcmd += ["--set", s]
        print("daemon:", " ".join(dcmd), flush=True)
        dproc = subprocess.Popen(dcmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                 universal_newlines=True, env=dict(os.environ, LCM_DEFAULT_URL=url(port_a)))
        # the daemon stops after --duration and the client on its stop event; a client
        # that ended before leaves the daemon waiting in lockstep: stopped 5 s later
        deadline = time.monotonic() + a.timeout
        while cproc.poll() is None and dproc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        try:
            cproc.wait(timeout=max(0.0, deadline - time.monotonic()))
            dproc.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            pass
        if cproc.poll() is None:
            stop(cproc, 3.0)
            print("".join(lines) + "FAIL: the client did not finish within %g s" % a.timeout)
            print("client stderr:\n" + cproc.stderr.read())
            return 1
        stop(dproc, 3.0)
        th.join(5.0)
        err = cproc.stderr.read()
    finally:
        done.set()
        if fth:
            fth.join(5.0)
        if relay:
            relay.close()
        stop(cproc, 3.0)
        stop(dproc, 3.0)
    out = "".join(lines)
    sys.stdout.write(out)
    if err:
        sys.stdout.write("client stderr:\n" + err)
    derr = dproc.stderr.read()
    if derr.strip():
        sys.stdout.write("daemon stderr:\n" + derr)
    if cproc.returncode != 0 or dproc.returncode != 0:
        print("FAIL: exit status %d (client), %d (daemon)" % (cproc.returncode, dproc.returncode))
        return 1
    vals = parse_summary(out)
    if vals is None:
        print("FAIL: no summary line from the client")
        return 1
    lost = relay.lost() if relay else set()
    n, stale, fails = check_log(t, log, prefix, lost)
    for f in fails[:10]:
        print("FAIL: " + f)
    print("%d commands checked against the log; %d references lost on the way; "
          "%d states answered with an older reference" % (n, len(lost), stale))
    ok = not fails
    names = dict(vals, expected_stale=stale, lost=len(lost), hostile=n_hostile[0], commands=n,
                 math=math)
    ok = check_expressions(a.check, names) and ok
    if ok:
        os.remove(log)
        os.rmdir(tmp)
    else:
        print("the log: %s" % log)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
