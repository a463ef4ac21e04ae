#!/usr/bin/env python3
"""The project's structure rules, each a ctest of its own (label structure):

  check_structure.py harness SOURCE_DIR
      Every C test program uses the one harness (tests/common/lagsim_test.h): no file under
      tests/ but tests/common/ defines a check macro (ENSURE*, CHECK*, EXPECT*, ASSERT*,
      REQUIRE*, LT_*) or a file-scope check/failure counter; every test program
      (tests/**/test_*.c, tests/**/*_test.c) runs its cases through lt_main or lt_run, and
      none dispatches them through a strcmp chain. The Python tests have theirs
      (tests/common/lagsim_check.py): no .py file under tests/ but tests/common/ defines a
      check() of its own.
  check_structure.py names BUILD_DIR [--ctest CTEST | --json FILE]
      Every ctest's name is lowercase words joined by "_" (a word may hold a "-": a model's
      name such as flying-stick, a number such as -1 or 1e-04; never a "." or a capital),
      every ctest has a label, and exactly one tier (a label of LAGSIM_TIERS,
      tests/common/tiers.cmake, given by the rules there) with that tier's share of a core
      as its PROCESSORS; every tier has a row of LAGSIM_TIER_RUN, and every row a tier.
  check_structure.py docs SOURCE_DIR BUILD_DIR [--ctest CTEST | --json FILE]
      Every test name the docs (README.md, docs/**/*.md) give in backquotes is a ctest
      (`a_{b,c}` is two names, `a_*` must match one, `_b` after `a_x` is a_b, `a` alone the
      family of the ctests a_*; a dotted word is a key, not a name); the tier table of
      docs/testing.md has exactly the tiers of tests/common/tiers.cmake, its label table
      exactly the other labels the ctests carry; and every file a doc or a source file's
      comment names exists (check_named_files).
  check_structure.py function_length SOURCE_DIR [--max 80]
      No C function in server/, clients/, bench/ (nor C++ function in clients/) is longer than 80 lines (universal-ctags:
      from the line of its name to the line of its closing brace).
  check_structure.py ticks SOURCE_DIR
      Time to ticks is converted by the core alone (lag_ticks_ceil / _floor / _exact,
      lagsim.h, one tolerance LAG_TICK_TOL): no C file in server/ (but server/core/),
      clients/, bench/ rounds a time divided by a dt (llround, lround, ceil, floor, round,
      trunc, rint, or an integer cast of x + 0.5, on `t / dt`, `t / sc->sim.integrator.dt`,
      or on a variable set from one a few lines before) or keeps a tolerance of its own in
      ticks (`1e-9 * dt`). A few files wait or keep a rule of their own (TICKS_EXEMPT):
      the check fails when one no longer needs its exemption, so the list only shrinks.

Each prints what breaks the rule, one line each, and exits 1 then; 0 when nothing does.
"""
import argparse
import fnmatch
import json
import os
import re
import subprocess
import sys

# ---------------------------------------------------------------- harness

MACRO = re.compile(r'^\s*#\s*define\s+((?:ENSURE|CHECK|EXPECT|ASSERT|REQUIRE|LT_)\w*)', re.M)
COUNTER = re.compile(r'^static\s+(?:volatile\s+)?(?:unsigned\s+)?(?:int|long|size_t|int64_t)\s+'
                     r'[^;(]*\b(?:g_)?(?:n_?)?(?:checks|failures|fails|failed|errors)\b[^;(]*;', re.M)
# a case chosen by comparing a name: `if (!strcmp(g_case, "file")) case_file();`
CHAIN = re.compile(r'\bstrcmp\s*\([^;{}()]*(?:\([^;{}()]*\)[^;{}()]*)*\)\s*(?:==\s*0\s*)?\)\s*'
                   r'\{?\s*(?:case|test|check|run)_\w+\s*\(')


PY_CHECK = re.compile(r'^[ \t]*def[ \t]+check[ \t]*\(', re.M)


def c_files(root, sub, endings=('.c', '.h')):
    for dirpath, _, names in os.walk(os.path.join(root, sub)):
        for n in sorted(names):
            if n.endswith(endings):
                yield os.path.join(dirpath, n)


def check_harness(src):
    bad = []
    common = os.path.join(src, 'tests', 'common') + os.sep
    for path in c_files(src, 'tests'):
        rel = os.path.relpath(path, src)
        if path.startswith(common):
            continue
        text = open(path, encoding='utf-8', errors='replace').read()
        for m in MACRO.finditer(text):
            line = text.count('\n', 0, m.start()) + 1
            bad.append(f'{rel}:{line}: defines {m.group(1)}: use tests/common/lagsim_test.h')
        for m in COUNTER.finditer(text):
            line = text.count('\n', 0, m.start()) + 1
            bad.append(f'{rel}:{line}: a counter of its own ({m.group(0).strip()}): '
                       'the harness counts checks')
        base = os.path.basename(path)
        if base.endswith('.c') and (base.startswith('test_') or base.endswith('_test.c')):
            if not re.search(r'\blt_(main|run)\s*\(', text):
                bad.append(f'{rel}: a test program that does not run its cases through '
                           'lt_main or lt_run')
            for m in CHAIN.finditer(text):
                line = text.count('\n', 0, m.start()) + 1
                bad.append(f'{rel}:{line}: dispatches through a strcmp chain: list the cases '
                           'in an lt_case table')
    for path in c_files(src, 'tests', ('.py',)):
        if path.startswith(common):
            continue
        text = open(path, encoding='utf-8', errors='replace').read()
        for m in PY_CHECK.finditer(text):
            line = text.count('\n', 0, m.start()) + 1
            bad.append(f'{os.path.relpath(path, src)}:{line}: defines check() of its own: use '
                       'tests/common/lagsim_check.py')
    return bad

# ---------------------------------------------------------------- names


NAME = re.compile(r'^[a-z][a-z0-9]*(_-?[a-z0-9]+(-[a-z0-9]+)*)+$')


def load_tests(build, ctest, json_file):
    """[(name, labels)] of every ctest, and {name: PROCESSORS} of those that have it."""
    if json_file:
        text = open(json_file).read()
    else:
        text = subprocess.run([ctest, '--show-only=json-v1'], cwd=build, check=True,
                              capture_output=True, text=True).stdout
    tests, shares = [], {}
    for t in json.loads(text)['tests']:
        labels = []
        for p in t.get('properties', []):
            if p['name'] == 'LABELS':
                labels = p['value']
            if p['name'] == 'PROCESSORS':
                shares[t['name']] = p['value']
        tests.append((t['name'], labels))
    return tests, shares


def load_tiers(path):
    """The tiers tests/common/tiers.cmake defines (set(LAGSIM_TIERS ...)), and the share
    of a core its table of how they run gives each ({tier: share}, LAGSIM_TIER_RUN)."""
    text = open(path, encoding='utf-8').read()
    m = re.search(r'set\(LAGSIM_TIERS\s+([a-z_\s]+)\)', text)
    tiers = m.group(1).split() if m else []
    run = re.search(r'set\(LAGSIM_TIER_RUN\s+(.*?)\n\)', text, re.S)
    rows = re.findall(r'"([a-z_]+) +([0-9]+) +[0-9]+"', run.group(1)) if run else []
    return tiers, {t: int(share) for t, share in rows}


def check_names(loaded, tiers_rows):
    (tests, shares), (tiers, rows) = loaded, tiers_rows
    bad = []
    if not tiers:
        bad.append('tests/common/tiers.cmake: no set(LAGSIM_TIERS ...)')
    for name, labels in tests:
        if not NAME.match(name):
            bad.append(f'{name}: not lowercase words joined by "_" (no ".", no capital, '
                       'no empty word)')
        if not labels:
            bad.append(f'{name}: no label')
        has = [l for l in labels if l in tiers]
        if tiers and not has:
            bad.append(f'{name}: no tier (none of {" ".join(tiers)}): no rule of '
                       'tests/common/tiers.cmake matches it; add one')
        elif len(has) > 1:
            bad.append(f'{name}: more than one tier ({" ".join(has)})')
        elif has and shares.get(name) != rows.get(has[0]):
            bad.append(f'{name}: PROCESSORS {shares.get(name)}, not its tier\'s share '
                       f'({has[0]}: {rows.get(has[0])}, LAGSIM_TIER_RUN in '
                       'tests/common/tiers.cmake)')
    for t in tiers:
        if t not in rows:
            bad.append(f'tests/common/tiers.cmake: the tier {t} has no row in LAGSIM_TIER_RUN')
    for t in rows:
        if t not in tiers:
            bad.append(f'tests/common/tiers.cmake: LAGSIM_TIER_RUN has a row for {t}, '
                       'which is no tier of LAGSIM_TIERS')
    if not tests:
        bad.append('no ctest at all')
    return bad

# ---------------------------------------------------------------- docs


def expand_braces(tok):
    m = re.search(r'\{([^{}]*)\}', tok)
    if not m:
        return [tok]
    out = []
    for alt in m.group(1).split(','):
        out += expand_braces(tok[:m.start()] + alt + tok[m.end():])
    return out


def source_words(src):
    """Every word of the sources (not the docs): a program, a function, an event kind that
    looks like a test name is one of these and not a test reference."""
    words = set()
    for top in ('server', 'clients', 'bench', 'tests', 'lcmtypes', 'config', 'cmake'):
        for dirpath, dirs, names in os.walk(os.path.join(src, top)):
            dirs[:] = [d for d in dirs if d not in ('corpus', 'crash')]
            for n in names:
                if not n.endswith(('.c', '.h', '.cpp', '.hpp', '.py', '.lua', '.java', '.m', '.sh', '.lcm',
                                   '.cmake', '.txt', '.yaml', '.html', '.js')):
                    continue
                try:
                    text = open(os.path.join(dirpath, n), encoding='utf-8',
                                errors='replace').read()
                except OSError:
                    continue
                words.update(re.findall(r'[A-Za-z0-9_]+', text))
    words.update(re.findall(r'[A-Za-z0-9_]+', open(os.path.join(src, 'CMakeLists.txt')).read()))
    return words


def doc_files(src):
    yield os.path.join(src, 'README.md')
    for dirpath, _, names in os.walk(os.path.join(src, 'docs')):
        for n in sorted(names):
            if n.endswith('.md'):
                yield os.path.join(dirpath, n)


def check_docs(src, tests, absent=()):
    """absent: globs of the tests this build does not define although the docs name them
    (the Go controllers' without go or in a sanitizer build: tests/structure.cmake)."""
    bad = []
    names = {n for n, _ in tests}
    areas = {re.split(r'[_.]', n)[0] for n in names}
    words = source_words(src)
    token_re = re.compile(r'^[a-z][a-z0-9_.*{},-]*$')

    def exists(pattern):
        if any(fnmatch.fnmatchcase(pattern.replace('*', 'x'), g) for g in absent):
            return True
        if '*' in pattern:
            return any(fnmatch.fnmatchcase(n, pattern) for n in names)
        return pattern in names

    for path in doc_files(src):
        rel = os.path.relpath(path, src)
        for lineno, line in enumerate(open(path, encoding='utf-8'), 1):
            prev = None  # the last full test name of this line, for `_suffix` continuations
            for span in re.findall(r'`([^`\n]+)`', line):
                for tok in re.split(r'[\s,;()]+(?![^{]*\})', span):
                    tok = tok.strip('.:')
                    if tok.startswith('_') and prev and re.match(r'^_[a-z0-9_-]+$', tok):
                        parts = prev.split('_')
                        if not any(exists('_'.join(parts[:k]) + tok)
                                   for k in range(1, len(parts))):
                            bad.append(f'{rel}:{lineno}: `{tok}` (after {prev}) names no ctest')
                        continue
                    if not token_re.match(tok) or re.search(r'\.(c|h|py|md|yaml|lcm|sh|cmake|'
                                                            r'txt|csv|json|png|svg|java|lua|m|'
                                                            r'html|js)$', tok):
                        continue
                    area = tok.split('_')[0]
                    # a dotted word is a scene key or a path (structure_names keeps "." out
                    # of test names)
                    if area not in areas or '.' in tok or '_' not in tok:
                        continue
                    if tok in words:  # a program, a function, an event kind
                        continue
                    for name in expand_braces(tok):
                        if exists(name) or exists(name + '_*'):  # a test or a family
                            if '*' not in name:
                                prev = name
                        elif name not in words:
                            bad.append(f'{rel}:{lineno}: `{name}` names no ctest')
    # docs/testing.md's tier table against tests/common/tiers.cmake, its label table against
    # the other labels the ctests carry
    tiers, _ = load_tiers(os.path.join(src, 'tests', 'common', 'tiers.cmake'))
    tier_table = doc_table(src, 'tier')
    for t in tiers:
        if t not in tier_table:
            bad.append(f'docs/testing.md: the tier {t} has no row in the tier table')
    for t in sorted(tier_table - set(tiers)):
        bad.append(f'docs/testing.md: the tier table names {t}, which tests/common/tiers.cmake '
                   'does not define')
    labels = {l for _, ls in tests for l in ls} - set(tiers)
    table = doc_table(src, 'label')
    for l in sorted(labels - table):
        bad.append(f'docs/testing.md: the label {l} has no row in the label table')
    # a label of another build (bench off, fuzzing on, root's package tests) is declared in
    # the tests' CMake files though no ctest of this build carries it
    for l in sorted(table - labels - declared_labels(src)):
        bad.append(f'docs/testing.md: the label table names {l}, which no ctest carries')
    return bad + check_named_files(src)


# ---------------------------------------------------------------- files named

# Where a file is named: the tree's own directories (a path is read from one of these on)
TREE_TOPS = ('server', 'clients', 'bench', 'tests', 'docs', 'config', 'lcmtypes', 'cmake',
             '.ci')
PATH_RE = re.compile(r'(?<![\w./<>{}$@-])((?:' + '|'.join(re.escape(t) for t in TREE_TOPS) +
                     r')/[A-Za-z0-9_./@+-]*[A-Za-z0-9_/@+-])')
# a bare file name in a comment, of the kinds the tree is made of
BARE_RE = re.compile(r'(?<![\w./@<>{}$*-])([A-Za-z0-9_@+-]+\.(?:c|h|py|sh|cmake|lua|java))'
                     r'(?![\w./(@-])')
LINK_RE = re.compile(r'\]\(([^)\s#]+)(?:#[^)\s]*)?\)')
# Files not in the tree that a comment may name by their bare name (what they are): other
# projects' files, a user's files that a doc's recipe writes.
FOREIGN_FILES = {
    'balance.py': "the controller docs/clients.md's walkthrough has its reader write",
    'lcm_udpm.c': "LCM's UDP multicast provider (the URL grammar lagsim_url.h makes strict)",
    'lcmgen.c': "lcm-gen's source (the type fingerprint)",
    'complex.h': "the C library's header",
    'ae.c': "redis's event loop (the daemon's loop takes it for a model)",
    'extra.c': "an example argument in lagsim_fuzz_target's usage",
}
COMMENT_RE = {
    ('.c', '.h', '.java', '.js'): re.compile(r'/\*.*?\*/|//[^\n]*', re.S),
    ('.py', '.sh', '.cmake', '.txt', '.yaml', '.gp', '.in'): re.compile(r'#[^\n]*'),
    ('.lua',): re.compile(r'--[^\n]*'),
    ('.m',): re.compile(r'%[^\n]*'),
}


def tree_files(src):
    """{relative path} of the tree's own files (the directories TREE_TOPS and README.md)."""
    out = {'README.md', 'CMakeLists.txt'}
    for top in TREE_TOPS:
        for dirpath, dirs, names in os.walk(os.path.join(src, top)):
            out.add(os.path.relpath(dirpath, src))
            out.update(os.path.relpath(os.path.join(dirpath, n), src) for n in names)
    return out


def named_paths(rel, text):
    """(line, path, is_bare) of each file a doc (every line) or a source file (its comments)
    names."""
    ext = os.path.splitext(rel)[1]
    if os.path.basename(rel) == 'CMakeLists.txt':
        ext = '.cmake'
    if ext == '.md':
        spans = [(0, text)]
    else:
        rx = next((r for exts, r in COMMENT_RE.items() if ext in exts), None)
        spans = [(m.start(), m.group(0)) for m in rx.finditer(text)] if rx else []
    for start, span in spans:
        for m in PATH_RE.finditer(span):
            after = span[m.end():m.end() + 2]
            if after[:1] in ('<', '*', '{', '$') or after == '.{':
                continue  # a pattern: tests/fuzz/<name>/corpus, docs/*.md, a.{c,h}
            path = m.group(1).rstrip('.')
            if re.search(r'(^|/)[A-Z][A-Z0-9_]*(\.|/|$)', path):
                continue  # a placeholder: config/NAME.yaml
            yield text.count('\n', 0, start + m.start()) + 1, path, False
        if ext == '.md':
            for m in LINK_RE.finditer(span):
                target = m.group(1)
                if re.match(r'^[a-z]+:', target):
                    continue  # https:, mailto:
                path = os.path.normpath(os.path.join(os.path.dirname(rel), target))
                yield text.count('\n', 0, start + m.start()) + 1, path, False
        else:
            for m in BARE_RE.finditer(span):
                name = m.group(1)
                if re.match(r'^[A-Z][A-Z0-9_]*\.', name) or name in FOREIGN_FILES:
                    continue
                yield text.count('\n', 0, start + m.start()) + 1, name, True


def check_named_files(src):
    """A file named in a doc or in a source file's comment exists: a path from one of the
    tree's directories (server/daemon/rt_pace.c, docs/server.md, tests/net/), a link of a
    page, or a bare file name of a kind the tree is made of (rhs.c, exit_docs.py) in a
    comment, which must be some file's name."""
    have = tree_files(src)
    bases = {os.path.basename(f) for f in have}
    bad = []
    readers = ['README.md'] + sorted(f for f in have if f.endswith('.md') and
                                     f.startswith('docs' + os.sep))
    readers += sorted(f for f in have if f.split(os.sep)[0] in TREE_TOPS[:4] + ('cmake', '.ci',
                                                                              'lcmtypes')
                      and not f.endswith('.md') and '/corpus/' not in f and '/crash/' not in f
                      and os.path.isfile(os.path.join(src, f)))
    for rel in readers:
        try:
            text = open(os.path.join(src, rel), encoding='utf-8').read()
        except (OSError, UnicodeDecodeError):
            continue
        for line, path, bare in named_paths(rel, text):
            if bare:
                if path not in bases:
                    bad.append(f'{rel}:{line}: names {path}, which is no file of the tree')
                continue
            p = path.rstrip('/')
            # a module named without its extension (server/wire/lagsim_bus: .c and .h)
            if p in have or any(f.startswith(p + '.') for f in have):
                continue
            bad.append(f'{rel}:{line}: names {path}, which does not exist')
    return bad


def doc_table(src, head):
    """The first column's names of docs/testing.md's table headed `| HEAD |`."""
    table = set()
    in_table = False
    for line in open(os.path.join(src, 'docs', 'testing.md'), encoding='utf-8'):
        if re.match(r'^\| ' + head + r' \|', line):
            in_table = True
            continue
        if in_table:
            if not line.startswith('|'):
                break
            m = re.match(r'^\| `([a-z_]+)` \|', line)
            if m:
                table.add(m.group(1))
    return table


def declared_labels(src):
    """The labels the CMake files of tests/ and bench/ give (LABELS words, and the label
    argument of lagsim_add_test_cases), whatever this build turns on."""
    out = set()
    paths = [os.path.join(src, 'bench', 'CMakeLists.txt')]
    for dirpath, _, names in os.walk(os.path.join(src, 'tests')):
        paths += [os.path.join(dirpath, n) for n in names
                  if n.endswith('.cmake') or n == 'CMakeLists.txt']
    for path in paths:
        if not os.path.exists(path):
            continue
        text = open(path, encoding='utf-8').read()
        for m in re.finditer(r'LABELS\s+"?([a-z_;]+)"?', text):
            out.update(m.group(1).split(';'))
        for m in re.finditer(r'lagsim_add_test_cases\(\s*\S+\s+\S+\s+([a-z_]+)', text):
            out.add(m.group(1))
    return out

# ---------------------------------------------------------------- functions


def check_function_length(src, limit):
    files = []
    for top in ('server', 'clients', 'bench'):
        files += [f for f in c_files(src, top)]
    cxx = []  # the C++ of clients/ (lagsim_client.hpp, the C++ example) too
    for dirpath, _, names in os.walk(os.path.join(src, 'clients')):
        cxx += [os.path.join(dirpath, n) for n in sorted(names) if n.endswith(('.cpp', '.hpp'))]
    try:
        out = subprocess.run(['ctags', '-x', '--c-kinds=f', '--_xformat=%N %F %n %e'] + files,
                             check=True, capture_output=True, text=True).stdout
        if cxx:
            out += subprocess.run(['ctags', '-x', '--c++-kinds=f', '--_xformat=%N %F %n %e'] + cxx,
                                  check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        return [f'universal-ctags did not run ({e}): install universal-ctags '
                '(.ci/install-deps.sh)']
    bad = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) != 4 or not parts[3].isdigit():
            continue
        name, path, start, end = parts[0], parts[1], int(parts[2]), int(parts[3])
        n = end - start + 1
        if n > limit:
            bad.append((n, f'{os.path.relpath(path, src)}:{start}: {name} has {n} lines '
                           f'(at most {limit})'))
    return [b for _, b in sorted(bad, reverse=True)]

# ---------------------------------------------------------------- ticks

# (file, why): files that still convert by hand.
TICKS_EXEMPT = {
    # a run's length (--duration) in ticks: a guard that grows with the count
    # (x (1 - 1e-12) - 1e-9); the core's fixed LAG_TICK_TOL gives one tick more where the
    # rounding of t / dt passes 1e-9 ticks (18.0405 s at dt 1 us: 18040501 ticks)
    'server/daemon/rt_pace.c': 'rt_ticks_for: a tolerance that grows with the count',
    # the loader's period check accepts |r - k| <= 1e-9 r, more than lag_ticks_exact's
    # 1e-9 for r > 1: switching would refuse periods it accepts
    'server/scene/scene_schema.c': 'check_period: a tolerance that grows with the count',
    # files under another change at the time of writing
    'server/accuracy/cost.c': 'the cost table\'s period in ticks',
    'bench/bench_common.c': 'the benchmarks\' period in ticks',
    'bench/accuracy_choice.c': 'the period in ticks',
    'bench/peer_mujoco.c': 'the period in ticks',
    'bench/peer_sundials.c': 'the period in ticks',
}

ROUND = r'\b(?:llround|lround|llrint|lrint|ceil|floor|round|trunc|rint|nearbyint)\s*\('
CAST = r'\(\s*(?:int64_t|int|long|long\s+long|size_t|uint64_t)\s*\)\s*\('
BY_DT = r'/\s*(?:\(\s*double\s*\)\s*)?(?:[A-Za-z_]\w*(?:->|\.))*dt\b'
TICKS_DIRECT = re.compile(ROUND + r'[^;]*?' + BY_DT + r'|' + CAST + r'[^;]*?' + BY_DT +
                          r'[^;]*?\+\s*0\.5\s*\)')
TICKS_TOL = re.compile(r'\b(?:1e-9|1e-12|LAG_TICK_TOL)\s*\*\s*(?:[A-Za-z_]\w*(?:->|\.))*dt\b')
TICKS_SET = re.compile(r'\b([A-Za-z_]\w*)\s*=(?!=)[^;]*?' + BY_DT + r'[^;]*;')
TICKS_NEAR = 20  # lines after the assignment in which rounding the variable counts


def c_code(text):
    """The C text with comments blanked and string literals emptied (lines kept)."""
    text = re.sub(r'/\*.*?\*/', lambda m: '\n' * m.group(0).count('\n') + ' ', text, flags=re.S)
    text = re.sub(r'//[^\n]*', ' ', text)
    return re.sub(r'"(?:\\.|[^"\\\n])*"', '""', text)


def ticks_findings(src):
    """{file: [line, ...]} of hand conversions of a time to ticks outside server/core."""
    out = {}
    core = os.path.join('server', 'core') + os.sep
    for top in ('server', 'clients', 'bench'):
        for path in c_files(src, top):
            rel = os.path.relpath(path, src)
            if rel.startswith(core):
                continue
            code = c_code(open(path, encoding='utf-8', errors='replace').read())
            lines = set()
            for rx in (TICKS_DIRECT, TICKS_TOL):
                lines |= {code.count('\n', 0, m.start()) + 1 for m in rx.finditer(code)}
            for m in TICKS_SET.finditer(code):
                var = re.escape(m.group(1))
                start = code.count('\n', 0, m.start()) + 1
                after = code[m.end():]
                near = '\n'.join(after.split('\n')[:TICKS_NEAR])
                rounded = re.search(ROUND + r'[^;]*?\b' + var + r'\b|' + CAST + r'\s*' + var +
                                    r'\s*\+\s*0\.5\s*\)', near)
                if rounded:
                    lines.add(start)
            if lines:
                out[rel] = sorted(lines)
    return out


def check_ticks(src):
    bad = []
    found = ticks_findings(src)
    for rel, lines in sorted(found.items()):
        if rel in TICKS_EXEMPT:
            continue
        for ln in lines:
            bad.append(f'{rel}:{ln}: converts a time to ticks by hand: call lag_ticks_ceil, '
                       'lag_ticks_floor or lag_ticks_exact (lagsim.h)')
    for rel in sorted(TICKS_EXEMPT):
        if rel not in found:
            bad.append(f'{rel}: exempt from the ticks check but no longer needs it: drop it '
                       'from TICKS_EXEMPT in tests/structure/check_structure.py')
    return bad

# ---------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('rule', choices=['harness', 'names', 'docs', 'function_length', 'ticks'])
    ap.add_argument('dirs', nargs='+', help='SOURCE_DIR and/or BUILD_DIR (see above)')
    ap.add_argument('--ctest', default='ctest')
    ap.add_argument('--json', help="ctest --show-only=json-v1's output, instead of running it")
    ap.add_argument('--max', type=int, default=80)
    ap.add_argument('--absent', action='append', default=[],
                    help='docs: a glob of tests this build does not define (say why in CMake)')
    ap.add_argument('--tiers', default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                    '..', 'common', 'tiers.cmake'),
                    help="the tiers' table (names: tests/common/tiers.cmake)")
    a = ap.parse_args()
    if a.rule == 'harness':
        bad = check_harness(a.dirs[0])
    elif a.rule == 'names':
        bad = check_names(load_tests(a.dirs[0], a.ctest, a.json), load_tiers(a.tiers))
    elif a.rule == 'docs':
        bad = check_docs(a.dirs[0], load_tests(a.dirs[1], a.ctest, a.json)[0], a.absent)
    elif a.rule == 'ticks':
        bad = check_ticks(a.dirs[0])
    else:
        bad = check_function_length(a.dirs[0], a.max)
    for b in bad:
        print(b)
    print(f'{a.rule}: {len(bad)} breaking the rule')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
