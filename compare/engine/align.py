"""Putting two solvers' signals on one footing: resampling, steady state, lag.

* :func:`resample` — anti-aliased resampling onto a uniform grid: a zero-phase 8th-order
  Butterworth low-pass at ``ANTI_ALIAS_FRACTION`` of the grid's Nyquist frequency, then
  linear interpolation.  The filter is applied even when the rates match, so that two
  signals put on one grid always pass through the same filter (a rectangular mesh
  stiffness makes mesh forces jump, and a jump has content up to any Nyquist frequency).
* :func:`steady_start` — the start of the steady state: the first of
  ``STEADY_CYCLES`` consecutive cycles (a cycle = one period of the slowest mesh) whose
  mean and standard deviation differ from the previous cycle's by less than
  ``threshold`` of the standard deviation (the fluctuation, not the mean load, sets the
  scale).
* :func:`steady_state` — the steady window of a train: every stage's mesh forces steady over
  that stage's own mesh cycle (detected), or else the start's free vibration decayed to
  ``STEADY_THRESHOLD`` by the model's own damping (decayed: stages whose mesh frequencies are
  incommensurate make each other's forces quasi-periodic, which no cycle test settles).
* :func:`sensor_filter` — an optional model of the accelerometer chain: a zero-phase
  4th-order Butterworth band-pass between the sensor's lower and upper band limits, applied
  alike to both solvers' accelerations (published test amplitudes are filtered measurements).
* :func:`estimate_lag` — the delay of ``b`` behind ``a`` by cross-correlation with
  parabolic sub-sample refinement, searched within +/- ``max_lag``.
"""

from __future__ import annotations

import numpy as np

ANTI_ALIAS_FRACTION = 0.8
STEADY_CYCLES = 3
STEADY_THRESHOLD = 2e-3
CYCLE_POINTS = 256


def uniform_grid(t0: float, t1: float, fs: float) -> np.ndarray:
    n = int(np.floor((t1 - t0) * fs + 1e-9)) + 1
    return t0 + np.arange(n) / fs


def resample(t: np.ndarray, x: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """``x(t)`` (time along axis 0) on ``grid``, low-pass filtered at 0.8 x the grid's Nyquist first."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    fs_old = (t.size - 1) / (t[-1] - t[0])
    fs_new = (grid.size - 1) / (grid[-1] - grid[0])
    cutoff = ANTI_ALIAS_FRACTION * 0.5 * fs_new
    if cutoff < 0.5 * fs_old:
        from scipy import signal  # here: importing scipy.signal costs 0.4 s, which most commands never need

        sos = signal.butter(8, cutoff, fs=fs_old, output="sos")
        x = signal.sosfiltfilt(sos, x, axis=0)
    return resample_at(t, x, grid)


def resample_at(t: np.ndarray, x: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``x`` (time along axis 0) at ``times``, no filtering."""
    if x.ndim == 1:
        return np.interp(times, t, x)
    out = np.empty((np.size(times), x.shape[1]))
    for j in range(x.shape[1]):
        out[:, j] = np.interp(times, t, x[:, j])
    return out


def steady_start(t: np.ndarray, x: np.ndarray, cycle: float, threshold: float = STEADY_THRESHOLD,
                 cycles: int = STEADY_CYCLES) -> float | None:
    """Time at which ``x`` (1-D or time x channels) becomes cycle-to-cycle steady, or None."""
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    edges = np.arange(t[0], t[-1] + 1e-12, cycle)
    if edges.size < cycles + 2:
        return None
    std, mean = _cycle_statistics(t, x, edges[:-1], cycle)
    change = np.maximum(np.abs(np.diff(std, axis=0)), np.abs(np.diff(mean, axis=0))) / np.maximum(std[1:], 1e-300)
    run = 0
    for k, steady in enumerate(np.all(change < threshold, axis=1), start=1):
        run = run + 1 if steady else 0
        if run >= cycles:
            return float(edges[k - cycles])
    return None


CYCLES_PER_BLOCK = 256  # cycles resampled at once by _cycle_statistics


def _cycle_statistics(t: np.ndarray, x: np.ndarray, starts: np.ndarray, cycle: float) -> tuple[np.ndarray, np.ndarray]:
    """(standard deviation, mean) of ``x`` (time x channels) over the cycles from ``starts``, each (cycles x
    channels), from ``CYCLE_POINTS`` samples at the same phases in every cycle."""
    x = np.asfortranarray(x)  # each channel contiguous: np.interp reads it without a copy
    offsets = np.arange(CYCLE_POINTS) / CYCLE_POINTS * cycle
    std, mean = np.empty((2, starts.size, x.shape[1]))
    for first in range(0, starts.size, CYCLES_PER_BLOCK):
        block = starts[first:first + CYCLES_PER_BLOCK]
        w = resample_at(t, x, (block[:, None] + offsets).ravel()).reshape(block.size, CYCLE_POINTS, -1)
        std[first:first + block.size], mean[first:first + block.size] = np.std(w, axis=1), np.mean(w, axis=1)
    return std, mean


STEADY_WINDOW_CYCLES = 4  # slowest mesh cycles a steady window must hold after a start found by decay


def steady_state(t: np.ndarray, groups, settle: float | None) -> tuple[float | None, str | None]:
    """(start, how) of the steady state of a run sampled at ``t``: ``groups`` is a list of (forces
    (time x meshes), cycle) per stage; ``settle`` the time the model's free vibration takes to decay to
    ``STEADY_THRESHOLD`` (None: unknown).  ``how`` is "detected" (every stage passes
    :func:`steady_start` over its own cycle), "decayed" (the run holds ``settle`` plus
    ``STEADY_WINDOW_CYCLES`` of the slowest cycle) or None (no steady state in this run)."""
    starts = [steady_start(t, x, cycle) for x, cycle in groups]
    if all(s is not None for s in starts):
        return max(starts), "detected"
    slowest = max(cycle for _, cycle in groups)
    if settle is not None and settle + STEADY_WINDOW_CYCLES * slowest <= t[-1] + 1e-12:
        return settle, "decayed"
    return None, None


def sensor_filter(x: np.ndarray, fs: float, band: tuple[float, float]) -> np.ndarray:
    """Band-pass ``x`` (time along axis 0) to ``band`` = (low, high) Hz, zero phase."""
    from scipy import signal

    low, high = band
    sos = signal.butter(4, [low, high], btype="bandpass", fs=fs, output="sos")
    return signal.sosfiltfilt(sos, x, axis=0)


def estimate_lag(a: np.ndarray, b: np.ndarray, fs: float, max_lag: float) -> float:
    """Delay (s) of ``b`` behind ``a`` (positive: b happens later) on a uniform grid of rate ``fs``."""
    from scipy import signal

    a = np.asarray(a, dtype=float) - np.mean(a)
    b = np.asarray(b, dtype=float) - np.mean(b)
    n = a.size
    max_shift = max(1, min(n - 1, int(np.ceil(max_lag * fs))))
    corr = signal.correlate(b, a, mode="full", method="fft")[n - 1 - max_shift: n + max_shift]
    k = int(np.argmax(corr))
    shift = float(k - max_shift)
    if 0 < k < corr.size - 1:
        y0, y1, y2 = corr[k - 1], corr[k], corr[k + 1]
        denom = y0 - 2 * y1 + y2
        if denom != 0:
            shift += 0.5 * (y0 - y2) / denom
    return shift / fs


def shift_signal(x: np.ndarray, delay: float, fs: float) -> np.ndarray:
    """``x`` advanced by ``delay`` seconds (linear interpolation, ends held)."""
    n = x.size
    idx = np.arange(n) + delay * fs
    return np.interp(idx, np.arange(n), x)
