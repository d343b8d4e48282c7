"""Natural frequencies and mode types, solver-neutral: the generalized eigenproblem, Lin & Parker's
mode types and multiplicities, and the result both solvers return.

K q = omega^2 M q.  Mode types (Lin & Parker 1999, 2000):

* rotational: the central members only rotate and all planets move alike;
* translational: the central members only translate (degenerate pairs);
* planet: the central members do not move (multiplicity N - 3);
* rigid: zero frequency (a free rotation);
* mixed: none of these (unequal spacing, couplings between stages ...);
* elastic: a non-zero frequency of a model that has no central members to classify by.

The classification reads the mode's kinetic-energy fractions in central translation, central
rotation and the rest; a fraction below ``ENERGY_TOLERANCE`` counts as zero.  Zero amplitude of a
group is a physical statement (the sun, ring and carrier do not translate / do not turn), so the
types do not depend on a solver's choice of coordinates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
import scipy.linalg as sla

ENERGY_TOLERANCE = 1e-8
DEGENERACY_TOLERANCE = 1e-7  # relative frequency difference grouped as one multiple frequency
RIGID_TOLERANCE = 1e-9  # omega^2 below this times the largest one is a rigid-body mode


@dataclass
class ModalResult:
    """Natural frequencies (Hz), mass-normalised mode shapes and their types."""

    train: str
    frequencies: np.ndarray
    shapes: np.ndarray  # (n_dof, n_modes)
    types: list[str]
    multiplicity: list[int]
    dof_labels: list[str]
    solver: str = "lumped"

    def __len__(self) -> int:
        return len(self.frequencies)

    def to_dataframe(self) -> pd.DataFrame:
        return pd.DataFrame({"mode": np.arange(1, len(self) + 1), "frequency_hz": self.frequencies,
                             "type": self.types, "multiplicity": self.multiplicity})

    def to_dict(self) -> dict:
        return {
            "train": self.train, "solver": self.solver, "unit": "Hz",
            "modes": [{"mode": i + 1, "frequency_hz": float(f), "type": t, "multiplicity": m}
                      for i, (f, t, m) in enumerate(zip(self.frequencies, self.types, self.multiplicity))],
        }


def generalized_modes(K: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of K x = w^2 M x: (frequencies in Hz, ascending; mass-normalised shapes)."""
    w2, shapes = sla.eigh(K, M)
    w2[np.abs(w2) < RIGID_TOLERANCE * np.max(np.abs(w2))] = 0.0
    return np.sqrt(np.clip(w2, 0.0, None)) / (2.0 * np.pi), shapes


def quadratic_eigenvalues(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of (M s^2 + D s + K) x = 0 through the first-order form y = (x, s x): (s, x), x over the
    coordinates.  D holds damping and gyroscopic terms, K every stiffness term (rotating frame included)."""
    n = M.shape[0]
    J = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    s, y = np.linalg.eig(J)
    return s, y[:n]


def settling_time(M: np.ndarray, D: np.ndarray, K: np.ndarray, fraction: float) -> float:
    """How long the slowest-decaying free vibration of M q'' + D q' + K q = 0 takes to fall to ``fraction``
    of its start: ln(1/fraction) / min(-Re s) over the elastic eigenvalues s (rigid ones, |s| below
    ``RIGID_TOLERANCE`` of the largest in the square, left out); infinite when one does not decay."""
    s, _ = quadratic_eigenvalues(M, D, K)
    s = s[np.abs(s) ** 2 > RIGID_TOLERANCE * np.max(np.abs(s)) ** 2]
    rate = float(np.min(-s.real)) if s.size else math.inf
    return math.log(1.0 / fraction) / rate if rate > 0 else math.inf


def multiplicities(frequencies: np.ndarray) -> list[int]:
    groups: list[list[int]] = []
    for i, f in enumerate(frequencies):
        if groups and _same(frequencies[groups[-1][0]], f):
            groups[-1].append(i)
        else:
            groups.append([i])
    out = [0] * len(frequencies)
    for g in groups:
        for i in g:
            out[i] = len(g)
    return out


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= DEGENERACY_TOLERANCE * max(abs(a), abs(b)) or (a == 0.0 and b == 0.0)


def mode_types(M: np.ndarray, shapes: np.ndarray, frequencies: np.ndarray, translation, rotation) -> list[str]:
    """Lin & Parker types from each mode's kinetic-energy fractions phi_g' M_gg phi_g / phi' M phi
    in the central members' translations and rotations (index lists over the coordinates)."""
    translation, rotation = list(translation), list(rotation)
    types = []
    for j, f in enumerate(frequencies):
        if f == 0.0:
            types.append("rigid")
            continue
        phi = shapes[:, j]
        total = phi @ M @ phi
        trans = phi[translation] @ M[np.ix_(translation, translation)] @ phi[translation] / total
        rot = phi[rotation] @ M[np.ix_(rotation, rotation)] @ phi[rotation] / total
        if trans < ENERGY_TOLERANCE and rot < ENERGY_TOLERANCE:
            types.append("planet")
        elif trans < ENERGY_TOLERANCE:
            types.append("rotational")
        elif rot < ENERGY_TOLERANCE:
            types.append("translational")
        else:
            types.append("mixed")
    return types


def rigid_or_elastic(frequencies: np.ndarray) -> list[str]:
    """The types of a model without central members to classify by: rigid (0 Hz) or elastic."""
    return ["rigid" if f == 0 else "elastic" for f in frequencies]


def modal_result(train: str, solver: str, K: np.ndarray, M: np.ndarray, dof_labels, translation=None,
                 rotation=None) -> ModalResult:
    """Solve K x = w^2 M x and classify: Lin & Parker types over the central members' translation and
    rotation coordinates when they are given, rigid/elastic otherwise."""
    frequencies, shapes = generalized_modes(K, M)
    types = (rigid_or_elastic(frequencies) if translation is None
             else mode_types(M, shapes, frequencies, translation, rotation))
    return ModalResult(train, frequencies, shapes, types, multiplicities(frequencies), list(dof_labels), solver)
