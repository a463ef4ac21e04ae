#!/usr/bin/env python3
"""A run whose parameters were changed while it ran, replayed from its log.

    test_set_replay.py --bin BUILD/bin --source SRC [--lcm-logger PATH]

dipc_lqr balances the DIPC of config/dipc.yaml in real time for 6 s of sim time while
lcm-logger records the bus (and, when lagsimd has --log, the daemon records its own log);
after about 2 s `lagsimctl set parameters.m2=1.0` and after about 3.5 s `lagsimctl set
effects.damping={theta1: 0.01, theta2: 0.01}` change the plant: each exits 0 with the
daemon's `set` event. Then `lagsimd --replay` of each log must say that it applied the 2
changes and that the largest difference is exactly 0; the same log with its `set` events
taken out must not replay exactly (the changes mattered: a replay that ignored them
would fail here).
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, replay, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_log import read_log, write_log  # noqa: E402
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--lcm-logger", default="")
    a = ap.parse_args()
    lagsimd, ctl, lqr = (os.path.join(a.bin, p) for p in ("lagsimd", "lagsimctl", "dipc_lqr"))
    sys.path.insert(0, os.path.join(os.path.dirname(a.bin), "python"))  # lagsim_lcm
    cfg = os.path.join(a.source, "config", "dipc.yaml")
    prefix = "SETR_%d" % os.getpid()
    # a multicast port of this run's own (ttl=0: this host), through LCM_DEFAULT_URL, which
    # every process here reads: nothing else on the machine is heard, nothing of this run
    # is heard elsewhere; 4 MB receive buffers so that the logger keeps up
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")
    print("LCM_DEFAULT_URL=%s" % os.environ["LCM_DEFAULT_URL"])
    tmp = tempfile.mkdtemp(prefix="lagsim_set_replay_")
    logs = []
    help_text = subprocess.run([lagsimd, "--help"], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True).stdout
    dcmd = [lagsimd, "--config", cfg, "--set", "lcm.prefix=" + prefix, "--duration", "6", "-q"]
    if "--log" in help_text:
        logs.append(os.path.join(tmp, "daemon.lcm"))
        dcmd += ["--log", logs[-1]]
    logger = None
    if a.lcm_logger:
        logs.append(os.path.join(tmp, "logger.lcm"))
        logger = subprocess.Popen([a.lcm_logger, "-q", "-f", "-c", prefix + "_.*", logs[-1]])
        check(waits.logger_wrote(logs[-1], prefix + "_PROBE", b"logger-up"),
              "lcm-logger records (a probe in its file)")
    if not check(logs, "a log to replay (lagsimd --log or lcm-logger)"):
        return 1
    # --timeout 30: the daemon starts once the controller is subscribed, and a loaded
    # machine's may take more than the default 5 s to publish its scene; the sets' times
    # count from the daemon answering (from its start, it may not be up yet)
    c = subprocess.Popen([lqr, "--prefix", prefix, "-q", "--timeout", "30"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    check(waits.subscribed(c) is not None, "dipc_lqr subscribed")
    d = subprocess.Popen(dcmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         universal_newlines=True)
    check(waits.daemon_answers(ctl, prefix), "the daemon answers")
    t0 = time.monotonic()
    sets = [(2.0, "parameters.m2=1.0"), (3.5, "effects.damping={theta1: 0.01, theta2: 0.01}")]
    for at, kv in sets:
        time.sleep(max(0.0, t0 + at - time.monotonic()))
        r = subprocess.run([ctl, "--prefix", prefix, "set", kv], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, universal_newlines=True, timeout=20)
        print("$ lagsimctl set %s   -> exit %d\n  %s" % (kv, r.returncode,
                                                        r.stdout.splitlines()[0] if r.stdout else r.stderr))
        check(r.returncode == 0 and r.stdout.startswith("event set ") and kv in r.stdout,
              "lagsimctl set %s: exit 0, the daemon's set event" % kv)
    dout, _ = d.communicate(timeout=30)
    cout, _ = c.communicate(timeout=30)
    print(dout.strip())
    print(cout.strip())
    check(d.returncode == 0, "lagsimd ran 6 s and exited 0")
    if logger:  # stopped once it has written what it heard of the run
        check(waits.logger_wrote(logs[-1], prefix + "_PROBE", b"run-over"),
              "lcm-logger wrote a probe sent after the run")
        logger.send_signal(2)
        logger.wait(timeout=10)

    for log in logs:
        r, diff = replay(lagsimd, cfg, prefix, log)
        check(r.returncode == 0 and "2 change(s) made while running applied" in r.stdout and
              diff == 0.0, "%s: replayed with the 2 changes, difference exactly 0 (%s)"
              % (os.path.basename(log), diff))
        recs = read_log(log)
        kept = [x for x in recs if not (x[1] == prefix + "_EVENT" and b"\x00\x00\x00\x04set\x00" in x[2])]
        check(len(recs) - len(kept) == 2, "%s: 2 set events in the log" % os.path.basename(log))
        bare = log[:-4] + "_without_sets.lcm"
        write_log(bare, kept)
        r, diff = replay(lagsimd, cfg, prefix, bare)
        check(diff is not None and diff > 1e-9,
              "%s without its set events: the replay differs (%s)" % (os.path.basename(log), diff))
    for f in os.listdir(tmp):
        os.remove(os.path.join(tmp, f))
    os.rmdir(tmp)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
