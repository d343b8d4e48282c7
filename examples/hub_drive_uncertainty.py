"""The uncertainty band of the hub-drive Table 1 prediction (Li et al. 2026): Monte Carlo of calibrate-then-predict.

The hub-drive preset's unpublished numbers (the paper gives no parameter table) are drawn from the plausible
ranges of ``DISTRIBUTIONS`` (each with its reason); in every sample the calibration of docs/hub-drive-calibration
is repeated (stage I transmission error 0.2-20 um and drag 20-20000 N·m fitted on Table 1 at 606 rpm, runs of
0.45 s, window from the start-up's decay) and ring I and carrier II are predicted at 1823 rpm with the lumped
solver.  Writes samples.csv, summary.json and two figures into --out.

The samples run in chunks (``--chunk``) cached in ``--cache``, so an interrupted study resumes, and
``--minutes`` stops starting new chunks after that long: the table holds the first N samples of the seed,
whatever the chunking.

Run:  OPENBLAS_NUM_THREADS=1 python examples/hub_drive_uncertainty.py --samples 60 --workers 2
      python examples/hub_drive_uncertainty.py --report-only      (figures and summary from samples.csv)
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

import gearcheck
from gearcheck.compare.studies import NOMINAL, band, drivers, uncertainty_study

G = 9.8  # m/s^2 per g, as the paper
FITS = ["stages[0].mesh.ste[0].amplitude_um=0.2:20", "operating.output_torque=20:20000"]
FIT_RPM, PREDICT_RPM = 606.0, 1823.0
RING, CARRIER = "I.ring.ay.world.peak", "II.carrier.ay.world.peak"
TEST = {RING: 3.83, CARRIER: 0.29}  # g, Table 1 at 1823 rpm
PAPER = {RING: 3.49, CARRIER: 0.31}  # g, the paper's model at 1823 rpm

# field -> (distribution in the file's units, why).  Medians are the preset's representative values.
DISTRIBUTIONS = {
    "stages[0].mesh.stiffness.youngs_modulus": (
        "lognormal(206e9, 1.2)", "stage I mesh stiffness factor (k of the energy method is proportional to E): "
        "the energy method lies within 10 % of ISO 6336-1 c_gamma, whose own spread against measured stiffness "
        "is some 20 %"),
    "stages[1].mesh.stiffness.youngs_modulus": ("lognormal(206e9, 1.2)", "stage II mesh stiffness factor, as stage I"),
    "stages[0].mesh.damping.ratio": ("uniform(0.03, 0.17)", "the paper's own range of mesh damping ratios "
                                                            "(sec. 3.3: 0.03-0.17, 0.07 used)"),
    "stages[1].mesh.damping.ratio": ("uniform(0.03, 0.17)", "as stage I"),
    "stages[1].mesh.ste[0].amplitude_um": (
        "lognormal(1.0, 2.0)", "stage II transmission error: 0.3-3 um (90 %) for ground gears of ISO 1328 grade "
        "5-7 at module 8"),
    "stages[0].planet.bearing.radial_stiffness": (
        "lognormal(2e9, 1.6)", "planet bearings: cylindrical roller bearings of this size, 1e9-5e9 N/m "
        "(90 % within x/2.2 of the preset's value)"),
    "stages[1].planet.bearing.radial_stiffness": ("lognormal(3e9, 1.6)", "as stage I"),
    "stages[0].sun.support.radial_stiffness": (
        "lognormal(5e7, 2.0)", "floating sun I: held radially by the motor shaft's bending and the meshes only, "
        "1e7-2e8 N/m"),
    "stages[1].sun.support.radial_stiffness": ("lognormal(1e8, 2.0)", "sun II centred by the spline, as sun I"),
    "stages[0].carrier.support.radial_stiffness": (
        "lognormal(1e8, 2.0)", "carrier I floats on the spline to sun II: 3e7-3e8 N/m"),
    "stages[1].carrier.support.radial_stiffness": (
        "lognormal(5e9, 1.6)", "carrier II in the hub's large roller bearings to the housing (the housing sensor): "
        "2e9-1e10 N/m"),
    "stages[0].ring.support.radial_stiffness": (
        "lognormal(1e10, 2.0)", "ring I bolted to the housing (its sensor): the housing wall's flexibility, "
        "3e9-3e10 N/m"),
    "stages[0].ring.support.torsional_stiffness": (
        "lognormal(5.29e8, 2.0)", "ring I held torsionally by bolts or splines at its pitch radius, as its radial "
        "support"),
    "couplings[0].torsional_stiffness": (
        "lognormal(2.45e6, 2.0)", "spline carrier I - sun II: spline stiffness models differ by a factor 2-3"),
    "operating.input_shaft_stiffness": (
        "lognormal(6.441e5, 1.5)", "motor shaft G J / L with d and L assumed (d 80-100 mm: x/1.6 in J)"),
}


FIT_OK = 0.10  # a sample "reaches" 606 rpm when both sensors are within 10 %, the measurements' stated uncertainty


def g(x):
    return np.asarray(x, dtype=float) / G


def run(args) -> pd.DataFrame:
    text, source = gearcheck.preset_text("hub-drive"), "preset:hub-drive"
    entries = list(gearcheck.load_text(text, source).measurements)
    laws = {path: law for path, (law, _) in DISTRIBUTIONS.items()}
    args.cache.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    frames = []
    common = dict(text=text, source=source, entries=entries, distributions=laws, fits=FITS, fit_speed=FIT_RPM,
                  predict_speed=PREDICT_RPM, duration=args.duration, seed=args.seed, workers=args.workers)

    def progress(done, total, row):
        print(f"  {done}/{total} sample {row['sample']} {time.perf_counter() - started:.0f} s "
              f"{row.get('error') or ''}", file=sys.stderr, flush=True)

    nominal = args.cache / "nominal.pkl"
    if not nominal.exists():
        print("nominal (the plain calibration)", file=sys.stderr)
        frame = uncertainty_study(**{**common, "workers": 1}, samples=0, nominal=True, progress=progress)
        frame[frame["sample"] == NOMINAL].to_pickle(nominal)
    frames.append(pd.read_pickle(nominal))
    for first in range(0, args.samples, args.chunk):
        path = args.cache / f"seed{args.seed}-{first:05d}-{args.chunk}.pkl"
        if not path.exists():
            if time.perf_counter() - started > 60 * args.minutes:
                print(f"stopped after {args.minutes} minutes: {first} samples", file=sys.stderr)
                break
            print(f"samples {first}..{first + args.chunk - 1}", file=sys.stderr)
            frame = uncertainty_study(**common, samples=args.chunk, first=first, progress=progress)
            frame.to_pickle(path)
        frames.append(pd.read_pickle(path))
    frame = pd.concat(frames, ignore_index=True)
    print(f"{len(frame) - 1} samples, {time.perf_counter() - started:.0f} s this run", file=sys.stderr)
    return frame


def _fmt(x, digits=3):
    return f"{x:.{digits}g}"


def summarise(frame: pd.DataFrame) -> dict:
    ok = frame[(frame["sample"] != NOMINAL) & (frame["error"] == "")]
    nominal = frame[frame["sample"] == NOMINAL].iloc[0]
    out = {"samples": int((frame["sample"] != NOMINAL).sum()), "failed": int(((frame["sample"] != NOMINAL)
                                                                               & (frame["error"] != "")).sum()),
           "seed": int(ok["seed"].iloc[0]), "distributions": {p: {"law": law, "why": why}
                                                             for p, (law, why) in DISTRIBUTIONS.items()},
           "fits": FITS, "fit_rpm": FIT_RPM, "predict_rpm": PREDICT_RPM, "outputs": {}}
    fit_ok = (ok["fit_error:" + RING].abs() < FIT_OK) & (ok["fit_error:" + CARRIER].abs() < FIT_OK)
    for q in (RING, CARRIER):
        pred = g(ok["predicted:" + q])
        b5 = band(pred, (5, 10, 50, 90, 95))
        sub = g(ok.loc[fit_ok, "predicted:" + q])
        out["outputs"][q] = {
            "test_g": TEST[q], "paper_model_g": PAPER[q], "nominal_g": float(g(nominal["predicted:" + q])),
            "band_g": {f"p{int(r.level)}": {"value": float(r.value), "standard_error": float(r.standard_error)}
                       for r in b5.itertuples()},
            "test_percentile": float(100 * np.mean(pred <= TEST[q])),
            "paper_percentile": float(100 * np.mean(pred <= PAPER[q])),
            "fitted_at_606_within_10pct": {"n": int(fit_ok.sum()), **({} if fit_ok.sum() < 2 else {
                f"p{int(r.level)}": float(r.value) for r in band(sub, (5, 50, 95)).itertuples()})},
            "fit_error_606": {f"p{lv}": float(v) for lv, v in zip((5, 50, 95), np.percentile(
                ok["fit_error:" + q], (5, 50, 95)))},
        }
    table = drivers(ok, ["predicted:" + RING, "predicted:" + CARRIER, "fit_cost"])
    out["drivers"] = table.to_dict(orient="records")
    fitted = [c for c in ok.columns if c.startswith("fitted:")]
    out["fitted_vs_predicted_spearman"] = {
        f"{c.removeprefix('fitted:')} -> {q}": float(ok[c].rank().corr(ok["predicted:" + q].rank()))
        for c in fitted for q in (RING, CARRIER)}
    out["fit_quality"] = {
        "within_10pct_both": int(fit_ok.sum()), "fit_cost_median": float(ok["fit_cost"].median()),
        "at_bound": {str(k): int(v) for k, v in ok["at_bound"].fillna("").value_counts().items()},
        "fitted": {c.removeprefix("fitted:"): {f"p{lv}": float(v) for lv, v in zip(
            (5, 50, 95), np.percentile(ok[c], (5, 50, 95)))} for c in ok.columns if c.startswith("fitted:")},
    }
    return out


def _plain(axis):
    """Log-axis tick labels as plain numbers (0.2, not 2 x 10^-1)."""
    from matplotlib.ticker import FuncFormatter

    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}" if f"{v:.1e}"[0] in "235" else ""))


def band_figure(frame: pd.DataFrame) -> Figure:
    ok = frame[(frame["sample"] != NOMINAL) & (frame["error"] == "")]
    nominal = frame[frame["sample"] == NOMINAL].iloc[0]
    fit_ok = (ok["fit_error:" + RING].abs() < FIT_OK) & (ok["fit_error:" + CARRIER].abs() < FIT_OK)
    fig = Figure(figsize=(12, 9), layout="constrained")
    axes = fig.subplots(2, 2)
    for ax, q, name in ((axes[0, 0], RING, "ring I"), (axes[0, 1], CARRIER, "carrier II")):
        pred = g(ok["predicted:" + q])
        lo, hi = min(pred.min(), TEST[q], PAPER[q]) / 1.3, max(pred.max(), TEST[q], PAPER[q]) * 1.3
        bins = np.geomspace(lo, hi, 31)
        ax.hist([pred[~fit_ok.to_numpy()], pred[fit_ok.to_numpy()]], bins=bins, stacked=True,
                color=["0.7", "tab:blue"], label=["samples whose fit misses 606 rpm by > 10 %",
                                                  "samples whose fit reaches 606 rpm within 10 %"])
        p5, p50, p95 = np.percentile(pred, (5, 50, 95))
        ax.axvspan(p5, p95, color="tab:blue", alpha=0.08, label=f"5-95 %: {_fmt(p5)}-{_fmt(p95)} g")
        ax.axvline(p50, color="tab:blue", lw=1.5, label=f"median {_fmt(p50)} g")
        ax.axvline(TEST[q], color="k", lw=2, label=f"test {TEST[q]} g")
        ax.axvline(PAPER[q], color="tab:red", lw=1.5, ls="--", label=f"paper's model {PAPER[q]} g")
        ax.axvline(g(nominal["predicted:" + q]), color="tab:green", lw=1.5, ls=":",
                   label=f"preset's values, fitted: {_fmt(g(nominal['predicted:' + q]))} g")
        ax.set_xscale("log")
        _plain(ax.xaxis)
        ax.set_ylim(0, ax.get_ylim()[1] * 2.6)
        ax.set_xlabel(f"{name}: peak y acceleration at {PREDICT_RPM:g} rpm [g]")
        ax.set_ylabel("samples")
        ax.set_title(f"{name}, {PREDICT_RPM:g} rpm ({len(ok)} samples)", fontsize=10)
        ax.legend(fontsize=6.5, loc="upper left")
    ax = axes[1, 0]
    sc = ax.scatter(100 * ok["fit_error:" + RING], 100 * ok["fit_error:" + CARRIER], c=np.log10(g(
        ok["predicted:" + RING])), cmap="viridis", s=22)
    ax.scatter([100 * nominal["fit_error:" + RING]], [100 * nominal["fit_error:" + CARRIER]], marker="*", s=160,
               color="tab:green", label="preset's values (docs/hub-drive-calibration)")
    ax.scatter([-14.63], [9.09], marker="x", s=60, color="tab:red", label="paper's model at 606 rpm")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel(f"ring I fit error at {FIT_RPM:g} rpm [%]")
    ax.set_ylabel(f"carrier II fit error at {FIT_RPM:g} rpm [%]")
    ax.set_title("how well each sample's calibration reaches 606 rpm", fontsize=10)
    fig.colorbar(sc, ax=ax, label="log10 ring I at 1823 rpm [g]", fraction=0.05, pad=0.01)
    ax.legend(fontsize=7, loc="best")
    ax = axes[1, 1]
    ax.scatter(g(ok["predicted:" + RING]), g(ok["predicted:" + CARRIER]), c=np.where(fit_ok, "tab:blue", "0.6"),
               s=18, label="samples (blue: fit within 10 % at 606 rpm)")
    ax.scatter([TEST[RING]], [TEST[CARRIER]], marker="s", s=70, color="k", label="test")
    ax.scatter([PAPER[RING]], [PAPER[CARRIER]], marker="x", s=70, color="tab:red", label="paper's model")
    ax.scatter([g(nominal["predicted:" + RING])], [g(nominal["predicted:" + CARRIER])], marker="*", s=160,
               color="tab:green", label="preset's values, fitted")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain(ax.xaxis)
    _plain(ax.yaxis)
    ax.set_xlabel(f"ring I at {PREDICT_RPM:g} rpm [g]")
    ax.set_ylabel(f"carrier II at {PREDICT_RPM:g} rpm [g]")
    ax.set_title("joint prediction at 1823 rpm", fontsize=10)
    ax.legend(fontsize=7, loc="best")
    fig.suptitle("hub-drive (Li et al. 2026, Table 1): Monte Carlo of calibrate-at-606-then-predict-1823 over the "
                 "unpublished parameters' plausible ranges", fontsize=10)
    return fig


def drivers_figure(frame: pd.DataFrame) -> Figure:
    ok = frame[(frame["sample"] != NOMINAL) & (frame["error"] == "")]
    outputs = [("predicted:" + RING, "ring I at 1823 rpm"), ("predicted:" + CARRIER, "carrier II at 1823 rpm"),
               ("fit_cost", "fit cost at 606 rpm")]
    table = drivers(ok, [o for o, _ in outputs])
    order = (table.assign(a=table["spearman"].abs()).groupby("parameter")["a"].max().sort_values().index.tolist())
    fitted = [c for c in ok.columns if c.startswith("fitted:")]
    table = pd.concat([table, drivers(ok, [o for o, _ in outputs], fitted).assign(srrc=np.nan)])
    order += [c.removeprefix("sampled:") for c in fitted]
    fig = Figure(figsize=(12, 7), layout="constrained")
    axes = fig.subplots(1, 3, sharey=True)
    noise = 2 / math.sqrt(len(ok))
    for ax, (out, name) in zip(axes, outputs):
        t = table[table["output"] == out].set_index("parameter").reindex(order)
        y = np.arange(len(order))
        ax.axhspan(len(order) - len(fitted) - 0.5, len(order) - 0.5, color="gold", alpha=0.15)
        ax.barh(y + 0.18, t["spearman"], height=0.36, color=np.where(t["spearman"] > 0, "tab:red", "tab:blue"),
                label="Spearman rho")
        ax.barh(y - 0.18, t["srrc"], height=0.36, color="0.6", label="rank-regression coefficient")
        ax.axvspan(-noise, noise, color="k", alpha=0.07, label=f"|rho| < 2/sqrt(n) = {noise:.2f}: noise")
        ax.axvline(0, color="k", lw=0.6)
        ax.set_xlim(-1, 1)
        r2 = table[(table["output"] == out) & table["parameter"].str.startswith("stages[0].mesh.damping")]
        ax.set_title(f"{name}\ndrawn numbers: rank R^2 {r2['r2'].iloc[0]:.2f} (adjusted "
                     f"{r2['r2_adjusted'].iloc[0]:.2f})", fontsize=9)
        ax.set_xlabel("rank correlation with the drawn number")
    axes[0].set_yticks(np.arange(len(order)), [p.replace("fitted:", "FITTED at 606 rpm: ").replace(
        "stages[0]", "I").replace("stages[1]", "II") for p in order], fontsize=8)
    axes[0].legend(fontsize=7.5, loc="lower left")
    fig.suptitle(f"What drives the spread: {len(ok)} samples, each calibrated at 606 rpm (shaded rows: the fit's "
                 "results, Spearman only; the others: drawn numbers)", fontsize=10)
    return fig


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=60)
    parser.add_argument("--chunk", type=int, default=10)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--duration", type=float, default=0.45)
    parser.add_argument("--minutes", type=float, default=math.inf, help="start no new chunk after this long")
    parser.add_argument("--out", type=Path, default=Path("docs/hub-drive-uncertainty"))
    parser.add_argument("--cache", type=Path, default=Path("out/hub-drive-uncertainty-cache"))
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    csv = args.out / "samples.csv"
    if args.report_only:
        frame = pd.read_csv(csv, dtype={"error": str, "at_bound": str})
        frame[["error", "at_bound"]] = frame[["error", "at_bound"]].fillna("")
    else:
        frame = run(args)
        frame.to_csv(csv, index=False, float_format="%.10g")
    summary = summarise(frame)
    (args.out / "summary.json").write_text(json.dumps(summary, indent=1, sort_keys=True) + "\n")
    for name, draw in (("band.png", band_figure), ("drivers.png", drivers_figure)):
        draw(frame).savefig(args.out / name, dpi=110, metadata={"Software": None})
    for q in (RING, CARRIER):
        o = summary["outputs"][q]
        b = o["band_g"]
        print(f"{q}: median {b['p50']['value']:.3g} g, 5-95 % {b['p5']['value']:.3g}-{b['p95']['value']:.3g} g, "
              f"test {o['test_g']} g at percentile {o['test_percentile']:.0f}, paper {o['paper_model_g']} g, "
              f"preset fitted {o['nominal_g']:.3g} g")


if __name__ == "__main__":
    main()
