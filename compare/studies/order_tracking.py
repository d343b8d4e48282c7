"""Order tracking of a run-up: order curves by computed order tracking, and the waterfall map.

Computed order tracking (Potter 1990; Fyfe & Munck 1997): the signal, sampled uniformly in time, is resampled at
uniform increments of the reference shaft's angle (``samples_per_rev`` a revolution), cut into blocks of
``revs_per_block`` revolutions (Hann window, ``overlap``), and each block is projected on exp(-i 2 pi k theta) for
every requested order k: ``A e^{i phase} = 2 sum w (x - xbar_w) e^{-i 2 pi k theta} / sum w`` for
x ~ A cos(2 pi k theta + phase), theta the reference angle in revolutions, xbar_w the window-weighted mean.  The sum
of the window is its coherent gain, so any order, integer or not (a mesh order z * relative speed / input speed),
is read without a bin to fall on; a block's speed is its window-weighted mean speed, at which an amplitude linear
in speed is read exactly.

Why not a Vold-Kalman filter (Vold & Leuridan 1993): the reference angle is known exactly here (the nominal
clock of the run, not a tachometer), so nothing is left to estimate; the projection needs no filter bandwidth to
tune and, in the angle domain, an order of constant amplitude is a pure tone whatever the speed does within the
block, so it is read exactly (up to the window's leakage, below).  Its limits: a block spans a speed range
(``OrderTrack.speed_span_rpm``): an amplitude that curves within it is read as its window-weighted mean, biased by
1/2 A'' var_w (var_w: the window-weighted variance of the speed over the block, ``(1/12 - 1/(2 pi^2))`` of the
square of the block's speed span for a constant slope); so a resonance narrower than a few blocks is smeared (the
peak lowered and widened), and its free vibration after the passage, at a fixed frequency, sweeps through the
orders and leaks into the one tracked.  Orders closer than about 2 / revs_per_block leak into each other: the Hann
window's spectrum at b bins is |sin(pi b)| / (pi b |1 - b^2|) of its peak (Harris 1978), zero at every integer
b >= 2.

Interpolation: a cubic spline of the signal against the angle.  Between samples its gain on a tone of p samples
a cycle is sinc(1/p)^4 * 3 / (2 + cos(2 pi / p)) (the cardinal cubic spline), 1 - 6e-4 at p = 8 and 1 - 1.5e-2
at p = 4, where a linear interpolation's, sinc(1/p)^2, loses 5 % at p = 8 (Fyfe & Munck 1997 trace the method's
error to the interpolation: its order and the sampling rate).  So the time samples must give at least
``MIN_SAMPLES_PER_CYCLE`` samples a cycle of the highest order at the top speed, else :class:`GearcheckError`.
By default the angle grid is at least as fine as the time samples anywhere in the run, so no content the time
samples resolve aliases in the angle domain (at low speed a fixed high frequency is a high order).

The waterfall (:func:`waterfall`) is the time-frequency map: Hann-windowed FFTs of blocks of the time signal, each
at its mean speed; orders draw diagonal lines f = k rpm / 60 on it, natural frequencies horizontal ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy.interpolate import CubicSpline

from gearcheck.compare.engine.line_projection import hann_tail_transform
from gearcheck.shared.errors import GearcheckError

MIN_SAMPLES_PER_CYCLE = 8  # cubic spline gain error below 6e-4 (the module's docstring)
PADDING = 4  # the waterfall's zero-padding: bins a quarter of its resolution apart
MAX_GRID = 2 ** 24  # angle samples of a run by default (128 MB); a run from near rest would need too many


@dataclass(frozen=True)
class OrderTrack:
    """Order curves of a run: per block (rows) and order (columns) ``x ~ A cos(2 pi k theta + phase)``."""

    orders: np.ndarray  # (orders,)
    speed_rpm: np.ndarray  # (blocks,) window-weighted mean speed of each block
    speed_span_rpm: np.ndarray  # (blocks, 2) lowest and highest speed within each block
    time_s: np.ndarray  # (blocks,) time at each block's centre
    complex_amplitude: np.ndarray  # (blocks, orders) A e^{i phase}
    revs_per_block: float
    overlap: float
    samples_per_rev: int

    @property
    def amplitude(self) -> np.ndarray:
        return np.abs(self.complex_amplitude)

    @property
    def phase(self) -> np.ndarray:
        """Phase (rad, in (-pi, pi]) against the reference angle."""
        return np.angle(self.complex_amplitude)

    def column(self, order: float) -> int:
        """The column of ``order``; GearcheckError listing the tracked orders when it is not one."""
        hit = np.flatnonzero(np.isclose(self.orders, order, rtol=1e-12, atol=0.0))
        if hit.size == 0:
            raise GearcheckError(f"order: {order!r} was not tracked (tracked: "
                                 + ", ".join(f"{k:g}" for k in self.orders) + ")")
        return int(hit[0])

    def curve(self, order: float) -> tuple[np.ndarray, np.ndarray]:
        """(speed in rpm, amplitude) of ``order``, by block."""
        return self.speed_rpm, self.amplitude[:, self.column(order)]


@dataclass(frozen=True)
class Waterfall:
    """Amplitude spectra of time blocks of a run (Hann, coherent gain corrected: a tone reads its amplitude)."""

    speed_rpm: np.ndarray  # (blocks,) window-weighted mean speed of each block
    time_s: np.ndarray  # (blocks,)
    frequency_hz: np.ndarray  # (bins,)
    amplitude: np.ndarray  # (blocks, bins)


def order_track(t, signal, angle_rev, orders, *, revs_per_block: float = 8.0, overlap: float = 0.5,
                samples_per_rev: int | None = None, steps=None) -> OrderTrack:
    """The order curves of ``signal`` (samples at times ``t``) against the reference angle ``angle_rev``
    (revolutions of the reference shaft at each sample, strictly increasing) for ``orders`` (per revolution of that
    shaft, > 0, integer or not), by computed order tracking (see the module's docstring).  ``samples_per_rev``:
    the angle grid (default: the time samples' finest angle step, rounded up to a power of two).  ``steps``: (angles
    in revolutions, sizes) of jumps that ``signal`` has had taken out (a switching mesh stiffness makes a force jump
    between samples, which no interpolation resolves: an error of order the jump over the samples a cycle in every
    line); each is added back by its exact windowed projection, as
    :func:`gearcheck.compare.engine.line_projection.harmonics` does in time (Eckhoff 1995)."""
    t, x, theta = _run(t, signal, angle_rev)
    orders = checked_array("orders", orders)
    if np.any(orders <= 0):
        raise GearcheckError(f"orders: must be positive, got {orders[orders <= 0][0]:g}")
    revs_per_block, overlap = _blocking(revs_per_block, overlap)
    step = np.diff(theta)
    per_cycle = 1.0 / (orders.max() * step.max())
    if per_cycle < MIN_SAMPLES_PER_CYCLE:
        j = int(np.argmax(step))
        top = 60.0 * step[j] / (t[j + 1] - t[j])
        raise GearcheckError(
            f"t: the samples give {per_cycle:.3g} samples a cycle of order {orders.max():g} at {top:.6g} rpm "
            f"({orders.max() * top / 60.0:.6g} Hz), computed order tracking needs {MIN_SAMPLES_PER_CYCLE}: sample "
            f"at least every {1.0 / (MIN_SAMPLES_PER_CYCLE * orders.max() * top / 60.0):.3g} s there, or track "
            f"orders up to {orders.max() * per_cycle / MIN_SAMPLES_PER_CYCLE:.4g}")
    n = _samples_per_rev(samples_per_rev, step, orders.max(), theta[-1] - theta[0])
    grid = np.arange(np.ceil(theta[0] * n), np.floor(theta[-1] * n) + 1) / n
    length = int(round(revs_per_block * n))
    if grid.size < length:
        raise GearcheckError(f"revs_per_block: {revs_per_block:g} revolutions, but the run turns the reference "
                             f"shaft {theta[-1] - theta[0]:.6g} revolutions")
    hop = max(1, int(round(length * (1.0 - overlap))))
    w = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(length) / length)  # periodic Hann: exact at integer bins
    blocks = sliding_window_view(CubicSpline(theta, x)(grid), length)[::hop]
    starts = grid[::hop][:blocks.shape[0]]
    kernel = w * np.exp(-2j * np.pi * np.outer(orders, np.arange(length) / n))  # (orders, length)
    mean = blocks @ w / w.sum()
    c = 2.0 * (blocks @ kernel.T - np.outer(mean, kernel.sum(axis=1))) / w.sum()
    c *= np.exp(-2j * np.pi * np.outer(starts, orders))  # the phase against the absolute angle
    if steps is not None:
        c += _step_lines(starts, length / n, orders, *steps)
    time = CubicSpline(theta, t)
    at = sliding_window_view(grid, length)[::hop]
    speed = 60.0 / time.derivative()(at)  # rpm; rev / s = 1 / (dt / dtheta)
    return OrderTrack(orders, speed @ w / w.sum(), np.column_stack([speed.min(axis=1), speed.max(axis=1)]),
                      time(starts + 0.5 * length / n), c, length / n, overlap, n)


def _step_lines(starts: np.ndarray, span: float, orders: np.ndarray, angles, sizes) -> np.ndarray:
    """(blocks, orders) the windowed projections of steps of ``sizes`` at ``angles`` (rev) on the blocks of ``span``
    revolutions from ``starts``, the window's weighted mean taken out as from the signal: for a step J at a inside a
    block, 2 J (T_k(a) - T_0(a) F_k / F_0) / F_0 with T_k(a) the integral from a to the block's end of the Hann
    window times e^{-i 2 pi k theta} and F_k that over the block."""
    angles, sizes = np.asarray(angles, dtype=float), np.asarray(sizes, dtype=float)
    out = np.zeros((starts.size, orders.size), dtype=complex)
    for b, a in enumerate(starts):
        inside = (angles > a) & (angles < a + span)
        if not inside.any():
            continue
        tail = hann_tail_transform(a, a + span, angles[inside], orders)  # (orders, steps)
        weight = hann_tail_transform(a, a + span, angles[inside], np.zeros(1)).real[0]  # (steps,)
        full = hann_tail_transform(a, a + span, np.array([a]), orders)[:, 0]
        area = 0.5 * span
        out[b] = 2.0 * ((tail - np.outer(full, weight) / area) @ sizes[inside]) / area
    return out


def waterfall(t, signal, angle_rev, block_s: float, *, overlap: float = 0.5, max_hz: float | None = None) -> Waterfall:
    """The time-frequency map of ``signal``: amplitude spectra of Hann-windowed blocks of ``block_s`` seconds
    (resolution 1 / block_s; zero-padded to ``PADDING`` times the block, so a tone is at most an eighth of a bin from
    the nearest and reads within 1 % of its amplitude), each at the block's window-weighted mean speed from
    ``angle_rev``, up to ``max_hz`` (default: the Nyquist frequency).  The speed changes within a block, so order
    k's line is smeared over k times the block's speed span / 60 Hz.  Samples not uniform in time are first put on
    a uniform grid of their median step by a cubic spline."""
    t, x, theta = _run(t, signal, angle_rev)
    block_s, overlap = _blocking(block_s, overlap, what="block_s")
    h = float(np.median(np.diff(t)))
    uniform = t[0] + h * np.arange(int(np.floor((t[-1] - t[0]) / h + 1e-9)) + 1)
    length = int(round(block_s / h))
    if length < 8 or uniform.size < length:
        raise GearcheckError(f"block_s: {block_s:g} s must span at least 8 samples ({8 * h:.3g} s) and at most "
                             f"the run ({t[-1] - t[0]:.6g} s)")
    hop = max(1, int(round(length * (1.0 - overlap))))
    w = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(length) / length)
    blocks = sliding_window_view(CubicSpline(t, x)(uniform), length)[::hop]
    frequency = np.fft.rfftfreq(PADDING * length, h)
    keep = frequency <= (0.5 / h if max_hz is None else max_hz)
    windowed = (blocks - (blocks @ w / w.sum())[:, None]) * w
    spectra = 2.0 * np.abs(np.fft.rfft(windowed, n=PADDING * length, axis=1)[:, keep]) / w.sum()
    speed = 60.0 * CubicSpline(t, theta).derivative()(sliding_window_view(uniform, length)[::hop])
    centre = uniform[::hop][:blocks.shape[0]] + 0.5 * length * h
    return Waterfall(speed @ w / w.sum(), centre, frequency[keep], spectra)


def _run(t, signal, angle_rev):
    """(t, signal, angle) as checked float arrays: one length (>= 4 samples), finite, t and angle strictly
    increasing."""
    t, x, theta = (checked_array(name, v) for name, v in (("t", t), ("signal", signal), ("angle_rev", angle_rev)))
    for name, v in (("signal", x), ("angle_rev", theta)):
        if v.size != t.size:
            raise GearcheckError(f"{name}: {v.size} samples, but t has {t.size}")
    if t.size < 4:
        raise GearcheckError(f"t: {t.size} samples, a cubic spline needs at least 4")
    for name, v in (("t", t), ("angle_rev", theta)):
        bad = np.flatnonzero(np.diff(v) <= 0)
        if bad.size:
            raise GearcheckError(f"{name}: must increase strictly (a run of positive speed); it does not after "
                                 f"sample {bad[0]} ({v[bad[0]]:.9g} then {v[bad[0] + 1]:.9g})")
    return t, x, theta


def checked_array(name: str, value) -> np.ndarray:
    """``value`` as a non-empty, finite, one-dimensional float array; GearcheckError naming ``name`` otherwise."""
    try:
        v = np.atleast_1d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise GearcheckError(f"{name}: not an array of numbers") from None
    if v.ndim != 1 or v.size == 0:
        raise GearcheckError(f"{name}: must be a non-empty one-dimensional array, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise GearcheckError(f"{name}: not finite at sample {int(np.flatnonzero(~np.isfinite(v))[0])}")
    return v


def _blocking(length: float, overlap: float, what: str = "revs_per_block") -> tuple[float, float]:
    if not np.isfinite(length) or length <= 0:
        raise GearcheckError(f"{what}: must be positive, got {length!r}")
    if not 0.0 <= overlap < 1.0:
        raise GearcheckError(f"overlap: a fraction in [0, 1), got {overlap!r}")
    return float(length), float(overlap)


def _samples_per_rev(n: int | None, step: np.ndarray, top_order: float, revs: float) -> int:
    """The angle grid: ``n``, checked to resolve ``top_order`` (Nyquist), or the time samples' finest angle step
    rounded up to a power of two, for a grid of at most ``MAX_GRID`` samples over ``revs`` revolutions."""
    if n is None:
        n = 2 ** int(np.ceil(np.log2(1.0 / step.min())))
        if n * revs > MAX_GRID:
            raise GearcheckError(
                f"samples_per_rev: matching the time samples where the shaft turns slowest needs {n} a revolution, "
                f"{n * revs:.3g} samples over the run (at most {MAX_GRID}); pass fewer (content above "
                "samples_per_rev * speed / 2 Hz then aliases in the angle domain) or leave out the slowest part")
        return n
    if int(n) != n or n <= 2 * top_order:
        raise GearcheckError(f"samples_per_rev: {n!r} does not resolve order {top_order:g} (needs an integer above "
                             f"{2 * top_order:g})")
    return int(n)
