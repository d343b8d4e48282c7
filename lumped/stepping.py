"""The fixed RK4 time step both solvers take by default and refuse beyond.

RK4 is stable for omega h < 2.83 on an undamped mode.  A step above ``STABILITY_MARGIN`` times
that limit for the highest natural frequency omega_max (every mesh at its cycle-maximum
stiffness) is refused; the default takes ``POINTS_PER_PERIOD`` steps per period of that mode and
at least ``POINTS_PER_MESH_CYCLE`` per mesh cycle, made a whole fraction of the slowest mesh
period (:func:`lumped.excitation.commensurate_step`).  Each solver supplies its own omega_max:
the lumped model's eigenvalues, or MuJoCo's own linearisation.
"""

from __future__ import annotations

import math

from .errors import SolverError
from .excitation import commensurate_step

RK4_LIMIT = 2.0 * math.sqrt(2.0)
STABILITY_MARGIN = 0.9
POINTS_PER_PERIOD = 20
POINTS_PER_MESH_CYCLE = 64


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
