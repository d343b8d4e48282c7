"""Where a mesh acts: its pitch point and line of action in the carrier frame.

Both models use this description-level geometry: the lumped assembler turns it into
a deflection row, the MuJoCo builder dots it with the Jacobians of its own bodies.

Convention (one for every mesh): the central gear is side A, the planet side B.
``direction`` is the unit vector of the contact force ON THE PLANET BY THE CENTRAL
GEAR when the teeth are compressed, so the mesh deflection is

    delta = (u_A(p) - u_B(p)) . direction,

u_X(p) the small displacement of body X's material at the pitch point p.  The radial
component of ``direction`` separates the gears (outward from the sun, inward from
the ring); its tangential component is flank * cos(alpha'), the loaded flank
(+1 or -1) being chosen from the nominal torque (:mod:`gearcheck.train.kinematics`).

A helical mesh pushes along the normal line of action, tilted out of the transverse plane by the
base helix angle beta_b: its transverse part is ``direction`` (already scaled by cos beta_b) and its
axial part ``axial`` (along the stage axis +z).  The sign of the axial part follows from the flank
being normal to the tooth trace: a right-hand tooth trace runs along e_z cos(beta) + e_t sin(beta),
so a flank force that turns its gear forward (+e_t) pushes it along -z, F_z = -F_t tan(beta) (left
hand: +z).  The force on the central gear turns it by -flank, hence on the planet
axial = -hand(central) * flank * sin(beta_b); for the planet, whose helix runs the other way on an
external pair and the same way on an internal one, this is the same rule seen from its own side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LineOfAction:
    pitch_point: np.ndarray  # (2,) carrier frame, origin at the stage's central axis
    direction: np.ndarray  # (2,) transverse part of the unit force on the planet by the central gear
    planet_centre: np.ndarray  # (2,)
    axial: float = 0.0  # its axial part (+z): (direction, axial) is a unit vector


def line_of_action(mesh, planet_angle: float, carrier_radius: float, flank: int) -> LineOfAction:
    """Pitch point and line-of-action direction of ``mesh`` at its nominal position."""
    g = mesh.geometry
    e_r = np.array([math.cos(planet_angle), math.sin(planet_angle)])
    e_t = np.array([-math.sin(planet_angle), math.cos(planet_angle)])
    radial = -math.sin(g.pressure_angle) if mesh.internal else math.sin(g.pressure_angle)
    direction = (flank * math.cos(g.pressure_angle) * e_t + radial * e_r) * math.cos(g.base_helix_angle)
    axial = -mesh.central_gear.hand * flank * math.sin(g.base_helix_angle)
    return LineOfAction(g.central_pitch_radius * e_r, direction, carrier_radius * e_r, axial)


def lever(point: np.ndarray, centre: np.ndarray, direction: np.ndarray) -> float:
    """z-component of (point - centre) x direction: the moment arm of a unit force along ``direction``."""
    rx, ry = point - centre
    return float(rx * direction[1] - ry * direction[0])
