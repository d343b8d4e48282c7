"""Helical planetary stages: the normal line of action, axial degrees of freedom, both solvers.

A helical mesh pushes along the normal line of action, tilted by the base helix angle beta_b out of the
transverse plane: its force F_n carries the torque with F_n cos(beta_b) on the base radius and pushes the
gears apart axially with F_n sin(beta_b) (Eritenel & Parker 2009).  Checked in closed form:

* statics of a sun-in, ring-held stage with N planets and input torque T: every mesh carries
  F_n = T / (N r_bs cos beta_b); the sun's axial support takes T tan(beta_b) / r_bs (its tangential force
  times tan beta_b), the ring's the same the other way, and the planets' sun and ring meshes push them
  equally both ways (their bearings and the carrier take no axial load);
* a vanishing helix leaves the planar spectrum and adds one axial mode per member, sqrt(k_axial / m) for
  the central members, each on its own support, and the planets' on their pins;
* a zero helix angle is today's planar model, to the bit;
* MuJoCo's twin, whose mesh tendons take their axial coefficients from MuJoCo's own Jacobians along the
  tilted line of action, has the same natural frequencies and the same static mesh forces.
"""

import math

import numpy as np
import pytest

import gearcheck
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.static import static_solution
from gearcheck.lumped.transmission_error import static_transmission_error
from gearcheck.train.variants import helical_stage

AXIAL = 5.0e8  # N/m, helical_stage's default axial support stiffness


def _ratio(spec) -> float:
    z_s, z_r = spec.meshes[0].central_gear.teeth, spec.meshes[-1].central_gear.teeth
    return 1.0 + z_r / z_s  # sun in, ring held, carrier out


@pytest.mark.parametrize("helix", [8.0, 15.0, -25.0])
def test_static_forces_of_a_helical_stage(helix):
    spec = helical_stage(helix)
    static = static_solution(build_model(spec))
    sun = spec.meshes[0].central_gear
    beta_b = spec.meshes[0].geometry.base_helix_angle
    torque = spec.operating.output_torque / _ratio(spec)
    n = len(spec.stages[0].planets)
    np.testing.assert_allclose(static.mesh_force, torque / (n * sun.base_radius * math.cos(beta_b)), rtol=1e-9)
    rows = dict(zip(static.row_names, static.row_forces))
    axial = torque * math.tan(beta_b) / sun.base_radius
    # a left-hand sun (helix > 0 on the planets) driven forward is pushed along -z (see line_of_action)
    assert rows["stage1.sun.support_z"] == pytest.approx(-math.copysign(axial, helix), rel=1e-9)
    assert rows["stage1.ring.support_z"] == pytest.approx(math.copysign(axial, helix), rel=1e-9)
    for name in ["stage1.carrier.support_z"] + [f"{p}.bearing_axial" for p in spec.stages[0].planets]:
        assert abs(rows[name]) < 1e-9 * axial, name


@pytest.mark.parametrize("helix", [15.0, -25.0])
def test_both_solvers_agree_on_modes_and_statics(helix):
    spec = helical_stage(helix)
    lumped = gearcheck.modes(spec, solver="lumped")
    mujoco = gearcheck.modes(spec, solver="mujoco")
    assert len(lumped.frequencies) == 4 * len(spec.members)  # x, y, theta and z of every member
    np.testing.assert_allclose(lumped.frequencies, mujoco.frequencies, rtol=1e-9)
    result = gearcheck.crosscheck(spec, speed=3000.0, duration=0.03)
    assert result.verdict == "PASS", result.failures
    lumped_run, mujoco_run = result.results
    for mesh in spec.meshes:
        assert mujoco_run.static[f"{mesh.id}.force"] == pytest.approx(lumped_run.static[f"{mesh.id}.force"],
                                                                       rel=1e-7)


def test_a_vanishing_helix_adds_the_axial_modes_to_the_planar_spectrum():
    planar = np.array(gearcheck.modes(gearcheck.load("demo-3p"), solver="lumped").frequencies)
    spec = helical_stage(1e-7)
    helical = np.array(gearcheck.modes(spec, solver="lumped").frequencies)
    matched = np.zeros(helical.size, dtype=bool)
    for f in planar:
        j = np.argmin(np.abs(helical - f) + matched * 1e300)
        assert helical[j] == pytest.approx(f, rel=1e-6)
        matched[j] = True
    # axially, the sun and the ring sit alone on their supports; the N planets on their pins of a carrier
    # on its support: N - 1 modes of the planets against a still carrier, and two of the carrier with
    # the planets in phase, K = [[k + N k, -N k], [-N k, N k]], M = diag(m_c, N m_p)
    m = {kind: next(x.mass for x in spec.members.values() if x.kind == kind) for kind in ("sun", "ring", "carrier",
                                                                                           "planet")}
    n = len(spec.stages[0].planets)
    omega2 = [AXIAL / m["sun"], AXIAL / m["ring"]] + [AXIAL / m["planet"]] * (n - 1)
    K = np.array([[AXIAL * (1 + n), -n * AXIAL], [-n * AXIAL, n * AXIAL]])
    omega2 += list(np.linalg.eigvals(np.linalg.solve(np.diag([m["carrier"], n * m["planet"]]), K)).real)
    expected = np.sort(np.sqrt(omega2) / (2 * math.pi))
    np.testing.assert_allclose(np.sort(helical[~matched]), expected, rtol=1e-6)


def test_a_zero_helix_angle_is_the_planar_model_to_the_bit():
    planar = build_model(gearcheck.load("demo-3p"))
    zero = build_model(helical_stage(0.0, stiffness="rectangular"))
    assert zero.dofs.labels() == planar.dofs.labels()
    for name in ("M", "G", "K_mean", "K_frame", "C", "mesh_rows", "F_static"):
        assert np.array_equal(getattr(zero, name), getattr(planar, name)), name


def test_a_helical_pair_keeps_contact_through_its_overlap():
    """At 45 deg demo-3p's teeth have a transverse contact ratio below 1 (0.998), which a spur pair could not
    run with; the face overlap (eps_b = 3.001) keeps about four pairs in contact, and with eps_b nearly whole
    the total contact length, so the mesh stiffness, hardly varies (Maatar & Velex 1996: constant for a whole
    eps_b): both solvers agree and the loaded transmission error is flat to 1e-3 of its mean."""
    spec = helical_stage(45.0, stiffness="contact-line")
    g = spec.meshes[0].geometry
    assert g.contact_ratio < 1.0 < g.face_contact_ratio
    np.testing.assert_allclose(gearcheck.modes(spec, solver="lumped").frequencies,
                               gearcheck.modes(spec, solver="mujoco").frequencies, rtol=1e-9)
    curve = static_transmission_error(spec)[0]
    assert np.ptp(curve.loaded) < 1e-3 * np.mean(curve.loaded)


def test_a_sun_eccentricity_on_in_phase_planets_is_decided():
    """helical-planetary with a 5 um sun eccentricity: its in-phase planets cancel the mesh forces on the sun to 1e-4
    of their size, so the sun's accelerations are small differences of large forces, and an error of order h in
    either solver shows there first.  With every RK4 stage driven from its own state (MuJoCo's world-frame mesh
    coefficients turned at each stage, not once a step) the cross-check passes: the sun's accelerations agree to
    NRMSE 2.4e-3 against a tolerance of 0.05 (they differed by 0.66 when the coefficients turned once a step)."""
    from gearcheck.train.variants import edited

    spec = edited("helical-planetary", [(r"^(\[stages.sun\]\n)", r"\1eccentricity_um = 5.0\n")], "sun eccentric 5 um")
    result = gearcheck.crosscheck(spec)
    assert result.verdict == "PASS", (result.failures, result.unresolved)
    for name in ("stage1.sun.ax.world", "stage1.sun.ay.world"):
        assert result[name].metrics["nrmse"] < 0.01
