"""Every stepper of both sides against one problem with a closed-form solution, as scipy.integrate's tests check
theirs: errors normalised by the error the method is expected to make at its step (or tolerance), and the work
each run reports (:class:`~gearcheck.shared.run_info.RunInfo`) asserted.

The problem: demo-3p with a constant mesh stiffness, at 1 rpm, from its unloaded static state, loaded at t = 0
by a step of its torques (0.015 N·m on the carrier and the input torque that balances it).  Its equations are
linear with constant coefficients, M q'' + C q' + K q = F (the lumped model's M, C + G, K_mean + K_frame and mean
load; a :class:`~gearcheck.lumped.linear_model.LinearModel`'s own matrices).  With y = (q, q'),

    y' = A y + b,   A = [[0, I], [-M^-1 K, -M^-1 C]],   b = (0, M^-1 F),

and the equilibrium y_s = (K^-1 F, 0) (K is regular: the input shaft and the ring's support hold every rotation).
The departure e = y - y_s obeys e' = A e, so e(t) = exp(A t) e(0):

    y(t) = y_s + exp(A t) (y(0) - y_s),

evaluated on the sample grid t_j = j dt_out by e_(j+1) = exp(A dt_out) e_j (round-off grows like j eps).  Every run
is compared through the mesh deflections a_m.q (its ``MESH.dte``), relative to their largest change.

Why 1 rpm and a light load: the MuJoCo twin's bodies move on their real joints (the planets on the turning carrier,
the mesh coefficients turned with it), so its equations are the linear ones up to terms of the order of the
vibration's amplitude: 1e-4 of the response at the preset's 1500 N·m, 1e-9 at 0.015 N·m, below the integration
error.  The stiffness is constant, so RK4 keeps its fourth order on both sides (no jumps to split steps at, and a
constant drive is sampled exactly however a stepper samples it).

Not in the matrix: the published 4-DOF twin (``mujoco-step``, :func:`gearcheck.mbd_models.published_twin.
simulate_twin`) runs a paper's parameter set, not a train: it cannot represent this problem.
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.linalg import expm

from gearcheck.lumped import time_solver
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.export import reference_linear_model
from gearcheck.lumped.linear_run import simulate_linear
from gearcheck.lumped.static import mean_load, static_solution
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.static_state import static_state
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings
from gearcheck.train.variants import edited

STEP_LOAD = [(r'model = "rectangular"', 'model = "constant"'), (r"^input_speed_rpm = .*", "input_speed_rpm = 1.0"),
             (r"^output_torque = 1500.0", "output_torque = 0.015")]
RK4_STEPS = 1064  # 0.004 s at the default step: 60 periods of the fastest mode
ADAPTIVE_STEPS = 272  # 0.001 s, a whole number of samples
EVERY = 8  # default steps between samples
ORDER = 4


@pytest.fixture(scope="module")
def problem():
    spec = edited("demo-3p", STEP_LOAD, "constant stiffness, step load")
    model = build_model(spec)
    return spec, model, time_solver.default_step(model)


def exact(M, C, K, F, y0, t) -> np.ndarray:
    """y(t) = y_s + exp(A t)(y0 - y_s) (see the module docstring) on the uniform grid t, time along axis 0."""
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ys = np.concatenate([np.linalg.solve(K, F), np.zeros(n)])
    step, e = expm(A * (t[1] - t[0])), y0 - ys
    y = [e]
    for _ in t[1:]:
        e = step @ e
        y.append(e)
    return np.array(y) + ys


def unloaded(model) -> np.ndarray:
    """The lumped model's unloaded static state (q, q')."""
    return np.concatenate([static_solution(model, load_scale=0.0).q, np.zeros(model.n)])


def lumped_exact(model, t) -> np.ndarray:
    return exact(model.M, model.C + model.G, model.K_mean + model.K_frame, mean_load(model), unloaded(model), t)


def deflections(result, spec) -> np.ndarray:
    return np.column_stack([result[f"{mesh.id}.dte"] for mesh in spec.meshes])


def lumped_run(spec, model, settings, **options):
    """(result, its mesh deflections, the exact ones) of :func:`~gearcheck.lumped.time_solver.simulate`."""
    y0 = unloaded(model)
    result = time_solver.simulate(model, settings, y0=(y0[:model.n], y0[model.n:]), **options)
    return result, deflections(result, spec), lumped_exact(model, result.t)[:, :model.n] @ model.mesh_rows.T


def linear_run(spec, model, settings):
    """The reference model as a user's linear model (:func:`~gearcheck.lumped.export.reference_linear_model`),
    from rest (its way to start unloaded: q = 0), against the exact solution of its own matrices."""
    linear = dataclasses.replace(reference_linear_model(spec), start="rest")
    result = simulate_linear(linear, settings)
    K = linear.K_mean + linear.matrix("K_omega")
    want = exact(linear.M, linear.damping, K, linear.F_at(0.0), np.zeros(2 * linear.n), result.t)
    q = np.column_stack([result[name] for name in linear.coordinates])
    return result, q @ linear.mesh_rows.T, want[:, :linear.n] @ linear.mesh_rows.T


def mujoco_run(spec, model, settings, **options):
    """:func:`~gearcheck.mbd_models.runner.simulate_mujoco` from the twin's own unloaded static state."""
    mb = compile_train(spec)
    start = static_state(mb, 0.0)
    result = simulate_mujoco(mb, settings, initial_state=(start.qpos, start.qvel), **options)
    return result, deflections(result, spec), lumped_exact(model, result.t)[:, :model.n] @ model.mesh_rows.T


RK4_STEPPERS = {  # name: (the engine it reports, run, options)
    "numba-rk4": ("numba-rk4", lumped_run, {}),
    "python-rk4": ("python-rk4", lumped_run, {"method": "rk4-stages"}),
    "linear-rk4": ("linear-rk4", linear_run, {}),
    "mujoco-compiled": ("mujoco-compiled", mujoco_run, {"engine": "compiled"}),
    "mujoco-python": ("mujoco-python", mujoco_run, {"engine": "python"}),
}


@pytest.mark.parametrize("stepper", list(RK4_STEPPERS))
def test_rk4_steppers_converge_to_the_exact_solution_at_fourth_order(problem, stepper):
    """At the default step h and at h/2: the error at h (measured 1.5e-6 of the response) is the one expected of a
    fourth-order method, the Richardson estimate |y_h - y_(h/2)| 2^4/(2^4 - 1), within 10 % (measured 0.998 of it);
    the error falls 2^4-fold (observed order 4 +- 0.3, measured 4.04-4.05: a third-order slip measures 3.0); 4
    right-hand sides (``mj_forward`` and RK4's stages for MuJoCo) a step."""
    spec, model, h = problem
    engine, run, options = RK4_STEPPERS[stepper]
    errors, runs = [], []
    for dt in (h, h / 2):
        result, got, want = run(spec, model, RunSettings(RK4_STEPS * h, dt=dt, output_dt=EVERY * h), **options)
        info = result.info
        assert (info.engine, info.stages, info.steps) == (engine, 4, round(RK4_STEPS * h / dt))
        assert info.rhs_calls == 4 * info.steps and info.wall_s > 0
        scale = np.max(np.abs(want - want[0]))
        errors.append(np.max(np.abs(got - want)) / scale)
        runs.append(got / scale)
    expected = np.max(np.abs(runs[0] - runs[1])) * 2**ORDER / (2**ORDER - 1)
    assert 0.9 < errors[0] / expected < 1.1
    assert abs(math.log2(errors[0] / errors[1]) - ORDER) < 0.3
    assert errors[0] < 1e-5  # the default step is accurate


ADAPTIVE = {"RK45": 5, "DOP853": 5, "Radau": 5, "BDF": 20, "LSODA": 20}  # bound on the normalised error
RTOL, ATOL = 1e-8, 1e-20  # atol below every state's scale: the tolerance is relative


@pytest.mark.parametrize("method", list(ADAPTIVE))
def test_scipy_methods_meet_their_tolerance(problem, method, monkeypatch):
    """scipy's methods over 0.001 s (each of their steps at most 8 default steps): the largest error of q and of
    q', each over RTOL times the largest |q| or |q'|, within a few tolerances (global errors of a local error
    control; bounds in ``ADAPTIVE``, measured at most 1.3, 2.3, 0.03, 9.3 and 6.6); the run reports scipy's count
    of right-hand sides, each of which evaluated the model's once (the implicit methods' Jacobian differences
    evaluate it more)."""
    spec, model, h = problem
    calls = []
    acceleration = time_solver._System.acceleration

    def counted(*args, **kwargs):
        calls.append(1)
        return acceleration(*args, **kwargs)

    monkeypatch.setattr(time_solver._System, "acceleration", counted)
    settings = RunSettings(ADAPTIVE_STEPS * h, dt=h, output_dt=EVERY * h)
    y0 = unloaded(model)
    result = time_solver.simulate(model, settings, method=method, rtol=RTOL, atol=ATOL,
                                  y0=(y0[:model.n], y0[model.n:]))
    info = result.info
    assert (info.engine, info.stages, info.steps) == (f"scipy-{method}", None, ADAPTIVE_STEPS)
    assert info.rhs_calls == info["rhs_evaluations"] > 0
    stepping = len(calls) - 1  # one more for the outputs
    assert stepping == info.rhs_calls if method in ("RK45", "DOP853") else stepping >= info.rhs_calls
    labels = model.dofs.labels()
    got = np.column_stack([result.raw[x] for x in labels] + [result.raw[x + "_dot"] for x in labels])
    want = lumped_exact(model, result.t)
    for part in (slice(0, model.n), slice(model.n, 2 * model.n)):
        error = np.max(np.abs(got[:, part] - want[:, part])) / (RTOL * np.max(np.abs(want[:, part])))
        assert error < ADAPTIVE[method]
