#!/usr/bin/env python3
"""The conformance controller in Python, over the Python client library
(clients/python/lagsim_controller.py): the conformance law, for tests/protocol/play.py.

    conformance.py --types BUILD/python --prefix P --url URL [--timeout S]

For each state the library hands it: u = -(kp q + kd qd) on each actuated joint of the
scene of that state's generation (kp, kd: the scene's parameters of those names), one
line "conformance: law generation=G sim_time=T" on stdout before the command goes
(docs/protocol.md, "Checking a binding of your own").
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "clients", "python"))
from lagsim_controller import Controller  # noqa: E402

ctl = Controller("conformance.py", default_prefix="CONFORMANCE", model="dipc")
ctl.parser.set_defaults(timeout=60.0)
ctl.start()
laws = 0
for st in ctl.states():
    sc, kp, kd = ctl.scene, ctl.params["kp"], ctl.params["kd"]
    names, efforts = [], []
    for j, name in enumerate(sc.joint_name):
        if sc.actuated[j]:
            i = st.name.index(name)
            names.append(name)
            efforts.append(-(kp * st.position[i] + kd * st.velocity[i]))
    laws += 1
    print("conformance: law generation=%d sim_time=%.17g" % (st.generation, st.sim_time), flush=True)
    ctl.command(st.sim_time, names, efforts)
sys.exit(ctl.finish("laws=%d held=%d" % (laws, ctl.held)))
