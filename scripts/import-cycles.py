#!/usr/bin/env python3
"""Finds import circles among the modules of Rust crates.

Usage: python3 scripts/import-cycles.py SRC_DIR [SRC_DIR ...] [--edges]

Each `.rs` file under SRC_DIR is a module (`a/b.rs` and `a/b/mod.rs` are `a::b`). A module
imports another when its non-test code names it through `crate::`, `super::` or `self::`
paths (in `use` lines or inline), or, for a parent module, through `use child::...` or
`pub use child::...` (re-exports count: a parent that re-exports a child which imports the
parent is a circle). Comments and `#[cfg(test)] mod ... { }` blocks are ignored: tests may
reach anywhere. A path that names an item rather than a module counts as an import of the
deepest module it names.

Prints each strongly connected component with more than one module and exits 1 when there is
one; prints "no cycles" and exits 0 otherwise. `--edges` also prints every module's imports.
"""

import os
import re
import sys

PATH = re.compile(r"\b((?:crate|super|self)(?:::\w+)+)(?:::\{([^;]*?)\})?")
CHILD_USE = re.compile(r"\buse\s+(\w+)")
TEST_BLOCK = re.compile(r"#\[cfg\(test\)\]\s*\n\s*(pub(\(\w+\))?\s+)?mod\s+\w+\s*\{")


def modules(src):
    """Module path -> file, for every .rs file under src."""
    found = {}
    for root, _, files in os.walk(src):
        for name in files:
            if not name.endswith(".rs"):
                continue
            path = os.path.join(root, name)
            parts = os.path.relpath(path, src)[:-3].split(os.sep)
            if parts[-1] in ("mod", "lib", "main"):
                parts = parts[:-1]
            found["::".join(parts)] = path
    return found


def code_of(path):
    """The file's text without comments and without a trailing test module."""
    text = open(path, encoding="utf-8").read()
    test = TEST_BLOCK.search(text)
    if test:
        text = text[: test.start()]
    lines = []
    for line in text.split("\n"):
        lines.append("" if line.strip().startswith("//") else line.split("//")[0])
    return "\n".join(lines)


def resolve(known, current, path):
    """The deepest known module a `crate::`/`super::`/`self::` path names, or None."""
    segments = path.split("::")
    base = current.split("::") if current else []
    if segments[0] == "crate":
        base, segments = [], segments[1:]
    elif segments[0] == "super":
        while segments and segments[0] == "super":
            base, segments = base[:-1], segments[1:]
    else:
        segments = segments[1:]
    full = base + segments
    for length in range(len(full), 0, -1):
        candidate = "::".join(full[:length])
        if candidate in known:
            return candidate
    return None


def imports_of(known, module, code):
    """The modules `module` imports (never itself or one of its ancestors)."""
    targets = set()
    for match in PATH.finditer(code):
        paths = [match.group(1)]
        for item in (match.group(2) or "").split(","):
            item = re.sub(r"[{}\s]", "", item.split(" as ")[0])
            if item:
                paths.append(match.group(1) + "::" + item.split("::")[0])
        for path in paths:
            target = resolve(known, module, path)
            if target and target != module and not module.startswith(target + "::"):
                targets.add(target)
    for match in CHILD_USE.finditer(code):
        child = f"{module}::{match.group(1)}" if module else match.group(1)
        if child in known:
            targets.add(child)
    return targets


def strongly_connected(graph):
    """Tarjan's strongly connected components of graph (node -> set of nodes)."""
    index, low, stack, on_stack, components = {}, {}, [], set(), []
    counter = [0]

    def visit(node):
        index[node] = low[node] = counter[0]
        counter[0] += 1
        stack.append(node)
        on_stack.add(node)
        for succ in graph[node]:
            if succ not in index:
                visit(succ)
                low[node] = min(low[node], low[succ])
            elif succ in on_stack:
                low[node] = min(low[node], index[succ])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            components.append(sorted(component))

    sys.setrecursionlimit(10000)
    for node in graph:
        if node not in index:
            visit(node)
    return components


def check(src, show_edges):
    known = modules(src)
    graph = {m: imports_of(known, m, code_of(p)) for m, p in known.items()}
    if show_edges:
        for module in sorted(graph):
            print(f"{src}: {module or '(root)'} -> {', '.join(sorted(graph[module]))}")
    circles = [c for c in strongly_connected(graph) if len(c) > 1]
    for circle in circles:
        print(f"{src}: import circle of {len(circle)} modules: {', '.join(circle)}")
    return not circles


def main(argv):
    show_edges = "--edges" in argv
    dirs = [a for a in argv if a != "--edges"]
    if not dirs:
        print(__doc__.strip().split("\n")[2], file=sys.stderr)
        return 2
    clean = all([check(d, show_edges) for d in dirs])
    if clean:
        print("no cycles")
    return 0 if clean else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
