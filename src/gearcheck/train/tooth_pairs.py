"""The tooth pairs of a mesh, one per slice of the face and per tooth in contact: their stiffness and the gap
their gears' tip reliefs open, as functions of the mesh position.

Thin-slice model (Velex & Maatar 1996; :func:`gearcheck.train.helical_mesh.contact_pairs`): a pair has
the stiffness per unit face width that gives the mesh its mean stiffness, k_mean / (eps_a b), so that
without relief the pairs add up to the contact-line model.  A pair's gap is the sum of both gears'
reliefs at its place on the path of contact, where the planet's tip enters a sun mesh and the ring's tip a
ring mesh (the convention of :mod:`gearcheck.train.kinematics` and :mod:`gearcheck.train.tooth_stiffness`).
The mesh force over the pairs is sum_j k_j max(0, delta - e_j) (Harris 1958).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.train import helical_mesh

DYNAMIC_SLICES = 20  # slices across a helical face in the time solvers (each pair-slice is a contact)


def relieved(mesh) -> bool:
    """Whether a gear of ``mesh`` carries a tip relief."""
    return bool(mesh.central_gear.relief_amount or mesh.planet_gear.relief_amount)


def mesh_relief(mesh):
    """e(s): the gap both gears' tip reliefs open at s from the start of contact (m)."""
    first, last = (mesh.central_gear, mesh.planet_gear) if mesh.internal else (mesh.planet_gear, mesh.central_gear)
    path = mesh.geometry.contact_ratio * mesh.geometry.base_pitch

    def tip(gear, at_start: bool):
        shape = "parabolic" if gear.relief_power == 2 else "linear"
        amount, length = gear.relief_amount, gear.relief_length
        if at_start:
            return lambda s: helical_mesh.relief_separation(s, path, 0.0, 0.0, amount, length, shape)
        return lambda s: helical_mesh.relief_separation(s, path, amount, length, 0.0, 0.0, shape)

    start, end = tip(first, True), tip(last, False)
    return lambda s: start(s) + end(s)


class ToothPairs:
    """(k_j, e_j) of every slice-and-pair j of ``mesh`` at mesh positions xi: shape xi.shape + (size,);
    pairs out of contact have k = 0 and e = inf.  ``slices`` across a helical face (a spur face is one)."""

    def __init__(self, mesh, mean_stiffness: float, slices: int = DYNAMIC_SLICES):
        g = mesh.geometry
        self.slices = slices if g.face_contact_ratio else 1
        self.size = self.slices * math.ceil(g.contact_ratio + g.face_contact_ratio)
        per_width = mean_stiffness / (g.contact_ratio * g.face_width)
        self._stiffness = lambda s: np.full(np.shape(s), per_width)
        self._line = (g.contact_ratio, g.face_contact_ratio, g.base_pitch, g.face_width)
        self._relief = mesh_relief(mesh)

    def __call__(self, xi):
        return helical_mesh.contact_pairs(xi, *self._line, self._stiffness, self.slices, self._relief)
