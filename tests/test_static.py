"""Static load sharing and torque balance."""

import numpy as np
import pytest

from lumped import build_model, load_train
from lumped.static import static_solution


def input_torque_through_meshes(spec, static):
    sun = spec.input
    r_b = next(iter(spec.members[sun].gears.values())).base_radius
    return sum(f for m, f in zip(spec.meshes, static.mesh_force) if m.central == sun) * r_b


def test_equal_load_sharing_and_torque_balance(preset):
    """Virtual work with the train's rigid-body motion: sum over the sun meshes of F r_b = T_out/ratio."""
    spec = load_train(preset)
    model = build_model(spec, rotating_frame_terms=False)
    static = static_solution(model)
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    expected = abs(model.kin.output_torque / model.kin.ratio)
    assert input_torque_through_meshes(spec, static) == pytest.approx(expected, rel=1e-12)


def test_rotating_frame_torque_defect_of_the_linear_model(preset):
    """Lin & Parker's rotating-frame terms are not invariant under a rigid rotation of the carrier:
    a planet displaced tangentially by eta (here by the static twist of the input shaft) feels the
    centripetal softening m Omega^2 eta along its tangent, a torque m Omega^2 r_c eta on the carrier
    that the real, rotating bearing (whose preload turns with the pin) cancels.  The linear model
    therefore transmits T_out/ratio plus sum m_p Omega^2 r_c eta_p / ratio; this test pins that defect
    exactly, so the cross-check with MuJoCo (which has no such defect) can be read."""
    spec = load_train(preset)
    model = build_model(spec)
    static = static_solution(model)
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    defect = 0.0
    for stage in spec.stages:
        omega = model.kin.speeds[stage.carrier]
        for pid in stage.planets:
            p = spec.members[pid]
            defect += p.mass * omega**2 * p.radius * static.q[model.dofs(pid, "tangential")]
    # virtual work along the rigid motion (d theta_c = d theta_in / ratio, d eta = r_c d theta_c):
    # T_in = -(T_out + defect) / ratio, T_out < 0 opposing the carrier
    ratio = model.kin.ratio
    expected = -(model.kin.output_torque + defect) / ratio
    assert input_torque_through_meshes(spec, static) == pytest.approx(expected, rel=1e-9)
    assert abs(defect / model.kin.output_torque) > 1e-6  # it is there, and small


def test_backlash_shifts_deflection_not_force():
    """A backlash 2b moves the loaded mesh's deflection by b and leaves its force unchanged."""
    from conftest import text_variant

    plain = static_solution(build_model(load_train("demo-3p"), rotating_frame_terms=False))
    loose = static_solution(build_model(text_variant("demo-3p", [
        (r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 100.0")]),
        rotating_frame_terms=False))
    np.testing.assert_allclose(loose.mesh_force, plain.mesh_force, rtol=1e-9)
    assert np.all(loose.in_contact)
    assert np.all(loose.mesh_deflection > 50e-6)
