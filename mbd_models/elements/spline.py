"""An RV reducer's planet on its crankshaft: fixed tendons between their slides (both on the same pin of the
carrier) and hinges."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import ROTATION, fixed, member_axes


@ELEMENTS.register("spline")
class Spline(Element):
    def tendons(self, part, spec) -> list[str]:
        s = part.spline
        p, c = spec.members[part.planet].label, spec.members[part.crank].label
        radial, tangential = member_axes(spec.members[part.crank])
        lines = []
        for axis, k, damping in ((radial, s.radial_stiffness, s.radial_damping),
                                 (tangential, s.radial_stiffness, s.radial_damping),
                                 (ROTATION, s.torsional_stiffness, s.torsional_damping)):
            lines += fixed(f"{c}_spline_{axis}", [(f"{p}_{axis}", 1.0), (f"{c}_{axis}", -1.0)], k, damping)
        return lines
