"""The excitation's sums and splines compiled (numba): one pass over the samples, no temporaries.

Both solvers sample the excitation at every stage time of a chunk of steps, and each sample is worth the bits it
had in numpy and scipy:

* :meth:`gearcheck.train.excitation.Excitation.transmission_error`: in numpy each harmonic or eccentricity term
  made some ten arrays of the chunk's size.  :func:`add_terms` does the same arithmetic in the same order (so the
  same bits: numpy's float64 cosine and sine are the C library's, as numba's are), a sample at a time.
* :class:`gearcheck.train.mesh_stiffness.EnergyMethodStiffness`, two cubic splines over the parts of a mesh cycle:
  scipy found each sample's interval by a binary search, and the two parts' masks and gathers cost as much again.
  :func:`spline_parts` finds the interval on the splines' even grid by one division, corrected against the
  breakpoints so that it is the interval scipy's search finds, and sums the cubic as scipy's ``PPoly`` does (so
  the same bits; a test compares them).
* :func:`gearcheck.train.helical_mesh.contact_line_length`, the lines of contact of a helical mesh: in numpy each
  sample's lines were a row of some eight arrays.  :func:`contact_line_shares` adds a sample's lines one by one,
  as numpy's ``sum`` does below 8 terms: the same bits below a total contact ratio of 7 (every shipped train's is
  below 5), and above it a sum of at most as many rounding errors as numpy's pairwise one.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from gearcheck.shared.compiled_cache import ensure_cache_folder

ensure_cache_folder(Path(__file__).parent)  # before the cached kernel below is defined


@njit(cache=True)
def add_terms(angle, scale, frequency, phase, harmonics, eccentric, e, de):
    """Add the transmission error terms to e and de (rows: samples; columns: meshes), at the nominal angles
    ``angle`` (the time a constant speed would take) and the clock's rates ``scale`` (one per sample).

    harmonics: rows (mesh, harmonic h, amplitude, phase phi) of e = amp cos(2 pi h (f angle - phase_mesh) + phi),
    f and phase_mesh the mesh's frequency and phase;
    eccentric: rows (mesh, amplitude, omega, beta0, dx, dy) of e = amp (cos(beta) dx + sin(beta) dy),
    beta = omega angle + beta0 (:meth:`~gearcheck.train.excitation.Excitation.transmission_error`)."""
    for row in range(harmonics.shape[0]):
        i = int(harmonics[row, 0])
        h, amp, phi = harmonics[row, 1], harmonics[row, 2], harmonics[row, 3]
        f, offset = frequency[i], phase[i]
        for j in range(angle.size):
            arg = 2 * math.pi * h * (f * angle[j] - offset) + phi
            e[j, i] += amp * math.cos(arg)
            de[j, i] -= amp * 2 * math.pi * h * f * scale[j] * math.sin(arg)
    for row in range(eccentric.shape[0]):
        i = int(eccentric[row, 0])
        amp, omega, beta0 = eccentric[row, 1], eccentric[row, 2], eccentric[row, 3]
        dx, dy = eccentric[row, 4], eccentric[row, 5]
        for j in range(angle.size):
            beta = omega * angle[j] + beta0
            c, s = math.cos(beta), math.sin(beta)
            e[j, i] += amp * (c * dx + s * dy)
            de[j, i] += amp * omega * scale[j] * (-s * dx + c * dy)


@njit(cache=True)
def spline_parts(x, split, breaks, coefficients, out):
    """out[j]: at x[j] (a fraction of a mesh cycle), the first of two piecewise cubics below ``split``, the second at
    and above it.  Part p has ``breaks[p]`` (evenly spaced, ascending) and ``coefficients[p]`` (4, breaks - 1), as
    scipy's ``PPoly`` holds them; it is evaluated as ``PPoly`` evaluates it, extrapolating: the interval i with
    breaks[i] <= x < breaks[i + 1] (the first below the first break, the last from the last interior break on),
    then sum_k c[3 - k, i] s^k, s = x - breaks[i], summed from k = 0 up with s^k by repeated products.  NaN gives
    NaN."""
    n = breaks.shape[1]
    scale = (n - 1) / (breaks[0, n - 1] - breaks[0, 0]), (n - 1) / (breaks[1, n - 1] - breaks[1, 0])
    for j in range(x.size):  # breaks[p, i], not a view of row p: a view per sample costs as much as the sum
        value = x[j]
        if value != value:
            out[j] = value
            continue
        p = 0 if value < split else 1
        i = 0
        if value > breaks[p, 0]:
            guess = (value - breaks[p, 0]) * scale[p]
            i = int(guess) if guess < n - 2 else n - 2
        while i > 0 and value < breaks[p, i]:
            i -= 1
        while i < n - 2 and value >= breaks[p, i + 1]:
            i += 1
        s = value - breaks[p, i]
        out[j] = ((coefficients[p, 3, i] + coefficients[p, 2, i] * s) + coefficients[p, 1, i] * (s * s)) + \
            coefficients[p, 0, i] * (s * s * s)


@njit(cache=True)
def contact_line_shares(xi, eps_a, eps_b, lines, out):
    """out[j]: the share of the face width in contact summed over the ``lines`` lines that entered u + i cycles ago
    (i = 0 .. lines - 1), u = xi[j] - floor(xi[j]) (np.mod(xi[j], 1.0) to the bit: both round the same fraction
    once): clip(v, 0, eps_b) - clip(v - eps_a, 0, eps_b) over eps_b at v = u + i, or (v < eps_a) for spur gears
    (eps_b = 0), clipped as numpy clips (NaN stays NaN), added one by one from 0."""
    for j in range(xi.size):
        u = xi[j] - np.floor(xi[j])  # a float: math.floor is an integer in numba
        total = 0.0
        for i in range(lines):
            v = u + i
            if eps_b > 0.0:
                total += (_clip(v, 0.0, eps_b) - _clip(v - eps_a, 0.0, eps_b)) / eps_b
            else:
                total += 1.0 if v < eps_a else 0.0
        out[j] = total


@njit(cache=True)
def _clip(v, low, high):
    """numpy's clip of a float: max(v, low), then min(., high), NaN kept."""
    if v != v:
        return v
    v = v if v > low else low
    return v if v < high else high


def compile_now() -> None:
    """Compile :func:`add_terms`, :func:`spline_parts` and :func:`contact_line_shares` (or load them from numba's
    cache) for the arrays the excitation passes them."""
    e = np.zeros((1, 1))
    add_terms(np.zeros(1), np.ones(1), np.zeros(1), np.zeros(1), np.zeros((1, 4)), np.zeros((0, 6)), e, e.copy())
    spline_parts(np.zeros(1), 0.5, np.array([[0.0, 1.0], [0.0, 1.0]]), np.zeros((2, 4, 1)), np.zeros(1))
    contact_line_shares(np.zeros(1), 1.5, 0.5, 2, np.zeros(1))
