#!/usr/bin/env python3
"""Nothing lagsim-eval or lagsim-sweep starts outlives it, however it ends.

usage: test_procs.py BIN_DIR SOURCE_DIR TOOL HOW
  TOOL  eval    lagsim-eval, one case (a daemon and a controller)
        sweep   lagsim-sweep -j 2 with kept workers (per worker a daemon and a controller)
  HOW   sigint     Ctrl-C: SIGINT to the tool's process group, as a terminal sends it
        sigterm    SIGTERM to the tool alone (kill, timeout, systemd)
        sigkill    SIGKILL to the tool alone: no code of the tool runs
        groupkill  SIGKILL to the tool's process group (timeout -s KILL): the tool and its
                   workers at once
        stalled    eval: the controller stops answering and ignores SIGTERM (its lockstep
                   daemon waits for it); sweep: the workers stopped (SIGSTOP) and, once
                   their kept daemons wait for the next STEP (the controllers, which ignore
                   SIGTERM, have had no state for 0.5 s), SIGKILL to the tool
        gnuplot    SIGTERM while the tool waits for gnuplot (--report, --plot; a gnuplot
                   first on PATH that starts a grandchild and waits)

The controller (tests/eval/procs_controller.py, under `sh -c`) starts a grandchild in its
process group and one in a session of its own, and writes a ready file once its daemon's
states are answered: the signal is sent on that event. The run's processes are found by a
marker in their environment (LAGSIM_PROCS_TEST, this test's own value: every process the
tool starts inherits it), never by name. After SIGINT or SIGTERM the tool must end by that
signal (the shell's 128 + N) with no process of the run left at that moment and its
temporary directory (under TMPDIR) removed; after a kill no process may be left within
PROCS_WAIT_S. A process the test started beside the tool must be alive at the end.
"""
import ctypes
import glob
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

BIN, SRC, TOOL, HOW = sys.argv[1:5]
SCENE = os.path.join(SRC, "config", "cartpole.yaml")
CTRL = os.path.join(SRC, "tests", "eval", "procs_controller.py")
PROCS_WAIT_S = 20.0   # after a kill: the keepers stop what is left (2 s grace, then SIGKILL)
# a sweep's runs: more than one per worker (-j 2), so that a worker's kept pair runs again;
# signalled mid-sweep they are never all run; gnuplot, signalled once every run ended,
# draws them all (1000 runs made it 100000 lockstep periods of a Python controller)
SWEEP_RUNS = 4 if HOW == "gnuplot" else 1000
READY_WAIT_S = 120.0  # python controllers start slowly on a loaded machine


def marked(marker):
    """(pid, command line) of every live process whose environment holds the marker."""
    out = []
    needle = ("LAGSIM_PROCS_TEST=%s" % marker).encode() + b"\0"
    for d in glob.glob("/proc/[0-9]*"):
        try:
            with open(d + "/environ", "rb") as f:
                env = f.read() + b"\0"
            if needle not in env:
                continue
            with open(d + "/stat") as f:
                if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                    continue  # a zombie has ended
            with open(d + "/cmdline", "rb") as f:
                out.append((int(d[6:]), f.read().replace(b"\0", b" ").decode(errors="replace")))
        except (OSError, IndexError):
            pass  # ended meanwhile, or not ours to read
    return out


def children(pid):
    try:
        with open("/proc/%d/task/%d/children" % (pid, pid)) as f:
            return [int(x) for x in f.read().split()]
    except OSError:
        return []


def die_with_test():
    """In the tool before it runs: SIGKILL when this test dies (a ctest timeout), so that
    what a failed run leaves does not run on."""
    ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def command(tmp, ready):
    ctrl = "python3 %s -q --prefix {prefix} --ready %s" % (CTRL, ready)
    if HOW == "stalled":
        ctrl += " --hang" if TOOL == "eval" else " --deaf --idle --pace 0"
    if HOW == "gnuplot":
        ctrl += " --pace 0"
    duration = "1" if HOW == "gnuplot" else "0.5" if HOW == "stalled" else "600"
    if TOOL == "eval":
        suite = os.path.join(tmp, "suite.yaml")
        with open(suite, "w") as f:
            f.write("cases:\n  - name: long\n    duration: %s\n" % duration)
            if HOW in ("sigint", "sigterm"):  # a case not run yet: its report made, unwritten
                f.write("  - name: long2\n    duration: %s\n" % duration)
        cmd = [os.path.join(BIN, "lagsim-eval"), "--config", SCENE, "--suite", suite,
               "--controller", ctrl]
        if HOW in ("gnuplot", "sigint", "sigterm"):
            cmd += ["--report", os.path.join(tmp, "report")]
        return cmd
    cmd = [os.path.join(BIN, "lagsim-sweep"), "--config", SCENE, "--controller", ctrl,
           "--duration", duration, "--vary", "parameters.m0=uniform(0.9,1.1)", "--runs",
           str(SWEEP_RUNS), "-j", "2"]
    if HOW == "gnuplot":  # the signal comes once every run ended, as gnuplot draws
        cmd += ["--plot", os.path.join(tmp, "sweep.png"), "--csv", os.path.join(tmp, "sweep.csv")]
    return cmd


def fake_gnuplot(tmp, ready):
    """A gnuplot first on PATH: a grandchild, the ready file, then it waits."""
    d = os.path.join(tmp, "path")
    os.makedirs(d)
    with open(os.path.join(d, "gnuplot"), "w") as f:
        f.write("#!/bin/sh\nsleep 600 &\ntouch %s/ready.gnuplot\nwait\n" % ready)
    os.chmod(os.path.join(d, "gnuplot"), 0o755)
    return d


def wait_ready(p, ready, n):
    """n ready files of the controllers, or gnuplot's."""
    which = "ready.gnuplot" if HOW == "gnuplot" else "ready.*"
    return wait_files(p, os.path.join(ready, which), n)


def wait_files(p, pattern, n):
    deadline = time.monotonic() + READY_WAIT_S
    while time.monotonic() < deadline and p.poll() is None:
        if len(glob.glob(pattern)) >= n:
            return True
        time.sleep(0.05)
    return False


def deliver(p, ready):
    if HOW == "sigint":
        os.killpg(p.pid, signal.SIGINT)
        return -signal.SIGINT
    if HOW in ("sigterm", "gnuplot"):
        p.send_signal(signal.SIGTERM)
        return -signal.SIGTERM
    if HOW == "groupkill":
        os.killpg(p.pid, signal.SIGKILL)
        return -signal.SIGKILL
    if HOW == "stalled" and TOOL == "sweep":
        workers = children(p.pid)
        for w in workers:
            os.kill(w, signal.SIGSTOP)
        for f in glob.glob(os.path.join(ready, "idle.*")):
            os.unlink(f)
        check(wait_files(p, os.path.join(ready, "idle.*"), 2),
              "workers %s stopped: both kept daemons wait for their next STEP" % workers)
    p.kill()
    return -signal.SIGKILL


def drawn_whole(tmp, err):
    """A sweep stopped while gnuplot draws: every run ended and its CSV was written whole
    before (SWEEP_RUNS rows, no held line), and it names no command to finish it."""
    err.flush()
    err.seek(0)
    text = err.read()
    path = os.path.join(tmp, "sweep.csv")
    lines = open(path).read().splitlines() if os.path.exists(path) else []
    rows = [x for x in lines if x and not x.startswith("#")][1:]
    check(len(rows) == SWEEP_RUNS and not any(x.startswith("# held") for x in lines) and
          "--only" not in text, "the CSV whole (%d rows, no held line), no command said to "
          "finish it" % len(rows))


def main():
    marker = "%d.%d" % (os.getpid(), time.monotonic_ns())
    tmp = tempfile.mkdtemp(prefix="lagsim-procs.")
    ready, tooltmp = os.path.join(tmp, "ready"), os.path.join(tmp, "tmp")
    os.makedirs(ready)
    os.makedirs(tooltmp)
    env = dict(os.environ, LAGSIM_PROCS_TEST=marker, TMPDIR=tooltmp,
               PYTHONPATH=os.path.join(os.path.dirname(BIN), "python"))
    want = 2 if TOOL == "sweep" else 1
    if HOW == "gnuplot":
        env["PATH"] = fake_gnuplot(tmp, ready) + ":" + env["PATH"]
        want = 1
    bystander = subprocess.Popen(["sleep", "600"])
    cmd = command(tmp, ready)
    print("$", " ".join(cmd), flush=True)
    out, err = open(os.path.join(tmp, "out"), "w+"), open(os.path.join(tmp, "err"), "w+")
    p = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                         start_new_session=True, preexec_fn=die_with_test)
    try:
        ok = wait_ready(p, ready, want)
        check(ok, "gnuplot runs" if HOW == "gnuplot" else
              "%d ready file(s): the run's daemon publishes and its controller answers" % want)
        if not ok:
            return
        print("marked processes before:", *marked(marker), sep="\n  ")
        made = os.listdir(tooltmp)
        check(len(made) == 1 and made[0].startswith("lagsim-%s." % TOOL),
              "the tool's temporary directory is under TMPDIR: %s" % made)
        expect = deliver(p, ready)
        t0 = time.monotonic()
        try:
            rc = p.wait(30)
        except subprocess.TimeoutExpired:
            rc = None
        left = marked(marker)
        check(rc == expect, "%s ended by %s: status %s (%s expected)"
              % (TOOL, HOW, rc, expect))
        if expect in (-signal.SIGINT, -signal.SIGTERM):
            check(not left, "no process of the run left when the tool ended: %s" % left)
            check(os.listdir(tooltmp) == [], "its temporary directory removed: %s"
                  % os.listdir(tooltmp))
            if TOOL == "eval":  # the report files of the case in progress and of the next
                rep = os.listdir(os.path.join(tmp, "report"))
                check(rep == [], "the report's files it made and did not finish removed: %s"
                      % sorted(rep))
        if TOOL == "sweep" and HOW == "gnuplot":
            drawn_whole(tmp, err)
        while left and time.monotonic() < t0 + PROCS_WAIT_S:
            time.sleep(0.1)
            left = marked(marker)
        check(not left, "no process of the run left %.1f s after the %s: %s"
              % (time.monotonic() - t0, HOW, left))
        check(bystander.poll() is None, "a process started beside the tool is still alive")
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
        for pid, _ in marked(marker):  # what a failed run left: not left for the next test
            try:
                os.kill(pid, signal.SIGCONT)
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        bystander.kill()
        bystander.wait()
        for f in (out, err):
            f.seek(0)
            print(f.read()[-2000:])
        subprocess.run(["rm", "-rf", tmp])


main()
sys.exit(verdict(TOOL + " " + HOW))
