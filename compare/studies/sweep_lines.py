"""Which mesh-harmonic lines of a sweep table are read as numbers (the peaks, the order plots' lines).

A line is *measured* when the steady window resolves it (``resolved``) in a run that reached its steady state,
and it *counts* when, besides, its integration error estimate (its change when the step doubles) is within
``CONVERGED`` of its amplitude.  A sweep checks a subset of its points: a line at a point without the check is
read by the estimates of the same line at the checked points next to it in speed, below and above (the larger of
their relative estimates), which the subset places at least every eighth speed and at every resonance, where the
estimate changes fastest.  A line no check reaches (a sweep without checks) counts.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

CONVERGED = 0.1
LINE = ["sample", "solver", "quantity", "mesh", "order"]  # what makes a row the same line at another speed


def measured(rows):
    """The harmonic rows that the window resolves, from a run that reached its steady state."""
    return rows["resolved"].fillna(False).astype(bool) & (rows["steady"] != "none")


def counted(rows):
    """The measured rows that count in the peaks and plots: with a relative integration error estimate, their own
    or else their checked neighbours', within ``CONVERGED``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = rows["integration_error"] / rows["amplitude"].abs()
    relative = relative.where(~((rows["integration_error"] == 0) & (rows["amplitude"] == 0)), 0.0)
    if "speed_rpm" in rows and all(k in rows for k in LINE):
        relative = relative.fillna(_from_neighbours(rows, relative.where(measured(rows))))
    return measured(rows) & (relative.isna() | (relative <= CONVERGED))


def _from_neighbours(rows, relative) -> pd.Series:
    """For every row, the larger of the relative estimates of the same line at the nearest checked speeds below and
    above it (NaN where there is none)."""
    frame = rows[LINE + ["speed_rpm"]].assign(relative=relative).sort_values("speed_rpm", kind="stable")
    line = frame.groupby(LINE, sort=False, dropna=False)["relative"]
    return pd.concat([line.ffill(), line.bfill()], axis=1).max(axis=1).reindex(rows.index)
