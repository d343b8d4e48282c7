"""Sphinx configuration of gearcheck's documentation site: ``python -m sphinx -W -b html docs out/site``.

The pages are the repository's own Markdown (MyST): the README in parts, the audits of the seed papers, the CI
recipe, the developer guide; the API reference is generated from the numpydoc docstrings of the front door; the
teaching notebooks are executed while the site is built (myst-nb), so their figures are on their pages.  Why
Sphinx: numpydoc docstrings and executed notebooks are first-class there, and ``-W`` makes a broken link or
reference, a malformed docstring or a failing notebook an error.  ``GEARCHECK_DOCS_EXECUTE=off`` builds without
running the notebooks (the quick check of the tests).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import gearcheck

HERE = Path(__file__).resolve().parent
NOTEBOOKS = HERE.parent / "examples" / "teaching"

project = "gearcheck"
author = "the gearcheck developers"
copyright = "gearcheck developers, MIT licence"
release = version = gearcheck.__version__

extensions = ["myst_nb", "sphinx.ext.autodoc", "numpydoc"]
source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
exclude_patterns = ["_build/**"]
myst_enable_extensions = ["colon_fence"]
myst_heading_anchors = 3
nb_execution_mode = os.environ.get("GEARCHECK_DOCS_EXECUTE", "force")
nb_execution_timeout = 300
nb_execution_raise_on_error = True
numpydoc_show_class_members = False
autodoc_typehints = "none"
html_theme = "furo"
html_title = f"gearcheck {release}"
html_static_path: list[str] = []
suppress_warnings: list[str] = []


def _notebooks(app) -> None:
    """The teaching notebooks into ``teaching/notebooks/`` of the source (Sphinx reads only its own tree)."""
    target = HERE / "teaching" / "notebooks"
    if target.exists():
        shutil.rmtree(target)
    target.mkdir(parents=True)
    for notebook in sorted(NOTEBOOKS.glob("*.ipynb")):
        shutil.copy2(notebook, target / notebook.name)


def _site_links(app, docname: str, source: list[str]) -> None:
    """Links from the teaching page to the notebooks where the repository keeps them
    (``../../examples/teaching/``) lead, on the site, to their executed pages (``notebooks/``)."""
    if docname == "teaching/README":
        source[0] = source[0].replace("(../../examples/teaching/)", "(#teaching)").replace(
            "../../examples/teaching/", "notebooks/")


def setup(app) -> None:
    app.connect("builder-inited", _notebooks)
    app.connect("source-read", _site_links)
