"""The start-up of Matejic et al. (2021), Figs. 3-6: the double-planet reducer from rest under an initiation torque.

The paper drives its 4-DOF model (y1, theta_h, theta_f, theta_b; Eqs. 6-13) from rest by an "initiation torque"
on the carrier (Fig. 3) with no load on ring b, and plots the accelerations (Fig. 4), velocities (Fig. 5) and
displacements (Fig. 6) of the four coordinates.  The seed's text has the figures only as captions, so the torque
here is the representative curve shipped beside the preset (``double-planet-initiation-torque.csv``: a pulsating
torque about a mean rising from zero; replace it by a digitised curve to reproduce Fig. 3 itself).

Three models of the paper's coordinates run from rest under it (``gearcheck crosscheck double-planet --model ...
--torque-profile ... --load-profile 0:0``): the as-published matrices (Eqs. 10-12), the model derived from the
paper's own energies (Eqs. 3-5), and the MuJoCo twin of that idealisation, whose joints really turn.  And
gearcheck's general model of the same train against its twin under the same torque.  Prints each model's
difference from the twin, the start-up's speeds and the loads the turning carrier puts on y1, and writes
``startup.png`` (3 x 4 panels, as Figs. 4-6) and ``torque.png`` (as Fig. 3) into the folder given.

Run:  python examples/double_planet_startup.py docs/double-planet-startup    (about 3 minutes)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import gearcheck

TORQUE = "double-planet-initiation-torque.csv"
DURATION = 0.3  # s
COORDINATES = ("y1", "theta_h", "theta_f", "theta_b")
UNITS = {"y1": "m", "theta_h": "rad", "theta_f": "rad", "theta_b": "rad"}
ROWS = (("acceleration", ".acceleration", "/s²"), ("velocity", ".velocity", "/s"), ("displacement", "", ""))


def nrmse(a, b) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b**2)))


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    spec = gearcheck.load("double-planet", torque_profile=str(gearcheck.preset_data(TORQUE)), load_profile="0:0")
    runs = {}
    for model in ("as-published", "energy-derived"):
        result = gearcheck.crosscheck(spec, model=model, duration=DURATION)
        runs[model], runs[f"twin ({model})"] = result.results
        print(f"{model}: {result.verdict}")
    general = gearcheck.crosscheck(spec, duration=DURATION)
    print(f"general model against its twin: {general.verdict}, largest NRMSE of a gated quantity "
          f"{max(q.metrics['nrmse'] for q in general.quantities if q.status != 'negligible'):.2g}")
    twin = runs["twin (energy-derived)"]
    print("\ncoordinate        as-published  energy-derived   (NRMSE of the acceleration against the twin)")
    for c in COORDINATES:
        name = f"{c}.acceleration"
        print(f"{c:16s}  {nrmse(runs['as-published'][name], twin[name]):12.3g}  "
              f"{nrmse(runs['energy-derived'][name], twin[name]):14.3g}")
    p = gearcheck.load("double-planet").members["stage1.planet1"]
    w_h = twin["theta_h.velocity"]
    r_h = spec.stages[0].carrier_radius
    print(f"\nat {DURATION:g} s the carrier turns at {w_h[-1]:.4g} rad/s ({w_h[-1] * 60 / (2 * np.pi):.4g} rpm), "
          f"{twin['theta_h'][-1]:.3g} rad from its start; the planet set's centrifugal load m_p r_h w^2 is then "
          f"{p.mass * r_h * w_h[-1]**2:.4g} N per planet, which the paper's equations (no rotating-frame terms) do "
          "not have")
    figure = Figure(figsize=(13, 8), layout="constrained")
    axes = figure.subplots(3, 4, sharex=True)
    for row, (what, suffix, per) in enumerate(ROWS):
        for col, c in enumerate(COORDINATES):
            ax = axes[row, col]
            for label, style in (("as-published", ":"), ("energy-derived", "-"), ("twin (energy-derived)", "--")):
                run = runs[label]
                ax.plot(run.t, run[c + suffix], style, lw=0.9, label=label)
            ax.set_title(f"{c}: {what}", fontsize=9)
            ax.set_ylabel(f"{UNITS[c]}{per}", fontsize=8)
            ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("t (s)")
    axes[0, 0].legend(fontsize=7)
    figure.suptitle("double-planet start-up from rest under the initiation torque (as Matejic et al. 2021, "
                    "Figs. 4-6): as published, derived from the paper's energies, and the MuJoCo twin", fontsize=10)
    figure.savefig(out / "startup.png", dpi=110, metadata={"Software": None})
    t = np.linspace(0, DURATION, 2001)
    fig = Figure(figsize=(6, 3), layout="constrained")
    ax = fig.subplots()
    ax.plot(t, spec.operating.history.torque(t), lw=1.0)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("M_h (N·m)")
    ax.set_title("initiation torque on the carrier (representative; the paper's Fig. 3 is an image)", fontsize=9)
    ax.grid(alpha=0.3)
    fig.savefig(out / "torque.png", dpi=110, metadata={"Software": None})
    print(f"\nfigures in {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="folder for the figures")
    main(parser.parse_args().out)
