"""Convergence order of both solvers on every preset, at its own operating point.

Each solver runs the preset from its own static start over ``STEPS`` steps at h, h/2, h/4 and h/8 (h twice the
lumped solver's default step where both solvers take it stably, else the default step; the same for both sides),
sampled on one grid (every h).  For each kind of signal
(transmission error, mesh force, accelerations) the difference between successive halvings,

    d(h) = max |y_h - y_(h/2)| / max |y_(h/8)|,

falls as h^p for a method of order p, so p = log2(d(h) / d(h/2)) is printed for the pairs (h, h/2) and
(h/2, h/4) next to d(h/2), the error at the finer step.  A difference at round-off (below ``FLOOR``: the twin
of double-planet, whose planet accelerations are small differences of large mesh moments, reaches 1e-10) gives no
order ("-").

    python bench/bench_order.py [PRESET ...] [--steps N] [--coarsest H_OVER_DEFAULT]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from gearcheck.lumped import time_solver
from gearcheck.lumped.assembly import build_model
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import stable_step
from gearcheck.train.loader import load_train, preset_names

STEPS = 400
KINDS = ("dte", "mesh_force", "acceleration")
FLOOR = 1e-9


def runs(solver: str, spec, h: float, steps: int) -> list:
    """The solver's results at h, h/2, h/4, h/8, each sampled every h."""
    if solver == "lumped":
        model = build_model(spec)
        return [time_solver.simulate(model, RunSettings(duration=steps * h, dt=h / 2**i, output_dt=h))
                for i in range(4)]
    twin = compile_train(spec)
    return [simulate_mujoco(twin, RunSettings(duration=steps * h, dt=h / 2**i, output_dt=h)) for i in range(4)]


def orders(results) -> dict[str, tuple[float, float, float]]:
    """kind -> (order over h..h/4, order over h/2..h/8, relative difference at h/2)."""
    out = {}
    for kind in KINDS:
        y = [r.select(kind) for r in results]
        n = min(len(x) for x in y)
        scale = float(np.max(np.abs(y[-1][:n]))) or 1.0
        d = [float(np.max(np.abs(a[:n] - b[:n]))) / scale for a, b in zip(y, y[1:])]
        p = [math.log2(a / b) if min(a, b) > FLOOR else math.nan for a, b in zip(d, d[1:])]
        out[kind] = (p[0], p[1], d[1])
    return out


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
        model, twin = build_model(spec), compile_train(spec)
        h = min(args.coarsest * time_solver.default_step(model), time_solver.stable_step(model),
                stable_step(twin.limits))
        for solver in ("lumped", "mujoco"):
            started = time.perf_counter()
            table = orders(runs(solver, spec, h, args.steps))
            cells = " ".join(f"{fmt(a):>6} {fmt(b):>6} {c:9.2e}  " for a, b, c in table.values())
            wall = time.perf_counter() - started
            print(f"{name:18} {solver:7} {h / time_solver.default_step(model):5.2f} {cells} {wall:6.1f}s", flush=True)


def fmt(p: float) -> str:
    return "-" if math.isnan(p) else f"{p:.2f}"


if __name__ == "__main__":
    main()
