"""Steady harmonic response of the linear(ised) model.

X(omega) = [K - omega^2 M + i omega (C + G)]^-1 F for a complex force amplitude F, the
response being Re(X e^{i omega t}).  The mesh stiffness is at its mean (the parametric
variation is left to the time solver).

``transmission_error_force`` builds the force of one harmonic of static transmission
error on a set of meshes, each with its mesh phase: a mesh of stiffness k carrying
e(t) = E cos(2 pi l (f t - gamma)) pushes the coordinates with a k E e^{-i 2 pi l gamma}
(Parker 2000, J. Sound Vib. 236, Eq. 7 with the phasing of Parker & Lin 2004).
"""

from __future__ import annotations

import numpy as np

from gearcheck.lumped.static import stiffness_with_rotation


def harmonic_response(model, omega: float, force: np.ndarray) -> np.ndarray:
    K = stiffness_with_rotation(model, model.excitation.mean_stiffness)
    dynamic = K - omega**2 * model.M + 1j * omega * (model.C + model.G)
    return np.linalg.solve(dynamic, force)


def transmission_error_force(model, harmonic: int, central: str, amplitude: float = 1e-6) -> np.ndarray:
    """Complex generalized force of harmonic ``harmonic`` of an STE of ``amplitude`` (m)
    on every mesh of the central member ``central``."""
    exc = model.excitation
    force = np.zeros(model.n, dtype=complex)
    for j, mesh in enumerate(model.spec.meshes):
        if mesh.central == central:
            phase = np.exp(-2j * np.pi * harmonic * exc.phase[j])
            force += model.mesh_rows[j] * exc.mean_stiffness[j] * amplitude * phase
    return force
