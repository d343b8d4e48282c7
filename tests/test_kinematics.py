"""Willis kinematics, power balance, mesh frequencies and phasing."""

import math

import numpy as np
import pytest

from gearcheck.train.kinematics import kinematics
from gearcheck.train.loader import load_train
from gearcheck.train.variants import edited


def test_willis_for_every_stage_of_every_preset(preset):
    spec = load_train(preset)
    kin = kinematics(spec)
    for stage in spec.stages:
        wc = kin.speeds[stage.carrier]
        for mesh in spec.meshes:
            if mesh.stage != stage.name:
                continue
            # each planet rolls on each central gear: z_C (w_C - w_c) = -/+ z_p (w_p - w_c)
            wC = kin.speeds[mesh.central] - wc
            wp = kin.speeds[mesh.planet] - wc
            sign = 1.0 if mesh.internal else -1.0
            assert mesh.central_gear.teeth * wC == pytest.approx(sign * mesh.planet_gear.teeth * wp, rel=1e-12)


def test_demo_ratio_is_one_plus_zr_over_zs():
    kin = kinematics(load_train("demo-3p"))
    assert kin.ratio == pytest.approx(1 + 62 / 22, rel=1e-13)


def test_power_balance(preset):
    spec = load_train(preset)
    kin = kinematics(spec)
    p_in = kin.input_torque * spec.operating.input_speed
    p_out = kin.output_torque * kin.speeds[spec.output]
    assert p_in == pytest.approx(-p_out, rel=1e-12)


def test_mesh_frequency_and_planet_phases():
    spec = load_train("demo-3p")
    kin = kinematics(spec)
    w_s, w_c = kin.speeds["stage1.sun"], kin.speeds["stage1.carrier"]
    f_mesh = 22 * (w_s - w_c) / (2 * math.pi)
    for mesh in spec.meshes:
        assert kin.mesh_frequency[mesh.id] == pytest.approx(f_mesh, rel=1e-12)
    # gamma_sn = z_s psi_n / 2 pi (mod 1): 22/3 -> 1/3, 2/3
    sun = [kin.mesh_phase[f"stage1.planet{n}.sun"] for n in (1, 2, 3)]
    np.testing.assert_allclose(sun, [0.0, 1 / 3, 2 / 3], atol=1e-12)


def _sun_ring_phase_at_pitch_points(spec):
    """gamma_rs between pitch points (Parker & Lin's reference) from our start-of-contact phases:
    gamma_rs = (B1P1 - B2P2)/p_b - (phase_ring - phase_sun)."""
    kin = kinematics(spec)
    sun = spec.meshes[0]
    ring = next(m for m in spec.meshes if m.internal and m.planet == sun.planet)
    planet, rg = ring.planet_gear, ring.central_gear
    a = sun.geometry.pressure_angle
    p = planet.base_pitch
    b1p1 = math.sqrt(planet.tip_radius**2 - planet.base_radius**2) - planet.base_radius * math.tan(a)
    b2p2 = rg.base_radius * math.tan(a) - math.sqrt(rg.tip_radius**2 - rg.base_radius**2)
    return ((b1p1 - b2p2) / p - (kin.mesh_phase[ring.id] - kin.mesh_phase[sun.id])) % 1.0


def test_sun_ring_phase_even_planet_teeth_half_cycle():
    """Parker & Lin 2004: unshifted planets with even z_p have gamma_rs = 1/2."""
    assert _sun_ring_phase_at_pitch_points(load_train("demo-3p")) == pytest.approx(0.5, abs=1e-9)


def test_sun_ring_phase_odd_planet_teeth_in_phase():
    """... and odd z_p gives gamma_rs = 0 (two planets: (22 + 64)/2 = 43 assembles)."""
    spec = edited("demo-3p", [(r"^planets = 3", "planets = 2"), (r"^teeth = 20", "teeth = 21"),
                                    (r"^teeth = 62", "teeth = 64")])
    gamma = _sun_ring_phase_at_pitch_points(spec)
    assert min(gamma, 1.0 - gamma) < 1e-9
