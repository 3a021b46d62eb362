#!/usr/bin/env python3
"""Lists the import circles between the modules of each crate in the workspace.

A module is a file under `src/` (a `mod.rs` names its folder). Module A imports module B
when A's text names `crate::B...` (in a `use` or in a path) or, inside the same parent,
`super::B`. Tests (`tests.rs`, `*_tests.rs`, `#[cfg(test)] mod tests` bodies after the
marker) are left out: a test may reach anywhere. Exit 1 when any circle is found.

It also checks the workspace crates some folders must not name (`SEPARATED`): the code
of `sweephold identify` (host/cli/src/identify/) runs on logs alone and names neither the
simulator (`rotorsim`) nor its truth (`truth`). Exit 1 when one does.

    python3 docs/import_cycles.py [--crate DIR ...]
"""
import os
import re
import sys

# (folder, crates its non-test code must not name).
SEPARATED = [("host/cli/src/identify", ["rotorsim", "truth"])]

CRATES = ["shared", "firmware", "firmware/board", "host/rotorsim", "host/sysid", "host/cli", "host/truth"]


def module_of(src, path):
    rel = os.path.relpath(path, src)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"):
        rel = rel[:-1]
    return tuple(rel)


def strip_tests(text):
    # Drop everything from a `#[cfg(test)]` module to the end of the file: by convention
    # the test module is the file's last item in this project.
    m = re.search(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{", text)
    return text[: m.start()] if m else text


def strip_comments(text):
    return re.sub(r"//[^\n]*", "", text)


def modules(src):
    mods = {}
    for root, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            if f == "tests.rs" or f.endswith("_tests.rs") or f == "test_support.rs":
                continue
            p = os.path.join(root, f)
            if "/bin/" in p:
                continue
            with open(p, encoding="utf-8") as h:
                mods[module_of(src, p)] = strip_comments(strip_tests(h.read()))
    return mods


def resolve(mods, path):
    """Longest known module prefix of `path`."""
    for n in range(len(path), 0, -1):
        if tuple(path[:n]) in mods:
            return tuple(path[:n])
    return None


def edges(mods):
    out = {m: set() for m in mods}
    for m, text in mods.items():
        for hit in re.finditer(r"\bcrate((?:::\w+)+)", text):
            target = resolve(mods, hit.group(1).strip(":").split("::"))
            if target and target != m:
                out[m].add(target)
        for hit in re.finditer(r"\bcrate::\{([^}]*)\}", text):
            for part in hit.group(1).split(","):
                target = resolve(mods, part.strip().split("::"))
                if target and target != m:
                    out[m].add(target)
        parent = m[:-1] if m else ()
        for hit in re.finditer(r"\bsuper((?:::\w+)+)", text):
            target = resolve(mods, list(parent) + hit.group(1).strip(":").split("::"))
            if target and target != m:
                out[m].add(target)
    return out


def lift(graph, depth_of):
    """Collapse modules to siblings: an edge a.x -> a.y.z counts as a.x -> a.y."""
    lifted = {}
    for a, targets in graph.items():
        for b in targets:
            common = 0
            while common < min(len(a), len(b)) and a[common] == b[common]:
                common += 1
            if common == len(a) or common == len(b):
                continue  # parent/child: not a circle between siblings
            sa, sb = a[: common + 1], b[: common + 1]
            lifted.setdefault(sa, set()).add(sb)
            lifted.setdefault(sb, set())
    return lifted


def cycles(graph):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
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
    for v in list(graph):
        if v not in index:
            visit(v)
    return out


def main():
    args = sys.argv[1:]
    crates = CRATES
    if args[:1] == ["--crate"]:
        crates = args[1:]
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    found = 0
    for crate in crates:
        src = os.path.join(root, crate, "src")
        if not os.path.isdir(src):
            continue
        for comp in cycles(lift(edges(modules(src)), None)):
            found += 1
            names = ["::".join(c) or "crate" for c in comp]
            print(f"{crate}: " + " <-> ".join(names))
    named = separated_named(root)
    for line in named:
        print(line)
    if found:
        print(f"{found} import circle(s)")
    if found or named:
        return 1
    print("no import circles; no folder names a crate it must not")
    return 0


def separated_named(root):
    """`FILE: names CRATE` for each file of a `SEPARATED` folder naming a crate it must not."""
    out = []
    for folder, banned in SEPARATED:
        for base, _, files in os.walk(os.path.join(root, folder)):
            for f in sorted(files):
                if not f.endswith(".rs") or f == "tests.rs" or f.endswith("_tests.rs"):
                    continue
                path = os.path.join(base, f)
                with open(path, encoding="utf-8") as h:
                    text = strip_comments(strip_tests(h.read()))
                for crate in banned:
                    if re.search(r"(\b|::)" + crate + r"\s*::|\buse\s+" + crate + r"\b", text):
                        out.append(f"{os.path.relpath(path, root)}: names `{crate}`, which it must not")
    return out


if __name__ == "__main__":
    sys.exit(main())
