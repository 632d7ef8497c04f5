#!/usr/bin/env python3
"""Checks that the Python extension's build can reuse the workspace's test build.

Usage: python3 scripts/shared-crates.py   (from the repository root)

python/ is a workspace member built apart: `.ci/run` tests the workspace without it
(`--exclude frictionid-python`, as it links against Python), then maturin builds it into the
same target/ with the test profile. The lock file is one, so the versions agree; cargo
reuses a crate compiled by the test build only where its features are the same in both
graphs too. Every crate the two graphs share with other features is printed as
`name version: workspace [...] / python [...]` and the exit code is 1 when there is one
(turn the feature on in the graph that lacks it: the root's dev-dependencies, python/
Cargo.toml's dependencies); "shared crates aligned" and 0 otherwise.
"""

import subprocess
import sys

FORMAT = ["-f", "{p}|{f}", "--prefix", "none"]
WORKSPACE = [
    "cargo", "tree", "--workspace", "--exclude", "frictionid-python", "-e", "normal,build,dev",
    *FORMAT,
]
PYTHON = [
    "cargo", "tree", "-p", "frictionid-python", "-e", "normal,build",
    "--features", "pyo3/extension-module", *FORMAT,
]


def features(command):
    """{(name, version): {features, ...}} of the crates `command` (a cargo tree) lists."""
    text = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    crates = {}
    for line in text.splitlines():
        if "|" not in line:
            continue
        package, flags = line.removesuffix("(*)").split("|", 1)
        name, version = package.split()[:2]
        crates.setdefault((name, version), set()).add(flags.strip())
    return crates


def main():
    workspace, python = features(WORKSPACE), features(PYTHON)
    names = {name for name, _ in workspace}
    bad = []
    for (name, version), flags in sorted(python.items()):
        if name not in names or name.startswith("frictionid"):
            continue
        theirs = workspace.get((name, version))
        if theirs != flags:
            bad.append(f"{name} {version}: workspace {sorted(theirs or [])} / python {sorted(flags)}")
    for line in bad:
        print(line)
    if bad:
        return 1
    print("shared crates aligned")
    return 0


if __name__ == "__main__":
    sys.exit(main())
