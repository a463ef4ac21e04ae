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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lagsim_client import (Client, ClientError, ERR_AMBIGUOUS, LOCATE_HOST, OK,  # noqa: E402
                           locate, pick_plant, plant_urls, plants_instead)


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


class Controller(object):
    """The protocol is the C client library's (lagsim_client.py, ctypes over
    liblagsim_client.so.1): the URLs, finding the plant, DESCRIBE until the scene comes,
    each state once with its copies answered, the scene rule, the generation on every
    command, every message decoded whole and bounded. This class keeps the options, how a
    run ends, the trace and the summary."""

    def __init__(self, name, default_prefix, model, description=""):
        self.name = name
        self.model = model
        p = argparse.ArgumentParser(prog=name, description=description)
        self.default_prefix = default_prefix
        p.add_argument("--prefix", default=None,
                       help="channel prefix (default: the only %s plant on the bus; none "
                            "yet: %s; several: they are named, exit 2)" % (model, default_prefix))
        p.add_argument("--url", default=None,
                       help="the plant's LCM URL, its lcm.url (default: the URL a host's "
                            "directory on LCM's default bus names for --prefix, else LCM's "
                            "default); commands go to the next port")
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
        self.client = None
        self.scene = None
        self.reference = None  # the latest reference (reference_t's fields), or None

    def _count(self, name):
        return self.client.counters()[name] if self.client else 0

    # the library's counts: messages dropped (undecodable, out of range, non-finite), copies
    # answered again, states held until the scene of their generation came
    dropped = property(lambda self: self._count("dropped"))
    repeats = property(lambda self: self._count("repeats"))
    held = property(lambda self: self._count("held"))

    def start(self):
        a = self.parser.parse_args()
        if not (a.timeout > 0 and a.duration >= 0 and math.isfinite(a.duration)):
            self.parser.error("--timeout must be > 0 and --duration a number >= 0")
        self.args = a
        self.t = _import_types(a.types, self.name)
        self._trace = open(a.trace, "w") if a.trace else None
        self._current = None
        self._stop = False

        def on_signal(signum, frame):
            self._stop = True

        signal.signal(signal.SIGINT, on_signal)
        signal.signal(signal.SIGTERM, on_signal)
        try:
            state_url, _ = plant_urls(a.url)
        except ValueError as e:
            self.parser.error("--url: %s" % e)
        if a.prefix is None:
            a.prefix = self._find_plant(a.url, state_url)
        elif not a.url:
            a.url = self._locate(a.prefix)
        self.client = Client(a.prefix, a.url)
        # subscribed: from here on no state is missed (test harnesses wait for this line)
        print("%s: waiting for the scene description on %s_SCENE" % (self.name, a.prefix),
              flush=True)
        deadline = self.client.now() + a.timeout
        while self.scene is None and not self._stop:
            left = deadline - self.client.now()
            if left <= 0:
                sys.stderr.write("%s: no scene on %s_SCENE within %g s: %s\n"
                                 % (self.name, a.prefix, a.timeout,
                                    plants_instead(a.url, a.prefix, 1.0)))
                sys.exit(1)
            self.scene = self.client.wait_scene(min(left, 0.25))  # DESCRIBE every 0.25 s
        if self.scene is None:  # SIGINT or SIGTERM while waiting: a run that ended, cleanly
            self.end = "signal"
            sys.exit(self.finish("states=0"))
        if self.scene.model != self.model:
            sys.stderr.write("%s: prefix %s runs model %r, not %s\n"
                             % (self.name, a.prefix, self.scene.model, self.model))
            sys.exit(1)
        self.params = dict(zip(self.scene.param_name, self.scene.param_value))
        return a

    def _find_plant(self, url, state_url):
        """The only plant of this model on the bus (lag_client_pick_plant: 1 s at most);
        none: the default prefix is waited on (a controller may start before its plant);
        several: named, exit 2."""
        rc, plant, msg = pick_plant(url, self.model, 1.0)
        if rc == OK:
            print("%s: the only %s plant on the bus: prefix %s" % (self.name, self.model,
                                                                   plant.prefix), flush=True)
            if not url and plant.url != state_url:  # a host's plant: on the URL it names
                self.args.url = plant.url
            return plant.prefix
        if rc == ERR_AMBIGUOUS:
            sys.stderr.write("%s: %s; choose one with --prefix\n" % (self.name, msg))
            sys.exit(2)
        print("%s: %s; waiting for prefix %s" % (self.name, msg, self.default_prefix), flush=True)
        return self.default_prefix

    def _locate(self, prefix):
        """--prefix without --url: the URL a host's directory on LCM's default bus names
        for prefix (lag_client_locate, 1 s at most), else None (LCM's default: a plant of
        that bus, or one not started yet)."""
        try:
            where, url = locate(prefix)
        except ClientError as e:
            self.parser.error("--prefix: %s" % e)
        if where != LOCATE_HOST:
            return None
        print("%s: prefix %s runs on %s (the host's directory)" % (self.name, prefix, url),
              flush=True)
        return url

    def _ended(self, heard):
        """Why the run ended (and self.end set), or None while it goes on."""
        if self._stop:
            self.end = "signal"
        elif self.client.stopped:
            self.end = "stop"
        elif self.client.now() - heard > self.args.timeout:
            self.end = "silence"
        return self.end

    def _heard(self):
        """How many messages came from the daemon (kept or dropped)."""
        k = self.client.counters()
        return sum(k[n] for n in ("states", "scenes", "statuses", "events", "references",
                                  "dropped", "copies"))

    def states(self):
        """Yields each newest state once until the run ends (self.end says why). A copy of
        the state answered last is answered by the library at once with the same command
        and not yielded: the control law runs once per state (docs/clients.md, the rule).
        A state is yielded only once self.scene (and self.params) is the scene of its
        generation (the library holds it until that scene came)."""
        a = self.args
        t_first = None
        heard, count = self.client.now(), self._heard()
        while True:
            if self._stop:  # a signal ends the run even while states keep coming
                self.end = "signal"
                return
            st = self.client.wait_state(0.05)
            n = self._heard()
            if n != count:
                heard, count = self.client.now(), n
            if st is None:
                if self._ended(heard):
                    return
                continue
            if st.generation != self.scene.generation:
                self.scene = self.client.latest_scene()
                self.params = dict(zip(self.scene.param_name, self.scene.param_value))
            self.reference = self.client.latest_reference()
            self._current = st
            if t_first is None:
                t_first = st.sim_time
            yield st
            if a.duration > 0 and \
                    st.sim_time - t_first >= a.duration - 0.5 * self.scene.control_period:
                self.end = "duration"
                return

    def command(self, sim_time, names, efforts):
        st = self._current
        efforts = [x if math.isfinite(x) else 0.0 for x in efforts]  # never send NaN
        self.client.send_command(sim_time, names, efforts)
        if self._trace and st is not None and st.sim_time == sim_time:
            # sim_time, positions, velocities, efforts sent: %.17g reads back to the same double
            f = [st.sim_time] + list(st.position) + list(st.velocity) + efforts
            self._trace.write(" ".join("%.17g" % x for x in f) + "\n")

    def finish(self, summary):
        if self._trace:
            self._trace.close()
        print("%s: summary end=%s %s dropped=%d repeats=%d"
              % (self.name, self.end, summary, self.dropped, self.repeats), flush=True)
        if self.client:
            self.client.close()
            self.client = None
        return 0
