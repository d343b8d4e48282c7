"""Benchmark of the lumped reference solver (not a test): its cost per step against a compiled yardstick and
against scipy, and how the cost grows.

Every figure below is measured in this one run, side by side:

1. First-call cost of the compiled steps (:mod:`gearcheck.lumped.compiled_steps`): in a fresh process with an
   empty numba cache (compile) and again with the cache filled (load).
2. us/step of :func:`~gearcheck.lumped.time_solver.simulate` (``method="rk4"``, the whole call: drive, splits at
   stiffness jumps, contacts, outputs, divergence checks) on every preset, against a minimal numba RK4 of
   M q'' = F(t) - C q' - K(t) q, K(t) q = K_0 q + A^T (k(t) * A q), over the same steps with the same stiffness
   history (the yardstick; its kernel alone is timed, the history precomputed).  Target: ratio <= 3.
   The loop against its own kernel, in one process (cProfile): the RK4 loop of ``simulate`` (the drive sampled
   per chunk, steps split at stiffness jumps, divergence checks) over the compiled steps alone
   (``rk4_steps``).  Target: <= 1.2.
3. scipy.integrate.solve_ivp RK45 (``simulate(method="RK45")``) at equal accuracy on hub-drive and demo-3p: the
   error is the largest mesh-force difference from a reference run (RK4 at a sixteenth of the default step,
   drive at each stage's own time) over the samples, over the peak mesh force; RK45 takes the loosest rtol of a
   ladder 1e-3, 3.2e-4, ... 1e-10 (atol = 1e-9 rtol) whose error is at most RK4's at its default step.
   Target: RK45 wall / RK4 wall >= 50.
4. The periodic steady state by shooting (:mod:`gearcheck.lumped.periodic_steady_state`, to a residual of 1e-10)
   against time marching from the static state until within 1e-7 of it (a period's end state), and the trains
   it refuses (no common period).
5. Growth with duration, planets, stages (1, 2, 3; with and without radial splines, which turn with the
   stages' carriers) and tip relief.

Run:  python bench/bench_lumped.py [--quick]
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit

from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.periodic_steady_state import periodic_steady_state
from gearcheck.lumped.time_solver import default_step, simulate
from gearcheck.train.variants import chained, edited, wide_stage
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import STAGE_OFFSETS, STAGE_SIDES

LIGHT_BACKLASH = [(r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 40.0\n"
                   "ste = [{ harmonic = 1, amplitude_um = 5.0 }]"), (r"^output_torque = .*", "output_torque = 30.0")]
PRESETS = ("demo-3p", "demo-4p", "double-planet", "helical-planetary", "hub-drive", "rv-reducer")


# ---------------------------------------------------------------------------------------------- yardstick
@njit(cache=True)
def _acceleration(q, v, k, F, minv, C, K0, A, out):
    n, m = q.size, A.shape[0]
    for i in range(n):
        s = F[i]
        for j in range(n):
            s -= C[i, j] * v[j] + K0[i, j] * q[j]
        out[i] = s
    for r in range(m):
        d = 0.0
        for j in range(n):
            d += A[r, j] * q[j]
        f = k[r] * d
        for j in range(n):
            out[j] -= A[r, j] * f
    for i in range(n):
        out[i] *= minv[i]


@njit(cache=True)
def yardstick_rk4(q, v, h, minv, C, K0, A, k, F):
    """RK4 of M q'' = F - C q' - K0 q - A^T (k * A q) over k.shape[0] steps; k, F (steps, 3, .): the drive at
    the stage times t, t + h/2, t + h."""
    n = q.size
    a1, a2, a3, a4 = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    q2, v2, q3, v3, q4, v4 = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for s in range(k.shape[0]):
        _acceleration(q, v, k[s, 0], F[s, 0], minv, C, K0, A, a1)
        for i in range(n):
            q2[i] = q[i] + 0.5 * h * v[i]
            v2[i] = v[i] + 0.5 * h * a1[i]
        _acceleration(q2, v2, k[s, 1], F[s, 1], minv, C, K0, A, a2)
        for i in range(n):
            q3[i] = q[i] + 0.5 * h * v2[i]
            v3[i] = v[i] + 0.5 * h * a2[i]
        _acceleration(q3, v3, k[s, 1], F[s, 1], minv, C, K0, A, a3)
        for i in range(n):
            q4[i] = q[i] + h * v3[i]
            v4[i] = v[i] + h * a3[i]
        _acceleration(q4, v4, k[s, 2], F[s, 2], minv, C, K0, A, a4)
        for i in range(n):
            q[i] += h / 6.0 * (v[i] + 2 * v2[i] + 2 * v3[i] + v4[i])
            v[i] += h / 6.0 * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i])
    return q, v


def yardstick_cost(model, dt: float, steps: int, repeats: int = 5) -> float:
    """us/step of :func:`yardstick_rk4` on ``model``'s matrices (rows of turning elements frozen at t = 0) with its
    mesh stiffness and torques sampled as the solver samples them, best of ``repeats``."""
    exc = model.excitation
    times = (np.arange(steps)[:, None] + np.array(STAGE_OFFSETS)[None, :]) * dt
    k = exc.stiffness(times, np.array(STAGE_SIDES))
    t_in, t_out = exc.torques(times)
    F = model.F_static + np.multiply.outer(t_in, model.b_input) + np.multiply.outer(t_out, model.b_output)
    minv = 1.0 / np.diag(model.M)
    C, K0, A = model.C + model.G, model.K_b + model.K_frame, np.ascontiguousarray(model.mesh_rows)
    best = np.inf
    for _ in range(repeats):
        q, v = np.zeros(model.n), np.zeros(model.n)
        started = time.perf_counter()
        yardstick_rk4(q, v, dt, minv, C, K0, A, k, F)
        best = min(best, time.perf_counter() - started)
    return 1e6 * best / steps


# ---------------------------------------------------------------------------------------------- solver cost
def solver_cost(model, duration: float, repeats: int = 1):
    """(us/step of the best of ``repeats`` runs, info of the last run)."""
    best, info = np.inf, None
    for _ in range(repeats):
        info = simulate(model, RunSettings(duration)).info
        best = min(best, info.wall_s / info.steps)
    return 1e6 * best, info


def cost_table(title: str, label: str, cases, repeats: int = 1):
    print(f"\n{title}")
    print(f"{label:<22} {'DOF':>4} {'dt [s]':>10} {'steps':>7} {'solver [s]':>10} {'us/step':>8} {'yardstick':>9} "
          f"{'ratio':>6} {'growth':>7}")
    first = None
    rows = []
    for name, spec, duration in cases:
        model = build_model(spec)
        per_step, info = solver_cost(model, duration, repeats)
        yard = yardstick_cost(model, info["dt_s"], info.steps, max(repeats, 3))
        first = first or per_step * info.steps
        print(f"{name:<22} {model.n:>4} {info['dt_s']:>10.4g} {info.steps:>7} {info.wall_s:>10.3f} "
              f"{per_step:>8.2f} {yard:>9.2f} {per_step / yard:>6.2f} {per_step * info.steps / first:>7.2f}")
        rows.append((name, per_step, yard))
    return rows


def loop_and_kernel(model, duration: float, repeats: int = 3) -> tuple[float, float]:
    """(seconds of the RK4 loop of :func:`simulate`, of which in its compiled kernel) on ``model`` over
    ``duration``, from cProfile in one process, the run with the fastest loop of ``repeats``: a machine whose speed
    drifts moves both alike.  The kernel is one Python call a chunk, so the profile costs it nothing."""
    best = (np.inf, np.inf)
    for _ in range(repeats):
        profile = cProfile.Profile()
        profile.runcall(simulate, model, RunSettings(duration))
        stats = pstats.Stats(profile).stats  # (file, line, function) -> (calls, primitive calls, own, cumulative, ...)
        loop = next(v[3] for k, v in stats.items() if k[2] == "_rk4" and k[0].endswith("time_solver.py"))
        kernel = next(v[3] for k, v in stats.items() if k[2] == "rk4_steps")
        best = min(best, (loop, kernel))
    return best


def loop_table(duration: float):
    print(f"\nthe lumped loop against its kernel ({duration:g} s, cProfile in one process; target <= 1.2)")
    print(f"{'preset':<22} {'loop [s]':>9} {'kernel [s]':>10} {'ratio':>6}")
    for name in PRESETS:
        loop, kernel = loop_and_kernel(build_model(load_train(name)), duration)
        print(f"{name:<22} {loop:>9.3f} {kernel:>10.3f} {loop / kernel:>6.2f}")


# ---------------------------------------------------------------------------------------------- equal accuracy
def mesh_force_error(run, reference) -> float:
    a, b = run.select("mesh_force"), reference.select("mesh_force")
    n = min(len(a), len(b))
    return float(np.max(np.abs(a[:n] - b[:n])) / np.max(np.abs(b[:n])))


def equal_accuracy(name: str, duration: float, every: int = 16):
    model = build_model(load_train(name))
    h = default_step(model)
    reference = simulate(model, RunSettings(duration, h / 16, output_dt=every * h))
    rk4 = simulate(model, RunSettings(duration, h, output_dt=every * h))
    target = mesh_force_error(rk4, reference)
    chosen = None
    for rtol in 10.0 ** -np.arange(3.0, 10.01, 0.5):
        run = simulate(model, RunSettings(duration, h, output_dt=every * h), method="RK45", rtol=rtol,
                       atol=1e-9 * rtol)
        error = mesh_force_error(run, reference)
        chosen = (rtol, run, error)
        if error <= target:
            break
    rtol, run, error = chosen
    ratio = run.info.wall_s / rk4.info.wall_s
    print(f"{name:<10} {duration:>6g} {rk4.info.steps:>7} {1e6 * rk4.info.wall_s / rk4.info.steps:>8.2f} "
          f"{rk4.info.wall_s:>9.4f} {target:>9.2e} {rtol:>7.0e} {run.info.rhs_calls:>8} "
          f"{run.info.wall_s:>9.3f} {error:>9.2e} {ratio:>7.1f}")
    return ratio


def accuracy_table(quick: bool):
    print("\nsolve_ivp RK45 at equal accuracy (max mesh-force error over its peak, against RK4 at h/16)")
    print(f"{'train':<10} {'T [s]':>6} {'steps':>7} {'us/step':>8} {'RK4 [s]':>9} {'RK4 err':>9} {'rtol':>7} "
          f"{'RK45 rhs':>8} {'RK45 [s]':>9} {'RK45 err':>9} {'speedup':>7}")
    for name, duration in (("hub-drive", 0.01 if quick else 0.02), ("demo-3p", 0.005 if quick else 0.01)):
        equal_accuracy(name, duration)


# ---------------------------------------------------------------------------------------------- steady state
def steady_state_row(label: str, spec, settle: float = 1e-7, max_periods: int = 400, **options):
    """Shooting (:func:`~gearcheck.lumped.periodic_steady_state.periodic_steady_state`) against time marching from
    the static state: the periods the march takes until its state at a period's end is within ``settle`` of the
    shot state (largest coordinate difference over the largest coordinate), and their wall time."""
    model = build_model(spec)
    try:
        shot = periodic_steady_state(model, **options)
    except SolverError as error:
        print(f"{label:<22} {'-':>9} {'-':>6} {'-':>5} {'-':>9} {'-':>8}   refused: {str(error).split(':')[1].strip()}")
        return
    run = simulate(model, RunSettings(max_periods * shot.period, shot.dt, output_dt=shot.period))
    q = np.array([run.raw[label] for label in model.dofs.labels()]).T
    error = np.max(np.abs(q - shot.q), axis=1) / np.max(np.abs(shot.q))
    settled = np.flatnonzero(error < settle)
    periods = int(settled[0]) if settled.size else None
    march = None if periods is None else run.info.wall_s * periods / (run.t.size - 1)
    marched = "not within the march" if periods is None else \
        f"{periods:>8} {march:>8.3f} {march / shot.info.wall_s:>7.1f}"
    print(f"{label:<22} {shot.period * 1e3:>9.4f} {shot.steps:>6} {shot.method:>6} {shot.residual:>9.1e} "
          f"{shot.runs:>5} {shot.info.wall_s:>8.3f} {marched}")


def steady_state_table():
    print("\nperiodic steady state: shooting (Anderson-accelerated period map, residual 1e-10) against time marching "
          "from the static state until within 1e-7 of it")
    periodic_steady_state(build_model(load_train("demo-3p")))  # the compiled steps loaded
    print(f"{'train':<22} {'T [ms]':>9} {'steps':>6} {'method':>6} {'residual':>9} {'runs':>5} {'shoot [s]':>8} "
          f"{'periods':>8} {'march [s]':>8} {'saving':>7}")
    steady_state_row("demo-3p", load_train("demo-3p"))
    steady_state_row("demo-4p", load_train("demo-4p"))
    steady_state_row("helical-planetary", load_train("helical-planetary"))
    steady_state_row("double-planet", load_train("double-planet"), max_periods=200)
    steady_state_row("demo-3p, backlash", edited("demo-3p", LIGHT_BACKLASH, "light backlash"))
    steady_state_row("2 stages", chained(2), max_periods=30)
    steady_state_row("hub-drive", load_train("hub-drive"))
    steady_state_row("rv-reducer", load_train("rv-reducer"))
    steady_state_row("rv-reducer, 80 periods", load_train("rv-reducer"), max_periods=4, max_mesh_periods=80)


# ---------------------------------------------------------------------------------------------- compile time
COMPILE_PROBE = """
import time
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train
from gearcheck.lumped.time_solver import simulate
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings
walls = []
for name in ("demo-3p", "hub-drive", "rv-reducer", "helical-planetary"):
    model = build_model(load_train(name))
    for _ in range(2):
        started = time.perf_counter()
        simulate(model, RunSettings(2e-4))
        walls.append(time.perf_counter() - started)
print(sum(walls[0::2]) - sum(walls[1::2]))
"""


def compile_table():
    """First-call cost of the compiled steps (first run minus second run on four presets that take every branch
    of the kernel), in fresh processes: with an empty numba cache, then with the cache that run filled."""
    print("\nfirst-call cost of the compiled steps (numba, cache=True), fresh processes")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for label in ("compile (empty cache)", "load (cache filled)"):
            out = subprocess.run([sys.executable, "-c", COMPILE_PROBE], env=env, capture_output=True, text=True,
                                 check=True)
            print(f"{label:<24} {float(out.stdout.split()[-1]):8.2f} s")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    parser.add_argument("--no-compile", action="store_true", help="skip the first-call (compile) measurement")
    args = parser.parse_args()
    scale = 0.5 if args.quick else 1.0
    if not args.no_compile:
        compile_table()
    cost_table("every preset (0.02 s; yardstick: minimal numba RK4 of the same M, C, K(t), F(t), same steps)",
               "preset", [(name, load_train(name), 0.02 * scale) for name in PRESETS], repeats=5)
    loop_table(0.5 * scale)
    accuracy_table(args.quick)
    steady_state_table()
    demo = load_train("demo-3p")
    cost_table("duration (demo-3p at 1500 rpm)", "duration", [(f"{d:g} s", demo, d * scale) for d in (0.05, 0.1, 0.2)])
    cost_table("planets (z = 30/24/78, 0.05 s)", "planets", [(f"{n}", wide_stage(n), 0.05 * scale) for n in (3, 4, 6)])
    cost_table("stages (demo-3p stage chained, 0.05 s)", "stages",
               [(f"{n}", demo if n == 1 else chained(n), 0.05 * scale) for n in (1, 2, 3)]
               + [(f"{n}, radial splines", chained(n, 1e8), 0.05 * scale) for n in (2, 3)])
    helical = [(f"{a:g} um", edited("helical-planetary", [(r"amount_um = 0.0", f"amount_um = {a!r}")], "relief"),
                0.02 * scale) for a in (0.0, 15.0)]
    cost_table("tip relief (helical-planetary, 0.02 s: the relieved meshes' tooth pairs, 20 slices each)",
               "relief", helical)


if __name__ == "__main__":
    main()
