"""The command line: listing, showing, modes as JSON, a lumped run writing its files."""

import json
import logging
import re
import subprocess
import sys

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import gearcheck
from gearcheck import cli
from gearcheck.cli import main
from gearcheck.shared import settings
from gearcheck.train.loader import preset_text
from gearcheck.shared.results import units_of


def test_presets_lists_every_preset_with_its_source(capsys):
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    assert "demo-3p" in out and "demo-4p" in out and "gearcheck demo design" in out


HEAVY = {"numpy", "scipy", "mujoco", "numba", "pandas", "matplotlib"}


@pytest.mark.parametrize("flag", ["--version", "--help"])
def test_version_and_help_import_no_solver(flag):
    """``python -m gearcheck --version`` and ``--help`` answer without loading the numerical stack: the modules
    that ``-X importtime`` lists (every import of the process) include none of it."""
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "gearcheck", flag], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0 and ("gearcheck " in done.stdout), done.stderr[-2000:]
    imported = {line.rsplit("|", 1)[1].strip().split(".")[0] for line in done.stderr.splitlines()
                if line.startswith("import time:") and "|" in line}
    assert "gearcheck" in imported and not HEAVY & imported


def test_the_names_the_parser_offers_are_the_librarys():
    from gearcheck.compare.engine.crosscheck import MODELS

    assert cli.SOLVERS == tuple(gearcheck.SOLVERS) and ("general", *cli.PUBLISHED_MODELS) == MODELS


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


def test_sensitivity_against_a_parameters_values(tmp_path, capsys):
    """Yang, Chen & Wang's (2018) Figs. 6, 8, 10 as a command: d|Q_h|/dp at a constant speed over the parameter's
    values.  Its derivative is the slope of its own amplitudes: between two values 1 % apart the difference
    quotient equals the mean of the two derivatives to O(dp^2) (measured 6e-6 to 2e-4 relative: the third harmonic
    barely depends on the support, d ln|Q|/d ln p = -5e-7);
    at the file's own value it is the speed map's row at that speed to round-off."""
    from gearcheck.compare.studies.sensitivity import sensitivity_map
    from gearcheck.train.loader import read_train_text

    text, source = read_train_text("demo-3p")
    path = "stages[0].sun.support.radial_stiffness"
    k = 1.0e8  # the file's value
    frame = sensitivity_map(text, source, [path], [1500.0], "stage1.carrier.theta", values=[0.5 * k, 0.505 * k, k])
    over_speed = sensitivity_map(text, source, [path], [1500.0], "stage1.carrier.theta")
    for h, rows in frame.groupby("harmonic"):
        a, b, own = (rows[rows["value"] == v].iloc[0] for v in (0.5 * k, 0.505 * k, k))
        slope = (b["amplitude"] - a["amplitude"]) / (b["value"] - a["value"])
        mean = 0.5 * (a["d_amplitude_d_p"] + b["d_amplitude_d_p"])
        quotient_round_off = 1e-10 * a["amplitude"] / (b["value"] - a["value"])  # the solves' relative precision
        assert slope == pytest.approx(mean, rel=1e-3, abs=quotient_round_off), h
        speed_row = over_speed[over_speed["harmonic"] == h].iloc[0]
        assert own["d_amplitude_d_ln_p"] == pytest.approx(speed_row["d_amplitude_d_ln_p"], rel=1e-9, abs=1e-30), h
    assert main(["sensitivity", "demo-3p", "--parameter", path, "--values", "5e7", "1e8", "2e8", "--speeds",
                 "1000:2000:2", "--out", str(tmp_path)]) == 0
    written = pd.read_csv(tmp_path / "sensitivity_values.csv")
    assert len(written) == 2 * 3 * 3 and (tmp_path / "sensitivity_values.png").stat().st_size > 10_000
    assert main(["sensitivity", "demo-3p", "--parameter", path, "--parameter", "stages[0].sun.mass", "--values", "1",
                 "--out", str(tmp_path / "two")]) == 2
    assert "takes one parameter" in capsys.readouterr().err and not (tmp_path / "two").exists()
    # a number nothing depends on is said to be so: the RV reducer's in-phase planets never load the sun's
    # translations (its mass moves |Q_h| by 1e-26 relative, round-off)
    assert main(["sensitivity", "rv-reducer", "--parameter", "stages[0].sun.mass", "--values", "0.65", "1.3",
                 "--out", str(tmp_path / "null")]) == 0
    assert "does not depend on it" in capsys.readouterr().out
    assert pd.read_csv(tmp_path / "null" / "sensitivity_values.csv")["negligible"].all()
    assert not written["negligible"].all()
    # every value is a valid train before anything is computed: 2.8 mm undercuts the RV reducer's discs
    assert main(["sensitivity", "rv-reducer", "--parameter", "stages[0].crank.eccentricity_mm", "--values", "1.0",
                 "2.8", "--out", str(tmp_path / "undercut")]) == 2
    err = capsys.readouterr().err
    assert "eccentricity_mm = 2.8 is no valid train" in err and "undercut" in err and err.count("\n") == 1
    assert not (tmp_path / "undercut").exists()


def test_sensitivity_family_over_values_and_speeds(tmp_path):
    """Yang, Chen & Wang's (2018) Figs. 5, 7, 9 as a command: --values over a --speeds range, a family of curves over
    the mesh frequency, one per value.  At every speed the family's curve at the file's value is the speed map's to
    round-off, and its derivative is the slope of its own amplitudes across two values 1 % apart (the difference
    quotient equals the mean of the two derivatives to O(dp^2))."""
    from gearcheck.compare.studies.sensitivity import sensitivity_map
    from gearcheck.train.loader import read_train_text

    text, source = read_train_text("demo-3p")
    path = "stages[0].sun.support.radial_stiffness"
    k = 1.0e8  # the file's value
    speeds = [800.0, 1700.0, 2600.0]
    family = sensitivity_map(text, source, [path], speeds, "stage1.carrier.theta", values=[0.5 * k, 0.505 * k, k])
    over_speed = sensitivity_map(text, source, [path], speeds, "stage1.carrier.theta")
    assert len(family) == 3 * len(over_speed)
    for (rpm, h), rows in family.groupby(["speed_rpm", "harmonic"]):
        a, b, own = (rows[rows["value"] == v].iloc[0] for v in (0.5 * k, 0.505 * k, k))
        speed_row = over_speed[(over_speed["speed_rpm"] == rpm) & (over_speed["harmonic"] == h)].iloc[0]
        for column in ("mesh_frequency_hz", "amplitude", "d_amplitude_d_p"):
            assert own[column] == pytest.approx(speed_row[column], rel=1e-9, abs=1e-30), (rpm, h, column)
        slope = (b["amplitude"] - a["amplitude"]) / (b["value"] - a["value"])
        mean = 0.5 * (a["d_amplitude_d_p"] + b["d_amplitude_d_p"])
        quotient_round_off = 1e-10 * a["amplitude"] / (b["value"] - a["value"])  # the solves' relative precision
        assert slope == pytest.approx(mean, rel=1e-3, abs=quotient_round_off), (rpm, h)
    # the command: over 4 speeds the family alone (a line style per speed would not be read), up to 4 the
    # against-the-value figure, from 3 both
    command = ["sensitivity", "demo-3p", "--parameter", path, "--values", "5e7", "1e8"]
    assert main(command + ["--speeds", "1000:3000:5", "--out", str(tmp_path / "five")]) == 0
    assert sorted(p.name for p in (tmp_path / "five").glob("*.png")) == ["sensitivity_family.png"]
    assert (tmp_path / "five" / "sensitivity_family.png").stat().st_size > 10_000
    assert len(pd.read_csv(tmp_path / "five" / "sensitivity_values.csv")) == 5 * 2 * 3
    assert main(command + ["--speeds", "1000:3000:3", "--out", str(tmp_path / "three")]) == 0
    assert sorted(p.name for p in (tmp_path / "three").glob("*.png")) == ["sensitivity_family.png",
                                                                          "sensitivity_values.png"]
    assert main(command + ["--speeds", "1000:3000:2", "--out", str(tmp_path / "two")]) == 0
    assert sorted(p.name for p in (tmp_path / "two").glob("*.png")) == ["sensitivity_values.png"]
