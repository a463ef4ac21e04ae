#!/usr/bin/env python3
"""A prefix nobody has (a misspelt one): every side says who is there instead.

    test_misspelt.py --bin BUILD/bin --source SRC

On a multicast port of this run's own, a manipulator plant on prefix MANIPULATOR<pid>
waiting for its first command (its stderr read), and a DIPC on DP<pid>. Then:
  lagsimctl --prefix MANIP<pid>... status   (a prefix the plant's starts with) exit 3: "no
                            plant on prefix ...; plants heard on URL: ...; did you mean
                            MANIPULATOR<pid>?"
  manipulator_pd --prefix MANIPULATR<pid>  (one letter out) exit 1, the same
  manipulator_pd.py --prefix MANIPULATR<pid>  (Python, its own discovery) the same
  manipulator_ct --prefix MANIPULATR<pid>  (C++, lagsim_client.hpp) the same
  lagsimctl --prefix DP<pid> status  (another plant's: answered, not reported)
  a STATUS on MANIPULATOR<pid>_CONTROL sent to the state port (the wrong port)
The plant's wait line (stderr) and its status's waiting_got then name the misspelt
prefixes with their requests ("requests for prefixes no plant here has, on the command
port P: MANIPULATR<pid> (DESCRIBE n), ...; this plant is MANIPULATOR<pid>"), the control
request on the state port, and never DP<pid> (a plant answered for it).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
import waits  # noqa: E402  (events waited on, bounded)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def run(args, timeout=60):
    r = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    print("$ %s %s   -> exit %d" % (os.path.basename(args[0]), " ".join(args[1:]), r.returncode))
    if r.stderr.strip():
        print("  stderr: " + r.stderr.strip()[-600:])
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    b = lambda p: os.path.join(a.bin, p)
    types = os.path.join(os.path.dirname(a.bin), "python")
    pid = os.getpid()
    plant, other = "MANIPULATOR%d" % pid, "DP%d" % pid
    short, typo = "MANIP", "MANIPULATR%d" % pid
    url = lcm_url()  # a port pair of this process's own (not one drawn from the pid)
    port = int(url.split(":")[2].split("?")[0])
    os.environ["LCM_DEFAULT_URL"] = url
    err_path = "/tmp/lagsim_misspelt_%d.err" % pid
    err = open(err_path, "w")
    d = subprocess.Popen([b("lagsimd"), "--config", os.path.join(a.source, "config", "manipulator.yaml"),
                          "--set", "lcm.prefix=" + plant], stdout=subprocess.DEVNULL, stderr=err)
    d2 = subprocess.Popen([b("lagsimd"), "--config", os.path.join(a.source, "config", "dipc.yaml"),
                           "-q", "--set", "lcm.prefix=" + other],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for prefix in (plant, other):  # each answers (waited on, bounded)
            check(waits.daemon_answers(b("lagsimctl"), prefix), "lagsimd %s answers" % prefix)
        instead = ("plants heard on %s: %s (dipc, realtime, waiting), %s (manipulator, realtime, "
                   "waiting); did you mean %s?" % (url, other, plant, plant))
        r = run([b("lagsimctl"), "--prefix", short, "status"])
        check(r.returncode == 3 and ("no answer on %s_* within 2 s: no plant on prefix %s; %s"
                                     % (short, short, instead)) in r.stderr,
              "lagsimctl --prefix %s status: exit 3, the plants heard, the one meant" % short)
        r = run([b("manipulator_pd"), "--prefix", typo, "--timeout", "1.5"])
        check(r.returncode == 1 and ("manipulator_pd: no scene description on %s_SCENE within "
                                     "1.5 s: no plant on prefix %s; %s" % (typo, typo, instead))
              in r.stderr, "manipulator_pd --prefix %s: exit 1, the plants heard, the one meant" % typo)
        r = run([sys.executable, os.path.join(a.source, "clients", "python", "manipulator_pd.py"),
                 "--types", types, "--prefix", typo, "--timeout", "1.5"])
        check(r.returncode == 1 and ("no scene on %s_SCENE within 1.5 s: no plant on prefix %s; %s"
                                     % (typo, typo, instead)) in r.stderr,
              "manipulator_pd.py --prefix %s: exit 1, the same (the library's discovery, "
              "through ctypes)" % typo)
        r = run([b("manipulator_ct"), "--prefix", typo, "--timeout", "1.5"])
        check(r.returncode == 1 and ("no scene description on %s_SCENE within 1.5 s: no plant "
                                     "on prefix %s; %s" % (typo, typo, instead)) in r.stderr,
              "manipulator_ct --prefix %s: exit 1, the same (C++: lagsim::Controller::wait_scene)"
              % typo)
        r = run([b("lagsimctl"), "--prefix", other, "status"])
        check(r.returncode == 0, "lagsimctl --prefix %s status: the other plant answers" % other)
        # this plant's control request on the state port (the wrong one)
        sys.path.insert(0, types)
        from lagsim_lcm import LCM
        from lagsim import control_t
        lc = LCM(url)
        c = control_t()
        c.request = control_t.STATUS
        lc.publish(plant + "_CONTROL", c.encode())
        lc.close()
        time.sleep(1.0)
        r = run([b("lagsimctl"), "--prefix", plant, "--json", "status"])
        st = json.loads(r.stdout.splitlines()[0]) if r.returncode == 0 and r.stdout else {}
        got = st.get("waiting_got", "")
        print("waiting_got:", got)
        # (the status holds 255 bytes of it: the end may be cut)
        want = re.compile(r"requests for prefixes no plant here has, on the command port %d: "
                          r"%s \(DESCRIBE \d+\), %s \((STATUS|DESCRIBE) 1"
                          % (port + 1, typo, short))
        check(want.search(got) is not None, "status waiting_got: both misspelt prefixes, the "
              "most recent first, and their requests")
        check(("1 control request (STATUS 1) on %s_CONTROL at the state port %d (requests go "
               "to port %d)" % (plant, port, port + 1)) in got,
              "status waiting_got: the control request on the state port")
        check(other not in got, "another plant's prefix is not named")
        time.sleep(max(0.0, 6.5 - 4.0))
    finally:
        for p in (d, d2):
            p.terminate()
            p.wait(timeout=20)
        err.close()
    text = open(err_path).read()
    os.unlink(err_path)
    lines = [l for l in text.splitlines() if " waits " in l]
    for l in lines:
        print("wait line:", l)
    check(any(typo in l and "no plant here has" in l and "this plant is " + plant in l
              for l in lines) and not any(other in l for l in lines),
          "the daemon's wait line names the misspelt prefix, not the other plant's")
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
