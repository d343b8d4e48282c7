"""Rows of fixed tendons: from MuJoCo's own Jacobians, the coefficients over all dofs of a point's relative
displacement along a direction, or of a relative rotation about one, at the data's configuration; and the
coefficients as a compiled model holds them.

The twin's tendons whose coefficients are not written from a formula (a mesh's rows, a bearing station's) take
them from here (:mod:`gearcheck.mbd_models.twin`), so every kinematic relation (a planet on its carrier, a tilt
moving a point off the axis) is MuJoCo's.
"""

from __future__ import annotations

import mujoco
import numpy as np


def named(model, kind, name: str) -> int:
    """The id of the ``kind`` object ``name`` of the compiled model (KeyError when it has none)."""
    i = mujoco.mj_name2id(model, kind, name)
    if i < 0:
        raise KeyError(f"no {kind} named {name!r} in the MuJoCo model")
    return i


def rows_combined(weights, rows: np.ndarray) -> np.ndarray:
    """sum_i weights[i] rows[i], added in index order.

    Written out rather than as a matrix product: BLAS picks its kernel (and with it the order of the
    additions and the use of fused multiply-adds) by processor and environment, and the coefficients
    written into the MJCF must come out the same to the last bit on every machine.
    """
    total = weights[0] * rows[0]
    for weight, row in zip(weights[1:], rows[1:]):
        total = total + weight * row
    return total


def point_row(model, data, body: int, reference: int, point, direction) -> np.ndarray:
    """direction . (Jp_body(point) - Jp_reference(point)): the displacement of ``body``'s material at ``point``
    relative to ``reference``'s there (the world, body 0: absolute), along ``direction`` (world frame).  ``data``
    must have its kinematics computed (``mj_kinematics`` and ``mj_comPos``, or ``mj_forward``)."""
    jac_b, jac_r = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    mujoco.mj_jac(model, data, jac_b, None, point, body)
    mujoco.mj_jac(model, data, jac_r, None, point, reference)
    return rows_combined(direction, jac_b - jac_r)


def rotation_row(model, data, body: int, reference: int, direction) -> np.ndarray:
    """direction . (Jr_body - Jr_reference): the small rotation of ``body`` relative to ``reference`` about
    ``direction`` (world frame), as :func:`point_row`."""
    jac_b, jac_r = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    mujoco.mj_jac(model, data, None, jac_b, data.xpos[body], body)
    mujoco.mj_jac(model, data, None, jac_r, data.xpos[reference], reference)
    return rows_combined(direction, jac_b - jac_r)


def tendon_rows(model, tendons) -> np.ndarray:
    """(len(tendons), nv) coefficients of fixed tendons as the model holds them now."""
    J = np.zeros((len(tendons), model.nv))
    for j, t in enumerate(tendons):
        wraps = np.arange(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t])
        J[j, model.jnt_dofadr[model.wrap_objid[wraps]]] = model.wrap_prm[wraps]
    return J
