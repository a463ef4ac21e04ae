#!/usr/bin/env python3
"""Runs the shell recipes of README.md, docs/clients.md and docs/evaluation.md as written,
so that they cannot drift from the programs.

    readme_recipes.py --build DIR --source DIR NAME...

A recipe is marked with <!-- recipe: NAME --> on the line before its ```sh fence; a file
it needs with <!-- recipe-file: NAME FILE --> before any fence (its text is written to
FILE first; NAME,NAME... for a file of several recipes). The block runs in bash in a fresh temporary directory, with `build/`, and
`config/`, `tests/`, `clients/` pointing into this tree's build and sources; a line that builds (`cmake ...`)
or installs the Debian packages (`.ci/install-deps.sh`) is left out, the tree being built
already. LCM_DEFAULT_URL gets a multicast port of this run's own (ttl=0), which every
program of the recipe honours, so that the recipe's default prefix cannot meet another
test's. Each recipe has its own checks below: what a person who ran it would look at.
"""
import argparse
import csv
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


DOCS = ("README.md", os.path.join("docs", "clients.md"), os.path.join("docs", "evaluation.md"))


def recipes(src):
    """{name: shell text} and {name: [(file, text)]} of every marked block of DOCS"""
    found, files = {}, {}
    for doc in DOCS:
        text = open(os.path.join(src, doc)).read()
        for m in re.finditer(r"<!-- recipe: (\S+) -->\s*\n```sh\n(.*?)\n```", text, re.S):
            found[m.group(1)] = m.group(2)
        for m in re.finditer(r"<!-- recipe-file: (\S+) (\S+) -->\s*\n```\w*\n(.*?\n)```", text, re.S):
            for name in m.group(1).split(","):  # NAME,NAME...: a file several recipes use
                files.setdefault(name, []).append((m.group(2), m.group(3)))
    return found, files


def rows(path):
    with open(path) as f:
        return list(csv.reader(f))


def check_by_hand(out, tmp):
    """the controller balanced 10 s of real time and ended on the server's stop; lagsimctl
    printed a running status; the offline run wrote 10 s of CSV"""
    checks = []
    summ = [l for l in out.splitlines() if l.startswith("dipc_lqr: summary")]
    kv = dict(t.split("=", 1) for t in summ[-1].split()[2:] if "=" in t) if summ else {}
    checks.append((kv.get("end") == "stop", "dipc_lqr ended on the server's stop (%s)" % kv.get("end")))
    checks.append((kv.get("t_first") == "0.000000" and abs(float(kv.get("end_theta1", "9"))) < 0.01,
                   "dipc_lqr balanced from t = 0 (t_first %s, theta1 at the end %s)"
                   % (kv.get("t_first"), kv.get("end_theta1"))))
    st = [l for l in out.splitlines() if l.split() == ["run_state", "running"]]
    checks.append((bool(st), "lagsimctl status: running (its run_state line)"))
    path = os.path.join(tmp, "run.csv")
    r = rows(path) if os.path.exists(path) else []
    checks.append((len(r) >= 1001 and float(r[-1][0]) == 10.0,
                   "run.csv: %d rows, the last at t = %s" % (len(r), r[-1][0] if r else "?")))
    return checks


def check_record(out, tmp):
    """--log kept every state of the 10 s run (at 100 Hz: t = 0 to 10 s, 1001 states, the one
    at t = 0 maybe published again while the daemon waited for the controller's first
    command), the replay found them exact, the log became one CSV per channel and a plot"""
    checks = []
    m = re.search(r"replay run.lcm: (\d+) states compared on DIPC_STATE \(\d+ restarts at "
                  r"resets, (\d+) gaps", out)
    # each state re-simulated from the one before (a repeat from the one it repeats)
    checks.append((m is not None and int(m.group(1)) >= 1000 and m.group(2) == "0"
                   and "\nmax difference = 0\n" in out,
                   "--replay: every state compared, 0 gaps, max difference 0 (%s)"
                   % (m.group(0) if m else "no replay line")))
    checks.append(("gaps 0 (0 states missing" in out and "sim time 0 .. 10 s, step 0 .. 10000" in out,
                   "lagsim-log2csv's summary: states from 0 to 10 s, 0 gaps"))
    path = os.path.join(tmp, "run", "DIPC_STATE.csv")
    r = rows(path) if os.path.exists(path) else []
    times = {row[0] for row in r[1:]}
    checks.append((len(times) == 1001, "run/DIPC_STATE.csv: %d distinct sim times in %d rows"
                   % (len(times), len(r) - 1 if r else 0)))
    png = os.path.join(tmp, "run", "DIPC_STATE.png")
    checks.append((os.path.exists(png) and os.path.getsize(png) > 1000, "run/DIPC_STATE.png drawn"))
    return checks


def check_evaluate(out, tmp):
    """lagsim-eval measured both cases and they met the requirement; lagsim-sweep ran 200
    runs, none failed, some missed --require (the README says it exits 1: the plants drawn
    red), and drew its figure"""
    checks = []
    for case in ("tilt", "heavy_pole"):
        checks.append((re.search(r"^%s\s+x\s+ok\b" % case, out, re.M) is not None,
                       "lagsim-eval: case %s measured, ok" % case))
    checks.append(("UNMET" not in out and "FAIL" not in out, "lagsim-eval: no case failed or unmet"))
    m = re.search(r"^200 runs: (\d+) passed \([\d.]+ %\), 0 failed, (\d+) missed --require",
                  out, re.M)
    checks.append((m is not None and int(m.group(1)) + int(m.group(2)) == 200 and
                   int(m.group(2)) > 0, "lagsim-sweep: 200 runs, none failed, some missed "
                   "--require (%s)" % (m.group(0) if m else "no summary")))
    png = os.path.join(tmp, "sweep.png")
    checks.append((os.path.exists(png) and os.path.getsize(png) > 1000, "sweep.png drawn"))
    return checks


def check_walkthrough(out, tmp):
    """docs/clients.md's newcomer walkthrough: balance.py balanced the cart-pole for the 10 s
    of the run and ended on its stop; the replay found every state exact; the summary, the
    CSV and the plot are there; the view, fed the log by lcm-logplayer, kept every state"""
    checks = []
    checks.append(("balance.py: the plant stopped at t = 10.00 s" in out,
                   "balance.py ended on the plant's stop at t = 10 s"))
    m = re.search(r"replay run.lcm: (\d+) states compared on CARTPOLE_STATE \(\d+ restarts at "
                  r"resets, (\d+) gaps", out)
    checks.append((m is not None and int(m.group(1)) >= 1000 and m.group(2) == "0"
                   and "\nmax difference = 0\n" in out,
                   "--replay: every state compared, 0 gaps, max difference 0 (%s)"
                   % (m.group(0) if m else "no replay line")))
    checks.append(("sim time 0 .. 10 s, step 0 .. 10000; gaps 0 (0 states missing" in out,
                   "lagsim-log2csv's summary: states from 0 to 10 s, 0 gaps"))
    path = os.path.join(tmp, "run", "CARTPOLE_STATE.csv")
    r = list(csv.DictReader(open(path))) if os.path.exists(path) else []
    t = [float(x["t"]) for x in r]
    th = [float(x["theta"]) for x in r]
    x = [float(v["x"]) for v in r]
    late = [abs(b) for a, b in zip(t, th) if a >= 3]
    checks.append((len(set(t)) == 1001 and max(map(abs, th)) == 0.05 and late and max(late) < 0.003
                   and 0.1 < max(x) < 0.2 and abs(x[-1]) < 0.01,
                   "balanced, as the text says: %d sim times, |theta| <= %s, < 0.003 rad after 3 s "
                   "(%s), x peaks at %s m, ends at %s m" % (len(set(t)), max(map(abs, th)) if th else "?",
                                                           max(late) if late else "?",
                                                           max(x) if x else "?", x[-1] if x else "?")))
    png = os.path.join(tmp, "run", "CARTPOLE_STATE.png")
    checks.append((os.path.exists(png) and os.path.getsize(png) > 1000, "run/CARTPOLE_STATE.png drawn"))
    m = re.search(r'\{"of":"state","first":(\d+),"last":(\d+)', out)
    checks.append((m is not None and int(m.group(2)) - int(m.group(1)) + 1 >= 990,
                   "the view kept the replayed run: %s" % (m.group(0) if m else "no history answer")))
    return checks


def check_walkthrough_lockstep(out, tmp):
    """the walkthrough's balance.py, unchanged, in lockstep: the daemon stepped on its answers
    (which carry the state's generation) to the end and balance.py ended on the stop"""
    return [("balance.py: the plant stopped at t = 2.00 s" in out,
             "balance.py answered every state in lockstep and ended on the stop at t = 2 s"),
            ("of generation 0" not in out and "another sim_time" not in out,
             "lagsimd refused none of its answers")]


def eval_checks(out, cases, runs):
    """lagsim-eval measured each of the cases, ok (none failed or unmet); lagsim-sweep ran
    every run and each passed"""
    checks = []
    for case, joint in cases:
        checks.append((re.search(r"^%s\s+%s\s+ok\b" % (case, joint), out, re.M) is not None,
                       "lagsim-eval: case %s measured, ok" % case))
    checks.append(("UNMET" not in out and "FAIL" not in out, "lagsim-eval: no case failed or unmet"))
    m = re.search(r"^%d runs: %d passed \(100\.0 %%\), 0 failed, 0 missed --require" % (runs, runs),
                  out, re.M)
    checks.append((m is not None, "lagsim-sweep: %d runs, all passed" % runs))
    return checks


def check_eval_python(out, tmp):
    """docs/evaluation.md: the shipped Python DIPC controller under lagsim-eval (two cases of
    the suite written from the page) and lagsim-sweep (20 runs)"""
    return eval_checks(out, [("tilt", "theta0"), ("push", "theta0")], 20)


def check_eval_octave(out, tmp):
    """docs/evaluation.md: the Octave cart-pole controller, {prefix} inside Octave's quotes
    inside the shell's, under lagsim-eval (case tilt) and lagsim-sweep (4 runs)"""
    return eval_checks(out, [("tilt", "x")], 4)


def check_scene_params(out, tmp):
    """docs/clients.md: hold.py reads the manipulator's parameters from ctl.params: it says
    m2 = 1 at the start and m2 = 2 at the first state after lagsimctl's SET, and holds the
    arm at its targets through the change (within 1 mm and 1 mrad at the end)"""
    checks = [("t = 0.00 s: m2 = 1 kg, g = 9.81 m/s^2" in out, "hold.py read m2 = 1 at t = 0")]
    m = re.search(r"t = (\d+\.\d\d) s: m2 = 2 kg", out)
    checks.append((m is not None and float(m.group(1)) > 0, "and m2 = 2 after the SET (%s)"
                   % (m.group(0) if m else "not said")))
    m = re.search(r"hold\.py: summary end=stop q1=(\S+) q2=(\S+)", out)
    checks.append((m is not None and abs(float(m.group(1)) - 0.3) < 1e-3 and
                   abs(float(m.group(2)) - 0.6) < 1e-3,
                   "held at q1 = 0.3 rad, q2 = 0.6 m to the end (%s)" % (m.group(0) if m else
                                                                        "no summary")))
    return checks


# a recipe's exit status when it is not 0, as its doc says (the last command's)
EXIT = {"evaluate": 1}
# wall s a recipe may take when it is not --timeout (a short run: a hang fails soon)
TIMEOUT = {"walkthrough-lockstep": 60}

CHECKS = {"by-hand": check_by_hand, "record": check_record, "evaluate": check_evaluate,
          "walkthrough": check_walkthrough, "walkthrough-lockstep": check_walkthrough_lockstep,
          "eval-python": check_eval_python,
          "eval-octave": check_eval_octave, "scene-params": check_scene_params}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--timeout", type=float, default=150, help="wall s a recipe may take")
    ap.add_argument("names", nargs="+")
    a = ap.parse_args()
    build, src = os.path.abspath(a.build), os.path.abspath(a.source)
    found, files = recipes(src)
    for name in a.names:
        if not check(name in found and name in CHECKS,
                     "a recipe %s in %s, and checks for it" % (name, " or ".join(DOCS))):
            continue
        lines = []
        for line in found[name].splitlines():
            if line.startswith("cmake ") or line.startswith(".ci/install-deps.sh"):
                print("(left out, the tree is built: %s)" % line)
                continue
            line = re.sub(r"(^|[\s;&(='])build/", r"\g<1>%s/" % build, line)
            line = re.sub(r"(^|[\s;&(=])config/", r"\g<1>%s/config/" % src, line)
            line = re.sub(r"(^|[\s;&(=])tests/", r"\g<1>%s/tests/" % src, line)
            line = re.sub(r"(^|[\s;&(='])clients/", r"\g<1>%s/clients/" % src, line)
            lines.append(line)
        script = "\n".join(lines) + "\n"
        # the walkthrough's lagsim-view port (8765, as the page says) becomes a free one of
        # this run's: another suite on the machine may be walking through it too
        if ":8765" in script or "--port 8765" in script:
            with socket.socket() as sk:
                sk.bind(("127.0.0.1", 0))
                view_port = sk.getsockname()[1]
            script = script.replace("--port 8765", "--port %d" % view_port) \
                           .replace(":8765/", ":%d/" % view_port)
            print("(lagsim-view's port 8765 taken as %d, a free one)" % view_port)
        tmp = tempfile.mkdtemp(prefix="lagsim_recipe_")
        for fname, text in files.get(name, []):
            with open(os.path.join(tmp, fname), "w") as f:
                f.write(text)
            print("---- %s written as given" % fname)
        env = dict(os.environ)
        env["LCM_DEFAULT_URL"] = lcm_url()
        print("---- recipe %s in %s, LCM_DEFAULT_URL=%s\n%s" % (name, tmp, env["LCM_DEFAULT_URL"], script))
        # a session of its own: a recipe that hangs is stopped whole, its background jobs too
        p = subprocess.Popen(["bash", "-c", script], cwd=tmp, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, universal_newlines=True,
                             start_new_session=True)
        try:
            out, _ = p.communicate(timeout=TIMEOUT.get(name, a.timeout))
            code = p.returncode
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGTERM)
            try:
                out, _ = p.communicate(timeout=5)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                out, _ = p.communicate()
            out, code = (out or "") + "\n(timed out: stopped)", -1
        try:
            os.killpg(p.pid, signal.SIGKILL)  # whatever the recipe left running
        except ProcessLookupError:
            pass
        print(out.rstrip()[-3000:])
        want = EXIT.get(name, 0)
        checks = [(code == want, "the recipe exited %d (%d)" % (want, code))] + CHECKS[name](out, tmp)
        for good, what in checks:
            check(good, what)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
