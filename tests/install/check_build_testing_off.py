#!/usr/bin/env python3
"""A build for users: -DBUILD_TESTING=OFF configures the programs and libraries only.

    check_build_testing_off.py --source SRC --build BUILD

Configures SRC into a temporary directory with -DBUILD_TESTING=OFF (nothing is built) and
reads the build system's targets (`cmake --build DIR --target help`): every program with a
man page (docs/man/*.1) that BUILD (a full build) builds, the client library (shared and static), the man pages and the
message types are there; no test program (test_*), fuzz target (fuzz_*), benchmark
(bench_*, lagsim_bench*) and no ctest file (CTestTestfile.cmake) is. Exit 0 when all hold.
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)


def targets_of(build):
    h = subprocess.run(["cmake", "--build", build, "--target", "help"], stdout=subprocess.PIPE,
                       universal_newlines=True).stdout
    return set(re.findall(r"^\.\.\. (\S+)", h, re.M))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--build", required=True)
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="lagsim_user_build_")
    try:
        r = subprocess.run(["cmake", "-S", a.source, "-B", tmp, "-DBUILD_TESTING=OFF"],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        if not check(r.returncode == 0, "cmake -DBUILD_TESTING=OFF configures", r.stdout):
            return verdict()
        targets, full = targets_of(tmp), targets_of(a.build)
        programs = [os.path.basename(p)[:-2] for p in glob.glob(os.path.join(a.source, "docs/man/*.1"))]
        programs = [p for p in programs if p in full]
        want = programs + ["lagsim_client_shared", "lagsim_client", "man_pages", "lagsim_lcmtypes"]
        missing = [t for t in want if t not in targets]
        unwanted = sorted(t for t in targets if re.match(r"(test_|fuzz_|bench_|lagsim_bench)", t))
        check(not missing, "the %d programs with a man page, the client library, the man pages "
              "and the types are built%s" % (len(programs), "; missing: " + " ".join(missing) if missing else ""))
        check(not unwanted, "no test, fuzz or benchmark target%s"
              % ("; found: " + " ".join(unwanted[:20]) if unwanted else ""))
        check(not os.path.exists(os.path.join(tmp, "CTestTestfile.cmake")), "no ctest file")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
