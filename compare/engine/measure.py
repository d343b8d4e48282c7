"""The measurement chain: the number a test rig reports, computed from a solver's series.

A measured amplitude is a statistic of the steady-state signal of one sensor: ``peak``
(max |x|), ``rms`` or ``peak_to_peak``, after the sensor chain's band-pass when one is given
(:func:`gearcheck.compare.engine.align.sensor_filter`, zero phase, applied to the whole series before the
window is cut so that the filter's start-up does not enter it).  The same function serves
the cross-check's measured column and the calibration, so both read a solver the same way.
"""

from __future__ import annotations

import numpy as np

from gearcheck.compare.engine.align import STEADY_WINDOW_CYCLES, resample, sensor_filter, steady_state, uniform_grid
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


def steady_window(grid: np.ndarray, forces: np.ndarray, cycle: float, settle: float | None) -> np.ndarray:
    """The steady window of a run from its mesh forces (time x meshes), by the cross-check's rule
    (:func:`gearcheck.compare.engine.align.steady_state`; ``settle`` the decay time of the model's free vibration);
    a run that reaches no steady state is refused, naming the duration it needs."""
    start, how = steady_state(grid, [(forces, cycle)], settle)
    if how is None:
        need = "" if settle is None else f"; its start's free vibration decays in {settle:.4g} s, so give at least " \
            f"{settle + STEADY_WINDOW_CYCLES * cycle:.4g} s"
        raise GearcheckError(f"a run of {grid[-1]:.4g} s reaches no steady state to measure{need} (duration=)")
    return grid >= start


def measure(result, entries, cycle: float, settle: float | None = None) -> list[float]:
    """Each measurement entry's statistic from one solver's ``result`` (the calibration's model side), over
    its steady window (``cycle`` the slowest mesh period, ``settle`` the free vibration's decay time)."""
    fs = (result.t.size - 1) / (result.t[-1] - result.t[0])
    grid = uniform_grid(0.0, result.t[-1], fs)
    forces = resample(result.t, result.select("mesh_force"), grid)
    window = steady_window(grid, forces, cycle, settle)
    values = []
    for entry in entries:
        if entry["quantity"] not in result:
            raise GearcheckError(f"measurement of unknown quantity {entry['quantity']!r} (quantities: "
                                 f"{', '.join(result.names(compared=True))[:400]}...)")
        series = resample(result.t, result[entry["quantity"]], grid)
        values.append(chain_statistic(series, window, fs, entry["metric"], entry.get("sensor_band_hz")))
    return values
