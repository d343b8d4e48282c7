"""Benchmark of the sweep engine (not a test): a hub-drive speed sweep on 1 and 2 local worker processes and on a
Dask LocalCluster of 2 single-threaded worker processes, no cache.

Prints, per backend, the wall time, the wall time per point, the speed-up and parallel efficiency against one
worker, and the time the full target sweep would take at that rate: 181 points (200 to 2000 rpm in 10 rpm
steps), 0.5 s simulated each, both solvers, in at most 3 minutes on 2 cores.  It also checks that every
backend gave the same table, byte for byte.  Run it small:

    OPENBLAS_NUM_THREADS=1 python bench/bench_sweep.py --points 6 --duration 0.1

and in full with ``--points 181``.  The points are spread evenly over the target's speed range, so a small run
samples the same mix of slow and fast points; the per-point rate extrapolates linearly (pool and cluster start-up
included, so a small run understates the scaling).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from gearcheck.compare.studies.sweep import sweep

TARGET_POINTS, TARGET_S = 181, 180.0


def warm() -> None:
    """One tiny point in a Dask worker: its imports and the solvers' compiled kernels loaded, as in a cluster that
    has run before (the local pool's workers inherit the imports from its fork server)."""
    from gearcheck.compare.studies import sweep as engine

    engine.run_point(engine.plan_sweep("demo-3p", speeds=[1000.0], duration=0.01).points[0])


def mujoco_floor(train: str, speed: float, duration: float) -> float:
    """CPU seconds of the MuJoCo twin's run of one point (compiled step loop, the model already built)."""
    from gearcheck.train.loader import load_train
    from gearcheck.mbd_models.side import MujocoSide
    from gearcheck.shared.settings import RunSettings

    side = MujocoSide(load_train(train, speed))
    side.run(RunSettings(0.001))  # the model built and the kernel loaded outside the timing
    started = time.process_time()
    side.run(RunSettings(duration))
    return time.process_time() - started


def timed(label, count, speeds, args, **backend):
    started = time.perf_counter()
    result = sweep(args.train, speeds=speeds, solvers=args.solver, duration=args.duration, cache=None,
                   integration_check=args.integration_check, **backend)
    wall = time.perf_counter() - started
    return {"label": label, "workers": count, "wall": wall, "per_point": wall / len(speeds),
            "busy": sum(result.point_wall_s) / (count * wall), "load": os.getloadavg()[0],
            "cpu": sum(result.point_cpu_s) / len(speeds), "cores": sum(result.point_cpu_s) / wall,
            "bytes": result.parquet()}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--train", default="hub-drive")
    p.add_argument("--points", type=int, default=TARGET_POINTS, help="speeds from --low to --high (default 181)")
    p.add_argument("--low", type=float, default=200.0)
    p.add_argument("--high", type=float, default=2000.0)
    p.add_argument("--duration", type=float, default=0.5, help="simulated s per point and solver (default 0.5)")
    p.add_argument("--solver", default="both", choices=("both", "lumped", "mujoco"))
    p.add_argument("--workers", default="1,2", help="local process counts (default 1,2)")
    p.add_argument("--no-dask", action="store_true", help="leave the Dask LocalCluster out")
    p.add_argument("--integration-check", action="store_true",
                   help="run each solver's integration check too (the sweep's default; the target counts each "
                        "solver once per point)")
    args = p.parse_args(argv)
    speeds = np.linspace(args.low, args.high, args.points).tolist() if args.points > 1 else [args.low]
    print(f"{args.train}: {args.points} points from {speeds[0]:g} to {speeds[-1]:g} rpm, {args.duration:g} s each, "
          f"solver {args.solver}, integration check {'on' if args.integration_check else 'off'}")
    rows = [timed(f"processes ({n})" if n > 1 else "in-process (1)", n, speeds, args, workers=n)
            for n in (int(w) for w in args.workers.split(","))]
    if not args.no_dask:
        from distributed import Client, LocalCluster

        started = time.perf_counter()
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
                Client(cluster) as client:
            client.run(warm)
            up = time.perf_counter() - started
            rows.append(timed(f"dask LocalCluster (2; start-up {up:.1f} s not counted)", 2, speeds, args,
                              scheduler=client))
    base = rows[0]["per_point"] * rows[0]["workers"]
    print(f"\n{'backend':<48} {'workers':>7} {'wall [s]':>9} {'s/point':>8} {'speed-up':>8} {'efficiency':>10} "
          f"{'busy':>5} {'CPU s/point':>11} {'cores used':>10} {'load':>5} {'181 points [s]':>14}")
    for r in rows:
        speedup = base / r["per_point"]
        print(f"{r['label']:<48} {r['workers']:>7} {r['wall']:>9.2f} {r['per_point']:>8.3f} {speedup:>8.2f} "
              f"{speedup / r['workers']:>10.2f} {r['busy']:>5.2f} {r['cpu']:>11.3f} {r['cores']:>10.2f} "
              f"{r['load']:>5.1f} {r['per_point'] * TARGET_POINTS:>14.1f}")
    print("busy: the share of the workers' time spent inside points (1: the engine leaves no worker idle); CPU "
          "s/point: the CPU time of a point in its worker (the same work on every backend); cores used: the workers' "
          "CPU time over the wall time; load: the 1-minute load average after the run, on "
          f"{os.cpu_count()} cores (above the worker count, other processes share the cores, and the speed-up "
          "measures them too)")
    print(f"\nCPU time per point (one worker): {rows[0]['cpu']:.3f} s; on 2 idle cores the {TARGET_POINTS}-point sweep "
          f"would take {rows[0]['cpu'] * TARGET_POINTS / 2:.0f} s at that rate")
    floor = mujoco_floor(args.train, 0.5 * (speeds[0] + speeds[-1]), args.duration)
    print(f"MuJoCo's share (one run at {0.5 * (speeds[0] + speeds[-1]):g} rpm, in this process): {floor:.3f} s CPU; "
          f"{TARGET_POINTS} runs on 2 cores take {floor * TARGET_POINTS / 2:.0f} s of MuJoCo alone")
    same = all(r["bytes"] == rows[0]["bytes"] for r in rows)
    print(f"tables identical across backends: {'yes' if same else 'NO'}")
    best = min(r["per_point"] * TARGET_POINTS for r in rows if r["workers"] <= 2)
    full = args.duration == 0.5 and args.solver == "both" and args.train == "hub-drive" and not args.integration_check
    verdict = ("met" if best <= TARGET_S else "not met") if full else "not judged"
    print(f"target: {TARGET_POINTS} points, 0.5 s each, both solvers, <= {TARGET_S:.0f} s on 2 cores; "
          f"{'this run' if full else 'this run (NOT the target settings: --duration 0.5 --solver both, no check)'} "
          f"extrapolates to {best:.0f} s on 2 workers: {verdict}")


if __name__ == "__main__":
    main()
