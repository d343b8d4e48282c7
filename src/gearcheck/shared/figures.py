"""Figures of the floor's results: a time run, a set of modes.

Drawn on :class:`matplotlib.figure.Figure` objects without pyplot, so drawing never touches the user's matplotlib
backend (the compare-level results draw with :mod:`gearcheck.compare.presentation.plots` the same way).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gearcheck.shared.modal import GROUPS


def time_figure(result, names) -> Figure:
    """The signals ``names`` of a :class:`~gearcheck.shared.results.TimeResult` against time, one panel per kind
    of signal (and unit), one line per signal."""
    panels: dict[tuple[str, str], list[str]] = {}
    for name in names:
        s = result.signal(name)
        panels.setdefault((s.kind, s.unit), []).append(name)
    fig = Figure(figsize=(9, 2.2 * len(panels) + 0.6), layout="constrained")
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for ax, ((kind, unit), members) in zip(axes, panels.items()):
        for name in members:
            ax.plot(result.t, result[name], lw=0.9, label=name)
        ax.set_ylabel(f"{kind.replace('_', ' ')} [{unit}]", fontsize=8)
        ax.legend(loc="upper right", fontsize=6, ncol=2)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(f"{result.train} ({result.solver})", fontsize=9)
    return fig


def modes_figure(modal, types) -> Figure:
    """Natural frequencies of a :class:`~gearcheck.shared.modal.ModalResult` against mode number, one marker
    series per mode type (Lin & Parker 1999), of the modes of ``types``; below, each mode's kinetic-energy shares
    when the result has them."""
    fig = Figure(figsize=(9, 6.5 if modal.fractions is not None else 4), layout="constrained")
    axes = fig.subplots(2 if modal.fractions is not None else 1, 1, sharex=True, squeeze=False)[:, 0]
    number = np.arange(1, len(modal) + 1)
    shown = np.isin(modal.types, types)
    for kind in types:
        mine = np.asarray(modal.types) == kind
        axes[0].plot(number[mine], modal.frequencies[mine], "o", ms=4, label=kind)
    axes[0].set_ylabel("natural frequency [Hz]")
    axes[0].legend(fontsize=7)
    speed = "at rest" if modal.speed_rpm is None else f"at {modal.speed_rpm:g} rpm"
    axes[0].set_title(f"{modal.train} ({modal.solver}): natural frequencies {speed}", fontsize=9)
    if modal.fractions is not None:
        bottom = np.zeros(int(shown.sum()))
        for j, group in enumerate(GROUPS):
            share = modal.fractions[shown, j]
            axes[1].bar(number[shown], share, bottom=bottom, label=group.replace("_", " "))
            bottom += share
        axes[1].set_ylabel("kinetic energy share [1]")
        axes[1].legend(fontsize=7)
    axes[-1].set_xlabel("mode")
    for ax in axes:
        ax.grid(alpha=0.3)
    return fig
