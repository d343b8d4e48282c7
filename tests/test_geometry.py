"""Involute geometry against closed forms and textbook values."""

import math

import pytest

from gearcheck.train.geometry import Gear, inverse_involute, involute, mesh_geometry
from gearcheck.train.loader import load_train


def gear(z, internal=False, x=0.0, m=3e-3, alpha=math.radians(20)):
    return Gear("g", z, m, alpha, 0.04, 1.0, 1.25, x, internal, 0.5 * m * z * math.cos(alpha))


def test_inverse_involute_round_trip():
    for deg in (5.0, 14.5, 20.0, 25.0, 35.0):
        a = math.radians(deg)
        assert inverse_involute(involute(a)) == pytest.approx(a, rel=1e-13)


def test_external_contact_ratio_closed_form():
    # z = 22 / 20, m = 3, 20 deg, no shift:  eps = [sqrt(36^2-rb1^2) + sqrt(33^2-rb2^2) - 63 sin20]/(pi m cos20)
    g = mesh_geometry(gear(22), gear(20))
    rb1, rb2 = 33 * math.cos(math.radians(20)), 30 * math.cos(math.radians(20))
    expected = (math.sqrt(36**2 - rb1**2) + math.sqrt(33**2 - rb2**2) - 63 * math.sin(math.radians(20))) / (
        math.pi * 3 * math.cos(math.radians(20)))
    assert g.contact_ratio == pytest.approx(expected, rel=1e-12)
    assert g.centre_distance == pytest.approx(0.063, rel=1e-12)


def test_internal_contact_ratio_closed_form():
    g = mesh_geometry(gear(62, internal=True), gear(20))
    a20 = math.radians(20)
    rbp, rbr = 30 * math.cos(a20), 93 * math.cos(a20)
    expected = ((math.sqrt(33**2 - rbp**2) - math.sqrt(90**2 - rbr**2) + 63 * math.sin(a20))
                / (3 * math.pi * math.cos(a20)))
    assert g.contact_ratio == pytest.approx(expected, rel=1e-12)
    assert g.centre_distance == pytest.approx(0.063, rel=1e-12)


def test_profile_shift_operating_centre_distance():
    # x1 + x2 = 0.5 on z = 22/20: inv a' = inv a + 2 tan a (0.5)/42; a' = 63 cos a / cos a'
    g = mesh_geometry(gear(22, x=0.25), gear(20, x=0.25))
    a = math.radians(20)
    a_op = inverse_involute(involute(a) + 2 * math.tan(a) * 0.5 / 42)
    assert g.pressure_angle == pytest.approx(a_op, rel=1e-12)
    assert g.centre_distance == pytest.approx(0.063 * math.cos(a) / math.cos(a_op), rel=1e-12)
    assert g.centre_distance > 0.063


def test_shifted_ring_keeps_the_stage_consistent():
    """A shifted sun/planet pair needs a matching ring shift: the spec accepts x_r with equal a'."""
    sun, planet = gear(22, x=0.2), gear(20, x=0.1)
    a_sp = mesh_geometry(sun, planet).centre_distance
    from scipy.optimize import brentq

    x_r = brentq(lambda x: mesh_geometry(gear(62, True, x), planet).centre_distance - a_sp, -0.5, 2)
    assert mesh_geometry(gear(62, True, x_r), planet).centre_distance == pytest.approx(a_sp, abs=1e-12)


def test_base_radius_from_preset():
    spec = load_train("demo-3p")
    sun = spec.members["stage1.sun"].gears["sun"]
    assert sun.base_radius == pytest.approx(0.033 * math.cos(math.radians(20)), rel=1e-14)
