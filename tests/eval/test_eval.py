#!/usr/bin/env python3
"""lagsim-eval end to end: the cart-pole held by lqr_balance through the cases of
tests/eval/cartpole_cases.yaml.

usage: test_eval.py BIN_DIR SOURCE_DIR CASE
  metrics    each joint's metrics against an independent look at the logged states
             (lagsim-log2csv's CSV of the run's kept log): settling time where |q| last
             leaves the 2 % band, peak error, IAE by trapezoids, the effort's peak, and
             the case that passes a bound fails
  require    --require holding (exit 0), not holding (exit 1), naming an unknown joint
             or metric (exit 2)
  errors     a case file with a mistake: exit 2 and file:line:column
  scene      cases in the scene file: lagsimd ignores them, lagsim-eval runs them
  owned      the keys the tools set on every run (their --help's table): a case's set:
             naming one, or a mapping above one, is refused (exit 2, file:line:column,
             the key) by lagsim-eval and lagsim-sweep, and so is a --vary of one;
             docs/evaluation.md and both man pages list exactly the table's keys; every
             key of the loader's table is either the tools' or one the test says a case
             may set (and why), never neither
  bus        the runs' URL: the group and options of LCM_DEFAULT_URL or --url, ports of
             the tools' own (an even pair of 64000..65535): two lagsim-evals and a sweep of
             two workers run at once on four pairs, each held (its lock file locked) while
             its controller runs; ttl above 0 only with --allow-lan; memq:// and other
             providers refused; {prefix} and {url} replaced as they are, inside quotes too
  notes      what a new user misread, said: -v names the directory where it keeps the
             runs' logs; a case with a reference for q1 and none for q2 says in the
             table's notes that q2 is scored against r = 0 (a case with both: no note); a
             controller command with {url} outside quotes that ends before its run says
             to write '{url}' (the URL's '&' ended the command), quoted: no such words
  waits      a controller on another prefix (alive, waiting for its scene): within
             seconds of the case's start, long before --timeout, one line on stderr says in
             the daemon's words what the plant waits for (the first command, on the run's
             <PREFIX>_COMMAND at its command URL) and to give the command {prefix}; a
             controller on the run's prefix: no such line
  stderr     without -v the controller's stderr is the run's, not the terminal's: a
             controller that talks on stderr and works says nothing through lagsim-eval
             or lagsim-sweep; one that fails has its last 8 lines shown under the case's
             note (lagsim-sweep: a worker's first failed run, on stderr); -v passes it
             through
  outputs    no output of lagsim-eval or lagsim-sweep is a file they read (the scene, the
             suite, the daemon; merge's shards) or another of their outputs (the CSV and
             the report's or the plot's files), whatever its spelling (./, a hard link),
             with --force too: exit 2 before any run, the file untouched
"""
import csv
import glob
import math
import os
import re
import select
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

BIN, SRC, CASE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]), sys.argv[3]
SCENE = os.path.join(SRC, "config", "cartpole.yaml")
SUITE = os.path.join(SRC, "tests", "eval", "cartpole_cases.yaml")
CTRL = os.path.join(BIN, "lqr_balance") + " -q --prefix {prefix}"
EVAL = os.path.join(BIN, "lagsim-eval")


def run(*args, timeout=300):
    p = subprocess.run([EVAL, "--config", SCENE, "--controller", CTRL] + list(args),
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    print("$ lagsim-eval", " ".join(args), "->", p.returncode)
    print(p.stdout[-3000:], p.stderr[-3000:])
    return p


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def settle(t, q, band):
    """The last time |q| leaves the band, interpolated linearly (0 if it never does)."""
    last = None
    for k in range(len(t) - 1):
        a, b = abs(q[k]), abs(q[k + 1])
        if a > band >= b:
            # |q| is monotone across the sample pair here (one sign); linear crossing
            qa, qb = q[k], q[k + 1]
            s = band if qa > 0 else -band
            last = t[k] + (t[k + 1] - t[k]) * (qa - s) / (qa - qb) if qa != qb else t[k + 1]
        elif b > band:
            last = math.inf  # still outside
    return 0.0 if last is None else last


def case_metrics():
    with tempfile.TemporaryDirectory() as d:
        rep = os.path.join(d, "report")
        out = os.path.join(d, "eval.csv")
        p = run("--suite", SUITE, "--case", "tilt", "--case", "push", "--case", "push_end",
                "--csv", out, "--report", rep, "-v")
        check(p.returncode == 0, "tilt, push and push_end pass (exit 0)")
        rows = {(r["case"], r["joint"]): r for r in read_csv(out)}
        cases = ("tilt", "push", "push_end")
        check(set(rows) == {(c, j) for c in cases for j in ("x", "theta")},
              "one CSV row per case and joint")
        check(all(os.path.getsize(os.path.join(rep, c + ".png")) > 10000 for c in cases),
              "a PNG report per case")
        # the logs in case order (the prefix ends in the case's index in the suite)
        logs = sorted(glob.glob(os.path.join(rep, "EVAL*_*.lcm")),
                      key=lambda p: int(p.rsplit("_", 1)[1].split(".")[0]))
        check(len(logs) == 3, "-v keeps each run's log (%d)" % len(logs))
        for log, case in zip(logs, cases):
            cdir = os.path.join(d, case)
            subprocess.run([os.path.join(BIN, "lagsim-log2csv"), log, "-o", cdir, "-q"],
                           check=True)
            st = read_csv(glob.glob(os.path.join(cdir, "*_STATE.csv"))[0])
            t = [float(r["t"]) for r in st]
            # a state published twice (a lockstep retry) is one sample
            keep = [k for k in range(len(t)) if k == 0 or t[k] > t[k - 1]]
            t = [t[k] for k in keep]
            T = 1.1 if case == "push_end" else 8.0
            check(abs(t[-1] - T) < 1e-9 and len(t) == round(T * 100) + 1,
                  "%s: a state every 10 ms up to t = %g s (%d, %g)" % (case, T, len(t), t[-1]))
            for j in ("x", "theta"):
                q = [float(st[k][j]) for k in keep]
                u = [float(st[k][j + "_effort"]) for k in keep]
                m = rows[(case, j)]
                A = 0.0 - q[0]
                peak = max(abs(v) for v in q)
                band = 0.02 * (abs(A) if A != 0 else peak)
                ts = settle(t, q, band)
                # a run that ends outside the band has no settling time (nan)
                check(m["settle"] == "nan" if ts == math.inf else
                      abs(float(m["settle"]) - ts) < 1e-6,
                      "%s %s: settle %s = last exit of the %.3g band %.9g"
                      % (case, j, m["settle"], band, ts))
                check(abs(float(m["peak_error"]) - peak) < 1e-5 * max(peak, 1e-9),
                      "%s %s: peak_error %s = max|q| %.9g" % (case, j, m["peak_error"], peak))
                iae = 0.0
                for k in range(len(t) - 1):  # |e| by trapezoids, split at sign changes
                    a, b = q[k], q[k + 1]
                    h = t[k + 1] - t[k]
                    if a * b >= 0:
                        iae += 0.5 * h * (abs(a) + abs(b))
                    else:
                        iae += 0.5 * h * (a * a + b * b) / (abs(a) + abs(b))
                check(abs(float(m["iae"]) - iae) < 1e-5 * iae,
                      "%s %s: iae %s = trapezoids %.9g" % (case, j, m["iae"], iae))
                # a state carries the effort held over the period that ended at it: the
                # effort held from t[k] to t[k+1] is state k+1's
                rms = math.sqrt(sum(u[k + 1] ** 2 * (t[k + 1] - t[k])
                                    for k in range(len(t) - 1)) / (t[-1] - t[0]))
                check(abs(float(m["effort_rms"]) - rms) < 1e-9 + 1e-6 * rms,
                      "%s %s: effort_rms %s = held efforts' %.9g" % (case, j,
                                                                     m["effort_rms"], rms))
                ep = max(abs(v) for v in u)
                check(abs(float(m["effort_peak"]) - ep) < 1e-5 * max(ep, 1e-9),
                      "%s %s: effort_peak %s = max|effort| %.9g" % (case, j,
                                                                    m["effort_peak"], ep))
        # the push moves nothing before t = 1 s: no step, the band is 2 % of the peak
        check(rows[("push", "theta")]["rise"] == "nan", "push: no step, no rise time")
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "falls.csv")
        p = run("--suite", SUITE, "--case", "falls", "--csv", out)
        check(p.returncode == 1, "a bound passed fails the case (exit 1)")
        r = read_csv(out)
        check(all(x["failed"] == "1" and "past its bound 0.05" in x["reason"] for x in r),
              "the CSV says why: " + r[0]["reason"])


def case_require():
    p = run("--suite", SUITE, "--case", "tilt", "--require",
            "theta.settle < 7 and theta.peak_error <= 0.1 and x.effort_peak < 10")
    check(p.returncode == 0, "--require that holds: exit 0")
    with tempfile.TemporaryDirectory() as d:
        p = run("--suite", SUITE, "--case", "tilt", "--require", "theta.settle<2",
                "--report", d)
        check(p.returncode == 1 and "theta.settle < 2 fails" in p.stdout,
              "--require that does not hold: exit 1, the term named")
        # the report's title says what the table says: UNMET and the term
        title = [l for l in open(os.path.join(d, "tilt.gp")) if "multiplot layout" in l]
        check(len(title) == 1 and "UNMET" in title[0] and "theta.settle < 2 fails" in title[0]
              and "passed" not in title[0], "the report's title: UNMET and the term (%s)"
              % title)
        check("Warning" not in p.stderr, "gnuplot said nothing on stderr")
        # every term that fails, each with its value, in the notes, the CSV and the title;
        # the one that holds (theta.peak_error <= 0.1) not
        out = os.path.join(d, "two.csv")
        p = run("--suite", SUITE, "--case", "tilt", "--require",
                "theta.settle < 2 and theta.peak_error <= 0.1 and x.settle < 3", "--csv", out,
                "--report", d, "--force")
        note = [l for l in p.stdout.splitlines() if "--require:" in l]
        both = re.compile(r"theta\.settle < 2 fails \(5\.5\d*\); x\.settle < 3 fails \(5\.8\d*\)")
        check(p.returncode == 1 and len(note) == 1 and both.search(note[0]) and
              "peak_error" not in note[0], "two terms fail: both named with their values (%s)"
              % note)
        r = read_csv(out)
        check(len(r) == 2 and all(both.fullmatch(x["reason"]) for x in r),
              "the CSV's reason: both terms (%s)" % [x["reason"] for x in r])
        title = [l for l in open(os.path.join(d, "tilt.gp")) if "multiplot layout" in l]
        check(len(title) == 1 and "theta.settle < 2 fails" in title[0] and
              "\\nx.settle < 3 fails" in title[0], "the report's title: each term on its line (%s)"
              % title)
    p = run("--suite", SUITE, "--case", "tilt", "--require", "phi.settle<2")
    check(p.returncode == 2 and "no joint 'phi'" in p.stderr, "unknown joint: exit 2")
    check(p.stderr.count("--require") == 1, "--require said once: %r" % p.stderr.strip())
    p = run("--suite", SUITE, "--case", "tilt", "--require", "theta.settling<2")
    check(p.returncode == 2 and "settle" in p.stderr, "unknown metric: exit 2")


def case_stderr():
    talk = "echo EVAL-TALKS >&2; " + CTRL          # works, and talks on stderr
    # fails at once after 12 lines on stderr
    fail = "for i in 1 2 3 4 5 6 7 8 9 10 11 12; do echo EVAL-LINE-$i >&2; done; exit 3"
    base = [EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt", "--timeout", "20"]
    p = subprocess.run(base + ["--controller", talk], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
    print(p.stdout, p.stderr)
    check(p.returncode == 0 and "EVAL-TALKS" not in p.stderr + p.stdout,
          "a controller that works: its stderr not on lagsim-eval's (%r)" % p.stderr[-200:])
    p = subprocess.run(base + ["--controller", fail], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
    print(p.stdout, p.stderr)
    lines = re.findall(r"^    \| EVAL-LINE-(\d+)$", p.stdout, re.M)
    check(p.returncode == 1 and "tilt failed: the controller ended (exit status 3)" in p.stdout
          and "    the controller's stderr, its last 8 lines:" in p.stdout and
          lines == [str(i) for i in range(5, 13)] and "EVAL-LINE" not in p.stderr,
          "a controller that fails: its last 8 lines under the note (%s)" % lines)
    p = subprocess.run(base + ["--controller", talk, "-v"], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
    check(p.returncode == 0 and "EVAL-TALKS" in p.stderr, "-v: passed through")
    sweep = [os.path.join(BIN, "lagsim-sweep"), "--config", SCENE, "--duration", "1",
             "--runs", "2", "--seed", "1", "--timeout", "20", "--vary",
             "parameters.m0=uniform(1,1.5)"]
    with tempfile.TemporaryDirectory() as d:
        p = subprocess.run(sweep + ["--controller", talk, "--csv", os.path.join(d, "a.csv")],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        print(p.stdout[-500:], p.stderr)
        check(p.returncode == 0 and "EVAL-TALKS" not in p.stderr + p.stdout,
              "lagsim-sweep, a controller that works: its stderr not on the sweep's")
        tail = "the controller's stderr, its last 8 lines:\n" + "".join(
            "| EVAL-LINE-%d\n" % i for i in range(5, 13))
        # a pair kept for the runs: it cannot start (the sweep ends, exit 2), said at once
        p = subprocess.run(sweep + ["--controller", fail, "--csv", os.path.join(d, "b.csv")],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        print(p.stdout[-300:], p.stderr)
        check(p.returncode == 2 and "run 0, worker 0: the controller ended (exit status 3) "
              "before it answered the kept lagsimd's first state\n" + tail in p.stderr,
              "lagsim-sweep, a kept pair whose controller fails: why, and its last 8 lines")
        # a pair a run: the run fails, the sweep goes on; the first failure's lines, once
        p = subprocess.run(sweep + ["--restart", "--controller", fail, "--csv",
                                    os.path.join(d, "c.csv")],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        print(p.stdout[-300:], p.stderr)
        check(p.returncode == 1 and p.stderr.count("failed: ") == 1 and
              "run 0 failed: the controller ended (exit status 3) before the run did\n" + tail
              in p.stderr and "-v passes" in p.stderr,
              "lagsim-sweep --restart, a controller that fails: the first failed run's last "
              "8 lines, once")


BAD = [
    ("cases:\n  - name: a\n    duration: -1\n", ":3:15:", "duration"),
    ("cases:\n  - name: a\n    duration: 1\n    set: [\"initial.q\"]\n", ":4:11:",
     "key=value"),
    ("cases:\n  - name: a\n    duration: 1\n    colour: red\n", ":4:5:", "unknown key"),
    ("cases:\n  - name: a\n    duration: 1\n    set: [\"parameters.m1=-3\"]\n",
     ":4:11: cases[0].set[0]:", "parameters.m1"),
    # an override's YAML mistake: at the override's place in the case file
    ("cases:\n  - name: a\n    duration: 1\n  - name: b\n    duration: 1\n"
     "    set: [\"initial.qd=[0, 0]\",\n          \"initial.q=[0,\"]\n",
     ":7:11: cases[1].set[1]:", "initial.q"),
    ("cases:\n  - name: a\n    duration: 1\n    bounds: {phi: 1}\n", "case a", "no joint"),
]


def case_errors():
    with tempfile.TemporaryDirectory() as d:
        for k, (text, where, what) in enumerate(BAD):
            f = os.path.join(d, "suite%d.yaml" % k)
            with open(f, "w") as fh:
                fh.write(text)
            p = run("--suite", f)
            check(p.returncode == 2 and where in p.stderr and what in p.stderr,
                  "bad suite %d: exit 2 with %r and %r" % (k, where, what))
        p = run()
        check(p.returncode == 2 and "has no `cases:`" in p.stderr,
              "a scene without cases: exit 2")
    # a controller that cannot start: the case fails at once, the lockstep plant is not
    # left waiting for ever
    t0 = time.monotonic()
    p = subprocess.run([EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt",
                        "--controller", "/nonexistent/controller --prefix {prefix}"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=120)
    check(p.returncode == 1 and "the controller ended (exit status 127) before the run did"
          in p.stdout and time.monotonic() - t0 < 60,
          "a controller that does not start: the case fails within a minute (%.1f s, exit %d)"
          % (time.monotonic() - t0, p.returncode))
    # a controller on another prefix than the run's never answers: the run ends at
    # --timeout, and the reason says what to look at; the report of a run that never left
    # t = 0 draws without gnuplot's warnings
    with tempfile.TemporaryDirectory() as d:
        p = subprocess.run([EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt",
                            "--timeout", "5", "--report", d, "--controller",
                            os.path.join(BIN, "lqr_balance") +
                            " -q --prefix NOT_THE_RUNS --timeout 60"],  # waits past --timeout
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=120)
        print(p.stdout, p.stderr)
        check(p.returncode == 1 and "no command answered the first state" in p.stdout and
              "LAGSIM_PREFIX" in p.stdout,
              "a controller on another prefix: exit 1, the reason names the prefix")
        title = [l for l in open(os.path.join(d, "tilt.gp")) if "multiplot layout" in l]
        check(len(title) == 1 and "FAIL" in title[0] and "no command answered" in title[0],
              "its report's title: FAIL and why (%s)" % title)
        check("Warning" not in p.stderr and os.path.getsize(os.path.join(d, "tilt.png")) > 5000,
              "its report drawn, gnuplot said nothing on stderr")


def case_scene():
    """Cases in the scene file itself: lagsimd runs the scene as if they were not there,
    lagsim-eval runs them without --suite."""
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "cartpole_cases.yaml")
        with open(SCENE) as f, open(SUITE) as g:
            text = f.read() + "\n" + g.read()
        with open(scene, "w") as f:
            f.write(text)
        plain = subprocess.run([os.path.join(BIN, "lagsimd"), "--config", SCENE, "--offline",
                                "--duration", "1", "--csv", "-"], stdout=subprocess.PIPE,
                               universal_newlines=True)
        with_cases = subprocess.run([os.path.join(BIN, "lagsimd"), "--config", scene,
                                     "--offline", "--duration", "1", "--csv", "-"],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    universal_newlines=True)
        print(with_cases.stderr)
        check(with_cases.returncode == 0 and with_cases.stdout == plain.stdout,
              "lagsimd runs a scene with cases: as the same scene without them")
        p = subprocess.run([EVAL, "--config", scene, "--controller", CTRL, "--case", "tilt"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        print(p.stdout, p.stderr)
        check(p.returncode == 0 and "tilt" in p.stdout, "lagsim-eval runs the scene's own cases")


def owned_keys(tool):
    """The keys of the table the tool's --help prints: {key: its text}."""
    out = subprocess.run([os.path.join(BIN, tool), "--help"], stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    keys, cur, inside = {}, None, False
    for line in out.splitlines():
        if line.startswith("keys %s sets on every run" % tool):
            inside = True
        elif inside and not line.strip():
            break
        elif inside and line.startswith("  ") and not line.startswith("   "):
            cur = line.split()[0]
            keys[cur] = " ".join(line.split()[1:])
        elif inside and cur and line.startswith("   "):
            keys[cur] += " " + line.strip()
    return keys


# a value the loader takes for each owned key (so that, were it not refused, the case
# would run with it) and for the mappings above them
OWNED_VALUES = {"realtime.mode": "realtime", "realtime.start": "paused",
                "realtime.lockstep_timeout": "5",
                "lcm.url": "'udpm://239.255.76.67:7667?ttl=0'", "lcm.prefix": "OTHER",
                "lcm.allow_lan": "true", "realtime": "{mode: realtime}",
                "lcm": "{prefix: OTHER}"}


# The scene keys a case may set, each with why the tools' guarantees hold whatever it says;
# every other key of the loader's table must be the tools' (their --help table), so that a
# key added to the loader (a `log:` section, an lcm.interface) is refused in a case until
# someone decides which it is.
CASE_KEYS = {
    "model": "the plant", "parameters": "the plant", "initial": "the plant",
    "integrator": "the plant", "publish_hz": "the plant", "explode_limit": "the plant",
    "effects": "the plant", "reference": "what the plant should follow",
    "cases": "lagsim-eval's own key, which lagsimd ignores",
    "realtime.rate": "real-time pacing: lockstep does not read it",
    "realtime.command_timeout": "the watchdog, in sim time: the run stays deterministic",
    "realtime.lockstep_retry": "when a state is sent again: the states do not change",
    "realtime.status_hz": "the status rate: no metric reads a status",
    "realtime.effort_limit": "the plant's actuators",
}


def loader_keys(section):
    """The keys the loader's table has at the top (section "") or in a section, from
    lagsimd's refusal of an unknown one ("...; allowed: a, b, c")."""
    key = (section + "." if section else "") + "no_such_key_here"
    p = subprocess.run([os.path.join(BIN, "lagsimd"), "--config", SCENE, "--set", key + "=1",
                        "--offline", "--duration", "0.01", "--csv", "/dev/null"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    m = re.search(r"allowed: (.*)$", p.stderr.strip(), re.M)
    return [(section + "." if section else "") + k.strip() for k in m.group(1).split(",")] \
        if m else []


def case_owned():
    keys = owned_keys("lagsim-eval")
    # every key of the loader: the tools' or one a case may set, never neither
    top = loader_keys("")
    check(len(top) >= 10, "the loader's top-level keys: %s" % top)
    every = [k for k in top if k not in ("realtime", "lcm")] + loader_keys("realtime") + \
        loader_keys("lcm")
    check(len(every) >= 18, "the loader's keys of the realtime and lcm sections read")
    for k in every:
        check((k in keys) != (k in CASE_KEYS),
              "%s is %s" % (k, "the tools' (--help)" if k in keys else
                            "a case's: " + CASE_KEYS[k] if k in CASE_KEYS else
                            "NEITHER the tools' nor a case's: classify it"))
    check(len(keys) >= 6 and keys == owned_keys("lagsim-sweep"),
          "lagsim-eval and lagsim-sweep print one table of owned keys: %s" % sorted(keys))
    must = {"realtime.mode", "realtime.start", "realtime.lockstep_timeout", "lcm.url",
            "lcm.prefix", "lcm.allow_lan"}
    check(must <= set(keys), "the mode, start, lockstep timeout, URL, prefix and LAN access "
          "are owned")
    # every key of the table and every mapping above one
    paths = sorted(set(keys) | must | {k.split(".")[0] for k in set(keys) | must})
    sweep = os.path.join(BIN, "lagsim-sweep")
    with tempfile.TemporaryDirectory() as d:
        for k in paths:
            check(k in OWNED_VALUES, "the test has a value for %s" % k)
            text = ('cases:\n  - name: ok\n    duration: 1\n  - name: own\n    duration: 1\n'
                    '    set: ["initial.q=[0, 0.05]", "%s=%s"]\n'
                    % (k, OWNED_VALUES.get(k, "1").replace('"', '\\"')))
            f = os.path.join(d, "suite.yaml")
            with open(f, "w") as fh:
                fh.write(text)
            p = run("--suite", f, "--timeout", "20")
            check(p.returncode == 2 and "suite.yaml:6:34: cases[1].set[1]:" in p.stderr and
                  "a case cannot set it" in p.stderr and
                  (k + " is set by" in p.stderr or k + " holds " in p.stderr),
                  "lagsim-eval: a case setting %s: exit 2 at its place, the key named (%d)"
                  % (k, p.returncode))
            p = subprocess.run([sweep, "--config", SCENE, "--controller", CTRL, "--suite", f,
                                "--case", "ok", "--vary", "parameters.m1=uniform(0.1,0.2)",
                                "--timeout", "20"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
            print(p.stderr)
            check(p.returncode == 2 and "suite.yaml:6:34: cases[1].set[1]:" in p.stderr,
                  "lagsim-sweep: the same suite refused at the same place (%d)" % p.returncode)
            p = subprocess.run([sweep, "--config", SCENE, "--controller", CTRL, "--duration",
                                "1", "--vary", k + "=uniform(0,1)", "--timeout", "20"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               universal_newlines=True, timeout=300)
            print(p.stderr)
            check(p.returncode == 2 and "--vary %s=" % k in p.stderr and
                  "a sweep cannot vary it" in p.stderr,
                  "lagsim-sweep --vary %s: exit 2, said why (%d)" % (k, p.returncode))
    # the docs' table and the man pages name the table's keys, no other
    text = open(os.path.join(SRC, "docs", "evaluation.md")).read()
    sec = text.split("**What a case cannot change.**", 1)
    documented = []
    if len(sec) == 2:
        lines = sec[1].splitlines()
        while lines and not lines[0].startswith("|"):  # the text before the table
            lines.pop(0)
        for line in lines:
            if not line.startswith("|"):
                break
            cell = line.split("|")[1].strip()
            if cell.startswith("`"):
                documented.append(cell.strip("`"))
    check(sorted(documented) == sorted(keys),
          "docs/evaluation.md's table of owned keys is the tools' (%s)" % documented)
    for page in ("lagsim-eval.1", "lagsim-sweep.1"):
        man = open(os.path.join(SRC, "docs", "man", page)).read().replace("\\", "")
        sub = man.split(".SS Keys", 1)[-1].split(".SH", 1)[0] if ".SS Keys" in man else ""
        named = set(re.findall(r"^\.TP\n\.B (\S+)$", sub, re.M))
        check(named == set(keys), "%s names the owned keys (%s)" % (page, sorted(named)))


# A controller that writes its URL and whether the lock file of its state port is held by
# another (flock -n fails: 99), waits until every controller of the test wrote (the runs
# overlap in time), then runs lqr_balance
BUS_CTL = r"""#!/bin/sh
port=${LCM_DEFAULT_URL##*:}; port=${port%%\?*}
flock -n -E 99 "/run/lock/lagsim-udp-$port.lock" true; held=$?
echo "$LCM_DEFAULT_URL $held" >> "$BUS_OUT"
i=0
while [ "$(wc -l < "$BUS_OUT")" -lt "$BUS_N" ] && [ $i -lt 300 ]; do sleep 0.1; i=$((i+1)); done
exec "$@"
"""


def case_bus():
    sweep = os.path.join(BIN, "lagsim-sweep")
    with tempfile.TemporaryDirectory() as d:
        ctl = os.path.join(d, "ctl.sh")
        with open(ctl, "w") as f:
            f.write(BUS_CTL)
        out = os.path.join(d, "urls")
        open(out, "w").close()
        env = dict(os.environ, LCM_DEFAULT_URL="udpm://239.255.76.99:7720?ttl=0",
                   BUS_OUT=out, BUS_N="4")
        c = "sh %s %s -q --prefix {prefix}" % (ctl, os.path.join(BIN, "lqr_balance"))
        evals = [[EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt", "--controller",
                  c] for _ in range(2)]
        sw = [sweep, "--config", SCENE, "--controller", c, "--duration", "1", "--runs", "4",
              "-j", "2", "--vary", "parameters.m1=uniform(0.1,0.2)"]
        procs = [subprocess.Popen(a, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  universal_newlines=True) for a in evals + [sw]]
        res = [p.communicate(timeout=300) + (p.returncode,) for p in procs]
        for o, e, rc in res:
            print(rc, o[-800:], e[-800:])
        check(all(rc == 0 for _, _, rc in res), "two lagsim-evals and a sweep ran at once "
              "(exit %s)" % [rc for _, _, rc in res])
        lines = [l.split() for l in open(out).read().splitlines()]
        print(lines)
        urls = [l[0] for l in lines]
        m = [re.match(r"^udpm://239\.255\.76\.99:(\d+)\?ttl=0$", u) for u in urls]
        check(len(urls) == 4 and all(m), "each run's URL has LCM_DEFAULT_URL's group and "
              "options, nothing added: %s" % urls)
        ports = [int(x.group(1)) for x in m if x]
        check(len(set(ports)) == 4 and all(64000 <= p <= 65534 and p % 2 == 0 for p in ports),
              "four pairs of ports of the tools' range, none shared: %s" % ports)
        check(all(l[1:] == ["99"] for l in lines), "each pair's lock file held while its runs "
              "ran (flock -n: 99): %s" % [l[1:] for l in lines])
        # --url over LCM_DEFAULT_URL; a ttl above 0 only with --allow-lan
        env = dict(os.environ, LCM_DEFAULT_URL="udpm://239.255.76.99:7720?ttl=1")
        pr = "echo \"$LCM_DEFAULT_URL\" > %s; exec %s -q --prefix {prefix}" % (
            out, os.path.join(BIN, "lqr_balance"))
        base = [EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt", "--controller", pr]
        p = subprocess.run(base, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        check(p.returncode == 2 and "LCM_DEFAULT_URL" in p.stderr and "ttl=1" in p.stderr and
              "--allow-lan" in p.stderr, "LCM_DEFAULT_URL with ttl=1: exit 2, --allow-lan named")
        p = subprocess.run(base + ["--allow-lan"], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
        u = open(out).read().strip()
        check(p.returncode == 0 and re.match(r"^udpm://239\.255\.76\.99:\d+\?ttl=1$", u),
              "with --allow-lan: the run on ttl=1 (%s, exit %d)" % (u, p.returncode))
        p = subprocess.run(base + ["--url", "udpm://239.255.76.98?ttl=0&recv_buf_size=65536"],
                           env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        u = open(out).read().strip()
        check(p.returncode == 0 and
              re.match(r"^udpm://239\.255\.76\.98:\d+\?ttl=0&recv_buf_size=65536$", u),
              "--url's group and options over LCM_DEFAULT_URL (%s, exit %d)" % (u, p.returncode))
        # {prefix} and {url} replaced as they are, inside the command's own quotes too
        pr = ("printf '%%s|%%s|%%s|%%s|%%s\\n' '{prefix}' \"{prefix}\" \"$LAGSIM_PREFIX\" "
              "'{url}' \"$LCM_DEFAULT_URL\" > %s; exec %s -q --prefix {prefix}"
              % (out, os.path.join(BIN, "lqr_balance")))
        p = subprocess.run([EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt",
                            "--controller", pr], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        f = open(out).read().strip().split("|")
        check(p.returncode == 0 and len(f) == 5 and f[0] == f[1] == f[2] and f[3] == f[4] and
              re.match(r"^EVAL\d+_0$", f[0]) and f[3].startswith("udpm://"),
              "'{prefix}', \"{prefix}\" and '{url}' are the run's prefix and URL as they are "
              "(%s, exit %d)" % (f, p.returncode))
        for tool in (EVAL, sweep):
            for url, what in (("memq://", "memq://"), ("file:///tmp/x", "file://"),
                              ("udpm://239.255.76.67:7667?ttl=0&foo=1", "foo"),
                              ("udpm://10.0.0.1:7667?ttl=0", "not a multicast address")):
                args = [tool, "--config", SCENE, "--suite", SUITE, "--case", "tilt",
                        "--controller", CTRL, "--url", url]
                if tool == sweep:
                    args += ["--vary", "parameters.m1=uniform(0.1,0.2)"]
                p = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   universal_newlines=True, timeout=60)
                check(p.returncode == 2 and "--url " + url in p.stderr and what in p.stderr,
                      "%s --url %s: exit 2, said why (%d: %s)"
                      % (os.path.basename(tool), url, p.returncode, p.stderr.strip()[:200]))


def case_outputs():
    sweep = os.path.join(BIN, "lagsim-sweep")
    with tempfile.TemporaryDirectory() as d:
        suite = os.path.join(d, "suite.yaml")
        text = "cases:\n  - name: a\n    duration: 0.5\n    set: [\"initial.q=[0, 0.05]\"]\n"
        rep = os.path.join(d, "r")
        os.mkdir(rep)
        daemon = os.path.join(d, "lagsimd")
        shutil.copy(os.path.join(BIN, "lagsimd"), daemon)
        before = open(daemon, "rb").read()

        def attempt(what, args, victim, tool=EVAL, cwd=None, untouched=True):
            """runs the tool; exit 2 before any run, victim unchanged (untouched: else one
            output of the two, which --force lets replace it)"""
            if victim in (suite, os.path.join(rep, "a.dat"), os.path.join(rep, "a.gp")):
                with open(victim, "w") as f:
                    f.write(text)
            old = open(victim, "rb").read()
            base = [tool, "--config", SCENE, "--controller", CTRL]
            p = subprocess.run(base + args + ["--force"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, universal_newlines=True, timeout=300,
                               cwd=cwd)
            print("$", " ".join(args), "->", p.returncode, p.stdout[-500:], p.stderr[-800:])
            check(p.returncode == 2 and "the same file as" in p.stderr and
                  "refused" in p.stderr and "case " not in p.stdout and "runs:" not in p.stdout
                  and (open(victim, "rb").read() == old or not untouched),
                  "%s: exit 2 before any run, %s untouched (%d)"
                  % (what, os.path.basename(victim), p.returncode))

        with open(suite, "w") as f:
            f.write(text)
        attempt("lagsim-eval --csv the suite", ["--suite", suite, "--csv", suite], suite)
        attempt("lagsim-eval --csv ./suite.yaml", ["--suite", "suite.yaml", "--csv",
                                                   "./suite.yaml"], suite, cwd=d)
        link = os.path.join(d, "link.csv")
        os.link(suite, link)
        attempt("lagsim-eval --csv a hard link to the suite", ["--suite", suite, "--csv", link],
                suite)
        os.unlink(link)
        for ext in ("dat", "gp"):
            victim = os.path.join(rep, "a." + ext)
            attempt("lagsim-eval --report: the suite is its a.%s" % ext,
                    ["--suite", victim, "--report", rep], victim)
            os.unlink(victim)
        png = os.path.join(rep, "a.png")
        with open(png, "w") as f:
            f.write("an old PNG")
        attempt("lagsim-eval --csv the report's PNG", ["--suite", suite, "--csv", png,
                                                       "--report", rep], png, untouched=False)
        check(sorted(os.listdir(rep)) == ["a.png"], "a refused run leaves no file it made "
              "(%s)" % sorted(os.listdir(rep)))
        os.link(os.path.join(rep, "a.png"), os.path.join(rep, "a.gp"))
        attempt("lagsim-eval --report: its script a hard link to its PNG",
                ["--suite", suite, "--report", rep], png)
        attempt("lagsim-eval --csv the daemon", ["--suite", suite, "--lagsimd", daemon, "--csv",
                                                 daemon], daemon)
        # lagsim-sweep
        sw = ["--suite", suite, "--case", "a", "--vary", "parameters.m1=uniform(0.1,0.2)"]
        attempt("lagsim-sweep --csv the suite", sw + ["--csv", suite], suite, tool=sweep)
        out = os.path.join(d, "s.out")
        with open(out, "w") as f:
            f.write("an old result")
        attempt("lagsim-sweep --csv and --plot one file", sw + ["--csv", out, "--plot", out], out,
                tool=sweep, untouched=False)
        attempt("lagsim-sweep --csv the daemon", sw + ["--lagsimd", daemon, "--csv", daemon],
                daemon, tool=sweep)
        check(open(daemon, "rb").read() == before, "the daemon's copy is whole")
        # the controller command's own files (its script, bare or quoted, a path into d):
        # read by every run, so never an output, with --force either
        script = os.path.join(d, "gs copy.py")
        with open(script, "w") as f:
            f.write("# a controller's script\n")
        ctl_old = open(script).read()
        for tool, args in ((EVAL, ["--suite", suite]), (sweep, sw)):
            for ctl, out in (("python3 'gs copy.py' --prefix {prefix}", "gs copy.py"),
                             ('cd . && python3 "%s" --prefix {prefix}' % script, script),
                             ("python3 gs\\ copy.py -q", "./gs copy.py")):
                p = subprocess.run([tool, "--config", SCENE, "--controller", ctl, "--csv", out,
                                    "--force"] + args, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, universal_newlines=True, timeout=300,
                                   cwd=d)
                check(p.returncode == 2 and "the same file as" in p.stderr and
                      open(script).read() == ctl_old,
                      "%s --controller %r --csv %r --force: exit 2, the script untouched (%d)"
                      % (os.path.basename(tool), ctl, out, p.returncode))
        # merge: -o never one of its shards
        shard = os.path.join(d, "shard.csv")
        subprocess.run([sweep, "--config", SCENE, "--controller", CTRL, "--duration", "0.2",
                        "--vary", "parameters.m1=uniform(0.1,0.2)", "--csv", shard],
                       stdout=subprocess.PIPE, timeout=300)
        os.link(shard, os.path.join(d, "merged.csv"))
        old = open(shard).read()
        p = subprocess.run([sweep, "merge", shard, "-o", os.path.join(d, "merged.csv"),
                            "--force"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True)
        check(p.returncode == 2 and "the same file as" in p.stderr and open(shard).read() == old,
              "merge -o a hard link to its shard: exit 2, the shard untouched")


def case_notes():
    manip = os.path.join(SRC, "config", "manipulator.yaml")
    pd = os.path.join(BIN, "manipulator_pd") + " -q --prefix {prefix}"
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, TMPDIR=d)
        # -v keeps the runs' logs: where, said once
        p = subprocess.run([EVAL, "--config", SCENE, "--controller", CTRL, "--suite", SUITE,
                            "--case", "tilt", "-v"], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
        m = re.search(r"^lagsim-eval: -v: each case's log \(EVAL\d+_<case's index>\.lcm\) is "
                      r"kept in (\S+)$", p.stderr, re.M)
        logs = glob.glob(os.path.join(m.group(1), "EVAL*_*.lcm")) if m else []
        check(p.returncode == 0 and m and m.group(1).startswith(d) and len(logs) == 1 and
              p.stderr.count("is kept in") == 1,
              "-v: the directory of the kept logs said once, the log there (%s, %s)"
              % (m.group(1) if m else None, logs))
        # a reference for q1 alone: q2 is scored against r = 0, and the notes say it
        suite = os.path.join(d, "ref.yaml")
        with open(suite, "w") as f:
            f.write('cases:\n  - name: q1_only\n    duration: 1\n'
                    '    set: ["reference={q1: {type: step, amplitude: 0.2}}"]\n'
                    '  - name: both\n    duration: 1\n')
        p = subprocess.run([EVAL, "--config", manip, "--controller", pd, "--suite", suite],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=300)
        print(p.stdout, p.stderr)
        notes = re.findall(r"^  (\S+): (.*r = 0.*)$", p.stdout, re.M)
        check(len(notes) == 1 and notes[0][0] == "q1_only" and
              notes[0][1].startswith("q2 has no reference") and "q1 has" not in notes[0][1],
              "a reference for q1 alone: a note says q2 is scored against r = 0, none for the "
              "case with both (%s)" % notes)
    # {url} outside quotes: the URL's '&' ends the shell command, and lqr_balance (sent to
    # the background) ends with it; the reason says to quote it
    url = "udpm://239.255.76.67?ttl=0&recv_buf_size=4194304"
    bare = os.path.join(BIN, "lqr_balance") + " -q --prefix {prefix} --url {url}"
    p = subprocess.run([EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt", "--url",
                        url, "--controller", bare], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
    print(p.stdout, p.stderr)
    check(p.returncode == 1 and "the controller ended (exit status 0) before the run did; "
          "{url} stands outside quotes" in p.stdout and "write '{url}'" in p.stdout and
          "'&'" in p.stdout, "a bare {url} whose '&' ended the command: the reason says to "
          "write '{url}' (exit %d)" % p.returncode)
    quoted = bare.replace("{url}", "'{url}'")
    p = subprocess.run([EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt", "--url",
                        url, "--controller", quoted], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
    check(p.returncode == 0 and "{url}" not in p.stdout,
          "'{url}' quoted: the case runs, no such words (exit %d)" % p.returncode)


def case_waits():
    # lqr_balance waits 100 s for a scene on its own prefix: it never answers the run's
    # plant, which waits at t = 0 for the first command
    wrong = os.path.join(BIN, "lqr_balance") + " -q --prefix NOT_THE_RUNS --timeout 100"
    p = subprocess.Popen([EVAL, "--config", SCENE, "--suite", SUITE, "--case", "tilt",
                          "--timeout", "120", "--controller", wrong], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, universal_newlines=True)
    t0, text = time.monotonic(), ""
    while time.monotonic() < t0 + 30 and "has not left" not in text:  # at most 30 s
        if select.select([p.stderr], [], [], 0.2)[0]:
            chunk = os.read(p.stderr.fileno(), 65536).decode(errors="replace")
            if not chunk:
                break
            text += chunk
    took = time.monotonic() - t0
    p.terminate()
    while "\n" not in text[text.find("has not left"):] and "has not left" in text:
        chunk = os.read(p.stderr.fileno(), 65536).decode(errors="replace")
        if not chunk:
            break
        text += chunk
    lines = text.splitlines(True)
    line = next((x for x in lines if "has not left" in x), "")
    rest = "".join(lines[lines.index(line) + 1:]) if line else text
    p.wait(timeout=60)
    rest += p.stderr.read()
    print(line, rest)
    check(re.match(r"^lagsim-eval: case tilt: the plant has not left t = 0 after 5 s: lagsimd "
                   r"waits \d+ s for the first command \(sim_time 0\) on EVAL\d+_0_COMMAND at "
                   r"udpm://[0-9.]+:\d+\?\S+; .*give the command \{prefix\} or LAGSIM_PREFIX "
                   r"\(else the run ends at --timeout, 120 s\)$", line) and took < 30,
          "a controller on another prefix: said in %.1f s (--timeout 120): %r" % (took, line))
    check("has not left" not in rest, "said once")
    p = run("--suite", SUITE, "--case", "tilt")
    check(p.returncode == 0 and "has not left" not in p.stderr,
          "a controller on the run's prefix: no such line")


{"metrics": case_metrics, "require": case_require, "errors": case_errors, "notes": case_notes,
 "waits": case_waits, "scene": case_scene, "owned": case_owned, "outputs": case_outputs,
 "bus": case_bus, "stderr": case_stderr}[CASE]()
sys.exit(verdict(CASE))
