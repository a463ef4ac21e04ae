#!/usr/bin/env python3
"""The MATLAB/Octave clients must run in MATLAB too: no GNU Octave-only syntax.

    matlab_syntax.py FILE.m ... [--readme README.md] [--snippets docs/clients.md]

GNU Octave accepts a superset of MATLAB's language; what it alone accepts fails in MATLAB,
and only GNU Octave runs in the tests. Flagged, outside strings and % comments: # comments,
!, !=, ++, --, +=, -=, *=, /=, the end keywords endfunction, endif, endwhile, endfor,
endswitch, end_try_catch, endclassdef, endmethods, endproperties, unwind_protect, double
quotes (MATLAB reads "..." as a string object, not a char vector), Octave-only functions
(printf, puts, fputs, fdisp, argv, program_name), and fflush or pkg unless the three lines
before test exist('OCTAVE_VERSION', 'builtin'). --readme also checks a Markdown file's
```matlab blocks, --snippets those of its blocks that are marked <!-- snippet: NAME -->
(programs run as written; the others may show MATLAB's command syntax, `f --opt`). Before the files, the checker runs on lines that must be flagged and
lines that must pass, so it cannot pass by checking nothing.
"""
import os
import re
import sys

END_WORDS = ("endfunction", "endif", "endwhile", "endfor", "endswitch", "end_try_catch",
             "endclassdef", "endmethods", "endproperties", "unwind_protect",
             "end_unwind_protect")
OCTAVE_FUNCS = ("printf", "puts", "fputs", "fdisp", "argv", "program_name")
GUARDED = ("fflush", "pkg")


def code_of(line):
    """The line without its strings (each '...' becomes '') and its % comment; None when a
    double quote starts a string."""
    out = []
    i = 0
    while i < len(line):
        c = line[i]
        if c == "%":
            break
        if c == '"':
            return None
        if c == "'":
            prev = line[:i].rstrip()[-1:] if line[:i].strip() else ""
            transpose = i > 0 and line[i - 1] not in " \t,;([{=" and \
                (prev.isalnum() or prev in "_)]}.'")
            if not transpose:
                j = i + 1
                while j < len(line):
                    if line[j] == "'" and j + 1 < len(line) and line[j + 1] == "'":
                        j += 2
                    elif line[j] == "'":
                        break
                    else:
                        j += 1
                out.append("''")
                i = j + 1
                continue
        out.append(c)
        i += 1
    return "".join(out)


def problems(lines):
    """(line number, what) for every Octave-only construct in lines."""
    found = []
    for n, line in enumerate(lines, 1):
        code = code_of(line)
        if code is None:
            found.append((n, "a double-quoted string"))
            continue
        if "#" in code:
            found.append((n, "# (MATLAB comments start with %)"))
        if re.search(r"!", code):
            found.append((n, "! or != (MATLAB: ~ and ~=)"))
        if re.search(r"\+\+|--|[-+*/]=", code.replace("==", "").replace("~=", "")
                     .replace("<=", "").replace(">=", "")):
            found.append((n, "++, --, +=, -=, *= or /="))
        for w in END_WORDS:
            if re.search(r"\b%s\b" % w, code):
                found.append((n, w))
        for f in OCTAVE_FUNCS:
            if re.search(r"(?<![\w.])%s\b" % f, code):
                found.append((n, "%s (GNU Octave only)" % f))
        for f in GUARDED:
            if re.search(r"(?<![\w.])%s\b" % f, code) and \
                    not any("OCTAVE_VERSION" in lines[k] for k in range(max(0, n - 4), n - 1)):
                found.append((n, "%s outside an exist('OCTAVE_VERSION', 'builtin') test" % f))
    return found


BAD = ["# a comment", "if a != b", "x++;", "x += 1;", "endfunction", "endif",
       "end_try_catch", "s = \"text\";", "printf('%d', 1);", "args = argv();",
       "fflush(stdout);", "pkg load control", "if !ok", "y = x'; # transpose, then a comment",
       "    endwhile"]
GOOD = ["% a comment with # and != and endif", "if a ~= b", "x = x + 1;", "end",
        "s = 'it''s # not a comment';", "fprintf('%d\\n', 1);", "y = x';  z = [x' y'];",
        "a = b'';", "if a <= b && c >= d || e == f", "u = u - K(k) * x(k);",
        "%#ok<AGROW>", "v = {'--prefix', '-q'};", "obj.values{k} = v;"]


def main():
    ok = True
    for line in BAD:
        if not problems([line]):
            print("FAIL: the checker misses Octave-only syntax in: %s" % line)
            ok = False
    for line in GOOD:
        if problems([line]):
            print("FAIL: the checker flags MATLAB syntax in: %s (%s)" % (line, problems([line])))
            ok = False
    guarded = ["if exist('OCTAVE_VERSION', 'builtin')", "    fflush(stdout);", "end"]
    if problems(guarded):
        print("FAIL: the checker flags a guarded fflush")
        ok = False
    args = sys.argv[1:]
    files = []
    while args:
        a = args.pop(0)
        if a in ("--readme", "--snippets"):
            path = args.pop(0)
            text = open(path).read()
            marked = r"<!-- snippet: \S+ -->\s*\n" if a == "--snippets" else ""
            for k, m in enumerate(re.finditer(marked + r"```matlab\n(.*?)```", text, re.S)):
                files.append(("%s block %d" % (os.path.basename(path), k + 1),
                              m.group(1).splitlines()))
        else:
            files.append((a, open(a).read().splitlines()))
    if not files:
        print("FAIL: nothing to check")
        return 1
    for name, lines in files:
        for n, what in problems(lines):
            print("FAIL: %s:%d: %s" % (name, n, what))
            ok = False
    print("%s: %d files, %d lines checked" % ("ok  " if ok else "FAIL", len(files),
                                              sum(len(l) for _, l in files)))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
