#!/usr/bin/env python3
"""Installs the build into a temporary prefix and holds the documentation of what was
installed to what the programs say.

    check_man.py --build DIR --models BIN CASE        (CASE: pages | models)

pages:  every program in bin/ has a man page in share/man/man1 (a ".so" page followed)
        that renders without a warning and names exactly the options of the program's
        --help: an option added without documentation, or documented but gone, fails.
        Options are read from --help's option lines ("  -c, --config FILE ...") and from
        the page's .TP tags under OPTIONS (and, in a page of several programs, under the
        .SS of that program, or of several programs naming it: ".SS a, b").
models: the lists of models, each against the core's table (BIN prints it) name for
        name, missing and extra names alike: lagsimd --help's list, the list of lagsimd.1's
        DESCRIPTION (its .B names between the two dashes) and the comment of scene_t.model
        in scene_t.lcm (the names after "lagsimd --list models:"). Besides these, any run of two or more
        of the table's names joined by commas, "or" or "and" (the table's spelling, whole
        words) in each installed program's --help, the Python, Lua and Java examples'
        --help, every installed man page and every installed .lcm file's comments is a
        list of models and must name them all; a model's name inside other words ("double
        inverted pendulum") is no list. No --help prints a Lua table's address.
"""
import argparse
import glob
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from lagsim_check import check, verdict  # noqa: E402  (tests/common: the one harness)


def run_help(cmd, env=None):
    r = subprocess.run(cmd + ["--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True, timeout=60, env=dict(os.environ, **(env or {})))
    return r.returncode, r.stdout


OPT = r"--?[A-Za-z0-9][\w-]*"


def help_options(text):
    """Options of --help's option lines: indented at most 8 spaces, starting with '-'."""
    opts = set()
    for line in text.splitlines():
        m = re.match(r"^ {1,8}(%s(?:,\s*%s)*)" % (OPT, OPT), line)
        if m:
            opts.update(o.strip() for o in m.group(1).split(","))
    return opts


def read_page(path, mandir):
    text = open(path).read()
    m = re.match(r"\.so\s+(\S+)\s*$", text)
    if m:  # a page that is another's: man1/x.1 relative to the man directory
        return read_page(os.path.join(mandir, m.group(1)), mandir)
    return text


def untroff(s):
    s = re.sub(r"\\f[BIRP]", "", s)
    return s.replace("\\-", "-").replace("\\(em", "-").replace("\\(bu", "")


def page_options(text, prog):
    """.TP tags under .SH OPTIONS, or under .SS <prog> (or .SS <prog>, <other>, ...: the
    section of several programs) of any section."""
    opts, sh, ss = set(), "", None
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(".SH"):
            sh, ss = line[3:].strip().strip('"'), None
        elif line.startswith(".SS"):
            ss = line[3:].strip().strip('"')
        elif line.startswith(".TP") and i + 1 < len(lines):
            if (sh == "OPTIONS" and ss is None) or (ss is not None and
                                                    prog in [x.strip() for x in ss.split(",")]):
                opts.update(re.findall(r"(?<![\w-])(%s)" % OPT, untroff(lines[i + 1])))
    return opts


def case_pages(prefix):
    mandir = os.path.join(prefix, "share", "man")
    progs = sorted(os.listdir(os.path.join(prefix, "bin")))
    check(len(progs) >= 5, "programs installed: %s" % " ".join(progs))
    for p in progs:
        page = os.path.join(mandir, "man1", p + ".1")
        if not check(os.path.exists(page), "%s: man page %s" % (p, os.path.relpath(page, prefix))):
            continue
        man = subprocess.run(["man", "--warnings", "-l", page], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, universal_newlines=True, cwd=mandir,
                             env=dict(os.environ, MANPAGER="cat", MANWIDTH="80"))
        check(man.returncode == 0 and man.stdout.strip() and not man.stderr.strip(),
              "%s: the page renders without a warning %s" % (p, man.stderr.strip()[:300]))
        rc, hlp = run_help([os.path.join(prefix, "bin", p)])
        h = help_options(hlp)
        m = page_options(read_page(page, mandir), p)
        check(rc == 0 and "--help" in h, "%s --help: exit 0, options listed (%d)" % (p, len(h)))
        check(h == m, "%s: the page names the options of --help%s%s" % (
            p, "; not in the page: " + " ".join(sorted(h - m)) if h - m else "",
            "; not in --help: " + " ".join(sorted(m - h)) if m - h else ""))


LIST_SEP = r"(?:\s*,\s*(?:(?:or|and)\s+)?|\s+(?:or|and)\s+)"


def model_runs(text, models):
    """Runs of two or more of the table's names joined by list separators ("a, b or c")."""
    name = r"(?<![\w-])(?:%s)(?![\w-])" % "|".join(re.escape(m) for m in models)
    out = []
    for m in re.finditer(r"%s(?:%s%s)+" % (name, LIST_SEP, name), text):
        out.append((" ".join(m.group(0).split()), set(re.findall(name, m.group(0)))))
    return out


def check_runs(what, text, models):
    runs = model_runs(text, models)
    for run, names in runs:
        missing = [m for m in models if m not in names]
        check(not missing, "%s lists models and names all %d%s ('%s')" % (
            what, len(models), "; missing " + ", ".join(missing) if missing else "", run))
    return len(runs)


def check_list(what, names, models):
    """A list the test knows by its place: exactly the table's names."""
    if names is None:
        return check(False, "%s: the list of models is not where the test looks for it" % what)
    missing = [m for m in models if m not in names]
    extra = [n for n in names if n not in models]
    return check(not missing and not extra and len(names) == len(set(names)),
                 "%s's list of models is the core's table (%s)%s%s" % (
                     what, ", ".join(names), "; missing " + ", ".join(missing) if missing else "",
                     "; not in the table: " + ", ".join(extra) if extra else ""))


def split_names(s):
    return [n for n in re.split(LIST_SEP, s.strip().rstrip(".")) if n]


def help_list(hlp):
    """lagsimd --help: "Steps one Lagrangian model (a, b, ...)"."""
    m = re.search(r"Lagrangian model \(([^)]*)\)", hlp)
    return split_names(m.group(1)) if m else None


def page_list(troff):
    """lagsimd.1: the .B names of the DESCRIPTION between its first two dashes (\\(em)."""
    d = troff.find(".SH DESCRIPTION")
    a = troff.find("\\(em", d) if d >= 0 else -1
    b = troff.find("\\(em", a + 1) if a >= 0 else -1
    if b < 0:
        return None
    return [untroff(l[3:]).strip() for l in troff[a:b].splitlines() if l.startswith(".B ")]


def lcm_list(text):
    """scene_t.lcm: the comment of `model` and its continuation lines, after "lagsimd --list
    models:" (the names a | b | c, generated from the table: server/lists)."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if re.match(r"\s*string\s+model;", line):
            comment = line.partition("//")[2]
            for more in lines[i + 1:]:
                if not more.strip().startswith("//"):
                    break
                comment += " " + more.strip()[2:]
            if "lagsimd --list models:" in comment:
                return [n.strip() for n in comment.split("lagsimd --list models:", 1)[1].split("|")]
    return None


def case_models(prefix, models, src):
    check(len(models) >= 4, "the core's table: %s" % ", ".join(models))
    found = 0
    texts = []
    for p in sorted(os.listdir(os.path.join(prefix, "bin"))):
        rc, hlp = run_help([os.path.join(prefix, "bin", p)])
        texts.append(("%s --help" % p, hlp))
    pydir = (glob.glob(os.path.join(prefix, "lib", "python3*", "dist-packages")) or [""])[0]
    for f in sorted(glob.glob(os.path.join(prefix, "share/lagsim/examples/python/*.py"))):
        rc, hlp = run_help([sys.executable, f], {"PYTHONPATH": pydir})
        texts.append(("%s --help" % os.path.basename(f), hlp))
        check(rc == 0, "%s --help: exit 0" % os.path.basename(f))
    lua_path = "%s/?.lua;%s/?/init.lua;;" % ((os.path.join(prefix, "share/lua/5.2"),) * 2)
    for f in sorted(glob.glob(os.path.join(prefix, "share/lagsim/examples/lua/*.lua"))):
        rc, hlp = run_help(["lua5.2", f], {"LUA_PATH": lua_path})
        texts.append(("%s --help" % os.path.basename(f), hlp))
        check(rc == 0 and not re.search(r"table: 0x|function: 0x", hlp),
              "%s --help: exit 0, no Lua address printed as a default" % os.path.basename(f))
    jars = [os.path.join(prefix, "share/java", j) for j in ("lagsim_types.jar", "lagsim_examples.jar")]
    if all(os.path.exists(j) for j in jars):
        for f in sorted(glob.glob(os.path.join(src, "clients/java/lagsim/examples/*.java"))):
            if "static void main" not in open(f).read():
                continue
            cls = "lagsim.examples." + os.path.basename(f)[:-5]
            rc, hlp = run_help(["java", "-cp", ":".join(["/usr/share/java/lcm.jar"] + jars), cls])
            texts.append(("%s --help" % cls, hlp))
    mandir = os.path.join(prefix, "share", "man")
    check_list("lagsimd --help", help_list(run_help([os.path.join(prefix, "bin", "lagsimd")])[1]), models)
    check_list("lagsimd.1", page_list(read_page(os.path.join(mandir, "man1", "lagsimd.1"), mandir)),
               models)
    check_list("scene_t.lcm", lcm_list(open(os.path.join(prefix, "share/lagsim/lcmtypes/scene_t.lcm")).read()),
               models)
    for f in sorted(glob.glob(os.path.join(prefix, "share/man/man1/*.1"))):
        # paragraphs, tags and each line of an example (.nf) end a sentence
        lines, nofill = [], False
        for line in open(f).read().splitlines():
            nofill = (nofill or line.startswith(".nf")) and not line.startswith(".fi")
            brk = nofill or re.match(r"\.(SH|SS|PP|TP|IP|RS|RE|br|sp)\b", line)
            lines.append(line + (" ;" if brk else ""))
        texts.append((os.path.basename(f), untroff("\n".join(lines))))
    for f in sorted(glob.glob(os.path.join(prefix, "share/lagsim/lcmtypes/*.lcm"))):
        comments = " ".join(re.findall(r"//(.*)", open(f).read()))
        texts.append((os.path.basename(f), comments))
    for what, text in texts:
        found += check_runs(what, text, models)
    print("other runs of model names found and checked: %d" % found)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--models", required=True, help="a program printing the core's model names")
    ap.add_argument("case", choices=["pages", "models"])
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="lagsim_man_") as tmp:
        prefix = os.path.join(tmp, "prefix")
        r = subprocess.run(["cmake", "--install", a.build, "--prefix", prefix], stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True)
        if not check(r.returncode == 0, "cmake --install into %s" % prefix):
            print(r.stdout)
            return 1
        if a.case == "pages":
            case_pages(prefix)
        else:
            models = subprocess.run([a.models], stdout=subprocess.PIPE, universal_newlines=True,
                                    check=True).stdout.split()
            case_models(prefix, models, os.path.abspath(a.source))
    return verdict(a.case)


if __name__ == "__main__":
    sys.exit(main())
