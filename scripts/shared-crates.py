#!/usr/bin/env python3
"""Checks that the Python extension's build can reuse the workspace's test build.

Usage: python3 scripts/shared-crates.py   (from the repository root)

python/ is a workspace of its own (its crate links against Python), so its Cargo.lock and
its feature resolution are its own. `.ci/run` builds it into the workspace's target/ with the
workspace's test-profile settings; cargo reuses a crate compiled by `cargo test --workspace`
only where the version and the features are the same in both graphs. Every crate the two
graphs share at a different version or with other features is printed as
`name version: workspace [...] / python [...]` and the exit code is 1 when there is one
(pin the version in python/Cargo.lock, or turn the feature on in the graph that lacks it:
the root's dev-dependencies, python/Cargo.toml's dependencies); "shared crates aligned" and
0 otherwise.
"""

import subprocess
import sys

FORMAT = ["-f", "{p}|{f}", "--prefix", "none"]
WORKSPACE = ["cargo", "tree", "--workspace", "-e", "normal,build,dev", *FORMAT]
PYTHON = [
    "cargo", "tree", "--manifest-path", "python/Cargo.toml", "-e", "normal,build",
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
