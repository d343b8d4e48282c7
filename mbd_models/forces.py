"""Mesh and bearing forces as MuJoCo computed them, read from its generalized forces.

MuJoCo keeps no per-tendon force, only the generalized spring and damper forces
(``qfrc_spring``, ``qfrc_damper``) that its tendons and joints add up to.  Two probe copies of the model,
evaluated by ``mj_passive`` on the same state, take them apart:

* the mesh probe, with every joint spring and damper and every tendon but the meshes removed, gives the mesh
  tendons' generalized forces alone, J_P^T f at the planets' joints (J_P: the mesh tendons' coefficients on
  those joints, which do not turn with the carrier and are constant); the mesh force is F = -(f + g) with
  f = P (J_P^T f) for P the left inverse of J_P^T, and g the runner's own damping correction
  (``qfrc_applied`` = J^T g; see :mod:`gearcheck.mbd_models.runner`);
* the bearing probe, with every tendon removed but the bearing stations' (a tilting member's,
  :mod:`~gearcheck.mbd_models.elements.stations`), gives the joints' own springs and dampers and the stations':
  a bearing force (of a planet, or of an RV reducer's crankshaft on its carrier) is minus its slides' generalized
  forces (a station's tendon moves a slide with coefficient 1).

A torsional planet (no slides: it rides its pin) has a hinge alone for its two meshes, and the planets' joints no
longer tell the meshes apart (nor do all the joints: the load sharing among torsional planets moves no joint).
Then the mesh probe holds one mesh tendon at a time, whose force is f_j = J_j . (J_j^T f_j) / |J_j|^2, and g is
read from the runner's damping correction (:class:`~gearcheck.mbd_models.static_state.DampingCorrection`).

Nothing here restates a force law: the dead band, the spring and the damper are MuJoCo's.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
from scipy.linalg import block_diag

from gearcheck.mbd_models.elements.stations import station_names, station_tendon, stations
from gearcheck.mbd_models.jacobians import named, tendon_rows
from gearcheck.mbd_models.mjcf_text import TILT, member_axes
from gearcheck.shared.errors import SolverError

TILTS = TILT["axis"] + TILT["pin"]  # every tilt hinge's suffix


class ForceReader:
    """Reads mesh forces, meshes' tilting moments and bearing forces from MuJoCo's generalized forces for one compiled
    twin and its data."""

    def __init__(self, mb, d: mujoco.MjData, correction=None):
        m = mb.model
        self.mb, self.model, self.d, self.correction = mb, m, d, correction
        self.n_mesh = len(mb.mesh_tendon)
        self.n_rows = n = len(mb.corrected)  # the meshes' tendons and their tilting tendons
        self.probe = copy.copy(m)
        self.probe.jnt_stiffness[:] = 0.0
        self.probe.dof_damping[:] = 0.0
        self.probe.tendon_stiffness[n:] = 0.0
        self.probe.tendon_damping[n:] = 0.0
        self.joints_only = copy.copy(m)
        stations = [named(m, mujoco.mjtObj.mjOBJ_TENDON, name) for name in station_names(mb.spec)]
        others = np.setdiff1d(np.arange(m.ntendon), stations)
        self.joints_only.tendon_stiffness[others] = 0.0
        self.joints_only.tendon_damping[others] = 0.0
        planets = [member for member in mb.spec.members.values() if member.is_planet]
        self.dofs = np.array([dof for p in planets for dof in mb.dadr[p.id].values()] + mb.joint_dofs(planets, TILTS),
                             dtype=int)
        tilts = mb.joint_dofs(mb.spec.members.values(), TILTS)  # the bearing probe keeps no spring on a tilt hinge
        self.joints_only.jnt_stiffness[m.dof_jntid[tilts]] = 0.0
        self.joints_only.dof_damping[tilts] = 0.0
        self.slides, self.bearing_map = self._bearings(mb)
        J_P = tendon_rows(m, mb.corrected)[:, self.dofs]
        self.one_by_one = any(p.torsional for p in planets)
        if not self.one_by_one and np.linalg.matrix_rank(J_P) < n:
            raise SolverError(f"{mb.spec.name}: the mesh forces cannot be told apart at the planets' joints "
                              "(a planet meshes with more than three central gears)")
        self.P = None if self.one_by_one else np.linalg.pinv(J_P.T)
        # views kept once: the hot path only copies into them
        self._sum = np.empty(m.nv)
        self._spring, self._damper, self._applied = d.qfrc_spring, d.qfrc_damper, d.qfrc_applied
        self._stiffness, self._probe_stiffness = m.tendon_stiffness[:n], self.probe.tendon_stiffness[:n]
        self._lengths, self._probe_lengths = m.tendon_lengthspring[:n], self.probe.tendon_lengthspring[:n]
        self._damping, self._probe_damping = m.tendon_damping[:n], self.probe.tendon_damping[:n]

    def _bearings(self, mb) -> tuple[np.ndarray, np.ndarray]:
        """(dofs read, map): the dofs of the bearing probe whose generalized forces give the bearing forces, and the
        map from those to the bearings' forces (:func:`~gearcheck.shared.results.bearing_names` order).  A bearing
        without stations: its slides' forces; with stations: its slides' and tilt hinges' forces
        J_S^T f (the bearing probe keeps no spring on those hinges), whence f = P_S (J_S^T f), P_S the left inverse
        of J_S^T, J_S the stations' rows there."""
        m = mb.model
        dofs, blocks = [], []
        for member in mb.spec.members.values():
            if not (member.orbits and member.bearing):
                continue
            slides = [mb.dadr[member.id][a] for a in member_axes(member)]
            names = [station_tendon(member, i, a) for i, _ in enumerate(stations(member, member.bearing))
                     for a in member_axes(member)]
            if not names:
                dofs += slides
                blocks.append(np.eye(len(slides)))
                continue
            read = slides + mb.joint_dofs([member], TILTS)
            dofs += read
            J_S = tendon_rows(m, [named(m, mujoco.mjtObj.mjOBJ_TENDON, name) for name in names])[:, read]
            blocks.append(np.linalg.pinv(J_S.T))
        return np.array(dofs, dtype=int), block_diag(*blocks) if blocks else np.zeros((0, 0))

    @property
    def width(self) -> int:
        return 2 * (self.n_rows if self.one_by_one else len(self.dofs)) + len(self.slides)

    def sample(self, out: np.ndarray) -> None:
        """After ``mj_forward``: write the planet joints' (mesh-only, applied) generalized forces and the bearing
        probe's ones into ``out`` (one row of :attr:`width`), for :meth:`forces`.  Leaves the data's passive forces
        those of a probe (nothing that the RK4 stages read)."""
        n, dofs, total = len(self.dofs), self.dofs, self._sum
        if self.one_by_one:
            n = self._each(out)
        else:
            self._probe_stiffness[:] = self._stiffness
            self._probe_lengths[:] = self._lengths
            mujoco.mj_passive(self.probe, self.d)
            np.add(self._spring, self._damper, out=total)
            out[:n] = total[dofs]
            out[n:2 * n] = self._applied[dofs]
        mujoco.mj_passive(self.joints_only, self.d)
        np.add(self._spring, self._damper, out=total)
        out[2 * n:] = total[self.slides]

    def _each(self, out: np.ndarray) -> int:
        """Each mesh tendon's (and tilting tendon's) force alone in the probe, and the damping correction's g, into
        ``out``; returns their number."""
        n, J, total = self.n_rows, tendon_rows(self.model, self.mb.corrected), self._sum
        for j in range(n):
            self._probe_stiffness[:], self._probe_damping[:] = 0.0, 0.0
            self._probe_stiffness[j], self._probe_damping[j] = self._stiffness[j], self._damping[j]
            self._probe_lengths[j] = self._lengths[j]
            mujoco.mj_passive(self.probe, self.d)
            np.add(self._spring, self._damper, out=total)
            out[j] = J[j] @ total / (J[j] @ J[j])
        out[n:2 * n] = 0.0 if self.correction is None else self.correction.g
        return n

    def forces(self, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mesh forces (n, n_mesh), tilting meshes' moments (n, n_tilt), bearing forces (n, n_bearing)) from rows
        written by :meth:`sample`."""
        n = self.n_rows if self.one_by_one else len(self.dofs)
        mesh, applied, bearing = samples[:, :n], samples[:, n:2 * n], samples[:, 2 * n:]
        rows = -(mesh + applied) @ (np.eye(n) if self.P is None else self.P.T)
        return rows[:, :self.n_mesh], rows[:, self.n_mesh:], -bearing @ self.bearing_map.T

