"""Matejic, Blagojevic & Matejic (2021): the double-planet preset and its 4-DOF model as
published (Eqs. 10-13) and as derived from its own energies (Eqs. 3-5), each against MuJoCo."""

from __future__ import annotations

import numpy as np
import pytest

import gearcheck
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import modes
from gearcheck.lumped.published import four_dof_model, natural_frequencies
from gearcheck.train.published_parameters import MODELS, PaperParameters
from gearcheck.mbd_models.published_twin import build_twin, linearise, twin_modes


@pytest.fixture(scope="module")
def spec():
    return load_train("double-planet")


@pytest.fixture(scope="module")
def params(spec):
    return PaperParameters.from_spec(spec)


def test_preset_reproduces_table_1_and_pins_the_ratio(spec, params):
    from gearcheck.train.kinematics import kinematics

    assert kinematics(spec).ratio == pytest.approx(10920 / 552, rel=1e-12)  # 19.7826..., the paper rounds to 20
    assert params.ratio == pytest.approx(10920 / 552, rel=1e-12)
    table_1 = {"m_h": 11.152, "m_p": 3.376 + 8.563, "J_ch": 116.086e-3, "J_p": 3.039e-3 + 16.778e-3,
               "J_cb": 306.512e-3, "r_h": 0.069, "r_f": 0.0525, "r_g": 0.048, "r_b": 0.117,
               "c1": 1.67e10, "c2": 1.56e10, "k1": 3200.0, "k2": 2400.0}
    for name, value in table_1.items():
        assert getattr(params, name) == pytest.approx(value, rel=1e-12), name
    # 5 kW at 1200 rpm in: M_h = 39.789 N m, output torque through the exact ratio
    assert params.input_torque == pytest.approx(5000 / (1200 * 2 * np.pi / 60), rel=1e-6)
    assert params.output_torque == pytest.approx(-787.12499, rel=1e-12)


def test_as_published_matrices_are_eqs_10_to_12_entry_by_entry(params):
    p = params
    mh, mp, Jh, Jp, Jb = p.m_h, p.m_p, p.J_ch, p.J_p, p.J_cb
    rh, rf, rg, rb, c1, c2, k1, k2 = p.r_h, p.r_f, p.r_g, p.r_b, p.c1, p.c2, p.k1, p.k2
    model = four_dof_model(p, "as-published")
    M_eq10 = {(0, 0): mh + mp, (1, 1): mh * rh**2 + Jh + mp * rh**2 + Jp, (1, 2): Jp, (2, 1): Jp, (2, 2): Jp,
              (3, 3): Jb}
    # Eq. 11 and Eq. 12 have the same pattern, k for damping and c for stiffness
    def eq11_12(a1, a2):
        return {(0, 0): a1 + a2,
                (1, 1): a1 * (rf + rh)**2 + a2 * (rg + rh)**2,
                (1, 2): a1 * rf * (rf + rh) + a2 * rg * (rg + rh), (1, 3): -a2 * rb * (rg + rh),
                (2, 1): a1 * (rf**2 + rf * rh) + a2 * (rg**2 + rg * rh), (2, 2): a1 * rf**2 + a2 * rg**2,
                (2, 3): -a2 * rb * rg,
                (3, 1): -a2 * (rb * rg + rb * rh), (3, 2): -a2 * rb * rg, (3, 3): a2 * rb**2}
    for matrix, expected in ((model.M, M_eq10), (model.B, eq11_12(k1, k2)), (model.C, eq11_12(c1, c2))):
        for i in range(4):
            for j in range(4):
                assert matrix[i, j] == pytest.approx(expected.get((i, j), 0.0), rel=1e-14, abs=0.0), (i, j)
    np.testing.assert_array_equal(model.D(np.array([0.0]), load=False)[0], [0.0, p.input_torque * 1.5, 0.0, 0.0])


def test_energy_derived_model_keeps_the_y1_coupling_that_eqs_11_12_drop(params):
    published, derived = four_dof_model(params, "as-published"), four_dof_model(params, "energy-derived")
    np.testing.assert_array_equal(published.M, derived.M)  # Eq. 10 is Eq. 3 differentiated
    p = params
    assert derived.C[0, 1] == pytest.approx(-(p.c1 * (p.r_f + p.r_h) + p.c2 * (p.r_g + p.r_h)), rel=1e-14)
    assert derived.C[0, 3] == pytest.approx(p.c2 * p.r_b, rel=1e-14)
    np.testing.assert_allclose(derived.C[1:, 1:], published.C[1:, 1:], rtol=1e-14)  # the rotational block agrees
    assert natural_frequencies(published).types.count("rigid") == 1
    assert natural_frequencies(derived).types.count("rigid") == 2


@pytest.mark.parametrize("model, y1, carrier_mass", [
    ("energy-derived", "radial", "pitch"),
    ("energy-derived-axis", "radial", "axis"),
    ("consistent", "tangential", "axis"),
])
def test_derived_frequencies_match_the_mujoco_4dof_twin(params, model, y1, carrier_mass):
    twin = build_twin(params, y1, carrier_mass)
    f_twin = twin_modes(twin).frequencies
    derived = natural_frequencies(four_dof_model(params, model))
    assert twin_modes(twin).types.count("rigid") == derived.types.count("rigid") == 2
    np.testing.assert_allclose(f_twin, derived.frequencies, rtol=1e-6, atol=1e-9)
    M, K, C = linearise(twin)
    lumped = four_dof_model(params, model)
    np.testing.assert_allclose(M, lumped.M, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(K, lumped.C, rtol=1e-7, atol=1e-6 * np.abs(lumped.C).max())
    np.testing.assert_allclose(C, lumped.B, rtol=1e-7, atol=1e-9 * np.abs(lumped.B).max())
    # and the as-published model matches no twin
    published = natural_frequencies(four_dof_model(params, "as-published")).frequencies
    assert np.max(np.abs(published - f_twin) / np.maximum(f_twin, 1.0)) > 0.1


def test_general_model_frequencies_match_the_mujoco_general_twin(spec):
    lumped, mj = modes(build_model(spec)), gearcheck.modes(spec, "mujoco")
    assert len(lumped.frequencies) == len(mj.frequencies) == 18
    np.testing.assert_allclose(mj.frequencies, lumped.frequencies, rtol=1e-6, atol=1e-6)


def test_crosscheck_as_published_fails_by_name_and_energy_derived_passes(spec, tmp_path):
    published = gearcheck.crosscheck(spec, model="as-published", duration=0.01)
    assert not published.passed
    for name in ("y1.acceleration", "theta_h.acceleration", "theta_f.acceleration", "theta_b.acceleration"):
        assert name in published.failures
    assert "mode 2" in published.failures
    derived = gearcheck.crosscheck(spec, model="energy-derived", duration=0.01)
    assert derived.passed, derived.failures
    assert all(r["rel_error"] < 1e-6 for r in derived.modal)
    published.write(tmp_path)
    assert "y1.acceleration" in (tmp_path / "report.md").read_text()


def test_every_model_name_is_known(params):
    for name in MODELS:
        assert four_dof_model(params, name).name == name
    with pytest.raises(Exception, match="unknown 4-DOF model"):
        four_dof_model(params, "as-printed")
