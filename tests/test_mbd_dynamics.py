"""The driven MuJoCo run: energy, centripetal load, dead band, agreement with the lumped solver, step checks."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.static import static_solution
from gearcheck.lumped.time_solver import simulate
from gearcheck.train.variants import edited
from gearcheck.mbd_models.runner import simulate_mujoco, static_state
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.contact_laws import deadzone
from gearcheck.shared.errors import DivergenceError, SolverError
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import RK4_LIMIT, STAGE_SIDES


def variant(pairs, name="variant"):
    return edited("demo-3p", pairs, name)


UNDAMPED = [(r"damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.0 }"),
            (r"radial_damping = [0-9.]+", "radial_damping = 0.0"),
            (r"torsional_damping = [0-9.]+", "torsional_damping = 0.0")]
CONSTANT = [(r'model = "rectangular"', 'model = "constant"')]
FREE_INPUT = [(r"^input_shaft_(stiffness|damping).*$", "")]


def nrms(a, b):
    """RMS of the difference over the RMS of the reference."""
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b**2)))


# ---------------------------------------------------------------------------------------------- statics


def test_static_state_matches_lumped_statics():
    """MuJoCo's own steady rotating equilibrium: the load shared equally and the lumped static force.

    They agree to 1e-12 at 1500 rpm.  With Lin & Parker's (1999) centripetal softening alone they
    differed by 3.4e-5, and with a geometric stiffness of the pins' preload added (the lumped model
    of an earlier version) still by 6.3e-6, which was blamed on the carrier's finite wind-up: it was
    the centripetal potential's carrier-rotation x bearing-deflection term (the lumped assembly's
    docstring), which MuJoCo, moving the planets with their carrier, has exactly.
    """
    spec = load_train("demo-3p")
    mb = compile_train(spec)
    st = static_state(mb)
    ref = static_solution(build_model(spec)).mesh_force
    assert np.all(st.mesh_deflection > 0)  # compressed under the nominal load
    np.testing.assert_allclose(st.mesh_force, ref, rtol=1e-10)
    slow = spec.with_operating(input_speed=1e-3)
    np.testing.assert_allclose(static_state(compile_train(slow)).mesh_force,
                               static_solution(build_model(slow)).mesh_force, rtol=1e-10)


# ---------------------------------------------------------------------------------------------- energy


def test_energy_conserved_free_spinning_undamped():
    """Constant stiffness, no damping, no input shaft, no load: nothing does work on the train.

    The train spins freely at its nominal speeds with a vibration added (0.01 m/s on every
    planet).  MuJoCo's own energy (mjENBL_ENERGY) may only fall, by RK4's numerical
    dissipation: per step a mode of frequency omega keeps 1 - (omega h)^6/72 of its energy,
    so over N steps the loss is at most E_vib (1 - (1 - (omega_max h)^6/72)^N) (6.8 % here);
    it must also fall as h^5 (halving the step divides it by about 32).  Energy may never rise
    above its start beyond rounding (1e-12 of the total).
    """
    spec = variant(UNDAMPED + CONSTANT + FREE_INPUT + [(r"^output_torque = .*$", "output_torque = 0.0")],
                   "energy-variant")
    mb = compile_train(spec)
    st = static_state(mb)
    qvel = st.qvel.copy()
    for mid, member in spec.members.items():
        if member.is_planet:
            dr, dt_ = mb.dadr[mid]["radial"], mb.dadr[mid]["tangential"]
            qvel[dr] += 0.01
            qvel[dt_] -= 0.01
    d = mujoco.MjData(mb.model)
    d.qpos[:] = st.qpos
    mujoco.mj_forward(mb.model, d)
    M = np.zeros((mb.model.nv, mb.model.nv))
    mujoco.mj_fullM(mb.model, d, M)
    dv = qvel - st.qvel
    e_vib = 0.5 * dv @ M @ dv
    omega_max = mb.omega_max
    h0 = mb.default_step
    losses = []
    for h in (h0, h0 / 2):
        res = simulate_mujoco(mb, RunSettings(0.02, h, 1e-5), initial_state=(st.qpos, qvel), record_energy=True)
        energy = res.raw["energy_kinetic"] + res.raw["energy_potential"]
        n = res.info["steps"]
        bound = e_vib * (1 - (1 - (omega_max * h) ** 6 / 72) ** n)
        loss = energy[0] - energy[-1]
        assert np.max(energy - energy[0]) <= 1e-12 * energy[0], "energy rose: a force does work it should not"
        assert 0 <= loss <= bound
        losses.append(loss)
        print(f"h = {h:.4g} s: energy loss {loss / e_vib:.3e} of the vibration energy, RK4 bound {bound / e_vib:.3e}")
    assert 16 < losses[0] / losses[1] < 64, f"loss ratio {losses[0] / losses[1]:.3g} is not RK4's h^5"


# ---------------------------------------------------------------------------------------------- centripetal


def test_planet_bearings_carry_the_centripetal_load():
    """Steady rotation: the planets' radial bearing force is m_p r_c Omega_c^2 (the radial mesh
    components of sun and ring cancel).  Constant mesh stiffness, so the steady state is steady;
    measured from the radial slide joints' passive force at two speeds."""
    base = variant(CONSTANT, "centripetal")
    for factor in (1.0, 2.0):
        spec = base.with_operating(input_speed=base.operating.input_speed * factor)
        mb = compile_train(spec)
        res = simulate_mujoco(mb, RunSettings(0.01, output_dt=1e-5))
        w = res.steady
        for pid in spec.stages[0].planets:
            p = spec.members[pid]
            expected = p.mass * p.radius * mb.kin.speeds["stage1.carrier"] ** 2
            force = res[f"{pid}.bearing_radial.force"][w]
            assert np.mean(force) == pytest.approx(expected, rel=2e-3)
            assert np.ptp(force) < 1e-3 * expected  # steady, and the carrier did turn
        turned = res.raw["stage1_carrier_angle"][-1] - res.raw["stage1_carrier_angle"][0]
        assert turned == pytest.approx(mb.kin.speeds["stage1.carrier"] * res.t[-1], rel=1e-3)
        print(f"speed x{factor:g}: radial bearing force {np.mean(force):.4f} N, m r Omega^2 = {expected:.4f} N")


# ---------------------------------------------------------------------------------------------- dead band


def test_backlash_dead_band_in_mujoco_tendon():
    """MuJoCo's own spring force of a backlash mesh tendon is zero inside |delta| < b and
    k(|delta| - b) beyond, read from qfrc_spring with and without that tendon's stiffness."""
    spec = variant([(r"^\[stages.mesh\]$", "[stages.mesh]\nbacklash_um = 40.0")], "backlash")
    mb = compile_train(spec)
    m = mb.model
    d = mujoco.MjData(m)
    t = int(mb.mesh_tendon[0])
    b = spec.meshes[0].backlash / 2
    assert b == pytest.approx(20e-6)
    row = np.zeros(m.nv)
    for w in range(m.tendon_adr[t], m.tendon_adr[t] + m.tendon_num[t]):
        row[m.jnt_dofadr[m.wrap_objid[w]]] = m.wrap_prm[w]
    k = m.tendon_stiffness[t]
    for delta in np.linspace(-2.5 * b, 2.5 * b, 11):
        d.qpos[:] = row * delta / (row @ row)
        forces = []
        for stiffness in (k, 0.0):
            m.tendon_stiffness[t] = stiffness
            mujoco.mj_forward(m, d)
            forces.append(d.qfrc_spring.copy())
        m.tendon_stiffness[t] = k
        assert d.ten_length[t] == pytest.approx(delta, abs=1e-15)
        tendon_force = -(forces[0] - forces[1]) @ row / (row @ row)  # generalized force = -J' F
        expected = k * (delta - b) if delta > b else k * (delta + b) if delta < -b else 0.0
        assert tendon_force == pytest.approx(expected, abs=1e-6 * k * b)


def test_backlash_mesh_separates_and_carries_no_force():
    """Light load, rectangular stiffness, 40 um backlash, no mesh damping: the teeth separate in
    the run; while |delta| < b the mesh force is zero, outside it is k(t)(|delta| - b)."""
    spec = variant([(r"^\[stages.mesh\]$", "[stages.mesh]\nbacklash_um = 40.0"),
                    (r"damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.0 }"),
                    (r"^output_torque = .*$", "output_torque = 20.0")], "backlash-light")
    res = simulate_mujoco(compile_train(spec), RunSettings(0.02))
    b = spec.meshes[0].backlash / 2
    deflection, force, stiffness = (res.select(kind) for kind in ("dte", "mesh_force", "mesh_stiffness"))
    inside = np.abs(deflection) < b
    assert inside.any(), "no separation happened: the test needs a lighter load"
    scale = np.max(np.abs(force))
    np.testing.assert_allclose(force[inside], 0.0, atol=1e-12 * scale)  # read from MuJoCo's own forces
    outside = ~inside
    np.testing.assert_allclose(np.abs(force[outside]), stiffness[outside] * (np.abs(deflection[outside]) - b),
                               rtol=1e-9, atol=1e-12 * scale)
    print(f"fraction of samples with a mesh in its dead band: {inside.mean():.3f}")


# ---------------------------------------------------------------------------------------------- lumped


def test_time_response_matches_lumped():
    """demo-3p at its operating point: steady mesh forces and the ring's world-frame accelerations of
    MuJoCo and the lumped RK4 solver within 1 % normalised RMS (the default tolerance), and in fact within
    1e-3, at the default step.

    Measured (0.05 s, steady window from 0.025 s), default step -> half step: mesh force 2.9e-5 ->
    1.8e-5, ring world axes 1.70e-4 -> 1.70e-4, ring carrier axes 1.63e-4 -> 1.31e-4.  Both solvers
    drive their steps alike and the input servo is exact, so what is left is not the step but the models: MuJoCo
    turns the real geometry by the carrier's finite wind-up and refreshes its mesh coefficients every step, the
    linear model does neither (second order).  Before the integrated-velocity servo the differences were 5.2e-4
    and 1.7e-3 and halved with the step.
    """
    spec = load_train("demo-3p")
    model = build_model(spec)
    mb = compile_train(spec)
    h0 = mb.default_step
    table = []
    for h in (h0, h0 / 2):
        settings = RunSettings(0.05, h, settle=0.025)
        mj = simulate_mujoco(mb, settings)
        lp = simulate(model, settings)
        assert np.array_equal(mj.t, lp.t)
        w = mj.steady
        force = max(nrms(mj[n][w], lp[n][w]) for n in mj.names("mesh_force"))
        world = max(nrms(mj[n][w], lp[n][w]) for n in ("stage1.ring.ax.world", "stage1.ring.ay.world",
                                                       "stage1.ring.alpha"))
        carrier = max(nrms(mj[n][w], lp[n][w]) for n in ("stage1.ring.ax.carrier", "stage1.ring.ay.carrier"))
        table.append((h, force, world, carrier))
        assert force < 1e-3 and world < 1e-3 and carrier < 1e-3
    print("\n      dt [s]   mesh force   ring world   ring carrier axes  (normalised RMS difference)")
    for h, force, world, carrier in table:
        print(f"  {h:.4e}   {force:.3e}    {world:.3e}    {carrier:.3e}")
    # the step no longer dominates: halving it changes nothing by more than 10 % upwards
    for col in (1, 2, 3):
        assert table[1][col] < 1.1 * table[0][col]


# ---------------------------------------------------------------------------------------------- steps


def test_unstable_step_refused():
    spec = load_train("demo-3p")
    mb = compile_train(spec)
    omega_max = mb.omega_max
    with pytest.raises(SolverError, match=r"unstable.*use dt <="):
        simulate_mujoco(mb, RunSettings(0.001, 1.05 * RK4_LIMIT / omega_max))
    with pytest.raises(SolverError, match="dt must be a positive number"):
        RunSettings(0.001, -1.0)
    # the default is well inside the limit: at least 20 points per period of the highest mode,
    # rounded down to a whole fraction of the mesh period (at most one step more per cycle)
    h = mb.default_step
    period = 1.0 / mb.excitation.frequency.min()
    assert period / h == pytest.approx(round(period / h), abs=1e-6)
    assert 2 * math.pi / 20 * (1 - h / period) <= h * omega_max <= 2 * math.pi / 20


def test_result_signals_and_frames():
    """The same signals as the lumped solver; a planet's world-frame acceleration is MuJoCo's own
    framelinacc sensor, its carrier-frame one that vector turned by the carrier angle + psi."""
    spec = load_train("demo-4p")
    res = simulate_mujoco(compile_train(spec), RunSettings(0.002, output_dt=1e-4))
    assert res.solver == "mujoco"
    assert res.names() == simulate(build_model(spec), RunSettings(0.002, output_dt=1e-4)).names()
    np.testing.assert_allclose(res["stage1.planet2.ax.world"], res.raw["stage1_planet2_linacc_x"], rtol=1e-12,
                               atol=1e-9)
    phi = res.raw["stage1_carrier_angle"] + math.pi / 2  # planet 2 of 4 sits at 90 deg
    ax, ay = res["stage1.planet2.ax.carrier"], res["stage1.planet2.ay.carrier"]
    np.testing.assert_allclose(np.cos(phi) * ax - np.sin(phi) * ay, res["stage1.planet2.ax.world"], rtol=1e-12,
                               atol=1e-9)
    assert np.all(np.isfinite(res.to_dataframe().to_numpy()))


def test_mesh_forces_are_mujocos_own():
    """The runner reports the mesh forces MuJoCo applied, read from its generalized forces (a force law
    restated on the MuJoCo side would hide a sign error of that law).  They equal the
    mesh law applied to MuJoCo's own tendon lengths and true deflection rates (the tendon velocity
    plus the turning coefficients' part) to round-off, with backlash, transmission error and damping
    all acting; and each planet's bearing force is its slides' spring-damper force."""
    spec = variant([(r"^\[stages.mesh\]$", "[stages.mesh]\nbacklash_um = 40.0"),
                    (r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\n"
                                                      "ste = [{ harmonic = 1, amplitude_um = 5.0 }]"),
                    (r"^output_torque = .*$", "output_torque = 60.0")], "forces")
    mb = compile_train(spec)
    res = simulate_mujoco(mb, RunSettings(0.01))
    raw, tc = res.raw, mb.turning
    deflection = np.column_stack([raw[f"{m.label}_deflection"] for m in spec.meshes])
    carrier = spec.members[spec.stages[0].carrier].label
    slides = {mb.qadr[mid][axis]: f"{spec.members[mid].label}_{axis}_pos" for mid, m in spec.members.items()
              if not m.is_planet for axis in "xy"}
    slide = np.column_stack([raw[slides[q]] for q in tc.joint_qadr])
    phi = np.repeat(raw[f"{carrier}_angle"][:, None], len(tc.wraps), axis=1)
    phidot = np.repeat(raw[f"{carrier}_angle_rate"][:, None], len(tc.wraps), axis=1)
    rate = np.column_stack([raw[f"{m.label}_rate"] for m in spec.meshes])
    rate = rate + tc.missing_rate(phi, phidot, slide, len(spec.meshes))
    e, de = mb.excitation.transmission_error(res.t)
    law = (mb.excitation.stiffness(res.t, STAGE_SIDES[0]) * deadzone(deflection - e, mb.half_backlash)
           + mb.mesh_damping * (rate - de))
    force = res.select("mesh_force")
    assert np.any(np.abs(deflection - e) < mb.half_backlash), "no tooth separated: the load is too high"
    np.testing.assert_allclose(force, law, rtol=0, atol=1e-9 * np.max(np.abs(law)))
    for mid, member in spec.members.items():
        if member.is_planet:
            b = member.bearing
            for axis in ("radial", "tangential"):
                expected = (b.radial_stiffness * raw[f"{member.label}_{axis}_pos"]
                            + b.radial_damping * raw[f"{member.label}_{axis}_vel"])
                np.testing.assert_allclose(res[f"{mid}.bearing_{axis}.force"], expected, rtol=0,
                                           atol=1e-9 * np.max(np.abs(expected)))


def test_divergence_is_reported():
    spec = load_train("demo-3p")
    mb = compile_train(spec)
    st = static_state(mb)
    qpos = st.qpos.copy()
    qpos[mb.dadr["stage1.planet1"]["radial"]] = np.nan
    with pytest.raises(DivergenceError, match="diverged at t ="):
        simulate_mujoco(mb, RunSettings(0.001), initial_state=(qpos, st.qvel))


def test_parametric_resonance_diverges_in_both_solvers_at_the_same_instant():
    """Undamped demo-3p at 3700 rpm: the rectangular mesh stiffness (+-36 % about its mean) pumps the
    first rotational mode (513 Hz) at its principal parametric resonance, f_mesh = 1001 Hz ~ 2 f_1
    (Lin & Parker 2002's instability of the Mathieu type).  The response grows exponentially: both
    solvers must stop with a DivergenceError at the first sample past a thousand times the static
    deflection, the same sample in both; with the preset's 5 % mesh damping the same run stays bounded."""
    spec = variant(UNDAMPED + [(r"^input_shaft_damping = .*", "input_shaft_damping = 0.0")], "undamped")
    settings = RunSettings(0.1, output_dt=1e-4)
    times = []
    for run in (lambda s: simulate(build_model(s), settings), lambda s: simulate_mujoco(compile_train(s), settings)):
        with pytest.raises(DivergenceError, match="over 1000 times its static scale") as caught:
            run(load_train(spec, 3700.0))
        times.append(caught.value.time)
    assert times[0] == times[1] and 0.01 < times[0] < 0.1
    damped = simulate(build_model(load_train("demo-3p", 3700.0)), settings)
    kv = damped.select("dynamic_factor")
    assert np.all(np.isfinite(kv)) and np.max(np.abs(kv)) < 5


def test_the_step_rule_accounts_for_damping():
    """A sun support damped at 2e6 N·s/m on a 1 kg sun has a mode decaying at c/m = 2e6 1/s: RK4's real-axis
    limit 2.785/2e6 s is below the default of 20 steps per period of the highest frequency, so the default
    step shrinks to stay stable, both solvers agree on the limit, and a run at the default step is stable."""
    from gearcheck.lumped.time_solver import step_limits
    from gearcheck.shared.stepping import rk4_stable_step

    assert rk4_stable_step([1j]) == pytest.approx(2 * math.sqrt(2), rel=1e-12)
    assert rk4_stable_step([-1.0]) == pytest.approx(2.785293563405, rel=1e-10)
    spec = variant([(r"radial_stiffness = 1.0e8, radial_damping = 500.0", "radial_stiffness = 1.0e8, "
                                                                             "radial_damping = 2.0e6")], "damped-sun")
    model, mb = build_model(spec), compile_train(spec)
    lumped = step_limits(model)
    assert lumped.stable == pytest.approx(mb.limits.stable, rel=1e-6)
    assert lumped.stable < 2 * math.pi / (20 * lumped.omega_max)  # damping binds, not the frequency
    assert mb.default_step <= 0.9 * mb.limits.stable
    result = simulate(model, RunSettings(0.005))
    assert np.all(np.isfinite(result.select("mesh_force")))
    with pytest.raises(SolverError, match="unstable"):
        simulate(model, RunSettings(0.005, dt=1.0 * lumped.stable))
