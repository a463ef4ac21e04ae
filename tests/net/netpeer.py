#!/usr/bin/env python3
"""Helpers of the two-host test (tests/net/two_hosts.sh), with lcm-gen's Python types.

    netpeer.py send --types DIR --url URL --prefix P [--commands N] [--controls N]
                    [--effort E] [--interval S] [--raw]
        publishes N commands (efforts E on the first actuated joint of the DIPC) and N
        STATUS requests on the plant's command URL (plant_urls(URL)), or with --raw on
        URL itself, S s apart
    netpeer.py scene --types DIR --url URL --prefix P [--count N]
        publishes N forged scenes of a DIPC on prefix P on URL itself (the state URL, where
        plants announce themselves), 0.1 s apart
    netpeer.py summary --types DIR --prefix P LOG
        reads an LCM log (lcm-logger) and prints one JSON object: the states (one per step,
        duplicates counted), the events (kind, value, sim time), the last status, and
        how many numbers were not finite
    netpeer.py compare [--first N] TRACE_A TRACE_B
        two --trace files of a controller: one line per answered state (duplicates
        included); after dropping repeated lines of the same sim time, the two must be the
        same text line for line (%.17g: the same bits); with --first, both must have at
        least N states and their first N are compared. Prints the counts; exit 1 if not.
"""
import argparse
import json
import math
import os
import struct
import sys
import time


def load(types, clients_python):
    sys.path.insert(0, types)
    sys.path.insert(0, clients_python)
    import lagsim
    from lagsim_lcm import LCM, plant_urls
    return lagsim, LCM, plant_urls


def read_log(path, stamps=None):
    """Records of an LCM log file: (channel, data); their timestamps (us) appended to the
    list `stamps` if one is given. The format: sync word 0xEDA1DA01, event number (8
    bytes), timestamp (8), channel length (4), data length (4), channel, data; all
    big-endian."""
    out = []
    with open(path, "rb") as f:
        buf = f.read()
    i = 0
    while i + 28 <= len(buf):
        sync, _, utime, clen, dlen = struct.unpack(">IqqII", buf[i:i + 28])
        if sync != 0xEDA1DA01 or i + 28 + clen + dlen > len(buf):
            break
        ch = buf[i + 28:i + 28 + clen].decode("ascii", "replace")
        out.append((ch, buf[i + 28 + clen:i + 28 + clen + dlen]))
        if stamps is not None:
            stamps.append(utime)
        i += 28 + clen + dlen
    return out


def cmd_send(a):
    lagsim, LCM, plant_urls = load(a.types, a.clients)
    command_url = a.url if a.raw else plant_urls(a.url)[1]
    lc = LCM(command_url)
    for k in range(max(a.commands, a.controls)):
        if k < a.commands:
            c = lagsim.joint_command_t()
            c.utime = int(time.time() * 1e6)
            c.sim_time = 0.0
            c.num_joints, c.name, c.effort = 1, ["theta0"], [a.effort]
            lc.publish(a.prefix + "_COMMAND", c.encode())
        if k < a.controls:
            r = lagsim.control_t()
            r.utime = int(time.time() * 1e6)
            r.request = lagsim.control_t.STATUS
            lc.publish(a.prefix + "_CONTROL", r.encode())
        time.sleep(a.interval)
    lc.close()
    print("sent %d commands and %d STATUS requests to %s" % (a.commands, a.controls, command_url))
    return 0


def cmd_scene(a):
    lagsim, LCM, _ = load(a.types, a.clients)
    lc = LCM(a.url)
    for k in range(a.count):
        s = lagsim.scene_t()
        s.utime = int(time.time() * 1e6)
        s.model, s.prefix = "dipc", a.prefix
        s.num_params, s.param_name, s.param_value = 1, ["m0"], [1.5]
        s.num_joints, s.joint_name = 3, ["theta0", "theta1", "theta2"]
        s.actuated, s.initial_q, s.initial_qd = [True, False, False], [0.0] * 3, [0.0] * 3
        s.dt, s.control_period, s.integrator, s.mode = 0.001, 0.01, "rk4", "realtime"
        s.rate, s.command_timeout, s.effects = 1.0, 0.5, ""
        s.limit_on, s.limit_lower, s.limit_upper = [False] * 3, [0.0] * 3, [0.0] * 3
        lc.publish(a.prefix + "_SCENE", s.encode())
        time.sleep(0.1)
    lc.close()
    print("sent %d forged scenes of prefix %s to %s" % (a.count, a.prefix, a.url))
    return 0


def cmd_summary(a):
    lagsim, _, _ = load(a.types, a.clients)
    states, dup, events, status, nonfinite = {}, 0, [], None, 0
    statuses = 0
    stamps, first_seen = [], {}  # the logger's receive time of each step's first copy
    for k, (ch, data) in enumerate(read_log(a.log, stamps)):
        if ch == a.prefix + "_STATE":
            st = lagsim.joint_state_t.decode(data)
            first_seen.setdefault(st.step, stamps[k])
            nums = [st.sim_time] + list(st.position) + list(st.velocity) + list(st.effort)
            nonfinite += sum(1 for x in nums if not math.isfinite(x))
            key = st.step
            row = [st.sim_time] + list(st.position) + list(st.velocity) + list(st.effort)
            if key in states:
                dup += 1
                if states[key] != row and st.step != 0:
                    print("state at step %d published twice with different values" % key,
                          file=sys.stderr)
            states[key] = row
        elif ch == a.prefix + "_EVENT":
            ev = lagsim.event_t.decode(data)
            nonfinite += 0 if math.isfinite(ev.value) and math.isfinite(ev.sim_time) else 1
            events.append({"kind": ev.kind, "value": ev.value, "t": ev.sim_time,
                           "detail": ev.detail})
        elif ch == a.prefix + "_STATUS":
            s = lagsim.status_t.decode(data)
            statuses += 1
            for x in (s.sim_time, s.rtf, s.energy, s.wall_time):
                nonfinite += 0 if math.isfinite(x) else 1
            status = {k: getattr(s, k) for k in s.__slots__} if hasattr(s, "__slots__") else vars(s)
    steps = sorted(states)
    # the longest wall time from one state to the next (in lockstep: an answer's round
    # trip), from the second state on (the first waits for the controller to start)
    gaps = [first_seen[b] - first_seen[a] for a, b in zip(steps[1:], steps[2:])]
    print(json.dumps({"states": len(states), "duplicates": dup,
                      "slowest_step_s": max(gaps) * 1e-6 if gaps else None,
                      "first_step": steps[0] if steps else None,
                      "last_step": steps[-1] if steps else None,
                      "last_state": states[steps[-1]] if steps else None,
                      "events": events, "statuses": statuses, "status": status,
                      "nonfinite": nonfinite}, default=str))
    return 0


def dedup(path):
    lines, seen = [], set()
    for line in open(path):
        t = line.split(" ", 1)[0]
        if t in seen:
            continue
        seen.add(t)
        lines.append(line)
    return lines


def cmd_compare(a):
    ra, rb = open(a.a).read().splitlines(), open(a.b).read().splitlines()
    da, db = dedup(a.a), dedup(a.b)
    print("trace %s: %d lines, %d states; trace %s: %d lines, %d states"
          % (a.a, len(ra), len(da), a.b, len(rb), len(db)))
    if a.first:
        if len(da) < a.first or len(db) < a.first:
            print("fewer than %d states" % a.first)
            return 1
        da, db = da[:a.first], db[:a.first]
    if da != db:
        n = min(len(da), len(db))
        k = next((i for i in range(n) if da[i] != db[i]), n)
        print("first difference at state %d:\n  %s  %s" % (k, da[k].strip() if k < len(da) else "-",
                                                           db[k].strip() if k < len(db) else "-"))
        return 1
    print("the same %d states, bit for bit" % len(da))
    return 0


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    here = os.path.dirname(os.path.abspath(__file__))
    clients = os.path.join(here, "..", "..", "clients", "python")
    s = sub.add_parser("send")
    s.add_argument("--types", required=True)
    s.add_argument("--url", required=True)
    s.add_argument("--prefix", required=True)
    s.add_argument("--commands", type=int, default=20)
    s.add_argument("--controls", type=int, default=5)
    s.add_argument("--effort", type=float, default=50.0)
    s.add_argument("--interval", type=float, default=0.05)
    s.add_argument("--raw", action="store_true", help="publish on URL, not its command URL")
    f = sub.add_parser("scene")
    f.add_argument("--types", required=True)
    f.add_argument("--url", required=True)
    f.add_argument("--prefix", required=True)
    f.add_argument("--count", type=int, default=3)
    m = sub.add_parser("summary")
    m.add_argument("--types", required=True)
    m.add_argument("--prefix", required=True)
    m.add_argument("log")
    c = sub.add_parser("compare")
    c.add_argument("--first", type=int, default=0)
    c.add_argument("a")
    c.add_argument("b")
    a = ap.parse_args()
    a.clients = clients
    return {"send": cmd_send, "scene": cmd_scene, "summary": cmd_summary,
            "compare": cmd_compare}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
