#!/usr/bin/env python3
"""lagsimd --log FILE --increment: a series of files that never runs out, --keep N that
removes only the series' own oldest files, --split-mb that goes on in the next file while
running, and a file-size limit (RLIMIT_FSIZE, a unit's LimitFSIZE) said, never a kill.

    test_series.py --bin BUILD/bin --types BUILD/python --source SRC CASE

Cases:
  numbering  FILE and 100 files FILE.00 ... FILE.99 there (what lcm-logger -i and earlier
             lagsimd wrote; once, lagsimd refused to start with exit 2): FILE.000000,
             FILE.000001, ... written, in the order `ls` and a glob sort, none of the 101
             touched; after FILE.999999, FILE.1000000 and FILE.1000001; a removed file's
             number is not reused (one past the highest)
  keep       --keep 3 among the series' own files, a symbolic link (to a file that must
             survive), a directory and another user's file at series numbers, and names
             that are not the series' (FILE.00, FILE.0000007, FILE.000008.bak, other
             prefixes): only the own oldest removed, each foreign entry and link target
             intact; said on stderr
  split      --split-mb 0.0625 --keep 2 on a fast run of about 355 kB: files cut at a
             record's end after 64 KiB, each a whole LCM log read by this file's reader,
             record numbers going on across files, 2 left; the last replays exactly
  options    --keep and --split-mb need --increment, ranges; under a file-size limit a
             --split-mb too large is refused (exit 2), a log without it stops at the limit
             with EFBIG said and the run going on (exit 1 at the end: the log is
             incomplete), not killed by SIGXFSZ
"""
import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_log import records  # noqa: E402  (tests/common/lcm_log.py)
from lcm_port import lcm_url  # noqa: E402  (tests/common/lcm_port.py)


def read_log(path):
    """[(eventnum, timestamp, channel, data)] of a whole LCM log (raises otherwise)."""
    return [r[:4] for r in records(path, whole=True)]


class Run:
    def __init__(self, a, tmp):
        self.a, self.tmp = a, tmp
        self.scene = os.path.join(a.source, "config", "dipc.yaml")
        self.prefix = f"LS{os.getpid()}"

    def lagsimd(self, *args, duration="0.2", fsize=None):
        def limit():
            if fsize is not None:
                resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))
        p = subprocess.run([os.path.join(self.a.bin, "lagsimd"), "--config", self.scene, "-q",
                            "--set", f"lcm.prefix={self.prefix}", "--set", "realtime.mode=fast",
                            "--set", "realtime.start=running", "--duration", duration, *args],
                           capture_output=True, text=True, timeout=120, cwd=self.tmp,
                           preexec_fn=limit)
        print(f"$ lagsimd {' '.join(args)}: exit {p.returncode}\n" +
              "".join("  | " + l + "\n" for l in p.stderr.splitlines()[-6:]), flush=True)
        return p


def listing(d):
    return sorted(os.listdir(d))


def case_numbering(r, tmp):
    base = os.path.join(tmp, "run.lcm")
    old = [base] + [f"{base}.{k:02d}" for k in range(100)]
    for k, p in enumerate(old):
        with open(p, "w") as f:
            f.write(f"record {k}\n")
    before = {p: open(p).read() for p in old}
    wrote = []
    for k in range(3):
        p = r.lagsimd("--log", "run.lcm", "--increment")
        name = f"run.lcm.{k:06d}"
        wrote.append(name)
        check(p.returncode == 0 and os.path.getsize(os.path.join(tmp, name)) > 1000 and
              f"writing {name}" in p.stderr,
              f"start {k + 1} with FILE and FILE.00 to .99 there: exit {p.returncode}, "
              f"wrote {name}")
    check(all(open(p).read() == t for p, t in before.items()),
          "FILE and FILE.00 ... FILE.99: none touched")
    check([n for n in listing(tmp) if len(n) == len("run.lcm.000000")] == wrote,
          "`ls` (a sorted glob) lists the series in the order it was written")
    # the numbers widen past 999999 and go on from the highest
    open(os.path.join(tmp, "run.lcm.999999"), "w").close()
    for name in ("run.lcm.1000000", "run.lcm.1000001"):
        p = r.lagsimd("--log", "run.lcm", "--increment")
        check(p.returncode == 0 and os.path.exists(os.path.join(tmp, name)),
              f"after run.lcm.999999: {name} written (exit {p.returncode})")
    # a removed file's number is not reused, even the lowest: one past the highest
    for name in ("run.lcm.1000000", "run.lcm.1000001", "run.lcm.999999"):
        os.remove(os.path.join(tmp, name))
    os.remove(os.path.join(tmp, "run.lcm.000001"))
    p = r.lagsimd("--log", "run.lcm", "--increment")
    check(p.returncode == 0 and os.path.exists(os.path.join(tmp, "run.lcm.000003")) and
          not os.path.exists(os.path.join(tmp, "run.lcm.000001")),
          "with run.lcm.000001 removed, the next is run.lcm.000003 (one past the highest)")


def case_keep(r, tmp):
    base = os.path.join(tmp, "run.lcm")
    precious = os.path.join(tmp, "precious.txt")
    with open(precious, "w") as f:
        f.write("results of a week\n")
    own = [0, 1, 2, 3, 7, 8, 9]
    for k in own:
        with open(f"{base}.{k:06d}", "w") as f:
            f.write(f"run {k}\n")
    os.symlink(precious, f"{base}.000004")            # a link at a series number
    os.mkdir(f"{base}.000005")                        # a directory there
    foreign = f"{base}.000006"                        # another user's file
    with open(foreign, "w") as f:
        f.write("not ours\n")
    root = os.geteuid() == 0
    if root:
        os.chown(foreign, 65534, 65534)
    others = [f"{base}.00", f"{base}.0000007", f"{base}.000008.bak", os.path.join(tmp, "other.lcm.000000"),
              os.path.join(tmp, "run.lcmx.000000"), base]
    for o in others:
        with open(o, "w") as f:
            f.write("not the series\n")
    p = r.lagsimd("--log", "run.lcm", "--increment", "--keep", "3")
    left = listing(tmp)
    expect_gone = [f"run.lcm.{k:06d}" for k in (0, 1, 2, 3, 7)] + ([] if root else ["run.lcm.000006"])
    check(p.returncode == 0 and "writing run.lcm.000010" in p.stderr,
          f"--keep 3: exit {p.returncode}, wrote run.lcm.000010 (one past the highest, the link's and the "
          f"directory's numbers counted)")
    check(all(n not in left for n in expect_gone) and
          all(f"run.lcm.{k:06d}" in left for k in (8, 9, 10)),
          f"the series' own files: the 3 newest left (8, 9, 10), the older removed: {left}")
    check(os.path.islink(f"{base}.000004") and open(precious).read() == "results of a week\n",
          "the symbolic link at a series number: not removed, its target intact")
    check(os.path.isdir(f"{base}.000005"), "the directory at a series number: left")
    if root:
        check(os.path.exists(foreign) and open(foreign).read() == "not ours\n",
              "another user's file at a series number: left")
    check(all(os.path.exists(o) and open(o).read() == "not the series\n" for o in others),
          "names that are not the series' (FILE, FILE.00, FILE.0000007, FILE.000008.bak, other "
          "prefixes): left")
    n_removed = len(expect_gone)
    check(f"--keep 3: {n_removed} older removed" in p.stderr,
          f"stderr says how many were removed ({n_removed})")


def case_split(r, tmp):
    p = r.lagsimd("--log", "run.lcm", "--increment", "--split-mb", "0.0625", "--keep", "2",
                  duration="20")
    files = [n for n in listing(tmp) if n.startswith("run.lcm.")]
    check(p.returncode == 0 and files == ["run.lcm.000004", "run.lcm.000005"],
          f"a run of about 355 kB split every 64 KiB into 6 files, 2 kept: {files}")
    nums = []
    for n in files:
        path = os.path.join(tmp, n)
        recs = read_log(path)   # raises unless whole
        nums += [num for num, _, _, _ in recs]
        last = 28 + len(recs[-1][2]) + len(recs[-1][3])
        size = os.path.getsize(path)
        check(n == files[-1] or 65536 <= size < 65536 + last,
              f"{n}: a whole LCM log of {len(recs)} records, {size} bytes (64 KiB and the record "
              f"that crossed it)")
    check(nums == list(range(nums[0], nums[0] + len(nums))),
          f"record numbers go on across the files ({nums[0]} to {nums[-1]})")
    rp = subprocess.run([os.path.join(r.a.bin, "lagsimd"), "--config", r.scene, "--set",
                         f"lcm.prefix={r.prefix}", "--replay", os.path.join(tmp, files[-1])],
                        capture_output=True, text=True, timeout=120)
    check(rp.returncode == 0 and "max difference = 0\n" in rp.stdout,
          f"the last file replays from its first state, exactly (exit {rp.returncode})")


def case_options(r, tmp):
    for args, what in ((["--keep", "3"], "--increment"), (["--split-mb", "1"], "--increment"),
                       (["--increment", "--keep", "0"], "--keep"),
                       (["--increment", "--keep", "2.5"], "--keep"),
                       (["--increment", "--split-mb", "0.01"], "--split-mb")):
        p = r.lagsimd("--log", "run.lcm", *args)
        check(p.returncode == 2 and what in p.stderr and not os.listdir(tmp),
              f"{' '.join(args)}: exit {p.returncode}, {what} named, nothing written")
    # under a file-size limit of 1 MiB: --split-mb 2 (plus a 0.25 MiB ring) refused
    p = r.lagsimd("--log", "run.lcm", "--increment", "--split-mb", "2", "--log-buffer", "0.25",
                  fsize=1 << 20)
    check(p.returncode == 2 and "RLIMIT_FSIZE" in p.stderr and not os.listdir(tmp),
          f"--split-mb above the file-size limit: exit {p.returncode}, said")
    p = r.lagsimd("--log", "run.lcm", "--increment", "--split-mb", "0.0625", "--log-buffer", "0.25",
                  fsize=1 << 20, duration="10")
    check(p.returncode == 0 and len(os.listdir(tmp)) >= 2,
          f"--split-mb below it: exit {p.returncode}, {len(os.listdir(tmp))} files")
    for n in os.listdir(tmp):
        os.remove(os.path.join(tmp, n))
    # a log that cannot split stops at the limit: EFBIG said, the run goes on, exit 1
    p = r.lagsimd("--log", "run.lcm", fsize=100000, duration="10")
    check(p.returncode == 1 and "File too large" in p.stderr and "INCOMPLETE" in p.stderr,
          f"a log at the file-size limit: exit {p.returncode} (not killed by SIGXFSZ), "
          f"'File too large' said")
    check("limited to" in p.stderr and os.path.getsize(os.path.join(tmp, "run.lcm")) <= 100000,
          "the limit is said at start; the file stops at it")


CASES = {"numbering": case_numbering, "keep": case_keep, "split": case_split,
         "options": case_options}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--types", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("case", choices=sorted(CASES))
    a = ap.parse_args()
    os.environ["LCM_DEFAULT_URL"] = lcm_url()  # a port pair of this process's own
    a.bin, a.types, a.source = (os.path.abspath(x) for x in (a.bin, a.types, a.source))
    tmp = tempfile.mkdtemp(prefix="lagsim_series_")
    try:
        CASES[a.case](Run(a, tmp), tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
