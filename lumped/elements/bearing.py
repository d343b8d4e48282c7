"""A member on a pin of its carrier (a planet, an RV reducer's crankshaft): an isotropic spring-damper between
its centre and the pin, and along the axis when the stage is helical."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, DofMap, Row
from gearcheck.train.spec import AXIAL, ROTATION


def pin_rows(spec, dofs: DofMap, mid: str) -> tuple[np.ndarray, np.ndarray]:
    """The member's centre minus its carrier's pin point, along the member's radial and tangential axes."""
    p = spec.members[mid]
    c = f"{p.stage}.carrier"
    radial_dof, tangential_dof = p.dofs[:2]
    cx, cy = spec.members[c].dofs[:2]
    cs, sn = math.cos(p.angle), math.sin(p.angle)
    radial = dofs.unit((mid, radial_dof, 1.0), (c, cx, -cs), (c, cy, -sn))
    tangential = dofs.unit((mid, tangential_dof, 1.0), (c, cx, sn), (c, cy, -cs), (c, ROTATION, -p.radius))
    return radial, tangential


@ELEMENTS.register("bearing")
def bearing_rows(part, build: Build) -> Contribution:
    mid, b = part.member, part.bearing
    radial, tangential = pin_rows(build.spec, build.dofs, mid)
    rows = [Row(f"{mid}.bearing_radial", "bearing", radial, b.radial_stiffness, b.radial_damping),
            Row(f"{mid}.bearing_tangential", "bearing", tangential, b.radial_stiffness, b.radial_damping)]
    if part.axial:
        axial = build.dofs.unit((mid, AXIAL, 1.0), (part.carrier, AXIAL, -1.0))
        rows.append(Row(f"{mid}.bearing_axial", "bearing", axial, b.axial_stiffness, b.axial_damping))
    return Contribution(rows)
