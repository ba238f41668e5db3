#!/usr/bin/env python3
"""Finds import circles between the modules of each crate given.

A module depends on another when its code names it through `crate::…` or
`super::…` (a module naming one of its own ancestors does not count, and
`#[cfg(test)] mod tests` blocks are left out). Prints every circle (a
strongly connected set of modules) and exits 1 if there is one. With
`--floors ROOT...` it also checks those crates' floors (top-level modules)
for circles. CI runs it over every crate, and the core's floors:
`python3 scripts/import-circles.py crates/*/src python/src --floors crates/topovox/src`.
"""

import os
import re
import sys


def module_of(root, path):
    parts = os.path.relpath(path, root)[: -len(".rs")].split(os.sep)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def dependencies(root):
    files = [os.path.join(d, f) for d, _, fs in os.walk(root) for f in fs if f.endswith(".rs")]
    modules = {module_of(root, f): f for f in files}
    edges = {m: set() for m in modules}
    for m, path in modules.items():
        src = open(path, encoding="utf-8").read()
        src = re.split(r"#\[cfg\(test\)\]\s*mod tests", src)[0]
        src = re.sub(r"//.*", "", src)
        for base, rest in re.findall(r"\b(crate|super)((?:::\w+)+)", src):
            names = [p for p in rest.split("::") if p]
            # `super` of a module is its parent (for `x/mod.rs` and `x.rs` alike).
            target = names if base == "crate" else list(m[:-1]) + names
            for k in range(len(target), 0, -1):
                t = tuple(target[:k])
                if t in modules:
                    if t != m and m[: len(t)] != t:
                        edges[m].add(t)
                    break
    return edges


def circles(edges):
    """Tarjan's strongly connected components with more than one module."""
    index, low, on, stack, out = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
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
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in edges:
        if v not in index:
            visit(v)
    return out


def floors(edges):
    """The graph of a crate's floors: each module stands for its first path
    segment (a top-level module: `geom`, `grid`, `voxelize`, ...)."""
    out = {}
    for m, targets in edges.items():
        if not m:
            continue
        out.setdefault((m[0],), set())
        for t in targets:
            if t and t[0] != m[0]:
                out[(m[0],)].add((t[0],))
                out.setdefault((t[0],), set())
    return out


def main(argv):
    """`ROOT...` checks modules; `--floors ROOT...` after them checks the
    top-level modules of those crates too (no arrow runs back up a floor)."""
    split = argv.index("--floors") if "--floors" in argv else len(argv)
    found = False
    for root in argv[:split]:
        for c in circles(dependencies(root)):
            found = True
            print(f"{root}: import circle: " + " <-> ".join("::".join(m) or "(crate root)" for m in c))
    for root in argv[split + 1 :]:
        for c in circles(floors(dependencies(root))):
            found = True
            print(f"{root}: floors in a circle: " + " <-> ".join("::".join(m) for m in c))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
