#!/usr/bin/env python3
"""Manipulator trajectory tracking in Python, standard library only.

Talks to lagsimd through lagsim_lcm (ctypes over liblcm.so.1) and the lcm-gen Python
types (PYTHONPATH=<build>/python, or --types DIR). Tracks the scene's reference (the
reference_t on <PREFIX>_REFERENCE, published just before each state: q_d = r, qd_d = r',
qdd_d = r'', the exact second derivative; a joint without a reference holds its first
position), as manipulator_pd in C does, with PD plus computed-torque feedforward, from the
parameters of the scene description:
    tau = M(q) (qdd_d + Kp e + Kd e_dot) + C(q, qd) qd + g(q),  Kp = wn^2, Kd = 2 wn.
The dynamics are written here in closed form from the model's T and U (docs/models.md),
independently of the C core:
    T = 1/2 (m1 l1^2 + m2 q2^2 + I1 + I2) q1d^2 + 1/2 m2 q2d^2,
    U = (m1 l1 + m2 q2) g sin q1
    tau1 = M11 q1dd + 2 m2 q2 q1d q2d + (m1 l1 + m2 q2) g cos q1,  M11 = m1 l1^2 + I1 + I2 + m2 q2^2
    tau2 = m2 q2dd - m2 q2 q1d^2 + m2 g sin q1
with the C core's operations in its order (M v + h, h the bias), so that Python, Lua, C
and C++ (clients/manipulator_ct.cpp) answer every state with the same bits.
Answers every state with a command carrying that state's sim_time (lockstep-safe), until
the daemon stops, falls silent for --timeout s, or --duration s of sim time have passed;
then prints a summary line. Exit status: 0 done, 1 no scene (no daemon?), 2 bad usage.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lagsim_controller import Controller  # noqa: E402


class Desired(object):
    """q_d, qd_d, qdd_d at each state, from the latest reference (manipulator_pd.c's rule)."""

    def __init__(self):
        self.hold = None
        self.stale = 0
        self.have = [False, False]

    def at(self, ref, st, q):
        if self.hold is None:
            self.hold = q
        if ref is not None and ref.sim_time != st.sim_time:
            self.stale += 1
        qdes, qddes, qdd = list(self.hold), [0.0, 0.0], [0.0, 0.0]
        for k, name in enumerate(("q1", "q2")):
            self.have[k] = ref is not None and name in ref.name
            if self.have[k]:
                j = ref.name.index(name)
                qdes[k], qddes[k], qdd[k] = ref.r[j], ref.rdot[j], ref.rddot[j]
        return qdes, qddes, qdd


def computed_torque(p, q, qd, v):
    """tau = M(q) v + C(q, qd) qd + g(q) for the manipulator (closed form above)."""
    m1, m2, l1, I1, I2, g = p["m1"], p["m2"], p["l1"], p["I1"], p["I2"], p["g"]
    s, c, a = math.sin(q[0]), math.cos(q[0]), m2 * q[1]
    M = (m1 * l1 * l1 + I1 + I2 + m2 * q[1] * q[1], 0.0, 0.0, m2)
    h = (2.0 * a * qd[0] * qd[1] + (m1 * l1 + a) * g * c, -a * qd[0] * qd[0] + m2 * g * s)
    return M[0] * v[0] + M[1] * v[1] + h[0], M[2] * v[0] + M[3] * v[1] + h[1]


def main():
    ctl = Controller("manipulator_pd.py", "MANIPULATOR", "manipulator",
                     description=__doc__.split("\n")[0])
    ctl.parser.add_argument("--wn", type=float, default=10.0,
                            help="PD bandwidth rad/s (default 10)")
    ctl.parser.add_argument("--settle", type=float, default=2.0,
                            help="error statistics skip the first S s (default 2)")
    a = ctl.start()
    if not (a.wn > 0 and a.settle >= 0):
        ctl.parser.error("--wn must be > 0, --settle >= 0")
    kp, kd = a.wn * a.wn, 2.0 * a.wn
    p = ctl.params
    missing = [k for k in ("m1", "m2", "l1", "I1", "I2", "g") if k not in p]
    if missing:
        sys.stderr.write("manipulator_pd.py: scene lacks parameters %s\n" % missing)
        return 1
    if not a.q:
        print("manipulator_pd.py: scene on %s_*: mode %s, control period %g s; Kp %g, Kd %g"
              % (a.prefix, ctl.scene.mode, ctl.scene.control_period, kp, kd), flush=True)

    names = ["q1", "q2"]
    des = Desired()
    states = 0
    n_settled = 0
    t_first = t_last = float("nan")
    t_report = -float("inf")
    emax = [0.0, 0.0]
    esq = [0.0, 0.0]
    emax_all = [0.0, 0.0]
    for st in ctl.states():
        try:
            i1, i2 = st.name.index("q1"), st.name.index("q2")
        except ValueError:
            continue
        q = (st.position[i1], st.position[i2])
        qd = (st.velocity[i1], st.velocity[i2])
        qdes, qddes, qdddes = des.at(ctl.reference, st, q)
        if states == 0 and not a.q:
            print("manipulator_pd.py: tracking q1 %s, q2 %s" % tuple(
                "its reference" if h else "its first position" for h in des.have), flush=True)
        v = [qdddes[k] + kp * (qdes[k] - q[k]) + kd * (qddes[k] - qd[k]) for k in range(2)]
        tau = computed_torque(p, q, qd, v)
        ctl.command(st.sim_time, names, tau)

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
    rms = [math.sqrt(esq[k] / n_settled) if n_settled else float("nan") for k in range(2)]
    return ctl.finish("states=%d t_first=%.6f t_last=%.6f settle=%g max_abs_e1=%.6g "
                      "max_abs_e2=%.6g rms_e1=%.6g rms_e2=%.6g max_abs_e1_all=%.6g "
                      "max_abs_e2_all=%.6g references_stale=%d"
                      % (states, t_first, t_last, a.settle, emax[0], emax[1], rms[0], rms[1],
                         emax_all[0], emax_all[1], des.stale))


if __name__ == "__main__":
    sys.exit(main())
