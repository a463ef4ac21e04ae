#!/usr/bin/env python3
"""lagsimd on a terminal, as a person sees it: its stderr is a pseudo-terminal this test
reads (and sizes), a controller of this test's own sends commands, stops, sends a bad one.

    test_term.py --bin BUILD/bin --python BUILD/python --source SRC CASE

Cases:
  live      the live line holds q (every joint), commands per second while commands come
            (about 100/s from a 100 Hz sender) and "no controller" before the first and
            after the watchdog trips (then cleared by new commands); each event (start, watchdog_trip, watchdog_clear,
            command_rejected, stop) on its own line above it, the live line cleared
            first; nothing wider than the terminal
  effects   the stick on its floor: each impact (and the rest) on its own line, with the
            sim time the core locates
  quiet     -q: nothing on stderr (no live line, no event line, no line saying where it
            listens), with lcm.allow_lan only that line (a warning: the network reaches the
            plant)
  pipe      stderr not a terminal: event lines only, no live line, no control codes
  waits     no controller: after 3 s, 6 s, 12 s ... a line says what the plant waits for
            (the first command, on <PREFIX>_COMMAND at the command URL) and, once a
            command for an unknown joint came and one on the state URL's port, what came
            instead; each on its own line above the live line
  stalled   waits, with the daemon held off the processor (SIGSTOP) for 2 s before its
            first line: the lines say the waits as they were, each at least twice the one
            before
"""
import argparse
import fcntl
import os
import pty
import re
import select
import signal
import struct
import subprocess
import sys
import termios
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


class Daemon:
    """lagsimd with stdout and stderr on a pseudo-terminal of `cols` columns (or a pipe)."""

    def __init__(self, a, config, prefix, *args, cols=200, tty=True):
        self.out = b""
        argv = [os.path.join(a.bin, "lagsimd"), "--config", config, "--set",
                f"lcm.prefix={prefix}", *args]
        if tty:
            self.master, slave = pty.openpty()
            fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, cols, 0, 0))
            self.p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=slave, stderr=slave)
            os.close(slave)
        else:
            r, w = os.pipe()
            self.master = r
            self.p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=w, stderr=w)
            os.close(w)

    def read(self, seconds):
        end = time.monotonic() + seconds
        while True:
            left = end - time.monotonic()
            if left <= 0:
                return
            r, _, _ = select.select([self.master], [], [], min(left, 0.05))
            if r:
                try:
                    chunk = os.read(self.master, 65536)
                except OSError:  # EIO: the terminal's other end closed
                    return
                if not chunk:
                    return
                self.out += chunk

    def read_until(self, done, limit=30.0):
        """Reads until done(text) holds (the event a check waits for), at most `limit` s."""
        end = time.monotonic() + limit
        while not done(self.text()) and time.monotonic() < end and self.p.poll() is None:
            self.read(0.05)

    def stop(self):
        if self.p.poll() is None:
            self.p.send_signal(signal.SIGTERM)
        t_end = time.monotonic() + 10
        while self.p.poll() is None and time.monotonic() < t_end:
            self.read(0.1)
        self.read(0.3)
        if self.p.poll() is None:
            self.p.kill()
        os.close(self.master)
        return self.p.wait()

    def text(self):
        # the terminal's line discipline writes \n as \r\n (onlcr): read it as \n
        return self.out.decode(errors="replace").replace("\r\n", "\n")


def live_lines(text, prefix):
    """Every drawing of the live line (the text after a \\r\\x1b[K up to the next \\r or \\n)."""
    return [m.group(1) for m in re.finditer(r"\r\x1b\[K(" + re.escape(prefix) + r" t=[^\r\n]*)", text)]


def event_lines_alone(text):
    """Each event line starts a line (at the start, after \\n, or after the live line was
    cleared) and runs to its \\n without a \\r: (ok, lines)."""
    ok, lines = True, []
    for m in re.finditer(r"lagsimd: event ", text):
        i = m.start()
        before = text[max(0, i - 4):i]
        starts = i == 0 or before.endswith("\n") or before.endswith("\r\x1b[K")
        end = text.find("\n", i)
        line = text[i:end if end >= 0 else len(text)]
        ok &= starts and end >= 0 and "\r" not in line
        lines.append(line)
    return ok, lines


class Sender:
    def __init__(self, a, prefix):
        sys.path.insert(0, a.python)
        from lagsim_lcm import LCM, plant_urls
        from lagsim import joint_command_t
        self.lc = LCM(plant_urls()[1])  # the daemon's command URL (the next port)
        self.cmd_t, self.prefix = joint_command_t, prefix

    def command(self, name="theta0", effort=0.0, lc=None):
        c = self.cmd_t()
        c.sim_time, c.num_joints, c.name, c.effort = 0.0, 1, [name], [effort]
        (lc or self.lc).publish(self.prefix + "_COMMAND", c.encode())

    def send_for(self, d, seconds, hz=100):
        end = time.monotonic() + seconds
        k = 0
        while time.monotonic() < end:
            self.command()
            k += 1
            d.read(1.0 / hz)
        return k


def case_live(a):
    prefix = f"TT{os.getpid()}"
    config = os.path.join(a.source, "config", "dipc.yaml")
    d = Daemon(a, config, prefix, "--set", "realtime.command_timeout=0.3")
    s = Sender(a, prefix)
    d.read(1.0)                       # no controller yet
    n0 = len(d.text())
    s.send_for(d, 2.5)                # a controller at about 100 Hz
    n1 = len(d.text())
    d.read(1.5)                       # it is gone: the watchdog trips after 0.3 s
    s.command(name="nope")            # a bad command: rejected, said
    d.read(0.8)
    n2 = len(d.text())
    s.send_for(d, 0.5)                # it is back: the watchdog clears
    rc = d.stop()
    t = d.text()
    print(t.replace("\r", "\\r\n").replace("\x1b", "\\e")[-4000:])
    check(rc == 0, f"lagsimd exit {rc}")
    lines = live_lines(t, prefix)
    check(len(lines) >= 15, f"the live line is redrawn ({len(lines)} times in about 6 s)")
    qs = [re.search(r" q=\(([^)]*)\) ", l) for l in lines]
    check(all(q and len(q.group(1).split()) == 3 for q in qs), "every live line holds q: 3 joints")
    before = live_lines(t[:n0], prefix)
    check(before and all("no controller" in l for l in before), "no controller before the first command")
    during = [l for l in live_lines(t[n0:n1], prefix) if "cmd/s" in l]
    rates = [int(re.search(r" (\d+) cmd/s ", l).group(1)) for l in during]
    print("commands per second shown:", rates)
    # a 100 Hz sender in Python on a loaded machine: between 40 and 130 a second
    check(len(rates) >= 4 and 40 <= max(rates) <= 130, f"commands per second while they come: {rates}")
    after = live_lines(t[n1:n2], prefix)
    check(after and "no controller" in after[-1], "no controller after the watchdog tripped")
    ok, evs = event_lines_alone(t)
    for e in evs:
        print("  event line:", e)
    check(ok, "each event on its own line, the live line cleared first")
    kinds = [re.match(r"lagsimd: event (\S+)", e).group(1) for e in evs]
    for k in ("start", "watchdog_clear", "watchdog_trip", "command_rejected", "stop"):
        check(k in kinds, f"event line: {k}")
    check(any("command rejected: unknown joint" in e for e in evs), "the reject says why")
    check(re.search(prefix + r" t=[^\r\n]* running\n\Z", t) is not None,
          "the final live line stays on screen")

    # a narrow terminal: the live line is cut, never wrapped
    d = Daemon(a, config, prefix + "N", cols=50)
    d.read(1.2)
    d.stop()
    lines = live_lines(d.text(), prefix + "N")
    check(lines and all(len(l) <= 49 for l in lines), f"50 columns: live lines of at most 49 "
          f"characters ({max(len(l) for l in lines) if lines else None})")


def case_effects(a):
    prefix = f"TT{os.getpid()}S"
    d = Daemon(a, os.path.join(a.source, "config", "stick.yaml"), prefix, "--set",
               "realtime.mode=fast", "--set", "realtime.start=running", "--duration", "5")
    d.read(10)
    rc = d.stop()
    t = d.text()
    check(rc == 0, f"lagsimd exit {rc}")
    ok, evs = event_lines_alone(t)
    for e in evs[:12]:
        print("  event line:", e)
    check(ok, "each event on its own line")
    impacts = [e for e in evs if e.startswith("lagsimd: event impact ")]
    check(len(impacts) >= 3, f"{len(impacts)} impact lines")
    # the first impact's time as the core locates it (tests/server: server_effects)
    check(impacts and impacts[0].startswith("lagsimd: event impact at t = 0.426664059 s, joint phi, value "),
          "the first impact at the located sim time, with its joint")
    check(any(e.startswith("lagsimd: event rest ") for e in evs), "the resting contact too")


def case_quiet(a):
    prefix = f"TT{os.getpid()}Q"
    d = Daemon(a, os.path.join(a.source, "config", "dipc.yaml"), prefix, "-q")
    s = Sender(a, prefix)
    s.command(name="nope")
    d.read(1.5)
    rc = d.stop()
    # -q: only warnings and errors; a rejected command and waiting are neither
    check(rc == 0 and d.out == b"", f"-q: nothing at all ({d.out[:300]!r}), exit {rc}")
    # with lcm.allow_lan the line saying that the network reaches the plant is a warning
    d = Daemon(a, os.path.join(a.source, "config", "dipc.yaml"), prefix + "L", "-q", "--set",
               "lcm.allow_lan=true")
    d.read(1.0)
    rc = d.stop()
    left = [l for l in d.text().splitlines() if l]
    check(rc == 0 and len(left) == 1 and f"lagsimd: {prefix}L: listening on " in left[0]
          and "from the network" in left[0] and "\r" not in d.text(),
          f"-q, lcm.allow_lan: only the line saying the network reaches it ({d.out[:300]!r}), exit {rc}")


def case_pipe(a):
    prefix = f"TT{os.getpid()}P"
    d = Daemon(a, os.path.join(a.source, "config", "dipc.yaml"), prefix, tty=False)
    d.read(1.0)
    rc = d.stop()
    t = d.text()
    print(t)
    check(rc == 0, f"exit {rc}")
    check("\r" not in t and "\x1b" not in t, "no live line, no control codes")
    ok, evs = event_lines_alone(t)
    check(ok and [e.split()[2] for e in evs] == ["start", "stop"], "the start and stop events, one line each")


def wait_lines(text, prefix):
    """The lines saying what the plant waits for: (each starts a line and ends at its \\n
    without a \\r, the lines)."""
    ok, lines = True, []
    for m in re.finditer(r"lagsimd: " + re.escape(prefix) + r" waits ", text):
        i = m.start()
        before = text[max(0, i - 4):i]
        end = text.find("\n", i)
        line = text[i:end if end >= 0 else len(text)]
        ok &= (i == 0 or before.endswith("\n") or before.endswith("\r\x1b[K")) and end >= 0 \
            and "\r" not in line
        lines.append(line)
    return ok, lines


def waited(line):
    """The seconds a wait line says the plant waited ("waits 6 s for ..."), or None."""
    m = re.search(r" waits (\d+) s for ", line)
    return int(m.group(1)) if m else None


def doubling(lines):
    """Whether the lines come as the daemon schedules them: the first after 3 s of the
    wait, each next once the wait has doubled (3, 6, 12, ... s; the seconds said are the
    wait's when the line was printed, rounded: a loaded machine's loop wakes late and says
    4 s where it meant 3, then 7, so each is checked against the one it follows, not
    against fixed times)."""
    w = [waited(l) for l in lines]
    return bool(w) and None not in w and w[0] >= 3 and all(b >= 2 * a - 1 for a, b in zip(w, w[1:]))


def case_waits(a, stall=0.0):
    prefix = f"TT{os.getpid()}W"
    sys.path.insert(0, a.python)
    from lagsim_lcm import LCM, plant_urls
    state_url, command_url = plant_urls()
    d = Daemon(a, os.path.join(a.source, "config", "dipc.yaml"), prefix)
    s = Sender(a, prefix)
    if stall:  # held off the processor across its first line's time, as a loaded machine may
        d.read_until(lambda t: len(live_lines(t, prefix)) > 0)
        d.read(2.0)
        d.p.send_signal(signal.SIGSTOP)
        time.sleep(stall)
        d.p.send_signal(signal.SIGCONT)
    # the events, not fixed times: the first wait line (3 s after the daemon's start, which
    # a loaded machine delays: after a fixed 4 s the sanitizer build had printed none), then
    # 0.5 s more, in which no second line may come (doubling: a second line is 3 s away)
    d.read_until(lambda t: len(wait_lines(t, prefix)[1]) >= 1)
    d.read(0.5)
    ok, lines = wait_lines(d.text(), prefix)
    for l in lines:
        print("  wait line:", l)
    check(ok and len(lines) >= 1 and doubling(lines),
          f"a line after at least 3 s of waiting, each on its own line, any next one once the "
          f"wait has doubled ({[waited(l) for l in lines]} s)")
    if stall:
        # the stop covered the first line's time: the line came when the daemon went on,
        # past 3 s of waiting, and says so (a line that says 3 s was printed before the stop,
        # and this case would test nothing the case without a stop does not)
        check(lines and (waited(lines[0]) or 0) > 3,
              f"the stop held the first line back: it says {waited(lines[0]) if lines else None} s "
              f"of waiting, more than 3")
    check(lines and re.match(f"lagsimd: {prefix} waits \\d+ s for the first command on "
                             f"{prefix}_COMMAND at {re.escape(command_url)}; nothing else came$",
                             lines[0]) is not None,
          "it says what it waits for, on which channel and URL, and that nothing else came")
    s.command(name="cart")
    wrong = LCM(state_url)
    s.command(lc=wrong)  # a controller publishing on the state URL's port
    # the next line that says what came instead: the one after 6 s of the wait, or, when a
    # loaded machine delivered the commands after that line was printed, the one after 12 s
    d.read_until(lambda t: any("got instead" in l for l in wait_lines(t, prefix)[1]))
    d.read(0.5)
    rc = d.stop()
    wrong.close()
    ok, lines = wait_lines(d.text(), prefix)
    for l in lines[1:]:
        print("  wait line:", l)
    came = [l for l in lines if "got instead" in l]
    check(ok and len(lines) >= 2 and doubling(lines) and bool(came) and
          all(l.endswith("nothing else came") for l in lines[:lines.index(came[0])]),
          f"a line at 3, 6, 12 s ... of the wait, each on its own line, 'nothing else came' "
          f"until a line says what came instead ({[waited(l) for l in lines]} s; "
          f"{len(came)} say what came)")
    last = came[0] if came else ""
    check(last.startswith(f"lagsimd: {prefix} waits ") and " s for the first command" in last and
          "got instead: 1 command rejected "
          "(unknown joint 1; the last: unknown joint: 'cart'; joints of dipc: theta0 (actuated), "
          "theta1, theta2)" in last, "what came instead: the rejected command and why")
    sport, cport = (int(re.search(r":(\d+)", u).group(1)) for u in (state_url, command_url))
    check(f"; 1 command on {prefix}_COMMAND at the state port {sport} (commands go to port "
          f"{cport})" in last, "and the command on the state URL's port")
    check(len(live_lines(d.text(), prefix)) > 0, "the live line below them")
    check(rc == 0, f"exit {rc}")


def case_stalled(a):
    """waits, the daemon stopped (SIGSTOP) 2 s after its first live line for 2 s: its
    lines come later than 3 and 6 s and say so (4 and 8 s, or so), still doubling"""
    case_waits(a, stall=2.0)


CASES = {"waits": case_waits, "stalled": case_stalled, "live": case_live, "effects": case_effects, "quiet": case_quiet, "pipe": case_pipe}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--python", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("case", choices=sorted(CASES))
    a = ap.parse_args()
    # a multicast port of this test's own (ttl=0: this host) for every process it starts,
    # through LCM_DEFAULT_URL: on one port every socket gets every datagram, and another
    # test's fast-mode daemon would flood this one's sockets; 4 MB receive buffers
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")  # and the next port: commands
    a.bin, a.python, a.source = (os.path.abspath(x) for x in (a.bin, a.python, a.source))
    CASES[a.case](a)
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
