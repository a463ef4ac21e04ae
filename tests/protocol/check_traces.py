#!/usr/bin/env python3
"""The conformance traces against what is written about them (ctest protocol_traces):

    check_traces.py [SOURCE_DIR]

- every trace of tests/protocol/traces/ reads (play.py's reader), uses only the steps
  play.py knows, sends and expects only messages it defined, and names its steps'
  ids once;
- docs/protocol.md's table of traces has a row for each trace file and for no other,
  its format table a row for each step play.py knows and for no other, and its table of
  types a row for each file of lcmtypes/ and for no other;
- each trace has a negative test in tests/protocol.cmake (a controller broken on purpose
  that must fail it at one of its steps), with the rule the table names for it;
- each fingerprint a trace forges as an earlier version's is one that docs/wire.md's
  table of versions gives.
Exit 0, or 1 naming each disagreement.
"""
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import play  # noqa: E402

problems = []


def fail(msg):
    problems.append(msg)
    print("FAIL " + msg)


def table_rows(text, header):
    """The first cells of the rows of the markdown table under the line `header`."""
    at = text.find(header)
    if at < 0:
        return None
    rows = []
    for line in text[at:].split("\n")[2:]:
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


def check_trace(path, known_do, known_what, whole=True):
    name = os.path.basename(path)
    try:
        steps = play.read_trace(path)
    except play.TraceError as e:
        fail(str(e))
        return []
    defined, named, ids = set(), set(), []
    for s in steps:
        where, do = s["_where"], s["do"]
        if do not in known_do:
            fail("%s: unknown step %r" % (where, do))
        if do == "define":
            if "like" in s and s["like"] not in defined:
                fail("%s: like %r, which is not defined before" % (where, s["like"]))
            defined.add(s["name"])
        for key in ("msg", "answers", "scene"):
            if key in s and s[key] not in defined:
                fail("%s: %s %r is not defined before" % (where, key, s[key]))
        if do == "on_describe" and s.get("send") is not None and s["send"] not in defined:
            fail("%s: on_describe sends %r, which is not defined" % (where, s["send"]))
        if do == "expect":
            if s.get("what") not in known_what:
                fail("%s: unknown expectation %r" % (where, s.get("what")))
            for key in ("same_as", "of"):
                if key in s and s[key] not in named:
                    fail("%s: %s %r names no command expected before" % (where, key, s[key]))
            if "name" in s:
                named.add(s["name"])
        if "id" in s:
            ids.append(s["id"])
    for i in set(ids):
        if ids.count(i) > 1:
            fail("%s: step id %r %d times" % (name, i, ids.count(i)))
    if whole and steps and steps[-1]["do"] != "end":
        fail("%s: its last step is not end" % name)
    return steps


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", ".."))
    tdir = os.path.join(root, "tests", "protocol", "traces")
    known_do = {k[3:] for k in dir(play.Player) if k.startswith("do_")} | {"include"}
    known_what = {k[7:] for k in dir(play.Player) if k.startswith("expect_")}
    files = sorted(f for f in os.listdir(tdir) if f.endswith(".trace"))
    traces = [f[:-6] for f in files if f != "common.trace"]
    steps = {t: check_trace(os.path.join(tdir, t + ".trace"), known_do, known_what) for t in traces}
    check_trace(os.path.join(tdir, "common.trace"), known_do, known_what, whole=False)

    with open(os.path.join(root, "docs", "protocol.md")) as f:
        doc = f.read()
    rows = table_rows(doc, "| trace | what it checks |")
    if rows is None:
        fail("docs/protocol.md: no table \"| trace | what it checks |\"")
        rows = []
    documented = {r[0].strip("`"): r for r in rows}
    for t in traces:
        if t not in documented:
            fail("docs/protocol.md's table of traces has no row for %s.trace" % t)
    for t in documented:
        if t not in traces:
            fail("docs/protocol.md's table of traces names %s, which is no trace" % t)
    lcm = sorted(f[:-4] for f in os.listdir(os.path.join(root, "lcmtypes")) if f.endswith(".lcm"))
    types = sorted(r[0].strip("`") for r in (table_rows(doc, "| type | file | carries |") or []))
    if types != lcm:
        fail("docs/protocol.md's table of types has %s; lcmtypes/ has %s" % (types, lcm))
    fmt = table_rows(doc, "| step | does |") or []
    in_doc = set()
    for r in fmt:
        m = re.search(r'"do": "(\w+)"(?:, "what": "(\w+)")?', r[0])
        if m:
            in_doc.add(m.group(2) or m.group(1))
    player = (known_do - {"expect"}) | known_what
    for k in sorted(player - in_doc):
        fail("docs/protocol.md's format table has no row for the step %r that play.py knows" % k)
    for k in sorted(in_doc - player):
        fail("docs/protocol.md's format table names a step %r that play.py does not know" % k)

    with open(os.path.join(root, "tests", "protocol.cmake")) as f:
        cmake = f.read()
    negs = re.findall(r'"(\w+):(\w+):(\w+)"', cmake)
    for t in traces:
        mine = [(rule, step) for tr, rule, step in negs if tr == t]
        if not mine:
            fail("%s.trace has no negative test in tests/protocol.cmake (a broken controller "
                 "it must fail)" % t)
        ids = {s.get("id") for s in steps.get(t, [])}
        for rule, step in mine:
            if step not in ids:
                fail("tests/protocol.cmake: %s.trace has no step %r" % (t, step))
            if t in documented and "`%s`" % rule not in documented[t][2]:
                fail("docs/protocol.md's row of %s does not name its broken rule `%s`" % (t, rule))

    with open(os.path.join(root, "docs", "wire.md")) as f:
        wire = f.read()
    known_fp = set(re.findall(r"`0x([0-9a-f]{16})`", wire))
    for t, ss in steps.items():
        for s in ss:
            fp = s.get("forge", {}).get("fingerprint")
            if fp and fp != "0" * 16 and fp not in known_fp:
                fail("%s: fingerprint %s is none of docs/wire.md's earlier versions" % (s["_where"], fp))
    print("%d traces, %d negative tests: %s" % (len(traces), len(negs),
                                                 "%d problems" % len(problems) if problems else "ok"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
