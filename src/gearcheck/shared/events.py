"""Contact events inside a fixed RK4 step: where a switching function crosses zero, and the drive of part of a step.

A contact law with a kink (a backlash's edge, a tooth pair or a pin making or breaking contact) costs a fixed-step
RK4 its order where the kink falls inside a step: the error of that step is of order h^2 instead of h^5.  Each
solver writes its contacts as switching functions g of its own state, which change sign at the kinks, with their
rates; over a step, :func:`first_crossing` finds the earliest crossing on the cubic Hermite interpolant of g
through the step's ends, the solver takes the step again to it, with the drive of that part
(:func:`samples_between`, quadratic in time from the step's three samples: an error of order h^3 in the drive of
the few steps that hold an event), and the rest of the step after it, itself checked (the functions just crossed
left out, :func:`crossed_together`: their kinks are behind); at most ``MAX_EVENTS`` a step
(the dense-output event location of Hairer, Norsett & Wanner 1993, sec. II.6, with RK4's end values and slopes).
Both solvers call these numerics; each locates its own events from its own state.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numba import njit

from gearcheck.shared.compiled_cache import ensure_cache_folder

ensure_cache_folder(Path(__file__).parent)  # before the cached kernels below are defined

MAX_EVENTS = 8  # contact events located within one (sub-)step; more are resolved to the step
MIN_FRACTION = 1e-9  # an event this close to a step's ends is taken as there
SIMULTANEOUS = 1e-6  # functions this close to zero (in fractions of the step, at their rate) cross together
APART = 0.25  # a function whose ends are both further than this times |R0| + |R1| from zero, on one side, does
# not cross: the cubic's slope terms theta (1 - theta)^2 R0 and -theta^2 (1 - theta) R1 are at most 4/27 of them


@njit(inline="always")
def hermite(g0, r0, g1, r1, theta):
    """The cubic through (0, g0) and (1, g1) with slopes r0 and r1 (per step) at theta."""
    t2 = theta * theta
    t3 = t2 * theta
    return (2 * t3 - 3 * t2 + 1) * g0 + (t3 - 2 * t2 + theta) * r0 + (3 * t2 - 2 * t3) * g1 + (t3 - t2) * r1


@njit(cache=True)
def first_crossing(g0, r0, g1, r1, span) -> tuple[float, int]:
    """The earliest fraction of the step at which a switching function crosses zero, on the cubic Hermite
    interpolant of its values g and rates r at the step's ends (length ``span``): where g changes sign, and where
    it does not but the cubic dips across zero and back (a contact made and broken within the step: the first
    crossing lies before the cubic's turning point); the root by the Illinois method, taken at the end of its last
    bracket past the crossing.  A function whose ends lie on one side, both further from zero than :data:`APART`
    times |R0| + |R1|, cannot cross and is passed over at once (a function away from its kink).  Returns (the
    fraction, the function; 2 and -1: none).  A step ended there starts
    within round-off of the kink, on either side: the caller takes that function as crossed for the rest of the
    step."""
    first, which = 2.0, -1
    for i in range(g0.size):
        G0, R0, G1, R1 = g0[i], r0[i] * span, g1[i], r1[i] * span
        if G0 * G1 > 0.0 and min(abs(G0), abs(G1)) > APART * (abs(R0) + abs(R1)):
            continue  # the cubic stays on G0's side: its slope terms are at most 4/27 of |R0| + |R1| on [0, 1]
        end = 1.0
        if not G0 * G1 < 0.0:
            a3, a2 = 2 * G0 + R0 - 2 * G1 + R1, -3 * G0 - 2 * R0 + 3 * G1 - R1
            end = 2.0
            if G0 * R0 < 0.0:  # heading for zero: does the cubic get there before it turns?
                disc = a2 * a2 - 3 * a3 * R0
                if disc >= 0.0:
                    for turn in ((-a2 - np.sqrt(disc)) / (3 * a3) if a3 != 0.0 else -R0 / (2 * a2),
                                 (-a2 + np.sqrt(disc)) / (3 * a3) if a3 != 0.0 else 2.0):
                        if 0.0 < turn < min(end, 1.0) and hermite(G0, R0, G1, R1, turn) * G0 < 0.0:
                            end = turn
            if end > 1.0:
                continue
        a, b, fa, fb = 0.0, end, G0, hermite(G0, R0, G1, R1, end)
        side = 0
        for _ in range(60):
            theta = (a * fb - b * fa) / (fb - fa)
            f = hermite(G0, R0, G1, R1, theta)
            if f * fb < 0.0:
                a, fa = b, fb
                side = 0
            else:
                fa = 0.5 * fa if side == 1 else fa
                side = 1
            b, fb = theta, f
            if f == 0.0 or abs(b - a) < 1e-12:
                break
        root = b if fb * G0 <= 0.0 else a
        if root < first:
            first, which = root, i
    return first, which


@njit(cache=True)
def crossed_together(g, rate, span, crossed) -> None:
    """At a located crossing of function ``crossed``: it, and every function within ``SIMULTANEOUS`` of the step's
    length of zero at its rate (the same contact on identical planets, crossing at the same instant to round-off),
    set to zero, at their kinks, so that the rest of the step does not locate them again."""
    g[crossed] = 0.0
    for i in range(g.size):
        if abs(g[i]) <= SIMULTANEOUS * abs(rate[i]) * span:
            g[i] = 0.0


@njit(cache=True)
def samples_between(source, a, b, target) -> None:
    """``target``'s three samples (axis 0) at the fractions a, (a + b)/2, b of a step whose samples at 0, 1/2 and 1
    are ``source`` (same shape), by quadratic interpolation; where a sample is infinite (a padded tooth pair) the
    nearest is taken."""
    flat_s, flat_t = source.reshape(3, -1), target.reshape(3, -1)
    for s in range(3):
        x = a + 0.5 * s * (b - a)
        w0, w1, w2 = 2.0 * (x - 0.5) * (x - 1.0), -4.0 * x * (x - 1.0), 2.0 * x * (x - 0.5)
        nearest = 0 if x < 0.25 else (1 if x < 0.75 else 2)
        for i in range(flat_t.shape[1]):
            y0, y1, y2 = flat_s[0, i], flat_s[1, i], flat_s[2, i]
            if np.isfinite(y0) and np.isfinite(y1) and np.isfinite(y2):
                flat_t[s, i] = w0 * y0 + w1 * y1 + w2 * y2
            else:
                flat_t[s, i] = flat_s[nearest, i]


@njit(inline="always")
def pair_switch(y, dy, g0, g1, g2, s, span):
    """(y - e_j, its rate) of a tooth pair whose gap e_j has the samples g0, g1, g2 over a step of length span, at
    sample s (0 or 2), y and dy the mesh's deflection and its rate; (-1, 0) for a pair out of the path at one of
    them."""
    if np.isfinite(g0) and np.isfinite(g1) and np.isfinite(g2):
        return y - (g0 if s == 0 else g2), dy - rate_from_samples(g0, g1, g2, s, span)
    return -1.0, 0.0


@njit(inline="always")
def rate_from_samples(y0, y1, y2, s, span):
    """The time derivative at sample s (0 or 2) of the quadratic through three samples of a step of length span."""
    return ((-3.0 * y0 + 4.0 * y1 - y2) if s == 0 else (y0 - 4.0 * y1 + 3.0 * y2)) / span
