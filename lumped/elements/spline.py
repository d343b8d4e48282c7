"""An RV reducer's planet on its crankshaft: bending along the carrier's radial and tangential axes (both
members at the same pin) and torsion."""

from __future__ import annotations

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row
from gearcheck.train.spec import ROTATION


@ELEMENTS.register("spline")
def spline_rows(part, build: Build) -> Contribution:
    s, planet, crank = part.spline, part.planet, part.crank
    radial, tangential = build.spec.members[crank].dofs[:2]
    rows = [Row(f"{crank}.spline_{dof}", "coupling", build.dofs.unit((planet, dof, 1.0), (crank, dof, -1.0)), k, c)
            for dof, k, c in ((radial, s.radial_stiffness, s.radial_damping),
                              (tangential, s.radial_stiffness, s.radial_damping),
                              (ROTATION, s.torsional_stiffness, s.torsional_damping))]
    return Contribution(rows)
