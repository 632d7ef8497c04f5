"""Executes notebooks top to bottom in their own folder (as CI does), failing on the first
cell that raises; the notebook files are left unchanged.

    pip install "./python[notebook]"
    python examples/python/run_notebook.py examples/python/tour.ipynb

The cells run in this interpreter, in one namespace per notebook, as a Jupyter kernel runs
them: a cell's last expression is displayed (its repr and every rich form it offers, such as
`_repr_html_`), and the figures a cell leaves open are drawn to PNG and closed, as the inline
backend does. No kernel is started, so nothing of Jupyter needs installing; a cell that needs
IPython's syntax (`%magic`, `!shell`) is refused.
"""

import ast
import contextlib
import io
import json
import os
import sys
import time
from pathlib import Path

# Rich forms a Jupyter front end asks a displayed value for.
RICH_FORMS = ("_repr_html_", "_repr_markdown_", "_repr_latex_", "_repr_json_", "_repr_png_",
              "_repr_svg_", "_repr_mimebundle_")


def code_cells(path):
    """The notebook's code cells as (number, source), numbered from 1 among all cells."""
    with open(path, encoding="utf-8") as f:
        notebook = json.load(f)
    for number, cell in enumerate(notebook["cells"], start=1):
        if cell["cell_type"] == "code":
            source = cell["source"]
            yield number, source if isinstance(source, str) else "".join(source)


def refuse_ipython_syntax(name, source):
    """Fails on a line only IPython understands (a magic or a shell escape)."""
    for line in source.splitlines():
        if line.lstrip().startswith(("%", "!")):
            raise SystemExit(f"{name}: needs IPython to run: {line.strip()}")


def display(value):
    """What a kernel does with a cell's last value: its repr and its rich forms."""
    if value is None:
        return
    print(repr(value))
    for form in RICH_FORMS:
        method = getattr(value, form, None)
        if callable(method):
            method()


def flush_figures():
    """Draws every open figure to PNG and closes it, as the inline backend does after a cell."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is None:
        return
    for number in pyplot.get_fignums():
        pyplot.figure(number).savefig(io.BytesIO(), format="png")
    pyplot.close("all")


def run_cell(name, source, namespace):
    """Runs one cell in `namespace`, displaying its last expression's value; what it prints is
    kept, as a kernel keeps a cell's output, and shown only when the cell raises."""
    refuse_ipython_syntax(name, source)
    tree = ast.parse(source, filename=name)
    last = None
    if tree.body and isinstance(tree.body[-1], ast.Expr):
        last = ast.Expression(tree.body.pop().value)
    output = io.StringIO()
    try:
        with contextlib.redirect_stdout(output):
            exec(compile(tree, name, "exec"), namespace)
            if last is not None:
                display(eval(compile(last, name, "eval"), namespace))
            flush_figures()
    except BaseException:
        sys.stdout.write(output.getvalue())
        raise


def execute(path):
    """Runs every code cell of the notebook at ``path``; returns the seconds it took."""
    path = Path(path).resolve()
    os.environ.setdefault("MPLBACKEND", "Agg")
    namespace = {"__name__": "__main__"}
    started = time.perf_counter()
    here = os.getcwd()
    os.chdir(path.parent)
    try:
        for number, source in code_cells(path):
            run_cell(f"{path.name}[cell {number}]", source, namespace)
    finally:
        os.chdir(here)
    return time.perf_counter() - started


if __name__ == "__main__":
    for name in sys.argv[1:]:
        print(f"{name}: executed in {execute(name):.1f} s")
