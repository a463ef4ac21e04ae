#!/usr/bin/env python3
"""Runs the controllers that README.md (and docs/clients.md) show, exactly as written there.

    readme_snippets.py --lagsimd BIN --build DIR --readme README.md NAME...

README.md marks each runnable block with an HTML comment on the line before its fence,
<!-- snippet: NAME -->. For each NAME given, the block is written to a fresh temporary
directory (so it runs from any directory, as the README promises), its channel prefix
DIPC is replaced by one unique to this run, and it is started the way the README says
(C and C++: compiled as the block's first line says, `cc balance.c $(pkg-config --cflags
--libs lagsim-client)` or `c++ -std=c++17 balance.cpp $(...)`, with the compiler given
(--cc, --cxx: gcc, g++, clang++) and -Wall -Wextra -Werror; Go: `go build balance.go`
(--go: the go command; cgo's C with -Wall -Werror, Go's cache in <build>/go, no network);
all against the build tree
(PKG_CONFIG_PATH=<build>/pkgconfig, the uninstalled lagsim-client.pc) or, with --install,
against `cmake --install <build> --prefix TMP` (PKG_CONFIG_PATH=TMP/lib/pkgconfig; run
with LD_LIBRARY_PATH=TMP/lib, as any library in a prefix off the loader's path);
PYTHONPATH=<build>/python; LUA_PATH=<build>/lua/...; java -cp
lcm.jar:types.jar:examples.jar File.java; octave --path <build>/octave --eval balance in
the file's folder). Once it asks for the scene (a DESCRIBE, as the client libraries do
first) or answers a probe state (sim time -1) it is subscribed; then lagsimd runs
config/dipc.yaml in lockstep for 2 s of sim time and stops.
The snippet must exit by itself with status 0 once the daemon announces its stop; the
daemon's final status must show every state before t = 2 s answered (200
commands_accepted, no lockstep timeout), and every state heard must keep both rods within 0.1 rad of
upright (the shipped scene starts at 0.05 rad). Everything runs on a multicast port of this
run's own (LCM_DEFAULT_URL): nothing of it may be heard on LCM's default URL.

--kill-after N SIGKILLs the daemon once N states were heard: the block must then end by
its silence rule within --silence S (5, as README says) of the last state, exit 0, and say
end=silence if it prints its end (a block that waits only for the stop event hangs).

--think S runs each block twice for --periods N periods: once as written, then as written
with a control law that takes S wall seconds per answer it builds (tests/clients/think/:
every joint_command_t the block constructs, or every lag_client_send_command it calls,
sleeps S first and is counted; the block's text is unchanged). The slow run must answer
every state, with no lockstep timeout, run its law once per sim_time, and hear the
states of the fast run bit for bit. In lockstep
the daemon publishes a state again until an answer arrives: a block that ran its law for
every copy would fall behind by a copy's worth of thinking per state and never catch up.
A law slower than realtime.lockstep_timeout is late by definition, so that timeout is
set to at least three think times, and to at least the think time plus 20 times the
slowest answer of the fast run just before (the time from a state's first copy to its
first command, measured here: what this machine takes to schedule the block, LCM and the
daemon now; a loaded machine or a sanitizer build gets the patience it needs, an idle one
keeps the floor: 30 s, as the sanitizer pass beside a load of 24 to 33 on 2 cores, seen
here, took 5.3 s to answer with a law of 0.15 s, 0.002 s being the fast run's slowest just
before; a lockstep timeout steps nothing, so the floor bounds a hang, and the daemon's
copies still come while the law thinks, the first 20 ms after the state, so the copy rule
is tested as before). A run that answers copies by thinking again falls further behind with every
state and meets any finite timeout; the law counted once per sim_time is the direct check.
The run as written (no think) gets the same floor (it had 1 s: a fixed window for one
answer, which the same loaded machine need not keep); its check is the same: every state
answered, no lockstep timeout.
"""
import argparse
import atexit
import hashlib
import math
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lcm_port import lcm_port, lcm_url  # noqa: E402  (a port pair of this process's own)

_TEMPS = []  # the directories this run made (blocks, an install): removed when it ends
atexit.register(lambda: [shutil.rmtree(d, ignore_errors=True) for d in _TEMPS])


def mkdtemp(prefix):
    _TEMPS.append(tempfile.mkdtemp(prefix=prefix))
    return _TEMPS[-1]


THINK_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "think")
# name: (file, command line (build, file, slow: the think wrapper, or ""), environment)
RUNNERS = {
    "c": ("balance.c", lambda b, f, slow: [os.path.splitext(f)[0]], lambda b: {}),
    "cpp": ("balance.cpp", lambda b, f, slow: [os.path.splitext(f)[0]], lambda b: {}),
    # Go through the C ABI (cgo), built by `go build balance.go` (docs/clients.md)
    "go": ("balance.go", lambda b, f, slow: [os.path.splitext(f)[0]], lambda b: {}),
    # stock lcm-gen --cpp types with lcm/lcm-cpp.hpp (docs/clients.md), no lagsim library
    "cpplcm": ("balance.cpp", lambda b, f, slow: [os.path.splitext(f)[0]], lambda b: {}),
    "python": ("balance.py",
               lambda b, f, slow: ["python3"] + ([os.path.join(THINK_DIR, "think.py")]
                                                 if slow else []) + [f],
               lambda b: {"PYTHONPATH": os.path.join(b, "python")}),
    "lua": ("balance.lua",
            lambda b, f, slow: ["lua5.2"] + ([os.path.join(THINK_DIR, "think.lua")]
                                             if slow else []) + [f],
            lambda b: {"LUA_PATH": "%s/lua/?.lua;%s/lua/?/init.lua;;" % (b, b)}),
    "java": ("Balance.java",
             lambda b, f, slow: ["java", "-cp", (slow + ":" if slow else "") +
                                 "/usr/share/java/lcm.jar:%s/lagsim_types.jar:"
                                 "%s/lagsim_examples.jar" % (b, b), f],
             lambda b: {}),
    # a plain octave --eval of the script, from its folder, the .m files on the path (no
    # think wrapper: the slow-law runs are the other languages')
    "octave": ("lqr_dipc.m",
               lambda b, f, slow: ["octave", "--no-gui", "--quiet", "--no-init-file", "--path",
                             os.path.join(b, "octave"), "--eval", "lqr_dipc"],
               lambda b: {}),
}


def java_think_classes(build, tmp):
    """A joint_command_t whose constructor takes LAGSIM_THINK_S wall seconds, compiled
    into tmp (think/think_java.py): first on the class path, it stands in for the types
    jar's."""
    sys.path.insert(0, THINK_DIR)
    from think_java import think_classes
    return think_classes(build, os.path.join(tmp, "think_java"))


def snippets(readme):
    text = open(readme).read()
    found = {}
    for m in re.finditer(r"<!-- snippet: (\S+) -->\s*\n```[a-z]*\n(.*?)\n```", text, re.S):
        found[m.group(1)] = m.group(2) + "\n"
    return found


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lagsimd", required=True)
    ap.add_argument("--build", required=True)
    ap.add_argument("--readme", action="append", required=True,
                    help="a file with marked blocks (repeatable: README.md, docs/clients.md)")
    ap.add_argument("--config", required=True)
    ap.add_argument("--cc", default="cc", help="the C block's compiler")
    ap.add_argument("--cxx", default="c++", help="the C++ block's compiler")
    ap.add_argument("--cflags", default="", help="more flags for both (a sanitizer build's)")
    ap.add_argument("--go", default="go", help="the go command (the Go block's)")
    ap.add_argument("--lcm-cpp-types", default="",
                    help="where lcm-gen --cpp wrote lagsim's types (the cpplcm block's -Igen)")
    ap.add_argument("--install", action="store_true",
                    help="build the C and C++ blocks against an install of the build tree")
    ap.add_argument("--think", type=float, default=0.0,
                    help="also run each block with a law of this many wall s per answer")
    ap.add_argument("--periods", type=int, default=200, help="control periods of a run")
    ap.add_argument("--go-static", action="store_true",
                    help="with --install: build the Go block with docs/clients.md's static-link "
                    "recipe (<!-- recipe: go-static -->) for the install's prefix instead of its "
                    "pkg-config line; the program must not load liblagsim_client.so, and runs "
                    "without LD_LIBRARY_PATH")
    ap.add_argument("--kill-after", type=int, default=0,
                    help="SIGKILL the daemon once this many states were heard: the block must "
                         "end by its silence rule (--silence S), exit 0, and print end=silence "
                         "if it prints an end")
    ap.add_argument("--silence", type=float, default=5.0,
                    help="the blocks' silence timeout, wall s (README: 5)")
    ap.add_argument("names", nargs="+")
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    # The snippet, the daemon and this script meet on LCM's default URL with a multicast
    # port of this run's own (ttl=0: this host), through LCM_DEFAULT_URL, which every
    # binding reads (the snippets name no URL, as a user's controller would not): on one
    # port every socket gets every datagram, so another run on the machine (a concurrent
    # ctest of another snippet, a fast-mode daemon, a flood test) would be heard here and
    # fill these sockets. The prefix stays unique as well. Receive buffers of 4 MB, as the
    # other client tests (run_e2e.py).
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")  # and the next port
    print("LCM_DEFAULT_URL=%s" % os.environ["LCM_DEFAULT_URL"])
    sys.path.insert(0, os.path.join(build, "python"))

    found = {}
    for f in a.readme:
        found.update(snippets(f))
    a.pkg_config_path, a.lib_path = os.path.join(build, "pkgconfig"), ""
    if a.install:
        prefix = os.path.join(mkdtemp("lagsim_readme_inst_"), "prefix")
        r = subprocess.run(["cmake", "--install", build, "--prefix", prefix],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        if r.returncode != 0:
            print("FAIL: cmake --install %s --prefix %s\n%s" % (build, prefix, r.stdout))
            return 1
        print("installed into %s" % prefix)
        a.pkg_config_path = os.path.join(prefix, "lib", "pkgconfig")
        a.lib_path = "" if a.go_static else os.path.join(prefix, "lib")
        a.prefix = prefix
    a.recipes = "".join(open(f).read() for f in a.readme)
    fails = 0
    for name in a.names:
        lang = name.split("-")[0]
        if name not in found or lang not in RUNNERS:
            print("FAIL: no block marked <!-- snippet: %s --> in %s" % (name, ", ".join(a.readme)))
            fails += 1
            continue
        thinks = [0.0] + ([a.think] if a.think > 0 else [])
        runs = []
        slowest = 0.0  # the fast run's slowest answer (s)
        for think in thinks:
            bad, states, slowest = run_block(a, build, found[name], name, lang, think, slowest)
            fails += bad
            runs.append(states)
        if len(runs) == 2:
            fast, slow = runs
            same = sorted(fast) == sorted(slow) and all(fast[t] == slow[t] for t in fast)
            diff = [t for t in sorted(fast) if slow.get(t) != fast[t]][:3]
            good = same and len(fast) == a.periods + 1
            print("%s: with a law of %g s per answer: the same %d states as the fast run, bit for "
                  "bit (%d heard; first differing sim times %s)"
                  % ("ok  " if good else "FAIL", a.think, len(fast), len(slow), diff))
            fails += 0 if good else 1
    return 1 if fails else 0


def build_block(a, text, lang, path, think):
    """Compiles the C or C++ block as its first line says, against the client library of
    a.pkg_config_path; with think > 0, with a slow law in front of its sends (think.h)."""
    said = {"c": r"cc balance\.c \$\(pkg-config --cflags --libs lagsim-client\)",
            "cpp": r"c\+\+ -std=c\+\+17 balance\.cpp \$\(pkg-config --cflags --libs lagsim-client\)",
            "cpplcm": r"c\+\+ -std=c\+\+17 -Igen balance\.cpp \$\(pkg-config --cflags --libs lcm\)"}
    if not re.search(said[lang], text.split("\n")[0] + text.split("\n")[1]):
        print("FAIL: the %s block's first lines do not say how it builds (%s)" % (lang, said[lang]))
        return False
    pkg = "lcm" if lang == "cpplcm" else "lagsim-client"
    env = dict(os.environ, PKG_CONFIG_PATH=a.pkg_config_path)
    pc = subprocess.run(["pkg-config", "--cflags", "--libs", pkg], env=env,
                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    if pc.returncode != 0:
        print("FAIL: PKG_CONFIG_PATH=%s pkg-config --cflags --libs %s:\n%s"
              % (a.pkg_config_path, pkg, pc.stdout))
        return False
    cmd = ([a.cc] if lang == "c" else [a.cxx, "-std=c++17"]) + ["-Wall", "-Wextra", "-Werror"]
    if lang == "cpplcm":  # "-Igen": the build's lcm-gen --cpp types
        cmd.append("-I" + a.lcm_cpp_types)
    cmd += shlex.split(a.cflags)
    if think > 0:  # the same block, built with a slow law in front of its sends
        cmd += ["-include", os.path.join(THINK_DIR, "think.h")]
    cmd += [path, "-o", os.path.splitext(path)[0]] + pc.stdout.split()
    print("$ PKG_CONFIG_PATH=%s %s" % (a.pkg_config_path, " ".join(cmd)))
    cc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                        universal_newlines=True)
    if cc.returncode != 0:
        print("FAIL: the %s block does not build:\n%s" % (lang, cc.stdout))
        return False
    return True


def cgo_inputs_key(pkg_config_path):
    """What cmake/go_build.cmake does for the tree's Go programs: the SHA-256 of the client
    library's headers and library that pkg-config points at, for CGO_CPPFLAGS, where Go's
    cache key sees it (Go does not hash a header included from another directory: built
    against a changed lagsim, the block would otherwise reuse cgo objects of the old one)."""
    r = subprocess.run(["pkg-config", "--cflags-only-I", "--libs-only-L", "lagsim-client"],
                       env=dict(os.environ, PKG_CONFIG_PATH=pkg_config_path),
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    if r.returncode != 0:
        print("FAIL: PKG_CONFIG_PATH=%s pkg-config lagsim-client:\n%s" % (pkg_config_path, r.stdout))
        return None
    h = hashlib.sha256()
    for flag in r.stdout.split():
        for rel in ("lagsim_client.h", "lagsim/version.h", "lagsim/result.h", "liblagsim_client.so.1"):
            f = os.path.join(flag[2:], rel)
            if flag[:2] in ("-I", "-L") and os.path.isfile(f):
                h.update(f.encode() + b"\0" + open(f, "rb").read())
    return h.hexdigest()[:32]


def build_go_block(a, build, text, path, think):
    """Builds the Go block as its first line says (go build balance.go), cgo finding the
    client library through pkg-config (a.pkg_config_path); Go's cache and GOPATH in
    <build>/go, the installed toolchain, no user configuration, no network. With think > 0,
    cgo's C includes think.h: every lag_client_send_command the block calls thinks first."""
    if not re.search(r"go build balance\.go", text.split("\n")[0]):
        print("FAIL: the go block's first line does not say how it builds (go build balance.go)")
        return False
    cflags = "-O2 -g -Wall -Werror"
    if think > 0:  # the block's preamble (only: CGO_CFLAGS would reach Go's runtime/cgo too)
        # includes think.h, by a #cgo directive added to the copy built; its code is unchanged
        with open(path) as f:
            code = f.read()
        directive = "#cgo pkg-config: lagsim-client\n"
        if directive not in code:
            print("FAIL: the go block has no '%s' line" % directive.strip())
            return False
        with open(path, "w") as f:
            f.write(code.replace(directive, directive + "#cgo CFLAGS: -include %s\n"
                                 % os.path.join(THINK_DIR, "think.h"), 1))
    if a.go_static and not go_static_recipe(a, path):
        return False
    key = cgo_inputs_key(a.pkg_config_path)
    if key is None:
        return False
    env = dict(os.environ, PKG_CONFIG_PATH=a.pkg_config_path, CGO_CFLAGS=cflags,
               CGO_CPPFLAGS="-DLAGSIM_CGO_INPUTS=" + key,
               GOCACHE=os.path.join(build, "go", "cache"), GOPATH=os.path.join(build, "go", "path"),
               GOTOOLCHAIN="local", GOENV="off", GOFLAGS="", GO111MODULE="on", CGO_ENABLED="1")
    cmd = [a.go, "build", "-o", os.path.splitext(path)[0], os.path.basename(path)]
    print("$ PKG_CONFIG_PATH=%s CGO_CFLAGS='%s' %s" % (a.pkg_config_path, cflags, " ".join(cmd)))
    r = subprocess.run(cmd, cwd=os.path.dirname(path), env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, universal_newlines=True)
    if r.returncode != 0:
        print("FAIL: the go block does not build:\n%s" % r.stdout)
        return False
    if a.go_static:
        ldd = subprocess.run(["ldd", os.path.splitext(path)[0]], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, universal_newlines=True).stdout
        print(ldd.rstrip())
        if "liblagsim_client" in ldd:
            print("FAIL: built by the static recipe, the block still loads liblagsim_client")
            return False
        print("ok  : built by the static recipe, the block loads no liblagsim_client")
    return True


def go_static_recipe(a, path):
    """The Go block's '#cgo pkg-config: lagsim-client' line replaced by the static-link
    recipe of docs/clients.md (the #cgo lines after <!-- recipe: go-static -->), its
    /opt/lagsim the install's prefix."""
    if not a.install:
        print("FAIL: --go-static needs --install")
        return False
    m = re.search(r"<!-- recipe: go-static -->\s*\n((?:[ \t]*\n|[ \t]+#cgo [^\n]*\n)+)", a.recipes)
    lines = [ln.strip() for ln in (m.group(1) if m else "").split("\n") if ln.strip()]
    if not lines:
        print("FAIL: no #cgo lines after <!-- recipe: go-static -->")
        return False
    recipe = "".join(ln.replace("/opt/lagsim", a.prefix) + "\n" for ln in lines)
    with open(path) as f:
        code = f.read()
    directive = "#cgo pkg-config: lagsim-client\n"
    if directive not in code:
        print("FAIL: the go block has no '%s' line" % directive.strip())
        return False
    with open(path, "w") as f:
        f.write(code.replace(directive, recipe, 1))
    print("the static recipe, for %s:\n%s" % (a.prefix, recipe.rstrip()))
    return True


def kill_daemon(a, name, path, daemon, snip, heard, listener):
    """--kill-after: SIGKILLs the daemon once a.kill_after states were heard (no stop event
    comes), then the block must end by its silence rule: exit 0 within a.silence - 0.5 to
    a.silence + 3 wall s of the last state heard here (the block's count starts at its own
    last message, which this listener may hear up to 0.5 s later on a loaded machine), and
    print end=silence if it prints an end. Returns (failures, {}, 0.0)."""
    th, th_cmd, listening, lc, lc_cmd, stray = listener
    deadline = time.monotonic() + 60
    while heard["states"] < a.kill_after and time.monotonic() < deadline and daemon.poll() is None:
        time.sleep(0.02)
    daemon.kill()
    daemon.communicate()
    t_kill = time.monotonic()
    try:
        out, _ = snip.communicate(timeout=a.silence + 20)
        t_end = time.monotonic()
    except subprocess.TimeoutExpired:
        snip.kill()
        out, _ = snip.communicate()
        t_end = None
        out += "\n(killed: did not exit %g s after the daemon died)" % (a.silence + 20)
    listening[0] = False
    th.join()
    th_cmd.join()  # both readers ended before their LCM objects are closed
    lc.close()
    lc_cmd.close()
    stray.close()
    silent = (t_end - heard.get("last_wall", t_kill)) if t_end else float("inf")
    ends = re.findall(r"end=(\w+)", out)
    checks = [
        (heard["states"] >= a.kill_after,
         "%d states heard before the daemon was killed (SIGKILL, no stop event)" % heard["states"]),
        (t_end is not None and snip.returncode == 0,
         "the snippet exited by itself, status %s (0 documented)" % snip.returncode),
        (a.silence - 0.5 <= silent < a.silence + 3,
         "it ended %.2f s after the last state heard (its silence timeout: %g s)" % (silent, a.silence)),
        (all(e == "silence" for e in ends), "its end: %s" % (ends or "not printed")),
    ]
    print("---- %s (%s) under a daemon killed after %d states" % (name, path, a.kill_after))
    if out.strip():
        print(out.rstrip())
    fails = 0
    for good, what in checks:
        print("%s: %s" % ("ok  " if good else "FAIL", what))
        fails += 0 if good else 1
    sys.stdout.flush()
    return fails, {}, 0.0


def run_block(a, build, text, name, lang, think, fast_slowest=0.0):
    """Runs one block against lagsimd for a.periods periods in lockstep, its law taking
    `think` wall s per answer (the daemon's lockstep_timeout from think and fast_slowest,
    the fast run's slowest answer); prints its checks. Returns (failures, {sim_time: the
    state's positions and velocities}, the slowest answer in s)."""
    from lagsim_lcm import LCM, plant_urls
    from lagsim import control_t, event_t, joint_command_t, joint_state_t, status_t
    fname, cmd, env_extra = RUNNERS[lang]
    prefix = "RDME%s_%d" % (lang.upper(), os.getpid())
    tmp = mkdtemp("lagsim_readme_")
    path = os.path.join(tmp, fname)
    with open(path, "w") as f:
        f.write(text.replace('"DIPC_', '"%s_' % prefix).replace("'DIPC_", "'%s_" % prefix)
                .replace('"DIPC"', '"%s"' % prefix))
    slow = ""
    if lang == "go":
        if not build_go_block(a, build, text, path, think):
            return 1, {}, 0.0
    elif lang in ("c", "cpp", "cpplcm"):
        if not build_block(a, text, lang, path, think):
            return 1, {}, 0.0
    elif think > 0:
        slow = java_think_classes(build, tmp) if lang == "java" else "yes"
    env = dict(os.environ)
    env.update(env_extra(build))
    if a.lib_path:
        env["LD_LIBRARY_PATH"] = a.lib_path
    env["LAGSIM_THINK_S"] = repr(think)
    think_log = os.path.join(tmp, "think.log")
    if think > 0:
        env["LAGSIM_THINK_LOG"] = think_log
    state_url, command_url = plant_urls()
    lc, lc_cmd = LCM(state_url), LCM(command_url)
    heard = {"states": 0, "max_th": 0.0, "t": -1.0, "status": None, "by_time": {}}
    first_state, first_command = {}, {}  # sim_time: the monotonic time first heard

    def on_state(ch, data):
        st = joint_state_t.decode(data)
        if st.sim_time < 0:
            return
        first_state.setdefault(st.sim_time, time.monotonic())
        heard["states"] += 1
        heard["last_wall"] = time.monotonic()
        heard["t"] = max(heard["t"], st.sim_time)
        heard["max_th"] = max([heard["max_th"]] + [abs(x) for x in st.position[1:3]])
        heard["by_time"][st.sim_time] = tuple(st.position) + tuple(st.velocity)

    def on_status(ch, data):
        heard["status"] = status_t.decode(data)

    heard["copy_rule"] = 0

    def on_event(ch, data):  # the daemon's hint that the law runs again on copies
        heard["copy_rule"] += event_t.decode(data).kind == "copy_rule"

    def on_command(ch, data):
        t = joint_command_t.decode(data).sim_time
        if t == -1.0:
            heard["ready"] = True
        else:
            first_command.setdefault(t, time.monotonic())

    def on_control(ch, data):  # a DESCRIBE: subscribed, asking for the scene (protocol.md)
        if control_t.decode(data).request == control_t.DESCRIBE:
            heard["ready"] = True

    # LCM's own default URL must hear nothing of this run: it is on its own port
    stray = LCM("udpm://239.255.76.67:7667?ttl=0")
    heard["stray"] = 0

    def on_stray(ch, data):
        heard["stray"] += 1

    stray.subscribe(prefix + "_.*", on_stray)
    lc.subscribe(prefix + "_STATE", on_state)
    lc.subscribe(prefix + "_STATUS", on_status)
    lc.subscribe(prefix + "_EVENT", on_event)
    lc_cmd.subscribe(prefix + "_COMMAND", on_command)
    lc_cmd.subscribe(prefix + "_CONTROL", on_control)
    heard["ready"] = False
    listening = [True]

    def listen():  # its own thread: the daemon in lockstep outruns a late reader
        while listening[0]:
            lc.handle_timeout(20)
            while stray.handle_timeout(0):
                pass

    def listen_commands():  # a thread of its own too: a command is timed when it comes,
        while listening[0]:  # not when the next state wakes the other reader
            lc_cmd.handle_timeout(20)

    th = threading.Thread(target=listen, daemon=True)
    th.start()
    th_cmd = threading.Thread(target=listen_commands, daemon=True)
    th_cmd.start()
    snip = subprocess.Popen(cmd(build, path, slow), cwd=tmp, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, universal_newlines=True)
    # Ready when it is subscribed: it asks for the scene (a DESCRIBE on <PREFIX>_CONTROL,
    # which a controller of the client libraries sends first, docs/protocol.md) or it
    # answers a probe state at sim time -1, published every 0.2 s (and more slowly than
    # its law; a block of lcm-gen's types alone asks for no scene). java compiles the
    # file first. Then the daemon starts.
    probe = joint_state_t()
    probe.sim_time, probe.num_joints = -1.0, 3
    probe.name = ["theta0", "theta1", "theta2"]
    probe.position = probe.velocity = probe.effort = [0.0, 0.0, 0.0]
    deadline = time.monotonic() + 30 + 2 * think
    while not heard["ready"] and time.monotonic() < deadline and snip.poll() is None:
        lc.publish(prefix + "_STATE", probe.encode())
        time.sleep(0.2 + 1.5 * think)
    heard["states"] = 0
    periods = a.periods
    # the fast run's too: its 1 s was a fixed window for one answer, which a loaded
    # machine's block (or the sanitizer build's) can miss where the slow run's took 5.3 s
    patience = max(30.0, 3 * think, think + 20 * fast_slowest)
    daemon = subprocess.Popen(
        [a.lagsimd, "--config", a.config, "--set", "lcm.prefix=" + prefix,
         "--set", "realtime.mode=lockstep",
         "--set", "realtime.lockstep_timeout=%r" % patience,
         "--duration", repr((periods if a.kill_after <= 0 else 100000) * 0.01), "-q"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    budget = 30 + 3 * think * periods  # three think times a state, and 30 s to start
    if a.kill_after > 0:
        listener = (th, th_cmd, listening, lc, lc_cmd, stray)
        return kill_daemon(a, name, path, daemon, snip, heard, listener)
    try:
        daemon.communicate(timeout=budget)
        in_time = True
    except subprocess.TimeoutExpired:  # too slow: stopped (its stop event ends the block)
        daemon.send_signal(signal.SIGINT)
        daemon.communicate()
        in_time = False
    try:
        out, _ = snip.communicate(timeout=20 + 3 * think)
    except subprocess.TimeoutExpired:
        snip.kill()
        out, _ = snip.communicate()
        out += "\n(killed: did not exit after the daemon's stop)"
    time.sleep(0.5)
    listening[0] = False
    th.join()
    th_cmd.join()
    lc.close()
    lc_cmd.close()
    stray.close()
    st = heard["status"]
    answers = [first_command[t] - first_state[t] for t in first_state if t in first_command]
    slowest = max(answers) if answers else 0.0
    acc = st.commands_accepted if st else -1
    lto = st.lockstep_timeouts if st else -1
    checks = [
        (in_time and daemon.returncode == 0,
         "lagsimd ran %d periods within %g s and exited 0" % (periods, budget)),
        (snip.returncode == 0, "the snippet exited 0 after the daemon's stop"),
        (acc == periods and lto == 0,
         "answered %d of the %d states before t = %g s, %d lockstep timeout(s) (lockstep_timeout "
         "%.3g s; slowest answer %.3f s)" % (acc, periods, periods * 0.01, lto, patience, slowest)),
        (heard["states"] > 0 and heard["max_th"] < 0.1 and math.isfinite(heard["max_th"]),
         "balanced: %d states heard, largest |theta1|, |theta2| %.4f rad"
         % (heard["states"], heard["max_th"])),
        (heard["stray"] == 0,
         "on a port of its own: %d of its messages heard on LCM's default URL"
         % heard["stray"]),
    ]
    if think > 0:
        # the law runs once per state: the probe's, the N answered, perhaps the last one
        laws = len(open(think_log).readlines()) if os.path.exists(think_log) else 0
        checks.append((periods + 1 <= laws <= periods + 2,
                       "its law ran %d times for the probe and %d states (once per sim_time: "
                       "%d or %d)" % (laws, periods + 1, periods + 1, periods + 2)))
        checks.append((heard["copy_rule"] == 0, "the daemon saw the copy rule kept (%d "
                       "copy_rule events)" % heard["copy_rule"]))
    print("---- %s (%s)%s" % (name, path, " with a law of %g s per answer" % think if think else ""))
    if out.strip():
        print(out.rstrip())
    fails = 0
    for good, what in checks:
        print("%s: %s" % ("ok  " if good else "FAIL", what))
        fails += 0 if good else 1
    sys.stdout.flush()
    return fails, heard["by_time"], slowest


if __name__ == "__main__":
    sys.exit(main())
