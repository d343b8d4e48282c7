"""What a periodic steady state found by shooting on a solver's own runs records of the search, the same for both
solvers: each keeps its own state and finds it on its own runs."""

from __future__ import annotations

from dataclasses import dataclass

from gearcheck.shared.run_info import RunInfo


@dataclass(frozen=True, kw_only=True)
class Shooting:
    """period: the drive's period shot over (s); dt: the RK4 step, a whole fraction of it; steps: steps per period;
    method: how the fixed point was found ("anderson", ...); iterations: its steps; residual: the size of
    y(T) - y0 the search stopped at, relative to the first guess; runs: one-period runs taken; info: their work
    (the search's own wall time included)."""

    period: float
    dt: float
    steps: int
    method: str
    iterations: int
    residual: float
    runs: int
    info: RunInfo

    def words(self, solver: str) -> str:
        """How the state was found, as a report says it."""
        return (f"{solver}: shooting over its period {self.period:.6g} s, {self.runs} runs ({self.method}), "
                f"residual {self.residual:.1e}")
