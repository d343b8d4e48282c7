"""Benchmark of the batched MuJoCo runner (MJX, float64; not a test): sweep points as worlds, on whatever device
JAX has (a GPU where there is one), against the CPU runner on this machine's cores, side by side in one run.

1. Agreement: ``simulate_mujoco_batch`` against ``simulate_mujoco`` on two speeds (every signal's largest
   difference over its largest value; the same located contact events and forward evaluations).
2. Cost: for each world count (``--worlds``, speeds spread over ``--speeds``), two runs of ``--duration`` s, the
   first of which compiles the program for the shapes of its chunks (its excess over the second: the compile);
   the time per world-step and per world, split into the host's start (static states), drive and results and
   the device's steps, against the CPU runner's time per point for the same duration (one core, the compiled
   loop) at the first, middle and last speed (``--no-cpu``: not run).  A 181-speed sweep's MuJoCo runs (0.5 s
   each, hub-drive) are then priced both ways from these rates, as the cost grows linearly with the steps.

Run:  python bench/bench_batched.py [--train hub-drive] [--worlds 1,32,181] [--duration 0.01] [--check 0.002]
      [--no-cpu] [--json PATH]
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from gearcheck.mbd_models import batched
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_train


def agreement(train: str, speeds, duration: float) -> dict:
    twins = [compile_train(load_train(train, s)) for s in speeds]
    cpu = [simulate_mujoco(mb, RunSettings(duration)) for mb in twins]
    batch = batched.simulate_mujoco_batch(twins, RunSettings(duration))
    worst = 0.0
    for a, b in zip(cpu, batch):
        for name in a.names():
            scale = float(np.max(np.abs(a[name]))) or 1.0
            worst = max(worst, float(np.max(np.abs(a[name] - b[name]))) / scale)
    same = all(a.info.settings["forward_evaluations"] == b.info.settings["forward_evaluations"]
               for a, b in zip(cpu, batch))
    return {"speeds_rpm": list(speeds), "duration_s": duration, "largest_relative_difference": worst,
            "same_forward_evaluations": same}


def cost(train: str, worlds: int, lo: float, hi: float, duration: float) -> dict:
    speeds = np.linspace(lo, hi, worlds) if worlds > 1 else np.array([0.5 * (lo + hi)])
    twins = [compile_train(load_train(train, float(s))) for s in speeds]
    started = time.perf_counter()
    batched.simulate_mujoco_batch(twins, RunSettings(duration))
    first = time.perf_counter() - started
    started = time.perf_counter()
    results = batched.simulate_mujoco_batch(twins, RunSettings(duration))
    wall = time.perf_counter() - started
    steps = sum(r.info.steps for r in results)
    timing = results[0].info.settings["timing_s"]
    return {"worlds": worlds, "first_run_s": first, "duration_s": duration, "wall_s": wall,
            "world_steps": steps, "us_per_world_step": 1e6 * wall / steps, "s_per_world": wall / worlds,
            "device_us_per_slot": 1e6 * timing["device_s"] / timing["slots"],
            **{k: round(v, 3) for k, v in timing.items() if k.endswith("_s")},
            "results_s": round(wall - timing["prepare_s"] - timing["loop_s"], 3)}


def cpu_cost(train: str, speeds, duration: float) -> dict:
    twins = [compile_train(load_train(train, float(s))) for s in speeds]
    simulate_mujoco(twins[0], RunSettings(min(duration, 0.001)))  # compiles the loop
    rows = []
    for mb in twins:
        started = time.process_time()
        r = simulate_mujoco(mb, RunSettings(duration))
        rows.append((time.process_time() - started, r.info.steps))
    cpu, steps = (sum(x) for x in zip(*rows))
    return {"speeds_rpm": [float(s) for s in speeds], "cpu_s_per_point": cpu / len(rows),
            "us_per_step": 1e6 * cpu / steps}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--train", default="hub-drive")
    parser.add_argument("--worlds", default="1,32,181")
    parser.add_argument("--speeds", default="200:2000", help="lowest:highest input speed, rpm")
    parser.add_argument("--check", type=float, default=0.002, help="s simulated by the agreement runs")
    parser.add_argument("--duration", type=float, default=0.01, help="s simulated by the timed runs")
    parser.add_argument("--no-cpu", action="store_true", help="leave out the CPU runner's pass")
    parser.add_argument("--json", help="write the figures here too")
    args = parser.parse_args()
    why = batched.available()
    if why:
        raise SystemExit(why)
    lo, hi = (float(x) for x in args.speeds.split(":"))
    out = {"device": batched.device(), "cores": os.cpu_count(), "train": args.train}
    print(f"device: {out['device']}; {out['cores']} cores", flush=True)
    out["agreement"] = agreement(args.train, [lo + 0.45 * (hi - lo), lo + 0.66 * (hi - lo)], args.check)
    print("agreement:", out["agreement"], flush=True)
    if not args.no_cpu:
        out["cpu"] = cpu_cost(args.train, [lo, 0.5 * (lo + hi), hi], args.duration)
        print("cpu runner:", out["cpu"], flush=True)
    out["batched"] = []
    for n in (int(x) for x in args.worlds.split(",")):
        row = cost(args.train, n, lo, hi, args.duration)
        if "cpu" in out:
            row["ratio_to_cpu_per_point"] = row["s_per_world"] / out["cpu"]["cpu_s_per_point"]
        out["batched"].append(row)
        print("batched:", row, flush=True)
    best = min(out["batched"], key=lambda r: r["s_per_world"])
    scale = 0.5 / args.duration
    cpu = f"{181 * out['cpu']['cpu_s_per_point'] * scale:.0f} CPU s on one core; " if "cpu" in out else ""
    print(f"a 181-point sweep's MuJoCo runs of 0.5 s: {cpu}{181 * best['s_per_world'] * scale:.0f} s batched on "
          f"{out['device']} at {best['worlds']} worlds")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
