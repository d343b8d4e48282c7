"""Multi-start least squares: a non-convex fit run from several starting points, so that it does not stop on the
local minimum nearest its one start.

The starts are the given point, then a Latin hypercube (McKay, Beckman & Conover 1979) over the box of the bounds,
drawn with a fixed seed so that a fit is reproducible.  Each start is a bounded trust-region least-squares fit
(:func:`scipy.optimize.least_squares`).  Solutions whose every coordinate lies within ``SAME_MINIMUM`` of each other
are one minimum; the report gives the best, how many starts reached it, and every distinct minimum found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

SEED = 20261129
SAME_MINIMUM = 1e-2  # in the fitted coordinates (ln p: 1 %), far above the solvers' tolerances, far below a basin
AS_GOOD = 1.0  # a minimum whose chi^2 exceeds the best's by less fits the measurements as well (one standard deviation)


@dataclass
class Minimum:
    """A minimum the fits found: its point, its sum of squared residuals and how many starts reached it."""

    x: np.ndarray
    chi2: float
    starts: int


@dataclass
class MultiStart:
    """The fits from every start (``solutions``, scipy's results, in the order of ``starts``) and the distinct minima
    they reached, the best first."""

    starts: np.ndarray
    solutions: list
    minima: list[Minimum]

    @property
    def best(self):
        return min(self.solutions, key=lambda s: s.cost)

    @property
    def as_good(self) -> list[Minimum]:
        """The minima that fit as well as the best (chi^2 within :data:`AS_GOOD` of it), the best first: more than
        one, and the measurements do not decide between them."""
        return [m for m in self.minima if m.chi2 <= self.minima[0].chi2 + AS_GOOD]


def start_points(x0: np.ndarray, low: np.ndarray, high: np.ndarray, count: int) -> np.ndarray:
    """``x0`` and ``count - 1`` points of a Latin hypercube in the box [low, high] (seed :data:`SEED`)."""
    from scipy.stats import qmc  # here: importing scipy.stats costs 0.2 s, which only a fit needs

    design = qmc.LatinHypercube(d=len(x0), rng=SEED).random(count - 1)
    return np.vstack([x0, low + design * (high - low)])


def multistart(fun, x0: np.ndarray, low: np.ndarray, high: np.ndarray, count: int, **options) -> MultiStart:
    """Minimise sum fun(x)^2 within [low, high] from the :func:`start_points`; ``options`` go to least_squares."""
    starts = start_points(np.asarray(x0, float), low, high, count)
    solutions = [least_squares(fun, x, bounds=(low, high), **options) for x in starts]
    minima: list[Minimum] = []
    for s in sorted(solutions, key=lambda s: s.cost):
        for m in minima:
            if np.all(np.abs(s.x - m.x) <= SAME_MINIMUM):
                m.starts += 1
                break
        else:
            minima.append(Minimum(s.x, 2 * float(s.cost), 1))
    return MultiStart(starts, solutions, minima)
