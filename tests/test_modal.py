"""Natural frequencies against analytic results and Lin & Parker's structure."""

import math

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import line_drives, line_resonances, modes, modes_at_speed
from gearcheck.shared.modal import driven_modes
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


def test_a_force_drives_the_modes_it_is_not_orthogonal_to_whatever_their_basis():
    """Two unit masses on springs 1 and 4 N/m, lightly damped: a force on the first drives its mode alone; one on
    both drives both equally (a unit oscillator's velocity residue at its pole s is f s / (2 s + c), about f / 2
    whatever its stiffness); springs 1 and 1 (a degenerate pair, in whatever basis the eigensolver picks): the
    force on the first drives the pair."""
    M, D = np.eye(2), 0.01 * np.eye(2)
    f, zeta, drive = driven_modes(M, D, np.diag([1.0, 4.0]), np.array([[1.0, 1.0], [0.0, 1.0]]))
    assert np.allclose(f, [1 / (2 * np.pi), 2 / (2 * np.pi)], rtol=1e-4) and np.allclose(zeta, [0.005, 0.0025])
    assert drive[0, 0] == 1.0 and drive[1, 0] < 1e-12
    assert np.allclose(drive[:, 1], 1.0)
    _, _, drive = driven_modes(M, D, np.eye(2), np.array([[1.0], [0.0]]))
    assert np.allclose(drive[:, 0], 1.0)


@pytest.mark.parametrize("n_planets, teeth", [(3, (22, 20, 62)), (4, (30, 24, 78)), (5, (21, 24, 69)),
                                              (6, (30, 24, 78))])
def test_a_mesh_harmonic_drives_the_family_of_modes_its_planets_phasing_selects(n_planets, teeth):
    """Parker (2000): with N equally spaced planets, the mesh harmonic k of a stage whose sun has z_s teeth drives
    only the rotational modes where k z_s is a multiple of N, only the translational modes where k z_s = +-1
    (mod N), only the planet modes otherwise.  Of each translational pair, split by the turning carrier's
    gyroscopic terms, +1 and -1 drive one whirl each.  :func:`line_resonances` finds the same, from the mesh
    forces' phases alone, on the rotating, damped model."""
    spec = wide_stage(n_planets, teeth)
    model = build_model(spec)
    undamped = modes_at_speed(model, spec.operating.input_speed)
    frequencies, types = np.asarray(undamped.frequencies), list(undamped.types)
    mesh_frequency = model.excitation.frequency[0]
    whirls = {}
    for k in range(1, 2 * n_planets + 1):
        natural, _ = line_resonances(model, [(mesh_frequency, k)])[0]
        nearest = [int(np.argmin(np.abs(frequencies - f))) for f in natural]
        assert np.allclose(frequencies[nearest], natural, rtol=2e-3)  # the damped modes are the undamped ones
        residue = k * teeth[0] % n_planets
        family = "rotational" if residue == 0 else "translational" if residue in (1, n_planets - 1) else "planet"
        assert {types[i] for i in nearest} == {family}, k
        if family == "translational":
            whirls.setdefault(residue, set()).update(nearest)
        else:
            assert len(nearest) == types.count(family), k
    if whirls:
        assert len(whirls) == 2 and not whirls[1] & whirls[n_planets - 1]
        assert len(whirls[1] | whirls[n_planets - 1]) == types.count("translational")


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


def test_a_line_at_no_mesh_frequency_is_refused_not_read_as_driving_nothing():
    """line_drives answers for lines of the train's mesh frequencies; a frequency no mesh has would find every mode
    undriven, an answer for a question it cannot decide."""
    model = build_model(load_train("demo-3p"))
    f_mesh = float(model.excitation.frequency[0])
    assert line_drives(model, [(f_mesh, 1)])[2].any()
    with pytest.raises(ValueError, match=r"line at 123\.4 Hz \(harmonic 1\) is no mesh frequency of demo-3p"):
        line_drives(model, [(f_mesh, 1), (123.4, 1)])
