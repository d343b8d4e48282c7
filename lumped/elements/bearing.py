"""A member on a pin of its carrier (a planet, an RV reducer's crankshaft): an isotropic spring-damper between
its centre and the pin, along the axis when the stage is helical, and on its tilt relative to the carrier's when
the stage tilts, the radial stiffness then shared over bearing stations along the pin."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, DofMap, Row
from gearcheck.lumped.elements.holding import holding_pairs, pair_rows
from gearcheck.train.spec import AXIAL, ROTATION, TILTS


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


def carrier_tilts(spec, dofs: DofMap, mid: str) -> tuple[np.ndarray, np.ndarray]:
    """Its carrier's tilt about the member's radial and tangential axes (the carrier's tilts are about its x, y)."""
    p = spec.members[mid]
    c = f"{p.stage}.carrier"
    tilt_x, tilt_y = TILTS["axis"]
    cs, sn = math.cos(p.angle), math.sin(p.angle)
    return dofs.unit((c, tilt_x, cs), (c, tilt_y, sn)), dofs.unit((c, tilt_x, -sn), (c, tilt_y, cs))


def relative_tilts(spec, dofs: DofMap, mid: str) -> list[np.ndarray]:
    """A tilting member's tilts about its radial and tangential axes less its carrier's tilts about them."""
    own = [dofs.unit((mid, t, 1.0)) for t in TILTS[spec.members[mid].frame]]
    return [a - c for a, c in zip(own, carrier_tilts(spec, dofs, mid))]


@ELEMENTS.register("bearing")
def bearing_rows(part, build: Build) -> Contribution:
    """The pin point at p along the axis moves with the carrier by phi_c x (r_c e_r + p e_z), the member's point
    there by phi x (p e_z) = p (phi_t e_r - phi_r e_t): a station deflects radially by the centres' difference plus
    p times the relative tangential tilt, tangentially minus p times the relative radial one, and the pin moves
    axially by -r_c times the carrier's tangential tilt (Eritenel & Parker 2009's 3-D bearing); a misaligned pin
    holds it where the rows rest (:mod:`~gearcheck.lumped.elements.holding`)."""
    spec, dofs = build.spec, build.dofs
    mid, b = part.member, part.bearing
    member = spec.members[mid]
    tilts = relative_tilts(spec, dofs, mid) if member.tilting else (None, None)
    rows = pair_rows(holding_pairs(f"{mid}.bearing_", ("radial", "tangential"), pin_rows(spec, dofs, mid),
                                   TILTS.get(member.frame), tilts, b, member.tilting), "bearing")
    if part.axial:
        axial = build.dofs.unit((mid, AXIAL, 1.0), (part.carrier, AXIAL, -1.0))
        if member.tilting:
            axial = axial + member.radius * carrier_tilts(spec, dofs, mid)[1]
        rows.append(Row(f"{mid}.bearing_axial", "bearing", axial, b.axial_stiffness, b.axial_damping))
    return Contribution(rows)
