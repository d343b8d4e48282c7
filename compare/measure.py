"""The measurement chain: the number a test rig reports, computed from a solver's series.

A measured amplitude is a statistic of the steady-state signal of one sensor: ``peak``
(max |x|), ``rms`` or ``peak_to_peak``, after the sensor chain's band-pass when one is given
(:func:`gearcheck.compare.align.sensor_filter`, zero phase, applied to the whole series before the
window is cut so that the filter's start-up does not enter it).  The same function serves
the cross-check's measured column and the calibration, so both read a solver the same way.
"""

from __future__ import annotations

import numpy as np

from gearcheck.compare.align import resample, sensor_filter, steady_start, uniform_grid
from gearcheck.shared.errors import GearcheckError

MIN_CYCLES = 1  # a run holds at least one cycle of its slowest mesh (or lowest mode) to be compared or measured

STATISTICS = {
    "peak": lambda x: float(np.max(np.abs(x))),
    "rms": lambda x: float(np.sqrt(np.mean(x**2))),
    "peak_to_peak": lambda x: float(np.ptp(x)),
}


def chain_statistic(x: np.ndarray, window: np.ndarray, fs: float, metric: str, band=None) -> float:
    """``metric`` of ``x`` over the boolean ``window``, after the optional sensor ``band``."""
    if band is not None and not band[1] < 0.5 * fs:
        raise GearcheckError(f"sensor band {band[0]:g}-{band[1]:g} Hz: its upper edge must lie below the sample "
                             f"rate's Nyquist frequency {0.5 * fs:.6g} Hz")
    if band is not None:
        x = sensor_filter(x, fs, tuple(band))
    return STATISTICS[metric](x[window])


def steady_window(grid: np.ndarray, forces: np.ndarray, cycle: float) -> tuple[np.ndarray, bool]:
    """The steady window of a run from its mesh forces (time x meshes): from the detected start,
    or the second half when no steady state is found."""
    start = steady_start(grid, forces, cycle)
    found = start is not None
    return grid >= (start if found else 0.5 * grid[-1]), found


def measure(result, entries, cycle: float) -> list[float]:
    """Each measurement entry's statistic from one solver's ``result`` (the calibration's model side)."""
    fs = (result.t.size - 1) / (result.t[-1] - result.t[0])
    grid = uniform_grid(0.0, result.t[-1], fs)
    forces = resample(result.t, result.select("mesh_force"), grid)
    window, _ = steady_window(grid, forces, cycle)
    values = []
    for entry in entries:
        if entry["quantity"] not in result:
            raise GearcheckError(f"measurement of unknown quantity {entry['quantity']!r} (quantities: "
                                 f"{', '.join(result.names(compared=True))[:400]}...)")
        series = resample(result.t, result[entry["quantity"]], grid)
        values.append(chain_statistic(series, window, fs, entry["metric"], entry.get("sensor_band_hz")))
    return values
