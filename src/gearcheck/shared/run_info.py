"""What a run did and what it cost: one record for every stepper of either side.

A :class:`RunInfo` states the work of a run in the same fields whatever ran it, as scipy.integrate states
``nfev``: tests assert them, so a cost regression fails a unit test.  It reads as the mapping of the run's own
settings (``result.info["dt_s"]``), which reports state as the side has always stated them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class RunInfo(Mapping):
    """The work of one run.

    engine: the stepper that ran: "numba-rk4" and "python-rk4" (the reference model's compiled and stage-by-stage
    RK4), "scipy-RK45" and the like, "linear-rk4" (a linear model's RK4), "mujoco-compiled" and "mujoco-python"
    (the twin's step loop in C or in Python), "mujoco-step" (``mj_step``).
    steps: whole steps of the run's step (a scipy method's: of the output grid, each of its own steps at most that).
    stages: right-hand-side evaluations per step (4 for RK4; None where it varies: scipy's methods).
    rhs_calls: right-hand-side evaluations the stepping took (MuJoCo's: forward-dynamics passes, one per RK4 stage),
    a step split at a stiffness jump counting each of its sub-steps, one holding a located contact event its first
    try and its two parts.
    wall_s: seconds the stepping took.
    settings: the run's settings and findings as its reports state them; the record reads as this mapping."""

    engine: str
    steps: int
    stages: int | None
    rhs_calls: int
    wall_s: float
    settings: dict = field(default_factory=dict)

    def __getitem__(self, key: str):
        return self.settings[key]

    def __iter__(self):
        return iter(self.settings)

    def __len__(self) -> int:
        return len(self.settings)
