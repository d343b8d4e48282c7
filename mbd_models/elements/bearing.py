"""A member on a pin of its carrier: its bearing is the stiffness and damping of its slides along the carrier's
radial and tangential axes (and of its axial slide and tilt hinges, relative to the carrier), or a tilting
member's radial stiffness shared over its stations (:mod:`~gearcheck.mbd_models.elements.stations`); a misaligned
pin's tilt is where they rest."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.elements.stations import HEADER, holding_springs, station_rows, station_tendons
from gearcheck.mbd_models.mjcf_text import AXIAL, Spring


@ELEMENTS.register("bearing")
class Bearing(Element):
    def joint_springs(self, part, spec) -> dict:
        springs = holding_springs(spec.members[part.member], part.bearing)
        if part.axial:
            springs[part.member, AXIAL] = Spring(part.bearing.axial_stiffness, part.bearing.axial_damping)
        return springs

    def header(self, part) -> list[str]:
        return HEADER if part.bearing.stations else []  # (a stage that does not tilt has none: set aside)

    def tendons(self, part, spec) -> list[str]:
        return station_tendons(spec.members[part.member], part.bearing)

    def late_rows(self, part, spec, kin, model, data) -> list[tuple]:
        return station_rows(spec.members[part.member], part.bearing, spec.members[part.carrier].label, model, data)
