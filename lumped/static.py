"""Static deflection and load sharing under the mean operating load.

(K_b + K_m,mean + K_frame) q = F_static + b_in T_in + b_out T_out + sum_m a_m k_m b_m,

where the last term shifts every mesh with backlash to its loaded flank (dead zone
f(delta) = delta - b for delta > b).  Meshes found out of contact are dropped and the
solve repeated (active set).  With a torque-driven input the stiffness is singular (a
rigid-body rotation) and the minimum-norm solution is taken.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from gearcheck.shared.contact_laws import deadzone
from gearcheck.shared.errors import SolverError


@dataclass
class StaticResult:
    q: np.ndarray
    mesh_ids: list[str]
    mesh_deflection: np.ndarray  # m
    mesh_force: np.ndarray  # N
    in_contact: np.ndarray  # bool
    row_names: list[str]
    row_forces: np.ndarray  # N or N·m of every bearing/support/coupling row

    def load_sharing(self, spec) -> pd.DataFrame:
        """Mesh force of each planet over the mean of its central gear's meshes."""
        rows = []
        for mesh, force in zip(spec.meshes, self.mesh_force):
            same = [f for m, f in zip(spec.meshes, self.mesh_force) if m.central == mesh.central]
            rows.append({"mesh": mesh.id, "central": mesh.central, "planet": mesh.planet, "force_n": force,
                         "sharing": force / np.mean(same)})
        return pd.DataFrame(rows)


def stiffness_with_rotation(model, k_mesh: np.ndarray) -> np.ndarray:
    return model.K_b + model.K_mesh(k_mesh) + model.K_frame


def mean_load(model, load_scale: float = 1.0) -> np.ndarray:
    """Constant generalized forces: centripetal planet loads plus the mean torques."""
    kin = model.kin
    t_in = kin.input_torque if model.spec.operating.input_shaft_stiffness is None else 0.0
    return model.F_static + load_scale * (model.b_input * t_in + model.b_output * kin.output_torque)


def static_solution(model, load_scale: float = 1.0) -> StaticResult:
    """Static equilibrium at mean stiffness, torques scaled by ``load_scale``."""
    k = model.excitation.mean_stiffness
    half_backlash = 0.5 * model.excitation.backlash
    F = mean_load(model, load_scale)
    active = np.ones(len(k), dtype=bool)
    for _ in range(len(k) + 1):
        k_act = np.where(active, k, 0.0)
        K = stiffness_with_rotation(model, k_act)
        # meshes are built so that the nominal load compresses them: contact on delta > b
        q = np.linalg.lstsq(K, F + model.mesh_rows.T @ (k_act * half_backlash), rcond=None)[0]
        delta = model.mesh_rows @ q
        contact = delta > half_backlash
        if np.array_equal(contact, active) or not np.any(half_backlash):
            break
        active = contact
    else:  # pragma: no cover - the active set settles in at most n_mesh passes
        raise SolverError("static solution: the contact set did not converge")
    force = k * deadzone(delta, half_backlash)
    row_forces = np.array([r.stiffness * (float(r.a @ q) - r.rest) for r in model.rows])
    return StaticResult(q, [m.id for m in model.spec.meshes], delta, force, contact,
                        [r.name for r in model.rows], row_forces)

