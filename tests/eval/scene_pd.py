#!/usr/bin/env python3
"""scene_pd.py: PD on the manipulator's joints, gains scaled by the scene's m2 (a test's
scene-reactive controller; tests/eval/scene_pd.c says what it is for).

It reads m2 from the controller's scene at every state: the scene of the last
<PREFIX>_SCENE received (lagsim_controller.py keeps it; a state comes only after the
scene of its own generation: docs/clients.md).
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "clients", "python"))
from lagsim_controller import Controller  # noqa: E402

KP, KD = 40.0, 12.0
TARGET = {"q1": 0.3, "q2": 0.6}


def main():
    ctl = Controller("scene_pd.py", "MANIPULATOR", "manipulator",
                     description=__doc__.split("\n")[0])
    ctl.start()
    states, m2 = 0, float("nan")
    for st in ctl.states():
        m2 = dict(zip(ctl.scene.param_name, ctl.scene.param_value))["m2"]
        tau = []
        for name in ("q1", "q2"):
            i = st.name.index(name)
            tau.append(m2 * (KP * (TARGET[name] - st.position[i]) - KD * st.velocity[i]))
        ctl.command(st.sim_time, ["q1", "q2"], tau)
        states += 1
    return ctl.finish("states=%d m2=%.17g" % (states, m2))


if __name__ == "__main__":
    sys.exit(main())
