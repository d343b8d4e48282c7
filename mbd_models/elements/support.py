"""A member on the housing: its support is the stiffness and damping of its own joints (radial on its slides,
torsional on its hinge, axial on its axial slide, tilting on its tilt hinges), or a tilting member's radial
stiffness shared over its stations (:mod:`~gearcheck.mbd_models.elements.stations`)."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.elements.stations import HEADER, holding_springs, station_rows, station_tendons
from gearcheck.mbd_models.mjcf_text import AXIAL, ROTATION, Spring


@ELEMENTS.register("support")
class Support(Element):
    def joint_springs(self, part, spec) -> dict:
        s, mid = part.support, part.member
        springs = holding_springs(spec.members[mid], s)
        springs[mid, ROTATION] = Spring(s.torsional_stiffness, s.torsional_damping)
        if part.axial and not spec.members[mid].torsional:
            springs[mid, AXIAL] = Spring(s.axial_stiffness, s.axial_damping)
        return springs

    def header(self, part) -> list[str]:
        return HEADER if part.support.stations else []  # (a stage that does not tilt has none: set aside)

    def tendons(self, part, spec) -> list[str]:
        return station_tendons(spec.members[part.member], part.support)

    def late_rows(self, part, spec, kin, model, data) -> list[tuple]:
        return station_rows(spec.members[part.member], part.support, "world", model, data)
