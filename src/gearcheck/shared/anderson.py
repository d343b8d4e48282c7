"""Anderson acceleration of a fixed-point iteration z <- P(z) (Walker & Ni 2011, type II), shared by both sides'
shooting for a periodic steady state."""

from __future__ import annotations

import math

import numpy as np

ANDERSON_DEPTH = 10  # differences kept


def anderson(P, z: np.ndarray, tolerance: float, max_runs: int, depth: int = ANDERSON_DEPTH):
    """Anderson acceleration of z <- P(z), keeping ``depth`` differences: (z, residual, iterations); the residual
    max |P(z) - z| of the z returned, which is the first within ``tolerance`` or the last of ``max_runs`` calls of P.
    On an affine map it is a Krylov method (GMRES in exact arithmetic)."""
    xs, fs = [], []
    residual = math.inf
    for iteration in range(max_runs):
        f = P(z) - z
        residual = float(np.max(np.abs(f)))
        if residual <= tolerance:
            return z, residual, iteration
        xs, fs = (xs + [z])[-depth - 1:], (fs + [f])[-depth - 1:]
        if len(xs) > 1:
            dx, df = np.diff(np.array(xs), axis=0).T, np.diff(np.array(fs), axis=0).T
            gamma = np.linalg.lstsq(df, f, rcond=None)[0]
            z = z + f - (dx + df) @ gamma
        else:
            z = z + f
    return z, residual, max_runs
