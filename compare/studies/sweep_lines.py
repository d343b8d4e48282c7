"""Which mesh-harmonic lines of a sweep table are read as numbers (the peaks, the order plots' lines).

A line is *measured* when the steady window resolves it (``resolved``) in a run that reached its steady state,
and it *counts* when, besides, its integration error estimate (its change when the step doubles) is within
``CONVERGED`` of its amplitude, or was not estimated.
"""

from __future__ import annotations

CONVERGED = 0.1


def measured(rows):
    """The harmonic rows that the window resolves, from a run that reached its steady state."""
    return rows["resolved"].fillna(False).astype(bool) & (rows["steady"] != "none")


def counted(rows):
    """The measured rows that count in the peaks and plots: (where checked) with an integration error estimate
    within ``CONVERGED`` of the amplitude."""
    error = rows["integration_error"]
    return measured(rows) & (error.isna() | (error <= CONVERGED * rows["amplitude"]))
