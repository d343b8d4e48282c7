"""Parts are elements: one registry per side, every part of every train built by the element of its kind, a
member's degrees of freedom defined once, and a new kind of part added by one description dataclass, one element
per side and this test file (DESIGN.md 8)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import mujoco
import numpy as np
import pytest

import gearcheck
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.elements import ELEMENTS as LUMPED
from gearcheck.lumped.elements.base import Contribution, Row
from gearcheck.lumped.modal import modes as lumped_modes
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.elements import ELEMENTS as MUJOCO
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import fixed, member_joints
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.elements import Registry
from gearcheck.shared.errors import GearcheckError
from gearcheck.train.parts import Part, train_parts
from gearcheck.train.spec import TrainSpec


def test_a_part_of_unknown_kind_is_named_with_the_kinds_the_side_knows():
    with pytest.raises(GearcheckError, match=r"the mujoco model has no element for parts of kind 'gearbox' \(it knows "
                                             r"bearing, coupling, cycloid, drive, mesh, spline, support"):
        MUJOCO["gearbox"]


def test_a_kind_registers_once():
    registry = Registry("lumped")
    registry.register("spring")(lambda part, build: Contribution())
    with pytest.raises(ValueError, match="'spring' registered twice"):
        registry.register("spring")(lambda part, build: Contribution())


def test_both_sides_build_the_same_kinds_of_part():
    assert LUMPED.kinds() == MUJOCO.kinds()
    for name in gearcheck.presets():
        kinds = {part.element for part in gearcheck.load(name).parts}
        assert kinds <= set(LUMPED.kinds()), name


@pytest.mark.parametrize("name", ["demo-3p", "helical-planetary", "rv-reducer"])
def test_a_members_degrees_of_freedom_are_defined_once(name):
    """The lumped coordinates and the twin's joints are both read off ``Member.dofs``: one coordinate per degree of
    freedom on each side, so both models have as many (MuJoCo's joints realise them in its own way: a disc's
    translations in polar joints)."""
    spec = gearcheck.load(name)
    model, twin = build_model(spec), compile_train(spec)
    assert model.dofs.labels() == [f"{mid}.{dof}" for mid, m in spec.members.items() for dof in m.dofs]
    assert twin.model.nv == model.n
    for member in spec.members.values():
        joints = [mujoco.mj_name2id(twin.model, mujoco.mjtObj.mjOBJ_JOINT, f"{member.label}_{j}")
                  for j in member_joints(member)]
        assert len(joints) == len(member.dofs) and min(joints) >= 0, member.id
    if name == "helical-planetary":  # every member of a helical stage slides axially
        assert all(m.dofs[-1] == "z" for m in spec.members.values())


# --------------------------------------------------------------------------- a new kind of part, end to end


@dataclass(frozen=True)
class TorsionPart(Part):
    """The description: a torsional spring between the rotations of two members on the stage axis (elastic: no
    rigid speed constraint, no periodic contact, Part's defaults)."""

    element: ClassVar[str] = "test-torsion"
    a: str
    b: str
    stiffness: float


@LUMPED.register("test-torsion")
def torsion_row(part, build) -> Contribution:
    a = build.dofs.unit((part.a, "theta", 1.0), (part.b, "theta", -1.0))
    return Contribution([Row(f"{part.a}-{part.b}.torsion", "coupling", a, part.stiffness, 0.0)])


@MUJOCO.register("test-torsion")
class Torsion(Element):
    def tendons(self, part, spec) -> list[str]:
        a, b = spec.members[part.a].label, spec.members[part.b].label
        return fixed(f"{a}_{b}_torsion", [(f"{a}_rz", 1.0), (f"{b}_rz", -1.0)], part.stiffness, 0.0)


def test_a_new_kind_of_part_reaches_both_models(monkeypatch):
    """A sun-to-carrier torsional spring, added as a part: both models gain it, and their natural frequencies,
    each computed its own way, still agree (to the 1e-8 that the twin's linearisation holds for demo-3p) while they
    moved by far more than that."""
    spec = gearcheck.load("demo-3p")
    before = lumped_modes(build_model(spec)).frequencies
    torsion = TorsionPart("stage1.sun", "stage1.carrier", 2e5)
    monkeypatch.setattr(TrainSpec, "parts", property(lambda s: train_parts(s) + (torsion,)))
    lumped = lumped_modes(build_model(spec)).frequencies
    twin = compile_train(spec)
    assert "stage1_sun_stage1_carrier_torsion" in twin.xml
    mujoco_frequencies = linearise.modes(twin).frequencies
    assert np.max(np.abs(lumped - before) / before) > 1e-3
    np.testing.assert_allclose(mujoco_frequencies, lumped, rtol=1e-8)
