"""The MuJoCo twin of an RV reducer (Yang, Chen & Wang 2018) against the reference lumped model.

The twin is an independent derivation: crankshafts on the carrier, discs as free bodies in polar joints,
needle bearings as MuJoCo's own spring-dampers between two sites, pin contacts as compression-only tendons
whose coefficients MuJoCo's Jacobians give at the discs' poses every step.  So its natural frequencies
agreeing with the lumped model's, its rigid mechanism turning without strain at the ratio of the description's
kinematics, and its static state meeting the lumped one as the load goes to zero are evidence both are right.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import modes
from gearcheck.lumped.static import static_solution
from gearcheck.train.variants import edited
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.static_state import nominal_speeds, static_state
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings

RELATIVE_TOLERANCE = 1e-6
ROUND_OFF = 1e-14  # m: a deflection this small is rounding (positions of 0.1 m, joint angles of tens of rad)
PIN_WHEEL = [(r'^(input = "rv.sun")$', r'\1' + '\nheld = ["rv.pin_wheel"]'),
             (r"^\[stages.cycloid\]$", "[stages.pin_wheel]\nmass = 8.0\ninertia = 0.25\nsupport = { radial_stiffness = "
                                       "2.0e9, radial_damping = 27200.0, torsional_stiffness = 4.0e7, torsional_damping"
                                       " = 544.0 }\n\n[stages.cycloid]")]


def clearance(um: float):
    return [(r"^contact = \{ (.*?)(, clearance_um = [-+.e0-9]+)? \}$", rf"contact = {{ \1, clearance_um = {um!r} }}")]


VARIANTS = {"preset": [], "pin wheel on a support": PIN_WHEEL, "clearance 0": clearance(0.0),
            "clearance 3 um": clearance(3.0)}


def variant(name: str):
    return edited("rv-reducer", VARIANTS[name], name) if VARIANTS[name] else load_train("rv-reducer")


@pytest.fixture(scope="module")
def twin():
    return compile_train(load_train("rv-reducer"))


@pytest.mark.parametrize("name", list(VARIANTS))
def test_frequencies_match_lumped(name):
    """Linearised at t = 0 with the pins of its own static equilibrium touching, the twin has the lumped model's
    natural frequencies, mode types and contact set."""
    spec = variant(name)
    lumped = build_model(spec)
    mb = compile_train(spec)
    assert [n for n, on in zip(mb.moving_contacts[0].names, mb.moving_contacts[0].contacts) if on] == [
        r.name for r in lumped.rows if r.kind == "contact"]
    a, b = modes(lumped), linearise.modes(mb)
    assert len(a) == len(b) and a.types == b.types and a.multiplicity == b.multiplicity
    rel = np.abs(b.frequencies - a.frequencies) / a.frequencies
    print(f"{name}: max relative frequency difference {rel.max():.2e}; first ten (Hz) "
          f"{np.round(b.frequencies[:10], 6)}")
    assert rel.max() < RELATIVE_TOLERANCE


def test_the_rigid_mechanism_turns_without_strain(twin):
    """On the rigid mechanism's nominal motion (the description's speeds), over three eccentric turns, every needle
    bearing's deflection and every pin's compression is rounding, and so is every pin tendon's length held over
    the step that follows (the RK4 stages see no strain either)."""
    m, d, cyc = twin.model, mujoco.MjData(twin.model), twin.moving_contacts[0]
    speeds, h = nominal_speeds(twin), twin.default_step
    turn = 2 * np.pi / abs(twin.kin.speeds["rv.crank1"] - twin.kin.speeds["rv.carrier"])
    worst = 0.0
    for t in np.linspace(0.0, 3 * turn, 601):
        d.qpos[:] = speeds * t
        worst = max(worst, np.abs(cyc.refresh(d)).max())
        for stage in (0.0, 0.5 * h, h):
            d.qpos[:] = speeds * (t + stage)
            mujoco.mj_fwdPosition(m, d)
            mujoco.mj_fwdActuation(m, d)
            worst = max(worst, np.abs(d.ten_length[cyc.tendons] - m.tendon_lengthspring[cyc.tendons, 1]).max(),
                        np.abs(d.actuator_length[cyc.needles]).max())
    print(f"largest needle deflection or pin compression over three eccentric turns: {worst:.2e} m")
    assert worst < ROUND_OFF


def test_the_ratio_is_mujocos_own(twin):
    """The one motion that strains no spring of the twin (every pin touching, the input shaft let go) is the
    description's nominal motion: sun to carrier 185."""
    K = linearise.stiffness_matrix(twin, every_pin=True)
    sun, carrier = twin.dadr["rv.sun"]["rz"], twin.dadr["rv.carrier"]["rz"]
    K[sun, sun] -= twin.spec.operating.input_shaft_stiffness
    w, v = np.linalg.eigh(K)
    assert abs(w[0]) < 1e-12 * w[-1] < w[1] * 1e-3  # one mechanism
    assert v[sun, 0] / v[carrier, 0] == pytest.approx(185.0, rel=1e-8)
    nominal = nominal_speeds(twin) / np.linalg.norm(nominal_speeds(twin))
    assert abs(v[:, 0] @ nominal) == pytest.approx(1.0, abs=1e-12)


def test_no_load_run_deflects_only_under_the_orbit_loads():
    """Driven at its nominal speeds without load or stiffness variation, the twin's needle bearings and pins carry
    the discs' centrifugal loads of their orbits (m e w_H^2, about 3 N a disc) and nothing that grows."""
    spec = edited("rv-reducer", [(r"^output_torque = .*$", "output_torque = 0.0"),
                                 (r'model = "rectangular"', 'model = "constant"')], "no load")
    mb = compile_train(spec)
    result = simulate_mujoco(mb, RunSettings(duration=0.01, output_dt=20 * mb.default_step))
    cyc = spec.cycloids[0]
    orbit = spec.members["rv.disc1"].mass * cyc.geometry.eccentricity * mb.kin.speeds["rv.crank1"] ** 2
    needles = np.column_stack([result[n] for n in result.names("bearing_force") if ".needle_" in n])
    pins = np.column_stack([result[n] for n in result.names("pin_force") if n.endswith(".force") and ".pin" in n])
    assert np.abs(needles).max() < orbit and pins.max() < orbit
    assert np.abs(needles).max() / cyc.needle.radial_stiffness < 1e-9  # m; the eccentricity is 2.2 mm


@pytest.mark.parametrize("scale", [1e-3, 1.0])
def test_static_state_meets_lumped_in_the_linear_limit(scale):
    """The twin's static state (its own equilibrium, its geometry at the deflected pose) and the lumped one (rows
    at the nominal pose) differ by second-order terms, in proportion to the load: at the rated torque 1.4 % of
    the largest pin force, 5 % of the crank bearings' small radial force (the carrier's windup against the discs,
    0.5 mrad, turns the 16 kN needle loads in the carrier's axes); at a thousandth of it, a thousandth of that.
    (Turning slowly: no orbit loads, no damping of the turning contact pattern.)"""
    spec = load_train("rv-reducer").with_operating(output_torque=3136.0 * scale, input_speed=0.01)
    lumped = static_solution(build_model(spec))
    mb = compile_train(spec)
    st = static_state(mb)
    rows = dict(zip(lumped.row_names, lumped.row_forces))
    pins = np.array([rows[n] for n in mb.moving_contacts[0].names if n in rows])
    names = mb.moving_contacts[0].names
    assert [n for n, on in zip(names, st.contacts) if on] == [n for n in names if n in rows]
    assert np.abs(st.pin_force[st.contacts] - pins).max() < 0.02 * scale * pins.max()
    np.testing.assert_allclose(st.mesh_force, lumped.mesh_force, rtol=1e-3 * scale)
    np.testing.assert_allclose(st.bearing_force[1::2], [rows[f"rv.crank{k}.bearing_tangential"] for k in (1, 2, 3)],
                               rtol=1e-5 * scale)
    np.testing.assert_allclose(st.bearing_force[::2], [rows[f"rv.crank{k}.bearing_radial"] for k in (1, 2, 3)],
                               rtol=0.06 * scale)


def test_run_reports_pin_and_needle_forces(twin):
    """A run names every pin's force (the load distribution), each disc's largest one and its loaded pins, and the
    needle bearings' forces; at the start they are the static state's."""
    result = simulate_mujoco(twin, RunSettings(duration=0.001))
    st = static_state(twin)
    assert result["rv.disc1.pin30.force"][0] == pytest.approx(st.pin_force[29], rel=1e-9)
    assert result["rv.disc1.pin_force_max"][0] == pytest.approx(st.pin_force[:40].max(), rel=1e-9)
    assert result["rv.disc2.pins_loaded"][0] == st.contacts[40:].sum()
    needle = np.hypot(result["rv.crank1.disc1.needle_x.force"], result["rv.crank1.disc1.needle_y.force"])
    assert 1e3 < needle[0] < 2e4  # N: its share of the crank's 16 kN


def test_mjcf_of_an_rv_reducer(twin):
    """Cranks ride on the carrier, discs are free bodies of the world, the pins (a fixed pin wheel) sites of the
    world; every needle bearing is a pair of site actuators and every pin a tendon."""
    m, spec = twin.model, twin.spec
    carrier = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "rv_carrier")
    for k in (1, 2, 3):
        assert m.body_parentid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"rv_crank{k}")] == carrier
    for j in (1, 2):
        assert m.body_parentid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"rv_disc{j}")] == 0
    assert m.nbody == 1 + len(spec.members)
    assert len(twin.moving_contacts[0].tendons) == 80 and twin.moving_contacts[0].needles.shape == (6, 2)
    assert all(m.site_bodyid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"rv_pin{i}")] == 0 for i in (1, 40))
    assert 'refsite="rv_disc2_bore3"' in twin.xml and 'springlength="' in twin.xml
