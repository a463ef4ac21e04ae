#!/usr/bin/env python3
"""Plays the daemon's side of a conformance trace against a controller.

    play.py [--types DIR] [--port P] [--expect-failure ID] [-q] TRACE -- CONTROLLER ARGS...

TRACE is a file of tests/protocol/traces/ (its format: docs/protocol.md, "Conformance
traces"). CONTROLLER ARGS... is a conformance controller's command line, in which {prefix}
and {url} become the run's channel prefix and the plant's state URL (LCM_DEFAULT_URL is
that URL too). The player takes a multicast port pair of its own (--port P: states on P,
commands on P + 1; default a pair held by this process and bound by no socket of the host,
tests/common/lcm_port.py), starts the controller and runs the trace's steps in order: it
publishes what the trace sends, exactly, on the state URL (or where the step says) and
checks what the controller sends on the command URL against what the trace expects, the conformance law's efforts bit for bit. It stops at the first step
that fails and names it (the trace's file and line, the step's id, what was expected and
what came), then ends the controller: a stop event, then SIGTERM and SIGKILL.

Exit status: 0 every step held; 1 a step failed (or, with --expect-failure ID, the trace
did not fail at the step ID: a negative test, for a controller broken on purpose); 2 bad
usage or a trace that does not parse.
"""
import argparse
import json
import math
import os
import re
import shlex
import signal
import struct
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from lagsim_lcm import LCM, plant_urls  # noqa: E402
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from lcm_port import lcm_port  # noqa: E402

LAW_LINE = "conformance: law "  # what a conformance controller prints for each law run
SPECIAL = {"NaN": float("nan"), "Infinity": float("inf"), "-Infinity": float("-inf")}


class TraceError(Exception):
    """A trace that does not parse, or names what it did not define."""


class StepFailed(Exception):
    pass


# ---------------------------------------------------------------- reading a trace

def _blank_comments(text):
    """The text with every line whose first non-blank character is # blanked (the line
    kept, so that line numbers stay)."""
    return "\n".join("" if ln.lstrip().startswith("#") else ln for ln in text.split("\n"))


def read_trace(path, seen=None):
    """The steps of a trace file, each a dict with "_where" (file:line), includes
    expanded in place."""
    seen = seen or []
    if os.path.abspath(path) in seen:
        raise TraceError("%s: included twice" % path)
    seen = seen + [os.path.abspath(path)]
    with open(path) as f:
        text = _blank_comments(f.read())
    dec, pos, steps = json.JSONDecoder(), 0, []
    name = os.path.basename(path)
    while True:
        while pos < len(text) and text[pos].isspace():
            pos += 1
        if pos >= len(text):
            break
        line = text.count("\n", 0, pos) + 1
        try:
            obj, pos = dec.raw_decode(text, pos)
        except ValueError as e:
            raise TraceError("%s:%d: not JSON: %s" % (name, line, e))
        if not isinstance(obj, dict) or "do" not in obj:
            raise TraceError("%s:%d: a step is an object with \"do\"" % (name, line))
        obj["_where"] = "%s:%d" % (name, line)
        if obj["do"] == "include":
            steps += read_trace(os.path.join(os.path.dirname(path), obj["file"]), seen)
        else:
            steps.append(obj)
    return steps


# ---------------------------------------------------------------- messages

URLS = {}  # "{url}", "{decoy_url}" in a message's strings: the run's (run())


def _value(v, prefix):
    if isinstance(v, str):
        if v in SPECIAL:
            return SPECIAL[v]
        for k, u in URLS.items():
            v = v.replace(k, u)
        return v.replace("{prefix}", prefix)
    if isinstance(v, list):
        return [_value(x, prefix) for x in v]
    return v


def build(types, msg, prefix):
    """The lcm-gen object for a definition {"type": ..., "fields": {...}}: fields not
    given keep lcm-gen's defaults (0, "", empty arrays); a count (num_*) not given is the
    length of the first array after it."""
    cls = getattr(types, msg["type"], None)
    if cls is None:
        raise TraceError("no message type %r" % msg["type"])
    m = cls()
    fields = msg["fields"]
    for k, v in fields.items():
        if k not in cls.__slots__:
            raise TraceError("%s has no field %r" % (msg["type"], k))
        setattr(m, k, _value(v, prefix))
    slots = list(cls.__slots__)
    for i, k in enumerate(slots):
        if k.startswith("num_") and k not in fields:
            for later in slots[i + 1:]:
                if isinstance(getattr(m, later), list):
                    setattr(m, k, len(getattr(m, later)))
                    break
    return m


def forge(data, ops):
    """The bytes after the trace's forgeries, in this order: fingerprint (replace the
    first 8 bytes), truncate (keep the first N bytes; negative: drop the last -N), patch
    ([[offset, hex], ...]; a negative offset counts from the end), append (hex)."""
    b = bytearray(data)
    if "fingerprint" in ops:
        b[0:8] = bytes.fromhex(ops["fingerprint"])
    if "truncate" in ops:
        n = ops["truncate"]
        b = b[:n] if n >= 0 else b[:len(b) + n]
    for off, hexs in ops.get("patch", []):
        raw = bytes.fromhex(hexs)
        off = off if off >= 0 else len(b) + off
        b[off:off + len(raw)] = raw
    if "append" in ops:
        b += bytes.fromhex(ops["append"])
    return bytes(b)


def bits(x):
    return struct.pack(">d", x).hex()


def law(scene, state):
    """The conformance law: for each actuated joint of the scene, in the scene's order,
    u = -(kp q + kd qd) with kp, kd the scene's parameters of those names and q, qd the
    state's position and velocity of that joint, in IEEE doubles in this order: kp q, kd
    qd, their sum, its negation. Returns {joint: effort}."""
    params = dict(zip(scene.param_name, scene.param_value))
    kp, kd = params["kp"], params["kd"]
    out = {}
    for j, name in enumerate(scene.joint_name):
        if scene.actuated[j]:
            i = list(state.name).index(name)
            out[name] = -(kp * state.position[i] + kd * state.velocity[i])
    return out


# ---------------------------------------------------------------- the controller

class Controller:
    def __init__(self, argv, env):
        self.lines, self.laws = [], 0
        self.p = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  stdin=subprocess.DEVNULL, universal_newlines=True,
                                  errors="replace", start_new_session=True)
        self.t = threading.Thread(target=self._read, daemon=True)
        self.t.start()

    def _read(self):
        for line in self.p.stdout:
            self.lines.append(line.rstrip("\n"))
            if line.startswith(LAW_LINE):
                self.laws += 1

    def exited(self):
        return self.p.poll()

    def stop(self, grace):
        """SIGTERM after `grace` s, SIGKILL 3 s later: nothing outlives the player."""
        for sig, wait in ((None, grace), (signal.SIGTERM, 3.0), (signal.SIGKILL, 3.0)):
            if sig is not None and self.p.poll() is None:
                try:
                    os.killpg(self.p.pid, sig)
                except ProcessLookupError:
                    pass
            try:
                self.p.wait(timeout=wait)
                break
            except subprocess.TimeoutExpired:
                continue
        self.t.join(timeout=2)

    def tail(self, n=25):
        return "\n".join("    | " + ln for ln in self.lines[-n:])


# ---------------------------------------------------------------- the daemon's side

class Player:
    def __init__(self, types, state_url, command_url, prefix, ctl, quiet, directory=None):
        self.t, self.prefix, self.ctl, self.quiet = types, prefix, ctl, quiet
        self.url = {"state": state_url, "command": command_url}
        self.out = LCM(state_url)
        self.out_cmd = LCM(command_url)
        self.inp = LCM(command_url)
        esc = re.escape(prefix)
        self.inp.subscribe(esc + "_COMMAND", self._on_command)
        self.inp.subscribe(esc + "_CONTROL", self._on_control)
        # a host's directory (the step "directory"): its bus, LCM_DEFAULT_URL's; DESCRIBE
        # there answered with a scene, as a host's directory answers it
        self.out_dir = self.dir_in = None
        self.dir_describe = None
        self.dir_describes = 0
        if directory is not None:
            self.out_dir = LCM(directory[0])
            self.dir_in = LCM(directory[1])
            self.dir_in.subscribe(esc + "_CONTROL", self._on_dir_control)
        self.every = []        # [period, next time, data, channel, prefix, url]
        self.defs = {}         # name -> {"type", "fields"}
        self.commands = []     # (bytes, decoded or None, reason) not yet taken by a step
        self.received = {}     # name -> bytes of a command an expect step named
        self.copyable = set()  # bytes of the commands a `copies` step allowed copies of
        self.describes = []    # monotonic times of the DESCRIBE requests handled
        self.others = 0        # other control requests
        self.last_send = time.monotonic()
        self.on_describe = None
        self.exit_expected = False

    # -- receiving
    def _on_command(self, channel, data):
        cls = self.t.joint_command_t
        try:
            c = cls.decode(data)
            whole = c.encode() == data
            finite = math.isfinite(c.sim_time) and all(math.isfinite(x) for x in c.effort)
            reason = None if whole and finite else \
                "does not decode whole" if not whole else "a NaN or an infinity"
        except Exception as e:
            c, reason = None, "not a joint_command_t of this version (%s)" % (e or type(e).__name__)
        self.commands.append((data, c if reason is None else None, reason))

    def _on_control(self, channel, data):
        try:
            c = self.t.control_t.decode(data)
        except Exception:
            self.others += 1
            return
        if c.request == self.t.control_t.DESCRIBE:
            self.describes.append(time.monotonic())
            if self.on_describe is not None:
                self.publish(self.defs_msg(self.on_describe), "SCENE", self.prefix, "state")
        else:
            self.others += 1

    def _on_dir_control(self, channel, data):
        try:
            c = self.t.control_t.decode(data)
        except Exception:
            return
        if c.request == self.t.control_t.DESCRIBE and self.dir_describe is not None:
            self.dir_describes += 1
            self.out_dir.publish("%s_SCENE" % self.prefix, self.defs_msg(self.dir_describe))

    def _repeat(self):
        """The sends with an "every": each again when its period has passed."""
        now = time.monotonic()
        for r in self.every:
            if now >= r[1]:
                self.publish(r[2], r[3], r[4], r[5])
                r[1] = now + r[0]

    def pump(self, seconds, until=None):
        """Handles what arrives for `seconds` (or until until() holds); fails if the
        controller exited meanwhile, unless an exit is what the step waits for."""
        end = time.monotonic() + seconds
        while True:
            if until is not None and until():
                return True
            left = end - time.monotonic()
            if left <= 0:
                return until is not None and until()
            self._repeat()
            if self.dir_in is not None:
                self.dir_in.handle_timeout(1)
            self.inp.handle_timeout(min(20, max(1, int(left * 1000))))
            if not self.exit_expected and self.ctl is not None and self.ctl.exited() is not None:
                raise StepFailed("the controller exited (status %s)" % self.ctl.exited())

    # -- sending
    def defs_msg(self, name):
        if name not in self.defs:
            raise TraceError("no message %r defined" % name)
        return build(self.t, self.defs[name], self.prefix).encode()

    def publish(self, data, channel, prefix, url):
        if url == "directory" and self.out_dir is None:
            raise TraceError("\"url\": \"directory\" in a trace without the step \"directory\"")
        lc = {"state": self.out, "command": self.out_cmd, "directory": self.out_dir}[url]
        lc.publish("%s_%s" % (prefix, channel), data)

    # -- the steps
    def step(self, s):
        do = s["do"]
        fn = getattr(self, "do_" + do, None)
        if fn is None:
            raise TraceError("%s: unknown step %r" % (s["_where"], do))
        return fn(s)

    def do_define(self, s):
        base = {"fields": {}}
        if "like" in s:
            if s["like"] not in self.defs:
                raise TraceError("%s: no message %r defined" % (s["_where"], s["like"]))
            base = self.defs[s["like"]]
        typ = s.get("type", base.get("type"))
        fields = dict(base["fields"])
        fields.update(s.get("fields", {}))
        self.defs[s["name"]] = {"type": typ, "fields": fields}
        build(self.t, self.defs[s["name"]], self.prefix)  # fails now if it cannot be built
        return "%s (%s)" % (s["name"], typ)

    def do_send(self, s):
        data = bytes.fromhex(s["hex"]) if "hex" in s else self.defs_msg(s["msg"])
        data = forge(data, s.get("forge", {}))
        prefix = s.get("prefix", "{prefix}").replace("{prefix}", self.prefix)
        url = s.get("url", "state")
        if url not in ("state", "command", "directory"):
            raise TraceError("%s: \"url\" is state, command or directory" % s["_where"])
        for _ in range(s.get("times", 1)):
            self.publish(data, s["channel"], prefix, url)
        if "every" in s:  # again and again until the trace ends, as a directory announces
            self.every.append([s["every"], time.monotonic() + s["every"], data, s["channel"],
                               prefix, url])
            return "%s on %s_%s (%s URL, %d bytes), every %g s" % (
                s.get("msg", "raw bytes"), prefix, s["channel"], url, len(data), s["every"])
        self.last_send = time.monotonic()
        return "%s on %s_%s (%s URL, %d bytes)" % (s.get("msg", "raw bytes"), prefix,
                                                   s["channel"], url, len(data))

    def do_start(self, s):
        if self.ctl is not None:
            raise TraceError("%s: the controller runs already" % s["_where"])
        self.ctl = self.start_ctl()
        return "the controller started"

    def do_directory(self, s):
        self.dir_describe = s.get("describe")
        return "LCM's default bus is a host's directory (%s); the controller was given no URL" \
            % URLS.get("{directory_url}")

    def do_drop(self, s):
        self.defs_msg(s["msg"])
        return "%s on %s: lost (sent to nobody)" % (s["msg"], s["channel"])

    def do_wait(self, s):
        self.pump(s["for"])
        return "%g s" % s["for"]

    def do_on_describe(self, s):
        self.on_describe = s.get("send")
        if self.on_describe is not None:
            self.defs_msg(self.on_describe)
        return "DESCRIBE answered with %s" % (self.on_describe or "nothing")

    def do_expect(self, s):
        what = s["what"]
        fn = getattr(self, "expect_" + what, None)
        if fn is None:
            raise TraceError("%s: unknown expectation %r" % (s["_where"], what))
        return fn(s)

    def expect_command(self, s):
        within = s.get("within", 5.0)
        if not self.pump(within, lambda: len(self.commands) > 0):
            raise StepFailed("no command within %g s" % within)
        data, c, reason = self.commands.pop(0)
        if reason is not None:
            raise StepFailed("a command that %s: %s" % (reason, data.hex()))
        if "same_as" in s:
            want = self.received.get(s["same_as"])
            if want is None:
                raise TraceError("%s: no command named %r" % (s["_where"], s["same_as"]))
            if data != want:
                raise StepFailed("not the same bytes as %s (a copy is answered with the command "
                                 "already sent, the law not run again):\n      got  %s\n      want %s"
                                 % (s["same_as"], describe_cmd(c), describe_cmd(
                                     self.t.joint_command_t.decode(want))))
        else:
            self.check_answer(s, c)
        if "name" in s:
            self.received[s["name"]] = data
        return describe_cmd(c)

    def check_answer(self, s, c):
        st = build(self.t, self.defs[s["answers"]], self.prefix)
        sc = build(self.t, self.defs[s["scene"]], self.prefix)
        want = law(sc, st)
        got = dict(zip(c.name, c.effort))
        problems = []
        if c.generation != st.generation:
            problems.append("generation %d, not the state's %d" % (c.generation, st.generation))
        if bits(c.sim_time) != bits(st.sim_time):
            problems.append("sim_time %.17g, not the state's %.17g" % (c.sim_time, st.sim_time))
        if len(got) != len(c.name) or sorted(got) != sorted(want):
            problems.append("joints %s, not the scene's actuated joints %s"
                            % (list(c.name), sorted(want)))
        else:
            for k in want:
                if bits(got[k]) != bits(want[k]):
                    problems.append("%s effort %.17g, not the law's %.17g (%s under %s)"
                                    % (k, got[k], want[k], s["answers"], s["scene"]))
        if problems:
            raise StepFailed("not the answer to %s under %s: %s\n      got  %s"
                             % (s["answers"], s["scene"], "; ".join(problems), describe_cmd(c)))

    def expect_no_command(self, s):
        self.pump(s["for"], lambda: len(self.commands) > 0)
        if self.commands:
            data, c, reason = self.commands[0]
            raise StepFailed("a command came: %s" % (describe_cmd(c) if c else reason))
        return "none in %g s" % s["for"]

    def expect_copies(self, s):
        """Commands with the bytes of the named one, any number (0 too), for a while."""
        want, n = self.received[s["of"]], 0
        self.copyable.add(want)
        end = time.monotonic() + s["for"]
        while time.monotonic() < end:
            self.pump(end - time.monotonic(), lambda: len(self.commands) > 0)
            while self.commands and self.commands[0][0] == want:
                self.commands.pop(0)
                n += 1
            if self.commands:
                break
        return "%d copies of %s" % (n, s["of"])

    def expect_describe(self, s):
        within, n = s.get("within", 5.0), s.get("at_least", 1)
        since = self.last_send

        def count():
            return sum(1 for t in self.describes if t >= since)

        if not self.pump(within, lambda: count() >= n):
            raise StepFailed("%d DESCRIBE since the last message sent, not at least %d, within %g s"
                             % (count(), n, within))
        return "%d DESCRIBE" % count()

    def expect_describes_during(self, s):
        """At least at_least DESCRIBE and at most at_most per `for` seconds. A loaded machine
        may not schedule the controller within the window: fewer than at_least are waited
        for (at most 30 s more), and the upper bound is a rate over the time taken."""
        start, span, lo = time.monotonic(), s["for"], s.get("at_least", 0)

        def count():
            return sum(1 for t in self.describes if t >= start)
        self.pump(span)
        if count() < lo:
            self.pump(30.0, lambda: count() >= lo)
        took, n = time.monotonic() - start, count()
        cap = s["at_most"] * max(1.0, took / span) if "at_most" in s else n
        if not lo <= n <= cap:
            raise StepFailed("%d DESCRIBE in %.3g s, not %s to %s" % (n, took, lo,
                                                                    s.get("at_most", "any")))
        return "%d DESCRIBE in %.3g s" % (n, took)

    def expect_no_describe(self, s):
        start = time.monotonic()
        self.pump(s["for"])
        n = sum(1 for t in self.describes if t >= start)
        if n:
            raise StepFailed("%d DESCRIBE in %g s" % (n, s["for"]))
        return "none in %g s" % s["for"]

    def expect_law_runs(self, s):
        lo = s.get("count", s.get("at_least", 0))
        hi = s.get("count", s.get("at_most", float("inf")))
        self.pump(2.0, lambda: self.ctl.laws >= lo)
        self.pump(0.1)
        if not lo <= self.ctl.laws <= hi:
            raise StepFailed("the law ran %d times so far, not %s" % (
                self.ctl.laws, lo if lo == hi else "%s to %s" % (lo, hi)))
        return "%d" % self.ctl.laws

    def expect_alive(self, s):
        self.pump(s.get("for", 0.0))
        return "running"

    def expect_exit(self, s):
        self.exit_expected = True
        within = s.get("within", 5.0)
        if not self.pump(within, lambda: self.ctl.exited() is not None):
            raise StepFailed("still running %g s later" % within)
        if "status" in s and self.ctl.exited() != s["status"]:
            raise StepFailed("exit status %d, not %d" % (self.ctl.exited(), s["status"]))
        return "exit status %d" % self.ctl.exited()

    def do_end(self, s):
        self.pump(s.get("for", 0.2))
        # a copy of an answer whose copies a step allowed may come after that step's window
        # on a loaded machine (the rule says copies are answered, not how soon): still one
        self.commands = [c for c in self.commands if c[0] not in self.copyable]
        if self.commands:
            data, c, reason = self.commands[0]
            raise StepFailed("%d command(s) no step expected, the first: %s"
                             % (len(self.commands), describe_cmd(c) if c else reason))
        return "no command left over"


def describe_cmd(c):
    if c is None:
        return "(undecodable)"
    return "generation %d sim_time %.17g %s" % (
        c.generation, c.sim_time, " ".join("%s=%.17g" % (n, e) for n, e in zip(c.name, c.effort)))


# ---------------------------------------------------------------- main

def stop_event(types, prefix):
    e = types.event_t()
    e.utime, e.kind, e.joint, e.detail = int(time.time() * 1e6), "stop", "", "the trace ended"
    return e.encode()


def run(a, steps, types):
    hosted = any(s["do"] == "directory" for s in steps)
    # pairs held by this process (tests/common/lcm_port.py): the plant's; with a directory,
    # the directory's and a decoy's after it
    port = a.port or lcm_port(6 if hosted else 2)
    url = "udpm://239.255.76.67:%d?ttl=0" % port
    state_url, command_url = plant_urls(url)
    name = re.sub(r"[^A-Z0-9]", "", os.path.splitext(os.path.basename(a.trace))[0].upper())
    prefix = "PT%s%d" % (name[:24], os.getpid())
    URLS["{url}"] = state_url
    directory = None
    if hosted:  # the controller is given no URL: LCM's default bus is the directory's
        directory = plant_urls("udpm://239.255.76.67:%d?ttl=0" % (port + 2))
        URLS["{directory_url}"] = directory[0]
        URLS["{decoy_url}"] = "udpm://239.255.76.67:%d?ttl=0" % (port + 4)
    given = "" if hosted else state_url
    argv = [w.replace("{prefix}", prefix).replace("{url}", given) for w in a.controller]
    env = dict(os.environ, LCM_DEFAULT_URL=directory[0] if hosted else state_url)
    say = (lambda *x: None) if a.quiet else (lambda *x: print(*x, flush=True))
    say("play %s: prefix %s, state URL %s, commands %s" % (a.trace, prefix, state_url, command_url))
    say("controller: %s" % " ".join(shlex.quote(w) for w in argv))
    # at once, or at the step "start" (a trace that sets a stage first: a directory that
    # announces its plant before the controller asks it)
    late = any(s["do"] == "start" for s in steps)
    p = Player(types, state_url, command_url, prefix, None if late else Controller(argv, env),
               a.quiet, directory)
    p.start_ctl = lambda: Controller(argv, env)
    failed = None
    try:
        for s in steps:
            label = "%-22s %s %s" % (s["_where"], s["do"], s.get("what", ""))
            try:
                got = p.step(s)
            except StepFailed as e:
                failed = (s, str(e))
                print("FAIL %s [%s]%s: %s" % (label.strip(), s.get("id", "no id"),
                                              " (" + s["why"] + ")" if "why" in s else "", e),
                      flush=True)
                break
            say("ok   %s: %s" % (label, got))
    finally:
        ctl = p.ctl
        if ctl is not None and ctl.exited() is None:
            p.publish(stop_event(types, prefix), "EVENT", prefix, "state")
        if ctl is not None:
            ctl.stop(grace=5.0)
        for lc in (p.out, p.out_cmd, p.inp, p.out_dir, p.dir_in):
            if lc is not None:
                lc.close()
    if (failed or not a.quiet) and ctl is not None:
        print("controller's output (last lines):\n" + ctl.tail(), flush=True)
    return failed


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--types", default=None, help="the lcm-gen Python types (BUILD/python)")
    ap.add_argument("--port", type=int, default=0, help="the state port (commands: the next)")
    ap.add_argument("--expect-failure", metavar="ID", default=None,
                    help="pass only if the trace fails at the step of this id")
    ap.add_argument("-q", "--quiet", action="store_true", help="only failures and the verdict")
    ap.add_argument("trace")
    ap.add_argument("controller", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    if a.controller[:1] == ["--"]:
        a.controller = a.controller[1:]
    if not a.controller:
        ap.error("no controller: TRACE -- CONTROLLER ARGS...")
    if a.port and not 1 <= a.port <= 65534:
        ap.error("--port: 1 to 65534")
    if a.types:
        sys.path.insert(0, a.types)
    try:
        import lagsim as types
    except ImportError:
        ap.error("cannot import the lcm-gen Python types: --types BUILD/python")
    try:
        steps = read_trace(a.trace)
        ids = [s["id"] for s in steps if "id" in s]
        if a.expect_failure is not None and a.expect_failure not in ids:
            raise TraceError("%s has no step with id %r" % (a.trace, a.expect_failure))
        failed = run(a, steps, types)
    except TraceError as e:
        print("play.py: %s" % e, file=sys.stderr)
        return 2
    if a.expect_failure is None:
        print("FAILED" if failed else "PASSED: every step of %s held" % os.path.basename(a.trace))
        return 1 if failed else 0
    at = failed[0].get("id") if failed else None
    if at == a.expect_failure:
        print("PASSED: failed where expected, at step %s" % at)
        return 0
    print("FAILED: expected the trace to fail at step %s; %s" % (
        a.expect_failure, "it failed at %s" % (at or failed[0]["_where"]) if failed else "every step held"))
    return 1


if __name__ == "__main__":
    sys.exit(main())
