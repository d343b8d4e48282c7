"""An RV reducer's cycloid-pin stage in the MuJoCo twin: pin contacts that follow the discs every step.

The bodies (:mod:`gearcheck.mbd_models.mjcf_builder`): each crankshaft rides on the carrier like a planet (its
support bearing the stiffness of its slides), each planet sits on its crankshaft (spline tendons), each disc
is a free planar body in polar joints about the stage axis (orbit hinge, radial slide, hinge about its centre),
in which the rigid mechanism's motion -- the disc orbiting at the cranks' speed w_H while it turns with the
carrier -- is linear in time.  MuJoCo carries the orbits' centrifugal loads itself.

Needle bearings are MuJoCo's own exact spring-dampers (site actuators, see the builder).  Pin contacts are
fixed tendons, compression only by a dead band, whose coefficients and spring lengths :meth:`CycloidTwin.refresh`
sets from the twin's own poses before every step (Yang, Chen & Wang 2018 write the same contacts in the carrier
frame):

* the disc's conjugate eccentric angle phi* = phase + w - Z_c (theta - w), theta the disc's rotation and w the
  pin wheel's (the disc rolls its pitch circle Z_c e inside the wheel's, Z_p e), places the pitch point
  P = O + Z_p e e(phi*) and the conjugate centre c* = O + e e(phi*), O the wheel's centre;
* pin i's normal n_i runs from P to its centre C_i (Willis), its compression is delta_i = n_i . (c - c*) - g
  (c the disc's centre, g the clearance), and its tendon coefficients are n_i . (J_disc(P) - J_wheel(P)) from
  ``mj_jac``; the upper edge of the dead band is the tendon length less delta_i, so MuJoCo's spring force is
  k max(delta_i, 0); the contact damping is on while the pin touches.

The coefficients are those of d delta_i / dq on the conjugate family, and the rigid mechanism rolls the disc
about P, so every coefficient row is orthogonal to its motion: with that motion linear in the joints, the
rigid orbit never shows as a deflection within a step either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from gearcheck.train.spec import TrainSpec
from gearcheck.mbd_models.elements.cycloid import (
    PIN_BAND,
    needle_actuator,
    needle_list,
    pin_joints,
    pin_list,
    pin_site,
    pin_tendon,
)

ORIGIN = np.zeros(3)  # the stage axis, where a fixed pin wheel's centre lies


@dataclass(frozen=True)
class _Stage:
    """One cycloid-pin stage's pins in the compiled model, arrays over its discs (the order of its tendons)."""

    rows: slice  # its pin tendons among all
    bodies: np.ndarray  # (N,) disc body ids
    wheel: int  # the pin wheel's body id, -1: the pins are on the world
    phases: np.ndarray  # (N,)
    lobes: int
    eccentricity: float
    pitch_radius: float  # Z_p e
    sites: np.ndarray  # (Z_p,) pin site ids
    dofs: np.ndarray  # (N, n) the dofs of each disc's tendons' joints (the disc's, then the wheel's)
    qadr: np.ndarray  # (N, n) their qpos addresses
    wraps: np.ndarray  # (N, Z_p, n) indices into wrap_prm
    jacobian: np.ndarray  # (N, 2, n) work space: J_disc(P) - J_wheel(P) on those dofs


class CycloidTwin:
    """The pin contacts and needle bearings of a compiled twin's cycloid-pin stages."""

    def __init__(self, spec: TrainSpec, model: mujoco.MjModel):
        m = self.model = model
        pins = pin_list(spec)
        T, B, S, J, A = (mujoco.mjtObj.mjOBJ_TENDON, mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_SITE,
                         mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_ACTUATOR)
        self.names = [f"{disc.id}.pin{i + 1}" for _, disc, i in pins]
        self.tendons = np.array([mujoco.mj_name2id(m, T, pin_tendon(disc, i)) for _, disc, i in pins], dtype=int)
        torque = spec.operating.output_torque
        self.stiffness = np.array([stage.cycloid.pin_stiffness(torque) for stage, _, _ in pins])
        self.damping = np.array([stage.cycloid.contact_damping for stage, _, _ in pins])
        self.clearance = np.array([stage.cycloid.clearance for stage, _, _ in pins])
        self.stages = []
        row = 0
        for stage in spec.stages:
            cyc = stage.cycloid
            if not cyc:
                continue
            g, discs = cyc.geometry, [spec.members[disc] for disc in cyc.discs]
            rows = slice(row, row + g.pins * len(discs))
            joints = np.array([[mujoco.mj_name2id(m, J, name) for name in pin_joints(spec, disc)] for disc in discs])
            tendons = self.tendons[rows].reshape(len(discs), g.pins)
            wraps = m.tendon_adr[tendons][..., None] + np.arange(joints.shape[1])
            assert np.array_equal(m.wrap_objid[wraps], np.broadcast_to(joints[:, None, :], wraps.shape))
            self.stages.append(_Stage(
                rows, np.array([mujoco.mj_name2id(m, B, disc.label) for disc in discs]),
                mujoco.mj_name2id(m, B, spec.members[cyc.pin_wheel].label) if cyc.pin_wheel else -1,
                np.array(cyc.phases), g.lobes, g.eccentricity, g.pitch_radius,
                np.array([mujoco.mj_name2id(m, S, pin_site(stage, i)) for i in range(g.pins)]),
                m.jnt_dofadr[joints], m.jnt_qposadr[joints], wraps, np.empty((len(discs), 2, joints.shape[1]))))
            row = rows.stop
        needles = needle_list(spec)
        self.needle_names = [f"{crank.id}.{disc.id.split('.')[-1]}.needle" for _, crank, disc, _, _ in needles]
        self.needles = np.array([[mujoco.mj_name2id(m, A, needle_actuator(crank, disc, axis)) for axis in "xy"]
                                 for _, crank, disc, _, _ in needles], dtype=int)
        self.contacts = np.ones(len(self.tendons), dtype=bool)  # the static contact set at t = 0, once solved
        self._jac = np.zeros((3, m.nv))
        n = len(self.tendons)
        self._delta, self._length, self._band = np.empty(n), np.empty(n), np.empty((n, 2))

    def refresh(self, d: mujoco.MjData, touching: np.ndarray | None = None, gaps: bool = True) -> np.ndarray:
        """Coefficients, spring lengths, stiffness and damping of every pin tendon at ``d.qpos`` (its kinematics
        computed here); returns the compressions delta_i (m).  ``touching`` None: compression only, damped while
        touching (a run); else linear springs, damped, on the pins ``touching`` and none on the others (the
        static contact set: the static solution, the linearisation).  ``gaps`` False: without the clearance."""
        m, jac = self.model, self._jac
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        delta, length = self._delta, self._length
        xpos, xmat, qpos = d.xpos, d.xmat, d.qpos
        for g in self.stages:
            c = xpos[g.bodies]
            if g.wheel >= 0:
                centre, w = xpos[g.wheel], math.atan2(xmat[g.wheel, 3], xmat[g.wheel, 0])
            else:
                centre, w = ORIGIN, 0.0
            rotation = xmat[g.bodies]
            phi = g.phases + (1 + g.lobes) * w - g.lobes * np.arctan2(rotation[:, 3], rotation[:, 0])
            u = np.array([np.cos(phi), np.sin(phi)]).T
            pitch = c.copy()
            pitch[:, :2] = centre[:2] + g.pitch_radius * u
            n = d.site_xpos[g.sites, :2] - pitch[:, None, :2]
            n /= np.sqrt((n * n).sum(axis=2))[..., None]
            delta[g.rows] = (n @ (c[:, :2] - centre[:2] - g.eccentricity * u)[..., None]).ravel()
            for i, (body, point, dofs) in enumerate(zip(g.bodies, pitch, g.dofs)):
                mujoco.mj_jac(m, d, jac, None, point, body)
                g.jacobian[i] = jac[:2, dofs]
                if g.wheel >= 0:
                    mujoco.mj_jac(m, d, jac, None, point, g.wheel)
                    g.jacobian[i] -= jac[:2, dofs]
            coef = n @ g.jacobian
            m.wrap_prm[g.wraps] = coef
            length[g.rows] = (coef @ qpos[g.qadr][..., None]).ravel()
        if gaps:
            delta -= self.clearance
        t, band = self.tendons, self._band
        band[:, 1] = length - delta
        if touching is None:
            band[:, 0] = band[:, 1] - PIN_BAND
            m.tendon_stiffness[t] = self.stiffness
            m.tendon_damping[t] = self.damping * (delta > 0.0)
        else:
            band[:, 0] = band[:, 1]
            m.tendon_stiffness[t] = self.stiffness * touching
            m.tendon_damping[t] = self.damping * touching
        m.tendon_lengthspring[t] = band
        return delta.copy()

    def pin_forces(self, d: mujoco.MjData) -> np.ndarray:
        """Every pin's contact force (N, >= 0 apart from damping), as MuJoCo's tendons carry it after
        ``mj_forward``: k (L - L_top) above the dead band's upper edge plus the damping c L'."""
        m, t = self.model, self.tendons
        compression = d.ten_length[t] - m.tendon_lengthspring[t, 1]
        return m.tendon_stiffness[t] * np.maximum(compression, 0.0) + m.tendon_damping[t] * d.ten_velocity[t]
