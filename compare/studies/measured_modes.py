"""Measured natural frequencies paired with the lumped model's modes, for a calibration.

A measured frequency (a ``[[natural_frequencies]]`` entry of a measurements file) names the model mode it is:

* ``mode = n``: the n-th mode as ``gearcheck modes`` lists them (ascending frequency);
* ``type`` and ``order``: the order-th distinct frequency of the modes of that type (Lin & Parker 1999), which
  follows a mode through a crossing with a mode of another type;
* ``shape`` alone (or with a ``type`` that narrows the candidates): the measured shape over named train
  coordinates, paired with the model frequency whose modes hold the largest share of it.

A measured shape's share in its paired frequency is the mass-weighted MAC (Allemang & Brown 1982) summed over the
modes of that frequency (any basis of a multiple frequency's space), on the measured coordinates with the model's
mass over them, as :mod:`gearcheck.compare.engine.mode_pairing` pairs two models' modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.shared.errors import GearcheckError, did_you_mean
from gearcheck.shared.modal import frequency_groups, modal_assurance


RANK_TOLERANCE = 1e-12  # of a mass-normalised mode's norm: a direction of its modes below it on the measured
# coordinates is round-off, far below any measurable share


@dataclass(frozen=True)
class Paired:
    """The model mode (0-based index, the first of its frequency group) a measured frequency is, its frequency (Hz)
    and, for a measured shape, the shape's share in that frequency's modes (MAC, 1: the same shape)."""

    mode: int
    frequency: float
    mac: float | None


def label(entry: dict) -> str:
    """How reports name a measured frequency: by the pairing it asks for."""
    if entry["mode"] is not None:
        return f"natural frequency, mode {entry['mode']}"
    if entry["shape"] is None:
        return f"natural frequency, {entry['type']} {entry['order'] or 1}"
    kind = "" if entry["type"] is None else f"{entry['type']} "
    return f"natural frequency, {kind}shape over {', '.join(entry['shape'])}"


def pair(entries: list[dict], modal, labels: list[str], M: np.ndarray) -> list[Paired]:
    """Pair every measured frequency in ``entries`` with a mode of ``modal`` (a ModalResult over the coordinates
    ``labels`` with mass matrix ``M``); an entry that names no elastic mode of the model is refused."""
    frequencies = np.asarray(modal.frequencies)
    groups = [g for g in frequency_groups(frequencies) if frequencies[g[0]] > 0]
    out = []
    for entry in entries:
        where = entry["where"]
        candidates = groups if entry["type"] is None else [g for g in groups if modal.types[g[0]] == entry["type"]]
        shares = None if entry["shape"] is None else _shares(entry, candidates, modal, labels, M)
        if entry["mode"] is not None:
            index = entry["mode"] - 1
            if index >= len(frequencies):
                raise GearcheckError(f"{where}.mode: {entry['mode']} but the model has {len(frequencies)} modes")
            if frequencies[index] == 0:
                raise GearcheckError(f"{where}.mode: {entry['mode']} is a rigid-body mode of the model (0 Hz)")
            chosen = next(k for k, g in enumerate(candidates) if index in g)
        elif entry["order"] is not None or shares is None:
            order = entry["order"] or 1
            if order > len(candidates):
                raise GearcheckError(f"{where}.order: {order} but the model has {len(candidates)} {entry['type']} "
                                     "frequencies")
            chosen = order - 1
        else:
            if not candidates:
                raise GearcheckError(f"{where}.type: the model has no {entry['type']} mode")
            chosen = int(np.argmax(shares))
        first = candidates[chosen][0]
        out.append(Paired(first, float(frequencies[first]), None if shares is None else shares[chosen]))
    return out


def _shares(entry: dict, groups: list[list[int]], modal, labels: list[str], M: np.ndarray) -> list[float]:
    """The measured shape's share in each of ``groups``: the sum of its MAC over a mass-orthonormal basis of their
    modes on the measured coordinates."""
    keep = []
    for name in entry["shape"]:
        if name not in labels:
            raise GearcheckError(f"{entry['where']}.shape: the model has no coordinate {name!r}"
                                 + did_you_mean(name, labels))
        keep.append(labels.index(name))
    measured = np.array([[entry["shape"][name]] for name in entry["shape"]])
    mass = M[np.ix_(keep, keep)]
    return [float(modal_assurance(mass, measured, _orthonormal(mass, modal.shapes[np.ix_(keep, g)])).sum())
            for g in groups]


def _orthonormal(mass: np.ndarray, shapes: np.ndarray) -> np.ndarray:
    """A mass-orthonormal basis of the span of ``shapes`` (mass-normalised modes, columns) on the measured
    coordinates, where the modes of a multiple frequency need not be orthogonal: the sum of a shape's MAC over it is
    its share in that span (at most 1).  Directions whose mass norm there is below :data:`RANK_TOLERANCE` of a whole
    mode's are round-off (a translational mode on the rotations) and left out."""
    gram = shapes.T @ mass @ shapes
    values, vectors = np.linalg.eigh((gram + gram.T) / 2)
    kept = values > RANK_TOLERANCE
    return shapes @ vectors[:, kept] / np.sqrt(values[kept])
