"""The input shaft: a torsional spring-damper on the input member's rotation (its other end is the drive's
reference angle, which the time solvers feed as a torque)."""

from __future__ import annotations

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row
from gearcheck.train.spec import ROTATION


@ELEMENTS.register("shaft")
def shaft_row(part, build: Build) -> Contribution:
    a = build.dofs.unit((part.member, ROTATION, 1.0))
    return Contribution([Row("input_shaft", "shaft", a, part.stiffness, part.damping)])
