"""The fixed RK4 time step both solvers take by default and refuse beyond, and how a step samples
the drive.

RK4 is stable for omega h < 2.83 on an undamped mode.  A step above ``STABILITY_MARGIN`` times
that limit for the highest natural frequency omega_max (every mesh at its cycle-maximum
stiffness) is refused; the default takes ``POINTS_PER_PERIOD`` steps per period of that mode and
at least ``POINTS_PER_MESH_CYCLE`` per mesh cycle, made a whole fraction of the slowest mesh
period (:func:`commensurate_step`).  Each solver supplies its own omega_max: the lumped model's
eigenvalues, or MuJoCo's own linearisation.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import SolverError

RK4_LIMIT = 2.0 * math.sqrt(2.0)
STABILITY_MARGIN = 0.9
POINTS_PER_PERIOD = 20
POINTS_PER_MESH_CYCLE = 64

STAGE_OFFSETS = (1e-9, 0.5, 1.0 - 1e-9)
"""Where a fixed-step solver samples the drive within a step [t, t + h]: just after t, at the
midpoint, just before t + h.  A stiffness switch that falls on a step boundary is then seen
on the same side by every mesh, whatever the round-off in its phase (planets with equal
phases stay identical, so the symmetry that mesh phasing relies on survives)."""

STEP_WEIGHTS = (4.0 / 5.0, 1.0 / 5.0)
"""Per-step drive (MuJoCo holds model fields and controls constant over a step after its first
RK4 stage): stage 1 sees x(t), stages 2-4 see (4 x(t + h/2) + x(t + h))/5.  With RK4's stage
weights (2, 2, 1)/6 this integrates a drive linear in time over the step exactly; a stiffness
switch inside a step is then seen as a weighted mean, the same in both solvers."""


def commensurate_step(h_max: float, mesh_frequencies, points_per_cycle: int) -> float:
    """The largest step <= h_max that divides the slowest mesh period into whole steps, with at
    least ``points_per_cycle`` steps per period of the fastest mesh.  A rectangular stiffness
    then switches at the same point of the step in every cycle and the discrete steady
    response is periodic, like the physical one (an incommensurate step dithers the switching
    instants from cycle to cycle)."""
    f = np.asarray(mesh_frequencies, dtype=float)
    f = f[f > 0]
    if f.size == 0:
        return h_max
    h = min(h_max, 1.0 / (points_per_cycle * f.max()))
    period = 1.0 / f.min()
    return float(period / math.ceil(period / h - 1e-9))


def stable_step(omega_max: float) -> float:
    return STABILITY_MARGIN * RK4_LIMIT / omega_max


def default_step(omega_max: float, mesh_frequencies) -> float:
    h = 2.0 * math.pi / (POINTS_PER_PERIOD * omega_max)
    return commensurate_step(h, mesh_frequencies, POINTS_PER_MESH_CYCLE)


def check_step(dt, omega_max: float, mesh_frequencies, model: str) -> None:
    """Refuse a step that is not a positive number or that RK4 cannot run stably on ``model``
    (named in the message, e.g. 'MuJoCo model of demo-3p')."""
    if not (isinstance(dt, (int, float)) and dt > 0 and math.isfinite(dt)):
        raise SolverError(f"time step must be a positive number of seconds, got {dt!r}")
    limit = stable_step(omega_max)
    if dt > limit:
        raise SolverError(
            f"time step {dt:.4g} s is unstable for the {model}: it cannot resolve the highest natural frequency "
            f"{omega_max / (2 * math.pi):.6g} Hz (meshes at maximum stiffness); RK4 is stable only for "
            f"dt < 2.83/omega_max = {RK4_LIMIT / omega_max:.4g} s; use dt <= "
            f"{default_step(omega_max, mesh_frequencies):.4g} s (the default) or at most {limit:.4g} s")


def per_step_drive(x: np.ndarray) -> np.ndarray:
    """Drive samples (steps, 3 stage times, ...) at :data:`STAGE_OFFSETS` -> stage 1 unchanged, stages
    2-4 the weighted mean :data:`STEP_WEIGHTS` (what a solver that holds its drive over a step sees)."""
    out = x.copy()
    out[:, 1] = out[:, 2] = STEP_WEIGHTS[0] * x[:, 1] + STEP_WEIGHTS[1] * x[:, 2]
    return out


TRANSIENT_POINTS_PER_PERIOD = 40.0


def transient_step(frequencies) -> float:
    """The step of a transient run compared sample by sample (the 4-DOF start-stop regime): the
    shortest natural period (of the highest of ``frequencies``, Hz) over
    ``TRANSIENT_POINTS_PER_PERIOD``."""
    return 1.0 / (float(np.max(frequencies)) * TRANSIENT_POINTS_PER_PERIOD)
