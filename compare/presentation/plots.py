"""Report figures (PNG, deterministic: no timestamps in the files).

Figures are drawn on :class:`matplotlib.figure.Figure` objects and saved through Agg without
pyplot, so writing a report never touches the user's matplotlib backend.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import NullLocator

from gearcheck.compare.presentation.envelope import envelope
from gearcheck.train.cycloid import conjugate_disc_angle, disc_profile
from gearcheck.train.mesh_stiffness import stiffness_model

REFERENCE_STYLE = {"color": "tab:blue", "lw": 1.2}
TEST_STYLE = {"color": "tab:orange", "lw": 1.0, "ls": "--"}


def _styles(result) -> tuple[dict, dict]:
    """The reference's and the test's line styles, labelled with their names."""
    a, b = result.solver_names
    return {**REFERENCE_STYLE, "label": a}, {**TEST_STYLE, "label": b}


def _figure(rows: int = 1, cols: int = 1, figsize=(9, 5), layout=None, **kwargs):
    """A figure and its axes; ``layout="constrained"`` keeps a two-line title clear of tall stacks of panels."""
    fig = Figure(figsize=figsize, layout=layout)
    return fig, fig.subplots(rows, cols, **kwargs)


def _save(fig, path):
    if fig.get_layout_engine() is None:
        fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None}, format="png")


def _png(fig) -> bytes:
    """The figure as PNG bytes (for :func:`gearcheck.shared.outputs.write_file`)."""
    png = io.BytesIO()
    _save(fig, png)
    return png.getvalue()


def headline_quantities(result) -> list[str]:
    """Carrier and ring accelerations (world y, as the accelerometers see them) and the first
    sun-planet and ring-planet mesh forces of every stage, those not negligible (a held ring's acceleration is
    both solvers' round-off); the first four quantities not negligible when none of those is."""
    names = []
    for stage in result.spec.stages:
        for member in (stage.carrier, *[c for c in stage.centrals if result.spec.members[c].kind == "ring"]):
            names.append(f"{member}.ay.world")
        for mesh in result.spec.meshes:
            if mesh.stage == stage.name and mesh.planet_index == 0:
                names.append(f"{mesh.id}.force")
    shown = {q.name for q in result.quantities if q.status != "negligible"}  # round-off draws as a disagreement
    names = [n for n in names if n in shown]
    if not names:  # trains compared on other quantities (a published 4-DOF model), or with those negligible
        names = ([q.name for q in result.quantities if q.name in shown] or [q.name for q in result.quantities])[:4]
    return names


def _title(result, what: str) -> str:
    s = result.settings
    a, b = result.solver_names
    return (f"{result.spec.name} at {s['input_speed_rpm']:.6g} rpm: {what}\n"
            f"{a} {s['reference'].get('method', '')} dt={s['reference'].get('dt_s', float('nan')):.3g} s, "
            f"{b} {s['test'].get('integrator', s['test'].get('method', ''))} "
            f"dt={s['test'].get('dt_s', float('nan')):.3g} s")


def time_histories_figure(result, names=None, cycles: int = 4) -> Figure:
    """Both sides of the quantities ``names`` (default: :func:`headline_quantities`) over the last ``cycles``
    steady cycles, one panel each."""
    names = headline_quantities(result) if names is None else names
    units = {q.name: q.unit for q in result.quantities}
    f_cycle = 1.0 / result.settings["steady_cycle_s"]
    t = result.grid
    t_end = t[-1]
    window = t >= t_end - cycles / f_cycle
    fig, axes = _figure(len(names), 1, figsize=(9, 2.2 * len(names)), layout="constrained", sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        a, b = result.series[name]
        style_a, style_b = _styles(result)
        ax.plot(*envelope(t[window] * 1e3, a[window]), **style_a)
        ax.plot(*envelope(t[window] * 1e3, b[window]), **style_b)
        ax.set_ylabel(f"[{units[name]}]")
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time [ms]")
    of = result.settings.get("steady_cycle_of", "the slowest mesh")
    fig.suptitle(_title(result, f"steady-state time histories, last {cycles} cycles of {of} ({f_cycle:.4g} Hz)"),
                 fontsize=9)
    return fig


def time_histories(result, path, cycles: int = 4):
    if not result.quantities:  # a cross-check of modes only: no run to draw
        return False
    _save(time_histories_figure(result, cycles=cycles), path)


LOG_SPAN = 20.0  # a spectrum spanning more than this ratio of frequencies gets a logarithmic frequency axis
MESH_HARMONICS = 3  # the spectra reach this harmonic of the fastest mesh
GUIDE_HARMONICS = 4  # harmonics of each mesh frequency marked (the spectral lines compared: k = 1..4)
DYNAMIC_RANGE = 1e6  # amplitudes shown below a panel's largest
MAX_FAILING = 6  # failing quantities plotted, the worst by NRMSE over tolerance
STAGE_COLORS = ("tab:green", "tab:purple", "tab:brown", "tab:olive", "tab:cyan", "tab:pink")  # their mesh harmonics


@dataclass(frozen=True)
class SpectrumRange:
    """The frequency axis of the spectra: ``low`` to ``high`` Hz, logarithmic when ``log``; with the mesh
    frequencies of each stage and the natural frequencies (elastic, both sides, below Nyquist) to mark."""

    low: float
    high: float
    log: bool
    meshes: dict[str, tuple[float, ...]]
    naturals: tuple[float, ...]


def spectrum_range(result) -> SpectrumRange:
    """Up to the higher of the third harmonic of the fastest mesh and the highest elastic natural frequency
    below Nyquist (and at most Nyquist), from zero, or logarithmic from half the lowest of those frequencies
    when the span exceeds ``LOG_SPAN``.  Mesh frequencies are those of the compared "1x mesh" lines, by stage
    (the first part of a quantity's name); without them (a transient) the cycle of the steady-state test."""
    nyquist = 0.5 * result.settings["common_sample_rate_hz"]
    meshes: dict[str, set[float]] = {}
    for q in result.quantities:
        for line in q.spectrum:
            if line["line"] == "1x mesh":
                meshes.setdefault(q.name.split(".")[0], set()).add(_distinct(line["frequency_hz"]))
    naturals = sorted({_distinct(f) for modal in result.modal_results if modal is not None
                       for f, kind in zip(modal.frequencies, modal.types) if kind != "rigid" and 0 < f < nyquist})
    mesh_values = sorted(f for stage in meshes.values() for f in stage)
    marks = mesh_values + naturals or [1.0 / result.settings["steady_cycle_s"]]
    top = max([MESH_HARMONICS * f for f in mesh_values[-1:]] + naturals, default=2 * MESH_HARMONICS * marks[0])
    high = min(nyquist, 1.1 * top)
    log = high / min(marks) > LOG_SPAN
    return SpectrumRange(0.5 * min(marks) if log else 0.0, high, log,
                         {k: tuple(sorted(v)) for k, v in sorted(meshes.items())}, tuple(naturals))


def _distinct(f: float) -> float:
    """A frequency to 9 significant digits: one mark for a multiple mode or a frequency both sides share."""
    return float(f"{f:.9g}")


def _amplitude_spectrum(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Hann-windowed amplitude spectrum of the fluctuation of ``x``."""
    seg = x - np.mean(x)
    w = np.hanning(seg.size)
    return np.fft.rfftfreq(seg.size, 1 / fs), 2 * np.abs(np.fft.rfft(seg * w)) / np.sum(w)


def _spectrum_panel(ax, result, name: str, rng: SpectrumRange, legend: bool) -> None:
    """Both sides' spectra of ``name`` over the steady window on ``rng``, mesh harmonics and natural
    frequencies marked."""
    window = result.grid >= result.steady_start_s
    fs = result.settings["common_sample_rate_hz"]
    peak = 0.0
    for x, style in zip(result.series[name], _styles(result)):
        freq, amp = _amplitude_spectrum(x[window], fs)
        shown = (freq >= rng.low) & (freq <= rng.high)
        peak = max(peak, float(np.max(amp[shown], initial=0.0)))
        low, high = np.searchsorted(freq, (rng.low, rng.high))  # drawn: the range shown, a sample beyond each end
        drawn = slice(max(low - 1, 1), high + 1)
        ax.plot(*envelope(freq[drawn], np.maximum(amp[drawn], 1e-30), log=rng.log), **style)
    ax.set_yscale("log")
    ax.yaxis.set_minor_locator(NullLocator())  # decades only: a grid line and a tick a minor step cost seconds
    if rng.log:
        ax.set_xscale("log")
    # marks as one collection per group (a line artist each made the layout's bounding boxes cost seconds)
    across = ax.get_xaxis_transform()
    for j, (stage, freqs) in enumerate(rng.meshes.items()):
        marks = [k * f for f in freqs for k in range(1, GUIDE_HARMONICS + 1) if k * f <= rng.high]
        if marks:
            ax.vlines(marks, 0, 1, transform=across, colors=STAGE_COLORS[j % len(STAGE_COLORS)], lw=0.8,
                      linestyles=":", label=f"{stage} mesh {freqs[0]:.4g} Hz x1-{GUIDE_HARMONICS}" if legend else None)
    if rng.naturals:
        ax.vlines(rng.naturals, 0, 1, transform=across, colors="tab:red", lw=0.5, linestyles="--", alpha=0.5,
                  label="natural frequencies" if legend else None)
    ax.set_xlim(rng.low, rng.high)
    if peak > 0:
        ax.set_ylim(peak / DYNAMIC_RANGE, 3 * peak)
    ax.grid(alpha=0.3, which="both")


def spectra_figure(result) -> Figure:
    """The headline quantities' spectra on :func:`spectrum_range`."""
    names = headline_quantities(result)
    units = {q.name: q.unit for q in result.quantities}
    rng = spectrum_range(result)
    fig, axes = _figure(len(names), 1, figsize=(9, 2.4 * len(names) + 0.6), layout="constrained", sharex=True,
                        squeeze=False)
    for i, (ax, name) in enumerate(zip(axes[:, 0], names)):
        _spectrum_panel(ax, result, name, rng, legend=i == 0)
        ax.set_ylabel(f"amplitude [{units[name]}]")
        ax.set_title(name, fontsize=9)
    axes[0, 0].legend(loc="upper right", fontsize=7, ncol=2)
    axes[-1, 0].set_xlabel(f"frequency [Hz]{' (log)' if rng.log else ''}; dotted: mesh harmonics of each stage, "
                           "dashed: natural frequencies")
    fig.suptitle(_title(result, "amplitude spectra of the steady window (Hann)"), fontsize=9)
    return fig


def spectra(result, path):
    if not result.quantities:
        return False
    _save(spectra_figure(result), path)


def _worst_first(result) -> list:
    """The failing quantities, the largest NRMSE over tolerance first (stable)."""
    def over(q):
        nrmse = q.metrics["nrmse"]
        return np.inf if nrmse is None or not q.tolerance else nrmse / q.tolerance
    return sorted((q for q in result.quantities if q.status == "fail"), key=over, reverse=True)


def failing_figure(result, cycles: int = 4) -> Figure | None:
    """One row per failing quantity (at most ``MAX_FAILING``, the worst first): both sides over the last
    ``cycles`` cycles of its own mesh (the steady-state cycle without one) with their difference, and both
    spectra on :func:`spectrum_range`; None when nothing fails."""
    failing = _worst_first(result)
    if not failing:
        return None
    shown = failing[:MAX_FAILING]
    rng = spectrum_range(result)
    t = result.grid
    fig, axes = _figure(len(shown), 2, figsize=(12, 2.6 * len(shown) + 0.8), layout="constrained",
                        squeeze=False, gridspec_kw={"width_ratios": [3, 2]})
    style_a, style_b = _styles(result)
    a_name, b_name = result.solver_names
    for i, (q, (ax_t, ax_f)) in enumerate(zip(shown, axes)):
        mesh = next((s["frequency_hz"] for s in q.spectrum if s["line"] == "1x mesh"), None)
        period = 1.0 / mesh if mesh else result.settings["steady_cycle_s"]
        window = t >= max(t[-1] - cycles * period, result.steady_start_s)
        a, b = (x[window] for x in result.series[q.name])
        ms = t[window] * 1e3
        ax_t.plot(*envelope(ms, b - a), color="tab:red", lw=0.7, alpha=0.6, label=f"{b_name} - {a_name}")
        ax_t.plot(*envelope(ms, a), **style_a)
        ax_t.plot(*envelope(ms, b), **style_b)
        ax_t.set_ylabel(f"[{q.unit}]")
        nrmse = q.metrics["nrmse"]
        ratio = f" ({nrmse / q.tolerance:.3g}x)" if nrmse is not None and q.tolerance else ""
        ax_t.set_title(f"{q.name}: NRMSE {_fmt(nrmse)} > tolerance {_fmt(q.tolerance)}{ratio}", fontsize=9,
                       loc="left")
        ax_t.grid(alpha=0.3)
        _spectrum_panel(ax_f, result, q.name, rng, legend=i == 0)
        ax_f.set_title("spectrum", fontsize=9)
    axes[0, 0].legend(loc="upper right", fontsize=7)
    axes[0, 1].legend(loc="upper right", fontsize=6)
    axes[-1, 0].set_xlabel(f"time [ms], last {cycles} mesh cycles")
    axes[-1, 1].set_xlabel(f"frequency [Hz]{' (log)' if rng.log else ''}")
    capped = (f"; the {MAX_FAILING} worst by NRMSE / tolerance shown, all {len(failing)} in the report's tables"
              if len(failing) > MAX_FAILING else "")
    fig.suptitle(_title(result, f"{len(failing)} failing quantities{capped}"), fontsize=9)
    return fig


def failing(result, path):
    fig = failing_figure(result)
    if fig is None:
        return False
    _save(fig, path)


def _fmt(x) -> str:
    return "—" if x is None else f"{x:.3g}"


def natural_frequencies(result, path):
    rows = result.modal
    if not rows:  # a recording without modes
        return False
    a, b = result.solver_names
    idx = np.arange(1, len(rows) + 1)
    fig, (ax, ax2) = _figure(2, 1, figsize=(9, 5), sharex=True)
    ax.plot(idx, [r["reference_hz"] for r in rows], "o", color="tab:blue", label=a)
    ax.plot(idx, [r["test_hz"] for r in rows], "x", color="tab:orange", label=b)
    ax.set_ylabel("natural frequency [Hz]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    errors = np.array([max(r["rel_error"], 1e-17) for r in rows])
    ax2.semilogy(idx, errors, "s", color="tab:green", label=f"|f_{b} - f_{a}| / f_{a}")
    ax2.axhline(result.modal_tolerance, color="tab:red", ls="--", label="tolerance")
    ax2.set_xlabel("mode")
    ax2.set_ylabel("relative difference [-]")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3, which="both")
    fig.suptitle(f"{result.spec.name}: natural frequencies at mean mesh stiffness", fontsize=9)
    _save(fig, path)


def error_bars(result, path):
    gated = [q for q in result.quantities if q.status != "negligible" and q.metrics["nrmse"] is not None]
    if not gated:
        return False
    fig, ax = _figure(figsize=(9, max(3.0, 0.22 * len(gated) + 1.5)))
    y = np.arange(len(gated))
    values = [max(q.metrics["nrmse"], 1e-12) for q in gated]
    colors = [{"fail": "tab:red", "unresolved": "tab:orange"}.get(q.status, "tab:green") for q in gated]
    ax.barh(y, values, color=colors)
    ax.scatter([q.tolerance or np.nan for q in gated], y, marker="|", s=200, color="black", label="tolerance")
    ax.set_yticks(y, [q.name for q in gated], fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel("normalised RMS error rms(b - a)/rms(a) [-]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="x", which="both")
    fig.suptitle(_title(result, "waveform error per quantity"), fontsize=9)
    _save(fig, path)


FIGURES = {  # failing.png only when a quantity fails
    "failing.png": failing,
    "time_histories.png": time_histories,
    "spectra.png": spectra,
    "natural_frequencies.png": natural_frequencies,
    "errors.png": error_bars,
}


def mesh_stiffness_figure(spec, cycles: int = 2) -> Figure:
    """k over ``cycles`` mesh cycles for the first planet's mesh with every central gear of every stage (the model
    the train file names), beside its mean."""
    first = [m for m in spec.meshes if m.planet_index == 0]
    fig, axes = _figure(len(first), 1, figsize=(9, 2.0 * len(first)), sharex=True, squeeze=False)
    xi = np.linspace(0.0, cycles, 2000 * cycles + 1)
    for ax, mesh in zip(axes[:, 0], first):
        model = stiffness_model(mesh)
        ax.plot(xi, model(xi) / 1e9, color="tab:blue", lw=1.2, label="k(xi)")
        ax.axhline(model.mean / 1e9, color="gray", ls="--", lw=0.8, label=f"mean {model.mean:.4g} N/m")
        ax.set_ylabel("k [N/µm]")
        ax.set_title(f"{mesh.id} ({mesh.stiffness['model']}, contact ratio {mesh.geometry.contact_ratio:.4f})",
                     fontsize=9)
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("mesh cycles (0 = a tooth pair enters contact)")
    fig.suptitle(f"{spec.name}: time-varying mesh stiffness", fontsize=9)
    return fig


def mesh_stiffness(spec, cycles: int = 2) -> bytes:
    """PNG of :func:`mesh_stiffness_figure`."""
    return _png(mesh_stiffness_figure(spec, cycles))


MODE_COLORS = {"rotational": "tab:blue", "translational": "tab:green", "planet": "tab:purple"}  # others: gray


def campbell_figure(result, solvers=None) -> Figure:
    """A :class:`~gearcheck.compare.studies.campbell.CampbellResult` drawn: lumped curves coloured by mode type
    (at the lowest speed), MuJoCo markers, mesh lines, their crossings with the curves (hollow where the line's
    phased mesh forces do not reach the mode: Parker 2000), instability zones shaded; ``solvers``: those drawn
    (default: all)."""
    fig, ax = _figure(figsize=(9, 6))
    speeds = result.speeds_rpm
    shown = list(result.results) if solvers is None else list(solvers)
    labelled = set()
    if "lumped" in shown:
        f, types = result.frequencies("lumped"), result.results["lumped"][0].types
        for mode in range(f.shape[1]):
            kind = types[mode]
            ax.plot(speeds, f[:, mode], color=MODE_COLORS.get(kind, "tab:gray"), lw=1.0,
                    label=None if kind in labelled else f"lumped, {kind}")
            labelled.add(kind)
    if "mujoco" in shown:
        f = result.frequencies("mujoco")
        for mode in range(f.shape[1]):
            ax.plot(speeds, f[:, mode], color="black", ls="none", marker=".", ms=2.5,
                    label="MuJoCo" if mode == 0 else None)
    top = max(float(np.max(result.frequencies(s))) for s in shown) * 1.05
    for line in result.mesh_lines:
        ax.plot(speeds, line["hz_per_rpm"] * speeds, color="gray", lw=0.7, ls=":" if line["harmonic"] > 1 else "-")
        end = min(speeds[-1], top / line["hz_per_rpm"]) if line["hz_per_rpm"] > 0 else speeds[-1]
        ax.annotate(f"{line['harmonic']}x {line['meshes'][0].rsplit('.', 2)[0]}", (end, line["hz_per_rpm"] * end),
                    fontsize=6, color="gray", ha="right", va="bottom")
    reached = [c for c in result.crossings if c["excited"] is not False]
    kept = [c for c in result.crossings if c["excited"] is False]
    if reached:
        ax.plot([c["speed_rpm"] for c in reached], [c["frequency_hz"] for c in reached], "kx", ms=5,
                label="mesh harmonic = natural frequency" + ("" if kept else " (no phasing rule applies)"
                                                             if all(c["excited"] is None for c in reached) else ""))
    if kept:
        ax.plot([c["speed_rpm"] for c in kept], [c["frequency_hz"] for c in kept], "o", ms=5, mfc="none",
                color="gray", label="crossing whose line does not reach the mode")
    for zone in result.zones:
        ax.axvspan(zone["from_rpm"], zone["to_rpm"], color="red", alpha=0.15,
                   label=f"unstable ({zone['solver']})" if zone is result.zones[0] else None)
    ax.set_xlim(speeds[0], speeds[-1])
    ax.set_ylim(0, top)
    ax.set_xlabel("input speed [rpm]")
    ax.set_ylabel("natural frequency [Hz]")
    agreement = result.agreement
    ax.set_title(f"{result.train}: Campbell diagram (gyroscopic modes at mean mesh stiffness)"
                 + (f"; solvers agree to {agreement:.1e}" if agreement is not None else ""), fontsize=9)
    ax.legend(loc="upper left", fontsize=7)
    ax.grid(alpha=0.3)
    return fig


def campbell_diagram(result) -> bytes:
    """PNG of :func:`campbell_figure`."""
    return _png(campbell_figure(result))


def static_transmission_error(curves, train: str) -> bytes:
    """PNG of the unloaded and loaded static TE over one mesh cycle of the first planet's meshes
    (:func:`gearcheck.lumped.transmission_error.static_transmission_error`)."""
    first = [c for c in curves if c.mesh.split(".")[1] in ("planet1",)] or curves[:1]
    fig, axes = _figure(len(first), 1, figsize=(9, 2.4 * len(first)), sharex=True, squeeze=False)
    for ax, c in zip(axes[:, 0], first):
        ax.plot(c.xi, c.loaded * 1e6, color="tab:blue", lw=1.2, label=f"loaded ({c.load:.4g} N)")
        ax.plot(c.xi, c.unloaded * 1e6, color="tab:orange", lw=1.0, label="unloaded")
        ax.axhline(c.mean_deflection * 1e6, color="gray", ls="--", lw=0.8,
                   label=f"F / k_mean = {c.mean_deflection * 1e6:.3g} µm")
        ax.set_ylabel("STE [µm]")
        ax.set_title(f"{c.mesh}: loaded peak-to-peak {np.ptp(c.loaded) * 1e6:.4g} µm", fontsize=9)
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("mesh cycles (0 = a tooth pair enters contact)")
    fig.suptitle(f"{train}: static transmission error (mesh approach along the line of action)", fontsize=9)
    return _png(fig)


def relief_sweep(sweep: dict, train: str) -> bytes:
    """PNG of the loaded static TE peak-to-peak against the tip relief amount, per mesh of the first planet,
    the load's mean deflection F / k_mean marked (:func:`gearcheck.lumped.transmission_error.relief_sweep`)."""
    fig, ax = _figure(figsize=(9, 5))
    amounts = np.array(sweep["amounts_m"]) * 1e6
    for j, (mesh, data) in enumerate((m, d) for m, d in sweep["meshes"].items() if ".planet1." in m):
        color = f"C{j}"
        ax.plot(amounts, np.array(data["loaded_peak_to_peak_m"]) * 1e6, color=color, marker=".", label=mesh)
        ax.axvline(data["mean_deflection_m"] * 1e6, color=color, ls="--", lw=0.8,
                   label=f"{mesh}: F / k_mean = {data['mean_deflection_m'] * 1e6:.3g} µm")
    ax.set_xlabel("tip relief amount $C_a$ [µm]")
    ax.set_ylabel("loaded STE peak-to-peak [µm]")
    ax.set_title(f"{train}: loaded static transmission error against the tip relief", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return _png(fig)


def mac_figure(pairing) -> Figure:
    """A :class:`~gearcheck.compare.engine.mode_pairing.ModePairing` drawn: the MAC matrix, reference modes down, test
    modes across, with the frequencies on the axes."""
    fig, ax = _figure(figsize=(7.5, 6.5))
    image = ax.imshow(pairing.mac, vmin=0.0, vmax=1.0, cmap="viridis", origin="upper", aspect="auto")
    fig.colorbar(image, ax=ax, label="MAC")
    ax.set_yticks(np.arange(len(pairing.frequencies_reference)),
                  [f"{i + 1}: {f:.5g}" for i, f in enumerate(pairing.frequencies_reference)], fontsize=6)
    ax.set_xticks(np.arange(len(pairing.frequencies_test)), [f"{f:.5g}" for f in pairing.frequencies_test],
                  fontsize=6, rotation=90)
    ax.set_ylabel(f"{pairing.reference} modes [Hz]")
    ax.set_xlabel(f"{pairing.test} modes [Hz]")
    ax.set_title(f"{pairing.train}: modal assurance criterion, worst paired {pairing.paired.min():.9f}"
                 + (f"; {len(pairing.findings)} findings" if pairing.findings else ""), fontsize=9)
    return fig


def mac_heatmap(pairing) -> bytes:
    """PNG of :func:`mac_figure`."""
    return _png(mac_figure(pairing))



DISC_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


def pin_loads(loads, index: int = 0, title: str | None = None) -> bytes:
    """PNG of a :class:`~gearcheck.lumped.pin_loads.PinLoads`: left, the pin circle at time ``times[index]`` with a
    radial bar per loaded pin (length proportional to its force; a black tick where the rigid-disc share would
    end) and each
    disc's profile and eccentric; right, the force against the pin's angle from its disc's eccentric over every
    time, beside the rigid-disc share and the classical peak 4 T / (Z_p r_c)."""
    fig = Figure(figsize=(12.0, 5.6), layout="constrained")
    ax, bx = fig.subplots(1, 2, width_ratios=(1.0, 1.25))
    _pin_circle(ax, loads, index)
    _pin_force_against_angle(bx, loads)
    if title:
        fig.suptitle(title, fontsize=11)
    return _png(fig)


def _pin_circle(ax, loads, index: int) -> None:
    """The pin circle at ``times[index]`` (mm, carrier frame): the pins, each disc with its loaded pins' bars and
    rigid-disc ticks, a force scale bar."""
    g = loads.geometry
    mm = 1e3
    scale = 0.45 * g.pin_circle_radius * mm / max(float(loads.forces.max()), float(loads.classical.max()), 1e-300)
    circle = np.linspace(0, 2 * np.pi, 361)
    ax.plot(g.pin_circle_radius * mm * np.cos(circle), g.pin_circle_radius * mm * np.sin(circle), color="0.6",
            lw=0.8, ls="--")
    for c in loads.pin_angles[index]:
        centre = g.pin_circle_radius * mm * np.array([math.cos(c), math.sin(c)])
        ax.plot(centre[0] + g.pin_radius * mm * np.cos(circle), centre[1] + g.pin_radius * mm * np.sin(circle),
                color="0.35", lw=0.7)
    for j in range(loads.forces.shape[1]):
        _disc_on_pin_circle(ax, loads, index, j, scale)
    ax.plot([], [], color="k", lw=0.9, label="rigid-disc share (tick)")
    ref = 10 ** math.floor(math.log10(max(float(loads.forces.max()), 1e-300)))
    reach = g.pin_circle_radius * mm + 0.5 * g.pin_circle_radius * mm
    ax.plot([-reach, -reach + scale * ref], [-reach, -reach], color="k", lw=2.0)
    ax.text(-reach + 0.5 * scale * ref, -reach + 3.0, f"{ref:g} N", ha="center", va="bottom", fontsize=8)
    ax.set_aspect("equal")
    lim = reach + 0.05 * g.pin_circle_radius * mm
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("x (mm), carrier frame")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"pin forces at t = {loads.times[index] * 1e3:.3f} ms (arrows: eccentrics)", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.1), ncol=2, fontsize=7.5, frameon=False)


def _disc_on_pin_circle(ax, loads, index: int, j: int, scale: float) -> None:
    """Disc ``j`` at ``times[index]``: its profile, an arrow along its eccentric, a radial bar of ``scale`` mm/N
    per loaded pin (side by side with the other discs' within a pitch) and a tick at its rigid-disc share."""
    g = loads.geometry
    mm = 1e3
    n_discs = loads.forces.shape[1]
    force, classical, psi = loads.forces[index], loads.classical[index], loads.pin_angles[index]
    base = g.pin_circle_radius * mm + g.pin_radius * mm
    colour = DISC_COLOURS[j % len(DISC_COLOURS)]
    phi = loads.eccentric_angles[index, j]
    theta = float(conjugate_disc_angle(g, phi, loads.pin_angles[index, 0]))
    rot = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    profile = (disc_profile(g, points_per_lobe=24) @ rot.T + g.eccentricity * np.array([math.cos(phi),
                                                                                        math.sin(phi)])) * mm
    ax.plot(np.r_[profile[:, 0], profile[0, 0]], np.r_[profile[:, 1], profile[0, 1]], color=colour, lw=0.6,
            alpha=0.6)
    ax.annotate("", xy=(0.55 * g.pin_circle_radius * mm * math.cos(phi),
                        0.55 * g.pin_circle_radius * mm * math.sin(phi)), xytext=(0, 0),
                arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.2})
    offset = (j - (n_discs - 1) / 2) * (2 * np.pi / g.pins) / (n_discs + 1)
    for i in np.nonzero(force[j] > 0)[0]:
        a = psi[i] + offset
        u = np.array([math.cos(a), math.sin(a)])
        tip = base + scale * force[j, i]
        ax.plot([base * u[0], tip * u[0]], [base * u[1], tip * u[1]], color=colour, lw=4.0,
                solid_capstyle="butt")
    for i in np.nonzero(classical[j] > 0)[0]:
        a = psi[i] + offset
        u, w = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
        tip = (base + scale * classical[j, i]) * u
        ax.plot(*np.array([tip - 2.0 * w, tip + 2.0 * w]).T, color="k", lw=0.9)
    ax.plot([], [], color=colour, lw=4.0, label=f"disc {j + 1}: {int((force[j] > 0).sum())} pins, "
                                                 f"peak {force[j].max():.0f} N")


def _pin_force_against_angle(bx, loads) -> None:
    """Every disc's pin forces at every time against the pin's angle from its disc's eccentric, beside the
    rigid-disc share and the classical peak 4 T / (Z_p r_c)."""
    g = loads.geometry
    fine = np.linspace(-np.pi, np.pi, 721)
    wrapped = np.degrees(np.mod(loads.relative_angles + np.pi, 2 * np.pi) - np.pi)  # (-180, 180]: one loaded zone
    k1 = g.K1
    arm = g.rolling_radius * np.sin(fine) / np.sqrt(1 + k1 * k1 - 2 * k1 * np.cos(fine))
    for j in range(loads.forces.shape[1]):
        colour = DISC_COLOURS[j % len(DISC_COLOURS)]
        on = loads.forces[:, j, :] > 0
        bx.plot(wrapped[:, j, :][on], loads.forces[:, j, :][on], ls="none",
                marker="o" if j == 0 else "x", ms=3.0, color=colour, alpha=0.7,
                label=f"disc {j + 1}, {len(loads.times)} frozen times")
    torque = float(np.mean(loads.disc_torque))
    peak = float(np.mean(loads.classical_peak))
    bx.plot(np.degrees(fine), np.where(np.sign(torque) * arm > 0, peak * np.abs(arm) / g.rolling_radius, 0.0),
            color="k", lw=1.0, ls="--", label="rigid disc, 4 T/(Z_p r_c) |l| / r_c")
    bx.axhline(peak, color="0.4", lw=0.8, ls=":", label=f"4 T/(Z_p r_c) = {peak:.0f} N")
    bx.set_xlim(-180, 180)
    bx.set_xticks(range(-180, 181, 45))
    bx.set_xlabel("pin angle from its disc's eccentric, φ [deg]")
    bx.set_ylabel("pin force (N)")
    s = loads.summary()
    rigid = (loads.classical > 0).sum(axis=-1)
    bx.set_title(f"{s['loaded_pins_min']}-{s['loaded_pins_max']} pins loaded per disc, disc torque "
                 f"{s['disc_torque_nm']:.1f} N m\npeak {s['peak_force_n']:.0f} N = {s['peak_ratio_max']:.3f} x "
                 f"4 T/(Z_p r_c) (rigid disc: {rigid.min()}-{rigid.max()} pins)", fontsize=10)
    bx.legend(loc="upper left", fontsize=7.5, frameon=False)
    bx.grid(True, lw=0.3)


def sensitivity_values(frame, coordinate: str, title: str) -> bytes:
    """PNG of a :func:`~gearcheck.compare.studies.sensitivity.sensitivity_map` table over one parameter's values:
    the amplitude of the three largest harmonics of ``coordinate`` and their sensitivity d|Q|/dp against the value, a
    line style per speed (as Yang, Chen & Wang 2018 draw their Figs. 6, 8, 10), round-off drawn as zero (and said
    in the title when every derivative is); a logarithmic value axis when the values are positive and span a decade
    or more."""
    parameter = frame["parameter"].iloc[0]
    largest = frame.groupby("harmonic", sort=False)["amplitude"].max().sort_values(ascending=False, kind="stable")
    harmonics = list(largest.index[:3])  # the three largest: a translation answers the eccentrics, not the mesh
    speeds = list(dict.fromkeys(frame["speed_rpm"]))
    fig, axes = _figure(2, 1, figsize=(8, 5.5), sharex=True, squeeze=False, layout="constrained")
    styles = ["-", "--", ":", "-."]
    for i, h in enumerate(harmonics):
        for j, rpm in enumerate(speeds):
            r = frame[(frame["harmonic"] == h) & (frame["speed_rpm"] == rpm)]
            label = f"h = {h}, {rpm:.6g} rpm"
            axes[0, 0].semilogy(r["value"], r["amplitude"], color=f"C{i}", ls=styles[j % 4], lw=1.2, label=label)
            slope = r["d_amplitude_d_p"].where(~r["negligible"].astype(bool), 0.0)  # round-off drawn as zero
            axes[1, 0].plot(r["value"], slope, color=f"C{i}", ls=styles[j % 4], lw=1.2, marker=".")
    values = frame["value"]
    if (values > 0).all() and values.max() >= 10 * values.min():
        axes[1, 0].set_xscale("log")
    unit = frame["amplitude_unit"].iloc[0]
    axes[0, 0].set_ylabel(f"|Q_h| of {coordinate} ({unit})", fontsize=8)
    axes[1, 0].set_ylabel(f"d|Q_h|/dp ({unit} per unit of p)", fontsize=8)
    axes[1, 0].axhline(0.0, color="0.5", lw=0.6)
    axes[1, 0].set_xlabel(f"{parameter} (the train file's unit)")
    axes[0, 0].legend(fontsize=7, ncol=2)
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
    null = bool(frame["negligible"].astype(bool).all())
    fig.suptitle(title + ("\nthe response does not depend on it: every derivative is round-off (negligible)" if null
                          else ""), fontsize=9)
    return _png(fig)


def sensitivity_family(frame, coordinate: str, title: str) -> bytes:
    """PNG of a :func:`~gearcheck.compare.studies.sensitivity.sensitivity_map` table over one parameter's values and
    a range of speeds: per harmonic of the table (a row of panels each), its amplitude |Q_h| and its sensitivity
    d|Q_h|/dp over the mesh frequency, a curve per value (Yang, Chen & Wang 2018, Figs. 5, 7, 9: the family of
    resonant curves as the parameter moves); round-off drawn as zero."""
    from matplotlib import colormaps

    parameter = frame["parameter"].iloc[0]
    harmonics = list(dict.fromkeys(frame["harmonic"]))
    values = sorted(dict.fromkeys(frame["value"]))
    colours = colormaps["viridis"](np.linspace(0.0, 0.85, len(values)))
    fig, axes = _figure(len(harmonics), 2, figsize=(11, 0.6 + 2.5 * len(harmonics)), sharex=True, squeeze=False,
                        layout="constrained")
    unit = frame["amplitude_unit"].iloc[0]
    for i, h in enumerate(harmonics):
        for value, colour in zip(values, colours):
            r = frame[(frame["harmonic"] == h) & (frame["value"] == value)].sort_values("mesh_frequency_hz")
            axes[i, 0].semilogy(r["mesh_frequency_hz"], r["amplitude"], color=colour, lw=1.2,
                                label=f"p = {value:.4g}")
            slope = r["d_amplitude_d_p"].where(~r["negligible"].astype(bool), 0.0)  # round-off drawn as zero
            axes[i, 1].plot(r["mesh_frequency_hz"], slope, color=colour, lw=1.2)
        axes[i, 0].set_ylabel(f"|Q_h|, h = {h} ({unit})", fontsize=8)
        axes[i, 1].set_ylabel(f"d|Q_h|/dp, h = {h}\n({unit} per unit of p)", fontsize=8)
        axes[i, 1].axhline(0.0, color="0.5", lw=0.6)
    axes[0, 0].legend(fontsize=7, ncol=2, title=f"p = {parameter}", title_fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("mesh frequency of the first stage (Hz)")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    null = bool(frame["negligible"].astype(bool).all())
    fig.suptitle(title + ("\nthe response does not depend on it: every derivative is round-off (negligible)" if null
                          else ""), fontsize=9)
    return _png(fig)


def sensitivity_map(frame, coordinate: str, title: str) -> bytes:
    """PNG of a :func:`~gearcheck.compare.studies.sensitivity.sensitivity_map` table: the amplitude of each harmonic of
    ``coordinate`` over the mesh frequency, then per parameter its sensitivity d|Q|/d ln p (solid) and the paper's
    Eq. (15) (dashed, when the table has it)."""
    parameters = list(dict.fromkeys(frame["parameter"]))
    harmonics = list(dict.fromkeys(frame["harmonic"]))[:6]
    fig, axes = _figure(1 + len(parameters), 1, figsize=(9, 2.4 * (1 + len(parameters))), sharex=True,
                        squeeze=False, layout="constrained")
    colours = [f"C{i}" for i in range(len(harmonics))]
    first = frame[frame["parameter"] == parameters[0]]
    for h, colour in zip(harmonics, colours):
        rows = first[first["harmonic"] == h]
        axes[0, 0].semilogy(rows["mesh_frequency_hz"], rows["amplitude"], color=colour, lw=1.2, label=f"h = {h}")
    axes[0, 0].set_ylabel(f"|Q_h| of {coordinate}", fontsize=8)
    axes[0, 0].legend(fontsize=7, ncol=3)
    for ax, parameter in zip(axes[1:, 0], parameters):
        rows = frame[frame["parameter"] == parameter]
        for h, colour in zip(harmonics, colours):
            r = rows[rows["harmonic"] == h]
            ax.plot(r["mesh_frequency_hz"], r["d_amplitude_d_ln_p"], color=colour, lw=1.2)
            if r["eq15_d_amplitude_d_ln_p"].notna().all():
                ax.plot(r["mesh_frequency_hz"], r["eq15_d_amplitude_d_ln_p"], color=colour, lw=0.9, ls="--")
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.set_ylabel(f"d|Q|/d ln p\n{parameter}", fontsize=8)
    axes[-1, 0].set_xlabel("mesh frequency of the first stage (Hz)")
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
    fig.suptitle(title + "\nsolid: differentiated harmonic equations; dashed: Yang, Chen & Wang (2018) Eq. (15)",
                 fontsize=9)
    return _png(fig)
