"""When a run has diverged: one rule for both solvers.

A run diverges when its state stops being finite or a mesh deflection grows past ``FACTOR`` times its
static scale (the largest static deflection plus the backlash, and 1 µm).  No gear mesh deflects a
thousand times more than its load does: what does is an unstable step, an undamped resonance, or a train
that is not stable at that speed.  The error gives the first sample at which it happened.
"""

from __future__ import annotations

import numpy as np

from gearcheck.shared.errors import DivergenceError

FACTOR = 1e3


def deflection_scale(static_deflection, half_backlash) -> float:
    return float(np.max(np.abs(static_deflection), initial=0.0) + np.max(half_backlash, initial=0.0) + 1e-6)


def check(t: np.ndarray, deflection: np.ndarray, scale: float, model: str) -> None:
    """Raise :class:`DivergenceError` at the first of the times ``t`` whose mesh ``deflection`` row is not
    finite or exceeds ``FACTOR * scale``."""
    bad = ~(np.max(np.abs(deflection), axis=1, initial=0.0) <= FACTOR * scale)  # NaN compares False: bad
    if np.any(bad):
        i = int(np.argmax(bad))
        worst = np.max(np.abs(deflection[i]))
        raise DivergenceError(float(t[i]), f"{model}: a mesh deflection of {worst:.3g} m is over {FACTOR:g} times its "
                                           f"static scale {scale:.3g} m (an unstable step, an undamped resonance, or "
                                           "a train that is not stable at this speed)")
