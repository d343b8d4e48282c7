"""What the cross-check asks of a model: its modes and a time run, both as named results.

The reference lumped model, the MuJoCo twin and the published 4-DOF models of Matejic et al.
(2021) and their twin all implement this; the cross-check engine knows nothing else about them.
"""

from __future__ import annotations

from typing import Protocol

from gearcheck.shared.modal import ModalResult
from gearcheck.shared.results import TimeResult
from gearcheck.shared.settings import RunSettings

DISPLAY = {"lumped": "lumped", "mujoco": "MuJoCo"}  # how reports write the built-in solvers' names


def display_name(solver: str) -> str:
    """How reports write a side's name: the built-in solvers as "lumped" and "MuJoCo", any other as it is."""
    return DISPLAY.get(solver, solver)


class Side(Protocol):
    solver: str  # how reports name it: "lumped", "mujoco", "as-published", ...
    references: tuple[str, ...]  # keys of gearcheck.shared.citations.REFERENCES its equations come from

    def modes(self) -> ModalResult:
        """Natural frequencies, mode shapes and types of the linear(ised) model."""

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        """A time run; ``progress`` is called with the fraction done."""

    def stable_step(self) -> float:
        """The largest fixed step its runs accept (s)."""
