"""Tilting members (issue 30) in the MuJoCo twin: bodies that tilt on hinges about their translation axes, bearing
stations as tendons from MuJoCo's Jacobians, meshes at their centres of stiffness with a tilting tendon.

Checked in closed form, each on MuJoCo's own linearisation of a train file:

* a sun held by two bearing stations (p_i, k_i) alone: its (x, tilt_y) block is
  [[k1 + k2, k1 p1 + k2 p2], [k1 p1 + k2 p2, k1 p1^2 + k2 p2^2]] with mass diag(m, I_d), whose two frequencies
  (twice: the (y, tilt_x) block is the same) are among the twin's;
* a spinning sun on a tilting stiffness k_t alone splits its tilting pair by its gyroscopic moments: about fixed
  axes I_d lambda^2 - J w lambda - k_t = 0 (forward and backward whirl, Euler's equations to first order), seen in
  its carrier's axes at lambda - Omega_c;
* a stage that does not tilt keeps its MJCF to the byte, whatever tilting keys its file holds;
* the world-frame coefficients of the meshes' tendons and tilting tendons turn with the carrier as a fresh
  ``mj_jac`` at the turned carrier gives them; the bearing stations' forces and the meshes' tilting moments read
  from MuJoCo's generalized forces are those of its own tendons; the compiled and the Python step loops agree.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

import gearcheck
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.elements.mesh import mesh_jacobian_row, mesh_tilt_row
from gearcheck.mbd_models.forces import ForceReader
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.static_state import DampingCorrection, static_state
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.errors import TrainNote
from gearcheck.shared.modal import generalized_modes
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_text, preset_text

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "helical-tilting.toml"
TENDON = mujoco.mjtObj.mjOBJ_TENDON


def _edited(text: str, pairs, label: str):
    for old, new in pairs:
        assert re.search(old, text, flags=re.M), old
        text = re.sub(old, new, text, flags=re.M)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TrainNote)
        return load_text(text, label)


def _example(*pairs):
    return _edited(EXAMPLE.read_text(encoding="utf-8"), pairs, "helical-tilting (edited)")


def _tilting_demo(sun_support: str):
    """demo-3p (spur, faces centred: no mesh row sees a tilt) tilting, every member held axially and by a tilting
    stiffness but the sun, held by ``sun_support``'s extra keys."""
    held = (r"^(support|bearing) = \{ (radial_stiffness = 1.0e9|radial_stiffness = 2.0e8)(.*) \}$",
            r"\1 = { \2\3, axial_stiffness = 5.0e8, tilting_stiffness = 2.0e6 }")
    sun = (r"^support = \{ radial_stiffness = 1.0e8, radial_damping = 500.0 \}$",
           f"support = {{ radial_stiffness = 1.0e8, radial_damping = 500.0, axial_stiffness = 5.0e8, {sun_support} }}\n"
           "tilting_inertia = 4.0e-4")
    return _edited(preset_text("demo-3p"), [(r"^planets = 3", "planets = 3\ntilting = true"), held, sun], "demo")


def _without_tilting_tendons(mb) -> None:
    """The meshes' tilting tendons without stiffness (what couples the members' tilts across the meshes)."""
    mb.model.tendon_stiffness[mb.tilt_tendon] = 0.0


def _dof(mb, joint: str) -> int:
    return int(mb.model.jnt_dofadr[mujoco.mj_name2id(mb.model, mujoco.mjtObj.mjOBJ_JOINT, joint)])


def test_a_sun_on_two_stations_is_the_closed_form():
    """The example's sun is overhung on its shaft's two bearings at -30 and -60 mm sharing 5e7 N/m; with the meshes
    and their tilting tendons off, its translation and tilt are held by the stations alone."""
    spec = _example()
    sun = spec.members["stage1.sun"]
    mb = compile_train(spec)
    _without_tilting_tendons(mb)
    K = linearise.stiffness_matrix(mb, np.zeros(len(spec.meshes)))
    M = linearise.mass_matrix(mb)
    p = np.array([s.position for s in sun.support.stations])
    k = np.array([s.radial_stiffness for s in sun.support.stations])
    block = np.array([[k.sum(), k @ p], [k @ p, k @ p**2]])
    x, ry, y, rx = (_dof(mb, f"stage1_sun_{j}") for j in ("x", "ry", "y", "rx"))
    np.testing.assert_allclose(K[np.ix_([x, ry], [x, ry])], block, rtol=1e-9)  # x + p tilt_y
    np.testing.assert_allclose(K[np.ix_([y, rx], [y, rx])], block * [[1, -1], [-1, 1]], rtol=1e-9)  # y - p tilt_x
    assert M[x, x] == sun.mass and M[ry, ry] == sun.tilting_inertia and M[x, ry] == 0.0
    mass = np.diag([sun.mass, sun.tilting_inertia])
    expected = np.sqrt(np.linalg.eigvals(np.linalg.solve(mass, block)).real) / (2 * math.pi)
    frequencies = generalized_modes(K, M)[0]
    for f in expected:
        near = np.sort(np.abs(frequencies - f) / f)[:2]  # (x, tilt_y) and (y, tilt_x)
        assert near.max() < 1e-9, (f, near)
    assert expected.min() < 0.2 * expected.max()  # the stations couple them: neither frequency is the uncoupled one


def test_a_spinning_sun_splits_its_tilting_pair_by_its_gyroscopic_moments():
    """demo-3p's sun on a tilting stiffness k_t, at three times its speed: forward and backward whirl."""
    k_t = 2.0e4
    spec = _tilting_demo(f"tilting_stiffness = {k_t!r}")
    sun = spec.members["stage1.sun"]
    mb = compile_train(spec)
    _without_tilting_tendons(mb)
    scale = 3.0
    result = linearise.modes_at_speed(mb, scale * spec.operating.input_speed)
    spin, omega_c = (scale * mb.kin.speeds[f"stage1.{m}"] for m in ("sun", "carrier"))
    # I_d lambda^2 - J w lambda - k_t = 0: lambda > 0 the forward whirl, lambda < 0 the backward one
    roots = np.roots([sun.tilting_inertia, -sun.inertia * spin, -k_t])
    expected = np.abs(roots - omega_c) / (2 * math.pi)
    split = abs(expected[0] - expected[1]) / expected.mean()
    assert split > 0.05  # the gyroscopic moments matter here
    for f in expected:
        assert np.min(np.abs(result.frequencies - f) / f) < 1e-6, f
    assert np.all(result.growth == 0.0)


def test_a_stage_that_does_not_tilt_keeps_its_mjcf_to_the_byte():
    """helical-planetary with every tilting key (stations, tilting stiffness and inertia, axial offsets) and the
    flag off is written as ``xml/helical-planetary.xml`` (but the header's path to the file)."""
    stations = "stations = [{ position_mm = -30.0, share = 0.5 }, { position_mm = -60.0, share = 0.5 }]"
    pairs = [(r"^helix_angle_deg = 12.0$", "helix_angle_deg = 12.0\ntilting = false"),
             (r"^(support = \{ radial_stiffness = 5.0e7.*) \}$", rf"\1, {stations}, tilting_stiffness = 1.0e6 }}"),
             (r"^(\[stages.sun\])", "\\1\ntilting_inertia = 4.0e-6\naxial_offset_mm = 1.0")]
    text = gearcheck.mjcf(_edited(preset_text("helical-planetary"), pairs, "tilting off"))
    expected = (ROOT / "xml" / "helical-planetary.xml").read_text(encoding="utf-8")
    assert text.split("-->", 1)[1] == expected.split("-->", 1)[1]


def test_turning_coefficients_are_mujocos_at_a_turned_carrier():
    """The runner turns the world-frame coefficients of the mesh tendons and of their tilting tendons (central
    members' slides and tilts, pair by pair) with the carrier: they equal a fresh mj_jac at a turned carrier."""
    spec = _example()
    mb = compile_train(spec)
    m = mb.model
    d = mujoco.MjData(m)
    d.qpos[mb.qadr["stage1.carrier"]["rz"]] = 0.7
    d.qpos[mb.qadr["stage1.sun"]["rz"]] = 2.1  # a gear's own angle does not change its coefficients
    mujoco.mj_forward(m, d)
    mb.refresh(d.qpos)
    tilted = set(m.wrap_objid[mb.turning.wraps])
    assert {mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"stage1_{c}_r{a}") for c in ("sun", "ring", "carrier")
            for a in "xy"} <= tilted
    for mesh, t, u in zip(spec.meshes, mb.mesh_tendon, mb.tilt_tendon):
        for tendon, row in ((t, mesh_jacobian_row(spec, mb.kin, m, d, mesh)),
                            (u, mesh_tilt_row(spec, mb.kin, m, d, mesh))):
            adr, n = m.tendon_adr[tendon], m.tendon_num[tendon]
            dofs = m.jnt_dofadr[m.wrap_objid[adr:adr + n]]
            np.testing.assert_allclose(m.wrap_prm[adr:adr + n], row[dofs], rtol=0, atol=1e-12)
            assert np.count_nonzero(np.abs(row) > 1e-15) <= n  # no joint outside the tendon moves it


def test_station_forces_and_tilting_moments_are_mujocos_own():
    """At a random state the force reader's bearing stations' forces are MuJoCo's own tendons' k L + c L', and the
    meshes' tilting moments k_t L + c_t L' of their tilting tendons, L' with their coefficients' turning."""
    spec = _example()
    mb = compile_train(spec)
    m = mb.model
    d = mujoco.MjData(m)
    rng = np.random.default_rng(3)
    d.qpos[:] = m.qpos0 + 1e-5 * rng.standard_normal(m.nq)
    d.qvel[:] = 1e-2 * rng.standard_normal(m.nv)
    mb.refresh(d.qpos)
    correction = DampingCorrection(mb, d)  # what the runner applies: the damping on the true rate
    correction.apply(None)
    reader = ForceReader(mb, d, correction)
    mujoco.mj_forward(m, d)
    sample = np.empty((1, reader.width))
    reader.sample(sample[0])
    _, moments, bearings = (f[0] for f in reader.forces(sample))
    mujoco.mj_forward(m, d)  # the reader left a probe's passive forces in the data
    names = [n for n in gearcheck.shared.results.bearing_names(spec)]
    for name, force in zip(names, bearings):
        member, row = name.split(".bearing_")
        axis, station = row.split(".station")
        t = mujoco.mj_name2id(m, TENDON, f"{spec.members[member].label}_station{station}_{axis}")
        law = m.tendon_stiffness[t] * d.ten_length[t] + m.tendon_damping[t] * d.ten_velocity[t]
        assert force == pytest.approx(law, rel=1e-9, abs=1e-9 * abs(law) + 1e-12)
    tc = mb.turning
    missing = tc.missing_rate(d.qpos[tc.carrier_qadr], d.qvel[tc.carrier_qadr], d.qpos[tc.joint_qadr], m.ntendon)
    for moment, t in zip(moments, mb.tilt_tendon):
        law = m.tendon_stiffness[t] * d.ten_length[t] + m.tendon_damping[t] * (d.ten_velocity[t] + missing[t])
        assert moment == pytest.approx(law, rel=1e-8)


def test_a_tilting_run_is_the_same_in_both_step_loops():
    spec = _example()
    mb = compile_train(spec)
    a = simulate_mujoco(mb, RunSettings(0.002), engine="python")
    b = simulate_mujoco(mb, RunSettings(0.002), engine="compiled")
    assert b.info["engine"] == "compiled"
    for name in a.names():
        scale = np.max(np.abs(a[name]))
        np.testing.assert_allclose(b[name], a[name], rtol=0, atol=1e-9 * scale + 1e-300, err_msg=name)
    tilts = [n for n in a.names() if ".tilt_" in n]
    assert tilts and max(np.max(np.abs(a[n])) for n in tilts) > 1e-5  # the helix tilts the planets


@pytest.mark.parametrize("held", [(r"^bearing = \{ radial_stiffness = 1.0e8, (.*) \}$",
                                   r"bearing = { radial_stiffness = 1.0e8, \1, tilting_stiffness = 1.0e11 }"),
                                  (r"^bearing = \{ radial_stiffness = 1.0e8, ",
                                   "bearing = { radial_stiffness = 1.0e15, ")], ids=["tilting stiffness", "stations"])
def test_a_planet_on_a_stiff_misaligned_pin_rests_at_its_tilt(held):
    """pin_tilts_urad: a planet held stiffly on its pin (a tilting stiffness relaxed at the pin's tilt, or stations
    whose tendons rest where the tilted pin's points are, p (gamma_t, -gamma_r)) sits in the static state at the
    pin's tilt, the loads and the meshes' tilting stiffness moving it by less than 1e-5 of it."""
    gamma = np.array([[40.0, -25.0], [0.0, 10.0], [-30.0, 0.0]]) * 1e-6
    pins = (r"^(\[stages.planet\])", "\\1\npin_tilts_urad = [[40.0, -25.0], [0.0, 10.0], [-30.0, 0.0]]")
    mb = compile_train(_example(pins, held))
    q = static_state(mb).qpos
    for j, planet in enumerate(("planet1", "planet2", "planet3")):
        tilt = [q[mb.model.jnt_qposadr[mujoco.mj_name2id(mb.model, mujoco.mjtObj.mjOBJ_JOINT, f"stage1_{planet}_{a}")]]
                for a in ("rradial", "rtangential")]
        np.testing.assert_allclose(tilt, gamma[j], rtol=0, atol=1e-5 * np.abs(gamma).max())
