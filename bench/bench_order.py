"""Convergence order of both solvers on every preset, at its own operating point.

Each solver runs the preset from its own static start over ``STEPS`` steps at h, h/2, h/4 and h/8 (h twice the
lumped solver's default step where both solvers take it stably, else less; the same for both sides), sampled on
one grid (every h), and :func:`gearcheck.compare.studies.convergence.observed_orders` gives the order of each
pair of halvings, p = log2(d(h) / d(h/2)), printed for (h, h/2, h/4) and (h/2, h/4, h/8) next to d(h/2), the
relative difference at the finer steps ("-": round-off).

    python bench/bench_order.py [PRESET ...] [--steps N] [--coarsest H_OVER_DEFAULT]
"""

from __future__ import annotations

import argparse
import math
import time

from gearcheck.compare.studies.convergence import KINDS, coarsest_step, halvings, observed_orders
from gearcheck.lumped import time_solver
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train, preset_names

STEPS = 400


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("presets", nargs="*", default=preset_names())
    parser.add_argument("--steps", type=int, default=STEPS)
    parser.add_argument("--coarsest", type=float, default=2.0, help="h in default steps (default 2)")
    args = parser.parse_args()
    print(f"{'preset':18} {'solver':7} {'h/h0':>5} " + " ".join(f"{k:>26}" for k in KINDS) + "   wall")
    print(f"{'':32}" + " ".join(f"{'p(h)  p(h/2)  d(h/2)':>26}" for _ in KINDS))
    for name in args.presets:
        spec = load_train(name)
        h = coarsest_step(spec, args.coarsest)
        h0 = time_solver.default_step(build_model(spec))
        for solver in ("lumped", "mujoco"):
            started = time.perf_counter()
            table = observed_orders(halvings(spec, solver, h, args.steps, 4))
            cells = " ".join(f"{fmt(p[0]):>6} {fmt(p[1]):>6} {d[1]:9.2e}  " for p, d in table.values())
            wall = time.perf_counter() - started
            print(f"{name:18} {solver:7} {h / h0:5.2f} {cells} {wall:6.1f}s", flush=True)


def fmt(p: float) -> str:
    return "-" if math.isnan(p) else f"{p:.2f}"


if __name__ == "__main__":
    main()
