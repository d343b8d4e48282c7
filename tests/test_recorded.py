"""Another solver's results read back: time series and modes of the reference model written as a user's
files would hold them (renamed columns, other units, other coordinate orders) come back equal in SI, the
files feed a RecordedSide the mode pairing accepts, and every bad file or map is one line naming the file
and what is wrong."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import scipy.io

import gearcheck
from gearcheck.compare.engine.mode_pairing import pair_modes
from gearcheck.compare.engine.recorded import RecordedSide, read_column_map, read_modes, read_time_series
from gearcheck.lumped.side import LumpedSide
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.results import train_signals
from gearcheck.shared.settings import RunSettings

SPEC = gearcheck.load("demo-3p")
MAP_TOML = """\
solver = "simulink"
time = "time_ms"
time_unit = "ms"
[signals]
"stage1.carrier.alpha" = "alpha_c"
"stage1.ring.ay.world" = { column = "ay_ring", unit = "mm/s^2" }
"stage1.planet1.sun.force" = { column = "F_sp1", scale = -1.0, unit = "kN" }
"stage1.planet2.ring.dte" = { column = "dte_rp2", unit = "um" }
"""
COLUMNS = {"alpha_c": ("stage1.carrier.alpha", 1.0), "ay_ring": ("stage1.ring.ay.world", 1e3),
           "F_sp1": ("stage1.planet1.sun.force", -1e-3), "dte_rp2": ("stage1.planet2.ring.dte", 1e6)}


@pytest.fixture(scope="module")
def lumped():
    side = LumpedSide(SPEC)
    return side, side.run(RunSettings(0.02, None))


def write_series(run, path):
    """The run's mapped signals as the other solver's file would hold them: renamed, in other units."""
    columns = {"time_ms": run.t * 1e3, **{c: run[name] * f for c, (name, f) in COLUMNS.items()}}
    if path.suffix == ".csv":
        pd.DataFrame(columns).to_csv(path, index=False)
    elif path.suffix == ".parquet":
        pd.DataFrame(columns).to_parquet(path)
    else:  # one variable per column, row and column vectors
        scipy.io.savemat(path, {c: (x[:, None] if c == "F_sp1" else x) for c, x in columns.items()})


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mat"])
@pytest.mark.parametrize("as_file", [True, False], ids=["toml", "dict"])
def test_time_series_round_trip(lumped, tmp_path, suffix, as_file):
    _, run = lumped
    path = tmp_path / f"sim{suffix}"
    write_series(run, path)
    (tmp_path / "map.toml").write_text(MAP_TOML)
    columns = tmp_path / "map.toml" if as_file else read_column_map(tmp_path / "map.toml")
    got = read_time_series(path, SPEC, columns)
    names = [s.name for s in train_signals(SPEC) if s.name in {n for n, _ in COLUMNS.values()}]
    assert got.names() == names and got.signals == [run.signal(n) for n in names]
    assert got.solver == "simulink" and got.train == SPEC.name and got.settle_time == 0.0 and not got.static
    np.testing.assert_allclose(got.t, run.t, rtol=1e-12, atol=0)
    for name in names:
        np.testing.assert_allclose(got[name], run[name], rtol=1e-12, atol=0, err_msg=name)
    assert got.info["dt_s"] == pytest.approx(run.info["dt_s"], rel=1e-12)
    assert got.info["source"] == path.name and got.info["start_s"] == 0.0 and got.info["samples"] == run.t.size


def test_a_recorded_side_returns_its_recording(lumped, tmp_path):
    _, run = lumped
    data = pd.DataFrame({"t": 1.5 + run.t, "a": run["stage1.carrier.alpha"]})
    data.to_csv(tmp_path / "own_code.csv", index=False)
    side = RecordedSide(SPEC, tmp_path / "own_code.csv", {"signals": {"stage1.carrier.alpha": "a"}})
    assert side.solver == "own_code" and side.references == () and side.rerunnable is False and not side.has_modes
    got = side.run(RunSettings(0.03, 1e-6))  # any settings: the recording, longer than half of it
    assert got.t[0] == 0.0 and got.info["start_s"] == 1.5 and side.duration == pytest.approx(run.t[-1], rel=1e-9)
    np.testing.assert_array_equal(got["stage1.carrier.alpha"], run["stage1.carrier.alpha"])
    assert side.stable_step() == got.info["dt_s"]
    with pytest.raises(GearcheckError, match=r"own_code\.csv: .* lasts 0\.02\d* s, less than 50% of the 0\.05 s"):
        side.run(RunSettings(0.05))
    with pytest.raises(GearcheckError, match="no modes file"):
        side.modes()


def write_modes(path, frequencies, labels, shapes, mass, cell):
    """A modes file; in a .mat the coordinates as a cell array or as a char matrix (rows padded with blanks)."""
    if path.suffix == ".npz":
        np.savez(path, frequencies=frequencies, shapes=shapes, coordinates=np.array(labels), mass=mass)
    else:
        scipy.io.savemat(path, {"frequencies": frequencies, "shapes": shapes, "mass": mass,
                                "coordinates": np.array(labels, dtype=object) if cell else labels})


@pytest.mark.parametrize("suffix, cell", [(".npz", False), (".mat", True), (".mat", False)],
                         ids=["npz", "mat-cell", "mat-char"])
def test_modes_round_trip(lumped, tmp_path, suffix, cell):
    side, _ = lumped
    modal = side.modes()
    labels, M, shapes = side.physical_modes(modal)
    rows = np.random.default_rng(1).permutation(len(labels))  # the other solver's coordinate order
    path = tmp_path / f"eig{suffix}"
    write_modes(path, modal.frequencies, [labels[i] for i in rows], shapes[rows], M[np.ix_(rows, rows)], cell)
    got, got_labels, got_mass = read_modes(path, SPEC)
    assert got_labels == labels == got.dof_labels and got.solver == "eig" and got.train == SPEC.name
    np.testing.assert_array_equal(got.frequencies, modal.frequencies)
    np.testing.assert_array_equal(got.shapes, shapes)
    np.testing.assert_array_equal(got_mass, M)
    assert got.types == modal.types and got.multiplicity == modal.multiplicity
    np.testing.assert_allclose(got.fractions, modal.fractions, rtol=1e-12, atol=1e-14)


def test_recorded_modes_pair_with_the_reference(lumped, tmp_path):
    """Modes in reverse order, without a mass: sorted back, and every reference mode finds its partner."""
    side, run = lumped
    modal = side.modes()
    labels, _, shapes = side.physical_modes(modal)
    np.savez(tmp_path / "eig.npz", frequencies=modal.frequencies[::-1], shapes=shapes[:, ::-1], coordinates=labels)
    pd.DataFrame({"t": run.t, "a": run["stage1.carrier.alpha"]}).to_csv(tmp_path / "sim.csv", index=False)
    recorded = RecordedSide(SPEC, tmp_path / "sim.csv", {"solver": "matlab", "signals": {"stage1.carrier.alpha": "a"}},
                            tmp_path / "eig.npz")
    assert recorded.has_modes and recorded.modes().solver == "matlab" and recorded.modes().types == modal.types
    assert recorded.physical_modes(recorded.modes())[1] is None
    pairing = pair_modes(SPEC.name, side, recorded)
    assert pairing.findings == [] and np.allclose(pairing.paired, 1.0, atol=1e-9)


def test_frequencies_only_and_a_subset_of_coordinates(lumped, tmp_path):
    side, _ = lumped
    modal = side.modes()
    modal.to_dataframe().to_csv(tmp_path / "freq.csv", index=False)
    got, labels, mass = read_modes(tmp_path / "freq.csv", SPEC)
    np.testing.assert_array_equal(got.frequencies, modal.frequencies)
    assert labels == [] and mass is None and got.shapes.shape == (0, len(modal)) and set(got.types) == {"elastic"}
    all_labels, _, shapes = side.physical_modes(modal)
    keep = [i for i, label in enumerate(all_labels) if label.endswith(".theta")][::-1]
    np.savez(tmp_path / "torsion.npz", frequencies=modal.frequencies, shapes=shapes[keep],
             coordinates=[all_labels[i] for i in keep])
    got, labels, _ = read_modes(tmp_path / "torsion.npz", SPEC)
    assert labels == [all_labels[i] for i in sorted(keep)]
    np.testing.assert_array_equal(got.shapes, shapes[sorted(keep)])


# --- bad inputs: each one line naming the file and what is wrong -------------------------------------------

GOOD_CSV = "t,ay,alpha\n0,1,2\n0.001,1,2\n0.002,1,2\n0.003,1,2\n0.004,1,2\n"
GOOD_MAP = {"signals": {"stage1.ring.ay.world": "ay", "stage1.carrier.alpha": "alpha"}}
FREQUENCIES = np.array([100.0, 200.0])
SHAPES = np.eye(18)[:, :2]
LABELS = LumpedSide(SPEC).model.dofs.labels()


def series(tmp, name="sim.csv", text=GOOD_CSV, columns=GOOD_MAP):
    path = tmp / name
    path.write_text(text)
    return read_time_series(path, SPEC, columns)


def rows(*lines):
    return "t,ay,alpha\n" + "".join(f"{line}\n" for line in lines)


def with_map(tmp, toml):
    (tmp / "map.toml").write_text(toml)
    return series(tmp, columns=tmp / "map.toml")


def mat(tmp, variables, columns=GOOD_MAP):
    scipy.io.savemat(tmp / "sim.mat", variables)
    return read_time_series(tmp / "sim.mat", SPEC, columns)


def npz(tmp, **arrays):
    np.savez(tmp / "eig.npz", **{"frequencies": FREQUENCIES, "shapes": SHAPES, "coordinates": LABELS, **arrays})
    return read_modes(tmp / "eig.npz", SPEC)


def garbage(tmp, name, read):
    (tmp / name).write_bytes(b"\x00garbage\xff")
    return read(tmp / name)


BAD = [
    pytest.param(lambda tmp: read_time_series(tmp / "nope.csv", SPEC, GOOD_MAP), ["nope.csv", "no such data file"],
                 id="missing-file"),
    pytest.param(lambda tmp: series(tmp, "sim.xlsx"), ["sim.xlsx", "'.xlsx'", ".csv, .parquet, .mat"], id="suffix"),
    pytest.param(lambda tmp: garbage(tmp, "sim.parquet", lambda p: read_time_series(p, SPEC, GOOD_MAP)),
                 ["sim.parquet", "cannot be read as .parquet"], id="unreadable-parquet"),
    pytest.param(lambda tmp: garbage(tmp, "sim.mat", lambda p: read_time_series(p, SPEC, GOOD_MAP)),
                 ["sim.mat", "cannot be read as .mat"], id="unreadable-mat"),
    pytest.param(lambda tmp: series(tmp, columns={**GOOD_MAP, "time": "time"}),
                 ["sim.csv", "column 'time'", "not in the file", "'ay'"], id="no-time-column"),
    pytest.param(lambda tmp: with_map(tmp, '[signals]\n"stage1.sun-planet1.force" = "ay"\n'),
                 ["map.toml", 'signals."stage1.sun-planet1.force"', "did you mean", "stage1.planet1.sun.force"],
                 id="unknown-signal"),
    pytest.param(lambda tmp: series(tmp, columns={"signals": {"stage1.ring.ay.world": "F_x"}}),
                 ["sim.csv", "column 'F_x'", "not in the file"], id="missing-column"),
    pytest.param(lambda tmp: series(tmp, text=rows("0,1,2", "0.001,1,2", "0.002,abc,2")),
                 ["sim.csv", "column 'ay'", "row 3", "'abc'"], id="not-a-number"),
    pytest.param(lambda tmp: series(tmp, text=rows("0,1,2", "0.001,1,", "0.002,1,2")),
                 ["sim.csv", "column 'alpha'", "row 2", "nan"], id="empty-cell"),
    pytest.param(lambda tmp: series(tmp, text=rows("0,1,2", "0.001,1,2", "0.002,1,-inf")),
                 ["sim.csv", "column 'alpha'", "row 3", "-inf"], id="infinite"),
    pytest.param(lambda tmp: series(tmp, text=rows("0,1,2", "0.002,1,2", "0.001,1,2", "0.003,1,2")),
                 ["sim.csv", "column 't'", "not strictly increasing at row 3", "0.001 s after 0.002 s"],
                 id="time-backwards"),
    pytest.param(lambda tmp: series(tmp, text=rows("0,1,2", "0.001,1,2", "0.0021,1,2", "0.003,1,2")),
                 ["sim.csv", "column 't'", "not uniform", "row 3", "fixed sample time"], id="time-non-uniform"),
    pytest.param(lambda tmp: series(tmp, text=rows("0,1,2")), ["sim.csv", "column 't'", "1 sample"],
                 id="one-sample"),
    pytest.param(lambda tmp: with_map(tmp, 'time = "t"\n[signals]\n'), ["map.toml", "signals", "maps no signal"],
                 id="empty-map"),
    pytest.param(lambda tmp: series(tmp, columns={"signals": {"stage1.ring.ay.world": {"column": "ay",
                                                                                        "unit": "furlong/s^2"}}}),
                 ["sim.csv", 'signals."stage1.ring.ay.world".unit', "'furlong/s^2'", "mm/s^2, g"], id="unit"),
    pytest.param(lambda tmp: with_map(tmp, 'time_unit = "h"\n[signals]\n"stage1.carrier.alpha" = "alpha"\n'),
                 ["map.toml", "time_unit", "'h'"], id="time-unit"),
    pytest.param(lambda tmp: with_map(tmp, '[signals]\n"stage1.carrier.alpha" = { column = "alpha", scale = 0 }\n'),
                 ["map.toml", 'signals."stage1.carrier.alpha".scale', "0"], id="scale"),
    pytest.param(lambda tmp: with_map(tmp, 'sigals = 1\n'), ["map.toml", "sigals", "unknown key"], id="map-key"),
    pytest.param(lambda tmp: with_map(tmp, '[signals\n'), ["map.toml", "not valid TOML"], id="map-toml"),
    pytest.param(lambda tmp: mat(tmp, {"t": np.arange(5.0), "ay": np.ones((3, 5)), "alpha": np.ones(5)}),
                 ["sim.mat", "variable 'ay'", "3x5 array, not a vector"], id="mat-matrix"),
    pytest.param(lambda tmp: mat(tmp, {"t": np.arange(5.0), "ay": np.ones(4), "alpha": np.ones(5)}),
                 ["sim.mat", "variable 'ay'", "has 4 values", "5"], id="mat-length"),
    pytest.param(lambda tmp: mat(tmp, {"t": np.arange(5.0), "ay": "fast", "alpha": np.ones(5)}),
                 ["sim.mat", "variable 'ay'", "'fast'"], id="mat-text"),
    pytest.param(lambda tmp: npz(tmp, frequencies=[100.0, -1.0]), ["eig.npz", "variable 'frequencies'", "-1 Hz"],
                 id="negative-frequency"),
    pytest.param(lambda tmp: npz(tmp, frequencies=[100.0, np.nan]),
                 ["eig.npz", "variable 'frequencies'", "value 2", "nan"], id="nan-frequency"),
    pytest.param(lambda tmp: npz(tmp, shapes=SHAPES[:, :1]), ["eig.npz", "variable 'shapes'", "18x1", "18x2"],
                 id="shapes-size"),
    pytest.param(lambda tmp: npz(tmp, coordinates=["stage1.sun.q", *LABELS[1:]]),
                 ["eig.npz", "variable 'coordinates'", "'stage1.sun.q'", "stage1.sun.x"], id="unknown-coordinate"),
    pytest.param(lambda tmp: npz(tmp, coordinates=[LABELS[0], *LABELS[:-1]]),
                 ["eig.npz", "variable 'coordinates'", "'stage1.sun.x' appears twice"], id="duplicate-coordinate"),
    pytest.param(lambda tmp: npz(tmp, mass=np.eye(18) + np.triu(np.ones((18, 18)), 1)),
                 ["eig.npz", "variable 'mass'", "not symmetric"], id="mass-asymmetric"),
    pytest.param(lambda tmp: npz(tmp, mass=-np.eye(18)), ["eig.npz", "variable 'mass'", "not positive definite"],
                 id="mass-indefinite"),
    pytest.param(lambda tmp: npz(tmp, shapes=np.column_stack([SHAPES[:, 0], np.zeros(18)])),
                 ["eig.npz", "variable 'shapes'", "mode 2 is zero"], id="zero-shape"),
    pytest.param(lambda tmp: (np.savez(tmp / "eig.npz", frequencies=FREQUENCIES, shapes=SHAPES),
                              read_modes(tmp / "eig.npz", SPEC)),
                 ["eig.npz", "variable 'coordinates'", "missing"], id="shapes-without-coordinates"),
    pytest.param(lambda tmp: garbage(tmp, "eig.npz", lambda p: read_modes(p, SPEC)),
                 ["eig.npz", "not an .npz archive"], id="npz-garbage"),
    pytest.param(lambda tmp: (pd.DataFrame({"f": [1.0]}).to_csv(tmp / "freq.csv"), read_modes(tmp / "freq.csv", SPEC)),
                 ["freq.csv", "column 'frequency_hz'", "not in the file"], id="modes-csv-column"),
]


@pytest.mark.parametrize("read, fragments", BAD)
def test_bad_input_is_one_line_naming_file_and_field(tmp_path, read, fragments):
    with pytest.raises(GearcheckError) as caught:
        read(tmp_path)
    message = str(caught.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
