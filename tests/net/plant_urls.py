"""plant_urls (clients/python/lagsim_lcm.py) against the cases every implementation
passes (tests/net/plant_urls.txt), and the tests' own pair (tests/common/lcm_port.py's
lcm_urls, which run_e2e.py listens to without the client library) against it.

    python3 plant_urls.py TABLE CLIENTS_PYTHON_DIR
"""
import os
import sys


def main():
    table, pydir = sys.argv[1], sys.argv[2]
    sys.path.insert(0, pydir)
    from lagsim_lcm import plant_urls
    os.environ.pop("LCM_DEFAULT_URL", None)
    fails = cases = 0
    for line in open(table):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        base, want_state, want_cmd = [f.strip() for f in line.split(" | ")]
        url = None if base == "(none)" else base
        cases += 1
        try:
            got = plant_urls(url)
        except ValueError as e:
            got = ("ERROR", "ERROR")
            why = str(e)
        if got != (want_state, want_cmd):
            print("FAIL: %r gives %r, expected %r%s" % (base, got, (want_state, want_cmd),
                  " (%s)" % why if got[0] == "ERROR" else ""))
            fails += 1
    os.environ["LCM_DEFAULT_URL"] = "udpm://239.9.9.9:9000?ttl=1"
    if plant_urls("") != ("udpm://239.9.9.9:9000?ttl=1", "udpm://239.9.9.9:9001?ttl=1"):
        print("FAIL: LCM_DEFAULT_URL is not the base of an absent URL")
        fails += 1
    # lcm_urls derives the command URL by the same rule, for harnesses that run against an
    # installed or packaged tree and so cannot load this build's client library
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
    from lcm_port import lcm_urls
    for options in ("", "recv_buf_size=4194304"):
        cases += 1
        pair = lcm_urls(options)
        if plant_urls(pair[0]) != pair:
            print("FAIL: lcm_urls(%r) gives %r, the library's rule %r"
                  % (options, pair, plant_urls(pair[0])))
            fails += 1
    print("plant_urls.py: %d cases, %d failures" % (cases, fails))
    return 1 if fails or cases < 10 else 0


if __name__ == "__main__":
    sys.exit(main())
