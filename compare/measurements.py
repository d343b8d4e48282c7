"""Measured reference values (a paper's test amplitudes) shown as a third column.

A value names a cross-check quantity, a statistic of its steady window (``peak``,
``rms``, ``peak_to_peak``), the value in the quantity's SI unit, optionally the input
speed it was measured at (attached only when the run is at that speed) and its source.
They come from the train file's ``[[measurements]]`` or a file given with
``--measurements`` holding the same array.  Errors are (solver - measured)/|measured|.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

from lumped.errors import GearcheckError, TrainFileError
from lumped.schema import parse_measurements

SPEED_MATCH = 1e-6  # relative


def load_measurements(path: str | Path) -> list[dict]:
    try:
        document = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise GearcheckError(f"{path}: cannot read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise TrainFileError(str(path), "", f"not valid TOML: {exc}") from None
    return parse_measurements(document, str(path))


def attach(result, entries) -> None:
    """Add the measured column to ``result`` (a CrosscheckResult) for entries at its speed."""
    speed = result.spec.operating.input_speed
    by_name = {q.name: q for q in result.quantities}
    rows = []
    for entry in entries:
        if entry.get("speed") is not None and abs(entry["speed"] - speed) > SPEED_MATCH * speed:
            continue
        q = by_name.get(entry["quantity"])
        if q is None:
            raise GearcheckError(f"measurement for unknown quantity {entry['quantity']!r} "
                                 f"(quantities: {', '.join(sorted(by_name))[:400]}...)")
        metric = entry["metric"]
        lumped, mujoco = q.metrics["reference"][metric], q.metrics["test"][metric]
        value = entry["value"]
        row = {
            "quantity": q.name, "metric": metric, "source": entry.get("source", ""),
            "measured": {"value": value, "unit": q.unit}, "lumped": {"value": lumped, "unit": q.unit},
            "mujoco": {"value": mujoco, "unit": q.unit},
            "error_lumped": {"value": (lumped - value) / abs(value) if value else math.nan, "unit": "1"},
            "error_mujoco": {"value": (mujoco - value) / abs(value) if value else math.nan, "unit": "1"},
        }
        q.measured.append(row)
        rows.append(row)
    result.measurements = rows
