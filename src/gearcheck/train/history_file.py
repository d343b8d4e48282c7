"""A history given as a table file: two columns, time and value, in CSV or Parquet, with their units.

CSV: an optional header line naming the columns with a unit suffix (``time_s,speed_rpm``; ``t_ms``;
``torque_Nm``, ``torque_kNm``; ``speed_rad_s``), then one pair of numbers a line.  Without a header the columns
are seconds and the quantity's own unit (rpm for a speed, N·m for a torque).  Parquet: two numeric columns, named
the same way or carrying a ``unit`` in their field metadata (as gearcheck writes them).  The file is data: it is
read bounded (:func:`gearcheck.train.files.read_bytes`), and a unit it does not know is refused, not guessed.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from gearcheck.shared.errors import GearcheckError, one_line
from gearcheck.train.files import read_bytes

TIME_UNITS = {"s": 1.0, "ms": 1e-3}
VALUE_UNITS = {  # quantity -> {unit: factor to the history's unit (rpm, N·m)}
    "speed": {"rpm": 1.0, "rad_s": 60.0 / (2.0 * math.pi), "hz": 60.0},
    "torque": {"nm": 1.0, "n_m": 1.0, "knm": 1e3},
}


def read_history_table(path: str | Path, quantity: str, label: str) -> np.ndarray:
    """(n, 2) time in s and value in the quantity's unit (rpm or N·m) from a CSV or Parquet file."""
    path = Path(path)
    data = read_bytes(path, f"{quantity} history")
    if path.suffix.lower() == ".parquet":
        names, columns = _parquet(data, label)
    else:
        names, columns = _csv(data.decode("utf-8", errors="replace"), label)
    time_factor = _factor(names[0], TIME_UNITS, label, "time") if names else 1.0
    value_factor = _factor(names[1], VALUE_UNITS[quantity], label, quantity) if names else 1.0
    return np.column_stack([columns[0] * time_factor, columns[1] * value_factor])


def _factor(name: str, units: dict, label: str, what: str) -> float:
    """The factor of a column named NAME_UNIT (or a bare name: the default unit, factor 1)."""
    name = name.strip().lower().replace("·", "_").replace(" ", "_").replace("/", "_")
    for unit, factor in sorted(units.items(), key=lambda u: -len(u[0])):
        if name.endswith("_" + unit) or name == unit:
            return factor
    if "_" not in name or name in ("t", "time"):
        return 1.0
    raise GearcheckError(f"{label}: column {name!r}: unknown {what} unit (use {', '.join(units)})")


def _csv(text: str, label: str):
    lines = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    names = None
    if lines and not number_row(lines[0]):
        names = [x.strip() for x in lines[0].split(",")]
        lines = lines[1:]
        if len(names) != 2:
            raise GearcheckError(f"{label}: the header must name two columns (time, value), got {len(names)}")
    try:
        data = np.loadtxt(io.StringIO("\n".join(lines)), delimiter=",", ndmin=2)
    except ValueError as exc:
        raise GearcheckError(f"{label}: {one_line(exc)}") from None
    if data.shape[1:] != (2,):
        raise GearcheckError(f"{label}: needs two columns (time, value), got {data.shape[1] if data.ndim == 2 else 0}")
    return names, (data[:, 0], data[:, 1])


def _parquet(data: bytes, label: str):
    from gearcheck.shared import parquet_bytes  # pyarrow only when a profile is a Parquet file

    try:
        table = parquet_bytes.read_table(data)
    except Exception as exc:  # pyarrow raises many kinds on a damaged file
        raise GearcheckError(f"{label}: cannot be read as Parquet: {one_line(exc)}") from None
    if table.num_columns != 2:
        raise GearcheckError(f"{label}: needs two columns (time, value), got {table.num_columns}")
    names = []
    for field in table.schema:
        unit = (field.metadata or {}).get(b"unit")
        names.append(f"{field.name}_{unit.decode()}" if unit else field.name)
    try:
        columns = [np.asarray(table.column(j).to_numpy(zero_copy_only=False), dtype=float) for j in range(2)]
    except (TypeError, ValueError) as exc:
        raise GearcheckError(f"{label}: its columns must be numbers ({one_line(exc)})") from None
    return names, columns


def number_row(line: str) -> bool:
    """Whether a CSV line is numbers (not a header)."""
    try:
        [float(x) for x in line.split(",")]
        return True
    except ValueError:
        return False
