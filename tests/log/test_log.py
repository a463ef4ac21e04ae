#!/usr/bin/env python3
"""lagsimd --log and --replay end to end, with the example LQR controller (dipc_lqr) in
lockstep, the log read back by this file's own reader, by liblcm's C reader (ctypes),
by lcm.jar's reader (what lcm-spy's log playback reads with) and by lcm-logplayer.

    test_log.py --bin BUILD/bin --types BUILD/python --source SRC CASE

Cases:
  lqr            60 s of sim time: 6001 states, 0 gaps, every command, replay difference 0;
                 a log changed by one ulp in one state fails the replay (exit 1), within
                 --tolerance it passes
  lqr_effects    the same with damping, friction, stops, a lagged and saturating actuator,
                 disturbances and noise: the inputs are logged, replay exact (efforts too);
                 without the inputs (as lcm-logger would record) the replay says it is
                 approximate and fails at tolerance 0
  gaps           states removed from a log (as UDP loses them under lcm-logger): each gap
                 reported, the replay restarts after it; exact again for rk4 without
                 memory, not compared (and said) for a scene whose restart cannot be exact
  readers        liblcm's reader, lcm.jar's reader and lcm-logplayer (into LCM's file:// writer,
                 at the log's pace) read the log whole
  cli            option errors: exit 2 with the option named, nothing run
  flood          3 s of refused commands on a logged realtime run: a bounded sample of them
                 logged, every state, the counts in the log and the summary, replay exact
  flood_applied  3 s of commands and pause/resume requests, each applied: the received
                 records' bytes within their buckets over the log's clock, every state,
                 the counts said, replay exact
"""
import argparse
import ctypes
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zlib
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
import lcm_log  # noqa: E402  (tests/common: LCM's log format)
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


# ---------------------------------------------------------------- LCM logs, read here
def read_log(path):
    """[(eventnum, timestamp, channel, data)] of a whole, undamaged log (raises otherwise)."""
    return [r[:4] for r in lcm_log.records(path, whole=True)]


def write_log(path, recs):
    """Writes [(eventnum, timestamp, channel, data)], numbered again from 0."""
    lcm_log.write_log(path, [r[1:] for r in recs])


def read_log_liblcm(path):
    """The same through liblcm's own reader (lcm/eventlog.h)."""
    lib = ctypes.CDLL("liblcm.so.1")

    class Event(ctypes.Structure):
        _fields_ = [("eventnum", ctypes.c_int64), ("timestamp", ctypes.c_int64),
                    ("channellen", ctypes.c_int32), ("datalen", ctypes.c_int32),
                    ("channel", ctypes.c_void_p), ("data", ctypes.c_void_p)]
    lib.lcm_eventlog_create.restype = ctypes.c_void_p
    lib.lcm_eventlog_create.argtypes = [ctypes.c_char_p, ctypes.c_char_p]
    lib.lcm_eventlog_read_next_event.restype = ctypes.POINTER(Event)
    lib.lcm_eventlog_read_next_event.argtypes = [ctypes.c_void_p]
    lib.lcm_eventlog_free_event.argtypes = [ctypes.POINTER(Event)]
    lib.lcm_eventlog_destroy.argtypes = [ctypes.c_void_p]
    log = lib.lcm_eventlog_create(path.encode(), b"r")
    out = []
    while True:
        e = lib.lcm_eventlog_read_next_event(log)
        if not e:
            break
        ev = e.contents
        out.append((ev.eventnum, ev.timestamp, ctypes.string_at(ev.channel, ev.channellen).decode(),
                    ctypes.string_at(ev.data, ev.datalen)))
        lib.lcm_eventlog_free_event(e)
    lib.lcm_eventlog_destroy(log)
    return out


class Run:
    def __init__(self, a, tmp):
        self.a, self.tmp = a, tmp
        self.bin = a.bin
        sys.path.insert(0, a.types)
        import lagsim  # lcm-gen's Python types: decoders that share nothing with the C code
        self.t = lagsim

    def lagsimd(self, *args, timeout=120):
        p = subprocess.run([os.path.join(self.bin, "lagsimd"), *args], capture_output=True,
                           text=True, timeout=timeout)
        print(f"$ lagsimd {' '.join(args)}\n  exit {p.returncode}\n" +
              "".join("  | " + l + "\n" for l in (p.stdout + p.stderr).splitlines()[-14:]), flush=True)
        return p

    def record(self, config, prefix, log, duration, *sets, lqr_args=()):
        """A lockstep run with dipc_lqr, logged; returns lagsimd's CompletedProcess."""
        # --timeout 30: the daemon starts once the controller is subscribed, and a loaded
        # machine's may take more than the default 5 s to publish its scene
        lqr = subprocess.Popen([os.path.join(self.bin, "dipc_lqr"), "--prefix", prefix, "-q",
                                "--timeout", "30", *lqr_args], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT,
                               text=True)
        try:
            check(waits.subscribed(lqr) is not None, "dipc_lqr subscribed")
            p = self.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--set",
                             "realtime.mode=lockstep", *sets, "--duration", str(duration),
                             "-q", "--log", log, "--force")  # a case may record twice
            out, _ = lqr.communicate(timeout=30)
        finally:
            if lqr.poll() is None:
                lqr.kill()
        print("  dipc_lqr: " + (out.strip().splitlines() or [""])[-1])
        check(lqr.returncode == 0, f"dipc_lqr ran to the daemon's stop (exit {lqr.returncode})")
        return p

    def states(self, records, prefix):
        out = []
        for num, ts, ch, data in records:
            if ch == prefix + "_STATE":
                out.append(self.t.joint_state_t.decode(data))
        return out


def replay_report(p):
    out = p.stdout + p.stderr
    m = re.search(r": (\d+) states compared on \S+ \((\d+) restarts at resets, (\d+) gaps", out)
    d = re.search(r"^max difference = (\S+)$", out, re.M)
    return (int(m.group(1)) if m else -1, int(m.group(3)) if m else -1,
            float(d.group(1)) if d else None, out)


def check_log_whole(r, log, prefix, n_states, period_ticks, commands):
    recs = read_log(log)
    check(all(num == k for k, (num, _, _, _) in enumerate(recs)), "records numbered 0, 1, 2, ...")
    check(all(recs[k][1] <= recs[k + 1][1] for k in range(len(recs) - 1)),
          "timestamps never go back")
    chans = [ch[len(prefix) + 1:] for _, _, ch, _ in recs]
    check(chans[:3] == ["SCENE", "EVENT", "STATE"], f"from the start: {chans[:4]}")
    st = r.states(recs, prefix)
    steps = [s.step for s in st]
    check(len(st) == n_states, f"{len(st)} states logged, {n_states} expected")
    check(steps == [k * period_ticks for k in range(n_states)], "every state one period after the last: 0 gaps")
    # every command received: what the daemon counted in its last status (a command that
    # UDP lost never reached it: lockstep then steps on after its timeout)
    last = r.t.status_t.decode([d for _, _, ch, d in recs if ch == prefix + "_STATUS"][-1])
    counted = (last.commands_accepted + last.commands_ignored  # ignored: a second answer to a retried state
               + sum(getattr(last, k) for k in dir(last) if k.startswith("rejected_")))
    check(chans.count("COMMAND") == counted and counted >= commands - 10,
          f"{chans.count('COMMAND')} commands logged, {counted} received by the daemon "
          f"({commands} sent if UDP lost none)")
    # the log's clock: a lockstep run is stamped at the pace of its sim time
    ts = [t for _, t, ch, _ in recs if ch == prefix + "_STATE"]
    check(ts[-1] - ts[0] == round(st[-1].sim_time * 1e6),
          f"states stamped on sim time: {ts[-1] - ts[0]} us for {st[-1].sim_time} s")
    return recs


def tamper(r, recs, prefix, index, joint):
    """The records with state `index`'s position[joint] moved by one ulp."""
    out, k = [], 0
    for rec in recs:
        if rec[2] == prefix + "_STATE":
            if k == index:
                s = r.t.joint_state_t.decode(rec[3])
                q = list(s.position)
                q[joint] = q[joint] + abs(q[joint]) * 2.0 ** -52 if q[joint] else 5e-324
                s.position = q
                rec = (rec[0], rec[1], rec[2], s.encode())
            k += 1
        out.append(rec)
    return out


# ---------------------------------------------------------------- cases
def case_lqr(r, a, tmp, effects=False):
    prefix = f"LG{os.getpid()}{'E' if effects else ''}"
    log = os.path.join(tmp, "run.lcm")
    config = os.path.join(a.source, "config", "dipc.yaml")
    if effects:
        config = os.path.join(tmp, "effects.yaml")
        with open(config, "w") as f:
            f.write(EFFECTS_SCENE)
    p = r.record(config, prefix, log, 60)
    check(p.returncode == 0, "lagsimd --log: exit 0")
    recs = check_log_whole(r, log, prefix, 6001, 10, 6000)
    chans = [ch for _, _, ch, _ in recs]
    check(chans.count(prefix + "_INPUT") == (6000 if effects else 0),
          f"{chans.count(prefix + '_INPUT')} commanded inputs logged (an actuator lag: one per period)")
    check(recs == read_log_liblcm(log), "liblcm's reader reads the same records")
    s2c = subprocess.run([os.path.join(r.bin, "lagsim-log2csv"), log, "-o", os.path.join(tmp, "csv")],
                         capture_output=True, text=True)
    check(f"{prefix}_STATE: joint_state_t, 6001 messages over 60.000 s of log time (100 /s)" in s2c.stdout
          and "gaps 0 (0 states missing" in s2c.stdout, "lagsim-log2csv: 6001 states at 100 Hz, 0 gaps")

    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--replay", log)
    n, gaps, diff, out = replay_report(rp)
    check(rp.returncode == 0 and n == 6000 and gaps == 0 and diff == 0.0,
          f"replay: 6000 states compared ({n}), 0 gaps ({gaps}), difference 0 ({diff}), exit 0")
    if effects:
        check("max |effort - effort_log| = 0\n" in out, "replay: the lagged efforts are exact too")

    # one ulp in one state's theta1: the check fails; with a tolerance it passes
    bad = os.path.join(tmp, "tampered.lcm")
    write_log(bad, tamper(r, recs, prefix, 3000, 1))
    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--replay", bad)
    n, gaps, diff, out = replay_report(rp)
    check(rp.returncode == 1 and diff is not None and 0 < diff < 1e-15 and "FAILED" in out,
          f"a log changed by one ulp fails: exit {rp.returncode}, difference {diff}")
    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--replay", bad,
                   "--tolerance", "1e-12")
    check(rp.returncode == 0, "... and passes within --tolerance 1e-12")
    # another scene (a different cart mass): the check fails
    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--set",
                   "parameters.m0=1.6", "--replay", log)
    check(rp.returncode == 1 and "FAILED" in rp.stderr, "the same log against another scene fails")
    # ... an edited scene (a cart mass, the initial angles): the failure names each key that
    # differs with both values, and the --set that gives the log's scene, which then passes
    edited = ["--set", "parameters.m0=1.6", "--set", "initial.q=[0,0.07,-0.03]"]
    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", *edited, "--replay", log)
    said = [l for l in rp.stderr.splitlines() if "differs from this one" in l]
    m0 = re.search(r"parameters\.m0: log (\S+), here 1\.6", said[0]) if said else None
    check(rp.returncode == 1 and m0 and "initial.q: log [" in said[0] and
          "here [0,0.07,-0.03]" in said[0],
          "the edited scene's failure names parameters.m0 and initial.q with both values: %s"
          % (said[:1],))
    sets = re.search(r"the log's scene is this one with: (.*)$", rp.stderr, re.M)
    check(sets and ("--set parameters.m0=%s" % (m0.group(1) if m0 else "?")) in sets.group(1),
          "... and says the --set that gives the log's scene: %s" % (sets.group(1) if sets else None))
    if sets:
        rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", *edited,
                       *sets.group(1).split(), "--replay", log)
        check(rp.returncode == 0, "the edited scene with that --set replays the log: exit %d"
              % rp.returncode)

    if effects:
        # as lcm-logger records it: the bus only, no inputs
        bus = os.path.join(tmp, "bus.lcm")
        write_log(bus, [rec for rec in recs if rec[2] != prefix + "_INPUT"])
        rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--replay", bus)
        n, gaps, diff, out = replay_report(rp)
        check(rp.returncode == 1 and "approximate" in out and diff is not None and diff > 0,
              f"without the inputs: said approximate, difference {diff} > 0, exit 1")
        rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--replay", bus,
                       "--tolerance", "1")
        check(rp.returncode == 0, "... and passes with --tolerance 1")


EFFECTS_SCENE = """model: dipc
initial:
  q: [0, 0.05, -0.03]
publish_hz: 100
effects:
  damping: {theta1: 0.002, theta2: 0.002}
  friction: {theta0: {static: 0.3, kinetic: 0.2}}
  limits: {theta0: {lower: -2, upper: 2, restitution: 0.3}}
  actuator: {theta0: {max: 40, lag: 0.004}}
  disturbance:
    - {t: 5.0, joint: theta1, impulse: 0.01}
    - {t: 20.0, joint: theta0, force: 2.0, duration: 0.5}
  noise: {seed: 7, q: {theta1: 1e-4, theta2: 1e-4}, qd: {theta0: 1e-3}}
"""


def case_lqr_effects(r, a, tmp):
    case_lqr(r, a, tmp, effects=True)


def drop_states(r, recs, prefix, indices):
    out, k = [], 0
    for rec in recs:
        if rec[2] == prefix + "_STATE":
            k += 1
            if k - 1 in indices:
                continue
        out.append(rec)
    return out


def case_gaps(r, a, tmp):
    for effects in (False, True):
        prefix = f"LG{os.getpid()}{'GE' if effects else 'G'}"
        log = os.path.join(tmp, "run.lcm")
        config = os.path.join(a.source, "config", "dipc.yaml")
        if effects:
            config = os.path.join(tmp, "effects.yaml")
            with open(config, "w") as f:
                f.write(EFFECTS_SCENE)
        check(r.record(config, prefix, log, 20).returncode == 0, "a 20 s run logged")
        recs = read_log(log)
        lossy = os.path.join(tmp, "lossy.lcm")
        write_log(lossy, drop_states(r, recs, prefix, {100, 1000, 1001}))
        rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--replay", lossy)
        n, gaps, diff, out = replay_report(rp)
        check(gaps == 2 and "gap: states missing between t = 0.99 s and t = 1.01 s (step 990 to 1010)"
              in out and "gap: states missing between t = 9.99 s and t = 10.02 s" in out,
              f"two gaps reported where they are ({gaps})")
        if not effects:
            # rk4 without effects keeps nothing but (q, qd): exact again after each gap
            check(rp.returncode == 0 and n == 2000 - 3 - 2 and diff == 0.0,
                  f"restarted after each gap: {n} states compared, difference {diff}, exit 0")
        else:
            # noise, lag and friction: a restart from a logged state cannot be exact
            m = re.search(r"^(\d+) states after a restart were not compared: (.*)$", out, re.M)
            check(rp.returncode == 0 and n == 99 and diff == 0.0 and m is not None
                  and int(m.group(1)) == 2000 - 99 - 3 - 2 and "noise" in m.group(2),
                  f"compared up to the first gap ({n}), the rest not compared and said why, exit 0")


def case_readers(r, a, tmp):
    prefix = f"LG{os.getpid()}R"
    log = os.path.join(tmp, "run.lcm")
    config = os.path.join(a.source, "config", "dipc.yaml")
    check(r.record(config, prefix, log, 5).returncode == 0, "a 5 s run logged")
    recs = read_log(log)
    crc = 0
    for _, _, ch, data in recs:
        crc = zlib.crc32(data, zlib.crc32(ch.encode(), crc))
    java = shutil.which("java")
    jar = "/usr/share/java/lcm.jar"
    if check(java is not None and os.path.exists(jar), "java and lcm.jar (liblcm-java) are installed"):
        p = subprocess.run([java, "-cp", jar, os.path.join(a.source, "tests", "log", "ReadLog.java"), log],
                           capture_output=True, text=True, timeout=120)
        print("  java:", p.stdout.strip(), p.stderr.strip()[-300:])
        check(p.stdout.strip() == f"records {len(recs)} crc {crc} numbered true ordered true",
              "lcm.jar's reader (lcm-spy's log playback) reads every record, numbered and in order")
    # lcm-logplayer plays it into LCM's own log writer (the file:// provider, mode w): every
    # message it publishes, without a network that may drop some on a loaded machine
    back = os.path.join(tmp, "back.lcm")
    speed = 5
    t0 = time.monotonic()
    p = subprocess.run(["lcm-logplayer", "-s", str(speed), f"--lcm-url=file://{back}?mode=w", log],
                       capture_output=True, text=True, timeout=60)
    took = time.monotonic() - t0
    got = read_log(back) if os.path.exists(back) else []
    print(f"  lcm-logplayer exit {p.returncode}, {len(got)} of {len(recs)} records back in {took:.2f} s")
    check(p.returncode == 0 and [(ch, d) for _, _, ch, d in got] == [(ch, d) for _, _, ch, d in recs],
          "lcm-logplayer plays every record, byte for byte and in order")
    # at the pace of the log's clock (the run's sim time), not as a burst: the wall time it
    # took is at least the log's span / speed (a loaded machine only makes it longer)
    span = (recs[-1][1] - recs[0][1]) * 1e-6
    played = (got[-1][1] - got[0][1]) * 1e-6 if got else 0.0
    check(span >= 4.9 and played >= 0.95 * span / speed,
          f"... at {speed}x the log's pace: {played:.3f} s of playing for {span:.3f} s of log")


def case_cli(r, a, tmp):
    config = os.path.join(a.source, "config", "dipc.yaml")
    for args, what in [
        (["--offline", "--duration", "1", "--log", "x.lcm"], "--log records the real-time server"),
        (["--replay", "x.lcm", "--log", "y.lcm"], "--log records the real-time server"),
        (["--log-buffer", "4"], "--log-buffer needs --log FILE"),
        (["--log", "x.lcm", "--log-buffer", "0.1"], "--log-buffer: expected a number of MiB from 0.25 to 1024"),
        (["--log", "x.lcm", "--log-buffer", "1e9"], "--log-buffer: expected a number of MiB from 0.25 to 1024"),
        (["--tolerance", "1"], "--tolerance needs --replay LOG"),
        (["--replay", "x.lcm", "--tolerance", "-1"], "--tolerance: expected a number >= 0"),
        (["--replay", "x.lcm", "--tolerance", "nan"], "--tolerance: expected a number >= 0"),
        (["--log"], "option --log needs a value"),
    ]:
        p = r.lagsimd("--config", config, *args, timeout=10)
        check(p.returncode == 2 and what in p.stderr, f"{' '.join(args)}: exit 2, '{what}'")
    # a path that cannot be written, a FIFO nobody reads: exit 2 at once, nothing published
    for path, what in [(os.path.join(tmp, "no", "dir", "run.lcm"), "No such file or directory"),
                       (tmp, "Is a directory")]:
        p = r.lagsimd("--config", config, "--set", f"lcm.prefix=LG{os.getpid()}C", "--log", path,
                      "--duration", "1", timeout=10)
        check(p.returncode == 2 and "cannot open" in p.stderr and what in p.stderr,
              f"--log {path}: exit 2, '{what}'")
    fifo = os.path.join(tmp, "fifo")
    os.mkfifo(fifo)
    t0 = time.monotonic()
    p = r.lagsimd("--config", config, "--set", f"lcm.prefix=LG{os.getpid()}C", "--log", fifo,
                  "--duration", "1", timeout=10)
    check(p.returncode == 2 and "a FIFO that nobody reads" in p.stderr and time.monotonic() - t0 < 5,
          "--log to a FIFO without a reader: exit 2 at once, not a hang")
    # a full disk: the run goes on, says so, exits 1
    p = r.lagsimd("--config", config, "--set", f"lcm.prefix=LG{os.getpid()}C", "--set",
                  "realtime.mode=fast", "--set", "realtime.start=running", "--log", "/dev/full",
                  "--duration", "2", timeout=60)
    check(p.returncode == 1 and "No space left on device" in p.stderr and "INCOMPLETE" in p.stderr,
          "--log /dev/full: said, the run ends, exit 1")


def case_flood(r, a, tmp):
    """A flood of refused commands (unknown joints, and undecodable bytes) for 3 s on a
    realtime run logged with --log: the log keeps every state and every message the daemon
    published, and of the flood only a sample of at most 8 KiB a second (the sample's
    bucket: 8 KiB at start, 8 KiB more each second); the counts are in the log (the
    last status's rejected_* fields, a log_sampled event) and in the summary on stderr;
    --replay gives difference 0."""
    sys.path.insert(0, a.types)
    from lagsim_lcm import LCM, plant_urls
    prefix = f"LG{os.getpid()}F"
    log = os.path.join(tmp, "flood.lcm")
    config = os.path.join(a.source, "config", "dipc.yaml")
    run_s, flood_s = 5.0, 3.0
    d = subprocess.Popen([os.path.join(r.bin, "lagsimd"), "--config", config, "--set",
                          f"lcm.prefix={prefix}", "--set", "realtime.start=running",
                          "--duration", str(run_s), "--log", log],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(waits.daemon_answers(os.path.join(r.bin, "lagsimctl"), prefix), "lagsimd answers")
    _, command_url = plant_urls()
    lc = LCM(command_url)
    bad = r.t.joint_command_t()
    bad.num_joints, bad.name, bad.effort = 1, ["bogus"], [1.0]
    payloads = [bad.encode(), b"\x00" * 40]  # an unknown joint; undecodable
    sent, t_end = 0, time.time() + flood_s
    while time.time() < t_end:
        for _ in range(200):
            lc.publish(prefix + "_COMMAND", payloads[sent % 7 == 0])
            sent += 1
    out, err = d.communicate(timeout=60)
    print(err.strip())
    check(d.returncode == 0, f"lagsimd: exit {d.returncode}")
    size = os.path.getsize(log)
    recs = read_log(log)
    cmd_bytes = sum(28 + len(ch) + len(data) for _, _, ch, data in recs if ch == prefix + "_COMMAND")
    rest = size - cmd_bytes
    print(f"  log: {size} bytes, {cmd_bytes} of them commands, for {sent} refused commands sent")
    last = r.t.status_t.decode([dt for _, _, ch, dt in recs if ch == prefix + "_STATUS"][-1])
    received = last.rejected_unknown_joint + last.rejected_undecodable
    each = 28 + len(prefix + "_COMMAND") + len(payloads[0])
    print(f"  flood: {sent} sent in {flood_s} s, {received} received by the daemon "
          f"({last.rejected_unknown_joint} unknown joint, {last.rejected_undecodable} undecodable); "
          f"log {size} bytes: {cmd_bytes} of commands, {rest} of the rest; "
          f"every refused one written would be {received * each} bytes")
    # the bound: the sample's bucket can have given at most 8 KiB at start plus 8 KiB for
    # each second of the log's clock (the run is run_s of sim time at rate 1, plus the start)
    bound = 8 * 1024 * (1 + run_s + 1)
    check(received > 20000, f"the flood reached the daemon ({received} refused commands counted)")
    check(cmd_bytes <= bound, f"commands in the log: {cmd_bytes} bytes <= {bound} (8 KiB a "
          f"second of the run and one at start)")
    check(size <= rest + bound and size < 2 * 1024 * 1024,
          f"the log: {size} bytes (< 2 MiB; written whole it would be over {received * each})")
    check(len(r.states(recs, prefix)) == 501, f"{len(r.states(recs, prefix))} states logged: every one")
    sampled = [r.t.event_t.decode(dt) for _, _, ch, dt in recs if ch == prefix + "_EVENT"]
    sampled = [e for e in sampled if e.kind == "log_sampled"]
    check(sampled and "counted only" in sampled[-1].detail and sampled[-1].value > 0,
          f"log_sampled events in the log ({len(sampled)}): "
          f"'{sampled[-1].detail if sampled else ''}'")
    m = re.search(r"complete; received (\d+) refused commands and control requests \((\d+) "
                  r"undecodable\) and \d+ status or describe requests: (\d+) written as a sample, "
                  r"(\d+) counted only", err)  # the summary at exit
    # the sample holds the refused commands and the status request lagsimctl sent (waiting
    # for the daemon to answer): every input record, _COMMAND and _CONTROL
    in_log = sum(1 for _, _, ch, _ in recs if ch in (prefix + "_COMMAND", prefix + "_CONTROL"))
    check(m is not None and int(m.group(1)) == received
          and int(m.group(2)) == last.rejected_undecodable and int(m.group(3)) == in_log,
          "the summary on stderr: refused received (as the last status counts them), "
          "undecodable, written as a sample (as the log holds), counted only: %s; status: %d "
          "refused, %d undecodable; log: %d" % (m.groups() if m else None, received,
                                                last.rejected_undecodable, in_log))
    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--set",
                   "realtime.start=running", "--replay", log)
    n, gaps, diff, _ = replay_report(rp)
    check(rp.returncode == 0 and n == 500 and gaps == 0 and diff == 0.0,
          f"replay: {n} states compared, {gaps} gaps, difference {diff}, exit {rp.returncode}")


def case_flood_applied(r, a, tmp):
    """A flood of messages the daemon applies, for 3 s on a realtime run logged with --log:
    good commands (a new effort each), and pause and resume requests. Each changes the run,
    so none is refused; the log still grows by a bounded amount: the received records'
    bytes are within their two buckets (applied ones: room for 2 full commands a control
    period, at least 8 KiB a second; refused ones and queries: 8 KiB a second; each full at
    start) over the span of the log's own clock or the run's wall time, whichever is
    longer, whatever was sent. The full command's size
    is computed here from lcm-gen's types. Every state is logged, the counts are said (a
    log_sampled event, the summary), and --replay gives difference 0."""
    sys.path.insert(0, a.types)
    from lagsim_lcm import LCM, plant_urls
    prefix = f"LG{os.getpid()}A"
    log = os.path.join(tmp, "applied.lcm")
    config = os.path.join(a.source, "config", "dipc.yaml")
    hz, run_s, flood_s = 100, 5.0, 3.0
    d = subprocess.Popen([os.path.join(r.bin, "lagsimd"), "--config", config, "--set",
                          f"lcm.prefix={prefix}", "--set", "realtime.start=running", "--set",
                          f"publish_hz={hz}", "--duration", str(run_s), "--log", log],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t_start = time.monotonic()
    check(waits.daemon_answers(os.path.join(r.bin, "lagsimctl"), prefix), "lagsimd answers")
    _, command_url = plant_urls()
    lc = LCM(command_url)
    cmd = r.t.joint_command_t()
    cmd.num_joints, cmd.name = 1, ["theta0"]
    ctl = r.t.control_t()
    payloads = []
    for k in range(50):
        cmd.effort = [0.001 * k]
        payloads.append((prefix + "_COMMAND", cmd.encode()))
    for req in (r.t.control_t.PAUSE, r.t.control_t.RESUME):
        ctl.request = req
        payloads.append((prefix + "_CONTROL", ctl.encode()))
    sent, t_end = 0, time.time() + flood_s
    while time.time() < t_end:
        for _ in range(200):
            lc.publish(*payloads[sent % len(payloads)])
            sent += 1
    ctl.request = r.t.control_t.RESUME  # the flood may end paused
    for _ in range(3):
        lc.publish(prefix + "_CONTROL", ctl.encode())
        time.sleep(0.1)
    out, err = d.communicate(timeout=120)
    wall = time.monotonic() - t_start
    print("\n".join(l for l in err.splitlines() if "log" in l)[-2000:])
    check(d.returncode == 0, f"lagsimd: exit {d.returncode}")
    recs = read_log(log)
    rx = [(ts, 28 + len(ch) + len(data)) for _, ts, ch, data in recs
          if ch in (prefix + "_COMMAND", prefix + "_CONTROL")]
    span = (recs[-1][1] - recs[0][1]) * 1e-6
    full = r.t.joint_command_t()
    full.num_joints, full.name, full.effort = 1, ["theta0"], [0.0]
    record = 28 + len(prefix + "_COMMAND") + len(full.encode())
    applied_bps = max(8192, 2 * hz * record)
    bound = (applied_bps + 8192) * (1 + max(span, wall))
    got = sum(b for _, b in rx)
    m = re.search(r"complete; received \d+ refused .* counted only; applied (\d+) commands and "
                  r"control requests: (\d+) written \(at most (\d+) bytes a second\), (\d+) "
                  r"counted only", err)
    print(f"  flood: {sent} sent in {flood_s} s; log {os.path.getsize(log)} bytes over "
          f"{span:.2f} s of its clock ({wall:.2f} s of wall time); received records: {len(rx)}, {got} bytes; bound "
          f"{bound:.0f} ({applied_bps} + 8192 bytes a second); summary: "
          f"{m.groups() if m else None}")
    check(m is not None and int(m.group(1)) > 20000,
          f"the flood reached the daemon and was applied ({m.group(1) if m else '?'} counted)")
    check(m is not None and int(m.group(3)) == applied_bps,
          f"the applied messages' bucket: {m.group(3) if m else '?'} bytes a second, as "
          f"computed here ({applied_bps}: 2 x {hz} Hz x {record} bytes)")
    check(got <= bound, f"received records in the log: {got} bytes <= {bound:.0f}")
    sampled = [r.t.event_t.decode(dt) for _, _, ch, dt in recs if ch == prefix + "_EVENT"]
    sampled = [e for e in sampled if e.kind == "log_sampled" and "applied" in e.detail]
    check(len(sampled) >= 2, f"log_sampled events say so ({len(sampled)})")
    n = len(r.states(recs, prefix))
    steps = [s.step for s in r.states(recs, prefix)]
    check(steps[-1] == 5000 and all(b - a in (0, 10) for a, b in zip(steps, steps[1:])),
          f"{n} states logged: every period's (paused ones repeat), to step {steps[-1]}")
    rp = r.lagsimd("--config", config, "--set", f"lcm.prefix={prefix}", "--set",
                   "realtime.start=running", "--set", f"publish_hz={hz}", "--replay", log)
    _, gaps, diff, _ = replay_report(rp)
    check(rp.returncode == 0 and gaps == 0 and diff == 0.0,
          f"replay: {gaps} gaps, difference {diff}, exit {rp.returncode}")


CASES = {"lqr": case_lqr, "lqr_effects": case_lqr_effects, "gaps": case_gaps,
         "readers": case_readers, "cli": case_cli, "flood": case_flood,
         "flood_applied": case_flood_applied}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--types", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("case", choices=sorted(CASES))
    a = ap.parse_args()
    # a multicast port of this test's own (ttl=0: this host) for every process it starts,
    # through LCM_DEFAULT_URL: on one port every socket gets every datagram, and another
    # test's fast-mode daemon would flood this one's sockets; 4 MB receive buffers
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")  # and the next port: commands
    a.bin, a.types, a.source = (os.path.abspath(x) for x in (a.bin, a.types, a.source))
    tmp = tempfile.mkdtemp(prefix="lagsim_log_")
    try:
        CASES[a.case](Run(a, tmp), a, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
