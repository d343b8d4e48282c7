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
from gearcheck.cli import main

README = Path(__file__).resolve().parent.parent / "README.md"


def readme_python_example() -> str:
    section = README.read_text(encoding="utf-8").split("## From Python", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)\n```", section, flags=re.S)[0]


def test_readme_example_gives_what_the_command_line_gives(tmp_path, capsys):
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
    assert main(["crosscheck", "hub-drive", "--duration", duration, "--out", str(tmp_path / "cli")]) == 0
    python, cli = (json.loads((tmp_path / d / "report.json").read_text()) for d in ("out/hub-drive", "cli"))
    for data in (python, cli):
        data.pop("volatile")
    assert python == cli
    rows = [f"{m['quantity']} {m['metric']} {m['measured']['value']} {m['lumped']['value']} {m['mujoco']['value']}"
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
