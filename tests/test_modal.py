"""Natural frequencies against analytic results and Lin & Parker's structure."""

import math

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import modes
from gearcheck.train.variants import edited, wide_stage

RIGID = "1.0e16"  # N/m or N·m/rad: supports this stiff perturb a 1e8..1e9 N/m mesh mode by O(1e-8)


def single_mesh_train():
    """Demo stage reduced to one sun-planet pair on fixed axes: carrier held, no ring, rigid supports,
    free sun (torque-driven), the planet as the output."""
    return edited("demo-3p", [
        (r"^planets = 3", "planets = 1"),
        (r'^output = "stage1.carrier"', 'output = "stage1.planet1"'),
        (r'^held = \["stage1.ring"\]', 'held = ["stage1.carrier"]'),
        (r"^input_shaft_stiffness = .*\n", ""),
        (r"^\[stages.ring\]\n(.*\n)*?support = .*\n", ""),
        (r"radial_stiffness = 1.0e8, radial_damping = 500.0", f"radial_stiffness = {RIGID}"),
        (r"radial_stiffness = 1.0e9, radial_damping = 2000.0", f"radial_stiffness = {RIGID}, "
                                                               f"torsional_stiffness = {RIGID}"),
        (r"radial_stiffness = 2.0e8, radial_damping = 500.0", f"radial_stiffness = {RIGID}"),
        (r'model = "rectangular"', 'model = "constant"'),
    ])


def test_single_mesh_frequency_is_sqrt_k_over_m_eq():
    spec = single_mesh_train()
    result = modes(build_model(spec))
    sun, planet = spec.members["stage1.sun"], spec.members["stage1.planet1"]
    rb_s, rb_p = sun.gears["sun"].base_radius, planet.gears["planet"].base_radius
    k = 8.0e8
    m_eq = 1.0 / (rb_s**2 / sun.inertia + rb_p**2 / planet.inertia)
    analytic = math.sqrt(k / m_eq) / (2 * math.pi)
    assert result.types.count("rigid") == 1  # the pair rolling together
    f = result.frequencies[1]  # the first elastic mode is the mesh mode, all others are > 1e4 x higher
    assert f == pytest.approx(analytic, rel=1e-6)
    assert result.frequencies[2] > 100 * f


def test_rigid_body_modes_count_free_rotations():
    # shaft-driven input, ring held: no free rotation
    assert modes(build_model(load_train("demo-3p"))).types.count("rigid") == 0
    # torque-driven input: the whole train turns freely -> one zero frequency
    free_input = edited("demo-3p", [(r"^input_shaft_stiffness = .*\n", "")])
    result = modes(build_model(free_input))
    assert result.types.count("rigid") == 1
    assert result.frequencies[0] == 0.0


@pytest.mark.parametrize("n_planets", [3, 4, 6])
def test_mode_multiplicities_for_equally_spaced_planets(n_planets):
    """Lin & Parker 1999: rotational modes simple, translational modes in pairs, planet modes of
    multiplicity N - 3 (none for N = 3)."""
    spec = wide_stage(n_planets)
    result = modes(build_model(spec))
    types = result.types
    assert "mixed" not in types
    for f, t, mult in zip(result.frequencies, types, result.multiplicity):
        expected = {"rotational": 1, "translational": 2, "planet": n_planets - 3}[t]
        assert mult == expected, (f, t, mult)
    # Lin & Parker: 6 rotational, 6 translational pairs, 3 distinct planet frequencies
    assert types.count("rotational") == 6
    assert types.count("translational") == 12
    assert types.count("planet") == 3 * (n_planets - 3)


def test_planet_mode_frequencies_independent_of_planet_count():
    f = {}
    for n in (4, 6):
        r = modes(build_model(wide_stage(n)))
        f[n] = np.unique(np.round([fr for fr, t in zip(r.frequencies, r.types) if t == "planet"], 6))
    assert len(f[4]) == 3
    np.testing.assert_allclose(f[4], f[6], rtol=1e-9)


def test_dof_count_and_labels():
    result = modes(build_model(load_train("demo-4p")))
    assert len(result) == 3 * (3 + 4)
    assert result.dof_labels[:3] == ["stage1.sun.x", "stage1.sun.y", "stage1.sun.theta"]
