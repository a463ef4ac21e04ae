#!/usr/bin/env python3
"""A slow control law for a Python controller run as written: python3 think.py SCRIPT ARGS...

Runs SCRIPT (its own directory first on sys.path, its arguments after it) with every
joint_command_t that it constructs taking LAGSIM_THINK_S wall seconds first: building an
answer is where a control law spends its time, so a script that builds one answer per
state thinks once per state, and one that builds an answer for every copy of a state
thinks once per copy. Each time it thinks it appends a line to the file LAGSIM_THINK_LOG
(if set), so a test counts how often the law ran. Nothing else of the script changes.
"""
import os
import runpy
import sys
import time

THINK = float(os.environ.get("LAGSIM_THINK_S", "0"))
LOG = os.environ.get("LAGSIM_THINK_LOG")
from lagsim import joint_command_t  # noqa: E402 (PYTHONPATH gives the types)

_init = joint_command_t.__init__


def _slow_init(self, *args, **kwargs):
    if LOG:
        with open(LOG, "a") as f:
            f.write("law\n")
    time.sleep(THINK)
    _init(self, *args, **kwargs)


joint_command_t.__init__ = _slow_init
sys.argv = sys.argv[1:]
sys.path[0] = os.path.dirname(os.path.abspath(sys.argv[0]))
runpy.run_path(sys.argv[0], run_name="__main__")
