"""Torsional members (issue 28): a member with its rotation only, honoured by both solvers.

A train whose every member is torsional is the purely torsional model of Kahraman (1994) (Lin & Parker 1999's
torsional reduction), written here independently from the base radii: the full model's limit as its supports and
bearings stiffen (converging as 1/k), the twin's modes, the count of its modes; bad input is one line.
"""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

import gearcheck
from gearcheck.cli import main
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.export import reference_linear_model, write_matrix_file
from gearcheck.lumped.modal import modes
from gearcheck.lumped.side import LinearSide, LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.errors import TrainFileError, TrainNote
from gearcheck.train.variants import chained_text, edited, edited_text, helical_stage

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
STAGE = (r"^planets = 3", "planets = 3\ntorsional = true")  # demo-3p's stage, every member torsional
PLANETS = (r"^\[stages.planet\]", "[stages.planet]\ntorsional = true")
CARRIER = (r"^\[stages.carrier\]", "[stages.carrier]\ntorsional = true")


def train(*pairs, label="torsional"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TrainNote)
        return edited("demo-3p", pairs, label)


def kahraman(spec) -> np.ndarray:
    """Natural frequencies (Hz) of the purely torsional model written from the train's data alone: rotations
    (sun, ring, carrier, planets), each mesh's deflection along its line of action
    delta_sn = r_bs th_s + r_bp th_n - (r_bs + r_bp) th_c, delta_rn = r_br th_r - r_bp th_n - (r_br - r_bp) th_c
    (the planet's centre moves r_c th_c across its pin, whose projection on a line of action at operating
    pressure angle alpha is r_c cos alpha = r_bs + r_bp, or r_br - r_bp), the carrier carrying the planets' mass
    at r_c; the ring's torsional support and the input shaft on the sun to the reference."""
    stage = spec.stages[0]
    sun, ring, carrier = (spec.members[f"{stage.name}.{k}"] for k in ("sun", "ring", "carrier"))
    planets = [spec.members[p] for p in stage.planets]
    r_s, r_r = sun.gears["sun"].base_radius, ring.gears["ring"].base_radius
    r_p = next(iter(planets[0].gears.values())).base_radius
    n = 3 + len(planets)
    M = np.diag([sun.inertia, ring.inertia, carrier.inertia + sum(p.mass * stage.carrier_radius**2 for p in planets)]
                + [p.inertia for p in planets])
    K = np.zeros((n, n))
    k_mesh = dict(zip((m.id for m in spec.meshes), build_model(spec).excitation.mean_stiffness))
    for j, p in enumerate(planets):
        for central, a in (("sun", [r_s, 0.0, -(r_s + r_p)]), ("ring", [0.0, r_r, -(r_r - r_p)])):
            row = np.zeros(n)
            row[:3] = a
            row[3 + j] = r_p if central == "sun" else -r_p
            K += k_mesh[f"{p.id}.{central}"] * np.outer(row, row)
    K[1, 1] += ring.support.torsional_stiffness
    K[0, 0] += spec.operating.input_shaft_stiffness
    return np.sqrt(np.abs(sla.eigh(K, M, eigvals_only=True))) / (2 * np.pi)


def test_every_member_torsional_is_kahraman_model():
    spec = train(STAGE)
    model = build_model(spec)
    assert model.dofs.labels() == [f"{m}.theta" for m in spec.members]
    modal = modes(model)
    assert np.allclose(modal.frequencies, kahraman(spec), rtol=1e-10)
    # planet modes: the planets alone, sum of their rotations zero (N - 1 of them), each a planet between its two
    # meshes, w^2 = (k_s + k_r) r_bp^2 / I_p (Lin & Parker 1999's planet modes at the torsional level)
    planet = spec.members["stage1.planet1"]
    k = dict(zip((m.id for m in spec.meshes), model.excitation.mean_stiffness))
    r_bp = next(iter(planet.gears.values())).base_radius
    f_planet = np.sqrt((k["stage1.planet1.sun"] + k["stage1.planet1.ring"]) * r_bp**2 / planet.inertia) / (2 * np.pi)
    planets = modal.frequencies[np.array(modal.types) == "planet"]
    assert planets.size == len(spec.stages[0].planets) - 1 and np.allclose(planets, f_planet, rtol=1e-12)
    assert all(t == "rotational" for t in modal.types if t != "planet")


def test_stiff_supports_converge_to_it_as_one_over_k():
    """The full model with every translational support and bearing stiffness k: its rotational modes tend to the
    torsional ones, the error falling tenfold for a tenfold k."""
    torsional = modes(build_model(train(STAGE))).frequencies
    errors = []
    for k in (1e12, 1e13):
        full = modes(build_model(train((r"radial_stiffness = [0-9.e]+", f"radial_stiffness = {k!r}")))).frequencies
        errors.append(np.abs(np.sort(full)[:torsional.size] / torsional - 1.0))
    assert np.all(errors[1] < 1e-4)
    assert np.allclose(errors[0] / errors[1], 10.0, rtol=0.02)


@pytest.mark.parametrize("pairs, rotations_only, helical", [
    ((STAGE,), True, False), ((PLANETS,), False, False), ((CARRIER,), False, False), ((STAGE,), True, True),
    ((PLANETS,), False, True)], ids=["every member", "planets", "carrier", "helical", "helical planets"])
def test_both_solvers_agree_on_the_free_coordinates(pairs, rotations_only, helical):
    """Lumped and twin agree; a mode per free coordinate (6 rotations when every member is torsional; a planet on
    its pin loses its two translations, a central member its two, and in a helical stage its axial one too: a
    planet's rides the carrier's)."""
    if helical:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TrainNote)
            spec = helical_stage(extra=pairs)
    else:
        spec = train(*pairs)
    lumped, twin = gearcheck.modes(spec, solver="lumped"), gearcheck.modes(spec, solver="mujoco")
    free = sum(len(m.coordinates) for m in spec.members.values())
    assert free == sum(len(m.dofs) - (len(m.dofs) - 1) * m.torsional for m in spec.members.values())
    assert lumped.frequencies.size == twin.frequencies.size == free
    assert free == len(spec.members) if rotations_only else free > len(spec.members)
    assert np.allclose(twin.frequencies, lumped.frequencies, rtol=1e-9)
    pairing = gearcheck.mode_pairing(spec)  # the shapes too, over the free coordinates both solvers keep
    assert not pairing.findings and pairing.paired.min() > 1 - 1e-9


@pytest.mark.parametrize("pairs", [(PLANETS,), (CARRIER,), ((r"^\[stages.sun\]", "[stages.sun]\ntorsional = true"),)],
                         ids=["planets", "carrier", "sun"])
def test_both_solvers_agree_at_speed(pairs):
    """At three times the train's speed the rotating frame's Coriolis and centripetal terms, reduced with the rest
    (a planet on its pin keeps its centre's terms through the carrier's coordinates), match the twin's own."""
    spec = train(*pairs)
    speed = 3.0 * spec.operating.input_speed
    lumped, twin = LumpedSide(spec).modes_at_speed(speed), MujocoSide(spec).modes_at_speed(speed)
    assert np.allclose(twin.frequencies, lumped.frequencies, rtol=1e-9)


@pytest.mark.parametrize("pairs", [(STAGE,), (STAGE, (r"^\[stages.planet\]", "[stages.planet]\ntorsional = false"))],
                         ids=["every member", "central members"])
def test_crosscheck_passes(pairs):
    """Both solvers' time runs agree (a torsional planet's two meshes on one hinge: the twin reads them one at a
    time), the mesh forces to round-off; the central members' translational accelerations are zero on both sides
    (reported, not compared)."""
    spec = train(*pairs)
    result = gearcheck.crosscheck(spec, duration=0.02)
    assert result.verdict == "PASS"
    table = result.to_dataframe()
    forces = table[(table.kind == "mesh_force") & (table.metric == "nrmse")]
    assert len(forces) == len(spec.meshes) and np.all(forces.value < 1e-3 * forces.tolerance)
    lumped, twin = result.results
    for run in (lumped, twin):
        assert np.all(run["stage1.sun.ax.world"] == 0.0) and np.all(run["stage1.carrier.ay.carrier"] == 0.0)


def test_a_users_torsional_model_is_the_torsional_train(tmp_path):
    """examples/torsional_user_model.py, a user's torsional derivation from Lin & Parker (1999), is the torsional
    train's reference itself (M and mean K to round-off, no projection), and the reference exported as a file of
    matrices passes the cross-check as a user's model, its map over the torsional train's coordinates."""
    sys.path.insert(0, str(EXAMPLES))
    try:
        from torsional_user_model import torsional_model
    finally:
        sys.path.remove(str(EXAMPLES))
    spec = train(STAGE)
    reference, user = build_model(spec), LinearSide(torsional_model(spec), spec).linear
    assert user.coordinates == reference.dofs.labels()
    np.testing.assert_allclose(user.M, reference.M, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(user.K_mean, reference.K_mean, rtol=1e-12, atol=1e-12 * np.abs(reference.K_mean).max())
    path = tmp_path / "torsional.mat"
    write_matrix_file(reference_linear_model(spec), path)
    result = gearcheck.crosscheck(spec, model=str(path), duration=0.05)
    assert result.verdict == "PASS", result.failures
    assert max(m["rel_error"] for m in result.modal) < 1e-12


def test_ignored_supports_are_noted():
    with pytest.warns(TrainNote, match="of stage1.sun's support, stage1.ring's support, stage1.carrier's "
                                     "support, the planets' bearing ignored"):
        edited("demo-3p", [STAGE])


@pytest.mark.parametrize("text, expected", [
    (edited_text("demo-3p", [(r"^planets = 3", 'planets = 3\ntorsional = "yes"')]),
     "stages[0].torsional: must be true or false, got 'yes'"),
    (edited_text("demo-3p", [(r"^\[stages.sun\]", "[stages.sun]\ntorsional = 1")]),
     "stages[0].sun.torsional: must be true or false, got 1"),
    (chained_text(2, 1e8).replace("planets = 3", "planets = 3\ntorsional = true", 1),
     "couplings[0].radial_stiffness: 1e+08 in a train with torsional members"),
], ids=["stage", "member", "radial coupling"])
def test_bad_input_is_one_line(tmp_path, refused, text, expected):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    line = refused(["modes", path, "-q"])
    assert line.startswith(f"gearcheck: error: {path}: {expected}"), line


def test_an_rv_reducer_has_no_torsional_level():
    with pytest.raises(TrainFileError, match=r"stages\[0\].torsional: an RV reducer's stage has no torsional level"):
        edited("rv-reducer", [(r'^name = "rv"', 'name = "rv"\ntorsional = true')])


def test_show_lists_the_torsional_members(tmp_path, capsys):
    path = tmp_path / "planets.toml"
    path.write_text(edited_text("demo-3p", [PLANETS]))
    assert main(["show", str(path), "--json"]) == 0
    stage = json.loads(capsys.readouterr().out)["stages"][0]
    assert stage["torsional"] == ["stage1.planet1", "stage1.planet2", "stage1.planet3"]
    assert main(["show", "demo-3p"]) == 0 and "torsional" not in capsys.readouterr().out
