"""Benchmark of the MuJoCo runner (not a test).

1. Per-step cost of ``simulate_mujoco`` against a bare ``mj_step`` loop on the same model
   (same RK4 integrator, same sensors, same step): the runner's extra Python work per step.
   Target: ratio <= 1.3.
2. Steps per second of the runner for 1, 2 and 3 planetary stages (demo-3p's stage chained,
   carrier k -> sun k+1 by a spline coupling).
3. With ``--convergence``: normalised RMS differences between MuJoCo and the lumped RK4 run of
   demo-3p as the step shrinks.

Run:  python bench/bench_runner.py [--steps N] [--convergence]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.loader import load_train
from gearcheck.lumped.time_solver import simulate
from gearcheck.lumped.variants import chained
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.settings import RunSettings


def bare_step_cost(mb, n_steps: int, dt: float) -> float:
    m = mb.model
    m.opt.timestep = dt
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(m)
    for mid, speed in mb.kin.speeds.items():
        d.qvel[mb.dadr[mid][2]] = speed
    mujoco.mj_forward(m, d)
    started = time.perf_counter()
    for _ in range(n_steps):
        mujoco.mj_step(m, d)
    return (time.perf_counter() - started) / n_steps


def runner_step_cost(mb, n_steps: int, dt: float) -> float:
    res = simulate_mujoco(mb, RunSettings(n_steps * dt, dt))
    return res.info["wall_time_s"] / res.info["steps"]


def cost_table(n_steps: int, repeats: int = 3):
    print(f"runner vs bare mj_step (RK4, same model, same step), best of {repeats}, {n_steps} steps")
    print(f"{'train':<10} {'bodies':>6} {'tendons':>7} {'dt [s]':>10} {'bare [us]':>10} {'runner [us]':>11} "
          f"{'ratio':>6} {'steps/s':>9} {'sim s per wall s':>16}")
    rows = []
    for n_stages in (1, 2, 3):
        spec = load_train("demo-3p") if n_stages == 1 else chained(n_stages)
        mb = compile_train(spec)
        dt = mb.model.opt.timestep  # the default step written into the MJCF
        bare = min(bare_step_cost(mb, n_steps, dt) for _ in range(repeats))
        run = min(runner_step_cost(mb, n_steps, dt) for _ in range(repeats))
        rows.append((n_stages, bare, run))
        label = f"{n_stages} stage" + ("s" if n_stages > 1 else "")
        print(f"{label:<10} {mb.model.nbody - 1:>6} {mb.model.ntendon:>7} {dt:>10.4g} {bare * 1e6:>10.2f} "
              f"{run * 1e6:>11.2f} {run / bare:>6.3f} {1 / run:>9.0f} {dt / run:>16.4f}")
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
    parser.add_argument("--convergence", action="store_true")
    args = parser.parse_args()
    print(f"mujoco {mujoco.__version__}")
    cost_table(args.steps)
    if args.convergence:
        convergence_table()


if __name__ == "__main__":
    main()
