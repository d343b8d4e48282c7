"""What holds a member in the plane and in tilt, shared by a support on the housing
(:mod:`~gearcheck.lumped.elements.support`) and a bearing on a carrier's pin
(:mod:`~gearcheck.lumped.elements.bearing`).

Both hold a member by pairs of perpendicular rows along its two translation axes: at its centre of mass, or, for a
tilting member, at each bearing station p along the axis, whose point deflects by the translations' rows plus
phi x (p e_z) = p (phi_2, -phi_1), phi_1 and phi_2 the tilts (relative to the holder) about the two axes
(Eritenel & Parker 2009's bearing at an axial station); and a pair on the tilts for a tilting stiffness.  A seat
tilted by gamma (a misaligned pin, a misaligned seat in the housing) holds the member where the rows rest: the
stations off by gamma x (p e_z), the tilts by gamma.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from gearcheck.lumped.elements.base import Row


class Pair(NamedTuple):
    """Two perpendicular rows of one connection: names, rows, stiffness, damping, and their rest deflections."""

    names: tuple[str, str]
    rows: tuple[np.ndarray, np.ndarray]
    stiffness: float
    damping: float
    rest: tuple[float, float]


def holding_pairs(prefix: str, axes, translations, tilt_names, tilts, holder, tilting: bool) -> list[Pair]:
    """The pairs that ``holder`` (a Support) makes of a member whose translations along ``axes`` (their names) are
    the rows ``translations`` and whose tilts (``tilt_names``) relative to the holder are the rows ``tilts``; row
    names ``prefix`` + an axis's name (+ ``.station<i>``)."""
    names = tuple(f"{prefix}{axis}" for axis in axes)
    pairs = [Pair(names, tuple(translations), holder.radial_stiffness, holder.radial_damping, (0.0, 0.0))]
    if not tilting:
        return pairs
    (a_u, a_v), (t_u, t_v), (gamma_1, gamma_2) = translations, tilts, holder.rest_tilt
    pairs = [Pair(tuple(f"{name}.station{i + 1}" for name in names), (a_u + st.position * t_v, a_v - st.position * t_u),
                  st.radial_stiffness, st.radial_damping, (st.position * gamma_2, -st.position * gamma_1))
             for i, st in enumerate(holder.stations)] or pairs
    if holder.tilting_stiffness or holder.tilting_damping:
        pairs.append(Pair(tuple(f"{prefix}{t}" for t in tilt_names), tuple(tilts), holder.tilting_stiffness,
                          holder.tilting_damping, (gamma_1, gamma_2)))
    return pairs


def pair_rows(pairs: list[Pair], kind: str) -> list[Row]:
    """The rows of ``pairs``, each pair's two in turn."""
    return [Row(name, kind, a, p.stiffness, p.damping, rest) for p in pairs
            for name, a, rest in zip(p.names, p.rows, p.rest)]
