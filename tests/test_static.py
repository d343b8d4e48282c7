"""Static load sharing and torque balance."""

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.static import static_solution, stiffness_with_rotation
from gearcheck.train.variants import edited


def input_torque_through_meshes(spec, static):
    """Torque the input passes into the train: its meshes' F r_b (a sun or ring input), or for an
    input without meshes (a carrier) the torque of its input shaft."""
    sun = spec.input
    if not spec.members[sun].gears:
        return -static.row_forces[static.row_names.index("input_shaft")]
    r_b = next(iter(spec.members[sun].gears.values())).base_radius
    # a helical mesh's force is tilted by the base helix angle: its transverse part turns the gear
    return sum(f * np.cos(m.geometry.base_helix_angle) for m, f in zip(spec.meshes, static.mesh_force)
               if m.central == sun) * r_b


def rigid_turn(model):
    """The mechanism advanced by one second of nominal motion: every member turned by its speed, every
    planet (and RV crank) carried r_c w_c along its orbit, every cycloid disc e w_H along its orbit about
    the pin wheel's centre (at t = 0, the carrier's axes)."""
    turn = np.zeros(model.n)
    for mid, member in model.spec.members.items():
        turn[model.dofs(mid, "theta")] = model.kin.speeds[mid]
        if member.orbits:
            turn[model.dofs(mid, "tangential")] = member.radius * model.kin.speeds[f"{member.stage}.carrier"]
        if member.kind == "disc":
            ecc = member.eccentric
            phi, w_h = ecc.phase, model.kin.speeds[ecc.crank]
            turn[model.dofs(mid, "x")] = -ecc.eccentricity * w_h * np.sin(phi)
            turn[model.dofs(mid, "y")] = ecc.eccentricity * w_h * np.cos(phi)
    return turn


def test_equal_load_sharing_and_torque_balance(preset):
    """Virtual work with the train's rigid-body motion: sum over the sun meshes of F r_b = T_out/ratio
    (to 1e-9: hub-drive's stiffness matrix spans 5e7 to 1e10 N/m and loses ~1e-11 to round-off)."""
    spec = load_train(preset)
    model = build_model(spec, rotating_frame_terms=False)
    static = static_solution(model)
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    expected = abs(model.kin.output_torque / model.kin.ratio)
    assert input_torque_through_meshes(spec, static) == pytest.approx(expected, rel=1e-9)


def test_rigid_turn_is_force_free_at_speed(preset):
    """At speed the train is a relative equilibrium: nothing in it depends on where the mechanism
    stands, so a rigid turn of the mechanism must be a null vector of the stiffness with every
    rotating-frame term, and the power balance T_in w_in + T_out w_out = 0 holds exactly (the
    centripetal forces do no work in steady rotation).  Lin & Parker's (1999) softening alone
    breaks both: demo-3p's static input torque at 1500 rpm is 6.3e-6 off the power balance, and the
    stiffness of demo-3p without its input shaft at 3000 rpm has the eigenvalue -5.3e-5 (unstable)."""
    spec = load_train(preset)
    model = build_model(spec)
    static = static_solution(model)
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    expected = abs(model.kin.output_torque / model.kin.ratio)
    assert input_torque_through_meshes(spec, static) == pytest.approx(expected, rel=1e-9)
    K = stiffness_with_rotation(model, model.excitation.mean_stiffness)
    for shaft in (r for r in model.rows if r.kind == "shaft"):  # the shaft that holds the input back
        K -= shaft.stiffness * np.outer(shaft.a, shaft.a)
    turn = rigid_turn(model)
    assert np.abs(K @ turn).max() < 1e-12 * np.abs(K).max() * np.abs(turn).max()


def test_backlash_shifts_deflection_not_force():
    """A backlash 2b moves the loaded mesh's deflection by b and leaves its force unchanged."""
    plain = static_solution(build_model(load_train("demo-3p"), rotating_frame_terms=False))
    loose = static_solution(build_model(edited("demo-3p", [
        (r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 100.0")]),
        rotating_frame_terms=False))
    np.testing.assert_allclose(loose.mesh_force, plain.mesh_force, rtol=1e-9)
    assert np.all(loose.in_contact)
    assert np.all(loose.mesh_deflection > 50e-6)
