"""Mesh stiffness models: k as a function of the mesh position.

The mesh position xi is the number of mesh cycles elapsed (one cycle = one base pitch
of travel along the line of action); xi = 0 is the instant a new tooth pair enters
contact.  Every model is a class with a ``name``, a ``parameters`` table (the schema of
its keys in the train file's ``stiffness`` table, checked and converted to SI like any
other field), a ``mean`` and ``__call__(xi) -> k``; it is built from those parameters
and the mesh (:class:`lumped.spec.MeshSpec`: both gears and the operating geometry).
Both solvers call the same objects, so a new model is one new class registered in
:data:`MODELS`.
"""

from __future__ import annotations

import math

import numpy as np

from .schema import Positive, Table


class MeshStiffness:
    """Base class; subclasses set ``name``, ``parameters`` and implement ``__call__``."""

    name = ""
    parameters = Table({"mean": Positive("mean mesh stiffness over a mesh cycle", "N/m")})

    def __init__(self, params: dict, mesh):
        self.mean = float(params["mean"])
        self.contact_ratio = mesh.geometry.contact_ratio

    def __call__(self, xi):
        raise NotImplementedError

    @property
    def maximum(self) -> float:
        """The largest stiffness over a cycle (what the time step must resolve); sampled unless a
        model knows it exactly."""
        return float(np.max(self(np.linspace(0.0, 1.0, 2001))))

    def __repr__(self) -> str:
        return f"{type(self).__name__}(mean={self.mean:.6g} N/m)"


class ConstantStiffness(MeshStiffness):
    """k(xi) = k_mean."""

    name = "constant"

    def __call__(self, xi):
        return np.full_like(np.asarray(xi, dtype=float), self.mean)


class RectangularStiffness(MeshStiffness):
    """Rectangular wave from the transverse contact ratio eps.

    The number of tooth pairs in contact is ceil(eps) during the first eps - floor(eps)
    of each cycle and floor(eps) for the rest; each pair carries k_mean/eps, so the
    cycle average is k_mean.
    """

    name = "rectangular"

    def __init__(self, params: dict, mesh):
        super().__init__(params, mesh)
        self.pairs_low = math.floor(self.contact_ratio)
        self.multi_fraction = self.contact_ratio - self.pairs_low
        self.pair_stiffness = self.mean / self.contact_ratio

    def pairs(self, xi):
        frac = np.mod(np.asarray(xi, dtype=float), 1.0)
        return self.pairs_low + (frac < self.multi_fraction)

    def __call__(self, xi):
        return self.pair_stiffness * self.pairs(xi)


MODELS: dict[str, type[MeshStiffness]] = {cls.name: cls for cls in (ConstantStiffness, RectangularStiffness)}


def stiffness_model(mesh) -> MeshStiffness:
    """The stiffness object of a :class:`~lumped.spec.MeshSpec` (parameters already checked, SI)."""
    return MODELS[mesh.stiffness["model"]](mesh.stiffness, mesh)
