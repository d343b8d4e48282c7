"""Report figures (PNG, deterministic: no timestamps in the files).

Figures are drawn on :class:`matplotlib.figure.Figure` objects and saved through Agg without
pyplot, so writing a report never touches the user's matplotlib backend.
"""

from __future__ import annotations

import io

import numpy as np
from matplotlib.figure import Figure

from gearcheck.lumped.mesh_stiffness import stiffness_model

REFERENCE_STYLE = {"color": "tab:blue", "lw": 1.2}
TEST_STYLE = {"color": "tab:orange", "lw": 1.0, "ls": "--"}


def _styles(result) -> tuple[dict, dict]:
    """The reference's and the test's line styles, labelled with their names."""
    a, b = result.solver_names
    return {**REFERENCE_STYLE, "label": a}, {**TEST_STYLE, "label": b}


def _figure(rows: int = 1, cols: int = 1, figsize=(9, 5), **kwargs):
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(rows, cols, **kwargs)


def _save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None}, format="png")


def _png(fig) -> bytes:
    """The figure as PNG bytes (for :func:`gearcheck.shared.outputs.write_file`)."""
    png = io.BytesIO()
    _save(fig, png)
    return png.getvalue()


def headline_quantities(result) -> list[str]:
    """Carrier and ring accelerations (world y, as the accelerometers see them) and the first
    sun-planet and ring-planet mesh forces of every stage; the first four quantities when none
    of those is compared."""
    names = []
    available = {q.name for q in result.quantities}
    for stage in result.spec.stages:
        for member in (stage.carrier, *[c for c in stage.centrals if result.spec.members[c].kind == "ring"]):
            names.append(f"{member}.ay.world")
        for mesh in result.spec.meshes:
            if mesh.stage == stage.name and mesh.planet_index == 0:
                names.append(f"{mesh.id}.force")
    names = [n for n in names if n in available]
    if not names:  # trains compared on other quantities (e.g. a published 4-DOF model): the first four
        names = [q.name for q in result.quantities][:4]
    return names


def _title(result, what: str) -> str:
    s = result.settings
    a, b = result.solver_names
    return (f"{result.spec.name} at {s['input_speed_rpm']:.6g} rpm: {what}\n"
            f"{a} {s['lumped'].get('method', '')} dt={s['lumped'].get('dt_s', float('nan')):.3g} s, "
            f"{b} {s['mujoco'].get('integrator', s['mujoco'].get('method', ''))} "
            f"dt={s['mujoco'].get('dt_s', float('nan')):.3g} s")


def time_histories(result, path, cycles: int = 4):
    names = headline_quantities(result)
    units = {q.name: q.unit for q in result.quantities}
    f_cycle = 1.0 / result.settings["steady_cycle_s"]
    t = result.grid
    t_end = t[-1]
    window = t >= t_end - cycles / f_cycle
    fig, axes = _figure(len(names), 1, figsize=(9, 2.2 * len(names)), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        a, b = result.series[name]
        style_a, style_b = _styles(result)
        ax.plot(t[window] * 1e3, a[window], **style_a)
        ax.plot(t[window] * 1e3, b[window], **style_b)
        ax.set_ylabel(f"[{units[name]}]")
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time [ms]")
    fig.suptitle(_title(result, f"steady-state time histories, last {cycles} mesh cycles"), fontsize=9)
    _save(fig, path)


def spectra(result, path):
    names = headline_quantities(result)
    units = {q.name: q.unit for q in result.quantities}
    window = result.grid >= result.steady_start_s
    fs = result.settings["common_sample_rate_hz"]
    f_mesh = 1.0 / result.settings["steady_cycle_s"]
    fig, axes = _figure(len(names), 1, figsize=(9, 2.2 * len(names)), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        for x, style in zip(result.series[name], _styles(result)):
            seg = x[window] - np.mean(x[window])
            w = np.hanning(seg.size)
            amp = 2 * np.abs(np.fft.rfft(seg * w)) / np.sum(w)
            freq = np.fft.rfftfreq(seg.size, 1 / fs)
            ax.semilogy(freq, np.maximum(amp, 1e-30), **style)
        for k in range(1, 6):
            ax.axvline(k * f_mesh, color="gray", lw=0.5, ls=":")
        ax.set_xlim(0, min(0.5 * fs, 6 * f_mesh))
        ax.set_ylabel(f"amplitude [{units[name]}]")
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3, which="both")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("frequency [Hz] (dotted: mesh harmonics)")
    fig.suptitle(_title(result, "amplitude spectra of the steady window (Hann)"), fontsize=9)
    _save(fig, path)


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
    fig, ax = _figure(figsize=(9, max(3.0, 0.22 * len(gated) + 1.5)))
    y = np.arange(len(gated))
    values = [max(q.metrics["nrmse"], 1e-12) for q in gated]
    colors = ["tab:red" if q.status == "fail" else "tab:green" for q in gated]
    ax.barh(y, values, color=colors)
    ax.scatter([q.tolerance or np.nan for q in gated], y, marker="|", s=200, color="black", label="tolerance")
    ax.set_yticks(y, [q.name for q in gated], fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel("normalised RMS error rms(b - a)/rms(a) [-]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="x", which="both")
    fig.suptitle(_title(result, "waveform error per quantity"), fontsize=9)
    _save(fig, path)


FIGURES = {
    "time_histories.png": time_histories,
    "spectra.png": spectra,
    "natural_frequencies.png": natural_frequencies,
    "errors.png": error_bars,
}


def mesh_stiffness(spec, cycles: int = 2) -> bytes:
    """PNG of k over ``cycles`` mesh cycles for the first planet's mesh with every central gear of every
    stage (the model the train file names), with the number of tooth pairs in contact."""
    first = [m for m in spec.meshes if m.planet_index == 0]
    fig, axes = _figure(len(first), 1, figsize=(9, 2.0 * len(first)), sharex=True, squeeze=False)
    xi = np.linspace(0.0, cycles, 2000 * cycles + 1)
    for ax, mesh in zip(axes[:, 0], first):
        model = stiffness_model(mesh)
        ax.plot(xi, model(xi) / 1e9, color="tab:blue", lw=1.2, label="k(xi)")
        ax.axhline(model.mean / 1e9, color="gray", ls="--", lw=0.8, label=f"mean {model.mean:.4g} N/m")
        ax.set_ylabel("k [N/um]")
        ax.set_title(f"{mesh.id} ({mesh.stiffness['model']}, contact ratio {mesh.geometry.contact_ratio:.4f})",
                     fontsize=9)
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("mesh cycles (0 = a tooth pair enters contact)")
    fig.suptitle(f"{spec.name}: time-varying mesh stiffness", fontsize=9)
    return _png(fig)


def campbell_diagram(result) -> bytes:
    """PNG of a :class:`~gearcheck.compare.campbell.CampbellResult`: lumped curves, MuJoCo markers, mesh
    lines, their crossings with the curves, instability zones shaded."""
    fig, ax = _figure(figsize=(9, 6))
    speeds = result.speeds_rpm
    for solver, style in (("lumped", {"color": "tab:blue", "lw": 1.0}),
                          ("mujoco", {"color": "tab:orange", "ls": "none", "marker": ".", "ms": 3})):
        if solver not in result.results:
            continue
        f = result.frequencies(solver)
        for mode in range(f.shape[1]):
            ax.plot(speeds, f[:, mode], **style, label=("lumped" if solver == "lumped" else "MuJoCo")
                    if mode == 0 else None)
    top = max(float(np.max(result.frequencies(s))) for s in result.results) * 1.05
    for line in result.mesh_lines:
        ax.plot(speeds, line["hz_per_rpm"] * speeds, color="gray", lw=0.7, ls=":" if line["harmonic"] > 1 else "-")
        end = min(speeds[-1], top / line["hz_per_rpm"]) if line["hz_per_rpm"] > 0 else speeds[-1]
        ax.annotate(f"{line['harmonic']}x {line['meshes'][0].rsplit('.', 2)[0]}", (end, line["hz_per_rpm"] * end),
                    fontsize=6, color="gray", ha="right", va="bottom")
    if result.crossings:
        ax.plot([c["speed_rpm"] for c in result.crossings], [c["frequency_hz"] for c in result.crossings], "kx",
                ms=4, label="mesh harmonic = natural frequency")
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
    return _png(fig)


def static_transmission_error(curves, train: str) -> bytes:
    """PNG of the unloaded and loaded static TE over one mesh cycle of the first planet's meshes
    (:func:`gearcheck.lumped.transmission_error.static_transmission_error`)."""
    first = [c for c in curves if c.mesh.split(".")[1] in ("planet1",)] or curves[:1]
    fig, axes = _figure(len(first), 1, figsize=(9, 2.4 * len(first)), sharex=True, squeeze=False)
    for ax, c in zip(axes[:, 0], first):
        ax.plot(c.xi, c.loaded * 1e6, color="tab:blue", lw=1.2, label=f"loaded ({c.load:.4g} N)")
        ax.plot(c.xi, c.unloaded * 1e6, color="tab:orange", lw=1.0, label="unloaded")
        ax.axhline(c.mean_deflection * 1e6, color="gray", ls="--", lw=0.8,
                   label=f"F / k_mean = {c.mean_deflection * 1e6:.3g} um")
        ax.set_ylabel("STE [um]")
        ax.set_title(f"{c.mesh}: loaded peak-to-peak {np.ptp(c.loaded) * 1e6:.4g} um", fontsize=9)
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
                   label=f"{mesh}: F / k_mean = {data['mean_deflection_m'] * 1e6:.3g} um")
    ax.set_xlabel("tip relief amount C_a [um]")
    ax.set_ylabel("loaded STE peak-to-peak [um]")
    ax.set_title(f"{train}: loaded static transmission error against the tip relief", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return _png(fig)


def mac_heatmap(pairing) -> bytes:
    """PNG of a :class:`~gearcheck.compare.mode_pairing.ModePairing`: the MAC matrix, reference modes down, test
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
    return _png(fig)
