"""A member on the housing: a spring-damper on each translation, on the rotation when it has torsional
stiffness or damping, along the axis when the member slides axially, and on each tilt when it tilts.

A tilting member's radial stiffness may be shared over bearing stations along the axis: the station at p
from the centre of mass deflects by the member's translation plus phi x (p e_z) = p (phi_2, -phi_1), phi_1 and
phi_2 its tilts about its two translation axes.  Its damping acts on the velocity relative to the housing, which
the rotating coordinates see as q' + Omega k x q: beside -c q' the circulatory term -c Omega k x q of every pair of
perpendicular rows (whirl damping; Lin & Parker 1999's frame)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row
from gearcheck.train.spec import AXIAL, ROTATION, TILTS


@ELEMENTS.register("support")
def support_rows(part, build: Build) -> Contribution:
    mid, s, dofs = part.member, part.support, build.dofs
    member = build.spec.members[mid]
    u, v = member.dofs[:2]
    pairs = [(f"{mid}.support_{u}", dofs.unit((mid, u, 1.0)), f"{mid}.support_{v}", dofs.unit((mid, v, 1.0)),
              s.radial_stiffness, s.radial_damping)]
    if member.tilting:
        tilt_u, tilt_v = TILTS[member.frame]
        pairs = [(f"{mid}.support_{u}.station{i + 1}", dofs.unit((mid, u, 1.0), (mid, tilt_v, st.position)),
                  f"{mid}.support_{v}.station{i + 1}", dofs.unit((mid, v, 1.0), (mid, tilt_u, -st.position)),
                  st.radial_stiffness, st.radial_damping) for i, st in enumerate(s.stations)] or pairs
        if s.tilting_stiffness or s.tilting_damping:
            pairs.append((f"{mid}.support_{tilt_u}", dofs.unit((mid, tilt_u, 1.0)), f"{mid}.support_{tilt_v}",
                          dofs.unit((mid, tilt_v, 1.0)), s.tilting_stiffness, s.tilting_damping))
    rows = [Row(name, "support", a, k, c) for name_u, a_u, name_v, a_v, k, c in pairs
            for name, a in ((name_u, a_u), (name_v, a_v))]
    if s.torsional_stiffness or s.torsional_damping:
        rows.append(Row(f"{mid}.support_{ROTATION}", "support", dofs.unit((mid, ROTATION, 1.0)),
                        s.torsional_stiffness, s.torsional_damping))
    if part.axial:
        rows.append(Row(f"{mid}.support_{AXIAL}", "support", dofs.unit((mid, AXIAL, 1.0)), s.axial_stiffness,
                        s.axial_damping))
    omega = build.kin.speeds[f"{member.stage}.carrier"]
    circulatory = sum(c * omega * (np.outer(a_v, a_u) - np.outer(a_u, a_v)) for _, a_u, _, a_v, _, c in pairs)
    return Contribution(rows, place=lambda model: replace(model, K_circulatory=model.K_circulatory + circulatory))
