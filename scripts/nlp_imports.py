#!/usr/bin/env python3
"""Draws the import graph of a crate's modules (default: nlp/src) and reports its cycles.

A node is a module file (`ipm/core/init.rs` is `ipm::core::init`, a `mod.rs` is its
folder's module). An edge A -> B means A names an item of B: a `use crate::…`,
`use super::…`, `use self::…` (globs included) or an inline `crate::…`/`super::…` path.
Re-exports (`pub use`, `pub(crate) use`) are followed to the module that defines the
item, so naming `crate::Ipm` is an edge to `ipm`, not to the crate root. A module's
`mod child;` declaration is not an edge. Tests (`#[cfg(test)]` modules and `tests.rs`
files) are left out.

Usage: python3 scripts/nlp_imports.py [SRC_DIR] [--edges] [--dot]
Prints every strongly connected component of more than one module (an import cycle)
with the edges inside it, and exits 1 if there is one.
"""
import os
import re
import sys


def module_of(src, path):
    rel = os.path.relpath(path, src)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"):
        rel = rel[:-1]
    return tuple(rel)


def strip_tests(text):
    """The text without `#[cfg(test)] mod … { … }` blocks and comments."""
    text = re.sub(r"//[^\n]*", "", text)
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(#\[[^\]]*\]\s*)*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{", text):
        if m.start() < i:
            continue
        out.append(text[i:m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    out.append(text[i:])
    return "".join(out)


def expand(tree):
    """`a::{b, c::{d, e}}` -> ['a::b', 'a::c::d', 'a::c::e'] (aliases dropped)."""
    tree = re.sub(r"\s+as\s+\w+", "", tree.strip())
    brace = tree.find("{")
    if brace < 0:
        return [tree]
    prefix, inner = tree[:brace], tree[brace + 1:tree.rfind("}")]
    parts, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += {"{": 1, "}": -1}.get(ch, 0)
        cur += ch
    parts.append(cur)
    return [p for part in parts if part.strip() for p in expand(prefix + part.strip())]


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    src = args[0] if args else "nlp/src"
    files = {}
    for root, _, names in os.walk(src):
        for n in names:
            if n.endswith(".rs") and n != "tests.rs":
                p = os.path.join(root, n)
                files[module_of(src, p)] = strip_tests(open(p, encoding="utf-8").read())
    modules = set(files)
    uses, reexports = {}, {}
    for mod, text in files.items():
        stmts = re.findall(r"\b(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);", text)
        uses[mod] = []
        for vis, tree in stmts:
            for path in expand(tree):
                uses[mod].append(path)
                if vis:
                    name = path.split("::")[-1]
                    reexports.setdefault(mod, {})[name] = path
        # Inline paths in code.
        body = re.sub(r"\buse\s+[^;]+;", "", text)
        uses[mod] += re.findall(r"\b(?:crate|super|self)(?:::\w+)+", body)

    def absolute(mod, path):
        segs = path.split("::")
        if segs[0] == "crate":
            return list(segs[1:])
        base = list(mod)
        while segs and segs[0] in ("self", "super"):
            if segs.pop(0) == "super":
                base = base[:-1]
        return base + segs

    def resolve(segs, seen=0):
        """The module defining the item at the absolute path `segs`."""
        k = len(segs)
        while k > 0 and tuple(segs[:k]) not in modules:
            k -= 1
        mod, rest = tuple(segs[:k]), segs[k:]
        if rest and rest[0] != "*" and seen < 10:
            target = reexports.get(mod, {}).get(rest[0])
            if target is not None:
                return resolve(absolute(mod, target) + rest[1:], seen + 1)
        return mod

    edges = {m: set() for m in modules}
    for mod, paths in uses.items():
        for path in paths:
            first = path.split("::")[0]
            if first not in ("crate", "self", "super") and (mod + (first,)) not in modules:
                continue  # another crate, or a name in scope
            target = resolve(absolute(mod, path))
            if target != mod and target in modules and target != ():
                edges[mod].add(target)

    # Tarjan's strongly connected components.
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
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
                on.remove(w)
                comp.append(w)
                if w == v:
                    break
            comps.append(comp)

    for v in sorted(modules):
        if v not in index:
            visit(v)
    name = lambda m: "::".join(m) or "(root)"
    if "--dot" in sys.argv:
        print("digraph nlp {")
        for a in sorted(edges):
            for b in sorted(edges[a]):
                print(f'  "{name(a)}" -> "{name(b)}";')
        print("}")
        return 0
    if "--edges" in sys.argv:
        for a in sorted(edges):
            print(f"{name(a)} -> {', '.join(name(b) for b in sorted(edges[a]))}")
    cycles = [sorted(c) for c in comps if len(c) > 1]
    for c in cycles:
        members = set(c)
        print(f"cycle of {len(c)} modules: {', '.join(name(m) for m in c)}")
        for a in c:
            inside = sorted(b for b in edges[a] if b in members)
            print(f"  {name(a)} -> {', '.join(name(b) for b in inside)}")
    print(f"{len(modules)} modules, {sum(len(e) for e in edges.values())} edges, "
          f"{len(cycles)} import cycles")
    return 1 if cycles else 0


if __name__ == "__main__":
    sys.exit(main())
