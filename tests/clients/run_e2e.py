#!/usr/bin/env python3
"""End-to-end harness: one lagsimd plus one controller on real LCM (loopback).

    run_e2e.py --lagsimd BIN --config YAML --mode lockstep [--name NAME] [--set k=v ...]
               [--daemon-arg ARG ...] [--kill-daemon-after S] [--daemon-first S]
               [--daemon-start-delay S] [--stall-daemon S] [--check EXPR ...]
               [--hostile DIR ...] [--timeout S] -- CLIENT ARGS...

The controller is started first, then (once it prints that it is waiting for the scene
description, i.e. it is subscribed and will see the very first state) the daemon, with a
channel prefix unique to this run (--set lcm.prefix=<prefix>; "{prefix}" in the client's
arguments is replaced by it) so that tests running in parallel never cross-talk; with
--daemon-first or --kill-daemon-after the daemon is started first instead (below). The
controller must exit by itself within --timeout wall seconds; the daemon is always
stopped (SIGTERM, then SIGKILL).
--daemon-first S starts the daemon first and the controller S wall seconds after the
daemon was heard on the bus (its scene, first state, status or start event: a late
controller, which the scene's realtime.start decides what it meets; counted from a
fixed start instead, a loaded machine's daemon was not up yet). --daemon-arg adds an
argument to the daemon's command line (e.g. --duration 2: the daemon
stops by itself and announces it); --kill-daemon-after S kills it with SIGKILL S wall
seconds after the controller's first command was heard (it goes silent without a word),
and starts the daemon first, the controller once the daemon was heard: such a controller
runs with a short --timeout (2 s), which bounds its wait for the scene too, and a daemon
started after it may take longer than that to publish its scene on a loaded machine
(seen: "no scene within 2 s" beside a load of 20). --daemon-start-delay S starts the
daemon's command S s late, as a loaded machine may (the order above is tested by it);
--stall-daemon S stops the daemon (SIGSTOP) for S s once the controller's first command was
heard, before the kill: with S over the controller's --timeout it ends on that silence,
and `silent` counts from its last state (its t_last), not the states heard after it.
The controller's last line
"... summary key=value ..." is parsed and every --check expression (Python, over those
keys; `wall` is the time from the daemon's end to the controller's summary line, s; with
--kill-daemon-after, `silent` is the time from the daemon's publication of the
controller's last state (its t_last; the state's utime, the daemon's wall clock) to the
controller's summary line as this harness read it, s: at least the silence the controller
counted, which starts when that state reached it) must hold.
--hostile DIR (repeatable) publishes every file of DIR (the fuzz_client corpus layout: the
first byte chooses the channel, _STATE, _STATUS, _EVENT or _SCENE, the rest is the payload)
on the run's channels: three times once the controller is subscribed, before the daemon
starts (a controller whose receive path dies on one never gets its scene), then once every
20 ms for as long as the controller runs. The controller must drop them and run as if
they had never come; `hostile` (messages published) joins the summary's keys.
"""
import argparse
import math
import os
import re
import signal
import struct
import subprocess
import sys
import threading
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check_expressions, stop  # noqa: E402  (tests/common: the one harness)
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_urls  # noqa: E402  (a port pair of this process's own)


def parse_summary(text):
    for line in reversed(text.splitlines()):
        if " summary " in line:
            vals = {}
            for tok in line.split(" summary ", 1)[1].split():
                if "=" in tok:
                    k, v = tok.split("=", 1)
                    try:
                        vals[k] = float(v)
                    except ValueError:
                        vals[k] = v
            return vals
    return None


def hostile_payloads(folders, prefix):
    """(channel, payload) of every file of `folders`, in name order."""
    out = []
    for folder in folders:
        for name in sorted(os.listdir(folder)):
            with open(os.path.join(folder, name), "rb") as f:
                data = f.read()
            if data:
                out.append((prefix + ("_STATE", "_STATUS", "_EVENT", "_SCENE")[data[0] % 4],
                            data[1:]))
    return out


def hostile_lcm(url):
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                    "clients", "python"))
    from lagsim_lcm import LCM
    return LCM(url)


class BusWatch:
    """The run's bus as the harness hears it, each URL read in a thread of its own: `up` is
    set once anything of the daemon came on the state URL (its scene, a state, its status
    or an event: it runs and answers), `answered` once a command came on the command URL
    (the controller runs its law); `published`, when the daemon published each state, by
    its sim time (to 1e-6 s), and `last_published`, the last: the state's own utime, the
    daemon's wall clock (time.time()) as it published it, s. (Not when this harness heard
    it: its reader is a Python thread, which a loaded machine runs seconds late: a state
    heard 1.4 s after the daemon's SIGKILL was seen.)"""

    def __init__(self, state_url, command_url, prefix):
        self.up, self.answered, self.done = threading.Event(), threading.Event(), threading.Event()
        self.last_published = None
        self.published = {}
        self.lcms = [hostile_lcm(state_url), hostile_lcm(command_url)]
        self.lcms[0].subscribe(re.escape(prefix) + "_(STATE|SCENE|STATUS|EVENT)", self._daemon)
        self.lcms[1].subscribe(re.escape(prefix) + "_COMMAND", lambda ch, data: self.answered.set())
        self.threads = [threading.Thread(target=self._pump, args=(lc,), daemon=True)
                        for lc in self.lcms]
        for th in self.threads:
            th.start()

    def _daemon(self, channel, data):
        if channel.endswith("_STATE") and len(data) >= 24:
            # joint_state_t: its fingerprint, utime (us since the epoch), sim_time
            utime, sim_time = struct.unpack(">qd", data[8:24])
            self.published[round(sim_time, 6)] = self.last_published = utime * 1e-6
        self.up.set()

    def _pump(self, lc):
        while not self.done.is_set():
            lc.handle_timeout(20)

    def close(self):
        self.done.set()
        for th in self.threads:
            th.join(5.0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--mode", default="lockstep")
    ap.add_argument("--name", default="E2E")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--daemon-arg", action="append", default=[])
    ap.add_argument("--kill-daemon-after", type=float, default=None)
    ap.add_argument("--daemon-first", type=float, default=None)
    ap.add_argument("--daemon-start-delay", type=float, default=0.0)
    ap.add_argument("--stall-daemon", type=float, default=0.0)
    ap.add_argument("--check", action="append", default=[])
    ap.add_argument("--hostile", action="append", default=[])
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("client", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    client = a.client[1:] if a.client and a.client[0] == "--" else a.client
    if not client:
        ap.error("no client command")
    prefix = "%s_%d" % (a.name.upper(), os.getpid())
    # The daemon and the controller meet on LCM's default URL with a multicast port of
    # this run's own (ttl=0: this host), through LCM_DEFAULT_URL, which every binding
    # reads: on one port every socket gets every datagram, so a flood anywhere on the
    # machine (a fast-mode daemon, a flood test) would fill this run's sockets and lose
    # its states; the prefix stays unique as well. Receive buffers of 4 MB: each small
    # datagram costs a socket about 1 kB of buffer, and a controller kept off a core by a
    # loaded machine must not lose a lockstep burst.
    env = dict(os.environ)
    state_url, command_url = lcm_urls("recv_buf_size=4194304")
    env["LCM_DEFAULT_URL"] = state_url
    client = [c.replace("{prefix}", prefix) for c in client]
    dcmd = [a.lagsimd, "--config", a.config, "--set", "lcm.prefix=" + prefix,
            "--set", "realtime.mode=" + a.mode, "-q"]
    for s in a.set:
        dcmd += ["--set", s]
    dcmd += a.daemon_arg
    if a.daemon_start_delay > 0:  # a daemon that starts late, as on a loaded machine
        dcmd = ["sh", "-c", 'sleep "$0" && exec "$@"', repr(a.daemon_start_delay)] + dcmd
    print("LCM_DEFAULT_URL=%s" % env["LCM_DEFAULT_URL"])
    print("client:", " ".join(client))
    print("daemon:", " ".join(dcmd), flush=True)

    if not os.access(a.lagsimd, os.X_OK):
        print("FAIL: no lagsimd executable at %s" % a.lagsimd)
        return 1
    cproc = dproc = fth = None
    done = threading.Event()
    n_hostile = 0
    t_daemon_end = t_client_end = None
    lines = []
    watch = None
    daemon_first = a.daemon_first
    if daemon_first is None and a.kill_daemon_after is not None:
        daemon_first = 0.0
    try:
        if daemon_first is not None or a.kill_daemon_after is not None:
            watch = BusWatch(state_url, command_url, prefix)
        if daemon_first is not None:
            t0 = time.monotonic()
            dproc = subprocess.Popen(dcmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                     universal_newlines=True, env=env)
            if not watch.up.wait(a.timeout) or dproc.poll() is not None:
                print("FAIL: the daemon was not heard on the bus within %g s (exit %s)"
                      % (a.timeout, dproc.poll()))
                return 1
            print("daemon heard after %.1f s" % (time.monotonic() - t0), flush=True)
            time.sleep(daemon_first)  # the controller's lateness, from the daemon's start
        cproc = subprocess.Popen(client, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 universal_newlines=True, env=env)
        # read the client's stdout in a thread; start the daemon once the client says it
        # is subscribed ("waiting for the scene"), so that it sees the very first state
        # (bounded by --timeout: a JVM, Octave or a compile first takes what the machine's
        # load makes it take; only a client that never gets ready fails here)
        rd = waits.Reader(cproc, lines, mark=" summary ")
        ready, th = rd.ready, rd.thread
        t0 = time.monotonic()
        if not ready.wait(a.timeout) or cproc.poll() is not None:
            print("".join(lines))
            print("FAIL: the client did not get ready within %g s" % a.timeout)
            return 1
        print("client ready after %.1f s" % (time.monotonic() - t0), flush=True)
        if a.hostile:
            forged = hostile_payloads(a.hostile, prefix)
            hlc = hostile_lcm(env["LCM_DEFAULT_URL"])
            for _ in range(3):
                for channel, data in forged:
                    hlc.publish(channel, data)
                    n_hostile += 1
            time.sleep(0.5)

            def flood():
                nonlocal n_hostile
                while cproc.poll() is None and not done.is_set():
                    for channel, data in forged:
                        hlc.publish(channel, data)
                        n_hostile += 1
                    done.wait(0.02)

            fth = threading.Thread(target=flood, daemon=True)
            fth.start()
        if dproc is None:
            dproc = subprocess.Popen(dcmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                     universal_newlines=True, env=env)
        t_daemon_end = None
        if a.kill_daemon_after is not None:
            # the controller runs (its first command heard), then S s more; the silence it
            # must count starts at its own last state (its t_last), which may precede the
            # kill by far when a loaded machine stalls the daemon (seen 0.6 s before the
            # kill, under a sanitizer build)
            deadline = time.monotonic() + a.timeout
            while not watch.answered.wait(0.1) and cproc.poll() is None and \
                    time.monotonic() < deadline:
                pass
            if watch.answered.is_set():
                print("the controller's first command heard", flush=True)
            if a.stall_daemon > 0:  # held off the processor, as a loaded machine may hold it
                dproc.send_signal(signal.SIGSTOP)
                time.sleep(a.stall_daemon)
                dproc.send_signal(signal.SIGCONT)
                print("the daemon stopped for %g s (SIGSTOP), then went on" % a.stall_daemon,
                      flush=True)
            try:
                dproc.wait(a.kill_daemon_after)
            except subprocess.TimeoutExpired:
                dproc.kill()
                dproc.wait()
            t_daemon_end = time.monotonic()
        try:
            if t_daemon_end is None and any(x == "--duration" for x in a.daemon_arg):
                dproc.wait(timeout=a.timeout)
                t_daemon_end = time.monotonic()
            cproc.wait(timeout=a.timeout)
        except subprocess.TimeoutExpired:
            stop(cproc, 3.0)
            th.join(5.0)
            print("".join(lines))
            print("FAIL: the client did not finish within %g s" % a.timeout)
            return 1
        t_client_end = time.monotonic()
        th.join(5.0)
        err = cproc.stderr.read()
    finally:
        done.set()
        if fth:
            fth.join(5.0)
        if watch:
            watch.close()
        stop(cproc, 3.0)
        stop(dproc, 3.0)
    out = "".join(lines)
    t_summary = rd.marked  # when the client printed its summary line
    derr = dproc.stderr.read() if dproc and dproc.stderr else ""
    sys.stdout.write(out)
    if err:
        sys.stdout.write("client stderr:\n" + err)
    if derr.strip():
        sys.stdout.write("daemon stderr:\n" + derr)
    if cproc.returncode != 0:
        print("FAIL: client exit status %d" % cproc.returncode)
        return 1
    vals = parse_summary(out)
    if vals is None:
        print("FAIL: no summary line from the client")
        return 1
    ok = True
    names = dict(vals)
    if a.hostile:
        names["hostile"] = n_hostile
        print("hostile: %d forged messages published" % n_hostile)
    if t_daemon_end is not None:
        # the controller's end is its summary line, the event that says how the run ended
        # (every client library flushes it as it decides), not its process's exit: what a
        # JVM or Octave takes to shut down afterwards is no part of the contract (seen on
        # a loaded machine: Octave's exit 5.7 s after the daemon's kill, past 2 + 3 s)
        end = t_summary if t_summary is not None else t_client_end
        names["wall"] = end - t_daemon_end
        print("wall = %.3f s from the daemon's end to the controller's summary line (its exit: "
              "%.3f s)" % (names["wall"], t_client_end - t_daemon_end))
    if a.kill_daemon_after is not None and watch.last_published is not None:
        # from the publication of the controller's last state (its t_last; the controller
        # counts from when it got it, a little later): a daemon held off the processor
        # beside a load of 26 went silent 2.26 s before the kill, the controller ended on
        # that silence, and the states after it (not the controller's) made a silence
        # counted from the last state on the bus negative. One clock: the state's utime is
        # CLOCK_REALTIME (lag_clock_wall_us), as time.time() is; the summary line's
        # monotonic time is put on it by their offset now.
        wall = time.time() - time.monotonic()  # monotonic to wall clock, s
        end = (t_summary if t_summary is not None else t_client_end) + wall
        t_last = vals.get("t_last")
        last = watch.published.get(round(t_last, 6)) if isinstance(t_last, float) else None
        if last is None:
            # counted from a later state than the controller's own: `silent` comes out
            # short by the time between the two, and says so
            print("silent: the controller's last state (t_last %r) was not heard on the bus; "
                  "counted from the last state heard instead" % (t_last,))
            last = watch.last_published
        names["silent"] = end - last
        print("silent = %.3f s from the publication of the controller's last state to its "
              "summary line (that state %.3f s before the kill, the last on the bus %.3f s)"
              % (names["silent"], t_daemon_end + wall - last,
                 t_daemon_end + wall - watch.last_published))
    names["math"] = math
    names["out"] = out  # the client's stdout, for checks of what it prints
    ok = check_expressions(a.check, names) and ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
