#!/usr/bin/env python3
"""Fail if the crate's own module files import each other in a cycle, or upwards.

Reads every `.rs` file under `src/`, collects the paths it names through
`crate::` and `super::` (in `use` items and inline paths alike), resolves each
to the module file that defines the named item's module, and looks for
strongly connected components of more than one file in that graph.

A module's use of its own descendants (`mod x;`, `use x::Item`,
`pub use x::Item`) is not an edge: a module and its submodules are one unit
and its parts. Every other path is: a child naming its parent or a sibling,
and any module naming another subtree. Test modules (`#[cfg(test)] mod tests { ... }`) are skipped:
a test may read any module. `main.rs` is the binary's root and is not part of
the library's module tree.

It also checks the layers (`FORBIDDEN` below): imports run downwards only,
so a lower layer naming a higher one is reported even where no cycle forms.

Exit status 0 when the graph is acyclic and keeps the layers; 1 with every
cycle and every crossing listed otherwise.
Run it from anywhere: `python3 scripts/check_import_cycles.py [SRC_DIR]`.
"""
import os
import re
import sys

SRC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
SRC = os.path.normpath(SRC)


def module_of(path):
    """The module path (list of names) a file defines, e.g. src/render/mod.rs -> ['render']."""
    rel = os.path.relpath(path, SRC)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib"):
        rel = rel[:-1]
    return rel


files = {}
for root, _, names in os.walk(SRC):
    for n in names:
        if n.endswith(".rs") and not (root == SRC and n == "main.rs"):
            p = os.path.join(root, n)
            files[tuple(module_of(p))] = p


def strip_tests_and_comments(text):
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    # Drop `#[cfg(test)] mod name { ... }` bodies by brace matching.
    out, i = [], 0
    pat = re.compile(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{")
    while True:
        m = pat.search(text, i)
        if not m:
            out.append(text[i:])
            break
        out.append(text[i:m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    return "".join(out)


def expand_use_tree(tree):
    """Expand `a::{b, c::{d, e}}` into ['a::b', 'a::c::d', 'a::c::e']."""
    tree = tree.strip()
    m = re.match(r"^(.*?)::\{(.*)\}$", tree, re.S)
    if not m:
        return [tree]
    prefix, inner = m.group(1), m.group(2)
    parts, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += ch == "{"
        depth -= ch == "}"
        cur += ch
    parts.append(cur)
    out = []
    for p in parts:
        p = p.strip()
        if not p:
            continue
        for e in expand_use_tree(p):
            out.append(prefix + "::" + e if e != "self" else prefix)
    return out


def resolve(module, path):
    """The module file a `crate::`/`super::` path points into, or None."""
    segs = [s.strip() for s in path.split("::")]
    segs = [re.sub(r"\s+as\s+\w+$", "", s) for s in segs]
    if segs[0] == "crate":
        base, rest = [], segs[1:]
    elif segs[0] in ("super", "self"):
        base = list(module)
        # A file's `super` is its parent module; `self` is the file's own module.
        while segs and segs[0] in ("super", "self"):
            if segs[0] == "super":
                base = base[:-1]
            segs = segs[1:]
        rest = segs
    elif tuple(module) + (segs[0],) in files:
        # Edition-2018 relative path: `use child::Item` names a child module.
        base, rest = list(module), segs
    else:
        return None
    # The longest prefix that names a module file.
    best = tuple(base) if tuple(base) in files else None
    cur = list(base)
    for s in rest:
        cur.append(s)
        if tuple(cur) in files:
            best = tuple(cur)
        else:
            break
    return best


graph = {m: set() for m in files}
for module, path in files.items():
    with open(path, encoding="utf-8") as f:
        text = strip_tests_and_comments(f.read())
    targets = []
    for m in re.finditer(r"\buse\s+((?:crate|super|self|[a-z_]\w*)\b[^;]*);", text, re.S):
        targets += expand_use_tree(m.group(1))
    # Inline paths outside `use` items.
    no_use = re.sub(r"\buse\s+[^;]*;", "", text, flags=re.S)
    targets += re.findall(r"\b((?:crate|super)(?:::\w+)+)", no_use)
    for t in targets:
        r = resolve(module, t)
        # A module using its own submodules is one unit using its parts
        # (like `mod child;`), not a dependency between peers.
        if r is not None and r != module and r[: len(module)] != tuple(module):
            graph[module].add(r)

# Tarjan's strongly connected components.
index, low, on, stack, sccs, counter = {}, {}, set(), [], [], [0]
sys.setrecursionlimit(10000)


def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
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
            sccs.append(sorted(comp))


for v in sorted(graph):
    if v not in index:
        visit(v)

name = lambda m: "::".join(m) or "crate"

# Layers: a module under the first prefix may not name one under the second.
# Imports run downwards: app/cli over chart/gallery over render over scene
# over math; inside render, accel finds hits and knows nothing of shading.
FORBIDDEN = [
    (("scene",), ("render",)),
    (("math",), ("scene",)),
    (("math",), ("render",)),
    (("display",), ("scene",)),
    (("display",), ("render",)),
    (("display",), ("app",)),
    (("display",), ("cli",)),
    (("render",), ("app",)),
    (("render",), ("cli",)),
    (("render",), ("chart",)),
    (("render",), ("gallery",)),
    (("chart",), ("app",)),
    (("gallery",), ("app",)),
    (("render", "accel"), ("render", "transport")),
    (("render", "accel"), ("render", "shadow")),
    (("render", "accel"), ("render", "raytrace")),
    (("render", "accel"), ("render", "raster")),
    (("render", "accel"), ("render", "frame")),
    (("render", "accel"), ("render", "opengl")),
    (("render", "raster"), ("render", "transport")),
    (("render", "raster"), ("render", "raytrace")),
    (("render", "raster"), ("render", "frame")),
    (("render", "transport"), ("render", "raytrace")),
    (("render", "transport"), ("render", "raster")),
    (("render", "transport"), ("render", "frame")),
]
under = lambda m, prefix: tuple(m[: len(prefix)]) == prefix
broken = sorted(
    (name(a), name(b))
    for a in graph
    for b in graph[a]
    for hi, lo in FORBIDDEN
    if under(a, hi) and under(b, lo)
)
if broken:
    print(f"{len(broken)} import(s) against the layers:")
    for a, b in broken:
        print(f"- {a} -> {b}")

if not sccs and not broken:
    print(f"no import cycles and no import against the layers among {len(files)} module files")
    sys.exit(0)
if not sccs:
    sys.exit(1)
print(f"{len(sccs)} import cycle(s) among {len(files)} module files:")
for c in sccs:
    print(f"- {len(c)} files: " + ", ".join(name(m) for m in c))
    cs = set(c)
    for m in c:
        print(f"    {name(m)} -> " + ", ".join(name(t) for t in sorted(graph[m] & cs)))
sys.exit(1)
