"""The diagnosis of a user's lumped model (gearcheck.compare.engine.diagnosis): broken copies of the reference, one term
changed each, are named by the term that was changed; the reference itself, and a mistake the evidence cannot
see, are said to agree."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import gearcheck
from gearcheck.compare.engine.diagnosis import KINDS, Evidence, diagnose
from gearcheck.lumped.assembly import build_model
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.modal import generalized_modes

ROUND_OFF = 1e-12


@pytest.fixture(scope="module")
def demo():
    return build_model(gearcheck.load("demo-3p"))


@pytest.fixture(scope="module")
def hub():
    return build_model(gearcheck.load("hub-drive"))


def with_row_coefficient(model, row: str, coordinate: str, value):
    """A copy of ``model`` with one coefficient of a mesh row (by mesh id) or a constant row set by ``value(a_j)``."""
    j = model.dofs.labels().index(coordinate)
    meshes = [mesh.id for mesh in model.spec.meshes]
    if row in meshes:
        mesh_rows = model.mesh_rows.copy()
        assert mesh_rows[meshes.index(row), j] != 0
        mesh_rows[meshes.index(row), j] = value(mesh_rows[meshes.index(row), j])
        return replace(model, mesh_rows=mesh_rows)
    rows = [replace(r, a=np.where(np.arange(model.n) == j, value(r.a[j]), r.a)) if r.name == row else r
            for r in model.rows]
    return replace(model, rows=rows)


def test_the_reference_agrees_with_itself(demo):
    diagnosis = diagnose(demo, Evidence.of_model(demo))
    assert diagnosis.agrees and diagnosis.best.kind == "no mistake"
    assert diagnosis.reference_score == diagnosis.best.score < ROUND_OFF
    assert diagnosis.lines()[0].startswith("No single-term mistake: agrees with the reference")
    assert all(c.score > 1e3 * ROUND_OFF for c in diagnosis.candidates[1:])  # the rest change something
    assert {c.kind for c in diagnosis.candidates} <= set(KINDS)
    assert json.loads(json.dumps(diagnosis.to_dict()))["agrees"] is True


@pytest.mark.parametrize("preset, row, coordinate, kind", [
    ("demo-3p", "stage1.planet2.sun", "stage1.sun.theta", "dropped coupling"),
    ("demo-3p", "stage1.planet2.ring", "stage1.planet2.tangential", "sign error"),
    ("hub-drive", "spline.torsion", "II.sun.theta", "dropped coupling"),
])
def test_a_broken_row_coefficient_is_named_exactly(demo, hub, preset, row, coordinate, kind):
    """Shapes tell planet 2's row from planets 1 and 3's, which have the same frequencies."""
    model = {"demo-3p": demo, "hub-drive": hub}[preset]
    value = (lambda a: 0.0) if kind == "dropped coupling" else np.negative
    broken = with_row_coefficient(model, row, coordinate, value)
    diagnosis = diagnose(model, Evidence.of_model(broken, at_speed=preset == "demo-3p"))
    best = diagnosis.best
    assert (best.kind, best.row, best.coordinate) == (kind, row, coordinate)
    assert best.score < ROUND_OFF < diagnosis.reference_score
    assert not best.equivalents
    assert diagnosis.candidates[1].score > 1e6 * best.score
    assert row in best.term and coordinate in best.term


def test_frequencies_alone_name_the_planets_symmetric_equivalents_as_one_class(demo):
    broken = with_row_coefficient(demo, "stage1.planet2.sun", "stage1.sun.theta", lambda a: 0.0)
    diagnosis = diagnose(demo, Evidence.of_model(broken, shapes=False))
    assert diagnosis.best.score < ROUND_OFF
    assert {(c.kind, c.row, c.coordinate) for c in diagnosis.best.alike()} == {
        ("dropped coupling", f"stage1.planet{i}.sun", "stage1.sun.theta") for i in (1, 2, 3)}


@pytest.mark.parametrize("member, dofs", [("stage1.carrier", ["theta"]), ("stage1.planet2", ["radial", "tangential"])])
def test_a_wrong_inertia_is_named_with_its_factor(demo, member, dofs):
    M = demo.M.copy()
    idx = [demo.dofs(member, d) for d in dofs]
    M[idx, idx] *= 1.5
    best = diagnose(demo, Evidence.of_model(replace(demo, M=M))).best
    assert (best.kind, best.member, best.coordinates) == ("inertia", member, [f"{member}.{d}" for d in dofs])
    assert best.factor == pytest.approx(1.5, rel=1e-3)
    assert best.score < 1e-9


def test_missing_gyroscopic_terms_show_only_at_speed(demo):
    """Without the Coriolis terms the degenerate pairs do not split at speed (Cooley & Parker 2012); at rest
    nothing differs."""
    broken = replace(demo, G=np.zeros_like(demo.G))
    at_speed = diagnose(demo, Evidence.of_model(broken))
    assert at_speed.best.kind == "gyroscopic" and at_speed.best.score < ROUND_OFF
    assert at_speed.reference_score > 1e-4
    at_rest = diagnose(demo, Evidence.of_model(broken, at_speed=False))
    assert at_rest.agrees and at_rest.best.kind == "no mistake"
    assert all(c.kind not in ("gyroscopic", "centripetal") for c in at_rest.candidates)


def test_held_coordinates_are_named(demo):
    """A user model without the sun's translations (a sun held on its axis) is the reference with them held."""
    labels = demo.dofs.labels()
    keep = [i for i, label in enumerate(labels) if label not in ("stage1.sun.x", "stage1.sun.y")]
    sub = np.ix_(keep, keep)
    frequencies, shapes = generalized_modes(demo.K_mean[sub], demo.M[sub])
    order = keep[::-1]  # in another order than the reference's
    evidence = Evidence([labels[i] for i in order], frequencies, shapes[::-1], demo.M[sub][::-1, ::-1])
    diagnosis = diagnose(demo, evidence)
    assert diagnosis.best.kind == "held coordinates"
    assert diagnosis.best.coordinates == diagnosis.held == ["stage1.sun.x", "stage1.sun.y"]
    assert diagnosis.best.score < ROUND_OFF and diagnosis.reference_score is None and not diagnosis.agrees


def test_evidence_in_unknown_coordinates_is_refused(demo):
    evidence = Evidence.of_model(demo, shapes=False, at_speed=False)
    with pytest.raises(GearcheckError, match="stage1.moon.x"):
        diagnose(demo, replace(evidence, labels=["stage1.moon.x", *evidence.labels[1:]]))
    with pytest.raises(GearcheckError, match="ascending"):
        diagnose(demo, replace(evidence, frequencies=evidence.frequencies[::-1]))


def test_n_rc_k_for_n_rc2_k_is_named_and_the_lost_rigid_mode_said(demo):
    """Issue 28: on a torque-driven train (no input shaft) the carrier's N r_c^2 k written N r_c k holds the rigid
    turn; in K that is exactly a spring from the carrier's rotation to ground, so both are named, the exact entry
    first."""
    free = replace(demo, rows=[r for r in demo.rows if r.name != "input_shaft"])
    i, r_c = free.dofs("stage1.carrier", "theta"), demo.spec.members["stage1.planet1"].radius
    bug = replace(free.rows[0], name="bug", stiffness=free.K_mean[i, i] * (1.0 / r_c - 1.0), a=np.eye(free.n)[i])
    diagnosis = diagnose(free, Evidence.of_model(replace(free, rows=[*free.rows, bug])))
    best = diagnosis.best
    carrier = "stage1.carrier"
    assert (best.kind, best.member, best.coordinates) == ("radius power", carrier, [f"{carrier}.theta"] * 2)
    assert best.factor == pytest.approx(1.0 / r_c, rel=1e-12) and best.score < ROUND_OFF
    assert [(e.kind, e.coordinates) for e in best.equivalents] == [("extra spring", ["stage1.carrier.theta"])]
    assert diagnosis.rigid_modes == {"evidence": 0, "reference": 1}
    assert diagnosis.lines()[0].startswith("Rigid-body modes lost: 1")
