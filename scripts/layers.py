#!/usr/bin/env python3
"""Checks that engine/src's modules import only downwards.

Usage: python3 scripts/layers.py [ENGINE_SRC]   (default: engine/src)

The top-level modules of the engine stand in layers (LAYERS, lowest first), and the floors
of `identify/` in floors (IDENTIFY_FLOORS, lowest first). A module may import a module of a
lower layer (a lower floor inside `identify/`), or one of its own top-level module (its own
floor); never one of a higher or the same layer, nor a re-export of the crate root
(`crate::Oscillator`) or of `identify`'s root from one of its floors: those are arrows that
run back up. Imports are read as scripts/import-cycles.py reads them (`use crate::...`,
inline `crate::x::` paths, `super::` paths; comments and test modules ignored), with its own
parsing. Every violation is printed as `file:line: module imports target (text)`, and the
exit code is 1 when there is one; "layers clean" and 0 otherwise.
"""

import importlib.util
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location(
    "import_cycles", os.path.join(HERE, "import-cycles.py")
)
cycles = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cycles)

# engine/src's top-level modules, lowest first; modules in one layer do not import each
# other. The crate root (lib.rs) re-exports them all and stands above them.
LAYERS = [
    ["error"],
    ["axis"],
    ["oscillator"],
    ["record"],
    ["data", "simulate"],
    ["energy"],
    ["exact", "synthetic"],
    ["testing"],
    ["identify"],
    ["campaign", "plan"],
    ["spec", "report"],
    ["jobs", "export"],
]

# The floors of identify/, lowest first; identify's root (mod.rs) re-exports them all.
IDENTIFY_FLOORS = [
    ["values"],
    ["problem"],
    ["search"],
    ["assessment"],
    ["fit"],
    ["compare"],
]

ROOT = "(crate root)"


def rank(table, name):
    """The index of the layer holding `name`, or None."""
    for index, layer in enumerate(table):
        if name in layer:
            return index
    return None


def located_imports(known, module, code):
    """(target, offset, text) for every module path in `code`, as import-cycles reads them;
    a `crate::` path naming no module is the crate root's re-export."""
    for match in cycles.PATH.finditer(code):
        paths = [match.group(1)]
        for item in (match.group(2) or "").split(","):
            item = cycles.re.sub(r"[{}\s]", "", item.split(" as ")[0])
            if item:
                paths.append(match.group(1) + "::" + item.split("::")[0])
        for path in paths:
            target = cycles.resolve(known, module, path)
            if target is None and path.startswith("crate::"):
                target = ROOT
            if target is not None:
                yield target, match.start(), path


def violation(module, target):
    """Why `module` may not import `target`, or None when it may."""
    if target == ROOT:
        return "the crate root's re-export"
    own, other = module.split("::"), target.split("::")
    if own[0] != other[0]:
        low, high = rank(LAYERS, other[0]), rank(LAYERS, own[0])
        if low is None or high is None:
            return None
        return None if low < high else "a module of a layer not below its own"
    if own[0] != "identify" or len(own) < 2:
        return None
    if len(other) < 2:
        return "identify's root re-export from one of its floors"
    low, high = rank(IDENTIFY_FLOORS, other[1]), rank(IDENTIFY_FLOORS, own[1])
    if low is None or high is None or low <= high:
        return None
    return "a floor of identify above its own"


def check(src):
    known = cycles.modules(src)
    unlisted = sorted({m.split("::")[0] for m in known if m} - {n for l in LAYERS for n in l})
    found = []
    for name in unlisted:
        found.append(f"{src}: top-level module `{name}` has no layer in scripts/layers.py")
    for module, path in sorted(known.items()):
        if not module:
            continue
        code = cycles.code_of(path)
        seen = set()
        for target, offset, text in located_imports(known, module, code):
            why = violation(module, target)
            line = code.count("\n", 0, offset) + 1
            if why and (target, line) not in seen:
                seen.add((target, line))
                found.append(f"{path}:{line}: {module} imports {target} ({text}): {why}")
    return found


def main(argv):
    src = argv[0] if argv else "engine/src"
    found = check(src)
    for message in found:
        print(message)
    if not found:
        print("layers clean")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
