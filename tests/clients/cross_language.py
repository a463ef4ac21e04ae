#!/usr/bin/env python3
"""The same lockstep scene driven by the same control law in several languages gives the
same states.

    cross_language.py --lagsimd BIN --config YAML [--set k=v ...] --states N
        --run NAME TOL "CLIENT COMMAND ... {prefix} ... {trace}"  (repeatable)

Each --run goes through run_e2e.py (controller first, then a lockstep daemon with a
prefix of its own) and must answer exactly N states; the client writes one line per
answered state to {trace} (sim time, positions, velocities, efforts sent; numbers that
read back to the same double). The first run is the reference. A run with TOL 0 must
match it bit for bit (every number, compared as IEEE doubles); a run with TOL > 0 must
have the same sim times and every other number within TOL (absolute). Prints the
largest difference of each run.
"""
import argparse
import os
import shlex
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, failures, verdict  # noqa: E402  (tests/common: the one harness)


def load(path):
    rows = []
    with open(path) as f:
        for line in f:
            rows.append([float(x) for x in line.split()])
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--states", type=int, required=True)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--run", nargs=3, action="append", metavar=("NAME", "TOL", "COMMAND"),
                    required=True)
    a = ap.parse_args()
    e2e = os.path.join(os.path.dirname(os.path.abspath(__file__)), "run_e2e.py")
    tmp = tempfile.mkdtemp(prefix="lagsim_xlang_")
    traces = []
    for name, tol, command in a.run:
        trace = os.path.join(tmp, name + ".trace")
        client = [c.replace("{trace}", trace) for c in shlex.split(command)]
        cmd = [sys.executable, e2e, "--lagsimd", a.lagsimd, "--config", a.config,
               "--mode", "lockstep", "--name", "XL" + name.upper(), "--timeout",
               str(a.timeout), "--check", "states == %d" % a.states]
        for s in a.set:
            cmd += ["--set", s]
        r = subprocess.run(cmd + ["--"] + client, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True)
        print("---- %s: %s" % (name, " ".join(client)))
        print(r.stdout.rstrip())
        if not check(r.returncode == 0 and os.path.exists(trace),
                     "the %s run: %d states answered, its trace written" % (name, a.states)):
            continue
        traces.append((name, float(tol), load(trace)))
    if failures():
        return verdict()
    ref_name, _, ref = traces[0]
    print("---- comparison with %s (%d states)" % (ref_name, len(ref)))
    for name, tol, rows in traces[1:]:
        if not check(len(rows) == len(ref) and all(len(r) == len(s) for r, s in zip(rows, ref)),
                     "%s: %d rows against %d, each of the same length" % (name, len(rows), len(ref))):
            continue
        if not check(all(r[0] == s[0] for r, s in zip(rows, ref)), "%s: the same sim times" % name):
            continue
        diff = max(abs(x - y) for r, s in zip(rows, ref) for x, y in zip(r, s))
        if tol == 0.0:
            same = all(struct.pack("<d", x) == struct.pack("<d", y)
                       for r, s in zip(rows, ref) for x, y in zip(r, s))
            check(same, "%s: bit for bit with %s%s" % (name, ref_name,
                  "" if same else " (largest difference %.3g)" % diff))
        else:
            check(diff <= tol, "%s: largest difference from %s %.3g (allowed %.3g)"
                  % (name, ref_name, diff, tol))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
