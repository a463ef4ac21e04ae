#!/usr/bin/env python3
"""Every program's documented exit statuses against the one result table (lagsim/result.h).

usage: exit_docs.py TEST_RESULT BIN_DIR MAN_DIR SOURCE_DIR

For each program: the statuses its man page's EXIT STATUS section lists and the ones its
--help lists are the same set; each is an exit status of the table; the status both call
"usage" is lag_result_exit(LAG_ERR_USAGE), the first one lag_result_exit(LAG_OK); and the
program itself exits with those for --help and for an unknown option. The Python and Lua
controller frameworks' docs, which mirror the C controllers' statuses, are read too.
Fails, naming the program and the disagreement, when a page, a --help or a program drifts
from the table.
"""
import os
import re
import subprocess
import sys

test_result, bindir, mandir, srcdir = sys.argv[1:5]

table = {}
for line in subprocess.run([test_result, "--table"], capture_output=True, text=True,
                           check=True).stdout.split("\n"):
    if line.strip():
        name, value, status = line.split()
        table[name] = int(status)
statuses = set(table.values())
USAGE, OK = table["LAG_ERR_USAGE"], table["LAG_OK"]

# program, man page, what its statuses are called in both texts ({word: code})
PROGRAMS = [
    ("lagsimd", "lagsimd.1", {"usage": "LAG_ERR_USAGE", "run-?time": "LAG_ERR_RUNTIME"}),
    ("lagsimctl", "lagsimctl.1", {"usage": "LAG_ERR_USAGE", "refused": "LAG_ERR_REFUSED",
                                  "no answer": "LAG_ERR_NOANSWER"}),
    ("lagsim-eval", "lagsim-eval.1", {"usage": "LAG_ERR_USAGE", "failed": "LAG_ERR_MISMATCH"}),
    ("lagsim-sweep", "lagsim-sweep.1", {"usage": "LAG_ERR_USAGE", "failed": "LAG_ERR_MISMATCH"}),
    ("lagsim-log2csv", "lagsim-log2csv.1", {"usage": "LAG_ERR_USAGE",
                                            "ends in an error": "LAG_ERR_RUNTIME"}),
    ("lagsim-view", "lagsim-view.1", {"usage": "LAG_ERR_USAGE", "runtime": "LAG_ERR_RUNTIME"}),
    ("lagsim-plot", "lagsim-plot.1", {"usage": "LAG_ERR_USAGE"}),
    ("dipc_lqr", "lagsim-controllers.1", {"usage": "LAG_ERR_USAGE", "no scene": "LAG_ERR_RUNTIME"}),
    ("lqr_balance", "lagsim-controllers.1", {"usage": "LAG_ERR_USAGE"}),
    ("manipulator_pd", "lagsim-controllers.1", {"usage": "LAG_ERR_USAGE"}),
    ("stick_push", "lagsim-controllers.1", {"usage": "LAG_ERR_USAGE"}),
]

failures = []


def fail(prog, msg):
    failures.append("%s: %s" % (prog, msg))


def man_statuses(path):
    """{status: text} from the page's EXIT STATUS section (.TP/.B N lists or one line)."""
    text = open(path).read()
    m = re.search(r'^\.SH "?EXIT STATUS"?\n(.*?)(?=^\.SH|\Z)', text, re.M | re.S)
    if not m:
        return None
    sec = m.group(1)
    out = {}
    items = re.split(r"^\.B (\d)\s*$", sec, flags=re.M)
    if len(items) > 1:
        for k in range(1, len(items), 2):
            out[int(items[k])] = re.sub(r"^\.\w+\s*", "", items[k + 1], flags=re.M)
        return out
    return inline_statuses(re.sub(r"^\.\w+\s*", "", sec, flags=re.M))


def inline_statuses(text):
    """'0 ok, 1 runtime failure, 2 usage ...' -> {0: 'ok', 1: 'runtime failure', ...}"""
    text = " ".join(text.split())
    parts = re.split(r"(?:^|(?<=[\s,;:]))(\d) (?=[A-Za-z])", text)
    return {int(parts[k]): parts[k + 1] for k in range(1, len(parts) - 1, 2)}


def help_statuses(text):
    """The statuses of the paragraph of --help that starts 'exit codes:' / 'exit status:'."""
    m = re.search(r"exit (?:codes|status):(.*?)(?:\n\s*\n|\Z)", text, re.I | re.S)
    return inline_statuses(m.group(1)) if m else None


def check_statuses(prog, where, got, words):
    if got is None:
        fail(prog, "%s states no exit statuses" % where)
        return
    for s in got:
        if s not in statuses:
            fail(prog, "%s gives exit status %d, which no code of the table has" % (where, s))
    if min(got) != OK:
        fail(prog, "%s: its first status is %d, lag_result_exit(LAG_OK) is %d" % (where, min(got), OK))
    for word, code in words.items():
        said = [s for s, t in got.items() if re.search(word, t, re.I)]
        if not said:
            fail(prog, "%s says no status for '%s'" % (where, word))
        elif table[code] not in said:
            fail(prog, "%s: '%s' is status %s, the table's %s is %d" % (where, word, said, code,
                                                                    table[code]))


for prog, page, words in PROGRAMS:
    exe = os.path.join(bindir, prog)
    if not os.path.exists(exe):
        fail(prog, "not built at %s" % exe)
        continue
    man = man_statuses(os.path.join(mandir, page))
    h = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=30)
    helped = help_statuses(h.stdout + h.stderr)
    check_statuses(prog, page, man, words)
    check_statuses(prog, "--help", helped, words)
    if man is not None and helped is not None and set(man) != set(helped):
        fail(prog, "%s lists statuses %s, --help %s" % (page, sorted(man), sorted(helped)))
    if h.returncode != OK:
        fail(prog, "--help exits %d, lag_result_exit(LAG_OK) is %d" % (h.returncode, OK))
    b = subprocess.run([exe, "--no-such-option"], capture_output=True, text=True, timeout=30)
    if b.returncode != USAGE:
        fail(prog, "an unknown option exits %d, lag_result_exit(LAG_ERR_USAGE) is %d"
             % (b.returncode, USAGE))
    print("%-15s man %s, --help %s" % (prog, sorted(man or {}), sorted(helped or {})))

# the other languages' controller frameworks mirror the C controllers' statuses
page = man_statuses(os.path.join(mandir, "lagsim-controllers.1"))
for path in ["clients/python/lagsim_controller.py", "clients/lua/lagsim_controller.lua"]:
    text = open(os.path.join(srcdir, path)).read()
    m = re.search(r"Exit\s+status:(.*?\.)\s", text, re.S)
    got = inline_statuses(m.group(1)) if m else None
    check_statuses(path, "its doc", got, {"usage": "LAG_ERR_USAGE", "no scene": "LAG_ERR_RUNTIME"})
    if got is not None and page is not None and set(got) != set(page):
        fail(path, "its doc lists statuses %s, lagsim-controllers.1 %s" % (sorted(got), sorted(page)))

for f in failures:
    print("FAIL " + f, file=sys.stderr)
print("%d programs checked, %d disagreements" % (len(PROGRAMS) + 2, len(failures)))
sys.exit(1 if failures else 0)
