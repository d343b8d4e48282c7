"""The command line: listing, showing, modes as JSON, a lumped run writing its files."""

import json
import logging
import re

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from gearcheck.cli import main
from gearcheck.shared import settings
from gearcheck.train.loader import preset_text
from gearcheck.shared.results import units_of


def test_presets_lists_every_preset_with_its_source(capsys):
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    assert "demo-3p" in out and "demo-4p" in out and "gearcheck demo design" in out


def test_show_json_derived_quantities(capsys):
    assert main(["show", "demo-3p", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["ratio"] == pytest.approx(1 + 62 / 22)
    assert {m["mesh"] for m in info["meshes"]} >= {"stage1.planet1.sun", "stage1.planet3.ring"}
    assert info["meshes"][0]["mesh_frequency_hz"] == pytest.approx(22 * (1500 - 1500 / info["ratio"]) / 60)


def test_modes_json_schema(capsys):
    assert main(["modes", "demo-4p", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    modes = data["solvers"][0]["modes"]
    assert data["unit"] == "Hz" and len(modes) == 21
    assert set(modes[0]) == {"mode", "frequency_hz", "type", "multiplicity", "energy"}
    for mode in modes:  # the shares add up, and a rotational mode has none in central translation
        assert sum(mode["energy"].values()) == pytest.approx(1.0)
        if mode["type"] == "rotational":
            assert mode["energy"]["central_translation"] < 1e-8 < mode["energy"]["central_rotation"]


def test_run_lumped_writes_timeseries_and_summary(tmp_path, capsys):
    assert main(["run", "demo-3p", "--solver", "lumped", "--duration", "0.01", "--speed", "1000",
                 "--output-dt", "2e-5", "--out", str(tmp_path)]) == 0
    df = pd.read_parquet(tmp_path / "timeseries.parquet")
    assert {"t", "stage1.ring.ay.world", "stage1.planet1.sun.force", "stage1.planet1.sun.dte"} <= set(df.columns)
    assert df["t"].iloc[-1] == pytest.approx(0.01, rel=1e-3)
    units = units_of(tmp_path / "timeseries.parquet")
    assert units["stage1.ring.ay.world"]["unit"] == "m/s^2" and units["stage1.planet1.sun.force"]["unit"] == "N"
    field = pq.read_schema(tmp_path / "timeseries.parquet").field("stage1.planet1.sun.force")  # per field too
    assert field.metadata[b"unit"] == b"N" and field.metadata[b"description"].decode() == units[field.name][
        "description"]
    assert main(["run", "demo-3p", "--duration", "0.01", "--speed", "1000", "--output-dt", "2e-5", "--format", "csv",
                 "--out", str(tmp_path / "csv")]) == 0
    csv = pd.read_csv(tmp_path / "csv" / "timeseries.csv")
    assert list(csv.columns) == list(df.columns)  # the same table, 9 significant digits
    np.testing.assert_allclose(csv.to_numpy(), df.to_numpy(), rtol=1e-8, atol=1e-12 * np.abs(df.to_numpy()).max())
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["solver"] == "lumped" and summary["info"]["method"] == "rk4"


def test_show_leaves_out_a_source_the_file_does_not_give(tmp_path, capsys):
    text = preset_text("demo-3p")
    path = tmp_path / "t.toml"
    path.write_text(re.sub(r'^source = .*$', 'source = ""', text, count=1, flags=re.M), encoding="utf-8")
    assert main(["show", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == f"  file: {path}" and not any("source:" in line for line in lines)


def test_verbose_tells_what_each_step_costs_and_quiet_leaves_errors_only(tmp_path, capsys, monkeypatch):
    """``-v`` logs every run's wall and CPU time and its work, ``-q`` silences notes (warnings) and progress;
    both at once are refused; the logger is left as it was."""
    assert main(["crosscheck", "demo-3p", "--duration", "0.05", "-v", "--out", str(tmp_path / "v")]) == 0
    err = capsys.readouterr().err
    assert re.search(r"^gearcheck: lumped run: \S+ s wall, \S+ s CPU$", err, re.M)
    assert re.search(r"^gearcheck: mujoco: mujoco-compiled, dt \S+ s, \d+ steps, \d+ right-hand-side calls$", err,
                     re.M)
    assert re.search(r"^gearcheck: demo-3p: 0.05 s simulated, steps \S+ s, \S+ s, from the static states$", err,
                     re.M)
    monkeypatch.setattr(settings, "LONG_STEPS", 100)  # every run is "long": a note on stderr
    run = ["run", "demo-3p", "--duration", "0.002", "--out", str(tmp_path / "r")]
    assert main(run) == 0
    assert "gearcheck: note: duration 0.002 s at the step" in capsys.readouterr().err
    assert main(run + ["-q"]) == 0
    assert capsys.readouterr().err == ""
    assert main(run + ["-q", "-v"]) == 2
    assert capsys.readouterr().err == "gearcheck: error: -v and -q: give one\n"
    logger = logging.getLogger("gearcheck")
    assert not logger.handlers and logger.level == logging.NOTSET and logger.propagate


def test_sensitivity_states_its_units_and_harmonic_notation(tmp_path, capsys):
    assert main(["sensitivity", "demo-3p", "--parameter", "stages[0].sun.mass", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "harmonic (k1, k2): the orders of the train's clocks" in out and "amplitudes in rad" in out
    frame = pd.read_csv(tmp_path / "sensitivity.csv")
    assert set(frame["amplitude_unit"]) == {"rad"} and list(frame["harmonic"][:2]) == ["(1,)", "(2,)"]
    assert main(["sensitivity", "demo-3p", "--parameter", "stages[0].sun.mass", "--coordinate", "stage1.sun.x",
                 "--out", str(tmp_path / "x")]) == 0
    assert set(pd.read_csv(tmp_path / "x" / "sensitivity.csv")["amplitude_unit"]) == {"m"}
