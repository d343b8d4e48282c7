"""Linearisation of the MuJoCo model and its natural frequencies.

At rest (:func:`modes`): M comes from ``mujoco.mj_fullM`` and K from central differences of the
generalized spring forces MuJoCo computes (``qfrc_passive`` + ``qfrc_actuator``: the input shaft's
position servo is a spring too) at the nominal configuration (every joint at its reference, carrier
angle 0), at rest, with every mesh tendon at its mean stiffness.  As in the lumped modal analysis
(Lin & Parker 1999, section 3) no rotation terms enter: the model is linearised at qvel = 0.

At speed (:func:`modes_at_speed`): central differences of the generalized forces MuJoCo computes,
f = qfrc_passive + qfrc_actuator - qfrc_bias (its Coriolis and centrifugal terms as MuJoCo computes
them), with respect to qpos and qvel at the nominal configuration with every body turning at its
nominal speed (damping removed), and its mass matrix there: M q'' = A q + B q'.  (The mass matrix is
held at the nominal configuration, as in the linear model: differentiating qacc = M(q)^-1 f instead
would add dM^-1/dq times the centrifugal force the nominal configuration leaves unbalanced.)
MuJoCo's central members translate along world axes (and tilt about them), which turn under a rotating train;
in the axes of their stage's carrier (x_w = R(Omega t) x_r) the system is time-invariant:
M q_r'' = (A + B P - M P^2) q_r + (B - 2 M P) q_r', P = Omega J on those slides' (and tilts') pairs.  A tilting
member spins about its own tilted axis, so its gyroscopic moments are in MuJoCo's bias forces.

Mode types are read from MuJoCo's own coordinates: the kinetic-energy fractions of the central
members' slides and tilts (translation: Eritenel & Parker 2009's translational-tilting modes) and hinges and
axial slides (rotation: their rotational-axial modes), classified by
:func:`gearcheck.shared.modal.mode_types`; they do not depend on MuJoCo's choice of coordinates
(planet slides relative to the carrier).  An RV reducer's cycloid discs sit in polar joints, which mix
translation and rotation: their x, y along the carrier's axes and their rotation take those joints' place
(:func:`_disc_axes`; at speed with the rates of that change of coordinates, as for the world-frame slides),
and its pins are those of its static contact set of t = 0, linear springs at the nominal configuration as
every other connection.

Every function takes a compiled twin (:class:`gearcheck.mbd_models.twin.MbdModel`).
"""

from __future__ import annotations

from contextlib import contextmanager

import mujoco
import numpy as np

from gearcheck.mbd_models.mjcf_text import AXIAL, ROTATION, TILT
from gearcheck.mbd_models.static_state import nominal_speeds, world_turning
from gearcheck.train.spec import TILTS
from gearcheck.shared import stepping
from gearcheck.shared.modal import ModalResult, modal_result, speed_modal_result
from gearcheck.shared.modal import settling_time as shared_settling_time
from gearcheck.shared.units import rad_s_to_rpm

FD_STEP = 1e-6  # m or rad; the spring forces are linear in qpos, so the step only sets rounding
VELOCITY_STEP = 1e-3  # m/s or rad/s


def _set_rest(mb, data: mujoco.MjData, qpos: np.ndarray) -> None:
    data.qpos[:] = qpos
    data.qvel[:] = 0.0
    data.ctrl[:] = 0.0
    if "input_shaft" in mb.actuator:
        data.ctrl[mb.actuator["input_shaft"]] = 0.0  # reference angle at the nominal configuration


def mass_matrix(mb, qpos: np.ndarray | None = None) -> np.ndarray:
    m = mb.model
    d = mujoco.MjData(m)
    _set_rest(mb, d, m.qpos0 if qpos is None else qpos)
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    return M


@contextmanager
def _frozen(mb, qpos: np.ndarray, every_pin: bool = False):
    """The twin's contacts (an RV reducer's pins) as linear springs at ``qpos`` on their static contact set of t = 0
    (or all touching: the stiffest the twin can be), their coefficients MuJoCo's Jacobians there; the tendon fields
    are restored afterwards.  Nothing for a train without contacts."""
    if not mb.moving_contacts:
        yield
        return
    m = mb.model
    saved = (m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.tendon_damping.copy(), m.wrap_prm.copy())
    try:
        d = mujoco.MjData(m)
        d.qpos[:] = qpos
        for c in mb.moving_contacts:
            c.freeze(d, every_pin)
        yield
    finally:
        m.tendon_stiffness[:], m.tendon_lengthspring[:], m.tendon_damping[:], m.wrap_prm[:] = saved


def stiffness_matrix(mb, tendon_stiffness: np.ndarray | None = None,
                     qpos: np.ndarray | None = None, every_pin: bool = False) -> np.ndarray:
    """-d(qfrc_passive + qfrc_actuator)/dqpos by central differences, at rest.

    tendon_stiffness: optional stiffness of the mesh tendons (one per mesh) used
    instead of the model's own values (which are restored afterwards).  A backlash
    dead band is closed for the linearisation (the teeth in contact on their loaded
    flank), so a mesh contributes its stiffness k and not the 0 of the band's inside;
    an RV reducer's pins are those of its static contact set of t = 0 (``every_pin``: all).
    """
    m = mb.model
    saved = m.tendon_stiffness.copy()
    saved_length = m.tendon_lengthspring.copy()
    q0 = (m.qpos0 if qpos is None else qpos).copy()
    try:
        m.tendon_lengthspring[mb.mesh_tendon] = 0.0
        if tendon_stiffness is not None:
            m.tendon_stiffness[mb.mesh_tendon] = tendon_stiffness
        d = mujoco.MjData(m)
        K = np.zeros((m.nv, m.nv))
        with _frozen(mb, q0, every_pin):
            for j in range(m.nv):  # hinge and slide joints only: qpos and dof addresses coincide
                forces = []
                for sign in (1.0, -1.0):
                    q = q0.copy()
                    q[j] += sign * FD_STEP
                    _set_rest(mb, d, q)
                    mujoco.mj_forward(m, d)
                    forces.append(d.qfrc_passive + d.qfrc_actuator)
                K[:, j] = -(forces[0] - forces[1]) / (2.0 * FD_STEP)
    finally:
        m.tendon_stiffness[:] = saved
        m.tendon_lengthspring[:] = saved_length
    return 0.5 * (K + K.T)


def damping_matrix(mb, qpos: np.ndarray | None = None, every_pin: bool = False) -> np.ndarray:
    """-d(qfrc_passive + qfrc_actuator)/dqvel by central differences, at rest: the joints' and tendons'
    damping, the input shaft's damper and an RV reducer's needle bearings and pins (as in
    :func:`stiffness_matrix`)."""
    m = mb.model
    d = mujoco.MjData(m)
    q0 = m.qpos0 if qpos is None else qpos
    C = np.zeros((m.nv, m.nv))
    with _frozen(mb, q0, every_pin):
        for j in range(m.nv):
            forces = []
            for sign in (1.0, -1.0):
                _set_rest(mb, d, q0)
                d.qvel[j] = sign * FD_STEP
                mujoco.mj_forward(m, d)
                forces.append(d.qfrc_passive + d.qfrc_actuator)
            C[:, j] = -(forces[0] - forces[1]) / (2.0 * FD_STEP)
    return C


def step_limits(mb) -> stepping.StepLimits:
    """RK4 step limits of the MuJoCo model with every mesh at its cycle-maximum stiffness (and every pin of an
    RV reducer touching), damping included."""
    return stepping.StepLimits.of(mass_matrix(mb), stiffness_matrix(mb, mb.excitation.max_stiffness, every_pin=True),
                                  damping_matrix(mb, every_pin=True))


def settling_time(mb, fraction: float) -> float:
    """How long the free vibration of the twin at rest, every mesh at its mean stiffness, takes to fall to
    ``fraction`` (:func:`gearcheck.shared.modal.settling_time` of MuJoCo's own matrices, in the axes of
    :func:`modes`)."""
    S = _disc_axes(mb)[0]
    return shared_settling_time(S.T @ mass_matrix(mb) @ S, S.T @ damping_matrix(mb) @ S,
                                S.T @ stiffness_matrix(mb, mb.excitation.mean_stiffness) @ S, fraction)


def joint_labels(mb) -> list[str]:
    m = mb.model
    return [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.dof_jntid[i])) for i in range(m.nv)]


def modes(mb) -> ModalResult:
    """Natural frequencies and mode types of the MuJoCo model at mean mesh stiffness (solver "mujoco")."""
    S = _disc_axes(mb)[0]
    result = modal_result(mb.spec.name, "mujoco", S.T @ stiffness_matrix(mb, mb.excitation.mean_stiffness) @ S,
                          S.T @ mass_matrix(mb) @ S, joint_labels(mb), *_central(mb))
    result.shapes = S @ result.shapes  # in MuJoCo's joints
    return result


def physical_coordinates(mb) -> tuple[list[str], np.ndarray]:
    """(labels, T): the train's physical coordinates as MuJoCo moves them, T (n, nv) mapping a small joint
    motion to them, read from MuJoCo's own Jacobians at rest: each member's centre moves along x, y (a
    planet or a crankshaft: along its radial and tangential axes), it turns about z, in a helical stage it moves
    along z, and in a tilting stage it turns about its two translation axes.  The labels are ``member.x`` ... as
    the lumped model names its coordinates; a torsional member has its rotation alone (its translations held or
    riding its pin), as the lumped model keeps it."""
    m = mb.model
    d = mujoco.MjData(m)
    _set_rest(mb, d, m.qpos0)
    mujoco.mj_forward(m, d)
    labels, rows = [], []
    for mid, member in mb.spec.members.items():
        body = mb.body[mid]
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jac(m, d, jp, jr, d.xipos[body], body)
        if member.orbits:
            c, s = np.cos(member.angle), np.sin(member.angle)
            axes = {"radial": np.array([c, s, 0.0]), "tangential": np.array([-s, c, 0.0])}
        else:
            axes = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0])}
        moves = [(f"{mid}.{name}", axis @ jp) for name, axis in axes.items()] + [(f"{mid}.theta", jr[2])]
        if member.axial:
            moves.append((f"{mid}.z", jp[2]))
        if member.tilting:  # about the same axes, absolute (a planet's as well)
            moves += [(f"{mid}.{tilt}", axis @ jr) for tilt, axis in zip(TILTS[member.frame], axes.values())]
        for label, row in moves:
            if label.rsplit(".", 1)[1] in member.coordinates:  # a torsional member's translations are not its own
                labels.append(label)
                rows.append(row)
    return labels, np.array(rows)


def _central(mb) -> tuple[list[int], list[int]]:
    """(translation, rotation) dofs of the central members; an axial slide goes with the rotation (a helical
    mesh's axial force goes with its torque: Eritenel & Parker 2009's rotational-axial modes) and a tilt with the
    translations (a bearing station's or an offset mesh's force moves and tilts a member together: their
    translational-tilting modes).  A cycloid disc is a planetary component, not a central member
    (:attr:`~gearcheck.train.spec.Member.central`)."""
    central = [member for member in mb.spec.members.values() if member.central]
    translation = [i for m in central for a, i in mb.dadr[m.id].items() if a != ROTATION]
    rotation = [mb.dadr[m.id][ROTATION] for m in central]
    return translation + mb.joint_dofs(central, TILT["axis"]), rotation + mb.joint_dofs(central, (AXIAL,))


def _disc_axes(mb, speed_ratio: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(S, S', S''): MuJoCo's joint deviations q = S x, x a cycloid disc's displacement along its carrier's axes and
    its rotation in place of its polar joints (orbit, radial, own hinge), the identity elsewhere; and S's first
    two time derivatives with the train turning at ``speed_ratio`` times its nominal speeds (the eccentric, at
    angle psi from the carrier's x axis, turning at w_H - Omega).  With (r, t) = x . (e_r(psi), e_t(psi)): radial
    slide r, orbit t / e, own hinge rotation - t / e."""
    n = mb.model.nv
    S, dS, ddS = np.eye(n), np.zeros((n, n)), np.zeros((n, n))
    for mid, member in mb.spec.members.items():
        if member.eccentric is None:
            continue
        e, psi = member.eccentric.eccentricity, member.eccentric.phase
        rate = speed_ratio * (mb.kin.speeds[member.eccentric.crank] - mb.kin.speeds[f"{member.stage}.carrier"])
        dofs = list(mb.dadr[mid].values())  # orbit, radial, own hinge
        i = np.ix_(dofs, dofs)
        for out, scale, angle in ((S, 1.0, psi), (dS, rate, psi + 0.5 * np.pi), (ddS, rate**2, psi + np.pi)):
            c, s = np.cos(angle), np.sin(angle)  # d/dpsi (cos, sin) = (cos, sin) of psi + pi/2
            out[i] = scale * np.array([[-s / e, c / e, 0.0], [c, s, 0.0], [s / e, -c / e, 0.0]])
        S[mb.dadr[mid][ROTATION], mb.dadr[mid][ROTATION]] = 1.0
    return S, dS, ddS


def modes_at_speed(mb, input_speed: float) -> ModalResult:
    """The undamped modes of the twin turning with its input at ``input_speed`` (rad/s, 0 allowed), every
    mesh at its mean stiffness (solver "mujoco"; see the module doc)."""
    m = mb.model
    ratio = input_speed / mb.spec.operating.input_speed if mb.spec.operating.input_speed else 0.0  # at rest: 0
    saved = (m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.tendon_damping.copy(), m.dof_damping.copy(),
             m.actuator_gainprm.copy(), m.actuator_biasprm.copy(), m.wrap_prm.copy())
    try:
        m.tendon_stiffness[mb.mesh_tendon] = mb.excitation.mean_stiffness
        m.tendon_lengthspring[mb.mesh_tendon] = 0.0  # a backlash band closed, as in :func:`stiffness_matrix`
        m.tendon_damping[:] = 0.0
        m.dof_damping[:] = 0.0
        if "input_shaft_damper" in mb.actuator:
            m.actuator_gainprm[mb.actuator["input_shaft_damper"], 0] = 0.0
            m.actuator_biasprm[mb.actuator["input_shaft_damper"], 2] = 0.0
        q0, v0 = m.qpos0.copy(), ratio * nominal_speeds(mb)
        d = mujoco.MjData(m)
        d.qpos[:] = q0
        for c in mb.moving_contacts:  # the contacts of t = 0 frozen, undamped (an RV reducer's pins, needles)
            c.freeze(d)
            c.undamp()
        P = np.zeros((m.nv, m.nv))  # a central member's world-frame slides (and tilts) turning with its carrier
        for (ix, iy), omega in world_turning(mb, ratio):
            P[ix, iy], P[iy, ix] = -omega, omega

        def force(q, v):
            d.qpos[:], d.qvel[:], d.act[:], d.ctrl[:] = q, v, 0.0, 0.0
            mb.refresh(d.qpos)
            mujoco.mj_forward(m, d)
            return d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias

        unbalanced = force(q0, v0)  # the orbits' centripetal loads, which no spring carries at the nominal pose
        A, B = np.zeros((m.nv, m.nv)), np.zeros((m.nv, m.nv))
        for j in range(m.nv):  # hinge and slide joints only: qpos and dof addresses coincide
            e = np.zeros(m.nv)
            e[j] = FD_STEP
            A[:, j] = (force(q0 + e, v0) - force(q0 - e, v0)) / (2 * FD_STEP)
            e[j] = VELOCITY_STEP  # the bias forces are quadratic in qvel: central differences are exact
            B[:, j] = (force(q0, v0 + e) - force(q0, v0 - e)) / (2 * VELOCITY_STEP)
        M = mass_matrix(mb)
    finally:
        (m.tendon_stiffness[:], m.tendon_lengthspring[:], m.tendon_damping[:], m.dof_damping[:],
         m.actuator_gainprm[:], m.actuator_biasprm[:], m.wrap_prm[:]) = saved
    # in the carriers' axes, q = S(t) x (world-frame slides: S = R(Omega t), S' = P, S'' = P^2; discs: _disc_axes):
    # S^T (M S x'' + (2 M S' - B S) x' + (M S'' - B S' - A S) x) = 0
    # (a disc's polar joints are curved in x: its unbalanced load f adds - sum_k f_k d2q_k/dx2)
    S, dS, ddS = _disc_axes(mb, ratio)
    dS, ddS = dS + P, ddS + P @ P
    return speed_modal_result(mb.spec.name, "mujoco", S.T @ M @ S, S.T @ (2 * M @ dS - B @ S),
                              S.T @ (M @ ddS - B @ dS - A @ S) + _disc_curvature(mb, unbalanced), joint_labels(mb),
                              *_central(mb), rad_s_to_rpm(input_speed))


def _disc_curvature(mb, force: np.ndarray) -> np.ndarray:
    """-sum_k f_k d2q_k/dx2 over a disc's polar joints k (:func:`_disc_axes`), ``force`` the generalized force f on
    them: with (r, t) its displacement along and across its eccentric, radial slide sqrt((e + r)^2 + t^2) - e and
    orbit atan2(t, e + r) (own hinge: minus that) have the second derivatives 1/e in t^2 and -1/e^2 in r t."""
    K = np.zeros((mb.model.nv, mb.model.nv))
    for mid, member in mb.spec.members.items():
        if member.eccentric is not None:
            e, psi = member.eccentric.eccentricity, member.eccentric.phase
            dofs = list(mb.dadr[mid].values())
            orbit, radial, own = force[dofs]
            axes = np.array([[np.cos(psi), np.sin(psi)], [-np.sin(psi), np.cos(psi)]])  # rows e_r, e_t
            curvature = np.array([[0.0, (orbit - own) / e**2], [(orbit - own) / e**2, -radial / e]])
            K[np.ix_(dofs[:2], dofs[:2])] = axes.T @ curvature @ axes
    return K
