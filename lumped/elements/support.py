"""A member on the housing: a spring-damper on each translation, on the rotation when it has torsional
stiffness or damping, and along the axis when the member slides axially."""

from __future__ import annotations

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row
from gearcheck.train.spec import AXIAL, ROTATION


@ELEMENTS.register("support")
def support_rows(part, build: Build) -> Contribution:
    mid, s, dofs = part.member, part.support, build.dofs
    u, v = build.spec.members[mid].dofs[:2]
    rows = [Row(f"{mid}.support_{u}", "support", dofs.unit((mid, u, 1.0)), s.radial_stiffness, s.radial_damping),
            Row(f"{mid}.support_{v}", "support", dofs.unit((mid, v, 1.0)), s.radial_stiffness, s.radial_damping)]
    if s.torsional_stiffness or s.torsional_damping:
        rows.append(Row(f"{mid}.support_{ROTATION}", "support", dofs.unit((mid, ROTATION, 1.0)),
                        s.torsional_stiffness, s.torsional_damping))
    if part.axial:
        rows.append(Row(f"{mid}.support_{AXIAL}", "support", dofs.unit((mid, AXIAL, 1.0)), s.axial_stiffness,
                        s.axial_damping))
    return Contribution(rows)
