"""The diagnosis against broken models from independent formulations (gearcheck.compare.studies.diagnosis_corpus):
the unbroken formulations are the reference to round-off, the right term is named first in at least 90 % of the
broken models with an effect, in every class, and every rigid-body mode lost or gained is reported.  The
broken models are demo-3p's and demo-4p's (a few tens of seconds); the bench adds six-planet's."""

from __future__ import annotations

import numpy as np
import pytest

from gearcheck.compare.studies.diagnosis_corpus import CLASSES, TRAINS, agreement, cases, rates, run

ROUND_OFF = 1e-12
HIT_RATE = 0.9
SUBSET = ("demo-3p", "demo-4p")  # the test's trains (bench/diagnosis_corpus.py runs six-planet too)


@pytest.fixture(scope="module")
def outcomes():
    return [run(case) for case in cases(SUBSET)]


@pytest.mark.parametrize("train", TRAINS)
@pytest.mark.parametrize("shaft", [True, False])
def test_the_unbroken_formulations_are_the_reference(train, shaft):
    """Lin & Parker's equations in u = r theta, mapped to theta, and the torsional form with the planet centres
    held give the reference's frequencies (at rest and at speed) and shapes (MAC) to round-off."""
    found = agreement(train, shaft)
    assert found["translational-torsional"].kind == "no mistake"
    assert found["torsional"].kind == "held coordinates"
    for best in found.values():
        assert best.score < ROUND_OFF
        assert set(best.parts) >= {"rest", "shapes"}


def test_the_right_term_is_named_first(outcomes):
    found = rates(outcomes)
    assert set(found) == set(CLASSES) | {"all"}  # every class has cases with an effect
    assert found["all"] >= HIT_RATE
    assert {name: rate for name, rate in found.items() if rate < HIT_RATE} == {}
    for o in outcomes:
        if o.effect and o.hit:  # the named term explains the evidence, and only a real pair is named as one
            assert o.diagnosis.best.score < 1e-9
            assert (o.diagnosis.best.kind == "pair") == (o.case.mistake == "pair")


def test_a_case_without_effect_changes_nothing_the_modes_see(outcomes):
    """Flipping a row's only coefficient leaves a a^T, so the matrices, as they are."""
    for o in outcomes:
        if not o.effect:
            b, u = o.case.broken, o.case.unbroken
            assert all(np.allclose(x, y, rtol=ROUND_OFF, atol=0.0) for x, y in ((b.K, u.K), (b.M, u.M), (b.G, u.G)))
            assert o.diagnosis.agrees or o.diagnosis.best.kind == "held coordinates"


def test_every_rigid_body_mode_lost_or_gained_is_reported(outcomes):
    """A spring to ground, N r_c k for N r_c^2 k or a planet sum for another count on a torque-driven train
    removes its rigid-body mode; the input shaft left out adds one."""
    changed = [o for o in outcomes if o.rigid[0] != o.rigid[1]]
    assert {o.rigid[0] < o.rigid[1] for o in changed} == {True, False}  # both lost and gained occur
    assert all(o.rigid_reported for o in outcomes)
    for o in changed:
        word = "lost" if o.rigid[0] < o.rigid[1] else "gained"
        assert o.diagnosis.to_dict()["rigid_modes"] == {"evidence": o.rigid[0], "reference": o.rigid[1]}
        assert any(line.startswith(f"Rigid-body modes {word}: {abs(o.rigid[0] - o.rigid[1])}")
                   for line in o.diagnosis.lines())
