#!/usr/bin/env python3
"""The Debian package: built and checked (`build`), installed, run and purged (`install`).

    check_package.py build   --build DIR --source DIR
    check_package.py install --build DIR --source DIR
    check_package.py service --build DIR --source DIR

build (any user):
  `cpack -G DEB` makes <build>/package/lagsim_<version>_<arch>.deb. Its files are
  exactly what `cmake --install --prefix /usr` installs (man pages gzipped) plus
  /usr/share/doc/lagsim/{copyright,changelog.gz}; the Debian places hold what they
  should (python3's and lua5.2's own search paths name the directories); programs are
  stripped, everything is root's; Depends names the package of every shared library the
  programs need (readelf + dpkg -S) and python3; the maintainer scripts parse; the
  unit has the hardening asked of it, each resource limit has its row in docs/deploy.md's
  hardening table and its header example is the one docs/deploy.md gives, it passes
  `systemd-analyze verify` and `systemd-analyze security --offline=yes` scores at most
  EXPOSURE_MAX; lintian reports
  no error (its warnings are printed).
install (root only, else skipped with exit 77; also skipped when a lagsim package is
  installed already, which this test would replace and remove):
  apt-get installs the .deb; `systemd-analyze verify` passes on the installed unit;
  the installed lagsimd runs offline, byte for byte as the build's; the installed
  dipc_lqr balances the installed lagsimd in real time, the installed Python example
  (modules from /usr/lib/python3/dist-packages, no PYTHONPATH) in lockstep, and so does
  the installed Octave dipc_balance.m when the package has it and octave is installed; a C program
  builds with `pkg-config lagsim-client`; then `dpkg --purge` leaves none of the
  package's files (dpkg -L, taken before) and no state directory behind.
service (root only, else skipped; skipped too when this host cannot start systemd in a
  PID and mount namespace of its own):
  installs the .deb, then runs systemd 252 as PID 1 of a new PID and mount namespace (the
  host's own units hidden: only the installed lagsimd@.service, journald and empty
  targets are on its unit path, /run and the journal on tmpfs) and, as docs/deploy.md
  says, puts a scene in /etc/lagsim and starts lagsimd@NAME with the unit header's example
  LAGSIMD_ARGS (in /etc/lagsim/NAME.env): the installed dipc_lqr balances it from outside;
  the daemon runs as a dynamic user without capabilities, with no_new_privs and a seccomp
  filter, and under the unit's limits (/proc/PID/limits, MemoryMax, TasksMax); its events
  are in the journal; --log writes into /var/lib/lagsim/NAME and replays exactly; a
  SIGKILL is followed by a restart and `systemctl restart` by another, each writing a new
  file of the series while the earlier stay; `systemctl stop` gives exit 0; a bad scene fails with exit 2
  and is not restarted; `dpkg --purge` run there stops an enabled, running instance and
  removes its link. The host form too: /etc/lagsim/NAME.d/ with two scenes runs both,
  lagsimctl list names each with its URL, dipc_lqr balances one, a file added starts its
  plant without a restart, each plant's --log lands in /var/lib/lagsim/NAME/STUDENT/ and
  replays exactly. Then the checks after the purge, as in install.
install and service run in a mount namespace of their own where /usr, /etc and /var are
overlays of the host's (in_own_root): what they install is seen by them and their children
only, and checked to be unseen outside, so the suite's other tests run beside them.
One run at a time on a host: a lock file (LOCK) is held for the whole of it.
"""
import argparse
import fcntl
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import SKIP, check, failures, verdict  # noqa: E402  (tests/common: the one harness)
from lcm_port import GROUP, lcm_port, lcm_url  # noqa: E402  (ports held, as every test takes them)

EXPOSURE_MAX = 2.0   # systemd-analyze security: the unit scores 1.1 ("OK" is below 4.5)
DEBIAN_PYTHON = "/usr/bin/python3"   # the python3 the package depends on (not a pyenv's)
LOCK = "/run/lock/lagsim-package-test.lock"  # the host's: /run is not overlaid (in_own_root)
# the unit's settings the deployment relies on (docs/deploy.md)
UNIT_MUST = ["ExecStart=/usr/bin/lagsimd --instance /etc/lagsim/%i $LAGSIMD_ARGS",
             "Restart=on-failure", "RestartPreventExitStatus=2", "DynamicUser=yes",
             "ProtectSystem=strict", "NoNewPrivileges=yes", "StateDirectory=lagsim/%i",
             "RestrictAddressFamilies=AF_INET", "MemoryMax=512M", "TasksMax=512",
             "LimitFSIZE=4G", "LimitCORE=0"]
# the unit's resource limits: each has its reason in docs/deploy.md's hardening table
LIMIT_RE = re.compile(r"^(Memory(?:Max|High|SwapMax)|TasksMax|Limit\w+)=\S+$")


def unit_example(text):
    """The LAGSIMD_ARGS the unit's header gives as its example (the one fact; docs/deploy.md
    quotes it and this test runs it)."""
    m = re.search(r"^#\s+(LAGSIMD_ARGS=.*\S)\s*$", text, re.M)
    return m.group(1)[len("LAGSIMD_ARGS="):] if m else None


def run(cmd, **kw):
    kw.setdefault("stdout", subprocess.PIPE)
    kw.setdefault("stderr", subprocess.STDOUT)
    return subprocess.run(cmd, universal_newlines=True, **kw)


def clean_env(**extra):
    """The environment of a user of the installed package: nothing pointing at a build."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "LUA_PATH", "LUA_CPATH", "CLASSPATH", "PKG_CONFIG_PATH",
                        "LD_LIBRARY_PATH", "MANPATH")}
    env["PATH"] = "/usr/sbin:/usr/bin:/sbin:/bin"
    env.update(extra)
    return env


def client_abi(source):
    """LAGSIM_CLIENT_ABI, as CMakeLists.txt sets it."""
    with open(os.path.join(source, "CMakeLists.txt")) as f:
        return int(re.search(r"set\(LAGSIM_CLIENT_ABI (\d+)\)", f.read()).group(1))


def deb_path(build):
    version = None
    with open(os.path.join(build, "CMakeCache.txt")) as f:
        for line in f:
            if line.startswith("CMAKE_PROJECT_VERSION:"):
                version = line.split("=", 1)[1].strip()
    arch = run(["dpkg", "--print-architecture"]).stdout.strip()
    return os.path.join(build, "package", "lagsim_%s_%s.deb" % (version, arch)), version


def deb_files(deb):
    """{path: (mode, owner)} of the regular files and links in the .deb, paths without './'."""
    out = {}
    for line in run(["dpkg-deb", "-c", deb]).stdout.splitlines():
        f = line.split()
        if len(f) >= 6 and not f[0].startswith("d"):
            out[f[5][2:] if f[5].startswith("./") else f[5]] = (f[0], f[1])
    return out


def unit_text(deb, tmp):
    x = os.path.join(tmp, "x")
    run(["dpkg-deb", "-x", deb, x])
    with open(os.path.join(x, "usr/lib/systemd/system/lagsimd@.service")) as f:
        return f.read(), x


def do_build(a):
    deb, version = deb_path(a.build)
    outdir = os.path.dirname(deb)
    shutil.rmtree(outdir, ignore_errors=True)
    r = run(["cpack", "-G", "DEB", "--config", os.path.join(a.build, "CPackConfig.cmake"),
             "-B", outdir], cwd=a.build)
    if not check(r.returncode == 0 and os.path.exists(deb), "cpack -G DEB makes %s"
                 % os.path.basename(deb), r.stdout):
        return
    pkg = deb_files(deb)
    tmp = tempfile.mkdtemp(prefix="lagsim_pkg_")

    # exactly what the install rules install under /usr, man pages gzipped, plus the docs
    stage = os.path.join(tmp, "stage")
    r = run(["cmake", "--install", a.build, "--prefix", "/usr"], env=dict(os.environ, DESTDIR=stage))
    check(r.returncode == 0, "cmake --install --prefix /usr (DESTDIR)", r.stdout)
    want = set()
    for d, _, files in os.walk(stage):
        for f in files:
            p = os.path.relpath(os.path.join(d, f), stage)
            want.add(p + ".gz" if re.match(r"usr/share/man/man\d/.*\.\d$", p) else p)
    want |= {"usr/share/doc/lagsim/copyright", "usr/share/doc/lagsim/changelog.gz"}
    missing, extra = sorted(want - set(pkg)), sorted(set(pkg) - want)
    check(not missing and not extra, "the package holds exactly the installed files (%d)%s%s"
          % (len(pkg), "; missing " + " ".join(missing) if missing else "",
             "; extra " + " ".join(extra) if extra else ""))

    # its description names every model of the core's table (lagsimd --list models: each
    # model's title, lagsim_lists print model-titles) and the languages of the examples
    desc = run(["dpkg-deb", "-f", deb, "Description"]).stdout
    flat = " ".join(l.strip() for l in desc.splitlines() if l.strip() != ".")
    names = run([os.path.join(a.build, "bin", "lagsimd"), "--list", "models"]).stdout.split()
    titles = run([os.path.join(a.build, "bin", "lagsim_lists"), "print", a.source,
                  "model-titles"]).stdout.replace("**", "").strip()
    titled = [re.sub(r"^an? ", "", t) for t in re.split(r", | and ", titles)]
    check(len(names) >= 5 and len(titled) == len(names) and all(t in flat for t in titled),
          "the Description names the %d models of lagsimd --list models (%s) as %s"
          % (len(names), ", ".join(names), "; ".join(t for t in titled if t not in flat) and
             "missing: " + "; ".join(t for t in titled if t not in flat) or "their titles"), desc)
    langs = ["C", "C++", "Python", "Lua", "Java", "MATLAB/Octave"]
    check(all(re.search(r"(^|[ ,])%s[,; ]" % re.escape(l), flat) for l in langs),
          "the Description names the controllers' languages: " + ", ".join(langs), desc)
    long_lines = [l for l in desc.splitlines()[1:] if len(l) > 80]
    check(not long_lines, "the Description's lines are at most 80 columns", "\n".join(long_lines))

    # docs/deploy.md's table names every header and library the package installs (the
    # generated types as a group; a library's real file by its SONAME)
    deploy = open(os.path.join(a.source, "docs", "deploy.md")).read()
    named = [os.path.basename(p) for p in pkg
             if (re.match(r"usr/include/lagsim/[^/]+$", p) and not p.endswith("_t.h")) or
             (re.match(r"usr/lib/[^/]+$", p) and not re.search(r"\.so\.\d+\.", p))]
    unnamed = [n for n in sorted(named) if "`%s`" % n not in deploy]
    check(named and not unnamed, "docs/deploy.md names the %d headers and libraries installed%s"
          % (len(named), "; not: " + " ".join(unnamed) if unnamed else ""))

    # Debian's places, each where Debian's own tools look
    places = ["usr/bin/lagsimd", "usr/bin/dipc_lqr", "usr/include/lagsim/lagsim_client.h",
              "usr/include/lagsim/lagsim_client.hpp", "usr/include/lagsim/version.h",
              "usr/lib/liblagsim_client.so.%d" % client_abi(a.source), "usr/lib/liblagsim_client.so",
              "usr/bin/manipulator_ct",
              "usr/include/lagsim/lagsim_joint_state_t.h", "usr/lib/liblagsim_client.a",
              "usr/lib/pkgconfig/lagsim-client.pc", "usr/lib/python3/dist-packages/lagsim/__init__.py",
              "usr/lib/python3/dist-packages/lagsim_lcm.py", "usr/share/lua/5.2/lagsim/init.lua",
              "usr/share/lua/5.2/lagsim_lcm.lua", "usr/lib/systemd/system/lagsimd@.service",
              "usr/share/lagsim/examples/python/dipc_balance.py"]
    if os.path.exists(os.path.join(a.build, "lagsim_types.jar")):
        places += ["usr/share/java/lagsim_types.jar", "usr/share/java/lagsim_examples.jar"]
    places += ["usr/share/man/man1/%s.gz" % os.path.basename(m)
               for m in glob.glob(os.path.join(a.source, "docs/man/*.1"))]
    places += ["usr/share/lagsim/config/" + os.path.basename(c)
               for c in glob.glob(os.path.join(a.source, "config/*.yaml"))]
    places += ["usr/share/lagsim/lcmtypes/" + os.path.basename(c)
               for c in glob.glob(os.path.join(a.source, "lcmtypes/*.lcm"))]
    absent = [p for p in places if p not in pkg]
    check(not absent, "in Debian's places: %d files (every man page, scene, .lcm)%s"
          % (len(places), "; absent " + " ".join(absent) if absent else ""))
    octave = [os.path.relpath(m, os.path.join(a.source, "clients/octave")) for m in
              glob.glob(os.path.join(a.source, "clients/octave/**/*.m"), recursive=True)]
    if octave:   # MATLAB/Octave: LAGSIM_OCTAVE_INSTALL_DIR's default, share/lagsim/octave
        absent = [m for m in octave if "usr/share/lagsim/octave/" + m not in pkg]
        check(not absent, "the %d .m files of clients/octave in /usr/share/lagsim/octave%s"
              % (len(octave), "; absent " + " ".join(absent) if absent else ""))
    pypath = run([DEBIAN_PYTHON, "-I", "-c", "import sys; print('\\n'.join(sys.path))"]).stdout.split()
    check("/usr/lib/python3/dist-packages" in pypath, "/usr/lib/python3/dist-packages is on python3's sys.path")
    lua = run(["lua5.2", "-e", "print(package.path)"], env=clean_env()).stdout
    check("/usr/share/lua/5.2/?.lua" in lua.split(";"), "/usr/share/lua/5.2 is on lua5.2's package.path")
    check(not [p for p in pkg if not p.startswith("usr/") or p.startswith("usr/local/")],
          "nothing outside /usr, nothing in /usr/local")
    check(all(o == "root/root" for _, o in pkg.values()), "every file is root's")

    # programs stripped; Depends names the package of every library they need, and python3
    x = os.path.join(tmp, "x")
    run(["dpkg-deb", "-x", deb, x])
    needed, unstripped = set(), []
    for p in sorted(p for p in pkg if p.startswith("usr/bin/")):
        sec = run(["readelf", "-S", "-d", os.path.join(x, p)]).stdout
        if "ELF" not in run(["readelf", "-h", os.path.join(x, p)]).stdout:
            continue
        if ".symtab" in sec or ".debug_info" in sec:
            unstripped.append(p)
        needed |= set(re.findall(r"\(NEEDED\).*\[(.+)\]", sec))
    check(not unstripped, "programs stripped%s" % (": not " + " ".join(unstripped) if unstripped else ""))
    depends = run(["dpkg-deb", "-f", deb, "Depends"]).stdout
    dep_names = set(re.findall(r"(?:^|[,|]\s*)([a-z0-9][a-z0-9.+-]+)", depends))
    owners = {}
    for so in sorted(needed):
        s = run(["dpkg", "-S", "*/" + so]).stdout
        owners[so] = sorted({l.split(":")[0] for l in s.splitlines() if ":" in l})
    unmet = ["%s (%s)" % (so, "/".join(o) or "no package") for so, o in owners.items()
             if not set(o) & dep_names and so not in ("ld-linux-x86-64.so.2",)]
    check(not unmet and "python3" in dep_names, "Depends (%s) covers the %d libraries the "
          "programs need, and python3%s" % (depends.strip(), len(needed),
                                           "; not: " + ", ".join(unmet) if unmet else ""))
    ctl = os.path.join(tmp, "control")
    run(["dpkg-deb", "-e", deb, ctl])
    for s in ("postinst", "prerm", "postrm"):
        r = run(["sh", "-n", os.path.join(ctl, s)])
        check(r.returncode == 0, "maintainer script %s parses (sh -n)" % s, r.stdout)

    # the unit: what it must say, verify, the security score
    text, _ = unit_text(deb, tmp)
    lines = [l.strip() for l in text.splitlines()]
    no = [u for u in UNIT_MUST if u not in lines]
    check(not no, "lagsimd@.service says %s" % (", ".join(UNIT_MUST) if not no else "; lacks " + " ".join(no)))
    limits = [l for l in lines if LIMIT_RE.match(l)]
    with open(os.path.join(a.source, "docs", "deploy.md")) as f:
        deploy = f.read()
    rows = [l for l in limits if not re.search(r"^\| `%s` \|" % re.escape(l), deploy, re.M)]
    check(limits and not rows, "each resource limit of the unit (%s) has its row, with its reason, "
          "in docs/deploy.md's hardening table%s" % (", ".join(limits), "; missing: " + " ".join(rows) if rows else ""))
    example = unit_example(text)
    check(example and ("    LAGSIMD_ARGS=%s\n" % example) in deploy,
          "the unit's header example (LAGSIMD_ARGS=%s) is the one docs/deploy.md gives" % example)
    # verify before installation: the build's lagsimd in ExecStart and its man page on MANPATH
    vdir = os.path.join(tmp, "verify")
    os.makedirs(os.path.join(vdir, "man", "man1"))
    for m in glob.glob(os.path.join(a.source, "docs/man/*.1")):
        shutil.copy(m, os.path.join(vdir, "man", "man1"))
    unit = os.path.join(vdir, "lagsimd@check.service")
    with open(unit, "w") as f:
        f.write(text.replace("/usr/bin/lagsimd", os.path.join(a.build, "bin", "lagsimd")))
    r = run(["systemd-analyze", "verify", unit], env=dict(os.environ, MANPATH=os.path.join(vdir, "man")))
    check(r.returncode == 0 and not r.stdout.strip(), "systemd-analyze verify lagsimd@check.service", r.stdout)
    with open(unit, "w") as f:
        f.write(text)
    r = run(["systemd-analyze", "security", "--offline=yes", unit])
    m = re.search(r"Overall exposure level for \S+: ([0-9.]+) (\S+)", r.stdout)
    check(m and float(m.group(1)) <= EXPOSURE_MAX, "systemd-analyze security --offline=yes: "
          "exposure %s (at most %.1f)" % (m.group(1) + " " + m.group(2) if m else "?", EXPOSURE_MAX),
          r.stdout)

    if shutil.which("lintian") is None:
        check(False, "lintian installed (.ci/install-deps.sh)")
    else:
        r = run(["lintian", "--tag-display-limit", "0", deb])
        tags = [l for l in r.stdout.splitlines() if re.match(r"^[EWIPX]: ", l)]
        errors = [l for l in tags if l.startswith("E: ")]
        for l in tags:
            print("      lintian " + l)
        check(tags and not errors or r.returncode == 0,
              "lintian: no error (%d warning(s) printed above)" % sum(l.startswith("W: ") for l in tags),
              r.stdout)
        # the warnings it prints are the ones docs/deploy.md keeps, each with its reason
        seen = {l.split()[2] for l in tags if l.startswith("W: ") and len(l.split()) > 2}
        doc = open(os.path.join(a.source, "docs", "deploy.md")).read()
        head = "lintian's warnings, kept"
        after = doc.split(head, 1)[-1].splitlines() if head in doc else []
        start = next((i for i, l in enumerate(after) if l.startswith("|")), len(after))
        rows = []
        for l in after[start + 2:]:
            if not l.startswith("|"):
                break
            rows.append(l)
        # a row's tags: the backquoted words its first cell begins with ("`a`, `b` (why)")
        kept = {t for row in rows for t in re.findall(
            r"`([a-z0-9-]+)`", re.match(r"\s*((?:`[a-z0-9-]+`(?:,\s*)?)*)", row.split("|")[1]).group(1))}
        check(rows, "docs/deploy.md has its table of lintian's warnings kept (under \"%s\")" % head)
        check(seen == kept, "lintian's warnings are docs/deploy.md's kept ones (printed, not "
              "kept: %s; kept, not printed: %s)" % (sorted(seen - kept) or "none",
                                                    sorted(kept - seen) or "none"))
    if failures() == 0:
        shutil.rmtree(tmp, ignore_errors=True)


def installed_version():
    r = run(["dpkg-query", "-W", "-f", "${Status}", "lagsim"], stderr=subprocess.DEVNULL)
    return r.returncode == 0 and "ok installed" in r.stdout


def known_to_dpkg():
    """Installed, half-installed or removed with its configuration left: purge it."""
    r = run(["dpkg-query", "-W", "-f", "${Status}", "lagsim"], stderr=subprocess.DEVNULL)
    return r.returncode == 0 and "not-installed" not in r.stdout


def do_install(a, service=False):
    deb, _ = deb_path(a.build)
    if not check(os.path.exists(deb), "%s made (test package_build)" % deb):
        return
    tmp = tempfile.mkdtemp(prefix="lagsim_pkg_inst_")
    before = {p: os.path.lexists("/" + p) for p in deb_files(deb)}
    env = clean_env(DEBIAN_FRONTEND="noninteractive")
    r = run(["apt-get", "install", "-y", "-q", "--no-install-recommends", deb], env=env)
    installed = installed_version()
    try:
        if not check(r.returncode == 0 and installed, "apt-get install %s" % os.path.basename(deb), r.stdout):
            return
        listed = [l for l in run(["dpkg", "-L", "lagsim"]).stdout.splitlines() if l.startswith("/")]
        files = [p for p in listed if os.path.isfile(p) or os.path.islink(p)]
        check(all(os.path.exists("/" + p) for p in before),
              "dpkg -L lagsim: %d paths, %d files; every file of the .deb is on disk" % (len(listed), len(files)))
        # other tests run beside this one: the host (the root of the process that made this
        # check's mount namespace) has none of what it installed
        host = "/proc/%s/root" % os.environ["LAGSIM_PKG_HOST_PID"]
        new = [p for p in files if not before.get(p.lstrip("/"), False)]
        seen = [p for p in new if os.path.lexists(host + p)]
        check(new and not seen and os.path.isdir(host + "/usr"),
              "outside this check's mount namespace none of the %d files it installed is seen%s"
              % (len(new), ": " + " ".join(seen[:5]) if seen else ""))

        state, result = False, None
        if service:
            had_state = os.path.lexists("/var/lib/lagsim") or os.path.lexists("/var/lib/private/lagsim")
            result = service_checks(a, tmp)
            state = not had_state and os.path.lexists("/var/lib/private/lagsim")
        else:
            installed_checks(a, tmp, env)
            # what systemd 252 makes for an instance's StateDirectory=lagsim/%i with DynamicUser
            # (seen under systemd: /var/lib/lagsim/NAME -> ../private/lagsim/NAME)
            if not os.path.lexists("/var/lib/lagsim") and not os.path.lexists("/var/lib/private/lagsim"):
                state = True
                os.makedirs("/var/lib/private/lagsim/pkgtest")
                open("/var/lib/private/lagsim/pkgtest/run.lcm", "w").close()
                os.makedirs("/var/lib/lagsim")
                os.symlink("../private/lagsim/pkgtest", "/var/lib/lagsim/pkgtest")
    finally:
        if known_to_dpkg():
            r = run(["dpkg", "--purge", "lagsim"], env=env)
            check(r.returncode == 0 and not installed_version(), "dpkg --purge lagsim", r.stdout)
    left = [p for p, existed in before.items() if not existed and os.path.lexists("/" + p)]
    left_dirs = sorted({os.path.dirname(p) for p in before if not before[p]} - {""})
    left_dirs = [d for d in left_dirs if d.split("/")[-1].startswith("lagsim") and os.path.exists("/" + d)]
    check(not left and not left_dirs, "after the purge, none of the package's files or lagsim "
          "directories is left%s" % (": " + " ".join(left + left_dirs) if left or left_dirs else ""))
    if state:
        check(not os.path.lexists("/var/lib/lagsim") and not os.path.lexists("/var/lib/private/lagsim"),
              "the purge removed the instances' state (/var/lib/lagsim, /var/lib/private/lagsim)")
    if failures() == 0:
        shutil.rmtree(tmp, ignore_errors=True)
    return result


def installed_checks(a, tmp, env):
    """The installed package from a user's shell: unit, man page, offline, controllers, C."""
    r = run(["systemd-analyze", "verify", "lagsimd@pkgtest.service"], env=env)
    check(r.returncode == 0 and not r.stdout.strip(),
          "systemd-analyze verify lagsimd@pkgtest.service (the installed unit, /usr/bin/lagsimd, man page)",
          r.stdout)
    r = run(["systemd-analyze", "security", "--offline=yes", "lagsimd@pkgtest.service"], env=env)
    m = re.search(r"Overall exposure level for \S+: ([0-9.]+)", r.stdout)
    check(m and float(m.group(1)) <= EXPOSURE_MAX, "systemd-analyze security --offline=yes "
          "lagsimd@pkgtest.service (installed): %s" % (m.group(1) if m else "?"), r.stdout)
    r = run(["man", "-w", "lagsimd"], env=env)
    check(r.stdout.strip() == "/usr/share/man/man1/lagsimd.1.gz", "man -w lagsimd: %s" % r.stdout.strip())

    # offline: the installed lagsimd, from elsewhere, as the build's, byte for byte
    args = ["--config", "/usr/share/lagsim/config/dipc.yaml", "--offline", "--duration", "1",
            "--csv", "-", "--set", "initial.q=[0,0.1,-0.1]"]
    inst = run(["/usr/bin/lagsimd"] + args, cwd=tmp, env=env, stderr=subprocess.PIPE)
    ref = run([os.path.join(a.build, "bin", "lagsimd")] + args, cwd=tmp, env=env, stderr=subprocess.PIPE)
    rows = inst.stdout.strip().splitlines()
    check(inst.returncode == 0 and len(rows) > 100 and inst.stdout == ref.stdout
          and "nan" not in inst.stdout and "inf" not in inst.stdout,
          "installed lagsimd --offline: %d rows, the same bytes as the build's" % len(rows),
          inst.stderr)

    # real time and lockstep: the installed daemon with the installed controllers
    py = run([DEBIAN_PYTHON, "-c", "import lagsim, lagsim_lcm; print(lagsim_lcm.__file__)"],
             cwd=tmp, env=env)
    check(py.stdout.strip() == "/usr/lib/python3/dist-packages/lagsim_lcm.py",
          "python3 imports lagsim_lcm from %s" % py.stdout.strip())
    lua = run(["lua5.2", "-e", "print(package.searchpath('lagsim_lcm', package.path))"], cwd=tmp, env=env)
    check(lua.stdout.strip() == "/usr/share/lua/5.2/lagsim_lcm.lua",
          "lua5.2 finds lagsim_lcm at %s" % lua.stdout.strip())
    e2e = [sys.executable, os.path.join(a.source, "tests/clients/run_e2e.py"), "--lagsimd",
           "/usr/bin/lagsimd", "--config", "/usr/share/lagsim/config/dipc.yaml", "--timeout", "60"]
    runs = [
        ("dipc_lqr in real time", ["--mode", "realtime", "--name", "PKGRT",
          "--check", "states >= 150", "--check", "t_last - t_first >= 3 - 0.011",
          "--check", "max_abs_theta1 <= 1.25 * pred_max_abs_theta1 + 0.005",
          "--check", "max_abs_theta0 < 1.0"],
         ["/usr/bin/dipc_lqr", "--prefix", "{prefix}", "--duration", "3", "--timeout", "5", "-q"]),
        ("Python dipc_balance.py in lockstep", ["--mode", "lockstep", "--name", "PKGPY",
          "--daemon-arg=--duration", "--daemon-arg=2",
          "--check", "states == 201", "--check", "max_abs_theta1 < 0.1"],
         [DEBIAN_PYTHON, "/usr/share/lagsim/examples/python/dipc_balance.py", "-q", "--prefix", "{prefix}"]),
    ]
    if os.path.exists("/usr/share/lagsim/octave/dipc_balance.m") and shutil.which("octave", path=env["PATH"]):
        # as docs/clients.md has a user run it: the installed folder on Octave's path
        runs.append(("Octave dipc_balance.m in lockstep", ["--mode", "lockstep", "--name", "PKGOCT",
                     "--daemon-arg=--duration", "--daemon-arg=2",
                     "--check", "states == 201", "--check", "max_abs_theta1 < 0.1"],
                     ["octave", "--no-gui", "--quiet", "--no-window-system", "--no-init-file", "--path",
                      "/usr/share/lagsim/octave", "--eval", "dipc_balance --prefix {prefix} -q"]))
    for name, opts, client in runs:
        r = run(e2e + opts + ["--"] + client, cwd=tmp, env=env)
        check(r.returncode == 0, "installed lagsimd with the installed %s" % name, r.stdout)

    # a C++ controller over the client library alone (/usr/lib/liblagsim_client.so, found
    # by the loader with no LD_LIBRARY_PATH), lagsim's C example over the core
    for pkg, compiler, source, out in (
            ("lagsim-client", ["c++", "-std=c++17"], "clients/manipulator_ct.cpp", "ct"),
            ("lagsim-core", ["cc", "-std=c11", "-D_GNU_SOURCE"], "clients/manipulator_pd.c", "pd")):
        pc = run(["pkg-config", "--cflags", "--libs", pkg], env=env)
        if check(pc.returncode == 0, "pkg-config %s (no PKG_CONFIG_PATH): %s" % (pkg, pc.stdout.strip()),
                 pc.stdout):
            r = run(compiler + ["-o", os.path.join(tmp, out), os.path.join(a.source, source)] +
                    pc.stdout.split(), env=env)
            check(r.returncode == 0, "%s builds against /usr/include and /usr/lib" % source, r.stdout)
    r = run([os.path.join(tmp, "ct"), "--help"], env=env)
    check(r.returncode == 0 and "manipulator_ct" in r.stdout,
          "the C++ controller runs: the loader finds liblagsim_client.so.%d" % client_abi(a.source),
          r.stdout + r.stderr if hasattr(r, "stderr") and r.stderr else r.stdout)



class NsSystemd:
    """systemd as PID 1 of a PID and mount namespace of its own, seeing only `units`."""

    def __init__(self, tmp, units):
        self.tmp, self.units, self.proc, self.pid = tmp, units, None, None
        self.log = os.path.join(tmp, "systemd.log")

    def start(self):
        self.cg_before = self.cgroups()
        inner = os.path.join(self.tmp, "inner.sh")
        with open(inner, "w") as f:
            f.write("set -e\n"
                    "mount -t tmpfs tmpfs /run\n"              # no /run/systemd for the host
                    "[ ! -d /var/log/journal ] || mount -t tmpfs tmpfs /var/log/journal\n"
                    "mount -t tmpfs tmpfs /etc/systemd/system\n"
                    "mount --bind %s /usr/lib/systemd/system\n"  # /lib -> usr/lib
                    "exec /lib/systemd/systemd --system --unit=pkgtest.target "
                    "--log-target=console --log-level=notice\n" % self.units)
        self.proc = subprocess.Popen(["unshare", "--pid", "--fork", "--mount", "--uts",
                                      "--mount-proc", "sh", inner], stdout=open(self.log, "w"),
                                     stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and self.proc.poll() is None:
            kids = run(["pgrep", "-P", str(self.proc.pid)]).stdout.split()
            if kids:
                self.pid = kids[0]
                st = self.ctl("is-system-running").stdout.strip()
                if st in ("running", "degraded"):
                    return True
            time.sleep(0.5)
        return False

    def sh(self, cmd, **kw):
        return run(["nsenter", "-t", self.pid, "-m", "-p"] + cmd, **kw)

    def ctl(self, *args):
        return self.sh(["systemctl", "--no-pager"] + list(args))

    def show(self, unit, prop):
        return self.ctl("show", "-p", prop, "--value", unit).stdout.strip()

    @staticmethod
    def cgroups():
        return {d for d, _, _ in os.walk("/sys/fs/cgroup")}

    def stop(self):
        if self.proc and self.proc.poll() is None:
            if self.pid:
                os.kill(int(self.pid), 9)   # the namespace's PID 1: every process in it goes
            self.proc.kill()
            self.proc.wait()
        time.sleep(0.5)
        for d in sorted(self.cgroups() - self.cg_before, key=len, reverse=True):
            try:
                os.rmdir(d)
            except OSError:
                pass


def host_form_checks(sd, tmp, env):
    """The unit's host form: /etc/lagsim/NAME.d/ instead of NAME.yaml, as docs/deploy.md's
    "A lab host for a class" sets it up."""
    name, d = "pkglab", "/etc/lagsim/pkglab.d"
    directory = lcm_port(8)  # the directory's pair and three plants' (held: lcm_port.py)
    dir_url = "udpm://%s:%d?ttl=0" % (GROUP, directory)
    url = lambda k: "udpm://%s:%d?ttl=0" % (GROUP, directory + 2 + 2 * k)
    os.makedirs(d, exist_ok=True)
    for st in ("alice", "bob"):
        shutil.copy("/usr/share/lagsim/config/dipc.yaml", "%s/%s.yaml" % (d, st))
        os.chmod("%s/%s.yaml" % (d, st), 0o644)
    os.chmod(d, 0o755)
    with open("/etc/lagsim/%s.env" % name, "w") as f:
        f.write("LCM_DEFAULT_URL=%s\nLAGSIMD_ARGS=--log run.lcm --increment\n" % dir_url)
    unit = "lagsimd@%s.service" % name
    lenv = dict(env, LCM_DEFAULT_URL=dir_url)

    def listed(want, seconds=30):
        """lagsimctl list on the directory until it names the plants of `want` (each call
        listens 2 s: the wait is the listening, no sleep), or `seconds` passed."""
        deadline, rows, ls = time.monotonic() + seconds, {}, None
        while time.monotonic() < deadline:
            ls = run(["/usr/bin/lagsimctl", "--timeout", "2", "list"], env=lenv, timeout=30)
            rows = {l.split()[0]: l.split()[-1] for l in ls.stdout.splitlines()[1:] if l.strip()}
            if all(k in rows for k in want):
                break
        return rows, ls.stdout if ls else ""

    try:
        r = sd.ctl("start", unit)
        rows, out = listed(("ALICE", "BOB"))
        check(r.returncode == 0 and sd.show(unit, "ActiveState") == "active",
              "the host form: systemctl start %s with %s/ (alice.yaml, bob.yaml)" % (unit, d), r.stdout)
        check(rows == {"ALICE": url(0), "BOB": url(1)},
              "lagsimctl list: ALICE and BOB, each on its own port pair after the directory's: %s"
              % rows, out)
        lqr = run(["/usr/bin/dipc_lqr", "--prefix", "ALICE", "--url", url(0), "--duration", "2",
                   "--timeout", "10", "-q"], env=env, timeout=60)
        check(lqr.returncode == 0 and "states=" in lqr.stdout,
              "the installed dipc_lqr balances ALICE on its URL", lqr.stdout)
        shutil.copy("/usr/share/lagsim/config/dipc.yaml", "%s/carol.yaml" % d)
        os.chmod("%s/carol.yaml" % d, 0o644)
        pid = sd.show(unit, "MainPID")
        rows, out = listed(("CAROL",))
        check(rows.get("CAROL") == url(2) and sd.show(unit, "NRestarts") == "0" and
              sd.show(unit, "MainPID") == pid,
              "carol.yaml added: CAROL runs on the next pair, without a restart (NRestarts %s)" %
              sd.show(unit, "NRestarts"), out)
        r = sd.ctl("stop", unit)
        check(r.returncode == 0 and sd.show(unit, "ExecMainStatus") == "0",
              "systemctl stop: exit %s" % sd.show(unit, "ExecMainStatus"), r.stdout)
        j = sd.sh(["journalctl", "-u", unit, "--no-pager", "-o", "cat"]).stdout
        check("ALICE: listening on" in j and "CAROL: event stop" in j,
              "its journal: each plant's lines", j)
        log = "/var/lib/lagsim/%s/alice/run.lcm.000000" % name
        rp = run(["/usr/bin/lagsimd", "--config", "%s/alice.yaml" % d, "--set", "lcm.prefix=ALICE",
                  "--replay", log], env=env, cwd=tmp)
        check(os.path.exists(log) and rp.returncode == 0,
              "ALICE's --log in %s: --replay exact (exit %d)" % (log, rp.returncode), rp.stdout)
    finally:
        shutil.rmtree(d, ignore_errors=True)
        if os.path.exists("/etc/lagsim/%s.env" % name):
            os.remove("/etc/lagsim/%s.env" % name)


def service_checks(a, tmp):
    units = os.path.join(tmp, "units")
    os.makedirs(units)
    shutil.copy("/usr/lib/systemd/system/lagsimd@.service", units)  # the installed unit
    for u in ("systemd-journald.service", "systemd-journald.socket",
              "systemd-journald-dev-log.socket", "systemd-journald-audit.socket"):
        shutil.copy("/usr/lib/systemd/system/" + u, units)
    for t in ("sysinit", "basic", "network-online", "multi-user", "shutdown", "local-fs", "sockets"):
        with open(os.path.join(units, t + ".target"), "w") as f:
            f.write("[Unit]\nDescription=%s (empty, for the test)\n" % t)
    with open(os.path.join(units, "pkgtest.target"), "w") as f:
        f.write("[Unit]\nDescription=package test\nWants=systemd-journald.service\n")

    name, bad = "pkgsvc", "pkgsvcbad"
    prefix = "PKGSVC_%d" % os.getpid()
    made_etc = not os.path.exists("/etc/lagsim")
    ours = ["/etc/lagsim/%s.yaml" % name, "/etc/lagsim/%s.env" % name, "/etc/lagsim/%s.yaml" % bad]
    os.makedirs("/etc/lagsim", exist_ok=True)
    shutil.copy("/usr/share/lagsim/config/dipc.yaml", ours[0])        # as docs/deploy.md says
    os.chmod(ours[0], 0o644)
    with open("/usr/lib/systemd/system/lagsimd@.service") as f:
        example = unit_example(f.read())   # the unit's own example, as an admin copies it
    if not check(example is not None and "--log run.lcm" in example,
                 "the installed unit's header gives an example LAGSIMD_ARGS with --log run.lcm: %s"
                 % example):
        return 0
    bus = lcm_url()  # a port pair of this test's own: other tests run beside it
    with open(ours[1], "w") as f:
        f.write("LCM_DEFAULT_URL=%s\nLAGSIMD_ARGS=--set lcm.prefix=%s %s\n" % (bus, prefix, example))
    with open(ours[2], "w") as f:
        f.write("model: dipc\nbogus: 1\n")
    os.chmod(ours[2], 0o644)
    sd = NsSystemd(tmp, units)
    try:
        if not sd.start():
            print("SKIP: systemd does not start in a PID and mount namespace here (unshare needs "
                  "CAP_SYS_ADMIN); its output:")
            with open(sd.log) as f:
                print(f.read()[-3000:])
            return SKIP
        check(True, "systemd %s runs as PID 1 of a namespace (host pid %s)"
              % (sd.sh(["systemctl", "--version"]).stdout.split()[1], sd.pid))
        unit = "lagsimd@%s.service" % name
        r = sd.ctl("start", unit)
        check(r.returncode == 0, "systemctl start %s" % unit, r.stdout)
        env = clean_env(LCM_DEFAULT_URL=bus)
        lqr = run(["/usr/bin/dipc_lqr", "--prefix", prefix, "--duration", "3", "--timeout", "10", "-q"],
                  env=env, timeout=60)
        summ = {k: v for k, v in re.findall(r"(\w+)=(\S+)", lqr.stdout.splitlines()[-1] if lqr.stdout else "")}
        ok = lqr.returncode == 0 and float(summ.get("states", 0)) >= 150 and \
            float(summ.get("max_abs_theta1", 9)) <= 1.25 * float(summ.get("pred_max_abs_theta1", 0)) + 0.005
        check(ok, "the installed dipc_lqr balances the service's plant in real time (%s states, "
              "max |theta1| %s)" % (summ.get("states"), summ.get("max_abs_theta1")), lqr.stdout)
        pid = sd.show(unit, "MainPID")
        st = sd.sh(["cat", "/proc/%s/status" % pid]).stdout
        f = dict(re.findall(r"^(\w+):\s*(.*)$", st, re.M))
        uid = f.get("Uid", "0").split()[0]
        check(sd.show(unit, "ActiveState") == "active" and uid != "0" and
              f.get("CapEff") == "0000000000000000" and f.get("NoNewPrivs") == "1" and
              f.get("Seccomp") == "2",
              "it runs as a dynamic user (uid %s), no capabilities (CapEff %s), NoNewPrivs %s, "
              "seccomp mode %s" % (uid, f.get("CapEff"), f.get("NoNewPrivs"), f.get("Seccomp")), st)
        r = sd.ctl("stop", unit)
        check(r.returncode == 0 and sd.show(unit, "ExecMainStatus") == "0" and
              sd.show(unit, "Result") == "success",
              "systemctl stop: SIGTERM, exit %s, result %s" % (sd.show(unit, "ExecMainStatus"),
                                                              sd.show(unit, "Result")), r.stdout)
        j = sd.sh(["journalctl", "-u", unit, "--no-pager", "-o", "cat"]).stdout
        check("listening on" in j and "event stop" in j and "SIGTERM" in j,
              "journalctl -u %s: the daemon's lines (listening on ..., event stop ... SIGTERM)" % unit, j)
        state = "/var/lib/lagsim/%s" % name
        log = state + "/run.lcm.000000"    # the example's --increment: the series' first file
        rp = run(["/usr/bin/lagsimd", "--config", "/usr/share/lagsim/config/dipc.yaml", "--set",
                  "lcm.prefix=" + prefix, "--replay", log], env=env, cwd=tmp)
        check(os.path.exists(log) and rp.returncode == 0, "%s wrote %s (%s bytes): --replay exact "
              "(exit %d)" % (example, log, os.path.getsize(log) if os.path.exists(log) else "no",
                             rp.returncode), rp.stdout)
        first_size = os.path.getsize(log) if os.path.exists(log) else -1

        def series():
            return sorted(n for n in os.listdir(state) if n.startswith("run.lcm.")) \
                if os.path.isdir(state) else []

        def grows(name):
            """The daemon is writing `name`: it grows while the plant runs (states at 100 Hz)."""
            path = os.path.join(state, name)
            size0 = os.path.getsize(path) if os.path.exists(path) else -1
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline:
                time.sleep(0.5)
                if os.path.exists(path) and os.path.getsize(path) > size0 + 1000:
                    return True
            return False

        # the limits the unit sets, as the kernel and systemd apply them to the daemon
        sd.ctl("start", unit)
        pid = sd.show(unit, "MainPID")
        lim = sd.sh(["cat", "/proc/%s/limits" % pid]).stdout
        lims = {k: re.search(r"^%s\s+(\S+)" % k, lim, re.M) for k in
                ("Max file size", "Max core file size", "Max open files")}
        lims = {k: v.group(1) if v else None for k, v in lims.items()}
        mem, tasks = sd.show(unit, "MemoryMax"), sd.show(unit, "TasksMax")
        check(lims == {"Max file size": str(4 << 30), "Max core file size": "0",
                       "Max open files": "4096"} and mem == str(512 << 20) and tasks == "512",
              "the unit's limits on the daemon: %s, MemoryMax %s, TasksMax %s" % (lims, mem, tasks), lim)
        # restarts with the example: a crash (SIGKILL) restarts it, and a start after a
        # crash goes on logging in a new file; `systemctl restart` once more, the same
        for k in range(1, 4):
            name = "run.lcm.%06d" % k
            if k == 2:
                r = sd.ctl("kill", "-s", "SIGKILL", unit)
                deadline, restarted = time.monotonic() + 20, False
                while time.monotonic() < deadline and not restarted:
                    time.sleep(0.5)
                    newpid = sd.show(unit, "MainPID")
                    restarted = sd.show(unit, "NRestarts") == "1" and newpid not in ("0", pid) and \
                        sd.show(unit, "ActiveState") == "active"
                check(restarted, "killed (SIGKILL), it is restarted (Restart=on-failure): NRestarts %s"
                      % sd.show(unit, "NRestarts"))
            elif k == 3:
                r = sd.ctl("restart", unit)
                check(r.returncode == 0, "systemctl restart %s" % unit, r.stdout)
            pid = sd.show(unit, "MainPID")
            check(sd.show(unit, "ActiveState") == "active" and grows(name),
                  "start %d with the example: active, writing %s (it grows)" % (k + 1, name))
        sd.ctl("stop", unit)
        j = sd.sh(["journalctl", "-u", unit, "--no-pager", "-o", "cat"]).stdout
        files = series()
        check(files == ["run.lcm.%06d" % k for k in range(4)] and
              os.path.getsize(log) == first_size and "writing run.lcm.000003" in j,
              "each start kept its own record (--increment): the first unchanged, one new file a "
              "start, each named in the journal: %s" % files, j)
        ubad = "lagsimd@%s.service" % bad
        sd.ctl("start", ubad)
        # failed (bounded: 30 s), then RestartSec and 1 s more: a restart would have come
        t = time.monotonic()
        while sd.show(ubad, "ActiveState") != "failed" and time.monotonic() - t < 30:
            time.sleep(0.1)
        restart_us = sd.show(ubad, "RestartUSec")  # "5s", "100ms", "1min 30s"
        restart_s = sum(float(v) * {"min": 60, "s": 1, "ms": 1e-3, "us": 1e-6}[u] for v, u in
                        re.findall(r"([\d.]+)(min|ms|us|s)", restart_us))
        time.sleep(restart_s + 1)
        jb = sd.sh(["journalctl", "-u", ubad, "--no-pager", "-o", "cat"]).stdout
        check(sd.show(ubad, "ExecMainStatus") == "2" and sd.show(ubad, "NRestarts") == "0" and
              sd.show(ubad, "ActiveState") == "failed" and "%s.yaml:2:1: unknown key" % bad in jb,
              "a bad scene: exit %s, %s, not restarted (NRestarts %s), file:line:column in the journal"
              % (sd.show(ubad, "ExecMainStatus"), sd.show(ubad, "ActiveState"), sd.show(ubad, "NRestarts")), jb)
        host_form_checks(sd, tmp, env)
        # removal where systemd runs: the prerm stops every instance, the purge removes the
        # links of enabled ones (dpkg run inside the namespace, which has /run/systemd/system)
        sd.ctl("enable", "--now", unit)
        t = time.monotonic()  # started (bounded: 30 s)
        while sd.show(unit, "ActiveState") != "active" and time.monotonic() - t < 30:
            time.sleep(0.1)
        link = "/etc/systemd/system/multi-user.target.wants/" + unit
        was = (sd.show(unit, "ActiveState"), sd.sh(["test", "-L", link]).returncode == 0)
        # in a mount namespace of its own under systemd's, without the unit directory shown
        # to systemd, so that dpkg removes the host's files, not the copies systemd sees
        r = sd.sh(["unshare", "--mount", "sh", "-c", "umount /usr/lib/systemd/system && "
                   "exec dpkg --purge lagsim"])
        now = (sd.show(unit, "ActiveState"), sd.sh(["test", "-L", link]).returncode == 0)
        gone = not os.path.lexists("/var/lib/lagsim/" + name) and not os.path.lexists("/var/lib/private/lagsim")
        check(r.returncode == 0 and was == ("active", True) and now == ("inactive", False) and gone,
              "dpkg --purge under systemd: the enabled, running instance (%s, linked %s) is stopped "
              "and unlinked (%s, linked %s); its state directory (the record) removed: %s"
              % (was + now + (gone,)), r.stdout)
    finally:
        sd.stop()
        for p in ours:
            if os.path.exists(p):
                os.remove(p)
        if made_etc:
            try:
                os.rmdir("/etc/lagsim")
            except OSError:
                pass
    return 0


# What an install writes to (the package's files, dpkg's and apt's state, ldconfig's cache).
OVERLAID = ("usr", "etc", "var")
NO_ROOT = 97  # the overlays could not be made


def in_own_root():
    """Runs this check again in a mount namespace of its own, where /usr, /etc and /var are
    overlays of the host's with their changes on a tmpfs of its own: the package it
    installs (its Python and Lua modules, its library, its programs) is seen by this check
    and its children only, and goes with them, so other tests run beside it. /run (the
    port and package locks) is the host's. Exit status: the check's."""
    if run(["unshare", "--mount", "true"]).returncode != 0:
        print("SKIP: this host cannot make a mount namespace (unshare --mount needs "
              "CAP_SYS_ADMIN), where the package is installed without other tests seeing it")
        return SKIP
    root = tempfile.mkdtemp(prefix="lagsim_pkg_root_")
    # the changes on a tmpfs of the namespace's own: gone with it, even when the check is
    # killed, and never an overlay's upper directory on an overlay (a container's /tmp)
    script = ('r=$1; shift; mount -t tmpfs lagsim_pkg "$r" || exit %d; for m in %s; do '
              'mkdir "$r/$m.up" "$r/$m.work" && mount -t overlay overlay -o '
              '"lowerdir=/$m,upperdir=$r/$m.up,workdir=$r/$m.work" "/$m" || exit %d; done; '
              'exec "$@"' % (NO_ROOT, " ".join(OVERLAID), NO_ROOT))
    # set only here: the run inside the namespace knows itself by it, and the host by its PID
    env = dict(os.environ, LAGSIM_PKG_HOST_PID=str(os.getpid()))
    try:
        r = subprocess.run(["unshare", "--mount", "--propagation", "private", "sh", "-c",
                            script, "sh", root, sys.executable, os.path.abspath(__file__)] +
                           sys.argv[1:], env=env)
    finally:
        os.rmdir(root)
    if r.returncode == NO_ROOT:
        print("FAIL cannot overlay /%s in a mount namespace of its own (`unshare --mount`, "
              "overlayfs): the package is installed there only" % ", /".join(OVERLAID))
        return 1
    return r.returncode


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("what", choices=("build", "install", "service"))
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    a.build, a.source = os.path.abspath(a.build), os.path.abspath(a.source)
    if shutil.which("systemd-analyze") is None:
        print("SKIP: the unit's checks need systemd-analyze (the package systemd, installed by "
              "`.ci/install-deps.sh dev`, not by tests/run.sh outside CI)")
        return SKIP
    if a.what in ("install", "service"):
        if os.geteuid() != 0:
            print("SKIP: installing the package needs root (CI runs the suite as root on a "
                  "throwaway machine); `sudo ctest -L package` runs it here")
            return SKIP
        if installed_version():
            print("SKIP: a lagsim package is installed on this host already; this test would "
                  "replace and purge it (dpkg --purge lagsim first to run it)")
            return SKIP
    if a.what in ("install", "service") and "LAGSIM_PKG_HOST_PID" not in os.environ:
        return in_own_root()
    os.makedirs(os.path.dirname(LOCK), exist_ok=True)
    with open(LOCK if a.what != "build" else os.path.join(a.build, ".package.lock"), "w") as lk:
        fcntl.flock(lk, fcntl.LOCK_EX)   # one run at a time: dpkg, one package name
        if a.what != "build" and installed_version():
            print("SKIP: a lagsim package got installed while this test waited for %s" % LOCK)
            return SKIP
        if a.what == "build":
            do_build(a)
        elif do_install(a, service=a.what == "service") == SKIP and failures() == 0:
            return SKIP
    return verdict()


if __name__ == "__main__":
    sys.exit(main())
