"""The RV reducer in the reference model (Yang, Chen & Wang 2018): kinematics, the rigid mechanism, the
frozen configurations, and the time solver's quasi-static limit."""

import numpy as np
import pytest

from gearcheck.lumped import time_solver
from gearcheck.lumped.assembly import build_model, contact_sets, frozen_at
from gearcheck.lumped.describe import describe
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import modes
from gearcheck.lumped.static import static_solution
from gearcheck.train.variants import edited
from gearcheck.shared.settings import RunSettings

CONSTANT_MESH = [(r'stiffness = \{ model = "rectangular", mean = 2.68e8 \}',
                  'stiffness = { model = "constant", mean = 2.68e8 }')]


@pytest.fixture(scope="module")
def model():
    return build_model(load_train("rv-reducer"))


def test_ratio_and_mesh_frequencies(model):
    """i = 1 + (z_p / z_s) Z_p = 185; the sun mesh at z_s (w_s - w_c), the pins at Z_p |w_H|, and their ratio
    z_p / Z_c = 69/39 at any speed: both are harmonics (69th, 39th) of the cranks' turn in the carrier."""
    kin = model.kin
    assert kin.ratio == pytest.approx(1 + 69 / 15 * 40, rel=1e-13)
    f_sun, f_pins = kin.mesh_frequency["rv.planet1.sun"], kin.mesh_frequency["rv.pins"]
    assert f_sun == pytest.approx(15 * (1000 - 1000 / 185) / 60, rel=1e-13)
    assert f_pins / f_sun == pytest.approx(39 / 69, rel=1e-13)
    crank = abs(kin.speeds["rv.crank1"] - kin.speeds["rv.carrier"]) / (2 * np.pi)
    assert (f_sun / crank, f_pins / crank) == pytest.approx((69, 39), rel=1e-13)


def test_published_parameters_give_table_3_mode_3(model):
    """Tables 1-2 as printed, 3 cranks and 2 discs: the lowest mode is the train turning on the sun's shaft
    at 695.9 Hz, Table 3's third mode (697.16 Hz, test 681.47 Hz); nothing near its 154.56 or 396.09 Hz."""
    f = modes(model).frequencies
    assert f[0] == pytest.approx(697.16, rel=0.005)
    assert f[0] > 600.0


def test_output_stiffness_against_the_catalogue_order(model):
    """The static windup of the output under the rated 3136 N·m, the input held by its shaft: 6.2e6 N·m/rad
    (1.8e3 N·m/arcmin), the order of the RV-320E's catalogue torsional rigidity (about 1e3 N·m/arcmin)."""
    static = static_solution(model)
    windup = abs(static.q[model.dofs("rv.carrier", "theta")] + static.q[model.dofs("rv.sun", "theta")] / 185)
    per_arcmin = 3136.0 / windup * np.pi / (180 * 60)
    assert 5e2 < per_arcmin < 5e3


def test_pin_contacts_take_the_load_on_one_side(model):
    """Compression only: in the static state about half of each disc's 40 pins touch, all on the side whose
    arm the load presses, and every touching pin is compressed."""
    static = static_solution(model)
    element = model.turning[-1]
    delta = element.pin_deflections(0.0, static.q)
    touching = delta > 0
    assert 15 <= touching[0].sum() <= 21 and 15 <= touching[1].sum() <= 21
    arms = element.pin_coefficients(0.0)[0][..., 2]
    for disc in range(2):  # a pin on the eccentric's line (arm 0) may be pressed by the disc's translation
        signs = np.sign(arms[disc][touching[disc] & (np.abs(arms[disc]) > 1e-9 * np.abs(arms).max())])
        assert len(np.unique(signs)) == 1


def test_show_prints_the_cycloid_pin_stage_as_its_part_describes_it(model):
    """``gearcheck show`` asks every part what it shows: the cycloid-pin stage, under its stage, with the pin pass
    of the kinematics, the pins' stiffness that the model takes and how many pins touch in its static contact set."""
    shown = describe(model.spec)["stages"][0]["cycloid"]
    assert (shown["discs"], shown["cranks"], shown["pins"], shown["clearance_m"]) == (2, 3, 40, 0.0)
    assert shown["pin_frequency_hz"] == model.kin.mesh_frequency["rv.pins"]
    assert shown["pin_stiffness_n_per_m"] == model.turning[-1].pin_stiffness
    assert shown["pins_touching_at_rest"] == contact_sets(model)[0].sum() > 0


def test_frozen_configurations_turn_with_the_eccentric(model):
    """One turn of the cranks in the carrier brings every configuration back: the frozen modes at t and at
    t + T_crank agree, and the pin-pass pattern (Z_c per turn) repeats after T_crank / Z_c."""
    crank = abs(model.kin.speeds["rv.crank1"] - model.kin.speeds["rv.carrier"])
    period = 2 * np.pi / crank
    t = 0.013
    a, b = modes(frozen_at(model, t)).frequencies, modes(frozen_at(model, t + period)).frequencies
    np.testing.assert_allclose(a, b, rtol=1e-9)
    c = modes(frozen_at(model, t + period / 39)).frequencies
    np.testing.assert_allclose(a, c, rtol=1e-9)


def test_slow_eccentric_motion_is_quasi_static():
    """With a constant mesh stiffness the only excitation is the eccentrics' geometry, at the crank's 3.6 Hz
    and the pin pass at 140.5 Hz, far below the 696 Hz lowest mode: the time response from the static start
    follows the static solutions of the frozen configurations (pin forces to 1e-4 of the largest, the output's
    windup to 1e-5 of itself)."""
    model = build_model(edited("rv-reducer", CONSTANT_MESH))
    run = time_solver.simulate(model, RunSettings(duration=0.012))
    labels = model.dofs.labels()
    q = np.stack([run.raw[label] for label in labels], axis=1)
    v = np.stack([run.raw[label + "_dot"] for label in labels], axis=1)
    element = model.turning[-1]
    theta = model.dofs("rv.carrier", "theta")
    for i in (len(run.t) // 2, len(run.t) - 1):
        frozen = static_solution(frozen_at(model, run.t[i]))
        dynamic = element.pin_forces(run.t[i], q[i], v[i])
        quasi_static = element.pin_forces(run.t[i], frozen.q, np.zeros_like(frozen.q))
        assert np.abs(dynamic - quasi_static).max() < 1e-4 * quasi_static.max()
        assert q[i, theta] == pytest.approx(frozen.q[theta], rel=1e-5)


def test_modes_read_like_the_papers_classes(model):
    """Yang, Chen & Wang (2018, Section 3.2) type an RV reducer's modes as planar planetary ones: the sun and the
    output wheel are the central members, planets, crankshafts and cycloid discs the planetary components.  Read
    so, every mode of the preset is rotational (central members only turn) or translational (they only
    translate) -- none mixed, where counting the discs as central left 22 of its first 23 mixed -- and the twin,
    typing from its own joints, agrees mode by mode."""
    import gearcheck

    lumped, twin = modes(model), gearcheck.modes("rv-reducer", solver="mujoco")
    assert set(lumped.types) == {"rotational", "translational"} and lumped.types == twin.types
    assert lumped.types[:4] == ["rotational", "translational", "translational", "rotational"]
