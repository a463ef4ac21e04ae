#!/usr/bin/env python3
"""The cart-pole controller of tests/eval/test_procs.py (PYTHONPATH=<build>/python).

Answers each state with no force, --pace s after it (so that a run lasts), and once it has
answered --ready-after states writes READY/ready.PREFIX: the run's daemon publishes states
and its controller answers them. Before the first state it starts two `sleep 600`: one in
its own process group (a grandchild of the tool, as python3 under `sh -c` is) and one in a
session of its own (setsid: out of every process group the tool knows).
  --hang   after the ready file it stops answering: its lockstep plant waits for it
  --deaf   it ignores SIGINT and SIGTERM (--hang too)
  --idle   it writes READY/idle.PREFIX whenever no state came for 0.5 s after its last
           answer: the plant waits for something other than this controller (a sweep's
           kept daemon, paused, for its worker's next STEP)
"""
import os
import signal
import subprocess
import sys
import threading
import time

from lagsim_controller import Controller

ctl = Controller("procs_controller", "CARTPOLE", "cartpole")
ctl.parser.add_argument("--ready", required=True, help="directory of the ready files")
ctl.parser.add_argument("--ready-after", type=int, default=3)
ctl.parser.add_argument("--pace", type=float, default=0.01)
ctl.parser.add_argument("--hang", action="store_true")
ctl.parser.add_argument("--deaf", action="store_true")
ctl.parser.add_argument("--idle", action="store_true")
a = ctl.start()
if a.deaf or a.hang:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
subprocess.Popen(["sleep", "600"])
subprocess.Popen(["sleep", "600"], start_new_session=True)


def mark(name):
    tmp = os.path.join(a.ready, ".%s.%s" % (name, a.prefix))
    with open(tmp, "w") as f:
        f.write("%d\n" % os.getpid())
    os.rename(tmp, os.path.join(a.ready, "%s.%s" % (name, a.prefix)))


n, timer = 0, None
for st in ctl.states():
    if timer:
        timer.cancel()
    time.sleep(a.pace)
    ctl.command(st.sim_time, ["x"], [0.0])
    n += 1
    if a.idle:
        timer = threading.Timer(0.5, mark, ("idle",))
        timer.daemon = True
        timer.start()
    if n == a.ready_after:
        mark("ready")
        while a.hang:
            time.sleep(60)
sys.exit(ctl.finish("answered=%d" % n))
