"""The rotating frames under an operating history: every frame term at the speed of the moment.

The model is assembled at its reference speed (:mod:`gearcheck.lumped.assembly`).  Under a history every nominal
speed is lambda(t) times its reference value (:class:`gearcheck.train.history.Clock`), so at each stage's time

    Coriolis and the supports' circulatory damping  ~ lambda       G, K_circulatory
    centripetal stiffness and the orbits' load      ~ lambda^2     K_centripetal, F_centripetal
    the drag of turning members                     ~ lambda       F_static - F_centripetal
    Euler terms of the frames' acceleration         ~ lambda'      K_euler (Omega' k x q, and the Euler load on
                                                                   a planet's turned tangent)
    the loads that accelerate the rigid train       ~ lambda'      F_inertia (-J w, -m r_c Omega per unit lambda')

(a member's inertial acceleration along rotating axes is q'' + 2 Omega k x q' + Omega' k x (q + r0)
- Omega^2 (q + r0); Meirovitch 1970, Ch. 1, for the terms of a rotating frame; the rotations are absolute angles
about the nominal angle w Lambda(t), so their nominal acceleration w lambda' appears as the load -J w lambda').
The model's own matrices hold the lambda = 1 values; :class:`FrameSchedule` adds the differences, as a turning
element (:class:`~gearcheck.lumped.elements.base.Turning`) that the time solvers call at every stage, compiled
(:class:`Schedule`).  At lambda = 1, lambda' = 0 it adds exact zeros: the constant-speed run to the bit.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
from numba import njit

from gearcheck.lumped.compiled_steps import Sparse
from gearcheck.lumped.elements.base import Turning, compiled_group
from gearcheck.shared.errors import UnsupportedError


class Schedule(NamedTuple):
    """The compiled form: ``active`` 0 or 1, the clock's ``knots`` and cubic ``coef``, the terms as sparse rows
    (G, K_centripetal, K_circulatory, K_euler) and vectors (F_centripetal, drag, F_inertia)."""

    active: int
    knots: np.ndarray
    coef: np.ndarray
    G: Sparse
    K2: Sparse
    K1: Sparse
    KE: Sparse
    F2: np.ndarray
    F1: np.ndarray
    FE: np.ndarray

    @classmethod
    def of(cls, schedules) -> "Schedule":
        if not schedules:
            none = Sparse.of(np.zeros((0, 0)))
            return cls(0, np.zeros(1), np.zeros((1, 4)), none, none, none, none, np.zeros(0), np.zeros(0), np.zeros(0))
        s = schedules[0]
        c = s.clock
        return cls(1, c.knots, c.coef, *(Sparse.of(x) for x in (s.G, s.K2, s.K1, s.KE)), s.F2, s.F1, s.FE)


@dataclass(frozen=True, eq=False)
class FrameSchedule(Turning):
    """The frame terms' change from their reference values under the nominal clock ``clock``."""

    clock: object  # gearcheck.train.history.Clock
    G: np.ndarray
    K2: np.ndarray  # ~ lambda^2
    K1: np.ndarray  # ~ lambda
    KE: np.ndarray  # ~ lambda'
    F2: np.ndarray
    F1: np.ndarray
    FE: np.ndarray
    rows: tuple = ()
    compiled = Schedule
    words = "an operating history (the frames' speed changing with time)"

    def forces(self, t, q, v) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        lam, rate = self.clock.scale(t)[..., None], self.clock.rate(t)[..., None]
        a, b = lam - 1.0, lam * lam - 1.0
        return (b * self.F2 + a * self.F1 + rate * self.FE
                - a * (v @ self.G.T) - b * (q @ self.K2.T) - a * (q @ self.K1.T) - rate * (q @ self.KE.T))

    def without_frame_terms(self):
        zero = np.zeros_like(self.G)
        return FrameSchedule(self.clock, zero, zero, zero, zero, np.zeros_like(self.F2), self.F1, self.FE)


def with_schedule(model):
    """``model`` with its history's :class:`FrameSchedule` among its turning elements (itself without a history);
    refused, in one line, where another element's rows turn with the nominal time (they would need the clock too)."""
    clock = model.excitation.clock
    if clock is None:
        return model
    if model.turning:
        raise UnsupportedError(f"{model.spec.name}: an operating history with {model.turning[0].words} is not "
                               "supported yet (its rows turn with the nominal time at the reference speed)")
    drag = model.F_static - model.F_centripetal - (0.0 if model.F_rest is None else model.F_rest)
    schedule = FrameSchedule(clock, model.G, model.K_centripetal, model.K_circulatory, model.K_euler,
                             model.F_centripetal, drag, model.F_inertia)
    return replace(model, turning=[schedule if model.rotating_frame_terms else schedule.without_frame_terms()])


@njit(inline="always")
def _row_times(sparse, i, x):
    p, idx, data = sparse
    total = 0.0
    for k in range(p[i], p[i + 1]):
        total += data[k] * x[idx[k]]
    return total


@njit(inline="always")
def schedule_forces(s, at) -> None:
    """The compiled steps' form of :meth:`FrameSchedule.forces`, added into ``out`` of ``at`` = (x, u, t, out)."""
    if s.active == 0:
        return
    x, u, t, out = at
    knots, coef = s.knots, s.coef
    k = np.searchsorted(knots, t, side="right") - 1
    k = min(max(k, 0), knots.size - 1)
    d = t - knots[k]
    lam = coef[k, 0] + d * (coef[k, 1] + d * (coef[k, 2] + d * coef[k, 3]))
    rate = coef[k, 1] + d * (2.0 * coef[k, 2] + d * 3.0 * coef[k, 3])
    a, b = lam - 1.0, lam * lam - 1.0
    for i in range(x.size):
        f = b * s.F2[i] + a * s.F1[i] + rate * s.FE[i]
        f -= a * _row_times(s.G, i, u) + b * _row_times(s.K2, i, x) + a * _row_times(s.K1, i, x)
        f -= rate * _row_times(s.KE, i, x)
        out[i] += f


compiled_group(Schedule, schedule_forces)
