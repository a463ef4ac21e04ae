#!/usr/bin/env python3
"""A log written by lagsim 0.1.0 (whose types had no generation) stays readable.

usage: test_old_log.py BIN_DIR SOURCE_DIR CASE

tests/log/fixtures/dipc_lockstep_0.1.0.lcm: 0.5 s of the DIPC in lockstep, dipc_lqr
answering, recorded by lagsimd --log of lagsim 0.1.0; dipc_lockstep_0.1.0_STATE.csv:
what 0.1.0's lagsim-log2csv wrote of its states.
  replay   lagsimd --replay re-simulates its 51 states exactly (difference 0, exit 0)
  log2csv  lagsim-log2csv reads every record (none undecodable) and writes the states
           0.1.0's lagsim-log2csv wrote, number for number, with a generation column (0:
           the version had none) after step
"""
import csv
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

BIN, SRC, CASE = sys.argv[1], sys.argv[2], sys.argv[3]
FIX = os.path.join(SRC, "tests", "log", "fixtures")
LOG = os.path.join(FIX, "dipc_lockstep_0.1.0.lcm")


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=120)
    print("$", " ".join(cmd), "->", p.returncode)
    print(p.stdout[-2000:], p.stderr[-2000:])
    return p


def case_replay(tmp):
    p = run([os.path.join(BIN, "lagsimd"), "--config", os.path.join(SRC, "config", "dipc.yaml"),
             "--set", "realtime.mode=lockstep", "--replay", LOG])
    check(p.returncode == 0 and "51 states compared" in p.stdout and
          "0 undecodable" in p.stdout and "max difference = 0\n" in p.stdout,
          "--replay of a 0.1.0 log: 51 states, none undecodable, difference 0, exit 0")


def case_log2csv(tmp):
    out = os.path.join(tmp, "csv")
    p = run([os.path.join(BIN, "lagsim-log2csv"), LOG, "-o", out])
    check(p.returncode == 0 and not re.search(r", \d+ undecodable", p.stdout),
          "lagsim-log2csv reads a 0.1.0 log whole (exit %d)" % p.returncode)
    with open(os.path.join(FIX, "dipc_lockstep_0.1.0_STATE.csv"), newline="") as f:
        old = list(csv.reader(f))
    path = os.path.join(out, "DIPC_STATE.csv")
    new = list(csv.reader(open(path, newline=""))) if os.path.exists(path) else [[]]
    want = old[0][:4] + ["generation"] + old[0][4:]
    check(new[0] == want, "the columns of 0.1.0 with generation after step: %s" % new[0])
    # 0.1.0 wrote a row for the copy of the state at t = 0 (the same step and numbers sent
    # again); today's writes each state once and counts the copy in its summary
    old_rows = [[float(x) for x in o] for o in old[1:]]
    once = [o for k, o in enumerate(old_rows)
            if k == 0 or not (o[3] == old_rows[k - 1][3] and o[4:] == old_rows[k - 1][4:])]
    # the same doubles (0.1.0 wrote %.17g, today's the shortest decimal that reads back)
    same = len(old) == 53 and len(once) == 51 and len(new) == 52 and all(
        [float(x) for x in n[:4]] == o[:4] and n[4] == "0" and
        [float(x) for x in n[5:]] == o[4:] for n, o in zip(new[1:], once))
    check(same and "copies 1 (a state sent again unchanged: one row)" in p.stdout,
          "51 states (0.1.0 wrote 52 rows: 51 and a copy), every number the double 0.1.0's "
          "lagsim-log2csv wrote, generation 0; the copy counted")
    for ch in ("DIPC_SCENE", "DIPC_COMMAND"):
        rows = list(csv.DictReader(open(os.path.join(out, ch + ".csv"), newline="")))
        check(len(rows) > 0 and all(r["generation"] == "0" for r in rows),
              "%s: %d rows, generation 0" % (ch, len(rows)))


if __name__ == "__main__":
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        {"replay": case_replay, "log2csv": case_log2csv}[CASE](tmp)
    sys.exit(verdict(CASE))
