"""What a time run is asked for, validated once for every solver.

``duration`` (s) is the simulated time, from ``start`` (s, the time of the first sample: a run that goes on from
where another ended, its state given; 0 otherwise); ``dt`` the fixed step (None: the solver's default from its
own highest natural frequency, :mod:`gearcheck.shared.stepping`); ``output_dt`` the sampling of the
result (None: every step); ``settle`` the start of the steady window (None: the larger of the load
ramp and half the duration); ``signals`` the names of the signals the result keeps (None: every one; a sweep keeps
those it reduces, and its runs then build no others).  Every solver turns a step into the same sample grid
(:meth:`RunSettings.grid`), so two runs at one step share their sample times exactly.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from gearcheck.shared.errors import LongRunWarning, SolverError

MAX_STEPS = 2e8  # about an hour of the slowest solver: longer runs are refused, not started
LONG_STEPS = 1e7  # a few minutes of the slowest solver: said before the run starts
MAX_OUTPUT_BYTES = 4 * 2**30  # what one run may hold in memory for its samples


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
    start: float = 0.0
    signals: tuple[str, ...] | None = None

    def __post_init__(self):
        _positive("duration", self.duration, False)
        _positive("dt", self.dt, True)
        _positive("output_dt", self.output_dt, True)
        if self.output_dt is not None and self.output_dt > self.duration:
            raise SolverError(f"output_dt={self.output_dt:g}: a sampling interval longer than the duration "
                              f"{self.duration:g} s; sample at least once in the run")
        if self.settle is not None and not (isinstance(self.settle, (int, float)) and 0 <= self.settle
                                            and math.isfinite(self.settle)):
            raise SolverError(f"settle must be a number of seconds >= 0, got {self.settle!r}")
        if isinstance(self.start, bool) or not isinstance(self.start, (int, float)) or not (
                0 <= self.start < math.inf):
            raise SolverError(f"start must be a number of seconds >= 0, got {self.start!r}")
        if self.signals is not None and not (isinstance(self.signals, tuple) and self.signals
                                             and all(isinstance(n, str) for n in self.signals)):
            raise SolverError(f"signals must be a tuple of signal names, got {self.signals!r}")

    def check_start(self, state, history, what: str) -> None:
        """Refuse a run from ``start`` > 0 without the ``state`` it goes on from (a solver's own start is the
        state at t = 0), or of a train with an operating ``history`` (which starts at 0); ``what`` names the model."""
        if self.start and state is None:
            raise SolverError(f"the {what} runs from start={self.start:g} s only from a state it is given (the run "
                              "it goes on from)")
        if self.start and history is not None:
            raise SolverError(f"the {what} runs its operating history from t = 0, not from start={self.start:g} s")

    def grid(self, dt: float) -> tuple[int, int]:
        """(steps, steps between samples) for the step ``dt``: the run ends on a sample at or just after
        ``duration``, and samples fall every ``output_dt`` rounded to whole steps."""
        every = 1 if self.output_dt is None else max(1, round(self.output_dt / dt))
        return every * max(1, math.ceil(self.duration / (dt * every) - 1e-9)), every

    def check_work(self, dt: float, columns: int, model: str) -> tuple[int, int]:
        """(steps, steps between samples) for the step ``dt``, refused before anything is allocated when the
        run would take more than ``MAX_STEPS`` steps or its ``columns`` sampled series more than
        ``MAX_OUTPUT_BYTES``, and a :class:`~gearcheck.shared.errors.LongRunWarning` past ``LONG_STEPS``; ``model``
        names the model in the messages."""
        steps = self.duration / dt
        if steps > MAX_STEPS:
            raise SolverError(f"duration {self.duration:g} s at the step {dt:.4g} s of the {model} is {steps:.3g} "
                              f"steps, more than the {MAX_STEPS:.0e} gearcheck runs in one go: shorten the duration")
        n_steps, every = self.grid(dt)
        size = (n_steps // every + 1) * columns * 8.0
        if size > MAX_OUTPUT_BYTES:
            raise SolverError(f"duration {self.duration:g} s sampled every {every * dt:.4g} s would hold "
                              f"{size / 2**30:.1f} GiB of series of the {model} (at most {MAX_OUTPUT_BYTES / 2**30:g} "
                              "GiB): sample less often (output_dt) or shorten the duration")
        if steps > LONG_STEPS:
            warnings.warn(f"duration {self.duration:g} s at the step {dt:.4g} s of the {model} is {steps:.3g} steps: "
                          "a run of minutes", LongRunWarning, stacklevel=2)
        return n_steps, every

    def settle_time(self, ramp: float) -> float:
        """Start of the steady window: ``settle``, or the larger of the load ramp and half the duration after
        ``start``."""
        return max(ramp, self.start + 0.5 * self.duration) if self.settle is None else self.settle
