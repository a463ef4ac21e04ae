"""What every Python example controller shares: options, connect, wait for the scene,
answer states until the run ends, a summary line.

    from lagsim_controller import Controller
    ctl = Controller("dipc_balance.py", default_prefix="DIPC", model="dipc")
    ctl.parser.add_argument(...)                 # the example's own options
    a = ctl.start()                              # parses argv, connects, waits for the scene
    for st in ctl.states():                      # each newest state once, until the end
        m0 = ctl.params["m0"]                    # the scene's parameters, of this state's
        ctl.command(st.sim_time, ["theta0"], [u])  # scene (ctl.scene: the whole scene_t)
    ctl.finish("states=%d ..." % n)              # prints "<name>: summary end=... states=..."

A run ends (and states() returns) when the daemon publishes its `stop` event, when
nothing came from the daemon (no state, status or event) for --timeout wall seconds, when
--duration seconds of sim time have passed since the first state, or on SIGINT/SIGTERM.
ctl.end says which: stop, silence, duration or signal. --trace FILE writes one line per
answered state: sim time, positions, velocities, efforts sent, each as %.17g. Exit status: 0 for all of these;
1 when no scene came within --timeout or the scene is another model's; 2 bad usage.
"""
import argparse
import math
import os
import signal
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lagsim_lcm import LCM, plant_urls  # noqa: E402

DESCRIBE_S = 0.25  # the pace of DESCRIBE while a scene is awaited (the C client's too)


def _import_types(types_dir, name):
    if types_dir:
        sys.path.insert(0, types_dir)
    try:
        import lagsim
        return lagsim
    except ImportError:
        sys.stderr.write("%s: cannot import the lcm-gen Python types 'lagsim'; set "
                         "PYTHONPATH=<build>/python or pass --types DIR\n" % name)
        sys.exit(2)


def _edits(a, b):
    """Edits (insert, delete, substitute) between a and b, capped at 3."""
    row = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        diag, row[0] = row[0], i
        for j in range(1, len(b) + 1):
            up = row[j]
            row[j] = min(diag + (a[i - 1] != b[j - 1]), up + 1, row[j - 1] + 1)
            diag = up
    return min(row[len(b)], 3)


def _nearness(heard, asked):
    """0 the same but for letter case, 1 it starts with the asked prefix, 2 + edits (at
    most 2); -1 not near (lag_client_plants_instead's rule)."""
    if heard.lower() == asked.lower():
        return 0
    if asked and heard.lower().startswith(asked.lower()):
        return 1
    e = _edits(heard, asked)
    return 2 + e if e <= 2 else -1


def _sound(v):
    """Every number finite; no string with a NUL inside (lcm-gen's decoder strips the one
    NUL a string ends with and keeps any other, which encodes back to the same bytes)."""
    if isinstance(v, float):
        return math.isfinite(v)
    if isinstance(v, str):
        return "\0" not in v
    if isinstance(v, (list, tuple)):
        return all(_sound(x) for x in v)
    return True


class Controller(object):
    def __init__(self, name, default_prefix, model, description=""):
        self.name = name
        self.model = model
        p = argparse.ArgumentParser(prog=name, description=description)
        self.default_prefix = default_prefix
        p.add_argument("--prefix", default=None,
                       help="channel prefix (default: the only %s plant on the bus; none "
                            "yet: %s; several: they are named, exit 2)" % (model, default_prefix))
        p.add_argument("--url", default=None,
                       help="the plant's LCM URL, its lcm.url (default: LCM's default); "
                            "commands go to the next port")
        p.add_argument("--duration", type=float, default=0.0,
                       help="stop after S s of sim time from the first state (default 0: "
                            "until the daemon stops)")
        p.add_argument("--timeout", type=float, default=5.0,
                       help="wall s without a scene, or without any message from the "
                            "daemon once running, before ending (default 5)")
        p.add_argument("--types", default=None,
                       help="directory holding the lagsim Python types")
        p.add_argument("--trace", default=None,
                       help="write each answered state and the efforts sent to this file")
        p.add_argument("-q", action="store_true", help="quiet: summary only")
        self.parser = p
        self.end = None
        self.dropped = 0
        self.scene = None
        self.reference = None  # the latest reference_t (the scene's reference), or None

    def start(self):
        a = self.parser.parse_args()
        if not (a.timeout > 0 and a.duration >= 0 and math.isfinite(a.duration)):
            self.parser.error("--timeout must be > 0 and --duration a number >= 0")
        self.args = a
        self.t = _import_types(a.types, self.name)
        self._trace = open(a.trace, "w") if a.trace else None
        self._current = None
        self._last = None  # (generation, step, sim_time, encoded command) of the last answer
        self.repeats = 0   # copies of a state answered again
        self.held = 0      # states held until the scene of their generation came
        self._stop = False

        def on_signal(signum, frame):
            self._stop = True

        signal.signal(signal.SIGINT, on_signal)
        signal.signal(signal.SIGTERM, on_signal)
        try:
            state_url, command_url = plant_urls(a.url)
        except ValueError as e:
            self.parser.error("--url: %s" % e)
        self.lc = LCM(state_url)                 # states, status, events, scene
        self.lc_cmd = LCM(command_url) if command_url != state_url else self.lc
        self._state = None
        self._stopped = False
        self._heard = time.monotonic()
        if a.prefix is None:
            a.prefix = self._find_plant(state_url) or self.default_prefix
        ch = a.prefix + "_"
        self.lc.subscribe(ch + "SCENE", self._on_scene)
        self.lc.subscribe(ch + "STATE", self._on_state)
        self.lc.subscribe(ch + "EVENT", self._on_event)
        self.lc.subscribe(ch + "STATUS", self._on_status)
        self.lc.subscribe(ch + "REFERENCE", self._on_reference)
        # subscribed: from here on no state is missed (test harnesses wait for this line)
        print("%s: waiting for the scene description on %sSCENE" % (self.name, ch), flush=True)
        deadline = time.monotonic() + a.timeout
        next_ask = 0.0
        while self.scene is None and not self._stop:
            now = time.monotonic()
            if now >= deadline:
                sys.stderr.write("%s: no scene on %sSCENE within %g s: %s\n"
                                 % (self.name, ch, a.timeout, self._instead(state_url)))
                sys.exit(1)
            if now >= next_ask:  # DESCRIBE every 0.25 s until the scene comes
                self._ask_scene()
                next_ask = now + DESCRIBE_S
            self.lc.handle_timeout(50)
        if self.scene is None:  # SIGINT or SIGTERM while waiting: a run that ended, cleanly
            self.end = "signal"
            sys.exit(self.finish("states=0"))
        if self.scene.model != self.model:
            sys.stderr.write("%s: prefix %s runs model %r, not %s\n"
                             % (self.name, a.prefix, self.scene.model, self.model))
            sys.exit(1)
        self.params = dict(zip(self.scene.param_name, self.scene.param_value))
        return a

    def _find_plant(self, state_url):
        """The only plant of this model on the bus, by the C library's rule
        (lag_client_pick_plant): every <PREFIX>_STATE, _STATUS, _EVENT or _SCENE heard on
        the state URL names a plant, which is asked for its scene (DESCRIBE) until it
        comes; listens 1 s at most, 0.5 s after the first plant once all are described.
        Returns its prefix; None when there is none (the caller waits on its default: a
        controller may start before its plant); several: named, exit 2."""
        found = self._plants()
        mine = sorted(p for p, m in found.items() if m == self.model)
        heard = ", ".join("%s (%s)" % (p, found[p] or "model unknown") for p in sorted(found))
        if len(mine) == 1:
            print("%s: the only %s plant on the bus: prefix %s" % (self.name, self.model, mine[0]),
                  flush=True)
            return mine[0]
        if len(mine) > 1:
            sys.stderr.write("%s: %d %s plants on %s: %s; choose one with --prefix\n"
                             % (self.name, len(mine), self.model, state_url,
                                ", ".join(mine)))
            sys.exit(2)
        print("%s: no %s plant on %s%s; waiting for prefix %s"
              % (self.name, self.model, state_url, " (heard: %s)" % heard if found else "",
                 self.default_prefix), flush=True)
        return None

    def _instead(self, state_url):
        """What the bus has instead of a plant on --prefix (no scene came: a misspelt
        prefix?), as the C library says it (lag_client_plants_instead): the plants heard
        and the one meant when a heard prefix is the asked one in other letter case,
        starts with it, or is at most 2 edits from it."""
        asked = self.args.prefix
        found = self._plants()
        if not found:
            return "no plant heard on %s within 1 s (is lagsimd running on this LCM URL?)" \
                % state_url
        heard = ", ".join("%s (%s)" % (p, found[p] or "model unknown") for p in sorted(found))
        near = [(_nearness(p, asked), p) for p in sorted(found)]
        near = sorted((k, p) for k, p in near if k >= 0)
        return "no plant on prefix %s; plants heard on %s: %s%s" % (
            asked, state_url, heard, "; did you mean %s?" % near[0][1] if near else "")

    def _plants(self):
        """{prefix: model (None until its scene came)} of the plants heard on the bus: 1 s
        at most, 0.5 s after the first once every one is described."""
        found, asked = {}, {}   # prefix -> model (None until its scene came); last ask

        def on_any(channel, data):
            for suf in ("_STATE", "_STATUS", "_EVENT", "_SCENE"):
                if channel.endswith(suf) and len(channel) > len(suf):
                    pre = channel[:-len(suf)]
                    found.setdefault(pre, None)
                    if suf == "_SCENE":
                        sc = self._decode(self.t.scene_t, data)
                        if sc is not None and sc.prefix == pre:
                            found[pre] = sc.model
                    return

        dropped = self.dropped
        sub = self.lc.subscribe(".*", on_any)
        t0, first = time.monotonic(), None
        while not self._stop:
            now = time.monotonic()
            if found and first is None:
                first = now
            for pre in [p for p, m in found.items() if m is None and now - asked.get(p, -1) >= 0.25]:
                req = self.t.control_t()
                req.utime = int(time.time() * 1e6)
                req.request = self.t.control_t.DESCRIBE
                self.lc_cmd.publish(pre + "_CONTROL", req.encode())
                asked[pre] = now
            if now - t0 >= 1.0 or (first is not None and now - first >= 0.5 and
                                   all(m is not None for m in found.values())):
                break
            self.lc.handle_timeout(50)
        self.lc.unsubscribe(sub)
        self.dropped = dropped  # other plants' messages are not this run's
        return found

    def _decode(self, cls, data):
        """The message of type `cls` in `data`, or None (counted in `dropped`). Like the C
        client, it keeps only a message that decodes whole: lcm-gen's decoder reads a
        string without its NUL, or with bytes left over, as if nothing were wrong, so the
        message must encode back to the very bytes that came; every number in it must be
        finite, and no string may hold a NUL but the one it ends with (the C wire module's
        rule). (lcm-gen gives boolean arrays as one-shot `map` iterators: they become
        lists.)"""
        try:
            m = cls.decode(data)
            for k in m.__slots__:
                if isinstance(getattr(m, k), map):
                    setattr(m, k, list(getattr(m, k)))
            if m.encode() == data and all(_sound(getattr(m, k)) for k in m.__slots__):
                return m
        except Exception:
            pass
        self.dropped += 1
        return None

    def _ask_scene(self):
        req = self.t.control_t()
        req.utime = int(time.time() * 1e6)
        req.request = self.t.control_t.DESCRIBE
        self.lc_cmd.publish(self.args.prefix + "_CONTROL", req.encode())

    def _on_scene(self, channel, data):
        self._heard = time.monotonic()
        sc = self._decode(self.t.scene_t, data)
        if sc is not None:
            self.scene = sc
            self.params = dict(zip(sc.param_name, sc.param_value))

    def _ended(self):
        """Why the run ended (and self.end set), or None while it goes on."""
        if self._stop:
            self.end = "signal"
        elif self._stopped:
            self.end = "stop"
        elif time.monotonic() - self._heard > self.args.timeout:
            self.end = "silence"
        return self.end

    def _with_scene(self, st):
        """st, or the newest state since, once the scene of its generation came (the
        daemon publishes it just before the first state of a generation; DESCRIBE asks
        for it again every 0.25 s, for when UDP lost it); None when the run ended first.
        So the control law never answers a state with another run's or scene's
        parameters (docs/clients.md, the scene rule)."""
        next_ask = 0.0
        while st.generation != self.scene.generation:
            if self._ended():
                return None
            now = time.monotonic()
            if now >= next_ask:
                self._ask_scene()
                next_ask = now + DESCRIBE_S
            self.lc.handle_timeout(20)
            if self._state is not None:  # a newer state: that one is answered
                st, self._state = self._state, None
        return st

    def _on_state(self, channel, data):
        self._heard = time.monotonic()
        st = self._decode(self.t.joint_state_t, data)
        if st is not None:
            self._state = st

    def _on_reference(self, channel, data):
        """The scene's reference, published just before each state with its sim_time."""
        self._heard = time.monotonic()
        r = self._decode(self.t.reference_t, data)
        if r is not None:
            self.reference = r

    def _on_status(self, channel, data):
        self._heard = time.monotonic()

    def _on_event(self, channel, data):
        ev = self._decode(self.t.event_t, data)
        if ev is None or ev.kind != "plant":  # a host's directory's, not the plant's own
            self._heard = time.monotonic()
        if ev is not None and ev.kind == "stop":
            self._stopped = True

    def states(self):
        """Yields each newest state once until the run ends (self.end says why). A copy of
        the state answered last (same generation, step and sim time: the daemon published
        it again because no answer reached it) is answered at once with the same command
        and not yielded: every state received is answered, the control law runs once per
        state (a law run for every copy would cost a think time per copy and fall behind
        for good: docs/clients.md, the rule). A state is yielded only once self.scene (and
        self.params) is the scene of its generation."""
        a = self.args
        t_first = None
        while True:
            while self._state is None:
                if self._ended():
                    return
                self.lc.handle_timeout(50)
            while self.lc.handle_timeout(0):  # drain what is queued: answer the newest
                pass
            st, self._state = self._state, None
            last = self._last
            if last is not None and (st.generation, st.step, st.sim_time) == last[:3]:
                self.lc_cmd.publish(self.args.prefix + "_COMMAND", last[3])
                self.repeats += 1
                continue
            if st.generation != self.scene.generation:
                self.held += 1
                st = self._with_scene(st)
                if st is None:
                    return
            self._current = st
            if t_first is None:
                t_first = st.sim_time
            yield st
            if a.duration > 0 and \
                    st.sim_time - t_first >= a.duration - 0.5 * self.scene.control_period:
                self.end = "duration"
                return

    def command(self, sim_time, names, efforts):
        cmd = self.t.joint_command_t()
        cmd.utime = int(time.time() * 1e6)
        cmd.sim_time = sim_time
        st = self._current
        # the generation of the state it answers (0: none yet, answers no state)
        cmd.generation = st.generation if st is not None else 0
        cmd.num_joints = len(names)
        cmd.name = list(names)
        cmd.effort = [x if math.isfinite(x) else 0.0 for x in efforts]  # never send NaN
        data = cmd.encode()
        self.lc_cmd.publish(self.args.prefix + "_COMMAND", data)
        if st is not None and st.sim_time == sim_time:
            self._last = (st.generation, st.step, sim_time, data)
        if self._trace and st is not None and st.sim_time == sim_time:
            # sim_time, positions, velocities, efforts sent: %.17g reads back to the same double
            f = [st.sim_time] + list(st.position) + list(st.velocity) + cmd.effort
            self._trace.write(" ".join("%.17g" % x for x in f) + "\n")

    def finish(self, summary):
        if self._trace:
            self._trace.close()
        print("%s: summary end=%s %s dropped=%d repeats=%d"
              % (self.name, self.end, summary, self.dropped, self.repeats), flush=True)
        if self.lc_cmd is not self.lc:
            self.lc_cmd.close()
        self.lc.close()
        return 0
