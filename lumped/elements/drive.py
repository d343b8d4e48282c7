"""The drive: with an input shaft, a torsional spring-damper on the input member's rotation (its other end is the
drive's reference angle, which the time solvers feed as a torque); the input and load torques act on the
rotations of the input and output members (the model's ``b_input`` and ``b_output``)."""

from __future__ import annotations

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row
from gearcheck.train.spec import ROTATION


@ELEMENTS.register("drive")
def drive_rows(part, build: Build) -> Contribution:
    if part.stiffness is None:
        return Contribution()
    a = build.dofs.unit((part.member, ROTATION, 1.0))
    return Contribution([Row("input_shaft", "shaft", a, part.stiffness, part.damping)])
