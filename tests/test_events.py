"""The contact events' numerics (:mod:`gearcheck.shared.events`) against closed forms: where the cubic Hermite
interpolant of a switching function over a step crosses zero, and which functions cannot cross at all."""

from __future__ import annotations

import numpy as np

from gearcheck.shared.events import APART, first_crossing, hermite


def test_a_crossing_is_found_where_the_cubic_crosses():
    """g = (1 - 2 theta)(1 + theta), a cubic through +1 and -2 with its slopes: its root is theta = 1/2; with a
    second function that stays positive, the first is the one crossed."""
    span = 1e-5
    g0, g1 = np.array([1.0, 3.0]), np.array([-2.0, 3.0])
    r0, r1 = np.array([-1.0, 0.0]) / span, np.array([-5.0, 0.0]) / span  # d/dtheta at 0 and 1, per second
    theta, which = first_crossing(g0, r0, g1, r1, span)
    assert which == 0 and abs(theta - 0.5) < 1e-12


def test_a_contact_made_and_broken_within_the_step_is_found_before_the_cubic_turns():
    """g = 1 - 4.5 theta + 4.5 theta^2 (theta (1 - theta) dips to 1 - 1.125 < 0): ends at 1 and 1, slopes -4.5 and
    +4.5; the first root, (3 - sqrt(1)) / 6 = 1/3, before the turning point at 1/2."""
    span = 2e-6
    theta, which = first_crossing(np.array([1.0]), np.array([-4.5 / span]), np.array([1.0]), np.array([4.5 / span]),
                                  span)
    assert which == 0 and abs(theta - 1.0 / 3.0) < 1e-12


def test_a_function_the_quick_test_passes_over_cannot_cross():
    """The quick test (both ends on one side, further from zero than APART times |R0| + |R1|) skips only
    functions whose cubic keeps one sign over the step: none of those it skips among 20,000 random ones (ends and
    slopes over twelve decades) and 5,000 at its edge (the nearer end within 1 % above the bound, the slopes
    pointing at zero) has a real root in [0, 1] or changes sign on a fine grid.  (The slope terms are at most 4/27
    = 0.148 of |R0| + |R1|; APART is 0.25.)"""
    rng = np.random.default_rng(7)
    n, edge = 20000, 5000
    G0, G1 = (rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-9, 3, n) for _ in range(2))
    R0, R1 = (rng.normal(size=n) * 10.0 ** rng.uniform(-9, 3, n) for _ in range(2))
    G1 = np.where(rng.random(n) < 0.8, np.abs(G1) * np.sign(G0), G1)  # mostly on one side, as in a step
    r0, r1 = (10.0 ** rng.uniform(-6, 0, edge) for _ in range(2))
    side = rng.choice([-1.0, 1.0], edge)
    near = APART * (r0 + r1) * (1.0 + 0.01 * rng.random(edge))
    G0 = np.concatenate([G0, side * near])
    G1 = np.concatenate([G1, side * near * (1.0 + rng.random(edge))])
    R0, R1 = np.concatenate([R0, -side * r0]), np.concatenate([R1, side * r1])  # down from G0, up into G1
    skipped = (G0 * G1 > 0.0) & (np.minimum(np.abs(G0), np.abs(G1)) > APART * (np.abs(R0) + np.abs(R1)))
    theta = np.linspace(0.0, 1.0, 2001)
    for i in np.flatnonzero(skipped):
        values = hermite(G0[i], R0[i], G1[i], R1[i], theta)
        assert np.all(values * G0[i] > 0.0), i
        a3, a2 = 2 * G0[i] + R0[i] - 2 * G1[i] + R1[i], -3 * G0[i] - 2 * R0[i] + 3 * G1[i] - R1[i]
        roots = np.roots([a3, a2, R0[i], G0[i]])
        real = roots[np.abs(roots.imag) < 1e-9].real
        assert not np.any((real >= 0.0) & (real <= 1.0)), (i, real)
        assert first_crossing(G0[i:i + 1], R0[i:i + 1], G1[i:i + 1], R1[i:i + 1], 1.0) == (2.0, -1)
    assert np.count_nonzero(skipped[:n]) > 3000 and np.all(skipped[n:])
