"""Benchmark of the MuJoCo runner (not a test).

1. Per-step cost of ``simulate_mujoco`` against a bare ``mj_step`` loop on the same model
   (same RK4 integrator, same sensors, same step), side by side in one run: the per-step loop in
   Python (``engine="python"``, before issue 15) and in C (``engine="compiled"``, the default), for
   1, 2 and 3 planetary stages (demo-3p's stage chained, carrier k -> sun k+1 by a spline coupling) and
   hub-drive (the sweeps' train: backlash, two turning carriers).
   The bare loop is timed both from Python (``mujoco.mj_step`` per step) and in C
   (``mujoco.rollout``, no Python per step).  Targets: runner / bare Python mj_step <= 1.3, runner / bare C
   (rollout) <= 1.1 (the runner does more than a bare step: the drive at every stage, contact events located,
   the mesh forces read at every sample).  Also without samples, as a sweep point's settling stretch runs: the
   runner sampling only its run's ends (its steps then go without MuJoCo's sensors) against ``rollout`` with
   the sensors disabled.  The table holds each column's best of the repeats; the ratios to ``rollout`` are the
   median of each repeat's own ratio (its runs back to back), which a machine whose speed drifts between repeats
   moves less than a ratio of two bests taken at different times.
2. Several twins at once (``simulate_mujoco_many``, threads): wall time per step per twin.
3. With ``--convergence``: normalised RMS differences between MuJoCo and the lumped RK4 run of
   demo-3p as the step shrinks.

Run:  python bench/bench_runner.py [--steps N] [--twins K] [--convergence]
"""

from __future__ import annotations

import argparse
import os
import time

import mujoco
import numpy as np
from mujoco import rollout

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.time_solver import simulate
from gearcheck.train.variants import chained
from gearcheck.mbd_models.runner import simulate_mujoco, simulate_mujoco_many
from gearcheck.mbd_models.mjcf_text import ROTATION
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings


def turning_data(mb, dt: float):
    """The twin's model on RK4 at step ``dt`` and a data with every body turning at its nominal speed."""
    m = mb.model
    m.opt.timestep = dt
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(m)
    for mid, speed in mb.kin.speeds.items():
        d.qvel[mb.dadr[mid][ROTATION]] = speed
    return m, d


def bare_step_cost(mb, n_steps: int, dt: float) -> float:
    m, d = turning_data(mb, dt)
    mujoco.mj_forward(m, d)
    started = time.perf_counter()
    for _ in range(n_steps):
        mujoco.mj_step(m, d)
    return (time.perf_counter() - started) / n_steps


def rollout_step_cost(mb, n_steps: int, dt: float, sensors: bool = True) -> float:
    """A bare mj_step loop in C: ``mujoco.rollout`` with the controls held, sensors recorded (or, ``sensors``
    False, disabled: ``mjDSBL_SENSOR``)."""
    m, d = turning_data(mb, dt)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state, spec)
    control = np.zeros((1, n_steps, m.nu))
    flags = m.opt.disableflags
    m.opt.disableflags = flags | (0 if sensors else int(mujoco.mjtDisableBit.mjDSBL_SENSOR))
    try:
        started = time.perf_counter()
        rollout.rollout(m, d, state[None], control)
        return (time.perf_counter() - started) / n_steps
    finally:
        m.opt.disableflags = flags


def runner_step_cost(mb, n_steps: int, dt: float, engine: str, sampled: bool = True) -> float:
    """Per step of ``simulate_mujoco``, sampling every step (or, ``sampled`` False, only the run's two ends: a
    sweep point's settling stretch, whose steps go without MuJoCo's sensors)."""
    res = simulate_mujoco(mb, RunSettings(n_steps * dt, dt, output_dt=None if sampled else n_steps * dt),
                          engine=engine)
    assert res.info.engine == f"mujoco-{engine}"
    return res.info.wall_s / res.info.steps


def many_step_cost(mb, n_steps: int, dt: float, twins: int, threads: int) -> float:
    """Wall time of ``twins`` copies of the twin run at once in ``threads`` threads (static states included),
    per step per twin."""
    started = time.perf_counter()
    simulate_mujoco_many([mb] * twins, RunSettings(n_steps * dt, dt), threads=threads)
    return (time.perf_counter() - started) / (twins * n_steps)


def cost_table(n_steps: int, twins: int, repeats: int = 5):
    threads = os.cpu_count() or 1
    print(f"runner vs bare mj_step (RK4, same model, same step), best of {repeats}, {n_steps} steps; us per step")
    print(f"{'':<10} {'':>6} {'':>7} {'':>10} {'bare mj_step':>19} {'runner':>23} {'runner/bare py':>17}"
          f" {f'{twins} twins, {threads} thr':>17}")
    print(f"{'train':<10} {'bodies':>6} {'tendons':>7} {'dt [s]':>10} {'python':>9} {'C':>9} {'python':>11} "
          f"{'compiled':>11} {'before':>8} {'after':>8} {'us/step':>8} {'/bare':>8}")
    rows = []
    for n_stages in (1, 2, 3, "hub-drive"):
        spec = load_train(n_stages) if isinstance(n_stages, str) else (
            load_train("demo-3p") if n_stages == 1 else chained(n_stages))
        mb = compile_train(spec)
        dt = mb.model.opt.timestep  # the default step written into the MJCF
        runner_step_cost(mb, 100, dt, "compiled")  # load the compiled loop
        costs = []
        for _ in range(repeats):  # interleaved, so that a change in the machine's load touches every column
            costs.append((bare_step_cost(mb, n_steps, dt), rollout_step_cost(mb, n_steps, dt),
                          runner_step_cost(mb, n_steps, dt, "python"), runner_step_cost(mb, n_steps, dt, "compiled"),
                          many_step_cost(mb, n_steps, dt, twins, threads),
                          rollout_step_cost(mb, n_steps, dt, sensors=False),
                          runner_step_cost(mb, n_steps, dt, "compiled", sampled=False)))
        bare, bare_c, before, after, many, quiet_c, quiet = np.min(costs, axis=0)
        paired = np.median([(c[3] / c[1], c[6] / c[5]) for c in costs], axis=0)  # each repeat's own ratios
        label = n_stages if isinstance(n_stages, str) else f"{n_stages} stage" + ("s" if n_stages > 1 else "")
        rows.append((label, bare, bare_c, before, after, many, quiet_c, quiet, *paired))
        print(f"{label:<10} {mb.model.nbody - 1:>6} {mb.model.ntendon:>7} {dt:>10.4g} {bare * 1e6:>9.2f} "
              f"{bare_c * 1e6:>9.2f} {before * 1e6:>11.2f} {after * 1e6:>11.2f} {before / bare:>8.3f} "
              f"{after / bare:>8.3f} {many * 1e6:>8.2f} {many / bare:>8.3f}")
    print("runner/bare C (compiled, sampled at every step; median of the repeats' own ratios): " + ", ".join(
        f"{r[0]} {r[8]:.3f}" for r in rows))
    print("without samples (a sweep's settling stretch), runner / bare C without sensors (best of each, then the "
          "median of the repeats' own ratios): " + ", ".join(
              f"{r[0]} {r[7] * 1e6:.2f} / {r[6] * 1e6:.2f} us, {r[9]:.3f}" for r in rows))
    return rows


def convergence_table(duration: float = 0.05, settle: float = 0.025):
    spec = load_train("demo-3p")
    model = build_model(spec)
    mb = compile_train(spec)
    h0 = mb.model.opt.timestep

    def nrms(a, b):
        return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b**2)))

    print(f"\nMuJoCo vs lumped RK4, demo-3p, steady window t >= {settle} s of {duration} s "
          "(normalised RMS of the difference)")
    print(f"{'dt [s]':>11} {'mesh force':>11} {'mesh dyn.':>10} {'ring world':>11} {'ring carrier':>13} "
          f"{'ring alpha':>11}")
    for f in (1, 2, 4):
        h = h0 / f
        settings = RunSettings(duration, h, settle=settle)
        mj, lp = simulate_mujoco(mb, settings), simulate(model, settings)
        w = mj.steady
        forces = mj.names("mesh_force")
        force = max(nrms(mj[n][w], lp[n][w]) for n in forces)
        dyn = max(nrms(mj[n][w] - lp.static[n], lp[n][w] - lp.static[n]) for n in forces)
        ring = "stage1.ring"
        world = max(nrms(mj[f"{ring}.a{c}.world"][w], lp[f"{ring}.a{c}.world"][w]) for c in "xy")
        carrier = max(nrms(mj[f"{ring}.a{c}.carrier"][w], lp[f"{ring}.a{c}.carrier"][w]) for c in "xy")
        alpha = nrms(mj[f"{ring}.alpha"][w], lp[f"{ring}.alpha"][w])
        print(f"{h:>11.4e} {force:>11.3e} {dyn:>10.3e} {world:>11.3e} {carrier:>13.3e} {alpha:>11.3e}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--twins", type=int, default=4)
    parser.add_argument("--convergence", action="store_true")
    args = parser.parse_args()
    print(f"mujoco {mujoco.__version__}")
    cost_table(args.steps, args.twins)
    if args.convergence:
        convergence_table()


if __name__ == "__main__":
    main()
