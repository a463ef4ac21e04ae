#!/usr/bin/env python3
"""A real run's state CSV, as people load it: docs/view.md's blocks run as written.

    test_log2csv_load.py --bin BUILD/bin --source SRC

lagsimd records the DIPC (--log) while it waits 1.5 s for its first command (the state at
t = 0 published again and again) and then dipc_lqr answers 1 s of states; lagsim-log2csv
makes run/DIPC_STATE.csv. Then:
  - the CSV: one row per state (sim time strictly increasing, 101 rows), the summary counts
    the copies of the state at t = 0; no quotes (no name needs them);
  - Octave (docs/view.md's block): importdata's column names are the header's, without
    quotes; its numbers and csvread's (from the second line) are the same, and are the
    doubles Python reads from the text;
  - Python's csv (the block) and pandas (the block, if pandas is installed) read the same.
"""
import argparse
import csv
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def blocks(src):
    """docs/view.md's blocks marked <!-- load: NAME -->: {NAME: code}."""
    text = open(os.path.join(src, "docs", "view.md")).read()
    return {m.group(1): m.group(2) for m in
            re.finditer(r"<!-- load: (\S+) -->\s*\n```\w+\n(.*?)\n```", text, re.S)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    a.bin, a.source = os.path.abspath(a.bin), os.path.abspath(a.source)
    b = lambda p: os.path.join(a.bin, p)
    code = blocks(a.source)
    check(set(code) >= {"octave", "python", "pandas"}, "docs/view.md's blocks: %s" % sorted(code))
    pid = os.getpid()
    os.environ["LCM_DEFAULT_URL"] = lcm_url()  # a port pair of this process's own
    tmp = tempfile.mkdtemp(prefix="lagsim_load_")
    try:
        d = subprocess.Popen([b("lagsimd"), "--config", os.path.join(a.source, "config", "dipc.yaml"),
                              "--duration", "1", "-q", "--log", "run.lcm"], cwd=tmp)
        time.sleep(1.5)  # the plant waits: the state at t = 0 goes out again and again
        c = subprocess.run([b("dipc_lqr"), "-q", "--duration", "1"], cwd=tmp,
                           stdout=subprocess.DEVNULL, timeout=60)
        rc = d.wait(timeout=60)
        check(rc == 0 and c.returncode == 0, "a run recorded (lagsimd %d, dipc_lqr %d)"
              % (rc, c.returncode))
        p = subprocess.run([b("lagsim-log2csv"), "run.lcm", "-o", "run"], cwd=tmp,
                           stdout=subprocess.PIPE, universal_newlines=True, timeout=60)
        m = re.search(r"copies (\d+) \(a state sent again unchanged: one row\)", p.stdout)
        check(p.returncode == 0 and m and int(m.group(1)) > 10,
              "the summary counts the copies of the state at t = 0 (%s)" % (m and m.group(0)))
        path = os.path.join(tmp, "run", "DIPC_STATE.csv")
        raw = open(path).read()
        rows = list(csv.reader(open(path, newline="")))
        head, data = rows[0], [[float(x) for x in r] for r in rows[1:]]
        t = [r[0] for r in data]
        check('"' not in raw and head[:6] == ["t", "wall_time", "log_time", "step",
                                               "generation", "theta0"],
              "no quotes: the header's names as they are (%s)" % head[:6])
        check(len(data) == 101 and all(b2 > b1 for b1, b2 in zip(t, t[1:])),
              "one row per state: 101 rows, sim time strictly increasing (%d rows)" % len(data))

        # Octave: the block, then what it gave
        if shutil.which("octave"):
            probe = (code["octave"] + "\n"
                     "printf('%s\\n', strjoin(d.colheaders, ','));\n"
                     "printf('%d %d %d %d\\n', size(d.data), size(m));\n"
                     "printf('%d\\n', isequal(d.data, m));\n"
                     "printf('%.17g\\n', theta1(end), t(end), sum(m(:, 7)));\n")
            o = subprocess.run(["octave", "--no-gui", "--quiet", "--norc", "--eval", probe],
                               cwd=tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               universal_newlines=True, timeout=120)
            out = o.stdout.split("\n")
            print(o.stdout[-600:], o.stderr[-600:])
            check(len(out) >= 6 and out[0] == ",".join(head),
                  "Octave importdata: the column names, no quotes (%s)" % out[:1])
            check(len(out) >= 6 and out[1] == "101 %d 101 %d" % (len(head), len(head))
                  and out[2] == "1", "Octave: importdata's numbers are csvread's (%s, %s)"
                  % (out[1:2], out[2:3]))
            j = head.index("theta1")
            want = [data[-1][j], data[-1][0], sum(r[j] for r in data)]
            got = [float(x) for x in out[3:6]] if len(out) >= 6 else []
            check(got[:2] == want[:2] and abs(got[2] - want[2]) <= 1e-12 * max(1, abs(want[2])),
                  "Octave reads the doubles Python reads (%s, %s)" % (got, want))
        else:
            check(False, "GNU Octave is installed (.ci/install-deps.sh)")

        # Python: the blocks
        env = {}
        cwd = os.getcwd()
        os.chdir(tmp)
        try:
            exec(code["python"], env)
            check(env["t"] == t and env["theta1"] == [r[head.index("theta1")] for r in data],
                  "Python's csv block: t and theta1")
            # pandas: in this Python, or Debian's (python3-pandas)
            py = [x for x in (sys.executable, "/usr/bin/python3") if os.path.exists(x) and
                  subprocess.run([x, "-c", "import pandas"], stderr=subprocess.DEVNULL).returncode == 0]
            if py:
                probe = code["pandas"] + "\nprint(','.join(d.columns))\nprint(repr(list(d['theta1'])))\n"
                o = subprocess.run([py[0], "-c", probe], stdout=subprocess.PIPE,
                                   universal_newlines=True, timeout=120)
                out = o.stdout.split("\n")
                check(len(out) > 1 and out[0] == ",".join(head) and
                      eval(out[1]) == env["theta1"], "pandas' block (%s): the same columns and "
                      "numbers" % py[0])
            else:
                print("pandas not installed here: its block not run")
        finally:
            os.chdir(cwd)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
