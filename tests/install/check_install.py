#!/usr/bin/env python3
"""Installs the build into a temporary prefix and runs what was installed.

    check_install.py --build DIR --source DIR

1. `cmake --install DIR --prefix TMP`; every file a user needs is there (programs, C
   headers and libraries with lagsim-client.pc, the .lcm files, the scenes, the Python,
   Lua and Java types and helpers, the example controllers, the man pages: check_man.py
   holds each to its program's --help; the systemd unit naming the installed lagsimd).
2. The installed lagsimd runs the installed config/dipc.yaml in lockstep with the
   installed dipc_lqr, then with the installed Python, Lua, Java and Octave examples, each from a
   directory of its own and finding its modules the way an installed tree is found
   (PYTHONPATH=TMP/lib/python3.X/dist-packages, which is on Debian's sys.path for
   /usr/local; lua5.2's default path shape; the jars in TMP/share/java, found by
   TMP/share/lagsim/octave/lagsim_setup.m). Every run must
   answer all 201 states of 2 s and balance.
3. Controllers build against the installed tree through pkg-config and drive the
   installed lagsimd: the C++ example (clients/manipulator_ct.cpp, `pkg-config
   lagsim-client`: liblagsim_client.so alone, found at run time through LD_LIBRARY_PATH
   as for any library in a prefix off the loader's path) and the C example
   clients/manipulator_pd.c (`pkg-config lagsim-core`: the core and the examples' setup).
   The installed liblagsim_client.so.N carries the SONAME of LAGSIM_CLIENT_ABI and exports
   the client's functions only.
"""
import argparse
import glob
import os
import shutil
import subprocess
import sys
import tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, failures, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import lcm_url  # noqa: E402  (a port pair of this process's own)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--cc", default="cc")
    ap.add_argument("--cxx", default="c++")
    ap.add_argument("--abi", type=int, required=True, help="LAGSIM_CLIENT_ABI")
    ap.add_argument("--cflags", default="", help="extra compiler flags (a sanitizer build's)")
    a = ap.parse_args()
    # every process here meets on LCM's default URL, a port pair of this run's own
    # (tests/common/lcm_port.py): nothing of another run on the machine is heard
    os.environ["LCM_DEFAULT_URL"] = lcm_url("recv_buf_size=4194304")
    build, src = os.path.abspath(a.build), os.path.abspath(a.source)
    tmp = tempfile.mkdtemp(prefix="lagsim_install_")
    prefix = os.path.join(tmp, "prefix")

    r = subprocess.run(["cmake", "--install", build, "--prefix", prefix],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    if not check(r.returncode == 0, "cmake --install into %s" % prefix):
        print(r.stdout)
        return 1
    pydirs = glob.glob(os.path.join(prefix, "lib", "python3*", "dist-packages"))
    pydir = pydirs[0] if pydirs else os.path.join(prefix, "lib", "python3", "dist-packages")
    want = ["bin/lagsimd", "bin/dipc_lqr", "bin/manipulator_pd",
            "include/lagsim/lagsim.h", "include/lagsim/lagsim_client.h",
            "include/lagsim/lagsim_joint_state_t.h", "lib/liblagsim_client.a",
            "include/lagsim/lagsim_client.hpp", "include/lagsim/version.h",
            "lib/liblagsim_client.so", "lib/liblagsim_client.so.%d" % a.abi,
            "bin/manipulator_ct", "share/man/man1/manipulator_ct.1",
            "lib/pkgconfig/lagsim-client.pc", "lib/pkgconfig/lagsim-core.pc",
            "share/man/man1/lagsimd.1",
            "share/lagsim/config/dipc.yaml", "share/lagsim/lcmtypes/joint_state_t.lcm",
            "share/lua/5.2/lagsim/init.lua", "share/lua/5.2/lagsim_lcm.lua",
            "share/lua/5.2/lagsim_client_path.lua", "lib/lua/5.2/lagsim_client.so",
            "share/lagsim/examples/python/dipc_balance.py",
            "share/lagsim/examples/lua/dipc_balance.lua",
            "share/java/lagsim_types.jar", "share/java/lagsim_examples.jar",
            "share/lagsim/octave/lagsim_setup.m", "share/lagsim/octave/dipc_balance.m"]
    # the other programs, each where the build made it
    for prog in ("lagsimctl", "lagsim-view", "lagsim-log2csv", "lagsim-plot", "stick_push",
                 "lagsim-eval", "lagsim-sweep"):
        if os.path.exists(os.path.join(build, "bin", prog)):
            want.append("bin/" + prog)
    if os.path.exists(os.path.join(build, "bin", "lagsim-sweep")):
        want.append("share/lagsim/slurm/lagsim-sweep-array.sh")
    for w in want:
        check(os.path.exists(os.path.join(prefix, w)), "installed %s" % w)
    unit = os.path.join(prefix, "lib/systemd/system/lagsimd@.service")
    execs = [l for l in open(unit)] if os.path.exists(unit) else []
    check(any(l.startswith("ExecStart=%s/bin/lagsimd " % prefix) for l in execs),
          "installed lib/systemd/system/lagsimd@.service, naming %s/bin/lagsimd" % prefix)
    for w in ("lagsim/__init__.py", "lagsim_lcm.py", "lagsim_controller.py", "lagsim_client.py",
              "lagsim_client_path.py"):
        check(os.path.exists(os.path.join(pydir, w)), "installed %s" % os.path.join(
            os.path.relpath(pydir, prefix), w))
    # the bindings' pointers name the installed client library and Lua module, not the build's
    for path, lib in ((os.path.join(pydir, "lagsim_client_path.py"),
                       os.path.join(prefix, "lib", "liblagsim_client.so.%d" % a.abi)),
                      (os.path.join(prefix, "share/lua/5.2/lagsim_client_path.lua"),
                       os.path.join(prefix, "lib/lua/5.2/lagsim_client.so"))):
        text = open(path).read() if os.path.exists(path) else ""
        check(lib in text and build not in text, "%s names %s" % (os.path.relpath(path, prefix),
                                                                   os.path.relpath(lib, prefix)))
    check(len(glob.glob(os.path.join(prefix, "share/lagsim/lcmtypes/*.lcm"))) ==
          len(glob.glob(os.path.join(src, "lcmtypes/*.lcm"))), "every .lcm file installed")
    # the shared library: its SONAME, its links, only the client's functions exported
    so = os.path.join(prefix, "lib", "liblagsim_client.so")
    dump = subprocess.run(["objdump", "-p", so], stdout=subprocess.PIPE, universal_newlines=True)
    check("SONAME               liblagsim_client.so.%d" % a.abi in dump.stdout and
          os.path.realpath(so) == os.path.realpath(so + ".%d" % a.abi),
          "lib/liblagsim_client.so -> .so.%d, SONAME liblagsim_client.so.%d" % (a.abi, a.abi))
    syms = subprocess.run(["nm", "-D", "--defined-only", so], stdout=subprocess.PIPE,
                          universal_newlines=True).stdout.split()
    names = [s for s in syms if s.startswith("lag") or s.startswith("__lagsim")]
    other = [s for s in names if not s.startswith("lag_client_") and not s.startswith("lag_result_")]
    check("lag_client_wait_state" in names and "lag_result_string" in names and not other,
          "%d functions exported, none but lag_client_* and lag_result_* (%s)"
          % (len(names), other[:5]))
    # controllers built against the installed tree through pkg-config
    env_pc = dict(os.environ, PKG_CONFIG_PATH=os.path.join(prefix, "lib", "pkgconfig"))
    builds = [("lagsim-client", a.cxx, ["-std=c++17"], "clients/manipulator_ct.cpp", "manipulator_ct_installed"),
              ("lagsim-core", a.cc, ["-std=c11", "-D_GNU_SOURCE"], "clients/manipulator_pd.c", "manipulator_pd_installed")]
    for pkg, compiler, std, source, out in builds:
        pc = subprocess.run(["pkg-config", "--cflags", "--libs", pkg], env=env_pc,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        if check(pc.returncode == 0, "pkg-config %s: %s" % (pkg, pc.stdout.strip() or pc.stderr.strip())):
            cc = subprocess.run([compiler] + std + a.cflags.split() + ["-o", os.path.join(tmp, out),
                                 os.path.join(src, source)] + pc.stdout.split(),
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
            if not check(cc.returncode == 0, "%s builds against the installed tree" % source):
                print(cc.stdout)

    lagsimd = os.path.join(prefix, "bin", "lagsimd")
    cfg = os.path.join(prefix, "share/lagsim/config")
    e2e = [sys.executable, os.path.join(src, "tests/clients/run_e2e.py"), "--lagsimd", lagsimd,
           "--mode", "lockstep", "--timeout", "60", "--daemon-arg=--duration", "--daemon-arg=2"]
    dipc = ["--config", os.path.join(cfg, "dipc.yaml"), "--check", "states == 201",
            "--check", "max_abs_theta1 < 0.1"]
    manip = ["--config", os.path.join(cfg, "manipulator.yaml"), "--check", "states == 201"]
    lua_path = "%s/?.lua;%s/?/init.lua;;" % ((os.path.join(prefix, "share/lua/5.2"),) * 2)
    jars = ":".join(["/usr/share/java/lcm.jar"] + [os.path.join(prefix, "share/java", j)
                    for j in ("lagsim_types.jar", "lagsim_examples.jar")])
    runs = [
        ("C dipc_lqr", dipc, [os.path.join(prefix, "bin/dipc_lqr"), "-q", "--duration", "2"], {}),
        ("C controller built with pkg-config lagsim-core", manip,
         [os.path.join(tmp, "manipulator_pd_installed"), "-q", "--duration", "2"],
         {"LD_LIBRARY_PATH": os.path.join(prefix, "lib")}),
        ("C++ controller built with pkg-config lagsim-client", manip,
         [os.path.join(tmp, "manipulator_ct_installed"), "-q", "--duration", "2"],
         {"LD_LIBRARY_PATH": os.path.join(prefix, "lib")}),
        ("C++ manipulator_ct", manip, [os.path.join(prefix, "bin/manipulator_ct"), "-q", "--duration", "2"], {}),
        ("Python dipc_balance.py", dipc,
         [sys.executable, os.path.join(prefix, "share/lagsim/examples/python/dipc_balance.py"), "-q"],
         {"PYTHONPATH": pydir}),
        ("Lua dipc_balance.lua", dipc,
         ["lua5.2", os.path.join(prefix, "share/lagsim/examples/lua/dipc_balance.lua"), "-q"],
         {"LUA_PATH": lua_path}),
        ("Java DipcBalance", dipc, ["java", "-cp", jars, "lagsim.examples.DipcBalance", "-q"], {}),
    ]
    if shutil.which("octave"):  # lagsim_setup finds the jars from share/lagsim/octave
        runs.append(("Octave dipc_balance.m", dipc,
                     [os.path.join(src, "tests/clients/octave_run.sh"),
                      os.path.join(prefix, "share/lagsim/octave"), "dipc_balance", "-q"], {}))
    elsewhere = tempfile.mkdtemp(prefix="lagsim_cwd_")
    for k, (name, checks, client, env_extra) in enumerate(runs):
        if not os.path.exists(client[0]) and client[0] not in ("lua5.2", "java", sys.executable):
            check(False, "%s: %s missing" % (name, client[0]))
            continue
        env = dict(os.environ)
        env.pop("PYTHONPATH", None)
        env.pop("LUA_PATH", None)
        env.update(env_extra)
        r = subprocess.run(e2e + ["--name", "INST%d" % k] + checks +
                           ["--"] + client + ["--prefix", "{prefix}"],
                           cwd=elsewhere, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True)
        if not check(r.returncode == 0, "installed lagsimd with the installed %s" % name):
            print(r.stdout)
    if failures() == 0:
        shutil.rmtree(tmp, ignore_errors=True)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
