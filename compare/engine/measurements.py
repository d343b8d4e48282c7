"""Measured reference values (a paper's test amplitudes) shown as a third column.

A value names a cross-check quantity, a statistic of its steady window (``peak``,
``rms``, ``peak_to_peak``), the value in the quantity's SI unit, optionally the input
speed it was measured at (attached only when the run is at that speed) and its source.
They come from the train file's ``[[measurements]]`` (and its ``measurements_file``) or a file
given with ``--measurements`` holding the same array.  An entry may name the band of its
measuring chain and the value the source's own model gave (``published_model``).  Errors are
(model - measured)/|measured|.
"""

from __future__ import annotations

import math
from pathlib import Path

from gearcheck.compare.engine.measure import chain_statistic
from gearcheck.train.files import read_toml
from gearcheck.train.schema import parse_measurements_file
from gearcheck.shared.errors import GearcheckError, did_you_mean

SPEED_MATCH = 1e-6  # relative


def load_measurements(path: str | Path) -> list[dict]:
    """The checked ``[[measurements]]`` of a TOML file."""
    return load_measurements_file(path)["measurements"]


def load_measurements_file(path: str | Path) -> dict:
    """The checked ``measurements`` (amplitudes) and ``natural_frequencies`` of a TOML measurements file."""
    return parse_measurements_file(read_toml(path, "measurements file"), str(path))


def check_quantities(entries, quantities) -> None:
    """Refuse a measurement of a quantity the cross-check does not compare."""
    known = set(quantities)
    for entry in entries:
        if entry["quantity"] not in known:
            raise GearcheckError(f"measurement of {entry['quantity']!r}: no such compared quantity"
                                 + did_you_mean(entry["quantity"], sorted(known)))


def attach(result, entries) -> None:
    """Add the measured column to ``result`` (a CrosscheckResult) for entries at its speed: both
    solvers read through the entry's measuring chain (:func:`gearcheck.compare.engine.measure.chain_statistic`)
    over the cross-check's steady window."""
    speed = result.spec.operating.input_speed
    by_name = {q.name: q for q in result.quantities}
    fs = result.settings["common_sample_rate_hz"]
    window = result.grid >= result.steady_start_s
    rows = []
    for entry in entries:
        if entry.get("speed") is not None and abs(entry["speed"] - speed) > SPEED_MATCH * speed:
            continue
        q = by_name[entry["quantity"]]  # known: check_quantities ran before the runs
        metric, band, value = entry["metric"], entry.get("sensor_band_hz"), entry["value"]
        reference, test = (chain_statistic(x, window, fs, metric, band) for x in result.series[q.name])
        published = entry.get("published_model")
        row = {
            "quantity": q.name, "metric": metric, "source": entry.get("source", ""),
            "sensor_band": None if band is None else {"value": list(band), "unit": "Hz"},
            "measured": {"value": value, "unit": q.unit}, "reference": {"value": reference, "unit": q.unit},
            "test": {"value": test, "unit": q.unit},
            "published_model": None if published is None else {"value": published, "unit": q.unit},
            "error_reference": {"value": _error(reference, value), "unit": "1"},
            "error_test": {"value": _error(test, value), "unit": "1"},
            "error_published_model": None if published is None else {"value": _error(published, value), "unit": "1"},
        }
        q.measured.append(row)
        rows.append(row)
    result.measurements = rows


def _error(model: float, measured: float) -> float:
    return (model - measured) / abs(measured) if measured else math.nan
