"""A run-up against the stepped sweep of the same train, measured side by side: cost, order curves, sweep rate.

    python bench/runup_vs_sweep.py [--points 181] [--durations 1 2 4] [--out out/runup-bench]

Runs the hub drive's stepped sweep from 200 to 2000 rpm (``--points`` speeds, 0.5 s each, the lumped model, one
process, no integration check: the cheapest sweep) and run-ups over the same range in each of ``--durations`` (the
lumped model, one process), timing each (wall seconds, each in one process).  Then, per tracked quantity and mesh
order, the run-up's order curve against the sweep's harmonic amplitudes where the comparison means something:

* the order is significant (its sweep amplitude above 5 % of its largest) and the speed is farther than 5 % of the
  top speed from every resonance of that order (its frequency at a natural frequency at rest);
* the teeth stay in contact at that speed in the sweep's steady state (every force of a mesh with a backlash has
  its mean above half its peak-to-peak): where they separate (the backlash), the response depends on its history,
  and a run-up follows its own branch where each stepped point lands on the one its cold start finds.

It prints the median and 90th percentile of the relative differences there, the share of the range where the teeth
separate, and the main resonance's peak (speed and amplitude) in the sweep and in each run-up: the sweep-rate
effect.  Writes each run-up's files (``gearcheck runup``) into ``--out``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import gearcheck
from gearcheck.compare.presentation.runup_report import RESONANCE_BAND, write_runup
from gearcheck.compare.studies.order_curves import peak
from gearcheck.compare.studies.runup import contact_kept, run_up, sweep_differences, sweep_line

TRAIN, START, STOP = "hub-drive", 200.0, 2000.0
QUANTITIES = ("I.planet1.sun.force", "I.carrier.ay.world", "I.ring.ay.world")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=181)
    parser.add_argument("--durations", type=float, nargs="+", default=[1.0, 2.0, 4.0, 8.0])
    parser.add_argument("--out", type=Path, default=Path("out/runup-bench"))
    args = parser.parse_args()
    spec = gearcheck.load(TRAIN)
    natural = gearcheck.modes(spec).frequencies
    started = time.perf_counter()
    sweep = gearcheck.sweep(TRAIN, speeds=np.linspace(START, STOP, args.points), solver="lumped",
                            integration_check=False, workers=1)
    sweep_wall = time.perf_counter() - started
    table = sweep.table.to_pandas()
    kept = contact_kept(table, [m.id for m in spec.meshes if m.backlash > 0])
    print(f"stepped sweep: {args.points} points x 0.5 s, lumped, one worker: {sweep_wall:.1f} s wall (its points "
          f"{sum(sweep.point_wall_s):.1f} s); the teeth separate, or no steady state, at {int((~kept).sum())} of "
          f"{kept.size} speeds")
    main_order = QUANTITIES[0]
    speeds, amps = sweep_line(table, "lumped", main_order, "I", 1)
    top = peak(speeds, amps, (500.0, 1000.0))
    print(f"main resonance ({main_order}, I x1) in the sweep: {top.amplitude:.4g} N at {top.speed_rpm:.5g} rpm")
    print("| run-up | rate (rpm/s) | wall (s) | sweep / run-up | compared | median diff. | 90th pct. | "
          "peak (N) at (rpm) |")
    print("|---|---|---|---|---|---|---|---|")
    for duration in args.durations:
        started = time.perf_counter()
        run = run_up(spec, START, STOP, duration, ("lumped",), QUANTITIES)
        used = time.perf_counter() - started
        diffs = np.concatenate([d for *_, d in sweep_differences(run, table, natural, RESONANCE_BAND * STOP)])
        curve = run.tracks[("lumped", main_order)].curve(next(o for m, k, o in run.orders if m == "I" and k == 1))
        p = peak(*curve, (500.0, 1000.0))
        print(f"| {duration:g} s | {run.rate_rpm_s:.4g} | {used:.1f} | {sweep_wall / used:.1f} | {len(diffs)} | "
              f"{np.median(diffs):.2%} | {np.percentile(diffs, 90):.2%} | {p.amplitude:.4g} at {p.speed_rpm:.5g} |")
        out = args.out / f"{duration:g}s"
        out.mkdir(parents=True, exist_ok=True)
        write_runup(run, out, natural, table)


if __name__ == "__main__":
    main()
