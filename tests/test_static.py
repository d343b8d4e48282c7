"""Static load sharing and torque balance."""

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.loader import load_train
from gearcheck.lumped.static import static_solution
from gearcheck.lumped.variants import edited


def input_torque_through_meshes(spec, static):
    """Torque the input passes into the train: its meshes' F r_b (a sun or ring input), or for an
    input without meshes (a carrier) the torque of its input shaft."""
    sun = spec.input
    if not spec.members[sun].gears:
        return -static.row_forces[static.row_names.index("input_shaft")]
    r_b = next(iter(spec.members[sun].gears.values())).base_radius
    return sum(f for m, f in zip(spec.meshes, static.mesh_force) if m.central == sun) * r_b


def test_equal_load_sharing_and_torque_balance(preset):
    """Virtual work with the train's rigid-body motion: sum over the sun meshes of F r_b = T_out/ratio
    (to 1e-9: hub-drive's stiffness matrix spans 5e7 to 1e10 N/m and loses ~1e-11 to round-off)."""
    spec = load_train(preset)
    model = build_model(spec, rotating_frame_terms=False)
    static = static_solution(model)
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    expected = abs(model.kin.output_torque / model.kin.ratio)
    assert input_torque_through_meshes(spec, static) == pytest.approx(expected, rel=1e-9)


def test_centripetal_loads_in_the_torque_balance(preset):
    """At speed, the only torque the centripetal loads add is that of a planet sitting off its pin:
    the bearing carries m Omega^2 r_p at the pin, so a planet displaced tangentially by eta_b
    relative to its pin loads the carrier with m Omega^2 r_c eta_b.  A wound-up carrier
    (eta = r_c theta_c for every planet) must add nothing: that is the geometric stiffness of the
    centripetal preload which Lin & Parker's rotating-frame model lacks (without it the linear
    model transmits an extra m Omega^2 r_c^2 theta_c per planet)."""
    spec = load_train(preset)
    model = build_model(spec)
    static = static_solution(model)
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    off_pin = 0.0  # virtual work of the off-pin torques per unit input rotation
    for stage in spec.stages:
        omega = model.kin.speeds[stage.carrier]
        theta_c = static.q[model.dofs(stage.carrier, "theta")]
        for pid in stage.planets:
            p = spec.members[pid]
            eta_b = static.q[model.dofs(pid, "tangential")] - p.radius * theta_c
            off_pin += p.mass * omega**2 * p.radius * eta_b * omega / spec.operating.input_speed
    # virtual work along the rigid motion (d theta_c = d theta_in w_c / w_in, d theta_out = d theta_in / ratio):
    # T_in = -T_out / ratio - off_pin  (a sun input with the carrier out: -(T_out + off_pin_c) / ratio)
    expected = -model.kin.output_torque / model.kin.ratio - off_pin
    assert input_torque_through_meshes(spec, static) == pytest.approx(expected, rel=1e-9)
    assert off_pin != 0.0  # the effect is there (and small: 5e-8 to 1e-5 of the output torque)


def test_backlash_shifts_deflection_not_force():
    """A backlash 2b moves the loaded mesh's deflection by b and leaves its force unchanged."""
    plain = static_solution(build_model(load_train("demo-3p"), rotating_frame_terms=False))
    loose = static_solution(build_model(edited("demo-3p", [
        (r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 100.0")]),
        rotating_frame_terms=False))
    np.testing.assert_allclose(loose.mesh_force, plain.mesh_force, rtol=1e-9)
    assert np.all(loose.in_contact)
    assert np.all(loose.mesh_deflection > 50e-6)
