"""How a linear sweep through a resonance delays and lowers its peak: the envelope of a lightly damped mode.

A mode (natural frequency f_n, damping ratio zeta) forced by a tone whose frequency passes f_n at the constant rate
f' (Hz/s; an order k of a run-up at r rpm/s: f' = k r / 60) responds as z = A(t) e^{i phi(t)}.  Near resonance
the slowly varying amplitude obeys A' + (zeta w_n + i (w(t) - w_n)) A = const (w = 2 pi f; the classic problem of
Lewis 1932), whose solution from rest long before is, relative to the steady peak, with u = (w - w_n) / (zeta w_n)
and the dimensionless sweep rate eps = w' / (zeta w_n)^2 = f' / (2 pi zeta^2 f_n^2):

    A(u) / A_steady(0) = integral_0^inf exp(-(1 + i u) v + i eps v^2 / 2) dv
                       = sqrt(pi / (4 a)) w(i (1 + i u) / (2 sqrt a)),

a = -i eps / 2, w the Faddeeva function (exp(z^2) erfc(z) = w(i z)): derived here for this module.  Its largest
modulus over u is the swept peak: it comes u* zeta f_n later in frequency than the steady one (u* = 2 eps to first
order: twice the envelope's time constant 1 / (zeta w_n)) and lower by a factor 1 - eps^2 / 2 to second order.
The full oscillator (x'' + 2 zeta w_n x' + w_n^2 x = F cos phi) adds -zeta eps / 2 to that ratio at first order in
the sweep rate (Re A1 / A0 of its quasi-static expansion A = A0 + A1 + ..., A0 = F / D(w),
A1 = -i w' A0 (1 + 4 (w - i zeta w_n)^2 / D) / D, D = w_n^2 - w^2 + 2 i zeta w_n w; derived here), which
``peak_ratio`` includes; the terms left out are of order zeta eps^2 and zeta^2.  Valid for zeta << 1 and a sweep
slow against the mode (f' << f_n^2), for a forcing of constant amplitude.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import wofz

from gearcheck.shared.errors import GearcheckError


@dataclass(frozen=True)
class Passage:
    eps: float  # dimensionless sweep rate f' / (2 pi zeta^2 f_n^2)
    delay_hz: float  # the swept peak's excitation frequency minus the steady peak's (the sweep's sign)
    peak_ratio: float  # the swept peak over the steady peak, the full oscillator's first-order term included


def envelope(u, eps: float) -> np.ndarray:
    """A / A_steady(0) at the detunings ``u`` = (w - w_n) / (zeta w_n) of a sweep at ``eps`` > 0 (module)."""
    root_a = np.sqrt(eps / 2.0) * np.exp(-0.25j * np.pi)
    return 0.5 * np.sqrt(np.pi) / root_a * wofz(1j * (1.0 + 1j * np.asarray(u, dtype=float)) / (2.0 * root_a))


def passage(natural_hz: float, zeta: float, sweep_hz_per_s: float) -> Passage:
    """The delay and lowering of the peak of a mode of ``natural_hz`` and ``zeta`` swept at ``sweep_hz_per_s``
    (negative: downwards, the peak then comes at a lower frequency)."""
    if not (natural_hz > 0 and 0 < zeta < 1 and np.isfinite(sweep_hz_per_s) and sweep_hz_per_s != 0):
        raise GearcheckError(f"passage: needs natural_hz > 0, 0 < zeta < 1 and a nonzero sweep rate, got "
                             f"{natural_hz!r}, {zeta!r}, {sweep_hz_per_s!r}")
    eps = abs(sweep_hz_per_s) / (2.0 * np.pi * zeta ** 2 * natural_hz ** 2)
    grid = np.linspace(-3.0, 3.0 + 4.0 * eps, 2001)
    best = grid[np.argmax(np.abs(envelope(grid, eps)))]
    step = grid[1] - grid[0]
    found = minimize_scalar(lambda u: -abs(envelope(u, eps)), bounds=(best - step, best + step), method="bounded",
                            options={"xatol": 1e-10})
    return Passage(eps, float(np.sign(sweep_hz_per_s) * found.x * zeta * natural_hz),
                   float(-found.fun - 0.5 * zeta * eps))
