"""An interstage coupling: torsion between two central members and, with a radial stiffness, both
translations; across frames that turn at different speeds, the radial part turns with time
(:class:`TurningCoupling`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row, Turning, compiled_group
from gearcheck.train.spec import ROTATION


@ELEMENTS.register("coupling")
def coupling_rows(part, build: Build) -> Contribution:
    spec, dofs, c = build.spec, build.dofs, part
    rows = [Row(f"{c.name}.torsion", "coupling", dofs.unit((c.a, ROTATION, 1.0), (c.b, ROTATION, -1.0)),
                c.torsional_stiffness, c.torsional_damping)]
    turning = []
    if c.radial_stiffness or c.radial_damping:
        axes = spec.members[c.a].dofs[:2]
        for axis in axes:
            rows.append(Row(f"{c.name}.{axis}", "coupling", dofs.unit((c.a, axis, 1.0), (c.b, axis, -1.0)),
                            c.radial_stiffness, c.radial_damping))
        wa = build.kin.speeds[f"{spec.members[c.a].stage}.carrier"]
        wb = build.kin.speeds[f"{spec.members[c.b].stage}.carrier"]
        if abs(wa - wb) > 1e-12 * max(abs(wa), abs(wb), 1.0):
            turning.append(TurningCoupling(tuple(dofs(c.a, x) for x in axes), tuple(dofs(c.b, x) for x in axes),
                                           wa, wb, c.radial_stiffness, c.radial_damping,
                                           tuple(f"{c.name}.{axis}" for axis in axes)))
    return Contribution(rows, turning=turning)


class Couplings(NamedTuple):
    """Radial couplings between turning frames: ``index`` (T, 4) the (a_x, a_y, b_x, b_y) coordinates, ``values``
    (T, 4) their (Omega_a, Omega_b, stiffness, damping)."""

    index: np.ndarray
    values: np.ndarray

    @classmethod
    def of(cls, couplings) -> "Couplings":
        return cls(np.array([[*e.a, *e.b] for e in couplings], dtype=np.int64).reshape(-1, 4),
                   np.array([[e.omega_a, e.omega_b, e.stiffness, e.damping] for e in couplings],
                            dtype=float).reshape(-1, 4))


@dataclass(frozen=True)
class TurningCoupling(Turning):
    """A radial coupling between members whose frames turn at different speeds (a ring shared by two
    stages, a radial spline between stages): member b's frame turns by phi = (Omega_b - Omega_a) t
    relative to a's, so the coupling's rows are periodic in time.  Its rows in ``rows`` are those of
    t = 0, when every frame coincides (what the modal and static analyses use, like MuJoCo's
    linearisation at its initial configuration); the time solver replaces them by
    :meth:`forces` at every stage."""

    a: tuple[int, int]  # (x, y) coordinates of member a
    b: tuple[int, int]
    omega_a: float
    omega_b: float
    stiffness: float
    damping: float
    rows: tuple[str, str]  # names of its t = 0 rows
    compiled = Couplings
    words = "a radial coupling between frames that turn apart"

    def forces(self, t, q, v) -> np.ndarray:
        """Generalized forces (time along axis 0 allowed) of the spring-damper between the two centres,
        acting on world-frame displacement and velocity and resolved in each member's own axes."""
        phi = (self.omega_b - self.omega_a) * np.asarray(t, dtype=float)
        c, s = np.cos(phi), np.sin(phi)
        ua = np.stack([q[..., self.a[0]], q[..., self.a[1]]], axis=-1)
        ub = np.stack([q[..., self.b[0]], q[..., self.b[1]]], axis=-1)
        # world velocities in own axes: u' + Omega k x u
        va = np.stack([v[..., self.a[0]] - self.omega_a * ua[..., 1], v[..., self.a[1]] + self.omega_a * ua[..., 0]],
                      axis=-1)
        vb = np.stack([v[..., self.b[0]] - self.omega_b * ub[..., 1], v[..., self.b[1]] + self.omega_b * ub[..., 0]],
                      axis=-1)
        # b's vectors in a's axes: R(phi) x
        rot = lambda x: np.stack([c * x[..., 0] - s * x[..., 1], s * x[..., 0] + c * x[..., 1]], axis=-1)  # noqa
        pull = self.stiffness * (ua - rot(ub)) + self.damping * (va - rot(vb))  # force on b, in a's axes
        on_b = np.stack([c * pull[..., 0] + s * pull[..., 1], -s * pull[..., 0] + c * pull[..., 1]], axis=-1)
        out = np.zeros(np.shape(q))
        out[..., self.a[0]] -= pull[..., 0]
        out[..., self.a[1]] -= pull[..., 1]
        out[..., self.b[0]] += on_b[..., 0]
        out[..., self.b[1]] += on_b[..., 1]
        return out


@njit(inline="always")
def coupling_forces(couplings, at) -> None:
    """The compiled steps' form of :meth:`TurningCoupling.forces`: every radial coupling between turning frames at
    ``at`` = (x, u, t, out), state (x, u) and time t, added into ``out`` (:mod:`gearcheck.lumped.compiled_steps`)."""
    x, u, t, out = at
    coupling_index, coupling = couplings
    for w in range(coupling.shape[0]):
        wa, wb, kc, cc = coupling[w, 0], coupling[w, 1], coupling[w, 2], coupling[w, 3]
        i0, i1, i2, i3 = coupling_index[w, 0], coupling_index[w, 1], coupling_index[w, 2], coupling_index[w, 3]
        phi = (wb - wa) * t
        cs, sn = np.cos(phi), np.sin(phi)
        va0, va1 = u[i0] - wa * x[i1], u[i1] + wa * x[i0]
        vb0, vb1 = u[i2] - wb * x[i3], u[i3] + wb * x[i2]
        p0 = kc * (x[i0] - (cs * x[i2] - sn * x[i3])) + cc * (va0 - (cs * vb0 - sn * vb1))
        p1 = kc * (x[i1] - (sn * x[i2] + cs * x[i3])) + cc * (va1 - (sn * vb0 + cs * vb1))
        out[i0] -= p0
        out[i1] -= p1
        out[i2] += cs * p0 + sn * p1
        out[i3] += -sn * p0 + cs * p1


compiled_group(Couplings, coupling_forces)
