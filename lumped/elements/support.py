"""A member on the housing: a spring-damper on each translation, on the rotation when it has torsional
stiffness or damping, along the axis when the member slides axially, and on each tilt when it tilts.

A tilting member's radial stiffness may be shared over bearing stations along the axis
(:mod:`~gearcheck.lumped.elements.holding`).  Its damping acts on the velocity relative to the housing, which
the rotating coordinates see as q' + Omega k x q: beside -c q' the circulatory term -c Omega k x q of every pair of
perpendicular rows (whirl damping; Lin & Parker 1999's frame).  A seat tilted in the housing (``tilt_urad``) holds
the member where its rows' deflections rest, fixed in the housing and so turning in the carrier's frame
(:class:`MisalignedSupport`)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
from numba import njit

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row, Turning, compiled_group
from gearcheck.lumped.elements.holding import holding_pairs, pair_rows
from gearcheck.train.spec import AXIAL, ROTATION, TILTS


@ELEMENTS.register("support")
def support_rows(part, build: Build) -> Contribution:
    mid, s, dofs = part.member, part.support, build.dofs
    member = build.spec.members[mid]
    tilt_names = TILTS.get(member.frame)
    tilts = [dofs.unit((mid, t, 1.0)) for t in tilt_names] if member.tilting else (None, None)
    pairs = holding_pairs(f"{mid}.support_", member.dofs[:2], [dofs.unit((mid, u, 1.0)) for u in member.dofs[:2]],
                          tilt_names, tilts, s, member.tilting)
    rows = pair_rows(pairs, "support")
    if s.torsional_stiffness or s.torsional_damping:
        rows.append(Row(f"{mid}.support_{ROTATION}", "support", dofs.unit((mid, ROTATION, 1.0)),
                        s.torsional_stiffness, s.torsional_damping))
    if part.axial:
        rows.append(Row(f"{mid}.support_{AXIAL}", "support", dofs.unit((mid, AXIAL, 1.0)), s.axial_stiffness,
                        s.axial_damping))
    omega = build.kin.speeds[f"{member.stage}.carrier"]
    circulatory = sum(p.damping * omega * (np.outer(p.rows[1], p.rows[0]) - np.outer(p.rows[0], p.rows[1]))
                      for p in pairs)
    turning = []
    if any(s.rest_tilt) and omega:  # the seat's offsets turn at -Omega in the carrier's frame
        turning.append(MisalignedSupport(
            sum(p.stiffness * (p.rows[0] * p.rest[0] + p.rows[1] * p.rest[1]) for p in pairs),
            sum(p.stiffness * (p.rows[0] * p.rest[1] - p.rows[1] * p.rest[0]) for p in pairs), omega))
    return Contribution(rows, turning=turning,
                        place=lambda model: replace(model, K_circulatory=model.K_circulatory + circulatory))


class MisalignedSupports(NamedTuple):
    """Misaligned supports on the housing, one row each: ``cos`` and ``sin`` (S, n) their loads' parts, ``omega``
    (S,) their carriers' speeds (:class:`MisalignedSupport`)."""

    cos: np.ndarray
    sin: np.ndarray
    omega: np.ndarray

    @classmethod
    def of(cls, supports) -> "MisalignedSupports":
        if not supports:
            return cls(np.zeros((0, 0)), np.zeros((0, 0)), np.zeros(0))
        return cls(np.array([e.cos for e in supports], dtype=float), np.array([e.sin for e in supports], dtype=float),
                   np.array([e.omega for e in supports], dtype=float))


@dataclass(frozen=True, eq=False)
class MisalignedSupport(Turning):
    """A support whose seat is tilted in the housing: its rows' rest deflections are fixed in the housing and turn
    at -Omega in the carrier's frame, R(-Omega t) r, so the load they exert, sum k (a . R(-Omega t) r) a, is
    cos(Omega t) ``cos`` + sin(Omega t) ``sin``.  The rows hold the rest of t = 0 (the model's static load holds
    that load, as the modal and static analyses take the rows of t = 0); the time solvers take the load at every
    stage, the harmonic methods as an orbit load on the carrier's clock."""

    cos: np.ndarray
    sin: np.ndarray
    omega: float
    rows = ()  # its rows stay the model's: only their rest turns
    compiled = MisalignedSupports
    words = "a support misaligned in the housing, its offsets turning in the carrier's frame"

    @property
    def clock_speed(self) -> float:
        return self.omega

    @property
    def static_load(self) -> np.ndarray:
        return self.cos

    def orbit_force(self, t) -> np.ndarray:
        phase = self.omega * np.asarray(t, dtype=float)[..., None]
        return np.cos(phase) * self.cos + np.sin(phase) * self.sin

    def forces(self, t, q, v) -> np.ndarray:
        """Its load less the static load the model holds (the compiled steps' form adds the whole load to the static
        load less :attr:`static_load`)."""
        return (self.orbit_force(t) - self.static_load) * np.ones_like(q)


@njit(inline="always")
def misaligned_forces(supports, at) -> None:
    """The compiled steps' form of :meth:`MisalignedSupport.forces`, added into ``out`` of ``at`` = (x, u, t, out)."""
    t, out = at[2], at[3]
    cos, sin, omega = supports
    for i in range(omega.size):
        c, s = np.cos(omega[i] * t), np.sin(omega[i] * t)
        for j in range(out.size):
            out[j] += c * cos[i, j] + s * sin[i, j]


compiled_group(MisalignedSupports, misaligned_forces)
