"""What a time run is asked for, validated once for every solver.

``duration`` (s) is the simulated time; ``dt`` the fixed step (None: the solver's default from its
own highest natural frequency, :mod:`gearcheck.shared.stepping`); ``output_dt`` the sampling of the
result (None: every step); ``settle`` the start of the steady window (None: the larger of the load
ramp and half the duration).  Every solver turns a step into the same sample grid
(:meth:`RunSettings.grid`), so two runs at one step share their sample times exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import SolverError


def _positive(name: str, value, optional: bool) -> None:
    if value is None and optional:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value > 0):
        raise SolverError(f"{name} must be a positive number of seconds, got {value!r}")


@dataclass(frozen=True)
class RunSettings:
    duration: float
    dt: float | None = None
    output_dt: float | None = None
    settle: float | None = None

    def __post_init__(self):
        _positive("duration", self.duration, False)
        _positive("dt", self.dt, True)
        _positive("output_dt", self.output_dt, True)
        if self.settle is not None and not (isinstance(self.settle, (int, float)) and 0 <= self.settle
                                            and math.isfinite(self.settle)):
            raise SolverError(f"settle must be a number of seconds >= 0, got {self.settle!r}")

    def grid(self, dt: float) -> tuple[int, int]:
        """(steps, steps between samples) for the step ``dt``: the run ends on a sample at or just after
        ``duration``, and samples fall every ``output_dt`` rounded to whole steps."""
        every = 1 if self.output_dt is None else max(1, round(self.output_dt / dt))
        return every * max(1, math.ceil(self.duration / (dt * every) - 1e-9)), every

    def settle_time(self, ramp: float) -> float:
        """Start of the steady window: ``settle``, or the larger of the load ramp and half the duration."""
        return max(ramp, 0.5 * self.duration) if self.settle is None else self.settle
