"""Tooth-contact mesh stiffness by Weber's energy method (Li et al. 2026, section 3.2).

The deflection of a tooth pair along the line of action at a contact point is the sum,
for each tooth, of

* bending, shear and axial compression of the tooth, cut into slices normal to its
  centreline (Weber; the slice formula of the paper, fig. 7),
* the rotation and translation of the tooth's root section on the gear body
  (fillet-foundation deflection, Cornell 1981, as the paper uses),

plus the load-dependent Hertzian approach of the two flanks.  A pair's stiffness is the
inverse of that total compliance; the mesh stiffness is the sum over the pairs in contact.

The tooth is a cantilever with coordinate ``u`` along its centreline from the root section
(``u = 0``) to the tip, and half thickness ``y(u)``.  A normal force F at a flank point
(u_j, y_j) makes angle beta_j with the centreline's normal; its component F sin(beta_j)
compresses the tooth towards the root.  The bending moment at section u < u_j is
M = F [cos(beta_j) (u_j - u) - sin(beta_j) y_j].  For an external tooth beta_j = alpha_r - psi_r,
for an internal (ring) tooth beta_j = alpha_r + psi_r (alpha_r the involute's pressure angle
at the contact radius r, psi_r the tooth's half angle there).

Profile: the involute flank from the tooth tip down to the base circle, a radial line below
it (external gears), and a circular root fillet of radius 0.38 m (the ISO 53 basic rack's tip
radius rho_fP) tangent to the root circle and the flank.  The exact generated fillet is a
trochoid; the circle has the same tangents at both ends.  (Against Tian's straight tooth below
the base circle the sliced compliance differs by under 2.5 %, see tests/test_mesh_stiffness.py.)

Everything is SI.  Functions are pure in :class:`~gearcheck.train.geometry.Gear` and material constants.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from gearcheck.train.geometry import Gear, involute

FILLET_RADIUS = 0.38  # root fillet radius / module: ISO 53 profile A rack tip radius rho_fP
WIDE_TOOTH_RATIO = 5.0  # Cornell: face width / pitch tooth thickness above which plane strain holds
HERTZ_COEFFICIENT = 1.275  # paper eq. for delta_C, SI units (m, N, Pa)


def flank_half_angle(gear: Gear, radius):
    """Half angle psi(r) subtended at the gear centre by the tooth at radius r (r >= r_b).

    External: psi = s/(2 r) + inv(alpha) - inv(alpha_r), s = m (pi/2 + 2 x tan alpha), r the
    reference radius.  Ring: its tooth space is such an external tooth with
    e = m (pi/2 + 2 x tan alpha) (gearcheck's sign: positive x moves ring teeth outward), so
    psi = pi/z - e/(2 r) - inv(alpha) + inv(alpha_r).
    """
    r = np.maximum(np.asarray(radius, dtype=float), gear.base_radius)
    inv_r = np.tan(np.arccos(gear.base_radius / r)) - np.arccos(gear.base_radius / r)
    alpha = gear.pressure_angle
    width = gear.module * (math.pi / 2 + 2 * gear.profile_shift * math.tan(alpha))
    half = width / (2 * gear.pitch_radius) + involute(alpha)
    if gear.internal:
        return math.pi / gear.teeth - half + inv_r
    return half - inv_r


@dataclass(frozen=True)
class ToothProfile:
    """A tooth as a stack of slices: boundaries ``u`` (from the root section), half thickness
    ``y`` at the slice mid points; ``root_x`` is the root section's distance from the gear
    centre along the centreline, ``root_half_thickness`` its half thickness y_m."""

    gear: Gear
    u: np.ndarray
    y: np.ndarray
    root_x: float
    root_half_thickness: float

    def contact_point(self, radius):
        """(u_j, y_j, beta_j) of the flank point at the given radius."""
        r = np.asarray(radius, dtype=float)
        psi = flank_half_angle(self.gear, r)
        alpha_r = np.arccos(np.minimum(self.gear.base_radius / r, 1.0))
        x = r * np.cos(psi)
        if self.gear.internal:
            return self.root_x - x, r * np.sin(psi), alpha_r + psi
        return x - self.root_x, r * np.sin(psi), alpha_r - psi


def _flank(gear: Gear, n: int = 400) -> np.ndarray:
    """Flank points (x, y) in the tooth frame (x along the centreline) from root to tip circle."""
    r = np.linspace(gear.root_radius, gear.tip_radius, n)
    if gear.internal:
        r = np.maximum(r, gear.base_radius * (1 + 1e-9))
    psi = flank_half_angle(gear, r)
    return np.column_stack([r * np.cos(psi), r * np.sin(psi)])


def _fillet(gear: Gear, flank: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and radius of the root fillet circle: tangent to the root circle and the flank,
    radius 0.38 m (module m), or smaller where the tooth space cannot hold it (centre on the space's
    symmetry line)."""
    sign = -1.0 if gear.internal else 1.0  # centre inside the root circle of a ring

    def centre(rho, phi):
        return (gear.root_radius + sign * rho) * np.array([math.cos(phi), math.sin(phi)])

    def gap(rho, phi):  # distance from the centre to the flank, minus the radius
        return float(np.min(np.hypot(*(flank - centre(rho, phi)).T))) - rho

    rho = FILLET_RADIUS * gear.module
    space_middle = math.pi / gear.teeth
    if gap(rho, space_middle) >= 0.0:
        on_flank = float(flank_half_angle(gear, gear.root_radius + sign * rho))  # centre on the flank: gap < 0
        phi = brentq(lambda p: gap(rho, p), on_flank, space_middle, xtol=1e-12)
    else:
        phi = space_middle
        rho = brentq(lambda q: gap(q, phi), 1e-9 * gear.module, rho, xtol=1e-15)
    return centre(rho, phi), rho


def tooth_profile(gear: Gear, slices: int) -> ToothProfile:
    """The tooth of ``gear`` from its root fillet to the tip cut into ``slices`` equal slices."""
    flank = _flank(gear)
    c, rho = _fillet(gear, flank)
    touch = int(np.argmin(np.hypot(*(flank - c).T)))
    direction = -1.0 if gear.internal else 1.0  # of the centreline from root to tip
    root = c - direction * rho * c / np.linalg.norm(c)  # where the fillet touches the root circle
    start = math.atan2(*(root - c)[::-1])
    end = math.atan2(*(flank[touch] - c)[::-1])
    end = start + (end - start + math.pi) % (2 * math.pi) - math.pi  # the short way round
    t = np.linspace(start, end, 60)
    arc = c + rho * np.column_stack([np.cos(t), np.sin(t)])
    # the root section is the fillet point nearest the gear body along the centreline (a ring's
    # root circle is not normal to the centreline where the fillet meets it)
    outline = np.vstack([arc[int(np.argmin(direction * arc[:, 0])):], flank[touch + 1:]])
    root_x, root_y = outline[0]
    u_outline = direction * (outline[:, 0] - root_x)
    if np.any(np.diff(u_outline) <= 0.0):
        raise ValueError(f"gear {gear.name}: tooth outline is not single-valued along its centreline")
    tip_x = gear.tip_radius * math.cos(float(flank_half_angle(gear, gear.tip_radius)))
    u = np.linspace(0.0, direction * (tip_x - root_x), slices + 1)
    y = np.interp(0.5 * (u[1:] + u[:-1]), u_outline, outline[:, 1])
    return ToothProfile(gear, u, y, float(root_x), float(root_y))


def elastic_constants(gear: Gear, youngs_modulus: float, poisson_ratio: float) -> tuple[float, float]:
    """(E_e, nu_e) of the paper's 'effective elastic modulus': plane stress (E, nu) for a
    narrow tooth, plane strain (E/(1 - nu^2), nu/(1 - nu)) when the face width exceeds 5
    pitch tooth thicknesses (Cornell's criterion).  The plane-strain pair keeps the shear
    modulus G = E_e / (2 (1 + nu_e)) = E / (2 (1 + nu))."""
    thickness = math.pi * gear.module / 2
    if gear.face_width / thickness > WIDE_TOOTH_RATIO:
        return youngs_modulus / (1 - poisson_ratio**2), poisson_ratio / (1 - poisson_ratio)
    return youngs_modulus, poisson_ratio


def tooth_compliance(profile: ToothProfile, radius, youngs_modulus: float, poisson_ratio: float):
    """Deflection per unit normal load (m/N) of one tooth loaded at the flank point of the
    given radius (array): sliced bending + shear + axial compression + fillet foundation.

    Slice i (length L_i, distance S_ij from the load to its outer end, area A_i = 2 y_i b,
    I_i = (2 y_i)^3 b/12) adds, by Castigliano with M = F [cos(b) s - sin(b) y_j]:
      [cos^2 b ((S+L)^3 - S^3)/3 - cos b sin b y_j ((S+L)^2 - S^2) + sin^2 b y_j^2 L] / (E_e I_i)
      + cos^2 b 12 (1 + nu_e) L / (5 E_e A_i) + sin^2 b L / (E_e A_i).
    Paper (sec. 3.2, delta_B): prints the cross term as cos b sin b (L^2 y_j + 2 L y_j S)/(2 I),
    half the value above, and drops sin^2 b y_j^2 L / I; that is Cornell's one-sided form,
    which is not the derivative of the strain energy (its compliance is not symmetric).
    """
    gear = profile.gear
    e, nu = elastic_constants(gear, youngs_modulus, poisson_ratio)
    b = gear.face_width
    uj, yj, beta = (np.asarray(v)[:, None] for v in profile.contact_point(np.atleast_1d(radius)))
    lo, hi = profile.u[None, :-1], profile.u[None, 1:]
    length = np.clip(np.minimum(hi, uj) - lo, 0.0, None)  # only the part between root and load
    near = np.maximum(uj - hi, 0.0)  # S_ij
    far = near + length
    area = 2.0 * profile.y * b
    inertia = (2.0 * profile.y) ** 3 * b / 12.0
    cos, sin = np.cos(beta), np.sin(beta)
    bending = (cos**2 * (far**3 - near**3) / 3 - cos * sin * yj * (far**2 - near**2)
               + sin**2 * yj**2 * length) / inertia
    shear = cos**2 * 12.0 * (1.0 + nu) * length / (5.0 * area)
    axial = sin**2 * length / area
    sliced = np.sum(bending + shear + axial, axis=1) / e
    return sliced + foundation_compliance(profile, uj[:, 0], yj[:, 0], beta[:, 0], e, nu)


def foundation_compliance(profile: ToothProfile, uj, yj, beta, e: float, nu: float):
    """Fillet-foundation compliance (m/N), Cornell (1981) after O'Donnell:
      cos^2 b / (E_e B) [5.306 (L_f/H_f)^2 + 2 (1 - nu_e) L_f/H_f + 1.534 (1 + 0.4167 tan^2 b)/(1 + nu_e)],
    L_f = u_j - y_j tan b (root section to where the load line crosses the centreline),
    H_f = 2 y_m.  This is the paper's narrow-tooth formula; with the plane-strain (E_e, nu_e)
    of a wide tooth it reproduces the paper's wide-tooth prefactor (1 - nu^2)/E and middle
    coefficient 2 (1 - nu - 2 nu^2)/(1 - nu^2) exactly, but gives 1.534 (...)(1 - nu) for the last
    term where the paper prints /(1 + nu): the printed wide-tooth formula is not the
    plane-strain form of the narrow one (a 9 % difference in that term for nu = 0.3).

    Cornell's rather than Sainsot et al. (2004): Sainsot's fit needs the bore radius of the
    gear body, which a train file does not give, and was fitted for external gears only;
    Cornell's semi-infinite foundation applies to the sun, planets and ring alike.
    """
    lf = uj - yj * np.tan(beta)
    hf = 2.0 * profile.root_half_thickness
    ratio = lf / hf
    bracket = 5.306 * ratio**2 + 2.0 * (1.0 - nu) * ratio + 1.534 * (1.0 + 0.4167 * np.tan(beta) ** 2) / (1.0 + nu)
    return np.cos(beta) ** 2 / (e * profile.gear.face_width) * bracket


def hertz_compliance(load: float, youngs_modulus: float, face_width: float) -> float:
    """Hertzian contact compliance delta_C / F = 1.275 / (E^0.9 B^0.8 F^0.1) (m/N).

    The paper prints delta_C = 1.275 / (E^0.9 B^0.8 F^0.1): that is the compliance delta_C / F,
    not the deflection, which is delta_C = 1.275 F^0.9 / (E^0.9 B^0.8) (dimensionally consistent
    in SI: m).  Load dependent, so the pair's secant stiffness is taken at ``load`` (N).
    """
    return HERTZ_COEFFICIENT / (youngs_modulus**0.9 * face_width**0.8 * load**0.1)


@dataclass(frozen=True)
class PathOfContact:
    """Contact radii on both gears along the path of contact, from its start.

    Positions s are measured along the line of action from the central gear's base-circle
    tangent point T_c.  External pair: the planet's contact radius is sqrt(r_bp^2 + (L - s)^2),
    L = a' sin(alpha'); contact begins at the planet tip.  Internal pair: both tangent points lie
    on the same side, planet radius sqrt(r_bp^2 + (s - L)^2); contact begins at the ring tip.
    """

    central: Gear
    planet: Gear
    start: float  # s at the start of contact
    length: float  # path of contact g_alpha
    span: float  # L = |T_c T_p|

    def radii(self, distance):
        """(central radius, planet radius) at ``distance`` from the start of contact."""
        s = self.start + np.asarray(distance, dtype=float)
        return np.hypot(self.central.base_radius, s), np.hypot(self.planet.base_radius, self.span - s)


def path_of_contact(mesh) -> PathOfContact:
    c, p, g = mesh.central_gear, mesh.planet_gear, mesh.geometry
    span = g.centre_distance * math.sin(g.pressure_angle)
    planet_tip = math.sqrt(p.tip_radius**2 - p.base_radius**2)
    central_tip = math.sqrt(c.tip_radius**2 - c.base_radius**2)
    start = central_tip if mesh.internal else span - planet_tip
    return PathOfContact(c, p, start, g.contact_ratio * g.base_pitch, span)


def pair_stiffness_along_path(mesh, distance, youngs_modulus: float, poisson_ratio: float,
                              slices: int, load: float):
    """Stiffness (N/m) of one tooth pair in contact at ``distance`` (m) from the start of contact."""
    path = path_of_contact(mesh)
    rc, rp = path.radii(distance)
    central = tooth_profile(mesh.central_gear, slices)
    planet = tooth_profile(mesh.planet_gear, slices)
    width = min(mesh.central_gear.face_width, mesh.planet_gear.face_width)
    compliance = (tooth_compliance(central, rc, youngs_modulus, poisson_ratio)
                  + tooth_compliance(planet, rp, youngs_modulus, poisson_ratio)
                  + hertz_compliance(load, youngs_modulus, width))
    return 1.0 / compliance
