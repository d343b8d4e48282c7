"""Dynamic effect of the planets' tip relief on the helical-planetary preset (Mo et al. 2024), both solvers.

    python examples/helical_relief_sweep.py docs/helical-planetary/dynamic

For each relief amount, both solvers run the train at 3000 rpm. The steady part of a 0.07 s run (from
0.04 s) gives, for planet 1's sun and ring meshes, the dynamic mesh force, the dynamic transmission error (DTE)
and the dynamic load factor Kv (mean, max, range). The results go to relief_sweep.json,
relief_sweep.png and relief_sweep.md, beside the paper's Tables 2-4 (before relief and after 15 um).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import gearcheck

AMOUNTS_UM = (0.0, 2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 30.0)
DURATION = 0.07
STEADY_FROM = 0.04  # s: after the start's free vibration (the cross-check detects the steady state by 0.04 s)
MESHES = {"sun": "stage1.planet1.sun", "ring": "stage1.planet1.ring"}
# Mo et al. (2024), Tables 2-4: (before, after 15 um) of mean, max, range
PAPER = {
    ("sun", "force"): ((2332, 3038, 1550), (2091, 2657, 1241)),
    ("ring", "force"): ((2488, 3064, 1163), (2083, 2631, 1029)),
    ("sun", "dte"): ((15.64, 20.43, 9.86), (14.0, 17.05, 7.03)),
    ("ring", "dte"): ((10.5, 13.75, 5.68), (8.79, 11.05, 3.94)),
    ("sun", "kv"): ((0.7123, 0.9279, 0.4735), (0.6386, 0.8116, 0.3792)),
    ("ring", "kv"): ((0.7599, 0.9359, 0.3552), (0.6364, 0.8037, 0.3144)),
}
SCALE = {"force": 1.0, "dte": 1e6, "kv": 1.0}  # N, um, -


def statistics(run, mesh: str) -> dict:
    window = run.t >= STEADY_FROM
    out = {}
    for what in ("force", "dte", "kv"):
        x = run[f"{mesh}.{what}"][window] * SCALE[what]
        out[what] = (float(x.mean()), float(x.max()), float(np.ptp(x)))
    return out


def main(out: Path) -> None:
    results = {}
    for amount in AMOUNTS_UM:
        train = gearcheck.Train(gearcheck.edited("helical-planetary", [(r"amount_um = 0.0", f"amount_um = {amount!r}")],
                                                 f"{amount} um"))
        runs = {solver: train.simulate(solver, duration=DURATION) for solver in ("lumped", "mujoco")}
        results[amount] = {solver: {name: statistics(run, mesh) for name, mesh in MESHES.items()}
                           for solver, run in runs.items()}
        print(f"{amount:5.1f} um (lumped; MuJoCo's figures in the files): " + "  ".join(
            f"{name} F range {results[amount]['lumped'][name]['force'][2]:.2f} N, DTE range "
            f"{results[amount]['lumped'][name]['dte'][2]:.4f} um" for name in MESHES), flush=True)
    out.mkdir(parents=True, exist_ok=True)
    (out / "relief_sweep.json").write_text(json.dumps({str(a): r for a, r in results.items()}, indent=2) + "\n")
    fig = Figure(figsize=(10, 7))
    axes = fig.subplots(3, 1, sharex=True)
    labels = {"force": "mesh force range [N]", "dte": "DTE range [um]", "kv": "Kv max"}
    for ax, what in zip(axes, ("force", "dte", "kv")):
        for j, name in enumerate(MESHES):
            index = 1 if what == "kv" else 2
            ax.plot(AMOUNTS_UM, [results[a]["lumped"][name][what][index] for a in AMOUNTS_UM], color=f"C{j}",
                    label=f"{name} mesh, lumped")
            ax.plot(AMOUNTS_UM, [results[a]["mujoco"][name][what][index] for a in AMOUNTS_UM], color=f"C{j}",
                    ls="none", marker="o", mfc="none", label=f"{name} mesh, MuJoCo")
        ax.set_ylabel(labels[what])
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[-1].set_xlabel("tip relief on the planets' tips C_a [um] (linear, 1.55 mm)")
    fig.suptitle("helical-planetary at 3000 rpm, 18 N·m: dynamic response against the tip relief", fontsize=9)
    fig.savefig(out / "relief_sweep.png", dpi=110, metadata={"Software": None})
    lines = ["# helical-planetary at 3000 rpm, 18 N·m: Mo et al. (2024)'s tip relief results beside gearcheck's", "",
             "| mesh | quantity | paper before | paper after 15 um | paper change | gearcheck before | "
             "gearcheck after 15 um | gearcheck change |", "|---|---|---|---|---|---|---|---|"]
    for (name, what), (before, after) in PAPER.items():
        ours_before, ours_after = results[0.0]["lumped"][name][what], results[15.0]["lumped"][name][what]
        for i, stat in enumerate(("mean", "max", "range")):
            change = (after[i] - before[i]) / before[i]
            ours = (ours_after[i] - ours_before[i]) / ours_before[i]
            lines.append(f"| {name} | {what} {stat} | {before[i]:.4g} | {after[i]:.4g} | {change:+.1%} | "
                         f"{ours_before[i]:.4g} | {ours_after[i]:.4g} | {ours:+.1%} |")
    (out / "relief_sweep.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "out/relief_sweep"))
