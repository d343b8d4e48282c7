"""`import gearcheck`: the README's Python example runs and gives what the command line gives; results
have named signals and pandas export; bad arguments raise gearcheck's own errors, naming them."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gearcheck
from gearcheck.compare.presentation.plots import MODE_COLORS

README = Path(__file__).resolve().parent.parent / "README.md"


def readme_python_example() -> str:
    section = README.read_text(encoding="utf-8").split("## From Python", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)\n```", section, flags=re.S)[0]


def test_readme_example_gives_what_the_command_line_gives(tmp_path):
    """The README's five lines, run as a user would (over 0.2 s instead of its 0.6 s, to keep the suite
    fast), and `gearcheck crosscheck` with the same options: the same verdict, failures, measurement
    rows and every compared number."""
    code = readme_python_example()
    assert len([line for line in code.splitlines() if line.strip()]) <= 7
    code = re.sub(r"duration=[0-9.]+", "duration=0.2", code)
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    printed = done.stdout.splitlines()
    assert printed[0] == "PASS []"
    assert [line.split()[:2] for line in printed[1:]] == [["I.ring.ay.world", "peak"], ["II.carrier.ay.world", "peak"]]
    duration = re.search(r"duration=([0-9.]+)", code).group(1)
    # the command in a fresh process too, as the example: a test worker's process state (libraries that earlier
    # tests loaded, thread pools) may move the last bits of a run, which the exact comparison below would see
    command = [sys.executable, "-m", "gearcheck", "crosscheck", "hub-drive", "--duration", duration, "--no-figures",
               "--out", "cli"]  # report.json is compared: the same with figures or without
    assert subprocess.run(command, cwd=tmp_path, capture_output=True, text=True).returncode == 0
    python, cli = (json.loads((tmp_path / d / "report.json").read_text()) for d in ("out/hub-drive", "cli"))
    for data in (python, cli):
        data.pop("volatile")
    assert python == cli
    rows = [f"{m['quantity']} {m['metric']} {m['measured']['value']} {m['reference']['value']} {m['test']['value']}"
            for m in cli["measurements"]]
    assert printed[1:] == rows


def test_simulate_returns_named_signals_with_pandas_export():
    result = gearcheck.simulate("demo-3p", "lumped", 0.01, output_dt=1e-4)
    frame = result.to_dataframe()
    assert result.names("mesh_force") == [f"stage1.planet{i}.{c}.force" for c in ("sun", "ring") for i in (1, 2, 3)]
    np.testing.assert_array_equal(frame["stage1.ring.ay.world"].to_numpy(), result["stage1.ring.ay.world"])
    assert result.signal("stage1.ring.ay.world").unit == "m/s^2"
    assert not result.signal("stage1.planet1.ax.world").compared  # planets are seen through their meshes
    twin = gearcheck.simulate("demo-3p", "mujoco", 0.01, output_dt=1e-4)
    assert twin.names() == result.names()
    force = "stage1.planet1.sun.force"
    assert np.max(np.abs(twin[force] - result[force])) < 0.01 * np.max(np.abs(result[force]))
    summary = result.summary()
    assert summary["series"][force]["unit"] == "N" and summary["series"][force]["rms"] > 0


def test_modes_and_mjcf_from_the_front_door():
    lumped, mujoco = gearcheck.modes("demo-3p"), gearcheck.modes("demo-3p", "mujoco")
    np.testing.assert_allclose(mujoco.frequencies, lumped.frequencies, rtol=1e-9)
    assert lumped.solver == "lumped" and mujoco.solver == "mujoco"
    assert gearcheck.mjcf("demo-3p") == (README.parent / "xml" / "demo-3p.xml").read_text(encoding="utf-8")


def test_a_train_already_loaded_passes_through_and_speed_replaces_its_own():
    spec = gearcheck.load("demo-3p")
    assert gearcheck.load(spec) is spec
    assert gearcheck.load(spec, speed=3000).operating.input_speed == pytest.approx(2 * spec.operating.input_speed)


@pytest.mark.parametrize("call, message", [
    (lambda: gearcheck.load("no-such-train"), "no such train file or preset"),
    (lambda: gearcheck.load("demo-3p", speed=-5), "speed must be a positive number of rpm, got -5"),
    (lambda: gearcheck.simulate("demo-3p", "abaqus"), "unknown solver 'abaqus'"),
    (lambda: gearcheck.simulate("demo-3p", "mujoco", method="RK45"), "applies to the lumped solver only"),
    (lambda: gearcheck.simulate("demo-3p", duration=0), "duration must be a positive number of seconds"),
    (lambda: gearcheck.crosscheck("demo-3p", model="as-printed"), "unknown model 'as-printed'"),
    (lambda: gearcheck.crosscheck("demo-3p", tolerances={"mesh_force.nrmse": -1}), "must be a positive number"),
])
def test_bad_arguments_raise_gearchecks_errors(call, message):
    with pytest.raises(gearcheck.GearcheckError, match=re.escape(message)):
        call()


# ----------------------------------------------------------------------------- the session and plot()
@pytest.fixture(scope="module")
def demo():
    return gearcheck.Train("demo-3p")


def test_a_session_builds_each_side_once(monkeypatch):
    """Modes, runs, a cross-check, a Campbell diagram, the mode pairing and the MJCF text of one session share one
    compiled twin and one lumped model."""
    import mujoco

    from gearcheck.lumped import side

    compiles, builds = [], []
    original, build = mujoco.MjModel.from_xml_string, side.build_model
    monkeypatch.setattr(mujoco.MjModel, "from_xml_string", lambda xml, *a: compiles.append(1) or original(xml, *a))
    monkeypatch.setattr(side, "build_model", lambda spec: builds.append(1) or build(spec))
    train = gearcheck.Train("demo-3p")
    assert compiles == [] and builds == []  # lazily
    assert isinstance(train.modes("mujoco"), gearcheck.ModalResult)
    assert isinstance(train.modes("lumped", speed=500), gearcheck.ModalResult)
    assert isinstance(train.simulate("mujoco", 0.005), gearcheck.TimeResult)
    assert isinstance(train.simulate("lumped", 0.005, method="RK45"), gearcheck.TimeResult)
    assert isinstance(train.simulate("lumped", 0.005), gearcheck.TimeResult)
    assert train.mjcf() == gearcheck.mjcf("demo-3p")
    assert type(train.mac()).__name__ == "ModePairing"
    assert type(train.campbell([0, 500])).__name__ == "CampbellResult"
    assert train.crosscheck(duration=0.02).verdict in ("PASS", "FAIL", "INCONCLUSIVE")
    assert len(compiles) == 2 and len(builds) == 1  # gearcheck.mjcf compiled its own twin: the second
    train.crosscheck(duration=0.02, speed=1000)  # another speed: models of their own
    assert len(compiles) == 3 and len(builds) == 2


def test_every_session_method_returns_its_result(demo, tmp_path):
    np.testing.assert_array_equal(demo.modes().frequencies, gearcheck.modes("demo-3p").frequencies)
    run = demo.simulate("lumped", 0.005)
    np.testing.assert_array_equal(run.values, gearcheck.simulate("demo-3p", "lumped", 0.005).values)
    assert isinstance(demo.crosscheck(duration=0.02), gearcheck.CrosscheckResult)
    curves = demo.ste()
    assert len(curves) == len(demo.spec.meshes) and curves[0].loaded.shape == curves[0].xi.shape
    assert type(demo.sweep(speeds=[900, 1000], solver="lumped", duration=0.02, workers=1,
                           integration_check=False)).__name__ == "SweepResult"
    gif = demo.animate(tmp_path / "mode.gif", mode=2, duration=0.2, fps=5, width=32, height=32)
    assert gif.read_bytes()[:6] == b"GIF89a"
    assert gearcheck.Train("demo-3p", speed=3000).spec.operating.input_speed == pytest.approx(
        2 * demo.spec.operating.input_speed)


def test_a_time_result_plots_its_signals_with_their_units(demo):
    run = demo.simulate("lumped", 0.005)
    fig = run.plot()
    kinds = dict.fromkeys((run.signal(n).kind, run.signal(n).unit) for n in run.names(compared=True))
    assert type(fig).__name__ == "Figure" and len(fig.axes) == len(kinds)
    assert [len(ax.lines) for ax in fig.axes] == [len(run.names(kind, compared=True)) for kind, _ in kinds]
    ax, = run.plot(["stage1.planet1.sun.force", "stage1.planet2.sun.force"]).axes
    assert ax.get_ylabel() == "mesh force [N]" and ax.get_xlabel() == "time [s]"
    np.testing.assert_array_equal(ax.lines[1].get_xydata(), np.c_[run.t, run["stage1.planet2.sun.force"]])
    ax, = run.plot("stage1.ring.ay.world").axes
    assert ax.get_ylabel() == "acceleration [m/s^2]" and len(ax.lines) == 1


def test_modes_plot_by_type(demo):
    modal = demo.modes()
    fig = modal.plot()
    types = list(dict.fromkeys(modal.types))
    assert len(fig.axes) == 2 and [line.get_label() for line in fig.axes[0].lines] == types
    rotational = np.asarray(modal.types) == "rotational"
    fig = modal.plot("rotational")
    line, = fig.axes[0].lines
    np.testing.assert_array_equal(line.get_ydata(), modal.frequencies[rotational])
    assert fig.axes[0].get_ylabel() == "natural frequency [Hz]"
    assert len(fig.axes[1].patches) == 3 * rotational.sum()  # three energy shares per mode


def test_compare_results_plot(demo):
    campbell = demo.campbell([0, 500, 1000])
    n_modes = campbell.frequencies("lumped").shape[1]
    colours = set(MODE_COLORS.values()) | {"tab:gray"}  # the lumped curves, each coloured by its mode's type
    curves = [line for line in campbell.plot("lumped").axes[0].lines if line.get_color() in colours]
    assert len(curves) == n_modes
    np.testing.assert_array_equal(curves[0].get_ydata(), campbell.frequencies("lumped")[:, 0])
    types = campbell.results["lumped"][0].types
    assert [c.get_color() for c in curves] == [MODE_COLORS.get(t, "tab:gray") for t in types]
    assert campbell.plot().axes[0].get_ylabel() == "natural frequency [Hz]"
    pairing = demo.mac()
    np.testing.assert_array_equal(pairing.plot().axes[0].images[0].get_array(), pairing.mac)
    result = demo.crosscheck(duration=0.02)
    ax, = result.plot("stage1.ring.ay.world").axes
    reference, twin = result.series["stage1.ring.ay.world"]
    assert len(ax.lines) == 2 and ax.get_ylabel() == "[m/s^2]"
    np.testing.assert_array_equal(ax.lines[1].get_ydata(), twin[-ax.lines[1].get_ydata().size:])
    assert len(result.plot().axes) == 4  # the report's headline quantities


def test_a_sweep_plots_and_carries_its_units(demo):
    sweep = demo.sweep(speeds=[900, 1000], solver="lumped", duration=0.02, workers=1, integration_check=False)
    frame = sweep.to_pandas()
    assert frame.attrs["units"]["speed_rpm"] == "rpm" and frame.attrs["units"]["frequency_hz"] == "Hz"
    fig = sweep.plot("stage1.ring.ay.world")
    assert fig.axes[1].get_ylabel() == "amplitude (m/s^2)" and fig.axes[1].get_xlabel() == "input speed (rpm)"
    with pytest.raises(gearcheck.GearcheckError, match=r"quantity: 'stage1\.ring\.ay\.wrld' .*did you mean "
                                                       r"'stage1\.ring\.ay\.world'"):
        sweep.plot("stage1.ring.ay.wrld")


def test_dataframes_carry_units(demo):
    run = demo.simulate("lumped", 0.005)
    units = run.to_dataframe().attrs["units"]
    assert units["t"] == "s" and units["stage1.planet1.sun.force"] == "N" and units["stage1.sun.alpha"] == "rad/s^2"
    assert list(units) == ["t", *run.names()]
    assert demo.modes().to_dataframe().attrs["units"]["frequency_hz"] == "Hz"
    assert demo.modes(speed=500).to_dataframe().attrs["units"]["growth_rate_1_s"] == "1/s"


@pytest.mark.parametrize("call, message", [
    (lambda t: t.simulate("lumped", 0.005).plot(["stage1.ring.ay.world", "stage1.ring.ay.wrld"]),
     "signals: 'stage1.ring.ay.wrld' is not a signal of lumped demo-3p (did you mean 'stage1.ring.ay.world'?)"),
    (lambda t: t.modes().plot("rotatonal"), "types: 'rotatonal' is not a mode type of demo-3p (did you mean "
                                            "'rotational'?)"),
    (lambda t: t.campbell([0, 500]).plot("mujuco"), "solvers: 'mujuco' is not a solver of this diagram (did you "
                                                    "mean 'mujoco'?)"),
    (lambda t: t.modes("abaqus"), "unknown solver 'abaqus'"),
])
def test_a_bad_plot_selection_names_the_parameter(demo, call, message):
    with pytest.raises(gearcheck.GearcheckError, match=re.escape(message)):
        call(demo)


def test_a_lumped_run_starts_where_another_ended(demo):
    """Train.simulate's y0: one branch of a nonlinear response followed from speed to speed (backlash_jump.ipynb)."""
    first = demo.simulate("lumped", 0.005)
    labels = demo.lumped.model.dofs.labels()
    y0 = (np.array([first.raw[c][-1] for c in labels]), np.array([first.raw[f"{c}_dot"][-1] for c in labels]))
    second = demo.simulate("lumped", 0.005, y0=y0)
    np.testing.assert_array_equal([second.raw[c][0] for c in labels], y0[0])
    assert not np.array_equal(second.values, first.values)
    with pytest.raises(gearcheck.GearcheckError, match="y0 applies to the lumped solver only"):
        demo.simulate("mujoco", 0.005, y0=y0)


def test_the_harmonic_response_of_a_session_is_the_front_doors(demo):
    from gearcheck.lumped.assembly import build_model
    from gearcheck.lumped.forced_response import parametric_problem
    from gearcheck.lumped.fourier_response import harmonic_balance_response

    direct = harmonic_balance_response(parametric_problem(build_model(gearcheck.load("demo-3p"))), (3,))
    for result in (demo.harmonic_response(orders=[3]), gearcheck.harmonic_response("demo-3p", orders=[3])):
        np.testing.assert_array_equal(result.amplitudes, direct.amplitudes)
    with pytest.raises(gearcheck.GearcheckError, match="method 'fourier': one of harmonic balance, Fourier series"):
        demo.harmonic_response("fourier")


def test_the_teaching_notebooks_use_the_front_door_only():
    """`import gearcheck` and its public names: no notebook reaches into the packages."""
    import nbformat

    for path in sorted((README.parent / "examples" / "teaching").glob("*.ipynb")):
        code = "\n".join(c.source for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code")
        assert not re.findall(r"(?:from|import)\s+gearcheck\.", code), path.name
        assert not re.findall(r"gearcheck\.\w+\.\w", code), path.name


def test_the_examples_use_public_names_only():
    """Every example imports ``gearcheck`` and, beyond it, only names a package lists as public (its ``__all__``,
    :func:`gearcheck.shared.public.public`): no module path, no internal name."""
    import ast
    import importlib

    for path in sorted((README.parent / "examples").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                assert all(a.name == "gearcheck" for a in node.names if a.name.startswith("gearcheck")), path.name
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("gearcheck"):
                package = importlib.import_module(node.module)
                assert hasattr(package, "__path__"), f"{path.name}: {node.module} is a module, not a package"
                for alias in node.names:
                    assert alias.name in package.__all__, f"{path.name}: {node.module}.{alias.name} is not public"
                    assert getattr(package, alias.name) is not None


def test_every_command_of_the_command_line_is_in_the_front_door():
    """Each command is a function of ``import gearcheck`` or a method of a Train session, which it calls."""
    from gearcheck.cli import _parser

    subparsers = next(a for a in _parser()._actions if a.dest == "command")
    front = {"presets": gearcheck.presets, "show": gearcheck.describe, "modes": gearcheck.modes,
             "campbell": gearcheck.campbell, "mac": gearcheck.mode_pairing, "ste": gearcheck.Train.ste,
             "run": gearcheck.simulate, "crosscheck": gearcheck.crosscheck, "calibrate": gearcheck.calibrate,
             "sweep": gearcheck.sweep, "sensitivity": gearcheck.sensitivity, "pins": gearcheck.pin_loads,
             "stiffness": gearcheck.Train.stiffness, "animate": gearcheck.Train.animate, "view": gearcheck.Train.view,
             "dashboard": gearcheck.dashboard, "export": gearcheck.export_model, "mjcf": gearcheck.mjcf,
             "runup": gearcheck.runup}
    assert set(subparsers.choices) == set(front)
    assert all(callable(f) and f.__doc__ for f in front.values())


def test_describe_and_stiffness_from_the_front_door():
    info = gearcheck.describe("demo-3p")
    assert info["train"] == "demo-3p" and len(info["meshes"]) == 6
    train = gearcheck.Train("demo-3p")
    fig = train.stiffness(cycles=2)
    first = [m for m in train.spec.meshes if m.planet_index == 0]
    assert len(fig.axes) == len(first)
    for bad in (0, -1, 101, "2", 2.5, True):
        with pytest.raises(gearcheck.GearcheckError, match=r"^cycles=.*: a whole number of mesh cycles from 1 to 100$"):
            train.stiffness(cycles=bad)
    x, k = fig.axes[0].lines[0].get_data()
    assert x[-1] == 2.0 and np.isclose(np.mean(k[:-1]), train.lumped.model.excitation.mean_stiffness[0] / 1e9,
                                       rtol=1e-3)
