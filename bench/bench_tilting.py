"""Benchmark of tilting members (not a test): what three dimensions cost per step against the planar+axial model.

Measured in this one run, side by side, on the helical stage of Mo et al. (2024): the shipped preset
helical-planetary (planar+axial, 4 coordinates a member) and examples/helical-tilting.toml (the same stage tilting,
6 a member), each solver at its own default step over the same simulated time, best of three:

1. us per step of each solver and the 3-D / planar+axial ratio (the lumped kernel's rows and the twin's joints,
   tendons and Jacobian-turned coefficients grow with the coordinates);
2. the default steps themselves (a tilting mode may be the stiffest, which shortens the step);
3. how the cost grows with planets (3, 4, 6 on demo-3p's stage, tilting and not).

Run:  python bench/bench_tilting.py [--quick]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import gearcheck
from gearcheck.shared.errors import TrainNote

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "helical-tilting.toml"
TILT = (r"^planets = (\d)", r"planets = \1\ntilting = true")
HELD = (r"^(support|bearing) = \{ (.*) \}$",
        r"\1 = { \2, axial_stiffness = 5.0e8, axial_damping = 500.0, tilting_stiffness = 2.0e5 }")
PLANETS = {3: [], 4: [(r"^planets = 3", "planets = 4"), (r"^teeth = 22", "teeth = 30"), (r"^teeth = 20", "teeth = 24"),
                      (r"^teeth = 62 .*$", "teeth = 78")],
           6: [(r"^planets = 3", "planets = 6"), (r"^teeth = 22", "teeth = 30"), (r"^teeth = 20", "teeth = 24"),
               (r"^teeth = 62 .*$", "teeth = 78")]}


def per_step(spec, solver: str, duration: float, repeats: int = 3) -> tuple[float, float]:
    """(best wall us per step, the step in s) of ``solver`` over ``duration`` at its default step."""
    train = gearcheck.Train(spec)
    train.simulate(solver, duration=min(duration, 2e-3))  # compiled kernels warm
    best, dt = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        run = train.simulate(solver, duration=duration)
        best = min(best, time.perf_counter() - start)
        dt = run.info["dt_s"]
    return 1e6 * best / (duration / dt), dt


def main(quick: bool) -> None:
    duration = 0.01 if quick else 0.04
    planar, tilting = gearcheck.load("helical-planetary"), gearcheck.load(EXAMPLE)
    print(f"1-2. helical stage of Mo et al. (2024), {duration:g} s at each solver's default step, best of 3")
    print(f"{'solver':<8} {'planar+axial us/step':>21} {'3-D us/step':>12} {'ratio':>6} {'steps (us)':>18}")
    for solver in ("lumped", "mujoco"):
        (a, dt_a), (b, dt_b) = per_step(planar, solver, duration), per_step(tilting, solver, duration)
        print(f"{solver:<8} {a:21.2f} {b:12.2f} {b / a:6.2f} {1e6 * dt_a:8.3f} {1e6 * dt_b:8.3f}")
    print("\n3. growth with planets (demo-3p's stage), us/step")
    print(f"{'planets':>7} {'lumped':>8} {'3-D':>8} {'MuJoCo':>8} {'3-D':>8}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TrainNote)
        for n, pairs in PLANETS.items():
            flat = gearcheck.edited("demo-3p", pairs, f"{n} planets")
            tilted = gearcheck.edited("demo-3p", [TILT, HELD, *pairs], f"{n} planets, tilting")
            row = [per_step(spec, solver, duration / 2, 1 if quick else 3)[0]
                   for solver in ("lumped", "mujoco") for spec in (flat, tilted)]
            print(f"{n:7d} " + " ".join(f"{x:8.2f}" for x in row))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    main(parser.parse_args().quick)
