"""Involute spur-gear geometry (ISO 21771 conventions, transverse plane).

Internal gears (rings) use positive teeth counts with ``internal=True``; a positive
profile shift of a ring moves its teeth outward (larger tip radius, larger operating
centre distance), so that for an internal pair
``inv a' = inv a + 2 tan a (x_ring - x_planet) / (z_ring - z_planet)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq


def involute(alpha: float) -> float:
    return math.tan(alpha) - alpha


def inverse_involute(value: float) -> float:
    """The angle whose involute is ``value`` (0 <= value, angle < 80 deg)."""
    if value <= 0.0:
        return 0.0
    return brentq(lambda a: involute(a) - value, 1e-9, math.radians(80.0), xtol=1e-15, rtol=1e-15)


@dataclass(frozen=True)
class Gear:
    """One gear's tooth geometry; lengths in m, angles in rad."""

    name: str
    teeth: int
    module: float
    pressure_angle: float
    face_width: float
    addendum: float
    dedendum: float
    profile_shift: float
    internal: bool
    base_radius: float
    eccentricity: float = 0.0
    eccentricity_phase: float = 0.0

    @property
    def pitch_radius(self) -> float:
        return 0.5 * self.module * self.teeth

    @property
    def tip_radius(self) -> float:
        """Addendum circle; for a ring the inner (tooth tip) circle."""
        m, x = self.module, self.profile_shift
        if self.internal:
            return self.pitch_radius - m * (self.addendum - x)
        return self.pitch_radius + m * (self.addendum + x)

    @property
    def root_radius(self) -> float:
        m, x = self.module, self.profile_shift
        if self.internal:
            return self.pitch_radius + m * (self.dedendum + x)
        return self.pitch_radius - m * (self.dedendum - x)

    @property
    def base_pitch(self) -> float:
        return 2.0 * math.pi * self.base_radius / self.teeth


@dataclass(frozen=True)
class MeshGeometry:
    """Operating geometry of a central gear meshing with a planet gear.

    ``central_pitch_radius`` and ``planet_pitch_radius`` are the operating pitch radii:
    distances from each centre to the pitch point along the line of centres.
    """

    pressure_angle: float
    centre_distance: float
    contact_ratio: float
    base_pitch: float
    central_pitch_radius: float
    planet_pitch_radius: float


def mesh_geometry(central: Gear, planet: Gear) -> MeshGeometry:
    """Operating pressure angle, centre distance and transverse contact ratio of a pair.

    External pair (sun-planet):  inv a' = inv a + 2 tan a (x1 + x2)/(z1 + z2),
    internal pair (ring-planet): inv a' = inv a + 2 tan a (x_r - x_p)/(z_r - z_p);
    a' = a0 cos a / cos a', eps_a = (g_a)/p_b with the path of contact
    g_a = sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - a' sin a' (external) or
    g_a = sqrt(ra_p^2 - rb_p^2) - sqrt(ra_r^2 - rb_r^2) + a' sin a' (internal).
    """
    alpha = central.pressure_angle
    zc, zp = central.teeth, planet.teeth
    base_pitch = central.base_pitch
    if central.internal:
        inv_op = involute(alpha) + 2.0 * math.tan(alpha) * (central.profile_shift - planet.profile_shift) / (zc - zp)
        a_ref = central.base_radius - planet.base_radius
    else:
        inv_op = involute(alpha) + 2.0 * math.tan(alpha) * (central.profile_shift + planet.profile_shift) / (zc + zp)
        a_ref = central.base_radius + planet.base_radius
    alpha_op = inverse_involute(inv_op)
    centre = a_ref / math.cos(alpha_op)
    along_planet = math.sqrt(max(planet.tip_radius**2 - planet.base_radius**2, 0.0))
    along_central = math.sqrt(max(central.tip_radius**2 - central.base_radius**2, 0.0))
    if central.internal:
        # the planet (external) tip ends the path on one side, the ring tip begins it
        path = along_planet - along_central + centre * math.sin(alpha_op)
    else:
        path = along_central + along_planet - centre * math.sin(alpha_op)
    return MeshGeometry(
        pressure_angle=alpha_op,
        centre_distance=centre,
        contact_ratio=path / base_pitch,
        base_pitch=base_pitch,
        central_pitch_radius=central.base_radius / math.cos(alpha_op),
        planet_pitch_radius=planet.base_radius / math.cos(alpha_op),
    )


def base_tooth_thickness(gear: Gear) -> float:
    """Arc tooth thickness on the base circle, s_b = r_b (s/r + 2 inv a), s = m (pi/2 + 2 x tan a)."""
    s = gear.module * (math.pi / 2 + 2 * gear.profile_shift * math.tan(gear.pressure_angle))
    return gear.base_radius * (s / gear.pitch_radius + 2 * involute(gear.pressure_angle))
