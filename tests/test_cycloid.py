"""Cycloid-pin geometry against an independent construction of the disc profile, rigid-body motions, closed
forms, and the numbers of the RV reducer of Yang, Chen & Wang (2018) (pin circle and pin radius estimated)."""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

from gearcheck.train.cycloid import (
    CycloidGeometry,
    classical_peak_force,
    conjugate_disc_angle,
    curvature_radius,
    cycloid_problem,
    disc_profile,
    min_curvature_radius,
    palmgren_deflection,
    palmgren_stiffness,
    pin_centre_locus,
    pin_contacts,
    rigid_disc_load_share,
)

RV = CycloidGeometry(lobes=39, pins=40, eccentricity=2.2e-3, pin_circle_radius=118e-3, pin_radius=5e-3,
                     contact_length=10e-3)
SMALL = CycloidGeometry(lobes=9, pins=10, eccentricity=3.0e-3, pin_circle_radius=45e-3, pin_radius=4e-3,
                        contact_length=8e-3)  # K1 = 0.667, few pins: the curvature changes fast
POSES = [(0.0, 0.0), (0.3, 0.0), (1.234, 0.0), (-2.5, 0.7), (4.0, -1.1)]  # (eccentric angle, pin wheel angle)


def rot(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def disc_angle_from_rolling(g, phi, w):
    """The disc rolls on the pin wheel at P: equal velocities there, e phi' + r_c theta' = Z_p e w', so
    theta = (Z_p w - phi) / Z_c (zero at phi = w = 0)."""
    return (g.pins * w - phi) / g.lobes


def locus_in_disc_frame(g, phi, w, i):
    """Pin i's centre seen from the disc, and its derivative in phi (the disc frame's tangent of the locus)."""
    theta = disc_angle_from_rolling(g, phi, w)
    angle = 2 * math.pi * i / g.pins + w
    centre = g.pin_circle_radius * np.array([math.cos(angle), math.sin(angle)])
    y = rot(-theta) @ (centre - g.eccentricity * np.array([math.cos(phi), math.sin(phi)]))
    j = np.array([[0.0, -1.0], [1.0, 0.0]])
    dtheta = -1.0 / g.lobes
    dy = -dtheta * j @ y + rot(-theta) @ (-g.eccentricity * np.array([-math.sin(phi), math.cos(phi)]))
    return y, dy, theta


@pytest.mark.parametrize("g", [RV, SMALL], ids=["rv", "small"])
def test_normal_passes_through_the_pitch_point_and_is_normal_to_the_exact_profile(g):
    """For every pin at several poses: the normal runs from P to the pin centre; it is the outward normal of the
    pin-centre locus built by kinematic inversion (to 1e-12); the contact point lies on the module's profile at
    the conjugate parameter (to 1e-12 R_p); the pin centre is exactly r_rp from the profile (minimised over the
    curve, to 1e-9 r_rp); and no pin comes closer than r_rp to any profile point (no interference)."""
    per_lobe = 400
    t_all = 2 * np.pi * np.arange(per_lobe * g.lobes) / (per_lobe * g.lobes)
    profile = disc_profile(g, t_all)
    for phi, w in POSES:
        c = pin_contacts(g, phi, w)
        p = c.pitch_point
        assert np.allclose(p, g.pitch_radius * np.array([math.cos(phi), math.sin(phi)]), rtol=0, atol=1e-15)
        for i in range(g.pins):
            n, centre = c.normal[i], c.pin_centre[i]
            to_pin = centre - p
            assert abs(to_pin[0] * n[1] - to_pin[1] * n[0]) < 1e-15 and to_pin @ n > 0
            assert abs(np.linalg.norm(n) - 1) < 1e-14
            y, dy, theta = locus_in_disc_frame(g, phi, w, i)
            outward = rot(theta) @ np.array([dy[1], -dy[0]]) / np.linalg.norm(dy)
            assert np.allclose(outward, n, rtol=0, atol=1e-12), (phi, w, i)
            assert np.allclose(rot(theta) @ y + g.eccentricity * np.array([math.cos(phi), math.sin(phi)]), centre,
                               rtol=0, atol=1e-15)
            t_i = 2 * math.pi * i / g.pins + w - theta
            assert theta == pytest.approx(float(conjugate_disc_angle(g, phi, w)), abs=1e-15)
            assert np.allclose(pin_centre_locus(g, t_i), y, rtol=0, atol=1e-12 * g.pin_circle_radius)
            contact_in_disc = rot(-theta) @ (c.contact_point[i] - g.eccentricity * np.array([math.cos(phi),
                                                                                              math.sin(phi)]))
            assert np.allclose(disc_profile(g, t_i), contact_in_disc, rtol=0, atol=1e-12 * g.pin_circle_radius)
            d = np.linalg.norm(profile - y, axis=1)
            assert d.min() > g.pin_radius * (1 - 1e-12)
            k = int(np.argmin(d))
            h = t_all[1]
            best = minimize_scalar(lambda t, y=y: float(np.linalg.norm(disc_profile(g, t) - y)),
                                   bounds=(t_all[k] - h, t_all[k] + h), method="bounded",
                                   options={"xatol": 1e-14})
            assert best.fun == pytest.approx(g.pin_radius, rel=1e-9)


def test_the_conjugate_family_is_strain_free():
    """Rolling about the pitch point, u = -r_c theta e_perp(phi), compresses no pin; nor does the rigid rotation
    of disc and pin wheel together about the wheel's centre (u = e theta e_perp(phi)).  A translation along the
    eccentric does (it is no rigid motion of the pair)."""
    phi = np.linspace(0, 2 * np.pi, 37)
    for g in (RV, SMALL):
        c = pin_contacts(g, phi, 0.3)
        perp = np.stack([-np.sin(phi), np.cos(phi)], axis=-1)
        roll = np.concatenate([-g.rolling_radius * perp, np.ones((phi.size, 1))], axis=-1)
        assert np.max(np.abs(np.einsum("tik,tk->ti", c.disc_row, roll))) < 1e-15 * g.rolling_radius * 10
        disc = np.concatenate([g.eccentricity * perp, np.ones((phi.size, 1))], axis=-1)
        wheel = np.tile([0.0, 0.0, 1.0], (phi.size, 1))
        both = np.einsum("tik,tk->ti", c.disc_row, disc) + np.einsum("tik,tk->ti", c.wheel_row, wheel)
        assert np.max(np.abs(both)) < 1e-15 * g.rolling_radius * 10
        along = np.concatenate([np.stack([np.cos(phi), np.sin(phi)], axis=-1), np.zeros((phi.size, 1))], axis=-1)
        assert np.max(np.abs(np.einsum("tik,tk->ti", c.disc_row, along))) > 0.5


def test_arms_and_normals_in_the_eccentric_frame():
    """l = r_c sin(varphi)/S, the arm about the wheel centre Z_p/Z_c of it, |l| <= r_c with the maximum r_c at
    cos(varphi) = K1, and the array shapes follow the angles'."""
    phi = np.linspace(-1, 5, 12).reshape(3, 4)
    c = pin_contacts(RV, phi, 0.2)
    assert c.arm.shape == (3, 4, 40) and c.normal.shape == (3, 4, 40, 2) and c.disc_row.shape == (3, 4, 40, 3)
    k = RV.K1
    s = np.sqrt(1 + k * k - 2 * k * np.cos(c.relative_angle))
    assert np.allclose(c.arm, RV.rolling_radius * np.sin(c.relative_angle) / s, rtol=0, atol=1e-15)
    assert np.allclose(c.wheel_arm, c.arm * 40 / 39, rtol=1e-14, atol=0)
    cross = c.pin_centre[..., 0] * c.normal[..., 1] - c.pin_centre[..., 1] * c.normal[..., 0]
    assert np.allclose(c.wheel_arm, cross, rtol=0, atol=1e-15)
    assert np.all(np.abs(c.arm) <= RV.rolling_radius * (1 + 1e-15))
    top = pin_contacts(RV, -math.acos(k))  # pin 0 at varphi = arccos(K1)
    assert top.arm[0] == pytest.approx(RV.rolling_radius, rel=1e-15)
    assert np.allclose(top.normal[0], [math.cos(-math.acos(k) + math.pi / 2), math.sin(-math.acos(k) + math.pi / 2)],
                       atol=1e-15)  # normal to the eccentric line there: along e_perp(phi)


def test_loaded_pins_of_the_rv_reducer():
    """19 or 20 of the 40 pins carry a torque, 19 when two pins sit at varphi = 0 and pi; the other sign the rest."""
    c = pin_contacts(RV, np.array([0.0, 0.05]))
    assert c.loaded(+1).sum(axis=-1).tolist() == [19, 20]
    assert c.loaded(-1).sum(axis=-1).tolist() == [19, 20]
    assert not np.any(c.loaded(+1) & c.loaded(-1))


def test_five_pins_always_load_two():
    """The smallest disc cycloid_problem accepts (4 lobes, 5 pins) has at least two loaded pins for either torque
    sign at every eccentric angle; 3 lobes on 4 pins drop to one."""
    phi = np.linspace(0, 2 * np.pi, 3601)
    for lobes, fewest in ((4, 2), (5, 2), (3, 1)):
        c = pin_contacts(CycloidGeometry(lobes, lobes + 1, 1e-3, (lobes + 1) * 1e-3 / 0.7, 0.5e-3, 0.01), phi)
        assert min(c.loaded(+1).sum(axis=-1).min(), c.loaded(-1).sum(axis=-1).min()) == fewest


def sum_of_squared_arms(g, phi):
    c = pin_contacts(g, phi)
    return np.sum(np.where(c.loaded(+1), c.arm, 0.0) ** 2, axis=-1)


@pytest.mark.parametrize("k1", [0.5, 0.75])
@pytest.mark.parametrize("pins", [20, 40, 80])
def test_sum_of_squared_arms_is_a_quarter_of_pins_times_r_c_squared(pins, k1):
    """Sum over the loaded pins of l_i^2 = Z_p r_c^2 / 4 (int_0^pi sin^2/(1 + K^2 - 2K cos) = pi/2), up to the
    Euler-Maclaurin error of the pin sum at the kinks of l^2 at varphi = 0 and pi:
    |rel. error| <= (4 sqrt(3) pi^2 / 27) ((1 - K1)^-2 + (1 + K1)^-2) / Z_p^3 (asymptotically, 2 pi / Z_p << 1 - K1;
    a factor 1.6 of margin), e.g. 1.6e-3 at Z_p = 40, K1 = 0.75.  Its mean over a pin pitch is exact (quad, 1e-11)."""
    g = CycloidGeometry(pins - 1, pins, 1e-3, pins * 1e-3 / k1, 0.2e-3, 0.01)
    target = pins * g.rolling_radius**2 / 4
    phi = np.linspace(0, 2 * np.pi / pins, 1001)
    rel = np.max(np.abs(sum_of_squared_arms(g, phi) / target - 1))
    bound = 1.6 * 4 * math.sqrt(3) * math.pi**2 / 27 * ((1 - k1) ** -2 + (1 + k1) ** -2) / pins**3
    assert rel < bound
    assert rel > 0.2 * bound  # the estimate is the right size, not just an upper bound
    pitch = 2 * math.pi / pins
    mean = quad(lambda p: float(sum_of_squared_arms(g, p)), 0, pitch, points=[pitch / 2], epsabs=0,
                epsrel=1e-13, limit=200)[0] / pitch
    assert mean == pytest.approx(target, rel=1e-11)


def test_rigid_load_share_carries_the_torque_exactly():
    """Sum F_i l_i = T to rounding, forces along the loaded pins only and proportional to their arms, the peak
    near the classical 4 T/(Z_p r_c) (within the sum-of-arms error) within a pin pitch of varphi = arccos K1; the
    other torque sign loads the other pins."""
    phi = np.linspace(0, 2 * np.pi, 50)
    torque = 3136.0 / 3
    for sign in (+1, -1):
        f = rigid_disc_load_share(RV, sign * torque, phi)
        c = pin_contacts(RV, phi)
        assert np.all(f >= 0) and np.all(f[~c.loaded(sign)] == 0)
        assert np.allclose(np.sum(f * c.arm, axis=-1), sign * torque, rtol=1e-14, atol=0)
        ratio = np.where(c.loaded(sign), f / np.where(c.loaded(sign), np.abs(c.arm), 1.0), np.nan)
        assert np.all(np.nanmax(ratio, axis=-1) - np.nanmin(ratio, axis=-1) < 1e-12 * np.nanmax(ratio, axis=-1))
        arms = np.where(c.loaded(sign), np.abs(c.arm), 0.0)
        f_max = torque * RV.rolling_radius / np.sum(arms**2, axis=-1)  # the force a pin at l = r_c would carry
        assert np.allclose(f.max(axis=-1), f_max * arms.max(axis=-1) / RV.rolling_radius, rtol=1e-14)
        assert np.allclose(f_max, classical_peak_force(RV, torque), rtol=1.1e-3)  # the sum-of-arms bound at Z_p 40
        assert np.all(np.abs(c.relative_angle[np.arange(50), f.argmax(axis=-1)]
                             - (math.acos(RV.K1) if sign > 0 else 2 * math.pi - math.acos(RV.K1))) < 2 * math.pi / 40)
    f = rigid_disc_load_share(RV, np.array([torque, 2 * torque, 0.0]), 0.1)
    assert np.allclose(f[1], 2 * f[0], rtol=1e-15) and np.all(f[2] == 0)


def test_curvature_radius_closed_form_against_the_locus():
    """rho(varphi) against |X'|^3 / (X' x X'') of the locus by central differences (1e-6), and rho_min against
    a dense search over the convex part (1e-9), for the RV reducer and a coarse disc."""
    for g in (RV, SMALL):
        t = np.linspace(0.01, 2 * np.pi / g.lobes, 200)
        h = 1e-5
        x0, xp, xm = pin_centre_locus(g, t), pin_centre_locus(g, t + h), pin_centre_locus(g, t - h)
        d1, d2 = (xp - xm) / (2 * h), (xp - 2 * x0 + xm) / h**2
        kappa_fd = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3
        kappa = 1 / curvature_radius(g, -g.lobes * t)  # cos(Z_c t) = cos(varphi) at the contact
        assert np.max(np.abs(kappa_fd - kappa)) < 1e-6 * np.max(np.abs(kappa))
        rho = curvature_radius(g, np.linspace(0, np.pi, 2_000_001))
        assert min_curvature_radius(g) == pytest.approx(rho[rho > 0].min(), rel=1e-9)
    # the closed form sqrt(27 (Z_p - 1)(1 - K1^2)/(Z_p + 1)^3) R_p where the stationary point lies inside
    k = RV.K1
    assert min_curvature_radius(RV) == pytest.approx(RV.pin_circle_radius * math.sqrt(27 * 39 * (1 - k * k) / 41**3),
                                                     rel=1e-14)
    tip = CycloidGeometry(9, 10, 0.2e-3, 40e-3, 1e-3, 0.01)  # K1 = 0.05: the stationary point lies past the tip
    rho = curvature_radius(tip, np.linspace(0, np.pi, 200_001))
    assert min_curvature_radius(tip) == pytest.approx(rho[rho > 0].min(), rel=1e-12)


def test_the_rv_reducer_of_the_paper_passes():
    """Z_c 39, Z_p 40, e 2.2 mm (printed), R_p 118 mm, r_rp 5 mm, 10 mm thick (estimates): K1 = 0.7458,
    r_c = 85.8 mm, rho_min = 9.717 mm (the undercut margin is 4.7 mm), pins 18.52 mm apart."""
    assert cycloid_problem(RV) is None
    assert RV.K1 == pytest.approx(0.74576, abs=1e-5)
    assert RV.rolling_radius == pytest.approx(85.8e-3, rel=1e-14) and RV.pitch_radius == pytest.approx(88e-3, rel=1e-14)
    assert min_curvature_radius(RV) == pytest.approx(9.717e-3, abs=1e-6)
    assert RV.pin_spacing == pytest.approx(18.516e-3, abs=1e-6)
    assert cycloid_problem(SMALL) is None


@pytest.mark.parametrize("change, field, words", [
    ({"lobes": 3, "pins": 4}, "lobes", "at least 4"),
    ({"pins": 41}, "pins", "one-tooth-difference"),
    ({"eccentricity": 0.0}, "eccentricity", "positive"),
    ({"pin_radius": -1e-3}, "pin_radius", "positive"),
    ({"pin_circle_radius": math.inf}, "pin_circle_radius", "finite"),
    ({"contact_length": 0.0}, "contact_length", "positive"),
    ({"eccentricity": 3.0e-3}, "eccentricity", "K1 = Z_p e / R_p = 1.017"),
    ({"pin_radius": 9.3e-3}, "pin_radius", "adjacent pins overlap"),
    ({"eccentricity": 0.99 * 118e-3 / 40}, "pin_radius", "undercut"),
    ({"pin_radius": 2.0e-3}, "eccentricity", "tooth depth"),
])
def test_each_problem_names_its_field(change, field, words):
    found = cycloid_problem(replace(RV, **change))
    assert found is not None and found[0] == field and words in found[1], found
    assert "\n" not in found[1]


def test_the_undercut_limit_is_where_the_profile_starts_to_loop():
    """Just below rho_min the real profile's convex radius rho - r_rp stays positive everywhere; just above it
    the equidistant turns back on itself (its tangent reverses against the locus's)."""
    rho = min_curvature_radius(RV)
    t = np.linspace(0, 2 * np.pi / RV.lobes, 20_001)

    def reversed_tangent(g):
        p = disc_profile(g, t)
        x = pin_centre_locus(g, t)
        return np.any(np.sum(np.diff(p, axis=0) * np.diff(x, axis=0), axis=1) < 0)

    assert not reversed_tangent(replace(RV, pin_radius=0.99 * rho))
    assert reversed_tangent(replace(RV, pin_radius=1.01 * rho))
    assert cycloid_problem(replace(RV, pin_radius=1.01 * rho))[0] == "pin_radius"


def test_palmgren_stiffness_at_the_audit_numbers():
    """delta = 3.84e-5 Q^0.9 / l^0.8 (mm, N); k = Q/(0.9 delta): F_max = 4 T/(Z_p r_c) for 3136 N m on three or two
    discs is 1218 or 1828 N; over l = 10-15 mm the stiffness is 3.7e8-5.4e8 N/m; k is dQ/d delta (1e-7).  (The
    torque about the disc centre is in fact (Z_c/Z_p)(1 - 1/185) 3136/N = 0.970 of it, which moves k by 0.3 %.)"""
    forces = classical_peak_force(RV, np.array([3136 / 3, 3136 / 2]))
    assert forces == pytest.approx([1218.3, 1827.5], abs=0.1)
    assert palmgren_stiffness(forces[0], 10e-3) == pytest.approx(3.7e8, rel=0.01)
    assert palmgren_stiffness(forces[1], 15e-3) == pytest.approx(5.4e8, rel=0.01)
    k = palmgren_stiffness(np.array([[1218.0, 1828.0]]), np.array([[10e-3], [15e-3]]))
    assert k.shape == (2, 2) and 3.7e8 <= k.min() * 1.005 and k.max() <= 5.4e8 * 1.005
    assert palmgren_deflection(1218.0, 10e-3) == pytest.approx(3.645e-6, rel=1e-3)
    dq = 1e-3
    slope = 2 * dq / (palmgren_deflection(1500 + dq, 12e-3) - palmgren_deflection(1500 - dq, 12e-3))
    assert palmgren_stiffness(1500.0, 12e-3) == pytest.approx(slope, rel=1e-7)
    assert palmgren_stiffness(0.0, 10e-3) == 0.0
    with pytest.raises(ValueError, match="compression only"):
        palmgren_stiffness(-1.0, 10e-3)
