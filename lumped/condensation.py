"""Massless coordinates of a user's model condensed out (Guyan 1965), as whole-drivetrain matrices carry them.

A coordinate whose row and column of M are exactly zero (a shaft node between two springs) has no inertia:
its equation K_sm q_m + K_ss q_s = F_s holds at every instant, so q_s = R q_m + K_ss^-1 F_s with
R = -K_ss^-1 K_sm, and the model over the other coordinates is T^T (.) T with T = [I; R].  That is exact
when nothing else acts on the massless coordinates: no damping (C, the meshes' damping), no gyroscopic or
speed-dependent term (G, K_omega), no mesh row (its stiffness varies in time) and no varying part of K(t);
a model where one does is refused in one line naming the coordinate and the matrix.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gearcheck.lumped.linear_model import LinearModel, Periodic

MOVING = ("C", "G", "K_omega", "G_per_speed", "K_omega_per_speed2")  # terms that would make the condensation inexact


def static_response(K: np.ndarray, s: list[int], m: list[int]) -> np.ndarray | None:
    """R = -K_ss^-1 K_sm: the coordinates ``s`` as the static response to the coordinates ``m`` (Guyan 1965), or
    None when no stiffness of their own holds them (K_ss singular)."""
    K_ss = K[np.ix_(s, s)]
    if np.linalg.matrix_rank(K_ss) < len(s):
        return None
    return -np.linalg.solve(K_ss, K[np.ix_(s, m)])


def condense_massless(model: LinearModel) -> LinearModel:
    """``model`` with its massless coordinates (:attr:`LinearModel.massless`) condensed out, and a note naming
    them; ``model`` itself when it has none."""
    s = model.massless
    if not s:
        return model
    m = [i for i in range(model.n) if i not in s]
    names = [model.coordinates[i] for i in s]
    _refuse_moving(model, s)
    R = static_response(model.matrix("K"), s, m)
    if R is None:
        raise model._error("K", f"massless coordinates {', '.join(names)} are held by no stiffness of their own: "
                           "their static condensation is undetermined")
    T = np.zeros((model.n, len(m)))
    T[m, np.arange(len(m))] = 1.0
    T[s] = R

    def reduce(name):
        return None if getattr(model, name) is None else T.T @ model.matrix(name) @ T

    stiffness = None if model.stiffness is None else _periodic(model.stiffness, lambda A: T.T @ A @ T)
    forcing = model.forcing
    if isinstance(forcing, Periodic):
        forcing = _periodic(forcing, lambda A: A @ T)
    elif forcing is not None:
        forcing = _Projected(forcing, T)
    physical = {label: _combination(combination, model.coordinates, m, T)
                for label, combination in model.physical_map().items()}
    coordinates = [model.coordinates[i] for i in m]
    note = (f"{model.name}: {len(s)} massless coordinate{'s' if len(s) > 1 else ''} ({', '.join(names)}) statically "
            "condensed out (Guyan 1965), exact since no damping, gyroscopic or mesh term acts on "
            f"{'them' if len(s) > 1 else 'it'}.")
    return replace(model, coordinates=coordinates, M=reduce("M"), K=reduce("K"), C=reduce("C"), G=reduce("G"),
                   K_omega=reduce("K_omega"), G_per_speed=reduce("G_per_speed"),
                   K_omega_per_speed2=reduce("K_omega_per_speed2"),
                   F=None if model.F is None else T.T @ model.matrix("F"), stiffness=stiffness, forcing=forcing,
                   meshes=[replace(x, row=np.asarray(x.row, dtype=float)[m]) for x in model.meshes],
                   physical=physical, descriptions={c: d for c, d in model.descriptions.items() if c in coordinates},
                   notes=[*model.notes, note])


def _refuse_moving(model: LinearModel, s: list[int]) -> None:
    """One line naming the first term that acts on a massless coordinate, or a force on one the map reads."""
    for name in MOVING:
        A = getattr(model, name)
        if A is not None and (np.any(A[s]) or np.any(A[:, s])):
            i = next(i for i in s if np.any(A[i]) or np.any(A[:, i]))
            raise model._error(name, f"acts on the massless coordinate {model.coordinates[i]}: give it mass, or "
                               "condense it yourself (exact only without damping and gyroscopic terms on it)")
    for j, mesh in enumerate(model.meshes):
        row = np.asarray(mesh.row, dtype=float)
        if np.any(row[s]):
            i = next(i for i in s if row[i])
            raise model._error(f"meshes[{j}].row", f"{mesh.id} acts on the massless coordinate {model.coordinates[i]} "
                               "(its stiffness varies in time): give it mass")
    if model.stiffness is not None:
        varying = model.stiffness.over_period() - model.stiffness.mean
        if np.any(varying[:, s]) or np.any(varying[:, :, s]):
            i = next(i for i in s if np.any(varying[:, i]) or np.any(varying[:, :, i]))
            raise model._error("stiffness", f"K(t) varies on the massless coordinate {model.coordinates[i]}: give it "
                               "mass")
    mapped = {c for combination in model.physical_map().values() for c in combination}
    forced = model.matrix("F")
    for i in s:
        if model.coordinates[i] in mapped and (forced[i] or model.forcing is not None):
            raise model._error("F", f"a force on the massless coordinate {model.coordinates[i]}, which the map to the "
                               "train reads: its static deflection is not a function of the others; give it mass")


def _periodic(p: Periodic, f) -> Periodic:
    """``p`` with ``f`` applied to each of its arrays (samples, or mean and Fourier coefficients)."""
    return replace(p, **{k: f(getattr(p, k)) for k in ("samples", "mean_value", "cos", "sin")
                         if getattr(p, k) is not None})


def _combination(combination: dict, coordinates: list[str], m: list[int], T: np.ndarray) -> dict:
    """A train coordinate's combination of the model's coordinates, over the kept ones (q_s = R q_m)."""
    row = np.zeros(len(coordinates))
    for c, x in combination.items():
        row[coordinates.index(c)] = x
    reduced = row @ T
    return {coordinates[i]: float(x) for i, x in zip(m, reduced) if x != 0}


class _Projected:
    """A forcing F(t) seen by the kept coordinates: T^T F(t)."""

    def __init__(self, forcing, T: np.ndarray):
        self.forcing, self.T = forcing, T

    def __call__(self, t):
        return np.asarray(self.forcing(t), dtype=float) @ self.T
