"""A user's model as a file of matrices (``.mat`` from MATLAB, or ``.npz`` from NumPy), read into a
:class:`~gearcheck.lumped.linear_model.LinearModel` and validated like a train file.

Variables (SI units throughout: kg, m, rad, N, s; n coordinates):

=====================  ======================  =====================================================
name                   shape                   meaning
=====================  ======================  =====================================================
coordinates            n strings               the model's coordinates; without ``physical``, the
                                               train's own labels (``stage1.sun.theta``, ...)
M, K                   n x n                   mass, mean stiffness (without the meshes below); a
                                               coordinate whose row and column of M are exact zeros
                                               is massless and condensed out (Guyan 1965)
C                      n x n (optional)        damping
G, K_omega             n x n (optional)        gyroscopic, speed-dependent stiffness, at the train's
                                               operating speed
G_per_speed            n x n (optional)        G per rad/s of the speed_of speed (instead of G)
K_omega_per_speed2     n x n (optional)        K_omega per (rad/s)^2 of it (instead of K_omega)
speed_of               string (optional)       whose speed the per-speed forms are per: "input"
                                               (default), "carrier" (a single stage) or a member id
F                      n (optional)            mean force
period                 scalar                  s, of every periodic quantity (a mesh cycle)
K_samples              N x n x n (.npz),       K(t) at t = i period / N (mean must be K)
                       n x n x N (.mat)
K_cos, K_sin, orders   H x n x n, H            K(t) = K + sum K_cos cos(2 pi o t / period) + K_sin sin(..)
                       (.mat: n x n x H)
F_samples              N x n (.mat: n x N)     F(t) over the period (mean must be F)
mesh_ids               m strings               the train's mesh ids (``stage1.planet1.sun``)
mesh_rows              m x n                   each mesh's deflection row
mesh_stiffness         m, or m x N             N/m: constant, or samples over the period
mesh_period            m (optional)            s, each mesh's own cycle (default: period)
mesh_damping           m (optional)            N s/m
mesh_interpolation     string (optional)       between the stiffness samples: "linear" (default) or "hold"
                                               (each sample held over its cell: a stiffness with jumps)
mesh_error             m x N (optional)        m, each mesh's static transmission error over the period:
                                               its force is k (row . q - e) + c (row . q' - e')
physical_labels        k strings               train coordinates the model has ...
physical               k x n                   ... as combinations of its coordinates; a coordinate
                                               in no combination is extra (a motor, a coupling):
                                               kept, and the modes it dominates set aside
reduction              string (optional)       the train coordinates the model lacks, in the
                                               reference compared with it: "held" (default) or
                                               "condensed" (Guyan 1965)
name                   string (optional)       how reports name the model (default: the file's stem)
start                  string (optional)       "static" (default) or "rest"
units                  string (optional)       "SI" (the only units accepted)
=====================  ======================  =====================================================

Every error is one line naming the file, the variable and the value.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gearcheck.lumped.linear_model import INTERPOLATIONS, LinearModel, Mesh, Periodic
from gearcheck.shared.errors import TrainFileError, shown
from gearcheck.train.files import read_arrays

SUFFIXES = (".mat", ".npz")
KNOWN = {"coordinates", "M", "K", "C", "G", "K_omega", "G_per_speed", "K_omega_per_speed2", "speed_of", "F", "period",
         "K_samples", "K_cos", "K_sin", "orders", "F_samples", "mesh_ids", "mesh_rows", "mesh_stiffness", "mesh_period",
         "mesh_damping", "mesh_interpolation", "mesh_error", "physical_labels", "physical", "name", "start",
         "reduction", "units"}


def read_matrix_file(path) -> LinearModel:
    """The model in ``path`` (validated in itself; :meth:`LinearModel.check` with the train checks the map)."""
    path = Path(path)
    source = path.name
    if path.suffix not in SUFFIXES:
        raise TrainFileError(source, "", f"a model file is {' or '.join(SUFFIXES)}, not {path.suffix or 'no suffix'!r}")
    data = read_arrays(path, "model file", squeeze_me=True, chars_as_strings=True)
    matlab = path.suffix == ".mat"
    unknown = sorted(set(data) - KNOWN)
    if unknown:
        raise TrainFileError(source, unknown[0], f"unknown variable (known: {', '.join(sorted(KNOWN))})")
    get = _Reader(source, data, matlab)
    units = get.string("units", "SI")
    if units != "SI":
        raise TrainFileError(source, "units", f"{shown(units)}: give every matrix in SI units (kg, m, rad, N, s)")
    coordinates = get.strings("coordinates", required=True)
    n = len(coordinates)
    period = get.scalar("period") if any(k in data for k in ("K_samples", "K_cos", "K_sin", "F_samples",
                                                             "mesh_error")) or (
        "mesh_stiffness" in data and np.ndim(data["mesh_stiffness"]) == 2 and "mesh_period" not in data) else None
    stiffness = None
    if "K_samples" in data:
        stiffness = Periodic(period, samples=get.stack("K_samples", (n, n)))
    elif "K_cos" in data or "K_sin" in data:
        orders = get.array("orders", required=True).reshape(-1)
        H = orders.size
        stiffness = Periodic(period, mean_value=get.array("K", required=True), orders=orders,
                             cos=get.stack("K_cos", (n, n), H), sin=get.stack("K_sin", (n, n), H))
    forcing = Periodic(period, samples=get.stack("F_samples", (n,))) if "F_samples" in data else None
    physical = None
    if "physical_labels" in data or "physical" in data:
        labels = get.strings("physical_labels", required=True)
        T = get.array("physical", required=True)
        if T.shape != (len(labels), n):
            raise TrainFileError(source, "physical", f"shape {T.shape}, expected ({len(labels)}, {n}): a row per "
                                 "physical label, a column per coordinate")
        physical = {label: {c: float(x) for c, x in zip(coordinates, row) if x != 0} for label, row in zip(labels, T)}
    return LinearModel(get.string("name", path.stem), coordinates, get.array("M", required=True),
                       get.array("K", required=True), C=get.array("C"), G=get.array("G"),
                       K_omega=get.array("K_omega"), G_per_speed=get.array("G_per_speed"),
                       K_omega_per_speed2=get.array("K_omega_per_speed2"), speed_of=get.string("speed_of", "input"),
                       F=get.array("F"), stiffness=stiffness, forcing=forcing,
                       meshes=_meshes(get, source, n, period), physical=physical,
                       start=get.string("start", "static"), reduction=get.string("reduction", "held"), source=source)


class _Reader:
    """Typed access to the file's variables, each failure one line naming the variable."""

    def __init__(self, source: str, data: dict, matlab: bool):
        self.source, self.data, self.matlab = source, data, matlab

    def fail(self, name: str, message: str) -> TrainFileError:
        return TrainFileError(self.source, name, message)

    def array(self, name: str, required: bool = False) -> np.ndarray | None:
        if name not in self.data:
            if required:
                raise self.fail(name, "missing")
            return None
        if np.iscomplexobj(self.data[name]):
            raise self.fail(name, "holds complex numbers; a model's matrices are real")
        try:
            return np.atleast_1d(np.asarray(self.data[name], dtype=float))
        except (TypeError, ValueError):
            raise self.fail(name, "not numeric") from None

    def scalar(self, name: str) -> float:
        value = self.array(name, required=True)
        if value.size != 1 or not np.isfinite(value[0]) or value[0] <= 0:
            raise self.fail(name, f"{shown(self.data[name])}: needs one positive number (s)")
        return float(value[0])

    def stack(self, name: str, shape: tuple, count: int | None = None) -> np.ndarray:
        """A stack of arrays of ``shape``: along the first axis (.npz) or the last (.mat, MATLAB's A(:,:,i))."""
        value = self.array(name, required=True)
        if self.matlab and value.ndim == len(shape) + 1:
            value = np.moveaxis(value, -1, 0)
        if value.ndim == len(shape):
            value = value[None]
        if value.shape[1:] != shape or (count is not None and len(value) != count):
            expected = " x ".join(map(str, ((count or "N"), *shape)))
            raise self.fail(name, f"shape {np.shape(self.data[name])}, expected {expected}"
                            + (" (MATLAB: the stack along the last index)" if self.matlab else ""))
        return value

    def strings(self, name: str, required: bool = False) -> list[str]:
        if name not in self.data:
            if required:
                raise self.fail(name, "missing")
            return []
        value = np.atleast_1d(np.asarray(self.data[name], dtype=object)).ravel()
        out = [str(v).strip() if isinstance(v, str) else None for v in value]
        if not out or None in out:
            raise self.fail(name, "needs a list of strings (MATLAB: a cell array of char vectors)")
        return out

    def string(self, name: str, default: str) -> str:
        if name not in self.data:
            return default
        value = np.asarray(self.data[name], dtype=object).ravel()
        if value.size != 1 or not isinstance(value[0], str):
            raise self.fail(name, f"{shown(self.data[name])}: needs one string")
        return value[0].strip()


def _meshes(get: _Reader, source: str, n: int, period: float | None) -> list[Mesh]:
    ids = get.strings("mesh_ids")
    if not ids:
        for name in ("mesh_rows", "mesh_stiffness", "mesh_damping", "mesh_error"):
            if name in get.data:
                raise TrainFileError(source, name, "given without mesh_ids")
        return []
    m = len(ids)
    rows = get.array("mesh_rows", required=True).reshape(-1)
    if rows.size != m * n:
        raise TrainFileError(source, "mesh_rows", f"shape {np.shape(get.data['mesh_rows'])}, expected ({m}, {n})")
    rows = rows.reshape(m, n)
    k = get.array("mesh_stiffness", required=True)
    k = k.reshape(m, -1) if k.size % m == 0 and k.size > 0 else None
    if k is None:
        raise TrainFileError(source, "mesh_stiffness", f"shape {np.shape(get.data['mesh_stiffness'])}, expected "
                             f"({m},) or ({m}, N)")
    c = get.array("mesh_damping")
    c = np.zeros(m) if c is None else c.reshape(-1)
    periods = get.array("mesh_period")
    periods = np.full(m, period if period is not None else np.nan) if periods is None else periods.reshape(-1)
    for name, values in (("mesh_damping", c), ("mesh_period", periods)):
        if values.size != m:
            raise TrainFileError(source, name, f"{values.size} values for {m} meshes")
    if k.shape[1] > 1 and not np.all(periods > 0):
        raise TrainFileError(source, "mesh_period", f"{periods.tolist()}: sampled mesh stiffness needs positive "
                             "periods (s)")
    interpolation = get.string("mesh_interpolation", INTERPOLATIONS[0])
    if interpolation not in INTERPOLATIONS:
        raise TrainFileError(source, "mesh_interpolation", f"{shown(interpolation)}: choose "
                             f"{' or '.join(INTERPOLATIONS)}")
    errors = [None] * m
    if "mesh_error" in get.data:
        e = get.array("mesh_error")
        if e.size % m or e.size < 2 * m:
            raise TrainFileError(source, "mesh_error", f"shape {np.shape(get.data['mesh_error'])}, expected ({m}, N): "
                                 "each mesh's samples over the period")
        errors = [Periodic(period, samples=row) for row in e.reshape(m, -1)]
    return [Mesh(i, rows[j], Periodic(float(periods[j]), samples=k[j], interpolation=interpolation)
                 if k.shape[1] > 1 else float(k[j, 0]),
                 float(c[j]), errors[j]) for j, i in enumerate(ids)]
