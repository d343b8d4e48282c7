"""The periodic steady state of the reference model by shooting, where its excitation has one period.

Where the train's drive has one period T (:func:`gearcheck.train.periods.common_period`: every time-varying part
of it a whole number of cycles over T), the steady response is T-periodic.  The state y = (q, v) after one period
of the compiled RK4 steps (:func:`gearcheck.lumped.time_solver.stepper`, the same steps, drive sampling and splits
as :func:`~gearcheck.lumped.time_solver.simulate`, with a step that divides T) is a map y(T) = P(y0), and the
steady state its fixed point, found from the static state by

* ``method="anderson"`` (default): Anderson acceleration of y <- P(y) (Walker & Ni 2011,
  :func:`gearcheck.shared.anderson.anderson`), one period run an iteration; on an affine map it is a Krylov method
  (GMRES in exact arithmetic), so it needs about as many runs as the map has modes that a period does not damp out
  (14-28 on the presets, 3 for a long period), and it takes the dead zones and contacts of a nonlinear model as
  they come.  Where it has not converged within ``MAX_ANDERSON_RUNS`` runs, Newton goes on from its last iterate;
* ``method="newton"``: Newton shooting, y0 <- y0 - (Phi - I)^-1 (P(y0) - y0), Phi = dP/dy0 by forward differences
  (2n runs), kept while each step shrinks the residual tenfold (a chord step costs one run).  For a linear model
  (no backlash, tip relief or pin contacts) P is affine, y(T) = Phi y0 + g, and one solve of
  (I - Phi) y0 = g is exact ("affine", 2n + 2 runs).

Either way the answer is the discrete orbit that time marching converges to, without the transient: a run
``simulate(model, RunSettings(duration, dt=result.dt), y0=result.y0)`` is steady from t = 0.  Where there is no
common period within the bound (hub-drive's two stages meet after 1491 periods of the slower mesh, three chained
demo-3p stages not within 64; the RV reducer's eccentrics turn once in 69 mesh periods: pass ``max_mesh_periods``
to shoot for it), or the drive is not periodic (a user torque function, a load ramp),
:func:`periodic_steady_state` raises
:class:`~gearcheck.shared.errors.SolverError` saying so: time-march and let the settle time
(:meth:`gearcheck.shared.settings.RunSettings.settle_time`) or the plan's steady-state detection find it.
"""

from __future__ import annotations

import math
import time as clock
from dataclasses import dataclass

import numpy as np

from gearcheck.lumped.time_solver import initial_state, step_limits, stepper
from gearcheck.shared import stepping
from gearcheck.shared.anderson import anderson
from gearcheck.shared.errors import SolverError
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.shooting import Shooting
from gearcheck.train.periods import MAX_MESH_PERIODS, common_period

MAX_ITERATIONS = 20  # Newton steps
MAX_ANDERSON_RUNS = 100


@dataclass(frozen=True)
class PeriodicSteadyState(Shooting):
    """The state at t = 0 of the T-periodic steady response and how it was found (:class:`Shooting`; method
    "anderson", "anderson, then newton", "affine" (Newton on a linear model: one solve) or "newton"; the residual
    max |y(T) - y0| over the largest |y| of the first guess, v weighted by 1/omega_max).

    q, v: pass ``(q, v)`` as ``y0`` to :func:`~gearcheck.lumped.time_solver.simulate` with ``dt``."""

    q: np.ndarray
    v: np.ndarray

    @property
    def y0(self) -> tuple[np.ndarray, np.ndarray]:
        return self.q, self.v


def _is_linear(model) -> bool:
    exc = model.excitation
    return not (np.any(exc.backlash > 0) or exc.relieved.size or not all(e.smooth for e in model.turning))


class _PeriodMap:
    """P(z) in scaled coordinates z = w y / scale (q in its units, v over omega_max, both over the largest of the
    first guess), counting its runs."""

    def __init__(self, run, w: np.ndarray, scale: float):
        self.run, self.w, self.scale, self.runs = run, w, scale, 0

    def __call__(self, z: np.ndarray) -> np.ndarray:
        self.runs += 1
        y = z * self.scale / self.w
        n = y.size // 2
        return np.concatenate(self.run(y[:n], y[n:])) * self.w / self.scale


def _newton(P: _PeriodMap, z: np.ndarray, tolerance: float, linear: bool, name: str):
    """Newton shooting with Phi = dP/dz by forward differences, 2n runs a column set, kept while each step shrinks
    the residual tenfold (a chord step): (z, residual, iterations).  A linear model's map is affine: one solve,
    exact whatever the differences' step, then one run to measure the residual."""
    size = z.size
    residual = last = math.inf
    jacobian = None
    for iteration in range(MAX_ITERATIONS + 1):
        zT = P(z)
        r = zT - z
        residual = float(np.max(np.abs(r)))
        if residual <= tolerance or (linear and iteration == 1) or iteration == MAX_ITERATIONS:
            return z, residual, iteration
        if jacobian is None or residual > 0.1 * last:
            eps = 1.0 if linear else 1e-6
            phi = np.empty((size, size))
            for i in range(size):
                zi = z.copy()
                zi[i] += eps
                phi[:, i] = (P(zi) - zT) / eps
            jacobian = np.eye(size) - phi
            if np.linalg.cond(jacobian) > 1e12:
                raise SolverError(f"{name}: I - Phi over one period is singular (a mode that neither decays nor "
                                  "grows, e.g. a rigid-body rotation): no unique periodic steady state; time-march "
                                  "instead")
        last = residual
        z = z + np.linalg.solve(jacobian, r)
    return z, residual, MAX_ITERATIONS  # pragma: no cover (the loop returns)


def periodic_steady_state(model, dt: float | None = None, tolerance: float = 1e-10,
                          y0=None, method: str = "anderson", max_mesh_periods: int = MAX_MESH_PERIODS
                          ) -> PeriodicSteadyState:
    """The T-periodic steady state of ``model`` (see the module docstring), T from :func:`common_period`.

    dt: the RK4 step, made a whole fraction of T (default: :func:`~gearcheck.lumped.time_solver.default_step`,
    rounded down to one); tolerance: on the residual
    max |y(T) - y0| (v over omega_max) over the largest |y0|; y0: the first guess (default: the static state);
    method: "anderson" (falls back to Newton where it has not converged in ``MAX_ANDERSON_RUNS`` runs) or "newton";
    max_mesh_periods: the longest common period sought (:func:`common_period`).
    Raises SolverError when the excitation has no common period, I - Phi is singular (a rigid-body mode: no
    unique periodic orbit) or shooting does not converge."""
    if method not in ("anderson", "newton"):
        raise SolverError(f"method must be 'anderson' or 'newton', not {method!r}")
    started = clock.perf_counter()
    period = common_period(model.excitation, max_mesh_periods)
    name = model.spec.name
    limits = step_limits(model)
    h = stepping.default_step(limits, model.excitation.frequency) if dt is None else dt
    stepping.check_step(h, limits, model.excitation.frequency, f"lumped model of {name}")
    steps = max(1, math.ceil(period / h - 1e-9))
    h = period / steps
    n = model.n
    w = np.concatenate([np.ones(n), np.full(n, 1.0 / limits.omega_max)])  # v in a displacement's units
    q0, v0 = initial_state(model) if y0 is None else y0
    y = np.concatenate([q0, v0])
    scale = float(np.max(np.abs(w * y))) or 1e-6
    run, sub_steps = stepper(model, h, steps)
    P = _PeriodMap(run, w, scale)
    z, residual, iterations = w * y / scale, math.inf, 0
    if method == "anderson":
        z, residual, iterations = anderson(P, z, tolerance, MAX_ANDERSON_RUNS)
    used = method
    if residual > tolerance:
        linear = _is_linear(model)
        used = "anderson, then newton" if method == "anderson" else "affine" if linear else "newton"
        z, residual, newton = _newton(P, z, tolerance, linear, name)
        iterations += newton
    if residual > tolerance:
        raise SolverError(f"{name}: shooting did not converge (residual {residual:.3g} > {tolerance:g} after "
                          f"{P.runs} period runs); time-march with a settle time (RunSettings.settle) instead")
    y = z * scale / w
    info = RunInfo("numba-rk4", P.runs * steps, 4, 4 * P.runs * sub_steps, clock.perf_counter() - started,
                   {"method": used, "dt_s": h, "steps": P.runs * steps})
    return PeriodicSteadyState(q=y[:n].copy(), v=y[n:].copy(), period=period, dt=h, steps=steps, method=used,
                               iterations=iterations, residual=residual, runs=P.runs, info=info)
