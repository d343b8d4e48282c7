"""A member on a pin of its carrier: its bearing is the stiffness and damping of its slides along the carrier's
radial and tangential axes (and of its axial slide, relative to the carrier)."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import AXIAL, member_axes


@ELEMENTS.register("bearing")
class Bearing(Element):
    def joint_springs(self, part, spec) -> dict:
        b, mid = part.bearing, part.member
        radial, tangential = member_axes(spec.members[mid])
        springs = {(mid, radial): (b.radial_stiffness, b.radial_damping),
                   (mid, tangential): (b.radial_stiffness, b.radial_damping)}
        if part.axial:
            springs[mid, AXIAL] = (b.axial_stiffness, b.axial_damping)
        return springs
