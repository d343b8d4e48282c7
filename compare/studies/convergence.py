"""The observed convergence order of a solver on a train: the same run at h, h/2, h/4, ... compared on one grid;
and how well the cross-check's integration error estimate tracks the error itself.

For a method of order p the difference between the runs at h and h/2 falls as h^p, so successive halvings give

    p = log2(d(h) / d(h/2)),   d(h) = max |y_h - y_(h/2)| / max |y_finest|,

per kind of signal (transmission error, mesh force, accelerations), without a reference solution (Richardson's
argument; Hairer, Norsett & Wanner 1993, sec. II.4).  A difference at round-off gives no order (NaN).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.lumped import time_solver
from gearcheck.lumped.assembly import build_model
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import richardson_factor, stable_step

KINDS = ("dte", "mesh_force", "acceleration")
ROUND_OFF = 1e-9  # relative differences below this are round-off (a twin's planet accelerations reach 1e-10)
FINEST = 16  # the error of a run at h is measured against the same run at h / FINEST (its error 16^4 times less)


def coarsest_step(spec, multiple: float) -> float:
    """``multiple`` lumped default steps, at most the largest step either solver takes stably."""
    model = build_model(spec)
    return min(multiple * time_solver.default_step(model), time_solver.stable_step(model),
               stable_step(compile_train(spec).limits))


def halvings(spec, solver: str, h: float, steps: int, levels: int) -> list:
    """``solver`` ("lumped" or "mujoco") on ``spec`` from its own static start over ``steps`` steps of h, at h,
    h/2, ... (``levels`` runs), each sampled every h."""
    if solver == "lumped":
        model = build_model(spec)
        return [time_solver.simulate(model, RunSettings(duration=steps * h, dt=h / 2**i, output_dt=h))
                for i in range(levels)]
    twin = compile_train(spec)
    return [simulate_mujoco(twin, RunSettings(duration=steps * h, dt=h / 2**i, output_dt=h)) for i in range(levels)]


def observed_orders(results, kinds=KINDS) -> dict[str, tuple[list[float], list[float]]]:
    """kind -> (the orders of successive halvings, the relative differences d), from :func:`halvings`' runs."""
    out = {}
    for kind in kinds:
        y = [r.select(kind) for r in results]
        n = min(len(x) for x in y)
        scale = float(np.max(np.abs(y[-1][:n]))) or 1.0
        d = [float(np.max(np.abs(a[:n] - b[:n]))) / scale for a, b in zip(y, y[1:])]
        p = [math.log2(a / b) if min(a, b) > ROUND_OFF else math.nan for a, b in zip(d, d[1:])]
        out[kind] = (p, d)
    return out


def estimate_tracking(side, h: float, duration: float, start: float, names) -> dict[str, tuple[float, float]]:
    """name -> (the cross-check's estimate of the error of ``side``'s run at step ``h``, the error itself), both
    relative to the run's RMS over t >= ``start``: the estimate Richardson's, from the same run at 2 h
    (:func:`gearcheck.shared.stepping.richardson_factor`), the error against the same run at h / ``FINEST``.
    All three runs start from the same state and are sampled at the same instants (every 2 h)."""
    run, check, fine = (side.run(RunSettings(duration, dt=h * f, output_dt=2 * h)) for f in (1, 2, 1 / FINEST))
    n = min(run.t.size, check.t.size, fine.t.size)
    window = run.t[:n] >= start
    out = {}
    for name in names:
        x, x2, xf = (r[name][:n][window] for r in (run, check, fine))
        scale = float(np.sqrt(np.mean(x**2)))
        if scale > 0.0:
            out[name] = (richardson_factor(2.0) * _rms(x2 - x) / scale, _rms(x - xf) / scale)
    return out


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))
