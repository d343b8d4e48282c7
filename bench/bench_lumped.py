"""Benchmark of the lumped reference solver (not a test): how its cost grows.

Prints wall time per simulated second and per step, at the default step, as the
simulated duration, the number of planets and the number of stages grow, and with tip relief, with
the ratios to the first row measured in the same run.

Run:  python bench/bench_lumped.py
"""

from __future__ import annotations

import time

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.loader import load_train
from gearcheck.lumped.modal import modes
from gearcheck.lumped.time_solver import simulate
from gearcheck.lumped.variants import chained, edited, wide_stage
from gearcheck.shared.settings import RunSettings


def timed_run(spec, duration):
    model = build_model(spec)
    started = time.perf_counter()
    result = simulate(model, RunSettings(duration))
    total = time.perf_counter() - started
    return model, result.info, total


def table(title, label, cases):
    print(f"\n{title}")
    print(f"{label:<12} {'DOF':>4} {'dt [s]':>10} {'steps':>8} {'solver [s]':>10} {'us/step':>8} "
          f"{'wall s/sim s':>12} {'ratio':>6} {'modes [ms]':>10}")
    first = None
    for name, spec, duration in cases:
        model, info, _ = timed_run(spec, duration)
        started = time.perf_counter()
        modes(model)
        modal = time.perf_counter() - started
        wall = info["wall_time_s"]
        first = first or wall
        print(f"{name:<12} {model.n:>4} {info['dt_s']:>10.4g} {info['steps']:>8} {wall:>10.3f} "
              f"{1e6 * wall / info['steps']:>8.2f} {wall / duration:>12.3f} {wall / first:>6.2f} {1e3 * modal:>10.2f}")


def main():
    demo = load_train("demo-3p")
    table("duration (demo-3p at 1500 rpm)", "duration",
          [(f"{d:g} s", demo, d) for d in (0.05, 0.1, 0.2, 0.4)])
    table("planets (z = 30/24/78, 0.1 s)", "planets", [(f"{n}", wide_stage(n), 0.1) for n in (3, 4, 6)])
    table("stages (demo-3p stage chained, 0.1 s)", "stages",
          [(f"{n}", load_train("demo-3p") if n == 1 else chained(n), 0.1) for n in (1, 2, 3)])
    helical = [(f"{a:g} um", edited("helical-planetary", [(r"amount_um = 0.0", f"amount_um = {a!r}")], "relief"), 0.02)
               for a in (0.0, 15.0)]
    table("tip relief (helical-planetary, 0.02 s: the relieved meshes' tooth pairs take the stage-by-stage path)",
          "relief", helical)


if __name__ == "__main__":
    main()
