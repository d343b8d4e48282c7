"""Benchmark of the sweep engine (not a test): a hub-drive speed sweep on local worker processes and on a Dask
LocalCluster, and what each of its savings gains.

The target grid is 181 speeds, 200 to 2000 rpm in 10 rpm steps, both solvers, the sweep's defaults (0.5 s for a
point from the static state, speed continuation, the integration check on the subset), in at most 3 minutes on
2 cores.  Two parts, side by side in one run:

* backends (``--workers``, ``--no-dask``): the default sweep on 1 and 2 local processes and on a Dask
  LocalCluster of 2 single-threaded workers, no cache: wall time, per point, speed-up and parallel efficiency,
  and that every backend gave the same table, byte for byte;
* gains (``--gains``): the same speeds under each setting that led to the default, each saving on its own --
  every point from the static state with every point checked (the engine before continuation), then the checked
  subset, then continuation without checks, then both -- CPU seconds per point and the ratio to the first.

``--span A:B`` runs only the grid's speeds from A to B rpm (the same 10 rpm steps, so a point continues from its
neighbour as in the full sweep), and the full sweep's wall time is extrapolated from the CPU per point, without a
verdict: a stretch continues its own share of points (94 % from 1000 to 1150 rpm, 71 % over the whole grid).  Quick:

    OPENBLAS_NUM_THREADS=1 python bench/bench_sweep.py --span 1000:1100 --no-dask --gains

and in full without ``--span``.

``--floor`` runs the stretch once more in this process and splits a point's CPU into the two solvers' compiled
step loops and everything else, and sets it against its floor: the MuJoCo forward passes its points took (every
RK4 stage of every run, the integration checks' and the discarded attempts' included) at the cost of a pass in
MuJoCo's own C ``rollout`` of the same model on this machine (with its sensors for the passes of sampled runs,
without them for the settling stretches, sampled only at their ends), plus the lumped kernel's own time.
The target asks 2 cores x 180 s / 181 points = 1.99 CPU s a point; the floor says whether these steps can meet it
here at all.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from gearcheck.compare.studies.sweep import sweep

TARGET_POINTS, TARGET_S = 181, 180.0
GAINS = {  # label: (continuation, integration check)
    "from rest, all checked (before)": (False, "all"),
    "from rest, subset checked": (False, "subset"),
    "continued, none checked": (True, "none"),
    "continued, subset checked (default)": (True, "subset"),
}


def warm() -> None:
    """One tiny point in a Dask worker: its imports and the solvers' compiled kernels loaded, as in a cluster that
    has run before (the local pool's workers inherit the imports from its fork server)."""
    from gearcheck.compare.studies import sweep as engine

    engine.run_point(engine.plan_sweep("demo-3p", speeds=[1000.0], duration=0.01).points[0])


def timed(label, count, speeds, args, continuation=True, check="subset", **backend):
    started = time.perf_counter()
    result = sweep(args.train, speeds=speeds, solvers=args.solver, duration=args.duration, cache=None,
                   integration_check=check, continuation=continuation, **backend)
    wall = time.perf_counter() - started
    frame = result.to_pandas().query("metric == 'rms'").drop_duplicates(["point", "solver"])
    return {"label": label, "workers": count, "wall": wall, "per_point": wall / len(speeds),
            "busy": sum(result.point_wall_s) / (count * wall), "load": os.getloadavg()[0],
            "cpu": sum(result.point_cpu_s) / len(speeds), "cores": sum(result.point_cpu_s) / wall,
            "continued": float(np.mean(frame["start"] == "continued")),
            "checked": float(np.mean(frame["checked"] != "no")), "bytes": result.parquet()}


def floor(speeds, args) -> None:
    """Where a point's CPU goes, in this process: MuJoCo's compiled step loop, the lumped kernel, and the rest, and
    the points' floor (their forward passes at ``rollout``'s cost, plus the lumped kernel)."""
    from bench_runner import rollout_step_cost

    from gearcheck.lumped import time_solver
    from gearcheck.mbd_models import compiled
    from gearcheck.mbd_models.side import MujocoSide
    from gearcheck.train.loader import load_train

    spent = {"mujoco": 0.0, "lumped": 0.0}
    passes = {True: 0, False: 0}  # sampled at every step or not

    def timed_kernel(kernel, solver):
        def run(*a, **k):
            started = time.process_time()
            try:
                return kernel(*a, **k)
            finally:
                spent[solver] += time.process_time() - started
        return run

    def counted(run_from):
        def run(self, settings, *a, **k):
            result, state = run_from(self, settings, *a, **k)
            passes[settings.output_dt is None] += result.info.rhs_calls
            return result, state
        return run

    patches = [(compiled, "run_steps", timed_kernel(compiled.run_steps, "mujoco")),
               (time_solver, "rk4_steps", timed_kernel(time_solver.rk4_steps, "lumped")),
               (MujocoSide, "run_from", counted(MujocoSide.run_from))]
    twin = MujocoSide(load_train(args.train, speeds[len(speeds) // 2]))
    mb, dt = twin.model, twin.default_step()

    def rollout_pass() -> np.ndarray:  # (with sensors, without), s a pass
        return np.array([min(rollout_step_cost(mb, 20000, dt, sensors=on) for _ in range(3)) / 4
                         for on in (True, False)])

    kept = [(owner, name, getattr(owner, name)) for owner, name, _ in patches]
    for owner, name, value in patches:
        setattr(owner, name, value)
    before = rollout_pass()
    try:
        row = timed("in-process (1), kernels timed", 1, speeds, args, workers=1)
    finally:
        for owner, name, value in kept:
            setattr(owner, name, value)
    after = rollout_pass()
    per_pass = 0.5 * (before + after)  # the machine's speed drifts: its mean over the run
    n, cpu = len(speeds), row["cpu"]
    rest = cpu - (spent["mujoco"] + spent["lumped"]) / n
    total = passes[True] + passes[False]
    at_floor = (passes[True] * per_pass[0] + passes[False] * per_pass[1] + spent["lumped"]) / n
    print(f"\nwhere a point's CPU goes (in-process, {n} points, load {row['load']:.1f} after): {cpu:.3f} s")
    print(f"  MuJoCo's compiled step loop   {spent['mujoco'] / n:7.3f} s  {spent['mujoco'] / n / cpu:5.1%}  "
          f"{total / n:,.0f} forward passes ({passes[True] / total:.0%} sampled), "
          f"{1e6 * spent['mujoco'] / total:.2f} us each")
    print(f"  the lumped compiled kernel    {spent['lumped'] / n:7.3f} s  {spent['lumped'] / n / cpu:5.1%}")
    print(f"  the rest (drives, results, reductions, plans, static states, modes) {rest:.3f} s  {rest / cpu:5.1%}")
    print(f"floor: the same forward passes at rollout's {1e6 * per_pass[0]:.2f} us sampled and {1e6 * per_pass[1]:.2f} "
          f"us not (sensors on and off, this machine; {1e6 * before[0]:.2f} and {1e6 * before[1]:.2f} before the "
          f"stretch, {1e6 * after[0]:.2f} and {1e6 * after[1]:.2f} after) plus the lumped kernel: {at_floor:.3f} s a "
          f"point; these points cost {cpu / at_floor:.2f} times their floor")
    print(f"the target's {2 * TARGET_S / TARGET_POINTS:.2f} CPU s a point (2 cores, {TARGET_S:.0f} s, {TARGET_POINTS} "
          f"points) is {2 * TARGET_S / TARGET_POINTS / at_floor:.2f} times this stretch's floor")


def memory(train: str, speed: float) -> tuple[float, float]:
    """Peak memory (MB, numpy's allocations by tracemalloc) of one point from rest and of the next, continued, in
    this process, both solvers, no integration check."""
    import tracemalloc

    from gearcheck.compare.studies import sweep as engine

    first, second = engine.plan_sweep(train, speeds=[speed, speed + 10.0], integration_check="none").points
    engine.run_point(engine.plan_sweep("demo-3p", speeds=[1000.0], duration=0.005).points[0])  # imports, kernels
    peaks = []
    tracemalloc.start()
    before = None
    for point in (first, second):
        tracemalloc.reset_peak()
        before, _, _ = engine.run_point(point, before)
        peaks.append(tracemalloc.get_traced_memory()[1] / 2**20)
    tracemalloc.stop()
    return peaks[0], peaks[1]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--train", default="hub-drive")
    p.add_argument("--points", type=int, default=TARGET_POINTS, help="speeds from --low to --high (default 181)")
    p.add_argument("--low", type=float, default=200.0)
    p.add_argument("--high", type=float, default=2000.0)
    p.add_argument("--span", metavar="A:B", help="run only the grid's speeds from A to B rpm")
    p.add_argument("--duration", type=float, default=0.5, help="simulated s of a point from rest (default 0.5)")
    p.add_argument("--solver", default="both", choices=("both", "lumped", "mujoco"))
    p.add_argument("--workers", default="1,2", help="local process counts (default 1,2)")
    p.add_argument("--no-dask", action="store_true", help="leave the Dask LocalCluster out")
    p.add_argument("--gains", action="store_true", help="also run each saving on its own (on the most workers)")
    p.add_argument("--memory", action="store_true", help="also measure a point's peak memory, from rest and continued")
    p.add_argument("--floor", action="store_true", help="also split a point's CPU and set it against its floor")
    args = p.parse_args(argv)
    grid = np.linspace(args.low, args.high, args.points) if args.points > 1 else np.array([args.low])
    if args.span:
        a, b = (float(x) for x in args.span.split(":"))
        grid = grid[(grid >= a - 1e-9) & (grid <= b + 1e-9)]
    speeds = grid.tolist()
    print(f"{args.train}: {len(speeds)} of the {args.points} grid points from {speeds[0]:g} to {speeds[-1]:g} rpm, "
          f"solver {args.solver}, {args.duration:g} s from rest; {os.cpu_count()} cores, load "
          f"{os.getloadavg()[0]:.1f} before")
    counts = [int(w) for w in args.workers.split(",")]
    rows = [timed(f"processes ({n})" if n > 1 else "in-process (1)", n, speeds, args, workers=n) for n in counts]
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
          f"{'busy':>5} {'CPU s/point':>11} {'cores used':>10} {'load':>5}")
    for r in rows:
        speedup = base / r["per_point"]
        print(f"{r['label']:<48} {r['workers']:>7} {r['wall']:>9.2f} {r['per_point']:>8.3f} {speedup:>8.2f} "
              f"{speedup / r['workers']:>10.2f} {r['busy']:>5.2f} {r['cpu']:>11.3f} {r['cores']:>10.2f} "
              f"{r['load']:>5.1f}")
    print("busy: the share of the workers' time spent inside points; CPU s/point: the CPU time of a point in its "
          "worker (the same work on every backend); cores used: the workers' CPU time over the wall time; load: "
          "the 1-minute load average after the run")
    print(f"tables identical across backends: {'yes' if all(r['bytes'] == rows[0]['bytes'] for r in rows) else 'NO'}")
    print(f"continued points: {rows[0]['continued']:.0%}; checked points: {rows[0]['checked']:.0%}")
    if args.gains:
        most = max(counts)
        gains = [timed(label, most, speeds, args, continuation, check, workers=most)
                 for label, (continuation, check) in GAINS.items()]
        print(f"\n{'setting':<40} {'CPU s/point':>11} {'gain':>6} {'wall [s]':>9} {'continued':>9} {'checked':>8} "
              f"{'load':>5}")
        for g in gains:
            print(f"{g['label']:<40} {g['cpu']:>11.3f} {gains[0]['cpu'] / g['cpu']:>6.2f} {g['wall']:>9.2f} "
                  f"{g['continued']:>9.0%} {g['checked']:>8.0%} {g['load']:>5.1f}")
    if args.floor:
        floor(speeds, args)
    if args.memory:
        rest, going_on = memory(args.train, speeds[len(speeds) // 2])
        print(f"\npeak memory of a point (numpy's allocations, both solvers, no check): from rest {rest:.0f} MB, "
              f"continued {going_on:.0f} MB (target <= 150 MB)")
    full = len(speeds) == TARGET_POINTS and args.points == TARGET_POINTS and args.train == "hub-drive" and \
        args.solver == "both" and args.duration == 0.5
    two = [r for r in rows if r["workers"] == 2]
    target = f"\ntarget: {TARGET_POINTS} points, both solvers, the defaults, <= {TARGET_S:.0f} s on 2 cores: "
    if two and full:
        measured = min(r["wall"] for r in two)
        print(f"{target}{measured:.0f} s (measured): {'met' if measured <= TARGET_S else 'not met'}")
    elif two:  # a stretch's points are not the grid's: its share of continued points is its own
        estimate = rows[0]["cpu"] * TARGET_POINTS / 2
        print(f"{target}{estimate:.0f} s if every point cost this stretch's {rows[0]['cpu']:.3f} CPU s on 2 idle "
              f"cores ({rows[0]['continued']:.0%} of its points continued): no verdict, the whole grid (no --span) "
              "decides")


if __name__ == "__main__":
    main()
