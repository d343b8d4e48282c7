"""The RK4 reference: energy conservation, its convergence order, step checks, steady state."""

import re

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_text, load_train, preset_text
from gearcheck.lumped.static import static_solution
from gearcheck.lumped.time_solver import default_step, mechanical_energy, simulate, stable_step
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings


def conservative_demo():
    """demo-3p with every damper removed and constant mesh stiffness: a conservative system."""
    t = preset_text("demo-3p")
    t = t.replace("damping = { ratio = 0.05 }", "damping = { ratio = 0.0 }")
    t = re.sub(r", (radial|torsional)_damping = [0-9.]+", "", t)
    t = re.sub(r"input_shaft_damping = .*", "input_shaft_damping = 0.0", t)
    t = t.replace('model = "rectangular"', 'model = "constant"')
    return load_text(t, "conservative-demo")


def energy_drift(model, dt, duration=0.05):
    """Relative energy change over ``duration`` after the full load is applied suddenly at rest,
    normalised by the vibration energy E(0) - E(static)."""
    zero = np.zeros(model.n)
    r = simulate(model, RunSettings(duration, dt), y0=(zero, zero))
    labels = model.dofs.labels()
    q = np.array([r.raw[lab] for lab in labels]).T
    v = np.array([r.raw[lab + "_dot"] for lab in labels]).T
    energy = mechanical_energy(model, q, v)
    q_static = static_solution(model).q
    e_static = mechanical_energy(model, q_static[None], zero[None])[0]
    return (energy - energy[0]) / (energy[0] - e_static)


def test_rk4_conserves_energy_with_gyroscopic_terms():
    """Bound: |dE|/E_vib < 1e-6 over 0.05 s (~15 000 steps) at the default step (measured 4.9e-7).
    RK4 loses energy as (omega h)^6 per step, so the drift must be a loss, and halving the step
    must shrink it by 2^5 = 32 per unit time (accept 25..40)."""
    model = build_model(conservative_demo())
    h = default_step(model)
    drift = energy_drift(model, h)
    assert abs(drift[-1]) < 1e-6
    assert drift[-1] < 0
    assert np.max(drift) < 1e-9  # never gains energy
    ratio = drift[-1] / energy_drift(model, h / 2)[-1]
    assert 25 < ratio < 40


def test_unstable_step_is_refused_with_a_suggestion():
    model = build_model(load_train("demo-3p"))
    limit = stable_step(model)
    with pytest.raises(SolverError, match=r"use dt <= .* s \(the default\)"):
        simulate(model, RunSettings(0.001, 1.5 * limit))


def test_rk4_converges_at_fourth_order_to_dop853():
    """A sudden load excites every mode.  Against scipy's DOP853 (rtol 1e-10), the RK4 mesh force
    error is below 1e-4 of its peak at the default step (measured 7.6e-5) and falls 16-fold
    (accept 12..20) when the step is halved: fourth order."""
    model = build_model(conservative_demo())
    zero = np.zeros(model.n)
    h = default_step(model)
    duration = 0.004
    reference = simulate(model, RunSettings(duration, h), method="DOP853", rtol=1e-10, atol=1e-16, y0=(zero, zero))
    name = reference.names("mesh_force")[0]
    peak = np.max(np.abs(reference[name]))

    def error(dt):
        r = simulate(model, RunSettings(duration, dt, output_dt=h), y0=(zero, zero))
        n = min(r.t.size, reference.t.size)
        np.testing.assert_allclose(r.t[:n], reference.t[:n], rtol=1e-12)
        return np.max(np.abs(r[name][:n] - reference[name][:n])) / peak

    coarse, fine = error(h), error(h / 2)
    assert coarse < 1e-4
    assert 12 < coarse / fine < 20


def test_steady_state_mesh_force_mean_equals_static_load():
    """With damping the response settles; the mean mesh force over whole mesh cycles is the static force
    to within the parametric (stiffness-variation) contribution, a few per cent."""
    model = build_model(load_train("demo-3p"))
    r = simulate(model, RunSettings(0.06, settle=0.03))
    forces = r.names("mesh_force")
    np.testing.assert_allclose([r[n][r.steady].mean() for n in forces], [r.static[n] for n in forces], rtol=0.03)
    # the rectangular stiffness makes it vibrate: Kv departs from 1
    assert np.ptp(r.select("dynamic_factor")[r.steady][:, 0]) > 0.05
