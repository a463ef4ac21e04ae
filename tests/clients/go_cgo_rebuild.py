#!/usr/bin/env python3
"""A cgo program is compiled again when a header it includes from another directory changes.

    go_cgo_rebuild.py --go GO --script cmake/go_build.cmake --cache DIR

Go's build cache keys a package on its Go files, its own directory's C files and the cgo
flags, not on a header included through -I from elsewhere (lagsim_client.h,
lagsim/version.h) nor on a library linked: after a new lagsim is installed, a plain `go
build` reuses cgo objects compiled with the old constants. The tree builds its Go programs
through cmake/go_build.cmake, which keys them on those files. Here a program printing a
constant of such a header is built by the script, the header's constant changed, and the
program built again: it must print the new value. (A plain `go build` with the same cache
is run too and its answer shown: the stale one where Go's cache is as described.)
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

PROGRAM = """package main

/*
#cgo CFLAGS: -I${SRCDIR}/../include
#include "HEADER_NAME"
*/
import "C"
import "fmt"

func main() { fmt.Println(C.LAGSIM_PROBE) }
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--go", required=True)
    ap.add_argument("--script", required=True)
    ap.add_argument("--cache", required=True, help="Go's cache (the build tree's)")
    a = ap.parse_args()
    a.script, a.cache = os.path.abspath(a.script), os.path.abspath(a.cache)
    tmp = tempfile.mkdtemp(prefix="lagsim_cgo_rebuild_")
    try:
        os.makedirs(os.path.join(tmp, "include"))
        os.makedirs(os.path.join(tmp, "prog"))
        header = os.path.join(tmp, "include", "lagsim_probe" + ".h")
        source = os.path.join(tmp, "prog", "probe.go")
        with open(source, "w") as f:  # the header, made here, by its name
            f.write(PROGRAM.replace("HEADER_NAME", os.path.basename(header)))
        env = ["GOCACHE=" + a.cache, "GOPATH=" + os.path.join(tmp, "gopath"), "GOTOOLCHAIN=local",
               "GOENV=off", "GOFLAGS=", "GO111MODULE=on", "CGO_ENABLED=1"]
        for value in (1, 2):
            with open(header, "w") as f:  # the same path, the same size: only the value moves
                f.write("#define LAGSIM_PROBE %d\n" % value)
            out = os.path.join(tmp, "probe%d" % value)
            r = subprocess.run(["cmake", "-DGO=" + a.go, "-DOUTPUT=" + out, "-DSOURCE=" + source,
                                "-DINPUTS=" + header, "-DENV=" + "|".join(env), "-P", a.script],
                               cwd=os.path.join(tmp, "prog"), stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True)
            got = subprocess.run([out], stdout=subprocess.PIPE, universal_newlines=True).stdout.strip() \
                if r.returncode == 0 else "(build failed: %s)" % r.stdout.strip()
            check(got == str(value), "header says %d, the program built by go_build.cmake prints %s"
                  % (value, got))
        plain = os.path.join(tmp, "probe_plain")  # what Go's own cache does, for the record
        penv = dict(os.environ, **dict(e.split("=", 1) for e in env))
        with open(header, "w") as f:
            f.write("#define LAGSIM_PROBE 1\n")
        subprocess.run([a.go, "build", "-o", plain, source], env=penv, cwd=os.path.join(tmp, "prog"))
        with open(header, "w") as f:
            f.write("#define LAGSIM_PROBE 3\n")
        if subprocess.run([a.go, "build", "-o", plain, source], env=penv,
                          cwd=os.path.join(tmp, "prog")).returncode == 0:
            got = subprocess.run([plain], stdout=subprocess.PIPE, universal_newlines=True).stdout.strip()
            print("info: a plain `go build` after the header became 3 prints %s%s"
                  % (got, " (stale: why the script keys the cache)" if got != "3" else ""))
        return verdict()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
