"""A linear model's run reports each coordinate, its velocity and its acceleration (lumped.linear_run): exact for an
oscillator up to RK4's own error, and for the 4-DOF models of Matejic et al. (2021) the same in the model and in
its MuJoCo twin, which reads them from its joints."""

from __future__ import annotations

import numpy as np
import pytest

from gearcheck.lumped.linear_model import LinearModel
from gearcheck.lumped.linear_run import simulate_linear
from gearcheck.lumped.side import PublishedSide
from gearcheck.mbd_models.side import PublishedTwinSide
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import transient_step
from gearcheck.train.loader import load_train
from gearcheck.train.published_parameters import LABELS


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def test_an_oscillator_from_a_displaced_moving_start_is_its_closed_form_to_rk4_error():
    """m x'' + k x = 0 from (x0, v0): x = x0 cos wt + (v0/w) sin wt, x' = -x0 w sin wt + v0 cos wt.  RK4 maps the
    state (x, x'/w), as a complex number, by R(iwh) = 1 + z + z^2/2 + z^3/6 + z^4/24 (z = iwh) per step, the exact
    flow by e^{iwh}; as |R| <= 1 the error after n steps is at most n |R(iwh) - e^{iwh}| |(x0, v0/w)|, about
    n (wh)^5/120, plus round-off.  Measured: the bound to 1e-9 (the error is RK4's phase lag, which that bound is)."""
    m, k, x0, v0 = 2.0, 8.0e4, 1e-3, 0.3
    w = np.sqrt(k / m)
    h = 0.05 / w
    model = LinearModel("oscillator", ["x"], np.array([[m]]), np.array([[k]]), start="rest")
    run = simulate_linear(model, RunSettings(20 * 2 * np.pi / w, h), y0=(np.array([x0]), np.array([v0])))
    t = run.t
    assert run.names() == ["x.acceleration", "x", "x.velocity"]
    assert run.signal("x.velocity").unit == "m/s" and not run.signal("x.velocity").compared
    x = x0 * np.cos(w * t) + v0 / w * np.sin(w * t)
    v = -x0 * w * np.sin(w * t) + v0 * np.cos(w * t)
    z = 1j * w * h
    step_error = abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24 - np.exp(z))
    n = np.round(t / h)
    size = np.hypot(x0, v0 / w)
    error = np.hypot(run["x"] - x, (run["x.velocity"] - v) / w)
    assert np.all(error <= n * step_error * size + 8 * (n + 1) * np.finfo(float).eps * size)
    assert error[-1] > 0.5 * n[-1] * step_error * size  # RK4's own error, not a smaller one
    np.testing.assert_allclose(run["x.acceleration"], -k / m * run["x"], rtol=1e-12, atol=1e-15)


@pytest.fixture(scope="module")
def four_dof():
    """The energy-derived and the as-published 4-DOF models and the twin of the energy-derived one, from rest over
    0.02 s (the cross-check's default) on the step that resolves them all."""
    spec = load_train("double-planet")
    derived, published = PublishedSide(spec, "energy-derived"), PublishedSide(spec, "as-published")
    twin = PublishedTwinSide(spec, "energy-derived")
    dt = transient_step(np.concatenate([side.modes().frequencies for side in (derived, published, twin)]))
    return {side: side.run(RunSettings(0.02, dt)) for side in (derived, published, twin)}


def test_the_twin_of_the_4dof_model_reads_the_same_velocity_of_ring_b(four_dof):
    """theta_b' of the energy-derived model against its twin's hinge velocity: NRMSE below the cross-check's
    displacement tolerance (``dte.nrmse``, 0.01) -- the twin's rigid bodies carry the kinematics the 4-DOF model
    linearises (y1 reaches 3.9 mm beside r_h = 69 mm), and theta_b's acceleration, which the cross-check gates,
    agrees to 1.4e-3.  Measured 2.7e-3, the same at half the step (a model difference, not integration error).  The
    as-published model (Eqs. 11-12 drop the y1 coupling) is off by 0.90 of it."""
    runs = list(four_dof.values())
    derived, published, twin = runs
    for run in runs:
        assert {f"{label}.{what}" for label in LABELS for what in ("velocity", "acceleration")} | set(LABELS) == set(
            run.names())
        assert run.signal("theta_b.velocity").unit == "rad/s" and run.signal("y1.velocity").unit == "m/s"
    theta_b = derived["theta_b.velocity"]
    assert rms(twin["theta_b.velocity"] - theta_b) < 0.01 * rms(theta_b)
    assert rms(published["theta_b.velocity"] - theta_b) > 0.5 * rms(theta_b)


@pytest.mark.parametrize("side", [0, 2])
def test_each_4dof_velocity_is_the_rate_of_its_coordinate(four_dof, side):
    """As for a train's members (tests/test_member_motion.py): the RMS of the central differences less the velocity
    is at most a quarter of the RMS of the velocity's second differences (h^2 x'''/6 against h^2 x''')."""
    run = list(four_dof.values())[side]
    h = run.t[1] - run.t[0]
    for label in LABELS:
        x, v = run[label], run[f"{label}.velocity"]
        error = rms((x[2:] - x[:-2]) / (2 * h) - v[1:-1])
        assert error <= rms(v[2:] - 2 * v[1:-1] + v[:-2]) / 4, label
