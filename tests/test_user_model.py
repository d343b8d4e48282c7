"""A user's own model through the front door: as matrices in Python or in a .mat/.npz file, as a factory
named on the command line, as another solver's time series; the published 4-DOF models through the same
door.  Physics: the reference exported and read back is the reference (modes to round-off, the cross-check
passes); a torsional model derived by hand is the reference constrained to rigid translations; bad files
end in one line and exit status 2 with nothing written."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.io

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.engine.align import STEADY_THRESHOLD
from gearcheck.compare.engine.mode_pairing import pair_modes
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.export import reference_linear_model, write_matrix_file
from gearcheck.lumped.linear_model import LinearModel, Periodic
from gearcheck.lumped.matrix_file import read_matrix_file
from gearcheck.lumped.side import LinearSide, LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.settings import RunSettings
from gearcheck.train.periods import common_period
from gearcheck.train.variants import edited, edited_text

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
TORSIONAL = f"{EXAMPLES / 'torsional_user_model.py'}:torsional_model"


@pytest.mark.parametrize("suffix", [".mat", ".npz"])
@pytest.mark.parametrize("preset", ["demo-3p", "helical-planetary"])
def test_exported_reference_reads_back_as_the_reference(tmp_path, preset, suffix):
    """Modes to round-off (every sample held over its cell; their mean is the exact mean stiffness) and each
    reference mode lies in its own partner's span to 1e-9."""
    spec = gearcheck.load(preset)
    path = tmp_path / f"model{suffix}"
    write_matrix_file(reference_linear_model(spec), path)
    side = LinearSide(read_matrix_file(path), spec)
    reference = LumpedSide(spec)
    fa, fb = reference.modes().frequencies, side.modes().frequencies
    np.testing.assert_allclose(fb, fa, rtol=1e-12, atol=1e-9)
    assert pair_modes(spec.name, reference, side).paired.min() > 1 - 1e-9
    assert side.modes().types == reference.modes().types


def test_exported_reference_passes_the_crosscheck(tmp_path):
    """The file route end to end: the reference as a .mat of held stiffness samples passes against the
    reference; the planet bearing forces it has no rows for are named as not compared."""
    path = tmp_path / "demo.mat"
    write_matrix_file(reference_linear_model(gearcheck.load("demo-3p")), path)
    result = gearcheck.crosscheck("demo-3p", model=str(path), duration=0.05)
    assert result.verdict == "PASS", result.failures
    gated = [q for q in result.quantities if q.status != "negligible"]
    assert len(gated) >= 20
    assert any("bearing_radial.force" in note for note in result.notes)
    assert max(m["rel_error"] for m in result.modal) < 1e-12
    report = result.write(tmp_path / "report")  # a PASS against its own export shows no red row
    lines = [s for q in report["quantities"] for s in q["spectrum"]]
    assert not [s for s in lines if s["status"] == "fail"]
    assert set(report["volatile"]["cpu_time"]) == {"lumped_modes_s", "test_modes_s", "lumped_run_s", "lumped_check_s",
                                                   "test_run_s", "test_check_s"}  # the user's model is no "mujoco"
    assert 'class="fail"' not in (tmp_path / "report" / "report.html").read_text()
    # the lines whose relative error exceeds their tolerance (the held samples move a jump by up to 1/SAMPLES of a
    # mesh period, which the phasing of the sun's lines does not forgive) carry under a tenth of it
    beyond = [(s, q) for q in report["quantities"] for s in q["spectrum"] if s["status"] == "pass" and s["rel_error"]
              and q["tolerance_nrmse"] and abs(s["rel_error"]["value"]) > q["tolerance_nrmse"]["value"]]
    assert beyond and all(s["nrmse_part"]["value"] < 0.1 * q["tolerance_nrmse"]["value"] for s, q in beyond)


EXCITED = [(r"^damping = \{ ratio = 0.05 \}",
            "damping = { ratio = 0.05 }\nste = [{ harmonic = 1, amplitude_um = 4.0 }]"),
           (r"^input_shaft_damping = .*", "input_shaft_damping = 2.0\n[[operating.ripple]]\nmember = \"output\"\n"
                                          "order = 3.0\namplitude = 0.05")]


def test_exported_reference_with_transmission_error_and_ripple(tmp_path, capsys):
    """Transmission error and torque ripple travel in the file: each mesh's error (``mesh_error``) and the
    torques' forcing (``F_samples``) sampled over the drive's common period (62 mesh periods: the ripple at 3x
    the carrier speed is 3/62 of the mesh frequency), exact at the samples; read back, the model passes against
    the reference with its mesh forces measured from the error (without it, the forces differ by k e: measured
    NRMSE 0.5).  A drive that never repeats (a load ramp) cannot be written: one line, exit 2, nothing written."""
    spec = edited("demo-3p", EXCITED, "excited")
    path = tmp_path / "excited.mat"
    model = reference_linear_model(spec)
    write_matrix_file(model, path)
    data = scipy.io.loadmat(path, squeeze_me=True)
    exc = build_model(spec).excitation
    period = common_period(exc)
    assert data["period"] == pytest.approx(period, rel=1e-15) and period * exc.frequency[0] == pytest.approx(62)
    times = np.arange(data["mesh_error"].shape[1]) * period / data["mesh_error"].shape[1]
    np.testing.assert_allclose(data["mesh_error"].T, exc.transmission_error(times)[0], rtol=0, atol=1e-18)
    np.testing.assert_allclose(data["F_samples"].T, [model.forcing(t) for t in times], rtol=1e-15, atol=1e-9)
    result = gearcheck.crosscheck(spec, model=str(path), duration=0.05)
    assert result.verdict == "PASS", result.failures
    forces = [q.metrics["nrmse"] for q in result.quantities if q.name.endswith(".force") and q.status == "pass"]
    assert len(forces) == 6 and max(forces) < 0.01
    train = tmp_path / "ramped.toml"
    train.write_text(edited_text("demo-3p", [*EXCITED, (r"^output_torque = 1500.0", "output_torque = 1500.0\n"
                                                                                    "ramp_s = 0.01")]))
    assert main(["export", str(train), "-o", str(tmp_path / "ramped.mat")]) == 2
    err = capsys.readouterr().err.strip()
    assert "transmission error" in err and "the load ramp over the first 0.01 s never repeats" in err, err
    assert "\n" not in err
    assert not (tmp_path / "ramped.mat").exists()


def test_torsional_model_is_the_reference_with_rigid_translations():
    """The hand-derived torsional model (examples/) equals the reference's K and M projected onto its map
    (planet centres riding their pins, every other translation held): M and mean K to round-off."""
    sys.path.insert(0, str(EXAMPLES))
    try:
        from torsional_user_model import torsional_model
    finally:
        sys.path.remove(str(EXAMPLES))
    spec = gearcheck.load("demo-3p")
    side = LinearSide(torsional_model(spec), spec)
    reference = LumpedSide(spec).model
    T, _ = side.linear.to_physical(reference.dofs.labels())
    np.testing.assert_allclose(T.T @ reference.M @ T, side.linear.M, rtol=1e-14, atol=1e-15)
    K = T.T @ reference.K_mean @ T
    np.testing.assert_allclose(side.linear.K_mean, K, rtol=1e-12, atol=1e-12 * np.abs(K).max())
    # fewer coordinates, fewer modes: the rotational ones are stiffened by the held translations
    f_user, f_ref = side.modes().frequencies, LumpedSide(spec).modes().frequencies
    assert len(f_user) == 6 and len(f_ref) == 18
    assert 1.0 < f_user[0] / f_ref[0] < 1.05


def test_factory_on_the_command_line(tmp_path, capsys):
    """--model file.py:factory: the torsional model is compared on the quantities it has; its modes are paired
    by shape; it fails, and says which quantities it does not report."""
    status = main(["crosscheck", "demo-3p", "--model", TORSIONAL, "--duration", "0.05", "--out", str(tmp_path)])
    assert status == 1
    report = (tmp_path / "report.md").read_text()
    assert "does not report" in report and "stage1.sun.ax.world" in report
    assert ("Diagnosis: No single-term mistake: agrees with the reference reduced to its 6 coordinates, the others "
            "held") in report
    assert "the reference is compared with stage1.sun.x, .y, stage1.ring.x, .y" in report
    capsys.readouterr()
    status = main(["mac", "demo-3p", "--model", TORSIONAL, "--out", str(tmp_path / "mac")])
    assert (tmp_path / "mac" / "mac.png").is_file()
    assert status == 0 and "torsional has 9 of the 18 coordinates of demo-3p" in capsys.readouterr().out


def test_published_models_through_the_same_door():
    """The 4-DOF models of Matejic et al. (2021) are LinearSides: their run is the RK4 of M q'' + B q' + C q = D
    from rest, checked here against the closed form of the first step's acceleration a(0) = M^-1 D(0)."""
    from gearcheck.lumped.side import PublishedSide

    side = PublishedSide(gearcheck.load("double-planet"), "energy-derived")
    assert isinstance(side, LinearSide)
    run = side.run(RunSettings(0.002, 1e-6))
    a0 = np.linalg.solve(side.model.M, side.model.D(0.0))
    np.testing.assert_allclose([run[f"{c}.acceleration"][0] for c in side.linear.coordinates], a0, rtol=1e-12,
                               atol=1e-12 * np.abs(a0).max())


def test_recorded_results_from_another_solver(tmp_path):
    """Another solver's results: the reference's own run written as CSV with renamed columns is compared
    against the twin and passes, with its integration check absent (nothing re-runs a recording)."""
    spec = gearcheck.load("demo-3p")
    run = LumpedSide(spec).run(RunSettings(0.06, None))
    names = ["stage1.ring.ay.world", "stage1.carrier.alpha", "stage1.planet1.sun.force"]
    columns = {name: f"c{i}" for i, name in enumerate(names)}
    import pandas as pd

    frame = pd.DataFrame({"t": run.t, **{columns[n]: run[n] for n in names}})
    frame.to_csv(tmp_path / "other.csv", index=False, float_format="%.17g")
    result = gearcheck.crosscheck("demo-3p", results=tmp_path / "other.csv",
                                  columns={"solver": "other", "signals": columns}, against="mujoco")
    assert result.verdict == "PASS", result.failures
    assert sorted(q.name for q in result.quantities) == sorted(names)
    assert all(q.metrics["integration_error"]["test"] is None for q in result.quantities)
    assert result.modal == []
    assert result.settle_s == MujocoSide(spec).settling_time(STEADY_THRESHOLD)  # the plan of the reference, the twin
    result.write(tmp_path / "report")
    report = (tmp_path / "report" / "report.md").read_text()
    assert "Test (other)" in report and "none: a recording" in report and "Natural frequencies" not in report


def _npz(path, **arrays):
    np.savez(path, **arrays)
    return path


def bad_files(tmp):
    spec = gearcheck.load("demo-3p")
    good = reference_linear_model(spec)
    write_matrix_file(good, tmp / "good.npz")
    base = dict(np.load(tmp / "good.npz"))
    n = len(good.coordinates)

    def edit(name, **changes):
        data = {k: v for k, v in base.items() if changes.get(k, 0) is not None}
        data.update({k: v for k, v in changes.items() if v is not None})
        return _npz(tmp / f"{name}.npz", **data)

    asym = base["M"].copy()
    asym[0, 1] = 1.0
    neg = base["M"].copy()
    neg[0, 0] = -1.0
    grams = base["M"].copy()
    grams[0, 0] *= 1000
    coords = base["coordinates"].copy()
    coords[0] = "stage1.sun.q"
    (tmp / "broken.mat").write_bytes(b"MATLAB 5.0 not really")
    (tmp / "model.txt").write_text("M = 1")
    return [
        (edit("missing-K", K=None), "K: missing"),
        (edit("shape", K=np.eye(n + 1)), "K: shape (19, 19), expected (18, 18)"),
        (edit("asym", M=asym), "M: not symmetric"),
        (edit("negative", M=neg), "M: not positive definite"),
        (edit("nan", K=np.where(np.eye(n) > 0, np.nan, base["K"])), "K: entry (0, 0) is nan"),
        (edit("grams", M=grams), "a unit slip"),
        (edit("unknown-label", coordinates=coords), "'stage1.sun.q' is not a coordinate of demo-3p"),
        (edit("units", units=np.array("mm")), "units: 'mm'"),
        (edit("extra", Q=np.eye(2)), "Q: unknown variable"),
        (edit("mesh-id", mesh_ids=np.array(["stage1.nope"] * 6)), "'stage1.nope' is not a mesh of demo-3p"),
        (edit("mesh-rows", mesh_rows=np.zeros((6, 3))), "mesh_rows: shape (6, 3), expected (6, 18)"),
        (edit("interpolation", mesh_interpolation=np.array("cubic")), "mesh_interpolation: 'cubic': choose linear "
                                                                        "or hold"),
        (edit("mesh-error", mesh_error=np.zeros(6), period=np.array(0.01)), "mesh_error: shape (6,), expected (6, N)"),
        (edit("mesh-error-nan", mesh_error=np.full((6, 8), np.nan), period=np.array(0.01)),
         "meshes[0].error"),
        (tmp / "broken.mat", "broken.mat: cannot be read as .mat"),
        (tmp / "model.txt", "a model file is .mat or .npz, not '.txt'"),
        (tmp / "absent.npz", "absent.npz: no such model file"),
    ]


def test_bad_model_files_one_line_exit_2(tmp_path, capsys):
    cases = bad_files(tmp_path)
    for path, fragment in cases:
        out = tmp_path / f"out-{path.stem}"
        status = main(["crosscheck", "demo-3p", "--model", str(path), "--out", str(out)])
        err = capsys.readouterr().err.strip()
        assert status == 2, (path, err)
        assert path.name in err and fragment in err, (fragment, err)
        assert "\n" not in err and "Traceback" not in err
        assert not out.exists()


def test_bad_factory_one_line(tmp_path, capsys):
    (tmp_path / "user.py").write_text("def broken(spec):\n    raise ValueError('my model is unfinished')\n")
    for model, fragment in [(f"{tmp_path / 'user.py'}:broken", "building the model failed: ValueError: my model"),
                            (f"{tmp_path / 'user.py'}:absent", "has no callable 'absent'"),
                            ("no_such_module_xyz:f", "importing no_such_module_xyz failed"),
                            ("plain", "unknown model 'plain': choose one of general")]:
        status = main(["crosscheck", "demo-3p", "--model", model, "--out", str(tmp_path / "o")])
        err = capsys.readouterr().err.strip()
        assert status == 2 and fragment in err and "\n" not in err, err


def test_mat_layout_matlab_stacks(tmp_path):
    """A MATLAB user's K(t) stack K(:,:,i) (n x n x N) reads as N samples whose mean must be K."""
    spec = gearcheck.load("demo-3p")
    model = reference_linear_model(spec)
    K_t = np.stack([model.K * (1 + 0.1 * np.cos(2 * np.pi * i / 8)) for i in range(8)], axis=-1)
    data = {"coordinates": np.array(model.coordinates, dtype=object), "M": model.M, "K": model.K, "K_samples": K_t,
            "period": 1e-3}
    scipy.io.savemat(tmp_path / "m.mat", data)
    read = read_matrix_file(tmp_path / "m.mat")
    assert read.stiffness.samples.shape == (8, 18, 18)
    np.testing.assert_allclose(read.stiffness(0.0), model.K * 1.1)
    data["K"] = model.K * 1.01
    scipy.io.savemat(tmp_path / "bad.mat", data)
    with pytest.raises(gearcheck.GearcheckError, match="K: is not the mean of the stiffness samples"):
        LinearSide(read_matrix_file(tmp_path / "bad.mat"), spec)


def _broken(spec, kind):
    """The reference as a user's LinearModel with one deliberate mistake of ``kind``."""
    from dataclasses import replace

    model = reference_linear_model(spec)
    model.name = kind
    sun = model.coordinates.index("stage1.sun.theta")
    if kind in ("dropped coupling", "sign error"):
        row = model.meshes[1].row.copy()
        row[sun] = 0.0 if kind == "dropped coupling" else -row[sun]
        model.meshes[1] = replace(model.meshes[1], row=row)
    elif kind == "inertia":
        model.M = model.M.copy()
        model.M[sun, sun] *= 1.5
    else:
        model.G = None
    return model


@pytest.mark.parametrize("kind, term", [
    ("dropped coupling", "mesh stage1.planet2.sun: coefficient of stage1.sun.theta dropped"),
    ("sign error", "mesh stage1.planet2.sun: sign of the stage1.sun.theta coefficient flipped"),
    ("inertia", "stage1.sun.theta inertia x 1.5"),
    ("gyroscopic", "gyroscopic terms missing"),
])
def test_diagnosis_through_the_door_names_the_term(kind, term):
    """A broken copy of the reference given as a user's model: the diagnosis names the broken term first, at
    round-off, and the reference itself scores far worse (a missing Coriolis term only shows at speed)."""
    from gearcheck.compare.engine.diagnosis import diagnose_side
    from gearcheck.lumped.assembly import build_model

    spec = gearcheck.load("demo-3p")
    diagnosis = diagnose_side(build_model(spec), LinearSide(_broken(spec, kind), spec))
    assert diagnosis.best.term.startswith(term), diagnosis.summary()
    assert diagnosis.best.score < 1e-9 < diagnosis.reference_score


def test_diagnosis_of_the_torsional_model_is_its_reduction():
    """The torsional model agrees with the reference reduced to its coordinates: its disagreement with the
    full reference is the reduction, which the diagnosis says instead of blaming a term."""
    from gearcheck.compare.engine.diagnosis import diagnose_side
    from gearcheck.compare.engine.user_model import user_side
    from gearcheck.lumped.assembly import build_model

    spec = gearcheck.load("demo-3p")
    diagnosis = diagnose_side(build_model(spec), user_side(TORSIONAL, spec))
    assert diagnosis.agrees and diagnosis.reduced_to == 6
    assert "the reduction itself" in diagnosis.lines()[0]


def test_train_file_registers_its_user_model(tmp_path, capsys):
    """train.user_model names the model (a file relative to the train file) that --model user checks; a train
    without one is refused in one line."""
    from gearcheck.train.loader import preset_text

    write_matrix_file(reference_linear_model(gearcheck.load("demo-3p")), tmp_path / "mine.npz")
    text = preset_text("demo-3p").replace("[train]\n", '[train]\nuser_model = "mine.npz"\n', 1)
    (tmp_path / "train.toml").write_text(text)
    spec = gearcheck.load(tmp_path / "train.toml")
    assert spec.user_model == str(tmp_path / "mine.npz")
    pairing = gearcheck.mode_pairing(spec, model=spec.user_model)
    assert pairing.paired.min() > 1 - 1e-9
    status = main(["crosscheck", "demo-3p", "--model", "user", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "demo-3p registers no user_model" in err and not (tmp_path / "o").exists()


def test_a_model_of_mass_and_stiffness_only_gets_a_modal_verdict(tmp_path, capsys):
    """The file engineers most often have: M and K, no mesh rows, nothing that varies in time (it crashed in the
    steady-state test, max() of nothing, exit 1).  Its runs would sit still, so its modes alone are compared, and
    the report says why and what to add; the same matrices 10 % too stiff FAIL on the modes."""
    ref = reference_linear_model(gearcheck.load("demo-3p"))
    K = ref.K + sum(float(np.mean(m.stiffness.samples)) * np.outer(m.row, m.row) for m in ref.meshes)
    for name, stiffness, status in (("right", K, 0), ("stiff", 1.1 * K, 1)):
        path = tmp_path / f"{name}.npz"
        write_matrix_file(LinearModel("mk-only", ref.coordinates, ref.M, stiffness), path)
        out = tmp_path / name
        assert main(["crosscheck", "demo-3p", "--model", str(path), "--out", str(out)]) == status
        data = json.loads((out / "report.json").read_text())
        assert data["steady_state"]["how"] == "modes only" and data["quantities"] == [] and len(data["modes"]) == 18
        assert any("nothing that drives it" in note for note in data["notes"])
        assert {m["status"] for m in data["modes"]} == ({"pass"} if status == 0 else {"fail"})
        assert (out / "natural_frequencies.png").exists() and not (out / "time_histories.png").exists()


def test_periodic_rate_is_the_derivative():
    """A series differentiates exactly; N samples by central differences, whose relative error on a harmonic
    of order o is 1 - sin(x)/x with x = 2 pi o / N (second order)."""
    period, N = 0.01, 128
    series = Periodic(period, mean_value=np.array(2.0), orders=np.array([1.0, 3.0]), cos=np.array([0.5, 0.0]),
                      sin=np.array([0.0, 0.25]))
    t = np.linspace(0.0, period, 7)
    w = 2 * np.pi / period
    exact = -0.5 * w * np.sin(w * t) + 0.75 * w * np.cos(3 * w * t)
    np.testing.assert_allclose(series.rate()(t), exact, rtol=1e-14, atol=1e-12 * w)
    sampled = Periodic(period, samples=series(np.arange(N) * period / N)).rate()
    at = np.arange(N) * period / N
    x = 2 * np.pi * np.array([1.0, 3.0]) / N
    expected = (-0.5 * w * np.sin(w * at) * np.sin(x[0]) / x[0]
                + 0.75 * w * np.cos(3 * w * at) * np.sin(x[1]) / x[1])
    np.testing.assert_allclose(sampled(at), expected, rtol=0, atol=1e-12 * w)


@pytest.mark.parametrize("suffix", [".mat", ".npz"])
def test_a_model_file_keeps_every_field_it_was_given(tmp_path, suffix):
    """What a model carries survives the file: per-unit-speed G and K_omega with their speed, the map to the
    train's coordinates, the declared reduction (a torsional model: its rotations, u = r theta for the sun)."""
    spec = gearcheck.load("demo-3p")
    ref = reference_linear_model(spec)
    keep = [i for i, c in enumerate(ref.coordinates) if c.endswith(".theta")]
    names = [ref.coordinates[i] for i in keep]
    r = 0.033
    physical = {c: {c: 1.0} for c in names}
    physical["stage1.sun.theta"] = {"stage1.sun.theta": 1.0 / r}
    T = np.eye(len(keep))
    T[names.index("stage1.sun.theta"), names.index("stage1.sun.theta")] = 1.0 / r
    M, K = (T.T @ ref.matrix(x)[np.ix_(keep, keep)] @ T for x in ("M", "K"))
    G = T.T @ ref.matrix("G")[np.ix_(keep, keep)] @ T
    model = LinearModel("torsional", names, M, K, G_per_speed=G / spec.operating.input_speed,
                        K_omega_per_speed2=np.zeros_like(K), physical=physical, reduction="condensed")
    path = tmp_path / f"model{suffix}"
    write_matrix_file(model, path)
    back = read_matrix_file(path)
    for name in ("M", "K", "G_per_speed", "K_omega_per_speed2"):
        np.testing.assert_array_equal(back.matrix(name), model.matrix(name))
    assert back.G is None and back.speed_of == "input" and back.reduction == "condensed"
    assert back.physical == physical and back.coordinates == names


def test_a_linear_models_periodic_state_is_the_forced_oscillators():
    """m x'' + c x' + k x = F cos(w t): the fixed point of the RK4 map over one period is the steady response
    X cos(w t - phi), X = F / sqrt((k - m w^2)^2 + (c w)^2), tan phi = c w / (k - m w^2), to RK4's own error
    (measured 7.6e-9 at 200 steps a cycle, 4.8e-10 at 400: fourth order); the map returns it to itself to
    round-off (9e-16)."""
    from gearcheck.lumped.linear_run import periodic_start

    m, c, k, F, f = 2.0, 3.0, 5.0e4, 7.0, 40.0
    w = 2 * np.pi * f
    forcing = Periodic(1 / f, mean_value=np.zeros(1), orders=np.array([1.0]), cos=np.array([[F]]),
                       sin=np.array([[0.0]]))
    model = LinearModel("oscillator", ["x"], np.array([[m]]), np.array([[k]]), C=np.array([[c]]), F=np.zeros(1),
                        forcing=forcing).check()
    q, v, h, residual = periodic_start(model, 1 / f / 200)
    X, phi = F / np.hypot(k - m * w * w, c * w), np.arctan2(c * w, k - m * w * w)
    assert h == pytest.approx(1 / f / 200, rel=1e-12) and residual < 1e-12
    np.testing.assert_allclose([q[0], v[0]], [X * np.cos(phi), X * w * np.sin(phi)], rtol=1e-7)
