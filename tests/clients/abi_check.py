#!/usr/bin/env python3
"""The client library's ABI against the baseline kept in the repository (abigail-tools).

    abi_check.py --library LIB.so --headers H.h... --baseline-dir clients/abi
                 --version X.Y.Z --abi N [--record [--same-version]]

The baseline is clients/abi/liblagsim_client-<version>.abi: `abidw` of the library as it
was recorded, at that lagsim version (the file's name), for the ABI number its soname
carries (liblagsim_client.so.<N>). The built library is compared with it by `abidiff`:

- no change: passes;
- a compatible change (functions added, fields appended at the end of a struct, which the
  library fills at the caller's size): fails until the minor version is raised
  (project(VERSION) in CMakeLists.txt) and the baseline recorded again;
- an incompatible change (a function or symbol removed or changed, a field moved,
  removed or retyped, anything this script cannot prove harmless): fails until
  LAGSIM_CLIENT_ABI (CMakeLists.txt) and the minor version are raised and the baseline
  recorded again.

Each failure says which of these it is and the commands that settle it. --record writes
the baseline (the cmake target lagsim_client_abi_record runs it) and refuses to when the
rules above are not met against the baseline it replaces; --same-version records over a
baseline of the same version (only while that version is unreleased).
Exit status: 0 ok (or recorded), 1 the ABI moved without what it needs, 2 usage or tools.
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile

RECORD = "cmake --build <build> --target lagsim_client_abi_record"


def abidw(lib, headers, out):
    """abidw of lib, its types those of the public headers only, without locations or
    paths (so that the baseline depends on the ABI, not on where the tree is)."""
    hdir = tempfile.mkdtemp(prefix="lagsim_abi_headers_")
    try:
        for h in headers:  # the public headers, in one directory
            shutil.copy(h, hdir)
        r = subprocess.run(["abidw", "--no-corpus-path", "--no-comp-dir-path", "--no-show-locs",
                            "--headers-dir", hdir, "--drop-private-types", "--out-file", out,
                            lib], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           universal_newlines=True)
        if r.returncode != 0:
            sys.exit("abi_check: abidw %s failed:\n%s" % (lib, r.stdout))
    finally:
        shutil.rmtree(hdir, ignore_errors=True)


def soname_abi(abi_xml):
    """The N of soname='liblagsim_client.so.N' in an abidw file, or None."""
    with open(abi_xml) as f:
        m = re.search(r"soname='liblagsim_client\.so\.(\d+)'", f.read(4096))
    return int(m.group(1)) if m else None


def classify(report):
    """'compatible' or 'incompatible' for an abidiff --leaf-changes-only report with
    changes, and the lines that decided it. Compatible: only additions (functions,
    variables, symbols) and struct members inserted at or after the struct's old end."""
    bad = []
    for m in re.finditer(r"(\d+) Removed", report):
        if int(m.group(1)):
            bad.append("removed: " + report[m.start():report.find("\n", m.start())])
    for m in re.finditer(r"(\d+) Changed", report):
        if int(m.group(1)):
            bad.append("changed: " + report[m.start():report.find("\n", m.start())])
    # each changed type: its lines after "'<type>' changed:"
    for block in re.split(r"\n(?='[^'\n]+' changed:)", report):
        head = block.split("\n", 1)[0]
        if not re.match(r"'[^']+' changed:", head):
            continue
        old_size = None
        for line in block.split("\n")[1:]:
            s = line.strip()
            if not s:
                continue
            m = re.match(r"type size changed from (\d+) to (\d+) \(in bits\)", s)
            if m:
                old_size = int(m.group(1))
                if int(m.group(2)) < old_size:
                    bad.append(head + " " + s)
                continue
            if re.match(r"\d+ data member insertions?:", s):
                continue
            m = re.match(r"'[^']+', at offset (\d+) \(in bits\)", s)
            if m and old_size is not None and int(m.group(1)) >= old_size:
                continue  # appended at the end
            bad.append(head + " " + s)
    return ("incompatible" if bad else "compatible"), bad


def compare(baseline, current):
    """abidiff of the two: (verdict, report), verdict None when there is no change."""
    r = subprocess.run(["abidiff", "--leaf-changes-only", baseline, current],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    if r.returncode & 3:
        sys.exit("abi_check: abidiff failed (exit %d):\n%s" % (r.returncode, r.stdout))
    if r.returncode == 0:
        return None, r.stdout
    verdict, why = classify(r.stdout)
    if r.returncode & 8:
        verdict = "incompatible"
    return verdict, r.stdout + ("\ndecided by:\n  " + "\n  ".join(why) if why else "")


def vtuple(v):
    return tuple(int(x) for x in v.split("."))


def baseline_file(d):
    files = sorted(glob.glob(os.path.join(d, "liblagsim_client-*.abi")))
    if len(files) > 1:
        sys.exit("abi_check: more than one baseline in %s: %s (keep the newest)" % (d, files))
    return files[0] if files else None


def needs(verdict, base_version, base_abi, version, abi):
    """What the change still needs before it may be recorded: a list of sentences."""
    todo = []
    minor_up = vtuple(version)[:2] > vtuple(base_version)[:2]
    if verdict == "incompatible" and abi <= base_abi:
        todo.append("raise LAGSIM_CLIENT_ABI in CMakeLists.txt from %d to %d (a program built "
                    "against lagsim %s's lagsim_client.h would break: SONAME "
                    "liblagsim_client.so.%d)" % (abi, base_abi + 1, base_version, base_abi + 1))
    if verdict == "compatible" and abi != base_abi:
        todo.append("keep LAGSIM_CLIENT_ABI at %d: the change is compatible" % base_abi)
    if verdict and not minor_up:
        major, minor, _ = vtuple(base_version)
        todo.append("raise the minor version in project(lagsim VERSION ...) of CMakeLists.txt "
                    "from %s to %d.%d.0" % (version, major, minor + 1))
    return todo


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--library", required=True)
    ap.add_argument("--headers", nargs="+", required=True)
    ap.add_argument("--baseline-dir", required=True)
    ap.add_argument("--version", required=True)
    ap.add_argument("--abi", type=int, required=True)
    ap.add_argument("--record", action="store_true")
    ap.add_argument("--same-version", action="store_true")
    a = ap.parse_args()
    for tool in ("abidw", "abidiff"):
        if not shutil.which(tool):
            print("abi_check: %s not found (Debian: apt-get install abigail-tools)" % tool)
            return 2
    tmp = tempfile.mkdtemp(prefix="lagsim_abi_")
    try:
        current = os.path.join(tmp, "current.abi")
        abidw(a.library, a.headers, current)
        if soname_abi(current) != a.abi:
            print("FAIL: %s has soname ABI %s, CMakeLists.txt's LAGSIM_CLIENT_ABI is %d"
                  % (a.library, soname_abi(current), a.abi))
            return 1
        base = baseline_file(a.baseline_dir)
        if base is None:
            if not a.record:
                print("FAIL: no baseline in %s: record one with %s" % (a.baseline_dir, RECORD))
                return 1
            return record(a, current, None)
        base_version = re.search(r"liblagsim_client-(.+)\.abi$", base).group(1)
        base_abi = soname_abi(base)
        verdict, report = compare(base, current)
        where = "%s (lagsim %s, ABI %d)" % (os.path.join(os.path.basename(os.path.dirname(base)),
                                                         os.path.basename(base)),
                                            base_version, base_abi)
        if a.record:
            todo = needs(verdict, base_version, base_abi, a.version, a.abi)
            if verdict and vtuple(a.version) == vtuple(base_version) and a.same_version:
                todo = [t for t in todo if "minor version" not in t]
            if todo and vtuple(a.version) == vtuple(base_version) and not a.same_version:
                todo.append("or, while %s is unreleased (no program was built against its "
                            "header), run this with --same-version" % a.version)
            if todo:
                print("REFUSED: the library's ABI has a%s %s change from %s; before recording:\n"
                      "  - %s\n%s" % ("n" if verdict == "incompatible" else "", verdict, where,
                                      "\n  - ".join(todo), report))
                return 1
            if verdict is None and base_version == a.version and base_abi == a.abi:
                print("abi_check: %s is the library's ABI already" % where)
                return 0
            return record(a, current, base)
        if verdict is None:
            if base_abi != a.abi:
                print("FAIL: LAGSIM_CLIENT_ABI is %d but %s is ABI %d and the ABI did not "
                      "change: put LAGSIM_CLIENT_ABI back to %d" % (a.abi, where, base_abi,
                                                                     base_abi))
                return 1
            print("ok: the library's ABI is %s's" % where)
            return 0
        todo = needs(verdict, base_version, base_abi, a.version, a.abi)
        todo.append("record the baseline: %s (it checks the above)" % RECORD)
        print("FAIL: the library's ABI has a%s %s change from %s. Either undo it, or:\n  - %s\n"
              "\nabidiff --leaf-changes-only:\n%s"
              % ("n" if verdict == "incompatible" else "", verdict, where,
                 "\n  - ".join(todo), report))
        return 1
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def record(a, current, old):
    new = os.path.join(a.baseline_dir, "liblagsim_client-%s.abi" % a.version)
    os.makedirs(a.baseline_dir, exist_ok=True)
    shutil.copy(current, new)
    if old and os.path.abspath(old) != os.path.abspath(new):
        os.remove(old)
    print("recorded %s (ABI %d)%s" % (new, a.abi, "; removed " + old if old and old != new else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
