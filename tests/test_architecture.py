"""The package's walls, read from the installed code: one import package, the MuJoCo side never
imports the lumped equations, imports run one way with no cycles, a twin compiles once, the data
files ship, and importing gearcheck leaves matplotlib's backend alone."""

from __future__ import annotations

import ast
import importlib.metadata
import importlib.resources
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

import gearcheck

ROOT = Path(gearcheck.__file__).parent
LAYERS = ["shared", "lumped", "mbd_models", "compare"]  # each may import those before it, never after
DESCRIPTION = {  # the modules of gearcheck.lumped that describe the train: what the MuJoCo side may use
    "schema", "loader", "spec", "geometry", "line_of_action", "kinematics", "mesh_stiffness", "tooth_stiffness",
    "iso6336", "excitation", "published_parameters", "cycloid",
}


def package_modules() -> dict[str, Path]:
    """Every module of the installed package by dotted name (package-dir mapped folders included)."""
    out = {}
    for sub in ["", *LAYERS]:
        pkg = importlib.import_module(f"gearcheck.{sub}" if sub else "gearcheck")
        for path in Path(pkg.__file__).parent.glob("*.py"):
            name = pkg.__name__ if path.stem == "__init__" else f"{pkg.__name__}.{path.stem}"
            out[name] = path
    return out


def imports_of(source: str, module: str, is_package: bool = False) -> set[str]:
    """Every gearcheck module imported anywhere in ``source`` (module level or inside functions)."""
    package = module if is_package else module.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            found.add(base)
            found |= {f"{base}.{alias.name}" for alias in node.names}  # `from pkg import module`
    return {name for name in found if name == "gearcheck" or name.startswith("gearcheck.")}


@pytest.fixture(scope="module")
def graph():
    modules = package_modules()
    return {name: {m for m in imports_of(path.read_text(encoding="utf-8"), name, path.stem == "__init__")
                   if m in modules and m != name}
            for name, path in modules.items()}


def wall_breaches(imports: set[str]) -> set[str]:
    """The modules of gearcheck.lumped outside its description that ``imports`` reach."""
    return {".".join(m.split(".")[:3]) for m in imports
            if m.startswith("gearcheck.lumped.") and m.split(".")[2] not in DESCRIPTION}


def test_the_mujoco_side_never_imports_the_lumped_equations(graph):
    mbd = {name: deps for name, deps in graph.items() if name.startswith("gearcheck.mbd_models")}
    assert len(mbd) >= 8
    for name, deps in mbd.items():
        assert not wall_breaches(deps), f"{name} imports the lumped equations: {sorted(wall_breaches(deps))}"


def test_the_wall_check_can_fail():
    breach = "from gearcheck.lumped.assembly import build_model\nfrom gearcheck.lumped import static\n"
    assert wall_breaches(imports_of(breach, "gearcheck.mbd_models.x")) == {"gearcheck.lumped.assembly",
                                                                          "gearcheck.lumped.static"}
    assert not wall_breaches(imports_of("from gearcheck.lumped.spec import TrainSpec\n", "gearcheck.mbd_models.x"))


def test_imports_run_one_way(graph):
    for name, deps in graph.items():
        layer = name.split(".")[1] if name.count(".") else "front door"
        if layer not in LAYERS:
            continue  # the front door and the command line sit on top
        allowed = {f"gearcheck.{lower}" for lower in LAYERS[:LAYERS.index(layer) + 1]}
        wrong = {d for d in deps if not any(d == a or d.startswith(a + ".") for a in allowed)}
        assert not wrong, f"{name} ({layer}) imports {sorted(wrong)}"


def test_no_import_cycles(graph):
    state: dict[str, int] = {}

    def visit(node, path):
        state[node] = 1
        for dep in sorted(graph[node]):
            if state.get(dep) == 1:
                pytest.fail("import cycle: " + " -> ".join(path[path.index(dep):] + [dep]) if dep in path
                            else f"import cycle through {dep}")
            if dep not in state:
                visit(dep, path + [dep])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])


def test_a_twin_compiles_once(monkeypatch):
    from gearcheck.mbd_models.twin import compile_train

    compiles = []
    original = mujoco.MjModel.from_xml_string
    monkeypatch.setattr(mujoco.MjModel, "from_xml_string", lambda xml, *a: compiles.append(1) or original(xml, *a))
    mb = compile_train(gearcheck.load("hub-drive"))
    assert len(compiles) == 1
    assert mb.model.opt.timestep == mb.default_step and f'timestep="{mb.default_step!r}"' in mb.xml
    assert mb.default_step <= 0.9 * 2 * 2**0.5 / mb.omega_max  # inside RK4's stability limit


def test_only_gearcheck_goes_into_site_packages():
    names = {name for name, dists in importlib.metadata.packages_distributions().items() if "gearcheck" in dists}
    assert names == {"gearcheck"}


def test_presets_and_baselines_ship_with_the_package():
    presets = importlib.resources.files("gearcheck.lumped.presets")
    baselines = importlib.resources.files("gearcheck.compare").joinpath("baselines")
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
