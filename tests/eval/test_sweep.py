#!/usr/bin/env python3
"""lagsim-sweep end to end: the cart-pole held by lqr_balance over its masses, 8 runs.

usage: test_sweep.py BIN_DIR SOURCE_DIR CASE
  same      the CSV of -j1, of -j2, of -j3 --plants-per-worker 2 (the workers' plants in
            two lagsimd hosts), and of two shards (run by GNU parallel on this host)
            merged, byte for byte equal; the grid's values are the grid's, the uniform
            ones inside their range and not all equal; a run's metrics equal lagsim-eval's
            for the same overrides; --seed changes the drawn values
  slurm     the job-array script: shell syntax, two array tasks run outside Slurm with
            Slurm's variables set (of an array 3-4 and of a stepped one, 0-2:2), merged,
            equal to the whole sweep
  merge     the identity lines a shard carries (each from its source: the scene's SHA-256
            by hashlib); merge refuses a shard given twice, a shard of a sweep without
            --require, shard 1 of 2 alone, shards 1-3 of 4 (the last one's runs past the
            others'), a shard that lost its last run (exit 2, no output); --partial merges
            and says which shards it holds, and its output with the missing shard merges
            into the whole sweep byte for byte; a varied coordinate of initial.q lands in
            the scene; an index on another key is refused; a header past its buffer
            (16 keys of 497 bytes) is refused before any run
  merge_rows  merge of shard 1/2 with a copy of shard 2/2 made wrong in one way each:
            a row cut in half, 5 or 3 extra columns, a NUL, a CR, failed=7, run 2^64+1,
            -1, 4 (of 4 runs), 0 (shard 1/2's), a metric 0x1p3, a comment among the rows,
            a 100 kB row then a bad one, the file cut inside its last row: exit 2 naming
            file:line (the right one after the long row) and what is wrong, no output
  merge_foreign  shard 2/2 of another sweep with shard 1/2: another --seed, scene file
            content, case, case override, --vary distribution, controller command,
            --restart, --require, --runs, version line, split (2/3), and a CSV without
            identity lines: exit 2 naming the first field that differs and both values
  notes     -v names the directory where it keeps the daemons' logs (they are there); a
            reference for q1 and none for q2: the summary's note says q2 is scored against
            r = 0
  shard     --shard refuses 1/2x, 0/2, 3/2, 1/0, spaces, signs, leading zeros, 1/2/3,
            numbers past 1e7 or 2^64 (exit 2 before any run); 4/4 runs run 3 alone
  kept      one lagsimd and one controller per worker (counted through wrappers), a
            process pair per run with --restart; the kept processes give the CSV of a
            process pair per run, byte for byte but the identity's restart line, where
            the controller's design is the same (the initial state varied; the masses at
            the scene's values after other masses were SET); a mass SET differs from the
            controller's design
  kept_python  the same with a Python controller (slow to start: copies of the first
            state pile up in its socket), three sweeps
  loss      in a network namespace whose loopback drops 1 UDP datagram in 15 (nftables):
            the same CSV as without loss, byte for byte (SET and RESET_TO sent again, the
            runs the bus lost states of read from the kept daemon's log)
  ssh       GNU parallel --sshlogin over two "hosts" (network namespaces, each running a
            private sshd on its own address): one shard on each, merged, equal to the whole
            sweep byte for byte (needs root, ip, sshd)
  stalled   the workers stopped and continued again and again (their sockets' queues
            overflow): runs read from the log, the same CSV, byte for byte
  vary      --vary mistakes refused before any run (exit 2, said why): a key or a
            coordinate varied twice, a key and one it holds, a reversed or one-point grid,
            arguments that are no plain decimal or whose values overflow (a grid's step,
            a normal's tail), a list varied whole, grids of more than 1e7 runs; integer
            options that are not integers; the spellings the docs use still run
  scene_c, scene_python  a controller that reads its gains from every scene (PD scaled by
            m2: tests/eval/scene_pd.c, scene_pd.py), 40 manipulator runs of 0.3 s over
            parameters.m2=uniform(0.3,1.2): -j1, -j2, two shards merged and --restart give
            the same CSV, byte for byte (a run's scene reaches the controller before the
            first state of the run)
  scene_loss  the same two controllers under 10 % datagram loss in a network namespace
            (nftables; root, else skipped): the same CSVs as without loss, byte for byte
  unanswered  a controller that never answers a run's last state: the worker waits for
            that answer; the run after fails saying so, and the next gets a new pair
  controller_exit  a controller that cannot run the sweep stops it (exit 2, said once, in
            seconds): one that exits at once ('exit 3': its exit status named), one on
            another prefix (the daemon's status says what it waits for); one that dies in
            the runs of a large m2 (tests/eval/mute_pd.py --exit-above) fails those runs
            (a row each, its exit status in the reason) and the next run gets a new pair;
            with --restart a controller that exits at once fails each run at once
  slow_start  a kept pair's controller that starts 12 s after its daemon (sleep 12), with
            --timeout 19: its scene request brings the state it is to answer, so the sweep
            runs (before, that state's copies had grown 10 s apart: the one after 10.2 s
            came at 20.5 s, past the 19 s, and the sweep stopped)
  progress  stderr a pseudo-terminal (100 columns): the progress line drawn again and again
            (each drawing after \\r and a clear), runs done never going back, at most 5
            drawings a second, none wider than the terminal, the last one the sweep's
            runs, its failures and its misses as the CSV counts them, ended by a newline;
            stderr a pipe: no progress text and no control byte; a pipe with --progress:
            whole lines, the last the count of every run
  interrupt  SIGINT to the sweep's process group (a terminal's Ctrl-C), SIGTERM to a
            shard's sweep, SIGHUP, each once the CSV holds a few rows: the sweep ends by
            the signal; its CSV holds the rows of the runs that ended, in run order, under
            the sweep's identity and a held line naming exactly them; stderr says so and
            gives the command that runs the others (--only) and the merge; both run as
            written give the whole sweep's CSV (the shard's, merged with the other
            shard), byte for byte. SIGKILL: the CSV as the sweep left it (held: unknown,
            the rows of the runs that had ended), merge --partial takes it, and with the
            runs it lacks (--only) it merges into the whole sweep byte for byte. --only
            mistakes refused before any run
"""
import contextlib
import csv
import filecmp
import glob
import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import SKIP, check, verdict  # noqa: E402  (tests/common: the one harness)

BIN, SRC, CASE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]), sys.argv[3]
SCENE = os.path.join(SRC, "config", "cartpole.yaml")
SWEEP = os.path.join(BIN, "lagsim-sweep")
CTRL = os.path.join(BIN, "lqr_balance") + " -q --prefix {prefix}"
# 5 s: the horizon in which half of these 8 plants settle (theta.settle 4.35 to 4.82 s) and
# half never do (nan), so that --require and --plot meet both
DUR = "5"
ARGS = ["--config", SCENE, "--controller", CTRL, "--duration", DUR,
        "--vary", "parameters.m0=uniform(0.5,2)", "--vary", "parameters.m1=grid(0.05,0.3,4)",
        "--runs", "2", "--seed", "7", "--require", "theta.settle<4.5"]
# The same sweep with runs of 0.5 s, for the cases that look at the CSV's identity and
# rows rather than at what the runs measure (merge, --shard): a tenth of the periods. Its
# --require on the pole's IAE in those 0.5 s (0.0142 for run 1, 0.0166 for run 3), so that
# some runs meet it (a row with no reason) and some do not
SHORT, REQ_SHORT = "0.5", "theta.iae<0.0155"
ARGS_SHORT = [{DUR: SHORT, ARGS[-1]: REQ_SHORT}.get(a, a) for a in ARGS]


def run(cmd, **kw):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=600, **kw)
    print("$", " ".join(cmd[:1] + cmd[-6:]), "->", p.returncode)
    print(p.stdout[-1500:], p.stderr[-1500:])
    return p


def rows(path):
    """The CSV's rows, its identity lines (comments, '#' first) left out."""
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def identity(path):
    """The identity lines of a sweep's CSV: [(key, value)], the version as 'lagsim-sweep'."""
    out = []
    for line in open(path, newline=""):
        if not line.startswith("#"):
            break
        k, _, v = line[2:].rstrip("\n").partition(": ")
        out.append(tuple(k.split(" ", 1)) if k.startswith("lagsim-sweep ") else (k, v))
    return out


def gnuplot_spy(d):
    """A gnuplot first on PATH that has the real one draw the script as a table too
    (d/table.txt: each curve's points, 'i' for one drawn inside the plot), then draw it."""
    real = shutil.which("gnuplot")
    spy = os.path.join(d, "spy")
    os.makedirs(spy)
    with open(os.path.join(spy, "gnuplot"), "w") as f:
        f.write("#!/bin/sh\nsed -e \"s|^set output .*|set output '/dev/null'\\nset table "
                "'%s/table.txt'|\" \"$1\" > %s/table.gp\n%s %s/table.gp\nexec %s \"$@\"\n"
                % (d, d, real, d, real))
    os.chmod(os.path.join(spy, "gnuplot"), 0o755)
    return dict(os.environ, PATH=spy + os.pathsep + os.environ["PATH"])


def drawn_first_panel(path):
    """The points drawn inside the first panel of a gnuplot table (its curves up to the
    next 'Curve 0')."""
    n, curves = 0, 0
    for line in open(path):
        if line.startswith("# Curve 0 of"):
            curves += 1
            if curves > 1:
                break
        f = line.split()
        n += len(f) == 3 and f[2] == "i"
    return n


def case_same(d):
    a1, a2, m = (os.path.join(d, n) for n in ("j1.csv", "j2.csv", "merged.csv"))
    png = os.path.join(d, "s.png")
    p = run([SWEEP] + ARGS + ["-j1", "--csv", a1, "--plot", png], env=gnuplot_spy(d))
    check(p.returncode in (0, 1), "the sweep ran (exit %d)" % p.returncode)
    check("8 runs:" in p.stdout and "theta.settle" in p.stdout, "a summary of 8 runs")
    check(os.path.getsize(png) > 5000, "a PNG of the metric")
    # every run drawn, those whose metric has no value (never settled) too
    nan = sum(x["theta.settle"] == "nan" for x in rows(a1))
    drawn = drawn_first_panel(os.path.join(d, "table.txt"))
    check(nan > 0 and drawn == 8, "--plot draws all 8 runs, the %d that never settled too "
          "(%d drawn)" % (nan, drawn))
    check(not glob.glob(png + ".*"), "no helper file beside the PNG: %s" % glob.glob(png + ".*"))
    # the outputs are checked before the first run: an existing PNG is refused at once
    p = run([SWEEP] + ARGS + ["-j1", "--csv", os.path.join(d, "again.csv"), "--plot", png])
    check(p.returncode == 2 and png in p.stderr and "runs:" not in p.stdout and
          not os.path.exists(os.path.join(d, "again.csv")),
          "--plot to an existing PNG without --force: exit 2 before any run, the PNG named")
    run([SWEEP] + ARGS + ["-j2", "--csv", a2])
    check(filecmp.cmp(a1, a2, shallow=False), "-j1 and -j2 give the same CSV, byte for byte")
    # the workers' plants in lagsimd hosts: two of 2 and 1 plants
    a3 = os.path.join(d, "ppw.csv")
    p = run([SWEEP] + ARGS + ["-j3", "--plants-per-worker", "2", "--csv", a3])
    check(os.path.exists(a3) and filecmp.cmp(a1, a3, shallow=False),
          "-j3 --plants-per-worker 2 (the workers' plants in two lagsimd hosts, of 2 and 1 "
          "plants) gives the same CSV, byte for byte (exit %d)" % p.returncode)
    # two shards with GNU parallel on this host, then merged
    sh = os.path.join(d, "shard-{}.csv")
    jl = os.path.join(d, "joblog")
    cmd = ["parallel", "--will-cite", "--joblog", jl, "-j2", SWEEP] + \
        ["'%s'" % a for a in ARGS] + ["--shard", "{}/2", "--csv", sh, ":::", "1", "2"]
    run(cmd)
    exits = [line.split("\t")[6] for line in open(jl).read().splitlines()[1:]]
    # a sweep exits 1 when a run misses --require: it ran
    check(len(exits) == 2 and all(e in ("0", "1") for e in exits),
          "GNU parallel ran both shards (exit statuses %s)" % exits)
    p = run([SWEEP, "merge", os.path.join(d, "shard-2.csv"), os.path.join(d, "shard-1.csv"),
             "-o", m])
    check(p.returncode == 0, "merge: exit 0")
    check(filecmp.cmp(a1, m, shallow=False), "2 shards merged = the whole sweep, byte for byte")
    r = rows(a1)
    check([int(x["run"]) for x in r] == list(range(8)), "8 rows in run order")
    # the whole sweep's identity lines are each shard's but the shard line
    check(all(identity(os.path.join(d, "shard-%d.csv" % k)) ==
              identity(a1) + [("shard", "%d/2" % k)] for k in (1, 2)) and
          identity(a1)[0][0] == "lagsim-sweep", "identity lines: the shards' = the whole "
          "sweep's and 'shard: K/2'")
    # gnuplot reads the CSV as written: the identity lines skipped, the names from the header
    tbl = os.path.join(d, "read.txt")
    subprocess.run(["gnuplot", "-e", "set datafile separator ','; set table '%s'; plot '%s' "
                    "using 'parameters.m0':'theta.iae'" % (tbl, a1)], check=True)
    pts = [line.split()[:2] for line in open(tbl) if line.strip() and line[0] != "#"]
    want = [(float(x["parameters.m0"]), float(x["theta.iae"])) for x in r]
    check(len(pts) == 8 and all(abs(float(p[0]) - w[0]) <= 1e-5 * w[0] and
                                abs(float(p[1]) - w[1]) <= 1e-5 * w[1] for p, w in zip(pts, want)),
          "gnuplot reads the CSV by column name, the identity lines skipped: %s" % pts)
    m1 = [float(x["parameters.m1"]) for x in r]
    grid = [0.05 + (0.3 - 0.05) * k / 3 for k in range(4)]
    check(all(abs(m1[i] - grid[i // 2]) < 1e-15 for i in range(8)),
          "grid(0.05,0.3,4) with 2 runs a point: %s" % m1)
    m0 = [float(x["parameters.m0"]) for x in r]
    check(all(0.5 < v < 2 for v in m0) and len(set(m0)) == 8,
          "uniform(0.5,2): 8 different values inside: %s" % m0)
    # run 5 again through lagsim-eval: with --restart (a controller started with the run's
    # values, as lagsim-eval starts it) the same overrides give the same metrics
    rr = os.path.join(d, "restart.csv")
    run([SWEEP] + ARGS + ["-j2", "--restart", "--csv", rr])
    suite = os.path.join(d, "one.yaml")
    with open(suite, "w") as f:
        f.write('cases:\n  - name: r5\n    duration: %s\n    set: ["parameters.m0=%s", '
                '"parameters.m1=%s"]\n' % (DUR, r[5]["parameters.m0"], r[5]["parameters.m1"]))
    e = os.path.join(d, "eval.csv")
    run([os.path.join(BIN, "lagsim-eval"), "--config", SCENE, "--controller", CTRL,
         "--suite", suite, "--csv", e])
    ev = {x["joint"]: x for x in rows(e)}
    r5 = rows(rr)[5]
    same = all(ev[j][mm] == r5[j + "." + mm] for j in ("x", "theta")
               for mm in ("rise", "settle", "overshoot", "sse", "iae", "ise", "peak_error",
                          "effort_peak", "effort_rms"))
    check(same, "--restart: run 5's metrics = lagsim-eval's for its overrides")
    req = [float(x["theta.settle"]) < 4.5 for x in r]
    check([x["required"] == "1" for x in r] == req and 0 < sum(req) < 8,
          "required column = theta.settle < 4.5 (%d of 8 runs)" % sum(req))
    # the values drawn depend on --seed alone, whatever the runs' length: runs of 0.1 s
    s8 = os.path.join(d, "seed8.csv")
    run([SWEEP] + [{"7": "8", DUR: "0.1"}.get(a, a) for a in ARGS] + ["-j2", "--csv", s8])
    check([x["parameters.m0"] for x in rows(s8)] != [x["parameters.m0"] for x in r],
          "another seed draws other values")


def case_slurm(d):
    script = os.path.join(SRC, "server", "tools", "slurm", "lagsim-sweep-array.sh")
    check(subprocess.run(["bash", "-n", script]).returncode == 0, "shell syntax")
    text = open(script).read()
    check("#SBATCH --array=" in text, "an #SBATCH --array line")
    whole = os.path.join(d, "whole.csv")
    run([SWEEP] + ARGS + ["-j2", "--csv", whole])
    out = os.path.join(d, "out")
    for task in (3, 4):  # an array 3-4: Slurm sets these in each task
        env = dict(os.environ, SLURM_ARRAY_TASK_ID=str(task), SLURM_ARRAY_TASK_MIN="3",
                   SLURM_ARRAY_TASK_COUNT="2", SLURM_CPUS_PER_TASK="1", LAGSIM_SWEEP=SWEEP)
        p = run(["bash", script, out, "--"] + ARGS, env=env)
        check(p.returncode in (0, 1), "array task %d ran" % task)
    shards = sorted(glob.glob(os.path.join(out, "shard-*-of-2.csv")))
    check(len(shards) == 2, "two shard CSVs: %s" % shards)
    m = os.path.join(d, "merged.csv")
    run([SWEEP, "merge"] + shards + ["-o", m])
    check(filecmp.cmp(whole, m, shallow=False), "the array's shards merged = the whole sweep")
    # a stepped array (--array=0-2:2): ids 0 and 2, shards 1/2 and 2/2
    out = os.path.join(d, "stepped")
    for task in (0, 2):
        env = dict(os.environ, SLURM_ARRAY_TASK_ID=str(task), SLURM_ARRAY_TASK_MIN="0",
                   SLURM_ARRAY_TASK_STEP="2", SLURM_ARRAY_TASK_COUNT="2",
                   SLURM_CPUS_PER_TASK="1", LAGSIM_SWEEP=SWEEP)
        p = run(["bash", script, out, "--"] + ARGS, env=env)
        check(p.returncode in (0, 1), "stepped array (0-2:2): task %d ran" % task)
    shards = sorted(glob.glob(os.path.join(out, "shard-*-of-2.csv")))
    m = os.path.join(d, "merged_stepped.csv")
    run([SWEEP, "merge"] + shards + ["-o", m])
    check(len(shards) == 2 and filecmp.cmp(whole, m, shallow=False),
          "a stepped array's shards (%s) merged = the whole sweep" % shards)
    p = run(["bash", script, out, "--"] + ARGS, env={"PATH": os.environ["PATH"]})
    check(p.returncode != 0 and "array task" in p.stderr, "outside an array task: refused")


def merge(d, *shards, out="m.csv", extra=()):
    """lagsim-sweep merge of the shards into d/out; the process and the output's path."""
    o = os.path.join(d, out)
    if os.path.exists(o):  # each merge on its own
        os.remove(o)
    return run([SWEEP, "merge"] + list(shards) + ["-o", o] + list(extra)), o


def refused(p, out, what, *texts):
    """merge exited 2, its message holds every text, and it wrote no output."""
    ok = p.returncode == 2 and all(t in p.stderr for t in texts) and not os.path.exists(out)
    check(ok, "%s: exit 2 naming %s, no output (exit %d: %s)"
          % (what, " and ".join(repr(t) for t in texts), p.returncode, p.stderr.strip()[-300:]))


def case_merge(d):
    a = os.path.join(d, "a.csv")
    run([SWEEP] + ARGS_SHORT + ["--runs", "1", "--shard", "1/4", "--csv", a])
    # the identity lines: what makes the runs what they are, each from its source
    with open(SCENE, "rb") as f:
        sha = hashlib.sha256(f.read()).hexdigest()
    want = [("lagsim-sweep", open(os.path.join(SRC, "CMakeLists.txt")).read().split(
                "project(lagsim VERSION ")[1].split()[0]),
            ("seed", "7"), ("scene-sha256", sha), ("case", "sweep"), ("duration", SHORT),
            ("vary", "parameters.m0=uniform(0.5,2)"), ("vary", "parameters.m1=grid(0.05,0.3,4)"),
            ("runs", "4"), ("controller", CTRL), ("restart", "no"),
            ("require", REQ_SHORT), ("shard", "1/4")]
    check(identity(a) == want, "a shard's identity lines: %s" % identity(a))
    b = os.path.join(d, "b.csv")
    shutil.copy(a, b)
    p, o = merge(d, a, b)
    refused(p, o, "one shard given twice", "shard 1/4 again", a)
    # another sweep: without --require
    c = os.path.join(d, "c.csv")
    run([SWEEP] + ARGS_SHORT[:-2] + ["--runs", "1", "--shard", "2/4", "--csv", c])
    p, o = merge(d, a, c)
    refused(p, o, "a shard of a sweep without --require",
            "not a shard of %s's sweep: require '%s' in %s, none here" % (a, REQ_SHORT, a))
    # shards that leave runs out: shard 1 of 2 of 4 runs alone holds runs 0 and 2
    h = os.path.join(d, "h.csv")
    run([SWEEP] + ARGS_SHORT + ["--runs", "1", "--shard", "1/2", "--csv", h])
    p, mh = merge(d, h, out="mh.csv")
    refused(p, mh, "shard 1 of 2 alone", "missing shard 2/2")
    p, mh = merge(d, h, out="mh.csv", extra=["--partial"])
    check(p.returncode == 0 and [x["run"] for x in rows(mh)] == ["0", "2"] and
          identity(mh) == identity(h),
          "--partial: the runs there merged, the output says it holds shard 1/2 (exit %d)"
          % p.returncode)
    # the partial merge and the shard it lacks make the whole sweep, byte for byte
    h2, whole = os.path.join(d, "h2.csv"), os.path.join(d, "whole.csv")
    run([SWEEP] + ARGS_SHORT + ["--runs", "1", "--shard", "2/2", "--csv", h2])
    run([SWEEP] + ARGS_SHORT + ["--runs", "1", "--csv", whole])
    p, o = merge(d, mh, h2, out="again.csv")
    check(p.returncode == 0 and filecmp.cmp(o, whole, shallow=False),
          "a partial merge and the missing shard merged: the whole sweep, byte for byte")
    check(identity(whole) == want[:-1], "the whole sweep: the same identity, no shard line")
    # the last shard missing, its runs past the others' (4 runs in 4 shards: 1 each)
    q = []
    for k in (1, 2, 3):
        q.append(os.path.join(d, "q%d.csv" % k))
        run([SWEEP] + ARGS_SHORT + ["--runs", "1", "--shard", "%d/4" % k, "--csv", q[-1]])
    p, o = merge(d, *q, out="q.csv")
    refused(p, o, "shards 1 to 3 of 4 (runs 0 to 2: no gap)", "missing shard 4/4")
    # a shard's sweep that lost a run (its last row gone)
    cut = os.path.join(d, "lost.csv")
    with open(h2) as f, open(cut, "w") as g:
        g.write("".join(f.readlines()[:-1]))
    p, o = merge(d, h, cut, out="lost_m.csv")
    refused(p, o, "shard 2/2 without its last run", "missing runs 3 ")
    # one coordinate of initial.q varied: joined into the scene's list (x stays 0); the
    # pole released at rest from theta0 under LQR peaks at theta0 itself
    g = os.path.join(d, "g.csv")
    run([SWEEP, "--config", SCENE, "--controller", CTRL, "--duration", "1",
         "--vary", "initial.q[1]=grid(0.02,0.08,2)", "--csv", g])
    r = rows(g)
    check([x["initial.q[1]"] for x in r] == ["0.02", "0.08"] and
          all(float(x["theta.peak_error"]) == float(x["initial.q[1]"]) for x in r) and
          all(float(x["x.peak_error"]) > 0 for x in r),
          "initial.q[1] varied: theta starts there (peak error = the value)")
    p = run([SWEEP] + ARGS_SHORT + ["--vary", "initial.x[0]=normal(0,1)"])
    check(p.returncode == 2 and "initial.q[i]" in p.stderr, "an index on another key: exit 2")
    # 16 varied keys of 497 bytes: refused before any run (a header past its buffer, 8192
    # bytes, was written past it); the loader's key limit (255) now refuses them first
    keys = sum((["--vary", "parameters.%s%02d=uniform(0,1)" % ("k" * 484, k)] for k in range(16)),
               [])
    p = run([SWEEP, "--config", SCENE, "--controller", CTRL, "--duration", "1"] + keys)
    check(p.returncode == 2 and ("header" in p.stderr or "at most 255" in p.stderr)
          and "runs:" not in p.stdout,
          "varied keys' names too long for the header: exit 2 before any run (exit %d)"
          % p.returncode)


def shard_pair(d, args=ARGS_SHORT):
    """Shards 1/2 and 2/2 of a sweep of 4 runs (args with --runs 1)."""
    out = []
    for k in (1, 2):
        out.append(os.path.join(d, "s%d.csv" % k))
        run([SWEEP] + args + ["--runs", "1", "--shard", "%d/2" % k, "--csv", out[-1]])
    return out


def case_merge_rows(d):
    s1, s2 = shard_pair(d)
    p, o = merge(d, s1, s2)
    check(p.returncode == 0, "the two shards as written: merged (exit %d)" % p.returncode)
    lines = open(s2, newline="").read().split("\n")  # the last is '' (the final newline)
    h = next(i for i, x in enumerate(lines) if x.startswith("run,"))
    row, last = lines[h + 1], len(lines) - 2  # shard 2/2: runs 1 and 3
    reason = row.index(',"",')
    at = h + 2  # the first row's line number
    bad = [
        ("a row cut in half", {h + 1: row[:len(row) // 2]}, at, "fields where the header has 24"),
        ("a row of 5 extra columns", {h + 1: row + ",1,2,3,4,5"}, at,
         "29 fields where the header has 24"),
        ("a row of 3 extra columns", {h + 1: row + ",0,0,0"}, at,
         "27 fields where the header has 24"),
        ("a NUL byte in the reason", {h + 1: row[:reason] + ',"a\0b",' + row[reason + 4:]}, at,
         "a NUL byte"),
        ("a CR (a spreadsheet's CRLF)", {h + 1: row + "\r"}, at, "a control byte"),
        ("failed=7", {h + 1: row[:reason - 4] + ",7,1" + row[reason:]}, at,
         "field 4 (failed): expected 0 or 1, found '7'"),
        ("run 2^64+1", {h + 1: "18446744073709551617" + row[1:]}, at,
         "field 1 (run): expected a run number of the sweep (0 to 3), "
         "found '18446744073709551617'"),
        ("run -1", {h + 1: "-1" + row[1:]}, at, "field 1 (run)", "found '-1'"),
        ("run 4 of a sweep of 4", {h + 1: "4" + row[1:]}, at, "(0 to 3), found '4'"),
        ("run 0 in shard 2/2's file", {h + 1: "0" + row[1:]}, at, "run 0 is shard 1/2's"),
        ("a metric that is no number", {h + 1: row[:row.rindex(",")] + ",0x1p3"}, at,
         "field 24 (theta.effort_rms): expected a number or nan, found '0x1p3'"),
        ("a comment among the rows", {h + 1: "# " + row}, at, "a comment line among the rows"),
        # a row of 100 kB (its reason) whole, the bad row after it reported at its own line
        ("a long row, then a bad one",
         {h + 1: row[:reason] + ',"' + "x" * 100000 + '",' + row[reason + 4:],
          h + 2: "garbage"}, at + 1, "1 field where the header has 24"),
        ("the file cut inside its last row", {last: lines[last][:40], last + 1: None}, last + 1,
         "the file ends inside this line"),
    ]
    for what, change, ln, *texts in bad:
        m = os.path.join(d, "bad.csv")
        new = [change.get(i, x) for i, x in enumerate(lines)]
        with open(m, "w", newline="") as f:
            f.write("\n".join(x for x in new if x is not None))
        p, o = merge(d, s1, m, out="bad_out.csv")
        refused(p, o, what, "%s:%d: " % (m, ln), *texts)


def case_merge_foreign(d):
    base = ARGS_SHORT + ["--runs", "1"]
    s1 = shard_pair(d)[0]
    scene = os.path.join(d, "scene.yaml")  # the same keys, other bytes
    with open(SCENE) as f, open(scene, "w") as g:
        g.write(f.read() + "\n# a comment: the same plant, another file\n")
    suite = os.path.join(d, "suite.yaml")
    with open(suite, "w") as f:
        f.write('cases:\n  - name: sweep\n    duration: %s\n    set: ["parameters.m0=1"]\n'
                '  - name: tilt\n    duration: %s\n' % (SHORT, SHORT))
    nodur = [a for a in base if a not in ("--duration", SHORT)]
    variants = [
        ("another --seed", [a if a != "7" else "1" for a in base], "seed '7' in"),
        ("another scene file's content", [a if a != SCENE else scene for a in base],
         "scene-sha256 '"),
        ("another case", nodur + ["--suite", suite, "--case", "tilt"], "case 'sweep' in"),
        ("the case's overrides", nodur + ["--suite", suite, "--case", "sweep"],
         "set (a line of them) none in"),
        ("another --vary distribution",
         [a.replace("uniform(0.5,2)", "uniform(0.5,2.5)") for a in base],
         "vary (a line of them) 'parameters.m0=uniform(0.5,2)' in"),
        ("another controller", [a if a != CTRL else CTRL.replace("-q --prefix", "-q  --prefix")
                                for a in base], "controller '"),
        ("--restart", base + ["--restart"], "restart 'no' in"),
        ("another --require", [a if a != REQ_SHORT else "theta.iae<0.02" for a in base],
         "require '%s' in" % REQ_SHORT),
        ("another --runs", base + ["--runs", "2"], "runs '4' in"),
    ]
    for what, args, text in variants:
        s2 = os.path.join(d, "other.csv")
        run([SWEEP] + args + ["--shard", "2/2", "--csv", s2, "--force"])
        p, o = merge(d, s1, s2, out="foreign.csv")
        refused(p, o, "shard 2/2 of a sweep with " + what,
                "%s: not a shard of %s's sweep: " % (s2, s1), text)
    # another lagsim-sweep's version: its first line
    s2 = shard_pair(d)[1]
    with open(s2) as f:
        text = f.read()
    first = text.split("\n", 1)[0]
    with open(s2, "w") as f:
        f.write(text.replace(first, "# lagsim-sweep 0.0.1", 1))
    p, o = merge(d, s1, s2, out="foreign.csv")
    refused(p, o, "a shard of another lagsim-sweep version",
            "lagsim-sweep %s wrote %s, 0.0.1 wrote this one" % (first.split()[-1], s1))
    # a shard of another split (2/3 with 1/2)
    s3 = os.path.join(d, "third.csv")
    run([SWEEP] + base + ["--shard", "2/3", "--csv", s3])
    p, o = merge(d, s1, s3, out="foreign.csv")
    refused(p, o, "shard 2/3 with 1/2", "another split: %s holds shards of 2 (--shard K/2), "
            "this file shards of 3 (--shard K/3)" % s1)
    # the whole sweep with a shard: said in words (it was "shards of 1 there (1: the whole
    # sweep)")
    w = os.path.join(d, "whole.csv")
    run([SWEEP] + base + ["--csv", w])
    p, o = merge(d, w, s3, out="foreign.csv")
    refused(p, o, "a shard with the whole sweep", "another split: %s holds the whole sweep "
            "(no --shard), this file shards of 3 (--shard K/3)" % w)
    # a CSV without identity lines (the rows alone)
    plain = os.path.join(d, "plain.csv")
    with open(plain, "w") as f:
        f.write("".join(x for x in open(s1) if not x.startswith("#")))
    p, o = merge(d, plain, out="foreign.csv")
    refused(p, o, "a CSV without identity lines", "%s:1: not a lagsim-sweep CSV" % plain)


def case_shard(d):
    out = os.path.join(d, "s.csv")
    for bad in ("1/2x", "0/2", "3/2", "1/0", " 1/2", "1/ 2", "1 /2", "+1/2", "01/2", "1/2/3",
                "1", "/2", "1/", "a/b", "", "18446744073709551617/2", "1/18446744073709551617",
                "1/10000001"):
        if os.path.exists(out):
            os.remove(out)
        p = run([SWEEP] + ARGS_SHORT + ["--shard", bad, "--csv", out])
        check(p.returncode == 2 and "--shard: expected K/N" in p.stderr and
              not os.path.exists(out) and "runs:" not in p.stdout,
              "--shard '%s': exit 2 before any run (exit %d)" % (bad, p.returncode))
    p = run([SWEEP] + ARGS_SHORT + ["--runs", "1", "--shard", "4/4", "--csv", out, "--force"])
    check(p.returncode in (0, 1) and [x["run"] for x in rows(out)] == ["3"],
          "--shard 4/4 of 4 runs: run 3 alone")


def same_but_restart(kept, fresh):
    """The CSV of kept processes and that of --restart: byte for byte the same but the
    identity's restart line (the sweeps differ there, and merge refuses to mix them)."""
    with open(kept, "rb") as f, open(fresh, "rb") as g:
        a, b = f.read(), g.read()
    return a.count(b"\n# restart: no\n") == 1 and \
        a.replace(b"\n# restart: no\n", b"\n# restart: yes\n") == b


def starts(path):
    return len(open(path).read().splitlines()) if os.path.exists(path) else 0


def case_kept(d):
    # wrappers that count the starts of the daemon and of the controller
    dcount, ccount = os.path.join(d, "daemons"), os.path.join(d, "controllers")
    wrap = os.path.join(d, "lagsimd")
    with open(wrap, "w") as f:
        f.write('#!/bin/sh\necho x >> %s\nexec %s "$@"\n' % (dcount, os.path.join(BIN, "lagsimd")))
    os.chmod(wrap, 0o755)
    ctrl = "echo x >> %s; exec %s" % (ccount, CTRL)
    base = ["--config", SCENE, "--controller", ctrl, "--duration", "4", "--lagsimd", wrap]
    q = base + ["--vary", "initial.q[1]=normal(0,0.05)", "--vary", "initial.qd[0]=uniform(-0.2,0.2)",
                "--runs", "8", "--seed", "3"]
    kept, fresh = os.path.join(d, "kept.csv"), os.path.join(d, "fresh.csv")
    run([SWEEP] + q + ["-j2", "--csv", kept])
    check((starts(dcount), starts(ccount)) == (2, 2),
          "-j2, 8 runs: 2 daemons and 2 controllers started (got %d, %d)"
          % (starts(dcount), starts(ccount)))
    run([SWEEP] + q + ["-j2", "--restart", "--csv", fresh])
    check((starts(dcount), starts(ccount)) == (10, 10),
          "--restart: one daemon and one controller a run (got %d, %d in all)"
          % (starts(dcount), starts(ccount)))
    check(same_but_restart(kept, fresh),
          "initial state varied: kept processes = a process pair per run, byte for byte")
    # the pole's mass: two runs at 0.3, then two at the scene's 0.1 (-j1: in that order)
    m = base + ["--vary", "parameters.m1=grid(0.05,0.1,2)", "--runs", "2"]
    kept, fresh = os.path.join(d, "kept_m.csv"), os.path.join(d, "fresh_m.csv")
    run([SWEEP] + m + ["-j1", "--csv", kept])
    run([SWEEP] + m + ["-j1", "--restart", "--csv", fresh])
    a, b = rows(kept), rows(fresh)
    check([x["parameters.m1"] for x in a] == ["0.05"] * 2 + ["0.1"] * 2,
          "grid(0.05,0.1,2): 0.05 twice, then the scene's 0.1 twice")
    check(a[2:] == b[2:], "the scene's mass SET back after another: the rows of a process "
          "pair started with it, byte for byte")
    check(a[0]["theta.iae"] != b[0]["theta.iae"] and a[0]["theta.iae"] != a[2]["theta.iae"],
          "mass 0.05 SET on the plant (rows differ from the scene's mass), the controller "
          "designed for the scene's (rows differ from --restart's)")


def case_kept_python(d):
    # a controller slow to start (Python): lockstep copies of the first state pile up in its
    # socket while it imports, and it answers each; an answer to a state before a RESET_TO
    # must not be taken for one of the run's (the same sim time). Three sweeps, the
    # manipulator tracking its reference: kept processes = --restart, byte for byte
    build_python = os.path.join(os.path.dirname(BIN), "python")
    env = dict(os.environ, PYTHONPATH=build_python)
    ctrl = "python3 %s -q --prefix {prefix}" % os.path.join(SRC, "clients", "python",
                                                            "manipulator_pd.py")
    q = ["--config", os.path.join(SRC, "config", "manipulator.yaml"), "--controller", ctrl,
         "--duration", "2", "--vary", "initial.q[0]=normal(0,0.05)", "--runs", "4", "-j2"]
    fresh = os.path.join(d, "fresh.csv")
    run([SWEEP] + q + ["--seed", "2", "--restart", "--csv", fresh], env=env)
    same = 0
    for k in range(3):
        kept = os.path.join(d, "kept%d.csv" % k)
        run([SWEEP] + q + ["--seed", "2", "--csv", kept], env=env)
        if same_but_restart(kept, fresh):
            same += 1
        else:  # which runs differ, for the one who reads the failure
            a, b = open(kept).read().splitlines(), open(fresh).read().splitlines()
            print("kept%d.csv and fresh.csv differ:\n%s" % (k, "\n".join(
                "  kept  %s\n  fresh %s" % (x, y) for x, y in zip(a, b) if x != y)))
    check(len(rows(fresh)) == 4 and same == 3,
          "Python controller, 3 sweeps with kept processes: %d of 3 equal to --restart's, "
          "byte for byte" % same)


@contextlib.contextmanager
def loss_namespace(name):
    """A network namespace of this process (NAME and the pid), its loopback up with the
    multicast route, and an nft chain `inet loss in` for rules that drop datagrams; the
    command prefix that runs in it is yielded, and it is removed after. The test is skipped
    where it cannot be made (root, ip and nft)."""
    if os.geteuid() != 0 or not shutil.which("nft") or not shutil.which("ip"):
        print("skipped: needs root, ip and nft")
        sys.exit(SKIP)
    ns = "%s%d" % (name, os.getpid())
    if subprocess.run(["ip", "netns", "add", ns]).returncode != 0:
        print("skipped: cannot make a network namespace here")
        sys.exit(SKIP)
    try:
        inns = ["ip", "netns", "exec", ns]
        for c in (["ip", "link", "set", "lo", "up"],
                  ["ip", "route", "add", "224.0.0.0/4", "dev", "lo"],
                  ["nft", "add", "table", "inet", "loss"],
                  ["nft", "add", "chain", "inet", "loss", "in",
                   "{ type filter hook input priority 0; }"]):
            subprocess.run(inns + c, check=True)
        yield inns
    finally:
        subprocess.run(["ip", "netns", "del", ns])


def case_loss(d):
    with loss_namespace("lgsweep") as inns:
        q = ARGS[:-2] + ["--vary", "initial.q[1]=normal(0,0.05)", "-j2", "-v"]
        clean, lossy = os.path.join(d, "clean.csv"), os.path.join(d, "lossy.csv")
        run(inns + [SWEEP] + q + ["--csv", clean])
        subprocess.run(inns + ["nft", "add", "rule", "inet", "loss", "in", "udp", "dport",
                               "64000-65535", "numgen", "random", "mod", "15", "==", "0",
                               "counter", "drop"], check=True)
        p = run(inns + [SWEEP] + q + ["--csv", lossy])
        dropped = subprocess.run(inns + ["nft", "list", "chain", "inet", "loss", "in"],
                                 stdout=subprocess.PIPE, universal_newlines=True).stdout
        print(dropped)
        check(" drop" in dropped and "packets 0 " not in dropped, "datagrams were dropped")
        check(p.returncode in (0, 1), "the sweep ran under loss (exit %d)" % p.returncode)
        check(filecmp.cmp(clean, lossy, shallow=False),
              "1 datagram in 15 lost: the same CSV as without loss, byte for byte")


def sshd_host(d, name, net):
    """A network namespace `name` joined to this one by a veth pair on 10.<net>.0.0/24, its
    loopback up with the multicast route (lagsim's bus stays on the host), and an sshd on
    10.<net>.0.2 that takes the key d/id for root. Returns the address."""
    host, peer = "10.%d.0.1" % net, "10.%d.0.2" % net
    va, vb = "lgs%da%d" % (net, os.getpid() % 10000), "lgs%db%d" % (net, os.getpid() % 10000)
    inns = ["ip", "netns", "exec", name]
    for c in (["ip", "netns", "add", name],
              ["ip", "link", "add", va, "type", "veth", "peer", "name", vb],
              ["ip", "link", "set", vb, "netns", name],
              ["ip", "addr", "add", host + "/24", "dev", va], ["ip", "link", "set", va, "up"],
              inns + ["ip", "addr", "add", peer + "/24", "dev", vb],
              inns + ["ip", "link", "set", vb, "up"], inns + ["ip", "link", "set", "lo", "up"],
              inns + ["ip", "route", "add", "224.0.0.0/4", "dev", "lo"]):
        subprocess.run(c, check=True)
    cfg = os.path.join(d, "sshd-%s.conf" % name)
    with open(cfg, "w") as f:
        f.write("ListenAddress %s\nHostKey %s/hostkey\nAuthorizedKeysFile %s/authorized_keys\n"
                "PermitRootLogin prohibit-password\nStrictModes no\nUsePAM no\n"
                "PidFile %s/sshd-%s.pid\n" % (peer, d, d, d, name))
    os.makedirs("/run/sshd", exist_ok=True)
    subprocess.run(inns + ["/usr/sbin/sshd", "-f", cfg, "-E", os.path.join(d, name + ".log")],
                   check=True)
    return peer


def case_ssh(d):
    if os.geteuid() != 0 or not os.path.exists("/usr/sbin/sshd") or not shutil.which("ip"):
        print("skipped: needs root, ip and sshd (openssh-server)")
        sys.exit(SKIP)
    for key in ("hostkey", "id"):
        subprocess.run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f",
                        os.path.join(d, key)], check=True)
    shutil.copy(os.path.join(d, "id.pub"), os.path.join(d, "authorized_keys"))
    names = ["lgsshb%d" % os.getpid(), "lgsshc%d" % os.getpid()]
    try:
        hosts = [sshd_host(d, n, 200 + k) for k, n in enumerate(names)]
        whole = os.path.join(d, "whole.csv")
        run([SWEEP] + ARGS + ["-j2", "--csv", whole])
        ssh = ("ssh -i %s -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null "
               "-o BatchMode=yes -o LogLevel=ERROR" % os.path.join(d, "id"))
        sh = os.path.join(d, "shard-{}.csv")
        # one shard a host (-j1 each): the shards run where ssh takes them
        jl = os.path.join(d, "joblog")
        run(["parallel", "--will-cite", "--joblog", jl, "--ssh", ssh, "--sshlogin",
             ",".join(hosts), "-j1", SWEEP] + ["'%s'" % a for a in ARGS] +
            ["-j1", "--shard", "{}/2", "--csv", sh, ":::", "1", "2"])
        jobs = [line.split("\t") for line in open(jl).read().splitlines()[1:]]
        # a sweep exits 1 when a run misses --require: it ran
        check(sorted(j[1] for j in jobs) == sorted(hosts) and all(j[6] in ("0", "1") for j in jobs),
              "GNU parallel --sshlogin ran one shard on each host: %s"
              % [(j[1], j[6]) for j in jobs])
        logins = [open(os.path.join(d, n + ".log")).read() for n in names]
        check(all("Accepted publickey for root" in x for x in logins),
              "each host's sshd took a login: %s" % [x.count("Accepted") for x in logins])
        m = os.path.join(d, "merged.csv")
        run([SWEEP, "merge", os.path.join(d, "shard-1.csv"), os.path.join(d, "shard-2.csv"),
             "-o", m])
        check(filecmp.cmp(whole, m, shallow=False),
              "the shards run over ssh, merged = the whole sweep, byte for byte")
    finally:
        for n in names:
            pid = os.path.join(d, "sshd-%s.pid" % n)
            if os.path.exists(pid):
                subprocess.run(["kill", open(pid).read().strip()])
            subprocess.run(["ip", "netns", "del", n], stderr=subprocess.DEVNULL)
        for k in range(2):
            subprocess.run(["ip", "link", "del", "lgs%da%d" % (200 + k, os.getpid() % 10000)],
                           stderr=subprocess.DEVNULL)


def case_stalled(d):
    # the workers stopped (SIGSTOP) for 0.2 s again and again while their daemons and
    # controllers go on: their sockets' queues overflow and the bus loses states for them
    # (runs of 8 s: 800 states, more than a queue holds)
    q = [{"2": "6", DUR: "8"}.get(a, a) for a in ARGS[:-2]] + [
        "--vary", "initial.q[1]=normal(0,0.05)", "-j2"]  # 24 runs
    clean, stalled = os.path.join(d, "clean.csv"), os.path.join(d, "stalled.csv")
    run([SWEEP] + q + ["--csv", clean])
    p = subprocess.Popen([SWEEP] + q + ["-v", "--csv", stalled], stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, universal_newlines=True)
    stops = 0
    while p.poll() is None:
        time.sleep(0.1)
        kids = subprocess.run(["pgrep", "-P", str(p.pid)], stdout=subprocess.PIPE,
                              universal_newlines=True).stdout.split()
        for sig in (signal.SIGSTOP, None, signal.SIGCONT):
            if sig is None:
                time.sleep(0.2)
                continue
            for k in kids:
                try:
                    os.kill(int(k), sig)
                except ProcessLookupError:  # a worker that ended since pgrep saw it
                    pass
        stops += bool(kids)
    err = p.stderr.read()
    print(err[-3000:])
    check(p.returncode in (0, 1) and stops > 0, "the sweep ran, its workers stopped %d times"
          % stops)
    check("read from the log" in err, "runs whose states the bus lost were read from the log")
    check(filecmp.cmp(clean, stalled, shallow=False),
          "workers stopped again and again: the same CSV, byte for byte")


# (the --vary arguments, what the refusal says)
BAD_VARY = [
    (["parameters.m1=uniform(0.1,0.2)", "parameters.m1=uniform(0.2,0.3)"], "the same key as"),
    (["initial.q[1]=normal(0,0.05)", "initial.q[1]=normal(0,0.1)"], "the same key as"),
    (["initial.q[1]=normal(0,0.05)", "initial.q[01]=normal(0,0.1)"], "the same key as"),
    (["parameters.m1=uniform(0.1,0.2)", "parameters=uniform(0,1)"], "holds or lies in"),
    (["initial.q[1]=normal(0,0.05)", "initial=uniform(0,1)"], "holds or lies in"),
    (["initial.q=uniform(0,1)"], "a list: vary one coordinate"),
    (["parameters.m1=grid(1e308,-1e308,3)"], "A < B"),
    (["parameters.m1=grid(-1e308,1e308,3)"], "B - A finite"),
    (["parameters.m1=grid(0.3,0.05,4)"], "A < B"),
    (["parameters.m1=grid(0.05,0.3,1)"], "an integer from 2"),
    (["parameters.m1=grid(0.05,0.3,2.5)"], "an integer from 2"),
    (["parameters.m1=grid(0.05,0.3,2000000)"], "an integer from 2"),
    (["parameters.m1=uniform(-1e308,1e308)"], "B - A finite"),
    (["parameters.m1=uniform(0.3,0.3)"], "A < B"),
    (["parameters.m1=uniform(inf,1)"], "plain decimal"),
    (["parameters.m1=uniform(0,1e999)"], "plain decimal"),
    (["parameters.m1=uniform(0x1p-3,1)"], "plain decimal"),
    (["parameters.m1=uniform(nan,1)"], "plain decimal"),
    (["parameters.m1=normal(0,1e308)"], "9 SD finite"),
    (["parameters.m1=normal(0.1,0)"], "SD > 0"),
    (["parameters.m1=normal(0.1,-1)"], "SD > 0"),
    (["parameters.m1=uniform(0.1,0.2)junk"], "plain decimal"),
    # the keys as the scene loader takes them, before any run (before, every run failed
    # with the loader's words in the CSV's reason, and the sweep exited 1)
    (["parameters.M1=uniform(0.05,0.3)"], "--vary parameters.M1=uniform(0.05,0.3): the scene "
     "refuses parameters.M1=0.175: case sweep: --set parameters.M1: unknown "
     "parameter 'M1'"),
    (["parameters.m1=uniform(-3,-1)"], "refuses parameters.m1=-2: case sweep: --set "
     "parameters.m1: expected a number > 0"),
    (["initial.q[1]=uniform(0,0.1)", "effects.friction=grid(0,1,3)"], "--vary "
     "effects.friction=grid(0,1,3): the scene refuses effects.friction=0.5"),
    (["parameters.m1=grid(0.1,0.2,1000)", "parameters.m0=grid(0.5,2,1000)",
      "initial.q[1]=grid(0,0.1,1000)"], "more than 1e7 runs"),
    # 1e36 runs: a count that overflowed to a negative one made "0 runs", exit 0
    (["parameters.m1=grid(0.1,0.2,1000000)", "parameters.m0=grid(0.5,2,1000000)"] +
     ["initial.%s[%d]=grid(0,0.1,1000000)" % (k, i) for k in ("q", "qd") for i in (0, 1)],
     "more than 1e7 runs"),
]


def case_vary(d):
    base = ["--config", SCENE, "--controller", CTRL, "--duration", "0.2"]
    for vs, why in BAD_VARY:
        args = sum((["--vary", v] for v in vs), [])
        p = run([SWEEP] + base + args + ["--csv", os.path.join(d, "v.csv"), "--force"])
        check(p.returncode == 2 and why in p.stderr and "runs:" not in p.stdout,
              "--vary %s: exit 2 before any run, %r said (%d)" % (" ".join(vs), why,
                                                                  p.returncode))
    for opt, val in (("--runs", "2.5"), ("--jobs", "1.5"), ("--seed", "1.5"),
                     ("--runs", "0x10"), ("--seed", "1e999")):
        p = run([SWEEP] + base + ["--vary", "parameters.m1=uniform(0.1,0.2)", opt, val])
        check(p.returncode == 2 and opt in p.stderr and "an integer" in p.stderr,
              "%s %s: exit 2, an integer expected (%d)" % (opt, val, p.returncode))
    # what the docs write runs: blanks after commas, two coordinates of one list, a grid
    out = os.path.join(d, "ok.csv")
    p = run([SWEEP] + base + ["--vary", "parameters.m1=grid(0.1, 0.2, 2)", "--vary",
                              "initial.q[0]=uniform(-0.01, 0.01)", "--vary",
                              "initial.q[1]=normal(0, 0.01)", "--runs", "2", "--csv", out])
    check(p.returncode == 0 and [x["parameters.m1"] for x in rows(out)] ==
          ["0.1"] * 2 + ["0.2"] * 2,
          "grid(0.1, 0.2, 2) with blanks, two coordinates of initial.q: 4 runs (%d)"
          % p.returncode)
    # a value refused for part of the range only: a failed run of its own, and the terminal
    # summary (and merge's, made from the rows) says why runs failed, with their counts
    out = os.path.join(d, "part.csv")
    p = run([SWEEP] + base + ["--vary", "parameters.m1=normal(0.01,0.1)", "--runs", "8",
                              "--seed", "3", "--csv", out])
    r = rows(out)
    bad = [x for x in r if x["failed"] == "1"]
    shown = re.findall(r"^  (\d+) failed: (.*)$", p.stdout, re.M)
    more = re.search(r"^  \.\.\. and (\d+) other reasons? \((\d+) runs?\)$", p.stdout, re.M)
    counted = sum(int(n) for n, _ in shown) + (int(more.group(2)) if more else 0)
    check(p.returncode == 1 and 0 < len(bad) < 8 and
          all(x["reason"].startswith("refused: --set parameters.m1: expected a number > 0")
              for x in bad) and counted == len(bad) and
          {w for _, w in shown} <= {x["reason"] for x in bad} and len(shown) == min(5, len(bad)),
          "normal(0.01,0.1): %d of 8 runs refused by the scene, each a failed run, the terminal "
          "says why (%d reasons shown, %d runs counted)" % (len(bad), len(shown), counted))
    m = run([SWEEP, "merge", out, "-o", os.path.join(d, "part-m.csv")])
    check(m.returncode == 0 and re.findall(r"^  \d+ failed: .*$", m.stdout, re.M) ==
          re.findall(r"^  \d+ failed: .*$", p.stdout, re.M),
          "merge's summary says the same reasons")


def scene_sweep(lang, runs=40, duration="1.5"):
    """The arguments of a sweep of the scene-reactive controller in `lang`, and the env."""
    build_python = os.path.join(os.path.dirname(BIN), "python")
    env = dict(os.environ, PYTHONPATH=build_python)
    ctrl = (os.path.join(BIN, "scene_pd") if lang == "c" else
            "python3 " + os.path.join(SRC, "tests", "eval", "scene_pd.py")) + " -q --prefix {prefix}"
    q = ["--config", os.path.join(SRC, "config", "manipulator.yaml"), "--controller", ctrl,
         "--duration", duration, "--vary", "parameters.m2=uniform(0.3,1.2)", "--runs", str(runs),
         "--seed", "11"]
    return q, env


def scene_same(d, lang):
    # runs of 0.3 s (30 states): what is at stake is each run's first states, whose answers
    # need the run's own scene; every answer after them goes into the metrics as well
    q, env = scene_sweep(lang, 40, "0.3")
    j1, j2, m, fresh = (os.path.join(d, lang + n) for n in
                        ("j1.csv", "j2.csv", "merged.csv", "restart.csv"))
    p = run([SWEEP] + q + ["-j1", "--csv", j1], env=env)
    check(p.returncode in (0, 1) and len(rows(j1)) == 40, "%s: 40 runs with -j1" % lang)
    m2 = [float(x["parameters.m2"]) for x in rows(j1)]
    check(all(0.3 < v < 1.2 for v in m2) and len(set(m2)) == 40, "%s: 40 masses drawn" % lang)
    run([SWEEP] + q + ["-j2", "--csv", j2], env=env)
    sh = os.path.join(d, lang + "shard-{}.csv")
    run(["parallel", "--will-cite", "-j2", SWEEP] + ["'%s'" % a for a in q] +
        ["-j1", "--shard", "{}/2", "--csv", sh, ":::", "1", "2"], env=env)
    run([SWEEP, "merge", sh.format(1), sh.format(2), "-o", m])
    run([SWEEP] + q + ["-j2", "--restart", "--csv", fresh], env=env)
    def data(path):  # the header and the rows: --restart is in the identity lines
        return [x for x in open(path) if not x.startswith("#")]
    for name, other in (("-j2", j2), ("two shards merged", m), ("--restart", fresh)):
        same = os.path.exists(other) and (data(j1) == data(other) if name == "--restart"
                                          else filecmp.cmp(j1, other, shallow=False))
        differ = 0 if not os.path.exists(other) else sum(
            a != b for a, b in zip(rows(j1), rows(other)))
        check(same, "%s, m2 varied: %s gives the CSV of -j1, byte for byte (%d rows differ)"
              % (lang, name, differ))
        if not same and os.path.exists(other):
            for a, b in [(a, b) for a, b in zip(rows(j1), rows(other)) if a != b][:3]:
                print("  run %s: -j1 failed=%s %r; %s failed=%s %r" % (
                    a["run"], a["failed"], a["reason"], name, b["failed"], b["reason"]))
    return j1


def case_scene_c(d):
    scene_same(d, "c")


def case_scene_python(d):
    scene_same(d, "python")


def case_scene_loss(d):
    with loss_namespace("lgscene") as inns:
        for lang in ("c", "python"):
            q, env = scene_sweep(lang, 20)
            clean, lossy = (os.path.join(d, lang + n) for n in ("clean.csv", "lossy.csv"))
            subprocess.run(inns + ["nft", "flush", "chain", "inet", "loss", "in"], check=True)
            run(inns + [SWEEP] + q + ["-j2", "--csv", clean], env=env)
            # 1 datagram in 10 dropped on the plants' ports, both ways
            subprocess.run(inns + ["nft", "add", "rule", "inet", "loss", "in", "udp", "dport",
                                   "64000-65535", "numgen", "random", "mod", "10", "==", "0",
                                   "counter", "drop"], check=True)
            p = run(inns + [SWEEP] + q + ["-j2", "-v", "--csv", lossy], env=env)
            dropped = subprocess.run(inns + ["nft", "list", "chain", "inet", "loss", "in"],
                                     stdout=subprocess.PIPE, universal_newlines=True).stdout
            print(dropped)
            check(" drop" in dropped and "packets 0 " not in dropped,
                  "%s: datagrams were dropped" % lang)
            check(p.returncode in (0, 1) and len(rows(lossy)) == 20,
                  "%s: the sweep ran under loss (exit %d)" % (lang, p.returncode))
            check(filecmp.cmp(clean, lossy, shallow=False),
                  "%s, m2 varied, 10 %% of datagrams lost: the CSV without loss, byte for byte"
                  % lang)


def case_unanswered(d):
    # a controller that never answers a run's last state (the one the daemon pauses at):
    # the worker does not start the next run on that pair (an answer of the run before
    # could still be on its way): that run fails, saying why, and the run after it gets a
    # new pair, as after a stalled run (tests/eval/mute_pd.py)
    q, env = scene_sweep("c", 3)
    mute = "python3 %s -q --mute-from 0.5 --prefix {prefix}" % os.path.join(
        SRC, "tests", "eval", "mute_pd.py")
    q[q.index("--controller") + 1] = mute
    q[q.index("--duration") + 1] = "0.5"
    out = os.path.join(d, "mute.csv")
    t0 = time.monotonic()
    p = run([SWEEP] + q + ["-j1", "--csv", out], env=env)
    took = time.monotonic() - t0
    said = p.stderr.count("did not answer the paused state")
    check(said == 1 and "a new lagsimd and controller for the next run" in p.stderr,
          "the controller's silence on the paused state is said once (%d), a new pair next"
          % said)
    r = rows(out) if os.path.exists(out) else []
    check([x["failed"] for x in r] == ["0", "1", "0"] and
          "did not answer the paused state" in r[1]["reason"] and took > 10,
          "run 1 failed with that reason after waiting 10 s for the answer, runs 0 and 2 "
          "(a new pair) did not (%.1f s)" % took)


def case_notes(d):
    manip = os.path.join(SRC, "config", "manipulator.yaml")
    pd = os.path.join(BIN, "manipulator_pd") + " -q --prefix {prefix}"
    env = dict(os.environ, TMPDIR=d)
    p = run([SWEEP, "--config", manip, "--controller", pd, "--duration", "0.5", "--vary",
             "parameters.m2=uniform(0.4,0.6)", "--runs", "2", "-v"], env=env)
    m = re.search(r"^lagsim-sweep: -v: the daemons' logs .* are kept in (\S+)$", p.stderr, re.M)
    logs = glob.glob(os.path.join(m.group(1), "SWEEP*_W0.lcm")) if m else []
    check(p.returncode == 0 and m and m.group(1).startswith(d) and len(logs) == 1,
          "-v: the directory of the kept logs said, the kept pair's log there (%s)" % logs)
    check("no reference" not in p.stdout, "both joints with a reference: no note")
    p = run([SWEEP, "--config", manip, "--controller", pd, "--vary",
             "parameters.m2=uniform(0.4,0.6)", "--runs", "2", "--suite", write_ref_suite(d),
             "--case", "q1_only"])
    check(p.returncode in (0, 1) and re.search(r"^note: q2 has no reference .*r = 0$",
                                               p.stdout, re.M),
          "a reference for q1 alone: the summary's note says q2 is scored against r = 0")


def write_ref_suite(d):
    path = os.path.join(d, "ref.yaml")
    with open(path, "w") as f:
        f.write('cases:\n  - name: q1_only\n    duration: 0.5\n'
                '    set: ["reference={q1: {type: step, amplitude: 0.2}}"]\n')
    return path


def pty_run(argv, cols=100, env=None):
    """argv with stderr on a pseudo-terminal of `cols` columns: (exit status, what it wrote
    there, the time it took)."""
    import fcntl
    import pty
    import select
    import struct
    import termios
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, cols, 0, 0))
    t0 = time.monotonic()
    p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=slave, env=env)
    os.close(slave)
    out = b""
    while True:
        r, _, _ = select.select([master], [], [], 0.1)
        if r:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # EIO: the other end closed
                chunk = b""
            if not chunk:
                break
            out += chunk
        elif p.poll() is not None:
            break
    os.close(master)
    return p.wait(), out.decode(errors="replace"), time.monotonic() - t0


PROGRESS = re.compile(r"lagsim-sweep: (\d+)/(\d+) runs \(\d+ %\), (\d+) failed, (\d+) missed "
                      r"--require, [0-9.e+]+ runs/s, ")


def case_progress(d):
    # 200 manipulator runs of 0.2 s, many more ends than the 4 drawings a second the line
    # may have: the controller (tests/eval/scene_pd.c) sleeps 1 ms before each of a run's
    # 20 answers, so that the sweep lasts 2 s or more however fast the machine, at next to
    # no CPU; m2 drawn from normal(0.5,0.5): the scene refuses the negative ones (failed
    # runs), and about half the others miss --require (q1.iae 0.0002 to 0.03)
    q = ["--config", os.path.join(SRC, "config", "manipulator.yaml"), "--controller",
         os.path.join(BIN, "scene_pd") + " -q --think 0.001 --prefix {prefix}", "--duration",
         "0.2", "--vary", "parameters.m2=normal(0.5,0.5)", "--runs", "200", "--seed", "3",
         "-j2", "--require", "q1.iae<0.0054"]
    out = os.path.join(d, "p.csv")
    rc, text, took = pty_run([SWEEP] + q + ["--csv", out])
    r = rows(out)
    failed = sum(x["failed"] == "1" for x in r)
    missed = sum(x["failed"] == "0" and x["required"] == "0" for x in r)
    draws = text.split("\r\x1b[K")[1:]
    got = [PROGRESS.match(x) for x in draws]
    print("%d drawings in %.1f s; the last: %r" % (len(draws), took, draws[-1] if draws else None))
    check(rc == 1 and len(r) == 200 and failed > 0 and missed > 0 and failed + missed < 200,
          "the sweep ran: 200 rows, %d failed, %d missed --require, the others met it"
          % (failed, missed))
    check(len(draws) >= 2 and all(got), "the progress line drawn %d times, each after \\r and "
          "a clear" % len(draws))
    done = [int(m.group(1)) for m in got if m]
    check(done == sorted(done) and all(int(m.group(2)) == 200 for m in got if m),
          "runs done never go back, of 200: %s" % done[:40])
    check(len(draws) <= 5 * took + 2, "at most 5 drawings a second (%d in %.1f s)"
          % (len(draws), took))
    last = got[-1] if got else None
    check(last and draws[-1].endswith("\n") and int(last.group(1)) == 200 and
          int(last.group(3)) == failed and int(last.group(4)) == missed,
          "the last drawing: 200 runs, %d failed, %d missed, as the CSV counts them, a newline "
          "after it (%r)" % (failed, missed, draws[-1] if draws else None))
    check(all(len(x.rstrip("\r\n")) <= 99 for x in draws), "no drawing wider than the "
          "terminal's 100 columns")
    # stderr a pipe: nothing of it
    p = run([SWEEP] + q + ["--csv", out, "--force"])
    check(p.returncode == 1 and "runs (" not in p.stderr and "\r" not in p.stderr and
          "\x1b" not in p.stderr, "stderr a pipe: no progress, no control byte")
    p = run([SWEEP] + q + ["--csv", out, "--force", "--progress"])
    lines = [x for x in p.stderr.splitlines() if x.startswith("lagsim-sweep: ") and " runs (" in x]
    check(p.returncode == 1 and lines and "\r" not in p.stderr and "\x1b" not in p.stderr and
          PROGRESS.match(lines[-1]) and lines[-1].startswith("lagsim-sweep: 200/200 runs"),
          "a pipe with --progress: whole lines, the last one of all 200 runs (%s)" % lines[-1:])


def rows_now(path):
    """The rows a CSV holds now (a sweep may be writing it)."""
    try:
        return sum(1 for x in open(path) if x[:1].isdigit())
    except FileNotFoundError:
        return 0


def stopped(argv, csv_path, sig, group=False, at_rows=4):
    """argv started (a session of its own), sig sent once csv_path holds at_rows rows:
    (exit status, stdout, stderr)."""
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         universal_newlines=True, start_new_session=True)
    end = time.monotonic() + 120
    while rows_now(csv_path) < at_rows and p.poll() is None and time.monotonic() < end:
        time.sleep(0.05)
    if p.poll() is None:
        (os.killpg if group else os.kill)(p.pid, sig)
    o, e = p.communicate(timeout=120)
    print("$ sweep, %s after %d rows -> %d\n%s%s" % (signal.Signals(sig).name, at_rows,
                                                    p.returncode, o[-800:], e[-3000:]))
    return p.returncode, o, e


def finish(e):
    """The two commands the stopped sweep gave (the runs it lacks, then the merge), run as
    written where it ran: their exit statuses."""
    cmds = [x.strip() for x in e.splitlines() if x.startswith("  ") and "lagsim-sweep" in x]
    out = []
    for c in cmds:
        p = subprocess.run(["sh", "-c", c], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True, timeout=600)
        print("$", c, "->", p.returncode, p.stderr[-500:])
        out.append(p.returncode)
    return cmds, out


def held_is(path, want_runs):
    """The CSV's rows are in run order and its held line names exactly them."""
    runs = [int(x["run"]) for x in rows(path)]
    held = dict(identity(path)).get("held", "")
    if not re.match(r"^\d+(-\d+)?(,\d+(-\d+)?)*$", held):
        return False, runs, held
    named = set()
    for part in held.split(","):
        a, _, b = part.partition("-")
        named |= set(r for r in range(int(a), int(b or a) + 1) if r in want_runs)
    return runs == sorted(runs) and named == set(runs), runs, held


def case_interrupt(d):
    # n runs: a signal comes after 4 rows, while most runs are still to come: the controller
    # (tests/eval/scene_pd.c) sleeps 2 ms before each of a run's 50 answers, so each run
    # lasts 0.1 s or more of wall time at next to no CPU, and the 36 runs after the 4th row
    # take 1.8 s or more however fast the machine (a quiet one ran all 40 runs of 8 s of
    # lqr_balance in the 50 ms between two looks at the CSV)
    n = 40
    q = ["--config", os.path.join(SRC, "config", "manipulator.yaml"), "--controller",
         os.path.join(BIN, "scene_pd") + " -q --think 0.002 --prefix {prefix}", "--duration",
         "0.5", "--vary", "parameters.m2=uniform(0.3,1.2)", "--runs", str(n), "--seed", "5",
         "-j2"]
    whole = os.path.join(d, "whole.csv")
    run([SWEEP] + q + ["--csv", whole])
    # SIGINT to the process group, as a terminal's Ctrl-C sends it
    out = os.path.join(d, "int.csv")
    rc, o, e = stopped([SWEEP] + q + ["--csv", out], out, signal.SIGINT, group=True)
    ok, runs, held = held_is(out, set(range(n)))
    check(rc == -signal.SIGINT and 0 < len(runs) < n and ok,
          "SIGINT: ended by it, the CSV holds %d runs in run order, its held line (%s) names "
          "them" % (len(runs), held))
    check([k for k, _ in identity(out)] == [k for k, _ in identity(whole)] + ["held"],
          "its identity: the whole sweep's and the held line")
    check("stopped by SIGINT: %s holds %d of the %d runs" % (out, len(runs), n) in e and
          "%d runs:" % len(runs) in o, "stderr says what it holds, stdout sums it up")
    cmds, codes = finish(e)
    merged = os.path.join(d, "int-whole.csv")
    check(len(cmds) == 2 and "--only" in cmds[0] and codes == [0, 0] and
          filecmp.cmp(merged, whole, shallow=False),
          "the commands it gives, run as written: the whole sweep's CSV, byte for byte (%s)"
          % codes)
    # SIGTERM to shard 2/2's sweep: the rest is of shard 2/2, merged with shard 1/2
    s1, s2 = os.path.join(d, "s1.csv"), os.path.join(d, "s2.csv")
    run([SWEEP] + q + ["--shard", "1/2", "--csv", s1])
    rc, o, e = stopped([SWEEP] + q + ["--shard", "2/2", "--csv", s2], s2, signal.SIGTERM)
    ok, runs, held = held_is(s2, set(range(1, n, 2)))
    check(rc == -signal.SIGTERM and ok and dict(identity(s2)).get("shard") == "2/2",
          "SIGTERM to shard 2/2: its %d runs, held %s (counted in the shard's runs)"
          % (len(runs), held))
    cmds, codes = finish(e)
    check(len(cmds) == 2 and "--shard 2/2 --only" in cmds[0] and codes == [0, 0],
          "its commands: the shard's missing runs (--shard 2/2 --only), then merge")
    p, m = merge(d, s1, os.path.join(d, "s2-whole.csv"), out="shards.csv")
    check(p.returncode == 0 and filecmp.cmp(m, whole, shallow=False),
          "shard 1/2 and the finished shard 2/2 merged: the whole sweep, byte for byte")
    # SIGHUP: the same partial CSV
    out = os.path.join(d, "hup.csv")
    rc, o, e = stopped([SWEEP] + q + ["--csv", out], out, signal.SIGHUP)
    ok, runs, held = held_is(out, set(range(n)))
    check(rc == -signal.SIGHUP and ok and "stopped by SIGHUP" in e,
          "SIGHUP: ended by it, %d runs held (%s)" % (len(runs), held))
    # SIGKILL: nothing of the sweep runs; the CSV holds what was written as runs ended
    out = os.path.join(d, "kill.csv")
    rc, o, e = stopped([SWEEP] + q + ["--csv", out], out, signal.SIGKILL, at_rows=6)
    ident = dict(identity(out))
    lines = open(out).read().split("\n")
    killed = [int(x["run"]) for x in rows(out)]
    check(rc == -signal.SIGKILL and ident.get("held", "").startswith("unknown") and
          len(killed) >= 6 and lines[-1] == "", "SIGKILL: the CSV holds the %d rows written as "
          "their runs ended, whole lines, held: unknown" % len(killed))
    p, part = merge(d, out, out="kill-part.csv", extra=["--partial"])
    ok, runs, held = held_is(part, set(range(n)))
    check(p.returncode == 0 and ok and sorted(killed) == runs and "--only" in p.stderr,
          "merge --partial takes it: its runs in order, the held line (%s), the runs to give "
          "--only said" % held)
    miss = [x.strip() for x in p.stderr.splitlines() if x.strip().startswith("--only")]
    rest = os.path.join(d, "kill-rest.csv")
    run([SWEEP] + q + (miss[0].split() if miss else ["--only", "0"]) + ["--csv", rest])
    p, m = merge(d, out, rest, out="kill-whole.csv")
    check(p.returncode == 0 and filecmp.cmp(m, whole, shallow=False),
          "the killed sweep's CSV and its missing runs (%s) merged: the whole sweep, byte "
          "for byte" % (miss[0] if miss else None))
    # --only mistakes: before any run
    for bad, why in (("5-3", "expected runs"), ("a", "expected runs"), ("0-%d" % n, "expected runs"),
                     ("3,2", "expected runs"), ("1", "no run of this sweep")):
        p = run([SWEEP] + q + ["--shard", "1/2", "--only", bad])
        check(p.returncode == 2 and why in p.stderr and "runs:" not in p.stdout,
              "--only %s (shard 1/2): exit 2 before any run, said why" % bad)


def case_controller_exit(d):
    base = ["--config", SCENE, "--duration", "1", "--vary", "parameters.m1=uniform(0.1,0.2)",
            "--runs", "4", "-j2"]
    # a controller that cannot start: the sweep stops at once, exit 2, the exit status said
    out = os.path.join(d, "exit3.csv")
    t0 = time.monotonic()
    p = run([SWEEP] + base + ["--controller", "exit 3", "--csv", out])
    took = time.monotonic() - t0
    check(p.returncode == 2 and p.stderr.count("the controller ended (exit status 3) before "
                                               "it answered") == 1 and
          "the sweep stops" in p.stderr and took < 20,
          "'exit 3': exit 2, the controller's exit status said once, in %.1f s" % took)
    # without --csv: no run ended, so no summary is pointed at
    p = run([SWEEP] + base + ["--controller", "exit 3"])
    check(p.returncode == 2 and "0 of the 4 runs had ended; without --csv they are kept "
          "nowhere\n" in p.stderr and "summary" not in p.stderr + p.stdout,
          "'exit 3' without --csv: 0 runs ended, no summary named (%s)" % p.stderr[-300:])
    # a controller on another prefix (alive: it waits 100 s for its scene): the daemon says
    # what it waits for, after the worker's first wait: 30 s, or a run's --timeout (8 s)
    t0 = time.monotonic()
    p = run([SWEEP] + base + ["-j1", "--timeout", "8", "--controller",
                              os.path.join(BIN, "lqr_balance") +
                              " -q --prefix NOT_THE_RUNS --timeout 100"])
    took = time.monotonic() - t0
    check(p.returncode == 2 and "did not answer the kept lagsimd's first state within 8 s" in
          p.stderr and
          re.search(r"lagsimd waits \d+ s for a command answering sim_time 0 on "
                    r"SWEEP\d+_W0_COMMAND at udpm://", p.stderr) and "{prefix}" in p.stderr and
          "does it start within 8 s? --restart" in p.stderr and
          8 <= took < 30,
          "a controller on another prefix, --timeout 8: exit 2 after 8 s (%.1f s), the "
          "daemon's wait said" % took)
    # a controller that dies in some runs (m2 above 0.6): those fail, a row each, and the
    # next run gets a new pair
    q, env = scene_sweep("c", 8)
    q[q.index("--controller") + 1] = "python3 %s -q --exit-above 0.6 --prefix {prefix}" % (
        os.path.join(SRC, "tests", "eval", "mute_pd.py"))
    out = os.path.join(d, "dies.csv")
    t0 = time.monotonic()
    p = run([SWEEP] + q + ["-j1", "--csv", out], env=env)
    took = time.monotonic() - t0
    r = rows(out) if os.path.exists(out) else []
    big = [x for x in r if float(x["parameters.m2"]) > 0.6]
    small = [x for x in r if float(x["parameters.m2"]) <= 0.6]
    check(len(r) == 8 and big and small and
          all(x["failed"] == "1" and re.match(r"the controller ended \(exit status 7\) at "
                                              r"t = 0\.2 s, before the run did$", x["reason"])
              for x in big) and all(x["failed"] == "0" for x in small),
          "a controller that dies at t = 0.2 in the %d runs of m2 > 0.6: those fail with its "
          "exit status, the %d others pass (%s)" % (len(big), len(small),
                                                   [(x["run"], x["reason"]) for x in r]))
    check(p.stderr.count("a new lagsimd and controller for the next run") == len(big) and
          took < 120, "each death said, a new pair for the next run (%.1f s)" % took)
    # --restart: each run's controller exits at once: a failed row each, without the 5 s a
    # daemon gets to end after its controller (it says it waits: stopped at once)
    out = os.path.join(d, "restart.csv")
    t0 = time.monotonic()
    p = run([SWEEP] + base + ["--restart", "--controller", "exit 3", "--csv", out])
    took = time.monotonic() - t0
    r = rows(out) if os.path.exists(out) else []
    check(p.returncode == 1 and len(r) == 4 and
          all(x["reason"] == "the controller ended (exit status 3) before the run did"
              for x in r) and took < 10,
          "--restart, 'exit 3': 4 failed rows naming exit status 3, in %.1f s" % took)


def case_slow_start(d):
    out = os.path.join(d, "slow.csv")
    lqr = os.path.join(BIN, "lqr_balance") + " -q --prefix {prefix}"
    t0 = time.monotonic()
    p = run([SWEEP, "--config", SCENE, "--duration", "0.5", "--runs", "2", "--seed", "1",
             "--vary", "parameters.m0=uniform(1,1.5)", "-j1", "--timeout", "19",
             "--controller", "sleep 12; exec " + lqr, "--csv", out])
    took = time.monotonic() - t0
    r = rows(out) if os.path.exists(out) else []
    check(p.returncode == 0 and len(r) == 2 and all(x["failed"] == "0" for x in r) and
          took >= 12,
          "a controller 12 s slow to start, --timeout 19: exit %d, %d rows passed, in %.1f s"
          "%s" % (p.returncode, len([x for x in r if x["failed"] == "0"]), took,
                            "" if p.returncode == 0 else ": " + p.stderr[-600:]))


def case_tmpdir(d):
    """Nothing of a sweep is left in TMPDIR when it ends without -v: a sweep that passes,
    one whose runs fail (--restart) and one whose controller cannot run (exit 2)."""
    lqr = os.path.join(BIN, "lqr_balance") + " -q --prefix {prefix}"
    base = [SWEEP, "--config", SCENE, "--duration", "0.5", "--runs", "2", "--seed", "1",
            "--vary", "parameters.m0=uniform(1,1.5)"]
    for name, extra, codes in [
            ("passes", ["--controller", lqr, "-j", "2"], (0,)),
            ("fails", ["--controller", "exit 3", "--restart"], (1, 2)),
            ("cannot run", ["--controller", "exit 3"], (2,))]:
        t = os.path.join(d, "t-" + name.replace(" ", "_"))
        os.mkdir(t)
        p = run(base + extra + ["--csv", os.path.join(d, name.replace(" ", "_") + ".csv")],
                env=dict(os.environ, TMPDIR=t))
        left = [os.path.join(r, f) for r, ds, fs in os.walk(t) for f in ds + fs]
        check(p.returncode in codes and not left,
              "a sweep that %s (exit %d): TMPDIR empty after it (%s)" % (name, p.returncode,
                                                                        left[:5]))


with tempfile.TemporaryDirectory() as tmp:
    {"same": case_same, "vary": case_vary, "slurm": case_slurm, "merge": case_merge,
     "kept": case_kept, "merge_rows": case_merge_rows, "merge_foreign": case_merge_foreign,
     "shard": case_shard,
     "loss": case_loss, "stalled": case_stalled, "ssh": case_ssh,
     "kept_python": case_kept_python, "scene_c": case_scene_c,
     "scene_python": case_scene_python, "scene_loss": case_scene_loss,
     "unanswered": case_unanswered, "notes": case_notes,
     "controller_exit": case_controller_exit, "slow_start": case_slow_start, "progress": case_progress,
     "interrupt": case_interrupt, "tmpdir": case_tmpdir}[CASE](tmp)
sys.exit(verdict(CASE))
