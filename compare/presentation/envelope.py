"""A long series reduced to what a figure's pixel columns can show of it.

A report's panel is under a thousand pixels wide; a series of 92,600 samples drawn across it looks the same as
the smallest and the largest sample of each column, joined in their order, and drawing those takes milliseconds
instead of seconds.  Every peak and jump stays (a min/max envelope, not a subsampling); the numbers a report
states are computed from the full series, never from this.
"""

from __future__ import annotations

import numpy as np

COLUMNS = 2000  # columns across a panel: about twice the pixels of a report figure's widest panel


def envelope(x, y, log: bool = False, columns: int = COLUMNS) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)`` (``x`` increasing) reduced to the first and last sample and the smallest and largest ``y`` of
    each of ``columns`` equal spans of ``x`` (of ``log10(x)`` where ``log``: a logarithmic axis's columns), each
    sample at its own ``x``, in order; as given when that would not make it shorter."""
    x, y = np.asarray(x), np.asarray(y)
    if y.size <= 2 * columns + 2:
        return x, y
    position = np.log10(x) if log else x
    edges = np.linspace(position[0], position[-1], columns + 1)
    column = np.clip(np.searchsorted(edges, position, side="right") - 1, 0, columns - 1)
    starts = np.flatnonzero(np.r_[True, column[1:] != column[:-1]])
    ends = np.r_[starts[1:], y.size]
    order = np.lexsort((y, column))  # by column, and by value within each: a column's smallest first
    keep = np.unique(np.r_[0, order[starts], order[ends - 1], y.size - 1])
    return x[keep], y[keep]
