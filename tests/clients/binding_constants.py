#!/usr/bin/env python3
"""The numbers the bindings copy from the client library's headers, against the headers.

    binding_constants.py --source SRC [--jar BUILD/lagsim_examples.jar]

Python's lagsim_client.py (ctypes cannot read a #define) and Java's lagsim.examples.Locate
(pure Java) repeat the header's capacities, result codes and lag_client_locate's answers
and wait; the Lua module and the C++ header use the C names themselves. Each copy must
equal clients/lagsim_client.h's #define (or server/include/lagsim/result.h's code).
Exit 0 when all agree, 1 otherwise.
"""
import argparse
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

# the binding's name: the header's
PYTHON = {"MAX_JOINTS": "LAG_CLIENT_MAX_JOINTS", "NAME_LEN": "LAG_CLIENT_NAME_LEN",
          "TEXT_LEN": "LAG_CLIENT_TEXT_LEN", "URL_LEN": "LAG_CLIENT_URL_LEN",
          "OK": "LAG_OK", "TIMEOUT": "LAG_TIMEOUT", "ERR_AMBIGUOUS": "LAG_ERR_AMBIGUOUS",
          "LOCATE_NONE": "LAG_CLIENT_LOCATE_NONE", "LOCATE_HERE": "LAG_CLIENT_LOCATE_HERE",
          "LOCATE_HOST": "LAG_CLIENT_LOCATE_HOST", "LOCATE_WAIT_S": "LAG_CLIENT_LOCATE_WAIT_S"}
JAVA = {"NONE": "LAG_CLIENT_LOCATE_NONE", "HERE": "LAG_CLIENT_LOCATE_HERE",
        "HOST": "LAG_CLIENT_LOCATE_HOST", "WAIT_S": "LAG_CLIENT_LOCATE_WAIT_S"}


def header_values(src):
    v = {}
    text = open(os.path.join(src, "clients", "lagsim_client.h")).read()
    for name, val in re.findall(r"^#define (LAG_CLIENT_[A-Z_]+) +([-0-9.]+)\b", text, re.M):
        v[name] = float(val)
    text = open(os.path.join(src, "server", "include", "lagsim", "result.h")).read()
    for name, val in re.findall(r"X\((LAG_[A-Z_]+), (-?[0-9]+),", text):
        v[name] = float(val)
    return v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--jar", default=None)
    a = ap.parse_args()
    want = header_values(a.source)
    sys.path.insert(0, os.path.join(a.source, "clients", "python"))
    import lagsim_client
    for ours, theirs in PYTHON.items():
        got = getattr(lagsim_client, ours)
        check(theirs in want and got == want[theirs],
              "lagsim_client.%s = %r, %s = %r" % (ours, got, theirs, want.get(theirs)))
    if a.jar:
        out = subprocess.run(["javap", "-constants", "-cp", a.jar, "lagsim.examples.Locate"],
                             capture_output=True, text=True).stdout
        for ours, theirs in JAVA.items():
            m = re.search(r"static final \w+ %s = ([-0-9.]+)d?;" % ours, out)
            got = float(m.group(1)) if m else None
            check(got is not None and theirs in want and got == want[theirs],
                  "Locate.%s = %r, %s = %r" % (ours, got, theirs, want.get(theirs)))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
