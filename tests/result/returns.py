#!/usr/bin/env python3
"""The old mixed returns stay gone: one result space, one mapping to exit statuses.

usage: returns.py SOURCE_DIR

- the loader's, the client's, lagsimd's and log2csv's functions are declared lag_result;
- no function typed lag_result returns a bare number (a -1, a 2: another space);
- no file defines exit statuses of its own (an enum or #define of EXIT_* = number);
- the programs converted end with lag_result_exit (the one mapping).
"""
import glob
import os
import re
import sys

src = sys.argv[1]
failures = []

DECLARED = {
    "server/scene/scene.h": ["lag_scene_load", "lag_scene_read", "lag_scene_load_buffer",
                             "lag_scene_read_decimal", "lag_scene_check_url"],
    "clients/lagsim_client.h": ["lag_client_feed", "lag_client_handle", "lag_client_wait_scene",
                                "lag_client_wait_state", "lag_client_send_command",
                                "lag_client_pause", "lag_client_resume", "lag_client_step",
                                "lag_client_reset", "lag_client_reset_to",
                                "lag_client_request_status", "lag_client_request_describe",
                                "lag_client_set", "lag_client_kick", "lag_client_reset_scene",
                                "lag_client_discover", "lag_client_pick_plant"],
    "server/daemon/daemon.h": ["lagsimd_offline", "lagsimd_realtime", "lagsimd_replay",
                               "lagsimd_choose_integrator", "lagsimd_cost"],
    "server/tools/log2csv.h": ["l2c_convert"],
}
for path, names in DECLARED.items():
    text = open(os.path.join(src, path)).read()
    for n in names:
        if not re.search(r"^lag_result %s\(" % n, text, re.M):
            failures.append("%s: %s is not declared as returning lag_result" % (path, n))

MAINS = ["server/daemon/main.c", "clients/lagsimctl.c", "server/tools/log2csv_main.c",
         "server/view/view_main.c"]
for path in MAINS:
    text = open(os.path.join(src, path)).read()
    m = re.search(r"^int main\(.*?^}", text, re.M | re.S)
    if not m or "lag_result_exit(" not in m.group(0):
        failures.append("%s: main does not end with lag_result_exit" % path)

files = sorted(glob.glob(os.path.join(src, "server/**/*.[ch]"), recursive=True) +
               glob.glob(os.path.join(src, "clients/*.[ch]")))
for path in files:
    rel = os.path.relpath(path, src)
    text = open(path).read()
    for m in re.finditer(r"^(?:static )?lag_result (\w+)\([^;{]*?\)\n\{\n(.*?)^\}", text,
                         re.M | re.S):
        for r in re.finditer(r"return\s+(-?\d+)\s*;", m.group(2)):
            line = text[:m.start(2) + r.start()].count("\n") + 1
            failures.append("%s:%d: %s returns %s, not a lag_result code"
                            % (rel, line, m.group(1), r.group(1)))
    for m in re.finditer(r"(?:#define\s+\w*EXIT\w*\s+-?\d+\b|\b\w*EXIT_\w+\s*=\s*-?\d+)", text):
        line = text[:m.start()].count("\n") + 1
        failures.append("%s:%d: exit statuses of its own: %s" % (rel, line, m.group(0)))

for f in failures:
    print("FAIL " + f, file=sys.stderr)
print("%d files read, %d findings" % (len(files), len(failures)))
sys.exit(1 if failures else 0)
