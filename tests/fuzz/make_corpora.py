#!/usr/bin/env python3
"""Writes the corpora of the wire, client, log and replay fuzz targets, and the kept
inputs that crashed, hung or leaked in the client library and --replay before they read
through the wire module.

    tests/fuzz/make_corpora.py BUILD_DIR            writes them
    tests/fuzz/make_corpora.py BUILD_DIR --check    writes nothing; exit 1 if a kept file
                                                  differs from what it would write

Messages are encoded by lcm-gen's Python types (BUILD_DIR/python), independently of the
wire module; the replay logs come from `test_replay ... write_logs` (a core run of
config/dipc.yaml written as lcm-logger writes it) and from `lagsimd --log`.
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile

build = os.path.abspath(sys.argv[1])
check = sys.argv[2:] == ["--check"]
stale = []
n_written = [0]
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
sys.path.insert(0, os.path.join(build, "python"))
from lagsim import control_t, event_t, joint_command_t, joint_state_t, reference_t, scene_t, status_t  # noqa

SYNC = 0xEDA1DA01


def log_shape(b):
    """The channels of an LCM log, each with the fingerprints of its messages: what stays
    of a log whose records carry wall-clock times (and whose statuses follow the wall
    clock in number)."""
    out, p = set(), 0
    while p + 28 <= len(b):
        cl, dl = struct.unpack(">II", b[p + 20:p + 28])
        out.add((b[p + 28:p + 28 + cl], b[p + 28 + cl:p + 36 + cl]))
        p += 28 + cl + dl
    return out


def write(target, kind, name, data, shape=None):
    d = os.path.join(here, target, kind)
    n_written[0] += 1
    if check:  # a message type that changed leaves its inputs behind: they stop at the
        path = os.path.join(d, name)  # fingerprint and test nothing they are named for
        key = shape or (lambda b: b)
        if not os.path.exists(path) or key(open(path, "rb").read()) != key(data):
            stale.append(os.path.relpath(path, here))
        return
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def state(n=3, names=("theta0", "theta1", "theta2"), t=0.01, step=10):
    m = joint_state_t()
    m.sim_time, m.step, m.num_joints = t, step, n
    m.name = list(names[:n])
    m.position = [0.1 * (i + 1) for i in range(n)]
    m.velocity = [-0.2 * i for i in range(n)]
    m.effort = [1.5 if i == 0 else 0.0 for i in range(n)]
    return m.encode()


def command():
    m = joint_command_t()
    m.sim_time, m.num_joints, m.name, m.effort = 0.01, 2, ["q1", "q2"], [1.5, -2.25]
    return m.encode()


def control(req=control_t.RESET_TO):
    m = control_t()
    m.request, m.count, m.num_joints = req, 3, 3
    m.q, m.qd = [0.0, 0.05, -0.03], [0.0, 0.0, 1.0]
    return m.encode()


def event():
    m = event_t()
    m.sim_time, m.step, m.kind, m.joint, m.value = 1.25, 1250, "impact", "theta0", -0.5
    m.detail = "impact at t = 1.25 s"
    return m.encode()


def status():
    m = status_t()
    for i, f in enumerate(status_t.__slots__):
        v = getattr(m, f)
        if isinstance(v, str):
            setattr(m, f, "rk4" if f == "integrator" else "field%d" % i)
        elif isinstance(v, bool):
            setattr(m, f, True)
        elif isinstance(v, float):
            setattr(m, f, i + 0.5)
        else:
            setattr(m, f, i)
    return m.encode()


def scene(nparams=7, njoints=3):
    m = scene_t()
    m.model, m.prefix = "dipc", "DIPC"
    m.num_params = nparams
    m.param_name = ["p%d" % i for i in range(nparams)]
    m.param_value = [1.0 + i for i in range(nparams)]
    m.num_joints = njoints
    m.joint_name = ["theta%d" % i for i in range(njoints)]
    m.actuated = [i == 0 for i in range(njoints)]
    m.initial_q = [0.0] * njoints
    m.initial_qd = [0.0] * njoints
    m.dt, m.control_period, m.integrator, m.mode = 0.001, 0.01, "rk4", "realtime"
    m.rate, m.command_timeout = 1.0, 0.5
    m.effects = "limits"
    m.limit_on = [i == 0 for i in range(njoints)]
    m.limit_lower = [-1.0 if i == 0 else 0.0 for i in range(njoints)]
    m.limit_upper = [1.0 if i == 0 else 0.0 for i in range(njoints)]
    return m.encode()


def reference(n=2, names=("theta0", "theta1"), t=0.01, step=10):
    m = reference_t()
    m.sim_time, m.step, m.num_joints = t, step, n
    m.name = list(names[:n])
    m.r = [0.2 * (i + 1) for i in range(n)]
    m.rdot = [-0.5 * i for i in range(n)]
    m.rddot = [3.0 * i - 1.0 for i in range(n)]
    return m.encode()


def forged_state(name_len, name_bytes, n=3, rest=True, pad_to=None):
    """A joint_state_t whose first name is written as name_len then name_bytes."""
    b = joint_state_t._get_packed_fingerprint() + struct.pack(">qdqh", 0, 0.0, 0, n)
    b += struct.pack(">I", name_len & 0xFFFFFFFF) + name_bytes
    if rest:
        for nm in ("theta1", "theta2")[: n - 1]:
            b += struct.pack(">I", len(nm) + 1) + nm.encode() + b"\0"
        b += b"\0" * (24 * n)
    if pad_to and len(b) < pad_to:
        b += b"A" * (pad_to - len(b))
    return b


def record(channel, data, num=0, stamp=0):
    c = channel.encode()
    return struct.pack(">IqqII", SYNC, num, stamp, len(c), len(data)) + c + data


# ---- wire: first byte = the bound on num_joints (9 -> 8)
B8 = b"\x09"
for name, data in [("joint-state.bin", state()), ("joint-command.bin", command()),
                   ("control-reset-to.bin", control()), ("control-step.bin", control(control_t.STEP)),
                   ("event.bin", event()), ("status.bin", status()), ("scene.bin", scene()),
                   ("scene-full.bin", scene(16, 8)), ("joint-state-no-joints.bin", state(0)),
                   ("reference.bin", reference()), ("reference-no-joints.bin", reference(0))]:
    write("wire", "corpus", name, B8 + data)
write("wire", "corpus", "joint-state-bound-2.bin", b"\x03" + state())
write("wire", "corpus", "joint-state-negative-count.bin", B8 + state()[:34 - 2] + b"\xff\xff")

# ---- client: first byte = channel (0 STATE, 1 STATUS, 2 EVENT, 3 SCENE, 4 REFERENCE)
for name, data in [("state.bin", b"\x00" + state()), ("status.bin", b"\x01" + status()),
                   ("event.bin", b"\x02" + event()), ("scene.bin", b"\x03" + scene()),
                   ("reference.bin", b"\x04" + reference())]:
    write("client", "corpus", name, data)
# what crashed, overread or leaked in the client's lcm-gen decoders
write("client", "crash", "state-negative-name-length.bin",
      b"\x00" + forged_state(-1, b"", rest=False, pad_to=145))
write("client", "crash", "state-name-without-nul.bin", b"\x00" + forged_state(6, b"theta0"))
write("client", "crash", "state-32767-joints.bin",
      b"\x00" + forged_state(7, b"theta0\0", n=32767, rest=False))
st = status_t._get_packed_fingerprint() + b"\0" * 72 + struct.pack(">I", 0xFFFFFFFF) + b"B" * 100
write("client", "crash", "status-negative-string-length.bin", b"\x01" + st)
ev = event_t._get_packed_fingerprint() + b"\0" * 24 + struct.pack(">I", 0x7FFFFFFF) + b"C" * 40
write("client", "crash", "event-string-length-7fffffff.bin", b"\x02" + ev)
# Java's decoder allocates a string's length first: 1e9 is 2 GB for a 77-byte message
ev = event_t._get_packed_fingerprint() + b"\0" * 24 + struct.pack(">I", 10**9) + b"C" * 40
write("client", "crash", "event-string-length-1e9.bin", b"\x02" + ev)
# each name's NUL replaced: Python, Lua and Java read "theta0X" as "theta0", a whole state
forged = state()
for nm in (b"theta0", b"theta1", b"theta2"):
    forged = forged.replace(nm + b"\0", nm + b"X")
write("client", "crash", "state-name-nul-replaced-by-x.bin", b"\x00" + forged)
sc = (scene_t._get_packed_fingerprint() + struct.pack(">q", 0) + struct.pack(">I", 2) + b"m\0"
      + struct.pack(">I", 2) + b"P\0" + struct.pack(">h", 32767) + struct.pack(">I", 3) + b"m0\0")
write("client", "crash", "scene-32767-params.bin", b"\x03" + sc)

# ---- log
log = record("DIPC_STATE", state(), 0, 1000) + record("DIPC_STATUS", status(), 1, 2000) + \
      record("OTHER", b"x" * 40, 2, 3000) + record("DIPC_EVENT", b"", 3, 4000)
write("log", "corpus", "three-channels.lcm", log)
write("log", "corpus", "junk-between.lcm", log[:60] + b"junk" + log[60:])
write("log", "corpus", "cut-short.lcm", log[:-5])
huge = struct.pack(">IqqII", SYNC, 0, 0, 10, 0x7FFFFFFF) + b"DIPC_STATE" + b"0123456789abcdef"
write("log", "crash", "data-length-7fffffff.lcm", record("DIPC_STATE", state()) + huge)

# ---- replay: the test's logs (a core run of config/dipc.yaml), kept small
tmp = tempfile.mkdtemp()
try:
    subprocess.check_call([os.path.join(build, "bin", "test_replay"),
                           os.path.join(build, "bin", "lagsimd"),
                           os.path.join(root, "config", "dipc.yaml"), "write_logs", tmp])

    def records(path):
        b = open(path, "rb").read()
        out, p = [], 0
        while p + 28 <= len(b):
            sync, num, stamp, cl, dl = struct.unpack(">IqqII", b[p:p + 28])
            if sync != SYNC or p + 28 + cl + dl > len(b):
                out.append(b[p:])  # a damaged tail: kept as it is
                break
            out.append(b[p:p + 28 + cl + dl])
            p += 28 + cl + dl
        return out

    def keep(name, target, kind, first=None, flood_max=None):
        recs = records(os.path.join(tmp, name + ".lcm"))
        if flood_max:  # fewer identical records
            seen, kept = 0, []
            for r in recs:
                if sum(1 for x in recs if x[20:] == r[20:]) > 1:
                    seen += 1
                    if seen > flood_max:
                        continue
                kept.append(r)
            recs = kept
        if first:
            recs = recs[:first]
        write(target, kind, name.replace("_", "-") + ".lcm", b"".join(recs))

    keep("valid", "replay", "corpus", first=12)     # states 0 .. 11 of a core run
    keep("step_jump", "replay", "corpus", first=24)  # ... and a step of 2^62 after state 19

    # a lagsimd --log log of 0.1 s with an actuator lag (its <PREFIX>_INPUT records, which
    # fuzz_replay's lagged scene reads), and the same without its sixth state (a gap)
    lagged = os.path.join(tmp, "lagged.lcm")
    subprocess.check_call([os.path.join(build, "bin", "lagsimd"), "--config",
                           os.path.join(root, "config", "dipc.yaml"), "--set",
                           "effects.actuator={theta0: {lag: 0.004, max: 40}}", "--set",
                           "realtime.mode=fast", "--set", "realtime.start=running",
                           "--set", "lcm.url=memq://", "--duration", "0.1",
                           "-q", "--log", lagged])
    recs = records(lagged)
    write("replay", "corpus", "lagged-inputs.lcm", b"".join(recs), shape=log_shape)
    states = [k for k, r in enumerate(recs) if r[28:28 + 10] == b"DIPC_STATE"]
    write("replay", "corpus", "lagged-gap.lcm", b"".join(r for k, r in enumerate(recs) if k != states[5]),
          shape=log_shape)

    # changes made while running: the valid log with `set` events (as the daemon publishes
    # them) after its 4th state (at its step), inside the 7th period (3 ticks in), and one
    # the scene loader refuses after the 10th
    def set_event(step, kv):
        e = event_t()
        e.sim_time, e.step, e.kind, e.joint, e.value, e.detail = step * 1e-3, step, "set", "", 0.0, kv
        return record("DIPC_EVENT", e.encode())

    recs = records(os.path.join(tmp, "valid.lcm"))[:12]
    st = [k for k, r in enumerate(recs) if r[28:28 + 10] == b"DIPC_STATE"]
    out = []
    for k, r in enumerate(recs):
        out.append(r)
        if len(st) > 3 and k == st[3]:
            out.append(set_event(30, "parameters.m2=1.0"))
        if len(st) > 6 and k == st[6]:
            out.append(set_event(63, "effects.damping={theta1: 0.01}"))
        if len(st) > 9 and k == st[9]:
            out.append(set_event(90, "parameters.m2=-1"))
    write("replay", "corpus", "changes-while-running.lcm", b"".join(out))
finally:
    shutil.rmtree(tmp)

# Kept inputs of --replay (small logs: the bug is in how a record or a step is read, not in
# the physics): a state, the hostile record(s), a state one period later.
s0, s10 = record("DIPC_STATE", state(t=0.0, step=0)), record("DIPC_STATE", state(t=0.1, step=100))


def at_step(step):
    """The DIPC upright at rest, no effort: an equilibrium, so a re-simulation across a
    huge step gap runs for ever instead of failing."""
    m = joint_state_t()
    m.sim_time, m.step, m.num_joints = 0.0, step, 3
    m.name = ["theta0", "theta1", "theta2"]
    m.position, m.velocity, m.effort = [0.0] * 3, [0.0] * 3, [0.0] * 3
    return record("DIPC_STATE", m.encode())


write("replay", "crash", "negative-name-length.lcm",       # crashed (SIGSEGV)
      s0 + record("DIPC_STATE", forged_state(-1, b"theta0")) + s10)
write("replay", "crash", "name-fills-buffer.lcm",          # heap overflow under ASan
      s0 + record("DIPC_STATE", forged_state(6, b"theta0")) + s10)
write("replay", "crash", "huge-data-length.lcm", s0 + huge + s10 + huge)  # crashed in liblcm
write("replay", "crash", "step-jump.lcm", at_step(0) + at_step(1 << 52))  # hung
write("replay", "crash", "step-int64-min.lcm",                             # overflow, hung
      at_step(0) + at_step(10) + at_step(-(1 << 63)))


def set_at(step):
    """A `set` event of a change at `step` (as the daemon publishes them, but any step)."""
    e = event_t()
    e.sim_time, e.step, e.kind, e.joint, e.value, e.detail = 0.0, step, "set", "", 0.0, "parameters.m2=1.0"
    return record("DIPC_EVENT", e.encode())


write("replay", "crash", "set-step-int64-min.lcm",                         # overflow (UBSan)
      at_step(0) + at_step(10) + set_at(-(1 << 63)) + at_step(20))
flood = record("DIPC_STATE", forged_state(7, b"theta0\0", n=32767, rest=False))
write("replay", "crash", "undecodable-flood.lcm", s0 + flood * 100 + s10)  # leaked 262 kB each
# ---- view (tests/fuzz/fuzz_view.c): first byte 0 = messages' bytes, 1 = an HTTP request
# ("@P": the port bound), 2 = a Host header's value
worst_text = bytes(range(1, 32)) + b'\x7f"\\\xff\xc0\xed\xa0\x80'
write("view", "corpus", "json-mixed.bin", b"\x00" + (b"\xff" + worst_text * 9) * 25)
# every length the longest, every byte 0xff (not UTF-8: 6 bytes of JSON each), 136 events
# (once the bytes run out, each a copy of the one before)
write("view", "corpus", "json-worst.bin", b"\x00" + b"\xff" * 6000)
write("view", "corpus", "json-plain.bin", b"\x00" + (b"\x06theta0" + b"\x3f\xf0" + b"\x00" * 6) * 60)
for name, req in [
        ("http-state.bin", b"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:@P\r\n\r\n"),
        ("http-page.bin", b"GET / HTTP/1.1\r\nHost: localhost:@P\r\nConnection: close\r\n\r\n"),
        ("http-events.bin", b"GET /events HTTP/1.1\r\nHost: 127.0.0.1:@P\r\n\r\n"),
        ("http-two-hosts.bin", b"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:@P\r\nHost: evil.example\r\n\r\n"),
        ("http-control.bin", b"POST /api/control?request=step&count=3 HTTP/1.1\r\nHost: 127.0.0.1:@P\r\n"
                             b"X-Lagsim: 1\r\nContent-Length: 4\r\n\r\nbody"),
        ("http-keepalive.bin", b"GET /view.js HTTP/1.1\r\nHost: 127.0.0.1:@P\r\n\r\n"
                               b"GET /api/state HTTP/1.1\r\nHost: [::1]:@P\r\n\r\n")]:
    write("view", "corpus", name, b"\x01" + req)
for name, host in [("host-port.bin", b"127.0.0.1:8765"), ("host-v6.bin", b"[::1]:8765"),
                   ("host-dot.bin", b"LOCALHOST.:8765"), ("host-noport.bin", b"localhost")]:
    write("view", "corpus", name, b"\x02" + host)
if check:
    for path in stale:
        print("stale: tests/fuzz/%s (run tests/fuzz/make_corpora.py BUILD_DIR)" % path)
    print("%d kept inputs checked against the types, %d stale" % (n_written[0], len(stale)))
    sys.exit(1 if stale else 0)
print("corpora written under", here)
