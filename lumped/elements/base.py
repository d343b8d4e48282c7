"""What every lumped element is made of: rows on named coordinates, and what an element adds to the model.

Every elastic connection is a row (DESIGN.md 4): a scalar deflection delta = a . q with stiffness k and damping
c.  An element builds its rows on the coordinates of :class:`DofMap` (each member's :attr:`dofs
<gearcheck.train.spec.Member.dofs>`) and returns them in a :class:`Contribution`: constant rows, a driven mesh
row, turning elements whose rows move with time (:class:`Turning`), and a last step that places it in the
finished model.

A turning element's compiled form is its kind's *group*: a named tuple of arrays that the compiled RK4 steps
(:mod:`gearcheck.lumped.compiled_steps`) take, with its functions on the hooks :data:`FORCES` and
:data:`SWITCHING` (:mod:`gearcheck.shared.kernel_hooks`), registered by :func:`compiled_group` in the kind's
element file.  The steps call every kind's functions without naming one.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, ClassVar

import numpy as np

from gearcheck.shared.kernel_hooks import Hook


@dataclass(frozen=True)
class Row:
    """One elastic connection: deflection a . q, stiffness, damping, and the deflection at which it carries no load
    (a connection made with an offset: a misaligned pin's bearing); its force k (a . q - rest) + c a . q'."""

    name: str
    kind: str  # mesh | bearing | support | coupling | shaft | contact
    a: np.ndarray
    stiffness: float
    damping: float
    rest: float = 0.0


@dataclass
class DofMap:
    """Named coordinates: (member id, dof name) -> index."""

    names: list[tuple[str, str]] = field(default_factory=list)
    _index: dict[tuple[str, str], int] = field(default_factory=dict)

    def add(self, member: str, dofs) -> None:
        for d in dofs:
            self._index[(member, d)] = len(self.names)
            self.names.append((member, d))

    def __call__(self, member: str, dof: str) -> int:
        return self._index[(member, dof)]

    def __len__(self) -> int:
        return len(self.names)

    def of_member(self, member: str) -> list[int]:
        return [i for i, (m, _) in enumerate(self.names) if m == member]

    def labels(self) -> list[str]:
        return [f"{m}.{d}" for m, d in self.names]

    def unit(self, *entries: tuple[str, str, float]) -> np.ndarray:
        """A row with ``value`` on coordinate (member, dof) for each (member, dof, value)."""
        a = np.zeros(len(self.names))
        for member, dof, value in entries:
            a[self(member, dof)] += value
        return a

    def indices(self, member: str) -> np.ndarray:
        """The coordinates of ``member`` in the order of its dofs."""
        return np.array(self.of_member(member))


@dataclass(frozen=True)
class Build:
    """What an element reads of the train being assembled."""

    spec: object  # TrainSpec
    kin: object  # Kinematics
    dofs: DofMap
    mean_stiffness: dict  # mesh id -> its mean stiffness, N/m (the excitation's)

    @property
    def n(self) -> int:
        return len(self.dofs)


@dataclass
class Contribution:
    """What one part adds: constant rows, its driven mesh row (a, damping), turning elements, and a step that
    places it in the finished model (``LumpedModel -> LumpedModel``)."""

    rows: list[Row] = field(default_factory=list)
    mesh: tuple[np.ndarray, float] | None = None
    turning: list = field(default_factory=list)
    place: Callable | None = None


class Turning:
    """An element whose rows move with time (a radial coupling across turning frames, a cycloid-pin stage).

    The model holds its rows of one time (``rows``, placed at :attr:`placed_at`) for the modal and static
    analyses; the time solvers call :meth:`forces` at every stage instead.  The defaults are those of an element
    with no contact set, no rotating-frame load and rows that the model keeps at t = 0."""

    rows: tuple[str, ...]
    has_contacts: ClassVar[bool] = False  # rows that touch or not (their set is solved with the static state)
    smooth: ClassVar[bool] = True  # its forces are linear in the state (no contact switching)
    compiled: ClassVar[type | None] = None  # its compiled group (:func:`compiled_group`; None: it has none)
    static_load: ClassVar[np.ndarray | float] = 0.0  # what of its forces the model's static load holds
    words: ClassVar[str] = "rows that turn with time"  # what it is, in a sentence that refuses it

    @property
    def clock_speed(self) -> float | None:
        """The speed (rad/s) of the one clock its rows turn with, for the harmonic methods
        (:mod:`gearcheck.lumped.forced_response`), which then also take its :meth:`orbit_force` and its
        ``static_load``; None: they cannot take it."""
        return None

    def orbit_force(self, t) -> np.ndarray:
        """Its load that turns with its clock at time ``t``, beyond the static load the model holds."""
        raise NotImplementedError

    def forces(self, t, q, v) -> np.ndarray:
        """Generalized forces (time along axis 0 allowed) of its rows at times ``t``."""
        raise NotImplementedError

    def switching(self, t: float, q, v) -> tuple[np.ndarray, np.ndarray]:
        """Functions of one state (q, v) that change sign where its forces have a kink (a contact made or broken),
        for the solver to end its step there, and their rates of change; none for a smooth element."""
        return np.zeros(0), np.zeros(0)

    def without_frame_terms(self):
        """The element with the rotating frame's terms off."""
        return self

    def held_load(self, n: int) -> np.ndarray:
        """(n,) the static load the model keeps of it without the rotating frame's terms."""
        return np.zeros(n)

    def place(self, model, t: float, touching=None):
        """``model`` with this element's rows of time ``t`` (and the contact set ``touching``)."""
        return model

    def contact_set(self, model):
        """Which of its contacts touch in the configuration ``model`` is placed at (None: it has none)."""
        return None


# ------------------------------------------------------------------------- the compiled steps' groups
FORCES = Hook("forces")  # function(group, (x, u, t, out)): its forces at state (x, u), time t added into out
SWITCHING = Hook("switching", threads=True)  # function(group, (x, u, t, g, rate), n) -> the next n: see below
GROUPS: list[type] = []  # the compiled groups, in the order the steps add their forces
_COUNTS: dict[type, Callable] = {}


def compiled_group(group: type, forces, switching=None, count: Callable | None = None) -> None:
    """Register the compiled form of a kind of turning element: ``group`` a named tuple class whose
    ``group.of(elements)`` packs that kind's elements of a model (none: empty arrays of the same types), ``forces``
    its :data:`FORCES` function; where its forces have kinks, ``switching`` writes its switching functions
    (:meth:`Turning.switching`, in their order) into g and their rates into ``rate`` from index n on and returns
    the index after them, and ``count(group)`` says how many it writes."""
    GROUPS.append(group)
    FORCES.register(group, forces)
    if switching is not None:
        SWITCHING.register(group, switching)
        _COUNTS[group] = count


def switch_count(groups) -> int:
    """How many switching functions the groups write (:data:`SWITCHING`)."""
    return sum(_COUNTS[type(g)](g) for g in groups if type(g) in _COUNTS)
