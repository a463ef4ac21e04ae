"""Waits on events, for the Python tests: a daemon that answers, a controller that is
subscribed, a logger that has written what came before. Each is bounded by a deadline
(30 s: what a loaded 2-core machine or the sanitizer build may take to start a process) and
returns whether the event came, so that the test says what it waited for; none sleeps a
fixed time in the hope that the event came meanwhile (docs/testing.md, "The suite under
load"). Reader keeps reading a controller's output in a thread, its readiness an event.
"""
import os
import subprocess
import threading
import time

WITHIN = 30.0


def daemon_answers(lagsimctl, prefix, within=WITHIN, url=None):
    """Whether the lagsimd of prefix answers `lagsimctl status` within `within` s (each try
    waits up to lagsimctl's own 2 s for the answer)."""
    cmd = [lagsimctl, "--prefix", prefix] + (["--url", url] if url else []) + ["status"]
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        if subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0:
            return True
    return False


def subscribed(proc, within=WITHIN, line="waiting for the scene"):
    """Reads a controller's merged output until it says it is subscribed (the controllers of
    the client libraries print "NAME: waiting for the scene description on ...": from there
    on they miss no state). Returns the lines read, or None when it ended first or the
    deadline passed."""
    deadline, seen = time.monotonic() + within, []
    for got in proc.stdout:
        seen.append(got)
        if line in got:
            return seen
        if time.monotonic() > deadline:
            break
    return None


def logger_wrote(path, channel, probe, url=None, within=WITHIN):
    """Publishes probe (bytes) on channel until lcm-logger has written it to path: the logger
    records, and, reading one socket in order, has written what came before the probe.
    url: the bus (default LCM_DEFAULT_URL). Needs lagsim_lcm on sys.path (BUILD/python)."""
    from lagsim_lcm import LCM
    lc = LCM(url or os.environ["LCM_DEFAULT_URL"])
    deadline = time.monotonic() + within
    try:
        while time.monotonic() < deadline:
            if os.path.exists(path):
                with open(path, "rb") as f:
                    if probe in f.read():
                        return True
            lc.publish(channel, probe)
            time.sleep(0.05)
        return False
    finally:
        lc.close()


class Reader:
    """A process's standard output read in a thread of its own, so that it never blocks on
    a full pipe: every line appended to `lines` (a list of the caller's, or a new one);
    `ready` set once a line holds `line` (a controller's "waiting for the scene": from there
    on it misses no state) or the output ended; `marked`, the time.monotonic() at which a
    line first held `mark` (when given), else None; `thread`, to join."""

    def __init__(self, proc, lines=None, line="waiting for the scene", mark=None):
        self.lines = [] if lines is None else lines
        self.ready = threading.Event()
        self.marked = None

        def read():
            for got in proc.stdout:
                self.lines.append(got)
                if line in got:
                    self.ready.set()
                if mark is not None and self.marked is None and mark in got:
                    self.marked = time.monotonic()
            self.ready.set()

        self.thread = threading.Thread(target=read, daemon=True)
        self.thread.start()
