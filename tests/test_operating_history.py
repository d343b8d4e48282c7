"""Operating histories: speed and torque over time in both solvers.

The nominal clock against closed forms; the constant-speed limit to the bit in both solvers; a run-up, a start from
rest and a torque-driven start-up in both solvers against each other; the twin's own hinge speed (its bodies
accelerated by the torques alone) against the clock of the rigid train's equation; tables with units; bad input.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.time_solver import simulate
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings
from gearcheck.train.history import Clock
from gearcheck.train.history_file import read_history_table
from gearcheck.train.loader import load_text, preset_text

DEMO = preset_text("demo-3p")


def demo(history: str, text: str = DEMO):
    return load_text(text + "\n[operating.history]\n" + history + "\n", "/tmp/demo-history.toml")


def both(spec, duration: float):
    settings = RunSettings(duration=duration)
    return simulate(build_model(spec), settings), simulate_mujoco(compile_train(spec), settings)


def worst(a, b, kinds=("mesh_force", "angular_acceleration", "acceleration", "bearing_force")) -> dict:
    """The largest difference of the two runs over each gated signal's largest magnitude, per kind."""
    out = {}
    for name in a.names(compared=True):
        kind = a.signal(name).kind
        if kind in kinds:
            scale = np.max(np.abs(a[name]))
            out[kind] = max(out.get(kind, 0.0), float(np.max(np.abs(a[name] - b[name])) / scale))
    return out


def test_clock_closed_forms():
    """lambda piecewise linear: Lambda is its exact integral (trapezoids per piece), the times at which Lambda reaches
    a value invert it; a Hermite clock reproduces a cubic exactly."""
    clock = Clock.piecewise_linear([0.0, 1.0, 3.0], [1.0, 2.0, 0.5])
    t = np.array([0.5, 1.0, 2.0, 3.0, 4.0])
    exact = np.array([0.5 + 0.125, 1.5, 1.5 + 2.0 - 0.375, 1.5 + 2.5, 4.0 + 0.5])
    assert np.allclose(clock.time(t), exact, rtol=0, atol=1e-15)
    assert np.allclose(clock.rate(np.array([0.5, 2.0, 5.0])), [1.0, -0.75, 0.0])
    assert np.allclose(clock.times_at(exact[:4], 0.0, 3.0), t[:4], atol=1e-14)
    cubic = lambda x: 1 + x - 0.3 * x**2 + 0.05 * x**3  # noqa: E731
    slope = lambda x: 1 - 0.6 * x + 0.15 * x**2  # noqa: E731
    knots = np.array([0.0, 0.7, 2.0])
    h = Clock.hermite(knots, cubic(knots), slope(knots))
    x = np.linspace(0, 2, 9)
    assert np.allclose(h.scale(x), cubic(x), atol=1e-14)
    assert np.allclose(h.time(x), x + x**2 / 2 - 0.1 * x**3 + 0.0125 * x**4, atol=1e-14)


def test_constant_speed_is_the_limit_to_the_bit():
    """A history at the train's own constant speed gives both solvers' constant-speed runs bit for bit."""
    plain = load_text(DEMO, "/tmp/demo.toml")
    held = demo("speed_points = [[0.0, 1500.0], [0.02, 1500.0]]")
    for run in (lambda s: simulate(build_model(s), RunSettings(duration=0.01)),
                lambda s: simulate_mujoco(compile_train(s), RunSettings(duration=0.01))):
        a, b = run(plain), run(held)
        assert np.array_equal(a.values, b.values)


def test_run_up_in_both_solvers():
    """1500 -> 3000 rpm in 0.05 s from the steady state: the two independent models agree (measured 1e-5 on the
    meshes, 1.5e-3 on the carrier's small angular acceleration, as at constant speed); without the rigid train's
    inertia loads the lumped model misses by over 1e-2 (measured on a 0.1 s run-up)."""
    spec = demo("speed_points = [[0.0, 1500.0], [0.05, 3000.0]]")
    a, b = both(spec, 0.05)
    errors = worst(a, b)
    assert errors["mesh_force"] < 1e-4
    assert errors["acceleration"] < 1e-3
    assert errors["angular_acceleration"] < 5e-3
    # the velocities (measured 1e-5), each read on its own side from the nominal clock
    for name in ("stage1.carrier.omega", "stage1.planet1.omega", "stage1.planet1.vx.world", "stage1.ring.vx.relative"):
        assert np.max(np.abs(a[name] - b[name])) < 1e-4 * np.max(np.abs(b[name])), name
    # the mesh frequency follows the integrated angle: the sun mesh goes through Lambda(t) f cycles
    exc = build_model(spec).excitation
    assert math.isclose(float(exc.nominal_time(0.05)), 0.05 * 1.5, rel_tol=1e-14)


def test_start_from_rest_and_torque_start_up():
    """From rest (speed 0 -> 1500 rpm) and under a torque history (the speed following from the rigid train) the two
    solvers agree; the twin's sun hinge, driven only by the torques, turns at the clock's speed lambda w_in (the
    rigid train's equation, inertia from the train's members) within its elastic vibration."""
    a, b = both(demo("speed_points = [[0.0, 0.0], [0.05, 1500.0]]"), 0.05)
    assert worst(a, b)["mesh_force"] < 1e-3
    spec = demo("torque_points = [[0.0, 0.0], [0.02, 400.0], [0.05, 400.0]]\n"
                "load_points = [[0.0, 0.0], [0.05, 1000.0]]")
    assert spec.operating.input_shaft_stiffness is None and spec.operating.history.start == "rest"
    a, b = both(spec, 0.05)
    assert worst(a, b)["mesh_force"] < 1e-3
    mb = compile_train(spec)
    carrier = b.raw["stage1_carrier_angle_rate"]  # the twin's carrier hinge, turned by the torques alone
    nominal = mb.kin.speeds["stage1.carrier"] * mb.excitation.clock.scale(b.t)
    late = b.t > 0.01
    assert np.max(np.abs(carrier[late] - nominal[late])) < 3e-3 * nominal[-1]  # measured 1.2e-3


def test_history_tables_with_units(tmp_path):
    """A CSV's header units (ms, rad/s) and a Parquet file's field units convert to s and rpm."""
    csv = tmp_path / "speed.csv"
    csv.write_text("t_ms,speed_rad_s\n0,0\n500,104.71975511965977\n")
    table = read_history_table(csv, "speed", "speed.csv")
    assert np.allclose(table, [[0.0, 0.0], [0.5, 1000.0]])
    import pyarrow as pa
    import pyarrow.parquet as pq

    fields = [pa.field("time", pa.float64(), metadata={b"unit": b"s"}),
              pa.field("torque", pa.float64(), metadata={b"unit": b"kNm"})]
    pq.write_table(pa.Table.from_arrays([pa.array([0.0, 1.0]), pa.array([0.0, 2.0])], schema=pa.schema(fields)),
                   tmp_path / "torque.parquet")
    assert np.allclose(read_history_table(tmp_path / "torque.parquet", "torque", "t"), [[0, 0], [1, 2000]])


def test_published_models_take_the_torque_history():
    """The 4-DOF models of Matejic et al. (2021) take M_h(t) from a torque history (their ripple replaced)."""
    from gearcheck.lumped.published import four_dof_model

    text = preset_text("double-planet") + ("\n[operating.history]\ntorque_points = [[0.0, 0.0], [0.1, 40.0]]\n"
                                           "load_points = [[0.0, 0.0]]\n")
    model = four_dof_model(load_text(text, "/tmp/dp.toml"), "energy-derived")
    assert np.allclose(model.D(np.array([0.05, 0.2]))[:, 1], [20.0, 40.0])
    assert np.allclose(model.D(np.array([0.05]))[:, 3], 0.0)


BAD = [
    ("speed-and-torque", "speed_points = [[0, 1500]]\ntorque_points = [[0, 1]]", "give the input speed"),
    ("negative-speed", "speed_points = [[0, 1500], [1, -5]]", "must stay >= 0 rpm"),
    ("times-back", "speed_points = [[0, 1500], [1, 1600], [0.5, 1700]]", "increase strictly"),
    ("late-start", "speed_points = [[0.1, 1500]]", "start at 0 s"),
    ("rest-not-at-rest", "speed_points = [[0, 1500]]\nstart = \"rest\"", "rest, but the speed history starts"),
    ("expression-no-end", "torque_expression = \"10 * t\"", "needs operating.history.until_s"),
    ("two-of-speed", "speed_points = [[0, 1500]]\nspeed_file = \"x.csv\"", "give one of"),
    ("file-missing", "speed_file = \"nowhere.csv\"", "nowhere.csv"),
]


@pytest.mark.parametrize("history, fragment", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_history_one_line(tmp_path, capsys, history, fragment):
    train = tmp_path / "t.toml"
    train.write_text(DEMO + "\n[operating.history]\n" + history + "\n")
    assert main(["run", str(train), "--duration", "0.01", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0] and "operating.history" in err[0], err
    assert not (tmp_path / "out").exists()


BAD_OPTIONS = [
    (["--speed-profile", "0:1500,x"], "--speed-profile '0:1500,x'"),
    (["--torque-profile", "0:1e300"], "--torque-profile: values must be within ±1e+09 N·m, got 1e+300"),
    (["--speed-profile", "0:1500,1e9:1600"], "--speed-profile: times must be <= 10000 s"),
    (["--start", "rest"], "--start applies to an operating history"),
    (["--torque-profile", "0:0,0.01:1"], "turn backwards"),
    (["--torque-profile", "0:500,0.005:500"], "ends at 0.005 s"),
]


@pytest.mark.parametrize("options, fragment", BAD_OPTIONS,
                         ids=["points", "torque-huge", "time-huge", "start", "backwards", "too-long"])
def test_bad_profile_options_one_line(tmp_path, capsys, options, fragment):
    assert main(["run", "demo-3p", "--duration", "0.01", "--out", str(tmp_path / "out"), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0], err
    assert not (tmp_path / "out").exists()


def test_a_table_file_says_its_own_name_and_the_unit_it_does_not_know(tmp_path, capsys):
    table = tmp_path / "speed.csv"
    table.write_text("time_s,speed_furlong\n0,1\n1,2\n")
    assert main(["run", "demo-3p", "--speed-profile", str(table), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"gearcheck: error: --speed-profile: {str(table)!r}: column 'speed_furlong': unknown speed unit "
                   "(use rpm, rad_s, hz)")
    with pytest.raises(gearcheck.GearcheckError, match=r"^operating.history.start: 'soon': one of steady, rest$"):
        gearcheck.load("demo-3p", speed_profile="0:1500,1:2000", start="soon")


def test_speed_history_needs_the_input_shaft(tmp_path, capsys):
    text = DEMO.replace("input_shaft_stiffness = 3.1809e4\n", "")
    train = tmp_path / "t.toml"
    train.write_text(text + "\n[operating.history]\nspeed_points = [[0, 1500], [1, 2000]]\n")
    assert main(["run", str(train), "--out", str(tmp_path / "o")]) == 2
    assert "drives the input through its shaft" in capsys.readouterr().err


def test_euler_terms_bring_the_models_together():
    """Under a violent run-up (1500 -> 15000 rpm in 5 ms) the Euler terms of the frame's angular acceleration bring the
    lumped planet bearing forces closer to the twin's: measured 2.2e-4 and 2.2e-3 of their largest values with them,
    3.4e-4 and 2.6e-3 without, 4.6e-4 and 3.0e-3 with their sign flipped."""
    from dataclasses import replace

    spec = demo("speed_points = [[0.0, 1500.0], [0.005, 15000.0]]")
    settings = RunSettings(duration=0.005)
    model = build_model(spec)
    twin = simulate_mujoco(compile_train(spec), settings)
    runs = [simulate(replace(model, K_euler=sign * model.K_euler), settings) for sign in (1.0, 0.0, -1.0)]
    for name, ratio in (("stage1.planet1.bearing_tangential.force", 0.75),
                        ("stage1.planet1.bearing_radial.force", 0.9)):
        error = [np.max(np.abs(run[name] - twin[name])) for run in runs]
        assert error[0] < ratio * error[1] < ratio * error[2], (name, error)


def test_the_papers_start_up_drives_its_unheld_mechanism():
    """Matejic et al. (2021)'s model derived from its energies has two rigid-body motions (the train's rotation, and
    y1 with the planet rolling on ring e, which no planet bearing holds).  From rest under a constant carrier torque
    M its coordinates follow the closed form of the rigid motions, q = sum_r phi_r (phi_r' D) t^2 / 2 over the
    mass-normalised null space of C, to within the elastic deflection (micrometres) -- y1 drifts quadratically."""
    import scipy.linalg

    from gearcheck.lumped.published import four_dof_model
    from gearcheck.lumped.side import PublishedSide
    from gearcheck.shared.settings import RunSettings

    text = preset_text("double-planet") + ("\n[operating.history]\ntorque_points = [[0.0, 40.0]]\n"
                                           "load_points = [[0.0, 0.0]]\n")
    spec = load_text(text, "/tmp/dp-start.toml")
    model = four_dof_model(spec, "energy-derived")
    side = PublishedSide(spec, "energy-derived")
    duration = 0.05
    run = side.run(RunSettings(duration=duration, dt=side.stable_step() / 4))
    null = scipy.linalg.null_space(model.C)
    null = null @ np.linalg.inv(np.linalg.cholesky(null.T @ model.M @ null)).T  # mass-normalised rigid motions
    D = model.D(np.array([0.0]))[0]
    rigid = null @ (null.T @ D) * duration**2 / 2
    assert null.shape[1] == 2
    q = np.array([run[c][-1] for c in ("y1", "theta_h", "theta_f", "theta_b")])
    assert abs(rigid[0]) > 1e-3  # y1 moves millimetres in 50 ms: a mechanism, not a vibration
    assert np.max(np.abs(q - rigid) / np.abs(rigid)) < 1e-3  # measured 5.5e-5: the elastic part


def test_a_speed_expression_is_its_points():
    """A speed given as an expression of t (a Fourier series here) runs on straight lines through 8192 samples of it:
    its nominal angle is the expression's integral to the trapezoids' error, (T/8192)^2/12 times the curvature."""
    spec = demo('speed_expression = "1500 + 300 * sin(2 * pi * 10 * t)"\nuntil_s = 0.1')
    clock = build_model(spec).excitation.clock
    t = np.array([0.013, 0.05, 0.0977])
    exact = t + 300 / 1500 * (1 - np.cos(2 * np.pi * 10 * t)) / (2 * np.pi * 10)
    curvature = 300 / 1500 * (2 * np.pi * 10) ** 2
    assert np.max(np.abs(clock.time(t) - exact)) < (0.1 / 8192) ** 2 / 12 * curvature * 0.1 * 2
