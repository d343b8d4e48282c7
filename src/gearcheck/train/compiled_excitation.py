"""The static transmission error's sums compiled (numba): one pass over the samples per term, no temporaries.

:meth:`gearcheck.train.excitation.Excitation.transmission_error` samples e(t) and de/dt at every stage time of a
chunk of steps, for both solvers; in numpy each harmonic or eccentricity term made some ten arrays of the chunk's
size.  :func:`add_terms` does the same arithmetic in the same order (so the same bits: numpy's float64 cosine and
sine are the C library's, as numba's are), a sample at a time.
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


def compile_now() -> None:
    """Compile :func:`add_terms` (or load it from numba's cache) for the arrays the excitation passes it."""
    e = np.zeros((1, 1))
    add_terms(np.zeros(1), np.ones(1), np.zeros(1), np.zeros(1), np.zeros((1, 4)), np.zeros((0, 6)), e, e.copy())
