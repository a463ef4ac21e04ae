#!/usr/bin/env python3
"""lagsim.examples.Messages for MATLAB/Octave users: docs/clients.md's table of its methods
is the class's, and GNU Octave lists them.

    messages_methods.py --build BUILD --source SRC

  - lagsim_methods('lagsim.examples.Messages') after lagsim_setup() (the jars on Octave's
    dynamic class path, where Octave 7's methods() cannot find the class) prints the
    class's methods with their signatures;
  - methods('lagsim.examples.Messages', '-full') with the jars on the static class path (a
    javaclasspath.txt in the folder Octave starts in) prints the same;
  - the table between <!-- messages-methods --> markers in docs/clients.md names exactly
    the class's own methods (those of java.lang.Object left out), with their return types.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

OBJECT = {"wait", "equals", "toString", "hashCode", "getClass", "notify", "notifyAll"}


def octave(code, cwd, path=None):
    args = ["octave", "--no-gui", "--quiet", "--norc"] + (["--path", path] if path else [])
    p = subprocess.run(args + ["--eval", code], cwd=cwd, stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=180)
    print(p.stdout[-1500:], p.stderr[-600:])
    return p


def own(lines):
    """{'rettype name(args)'} of the class's own methods."""
    out = set()
    for l in lines:
        m = re.match(r"\s*(\S+) (\w+)\((.*)\)", l)
        if m and m.group(2) not in OBJECT:
            out.add("%s %s(%s)" % (m.group(1), m.group(2), m.group(3)))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    build, src = os.path.abspath(a.build), os.path.abspath(a.source)
    text = open(os.path.join(src, "docs", "clients.md")).read()
    m = re.search(r"<!-- messages-methods -->\n(.*?)<!-- /messages-methods -->", text, re.S)
    rows = re.findall(r"^\| `([^`]+)` \| `([^`]+)` \|", m.group(1) if m else "", re.M)
    table = {"%s %s" % (ret, sig) for sig, ret in rows if sig != "method"}
    check(len(table) == 3, "docs/clients.md: the table of Messages' methods (%d rows)" % len(table))
    with tempfile.TemporaryDirectory() as tmp:
        p = octave("lagsim_setup(); lagsim_methods('lagsim.examples.Messages');", tmp,
                   os.path.join(build, "octave"))
        dyn = own(p.stdout.splitlines())
        check(p.returncode == 0 and dyn == table, "lagsim_methods (dynamic class path): the "
              "class's methods are the table's: %s" % sorted(dyn ^ table))
        with open(os.path.join(tmp, "javaclasspath.txt"), "w") as f:
            for jar in ("/usr/share/java/lcm.jar", os.path.join(build, "lagsim_types.jar"),
                        os.path.join(build, "lagsim_examples.jar")):
                f.write(jar + "\n")
        p = octave("methods('lagsim.examples.Messages', '-full')", tmp)
        stat = own(p.stdout.splitlines())
        check(p.returncode == 0 and stat == table, "methods(..., '-full') with the jars on the "
              "static class path: the same (%s)" % sorted(stat ^ table))
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
