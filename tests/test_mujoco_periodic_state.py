"""The MuJoCo twin's periodic steady state by shooting on its own runs, against the lumped model's, and its refusals."""

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.periodic_steady_state import periodic_steady_state
from gearcheck.lumped.time_solver import simulate
from gearcheck.mbd_models.periodic_state import TOLERANCE, nominal_advance, periodic_state, twin_period
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.static_state import nominal_speeds, static_state
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_train
from gearcheck.train.periods import common_period
from gearcheck.train.variants import edited


def both_shot(preset: str):
    """(the twin, its periodic state, its run of one T_M from there with the final state, the lumped model's run of
    one T from its periodic steady state), both on the lumped model's step, which divides T and so T_M."""
    spec = load_train(preset)
    model, mb = build_model(spec), compile_train(spec)
    lumped = periodic_steady_state(model)
    shot = periodic_state(mb, dt=lumped.dt)
    run = simulate_mujoco(mb, RunSettings(shot.period, dt=shot.dt), initial_state=shot.initial_state,
                          return_state=True)
    return mb, shot, run, simulate(model, RunSettings(lumped.period, dt=lumped.dt), y0=lumped.y0)


@pytest.fixture(scope="module")
def double_planet():
    return both_shot("double-planet")


def test_double_planet_period_is_two_drive_periods():
    """Constant mesh stiffness and a 40 Hz torque ripple: the drive repeats after T = 25 ms, the carrier (1200 rpm)
    turns once in T_M = 2 T = 50 ms, the period of the twin's world-frame equations."""
    mb = compile_train(load_train("double-planet"))
    assert common_period(mb.excitation) == pytest.approx(0.025, rel=1e-12)
    assert twin_period(mb) == pytest.approx(0.05, rel=1e-12)


def test_double_planet_periodic_state_is_a_fixed_point(double_planet):
    """The slow mode (145 Hz, 0.27 % damping: a 2.45 s start transient) is shot through: the period map's residual
    is within its tolerance (1e-8), and a run from the state returns to it after T_M, its hinges advanced by their
    nominal speeds times T_M, to the tolerance in the residual's unit: the first guess's (the static state's) largest
    deviation from the nominal motion."""
    mb, shot, (run, (qpos, qvel, _)), _ = double_planet
    assert shot.method == "anderson" and shot.residual <= TOLERANCE and shot.runs <= 20
    assert shot.period == pytest.approx(0.05, rel=1e-12) and shot.steps * shot.dt == pytest.approx(shot.period)
    assert (shot.info.steps, run.info["steps"]) == (shot.runs * shot.steps, shot.steps)
    start = static_state(mb)
    deflection = max(np.max(np.abs(start.qpos)), np.max(np.abs(start.qvel - nominal_speeds(mb))) / mb.omega_max)
    assert np.max(np.abs(qpos - nominal_advance(mb, shot.period) - shot.qpos)) <= TOLERANCE * deflection
    assert np.max(np.abs(qvel - shot.qvel)) <= TOLERANCE * deflection * mb.omega_max
    assert np.max(np.abs(shot.qvel - nominal_speeds(mb))) > 1e-6  # the state is more than the nominal motion


def test_double_planet_mesh_forces_agree_with_the_lumped_periodic_run(double_planet):
    """Both solvers on their periodic orbits, one step: the twin's mesh forces over the lumped period T agree with
    the lumped model's to 1e-4 of their swing over the period (measured 9.8e-6: 4.0e-5 N of a 4.0 N swing on 2387 N,
    the round-off of world-frame angles times 1.6e10 N/m), where a start from the static state misses by 13 swings."""
    mb, shot, (run, _), lumped = double_planet
    assert run.names("mesh_force") == lumped.names("mesh_force")
    n = lumped.t.size
    np.testing.assert_allclose(run.t[:n], lumped.t, rtol=0, atol=1e-12)
    reference = lumped.select("mesh_force")
    swing = np.ptp(reference, axis=0).max()
    assert np.max(np.abs(run.select("mesh_force")[:n] - reference)) < 1e-4 * swing
    static_start = simulate_mujoco(mb, RunSettings(lumped.t[-1], dt=shot.dt)).select("mesh_force")
    assert np.max(np.abs(static_start - reference)) > swing


def test_demo_3p_shot_in_two_runs():
    """demo-3p (rectangular stiffness, phased meshes, steps split at the stiffness jumps): T = one mesh period
    (2.46 ms), T_M = 62 of them (152.7 ms, one carrier turn); its meshes' 5 % damping leaves nothing of the start
    after T_M, so Anderson acceleration converges in 2 runs (residual 5.8e-13), the run from the state is periodic,
    and its mesh forces agree with the lumped periodic run's to 1e-4 of their swing (measured 3.8e-6: 0.029 N of
    7625 N)."""
    mb, shot, (run, (qpos, qvel, _)), lumped = both_shot("demo-3p")
    assert shot.period == pytest.approx(62 * common_period(mb.excitation), rel=1e-12)
    assert shot.residual < 1e-9 and shot.runs <= 3
    deflection = np.max(np.abs(shot.qpos))
    assert np.max(np.abs(qpos - nominal_advance(mb, shot.period) - shot.qpos)) < 1e-8 * deflection
    reference = lumped.select("mesh_force")
    swing = np.ptp(reference, axis=0).max()
    assert np.max(np.abs(run.select("mesh_force")[:lumped.t.size] - reference)) < 1e-4 * swing


@pytest.mark.parametrize("case, why", [
    (lambda: edited("demo-3p", [(r"^output_torque = .*", "output_torque = 1500.0\nramp_s = 0.01")], "ramp"),
     "the load ramp over the first 0.01 s not periodic"),
    (lambda: edited("double-planet", [(r"^order = 2.0", "frequency_hz = 41.3")], "41.3 Hz ripple"),
     r"carriers \(stage1.carrier 20 Hz\) turn no whole number of revolutions within 256 periods of the drive"),
    (lambda: load_train("rv-reducer"), "pin contacts follow the bodies' poses"),
])
def test_twin_without_a_period_is_refused(case, why):
    """A drive without a period (a load ramp), a ripple at 41.3 Hz against a carrier at 20 Hz (they meet after 413
    ripple periods) and an RV reducer's moving pin contacts are refused, naming the way out."""
    with pytest.raises(SolverError, match=why) as error:
        periodic_state(compile_train(case()))
    assert "time-march with a settle time" in str(error.value)
