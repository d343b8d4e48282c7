"""The teaching notebooks (examples/teaching/*.ipynb) execute, end with a figure and a sentence of physics.

Needs nbformat, nbclient and ipykernel (a ``python3`` kernel).  Run times are printed (``pytest -s``).
Set GEARCHECK_TEACHING_FIGURES=DIR to write each notebook's final figure to DIR/NAME.png
(docs/teaching/figures/ is made that way).
"""

from __future__ import annotations

import base64
import os
import time
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "examples" / "teaching").glob("*.ipynb"))
CELL_TIMEOUT_S = 120
BUDGET_S = 60  # each notebook must run in under a minute (measured on 2 cores)

nbformat = pytest.importorskip("nbformat", reason="the teaching notebooks need nbformat (test extra)")
nbclient = pytest.importorskip("nbclient", reason="the teaching notebooks need nbclient (test extra)")


def _kernel_available() -> str | None:
    try:
        from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel
    except ImportError:
        return "jupyter_client is not installed (install ipykernel)"
    try:
        KernelSpecManager().get_kernel_spec("python3")
    except NoSuchKernel:
        return "no 'python3' Jupyter kernel: install ipykernel into this environment"
    return None


def test_notebooks_exist():
    assert len(NOTEBOOKS) >= 5, f"teaching notebooks missing, found {[p.name for p in NOTEBOOKS]}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_and_ends_with_physics(path, tmp_path):
    missing = _kernel_available()
    assert missing is None, f"cannot run {path.name}: {missing}"
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        assert cell.cell_type != "code" or not cell.outputs, \
            f"{path.name}: stored outputs; clear them before committing"
    os.environ.setdefault("MPLBACKEND", "Agg")
    client = nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})  # any cwd: not the repo
    started = time.perf_counter()
    client.execute()  # raises CellExecutionError naming the cell on any error
    wall = time.perf_counter() - started
    print(f"\n{path.name}: {wall:.1f} s")
    code = [c for c in nb.cells if c.cell_type == "code"]
    for cell in code:
        errors = [o for o in cell.outputs if o.output_type == "error"]
        assert not errors, f"{path.name}: {errors[0].ename}: {errors[0].evalue}"
    images = [o["data"]["image/png"] for o in code[-1].outputs
              if o.output_type in ("display_data", "execute_result") and "image/png" in o.get("data", {})]
    assert images, f"{path.name}: the last code cell draws no figure"
    last = nb.cells[-1]
    assert last.cell_type == "markdown" and "**Physics:**" in last.source and last.source.rstrip().endswith("."), \
        f"{path.name}: must end with a markdown cell stating the physics in a sentence"
    assert wall < BUDGET_S * float(os.environ.get("GEARCHECK_TEACHING_SLACK", "1.5")), \
        f"{path.name}: {wall:.0f} s, over the one-minute budget"
    figures = os.environ.get("GEARCHECK_TEACHING_FIGURES")
    if figures:
        Path(figures).mkdir(parents=True, exist_ok=True)
        (Path(figures) / f"{path.stem}.png").write_bytes(base64.b64decode(images[-1]))
