"""Mesh and bearing forces as MuJoCo computed them, read from its generalized forces.

MuJoCo keeps no per-tendon force, only the generalized spring and damper forces
(``qfrc_spring``, ``qfrc_damper``) that its tendons and joints add up to.  At a planet's three
joints (radial and tangential slides, hinge) only two things act: the planet's bearing (the slides'
joint stiffness and damping) and the planet's mesh tendons.  So:

* a probe copy of the model with every joint spring and damper and every coupling tendon removed
  gives, through ``mj_passive`` on the same state, the mesh tendons' generalized forces alone,
  J_P^T f at the planet joints (J_P: the mesh tendons' coefficients on those joints, which do not
  turn with the carrier and are constant);
* the mesh force F = -(f + g) with f = P (J_P^T f) for P the left inverse of J_P^T, and g the
  runner's own damping correction (``qfrc_applied`` = J^T g; see :mod:`gearcheck.mbd_models.runner`);
* the bearing force is minus the planet slides' joint forces: the model's generalized forces at the
  slides less the probe's.

Nothing here restates a force law: the dead band, the spring and the damper are MuJoCo's.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from gearcheck.shared.errors import SolverError


class ForceReader:
    """Reads mesh and bearing forces from MuJoCo's generalized forces for one compiled twin and its data."""

    def __init__(self, mb, d: mujoco.MjData):
        m = mb.model
        self.model, self.d = m, d
        self.n_mesh = len(mb.mesh_tendon)
        self.probe = copy.copy(m)
        self.probe.jnt_stiffness[:] = 0.0
        self.probe.dof_damping[:] = 0.0
        self.probe.tendon_stiffness[self.n_mesh:] = 0.0
        self.probe.tendon_damping[self.n_mesh:] = 0.0
        planets = [mid for mid, member in mb.spec.members.items() if member.is_planet]
        self.dofs = np.array([dof for mid in planets for dof in mb.dadr[mid]], dtype=int)
        self.slides = np.array([3 * i + axis for i in range(len(planets)) for axis in (0, 1)], dtype=int)
        J_P = mb.mesh_jacobian()[:, self.dofs]
        if np.linalg.matrix_rank(J_P) < self.n_mesh:
            raise SolverError(f"{mb.spec.name}: the mesh forces cannot be told apart at the planets' joints "
                              "(a planet meshes with more than three central gears)")
        self.P = np.linalg.pinv(J_P.T)
        # views kept once: the hot path only copies into them
        self._sum = np.empty(m.nv)
        self._spring, self._damper, self._applied = d.qfrc_spring, d.qfrc_damper, d.qfrc_applied
        n = self.n_mesh
        self._stiffness, self._probe_stiffness = m.tendon_stiffness[:n], self.probe.tendon_stiffness[:n]
        self._lengths, self._probe_lengths = m.tendon_lengthspring[:n], self.probe.tendon_lengthspring[:n]

    @property
    def width(self) -> int:
        return 3 * len(self.dofs)

    def sample(self, out: np.ndarray) -> None:
        """After ``mj_forward``: write the planet joints' (model, mesh-only, applied) generalized forces
        into ``out`` (one row of :attr:`width`), for :meth:`forces`.  Leaves the data's passive forces those
        of the probe (nothing that ``mj_RungeKutta`` reads)."""
        n, dofs, total = len(self.dofs), self.dofs, self._sum
        np.add(self._spring, self._damper, out=total)
        out[:n] = total[dofs]
        self._probe_stiffness[:] = self._stiffness
        self._probe_lengths[:] = self._lengths
        mujoco.mj_passive(self.probe, self.d)
        np.add(self._spring, self._damper, out=total)
        out[n:2 * n] = total[dofs]
        out[2 * n:] = self._applied[dofs]

    def forces(self, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mesh forces (n, n_mesh), bearing forces (n, n_bearing)) from rows written by :meth:`sample`."""
        n = len(self.dofs)
        model, mesh, applied = samples[:, :n], samples[:, n:2 * n], samples[:, 2 * n:]
        return -(mesh + applied) @ self.P.T, -(model - mesh)[:, self.slides]
