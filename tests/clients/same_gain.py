#!/usr/bin/env python3
"""Two controllers that design a gain from the same scene must print the same gain.

    same_gain.py --lagsimd BIN --config YAML --tol REL
        --run NAME REGEX "CLIENT COMMAND ... {prefix} ..."  (twice or more)

Each --run goes through run_e2e.py (controller first, then a lockstep daemon with a
prefix of its own, so that the controller gets the scene it designs from) and must end
by itself; REGEX (Python) finds the line with its gain, whose first group holds the
numbers (separated by spaces or commas). The first run is the reference: every other
gain must have as many entries, each within REL of the reference's (|a - b| <= REL |b|).
Prints the gains and the largest relative difference.
"""
import argparse
import os
import re
import shlex
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--tol", type=float, required=True)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--run", nargs=3, action="append", metavar=("NAME", "REGEX", "COMMAND"),
                    required=True)
    a = ap.parse_args()
    e2e = os.path.join(os.path.dirname(os.path.abspath(__file__)), "run_e2e.py")
    gains = []
    for name, regex, command in a.run:
        cmd = [sys.executable, e2e, "--lagsimd", a.lagsimd, "--config", a.config,
               "--mode", "lockstep", "--name", "GAIN" + name.upper(), "--timeout", str(a.timeout),
               "--"] + shlex.split(command)
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           universal_newlines=True)
        m = re.search(regex, r.stdout)
        if not check(r.returncode == 0 and m, "the %s run ended by itself and printed a gain "
                     "matching %r" % (name, regex), r.stdout):
            return verdict()
        k = [float(x) for x in re.split(r"[,\s]+", m.group(1).strip())]
        print("%s: K = [%s]" % (name, ", ".join("%.17g" % x for x in k)))
        gains.append((name, k))
    ref_name, ref = gains[0]
    for name, k in gains[1:]:
        if not check(len(k) == len(ref), "%s has %d entries, %s %d" % (name, len(k), ref_name, len(ref))):
            continue
        rel = max(abs(x - y) / abs(y) if y != 0 else abs(x) for x, y in zip(k, ref))
        check(rel <= a.tol, "%s: largest relative difference from %s %.3g (allowed %.3g)"
              % (name, ref_name, rel, a.tol))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
