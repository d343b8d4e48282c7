"""Shooting for the periodic steady state against time marching, and its refusals."""

import numpy as np
import pytest

from gearcheck.lumped import periodic_steady_state as periodic_steady_state_module
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.periodic_steady_state import periodic_steady_state
from gearcheck.train.periods import MAX_MESH_PERIODS, common_period
from gearcheck.lumped.time_solver import default_step, simulate
from gearcheck.train.variants import chained, edited
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings

LIGHT_BACKLASH = [(r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 40.0\n"
                   "ste = [{ harmonic = 1, amplitude_um = 5.0 }]"), (r"^output_torque = .*", "output_torque = 30.0")]


def marched_and_shot(model, periods: int, **options):
    """(the last period of a run of ``periods`` periods from the static state, the first period from the shot state,
    the shooting result): mesh forces on the same step."""
    shot = periodic_steady_state(model, **options)
    marched = simulate(model, RunSettings(periods * shot.period, shot.dt))
    steady = simulate(model, RunSettings(shot.period, shot.dt), y0=shot.y0)
    assert steady.info["steps"] == shot.steps and marched.info["steps"] == periods * shot.steps
    return marched.select("mesh_force")[-shot.steps - 1:], steady.select("mesh_force"), shot


def test_linear_train_is_shot_by_anderson_acceleration():
    """demo-3p: one mesh period (its planets' meshes share it), the default step.  Anderson acceleration of the period
    map reaches the residual 1e-10 in fewer runs than the 2n + 2 of a dense Jacobian (measured 24 against 38), the
    shot run is periodic, and 40 periods of time marching from the static state arrive at it to 1e-6 of the mesh
    force's swing (measured 1e-9; RK4's own error at this step is ~1e-4 of the peak)."""
    model = build_model(load_train("demo-3p"))
    marched, steady, shot = marched_and_shot(model, 40)
    assert shot.method == "anderson" and shot.residual <= 1e-10 and shot.runs < 2 * model.n + 2
    assert shot.period == pytest.approx(1 / model.excitation.frequency[0], rel=1e-12)
    assert shot.dt == pytest.approx(default_step(model), rel=1e-12)
    swing = np.ptp(steady, axis=0).max()
    assert np.max(np.abs(steady[-1] - steady[0])) < 1e-8 * swing
    assert np.max(np.abs(marched - steady)) < 1e-6 * swing


def test_linear_train_is_shot_in_one_solve_by_newton():
    """method="newton" on a linear model: the period map is affine, one solve of (I - Phi) y0 = g with Phi from 2n
    unit states (2n + 2 runs) leaves a residual at round-off (measured 1.3e-15)."""
    model = build_model(load_train("demo-3p"))
    shot = periodic_steady_state(model, method="newton")
    assert shot.method == "affine" and shot.iterations == 1 and shot.runs == 2 * model.n + 2
    assert shot.residual < 1e-12
    assert (shot.info.engine, shot.info.steps) == ("numba-rk4", shot.runs * shot.steps)
    assert shot.info.rhs_calls >= 4 * shot.info.steps  # 4 a sub-step: demo-3p's steps split at stiffness jumps
    anderson = periodic_steady_state(model)
    assert np.max(np.abs(anderson.q - shot.q)) < 1e-9 * np.max(np.abs(shot.q))


@pytest.mark.parametrize("method", ["anderson", "newton"])
def test_backlash_train_is_shot(method):
    """A light load on meshes with backlash and transmission error: the teeth leave their drive flanks and the period
    map is piecewise linear.  Anderson acceleration (measured 23 runs) and Newton shooting with a kept Jacobian
    (226 runs) both converge, to 1e-6 of the swing of 40 marched periods (measured 7e-10)."""
    model = build_model(edited("demo-3p", LIGHT_BACKLASH, "light backlash"))
    marched, steady, shot = marched_and_shot(model, 40, method=method)
    assert shot.method == method and shot.residual <= 1e-10
    swing = np.ptp(steady, axis=0).max()
    assert np.max(np.abs(marched - steady)) < 1e-6 * swing


def test_newton_takes_over_where_anderson_has_not_converged(monkeypatch):
    monkeypatch.setattr(periodic_steady_state_module, "MAX_ANDERSON_RUNS", 3)
    model = build_model(load_train("demo-4p"))
    shot = periodic_steady_state(model)
    assert shot.method == "anderson, then newton" and shot.residual <= 1e-10
    with pytest.raises(SolverError, match="method must be 'anderson' or 'newton'"):
        periodic_steady_state(model, method="harmonic balance")


def test_common_period_of_commensurate_stages():
    """Two chained demo-3p stages: their mesh frequencies 405.95 and 106.32 Hz (and the planets' rotations) meet after
    11 periods of the slower mesh."""
    model = build_model(chained(2))
    period = common_period(model.excitation)
    assert period == pytest.approx(11 / 106.3208617, rel=1e-8)


def test_radial_coupling_between_turning_carriers_sets_the_period():
    """A radial spline from the first stage's carrier to the second's sun turns in their frames at the carriers' speed
    difference (Coupling.turning_frequencies, 4.83 Hz, the lumped model's turning coupling): the period doubles to 22
    periods of the slower mesh."""
    model = build_model(chained(2, radial_stiffness=1e8))
    (coupling,) = model.turning
    assert [p for part in model.spec.parts for p in part.turning_frequencies(model.spec, model.excitation.kin.speeds)
            ] == pytest.approx([abs(coupling.omega_b - coupling.omega_a) / (2 * np.pi)], rel=1e-14)
    assert common_period(model.excitation) == pytest.approx(22 / 106.3208617, rel=1e-8)


def test_rv_reducer_period_is_one_turn_of_its_eccentrics():
    """The RV reducer's meshes (248.6 Hz), eccentrics (3.60 Hz) and pins passing (140.5 Hz) meet after one turn of the
    eccentrics relative to the carrier, 69 mesh periods: beyond the default MAX_MESH_PERIODS, within a larger one."""
    model = build_model(load_train("rv-reducer"))
    assert common_period(model.excitation, max_mesh_periods=80) == pytest.approx(69 / 248.6486486, rel=1e-8)
    with pytest.raises(SolverError, match="no common period within 64 periods"):
        common_period(model.excitation)


@pytest.mark.parametrize("case, why", [
    (lambda: load_train("rv-reducer"), "no common period within 64 periods"),
    (lambda: load_train("hub-drive"), "no common period within 64 periods"),
    (lambda: chained(3), "no common period within 64 periods"),
    (lambda: edited("demo-3p", [(r"^output_torque = .*", "output_torque = 1500.0\nramp_s = 0.01")], "ramp"),
     "the load ramp over the first 0.01 s not periodic"),
])
def test_incommensurate_excitation_is_refused(case, why):
    """Where the excitation has no common period within MAX_MESH_PERIODS (an RV reducer's eccentric at 3.6 Hz against
    its meshes at 248.6 Hz; hub-drive's two stages; three chained stages) or is not periodic (a load ramp), the
    solver says so and names the way out: time marching with a settle time."""
    assert MAX_MESH_PERIODS == 64
    with pytest.raises(SolverError, match=why) as error:
        periodic_steady_state(build_model(case()))
    assert "time-march with a settle time" in str(error.value)
