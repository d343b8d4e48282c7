"""Steady harmonic response of the linear(ised) model.

X(omega) = [K - omega^2 M + i omega (C + G)]^-1 F for a complex force amplitude F, the
response being Re(X e^{i omega t}).  The mesh stiffness is at its mean (the parametric
variation is left to the time solver).

``phased_force`` is the force of one harmonic l of per-mesh force amplitudes, each mesh at its mesh phase
gamma; ``transmission_error_force`` that of one harmonic of static transmission error on a set of meshes: a mesh
of stiffness k carrying e(t) = E cos(2 pi l (f t - gamma)) pushes the coordinates with a k E e^{-i 2 pi l gamma}
(Parker 2000, J. Sound Vib. 236, Eq. 7 with the phasing of Parker & Lin 2004).
"""

from __future__ import annotations

import numpy as np

from gearcheck.lumped.static import stiffness_with_rotation


def harmonic_response(model, omega: float, force: np.ndarray) -> np.ndarray:
    K = stiffness_with_rotation(model, model.excitation.mean_stiffness)
    dynamic = K - omega**2 * model.M + 1j * omega * (model.C + model.G)
    return np.linalg.solve(dynamic, force)


def phased_force(model, harmonic: int, amplitudes) -> np.ndarray:
    """Complex generalized force sum_m a_m F_m e^{-i 2 pi l gamma_m} of harmonic l = ``harmonic`` of the mesh
    force amplitudes F_m (N, complex, one per mesh), each mesh at its mesh phase gamma_m."""
    return model.mesh_rows.T @ (np.asarray(amplitudes) * np.exp(-2j * np.pi * harmonic * model.excitation.phase))


def transmission_error_force(model, harmonic: int, central: str, amplitude: float = 1e-6) -> np.ndarray:
    """Complex generalized force of harmonic ``harmonic`` of an STE of ``amplitude`` (m)
    on every mesh of the central member ``central``."""
    on = np.array([mesh.central == central for mesh in model.spec.meshes])
    return phased_force(model, harmonic, np.where(on, model.excitation.mean_stiffness * amplitude, 0.0))
