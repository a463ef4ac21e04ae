#!/usr/bin/env python3
"""Every file a lagsim program writes is opened by one set of rules (lagsim_out.h): a
symbolic link is never followed, an input of the run is never written (the same st_dev and
st_ino, a hard link included, --force or not), an existing file is replaced only with
--force; each refusal is exit 2 with a message that names the path and what to do.

    test_outputs.py --bin BUILD/bin --source SRC WRITER

WRITER is one of the outputs, each run through the same table of cases:
  lagsimd_log   lagsimd --log FILE (the real-time server; input: the scene file)
  lagsimd_csv   lagsimd --offline --csv FILE (input: the scene file)
  log2csv       lagsim-log2csv LOG -o DIR (writes DIR/<PREFIX>_STATE.csv; input: LOG)
  plot          lagsim-plot CSV -o FILE (input: CSV)

The cases: FILE is the input itself (and a hard link to it), with and without --force:
refused, the input unchanged; FILE is a symbolic link to a file whose content must
survive, with --force: refused, the target unchanged; FILE exists: refused without
--force (unchanged), replaced with it; FILE is new: written. lagsimd --log --increment
writes FILE.000000, FILE.000001, ... beside an existing FILE, which it keeps (the series:
test_series.py).
"""
import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


class Writer:
    """One output path of one program: run(out, force) writes `out` (a path); input() is
    the file the run reads."""

    def __init__(self, a, tmp, kind):
        self.a, self.tmp, self.kind = a, tmp, kind
        self.prefix = f"LO{os.getpid()}{kind[:3].upper()}"
        self.scene = os.path.join(tmp, "scene.yaml")
        shutil.copy(os.path.join(a.source, "config", "dipc.yaml"), self.scene)
        self.bin = a.bin
        if kind in ("log2csv", "plot"):
            # a log, and the CSV of its states, to read
            self.log = os.path.join(tmp, "in.lcm")
            p = self.lagsimd("--log", self.log)
            assert p.returncode == 0, p.stderr
            self.csv = os.path.join(tmp, "in.csv")
            p = subprocess.run([os.path.join(self.bin, "lagsimd"), "--config", self.scene, "-q",
                                "--offline", "--duration", "1", "--csv", self.csv],
                               capture_output=True, text=True)
            assert p.returncode == 0, p.stderr

    def lagsimd(self, *args):
        return subprocess.run([os.path.join(self.bin, "lagsimd"), "--config", self.scene, "-q",
                               "--set", f"lcm.prefix={self.prefix}",
                               "--set", "realtime.mode=fast", "--set", "realtime.start=running",
                               "--duration", "0.2", *args],
                              capture_output=True, text=True, timeout=60)

    def input(self):
        if self.kind == "log2csv":
            return self.log
        return self.csv if self.kind == "plot" else self.scene

    def target(self, name):
        """Where the output goes when it is called `name`: log2csv writes
        DIR/<PREFIX>_STATE.csv, so `name` is its DIR's file of that name."""
        if self.kind == "log2csv":
            d = os.path.join(self.tmp, "out_" + name)
            os.makedirs(d, exist_ok=True)
            return os.path.join(d, f"{self.prefix}_STATE.csv")
        return os.path.join(self.tmp, name)

    def run(self, out, force):
        f = ["--force"] if force else []
        if self.kind == "lagsimd_log":
            return self.lagsimd("--log", out, *f)
        if self.kind == "lagsimd_csv":
            return subprocess.run([os.path.join(self.bin, "lagsimd"), "--config", self.scene,
                                   "-q", "--offline", "--duration", "0.5", "--csv", out, *f],
                                  capture_output=True, text=True, timeout=60)
        if self.kind == "log2csv":
            return subprocess.run([os.path.join(self.bin, "lagsim-log2csv"), self.log, "-q",
                                   "-o", os.path.dirname(out), *f],
                                  capture_output=True, text=True, timeout=60)
        return subprocess.run([os.path.join(self.bin, "lagsim-plot"), self.csv, "-o", out, *f],
                              capture_output=True, text=True, timeout=60)

    def wrote(self, out):
        """Does `out` now hold what this writer writes?"""
        with open(out, "rb") as f:
            head = f.read(16)
        if self.kind == "lagsimd_log":
            return head[:4] == b"\xed\xa1\xda\x01"
        if self.kind == "plot":
            return head[:8] == b"\x89PNG\r\n\x1a\n"
        return head.startswith(b"t,")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("writer", choices=["lagsimd_log", "lagsimd_csv", "log2csv", "plot"])
    a = ap.parse_args()
    # a multicast port of this test's own (the --log runs publish in fast mode)
    os.environ["LCM_DEFAULT_URL"] = lcm_url()
    tmp = tempfile.mkdtemp(prefix="lagsim_outputs_")
    try:
        w = Writer(a, tmp, a.writer)
        name = a.writer
        inp = w.input()

        # 1. the input itself, and a hard link to it: refused, --force or not
        if a.writer == "log2csv":
            # the log placed where the CSV would go: DIR/<PREFIX>_STATE.csv is the log
            out = w.target("self")
            shutil.copy(w.log, out)
            w.log = out
            inp = out
        for force in (False, True):
            before = digest(inp)
            p = w.run(inp if a.writer != "log2csv" else w.target("self"), force)
            check(p.returncode == 2 and "the same file as" in p.stderr and digest(inp) == before,
                  f"{name}: the output is the input{' (--force)' if force else ''}: exit "
                  f"{p.returncode}, input unchanged: {digest(inp) == before}; {p.stderr.strip()}")
        if a.writer != "log2csv":
            hard = w.target("hardlink")
            os.link(inp, hard)
            before = digest(inp)
            p = w.run(hard, True)
            check(p.returncode == 2 and "the same file as" in p.stderr and digest(inp) == before,
                  f"{name}: a hard link to the input (--force): exit {p.returncode}; {p.stderr.strip()}")
        else:
            w.log = os.path.join(tmp, "in.lcm")

        # 2. a symbolic link to a file whose content must survive: refused, with --force
        precious = os.path.join(tmp, "precious.txt")
        with open(precious, "w") as f:
            f.write("results of a week\n")
        link = w.target("link")
        os.symlink(precious, link)
        p = w.run(link, True)
        with open(precious) as f:
            kept = f.read() == "results of a week\n"
        check(p.returncode == 2 and "symbolic link" in p.stderr and kept and os.path.islink(link),
              f"{name}: a symbolic link to another file (--force): exit {p.returncode}, target "
              f"unchanged: {kept}; {p.stderr.strip()}")

        # 3. an existing file: refused without --force, unchanged; replaced with it
        existing = w.target("existing")
        with open(existing, "w") as f:
            f.write("an earlier run\n")
        p = w.run(existing, False)
        with open(existing) as f:
            kept = f.read() == "an earlier run\n"
        check(p.returncode == 2 and "exists" in p.stderr and "--force" in p.stderr and kept,
              f"{name}: an existing file without --force: exit {p.returncode}, unchanged: {kept}; "
              f"{p.stderr.strip()}")
        p = w.run(existing, True)
        check(p.returncode == 0 and w.wrote(existing),
              f"{name}: an existing file with --force: exit {p.returncode}, replaced: "
              f"{w.wrote(existing)} {p.stderr.strip()}")

        # 4. a new file
        new = w.target("new")
        p = w.run(new, False)
        check(p.returncode == 0 and w.wrote(new),
              f"{name}: a new file: exit {p.returncode} {p.stderr.strip()}")

        # 5. lagsimd --log --increment: FILE kept, the series' next file written (FILE.000000,
        #    then FILE.000001); a symbolic link's name is a number taken, its target untouched
        #    (the series itself: test_series.py)
        if a.writer == "lagsimd_log":
            before = digest(new)
            for k in ("000000", "000001"):
                p = w.lagsimd("--log", new, "--increment")
                nxt = f"{new}.{k}"
                check(p.returncode == 0 and digest(new) == before and os.path.exists(nxt)
                      and w.wrote(nxt) and f"writing {nxt}" in p.stderr,
                      f"{name}: --increment with the record there: exit {p.returncode}, kept: "
                      f"{digest(new) == before}, wrote {nxt}: {os.path.exists(nxt)}; {p.stderr.strip()}")
            os.symlink(precious, f"{new}.000002")
            p = w.lagsimd("--log", new, "--increment")
            check(p.returncode == 0 and os.path.exists(f"{new}.000003") and
                  open(precious).read() == "results of a week\n",
                  f"{name}: --increment skips a symbolic link's name: exit {p.returncode}")
            p = w.lagsimd("--log", new, "--increment", "--force")
            check(p.returncode == 2 and "not --force" in p.stderr,
                  f"{name}: --increment with --force refused: exit {p.returncode}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    sys.exit(verdict())


main()
