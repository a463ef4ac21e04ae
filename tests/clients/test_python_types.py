#!/usr/bin/env python3
"""The Python types the build generates (lcm-gen + lcmtypes/py_bool_lists.cmake) decode
every array as a list: a scene's `actuated` and `limit_on` (booleans) as well as its
names and numbers, read as often as one likes.
usage: test_python_types.py PYTHON_TYPES_DIR
"""
import os
import sys

sys.path.insert(0, sys.argv[1])
import lagsim  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

s = lagsim.scene_t()
s.model, s.prefix, s.integrator, s.mode, s.effects = "cartpole", "T", "rk4", "realtime", ""
s.num_joints, s.joint_name = 2, ["x", "theta"]
s.actuated, s.limit_on = [True, False], [False, True]
s.initial_q, s.initial_qd, s.limit_lower, s.limit_upper = [0.0, 0.1], [0.0, 0.0], [0, -1.0], [0, 1.0]
d = lagsim.scene_t.decode(s.encode())
for k in d.__slots__:
    v = getattr(d, k)
    check(not hasattr(v, "__next__"), "%s: not a one-shot iterator (%s)" % (k, type(v).__name__))
check(d.actuated == [True, False] and d.actuated == [True, False], "actuated: [True, False], twice")
check(d.limit_on == [False, True], "limit_on: [False, True]")
check(repr(d.actuated) == "[True, False]", "actuated prints as a list (%r)" % (d.actuated,))
sys.exit(verdict())
