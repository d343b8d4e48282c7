"""Calibration to natural frequencies and mode shapes (gearcheck.compare.studies.calibrate), from several starts.

The 'measurements' are the model's own modes at known parameter values, so the fit must return those values; the
parameter uncertainties are checked against the closed-form eigenvalue derivative of an added inertia (Fox &
Kapoor 1968), and Table 3 of Yang, Chen & Wang (2018) against an independent root-find on the mass matrix."""

import json
import tomllib
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.studies.measured_modes import pair
from gearcheck.compare.studies.multistart import SAME_MINIMUM
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.modal import modes
from gearcheck.train.loader import load_text, preset_text

RV = preset_text("rv-reducer")
PLATE, SHAFT, MOTOR = "stages[0].carrier.inertia", "operating.input_shaft_stiffness", "stages[0].sun.inertia"
TABLE3 = gearcheck.__file__.replace("__init__.py", "train/presets/data/rv-reducer-table3.toml")


def rv_model(carrier=0.106, shaft=1.16e4, sun=4.44e-4):
    text = (RV.replace("inertia = 0.106", f"inertia = {carrier!r}")
            .replace("input_shaft_stiffness = 1.16e4", f"input_shaft_stiffness = {shaft!r}")
            .replace("inertia = 4.44e-4", f"inertia = {sun!r}"))
    return build_model(load_text(text, "truth"))


def measured(model, numbers, shape_of=(), coordinates=()):
    """The model's own frequencies of the modes ``numbers`` (1-based), by number; those in ``shape_of`` with their
    shape over ``coordinates`` (paired by shape alone when ``numbers`` is empty)."""
    modal, labels = modes(model), model.dofs.labels()
    entries = []
    for k in sorted(set(numbers) | set(shape_of)):
        entry = {"frequency_hz": float(modal.frequencies[k - 1])}
        if k in numbers:
            entry["mode"] = k
        if k in shape_of:
            entry["shape"] = {c: float(modal.shapes[labels.index(c), k - 1]) for c in coordinates}
        entries.append(entry)
    return {"natural_frequencies": entries}


def test_known_inertias_are_recovered_with_the_closed_form_uncertainties():
    """The plate and motor inertias that made modes 1 and 2 come back to 1e-9, from the file's values; their
    uncertainties are the measurements' 1 % through d ln f_i / d ln J_j = -J_j phi_ij^2 / 2, phi mass-normalised
    at the rotation the inertia adds to (the eigenvalue derivative for dM/dJ = e e^T)."""
    truth = rv_model(carrier=5.0, sun=1e-3)
    fit = gearcheck.calibrate("rv-reducer", [f"{PLATE}=0.106:100", f"{MOTOR}=4.44e-4:4.44e-3"],
                              measurements=measured(truth, [1, 2]))
    assert fit.fitted == pytest.approx([5.0, 1e-3], rel=1e-10)
    modal = modes(truth)
    dofs = [truth.dofs("rv.carrier", "theta"), truth.dofs("rv.sun", "theta")]
    jacobian = np.array([[-0.5 * j * modal.shapes[d, i] ** 2 / 0.01 for j, d in zip((5.0, 1e-3), dofs)]
                         for i in (0, 1)])
    closed_form = np.sqrt(np.diag(np.linalg.inv(jacobian.T @ jacobian)))
    assert fit.relative_uncertainty == pytest.approx(closed_form, rel=1e-6)
    assert [r["error_after"] for r in fit.rows()] == pytest.approx([0, 0], abs=1e-12)


def test_a_single_start_stops_on_the_mirror_and_multistart_finds_the_truth():
    """The plate's mode (output against the bearings) and the input side's (sun against its shaft k_st) swap order
    as the plate inertia and k_st move: with modes 1 and 2 by number, a mirror point where each mode takes the
    other's frequency fits both frequencies exactly.  Mode 1's measured shape over the sun's and carrier's rotation
    tells them apart, so the mirror is a local minimum only.  From the file's values (a light output, the input
    mode lowest) the fit slides into the mirror; the 16 starts find the truth and report the mirror beside it."""
    truth = rv_model(carrier=5.0, shaft=9000.0)
    data = measured(truth, [1, 2], shape_of=[1], coordinates=["rv.sun.theta", "rv.carrier.theta"])
    fits = [f"{PLATE}=0.01:100", f"{SHAFT}=100:1e6"]
    single = gearcheck.calibrate("rv-reducer", fits, measurements=data, starts=1)
    mirror = single.rows()
    assert [r["error_after"] for r in mirror] == pytest.approx([0, 0], abs=1e-3)  # both frequencies fit ...
    assert mirror[0]["mac"] < 0.2  # ... by the other mode
    assert single.search.minima[0].chi2 > 25
    assert not single.fitted == pytest.approx([5.0, 9000.0], rel=0.1)

    multi = gearcheck.calibrate("rv-reducer", fits, measurements=data)
    assert len(multi.search.starts) == 16
    assert multi.fitted == pytest.approx([5.0, 9000.0], rel=1e-9)
    assert multi.rows()[0]["mac"] == pytest.approx(1, abs=1e-12)
    assert multi.search.minima[0].chi2 < 1e-12 and len(multi.search.as_good) == 1
    assert 1 <= multi.starts_at_best < 16
    assert any(np.all(np.abs(m.x - single.search.best.x) <= SAME_MINIMUM) for m in multi.search.minima[1:])


def test_frequencies_alone_do_not_decide_and_the_report_says_so():
    """Without the shape, the truth and its mirror fit the two frequencies equally (chi^2 of round-off): the
    calibration finds both and says the measurements do not decide between them."""
    truth = rv_model(carrier=5.0, shaft=9000.0)
    fit = gearcheck.calibrate("rv-reducer", [f"{PLATE}=0.01:100", f"{SHAFT}=100:1e6"],
                              measurements=measured(truth, [1, 2]))
    found = sorted(np.exp(m.x[0]) for m in fit.search.as_good)
    assert len(found) == 2 and found[1] == pytest.approx(5.0, rel=1e-9) and found[0] < 1.0


def test_measured_shapes_pair_the_modes_whatever_their_order():
    """Paired by their shapes over the rotations (not by number), modes 1 and 2 have no mirror: one start from the
    file's values, where the two modes are in the other order, reaches the truth."""
    truth = rv_model(carrier=5.0, shaft=9000.0)
    rotations = [label for label in truth.dofs.labels() if label.endswith(".theta")]
    fit = gearcheck.calibrate("rv-reducer", [f"{PLATE}=0.01:100", f"{SHAFT}=100:1e6"],
                              measurements=measured(truth, [], shape_of=[1, 2], coordinates=rotations), starts=1)
    assert fit.fitted == pytest.approx([5.0, 9000.0], rel=1e-9)
    assert [r["model_mode"] for r in fit.rows()] == [1, 2]
    assert [r["mac"] for r in fit.rows()] == pytest.approx([1, 1], abs=1e-12)


def test_type_and_order_follow_a_rotational_mode_past_a_translational_one():
    """demo-3p's rotational frequencies depend on the ring's torsional support and its translational ones do not
    (Lin & Parker 1999: the central members only turn in a rotational mode, only translate in a translational one).
    Four times stiffer, the second rotational frequency climbs past the second translational pair, so that its mode
    number changes; paired by type and order, one start recovers the support, and every translational frequency
    stays where it was."""
    text = preset_text("demo-3p")
    support = "torsional_stiffness = 7.64e6"
    base = modes(build_model(load_text(text, "demo")))
    truth = modes(build_model(load_text(text.replace(support, "torsional_stiffness = 3.0e7"), "truth")))
    second = [i for i, t in enumerate(truth.types) if t == "rotational"][1]
    assert second > [i for i, t in enumerate(base.types) if t == "rotational"][1]  # past a translational pair
    fit = gearcheck.calibrate("demo-3p", ["stages[0].ring.support.torsional_stiffness=1e6:1e9"], starts=1,
                              measurements={"natural_frequencies": [
                                  {"frequency_hz": float(truth.frequencies[second]), "type": "rotational",
                                   "order": 2}]})
    assert fit.fitted[0] == pytest.approx(3.0e7, rel=1e-9)
    assert fit.rows()[0]["model_mode"] == second + 1
    after = modes(build_model(load_text(fit.text(), "fitted")))
    translational = [f for f, t in zip(after.frequencies, after.types) if t == "translational"]
    assert translational == pytest.approx([f for f, t in zip(base.frequencies, base.types) if t == "translational"],
                                          rel=1e-12)


def plate_for(model, target):
    """The inertia added to the output's rotation that puts the lowest mode at ``target`` Hz (the mass matrix edited
    directly, as examples/rv_reducer_table3.py did before the calibration machinery)."""
    def lowest(j):
        M = model.M.copy()
        i = model.dofs("rv.carrier", "theta")
        M[i, i] += j
        return modes(replace(model, M=M)).frequencies[:2]
    j = brentq(lambda x: lowest(x)[0] - target, 1e-3, 1e3, xtol=1e-12)
    return j, lowest(j)[1]


def test_table3_as_a_command(tmp_path, capsys):
    """`gearcheck calibrate rv-reducer --measurements rv-reducer-table3.toml --fit carrier inertia`: the plate
    calibrated on the test's 148.95 Hz is the root-find's 7.003 kg m^2 on top of the file's 0.106, from all 16
    starts; the test's 681.47 Hz is predicted at 702.63 Hz (+3.11 %), the paper's own model at +2.30 %."""
    out = tmp_path / "out"
    assert main(["calibrate", "rv-reducer", "--measurements", TABLE3, "--fit", f"{PLATE}=0.106:100",
                 "--out", str(out)]) == 0
    data = json.loads((out / "calibration.json").read_text())
    plate, predicted = plate_for(build_model(load_text(RV, "rv")), 148.95)
    assert plate == pytest.approx(7.003, abs=5e-4)
    assert data["parameters"][0]["fitted"] == pytest.approx(0.106 + plate, rel=1e-9)
    assert data["parameters"][0]["relative_uncertainty"] == pytest.approx(0.02, rel=0.05)  # f ~ J^-1/2: 2 x 1 %
    assert data["starts"] == data["starts_at_best"] == 16 and len(data["minima"]) == 1
    fitted, prediction = data["measurements"]
    assert (fitted["role"], prediction["role"]) == ("fit", "prediction")
    assert fitted["after"] == pytest.approx(148.95, rel=1e-10)
    assert prediction["after"] == pytest.approx(predicted, rel=1e-9)
    assert round(100 * prediction["error_after"], 2) == 3.11
    assert round(100 * prediction["error_published_model"], 2) == 2.30
    assert "| natural frequency, mode 2 (model mode 2) | — | prediction | 681.47 |" in capsys.readouterr().out
    written = tomllib.loads((out / "rv-reducer-calibrated.toml").read_text())["stages"][0]["carrier"]["inertia"]
    assert written == pytest.approx(0.106 + plate, rel=1e-9)


def test_a_train_files_measurements_file_brings_its_natural_frequencies(tmp_path):
    """A train file whose measurements_file holds natural frequencies is calibrated on them without
    --measurements: the same plate as Table 3's file given on the command line."""
    (tmp_path / "table3.toml").write_text(open(TABLE3, encoding="utf-8").read(), encoding="utf-8")
    train = tmp_path / "rv.toml"
    train.write_text(RV.replace('output = "rv.carrier"', 'output = "rv.carrier"\nmeasurements_file = "table3.toml"'),
                     encoding="utf-8")
    own = gearcheck.calibrate(train, [f"{PLATE}=0.106:100"])
    given = gearcheck.calibrate("rv-reducer", [f"{PLATE}=0.106:100"], measurements=TABLE3)
    assert [r["role"] for r in own.rows()] == ["fit", "prediction"]
    assert own.fitted == pytest.approx(given.fitted, rel=1e-12)


def test_a_shape_over_the_central_rotations_has_no_share_in_a_translational_mode():
    """The central members do not turn in a translational mode (Lin & Parker 1999): their rotations there are
    round-off (1e-14), and a shape measured over them has no share in the pair, however that round-off points."""
    model = build_model(load_text(preset_text("demo-3p"), "demo-3p"))
    modal = modes(model)
    assert modal.types[1:3] == ["translational"] * 2
    entry = {"mode": 2, "type": None, "order": None, "where": "m.toml: natural_frequencies[0]",
             "shape": {f"stage1.{m}.theta": 1.0 for m in ("sun", "ring", "carrier")}}
    assert pair([entry], modal, model.dofs.labels(), model.M)[0].mac < 1e-12
