"""Steady forced response of M q'' + C q' + K(t) q = F with periodic or quasi-periodic stiffness.

The stiffness is a function of one or two phase angles, each 2 pi-periodic, theta_k = omega_k t + theta_k0,
expanded once on a grid: K(t) = sum_h K_h e^{i omega_h t}, omega_h = h . omega, over the integer lattice h.
Two incommensurate frequencies need no common fundamental: the lattice is two-dimensional.  A response is
q(t) = mean + Re sum_h Q_h e^{i omega_h t} over one of each pair {h, -h} (the one with omega_h > 0), so |Q_h|
is each coordinate's amplitude at omega_h.

* :func:`fourier_series_response` -- the "Fourier series method" (Yang, Chen & Wang 2018, Eqs. 5-6), here with
  damping: the variation acts on the static deflection only, (K_mean - omega_h^2 M + i omega_h C) Q_h =
  2 (F_h - K_h q_mean) with K_mean q_mean = F_mean.  The product of the variation and the dynamic response is
  dropped.
* :func:`harmonic_balance_response` -- Hill's method / harmonic balance (Bolotin 1964; Nayfeh & Mook 1979): the
  whole parametric problem, balanced on the truncated lattice |h_k| <= H_k as one sparse linear system.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy import sparse
from scipy.linalg import lu_factor, lu_solve
from scipy.sparse.linalg import splu

from gearcheck.shared.blas import one_blas_thread
from gearcheck.shared.errors import SolverError


def grid_angles(points: int) -> np.ndarray:
    """The angles at which :class:`ParametricProblem` samples a clock's turn: 2 pi j / ``points``."""
    return 2 * np.pi * np.arange(points) / points


@dataclass(frozen=True)
class ParametricProblem:
    """M q'' + C q' + K_of(theta(t)) q = F, theta_k = omegas[k] t + phases[k], with K_of((theta_1[, theta_2]))
    an (n, n) matrix.  Its harmonics come from a ``grid``-point FFT per angle (over the axes only when
    ``separable``: K a sum of functions of one angle each, checked at one point; then ``grid`` may give each
    angle its own size); entries below ``tol`` times the largest are dropped, and every entry in a grid's upper
    half band must be below ``alias`` (default ``tol``) times it (else :class:`SolverError`): a stiffness with
    jumps (a rectangular mesh wave, a pin entering contact) has harmonics that fall as 1/h, and ``alias`` is
    then the aliasing error accepted on the harmonics kept.  ``C_of``, like ``K_of``, adds a periodic part to the
    damping C (rows that turn with a clock); the Fourier-series method keeps only its mean.  ``F_of`` likewise
    adds a periodic part to the force F (loads that turn with a clock)."""

    M: np.ndarray
    C: np.ndarray
    K_of: Callable[[tuple[float, ...]], np.ndarray]
    omegas: tuple[float, ...]
    F: np.ndarray
    phases: tuple[float, ...] | None = None
    grid: int | tuple[int, ...] = 64
    tol: float = 1e-9
    separable: bool = False
    alias: float | None = None
    C_of: Callable[[tuple[float, ...]], np.ndarray] | None = None
    F_of: Callable[[tuple[float, ...]], np.ndarray] | None = None

    def __post_init__(self):
        n = len(self.F)
        if not 1 <= len(self.omegas) <= 2:
            raise SolverError(f"omegas: one or two base frequencies, not {len(self.omegas)}")
        if np.shape(self.M) != (n, n) or np.shape(self.C) != (n, n):
            raise SolverError(f"M and C must be {n} x {n}, like F: got {np.shape(self.M)} and {np.shape(self.C)}")
        if self.phases is not None and len(self.phases) != len(self.omegas):
            raise SolverError(f"phases: {len(self.omegas)} angles, one per frequency, not {len(self.phases)}")
        if len(self.grids) != self.dim or (len(set(self.grids)) > 1 and not self.separable):
            raise SolverError(f"grid: one size, or one per angle of a separable stiffness, not {self.grid}")

    @property
    def grids(self) -> tuple[int, ...]:
        return tuple(np.broadcast_to(np.asarray(self.grid, dtype=int), (self.dim,)))

    @property
    def n(self) -> int:
        return len(self.F)

    @property
    def dim(self) -> int:
        return len(self.omegas)

    @cached_property
    def stiffness_harmonics(self) -> dict[tuple[int, ...], np.ndarray]:
        """{h: K_h} for the retained h, K_h the complex coefficient of e^{i omega_h t} (phases included)."""
        return self._harmonics(self.K_of, "stiffness")

    @cached_property
    def damping_harmonics(self) -> dict[tuple[int, ...], np.ndarray]:
        """{h: C_h} like :attr:`stiffness_harmonics`: C alone, or C plus the harmonics of ``C_of``."""
        return self._constant_plus(self.C, self.C_of, "damping")

    @cached_property
    def force_harmonics(self) -> dict[tuple[int, ...], np.ndarray]:
        """{h: F_h} like :attr:`stiffness_harmonics`: F alone, or F plus the harmonics of ``F_of``."""
        return self._constant_plus(self.F, self.F_of, "force")

    def _constant_plus(self, constant, of, what: str) -> dict[tuple[int, ...], np.ndarray]:
        out = {} if of is None else self._harmonics(of, what)
        zero = (0,) * self.dim
        out[zero] = out.get(zero, 0) + constant
        return out

    @property
    def F_mean(self) -> np.ndarray:
        return self.force_harmonics[(0,) * self.dim].real

    def _harmonics(self, of, what: str) -> dict[tuple[int, ...], np.ndarray]:
        h, K_hat = self._spectrum(of)
        scale = np.abs(K_hat).max()
        if scale == 0:
            return {}
        tail = np.abs(K_hat[(np.abs(h) >= np.asarray(self.grids) / 4).any(axis=1)]).max(initial=0)
        alias = self.tol if self.alias is None else self.alias
        if tail > alias * scale:
            raise SolverError(f"{what} harmonics not converged on a {self.grid}-point grid: the upper half band "
                              f"reaches {tail / scale:.2e} of the largest entry (accepted {alias:g}); refine the "
                              f"grid or accept more aliasing")
        K_hat[np.abs(K_hat) <= self.tol * scale] = 0
        phases = np.zeros(self.dim) if self.phases is None else np.asarray(self.phases, float)
        return {tuple(int(x) for x in hk): K_j * np.exp(1j * hk @ phases) for hk, K_j in zip(h, K_hat) if K_j.any()}

    def _spectrum(self, of) -> tuple[np.ndarray, np.ndarray]:
        """(h, X_h) rows over the FFT grid of the matrix function ``of``: the whole torus, or only its axes when
        separable, X(theta) = sum_k X_k(theta_k), whose mean is the sum of the axes' means less (d - 1) X(0)."""
        g, d = self.grids[0], self.dim
        angles = grid_angles(g)
        freq = np.fft.fftfreq(g, 1 / g).astype(int)
        if not self.separable or d == 1:
            samples = np.array([of(theta) for theta in itertools.product(angles, repeat=d)], dtype=float)
            shape = samples.shape[1:]
            K_hat = np.fft.fftn(samples.reshape((g,) * d + shape), axes=tuple(range(d))) / g**d
            return np.stack(np.meshgrid(*[freq] * d, indexing="ij"), -1).reshape(-1, d), K_hat.reshape((-1,) + shape)
        probe = 2 * np.pi * (np.arange(d) + 1) / min(self.grids)
        origin, corner = (np.asarray(of(theta), dtype=float) for theta in ((0.0,) * d, tuple(probe)))
        edges = [of(tuple(a * (j == k) for j, a in enumerate(probe))) for k in range(d)]
        if np.abs(corner - sum(edges) + (d - 1) * origin).max() > self.tol * np.abs([origin, corner]).max():
            raise SolverError("K_of or C_of is not separable (a sum of functions of one angle each): set "
                              "separable=False")
        axes, h = [], [np.zeros((1, d), int)]
        for k, g in enumerate(self.grids):
            angles = grid_angles(g)
            axes.append(np.fft.fft([of(tuple(a * (j == k) for j in range(d))) for a in angles], axis=0) / g)
            h.append(np.outer(np.fft.fftfreq(g, 1 / g).astype(int)[1:], np.eye(d, dtype=int)[k]))
        h = np.concatenate(h)
        mean = sum(part[0] for part in axes) - (d - 1) * origin
        return h, np.concatenate([[mean]] + [part[1:] for part in axes])

    def force_harmonic(self, h) -> np.ndarray:
        return self.force_harmonics.get(tuple(int(x) for x in h), np.zeros(self.n))

    def stiffness_harmonic(self, h) -> np.ndarray:
        return self.stiffness_harmonics.get(tuple(int(x) for x in h), np.zeros((self.n, self.n)))

    @property
    def K_mean(self) -> np.ndarray:
        return self.stiffness_harmonic((0,) * self.dim).real

    @property
    def C_mean(self) -> np.ndarray:
        return self.damping_harmonics[(0,) * self.dim].real

    def dynamic_stiffness(self, omega: float) -> np.ndarray:
        return self.K_mean - omega**2 * self.M + 1j * omega * self.C_mean


@dataclass(frozen=True)
class HarmonicResponse:
    """q(t) = mean + Re sum_j amplitudes[j] e^{i frequencies[j] t}; ``harmonics[j]`` is the lattice index h of
    row j and frequencies[j] = h . omega (rad/s)."""

    method: str
    truncation: str
    harmonics: np.ndarray
    frequencies: np.ndarray
    mean: np.ndarray
    amplitudes: np.ndarray

    def harmonic(self, h) -> np.ndarray:
        """Q_h, the complex amplitudes of harmonic h (an int on a one-frequency lattice)."""
        rows = np.flatnonzero((self.harmonics == np.atleast_1d(h)).all(axis=1))
        if not rows.size:
            raise KeyError(f"harmonic {h} is not among the {len(self.harmonics)} computed")
        return self.amplitudes[rows[0]]

    def at(self, t) -> np.ndarray:
        """q at the times ``t``: shape t.shape + (n,)."""
        phasors = np.exp(1j * np.multiply.outer(np.asarray(t, float), self.frequencies))
        return self.mean + (phasors @ self.amplitudes).real


def harmonic_lattice(orders) -> np.ndarray:
    """The harmonics kept, as (P, d) rows in C (lexicographic) order, so that row P-1-j is minus row j and the
    centre row is h = 0: the box |h_k| <= H_k for ``orders`` (H_1, ..., H_d), or the union of boxes for several
    (``((45, 4), (4, 45))``, a cross that holds each clock's high harmonics without all their products: the
    truncated index sets of quasi-periodic harmonic balance, Guskov & Thouverez 2012)."""
    boxes = np.atleast_2d(orders)
    return np.unique(np.concatenate([np.stack(np.meshgrid(*[np.arange(-H, H + 1) for H in box], indexing="ij"), -1)
                                     .reshape(-1, boxes.shape[1]) for box in boxes]), axis=0)


def positive_harmonics(problem: ParametricProblem, orders) -> np.ndarray:
    """One of each pair {h, -h} != 0 of the lattice of ``orders``, the one with h . omega > 0."""
    lattice = harmonic_lattice(_orders(problem, orders))
    half = lattice[len(lattice) // 2 + 1:]
    return half * np.where(half @ problem.omegas < 0, -1, 1)[:, None]


def hill_operator(problem: ParametricProblem, orders) -> sparse.csc_matrix:
    """Harmonic balance of M q'' + C(t) q' + K(t) q on the lattice of ``orders``, unknowns ordered (lattice point in
    C order, coordinate): block (h, g) is -omega_h^2 M [h = g] + i omega_g C_{h-g} + K_{h-g}."""
    lattice = harmonic_lattice(_orders(problem, orders))
    w = lattice @ problem.omegas
    A = sparse.kron(sparse.diags(-w**2), problem.M)
    for harmonics, rate in ((problem.stiffness_harmonics, None), (problem.damping_harmonics, sparse.diags(1j * w))):
        for m, X_m in harmonics.items():
            rows = _rows(lattice, lattice + m)  # block (g + m, g)
            kept = rows >= 0
            if kept.any():
                shift = sparse.csr_matrix((np.ones(kept.sum()), (rows[kept], np.flatnonzero(kept))),
                                          shape=(len(lattice),) * 2)
                A = A + sparse.kron(shift if rate is None else shift @ rate, X_m)
    return sparse.csc_matrix(A)


def hill_force(problem: ParametricProblem, orders) -> np.ndarray:
    """The right-hand side of :func:`hill_operator`: each force harmonic F_h on its lattice point."""
    lattice = harmonic_lattice(_orders(problem, orders))
    out = np.zeros((len(lattice), problem.n), dtype=complex)
    for h, F_h in problem.force_harmonics.items():
        row = _rows(lattice, np.array([h]))[0]
        if row >= 0:
            out[row] += F_h
    return out.ravel()


@one_blas_thread
def fourier_series_response(problem: ParametricProblem, harmonics) -> HarmonicResponse:
    """The Fourier series method (Yang, Chen & Wang 2018, Eqs. 5-6) with damping, for ``harmonics``: orders
    (H for one frequency, (H1, H2) for two: every h != 0 with |h_k| <= H_k) or explicit (m, d) rows h."""
    h = _harmonics(problem, harmonics)
    w = h @ problem.omegas
    q = dense_solve(problem.K_mean, problem.F_mean)
    Q = [dense_solve(problem.dynamic_stiffness(wj),
                     2 * (problem.force_harmonic(hj) - problem.stiffness_harmonic(hj) @ q))
         for hj, wj in zip(h, w)]
    return HarmonicResponse("Fourier series", _fs_truncation(problem, h), h, w, q, np.reshape(Q, (len(h), problem.n)))


@one_blas_thread
def harmonic_balance_response(problem: ParametricProblem, orders) -> HarmonicResponse:
    """Harmonic balance (Hill's method; Bolotin 1964, Nayfeh & Mook 1979) on the lattice |h_k| <= H_k,
    ``orders`` = H, (H1, H2) or a union of such boxes (:func:`harmonic_lattice`)."""
    A, b = hill_operator(problem, orders), hill_force(problem, orders)
    return lattice_response(problem, orders, refined_solve(splu(A), A, b))


def dense_solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`refined_solve` for a dense matrix."""
    return refined_solve(_DenseLU(A), A, b)


class _DenseLU:
    def __init__(self, A: np.ndarray):
        self.factors = lu_factor(A)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return lu_solve(self.factors, b)


def refined_solve(lu, A, b, steps: int = 2) -> np.ndarray:
    """x with A x = b from the factors ``lu`` of A, improved by ``steps`` of iterative refinement: a gear train's
    Hill matrix mixes stiffnesses of 1e10 N/m with inertia terms of 1e-3 and loses digits to its condition."""
    x = lu.solve(b)
    for _ in range(steps):
        x = x + lu.solve(b - A @ x)
    return x


def lattice_response(problem: ParametricProblem, orders, X: np.ndarray) -> HarmonicResponse:
    """The response whose two-sided lattice coefficients (ordered as in :func:`hill_operator`) are ``X``."""
    orders = _orders(problem, orders)
    X = X.reshape(-1, problem.n)
    h = positive_harmonics(problem, orders)
    truncation = (f"harmonic balance on the lattice {_lattice_text(orders)} of omega = {_omega_text(problem)}; "
                  f"stiffness entries below {problem.tol:g} of the largest dropped")
    return HarmonicResponse("harmonic balance", truncation, h, h @ problem.omegas, X[len(X) // 2].real,
                            2 * X[_rows(harmonic_lattice(orders), h)])


def _rows(lattice: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The row of each of ``points`` in ``lattice`` (C order), -1 where it is not there."""
    span = np.abs(lattice).max(axis=0)
    inside = np.all(np.abs(points) <= span, axis=1)
    dims = tuple(2 * span + 1)
    keys = np.ravel_multi_index(tuple((lattice + span).T), dims)  # ascending: C order
    wanted = np.ravel_multi_index(tuple((np.where(inside[:, None], points, 0) + span).T), dims)
    rows = np.minimum(np.searchsorted(keys, wanted), len(keys) - 1)
    return np.where(inside & (keys[rows] == wanted), rows, -1)


def _orders(problem: ParametricProblem, orders) -> tuple:
    """``orders`` checked: H (one clock), (H_1, H_2), or a union of such boxes ((H_1, H_2), (H_1', H_2'))."""
    boxes = np.atleast_2d(np.asarray(orders, dtype=int))
    if boxes.ndim != 2 or boxes.shape[1] != problem.dim or boxes.min() < 0:
        raise SolverError(f"orders: {problem.dim} non-negative truncation orders, one per frequency (or several "
                          f"such boxes), not {orders}")
    return tuple(int(H) for H in boxes[0]) if len(boxes) == 1 else tuple(tuple(int(H) for H in b) for b in boxes)



def _harmonics(problem: ParametricProblem, harmonics) -> np.ndarray:
    h = np.asarray(harmonics, dtype=int)
    if h.ndim < 2:
        return positive_harmonics(problem, h)
    if h.shape[1] != problem.dim or not np.abs(h).sum(axis=1).all():
        raise SolverError(f"harmonics: rows of {problem.dim} indices, none all zero")
    return h


def _fs_truncation(problem: ParametricProblem, h: np.ndarray) -> str:
    highest = ", ".join(str(H) for H in np.abs(h).max(axis=0, initial=0))
    return (f"Fourier series method on {len(h)} harmonics (highest |h_k|: {highest}) of omega = "
            f"{_omega_text(problem)}: the stiffness variation times the dynamic response is dropped, so side "
            f"frequencies and parametric resonances are missing; stiffness entries below {problem.tol:g} of the "
            f"largest dropped")


def _lattice_text(orders) -> str:
    return " and ".join(", ".join(f"|h{k + 1}| <= {H}" for k, H in enumerate(box)) for box in np.atleast_2d(orders))


def _omega_text(problem: ParametricProblem) -> str:
    return "(" + ", ".join(f"{w:.6g}" for w in problem.omegas) + ") rad/s"
