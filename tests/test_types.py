"""The public API type-checks: mypy over the front door and the results it hands out, as installed.

The modules are checked as the installed package lays them out (a copy of it, so that an editable install,
whose subpackages live in the repository's top-level folders, reads the same), with the imports they follow
typed but not reported.  A public signature that lies about its types fails here."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mypy", reason="the type check needs mypy (test extra)")

PUBLIC = ["gearcheck", "gearcheck.api", "gearcheck.session", "gearcheck.shared.results", "gearcheck.shared.modal",
          "gearcheck.shared.progress", "gearcheck.compare.engine.comparison", "gearcheck.compare.engine.crosscheck",
          "gearcheck.compare.studies.campbell", "gearcheck.compare.studies.sweep"]
SUBPACKAGES = ("lumped", "mbd_models", "compare")  # installed beneath gearcheck, kept elsewhere in the repository


def _installed_copy(root: Path) -> Path:
    """The gearcheck package as it is installed, Python files only, under ``root``."""
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "presets", "xml")
    top = Path(importlib.util.find_spec("gearcheck").origin).parent
    shutil.copytree(top, root / "gearcheck", ignore=ignore)
    for name in SUBPACKAGES:
        if not (root / "gearcheck" / name).exists():
            source = importlib.util.find_spec(f"gearcheck.{name}").submodule_search_locations[0]
            shutil.copytree(source, root / "gearcheck" / name, ignore=ignore)
    return root


def test_the_public_api_type_checks(tmp_path):
    tree = _installed_copy(tmp_path / "tree")
    modules = [arg for name in PUBLIC for arg in ("-m", name)]
    done = subprocess.run([sys.executable, "-m", "mypy", "--follow-imports=silent", "--ignore-missing-imports",
                           "--cache-dir", str(tmp_path / "cache"), *modules], capture_output=True, text=True,
                          env={**os.environ, "MYPYPATH": str(tree)}, cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert f"no issues found in {len(PUBLIC)} source files" in done.stdout
