"""A member on the housing: its support is the stiffness and damping of its own joints (radial on its slides,
torsional on its hinge, axial on its axial slide)."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import AXIAL, ROTATION, member_axes


@ELEMENTS.register("support")
class Support(Element):
    def joint_springs(self, part, spec) -> dict:
        s, mid = part.support, part.member
        springs = {(mid, axis): (s.radial_stiffness, s.radial_damping) for axis in member_axes(spec.members[mid])}
        springs[mid, ROTATION] = (s.torsional_stiffness, s.torsional_damping)
        if part.axial and not spec.members[mid].torsional:
            springs[mid, AXIAL] = (s.axial_stiffness, s.axial_damping)
        return springs
