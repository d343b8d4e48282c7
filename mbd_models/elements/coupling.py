"""An interstage coupling: fixed tendons in torsion and, with a radial stiffness, along both world-frame slides
(MuJoCo's own world frame: the coupling turns with neither carrier)."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import ROTATION, fixed, member_axes


@ELEMENTS.register("coupling")
class Coupling(Element):
    def tendons(self, c, spec) -> list[str]:
        a, b = spec.members[c.a].label, spec.members[c.b].label
        lines = fixed(f"coupling_{c.name}_torsion", [(f"{a}_{ROTATION}", 1.0), (f"{b}_{ROTATION}", -1.0)],
                      c.torsional_stiffness, c.torsional_damping)
        if c.radial_stiffness or c.radial_damping:
            for axis in member_axes(spec.members[c.a]):
                lines += fixed(f"coupling_{c.name}_{axis}", [(f"{a}_{axis}", 1.0), (f"{b}_{axis}", -1.0)],
                               c.radial_stiffness, c.radial_damping)
        return lines
