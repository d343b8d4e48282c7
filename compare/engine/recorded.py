"""Results from another solver (Simulink, MATLAB, a user's own code), read, checked and presented as a
:class:`~gearcheck.shared.side.Side` the cross-check compares against its reference model.

Time series (:func:`read_time_series`): a ``.csv`` (header row), ``.parquet`` or ``.mat`` file (each
mapped column a numeric vector variable of that name: MATLAB ``save -v7``, not ``-v7.3``), read through
a column map, a dict or a TOML file (:func:`read_column_map`)::

    solver = "simulink"            # how reports name it (default: the data file's stem)
    time = "t"                     # the time column (default "t")
    time_unit = "s"                # s (default) or ms
    [signals]                      # gearcheck signal name = column, or a table
    "stage1.carrier.alpha" = "alpha_c"
    "stage1.ring.ay.world" = { column = "ay_ring", unit = "mm/s^2" }
    "stage1.planet1.sun.force" = { column = "F_sp1", scale = -1.0 }

A signal's value in SI is ``scale`` x the column x the factor of its ``unit`` (:data:`UNITS`: the
signal's own SI unit or one of a few alternatives).  The time must be strictly increasing and uniform:
each sample within ``UNIFORM_TOLERANCE`` of a step from the uniform grid (the engine's integration
check takes the record's one step; log at a fixed sample time and write the times at full precision).
It is shifted to start at 0 (the original start is ``info["start_s"]``).  Rows in messages count the
data rows from 1, header not counted.

Modes (:func:`read_modes`): an ``.npz`` or ``.mat`` file with ``frequencies`` (Hz, a vector) and
optionally ``shapes`` (n_coordinates x n_modes, real or complex), ``coordinates`` (the names of the
shapes' rows: the train's physical coordinates, ``stage1.sun.x``, ``stage1.planet1.tangential``,
``stage1.ring.theta``, ..., any order, a subset allowed) and ``mass`` (n_coordinates x n_coordinates,
symmetric positive definite); or a ``.csv`` with a ``frequency_hz`` column (frequencies only; other
columns ignored).  Unsorted frequencies are sorted, their shapes with them; the rows are put in the
reference model's coordinate order.

Every problem is a :class:`~gearcheck.shared.errors.GearcheckError` of one line naming the file, the
field or column and the value.
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from gearcheck.lumped.assembly import build_model
from gearcheck.train.files import MAX_DATA_BYTES, read_arrays, read_bytes, read_toml
from gearcheck.lumped.modal import central_coordinates
from gearcheck.shared.errors import GearcheckError, TrainFileError, UnsupportedError, did_you_mean, one_line, shown
from gearcheck.shared.modal import ModalResult, energy_fractions, mode_types, multiplicities, rigid_or_elastic
from gearcheck.shared.results import TimeResult, train_signals
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.side import Side

UNITS = {  # a signal's SI unit -> the units a column may hold it in, with the factor to SI
    "m/s^2": {"m/s^2": 1.0, "mm/s^2": 1e-3, "g": 9.80665},
    "rad/s^2": {"rad/s^2": 1.0, "deg/s^2": math.pi / 180.0},
    "N": {"N": 1.0, "kN": 1e3},
    "m": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6},
    "N/m": {"N/m": 1.0, "N/mm": 1e3, "N/um": 1e6},
    "1": {"1": 1.0},
}
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
UNIFORM_TOLERANCE = 1e-3  # largest deviation of a sample time from the uniform grid, in steps (printed times)
SERIES_SUFFIXES = (".csv", ".parquet", ".mat")
MODES_SUFFIXES = (".npz", ".mat", ".csv")
MIN_COVERAGE = 0.5  # a run asks for at most 1 / MIN_COVERAGE times the recorded duration
SYMMETRY_TOLERANCE = 1e-9  # relative to the largest mass entry


@dataclass(frozen=True)
class Column:
    """Where one signal comes from: SI value = ``scale`` x column x the factor of ``unit``."""

    column: str
    scale: float = 1.0
    unit: str | None = None  # None: the signal's own unit


@dataclass(frozen=True)
class ColumnMap:
    """A checked column map; ``source`` names it in messages."""

    signals: dict[str, Column]
    time: str = "t"
    time_unit: str = "s"
    solver: str | None = None
    source: str = "column map"


def read_column_map(path: str | Path) -> ColumnMap:
    """The column map of a TOML file."""
    return column_map(read_toml(path, "column map"), str(path))


def column_map(doc: Mapping, source: str = "column map") -> ColumnMap:
    """The column map of a dict in the TOML layout (module docstring); ``source`` names it in messages."""
    if not isinstance(doc, Mapping):
        raise TrainFileError(source, "", f"a column map is a table, got {type(doc).__name__}")
    unknown = sorted(set(doc) - {"solver", "time", "time_unit", "signals"})
    if unknown:
        raise TrainFileError(source, str(unknown[0]), "unknown key (known: solver, time, time_unit, signals)")
    solver = doc.get("solver")
    if solver is not None:
        _name(solver, source, "solver")
    time = _name(doc.get("time", "t"), source, "time")
    time_unit = doc.get("time_unit", "s")
    if time_unit not in TIME_UNITS:
        raise TrainFileError(source, "time_unit", f"{time_unit!r} is not a time unit: use s or ms")
    entries = doc.get("signals")
    if not isinstance(entries, Mapping):
        raise TrainFileError(source, "signals", f"a table of signal = column, got {shown(entries)}")
    if not entries:
        raise TrainFileError(source, "signals", "maps no signal")
    return ColumnMap({str(name): _column(entry, source, _key(name)) for name, entry in entries.items()},
                     time, time_unit, solver, source)


def _column(entry, source: str, where: str) -> Column:
    if isinstance(entry, str):
        return Column(_name(entry, source, where))
    if not isinstance(entry, Mapping):
        raise TrainFileError(source, where, f"a column name or a table {{column, scale, unit}}, got {shown(entry)}")
    unknown = sorted(set(entry) - {"column", "scale", "unit"})
    if unknown:
        raise TrainFileError(source, f"{where}.{unknown[0]}", "unknown key (known: column, scale, unit)")
    if "column" not in entry:
        raise TrainFileError(source, where, "names no column")
    scale = entry.get("scale", 1.0)
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) or scale == 0:
        raise TrainFileError(source, f"{where}.scale", f"a finite non-zero number, got {shown(scale)}")
    unit = entry.get("unit")
    if unit is not None and not isinstance(unit, str):
        raise TrainFileError(source, f"{where}.unit", f"a unit name, got {shown(unit)}")
    return Column(_name(entry["column"], source, f"{where}.column"), float(scale), unit)


def _name(value, source: str, where: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise TrainFileError(source, where, f"a column name, got {shown(value)}")
    return value


def read_time_series(path: str | Path, spec, columns: ColumnMap | Mapping | str | Path) -> TimeResult:
    """The signals ``columns`` maps (a :class:`ColumnMap`, a dict in the TOML layout or the path of a TOML map),
    read from ``path`` and converted to SI: a :class:`TimeResult` of those signals only (the
    :func:`~gearcheck.shared.results.train_signals` of ``spec``, in their order), its solver the map's
    ``solver`` (default: the file's stem); ``info``: ``dt_s`` (the uniform step), ``source`` (file name),
    ``start_s`` (the first time, before the shift to 0) and ``samples``."""
    path = Path(path)
    source = str(path)
    cmap = columns if isinstance(columns, ColumnMap) else (
        column_map(columns, f"column map of {source}") if isinstance(columns, Mapping) else read_column_map(columns))
    factors = _factors(cmap, spec)
    data = _read_table(path, SERIES_SUFFIXES)
    raw_t = _vector(data, cmap.time, source, "the time")
    if raw_t.size < 2:
        raise TrainFileError(source, _field(source, cmap.time), f"holds {raw_t.size} sample(s): at least 2 needed")
    t = _finite(raw_t, source, _field(source, cmap.time)) * TIME_UNITS[cmap.time_unit]
    dt = _uniform_step(t, source, cmap.time, cmap.time_unit)
    signals = [s for s in train_signals(spec) if s.name in cmap.signals]
    values = np.empty((t.size, len(signals)))
    for j, s in enumerate(signals):
        name = cmap.signals[s.name].column
        x = _vector(data, name, source, f"for {s.name}")
        if x.size != t.size:
            raise TrainFileError(source, _field(source, name), f"has {x.size} values, the time {cmap.time!r} {t.size}")
        values[:, j] = _finite(x, source, _field(source, name)) * factors[s.name]
    info = {"dt_s": dt, "source": path.name, "start_s": float(t[0]), "samples": int(t.size)}
    return TimeResult(spec.name, cmap.solver or path.stem, t - t[0], signals, values, 0.0, info)


def _factors(cmap: ColumnMap, spec) -> dict[str, float]:
    """Each mapped signal's factor to SI (scale x unit), the names and units checked against ``spec``."""
    known = {s.name: s for s in train_signals(spec)}
    factors = {}
    for name, col in cmap.signals.items():
        if name not in known:
            raise TrainFileError(cmap.source, _key(name), f"not a signal of {spec.name}"
                                 + _closest(name, known))
        unit = known[name].unit
        allowed = UNITS.get(unit, {unit: 1.0})
        given = unit if col.unit is None else col.unit
        if given not in allowed:
            raise TrainFileError(cmap.source, f"{_key(name)}.unit", f"{given!r} is not a unit of this signal "
                                 f"({unit}): use {', '.join(allowed)}")
        factors[name] = col.scale * allowed[given]
    return factors


def _closest(name: str, known) -> str:
    """The did-you-mean of a few signal names like ``name``: those of the same last part (``force``, ``alpha``
    ...) first."""
    last = name.rsplit(".", 1)[-1]
    pool = [n for n in known if n.rsplit(".", 1)[-1] == last] or list(known)
    return did_you_mean(name, pool, n=3, cutoff=0)


def _uniform_step(t: np.ndarray, source: str, column: str, unit: str) -> float:
    """The one step (s) of the times ``t`` (s): strictly increasing, each within ``UNIFORM_TOLERANCE`` steps
    of the uniform grid from the first to the last."""
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0)) + 1
        scale = TIME_UNITS[unit]
        raise TrainFileError(source, _field(source, column), f"time not strictly increasing at row {i + 1} "
                             f"({t[i] / scale:.9g} {unit} after {t[i - 1] / scale:.9g} {unit})")
    dt = (t[-1] - t[0]) / (t.size - 1)
    deviation = np.abs(t - (t[0] + dt * np.arange(t.size))) / dt
    worst = int(np.argmax(deviation))
    if deviation[worst] > UNIFORM_TOLERANCE:
        raise TrainFileError(source, _field(source, column), f"time step not uniform: row {worst + 1} lies "
                             f"{deviation[worst]:.3g} of the mean step {dt:.6g} s off the uniform grid (at most "
                             f"{UNIFORM_TOLERANCE:g}); the integration check needs one step: log at a fixed "
                             "sample time and write the times at full precision")
    return float(dt)


def read_modes(path: str | Path, spec, solver: str | None = None) -> tuple[ModalResult, list[str], np.ndarray | None]:
    """(modes, coordinate labels, mass matrix or None) of a modes file (module docstring).

    The modes' solver is ``solver`` (default: the file's stem); their shapes' rows and the mass are put in
    the order of ``spec``'s reference model coordinates (the labels returned, also ``dof_labels``).  Types:
    Lin & Parker's when the shapes cover every coordinate (energy shares weighted by the file's mass, or
    the reference model's without one), rigid/elastic otherwise."""
    path = Path(path)
    source = str(path)
    data = _read_table(path, MODES_SUFFIXES)
    field = "frequency_hz" if path.suffix.lower() == ".csv" else "frequencies"
    frequencies = _finite(_vector(data, field, source, "natural frequencies in Hz"), source, _field(source, field),
                          "value")
    if frequencies.size == 0:
        raise TrainFileError(source, _field(source, field), "holds no frequency")
    if np.any(frequencies < 0):
        i = int(np.argmax(frequencies < 0))
        raise TrainFileError(source, _field(source, field),
                             f"value {i + 1} is {frequencies[i]:.6g} Hz: frequencies are >= 0")
    order = np.argsort(frequencies, kind="stable")
    frequencies = frequencies[order]
    solver = solver or path.stem
    extras = [k for k in ("shapes", "coordinates", "mass") if k in data and field == "frequencies"]
    if not extras:
        return (ModalResult(spec.name, frequencies, np.zeros((0, frequencies.size)), rigid_or_elastic(frequencies),
                            multiplicities(frequencies), [], solver), [], None)
    for needed in ("shapes", "coordinates"):
        if needed not in extras:
            raise TrainFileError(source, _field(source, needed), f"missing (the file has {' and '.join(extras)}): "
                                 "mode shapes need shapes and coordinates")
    model = build_model(spec)
    known = model.dofs.labels()
    coordinates = _labels(data["coordinates"], source, known)
    shapes = _matrix(data["shapes"], source, "shapes", (len(coordinates), frequencies.size), "coordinates x modes",
                     complex_ok=True)
    zero = np.where(~np.any(shapes, axis=0))[0]
    if zero.size:
        raise TrainFileError(source, _field(source, "shapes"), f"the shape of mode {zero[0] + 1} is zero")
    rows = sorted(range(len(coordinates)), key=lambda i: known.index(coordinates[i]))
    labels = [coordinates[i] for i in rows]
    shapes = shapes[np.ix_(rows, order)]
    mass = _mass(data["mass"], source, len(coordinates))[np.ix_(rows, rows)] if "mass" in extras else None
    types, fractions = rigid_or_elastic(frequencies), None
    if labels == known:
        fractions = energy_fractions(model.M if mass is None else mass, shapes,
                                     *central_coordinates(spec, model.dofs.labels()))
        types = mode_types(fractions, frequencies)
    modal = ModalResult(spec.name, frequencies, shapes, types, multiplicities(frequencies), labels, solver, fractions)
    return modal, labels, mass


def _labels(raw, source: str, known: list[str]) -> list[str]:
    out = []
    for item in np.asarray(raw, dtype=object).ravel():
        if isinstance(item, np.ndarray):  # a MATLAB cell holds char arrays
            item = item.ravel()[0] if item.size == 1 else item
        if not isinstance(item, str):
            raise TrainFileError(source, _field(source, "coordinates"), f"holds {shown(item)}, not a coordinate name")
        label = item.strip()
        if label not in known:
            raise TrainFileError(source, _field(source, "coordinates"), f"{label!r} is not a coordinate of the train"
                                 + did_you_mean(label, known, n=3, cutoff=0))
        if label in out:
            raise TrainFileError(source, _field(source, "coordinates"), f"{label!r} appears twice")
        out.append(label)
    if not out:
        raise TrainFileError(source, _field(source, "coordinates"), "names no coordinate")
    return out


def _matrix(raw, source: str, field: str, shape: tuple[int, int], axes: str, complex_ok: bool = False) -> np.ndarray:
    """``raw`` checked: numbers (complex ones where ``complex_ok``), of ``shape`` (``axes`` in messages), finite."""
    x = np.asarray(raw)
    where = _field(source, field)
    if x.dtype.kind not in ("biufc" if complex_ok else "biuf"):
        raise TrainFileError(source, where, f"holds {x.dtype} values: {'real or complex' if complex_ok else 'real'} "
                             "numbers needed")
    if x.shape != shape:
        raise TrainFileError(source, where, f"is {'x'.join(map(str, x.shape)) or 'a scalar'}, expected "
                             f"{shape[0]}x{shape[1]} ({axes})")
    bad = ~np.isfinite(x)
    if np.any(bad):
        i, j = np.argwhere(bad)[0]
        raise TrainFileError(source, where, f"entry ({i + 1}, {j + 1}) is {x[i, j]}: finite numbers needed")
    return x.astype(complex if x.dtype.kind == "c" else float)


def _mass(raw, source: str, n: int) -> np.ndarray:
    M = _matrix(raw, source, "mass", (n, n), "coordinates x coordinates")
    asymmetry = float(np.max(np.abs(M - M.T)))
    if asymmetry > SYMMETRY_TOLERANCE * float(np.max(np.abs(M))):
        raise TrainFileError(source, _field(source, "mass"), f"not symmetric (|M - M^T| up to {asymmetry:.3g})")
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise TrainFileError(source, _field(source, "mass"), "not positive definite") from None
    return M


def _read_table(path: Path, suffixes: tuple[str, ...]) -> dict:
    """The columns (or variables) of a data file by name."""
    source = str(path)
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        raise TrainFileError(source, "", f"unknown file type {path.suffix or '(no suffix)'!r}: use "
                             f"{', '.join(suffixes)}")
    if suffix in (".mat", ".npz"):
        return read_arrays(path, "data file")
    stream = io.BytesIO(read_bytes(path, "data file", MAX_DATA_BYTES))
    try:
        frame = pd.read_csv(stream, skipinitialspace=True) if suffix == ".csv" else pd.read_parquet(stream)
    except ImportError as exc:
        raise TrainFileError(source, "", f"cannot read {suffix} files: {one_line(exc)}") from None
    except Exception as exc:  # pandas and pyarrow raise many kinds on a damaged file
        raise TrainFileError(source, "", f"cannot be read as {suffix}: {one_line(exc)}") from None
    return {str(c): frame[c].to_numpy() for c in frame.columns}


def _vector(data: dict, name: str, source: str, what: str) -> np.ndarray:
    """Column ``name`` (``what`` it is for, in messages) as a 1-D array; a .mat variable may be a row or column."""
    where = _field(source, name)
    if name not in data:
        have = ", ".join(map(repr, list(data)[:8])) + (", ..." if len(data) > 8 else "")
        raise TrainFileError(source, where, f"not in the file ({what}; it has {have or 'nothing'})")
    x = np.asarray(data[name])
    if x.ndim > 1 and sorted(x.shape)[:-1] != [1] * (x.ndim - 1):
        raise TrainFileError(source, where, f"is a {'x'.join(map(str, x.shape))} array, not a vector")
    if x.dtype.kind in "US":
        raise TrainFileError(source, where, f"holds text {shown(str(x.ravel()[0]) if x.size else '')}, not numbers")
    if x.dtype.kind in "cV":
        raise TrainFileError(source, where, f"holds {x.dtype} values, not real numbers")
    return x.ravel()


def _finite(x: np.ndarray, source: str, field: str, item: str = "row") -> np.ndarray:
    """``x`` as floats; the first value that is not a finite number is an error (its ``item`` counted from 1)."""
    values = x.astype(float) if x.dtype.kind in "biuf" else np.array([_float(v) for v in x], dtype=float)
    bad = ~np.isfinite(values)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise TrainFileError(source, field, f"{item} {i + 1} holds {shown(x[i])}, not a finite number")
    return values


def _float(value) -> float:
    """A number or the text of one as a float, anything else NaN."""
    try:
        return float(value) if isinstance(value, (str, int, float, np.number)) else math.nan
    except ValueError:
        return math.nan


def _field(source: str, name: str) -> str:
    """How messages name a column of a table, or a variable of a .mat or .npz file."""
    return f"{'variable' if source.lower().endswith(('.mat', '.npz')) else 'column'} {name!r}"


def _key(name) -> str:
    return f'signals."{name}"'



class RecordedSide(Side):
    """Another solver's results as a :class:`~gearcheck.shared.side.Side`: the recorded time series (read and
    checked at construction) and, with ``modes_path``, its modes.  Nothing is re-run: ``rerunnable`` is False,
    :meth:`run` returns the recording whatever its settings ask (the engine compares the overlap)."""

    rerunnable = False
    kind = "recording"

    def __init__(self, spec, series_path: str | Path, columns: ColumnMap | Mapping | str | Path,
                 modes_path: str | Path | None = None):
        self.spec = spec
        self.series = read_time_series(series_path, spec, columns)
        self.solver = self.series.solver
        self._modes = None if modes_path is None else read_modes(modes_path, spec, self.solver)

    @property
    def has_modes(self) -> bool:
        return self._modes is not None

    @property
    def duration(self) -> float:
        """The recorded time span (s)."""
        return float(self.series.t[-1])

    def modes(self) -> ModalResult:
        if self._modes is None:
            raise UnsupportedError(f"{self.solver}: no modes file was given, so there are no natural frequencies")
        return self._modes[0]

    def physical_modes(self, modal: ModalResult) -> tuple[list[str], np.ndarray | None, np.ndarray]:
        """(coordinate labels, the file's mass matrix or None, the shapes of ``modal``), rows in the reference
        model's coordinate order; pair with the reference's mass when None."""
        if self._modes is None or not self._modes[1]:
            raise UnsupportedError(f"{self.solver}: the modes file gives no mode shapes")
        return self._modes[1], self._modes[2], modal.shapes

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        """The recording; an error when it covers less than ``MIN_COVERAGE`` of ``settings.duration``."""
        if self.duration < MIN_COVERAGE * settings.duration:
            raise GearcheckError(f"{self.series.info['source']}: the {self.solver} recording lasts {self.duration:.6g} "
                                 f"s, less than {MIN_COVERAGE:.0%} of the {settings.duration:.6g} s asked for")
        if progress is not None:
            progress(1.0)
        return self.series

    def stable_step(self) -> float:
        """The recorded step (s)."""
        return self.series.info["dt_s"]
