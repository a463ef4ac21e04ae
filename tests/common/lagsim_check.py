"""The Python tests' harness, written once (the C tests' is lagsim_test.h): a check, the
count of failed ones, the closing line and the exit status ctest reads.

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
    from lagsim_check import check, verdict  # noqa: E402

    check(x == 1, "x is 1 (%r)" % x)      # prints "ok:   x is 1 (1)" or "FAIL: x is 1 (2)"
    ...
    sys.exit(verdict())                    # the closing line; 0, or 1 when a check failed

Exit statuses: 0 every check held; 1 a check failed, or the run made no check (a test that
checked nothing proves nothing, as lt_main says in C); SKIP (77, the SKIP_RETURN_CODE of
tests/*.cmake) when the test cannot run here, which the test says and exits with itself.
An error of the test itself (an exception) exits as Python does, with 1 and its traceback.

Also here: stop(), the one way a test ends a process it started (SIGTERM, then SIGKILL
after a grace), and daemon(), a lagsimd for the length of a with-block. LCM logs are read
by lcm_log.py, the bus's ports taken by lcm_port.py, events
waited on by waits.py, beside this file.
"""
import contextlib
import os
import signal
import subprocess
import sys

import waits

SKIP = 77   # ctest's SKIP_RETURN_CODE (tests/*.cmake, tests/common/cases.cmake)

_made = 0        # checks made
_failed = []     # what each failed check said


def check(cond, what, detail=""):
    """Prints "ok:   WHAT" or "FAIL: WHAT" (and `detail` under a failure); counts a failure.
    Returns cond, so that a test can go on only where what follows needs it."""
    global _made
    _made += 1
    print(("ok:   " if cond else "FAIL: ") + what, flush=True)
    if not cond:
        _failed.append(what)
        if detail:
            print(detail.rstrip(), flush=True)
    return cond


def failures():
    """How many checks failed so far."""
    return len(_failed)


def verdict(case=None):
    """The closing line, "NAME: passed (N checks)" or "NAME: FAILED (K of N checks)" with
    the failed checks listed again (NAME: the script's, and the case run where one is
    given); returns the exit status: 1 when a check failed or none was made, else 0."""
    name = os.path.splitext(os.path.basename(sys.argv[0]))[0] + (" " + case if case else "")
    if not _made:
        print("%s: FAILED: no check was made" % name, flush=True)
        return 1
    checks = "%d check%s" % (_made, "" if _made == 1 else "s")
    if _failed:
        print("%s: FAILED (%d of %s):" % (name, len(_failed), checks), flush=True)
        for what in _failed:
            print("  " + what.splitlines()[0][:200], flush=True)
        return 1
    print("%s: passed (%s)" % (name, checks), flush=True)
    return 0


def stop(proc, grace=5.0):
    """Ends a process the test started: SIGTERM, then SIGKILL when it has not ended `grace`
    s later; reaped either way. None or an ended process: nothing to do."""
    if proc is None or proc.poll() is not None:
        return
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()



def replay(lagsimd, config, prefix, log, timeout=60):
    """`lagsimd --config CONFIG --set lcm.prefix=PREFIX --replay LOG`, its output printed:
    (the completed process, its "max difference = D" as a float, or None when it said
    none)."""
    r = subprocess.run([lagsimd, "--config", config, "--set", "lcm.prefix=" + prefix,
                        "--replay", log], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True, timeout=timeout)
    print("$ lagsimd --replay %s   -> exit %d" % (os.path.basename(log), r.returncode))
    print("  " + r.stdout.strip().replace("\n", "\n  "), flush=True)
    diff = None
    for line in r.stdout.splitlines():
        if line.startswith("max difference = "):
            diff = float(line.split("=", 1)[1])
    return r, diff


def check_expressions(exprs, names):
    """check() of each expression of exprs (a tool's --check "states == 2001"), evaluated
    over the dictionary names (a run's summary values) with abs, min and max; an
    expression that does not evaluate (a value the run did not report) fails, saying why.
    Returns whether every one held."""
    ok = True
    for expr in exprs:
        try:
            res = bool(eval(expr, {"__builtins__": {"abs": abs, "min": min, "max": max}}, names))
        except Exception as e:  # a missing key is a failure, not a crash
            res = False
            print("check %s: %s" % (expr, e))
        ok = check(res, expr) and ok
    return ok


@contextlib.contextmanager
def daemon(lagsimd, lagsimctl, config, prefix, *args, grace=10.0):
    """`lagsimd --config CONFIG --set lcm.prefix=PREFIX -q ARGS...` (on LCM_DEFAULT_URL) for
    the with-block, which gets the process: checked first to answer `lagsimctl status`
    (waits.daemon_answers; the block runs either way), ended by SIGTERM after it and
    waited for `grace` s (a daemon that outlives that raises TimeoutExpired: an error of
    the test, as it should be)."""
    proc = subprocess.Popen([lagsimd, "--config", config, "--set", "lcm.prefix=" + prefix, "-q",
                             *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        check(waits.daemon_answers(lagsimctl, prefix), "lagsimd answers (waited on)")
        yield proc
    finally:
        proc.terminate()
        proc.wait(grace)
