"""Involute gear geometry (ISO 21771 conventions), worked in the transverse plane.

A helical gear is described by its normal module m_n, normal pressure angle alpha_n and signed
helix angle beta (positive: right hand); the transverse plane sees a spur gear of module
m_t = m_n / cos(beta) and pressure angle tan(alpha_t) = tan(alpha_n) / cos(beta), while addenda,
dedenda and profile shifts stay in normal modules (x m_n) and the profile shift's effect on tooth
thickness and operating pressure angle goes with tan(alpha_n) (ISO 21771, clauses 4-5).  With
beta = 0 every formula is the spur one.

An idealised gear (``teeth`` None) is what published modal models describe: a base radius and a pressure
angle, no teeth, module or tooth geometry.  Its pitch, tip and root circles are its operating pitch circle
r_b / cos(alpha_t), a plain cylinder; it has no base pitch (nan) and no contact ratio.

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
    """The angle whose involute is ``value``, between 0 and 80 deg; a ValueError outside."""
    limit = math.radians(80.0)
    if not 0.0 < value < involute(limit):
        raise ValueError(f"the operating pressure angle would be outside 0-80 deg (inv a' = {value:.4g})")
    return brentq(lambda a: involute(a) - value, 1e-9, limit, xtol=1e-15, rtol=1e-15)


@dataclass(frozen=True)
class Gear:
    """One gear's tooth geometry; lengths in m, angles in rad."""

    name: str
    teeth: int | None  # None: an idealised gear (base radius and pressure angle only)
    module: float | None
    pressure_angle: float
    face_width: float  # 0 when an idealised gear gives none
    addendum: float | None
    dedendum: float | None
    profile_shift: float
    internal: bool
    base_radius: float
    eccentricity: float = 0.0
    eccentricity_phase: float = 0.0
    helix_angle: float = 0.0  # signed: positive a right-hand helix
    installation_error: float = 0.0  # centre offset fixed to the gear's mount, m
    installation_error_phase: float = 0.0
    relief_amount: float = 0.0  # tip relief C_a, m
    relief_length: float = 0.0  # its roll length L_a along the line of action, m
    relief_power: int = 1  # 1 linear, 2 parabolic
    axial_offset: float = 0.0  # its face centre from its member's centre of mass along the axis, m

    @property
    def normal_module(self) -> float | None:
        """m_n = m_t cos(beta): the unit of addenda, dedenda and profile shifts (None for an idealised gear)."""
        return None if self.idealised else self.module * math.cos(self.helix_angle)

    @property
    def normal_pressure_angle(self) -> float:
        return self.pressure_angle if self.helix_angle == 0.0 else math.atan(self.tan_normal_pressure_angle)

    @property
    def tan_normal_pressure_angle(self) -> float:
        """tan(alpha_n) = tan(alpha_t) cos(beta)."""
        return math.tan(self.pressure_angle) * math.cos(self.helix_angle)

    @property
    def base_helix_angle(self) -> float:
        """|beta_b|: tan(beta_b) = tan(beta) cos(alpha_t)."""
        return math.atan(abs(math.tan(self.helix_angle)) * math.cos(self.pressure_angle))

    @property
    def hand(self) -> int:
        """+1 right hand, -1 left hand, 0 spur."""
        return (self.helix_angle > 0) - (self.helix_angle < 0)

    @property
    def idealised(self) -> bool:
        """No teeth: a base radius and a pressure angle, as published modal models give a gear."""
        return self.teeth is None

    @property
    def pitch_radius(self) -> float:
        if self.idealised:
            return self.base_radius / math.cos(self.pressure_angle)
        return 0.5 * self.module * self.teeth

    @property
    def tip_radius(self) -> float:
        """Addendum circle; for a ring the inner (tooth tip) circle."""
        if self.idealised:
            return self.pitch_radius
        m, x = self.normal_module, self.profile_shift
        if self.internal:
            return self.pitch_radius - m * (self.addendum - x)
        return self.pitch_radius + m * (self.addendum + x)

    @property
    def root_radius(self) -> float:
        if self.idealised:
            return self.pitch_radius
        m, x = self.normal_module, self.profile_shift
        if self.internal:
            return self.pitch_radius + m * (self.dedendum + x)
        return self.pitch_radius - m * (self.dedendum - x)

    @property
    def base_pitch(self) -> float:
        """2 pi r_b / z; nan for an idealised gear."""
        return math.nan if self.idealised else 2.0 * math.pi * self.base_radius / self.teeth


@dataclass(frozen=True)
class MeshGeometry:
    """Operating geometry of a central gear meshing with a planet gear.

    ``central_pitch_radius`` and ``planet_pitch_radius`` are the operating pitch radii:
    distances from each centre to the pitch point along the line of centres.
    """

    pressure_angle: float
    centre_distance: float
    contact_ratio: float  # transverse, eps_alpha
    base_pitch: float  # transverse
    central_pitch_radius: float
    planet_pitch_radius: float
    base_helix_angle: float = 0.0  # |beta_b|
    face_contact_ratio: float = 0.0  # eps_beta = b sin|beta| / (pi m_n), b the narrower face
    face_width: float = 0.0  # the narrower face: the length of contact across the face

    @property
    def total_contact_ratio(self) -> float:
        return self.contact_ratio + self.face_contact_ratio


def mesh_geometry(central: Gear, planet: Gear) -> MeshGeometry:
    """Operating pressure angle, centre distance and transverse contact ratio of a pair.

    External pair (sun-planet):  inv a' = inv a_t + 2 tan a_n (x1 + x2)/(z1 + z2),
    internal pair (ring-planet): inv a' = inv a_t + 2 tan a_n (x_r - x_p)/(z_r - z_p);
    a' = a0 cos a_t / cos a', eps_a = (g_a)/p_bt with the path of contact
    g_a = sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - a' sin a' (external) or
    g_a = sqrt(ra_p^2 - rb_p^2) - sqrt(ra_r^2 - rb_r^2) + a' sin a' (internal);
    eps_b = b sin|beta| / (pi m_n) with b the narrower face width.
    """
    alpha, tan_n = central.pressure_angle, central.tan_normal_pressure_angle
    zc, zp = central.teeth, planet.teeth
    base_pitch = central.base_pitch
    if central.internal:
        inv_op = involute(alpha) + 2.0 * tan_n * (central.profile_shift - planet.profile_shift) / (zc - zp)
        a_ref = central.base_radius - planet.base_radius
    else:
        inv_op = involute(alpha) + 2.0 * tan_n * (central.profile_shift + planet.profile_shift) / (zc + zp)
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
    width = min(central.face_width, planet.face_width)
    return MeshGeometry(
        pressure_angle=alpha_op,
        centre_distance=centre,
        contact_ratio=path / base_pitch,
        base_pitch=base_pitch,
        central_pitch_radius=central.base_radius / math.cos(alpha_op),
        planet_pitch_radius=planet.base_radius / math.cos(alpha_op),
        base_helix_angle=central.base_helix_angle,
        face_contact_ratio=width * abs(math.sin(central.helix_angle)) / (math.pi * central.normal_module),
        face_width=width,
    )


def idealised_mesh_geometry(central: Gear, planet: Gear) -> MeshGeometry:
    """The operating geometry of a pair of idealised gears: the line of action tangent to both base circles at the
    central gear's (transverse) pressure angle, a' = (r_bc +- r_bp) / cos a ('-' for a ring); no contact ratio or
    base pitch (nan).  A ValueError when a ring's base circle does not enclose the planet's."""
    alpha = central.pressure_angle
    a_ref = central.base_radius - planet.base_radius if central.internal else central.base_radius + planet.base_radius
    if a_ref <= 0.0:
        raise ValueError(f"a ring's base radius ({central.base_radius * 1e3:.6g} mm) must exceed its planet's "
                         f"({planet.base_radius * 1e3:.6g} mm)")
    return MeshGeometry(
        pressure_angle=alpha, centre_distance=a_ref / math.cos(alpha), contact_ratio=math.nan, base_pitch=math.nan,
        central_pitch_radius=central.base_radius / math.cos(alpha),
        planet_pitch_radius=planet.base_radius / math.cos(alpha), base_helix_angle=central.base_helix_angle,
        face_width=min(central.face_width, planet.face_width))


def reference_tooth_thickness(gear: Gear) -> float:
    """Transverse arc tooth thickness on the reference circle, s_t = m_t (pi/2 + 2 x tan a_n)."""
    return gear.module * (math.pi / 2 + 2 * gear.profile_shift * gear.tan_normal_pressure_angle)


def base_tooth_thickness(gear: Gear) -> float:
    """Arc tooth thickness on the base circle, s_b = r_b (s_t/r + 2 inv a_t)."""
    s = reference_tooth_thickness(gear)
    return gear.base_radius * (s / gear.pitch_radius + 2 * involute(gear.pressure_angle))


MIN_CONTACT_RATIO = 1.1
"""Below it a mesh does not keep a tooth pair in contact once manufacturing tolerances and tip edge
breaks have shortened the path of contact (about 0.1 of it); AGMA 913 asks for 1.2."""

INTERFERENCE_TOLERANCE = 0.05
"""How far (in modules, along the line of action) a tip may reach past the mate's base-circle tangent
point: the edge break every tooth tip carries (drawings specify about 0.05 m) takes that much off."""

BASE_PITCH_TOLERANCE = 1e-3
"""How far (relative) the base pitches of two gears in mesh may differ: base radii a paper rounds to 0.01 mm stay
within it."""


def tip_thickness(gear: Gear) -> float:
    """Arc tooth thickness on the tip circle of an external gear (ISO 21771):
    s_a = d_a (s_t/d + inv a_t - inv a_a), a_a = arccos(r_b / r_a) (transverse)."""
    s = reference_tooth_thickness(gear)
    alpha_tip = math.acos(min(gear.base_radius / gear.tip_radius, 1.0))
    return 2 * gear.tip_radius * (s / (2 * gear.pitch_radius) + involute(gear.pressure_angle) - involute(alpha_tip))


def undercut_limit(gear: Gear) -> float:
    """The smallest profile shift of an external gear generated by a rack without undercut,
    x_min = h_a* - z sin^2(a_t) / (2 cos beta) (ISO 21771; the tool's addendum taken as the gear's own)."""
    return gear.addendum - 0.5 * gear.teeth * math.sin(gear.pressure_angle) ** 2 / math.cos(gear.helix_angle)


def along_line(gear: Gear) -> float:
    """Distance along the line of action from the base circle's tangent point to the tip circle."""
    return math.sqrt(max(gear.tip_radius**2 - gear.base_radius**2, 0.0))


def gear_problem(gear: Gear) -> tuple[str, str] | None:
    """(field, message) of the first thing that makes ``gear`` an impossible involute gear, or None."""
    m = gear.normal_module
    if gear.tip_radius <= gear.base_radius:
        return "addendum_coefficient", (f"tip circle r_a = {gear.tip_radius * 1e3:.4g} mm lies inside the base circle "
                                        f"r_b = {gear.base_radius * 1e3:.4g} mm: there is no involute flank there")
    if gear.relief_length > along_line(gear):
        return "tip_relief.length_mm", (f"{gear.relief_length * 1e3:.4g} mm reaches below the base circle: the flank's "
                                        f"roll length from base to tip is {along_line(gear) * 1e3:.4g} mm")
    if gear.root_radius <= 0:
        return "dedendum_coefficient", f"root circle radius {gear.root_radius * 1e3:.4g} mm is not positive"
    if gear.internal:
        return None
    x_min = undercut_limit(gear)
    if gear.profile_shift < x_min - 1e-12:
        return "teeth", (f"undercut: {gear.teeth} teeth at {math.degrees(gear.pressure_angle):.4g} deg with profile "
                         f"shift {gear.profile_shift:g} need x >= {x_min:.3f} (x_min = h_a* - z sin^2(a)/2, ISO 21771)")
    s_a = tip_thickness(gear)
    if s_a <= 0:
        return "addendum_coefficient", (f"pointed teeth: the tip thickness is {s_a / m:.3f} m <= 0 "
                                        f"({math.degrees(gear.pressure_angle):.4g} deg, profile shift "
                                        f"{gear.profile_shift:g}, addendum {gear.addendum:g} m)")
    return None


def helix_problem(central: Gear, planet: Gear) -> str | None:
    """Why the pair's helices cannot mesh, or None: an internal pair's helices run the same way, an external
    pair's opposite (idealised gears too: the helix sets the line of action's axial part)."""
    same_hand = central.internal
    if central.helix_angle != (planet.helix_angle if same_hand else -planet.helix_angle):
        return (f"helix angle {math.degrees(central.helix_angle):.6g} deg cannot mesh with "
                f"{planet.name}'s {math.degrees(planet.helix_angle):.6g} deg: an "
                f"{'internal' if same_hand else 'external'} pair needs equal helix angles of "
                f"{'the same' if same_hand else 'opposite'} hand (positive = right hand)")
    return None


def mesh_problem(central: Gear, planet: Gear, geometry: MeshGeometry) -> tuple[str, str, str] | None:
    """(which gear: "central" or "planet", the field to blame, message) of the first thing that stops the pair
    meshing as involutes, or None: helices that do not match, base pitches that differ (an explicit base radius
    can make them: the meshes would turn at different frequencies), tips meeting the mate below its base circle
    (involute interference), tips hitting the mate's root circle, a contact ratio below ``MIN_CONTACT_RATIO``
    (transverse and face together for a helical pair)."""
    helix = helix_problem(central, planet)
    if helix:
        return "central", "teeth", helix
    if abs(central.base_pitch - planet.base_pitch) > BASE_PITCH_TOLERANCE * planet.base_pitch:
        return "central", "base_radius_mm", (
            f"base pitch {central.base_pitch * 1e3:.6g} mm, planet gear {planet.name}'s "
            f"{planet.base_pitch * 1e3:.6g} mm: gears in mesh share one base pitch (their base radii over their "
            "teeth), else their meshes turn at different frequencies")
    line = geometry.centre_distance * math.sin(geometry.pressure_angle)  # between the tangent points
    a, m = geometry.centre_distance, central.normal_module
    if central.internal:  # the ring's tip contact must lie beyond the planet's tangent point
        reach = {"central": line - along_line(central)}
        clearance = {"central": central.tip_radius - (a + planet.root_radius),
                     "planet": central.root_radius - (a + planet.tip_radius)}
    else:
        reach = {"central": along_line(central) - line, "planet": along_line(planet) - line}
        clearance = {"central": a - central.tip_radius - planet.root_radius,
                     "planet": a - planet.tip_radius - central.root_radius}
    names = {"central": central.name, "planet": f"planet gear {planet.name}"}
    for who, overlap in reach.items():
        if overlap > INTERFERENCE_TOLERANCE * m:
            mate = names["planet" if who == "central" else "central"]
            return who, "teeth", (f"involute interference: the {names[who]} tip meets the {mate} "
                                  f"{overlap * 1e3:.4g} mm ({overlap / m:.3f} m) below its base circle along the line "
                                  f"of action (tolerated: {INTERFERENCE_TOLERANCE:g} m)")
    for who, gap in clearance.items():
        if gap < -1e-12:
            return who, "teeth", (f"the {names[who]} tip hits the mate's root circle ({gap * 1e3:.4g} mm of "
                                  "clearance)")
    if geometry.total_contact_ratio < MIN_CONTACT_RATIO:  # a helical pair's overlap keeps contact too
        ratio = (f"transverse contact ratio {geometry.contact_ratio:.3f}" if not geometry.face_contact_ratio else
                 f"total contact ratio {geometry.contact_ratio:.3f} + {geometry.face_contact_ratio:.3f}")
        return "central", "teeth", (f"{ratio} < {MIN_CONTACT_RATIO:g} with {names['planet']}: the mesh cannot "
                                    "keep a tooth pair in contact")
    return None
