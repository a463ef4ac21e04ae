#!/usr/bin/env python3
"""The ABI check catches what it is for: the client library is built again from its
sources with one change each, as a developer might make it, and abi_check.py must judge
each as a compatible or incompatible change against the baseline, say what to raise, and
refuse to record it until that is raised.

    abi_mutations.py --check abi_check.py --source SRC --build BUILD --cc CC
                     --objects "O1;O2;..." --cflags "..." --libs "..."
                     --version X.Y.Z --abi N

Mutations (of clients/lagsim_client.h and lagsim_client.c, in a copy):
  same          nothing changed                          -> ok
  insert        a field inside lag_client_state           -> incompatible: raise the ABI
  retype        lag_client_event.value int64_t            -> incompatible
  remove        lag_client_kick no longer exported        -> incompatible
  append        a field at lag_client_state's end and a
                new function                              -> compatible: raise the minor
Recording: `append` is refused at this version and recorded at the next minor; `insert`
is refused at the next minor with this ABI number and recorded with the next one (its
soname liblagsim_client.so.N+1).
"""
import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)


def mutate(name, src, dst):
    """Copies of lagsim_client.h and .c into dst with mutation `name`; the version script
    to link with."""
    h = open(os.path.join(src, "clients/lagsim_client.h")).read()
    c = open(os.path.join(src, "clients/lagsim_client.c")).read()
    m = open(os.path.join(src, "clients/lagsim_client.map")).read()
    if name == "insert":
        h, n = re.subn(r"(typedef struct lag_client_state \{\n(?:.*\n)*?    double sim_time;[^\n]*\n)",
                       r"\1    double inserted_;\n", h, count=1)
        assert n == 1
    elif name == "retype":
        h, n = re.subn(r"(typedef struct lag_client_event \{\n(?:.*\n)*?)    double value;",
                       r"\1    int64_t value;", h, count=1)
        c = c.replace("o->value = m->value;", "o->value = (int64_t)m->value;")
        c = c.replace("o->value = ev->value;", "o->value = (double)ev->value;")
        assert n == 1
    elif name == "remove":
        m = m.replace("local:", "local:\n    lag_client_kick;")
    elif name == "append":
        h, n = re.subn(r"(typedef struct lag_client_state \{\n(?:.*\n)*?    double effort\[[^\n]*\n)",
                       r"\1    double appended_;\n", h, count=1)
        assert n == 1
        h = h.replace("double lag_client_now(void);",
                      "double lag_client_now(void);\nint lag_client_added(void);")
        c += "\nint lag_client_added(void) { return 1; }\n"
    open(os.path.join(dst, "lagsim_client.h"), "w").write(h)
    open(os.path.join(dst, "lagsim_client.c"), "w").write(c)
    open(os.path.join(dst, "lagsim_client.map"), "w").write(m)


def build(a, name, abi, tmp):
    d = os.path.join(tmp, name)
    os.makedirs(d)
    mutate(name, a.source, d)
    obj, lib = os.path.join(d, "lagsim_client.o"), os.path.join(d, "liblagsim_client.so.%d" % abi)
    # the copy's directory first: lagsim_client.c includes "lagsim_client.h" beside it
    inc = ["-I" + d, "-I" + os.path.join(a.source, "clients"),
           "-I" + os.path.join(a.build, "include"), "-I" + os.path.join(a.source, "server/wire"),
           "-I" + os.path.join(a.source, "server/include"),
           "-I" + os.path.join(a.build, "lcmtypes/c")]
    cmds = [[a.cc, "-std=c11", "-D_GNU_SOURCE", "-O2", "-g", "-fPIC"] + shlex.split(a.cflags) +
            inc + ["-c", os.path.join(d, "lagsim_client.c"), "-o", obj],
            [a.cc, "-shared", "-o", lib, "-Wl,-soname,liblagsim_client.so.%d" % abi,
             "-Wl,--version-script=" + os.path.join(d, "lagsim_client.map"), obj] +
            [o for o in a.objects.split(";") if o] + shlex.split(a.libs)]
    for cmd in cmds:
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           universal_newlines=True)
        if r.returncode != 0:
            sys.exit("abi_mutations: %s: %s\n%s" % (name, " ".join(cmd), r.stdout))
    return lib, os.path.join(d, "lagsim_client.h")


def run_check(a, lib, header, base_dir, version, abi, record=False):
    cmd = [sys.executable, a.check, "--library", lib, "--headers", header,
           os.path.join(a.build, "include/lagsim/version.h"),
           os.path.join(a.source, "server/include/lagsim/result.h"),
           "--baseline-dir", base_dir, "--version", version, "--abi", str(abi)]
    if record:
        cmd.append("--record")
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True)
    return r.returncode, r.stdout


def main():
    ap = argparse.ArgumentParser()
    for k in ("check", "source", "build", "cc", "objects", "version"):
        ap.add_argument("--" + k, required=True)
    ap.add_argument("--cflags", default="")
    ap.add_argument("--libs", default="")
    ap.add_argument("--abi", type=int, required=True)
    a = ap.parse_args()
    major, minor, _ = (int(x) for x in a.version.split("."))
    next_minor = "%d.%d.0" % (major, minor + 1)
    tmp = tempfile.mkdtemp(prefix="lagsim_abi_mut_")
    base = os.path.join(a.source, "clients/abi")
    try:
        lib, h = build(a, "same", a.abi, tmp)
        rc, out = run_check(a, lib, h, base, a.version, a.abi)
        check(rc == 0 and "ok:" in out, "unchanged: the baseline's ABI (exit %d)\n%s" % (rc, out))

        for name, what in (("insert", "a field inserted inside lag_client_state"),
                           ("retype", "lag_client_event.value made an int64_t"),
                           ("remove", "lag_client_kick no longer exported")):
            lib, h = build(a, name, a.abi, tmp)
            rc, out = run_check(a, lib, h, base, a.version, a.abi)
            check(rc == 1 and "an incompatible change" in out and
                  "raise LAGSIM_CLIENT_ABI in CMakeLists.txt from %d to %d" % (a.abi, a.abi + 1) in out
                  and "raise the minor version" in out and "lagsim_client_abi_record" in out,
                  "%s: an incompatible change, the ABI number and the minor version to raise "
                  "(exit %d)\n%s" % (what, rc, out))

        lib, h = build(a, "append", a.abi, tmp)
        rc, out = run_check(a, lib, h, base, a.version, a.abi)
        check(rc == 1 and "a compatible change" in out and "raise LAGSIM_CLIENT_ABI" not in out
              and "to %s" % next_minor in out,
              "a field appended at lag_client_state's end and a function added: a compatible "
              "change, the minor version to raise to %s (exit %d)\n%s" % (next_minor, rc, out))

        # recording: into a copy of the baseline directory
        work = os.path.join(tmp, "abi")
        shutil.copytree(base, work)
        rc, out = run_check(a, lib, h, work, a.version, a.abi, record=True)
        check(rc == 1 and "REFUSED" in out, "append recorded at %s: refused (exit %d)\n%s"
              % (a.version, rc, out))
        rc, out = run_check(a, lib, h, work, next_minor, a.abi, record=True)
        check(rc == 0 and os.path.exists(os.path.join(work, "liblagsim_client-%s.abi" % next_minor))
              and len(os.listdir(work)) == 1,
              "append recorded at %s: the new baseline replaces the old (exit %d)\n%s"
              % (next_minor, rc, out))
        rc, out = run_check(a, lib, h, work, next_minor, a.abi)
        check(rc == 0, "append against its own baseline: ok (exit %d)\n%s" % (rc, out))

        work2 = os.path.join(tmp, "abi2")
        shutil.copytree(base, work2)
        lib, h = build_named(a, "insert", a.abi, tmp, "insert_same")
        rc, out = run_check(a, lib, h, work2, next_minor, a.abi, record=True)
        check(rc == 1 and "REFUSED" in out and "raise LAGSIM_CLIENT_ABI" in out,
              "insert recorded at %s with ABI %d: refused (exit %d)\n%s" % (next_minor, a.abi, rc, out))
        lib, h = build_named(a, "insert", a.abi + 1, tmp, "insert_next")
        rc, out = run_check(a, lib, h, work2, next_minor, a.abi + 1, record=True)
        check(rc == 0 and "ABI %d" % (a.abi + 1) in out,
              "insert recorded at %s with ABI %d (soname .so.%d) (exit %d)\n%s"
              % (next_minor, a.abi + 1, a.abi + 1, rc, out))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return verdict()


def build_named(a, name, abi, tmp, label):
    d = os.path.join(tmp, label)
    os.makedirs(d)
    return build(a, name, abi, d)


if __name__ == "__main__":
    sys.exit(main())
