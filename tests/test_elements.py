"""Parts are elements: one registry per side, every part of every train built by the element of its kind, a
member's degrees of freedom defined once, and a new kind of part added by one description dataclass, one element
per side and this test file (DESIGN.md 8)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, NamedTuple

import mujoco
import numpy as np
import pytest
from numba import njit
from numba.core.caching import NullCache

import gearcheck
from gearcheck.lumped.assembly import build_model, sum_outer
from gearcheck.lumped import compiled_steps
from gearcheck.lumped.compiled_steps import rk4_steps
from gearcheck.lumped.elements import ELEMENTS as LUMPED
from gearcheck.lumped.elements import base as lumped_base
from gearcheck.lumped.elements.base import Contribution, Row, Turning, compiled_group
from gearcheck.lumped.modal import modes as lumped_modes
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.elements import ELEMENTS as MUJOCO
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import fixed, member_joints
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.elements import Registry
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.kernel_hooks import Hook
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


# --------------------------------------------------------------------------- a kind whose forces move with time
class Beats(NamedTuple):
    """The compiled group: per beating spring, its two coordinates and (k, depth, omega)."""

    index: np.ndarray
    values: np.ndarray

    @classmethod
    def of(cls, elements) -> "Beats":
        return cls(np.array([[e.i, e.j] for e in elements], dtype=np.int64).reshape(-1, 2),
                   np.array([[e.k, e.depth, e.omega] for e in elements], dtype=float).reshape(-1, 3))


@njit(inline="always")
def beat_forces(beats, at):
    x, _, t, out = at
    for b in range(beats.index.shape[0]):
        i, j = beats.index[b, 0], beats.index[b, 1]
        f = beats.values[b, 0] * (1.0 + beats.values[b, 1] * np.cos(beats.values[b, 2] * t)) * (x[i] - x[j])
        out[i] -= f
        out[j] += f


@dataclass(frozen=True)
class BeatingTorsion(Turning):
    """A torsional spring k (1 + depth cos(omega t)) between coordinates i and j: its row of t = 0 in the model,
    :meth:`forces` in time."""

    compiled = Beats
    i: int
    j: int
    k: float
    depth: float
    omega: float
    rows: tuple[str, ...]

    def forces(self, t, q, v) -> np.ndarray:
        f = self.k * (1.0 + self.depth * np.cos(self.omega * np.asarray(t, dtype=float))) * (
            q[..., self.i] - q[..., self.j])
        out = np.zeros(np.shape(q))
        out[..., self.i] -= f
        out[..., self.j] += f
        return out


@dataclass(frozen=True)
class BeatingPart(Part):
    element: ClassVar[str] = "test-beating-torsion"
    a: str
    b: str
    stiffness: float
    depth: float
    omega: float


def beating_rows(part, build) -> Contribution:
    name = f"{part.a}-{part.b}.beating"
    element = BeatingTorsion(build.dofs(part.a, "theta"), build.dofs(part.b, "theta"), part.stiffness, part.depth,
                             part.omega, (name,))
    a = build.dofs.unit((part.a, "theta", 1.0), (part.b, "theta", -1.0))
    return Contribution([Row(name, "coupling", a, part.stiffness * (1.0 + part.depth), 0.0)], turning=[element])


def test_a_kernel_hook_calls_each_groups_function_in_order_and_skips_the_unregistered():
    """The hooks that the compiled kernels call: one call per group in the tuple's order, a threaded index passed
    from one to the next, a group with no function skipped; from plain Python the hook refuses to run."""
    forces, counts = Hook("forces-test"), Hook("count-test", threads=True)

    class One(NamedTuple):
        value: float

    class Two(NamedTuple):
        values: np.ndarray

    @njit
    def add_one(group, at):
        at[0][0] = at[0][0] * 10.0 + group.value

    @njit
    def count_two(group, at, n):
        for v in group.values:
            at[0][n] = v
            n += 1
        return n

    forces.register(One, add_one)
    forces.register(Two, add_one)  # never reached: Two has no ``value``, so a call would not compile
    forces.functions.pop(Two)
    counts.register(Two, count_two)
    each_force, each_count = forces.each, counts.each

    @njit
    def kernel(groups, out, slots):
        each_force(groups, (out,))
        return each_count(groups, (slots,), 1)

    out, slots = np.zeros(1), np.zeros(5)
    n = kernel((One(1.0), Two(np.array([7.0, 8.0])), One(2.0), Two(np.array([9.0]))), out, slots)
    assert out[0] == 12.0 and n == 4 and list(slots) == [0.0, 7.0, 8.0, 9.0, 0.0]
    with pytest.raises(TypeError, match="compiled hook"):
        each_force((One(1.0),), (out,))


def test_a_part_whose_forces_move_with_time_runs_in_the_compiled_steps(monkeypatch):
    """A kind of part whose stiffness beats in time, registered from this file alone (a description, its lumped
    element, its compiled group): the compiled RK4 steps run it through the kernel's hooks without a line of the
    kernel changed, and agree with the same RK4 taken stage by stage in Python (the reference, which calls
    ``forces``) to rounding, while the beat moves the response by far more."""
    monkeypatch.setitem(LUMPED._kinds, "test-beating-torsion", beating_rows)
    kernels = (rk4_steps, compiled_steps._rk4, compiled_steps._switching)  # each takes the groups' types: a cache
    indexes = [Path(kernel._cache._cache_file._index_path) for kernel in kernels]  # entry naming this module's
    for kernel in kernels:  # would break every later process that cannot import it (numba unpickles the whole
        monkeypatch.setattr(kernel, "_cache", NullCache())  # index of a function to load any of its entries)
    monkeypatch.setattr(lumped_base, "GROUPS", list(lumped_base.GROUPS))
    monkeypatch.setattr(lumped_base.FORCES, "functions", dict(lumped_base.FORCES.functions))
    compiled_group(Beats, beat_forces)
    spec = gearcheck.load("demo-3p")
    plain = gearcheck.simulate(spec, "lumped", duration=0.01, dt=2e-6)
    beating = BeatingPart("stage1.sun", "stage1.carrier", 2e5, 0.5, 2 * np.pi * 300.0)
    monkeypatch.setattr(TrainSpec, "parts", property(lambda s: train_parts(s) + (beating,)))
    compiled = gearcheck.simulate(spec, "lumped", duration=0.01, dt=2e-6)
    python = gearcheck.simulate(spec, "lumped", duration=0.01, dt=2e-6, method="rk4-stages")
    name = "stage1.sun.alpha"
    scale = np.max(np.abs(python[name]))
    assert np.max(np.abs(compiled[name] - python[name])) < 1e-9 * scale
    assert np.max(np.abs(compiled[name] - plain[name])) > 1e-3 * scale
    for index in indexes:
        assert not index.exists() or b"test_elements" not in index.read_bytes(), index


@pytest.mark.parametrize("chunk_bytes", [1 << 23, 8 * 12 * 12 * 7, 1])
def test_the_rows_matrices_are_their_outer_products_added_in_order(chunk_bytes):
    """K_b = sum_r k_r a_r a_r^T, stacked and reduced in chunks, is the sum taken one outer product at a time, to the
    bit (the zeros' signs too): the generated files written from it do not move when the chunks do.  Rows of no
    stiffness are left out, and their infinite coefficients with them."""
    rng = np.random.default_rng(7)
    rows = [Row(f"r{i}", "bearing", rng.standard_normal(12) * 10.0 ** rng.integers(-4, 4),
                float(rng.choice([0.0, 1e8 * rng.standard_normal()])), 0.0) for i in range(300)]
    rows.append(Row("loose", "contact", np.full(12, np.inf), 0.0, 0.0))
    one_at_a_time = np.zeros((12, 12))
    for r in rows:
        if r.stiffness:
            one_at_a_time += r.stiffness * np.outer(r.a, r.a)
    summed = sum_outer(rows, "stiffness", 12, chunk_bytes)
    assert np.array_equal(summed, one_at_a_time) and np.array_equal(np.signbit(summed), np.signbit(one_at_a_time))
    assert not sum_outer(rows, "damping", 12, chunk_bytes).any()
