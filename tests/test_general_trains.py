"""Trains beyond the presets: stepped (compound) planets, unequal planet spacing, two stages.
Both solvers derive them independently; their natural frequencies must agree, and the lumped
statics and kinematics must follow the textbook relations."""

from pathlib import Path

import numpy as np
import pytest

import gearcheck
from gearcheck.lumped.assembly import build_model
from gearcheck.train.kinematics import kinematics
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import modes
from gearcheck.lumped.static import static_solution
from gearcheck.train.variants import edited

DATA = Path(__file__).parent / "data"


def assert_same_frequencies(spec):
    a, b = modes(build_model(spec)), gearcheck.modes(spec, "mujoco")
    np.testing.assert_allclose(b.frequencies, a.frequencies, rtol=1e-6)
    assert a.types == b.types
    return a


def test_stepped_planet_kinematics_statics_and_modes():
    spec = load_train(DATA / "stepped-planet.toml")
    kin = kinematics(spec)
    assert kin.ratio == pytest.approx(1 + 74 * 30 / (20 * 24), rel=1e-12)
    static = static_solution(build_model(spec, rotating_frame_terms=False))
    np.testing.assert_allclose(static.load_sharing(spec)["sharing"], 1.0, atol=1e-9)
    # planet torque balance: F_sun r_b,a = F_ring r_b,b for every planet
    planet = spec.members["s1.planet1"]
    rb_a, rb_b = planet.gears["a"].base_radius, planet.gears["b"].base_radius
    f = dict(zip((m.id for m in spec.meshes), static.mesh_force))
    assert f["s1.planet1.sun"] * rb_a == pytest.approx(f["s1.planet1.ring"] * rb_b, rel=1e-9)
    result = assert_same_frequencies(spec)
    assert "rotational" in result.types and "translational" in result.types


def test_unequally_spaced_planets():
    """Planets at 0, 115.714 and 240 deg (multiples of 360/(z_s + z_r) = 4.2857 deg): the mode types
    of Lin & Parker no longer separate (they need cyclic symmetry) and every mode is mixed, but
    the two derivations still agree."""
    spec = edited("demo-3p", [(r"^planets = 3", "planets = 3\nplanet_angles_deg = [0.0, 115.71428571428572, 240.0]")])
    result = assert_same_frequencies(spec)
    assert result.types.count("mixed") == len(result)
    assert len(set(result.multiplicity)) == 1  # no degenerate pairs without the symmetry


def test_two_stages_with_a_spline():
    from gearcheck.train.variants import chained

    spec = chained(2)
    kin = kinematics(spec)
    assert kin.ratio == pytest.approx((1 + 62 / 22) ** 2, rel=1e-12)
    assert_same_frequencies(spec)


def test_a_ring_shared_by_two_stages():
    """Two stages' rings joined into one (a coupling of kind "ring", stiff radially and torsionally): the
    carriers turn at different speeds, so in the lumped model the radial coupling is time-periodic
    (gearcheck.lumped.elements.coupling.TurningCoupling).  At t = 0 every frame coincides and the natural frequencies
    agree with MuJoCo's (whose rings' slides are world-fixed, so its coupling is constant); the time
    responses agree too, which they would not if the periodic rows were wrong."""
    from gearcheck.train.loader import load_text
    from gearcheck.train.variants import chained_text

    ring = ('\n[[couplings]]\nname = "ring"\nkind = "ring"\nfrom = "stage1.ring"\nto = "stage2.ring"\n'
            "torsional_stiffness = 1.0e8\nradial_stiffness = 1.0e10\n")
    spec = load_text(chained_text(2) + ring, "shared-ring")
    model = build_model(spec)
    assert len(model.turning) == 1
    assert_same_frequencies(spec)
    a, b = (gearcheck.simulate(spec, solver, 0.02) for solver in ("lumped", "mujoco"))
    w = a.t > 0.01
    ring_a, ring_b = a["stage2.ring.ay.world"][w], b["stage2.ring.ay.world"][w]
    assert np.sqrt(np.mean((ring_a - ring_b) ** 2)) < 0.02 * np.sqrt(np.mean(ring_a**2))
    fa, fb = a.select("mesh_force")[w], b.select("mesh_force")[w]
    force_error = np.sqrt(np.mean((fa - fb) ** 2)) / np.sqrt(np.mean(fa**2))
    assert force_error < 1e-3
