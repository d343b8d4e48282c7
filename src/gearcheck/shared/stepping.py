"""The fixed RK4 time step both solvers take by default and refuse beyond, and how a step samples
the drive.

RK4 is stable for omega h < 2.83 on an undamped mode and h |lambda| < 2.79 on an overdamped one
(:func:`rk4_stable_step` finds the limit for every eigenvalue of the damped system, every mesh at
its cycle-maximum stiffness).  A step above ``STABILITY_MARGIN`` times that limit is refused; the
default takes ``POINTS_PER_PERIOD`` steps per period of the highest natural frequency (at most the
refusal limit) and at least ``POINTS_PER_MESH_CYCLE`` per mesh cycle, made a whole fraction of the
slowest mesh period (:func:`commensurate_step`).  Each solver supplies its own matrices: the lumped
model's, or MuJoCo's own linearisation.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from gearcheck.shared.errors import SolverError

RK4_LIMIT = 2.0 * math.sqrt(2.0)
STABILITY_MARGIN = 0.9
POINTS_PER_PERIOD = 20
POINTS_PER_MESH_CYCLE = 64
ORDER = 4  # of both solvers' RK4, the drive set at every stage and contact events located (a test asserts it)

STAGE_OFFSETS = (0.0, 0.5, 1.0)
"""Where a fixed-step solver samples the drive within a step [t, t + h]: its start, midpoint and end."""

STAGE_SIDES = (1, 0, -1)
"""Which one-sided limit each stage sample takes of a drive that jumps there: the right-hand one at a step's start,
the left-hand one at its end (:data:`LIMIT_CYCLES`).  A stiffness switch that falls on a step boundary is then
seen on the same side by every mesh, whatever the round-off in its phase (planets with equal phases stay identical,
so the symmetry that mesh phasing relies on survives)."""

LIMIT_CYCLES = 1e-9
"""How far along its cycle a mesh's one-sided limit is read: far above the round-off of the cycle position
xi = f t - phase (eps f t, 3.6e-12 cycle after 16,000 cycles: 8 s at 2 kHz), far below any feature of a stiffness.
The limit was once read in time, 1e-9 of a step past t, which past a million steps fell within the round-off of t
itself: demo-3p at h/16 over 0.5 s, the sun's 1x line that three planets' phasing cancels read 0.33 rad/s^2 in
both solvers alike (0.0086 at h/4), the planets no longer seeing their switches on one side."""

SPLIT_MARGIN = 1e-9
"""A jump within this fraction of a step of a step boundary is left to the stages' one-sided limits (it lies well
inside :data:`LIMIT_CYCLES` of its mesh, a step being a small fraction of a mesh cycle) rather than split off."""


def split_steps(h: float, start: int, stop: int, switches, origin: float = 0.0) -> dict[int, np.ndarray]:
    """The steps among start..stop-1 (step i spans [origin + i h, origin + (i + 1) h]) inside which the drive jumps,
    each with the times of its jumps: both solvers end a sub-step there, so a rectangular mesh stiffness is
    constant over every (sub-)step and RK4 keeps its fourth order (a jump inside a step, seen as the step's mean,
    costs an error of the order of h).  A jump within ``SPLIT_MARGIN`` h of a step boundary is left to the
    stages' one-sided limits (:data:`STAGE_SIDES`), which see it on the same side in every mesh; jumps that close
    together are one."""
    switches = np.asarray(switches, dtype=float)
    since = switches - origin
    tol = SPLIT_MARGIN * h
    index = np.floor(since / h).astype(int)
    inside = ((since - index * h) > tol) & (((index + 1) * h - since) > tol) & (index >= start) & (index < stop)
    out: dict[int, np.ndarray] = {}
    for i, t in zip(index[inside], switches[inside]):
        times = out.get(int(i))
        if times is None:
            out[int(i)] = np.array([t])
        elif t - times[-1] > tol:
            out[int(i)] = np.append(times, t)
    return out


def sub_steps(t0: float, h: float, split: dict[int, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sub-steps of the ``split`` steps (:func:`split_steps`; step i spans [t0 + i h, t0 + (i + 1) h]), in the
    order of their steps: (each split step's count of sub-steps, the sub-steps' starts, their lengths), each step
    ended at its sorted inner times."""
    steps = sorted(split)
    counts = np.array([split[i].size + 1 for i in steps], dtype=np.int64)
    begins = t0 + np.array(steps, dtype=float) * h
    inner = np.concatenate([split[i] for i in steps]) if steps else np.empty(0)
    first = np.cumsum(counts) - counts
    starts, ends = np.empty(inner.size + counts.size), np.empty(inner.size + counts.size)
    later = np.ones(starts.size, dtype=bool)
    later[first] = False
    starts[first], starts[later] = begins, inner
    earlier = np.ones(ends.size, dtype=bool)
    earlier[first + counts - 1] = False
    ends[~earlier], ends[earlier] = begins + h, inner
    return counts, starts, ends - starts


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


@dataclass(frozen=True)
class StepLimits:
    """What bounds a model's RK4 step: its highest undamped natural angular frequency (rad/s, every mesh
    at its cycle-maximum stiffness), and the largest step at which RK4 keeps every mode of the damped
    first-order system from growing (s)."""

    omega_max: float
    stable: float

    @classmethod
    def of(cls, M: np.ndarray, K: np.ndarray, D: np.ndarray) -> "StepLimits":
        """The limits of M q'' + D q' + K q = 0 (D: damping and gyroscopic terms)."""
        return _limits(M.shape[0], np.concatenate([np.asarray(x, dtype=float).ravel() for x in (M, K, D)]).tobytes())


@functools.lru_cache(maxsize=64)
def _limits(n: int, matrices: bytes) -> StepLimits:
    """:meth:`StepLimits.of` of M, K, D given by their bytes: kept for the next ask of the same matrices (every run
    of a model checks its step, and a sweep point runs its model several times; 8 ms each on hub-drive)."""
    M, K, D = np.frombuffer(matrices).reshape(3, n, n).copy()
    w2 = sla.eigh(0.5 * (K + K.T), M, eigvals_only=True)
    MinvK, MinvD = np.linalg.solve(M, K), np.linalg.solve(M, D)
    J = np.block([[np.zeros((n, n)), np.eye(n)], [-MinvK, -MinvD]])
    return StepLimits(float(np.sqrt(max(w2.max(), 0.0))), rk4_stable_step(np.linalg.eigvals(J)))


def rk4_growth(z) -> np.ndarray:
    """|R(z)|, R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24: how much RK4 multiplies a mode per step (z = h lambda)."""
    return np.abs(1 + z * (1 + z * (1 / 2 + z * (1 / 6 + z / 24))))


def rk4_stable_step(eigenvalues) -> float:
    """The largest step h with |R(h lambda)| <= 1 for every eigenvalue lambda of y' = J y: 2.83/|lambda| for an
    undamped mode, 2.79/|lambda| for an overdamped one.  A mode that grows physically (Re lambda > 0, an
    instability of the model itself) is taken at its magnitude, as if undamped."""
    lam = np.asarray(eigenvalues, dtype=complex)
    lam = lam[np.abs(lam) > 1e-9 * np.max(np.abs(lam), initial=1.0)]
    if lam.size == 0:
        return math.inf
    rays = np.where(lam.real > 0, 1j, lam / np.abs(lam))  # directions of z = h lambda
    r = np.linspace(0.0, 3.0, 3001)[1:]
    outside = rk4_growth(np.outer(rays, r)) > 1 + 1e-12
    first = np.where(outside.any(axis=1), outside.argmax(axis=1), r.size - 1)
    best = math.inf
    for ray, i, size in zip(rays, first, np.abs(lam)):
        lo, hi = (r[i - 1] if i else 0.0), r[i]
        for _ in range(60):  # bisection on the ray to round-off
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if rk4_growth(mid * ray) <= 1 + 1e-12 else (lo, mid)
        best = min(best, lo / size)
    return best


def richardson_factor(ratio: float, order: int = ORDER) -> float:
    """What turns the change of a run at step h against the same run at ``ratio`` h (2 or 1/2) into an estimate
    of the run's own error, for an integrator of ``order`` p in its asymptotic range (Richardson's argument;
    Hairer, Norsett & Wanner 1993, sec. II.4): x_h - x = (x_2h - x_h) / (2^p - 1), or (x_h/2 - x_h) 2^p / (2^p - 1).
    """
    return 1.0 / (2**order - 1) if ratio > 1 else 2**order / (2**order - 1)


def stable_step(limits: StepLimits) -> float:
    return STABILITY_MARGIN * limits.stable


def undamped_stable_step(frequencies) -> float:
    """The stable step of an undamped model with natural frequencies ``frequencies`` (Hz)."""
    return STABILITY_MARGIN * RK4_LIMIT / (2.0 * math.pi * float(np.max(frequencies)))


def default_step(limits: StepLimits, mesh_frequencies) -> float:
    h = min(2.0 * math.pi / (POINTS_PER_PERIOD * limits.omega_max), stable_step(limits))
    return commensurate_step(h, mesh_frequencies, POINTS_PER_MESH_CYCLE)


def check_step(dt, limits: StepLimits, mesh_frequencies, model: str) -> None:
    """Refuse a step that is not a positive number or that RK4 cannot run stably on ``model``
    (named in the message, e.g. 'MuJoCo model of demo-3p')."""
    if not (isinstance(dt, (int, float)) and dt > 0 and math.isfinite(dt)):
        raise SolverError(f"time step must be a positive number of seconds, got {dt!r}")
    limit = stable_step(limits)
    if dt > limit:
        raise SolverError(
            f"time step {dt:.4g} s is unstable for the {model}: RK4 keeps its modes from growing only for "
            f"dt < {limits.stable:.4g} s (highest natural frequency {limits.omega_max / (2 * math.pi):.6g} Hz with "
            f"the meshes at maximum stiffness, and its damping); use dt <= "
            f"{default_step(limits, mesh_frequencies):.4g} s (the default) or at most {limit:.4g} s")


TRANSIENT_POINTS_PER_PERIOD = 40.0


def transient_step(frequencies) -> float:
    """The step of a transient run compared sample by sample (the 4-DOF start-stop regime): the
    shortest natural period (of the highest of ``frequencies``, Hz) over
    ``TRANSIENT_POINTS_PER_PERIOD``."""
    return 1.0 / (float(np.max(frequencies)) * TRANSIENT_POINTS_PER_PERIOD)
