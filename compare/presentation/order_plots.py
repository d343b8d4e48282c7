"""Figures of a run-up's order tracking (PNG through Agg, no pyplot: the user's backend is left alone).

* the order plot: above, each tracked order's amplitude against the input speed, one colour per run (several
  run-up rates side by side), one line style per order, the stepped sweep's steady amplitudes as markers; below,
  the phases (against the reference angle, unwrapped along the run);
* the waterfall: the time-frequency map of a run-up or run-down (colour: amplitude, logarithmic) against the input
  speed, with the Campbell diagram's lines over it: each order's f = k rpm / 60 (diagonal) and each natural
  frequency (horizontal).
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from gearcheck.compare.presentation.plots import _png
from gearcheck.compare.presentation.sweep_plots import COLOURS, LINESTYLES

DYNAMIC_RANGE = 1e-3  # the waterfall's colours span this fraction of its largest amplitude (60 dB)
LABEL_BOX = {"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.75}


def order_figure(tracks: dict, steady: dict | None = None, unit: str = "", title: str = "",
                 speed_range: tuple[float, float] | None = None) -> Figure:
    """``tracks``: {label: OrderTrack}; ``steady``: {order: (speeds in rpm, amplitudes)} of a stepped sweep, drawn
    as markers over the curves of that order; ``speed_range`` (rpm): the part drawn (default: all)."""
    fig = Figure(figsize=(9, 7), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2.0, 1.0))
    orders = list(dict.fromkeys(k for track in tracks.values() for k in track.orders))
    for i, (label, track) in enumerate(tracks.items()):
        for k in track.orders:
            colour, line = (i, orders.index(k)) if len(orders) == 1 else (orders.index(k), i)  # colour per order
            style = {"color": COLOURS[colour % len(COLOURS)], "ls": LINESTYLES[line % len(LINESTYLES)]}
            j = track.column(k)
            top.plot(track.speed_rpm, track.amplitude[:, j], lw=1.2, label=f"order {k:g}, {label}", **style)
            bottom.plot(track.speed_rpm, np.degrees(np.unwrap(track.phase[:, j])), lw=0.9, **style)
    for n, (k, (speed, amplitude)) in enumerate((steady or {}).items()):
        top.plot(speed, amplitude, ls="none", marker="o", ms=4, mfc="none", mec="black",
                 label="steady (stepped sweep)" if n == 0 else None)
    top.set_ylabel(f"order amplitude ({unit})" if unit else "order amplitude")
    top.set_title(title or "order tracking (computed order tracking: Hann blocks in the angle domain)", fontsize=10)
    top.grid(alpha=0.3)
    top.legend(fontsize=7, loc="best")
    bottom.set_ylabel("phase (deg, unwrapped)")
    bottom.set_xlabel("input speed (rpm)")
    bottom.grid(alpha=0.3)
    if speed_range is not None:
        bottom.set_xlim(*speed_range)
        shown = [a[(s >= speed_range[0]) & (s <= speed_range[1])] for s, a in _curves(tracks, steady)]
        top.set_ylim(0, 1.05 * max((float(a.max()) for a in shown if a.size), default=1.0))
    return fig


def _curves(tracks: dict, steady: dict | None):
    """Every (speed, amplitude) pair the order plot draws."""
    for track in tracks.values():
        yield from (track.curve(k) for k in track.orders)
    yield from (steady or {}).values()


def waterfall_figure(waterfall, orders=(), natural_hz=(), unit: str = "", title: str = "") -> Figure:
    """The time-frequency map of a :class:`~gearcheck.compare.studies.order_tracking.Waterfall` against speed, with
    the lines of ``orders`` (f = k rpm / 60) and ``natural_hz`` (Campbell)."""
    fig = Figure(figsize=(9, 6), layout="constrained")
    ax = fig.subplots()
    amplitude = waterfall.amplitude
    top = float(amplitude.max())
    norm = LogNorm(vmin=top * DYNAMIC_RANGE, vmax=top) if top > 0 else None
    mesh = ax.pcolormesh(waterfall.speed_rpm, waterfall.frequency_hz, np.clip(amplitude, top * DYNAMIC_RANGE, None).T,
                         norm=norm, cmap="viridis", shading="nearest", rasterized=True)
    fig.colorbar(mesh, ax=ax, label=f"amplitude ({unit})" if unit else "amplitude")
    speed = np.array([waterfall.speed_rpm.min(), waterfall.speed_rpm.max()])
    f_top = float(waterfall.frequency_hz[-1])
    for k in orders:
        ax.plot(speed, k * speed / 60.0, color="white", lw=1.0, ls="--")
        end = min(speed[1], 60.0 * 0.97 * f_top / k)
        ax.annotate(f"order {k:g}", (end, k * end / 60.0), fontsize=8, ha="right", va="bottom", bbox=LABEL_BOX)
    for f in natural_hz:
        ax.axhline(f, color="orangered", lw=1.2, ls=":")
        ax.annotate(f"f_n = {f:g} Hz", (speed[0], f), color="orangered", fontsize=8, ha="left", va="bottom",
                    xytext=(4, 2), textcoords="offset points", bbox=LABEL_BOX)
    ax.set_xlim(*speed)
    ax.set_ylim(0, f_top)
    ax.set_xlabel("input speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(title or "waterfall: time-frequency map over the run; dashed: orders, dotted: natural frequencies",
                 fontsize=10)
    return fig


def order_plot(tracks: dict, steady: dict | None = None, unit: str = "", title: str = "",
               speed_range: tuple[float, float] | None = None) -> bytes:
    """PNG of :func:`order_figure`."""
    return _png(order_figure(tracks, steady, unit, title, speed_range))


def waterfall_plot(waterfall, orders=(), natural_hz=(), unit: str = "", title: str = "") -> bytes:
    """PNG of :func:`waterfall_figure`."""
    return _png(waterfall_figure(waterfall, orders, natural_hz, unit, title))
