#!/usr/bin/env python3
"""A controller written from docs/protocol.md alone: LCM (clients/python/lagsim_lcm.py,
ctypes over liblcm) and lcm-gen's Python types, no lagsim client library. It runs the
conformance law, and every trace of tests/protocol/traces/ holds against it; --break RULE
breaks one rule of the protocol on purpose, and the trace that guards that rule must fail
against it (the negative tests of tests/protocol.cmake).

    minimal.py --types BUILD/python --prefix P --url URL [--timeout S] [--break RULE]

RULE: describe (never asks for the scene: waits for one to come), copies (runs the law
again for a copy), silent (answers a copy with nothing), stamp (commands carry generation
0), generation (knows a state by its step and sim time alone and answers with the scene
it has), hold (answers a state whose scene has not come with the scene it has), forever
(keeps holding a state of an old generation after newer ones were answered: it asks for
that scene for ever), trailing (keeps messages with bytes after their end), nan (keeps
messages with a NaN or an infinity, or a name with a NUL inside), foreign (listens to every prefix), old (reads a
state of lagsim 0.1.0's types as one of the current generation), stop (does not end on
the stop event), events (ends on any event), directory (given no URL, runs on the default
bus without asking a host's directory where the plant is).
"""
import argparse
import math
import os
import re
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "clients", "python"))
from lagsim_lcm import LCM, plant_urls  # noqa: E402

RULES = ("describe", "copies", "silent", "stamp", "generation", "hold", "forever", "trailing",
         "nan", "foreign", "old", "stop", "events", "directory")
DESCRIBE_S = 0.25


def sound(m):
    """Every number finite, no string with a NUL inside (its one NUL is its last byte,
    which lcm-gen's decoder strips)."""
    for k in m.__slots__:
        v = getattr(m, k)
        for x in (v if isinstance(v, (list, tuple)) else [v]):
            if isinstance(x, float) and not math.isfinite(x):
                return False
            if isinstance(x, str) and "\0" in x:
                return False
    return True


class Minimal:
    def __init__(self, a, t):
        self.a, self.t, self.brk = a, t, a.brk
        if not a.url and self.brk != "directory":
            a.url = self.locate()
        state_url, command_url = plant_urls(a.url)
        self.lc, self.lc_cmd = LCM(state_url), LCM(command_url)
        self.scene = None      # the scene of the newest generation heard
        self.held = None       # a state waiting for the scene of its generation
        self.last = None       # (generation, step, sim_time) answered last, and its bytes
        self.next_ask = 0.0
        self.stopped = False
        self.heard = time.monotonic()
        self.laws = 0
        pre = ".*" if self.brk == "foreign" else re.escape(a.prefix)
        for suffix, fn in (("STATE", self.on_state), ("SCENE", self.on_scene),
                           ("EVENT", self.on_event)):
            self.lc.subscribe(pre + "_" + suffix, fn)

    def locate(self):
        """No URL: where a host's directory on the default bus says the plant runs
        (docs/protocol.md, "A host's directory"), or None (the default bus)."""
        here = plant_urls(None)[0]
        found = []  # "here", or the plant's state URL

        def on(channel, data):
            if found:
                return
            if not channel.endswith("_EVENT"):
                found.append("here")  # its state, status or scene
                return
            ev = self.decode(self.t.event_t, data)
            if ev is None:
                return
            if ev.kind != "plant":
                found.append("here")
                return
            try:
                url = plant_urls(ev.detail)[0]
            except ValueError:
                return
            if url != here:
                found.append(url)

        lc = LCM(here)
        lc.subscribe(re.escape(self.a.prefix) + "_(EVENT|STATE|STATUS|SCENE)", on)
        end = time.monotonic() + 1.0
        while not found and time.monotonic() < end:
            lc.handle_timeout(max(1, int((end - time.monotonic()) * 1000)))
        lc.close()
        return found[0] if found and found[0] != "here" else None

    # -- decoding: a message counts only if it is whole (encodes back to its bytes) and
    # every number in it is finite
    def decode(self, cls, data):
        try:
            m = cls.decode(data)
        except Exception:
            if self.brk == "old" and cls is self.t.joint_state_t and self.scene is not None:
                return self.decode_old(cls, data)
            return None
        for k in m.__slots__:
            if isinstance(getattr(m, k), map):
                setattr(m, k, list(getattr(m, k)))
        if self.brk != "trailing" and m.encode() != data:
            return None
        if self.brk != "nan" and not sound(m):
            return None
        return m

    def decode_old(self, cls, data):
        """--break old: an earlier version's state read as today's, generation the scene's."""
        try:
            m = cls.decode(cls._get_packed_fingerprint() + data[8:] + bytes(8))
        except Exception:
            return None
        m.generation = self.scene.generation
        return m

    # -- the channels
    def on_scene(self, channel, data):
        self.heard = time.monotonic()
        sc = self.decode(self.t.scene_t, data)
        if sc is not None:
            self.scene = sc

    def on_event(self, channel, data):
        self.heard = time.monotonic()
        ev = self.decode(self.t.event_t, data)
        if ev is None:
            return
        if (ev.kind == "stop" and self.brk != "stop") or self.brk == "events":
            self.stopped = True

    def on_state(self, channel, data):
        self.heard = time.monotonic()
        st = self.decode(self.t.joint_state_t, data)
        if st is None:
            return
        key = (st.step, st.sim_time) if self.brk == "generation" else \
            (st.generation, st.step, st.sim_time)
        if self.last is not None and key == self.last[0] and self.brk != "copies":
            if self.brk != "silent":  # a copy: the answer already sent, again
                self.lc_cmd.publish(self.a.prefix + "_COMMAND", self.last[1])
            return
        if self.scene is None or (self.brk not in ("generation", "hold") and
                                  st.generation != self.scene.generation):
            self.held = st  # the scene rule: wait for the scene of its generation
            self.ask(now=self.scene is not None)
            return
        if self.brk != "forever":
            self.held = None  # a newer state was answered: the held one is obsolete
        self.answer(st, key)

    def ask(self, now=False):
        if self.brk == "describe" or (not now and time.monotonic() < self.next_ask):
            return
        req = self.t.control_t()
        req.utime, req.request = int(time.time() * 1e6), self.t.control_t.DESCRIBE
        self.lc_cmd.publish(self.a.prefix + "_CONTROL", req.encode())
        self.next_ask = time.monotonic() + DESCRIBE_S

    def answer(self, st, key):
        sc = self.scene
        p = dict(zip(sc.param_name, sc.param_value))
        cmd = self.t.joint_command_t()
        cmd.utime, cmd.sim_time = int(time.time() * 1e6), st.sim_time
        cmd.generation = 0 if self.brk == "stamp" else st.generation
        for j, name in enumerate(sc.joint_name):
            if sc.actuated[j]:
                i = list(st.name).index(name)
                cmd.name.append(name)
                cmd.effort.append(-(p["kp"] * st.position[i] + p["kd"] * st.velocity[i]))
        cmd.num_joints = len(cmd.name)
        self.laws += 1
        print("conformance: law generation=%d sim_time=%.17g" % (st.generation, st.sim_time),
              flush=True)
        data = cmd.encode()
        self.lc_cmd.publish(self.a.prefix + "_COMMAND", data)
        self.last = (key, data)

    def run(self):
        print("minimal.py: waiting for the scene on %s_SCENE" % self.a.prefix, flush=True)
        while self.scene is None:  # DESCRIBE at once, then every 0.25 s, until it comes
            self.ask()
            self.lc.handle_timeout(20)
            if time.monotonic() - self.heard > self.a.timeout:
                return 1
        while not self.stopped and time.monotonic() - self.heard < self.a.timeout:
            self.lc.handle_timeout(20)
            if self.held is not None:
                if self.held.generation == self.scene.generation:
                    st, self.held = self.held, None
                    self.answer(st, (st.generation, st.step, st.sim_time))
                else:
                    self.ask()
        print("minimal.py: summary end=%s laws=%d" % ("stop" if self.stopped else "silence",
                                                      self.laws), flush=True)
        return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--types", default=None)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--url", default=None)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--break", dest="brk", choices=RULES, default=None)
    a = ap.parse_args()
    if a.types:
        sys.path.insert(0, a.types)
    import lagsim
    return Minimal(a, lagsim).run()


if __name__ == "__main__":
    sys.exit(main())
