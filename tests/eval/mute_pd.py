#!/usr/bin/env python3
"""mute_pd.py: scene_pd.py's law, but no answer to a state at or after --mute-from s of
sim time: a controller that leaves a run's last state (the state the daemon pauses at)
unanswered, for lagsim-sweep's `unanswered` case (tests/eval/test_sweep.py); with
--exit-above M2 it exits (status 7) at the first state at or after 0.2 s of a run whose
scene's m2 is above M2: a controller that dies in some runs (`controller_exit`)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "clients", "python"))
from lagsim_controller import Controller  # noqa: E402


def main():
    ctl = Controller("mute_pd.py", "MANIPULATOR", "manipulator",
                     description=__doc__.split("\n")[0])
    ctl.parser.add_argument("--mute-from", type=float, default=float("inf"))
    ctl.parser.add_argument("--exit-above", type=float, default=float("inf"))
    a = ctl.start()
    for st in ctl.states():
        if st.sim_time >= a.mute_from - 1e-9:
            continue
        m2 = dict(zip(ctl.scene.param_name, ctl.scene.param_value))["m2"]
        if m2 > a.exit_above and st.sim_time >= 0.2 - 1e-9:
            sys.exit(7)
        tau = [m2 * (40.0 * (x - st.position[i]) - 12.0 * st.velocity[i])
               for i, x in ((st.name.index("q1"), 0.3), (st.name.index("q2"), 0.6))]
        ctl.command(st.sim_time, ["q1", "q2"], tau)
    return ctl.finish("")


if __name__ == "__main__":
    sys.exit(main())
