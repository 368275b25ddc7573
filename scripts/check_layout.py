#!/usr/bin/env python3
"""check_layout.py - the source tree's layout rules, checked (issue 31).

A folder is one job (core/contact, proto/result, server/http, ...). Files
in one folder may lean on each other freely; between folders, dependencies
must run one way: no circle of folders. Two graphs are checked, because
either alone can miss a circle:

  includes  folder A -> folder B when a file of A includes a header of B
            (quoted includes, resolved as the compiler does: the file's own
            folder first, then the -I roots core/, proto/, server/);
  calls     folder A -> folder B when an object of A uses a symbol that an
            object of B defines (nm over the built objects, when a build
            folder is given and holds them), which also catches a function
            declared by hand instead of through its folder's header.

Prints each circle with the includes or symbols that close it and exits 1
when there is one; lists files past the ~800-line mark without failing.

    check_layout.py [--objects build]
    check_layout.py --self-test   (shows that a circle is found, and only then)
"""
import argparse
import os
import re
import subprocess
import sys

ROOTS = ("core", "proto", "server", "runner")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
LONG_FILE = 800


def sources(top):
    for root in ROOTS:
        for d, _, names in os.walk(os.path.join(top, root)):
            for n in sorted(names):
                if n.endswith((".c", ".h")):
                    yield os.path.relpath(os.path.join(d, n), top)


def resolve(top, src, name):
    for base in [os.path.dirname(src)] + list(ROOTS):
        p = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(os.path.join(top, p)):
            return p
    return None


def include_edges(top):
    edges = {}
    for src in sources(top):
        with open(os.path.join(top, src), encoding="utf-8") as f:
            text = f.read()
        for name in INCLUDE.findall(text):
            dst = resolve(top, src, name)
            if dst is None or not dst.startswith(ROOTS):
                continue
            a, b = os.path.dirname(src), os.path.dirname(dst)
            if a != b:
                edges.setdefault((a, b), []).append(f"{src} includes {dst}")
    return edges


def call_edges(top, build):
    defined, used = {}, {}
    for root in ROOTS:
        for d, _, names in os.walk(os.path.join(build, root)):
            for n in names:
                if not n.endswith(".o"):
                    continue
                obj = os.path.join(d, n)
                folder = os.path.dirname(os.path.relpath(obj, build))
                out = subprocess.run(["nm", obj], capture_output=True, text=True,
                                     check=True).stdout
                for line in out.splitlines():
                    p = line.split()
                    if len(p) == 3 and p[1] in "TDBRC":
                        defined[p[2]] = (folder, os.path.relpath(obj, build))
                    elif len(p) == 2 and p[0] == "U":
                        used.setdefault(p[1], []).append((folder, os.path.relpath(obj, build)))
    edges = {}
    for sym, users in used.items():
        if sym not in defined:
            continue
        b, where = defined[sym]
        for a, obj in users:
            if a != b:
                edges.setdefault((a, b), []).append(f"{obj} uses {sym} ({where})")
    return edges


def circles(edges):
    """Strongly connected components of more than one folder (Tarjan)."""
    graph = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)
        graph.setdefault(b, set())
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
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
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def report(kind, edges):
    bad = circles(edges)
    for comp in bad:
        print(f"circle of folders through their {kind}: {' -> '.join(comp)}")
        members = set(comp)
        for (a, b), why in sorted(edges.items()):
            if a in members and b in members:
                print(f"  {a} -> {b}: {why[0]}" + (f" (and {len(why) - 1} more)" if len(why) > 1 else ""))
    return not bad


def self_test():
    """A tree with a circle of two folders must fail, the same tree without
    the include that closes it must pass: the check can fail."""
    import contextlib
    import io
    import tempfile
    ok = True
    for closed in (True, False):
        with tempfile.TemporaryDirectory() as top:
            for folder, text in (("a", '#include "b/b.h"\n'),
                                 ("b", '#include "a/a.h"\n' if closed else "")):
                os.makedirs(os.path.join(top, "core", folder))
                with open(os.path.join(top, "core", folder, folder + ".h"), "w") as f:
                    f.write("")
                with open(os.path.join(top, "core", folder, folder + ".c"), "w") as f:
                    f.write(text)
            with contextlib.redirect_stdout(io.StringIO()):
                passed = report("includes", include_edges(top))
            ok = ok and passed == (not closed)
    print(("PASS" if ok else "FAIL") + " layout_check_finds_a_circle_and_only_a_circle")
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", help="build folder whose objects to read with nm")
    ap.add_argument("--top", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--self-test", action="store_true", help=self_test.__doc__.split("\n")[0])
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    ok = report("includes", include_edges(args.top))
    if args.objects and os.path.isdir(os.path.join(args.objects, "core")):
        ok = report("calls", call_edges(args.top, args.objects)) and ok
    for src in sources(args.top):
        with open(os.path.join(args.top, src), encoding="utf-8") as f:
            n = sum(1 for _ in f)
        if n > LONG_FILE:
            print(f"note: {src} has {n} lines (split by job past ~{LONG_FILE})")
    print(("PASS" if ok else "FAIL") + " layout: no circle of folders in core/, proto/, server/")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
