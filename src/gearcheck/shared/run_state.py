"""The state a run ended in, to start another from: a speed sweep's continuation.

A speed sweep runs its speeds in chains, each point started from its neighbour's final state instead of the
static start, so that it settles in a fraction of the time (Seydel 2010's natural-parameter continuation, applied
to the time-marched steady response).  Every excitation of the train runs on the nominal angle w t (mesh cycles,
transmission errors, eccentricities, order ripple), so the state at time t of a train turning at w carries over to
a train turning at r w at the time t / r, where every excitation has the same phase; the coordinates stay as they
are and their rates, moving along the same angles, scale with r (:meth:`RunState.at_speed`).  Each solver keeps its
own coordinates: the lumped model its deflections and their rates, the MuJoCo twin its joints' positions, the input
servo's reference angle and the joints' velocities.
"""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass

import numpy as np

from gearcheck.shared.errors import GearcheckError


@dataclass(frozen=True)
class RunState:
    """``t`` (s): where the run ended; ``coordinates`` (kept when the speed changes) and ``rates`` (scaled with it),
    in the solver's own order (:meth:`gearcheck.shared.side.Side.run_from`)."""

    t: float
    coordinates: tuple[np.ndarray, ...]
    rates: tuple[np.ndarray, ...]

    def at_speed(self, ratio: float) -> "RunState":
        """The same state on the train turning ``ratio`` times as fast, at the instant its drive has the same
        phase."""
        return RunState(self.t / ratio, self.coordinates, tuple(ratio * r for r in self.rates))

    def to_text(self) -> str:
        """Lossless JSON text of the state (the arrays' float64 bytes in base64): a cached sweep point's final state,
        from which a resumed chain goes on to the same bits."""
        def code(arrays):
            return [base64.b64encode(np.ascontiguousarray(a, dtype="<f8").tobytes()).decode("ascii") for a in arrays]

        return json.dumps({"t": self.t.hex(), "coordinates": code(self.coordinates), "rates": code(self.rates)})

    @classmethod
    def from_text(cls, text: str) -> "RunState":
        """The state written by :meth:`to_text`; refused (one line) where the text is not one."""
        try:
            data = json.loads(text)

            def arrays(key):
                return tuple(np.frombuffer(base64.b64decode(x, validate=True), dtype="<f8").copy() for x in data[key])

            return cls(float.fromhex(data["t"]), arrays("coordinates"), arrays("rates"))
        except (ValueError, TypeError, KeyError) as exc:
            raise GearcheckError(f"not a run's final state: {exc}") from None
