#!/usr/bin/env python3
"""Manipulator trajectory tracking in Python, standard library only.

Talks to lagsimd through lagsim_lcm (ctypes over liblcm.so.1) and the lcm-gen Python
types (PYTHONPATH=<build>/python, or --types DIR). Tracks
    q1_d(t) = 0.3 sin(0.5 t)  rad,   q2_d(t) = 0.5 + 0.1 sin(t)  m   (t = sim time)
with PD plus computed-torque feedforward, from the parameters of the scene description:
    tau = M(q) (qdd_d + Kp e + Kd e_dot) + C(q, qd) qd + g(q),  Kp = wn^2, Kd = 2 wn.
The dynamics are written here in closed form from the brief's T and U (independent of
the C core):
    T = 1/2 (m1 l1^2 + m2 q2^2 + I1 + I2) q1d^2 + 1/2 m2 q2d^2,
    U = (m1 l1 + m2 q2) g sin q1
    tau1 = M11 q1dd + 2 m2 q2 q1d q2d + (m1 l1 + m2 q2) g cos q1,  M11 = m1 l1^2 + m2 q2^2 + I1 + I2
    tau2 = m2 q2dd - m2 q2 q1d^2 + m2 g sin q1
Answers every state with a command carrying that state's sim_time (lockstep-safe).
Exit status: 0 done, 1 no daemon/scene/state, 2 bad usage.
"""
import argparse
import math
import os
import signal
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lagsim_lcm import LCM  # noqa: E402


def import_types(types_dir):
    if types_dir:
        sys.path.insert(0, types_dir)
    try:
        import lagsim  # noqa: F401
        from lagsim import control_t, joint_command_t, joint_state_t, scene_t
    except ImportError:
        sys.stderr.write("manipulator_pd.py: cannot import the lcm-gen Python types "
                         "'lagsim'; set PYTHONPATH=<build>/python or pass --types\n")
        sys.exit(2)
    return control_t, joint_command_t, joint_state_t, scene_t


def desired(t):
    """(q, qd, qdd) of the reference trajectory at sim time t."""
    q = (0.3 * math.sin(0.5 * t), 0.5 + 0.1 * math.sin(t))
    qd = (0.15 * math.cos(0.5 * t), 0.1 * math.cos(t))
    qdd = (-0.075 * math.sin(0.5 * t), -0.1 * math.sin(t))
    return q, qd, qdd


def computed_torque(p, q, qd, v):
    """tau = M(q) v + C(q, qd) qd + g(q) for the manipulator (closed form above)."""
    m1, m2, l1, I1, I2, g = p["m1"], p["m2"], p["l1"], p["I1"], p["I2"], p["g"]
    M11 = m1 * l1 * l1 + m2 * q[1] * q[1] + I1 + I2
    tau1 = M11 * v[0] + 2.0 * m2 * q[1] * qd[0] * qd[1] + (m1 * l1 + m2 * q[1]) * g * math.cos(q[0])
    tau2 = m2 * v[1] - m2 * q[1] * qd[0] * qd[0] + m2 * g * math.sin(q[0])
    return tau1, tau2


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--prefix", default="MANIPULATOR", help="channel prefix (default MANIPULATOR)")
    ap.add_argument("--url", default=None, help="LCM URL (default: LCM's default)")
    ap.add_argument("--duration", type=float, default=0.0,
                    help="sim seconds from the first state (default 0: until SIGINT)")
    ap.add_argument("--wn", type=float, default=10.0, help="PD bandwidth rad/s (default 10)")
    ap.add_argument("--settle", type=float, default=2.0,
                    help="error statistics skip the first S s (default 2)")
    ap.add_argument("--timeout", type=float, default=5.0,
                    help="wall s without a scene or state before giving up (default 5)")
    ap.add_argument("--types", default=None, help="directory holding the lagsim Python types")
    ap.add_argument("-q", action="store_true", help="quiet: summary only")
    a = ap.parse_args()
    if a.timeout <= 0 or a.duration < 0 or a.wn <= 0 or a.settle < 0:
        ap.error("--timeout, --wn must be > 0; --duration, --settle >= 0")
    control_t, joint_command_t, joint_state_t, scene_t = import_types(a.types)
    kp, kd = a.wn * a.wn, 2.0 * a.wn

    stop = [False]

    def on_signal(signum, frame):
        stop[0] = True

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)

    lc = LCM(a.url)
    box = {"scene": None, "state": None, "new": False, "dropped": 0}

    def on_scene(channel, data):
        try:
            box["scene"] = scene_t.decode(data)
        except Exception:
            box["dropped"] += 1

    def on_state(channel, data):
        try:
            box["state"] = joint_state_t.decode(data)
            box["new"] = True
        except Exception:
            box["dropped"] += 1

    lc.subscribe(a.prefix + "_SCENE", on_scene)
    lc.subscribe(a.prefix + "_STATE", on_state)

    # subscribed: from here on no state is missed (test harnesses wait for this line)
    print("manipulator_pd.py: waiting for the scene description on %s_SCENE" % a.prefix,
          flush=True)
    # scene description: ask (DESCRIBE) every 0.25 s until it arrives
    deadline = time.monotonic() + a.timeout
    next_ask = 0.0
    while box["scene"] is None and not stop[0]:
        now = time.monotonic()
        if now >= deadline:
            sys.stderr.write("manipulator_pd.py: no scene on %s_SCENE within %g s\n"
                             % (a.prefix, a.timeout))
            return 1
        if now >= next_ask:
            req = control_t()
            req.utime = int(time.time() * 1e6)
            req.request = control_t.DESCRIBE
            lc.publish(a.prefix + "_CONTROL", req.encode())
            next_ask = now + 0.25
        lc.handle_timeout(50)
    sc = box["scene"]
    if sc is None:
        return 1
    if sc.model != "manipulator":
        sys.stderr.write("manipulator_pd.py: prefix %s runs model %r\n" % (a.prefix, sc.model))
        return 1
    p = dict(zip(sc.param_name, sc.param_value))
    missing = [k for k in ("m1", "m2", "l1", "I1", "I2", "g") if k not in p]
    if missing:
        sys.stderr.write("manipulator_pd.py: scene lacks parameters %s\n" % missing)
        return 1
    print("manipulator_pd.py: scene on %s_*: mode %s, control period %g s; Kp %g, Kd %g"
          % (a.prefix, sc.mode, sc.control_period, kp, kd), flush=True)

    names = ["q1", "q2"]
    states = 0
    n_settled = 0
    t_first = t_last = float("nan")
    t_report = -float("inf")
    emax = [0.0, 0.0]
    esq = [0.0, 0.0]
    emax_all = [0.0, 0.0]
    code = 0
    while not stop[0]:
        wait_until = time.monotonic() + (a.timeout if a.duration > 0 else 0.5)
        while not box["new"] and not stop[0] and time.monotonic() < wait_until:
            lc.handle_timeout(50)
        if stop[0]:
            break
        if not box["new"]:
            if a.duration > 0:
                sys.stderr.write("manipulator_pd.py: no state on %s_STATE within %g s\n"
                                 % (a.prefix, a.timeout))
                code = 1
                break
            continue
        while lc.handle_timeout(0):  # drain: answer the newest state
            pass
        st = box["state"]
        box["new"] = False
        try:
            i1, i2 = st.name.index("q1"), st.name.index("q2")
        except ValueError:
            continue
        q = (st.position[i1], st.position[i2])
        qd = (st.velocity[i1], st.velocity[i2])
        qdes, qddes, qdddes = desired(st.sim_time)
        v = [qdddes[k] + kp * (qdes[k] - q[k]) + kd * (qddes[k] - qd[k]) for k in range(2)]
        tau = [x if math.isfinite(x) else 0.0 for x in computed_torque(p, q, qd, v)]
        cmd = joint_command_t()
        cmd.utime = int(time.time() * 1e6)
        cmd.sim_time = st.sim_time
        cmd.num_joints = 2
        cmd.name = names
        cmd.effort = tau
        lc.publish(a.prefix + "_COMMAND", cmd.encode())

        if states == 0:
            t_first = st.sim_time
        states += 1
        t_last = st.sim_time
        e = (qdes[0] - q[0], qdes[1] - q[1])
        for k in range(2):
            emax_all[k] = max(emax_all[k], abs(e[k]))
        if st.sim_time - t_first >= a.settle:
            n_settled += 1
            for k in range(2):
                emax[k] = max(emax[k], abs(e[k]))
                esq[k] += e[k] * e[k]
        if not a.q and st.sim_time - t_report >= 1.0:
            t_report = st.sim_time
            print("t=%8.3f  q1=%+.5f (e %+.2e)  q2=%+.5f (e %+.2e)  tau=%+.3f %+.3f"
                  % (st.sim_time, q[0], e[0], q[1], e[1], tau[0], tau[1]), flush=True)
        if a.duration > 0 and st.sim_time - t_first >= a.duration - 0.5 * sc.control_period:
            break
    rms = [math.sqrt(esq[k] / n_settled) if n_settled else float("nan") for k in range(2)]
    print("manipulator_pd.py: summary states=%d t_first=%.6f t_last=%.6f settle=%g "
          "max_abs_e1=%.6g max_abs_e2=%.6g rms_e1=%.6g rms_e2=%.6g max_abs_e1_all=%.6g "
          "max_abs_e2_all=%.6g dropped=%d handler_errors=%d"
          % (states, t_first, t_last, a.settle, emax[0], emax[1], rms[0], rms[1],
             emax_all[0], emax_all[1], box["dropped"], lc.errors), flush=True)
    lc.close()
    return code


if __name__ == "__main__":
    sys.exit(main())
