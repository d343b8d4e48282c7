"""Excitations through both solvers: transmission error, eccentricity, torque ripple, load ramp."""

import numpy as np
import pytest

from gearcheck import crosscheck
from gearcheck.lumped.assembly import build_model
from gearcheck.train.line_of_action import line_of_action
from gearcheck.train.loader import load_train
from gearcheck.lumped.time_solver import simulate
from gearcheck.train.spec import with_profiles
from gearcheck.train.variants import edited
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.settings import RunSettings

EXCITED = [
    (r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nste = [{ harmonic = 1, amplitude_um = 4.0 }, "
                                       "{ harmonic = 2, amplitude_um = 1.0, phase_deg = 30.0 }]"),
    (r"^teeth = 22", "teeth = 22\neccentricity_um = 10.0"),
    (r"^input_shaft_damping = .*", "input_shaft_damping = 2.0\n[[operating.ripple]]\nmember = \"output\"\n"
                                   "order = 3.0\namplitude = 0.05"),
]


def test_transmission_error_eccentricity_and_ripple_agree_between_solvers():
    spec = edited("demo-3p", EXCITED, "excited")
    result = crosscheck(spec, duration=0.05)
    assert result.passed, result.failures
    assert result["stage1.planet1.sun.force"].metrics["nrmse"] < 2e-3


def test_transmission_error_drives_the_mesh_frequency_line():
    """The STE adds a force phasor at the mesh frequency to the one the stiffness variation makes;
    the response is linear in the STE (no backlash), so doubling the STE must double the change of
    the complex line amplitude (to the second-order parametric cross terms, a few per cent)."""
    base = build_model(load_train("demo-3p"))
    f_mesh = base.excitation.frequency[0]

    def line(amplitude_um):
        pairs = [(r"^damping = \{ ratio = 0.05 \}",
                  f"damping = {{ ratio = 0.05 }}\nste = [{{ harmonic = 1, amplitude_um = {amplitude_um} }}]")]
        model = build_model(edited("demo-3p", pairs))
        r = simulate(model, RunSettings(0.06, settle=0.03))
        x = r["stage1.planet1.sun.force"][r.steady]
        t = r.t[r.steady]
        w = np.hanning(x.size)
        return 2 * np.sum(w * (x - x.mean()) * np.exp(-2j * np.pi * f_mesh * t)) / np.sum(w)

    none, one, two = line(0.0), line(2.0), line(4.0)
    assert abs(two - none) == pytest.approx(2 * abs(one - none), rel=0.03)
    assert abs(one - none) > 0.05 * abs(none)


def test_load_ramp_settles_to_the_state_reached_from_the_static_start():
    ramped = build_model(edited("demo-3p", [(r"^input_shaft_damping = .*",
                                             "input_shaft_damping = 2.0\nramp_s = 0.01")]))
    static = build_model(load_train("demo-3p"))
    a, b = simulate(ramped, RunSettings(0.08)), simulate(static, RunSettings(0.08))
    fa, fb, name = a.select("mesh_force"), b.select("mesh_force"), "stage1.planet1.sun.force"
    assert fa[0, 0] < 0.05 * fb[0, 0]  # the ramped run starts unloaded
    tail = a.t > 0.07
    np.testing.assert_allclose(fa[tail], fb[tail], rtol=0, atol=2e-3 * b.static[name])


def test_torque_profile_from_a_csv_file(tmp_path):
    """A periodic torque profile (time, torque) next to the train file adds to the input torque."""
    from gearcheck.train.variants import edited_text

    (tmp_path / "pulse.csv").write_text("time_s,torque_nm\n0.0,0.0\n0.005,40.0\n0.01,0.0\n")
    path = tmp_path / "pulsed.toml"
    path.write_text(edited_text("demo-3p", [(r"^input_shaft_damping = .*",
                                             'input_shaft_damping = 2.0\ntorque_csv = "pulse.csv"')]))
    exc = build_model(load_train(path)).excitation
    t_in, _ = exc.torques(np.array([0.0025, 0.005, 0.0125, 0.02]))
    np.testing.assert_allclose(t_in, [20.0, 40.0, 20.0, 0.0])
    bad = tmp_path / "bad.toml"
    bad.write_text(edited_text("demo-3p", [(r"^input_shaft_damping = .*", 'torque_csv = "missing.csv"')]))
    with pytest.raises(GearcheckError, match="operating.torque_csv: .*missing.csv: no such torque profile"):
        load_train(bad)


def test_transmission_error_harmonics_in_closed_form_and_along_a_run_up():
    """The compiled sums of the transmission error's harmonics (ISO's e = sum_h A_h cos(2 pi h xi + phi_h), xi the
    mesh cycles elapsed) against the closed form on a steady train, and along a run-up, where xi is no longer f t,
    de/dt against the derivative of e itself (the clock's rate in the chain rule)."""
    spec = edited("demo-3p", EXCITED[:1], "transmission error")
    exc = build_model(spec).excitation
    t = np.linspace(0.0, 0.01, 4001)
    e, de = exc.transmission_error(t)
    for j in range(len(spec.meshes)):
        xi = exc.frequency[j] * t - exc.phase[j]
        arg1, arg2 = 2 * np.pi * xi, 4 * np.pi * xi + np.radians(30.0)
        np.testing.assert_allclose(e[:, j], 4e-6 * np.cos(arg1) + 1e-6 * np.cos(arg2), rtol=0, atol=1e-18)
        rate = -2 * np.pi * exc.frequency[j] * (4e-6 * np.sin(arg1) + 2e-6 * np.sin(arg2))
        np.testing.assert_allclose(de[:, j], rate, rtol=0, atol=1e-12 * np.abs(rate).max())
    ramped = build_model(with_profiles(spec, "0:300,0.02:3000")).excitation
    t = np.linspace(0.001, 0.019, 36001)
    e, de = ramped.transmission_error(t)
    slope = np.gradient(e, t, axis=0)[1:-1]
    np.testing.assert_allclose(de[1:-1], slope, rtol=0, atol=1e-5 * np.abs(de).max())
    assert np.abs(de[-1]).max() > 5 * np.abs(de[0]).max()  # the rate grows with the speed


def test_installation_errors_turn_with_their_mounts():
    """An installation error is a centre offset fixed to the gear's mount (Mo et al. 2024's "安装误差"): a sun's
    is fixed in the housing, so the carrier frame sees it turn backwards at the carrier speed, and each sun
    mesh sees e cos(-w_c t + phase) along its line of action; a planet's is fixed in the carrier, a constant
    transmission error of that planet's meshes.  Both solvers agree on the response."""
    pairs = [(r"^teeth = 22", "teeth = 22\ninstallation_error_um = 10.0\ninstallation_error_phase_deg = 30.0"),
             (r"^teeth = 20", "teeth = 20\ninstallation_error_um = 4.0")]
    spec = edited("demo-3p", pairs, "installation errors")
    model = build_model(spec)
    w_c = model.kin.speeds["stage1.carrier"]
    t = np.linspace(0.0, 2 * np.pi / w_c, 2001)
    e, de = model.excitation.transmission_error(t)
    for j, mesh in enumerate(spec.meshes):
        planet = spec.members[mesh.planet]
        d = line_of_action(mesh, planet.angle, spec.stages[0].carrier_radius, model.kin.flanks[mesh.id]).direction
        planet_part = -4e-6 * np.array([np.cos(planet.angle), np.sin(planet.angle)]) @ d
        expected = np.full_like(t, planet_part)
        if not mesh.internal:
            beta = -w_c * t + np.radians(30.0)
            expected += 10e-6 * (np.cos(beta) * d[0] + np.sin(beta) * d[1])
        np.testing.assert_allclose(e[:, j], expected, atol=1e-18)
        np.testing.assert_allclose(de[:, j], np.gradient(expected, t), atol=2e-3 * 10e-6 * w_c)
    result = crosscheck(spec, duration=0.05)
    assert result.passed, result.failures
