"""The cross-check's integration error estimate against the error itself, on every preset, both solvers.

For each preset the cross-check runs once (its default settings, the shipped baseline's duration) to find the
quantities it gates, their steady window and its first steps; each solver then runs from its own static start (a
train the cross-check starts on periodic states, double-planet, is run from rest here) at that step h, at 2 h and
at h / 16 (:func:`gearcheck.compare.studies.convergence.estimate_tracking`).  Printed per
preset and solver: the step, the largest true error over the gated quantities and its estimate, and the ratio
estimate / error over the gated quantities whose error is above round-off (1e-9): its least, median and largest.
A ratio of 1 is an exact estimate; below 1 it underestimates.  ``--hub-speed`` adds the hub drive at another speed
(default its second test speed, 1823 rpm, where backlash opens and closes in every mesh cycle).

    python bench/bench_estimate.py [PRESET ...] [--hub-speed RPM]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import gearcheck
from gearcheck.compare.engine.baseline import baseline_path, read_baseline
from gearcheck.compare.studies.convergence import ROUND_OFF, estimate_tracking
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.train.loader import load_train, preset_names


def cases(presets, hub_speed):
    for name in presets:
        yield name, None
    if hub_speed:
        yield "hub-drive", hub_speed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("presets", nargs="*", default=preset_names())
    parser.add_argument("--hub-speed", type=float, default=1823.0, help="the hub drive's extra speed (0: none)")
    args = parser.parse_args()
    print(f"{'train':22} {'solver':7} {'h [s]':>9} {'worst error':>11} {'its estimate':>12}   "
          f"{'estimate / error: min':>21} {'median':>6} {'max':>5} {'n':>3}  wall")
    for name, speed in cases(args.presets, args.hub_speed):
        spec = load_train(name, speed)
        stored = read_baseline(baseline_path("shipped", name)) if speed is None else None
        duration = stored["duration_s"] if stored else 0.1
        result = gearcheck.crosscheck(spec, duration=duration)
        gated = [q.name for q in result.quantities if q.status != "negligible"]
        label = name if speed is None else f"{name} {speed:g} rpm"
        for side, key in ((LumpedSide(spec), "lumped"), (MujocoSide(spec), "mujoco")):
            started = time.perf_counter()
            h = result.settings[key]["dt_s"]
            table = estimate_tracking(side, h, result.settings["simulated_s"], result.steady_start_s, gated)
            rows = [(e, est) for est, e in table.values() if e > ROUND_OFF]
            ratio = np.array([est / e for e, est in rows])
            worst = max(rows) if rows else (float("nan"), float("nan"))
            print(f"{label:22} {key:7} {h:9.3g} {worst[0]:11.2e} {worst[1]:12.2e}   {ratio.min():21.2f} "
                  f"{np.median(ratio):6.2f} {ratio.max():5.2f} {ratio.size:3d}  {time.perf_counter() - started:.0f}s",
                  flush=True)


if __name__ == "__main__":
    main()
