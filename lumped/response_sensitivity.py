"""Closed-form derivatives of the steady harmonic response to a design parameter xi.

A parameter enters through dM, dC, dK(theta) and dF, given as a :class:`ParametricProblem` of derivatives
(:func:`parameter_derivative`); the base frequencies are held.  Differentiating the harmonic equations:

* Fourier series method, L_h Q_h = A_h with L_h = K_mean - omega_h^2 M + i omega_h C, A_h = 2 (F_h - K_h q_mean),
  K_mean q_mean = F: dQ_h = L_h^-1 (dA_h - dL_h Q_h), dA_h = -2 (dK_h q_mean + K_h dq_mean),
  dq_mean = K_mean^-1 (dF - dK_mean q_mean).  With ``truncated`` the dA_h term is dropped, as in Yang, Chen &
  Wang (2018), Eqs. (14)-(15): exact only where the forcing -Delta K q_mean does not depend on xi.
* Harmonic balance, A X = R: dX = A^-1 (dR - dA X).

The amplitude of a coordinate moves as d|Q| = Re(conj(Q) dQ) / |Q| (Yang, Chen & Wang 2018, Eq. 13), which is
undefined where Q = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.sparse.linalg import splu

from gearcheck.lumped.fourier_response import (
    HarmonicResponse,
    ParametricProblem,
    dense_solve,
    fourier_series_response,
    hill_force,
    hill_operator,
    lattice_response,
    refined_solve,
)
from gearcheck.shared.blas import one_blas_thread


@dataclass(frozen=True)
class ResponseSensitivity:
    """A response and its derivative: ``derivative.mean`` is d mean / d xi, ``derivative.amplitudes`` dQ_h / d xi."""

    response: HarmonicResponse
    derivative: HarmonicResponse

    @property
    def d_modulus(self) -> np.ndarray:
        """d|Q_h| / d xi per harmonic and coordinate; nan where Q_h = 0."""
        Q, dQ = self.response.amplitudes, self.derivative.amplitudes
        return np.divide((Q.conj() * dQ).real, np.abs(Q), out=np.full(Q.shape, np.nan), where=np.abs(Q) > 0)


def parameter_derivative(problem: ParametricProblem, dM=None, dC=None, dK_of=None, dF=None,
                         dC_of=None, dF_of=None) -> ParametricProblem:
    """The derivatives of ``problem``'s data with respect to one parameter (None: independent of it)."""
    zero = np.zeros((problem.n, problem.n))
    return replace(problem, M=zero if dM is None else dM, C=zero if dC is None else dC,
                   K_of=(lambda theta: zero) if dK_of is None else dK_of, F=np.zeros(problem.n) if dF is None else dF,
                   C_of=dC_of, F_of=dF_of)


@one_blas_thread
def fourier_series_sensitivity(problem: ParametricProblem, derivative: ParametricProblem, harmonics,
                               truncated: bool = False) -> ResponseSensitivity:
    """d/d xi of :func:`fourier_series_response`; ``truncated``: Yang, Chen & Wang's Eq. (15), dA_h dropped."""
    response = fourier_series_response(problem, harmonics)
    q = response.mean
    dq = dense_solve(problem.K_mean, derivative.F_mean - derivative.K_mean @ q)
    dQ = []
    for h, w, Q in zip(response.harmonics, response.frequencies, response.amplitudes):
        dA = 0 if truncated else 2 * (derivative.force_harmonic(h) - derivative.stiffness_harmonic(h) @ q
                                      - problem.stiffness_harmonic(h) @ dq)
        dQ.append(dense_solve(problem.dynamic_stiffness(w), dA - derivative.dynamic_stiffness(w) @ Q))
    method = "Fourier series, dA dropped (Yang, Chen & Wang 2018, Eq. 15)" if truncated else "Fourier series"
    return ResponseSensitivity(response, replace(response, method=method, mean=dq,
                                                 amplitudes=np.reshape(dQ, response.amplitudes.shape)))


@one_blas_thread
def harmonic_balance_sensitivity(problem: ParametricProblem, derivative: ParametricProblem,
                                 orders) -> ResponseSensitivity:
    """d/d xi of :func:`harmonic_balance_response` on the lattice |h_k| <= H_k."""
    A = hill_operator(problem, orders)
    lu = splu(A)
    X = refined_solve(lu, A, hill_force(problem, orders))
    dX = refined_solve(lu, A, hill_force(derivative, orders) - hill_operator(derivative, orders) @ X)
    return ResponseSensitivity(lattice_response(problem, orders, X), lattice_response(problem, orders, dX))
