#!/usr/bin/env python3
"""The daemon's files stand on floors: no circle between server/daemon/*.c.

Reads the #include "..." lines and the function calls of every file in server/daemon
and draws a graph of files: A -> B when A calls a function B defines, or includes B's
header (X.h belongs to X.c; a header's includes count as its owner's). Fails when

  - the graph has a circle (a lower file calling, or including, a file above it), or
  - a file other than the loop's (realtime.c) includes the loop's header (rt_server.h),
    directly or through another header.

Prints the floors (0: calls no other daemon file) and, on failure, each circle with the
calls and includes that make it.

Usage: daemon_floors.py DIR   (DIR: server/daemon)
"""
import os
import re
import sys

LOOP_C, LOOP_H = "realtime.c", "rt_server.h"


def strip(text):
    """The C text without comments, strings and character literals."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    text = re.sub(r'"(?:\\.|[^"\\\n])*"', '""', text)
    return re.sub(r"'(?:\\.|[^'\\\n])*'", "''", text)


DEF = re.compile(r"^(?!static\b|typedef\b|extern\b|#)[A-Za-z_][\w \t\*]*?\b([A-Za-z_]\w*)"
                 r"\s*\([^;{}]*\)\s*\{", re.M)
CALL = re.compile(r"\b([A-Za-z_]\w*)\s*\(")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def main(d):
    files = sorted(f for f in os.listdir(d) if f.endswith((".c", ".h")))
    raw = {f: open(os.path.join(d, f), encoding="utf-8").read() for f in files}
    text = {f: strip(t) for f, t in raw.items()}
    sources = [f for f in files if f.endswith(".c")]
    owner = {f: f[:-2] + ".c" for f in files if f.endswith(".h") and f[:-2] + ".c" in sources}
    if LOOP_H in files and LOOP_C in sources:
        owner[LOOP_H] = LOOP_C
    defined = {}
    for f in sources:
        for m in DEF.finditer(text[f]):
            defined.setdefault(m.group(1), f)
    edges = {f: {} for f in sources}  # A -> {B: [why, ...]}

    def add(a, b, why):
        if a != b and a in edges and why not in edges[a].get(b, []):
            edges[a].setdefault(b, []).append(why)

    for f in sources:
        for name in sorted(set(CALL.findall(text[f]))):
            if name not in defined:
                continue
            add(f, defined[name], "calls " + name)

    def includes(f):
        return [h for h in INCLUDE.findall(raw[f]) if h in raw]

    bad = []
    for f in files:
        # what f includes, directly or through headers
        seen, todo = set(), includes(f)
        while todo:
            h = todo.pop()
            if h in seen:
                continue
            seen.add(h)
            todo += includes(h)
            src = owner.get(f, f) if f.endswith(".h") else f
            if h in owner and src.endswith(".c"):
                add(src, owner[h], "includes " + h)
        if LOOP_H in seen and f not in (LOOP_C, LOOP_H):
            bad.append("%s includes the loop's header %s" % (f, LOOP_H))

    # circles: strongly connected components (Tarjan)
    index, low, stack, on, sccs, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            sccs.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sources:
        if v not in index:
            visit(v)
    for comp in sccs:
        if len(comp) > 1:
            lines = ["a circle between %s:" % ", ".join(comp)]
            for a in comp:
                for b in comp:
                    if b in edges[a]:
                        lines.append("  %s -> %s (%s)" % (a, b, "; ".join(edges[a][b])))
            bad.append("\n".join(lines))

    # the floors (meaningful without circles): 0 calls no other daemon file
    floor = {}

    def level(v, path=()):
        if v in floor:
            return floor[v]
        if v in path:
            return 0
        floor[v] = 1 + max([level(w, path + (v,)) for w in edges[v]] or [-1])
        return floor[v]

    for v in sources:
        level(v)
    for k in range(max(floor.values()) + 1):
        on_k = [v for v in sources if floor[v] == k]
        print("floor %d: %s" % (k, " ".join(on_k)))
    if bad:
        print("\nFAIL: the daemon's files do not stand on floors:\n" + "\n".join(bad))
        return 1
    print("ok: no circle; only %s includes %s" % (LOOP_C, LOOP_H))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "server/daemon"))
