"""Executes notebooks top to bottom in their own folder (as CI does), failing on the first
cell that raises; the notebook files are left unchanged.

    pip install "./python[notebook]" nbclient ipykernel
    python examples/python/run_notebook.py examples/python/tour.ipynb
"""

import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient


def execute(path):
    """Runs every cell of the notebook at ``path``; returns the seconds it took."""
    notebook = nbformat.read(path, as_version=4)
    started = time.perf_counter()
    client = NotebookClient(
        notebook,
        timeout=300,
        kernel_name="python3",
        resources={"metadata": {"path": str(Path(path).resolve().parent)}},
    )
    client.execute()
    return time.perf_counter() - started


if __name__ == "__main__":
    for name in sys.argv[1:]:
        print(f"{name}: executed in {execute(name):.1f} s")
