"""The steady rotating state of a MuJoCo twin at its nominal operating point, and the mesh damping correction
that both the static solve and the runner apply.

:func:`static_state`: a Newton solve on MuJoCo's forward dynamics for the deflections at which every body
turns at its nominal speed with the deflection pattern turning with its carrier (a cycloid disc orbiting on
its eccentrics), frozen at t = 0.  An RV reducer's pin contacts are solved as an active set on MuJoCo's own
equilibrium: every pin touching at first, then those in compression, until the set settles (its t = 0
contact set, which the linearisation takes).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from gearcheck.mbd_models.forces import ForceReader
from gearcheck.mbd_models.jacobians import tendon_rows
from gearcheck.mbd_models.mjcf_text import ROTATION, member_axes, world_pairs
from gearcheck.shared.errors import SolverError

# --------------------------------------------------------------------------- damping correction


class DampingCorrection:
    """g = c (de/dt - m) per corrected tendon (``MbdModel.corrected``: the meshes' and their tilting tendons'; a
    transmission error's rate de/dt only on the meshes') as the generalized force J^T g (``qfrc_applied``), J those
    tendons' current coefficients, m the deflection rate their turning coefficients add
    (see :mod:`gearcheck.mbd_models.runner`)."""

    def __init__(self, mb, d: mujoco.MjData):
        self.mb, self.d = mb, d
        tc = mb.turning
        self.c = mb.corrected_damping
        self.n_mesh = len(mb.mesh_tendon)
        self.J = tendon_rows(mb.model, mb.corrected)
        self.c_wrap = np.zeros((len(self.c), len(tc.wraps)))  # damping per turning wrap
        self.c_wrap[tc.tendon, np.arange(len(tc.wraps))] = self.c[tc.tendon]
        self.half = len(tc.wraps) // 2
        self.g = np.zeros(len(self.c))  # the last applied

    def apply(self, de) -> None:
        tc, d, n = self.mb.turning, self.d, self.half
        coef = self.mb.model.wrap_prm[tc.wraps]
        self.J[tc.tendon, tc.joint_dof] = coef
        turned = np.concatenate([-coef[n:], coef[:n]])  # dc/dphi: a pair (first, second) turns as (-second, first)
        g = -(self.c_wrap @ (turned * d.qvel[tc.carrier_qadr] * d.qpos[tc.joint_qadr]))
        if de is not None:
            g[:self.n_mesh] += self.c[:self.n_mesh] * de
        d.qfrc_applied[:] = g @ self.J
        self.g = g


# --------------------------------------------------------------------------- static state


@dataclass
class StaticState:
    qpos: np.ndarray
    qvel: np.ndarray
    mesh_deflection: np.ndarray
    mesh_force: np.ndarray
    bearing_force: np.ndarray  # in gearcheck.shared.results.bearing_names order
    iterations: int
    residual: float
    contacts: np.ndarray | None = None  # which of the twin's contacts touch at t = 0 (an RV reducer's pins)
    pin_force: np.ndarray | None = None  # their forces, N


def nominal_speeds(mb) -> np.ndarray:
    """The joints' speeds in the rigid train's nominal motion: every hinge at its member's nominal speed (a planet's
    or a crankshaft's relative to its carrier; a cycloid disc's orbit hinge at its cranks' speed and its own hinge
    the rest), every slide at rest."""
    spec, kin = mb.spec, mb.kin
    qvel = np.zeros(mb.model.nv)
    for mid, member in spec.members.items():
        ir = mb.dadr[mid][ROTATION]
        omega = kin.speeds[f"{member.stage}.carrier"]
        if member.eccentric is not None:
            orbit = kin.speeds[member.eccentric.crank]
            qvel[mb.dadr[mid][member_axes(member)[0]]], qvel[ir] = orbit, kin.speeds[mid] - orbit
        else:
            qvel[ir] = kin.speeds[mid] - (omega if member.orbits else 0.0)
    return qvel


def _nominal(q: np.ndarray, speeds: np.ndarray, turning):
    """State (qpos, qvel) and the steady-rotation acceleration of deflection q at t = 0.

    Every body turns at its nominal speed (``speeds``, :func:`nominal_speeds`), and a central member's world-frame
    deflection (its slides, and its tilts when it tilts: :func:`~gearcheck.mbd_models.mjcf_text.world_pairs`) turns
    with its carrier (``turning``, :func:`world_turning`): x' = Omega k x x, x'' = -Omega^2 x.
    """
    qvel = speeds.copy()
    target = np.zeros_like(q)
    for (ix, iy), omega in turning:
        qvel[ix], qvel[iy] = -omega * q[iy], omega * q[ix]
        target[ix], target[iy] = -omega**2 * q[ix], -omega**2 * q[iy]
    return q.copy(), qvel, target


def world_turning(mb, speed_ratio: float = 1.0) -> list[tuple[tuple[int, int], float]]:
    """((dof of x, dof of y), Omega) of every pair of world-frame joints (:func:`~gearcheck.mbd_models.mjcf_text.
    world_pairs`), Omega its stage's carrier speed times ``speed_ratio``: the pairs that a deflection pattern
    turning with the carrier turns as a vector."""
    model = mb.model
    return [(tuple(int(model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{member.label}_{a}")])
                   for a in pair), speed_ratio * mb.kin.speeds[f"{member.stage}.carrier"])
            for member in mb.spec.members.values() for pair in world_pairs(member)]


def _set_static_drive(mb, d: mujoco.MjData, load_scale: float) -> None:
    kin, a = mb.kin, mb.actuator
    d.ctrl[:] = 0.0
    if "input_shaft_damper" in a:
        d.ctrl[a["input_shaft_damper"]] = mb.spec.operating.input_speed
    if "input_shaft" not in a:
        d.ctrl[a["input_torque"]] = kin.input_torque * load_scale
    d.ctrl[a["output_load"]] = kin.output_torque * load_scale


class _PinContacts:
    """An RV reducer's pin contacts as an active set on the static solve: every pin touching at first, then those
    in compression at the solution, until the set settles; the clearances last (:meth:`settle`)."""

    def __init__(self, mb, d: mujoco.MjData):
        self.contacts, self.slices, self.d = mb.moving_contacts, mb.moving_slices(), d
        self.touching = np.ones(sum(len(c.tendons) for c in self.contacts), dtype=bool)
        self.gaps = True
        self.name = mb.spec.name

    def refresh(self) -> np.ndarray:
        """Every contact set to ``touching`` at the data's pose; the compressions."""
        return np.concatenate([c.refresh(self.d, self.touching[at], self.gaps)
                               for c, at in zip(self.contacts, self.slices)])

    def settle(self, q: np.ndarray, newton, residual) -> np.ndarray:
        """``newton``'s solution with the contact set settled: without the clearances first (every pin touching
        is then the loaded half, whence the set with them follows; from all pins in tension, none might touch)."""
        for gaps in (False, True) if any(np.any(c.clearance) for c in self.contacts) else (True,):
            self.gaps = gaps
            q = newton(q)
            for rounds in itertools.count():
                residual(q)
                compressed = self.refresh() > 0.0
                if np.array_equal(compressed, self.touching):
                    break
                if rounds == len(self.touching):
                    raise SolverError(f"MuJoCo static state of {self.name}: the pin contact set did not settle")
                self.touching[:] = compressed
                q = newton(q)
        return q

    def forces(self) -> np.ndarray:
        return np.concatenate([c.pin_forces(self.d) for c in self.contacts])


def _newton(residual, q: np.ndarray, tol: float, max_iter: int, name: str) -> tuple[np.ndarray, int, float]:
    """Newton's method on residual(q) = 0 from q, the Jacobian by central differences, minimum-norm steps where a
    free rotation makes it singular, until a step is below ``tol``: (q, iterations, the residual's largest entry)."""
    res = math.inf
    for iteration in range(1, max_iter + 1):
        r0 = residual(q)
        J = np.empty((q.size, q.size))
        h = 1e-7
        for j in range(q.size):
            dq = np.zeros(q.size)
            dq[j] = h
            J[:, j] = (residual(q + dq) - residual(q - dq)) / (2 * h)
        step = np.linalg.lstsq(J, -r0, rcond=1e-12)[0]
        q = q + step
        res = float(np.max(np.abs(residual(q))))
        if np.max(np.abs(step)) < tol:
            return q, iteration, res
    raise SolverError(f"MuJoCo static state of {name}: Newton did not converge (residual {res:.3g} m/s^2)")


def static_state(mb, load_scale: float = 1.0, tol: float = 1e-13, max_iter: int = 40) -> StaticState:
    """Steady rotating equilibrium of the MuJoCo model under the mean load (times ``load_scale``); ``tol`` and
    ``max_iter`` for each Newton solve.

    Newton's method (:func:`_newton`) on r(q) = qacc(q) - qacc_steady(q), with MuJoCo's forward dynamics
    evaluated at the nominal speeds, every mesh at its mean stiffness and the damping acting on the
    true deflection rate (zero in steady rotation).  Backlash: solved first without it,
    then with every mesh on its drive flank.  Pin contacts: linear springs on an active set
    (:class:`_PinContacts`).
    """
    m = mb.model
    d = mujoco.MjData(m)
    saved = (m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.tendon_damping.copy(), m.wrap_prm.copy())
    t = mb.mesh_tendon
    correction = DampingCorrection(mb, d)
    pins = _PinContacts(mb, d) if mb.moving_contacts else None
    speeds, turning = nominal_speeds(mb), world_turning(mb)  # constants of the solve
    try:
        m.tendon_stiffness[t] = mb.excitation.mean_stiffness
        _set_static_drive(mb, d, load_scale)

        def residual(q):
            qpos, qvel, target = _nominal(q, speeds, turning)
            d.qpos[:], d.qvel[:] = qpos, qvel
            mb.refresh(d.qpos)
            if pins is not None:
                pins.refresh()
            correction.apply(None)
            mujoco.mj_forward(m, d)
            return d.qacc - target

        def newton(q):
            nonlocal iterations, res
            q, taken, res = _newton(residual, q, tol, max_iter, mb.spec.name)
            iterations += taken
            return q

        q = m.qpos0.copy()
        iterations, res = 0, math.inf
        for band in (False, True):
            # with backlash the loaded teeth sit on their drive flanks: a spring whose rest length is
            # +b (the dead band's upper edge) has the same force there and no flat zero-stiffness
            # region for Newton to wander in (the lumped static solution does the same)
            m.tendon_lengthspring[t, 0] = mb.half_backlash if band else 0.0
            m.tendon_lengthspring[t, 1] = mb.half_backlash if band else 0.0
            if band and not np.any(mb.half_backlash):
                break
            q = newton(q) if pins is None else pins.settle(q, newton, residual)
        residual(q)
        reader = ForceReader(mb, d)
        sample = np.empty((1, reader.width))
        reader.sample(sample[0])
        force, _, bearing = (f[0] for f in reader.forces(sample))
        qpos, qvel, _ = _nominal(q, speeds, turning)
        touching, pin_force = (None, None) if pins is None else (pins.touching, pins.forces())
        return StaticState(qpos, qvel, d.ten_length[t].copy(), force, bearing, iterations, res, touching, pin_force)
    finally:
        m.tendon_stiffness[:], m.tendon_lengthspring[:], m.tendon_damping[:], m.wrap_prm[:] = saved
