"""Modes of the turning train: the gyroscopic eigenproblem of both solvers, and the Campbell diagram.

The lumped model's matrices at speed (Coriolis G ~ Omega, centripetal K ~ Omega^2) and MuJoCo's own
linearisation of its forward dynamics (its bias forces differentiated, its world-frame slides turned
into the carriers' axes) are two derivations of one physics: their frequencies must agree to 1e-6 at
every speed.  With Lin & Parker's centripetal softening alone the lumped frequencies were 3.3e-6 off
MuJoCo's at demo-3p's own speed and 5.2e-5 at four times it.
"""

import json
import math

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.studies.campbell import nearest_mode_driven
from gearcheck.session import Train
from gearcheck.train.variants import edited

SPEED_FACTORS = (1.0, 4.0)


def elastic_difference(a, b) -> float:
    el = a.frequencies > 0
    return float(np.max(np.abs(a.frequencies - b.frequencies)[el] / a.frequencies[el]))


def test_zero_speed_is_the_train_at_rest(preset):
    for solver in gearcheck.SOLVERS:
        rest, zero = gearcheck.modes(preset, solver), gearcheck.modes(preset, solver, speed=0.0)
        np.testing.assert_allclose(zero.frequencies, rest.frequencies, rtol=1e-9, atol=1e-9)
        assert zero.types == rest.types and zero.multiplicity == rest.multiplicity
        assert zero.stable and set(zero.stability) <= {"stable", "rigid"}


@pytest.mark.parametrize("factor", SPEED_FACTORS)
def test_both_solvers_agree_at_speed(preset, factor):
    rpm = factor * gearcheck.load(preset).operating.input_speed * 30 / math.pi
    lumped, mujoco = (gearcheck.modes(preset, solver, speed=rpm) for solver in gearcheck.SOLVERS)
    assert elastic_difference(lumped, mujoco) < 1e-6
    assert lumped.types == mujoco.types and lumped.stable and mujoco.stable


def test_speed_splits_the_translational_pairs():
    """Gyroscopic coupling splits each degenerate translational pair (Cooley & Parker 2012), by an amount
    that grows in proportion to the speed at low speed; rotational modes stay single."""
    splits = []
    for rpm in (500.0, 1000.0):
        r = gearcheck.modes("demo-3p", speed=rpm)
        i = r.types.index("translational")
        splits.append(r.frequencies[i + 1] - r.frequencies[i])
        assert r.multiplicity[i] == 1 and r.types[i + 1] == "translational"
    assert splits[0] > 0 and splits[1] / splits[0] == pytest.approx(2.0, rel=0.01)


SOFT = [(r"radial_stiffness = 2.0e8", "radial_stiffness = 1.0e6"), (r"mean = 8.0e8", "mean = 2.0e7")]


def soft_train():
    """demo-3p with plastic-like gears (mean mesh stiffness 2e7 N/m) on soft planet bearings (1e6 N/m)."""
    return edited("demo-3p", SOFT, "soft planet bearings")


def test_divergence_where_the_centripetal_softening_beats_the_bearing():
    """A planet can move on its bearing in a way that leaves both its meshes undeformed (translating and
    spinning together); in the carrier's frame that motion is softened by m_p Omega_c^2 and only the
    bearing k_b resists it.  Above Omega_c = sqrt(k_b / m_p) the train diverges: for this train
    1158 rad/s on the carrier, 42 220 rpm at the sun.  Both solvers flag it on either side of that speed
    to 0.5 %, and the time solver's run there grows away."""
    spec = soft_train()
    planet = spec.members[spec.stages[0].planets[0]]
    z_s, z_r = 22, 62
    critical = math.sqrt(planet.bearing.radial_stiffness / planet.mass) * (z_s + z_r) / z_s * 30 / math.pi
    for solver in gearcheck.SOLVERS:
        below, above = (gearcheck.modes(spec, solver, speed=f * critical) for f in (0.995, 1.005))
        assert below.stable, solver
        assert not above.stable and "divergence" in above.stability, solver
    with pytest.raises(gearcheck.DivergenceError):
        gearcheck.simulate(spec, duration=0.2, speed=1.1 * critical)


def test_campbell_diagram_files_and_crossings(tmp_path, capsys):
    out = tmp_path / "campbell"
    assert main(["campbell", "demo-3p", "--speeds", "0:6000:13", "--out", str(out)]) == 0
    data = json.loads((out / "campbell.json").read_text())
    assert (out / "campbell.png").read_bytes().startswith(b"\x89PNG")
    assert data["max_relative_difference"] < 1e-6 and data["instability_zones"] == []
    # a crossing is where the mesh harmonic's line meets a mode's frequency
    for c in data["crossings"]:
        line = next(m for m in data["mesh_lines"] if m["harmonic"] == c["harmonic"] and m["meshes"] == c["meshes"])
        assert c["frequency_hz"] == pytest.approx(line["hz_per_rpm"] * c["speed_rpm"])
    first = min(data["crossings"], key=lambda c: c["speed_rpm"])
    rest = gearcheck.modes("demo-3p")
    assert first["frequency_hz"] == pytest.approx(rest.frequencies[rest.frequencies > 0][0], rel=1e-3)


def test_campbell_shades_the_unstable_range(tmp_path, capsys):
    spec_file = tmp_path / "soft.toml"
    from gearcheck.train.variants import edited_text

    spec_file.write_text(edited_text("demo-3p", SOFT))
    assert main(["campbell", str(spec_file), "--speeds", "40000:46000:7", "--solver", "lumped",
                 "--out", str(tmp_path / "c")]) == 0
    zones = json.loads((tmp_path / "c" / "campbell.json").read_text())["instability_zones"]
    assert zones == [{"solver": "lumped", "from_rpm": 43000.0, "to_rpm": 46000.0}]
    assert "UNSTABLE (lumped) from 43000 to 46000 rpm" in capsys.readouterr().out


@pytest.mark.parametrize("preset, sun_teeth, planets", [("demo-3p", 22, 3), ("demo-4p", 22, 4)])
def test_campbell_marks_the_crossings_the_planets_phasing_cannot_excite(preset, sun_teeth, planets):
    """Parker (2000), tested by forced response in test_phasing.py: harmonic l of N equally spaced planets reaches
    rotational modes when l z_s / N is an integer, translational when l z_s +- 1 is a multiple of N, planet modes
    otherwise.  At speed the carrier's gyroscopic terms split each translational pair into two whirls, and the
    phased forces, a vector turning one way for l z_s = +1 and the other for -1 (mod N), reach one of them: on
    these trains +1 the lower, -1 the upper.  Every crossing carries its mode's type and whether the harmonic
    reaches it, decided from the lumped model's phased mesh forces at the crossing's speed, and the diagram draws
    the unreachable ones hollow."""
    result = gearcheck.campbell(preset, np.linspace(0.0, 6000.0, 13), solver="lumped")
    assert result.crossings
    pairs = {}
    for c in result.crossings:
        r = (c["harmonic"] * sun_teeth) % planets
        if c["type"] == "translational" and r in (1, planets - 1):
            pairs.setdefault(c["harmonic"], []).append(c)
            continue
        expected = {"rotational": r == 0, "translational": False, "planet": r not in (0, 1, planets - 1)}[c["type"]]
        assert c["excited"] is expected, c
    for harmonic, crossings in pairs.items():
        crossings.sort(key=lambda c: c["speed_rpm"])
        assert len(crossings) % 2 == 0
        first = (harmonic * sun_teeth) % planets == 1  # +1: the lower whirl
        for lower, upper in zip(crossings[::2], crossings[1::2]):
            assert (lower["excited"], upper["excited"]) == (first, not first), (lower, upper)
    assert preset != "demo-3p" or sum(len(c) for c in pairs.values()) == 8
    kept = [c for c in result.crossings if c["excited"] is False]
    assert kept and len(kept) < len(result.crossings)
    hollow = [line for line in result.plot().axes[0].lines if line.get_marker() == "o"]
    assert len(hollow) == 1 and len(hollow[0].get_xdata()) == len(kept)


def test_campbell_decides_each_crossing_of_two_stages_from_the_forces_that_reach_it():
    """hub-drive, where no closed-form rule applies (two stages, 3 and 4 planets): every crossing says whether its
    line reaches its mode.  A mode with no kinetic energy in stage I (stage II's translational pair near 550 Hz:
    the spline between the stages holds them in torsion only) is out of reach of stage I's mesh forces, whatever
    the harmonic; stage I's first harmonic (22 teeth, 3 planets: l z_s = +1 mod 3) reaches one whirl of stage I's
    own translational pair near 225 Hz, the lower one, as on demo-3p."""
    result = gearcheck.campbell("hub-drive", np.linspace(0.0, 2500.0, 26), solver="lumped")
    assert result.crossings and all(c["excited"] in (True, False) for c in result.crossings)
    side = Train("hub-drive").side("lumped")
    labels = side.model.dofs.labels()
    stage_one = np.array([label.startswith("I.") for label in labels])
    out_of_reach = 0
    for c in result.crossings:
        if not c["meshes"][0].startswith("I."):
            continue
        modes = side.modes_at_speed(c["speed_rpm"] * math.pi / 30.0)
        shape = modes.shapes[:, np.argmin(np.abs(modes.frequencies - c["frequency_hz"]))]
        energy = np.real(np.conj(shape) * (side.model.M @ shape))
        if np.sum(energy[stage_one]) < 1e-12 * np.sum(energy):
            assert c["excited"] is False, c
            out_of_reach += 1
    assert out_of_reach >= 2
    pair = sorted((c for c in result.crossings if c["meshes"][0].startswith("I.") and c["harmonic"] == 1
                   and c["type"] == "translational" and c["frequency_hz"] < 240.0), key=lambda c: c["speed_rpm"])
    assert [c["excited"] for c in pair] == [True, False]


def test_campbell_leaves_undecided_what_the_lumped_drives_cannot_tell():
    """The RV reducer's pin pass is a line of no gear mesh, which the phased mesh forces say nothing of: its crossings
    are None, while its planetary stage's are decided.  The double-planet reducer's torque ripple would make the
    drives count every mode, and no closed-form rule covers its double planets: every crossing is None."""
    rv = gearcheck.campbell("rv-reducer", np.linspace(0.0, 6000.0, 7), solver="lumped")
    pins = [c["excited"] for c in rv.crossings if c["meshes"] == ["rv.pins"]]
    gears = [c["excited"] for c in rv.crossings if c["meshes"] != ["rv.pins"]]
    assert pins and all(e is None for e in pins)
    assert True in gears and False in gears and None not in gears
    assert not Train("double-planet").side("lumped").drives_known
    double = gearcheck.campbell("double-planet", np.linspace(0.0, 3000.0, 4), solver="lumped")
    assert double.crossings and all(c["excited"] is None for c in double.crossings)


def test_a_crossing_between_two_close_modes_driven_unlike_is_left_undecided():
    """The crossing's mode is the damped mode nearest the crossing's frequency.  Where the next mode is at most twice
    as far (a translational pair at low speed, barely split into its whirls) and the line drives one of the two
    only, which one it meets is not known: None.  The shipped trains' crossings are at least 7.6 times nearer their
    mode than the next (RV reducer; demo-3p 29, hub-drive 11), and all decided."""
    natural, driven = np.array([100.0, 223.2, 227.6, 400.0]), np.array([False, True, False, True])
    assert nearest_mode_driven(natural, driven, 223.3) is True  # 0.1 Hz from the lower whirl, 4.3 from the upper
    assert nearest_mode_driven(natural, driven, 227.0) is False
    assert nearest_mode_driven(natural, driven, 225.0) is None  # 1.8 and 2.6 Hz: either whirl
    assert nearest_mode_driven(natural, np.array([False, True, True, True]), 225.0) is True  # both driven alike
    assert nearest_mode_driven(np.array([250.0]), np.array([True]), 600.0) is True
