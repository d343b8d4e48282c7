"""What ``gearcheck runup`` writes: the order curves as a table, a summary, an order plot per quantity and a waterfall.

``orders.csv`` (one row per solver, quantity, order and block), ``runup.json`` (settings, each solver's cost, the
two solvers' agreement and, with a stepped sweep, the run-up's difference from it away from resonances),
``order_QUANTITY.png`` (both solvers' curves, the sweep's amplitudes as markers) and ``waterfall.png`` (the first
quantity's time-frequency map with the mesh orders and the natural frequencies drawn over it: a Campbell diagram
seen in the response).
"""

from __future__ import annotations

import json
from pathlib import Path

from gearcheck.compare.presentation.order_plots import order_plot, waterfall_plot
from gearcheck.compare.studies.runup import RunUp, against_sweep_table, contact_kept, sweep_line

RESONANCE_BAND = 0.05  # the sweep comparison leaves out this fraction of the top speed about each resonance speed


def write_runup(run: RunUp, out: Path, natural_hz, sweep=None) -> list[str]:
    """Write the run-up's files into the existing folder ``out``; ``natural_hz`` the train's natural frequencies
    (drawn on the waterfall, and where the sweep comparison stays away from), ``sweep`` a stepped sweep's table;
    returns the files' names."""
    written = []
    run.table().to_csv(out / "orders.csv", index=False, float_format="%.9g")
    written.append("orders.csv")
    summary = {"train": run.train, "start_rpm": run.start_rpm, "stop_rpm": run.stop_rpm, "duration_s": run.duration,
               "rate_rpm_per_s": run.rate_rpm_s, "orders": [{"mesh": m, "harmonic": k, "order": o}
                                                           for m, k, o in run.orders],
               "output_dt_s": run.output_dt, "switching_stiffness": run.switching,
               "wall_s": run.wall_s, "cpu_s": run.cpu_s, "solvers_agree": run.agreement(),
               "solvers_part_rpm": run.parting()}
    steady: dict[str, dict] = {}
    if sweep is not None:
        band = RESONANCE_BAND * run.stop_rpm
        compared = against_sweep_table(run, sweep, natural_hz, band)
        kept = contact_kept(sweep, run.backlash)
        summary["against_sweep"] = {"band_rpm": band, "natural_hz": [float(f) for f in natural_hz],
                                    "speeds_in_contact": int(kept.sum()), "speeds": int(kept.size),
                                    "orders": compared.to_dict(orient="records")}
        for quantity in {q for _, q in run.tracks}:
            lines = {order: sweep_line(sweep, "lumped", quantity, label, k) for label, k, order in run.orders}
            steady[quantity] = {order: line for order, line in lines.items() if line[0].size}
    for quantity in sorted({q for _, q in run.tracks}):
        tracks = {solver: track for (solver, q), track in run.tracks.items() if q == quantity}
        name = f"order_{quantity}.png"
        (out / name).write_bytes(order_plot(
            tracks, steady.get(quantity), run.units[quantity],
            f"{run.train}: {quantity}, run-up {run.start_rpm:g}-{run.stop_rpm:g} rpm in {run.duration:g} s; "
            "orders of the input: mesh harmonics"))
        written.append(name)
    if run.waterfalls:
        solver, cut = next(iter(run.waterfalls.items()))
        first = next(q for s, q in run.tracks if s == solver)
        shown = [f for f in natural_hz if 0 < f < cut.frequency_hz[-1]]
        (out / "waterfall.png").write_bytes(waterfall_plot(
            cut, [o for *_, o in run.orders], shown, run.units[first],
            f"{run.train} ({solver}): {first} over the run-up; dashed: mesh orders, dotted: natural frequencies"))
        written.append("waterfall.png")
    (out / "runup.json").write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
    return written + ["runup.json"]
