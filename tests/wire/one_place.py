#!/usr/bin/env python3
"""One fact, one place, for the wire layer's infrastructure (server/wire):

  clock     only server/wire/lagsim_clock.c reads a clock (clock_gettime, gettimeofday,
            timespec_get, ftime); every other file calls lag_clock_*;
  url       only server/wire/lagsim_url.c takes an LCM URL apart (compares it with
            "udpm://", "memq://", "://", or looks for its options ttl, recv_buf_size);
  channels  only server/wire/lagsim_bus.c spells a channel suffix ("_STATE", "%s_COMMAND",
            ...): the suffixes are read from its table, and a string literal elsewhere
            that is one, or has one right after a %s, is a second copy; names are built
            with lag_bus_channel_name / lag_bus_suffix;
  num       in server/ and clients/, only server/wire/lagsim_num.c prints a double at a
            fixed 15 to 17 digits (%.15g, %.16g, %.17g): a number printed to be read back
            is lag_num's, the shortest decimal that reads back (0.1, not
            0.10000000000000001). (bench/ writes its peers' model files and its own data.)

Looks at the C files (.c, .h) under server/, clients/ and bench/, comments left out.
A few files wait to move (EXEMPT below): the check fails when one of them no longer needs
its exemption too, so the list only shrinks.

usage: one_place.py SOURCE_DIR clock|url|channels|num
"""
import os
import re
import sys

CLOCK_FILE = "server/wire/lagsim_clock.c"
URL_FILE = "server/wire/lagsim_url.c"
TABLE_FILE = "server/wire/lagsim_bus.c"
NUM_FILE = "server/wire/lagsim_num.c"
DIRS = ("server", "clients", "bench")

# (check, file): files that still hold a copy and are to call the wire layer instead.
EXEMPT = {
    ("channels", "clients/lagsim_controller.c"),  # messages naming <PREFIX>_SCENE
    # the C controllers' --trace lines and printed gains are compared as text with the
    # Python, Lua, Java and Octave controllers', which print %.17g (docs/clients.md)
    ("num", "clients/lagsim_controller.c"),
    ("num", "clients/dipc_lqr.c"),
    ("num", "clients/lqr_balance.c"),
    ("num", "clients/stick_push.c"),
    # server/eval links only libm: two sample times in an error message
    ("num", "server/eval/metrics.c"),
}


def split_c(text):
    """(code with comments blanked, [(line, literal body)]) of a C source."""
    code, lits = [], []
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            i = j
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            nl = text.count("\n", i, j)
            code.append("\n" * nl if nl else " ")
            line += nl
            i = j
            continue
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            if c == '"':
                lits.append((line, text[i + 1:j]))
            code.append(text[i:j + 1])
            i = j + 1
            continue
        if c == "\n":
            line += 1
        code.append(c)
        i += 1
    return "".join(code), lits


def sources(root):
    for d in DIRS:
        for dirpath, _, files in os.walk(os.path.join(root, d)):
            for f in sorted(files):
                if f.endswith((".c", ".h")):
                    p = os.path.join(dirpath, f)
                    yield os.path.relpath(p, root), p


def line_of(code, pos):
    return code.count("\n", 0, pos) + 1


NUM_RE = re.compile(r"%[-+ #0]*\.1[5-7][lL]?[gGeE]")
CLOCK_RE = re.compile(r"\b(clock_gettime|gettimeofday|timespec_get|ftime)\s*\(")
URL_RE = re.compile(r"\b(strn?cmp|strn?casecmp|strstr|memcmp|sscanf)\s*\([^;]*?"
                    r"\"(udpm://|memq://|://|ttl|recv_buf_size)")


def suffixes(root):
    """The channel suffixes of the table in lagsim_bus.c."""
    with open(os.path.join(root, TABLE_FILE)) as f:
        code, _ = split_c(f.read())
    m = re.search(r"suffix\[[A-Z_]+\]\s*=\s*\{(.*?)\};", code, re.S)
    if not m:
        sys.exit("one_place: no table of suffixes in " + TABLE_FILE)
    found = re.findall(r"=\s*\"(_[A-Z]+)\"", m.group(1))
    if len(found) < 7:
        sys.exit("one_place: the table in %s has %d suffixes" % (TABLE_FILE, len(found)))
    return found


def findings(root, check):
    """{file: [line, ...]} of the copies the check finds outside the one place."""
    out = {}
    if check == "channels":
        sfx = "|".join(s[1:] for s in suffixes(root))
        lit_re = re.compile(r"^_(" + sfx + r")$|%[-+ #0-9.*]*s_(" + sfx + r")\b")
    for rel, path in sources(root):
        if rel == {"clock": CLOCK_FILE, "url": URL_FILE, "channels": TABLE_FILE,
                   "num": NUM_FILE}[check] or (check == "num" and rel.startswith("bench/")):
            continue
        with open(path, errors="replace") as f:
            code, lits = split_c(f.read())
        if check == "clock":
            lines = [line_of(code, m.start()) for m in CLOCK_RE.finditer(code)]
        elif check == "url":
            lines = [line_of(code, m.start()) for m in URL_RE.finditer(code)]
        elif check == "num":
            lines = [ln for ln, body in lits if NUM_RE.search(body)]
        else:
            lines = [ln for ln, body in lits if lit_re.search(body)]
        if lines:
            out[rel] = lines
    return out


def main():
    if len(sys.argv) != 3 or sys.argv[2] not in ("clock", "url", "channels", "num"):
        sys.exit(__doc__)
    root, check = sys.argv[1], sys.argv[2]
    what = {"clock": "reads a clock: call lag_clock_* (" + CLOCK_FILE + ")",
            "url": "takes an LCM URL apart: call lag_url_parse (" + URL_FILE + ")",
            "channels": "spells a channel suffix: use lag_bus_channel_name / lag_bus_suffix ("
                        + TABLE_FILE + ")",
            "num": "prints a number at 15 to 17 digits: call lag_num (" + NUM_FILE + ")"}[check]
    bad = 0
    found = findings(root, check)
    for rel, lines in sorted(found.items()):
        if (check, rel) in EXEMPT:
            continue
        for ln in lines:
            print("%s:%d: %s" % (rel, ln, what))
            bad += 1
    for c, rel in sorted(EXEMPT):
        if c == check and rel not in found:
            print("%s: exempt from the %s check but no longer needs it: drop it from EXEMPT in %s"
                  % (rel, check, "tests/wire/one_place.py"))
            bad += 1
    n = sum(len(v) for k, v in found.items() if (check, k) in EXEMPT)
    print("one_place %s: %d found, %d waiting in exempt files" % (check, bad, n))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
