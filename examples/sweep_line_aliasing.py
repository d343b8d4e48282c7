"""Mesh harmonics of a signal that jumps: the plain windowed sum against the corrected projection.

demo-3p's rectangular mesh stiffness switches twice a mesh cycle, so the mesh forces and the bodies' accelerations
jump there.  The lumped solver runs the train at 1500 rpm for 0.5 s at 2, 1, 1/2, 1/4 and 1/8 times its default
step h; the steady half of each run is projected on the first three mesh harmonics, once by the plain Hann-windowed
sum and once with each signal's jumps and changes of slope corrected where Newton's law puts them, as the sweep and
the cross-check read their lines (:func:`gearcheck.compare.engine.harmonics` at the plan's
:meth:`~gearcheck.compare.engine.plan.TrainPlan.singularities`).  The plain lines converge at first order in the
step (the jumps alias onto them: the step divides the mesh period), the corrected ones sit on their limit from the
default step on.  Writes line_aliasing.png and line_aliasing.json.

Run:  OPENBLAS_NUM_THREADS=1 python examples/sweep_line_aliasing.py --out docs/sweep
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import gearcheck
from gearcheck.compare.engine import TrainPlan, harmonics  # what this example shows at work

TRAIN, SPEED, DURATION = "demo-3p", 1500.0, 0.5
QUANTITIES = ("stage1.planet1.sun.force", "stage1.sun.alpha")
FACTORS = (2.0, 1.0, 0.5, 0.25, 0.125)  # of the default step


def lines(train, factor: float, frequencies: np.ndarray) -> dict:
    """{quantity: (plain, corrected) amplitudes at ``frequencies``} of the run at ``factor`` times the default step,
    over its second half."""
    default = train.simulate("lumped", 1e-3).info["dt_s"]
    run = train.simulate("lumped", DURATION, dt=factor * default)
    window = run.t >= 0.5 * DURATION
    t = run.t[window]
    switches, kinks = TrainPlan.of(train.spec, train.lumped, DURATION).singularities(QUANTITIES, t[0], t[-1])
    out = {}
    for j, q in enumerate(QUANTITIES):
        x = run[q][window]
        out[q] = (np.abs(harmonics(t, x, frequencies, np.inf)[:, 0]),
                  np.abs(harmonics(t, x, frequencies, np.inf, switches[j], kinks[j])[:, 0]))
    return out


def figure(steps_per_cycle, data, units) -> Figure:
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    for ax, q in zip(fig.subplots(1, len(QUANTITIES)), QUANTITIES):
        for k in range(3):
            colour = f"C{k}"
            ax.plot(steps_per_cycle, [d[q][0][k] for d in data], "--o", color=colour, ms=4, mfc="none",
                    label=f"{k + 1}× mesh, plain sum")
            ax.plot(steps_per_cycle, [d[q][1][k] for d in data], "-o", color=colour, ms=4,
                    label=f"{k + 1}× mesh, corrected")
        ax.axvline(steps_per_cycle[1], color="0.6", lw=0.8)
        ax.text(steps_per_cycle[1], 0.98, " default step", transform=ax.get_xaxis_transform(), va="top", fontsize=8,
                color="0.4")
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel("steps per mesh cycle")
        ax.set_ylabel(f"amplitude ({units[q]})")
        ax.set_title(q, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
    fig.axes[0].legend(fontsize=7, loc="best")
    fig.suptitle(f"{TRAIN} at {SPEED:g} rpm (lumped, {DURATION:g} s, steady half): mesh harmonics against the step",
                 fontsize=10)
    return fig


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/line-aliasing"))
    args = parser.parse_args(argv)
    train = gearcheck.Train(TRAIN, SPEED)
    f_mesh = float(np.max(train.lumped.model.excitation.frequency))
    frequencies = f_mesh * np.arange(1, 4)
    data = [lines(train, factor, frequencies) for factor in FACTORS]
    probe = train.simulate("lumped", 1e-3)
    default = probe.info["dt_s"]
    steps_per_cycle = [1.0 / (f_mesh * factor * default) for factor in FACTORS]
    units = {q: probe.signal(q).unit for q in QUANTITIES}
    args.out.mkdir(parents=True, exist_ok=True)
    figure(steps_per_cycle, data, units).savefig(args.out / "line_aliasing.png", dpi=110, metadata={"Software": None})
    summary = {"train": TRAIN, "speed_rpm": SPEED, "duration_s": DURATION, "mesh_frequency_hz": f_mesh,
               "steps_per_mesh_cycle": steps_per_cycle,
               "amplitudes": {q: {"plain": [d[q][0].tolist() for d in data],
                                  "corrected": [d[q][1].tolist() for d in data], "unit": units[q]}
                              for q in QUANTITIES}}
    (args.out / "line_aliasing.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    for q in QUANTITIES:
        print(q)
        for spc, d in zip(steps_per_cycle, data):
            print(f"  {spc:8.1f} steps/cycle  plain {np.array2string(d[q][0], precision=4)}  "
                  f"corrected {np.array2string(d[q][1], precision=4)} {units[q]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
