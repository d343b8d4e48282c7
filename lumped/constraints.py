"""The reference model over fewer coordinates: the train's coordinates q = T q_r, every term reduced alike.

A constraint that ties some of the train's coordinates to others (a held translation, a planet riding rigidly on
its carrier's pin) is a map q = T q_r from the kept coordinates; the model over q_r is the Rayleigh-Ritz
reduction M_r = T^T M T, G_r = T^T G T, K_r = T^T K T, every row a T (so K_b, C and the meshes' K_m(t) reduce with
their rows) and forces T^T F.  The reduced model remembers T (``expansion``) so that what is read of the train's
coordinates (member accelerations, bearing deflections) is read of T q_r.

:func:`torsional` applies it to a train's torsional members (:attr:`gearcheck.train.spec.Member.coordinates`):
a member on the stage axis has its translations held at zero; a planet's centre follows its carrier's pin (the
bearing's two rows :func:`~gearcheck.lumped.elements.bearing.pin_rows` held at zero, so its tangential
coordinate carries r_c theta_c of the carrier's rotation and its axial one the carrier's), which leaves the
purely torsional model of Kahraman (1994) and Lin & Parker (1999, their torsional reduction) when every member is
torsional.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gearcheck.lumped.elements.base import DofMap
from gearcheck.lumped.elements.bearing import pin_rows
from gearcheck.train.spec import AXIAL


def constrained(model, coordinates: list[str], T: np.ndarray):
    """The model over ``coordinates`` (``member.dof`` labels), the train's physical coordinates being T q
    (n x len(q)): M, G and the rotating-frame stiffness as T^T (.) T, every row a as a T.  A coordinate map that
    selects (T a column of the identity) holds the rest; one that combines (a planet's centre riding its pin,
    tangential = r_c theta_c) constrains the model (the Rayleigh-Ritz reduction)."""
    dofs = DofMap()
    for c in coordinates:
        member, dof = c.rsplit(".", 1)
        dofs.add(member, [dof])
    return replace(model, dofs=dofs, M=T.T @ model.M @ T, G=T.T @ model.G @ T,
                   K_centripetal=T.T @ model.K_centripetal @ T, K_circulatory=T.T @ model.K_circulatory @ T,
                   rows=[replace(r, a=r.a @ T) for r in model.rows], mesh_rows=model.mesh_rows @ T,
                   F_static=T.T @ model.F_static, b_input=T.T @ model.b_input, b_output=T.T @ model.b_output,
                   K_euler=T.T @ model.K_euler @ T, F_inertia=T.T @ model.F_inertia,
                   F_centripetal=T.T @ model.F_centripetal,
                   F_rest=None if model.F_rest is None else T.T @ model.F_rest,
                   expansion=T if model.expansion is None else model.expansion @ T,
                   train_dofs=model.train_dofs or model.dofs)


def torsional_map(spec, dofs: DofMap) -> tuple[list[str], np.ndarray]:
    """(kept coordinates, T): the train's coordinates ``dofs`` = T q over each member's
    :attr:`~gearcheck.train.spec.Member.coordinates`; a torsional member's translations held, or, on a pin, its
    centre on the pin (its two :func:`pin_rows` zero: each translation minus the pin's motion, which the carrier's
    coordinates give)."""
    kept = [(m, d) for m, d in dofs.names if d in spec.members[m].coordinates]
    T = np.zeros((len(dofs), len(kept)))
    for j, name in enumerate(kept):
        T[dofs(*name), j] = 1.0
    for mid, member in spec.members.items():  # after every central member's rows: a pin moves with its carrier
        if member.torsional and member.orbits:
            carrier = f"{member.stage}.carrier"
            for row, dof in zip(pin_rows(spec, dofs, mid), member.dofs[:2]):
                i = dofs(mid, dof)
                row[i] = 0.0  # the row is q_i + (the pin's motion . q): q_i = -(that) . q
                T[i] = -row @ T
            if member.axial:
                T[dofs(mid, AXIAL)] = T[dofs(carrier, AXIAL)]
    return [f"{m}.{d}" for m, d in kept], T


def torsional(model):
    """``model`` over its train's free coordinates (:func:`torsional_map`); itself when no member is torsional."""
    if not any(m.torsional for m in model.spec.members.values()):
        return model
    return constrained(model, *torsional_map(model.spec, model.dofs))
