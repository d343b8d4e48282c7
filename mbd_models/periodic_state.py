"""The periodic steady state of the MuJoCo twin by shooting on its own runs, where the train's drive has a period.

The second derivation of :mod:`gearcheck.lumped.periodic_steady_state`, from the twin's own state and steps.  The
twin works in world coordinates: its hinges turn at their nominal speeds
(:func:`~gearcheck.mbd_models.static_state.nominal_speeds`) and its mesh tendons' world-frame slide coefficients
turn with the carriers' angles.  Its equations therefore repeat after T_M, the shortest whole multiple of the
drive's period T (:func:`gearcheck.train.periods.common_period`) over which every carrier turns whole revolutions
(at most ``MAX_DRIVE_PERIODS`` periods; 1200 rpm and a 40 Hz ripple: T = 25 ms, T_M = 50 ms).  A run of T_M
(:func:`~gearcheck.mbd_models.runner.simulate_mujoco`, RK4 with a step that divides T_M) from y0 = (qpos, qvel)
ends at Phi(y0); the period map is P(y0) = S(Phi(y0)), S taking every joint's nominal advance (speed times T_M)
off its position.  The input servo's activation, its reference angle, starts every run at 0: the reference
advances by w_in T_M exactly, as the input hinge's nominal angle does.  The steady state is the fixed point
y0 = P(y0), found from the twin's static state (:func:`~gearcheck.mbd_models.static_state.static_state`) by
Anderson acceleration (Walker & Ni 2011, :func:`gearcheck.shared.anderson.anderson`), one run an iteration, to a
residual of ``TOLERANCE`` = 1e-8.  The lumped side's 1e-10 is below the round-off of world-frame angles: a hinge
turned to |theta| over the steps of a period carries errors of order |theta| eps sqrt(steps), on double-planet a
residual floor of 2-5e-10, near which Anderson acceleration stalls (asked for 1e-9 there, it spent 6 of its 14
runs between 6e-9 and 7e-10).  1e-8 stands 20-50 times above that floor; the start it leaves lies within 1e-8 of
the first guess's deviation from the nominal motion off the orbit, which moved double-planet's cross-check errors
by at most 1.3e-3 of their tolerances against the start shot to 1e-9.  A run
``simulate_mujoco(mb, RunSettings(duration, dt=result.dt), initial_state=result.initial_state)`` is steady from
t = 0.  Measured (compiled runner, a shared 2-core machine): double-planet 8 runs of 57173 steps, 10 s, where
its 2.45 s transient would take about 49 such periods of time marching; demo-3p (T_M = 62 mesh periods, over which
its 5 % mesh damping leaves nothing of the start) 2 runs, 2.8 s.

Refused (:class:`~gearcheck.shared.errors.SolverError`, saying why): a drive without a period, carriers that do not
turn whole revolutions within the bound, a twin whose pin contacts follow the bodies' poses (an RV reducer's: its
contact geometry repeats only with the discs' and pins' own turns), and shooting that does not converge.
"""

from __future__ import annotations

import math
import time as clock
from dataclasses import dataclass

import mujoco
import numpy as np

from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.static_state import StaticState, nominal_speeds, static_state
from gearcheck.mbd_models.twin import MbdModel
from gearcheck.shared import stepping
from gearcheck.shared.anderson import anderson
from gearcheck.shared.errors import SolverError
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.shooting import Shooting
from gearcheck.train.periods import MAX_MESH_PERIODS, common_period, whole_cycles

MAX_DRIVE_PERIODS = 256  # the longest T_M sought, in drive periods: a carrier turns once in z_ring mesh periods
MAX_ANDERSON_RUNS = 100
TOLERANCE = 1e-8  # on the residual, 20-50 times the round-off floor of world-frame angles


@dataclass(frozen=True)
class PeriodicState(Shooting):
    """The twin's state at t = 0 of its T_M-periodic steady response and how it was found (:class:`Shooting`;
    method "anderson"; the residual max |P(y0) - y0| over the largest |y0 - nominal motion| of the first guess,
    qvel weighted by 1/omega_max).

    qpos, qvel: pass ``initial_state`` to :func:`~gearcheck.mbd_models.runner.simulate_mujoco` with ``dt``."""

    qpos: np.ndarray
    qvel: np.ndarray

    @property
    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        return self.qpos, self.qvel


def twin_period(mb: MbdModel, max_mesh_periods: int = MAX_MESH_PERIODS) -> float:
    """T_M: the shortest whole multiple of the drive's period over which every carrier turns whole revolutions, at
    most ``MAX_DRIVE_PERIODS`` periods; :class:`SolverError` when there is none."""
    period = common_period(mb.excitation, max_mesh_periods)
    spec = mb.spec
    carriers = sorted({spec.stage_of(mid).carrier for mid in spec.members})
    turns = np.array([abs(mb.kin.speeds[c]) / (2 * math.pi) for c in carriers])
    for p in range(1, MAX_DRIVE_PERIODS + 1):
        if whole_cycles(turns * p * period):
            return p * period
    listed = ", ".join(f"{c} {f:.10g} Hz" for c, f in zip(carriers, turns))
    raise SolverError(f"{spec.name}: the carriers ({listed}) turn no whole number of revolutions within "
                      f"{MAX_DRIVE_PERIODS} periods of the drive ({period:.10g} s): the twin's world-frame equations "
                      "have no period to shoot for; time-march with a settle time (RunSettings.settle) instead")


def nominal_advance(mb: MbdModel, duration: float) -> np.ndarray:
    """(nq,) how far each joint's position moves in ``duration`` of the rigid train's nominal motion."""
    m = mb.model
    if np.any((m.jnt_type != mujoco.mjtJoint.mjJNT_HINGE) & (m.jnt_type != mujoco.mjtJoint.mjJNT_SLIDE)):
        raise SolverError(f"{mb.spec.name}: the twin has a joint that is neither a hinge nor a slide")
    advance = np.zeros(m.nq)
    advance[m.jnt_qposadr] = nominal_speeds(mb)[m.jnt_dofadr] * duration
    return advance


def periodic_state(mb: MbdModel, dt: float | None = None, tolerance: float = TOLERANCE, initial_state=None,
                   max_mesh_periods: int = MAX_MESH_PERIODS, engine: str = "auto",
                   static: StaticState | None = None) -> PeriodicState:
    """The T_M-periodic steady state of the twin ``mb`` (see the module docstring).

    dt: the RK4 step, made a whole fraction of T_M (default: ``mb.default_step``, rounded down to one); tolerance:
    on the residual; initial_state: the first guess (qpos, qvel) (default: the static state); max_mesh_periods: the
    longest drive period sought (:func:`~gearcheck.train.periods.common_period`); engine: the runner's; static:
    the twin's static state where the caller has it (found here otherwise), which every run of the shooting shares.
    Raises SolverError where there is no period, for a twin with moving contacts, and where Anderson acceleration
    has not converged in ``MAX_ANDERSON_RUNS`` runs."""
    name = mb.spec.name
    if mb.moving_contacts:
        raise SolverError(f"{name}: the twin's pin contacts follow the bodies' poses, which repeat only with the "
                          "discs' and pins' own turns: no MuJoCo periodic state is shot for it; time-march with a "
                          "settle time (RunSettings.settle) instead")
    started = clock.perf_counter()
    period = twin_period(mb, max_mesh_periods)
    h = mb.default_step if dt is None else dt
    stepping.check_step(h, mb.limits, mb.excitation.frequency, f"MuJoCo model of {name}")
    steps = max(1, math.ceil(period / h - 1e-9))
    h = period / steps
    advance, nominal = nominal_advance(mb, period), nominal_speeds(mb)
    static = static_state(mb) if static is None else static
    if initial_state is None:
        initial_state = static.qpos, static.qvel
    qpos0, qvel0 = (np.asarray(x, dtype=float) for x in initial_state)
    nq = qpos0.size
    # the map on the deviation from nominal motion, qvel over omega_max, both over the first guess's largest
    w = np.concatenate([np.ones(nq), np.full(qvel0.size, 1.0 / mb.omega_max)])
    offset = np.concatenate([np.zeros(nq), nominal])
    scale = float(np.max(np.abs(w * (np.concatenate([qpos0, qvel0]) - offset)))) or 1e-6
    runs = []

    def period_map(z: np.ndarray) -> np.ndarray:
        y = z * scale / w + offset
        result, (qpos, qvel, _) = simulate_mujoco(mb, RunSettings(period, dt=h, output_dt=period),
                                               initial_state=(y[:nq], y[nq:]), engine=engine, return_state=True,
                                               static=static)
        runs.append(result.info)
        return (np.concatenate([qpos - advance, qvel]) - offset) * w / scale

    z0 = (np.concatenate([qpos0, qvel0]) - offset) * w / scale
    z, residual, iterations = anderson(period_map, z0, tolerance, MAX_ANDERSON_RUNS)
    if residual > tolerance:
        raise SolverError(f"{name}: shooting on the MuJoCo twin did not converge (residual {residual:.3g} > "
                          f"{tolerance:g} after {len(runs)} period runs); time-march with a settle time "
                          "(RunSettings.settle) instead")
    y = z * scale / w + offset
    info = RunInfo(runs[0].engine, sum(r.steps for r in runs), 4, sum(r.rhs_calls for r in runs),
                   clock.perf_counter() - started, {"method": "anderson", "dt_s": h, "steps": len(runs) * steps})
    return PeriodicState(qpos=y[:nq].copy(), qvel=y[nq:].copy(), period=period, dt=h, steps=steps, method="anderson",
                         iterations=iterations, residual=residual, runs=len(runs), info=info)
