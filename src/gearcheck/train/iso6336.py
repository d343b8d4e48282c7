"""Tooth stiffness of spur and helical gears by ISO 6336-1:2006, method B (clause 9).

A quick, empirical estimate to set a train's ``mean`` mesh stiffness or to check a computed
one.  ISO works in N/(mm·µm) per unit face width; here everything is SI: stiffness per unit
face width in N/m², so 1 N/(mm·µm) = 1e9 N/m².

* theoretical single stiffness c'_th = 1/q', with the minimum flexibility of a tooth pair
  q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1² + C9 x2²
  (mm·µm/N; gear 1 the pinion, z_n = z for spur gears), fitted to Weber/Schmidt-type
  calculations of solid steel gears;
* single stiffness c' = c'_th C_M C_R C_B (E/E_st), C_M = 0.8 the correction between
  theory and measurement, C_R = 1 (solid gear blanks), C_B = [1 + 0.5 (1.2 - h_fP/m)]
  [1 - 0.02 (20° - alpha_P)] the basic rack factor (the mean of both gears');
* mean mesh stiffness per face width c_gamma_alpha = c' (0.75 eps_alpha + 0.25);
* helical gears: q' with the virtual teeth numbers z_n = z / (cos^2(beta_b) cos(beta)), and c' times
  cos(beta); the basic rack factor with the normal pressure angle.

The values hold for a line load F_t K_A / b >= 100 N/mm.  For an internal pair the ring is
gear 2 with z_n2 -> infinity.  With ISO 21771's signed teeth count (z2 < 0,
d_a2 = d2 + 2 m (h_aP + x2)) a positive x2 moves a ring's teeth inward and thickens them at
the reference circle, the reverse of gearcheck's sign (positive moves them outward), so
x2 = -x_ring here (both conventions coincide for the unshifted rings of the presets).
"""

from __future__ import annotations

import math

Q_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
CORRECTION_FACTOR = 0.8  # C_M
STEEL_MODULUS = 206e9  # E_st, Pa
UNIT = 1e9  # N/(mm·µm) in N/m²


def _pair(mesh):
    """(z_n1, x1, z_n2, x2): gear 1 the pinion (the planet of an internal pair)."""
    central, planet = mesh.central_gear, mesh.planet_gear
    if mesh.internal:
        return planet.teeth, planet.profile_shift, math.inf, -central.profile_shift
    pinion, wheel = sorted((central, planet), key=lambda g: g.teeth)
    return pinion.teeth, pinion.profile_shift, wheel.teeth, wheel.profile_shift


def theoretical_single_stiffness_of(z1: float, x1: float, z2: float, x2: float, beta: float = 0.0,
                                    normal_pressure_angle: float = math.radians(20.0)) -> float:
    """c'_th = 1/q' in N/m² (N/m of line of action per m of face width) of a pair with z1 <= z2 teeth
    (z2 = inf: an internal wheel), profile shifts x1, x2, helix angle beta (virtual teeth numbers)."""
    if beta:
        cos_bb2 = 1.0 - (math.sin(beta) * math.cos(normal_pressure_angle)) ** 2
        z1, z2 = (z / (cos_bb2 * math.cos(beta)) for z in (z1, z2))
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = Q_COEFFICIENTS
    q = c1 + c2 / z1 + c3 / z2 + c4 * x1 + c5 * x1 / z1 + c6 * x2 + c7 * x2 / z2 + c8 * x1**2 + c9 * x2**2
    return UNIT / q


def rack_factor(dedendum: float, normal_pressure_angle: float) -> float:
    """C_B of one basic rack: [1 + 0.5 (1.2 - h_fP/m)] [1 - 0.02 (20 - alpha_P/deg)]."""
    return (1 + 0.5 * (1.2 - dedendum)) * (1 - 0.02 * (20.0 - math.degrees(normal_pressure_angle)))


def single_stiffness_of(z1: float, x1: float, z2: float, x2: float, beta: float = 0.0,
                        normal_pressure_angle: float = math.radians(20.0), rack: float | None = None,
                        youngs_modulus: float = STEEL_MODULUS, correction: float = CORRECTION_FACTOR) -> float:
    """c' = c'_th C_M C_R C_B cos(beta) (E/E_st) in N/m²; ``rack`` C_B (default: h_fP = 1.25 m at the
    pressure angle); ``correction=1`` gives the theoretical value without C_M."""
    rack = rack_factor(1.25, normal_pressure_angle) if rack is None else rack
    return (theoretical_single_stiffness_of(z1, x1, z2, x2, beta, normal_pressure_angle) * correction * rack
            * math.cos(beta) * youngs_modulus / STEEL_MODULUS)


def mean_stiffness_of(single: float, contact_ratio: float, face_width: float) -> float:
    """c_gamma_alpha b = c' (0.75 eps_alpha + 0.25) b in N/m, from c' (N/m²)."""
    return single * (0.75 * contact_ratio + 0.25) * face_width


def _helix(mesh) -> tuple[float, float]:
    """(|beta|, alpha_n) of the pair."""
    gear = mesh.central_gear
    return abs(gear.helix_angle), gear.normal_pressure_angle


def basic_rack_factor(mesh) -> float:
    """C_B, the mean over both gears' basic racks."""
    return 0.5 * sum(rack_factor(g.dedendum, g.normal_pressure_angle) for g in (mesh.central_gear, mesh.planet_gear))


def single_stiffness(mesh, youngs_modulus: float = STEEL_MODULUS, correction: float = CORRECTION_FACTOR) -> float:
    """c' in N/m²; ``correction=1`` gives the theoretical value c'_th C_B cos(beta) (no C_M)."""
    return single_stiffness_of(*_pair(mesh), *_helix(mesh), basic_rack_factor(mesh), youngs_modulus, correction)


def mean_mesh_stiffness(mesh, youngs_modulus: float = STEEL_MODULUS, correction: float = CORRECTION_FACTOR) -> float:
    """c_gamma_alpha times the face width: the mean mesh stiffness of the pair in N/m."""
    g = mesh.geometry
    return mean_stiffness_of(single_stiffness(mesh, youngs_modulus, correction), g.contact_ratio,
                             min(mesh.central_gear.face_width, mesh.planet_gear.face_width))
