"""Figures of a sweep table (PNG, deterministic: no time stamps; drawn without pyplot).

* a speed sweep: one order plot per quantity, ``order_QUANTITY.png``: above, the Campbell-like map (the lumped
  model's natural frequencies at each speed, the mesh-harmonic lines k f_mesh(speed), and each harmonic's
  amplitude as the colour of a dot on its line: a waterfall seen from above); below, the amplitude of each
  mesh harmonic against speed, one colour per harmonic, a line style per solver, with a circle where the
  harmonic's frequency crosses a natural frequency (the speeds where it excites a mode), and the lines whose
  integration error estimate exceeds a tenth of them as faint circles off the lines;
* a parameter study or a Monte Carlo: ``study.png``, per quantity its dominant harmonic (the line with the
  largest median amplitude): at one speed, amplitude against the first swept field (grid) or its histogram
  (Monte Carlo); over several speeds, one line per parameter set of a small grid, else the median over the
  sets against speed with their band (min to max for a grid, 5 to 95 % for Monte Carlo).
"""

from __future__ import annotations

import re
import textwrap

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from gearcheck.compare.studies.distributions import Distribution
from gearcheck.compare.presentation.plots import _png
from gearcheck.compare.studies.sweep_lines import CONVERGED, counted, measured

MAX_LINES = 8  # a grid of up to this many parameter sets draws one line each; more: a band
LINESTYLES = ("-", "--", ":", "-.")
COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive",
           "tab:cyan", "tab:gray")


def file_name(quantity: str) -> str:
    return "order_" + re.sub(r"[^A-Za-z0-9._-]", "_", quantity) + ".png"


def figures(frame, plan, quantities) -> dict[str, bytes]:
    """The figures of a sweep (``frame``: its table as pandas) for ``quantities``, by file name."""
    speeds = np.unique(frame["speed_rpm"].to_numpy())
    harmonic = set(frame.loc[frame["metric"] == "harmonic", "quantity"])
    quantities = [q for q in quantities if q in harmonic]  # a quantity no run gave (every solver failed): no figure
    if not quantities:
        return {}
    if not plan.fields and speeds.size >= 2:
        return {file_name(q): order_plot(frame, plan.train, q) for q in quantities}
    if plan.fields:
        return {"study.png": study_plot(frame, plan, quantities)}
    return {}


def _modes(frame):
    """(speeds, frequencies (speeds x modes)) of the lumped natural frequencies."""
    modes = frame[frame["metric"] == "natural_frequency"]
    table = modes.pivot_table(index="speed_rpm", columns="order", values="frequency_hz", aggfunc="first")
    return table.index.to_numpy(), table.to_numpy()


def crossings(speeds, mode_hz, line_hz) -> list[tuple[float, int]]:
    """(speed, mode column) where the line's frequency (per speed) crosses a mode's."""
    out = []
    for j in range(mode_hz.shape[1]):
        gap = mode_hz[:, j] - line_hz
        for i in np.where(np.sign(gap[:-1]) * np.sign(gap[1:]) < 0)[0]:
            out.append((float(speeds[i] + (speeds[i + 1] - speeds[i]) * gap[i] / (gap[i] - gap[i + 1])), j))
    return sorted(out)


def order_plot(frame, train: str, quantity: str) -> bytes:
    return _png(order_figure(frame, train, quantity))


def order_figure(frame, train: str, quantity: str) -> Figure:
    """The order plot of ``quantity`` (see the module's docstring)."""
    rows = frame[(frame["quantity"] == quantity) & (frame["metric"] == "harmonic")]
    solvers = list(dict.fromkeys(rows["solver"]))
    unit = rows["unit"].iloc[0]
    lines = list(dict.fromkeys(zip(rows["mesh"], rows["order"])))
    mode_speeds, mode_hz = _modes(frame)
    fig = Figure(figsize=(9.5, 8.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(1.0, 1.1))
    reference = rows[(rows["solver"] == solvers[0]) & counted(rows)]
    unsteady = rows.loc[rows["steady"] == "none", "speed_rpm"].nunique()
    f_top = 1.15 * float(rows["frequency_hz"].max())
    for j in range(mode_hz.shape[1]):
        if np.nanmin(mode_hz[:, j]) < f_top:
            top.plot(mode_speeds, mode_hz[:, j], color="0.55", lw=0.8, zorder=1,
                     label="natural frequencies (lumped)" if j == 0 else None)
    amplitude = reference["amplitude"].to_numpy()
    positive = amplitude[np.isfinite(amplitude) & (amplitude > 0)]
    norm = LogNorm(vmin=max(positive.min(), positive.max() * 1e-4), vmax=positive.max()) if positive.size else None
    for i, (mesh, k) in enumerate(lines):
        line = rows[(rows["solver"] == solvers[0]) & (rows["mesh"] == mesh) & (rows["order"] == k)]
        line = line.sort_values("speed_rpm")
        top.plot(line["speed_rpm"], line["frequency_hz"], color=COLOURS[i % len(COLOURS)], lw=0.8, ls="--",
                 zorder=2)
    if norm is not None:
        dots = top.scatter(reference["speed_rpm"], reference["frequency_hz"],
                           c=np.clip(reference["amplitude"], norm.vmin, None), norm=norm, cmap="viridis", s=14,
                           zorder=3, edgecolors="none")
        fig.colorbar(dots, ax=top, label=f"{solvers[0]} amplitude ({unit})")
    top.set_ylim(0, f_top)
    top.set_ylabel("frequency (Hz)")
    top.set_title(f"{train}: {quantity}, mesh harmonics over input speed\n"
                  "grey: natural frequencies (lumped, gyroscopic, at each speed); dashed: k·f_mesh; dots: amplitude",
                  fontsize=10)
    for i, (mesh, k) in enumerate(lines):
        colour = COLOURS[i % len(COLOURS)]
        for s, solver in enumerate(solvers):
            line = rows[(rows["solver"] == solver) & (rows["mesh"] == mesh) & (rows["order"] == k)]
            line = line.sort_values("speed_rpm")
            y = np.where(counted(line), line["amplitude"], np.nan)
            bottom.plot(line["speed_rpm"], y, color=colour, ls=LINESTYLES[s % len(LINESTYLES)], lw=1.3 - 0.3 * s,
                        marker="x" if s else None, ms=3, label=f"{mesh} ×{k} ({solver})")
            shaky = line[measured(line) & ~counted(line)]
            bottom.plot(shaky["speed_rpm"], shaky["amplitude"], ls="none", marker="o", ms=2.5, mfc="none", mec=colour,
                        alpha=0.45, mew=0.6)
            if s == 0 and mode_hz.size:
                f_line = np.interp(mode_speeds, line["speed_rpm"], line["frequency_hz"])
                log_y = np.log(np.where(y > 0, y, np.nan))
                for speed, _ in crossings(mode_speeds, mode_hz, f_line):  # on the line as a log axis draws it
                    bottom.plot([speed], [np.exp(np.interp(speed, line["speed_rpm"], log_y))], "o", mfc="none",
                                mec=colour, ms=6)
    bottom.set_yscale("log")
    bottom.set_xlabel("input speed (rpm)")
    bottom.set_ylabel(f"amplitude ({unit})")
    bottom.set_title("amplitude of each mesh harmonic (" + ", ".join(
        f"{LINESTYLES[s]}{'x' if s else ''} {solver}" for s, solver in enumerate(solvers))
        + "); ○ where k·f_mesh crosses a natural frequency\nfaint circles: integration error estimate above "
        f"{CONVERGED:.0%} of the line; omitted: lines the window does not resolve"
        + (f", {unsteady} speeds without a steady state" if unsteady else ""), fontsize=9)
    bottom.grid(True, which="major", alpha=0.3)
    bottom.legend(fontsize=7, ncol=max(1, len(solvers)), loc="best")
    return fig


def dominant_line(rows) -> tuple[str, int]:
    """(mesh, order) of the harmonic with the largest median amplitude."""
    medians = rows.groupby(["mesh", "order"])["amplitude"].median()
    return medians.idxmax()


def study_plot(frame, plan, quantities) -> bytes:
    return _png(study_figure(frame, plan, quantities))


def study_figure(frame, plan, quantities) -> Figure:
    """The study plot of ``quantities`` (see the module's docstring)."""
    monte_carlo = bool(plan.settings.get("distributions"))
    speeds = np.unique(frame["speed_rpm"].to_numpy())
    n = len(quantities)
    cols = 2 if n > 1 else 1
    rows_n = (n + cols - 1) // cols
    fig = Figure(figsize=(5.2 * cols, 3.4 * rows_n + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows_n, cols, squeeze=False)).ravel()
    first = plan.fields[0]
    for ax, quantity in zip(axes, quantities):
        rows = frame[(frame["quantity"] == quantity) & (frame["metric"] == "harmonic")]
        mesh, k = dominant_line(rows)
        rows = rows[(rows["mesh"] == mesh) & (rows["order"] == k)]
        unit = rows["unit"].iloc[0]
        solvers = list(dict.fromkeys(rows["solver"]))
        for s, solver in enumerate(solvers):
            mine = rows[rows["solver"] == solver]
            colour = COLOURS[s % len(COLOURS)]
            if speeds.size >= 2 and not monte_carlo and mine["sample"].nunique() <= MAX_LINES:
                for j, (sample, one) in enumerate(mine.groupby("sample")):
                    one = one.sort_values("speed_rpm")
                    label = ", ".join(f"{f.rsplit('.', 1)[-1]}={one[f].iloc[0]:.4g}" for f in plan.fields)
                    ax.plot(one["speed_rpm"], one["amplitude"], color=COLOURS[j % len(COLOURS)],
                            ls=LINESTYLES[s % len(LINESTYLES)], marker="o", ms=3,
                            label=label + ("" if len(solvers) == 1 else f" ({solver})"))
                ax.set_xlabel("input speed (rpm)")
            elif speeds.size >= 2:
                by_speed = mine.groupby("speed_rpm")["amplitude"]
                low, high = (by_speed.quantile(0.05), by_speed.quantile(0.95)) if monte_carlo else \
                    (by_speed.min(), by_speed.max())
                median = by_speed.median()
                ax.fill_between(median.index, low, high, color=colour, alpha=0.25, lw=0)
                ax.plot(median.index, median, color=colour, ls=LINESTYLES[s % len(LINESTYLES)], label=solver)
                ax.set_xlabel("input speed (rpm)")
            elif monte_carlo:
                ax.hist(mine["amplitude"], bins=min(30, max(5, len(mine) // 4)), color=colour, alpha=0.5,
                        label=solver)
                ax.set_xlabel(f"amplitude ({unit})")
            else:
                ordered = mine.sort_values(first)
                ax.plot(ordered[first], ordered["amplitude"], "o" + LINESTYLES[s % len(LINESTYLES)], color=colour,
                        label=solver, ms=4)
                ax.set_xlabel(first)
        if speeds.size >= 2 or not monte_carlo:
            ax.set_ylabel(f"amplitude ({unit})")
        else:
            ax.set_ylabel("samples")
        ax.set_title(f"{quantity}: {mesh} ×{k}", fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axes[n:]:
        ax.set_visible(False)
    laws = plan.settings["distributions"]
    what = ("Monte Carlo over " + ", ".join(f"{f} ~ {Distribution.parse(d).label()}" for f, d in laws.items())
            + f" ({plan.settings['samples']} samples, seed {plan.settings['seed']})") if monte_carlo else \
        "grid over " + ", ".join(plan.fields)
    lines = not monte_carlo and frame["sample"].nunique() <= MAX_LINES
    band = "" if lines else " (median, band 5-95 %)" if monte_carlo else " (median, band min-max)"
    title = f"{plan.train}: {what}" + (band if speeds.size >= 2 else f" at {speeds[0]:g} rpm")
    fig.suptitle(textwrap.fill(title, width=60 * cols), fontsize=10)
    return fig
