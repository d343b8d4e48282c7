"""The package's walls, read from the installed code: one import package, the lumped and MuJoCo sides never
import each other at any depth and imports run one way (import-linter's contracts, each shown able to fail),
a twin compiles once, the data files ship, and importing gearcheck leaves matplotlib's backend alone."""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.resources
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import mujoco
import pytest

import gearcheck

PYPROJECT = Path(__file__).parents[1] / "pyproject.toml"  # the contracts: [tool.importlinter]
PACKAGES = ["gearcheck", "gearcheck.lumped", "gearcheck.mbd_models", "gearcheck.compare"]  # the mapped folders


def installed_tree(dest: Path) -> Path:
    """The installed package's source, laid out as one folder tree under ``dest`` (an editable install maps
    lumped/, mbd_models/ and compare/ from elsewhere; grimp reads a package from one folder)."""
    for name in PACKAGES:
        folder = Path(importlib.import_module(name).__file__).parent
        shutil.copytree(folder, dest.joinpath(*name.split(".")), dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return dest


def lint_imports(tree: Path) -> subprocess.CompletedProcess:
    lint = Path(sys.executable).with_name("lint-imports")
    env = {**os.environ, "PYTHONPATH": str(tree)}
    return subprocess.run([str(lint), "--no-cache", "--no-logo", str(PYPROJECT)], cwd=tree, env=env,
                          capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    return installed_tree(tmp_path_factory.mktemp("installed"))


def test_every_import_contract_holds(tree):
    done = lint_imports(tree)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Contracts: 4 kept, 0 broken." in done.stdout


@pytest.mark.parametrize("planted_in, planted, contract", [
    # three imports deep: train.excitation -> lumped.assembly; the twin reaches it through mbd_models.twin
    ("gearcheck/train/excitation.py", "import gearcheck.lumped.assembly", "The second derivation stays independent"),
    ("gearcheck/lumped/static.py", "from gearcheck.mbd_models import forces",
     "The second derivation stays independent"),
    ("gearcheck/shared/units.py", "import gearcheck.compare.engine.metrics", "Imports run one way"),
    ("gearcheck/compare/engine/align.py", "from gearcheck.compare.studies import sweep", "compare's rooms"),
    ("gearcheck/train/geometry.py", "from gearcheck.train import spec", "No import cycles"),  # spec imports geometry
])
def test_a_planted_import_breaks_its_contract(tmp_path, planted_in, planted, contract):
    """The negative control: one import added anywhere (inside a function too) fails the check."""
    tree = installed_tree(tmp_path)
    target = tree / planted_in
    target.write_text(target.read_text(encoding="utf-8") + f"\n\ndef _planted():\n    {planted}\n", encoding="utf-8")
    done = lint_imports(tree)
    assert done.returncode == 1, done.stdout + done.stderr
    broken = done.stdout.partition("Broken contracts")[2]
    assert contract in broken, done.stdout


def test_a_twin_compiles_once(monkeypatch):
    from gearcheck.mbd_models.twin import compile_train

    compiles = []
    original = mujoco.MjModel.from_xml_string
    monkeypatch.setattr(mujoco.MjModel, "from_xml_string", lambda xml, *a: compiles.append(1) or original(xml, *a))
    mb = compile_train(gearcheck.load("hub-drive"))
    assert len(compiles) == 1
    assert mb.model.opt.timestep == mb.default_step and f'timestep="{mb.default_step!r}"' in mb.xml
    assert mb.default_step <= 0.9 * 2 * 2**0.5 / mb.omega_max  # inside RK4's stability limit


def test_every_package_of_the_checkout_is_installed():
    """pyproject.toml lists the packages (the design card's folders are mapped, not found): a folder left out of
    the list would import from a checkout and fail from site-packages."""
    root = PYPROJECT.parent
    mapping = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["setuptools"]
    found = set()
    for package, folder in mapping["package-dir"].items():
        for init in (root / folder).rglob("__init__.py"):
            parts = init.parent.relative_to(root / folder).parts
            found.add(".".join((package, *parts)))
    assert found == set(mapping["packages"])


def test_only_gearcheck_goes_into_site_packages():
    names = {name for name, dists in importlib.metadata.packages_distributions().items() if "gearcheck" in dists}
    assert names == {"gearcheck"}


def test_presets_and_baselines_ship_with_the_package():
    presets = importlib.resources.files("gearcheck.train.presets")
    baselines = importlib.resources.files("gearcheck.compare.engine").joinpath("baselines")
    for name in gearcheck.presets():
        assert presets.joinpath(f"{name}.toml").is_file()
        assert baselines.joinpath(f"{name}.json").is_file()
    assert presets.joinpath("data", "hub-drive-table1.toml").is_file()


def run(code: str, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True)


def test_importing_and_reporting_leave_the_matplotlib_backend_alone(tmp_path):
    code = ("import matplotlib; matplotlib.use('svg'); import gearcheck\n"
            "gearcheck.crosscheck('demo-3p', duration=0.01).write('out')\n"
            "print(matplotlib.get_backend())")
    done = run(code, tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "svg"
    assert (tmp_path / "out" / "spectra.png").stat().st_size > 10_000


@pytest.mark.parametrize("argv", [["-m", "gearcheck", "--version"], ["-m", "gearcheck.cli", "--version"]])
def test_version_from_the_command_line(argv, tmp_path):
    done = subprocess.run([sys.executable, *argv], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.strip() == f"gearcheck {gearcheck.__version__}"
    assert gearcheck.__version__ == importlib.metadata.version("gearcheck")
