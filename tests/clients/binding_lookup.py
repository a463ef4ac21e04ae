#!/usr/bin/env python3
"""How the Python and Lua bindings find the client library (docs/clients.md): from the
build tree (the path CMake writes), from $LAGSIM_CLIENT_LIBRARY / LUA_CPATH, and, when
nothing is found, a clear error naming every place looked at.

    binding_lookup.py --build DIR --source DIR [--lua lua5.2]

Each case runs a fresh interpreter that asks for the plant URLs (lag_client_plant_urls):
  - the build's modules (<build>/python, <build>/lua): found, the rule's answer;
  - the source's modules (no path file), $LAGSIM_CLIENT_LIBRARY / LUA_CPATH naming the
    build's library or module: found;
  - the build's modules with $LAGSIM_CLIENT_LIBRARY naming a missing file: an error naming
    it (the variable is the user's choice: never skipped for another library);
  - the source's modules with nothing to find (no path file, no loader path): an error
    naming each place tried and what to set. (Lua has no such variable: LUA_CPATH is a
    search path, whose entries that find nothing are passed over by Lua itself.)
"""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)

URL = "udpm://239.9.9.9:9000?ttl=0"
WANT = "udpm://239.9.9.9:9000?ttl=0 udpm://239.9.9.9:9001?ttl=0"
PY = ("import sys; from lagsim_lcm import plant_urls; print(' '.join(plant_urls(%r)))" % URL)
LUA = ("local l = require('lagsim_lcm'); local s, c = l.plant_urls(%r); print(s .. ' ' .. c)"
       % URL)


def run(cmd, env):
    e = {k: v for k, v in os.environ.items() if k not in ("LAGSIM_CLIENT_LIBRARY", "LUA_CPATH",
                                                         "LUA_PATH", "PYTHONPATH", "LD_LIBRARY_PATH")}
    e.update(env)
    r = subprocess.run(cmd, env=e, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    return r.returncode, r.stdout.strip(), r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--lua", default="")
    a = ap.parse_args()
    a.build, a.source = os.path.abspath(a.build), os.path.abspath(a.source)

    # the library the build's path file names (in a sanitizer build the uninstrumented copy)
    lib = {}
    exec(open(os.path.join(a.build, "python", "lagsim_client_path.py")).read(), lib)
    lib = lib["LIBRARY"]
    py_src = os.path.join(a.source, "clients", "python")
    rc, out, err = run([sys.executable, "-c", PY], {"PYTHONPATH": os.path.join(a.build, "python")})
    check(rc == 0 and out == WANT, "Python from <build>/python: the library the build wrote", err)
    rc, out, err = run([sys.executable, "-c", PY], {"PYTHONPATH": py_src, "LAGSIM_CLIENT_LIBRARY": lib})
    check(rc == 0 and out == WANT, "Python from the sources, LAGSIM_CLIENT_LIBRARY=%s" % lib, err)
    # a $LAGSIM_CLIENT_LIBRARY naming no library is an error naming it, even where another
    # library would be found (the build's path file): who set it expects that one used
    missing = "/nonexistent/liblagsim_client.so.1"
    rc, out, err = run([sys.executable, "-c", PY], {"PYTHONPATH": os.path.join(a.build, "python"),
                                                    "LAGSIM_CLIENT_LIBRARY": missing})
    check(rc != 0 and "cannot load lagsim's client library $LAGSIM_CLIENT_LIBRARY=%s" % missing in err,
          "Python from <build>/python, LAGSIM_CLIENT_LIBRARY=%s: an error naming it, no other "
          "library loaded instead" % missing, "exit %d, out %r\n%s" % (rc, out, err))
    rc, out, err = run([sys.executable, "-c", PY], {"PYTHONPATH": py_src})
    check(rc != 0 and "cannot load lagsim's client library" in err and
          "LAGSIM_CLIENT_LIBRARY=<build>/lib/" in err and "liblagsim_client.so.1 (the dynamic loader" in err,
          "Python with nothing to find: an error naming each place tried and what to set", err)
    if a.lua:
        lua_build = os.path.join(a.build, "lua")
        lua_src = os.path.join(a.source, "clients", "lua")
        rc, out, err = run([a.lua, "-e", LUA], {"LUA_PATH": lua_build + "/?.lua;;"})
        check(rc == 0 and out == WANT, "Lua from <build>/lua: the module the build wrote", err)
        rc, out, err = run([a.lua, "-e", LUA], {"LUA_PATH": lua_src + "/?.lua;;",
                                                "LUA_CPATH": lua_build + "/?.so;;"})
        check(rc == 0 and out == WANT, "Lua from the sources, LUA_CPATH=%s/?.so;;" % lua_build, err)
        rc, out, err = run([a.lua, "-e", LUA], {"LUA_PATH": lua_src + "/?.lua;;",
                                                "LUA_CPATH": "/nonexistent/?.so;;"})
        check(rc != 0 and "cannot load lagsim's client module" in err and
              "/nonexistent/lagsim_client.so" in err and "LUA_CPATH" in err,
              "Lua with nothing to find: an error naming each place tried", err)
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
