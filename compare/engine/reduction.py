"""The reference reduced to a reduced model's coordinates, so that a model with fewer coordinates (a ring
eliminated, a torsional model) is compared with the reference it reduces, not with the full one.

The test's coordinates q are the reference's x = T q on the train coordinates it maps (its map; a selection
where it has none); on the others the reference is reduced as the model declares
(:attr:`~gearcheck.lumped.linear_model.LinearModel.reduction`):

* ``held``: x = 0 there (the coordinates fixed: the Rayleigh-Ritz reduction on T);
* ``condensed``: x = -K_ss^-1 K_sm T q there, the static response (Guyan 1965).

Reduced by Psi so, the reference is Psi^T M Psi, Psi^T K Psi over q.  Its stiffness over the train's
coordinates is the one its modes give, K = M Phi Omega^2 Phi^T M with mass-normalised shapes Phi, which serves
the lumped model and the MuJoCo twin alike.
"""

from __future__ import annotations

import numpy as np

from gearcheck.lumped.condensation import static_response
from gearcheck.lumped.linear_model import REDUCTIONS
from gearcheck.lumped.modal import central_coordinates
from gearcheck.shared.errors import GearcheckError, UnsupportedError
from gearcheck.shared.modal import ModalResult, modal_result


def reduction_basis(K: np.ndarray, T: np.ndarray, mapped: list[bool], how: str) -> np.ndarray:
    """Psi: the reference's coordinates (rows of ``K`` and ``T``) as the test's, T on the ``mapped`` ones and
    on the others 0 (``how`` "held") or the static response to them (``"condensed"``, Guyan 1965)."""
    if how not in REDUCTIONS:
        raise GearcheckError(f"reduction={how!r}: choose {' or '.join(REDUCTIONS)}")
    psi = np.array(T, dtype=float)
    s = [i for i, m in enumerate(mapped) if not m]
    if how == "condensed" and s:
        m = [i for i, x in enumerate(mapped) if x]
        R = static_response(K, s, m)
        if R is None:
            raise GearcheckError("reduction=condensed: the coordinates the model lacks are not held by the rest "
                                 "(their stiffness is singular): they cannot be condensed out; declare them held")
        psi[s] = R @ psi[m]
    return psi


class ReducedReference:
    """The reference as a reduced test model is compared with: its modes over the test's coordinates
    (``modes()``) and in the train's coordinates the test maps (``physical_modes``), as
    :func:`~gearcheck.compare.engine.mode_pairing.pair_modes` reads a side."""

    def __init__(self, spec, reference, labels, M, K, T, mapped, coordinates, how: str):
        self.spec, self.solver, self.references = spec, reference.solver, reference.references
        self.kept = [i for i, m in enumerate(mapped) if m]
        self.labels = [labels[i] for i in self.kept]
        self.M = M[np.ix_(mapped, mapped)]
        self.psi = reduction_basis(K, T, mapped, how)
        self.coordinates = coordinates
        self._K, self._M = self.psi.T @ K @ self.psi, self.psi.T @ M @ self.psi

    def modes(self) -> ModalResult:
        translation, rotation = central_coordinates(self.spec, self.coordinates)
        typed = (translation, rotation) if translation or rotation else (None, None)
        return modal_result(self.spec.name, self.solver, self._K, self._M, self.coordinates, *typed)

    def physical_modes(self, modal: ModalResult) -> tuple[list[str], np.ndarray, np.ndarray]:
        return self.labels, self.M, (self.psi @ modal.shapes)[self.kept]


def reduced_reference(reference, test, modes: tuple) -> tuple[object, ModalResult, str | None]:
    """(the reference as ``test`` is compared with, its modes, one sentence saying how, or None): the reference
    itself where the test has every train coordinate or gives no shapes in them; ``modes``: both sides' modes."""
    modes_a, modes_b = modes
    spec = reference.spec
    try:
        labels, M, shapes = reference.physical_modes(modes_a)
        labels_b, _, _ = test.physical_modes(modes_b)
    except UnsupportedError:
        return reference, modes_a, None
    linear = getattr(test, "linear", None)
    if linear is not None:
        T, mapped = linear.to_physical(labels)
        own = [i for i, c in enumerate(linear.coordinates) if c not in linear.extra]
        T, coordinates, how = T[:, own], [linear.coordinates[i] for i in own], linear.reduction
    else:
        mapped = [label in labels_b for label in labels]
        T, coordinates, how = np.eye(len(labels))[:, mapped], list(labels_b), "held"
    if all(mapped) or M is None or shapes.shape[1] != len(labels) or np.iscomplexobj(shapes):
        return reference, modes_a, None
    phi = shapes / np.sqrt(np.einsum("ip,ij,jp->p", shapes, M, shapes))
    omega2 = (2.0 * np.pi * np.asarray(modes_a.frequencies)) ** 2
    K = M @ (phi * omega2) @ phi.T @ M
    reduced = ReducedReference(spec, reference, labels, M, 0.5 * (K + K.T), T, mapped, coordinates, how)
    held = [label for label, m in zip(labels, mapped) if not m]
    words = {"held": "held", "condensed": "condensed out (Guyan 1965)"}[how]
    ties = "" if T.shape[1] == sum(mapped) else ", the rest tied as its map ties them"
    sentence = (f"{test.solver} has {sum(mapped)} of the {len(labels)} coordinates of {spec.name}; the reference is "
                f"compared with {_short(held)} {words}{ties}.")
    return reduced, reduced.modes(), sentence


def _short(labels: list[str]) -> str:
    """``stage1.ring.x, .y, .theta``: labels of one member after its first by their coordinate alone."""
    out, last = [], None
    for label in labels:
        member, dof = label.rsplit(".", 1)
        out.append(label if member != last else f".{dof}")
        last = member
    return ", ".join(out)
