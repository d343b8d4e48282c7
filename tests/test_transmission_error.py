"""Static transmission error of a train's meshes, unloaded and loaded, with tip relief (`gearcheck ste`).

Closed forms:

* no relief: the loaded TE is F / k(xi); for a helical mesh the thin slices add up to the contact-line
  model k_mean L(xi) / L_m (Maatar & Velex 1996) exactly;
* a spur mesh (1 < eps_a < 2) with equal linear long reliefs C on both tips, reaching the points of single
  contact, (eps_a - 1) p_b: in the single-pair zone delta = F / k_pair; in the double zone the two gaps sum
  to C, so delta = (F / k_pair + C) / 2, and for C > F / k_pair the entering pair opens at its start, where
  delta falls back to F / k_pair: peak-to-peak |C - F / k_pair| / 2, least at the pair's own deflection;
* a relief sits at its gear's tip: the gap at a contact point is C (1 - d / L_a) with d the roll distance
  from that gear's tip circle, whichever end of the path of contact the tip is at.
"""

import math

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.train import helical_mesh
from gearcheck.lumped.assembly import build_model
from gearcheck.train.tooth_pairs import DYNAMIC_SLICES, mesh_relief
from gearcheck.train.tooth_stiffness import path_of_contact
from gearcheck.lumped.transmission_error import mesh_static_transmission_error, static_transmission_error
from gearcheck.train.variants import edited


def with_relief(preset: str, amount_um: float, length_mm: float, gears=("planet",), shape="linear"):
    """``preset`` with a tip relief on the named gears (stage tables [stages.sun], [stages.planet], ...)."""
    relief = f"tip_relief = {{ amount_um = {amount_um!r}, length_mm = {length_mm!r}, shape = \"{shape}\" }}"
    pairs = [(rf"^(\[stages\.{gear}\])$", rf"\1\n{relief}") for gear in gears]
    return edited(preset, pairs, f"{amount_um} um relief")


def test_without_relief_a_helical_mesh_has_the_contact_line_models_te():
    spec = gearcheck.load("helical-planetary")
    for curve, mesh in zip(static_transmission_error(spec), spec.meshes):
        g = mesh.geometry
        line = helical_mesh.contact_line_length(curve.xi, g.contact_ratio, g.face_contact_ratio, g.face_width,
                                                g.base_helix_angle)
        k_line = curve.mean_stiffness * line / helical_mesh.mean_contact_line_length(g.contact_ratio, g.face_width,
                                                                                     g.base_helix_angle)
        np.testing.assert_allclose(curve.loaded, curve.load / k_line, rtol=1e-12)
        assert np.all(curve.unloaded == 0.0)


@pytest.mark.parametrize("amount_um", [0.0, 4.0, 8.0, 12.0, 16.0])
def test_equal_long_reliefs_on_a_spur_mesh_in_closed_form(amount_um):
    demo = gearcheck.load("demo-3p")
    g = demo.meshes[0].geometry
    reach_mm = (g.contact_ratio - 1.0) * g.base_pitch * 1e3
    spec = with_relief("demo-3p", amount_um, reach_mm, gears=("sun", "planet"))
    curve = static_transmission_error(spec, points=2001)[0]
    single = curve.load * g.contact_ratio / curve.mean_stiffness  # F / k_pair
    assert np.ptp(curve.loaded) == pytest.approx(abs(amount_um * 1e-6 - single) / 2, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("mesh_index", [0, 3])  # the sun and the ring mesh of planet 1
def test_a_relief_sits_at_its_gears_tip(mesh_index):
    spec = with_relief("demo-3p", 20.0, 6.0, gears=("sun", "ring", "planet"), shape="parabolic")
    mesh = spec.meshes[mesh_index]
    path = path_of_contact(mesh)
    s = np.linspace(0.0, mesh.geometry.contact_ratio * mesh.geometry.base_pitch, 101)
    expected = np.zeros_like(s)
    for gear, radius in zip((mesh.central_gear, mesh.planet_gear), path.radii(s)):
        roll = np.sqrt(radius**2 - gear.base_radius**2)
        d = np.abs(roll - math.sqrt(gear.tip_radius**2 - gear.base_radius**2))
        expected += 20e-6 * np.clip(1 - d / 6e-3, 0, None) ** 2
    np.testing.assert_allclose(mesh_relief(mesh)(s), expected, rtol=1e-9, atol=1e-18)


def test_more_load_closes_the_relieved_pairs():
    spec = with_relief("demo-3p", 10.0, 5.0, gears=("sun", "planet"))
    mesh = spec.meshes[0]
    light = mesh_static_transmission_error(mesh, 1000.0, 8e8)
    heavy = mesh_static_transmission_error(mesh, 40000.0, 8e8)
    assert np.all(np.diff(np.vstack([light.loaded, heavy.loaded]), axis=0) > 0)
    assert np.all(heavy.stiffness >= light.stiffness) and np.any(heavy.stiffness > light.stiffness)


def test_the_ste_command_and_its_sweep(tmp_path, capsys):
    out = tmp_path / "ste"
    assert main(["ste", "helical-planetary", "--relief-sweep", "0:4:3", "--slices", "50", "--out", str(out)]) == 0
    assert {p.name for p in out.iterdir()} >= {"ste.png", "ste.json", "relief_sweep.png"}
    assert "smallest loaded peak-to-peak" in capsys.readouterr().out
    assert main(["ste", "demo-3p", "--relief-sweep", "0:4:3", "--out", str(tmp_path / "none")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no gear has a tip_relief" in err
    assert not (tmp_path / "none").exists()


def relieved_helical(amount_um: float, rpm: float = 3000.0):
    spec = edited("helical-planetary", [(r"amount_um = 0.0", f"amount_um = {amount_um!r}")], f"{amount_um} um")
    return spec.with_operating(input_speed=rpm * math.pi / 30.0)


def test_tip_relief_in_both_time_solvers():
    """MuJoCo's tendons take the stiffness and spring length of the pairs in contact at their own length each
    step; the lumped solver sums the pairs at every stage: they agree, and a 15 um relief on the planets'
    tips takes the relieved pairs out of the load (the mean stiffness in effect falls below k_mean)."""
    result = gearcheck.crosscheck(relieved_helical(15.0), duration=0.03)
    assert result.verdict == "PASS", result.failures
    lumped, mujoco = result.results
    window = lumped.t >= result.steady_start_s
    for mesh in result.spec.meshes[:1] + result.spec.meshes[3:4]:
        k_mean = gearcheck.load("helical-planetary").meshes[mesh.planet_index].stiffness["mean"]
        k = lumped[f"{mesh.id}.stiffness"][window]
        assert k.mean() < 0.95 * k_mean
        np.testing.assert_allclose(mujoco[f"{mesh.id}.stiffness"][window], k, rtol=1e-6)


def test_at_low_speed_the_dynamic_te_is_the_loaded_static_te():
    """At 300 rpm the mesh frequency (112.5 Hz) is 1/16 of the lowest mode (1788 Hz): the time solver's mesh
    approach follows the quasi-static contact solution (sorted gaps, exact; another algorithm) to a few
    per cent of its peak-to-peak (measured 4.3 % sun, 1.3 % ring: the response of the relief's sharp
    corners' higher harmonics)."""
    spec = relieved_helical(15.0, rpm=300.0)
    run = gearcheck.simulate(spec, solver="lumped", duration=0.12)
    exc = build_model(spec).excitation
    window = run.t > 0.06
    for j in (0, 3):
        mesh = spec.meshes[j]
        curve = mesh_static_transmission_error(mesh, run.static[f"{mesh.id}.force"], exc.mean_stiffness[j],
                                               points=2001, slices=DYNAMIC_SLICES)
        xi = np.mod(exc.mesh_position(run.t[window])[:, j], 1.0)
        quasi_static = np.interp(xi, curve.xi, curve.loaded)
        error = np.max(np.abs(run[f"{mesh.id}.dte"][window] - quasi_static)) / np.ptp(curve.loaded)
        assert error < 0.06, (mesh.id, error)
