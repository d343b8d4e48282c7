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
MuJoCo's central members translate along world axes, which turn under a rotating train; in the axes
of their stage's carrier (x_w = R(Omega t) x_r) the system is time-invariant:
M q_r'' = (A + B P - M P^2) q_r + (B - 2 M P) q_r', P = Omega J on those slides.

Mode types are read from MuJoCo's own coordinates: the kinetic-energy fractions of the central
members' slides (translation) and hinges (rotation), classified by
:func:`gearcheck.shared.modal.mode_types`; they do not depend on MuJoCo's choice of coordinates
(planet slides relative to the carrier).

Every function takes a compiled twin (:class:`gearcheck.mbd_models.twin.MbdModel`).
"""

from __future__ import annotations

import mujoco
import numpy as np

from gearcheck.shared import stepping
from gearcheck.shared.modal import ModalResult, modal_result, speed_modal_result
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


def stiffness_matrix(mb, tendon_stiffness: np.ndarray | None = None,
                     qpos: np.ndarray | None = None) -> np.ndarray:
    """-d(qfrc_passive + qfrc_actuator)/dqpos by central differences, at rest.

    tendon_stiffness: optional stiffness of the mesh tendons (one per mesh) used
    instead of the model's own values (which are restored afterwards).  A backlash
    dead band is closed for the linearisation (the teeth in contact on their loaded
    flank), so a mesh contributes its stiffness k and not the 0 of the band's inside.
    """
    m = mb.model
    saved = m.tendon_stiffness.copy()
    saved_length = m.tendon_lengthspring.copy()
    try:
        m.tendon_lengthspring[mb.mesh_tendon] = 0.0
        if tendon_stiffness is not None:
            m.tendon_stiffness[mb.mesh_tendon] = tendon_stiffness
        d = mujoco.MjData(m)
        q0 = (m.qpos0 if qpos is None else qpos).copy()
        K = np.zeros((m.nv, m.nv))
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


def damping_matrix(mb, qpos: np.ndarray | None = None) -> np.ndarray:
    """-d(qfrc_passive + qfrc_actuator)/dqvel by central differences, at rest: the joints' and tendons'
    damping and the input shaft's damper."""
    m = mb.model
    d = mujoco.MjData(m)
    q0 = m.qpos0 if qpos is None else qpos
    C = np.zeros((m.nv, m.nv))
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
    """RK4 step limits of the MuJoCo model with every mesh at its cycle-maximum stiffness, damping included."""
    return stepping.StepLimits.of(mass_matrix(mb), stiffness_matrix(mb, mb.excitation.max_stiffness),
                                  damping_matrix(mb))


def joint_labels(mb) -> list[str]:
    m = mb.model
    return [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.dof_jntid[i])) for i in range(m.nv)]


def modes(mb) -> ModalResult:
    """Natural frequencies and mode types of the MuJoCo model at mean mesh stiffness (solver "mujoco")."""
    return modal_result(mb.spec.name, "mujoco", stiffness_matrix(mb, mb.excitation.mean_stiffness), mass_matrix(mb),
                        joint_labels(mb), *_central(mb))


def physical_coordinates(mb) -> tuple[list[str], np.ndarray]:
    """(labels, T): the train's physical coordinates as MuJoCo moves them, T (n, nv) mapping a small joint
    motion to them, read from MuJoCo's own Jacobians at rest: each member's centre moves along x, y (a
    planet: along its radial and tangential axes), it turns about z, and in a helical stage it moves
    along z.  The labels are ``member.x`` ... as the lumped model names its coordinates."""
    m = mb.model
    d = mujoco.MjData(m)
    _set_rest(mb, d, m.qpos0)
    mujoco.mj_forward(m, d)
    labels, rows = [], []
    for mid, member in mb.spec.members.items():
        body = mb.body[mid]
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jac(m, d, jp, jr, d.xipos[body], body)
        if member.is_planet:
            c, s = np.cos(member.angle), np.sin(member.angle)
            axes = {"radial": np.array([c, s, 0.0]), "tangential": np.array([-s, c, 0.0])}
        else:
            axes = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0])}
        moves = [(f"{mid}.{name}", axis @ jp) for name, axis in axes.items()] + [(f"{mid}.theta", jr[2])]
        if _axial_dof(mb, mid) is not None:
            moves.append((f"{mid}.z", jp[2]))
        for label, row in moves:
            labels.append(label)
            rows.append(row)
    return labels, np.array(rows)


def _central(mb) -> tuple[list[int], list[int]]:
    """(translation, rotation) dofs of the central members; an axial slide goes with the rotation (a helical
    mesh's axial force goes with its torque: Eritenel & Parker's rotational-axial modes)."""
    central = [mid for mid, member in mb.spec.members.items() if not member.is_planet]
    axial = [dof for mid in central if (dof := _axial_dof(mb, mid)) is not None]
    return [i for mid in central for i in mb.dadr[mid][:2]], [mb.dadr[mid][2] for mid in central] + axial


def _axial_dof(mb, mid: str) -> int | None:
    """The dof address of member ``mid``'s axial slide (a helical stage's members have one), or None."""
    joint = mujoco.mj_name2id(mb.model, mujoco.mjtObj.mjOBJ_JOINT, mb.spec.members[mid].label + "_z")
    return int(mb.model.jnt_dofadr[joint]) if joint >= 0 else None


def modes_at_speed(mb, input_speed: float) -> ModalResult:
    """The undamped modes of the twin turning with its input at ``input_speed`` (rad/s, 0 allowed), every
    mesh at its mean stiffness (solver "mujoco"; see the module doc)."""
    m = mb.model
    ratio = input_speed / mb.spec.operating.input_speed
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
        d = mujoco.MjData(m)
        q0, v0 = m.qpos0.copy(), np.zeros(m.nv)
        P = np.zeros((m.nv, m.nv))
        for mid, member in mb.spec.members.items():
            ix, iy, ir = mb.dadr[mid]
            omega = ratio * mb.kin.speeds[f"{member.stage}.carrier"]
            v0[ir] = ratio * mb.kin.speeds[mid] - (omega if member.is_planet else 0.0)  # planet hinges: relative
            if not member.is_planet:
                P[ix, iy], P[iy, ix] = -omega, omega

        def force(q, v):
            d.qpos[:], d.qvel[:], d.act[:], d.ctrl[:] = q, v, 0.0, 0.0
            mb.refresh(d.qpos)
            mujoco.mj_forward(m, d)
            return d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias

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
    # in the carriers' axes: M s^2 + D s + K with D = -(B - 2 M P), K = -(A + B P - M P^2)
    return speed_modal_result(mb.spec.name, "mujoco", M, 2 * M @ P - B, M @ P @ P - A - B @ P,
                              joint_labels(mb), *_central(mb), rad_s_to_rpm(input_speed))
