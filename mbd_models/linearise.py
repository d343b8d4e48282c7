"""Linearisation of the MuJoCo model and its natural frequencies.

M comes from ``mujoco.mj_fullM`` and K from central differences of the generalized
spring forces MuJoCo computes (``qfrc_passive`` + ``qfrc_actuator``: the input shaft's
position servo is a spring too) at the nominal configuration (every joint at its
reference, carrier angle 0), at rest, with every mesh tendon at its mean stiffness.
As in the lumped modal analysis (Lin & Parker 1999, section 3) no rotation terms
enter: the model is linearised at qvel = 0.

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
from gearcheck.shared.modal import ModalResult, modal_result

FD_STEP = 1e-6  # m or rad; the spring forces are linear in qpos, so the step only sets rounding


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
    central = [mb.dadr[mid] for mid, member in mb.spec.members.items() if not member.is_planet]
    return modal_result(mb.spec.name, "mujoco", stiffness_matrix(mb, mb.excitation.mean_stiffness), mass_matrix(mb),
                        joint_labels(mb), [i for x, y, _ in central for i in (x, y)], [rz for _, _, rz in central])
