"""Natural frequencies and mode types, solver-neutral: the generalized eigenproblem, Lin & Parker's
mode types and multiplicities, and the result both solvers return.

K q = omega^2 M q.  Mode types (Lin & Parker 1999, 2000):

* rotational: the central members only rotate (in a helical train: and move axially, Eritenel & Parker's
  2009 rotational-axial modes) and all planets move alike;
* translational: the central members only translate in the transverse plane (degenerate pairs);
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

from gearcheck.shared.selection import chosen

ENERGY_TOLERANCE = 1e-8
DEGENERACY_TOLERANCE = 1e-7  # relative frequency difference grouped as one multiple frequency
RIGID_TOLERANCE = 1e-9  # omega^2 below this times the largest one is a rigid-body mode


STABILITY_TOLERANCE = 1e-8  # a growth rate below this times the largest |s| counts as none (round-off)
GROUPS = ("central_translation", "central_rotation", "planets")
UNITS = {"mode": "", "frequency_hz": "Hz", "type": "", "multiplicity": "", "growth_rate_1_s": "1/s", "stability": ""}


@dataclass
class ModalResult:
    """Natural frequencies (Hz), mode shapes, their types and where their kinetic energy lies.

    At speed (``speed_rpm`` set: the gyroscopic eigenproblem) the shapes are complex, ``growth`` holds
    each mode's Re(s) (1/s; > 0 grows) and ``stability`` "stable", "rigid", "divergence" (s real and
    positive) or "flutter" (s complex with a positive real part)."""

    train: str
    frequencies: np.ndarray
    shapes: np.ndarray  # (n_dof, n_modes)
    types: list[str]
    multiplicity: list[int]
    dof_labels: list[str]
    solver: str = "lumped"
    fractions: np.ndarray | None = None  # (n_modes, 3): kinetic energy shares of GROUPS
    speed_rpm: float | None = None
    growth: np.ndarray | None = None
    stability: list[str] | None = None

    def __len__(self) -> int:
        return len(self.frequencies)

    @property
    def stable(self) -> bool:
        return self.stability is None or not any(s in ("divergence", "flutter") for s in self.stability)

    def to_dataframe(self) -> pd.DataFrame:
        columns = {"mode": np.arange(1, len(self) + 1), "frequency_hz": self.frequencies, "type": self.types,
                   "multiplicity": self.multiplicity}
        if self.growth is not None:
            columns.update(growth_rate_1_s=self.growth, stability=self.stability)
        if self.fractions is not None:
            columns.update({f"energy_{g}": self.fractions[:, j] for j, g in enumerate(GROUPS)})
        frame = pd.DataFrame(columns)
        frame.attrs["units"] = {name: UNITS.get(name, "1") for name in frame.columns}
        return frame

    def plot(self, types=None):
        """A :class:`matplotlib.figure.Figure` (no pyplot) of the natural frequencies of the modes of ``types`` (a
        mode type or several; default: all), with their kinetic-energy shares."""
        from gearcheck.shared.figures import modes_figure

        present = list(dict.fromkeys(self.types))
        shown = present if types is None else chosen("types", types, present, f"a mode type of {self.train}")
        return modes_figure(self, shown)

    def to_dict(self) -> dict:
        modes = []
        for i, (f, t, m) in enumerate(zip(self.frequencies, self.types, self.multiplicity)):
            mode: dict[str, object] = {"mode": i + 1, "frequency_hz": float(f), "type": t, "multiplicity": m}
            if self.growth is not None and self.stability is not None:
                mode.update(growth_rate_1_s=float(self.growth[i]), stability=self.stability[i])
            if self.fractions is not None:
                mode["energy"] = {g: float(x) for g, x in zip(GROUPS, self.fractions[i])}
            modes.append(mode)
        out: dict[str, object] = {"train": self.train, "solver": self.solver, "unit": "Hz", "modes": modes}
        if self.speed_rpm is not None:
            out.update(speed_rpm=self.speed_rpm, stable=self.stable)
        return out


def generalized_modes(K: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of K x = w^2 M x: (frequencies in Hz, ascending; mass-normalised shapes)."""
    w2, shapes = sla.eigh(K, M)
    w2[np.abs(w2) < RIGID_TOLERANCE * np.max(np.abs(w2))] = 0.0
    return np.sqrt(np.clip(w2, 0.0, None)) / (2.0 * np.pi), shapes


def quadratic_eigenvalues(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of (M s^2 + D s + K) x = 0 through the first-order form y = (x, s x): (s, x), x over the
    coordinates.  D holds damping and gyroscopic terms, K every stiffness term (rotating frame included)."""
    s, y = np.linalg.eig(_first_order(M, D, K))
    return s, y[:M.shape[0]]


def _first_order(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> np.ndarray:
    """The matrix of y' = J y, y = (q, q'), of M q'' + D q' + K q = 0."""
    n = M.shape[0]
    return np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])


def settling_time(M: np.ndarray, D: np.ndarray, K: np.ndarray, fraction: float) -> float:
    """How long the slowest-decaying free vibration of M q'' + D q' + K q = 0 takes to fall to ``fraction``
    of its start: ln(1/fraction) / min(-Re s) over the elastic eigenvalues s (rigid ones, |s| below
    ``RIGID_TOLERANCE`` of the largest in the square, left out); infinite when one does not decay."""
    s, _ = quadratic_eigenvalues(M, D, K)
    s = s[np.abs(s) ** 2 > RIGID_TOLERANCE * np.max(np.abs(s)) ** 2]
    rate = float(np.min(-s.real)) if s.size else math.inf
    return math.log(1.0 / fraction) / rate if rate > 0 else math.inf


def slowest_decaying_mode(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> tuple[float, float]:
    """(natural frequency in Hz, damping ratio) of the elastic mode of M q'' + D q' + K q = 0 whose free
    vibration decays slowest (the one :func:`settling_time` waits for)."""
    f, zeta = damped_modes(M, D, K)
    slowest = np.argmin(zeta * f)
    return float(f[slowest]), float(zeta[slowest])


def damped_modes(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(natural frequencies |s| / 2 pi in Hz, damping ratios -Re s / |s|) of the elastic modes of
    M q'' + D q' + K q = 0, s = -zeta w +- i w sqrt(1 - zeta^2) (one of each pair; an overdamped mode's two real
    roots each), lowest first."""
    s, _ = quadratic_eigenvalues(M, D, K)
    s = s[_elastic_order(s)]
    return np.abs(s) / (2 * math.pi), -s.real / np.abs(s)


def driven_modes(M: np.ndarray, D: np.ndarray, K: np.ndarray, forces: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`damped_modes` of M q'' + D q' + K q = f e^(i w t), with how much each force column f drives each
    mode: (frequencies, damping ratios, drive of shape (modes, forces)).  The mode's part of the response at any
    one frequency is its right eigenvector x_r times eta_r = y_r^H (0, M^-1 f) / (y_r^H x_r) over a resonance
    factor, y_r the left eigenvector of the first-order form; ``drive`` is the square root of that part's kinetic
    energy, over the largest among the modes: 1 for the mode the force drives most, 0 for one it is orthogonal
    to, whatever the frequency (a planetary's mesh-phasing selection rules, Parker 2000: 0 to round-off).  Modes
    of one eigenvalue (a degenerate pair of a train at rest) are taken together, in their own basis, so the
    eigensolver's arbitrary basis for them does not hide a driven one."""
    n = M.shape[0]
    s, left, right = sla.eig(_first_order(M, D, K), left=True, right=True)
    kept = _elastic_order(s)
    B = np.concatenate([np.zeros(forces.shape, dtype=complex), np.linalg.solve(M, forces)])
    energy = np.zeros((kept.size, forces.shape[1]))
    start = 0
    while start < kept.size:  # a run of equal eigenvalues, solved together
        stop = start + 1
        while stop < kept.size and abs(s[kept[stop]] - s[kept[start]]) <= 1e-8 * abs(s[kept[start]]):
            stop += 1
        Y, X = left[:, kept[start:stop]], right[:, kept[start:stop]]
        velocity = (X @ np.linalg.solve(Y.conj().T @ X, Y.conj().T @ B))[n:]
        energy[start:stop] = np.real(np.einsum("ij,ik,kj->j", velocity.conj(), M, velocity))
        start = stop
    top = np.max(energy, axis=0)
    drive = np.sqrt(np.clip(energy, 0.0, None) / np.where(top > 0, top, 1.0))
    return np.abs(s[kept]) / (2 * math.pi), -s[kept].real / np.abs(s[kept]), drive


def _elastic_order(s: np.ndarray) -> np.ndarray:
    """Indices of the elastic eigenvalues among ``s`` (rigid ones, |s| below ``RIGID_TOLERANCE`` of the largest in
    the square, left out; one of each complex pair), lowest |s| first."""
    kept = np.flatnonzero((np.abs(s) ** 2 > RIGID_TOLERANCE * np.max(np.abs(s)) ** 2) & (s.imag >= 0))
    return kept[np.argsort(np.abs(s[kept]), kind="stable")]


def frequency_groups(frequencies: np.ndarray) -> list[list[int]]:
    """Indices of the modes sharing one (multiple) frequency, in order."""
    groups: list[list[int]] = []
    for i, f in enumerate(frequencies):
        if groups and _same(frequencies[groups[-1][0]], f):
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def multiplicities(frequencies: np.ndarray) -> list[int]:
    out = [0] * len(frequencies)
    for g in frequency_groups(frequencies):
        for i in g:
            out[i] = len(g)
    return out


def modal_assurance(M: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Mass-weighted modal assurance criterion (Allemang & Brown 1982), MAC_ij =
    |a_i^H M b_j|^2 / ((a_i^H M a_i)(b_j^H M b_j)), for shapes A (n, p) and B (n, q) in the same coordinates:
    1 for the same shape, 0 for M-orthogonal ones.  The mass weighting makes it independent of the units
    (m or rad) and of the choice of coordinates."""
    cross = np.abs(np.conj(A).T @ M @ B) ** 2
    norm_a = np.real(np.einsum("ip,ij,jp->p", np.conj(A), M, A))
    norm_b = np.real(np.einsum("iq,ij,jq->q", np.conj(B), M, B))
    return cross / np.outer(norm_a, norm_b)


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= DEGENERACY_TOLERANCE * max(abs(a), abs(b)) or (a == 0.0 and b == 0.0)


def energy_fractions(M: np.ndarray, shapes: np.ndarray, translation, rotation) -> np.ndarray:
    """(n_modes, 3): each mode's kinetic-energy shares phi_g^H M_gg phi_g / phi^H M phi in the central members'
    translations, their rotations, and the rest (planets); complex shapes allowed."""
    translation, rotation = list(translation), list(rotation)
    out = np.zeros((shapes.shape[1], 3))
    for j in range(shapes.shape[1]):
        phi = shapes[:, j]
        total = float(np.real(np.conj(phi) @ M @ phi))
        for k, idx in enumerate((translation, rotation)):
            out[j, k] = float(np.real(np.conj(phi[idx]) @ M[np.ix_(idx, idx)] @ phi[idx])) / total
        out[j, 2] = max(0.0, 1.0 - out[j, 0] - out[j, 1])
    return out


def mode_types(fractions: np.ndarray, frequencies: np.ndarray) -> list[str]:
    """Lin & Parker types from each mode's energy fractions (:func:`energy_fractions`): a share below
    ``ENERGY_TOLERANCE`` counts as zero, and a mode whose energy both the central translations and the
    central rotations hold is mixed."""
    types = []
    for (trans, rot, _), f in zip(fractions, frequencies):
        if f == 0.0:
            types.append("rigid")
        elif trans < ENERGY_TOLERANCE and rot < ENERGY_TOLERANCE:
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
    if translation is None:
        return ModalResult(train, frequencies, shapes, rigid_or_elastic(frequencies), multiplicities(frequencies),
                           list(dof_labels), solver)
    fractions = energy_fractions(M, shapes, translation, rotation)
    return ModalResult(train, frequencies, shapes, mode_types(fractions, frequencies), multiplicities(frequencies),
                       list(dof_labels), solver, fractions)


def speed_modal_result(train: str, solver: str, M: np.ndarray, D: np.ndarray, K: np.ndarray, dof_labels,
                       translation, rotation, speed_rpm: float) -> ModalResult:
    """The modes of M q'' + D q' + K q = 0 at a speed (D gyroscopic, K with the centripetal terms): one mode
    per conjugate pair s = sigma +/- i omega (a divergence's real pair +/- sigma counts once, by its growing
    root; a flutter quadruple twice), ordered by frequency; rigid modes (|s| below RIGID_TOLERANCE of the
    largest, in the square) have frequency and growth 0."""
    s, x = quadratic_eigenvalues(M, D, K)
    scale = np.max(np.abs(s))
    rigid = np.abs(s) ** 2 <= RIGID_TOLERANCE * scale**2
    real = np.abs(s.imag) <= STABILITY_TOLERANCE * scale
    keep = np.where(~rigid & ((s.imag > STABILITY_TOLERANCE * scale) | (real & (s.real > 0))))[0]
    n_rigid = (int(np.sum(rigid)) + 1) // 2
    s_kept = np.concatenate([np.zeros(n_rigid), s[keep]])
    shapes = np.concatenate([x[:, np.where(rigid)[0][:n_rigid]], x[:, keep]], axis=1)
    frequencies = np.abs(s_kept.imag) / (2.0 * np.pi)
    growth = np.where(np.abs(s_kept.real) <= STABILITY_TOLERANCE * scale, 0.0, s_kept.real)
    order = np.lexsort((growth, frequencies))
    frequencies, growth, shapes = frequencies[order], growth[order], shapes[:, order]
    stability = ["rigid" if f == 0 and g == 0 else "stable" if g <= 0 else "divergence" if f == 0 else "flutter"
                 for f, g in zip(frequencies, growth)]
    if translation is None:  # no central members to classify by
        return ModalResult(train, frequencies, shapes, rigid_or_elastic(frequencies), multiplicities(frequencies),
                           list(dof_labels), solver, None, speed_rpm, growth, stability)
    fractions = energy_fractions(M, shapes, translation, rotation)
    return ModalResult(train, frequencies, shapes, mode_types(fractions, frequencies), multiplicities(frequencies),
                       list(dof_labels), solver, fractions, speed_rpm, growth, stability)
