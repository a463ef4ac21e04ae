#!/usr/bin/env python3
"""Installs the build into a temporary prefix and holds the documentation of what was
installed to what the programs say.

    check_man.py --build DIR --models BIN CASE        (CASE: pages | models)

pages:  every program in bin/ has a man page in share/man/man1 (a ".so" page followed)
        that renders without a warning and names exactly the options of the program's
        --help: an option added without documentation, or documented but gone, fails.
        Options are read from --help's option lines ("  -c, --config FILE ...") and from
        the page's .TP tags under OPTIONS (and, in a page of several programs, under the
        .SS of that program).
models: where a text names two or more models in one sentence (a list of models), it
        names every model of the core's table (BIN prints it): each installed program's
        --help, the Python, Lua and Java examples' --help, every installed man page, every
        installed .lcm file's comments. No --help prints a Lua table's address.
"""
import argparse
import glob
import os
import re
import subprocess
import sys
import tempfile

fails = 0


def check(cond, what):
    global fails
    print("%s: %s" % ("ok  " if cond else "FAIL", what), flush=True)
    fails += 0 if cond else 1
    return cond


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
    """.TP tags under .SH OPTIONS, or under .SS <prog> of any section."""
    opts, sh, ss = set(), "", None
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(".SH"):
            sh, ss = line[3:].strip().strip('"'), None
        elif line.startswith(".SS"):
            ss = line[3:].strip().strip('"')
        elif line.startswith(".TP") and i + 1 < len(lines):
            if (sh == "OPTIONS" and ss is None) or ss == prog:
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


def model_lists(text, models):
    """(sentence, names in it) for each sentence naming two or more models."""
    pat = re.compile(r"(?<![\w-])(%s)(?![\w-])" % "|".join(re.escape(m) for m in models), re.I)
    out = []
    for sentence in re.split(r"[.;:!?](?:\s|$)|\n\s*\n", text):
        names = {n.lower() for n in pat.findall(sentence)}
        if len(names) >= 2:
            out.append((" ".join(sentence.split())[:160], names))
    return out


def check_models(what, text, models):
    lists = model_lists(text, models)
    for sentence, names in lists:
        missing = [m for m in models if m not in names]
        check(not missing, "%s lists models and names all %d%s ('%s')" % (
            what, len(models), "; missing " + ", ".join(missing) if missing else "", sentence))
    return len(lists)


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
        # a --help's option lines are separate sentences
        text = re.sub(r"\n(?= {1,8}-)", ".\n", text)
        found += check_models(what, text, models)
    check(found >= 3, "lists of models found and checked: %d (lagsimd --help, lagsimd.1, scene_t.lcm)" % found)


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
    print("%s: %d failure(s)" % ("FAILED" if fails else "passed", fails))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
