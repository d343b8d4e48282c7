"""Cycloid-pin stage geometry: a cycloid disc with Z_c lobes on an eccentric inside a pin wheel of Z_p = Z_c + 1
cylindrical pins (a one-tooth-difference drive, as in the RV reducer's second stage).

Conventions (SI; angles counter-clockwise):

* the pin wheel's centre O is the origin of the *fixed frame* (the frame in which the eccentric angle is
  measured); pin i's centre is C_i = R_p e(psi_i), psi_i = 2 pi i / Z_p + w, w the pin wheel's angle;
* the disc centre sits at e e(phi), phi the eccentric (crank) angle; the pitch point P, the contact of the
  disc's rolling circle (radius r_c = Z_c e, about the disc centre) with the pin wheel's pitch circle
  (radius Z_p e, about O), lies on the same line at Z_p e e(phi);
* K1 = Z_p e / R_p, the short-width (curtate) coefficient; pin i's relative angle is varphi_i = psi_i - phi.

By Willis' theorem (law of gearing) the common normal of every contact passes through P; the pin being a
circle, it runs from P to the pin centre.  In the eccentric frame (x along e(phi)):

    n = (cos varphi - K1, sin varphi) / S,   S = sqrt(1 + K1^2 - 2 K1 cos varphi),
    l = r_c sin varphi / S          (arm of n about the disc centre),
    a = Z_p e sin varphi / S        (arm of n about the pin wheel's centre, = (C_i x n)_z),

n pointing from the disc into the pin.  The compression of pin i for small displacements (u, theta) of the
disc and (u_w, theta_w) of the pin wheel is

    delta_i = n.u + l theta - n.u_w - a theta_w,

and the disc rolling about P (u = -r_c theta e_perp(phi)) leaves every delta_i = 0.

The pin-centre locus in the disc frame (the theoretical profile) is the shortened epicycloid (epitrochoid)
X(t) = R_p e(t) - e e(Z_p t); the disc's real profile is its inner equidistant at the pin radius
(Litvin & Feng 1996; Shin & Kwon 2006; Chen et al. 2008).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MIN_LOBES = 4
"""With Z_p >= 5 pins an open half-turn of relative angle always holds at least two pins, so for either torque
sign at least two pins with independent normals carry load and the pins locate the disc in both directions
that they can (their 3x3 block has rank 2, its null vector the rolling about P).  Four pins (three lobes) leave
a single loaded pin at some eccentric angles."""

LOAD_THRESHOLD = 1e-12
"""A pin whose arm is below this fraction of r_c (a pin at varphi = 0 or pi, up to rounding) carries no load."""

PALMGREN_COEFFICIENT = 3.84e-5
"""delta [mm] = 3.84e-5 Q^0.9 / l^0.8, Q in N, l in mm: steel-on-steel line contact (Palmgren 1959)."""


def _e(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


@dataclass(frozen=True)
class CycloidGeometry:
    """One cycloid disc against its pin wheel; lengths in m."""

    lobes: int  # Z_c
    pins: int  # Z_p
    eccentricity: float  # e
    pin_circle_radius: float  # R_p, pin centres
    pin_radius: float  # r_rp
    contact_length: float  # disc thickness: the length of each line contact

    @property
    def K1(self) -> float:
        """Short-width coefficient K1 = Z_p e / R_p (< 1 for a shortened epicycloid)."""
        return self.pins * self.eccentricity / self.pin_circle_radius

    @property
    def rolling_radius(self) -> float:
        """r_c = Z_c e: the disc's rolling (pitch) circle, the largest arm of a pin force about the disc centre."""
        return self.lobes * self.eccentricity

    @property
    def pitch_radius(self) -> float:
        """Z_p e: the pin wheel's pitch circle, on which the pitch point P lies."""
        return self.pins * self.eccentricity

    @property
    def pin_spacing(self) -> float:
        """Distance between adjacent pin centres, 2 R_p sin(pi / Z_p)."""
        return 2.0 * self.pin_circle_radius * math.sin(math.pi / self.pins)


# ---------------------------------------------------------------------------------------------------------------
# curvature of the pin-centre locus and the design limits


def curvature_radius(geometry: CycloidGeometry, relative_angle):
    """Signed radius of curvature of the pin-centre locus where it passes the pin at ``relative_angle`` varphi:

        rho = R_p S^3 / (1 + Z_p K1^2 - (1 + Z_p) K1 cos varphi),

    from rho = |X'|^3 / (X' x X'') of X(t) = R_p e(t) - e e(Z_p t) with cos(Z_c t) = cos varphi at the contact.
    Positive where the locus is convex (the lobe tips), negative where it is concave (the tooth spaces); the real
    profile's radius there is rho - r_rp.
    """
    k, z = geometry.K1, geometry.pins
    c = np.cos(relative_angle)
    return geometry.pin_circle_radius * (1 + k * k - 2 * k * c) ** 1.5 / (1 + z * k * k - (1 + z) * k * c)


def min_curvature_radius(geometry: CycloidGeometry) -> float:
    """Smallest radius of curvature of the pin-centre locus on its convex part (needs 0 < K1 < 1).

    With c = cos varphi, d rho / dc = 0 at c* = 3 (1 + Z_p K1^2) / ((1 + Z_p) K1) - (1 + K1^2) / K1, which always
    lies on the convex part; where c* is in [-1, 1],

        rho_min = R_p sqrt(27 (Z_p - 1)(1 - K1^2) / (Z_p + 1)^3),

    else the minimum sits at an end of the convex range: the lobe tip (c = -1, rho = R_p (1 + K1)^2 / (1 + Z_p K1))
    or, for K1 <= 1/Z_p (a locus convex everywhere), the tooth space (c = 1).  The disc's profile, the inner
    equidistant at r_rp, is free of undercut (no loops, no cusps) where r_rp < rho_min: the non-undercutting
    condition of Shin & Kwon (2006) and Hwang & Hsieh (2007); the closed form is derived from ``curvature_radius``.
    """
    k, z = geometry.K1, geometry.pins
    candidates = [-1.0, 1.0, 3 * (1 + z * k * k) / ((1 + z) * k) - (1 + k * k) / k]
    rho = [float(curvature_radius(geometry, math.acos(c))) for c in candidates if -1.0 <= c <= 1.0]
    return min(r for r in rho if r > 0)


def cycloid_problem(geometry: CycloidGeometry) -> tuple[str, str] | None:
    """(field, message) of the first thing that makes ``geometry`` an impossible cycloid-pin stage, or None."""
    g = geometry
    mm = 1e3
    if g.lobes < MIN_LOBES:
        return "lobes", (f"{g.lobes} lobes: a cycloid disc needs at least {MIN_LOBES} (with fewer pins some eccentric "
                         "angles leave a single pin loaded, and the pins cannot locate the disc)")
    if g.pins != g.lobes + 1:
        return "pins", (f"{g.pins} pins with {g.lobes} lobes: a one-tooth-difference cycloid drive needs "
                        f"pins = lobes + 1 = {g.lobes + 1}")
    for name in ("eccentricity", "pin_circle_radius", "pin_radius", "contact_length"):
        value = getattr(g, name)
        if not (value > 0 and math.isfinite(value)):
            return name, f"{name} = {value * mm:.4g} mm must be positive and finite"
    if g.K1 >= 1:
        return "eccentricity", (f"K1 = Z_p e / R_p = {g.K1:.4g} >= 1 (e = {g.eccentricity * mm:.4g} mm, limit "
                                f"R_p / Z_p "
                                f"= {g.pin_circle_radius / g.pins * mm:.4g} mm): the pin-centre locus would be an "
                                "ordinary (K1 = 1, cusped) or prolate (K1 > 1, looped) epicycloid and no disc profile "
                                "exists; a cycloid disc needs the shortened epicycloid, K1 < 1 (Chen et al. 2008)")
    if 2 * g.pin_radius >= g.pin_spacing:
        return "pin_radius", (f"{g.pin_radius * mm:.4g} mm: adjacent pins overlap, their centres are "
                              f"2 R_p sin(pi/Z_p) = {g.pin_spacing * mm:.4g} mm apart, so the pin radius must stay "
                              f"below {g.pin_spacing / 2 * mm:.4g} mm")
    rho = min_curvature_radius(g)
    if g.pin_radius >= rho:
        return "pin_radius", (f"undercut: the pin radius {g.pin_radius * mm:.4g} mm is not below the smallest radius "
                              f"of curvature of the pin-centre locus on its convex part, rho_min = {rho * mm:.4g} mm "
                              f"(K1 = {g.K1:.4g}, Z_p = {g.pins}); the disc profile would loop at the lobe flanks "
                              "(non-undercutting condition r_rp < rho_min: Shin & Kwon 2006, Hwang & Hsieh 2007)")
    if g.eccentricity >= g.pin_radius:
        return "eccentricity", (f"{g.eccentricity * mm:.4g} mm is not below the pin radius {g.pin_radius * mm:.4g} mm: "
                                f"the lobe tips (radius R_p + e - r_rp = "
                                f"{(g.pin_circle_radius + g.eccentricity - g.pin_radius) * mm:.4g} mm) would pass the "
                                f"pin circle R_p = {g.pin_circle_radius * mm:.4g} mm, where the housing's grooves hold "
                                "the pins half-embedded; the tooth depth 2e must stay below the pin diameter")
    return None


# ---------------------------------------------------------------------------------------------------------------
# pin contacts


@dataclass(frozen=True)
class PinContacts:
    """Pin contacts at an array of poses: arrays of shape (..., Z_p) or (..., Z_p, 2), ``...`` the shape of the
    eccentric angles; vectors in the fixed frame."""

    relative_angle: np.ndarray  # varphi_i = psi_i - phi, in [0, 2 pi)
    normal: np.ndarray  # unit, from the pitch point towards the pin centre: the force on the pin, per unit
    arm: np.ndarray  # l_i, of the normal about the disc centre
    wheel_arm: np.ndarray  # a_i = (C_i x n)_z, of the normal about the pin wheel's centre
    pin_centre: np.ndarray  # C_i
    contact_point: np.ndarray  # C_i - r_rp n_i, on the disc's profile at the conjugate pose
    pitch_point: np.ndarray  # (..., 2)

    def loaded(self, torque_sign: float) -> np.ndarray:
        """The pins that carry load when a torque of ``torque_sign`` (the torque applied to the disc by everything
        but the pins, counter-clockwise positive) turns the disc against them: sign * l_i > 0."""
        scale = np.max(np.abs(self.arm), axis=-1, keepdims=True)
        return np.sign(torque_sign) * self.arm > LOAD_THRESHOLD * scale

    @property
    def disc_row(self) -> np.ndarray:
        """(..., Z_p, 3): d delta_i / d(x, y, theta) of the disc, (n_x, n_y, l_i)."""
        return np.concatenate([self.normal, self.arm[..., None]], axis=-1)

    @property
    def wheel_row(self) -> np.ndarray:
        """(..., Z_p, 3): d delta_i / d(x, y, theta) of the pin wheel, -(n_x, n_y, a_i)."""
        return -np.concatenate([self.normal, self.wheel_arm[..., None]], axis=-1)


def pin_contacts(geometry: CycloidGeometry, eccentric_angle, wheel_angle=0.0) -> PinContacts:
    """Normals and arms of all pins at eccentric angles ``eccentric_angle`` (any shape) and pin wheel angles
    ``wheel_angle`` (broadcast against it)."""
    g = geometry
    phi, w = np.broadcast_arrays(np.asarray(eccentric_angle, dtype=float), np.asarray(wheel_angle, dtype=float))
    psi = 2 * np.pi * np.arange(g.pins) / g.pins + w[..., None]
    rel = psi - phi[..., None]
    c, s = np.cos(rel), np.sin(rel)
    k = g.K1
    norm = np.sqrt(1 + k * k - 2 * k * c)
    nx, ny = (c - k) / norm, s / norm  # eccentric frame
    cp, sp = np.cos(phi)[..., None], np.sin(phi)[..., None]
    normal = np.stack([cp * nx - sp * ny, sp * nx + cp * ny], axis=-1)
    centre = g.pin_circle_radius * _e(psi)
    return PinContacts(
        relative_angle=np.mod(rel, 2 * np.pi),
        normal=normal,
        arm=g.rolling_radius * ny,
        wheel_arm=g.pitch_radius * ny,
        pin_centre=centre,
        contact_point=centre - g.pin_radius * normal,
        pitch_point=g.pitch_radius * _e(phi),
    )


def conjugate_disc_angle(geometry: CycloidGeometry, eccentric_angle, wheel_angle=0.0):
    """The disc's rotation at which its profile touches every pin: theta = w - (phi - w) / Z_c (the disc rolls
    its circle r_c inside the pin wheel's pitch circle Z_p e).  At phi = w = 0 pin 0 sits in the tooth space on
    the disc frame's +x axis."""
    return wheel_angle - (np.asarray(eccentric_angle) - wheel_angle) / geometry.lobes


# ---------------------------------------------------------------------------------------------------------------
# disc profile (disc frame: origin at the disc centre, rotated by the disc angle)


def pin_centre_locus(geometry: CycloidGeometry, t):
    """(..., 2): the theoretical profile X(t) = R_p e(t) - e e(Z_p t), t in [0, 2 pi) once round; a pin touching
    the disc at the conjugate pose lies at t = psi_i - theta (theta the disc angle)."""
    t = np.asarray(t, dtype=float)
    return geometry.pin_circle_radius * _e(t) - geometry.eccentricity * _e(geometry.pins * t)


def profile_normal(geometry: CycloidGeometry, t):
    """(..., 2): the outward unit normal of the locus, (e(t) - K1 e(Z_p t)) / S (the locus runs counter-clockwise);
    it points from the pitch point to the pin centre."""
    t = np.asarray(t, dtype=float)
    k = geometry.K1
    v = _e(t) - k * _e(geometry.pins * t)
    return v / np.sqrt(1 + k * k - 2 * k * np.cos(geometry.lobes * t))[..., None]


def disc_profile(geometry: CycloidGeometry, t=None, points_per_lobe: int = 64):
    """(..., 2): the disc's exact profile, the inner equidistant of the pin-centre locus at the pin radius,
    X(t) - r_rp N(t); at ``t`` or, by default, at ``points_per_lobe`` points per lobe counter-clockwise once round
    (the first point, t = 0, the bottom of the tooth space on +x, not repeated)."""
    if t is None:
        t = 2 * np.pi * np.arange(points_per_lobe * geometry.lobes) / (points_per_lobe * geometry.lobes)
    return pin_centre_locus(geometry, t) - geometry.pin_radius * profile_normal(geometry, t)


# ---------------------------------------------------------------------------------------------------------------
# contact stiffness and the classical load share


def palmgren_deflection(force, length):
    """Approach (m) of a steel line contact of ``length`` (m) under ``force`` (N >= 0):
    delta[mm] = 3.84e-5 Q^0.9 / l^0.8 with Q in N and l in mm (Palmgren 1959, Ball and Roller Bearing Engineering;
    also Harris & Kotzalas 2007)."""
    q = np.asarray(force, dtype=float)
    if np.any(q < 0):
        raise ValueError("a line contact carries compression only: the force must not be negative")
    return 1e-3 * PALMGREN_COEFFICIENT * q**0.9 / (np.asarray(length, dtype=float) * 1e3) ** 0.8


def palmgren_stiffness(force, length):
    """Tangent stiffness (N/m) of the Palmgren line contact at ``force`` (N), ``length`` (m):
    k = dQ/d delta = Q / (0.9 delta) = Q^0.1 l^0.8 / (0.9 * 3.84e-5) N/mm, l in mm; 0 at Q = 0."""
    q = np.asarray(force, dtype=float)
    if np.any(q < 0):
        raise ValueError("a line contact carries compression only: the force must not be negative")
    return 1e3 * q**0.1 * (np.asarray(length, dtype=float) * 1e3) ** 0.8 / (0.9 * PALMGREN_COEFFICIENT)


def rigid_disc_load_share(geometry: CycloidGeometry, torque, eccentric_angle=0.0, wheel_angle=0.0):
    """(..., Z_p) pin forces (N, >= 0, along each normal) of a rigid disc turning about its fixed centre against
    equally stiff pins under ``torque`` (N m, about the disc centre, applied to the disc by everything but the
    pins): delta_i = l_i theta on the loaded pins, so F_i = F_max l_i / r_c with F_max = |T| r_c / sum l_j^2, and
    sum F_i l_i = |T| exactly.  For many pins sum l_j^2 -> Z_p r_c^2 / 4 and F_max -> 4 |T| / (Z_p r_c), the
    classical load distribution of cycloid-drive design."""
    contacts = pin_contacts(geometry, eccentric_angle, wheel_angle)
    torque = np.asarray(torque, dtype=float)[..., None]
    scale = np.max(np.abs(contacts.arm), axis=-1, keepdims=True)
    arm = np.where(np.sign(torque) * contacts.arm > LOAD_THRESHOLD * scale, np.abs(contacts.arm), 0.0)
    total = np.sum(arm**2, axis=-1, keepdims=True)
    return np.abs(torque) * arm / np.where(total > 0, total, 1.0)


def classical_peak_force(geometry: CycloidGeometry, torque):
    """F_max = 4 |T| / (Z_p r_c): the largest pin force of the classical rigid-disc load share (many pins)."""
    return 4 * np.abs(torque) / (geometry.pins * geometry.rolling_radius)
