#!/usr/bin/env python3
"""How fast lagsimd --log grows under a flood on its input channels (docs/deploy.md).

    bench/log_growth.py [--build BUILD] [--seconds S] [KIND ...]

For each KIND a real-time DIPC plant (config/dipc.yaml, running, publish_hz 100) logs with
--log while this script sends KIND's messages to it as fast as one Python process can for
S seconds (default 10); the growth is the log's size at the end of the flood minus its
size at the start, over the flood's wall time. Prints one line per kind (bytes a second,
MB an hour, messages sent, how many the daemon counted and wrote), and the largest.
Nothing is asserted: a figure, with the command that gives it. (The bound itself is tested
structurally: ctest -R 'log_flood|log_rt_flood'.)

Kinds:
  idle        nothing sent (the plant alone, no controller)
  controller  build/bin/dipc_lqr balancing it (one command a control period)
  refused     commands for an unknown joint, and undecodable bytes
  commands    good commands, a new effort each (each applied)
  pause       pause and resume requests, alternating (each applied)
  reset       reset requests (each applied)
  set         set requests (parameters.m2, alternating values)
  queries     status and describe requests
  all         each of the above messages in turn
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

KINDS = ["idle", "controller", "refused", "commands", "pause", "reset", "set", "queries", "all"]


def payloads(t, prefix, kind):
    cmd, ctl = prefix + "_COMMAND", prefix + "_CONTROL"

    def control(req, count=0, key="", value=""):
        c = t.control_t()
        c.request, c.count, c.key, c.value = req, count, key, value
        return c.encode()

    def command(name, effort):
        c = t.joint_command_t()
        c.num_joints, c.name, c.effort = 1, [name], [effort]
        return c.encode()

    table = {
        "refused": [(cmd, command("bogus", 1.0))] * 6 + [(cmd, b"\x00" * 40)],
        "commands": [(cmd, command("theta0", 0.001 * k)) for k in range(50)],
        "pause": [(ctl, control(t.control_t.PAUSE)), (ctl, control(t.control_t.RESUME))],
        "reset": [(ctl, control(t.control_t.RESET))],
        "set": [(ctl, control(t.control_t.SET, key="parameters.m2", value=v))
                for v in ("0.75", "0.76")],
        "queries": [(ctl, control(t.control_t.STATUS)), (ctl, control(t.control_t.DESCRIBE))],
    }
    if kind == "all":
        return [p for k in ("refused", "commands", "pause", "reset", "set", "queries")
                for p in table[k][:2]]
    return table.get(kind, [])


def measure(a, t, LCM, plant_urls, kind, port):
    prefix = "GROW%d" % os.getpid()
    tmp = tempfile.mkdtemp(prefix="lagsim_growth_")
    log = os.path.join(tmp, "run.lcm")
    env = dict(os.environ, LCM_DEFAULT_URL="udpm://239.255.76.67:%d?ttl=0" % port)
    os.environ["LCM_DEFAULT_URL"] = env["LCM_DEFAULT_URL"]
    d = subprocess.Popen([os.path.join(a.build, "bin", "lagsimd"), "--config",
                          os.path.join(a.source, "config", "dipc.yaml"), "--set",
                          "lcm.prefix=" + prefix, "--set", "realtime.start=running", "--set",
                          "publish_hz=100", "--log", log], env=env, stderr=subprocess.PIPE,
                         text=True)
    helper = None
    try:
        time.sleep(1.0)
        _, command_url = plant_urls()
        lc = LCM(command_url)
        msgs = payloads(t, prefix, kind)
        if kind == "controller":
            helper = subprocess.Popen([os.path.join(a.build, "bin", "dipc_lqr"), "--prefix", prefix,
                                       "-q", "--duration", str(a.seconds + 5)], env=env,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(1.0)
        size0, t0 = os.path.getsize(log), time.monotonic()
        sent = 0
        while time.monotonic() - t0 < a.seconds:
            if not msgs:
                time.sleep(0.05)
                continue
            for _ in range(100):
                lc.publish(*msgs[sent % len(msgs)])
                sent += 1
        if kind == "pause":
            lc.publish(prefix + "_CONTROL", msgs[1][1])  # end running
        time.sleep(0.3)  # the writer writes within 100 ms
        size1, t1 = os.path.getsize(log), time.monotonic()
    finally:
        if helper:
            helper.terminate()
            helper.wait()
        d.send_signal(2)
        _, err = d.communicate(timeout=60)
    summary = [l for l in err.splitlines() if "--log" in l and "records" in l]
    os.remove(log)
    os.rmdir(tmp)
    rate = (size1 - size0) / (t1 - t0)
    print("%-10s %9.0f bytes/s %7.1f MB/h  sent %7d  %s" % (kind, rate, rate * 3600 / 1e6, sent,
          summary[-1].split(": ", 2)[-1] if summary else "(no summary: %s)" % err[-300:]),
          flush=True)
    return rate


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(root, "build"))
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("kinds", nargs="*", default=KINDS)
    a = ap.parse_args()
    a.build, a.source = os.path.abspath(a.build), root
    sys.path.insert(0, os.path.join(a.build, "python"))
    import lagsim
    from lagsim_lcm import LCM, plant_urls
    port = 30000 + 2 * (os.getpid() % 5000)
    worst = max((measure(a, lagsim, LCM, plant_urls, k, port), k) for k in a.kinds)
    print("largest: %s, %.0f bytes/s = %.1f MB/h" % (worst[1], worst[0], worst[0] * 3600 / 1e6))


if __name__ == "__main__":
    main()
