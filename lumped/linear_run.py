"""Modes and time runs of a :class:`~gearcheck.lumped.linear_model.LinearModel`, with the train's named signals.

* :func:`linear_modes` -- K_mean x = omega^2 M x (typed like the reference's modes when the model's
  coordinates are the train's), and :func:`linear_modes_at_speed`, the gyroscopic problem with G and
  K_omega (Cooley & Parker 2012); :func:`set_aside` parts the modes that the model's extra coordinates (a
  motor, a coupling: mapped to no train coordinate) dominate from the train's;
* :func:`simulate_linear` -- fixed-step classical RK4 from the static state (or from rest, or any state), the
  stiffness, meshes and forcing evaluated at each stage's time, its steps compiled (numba) where the stiffness K
  is constant (with a K(t), in Python); :func:`periodic_start`, the state its RK4 map
  returns to after the drive's period, solved exactly (the map is affine);
* :func:`linear_result` -- what the run reports: every coordinate, its velocity and its acceleration, and,
  through the model's map to the train's coordinates, the train's signals the model has (member accelerations,
  displacements and velocities in carrier and world axes, rotations and angular velocities, from
  :func:`~gearcheck.lumped.member_motion.member_motion`, its meshes' force, transmission error, load factor and
  stiffness).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from numba import njit

from gearcheck.lumped.linear_model import Periodic
from gearcheck.lumped.member_motion import member_motion
from gearcheck.lumped.modal import central_coordinates
from gearcheck.lumped.time_solver import rk4_step
from gearcheck.shared import stepping
from gearcheck.shared.blas import one_blas_thread
from gearcheck.shared.errors import DivergenceError, UnsupportedError
from gearcheck.shared.modal import ModalResult, modal_result, multiplicities, speed_modal_result
from gearcheck.shared.results import TimeResult, coordinate_signals, member_columns, train_signals
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.units import rad_s_to_rpm
from gearcheck.train.periods import whole_cycles
from gearcheck.train.spec import AXIAL, TILTS

CHUNK = 2000  # steps between progress reports
PERIOD_LIMIT = 64  # the longest common period sought, in multiples of the longest periodic part's
SINGULAR = 1e-12  # I - Phi closer than this (1 / condition number) to singular has no unique periodic state
EXTRA_DOMINATED = 0.5  # a mode with more of its kinetic energy in the extra coordinates is theirs, not the train's


def _typing(model, train) -> tuple:
    """(translation, rotation) indices for Lin & Parker's mode types: the model's coordinates that are the
    central members' own; (None, None) when it has none (then modes are rigid or elastic)."""
    if train is None:
        return None, None
    known = set(train.physical_dofs.labels())
    translation, rotation = central_coordinates(train.spec, [c if c in known else "" for c in model.coordinates])
    return (translation, rotation) if translation or rotation else (None, None)


def linear_modes(model, train=None) -> ModalResult:
    """Natural frequencies and shapes at mean stiffness, over the model's own coordinates."""
    return modal_result(train.spec.name if train else model.name, model.name, model.K_mean, model.M,
                        model.coordinates, *_typing(model, train))


def linear_modes_at_speed(model, train, input_speed: float) -> ModalResult:
    """The gyroscopic modes at ``input_speed`` (rad/s), G and K_omega at that speed
    (:meth:`~gearcheck.lumped.linear_model.LinearModel.frame_terms`)."""
    G, K_omega = model.frame_terms(input_speed)
    return speed_modal_result(train.spec.name, model.name, model.M, G, model.K_mean + 0.5 * (K_omega + K_omega.T),
                              model.coordinates,
                              *_typing(model, train), rad_s_to_rpm(input_speed))


def set_aside(model, modal: ModalResult) -> tuple[ModalResult, list[float]]:
    """(the modes of ``modal`` that are the train's, the frequencies in Hz of those set aside): a mode with more
    than ``EXTRA_DOMINATED`` of its kinetic energy phi^H M_ee phi / phi^H M phi in the model's extra coordinates
    (:attr:`~gearcheck.lumped.linear_model.LinearModel.extra`) has no counterpart in the train."""
    extra = [model.coordinates.index(c) for c in model.extra]
    if not extra:
        return modal, []
    phi, M = modal.shapes, model.M
    total = np.real(np.einsum("ip,ij,jp->p", phi.conj(), M, phi))
    part = np.real(np.einsum("ip,ij,jp->p", phi[extra].conj(), M[np.ix_(extra, extra)], phi[extra]))
    aside = part > EXTRA_DOMINATED * total
    keep = np.flatnonzero(~aside)
    kept = replace(modal, frequencies=modal.frequencies[keep], shapes=modal.shapes[:, keep],
                   types=[modal.types[i] for i in keep], multiplicity=multiplicities(modal.frequencies[keep]),
                   fractions=None if modal.fractions is None else modal.fractions[keep],
                   growth=None if modal.growth is None else modal.growth[keep],
                   stability=None if modal.stability is None else [modal.stability[i] for i in keep])
    return kept, [float(f) for f in modal.frequencies[aside]]


def step_limits(model) -> stepping.StepLimits:
    return stepping.StepLimits.of(model.M, model.K_peak(), model.damping)


def default_step(model) -> float:
    periods = [m.stiffness.period for m in model.meshes if hasattr(m.stiffness, "period")]
    if model.stiffness is not None:
        periods.append(model.stiffness.period)
    return stepping.default_step(step_limits(model), [1.0 / p for p in periods])


@one_blas_thread
def simulate_linear(model, settings: RunSettings, train=None, progress=None, y0=None) -> TimeResult:
    """Fixed-step RK4 of the model from ``y0`` (q, q') or its own start; ``train`` (spec, kin, dofs of the train, or
    None) names its signals.  The step defaults to :func:`default_step`; a step beyond RK4's stability limit is
    refused."""
    started = time.perf_counter()
    limits = step_limits(model)
    dt = default_step(model) if settings.dt is None else settings.dt
    stepping.check_step(dt, limits, [], f"model {model.name}")
    steps, every = settings.check_work(dt, 3 * model.n, f"model {model.name}")
    t = np.arange(steps + 1) * dt
    rates = _rates(model, t[:, None] + np.array(stepping.STAGE_OFFSETS) * dt)
    q0, v = _start(model) if y0 is None else (np.array(y0[0], dtype=float), np.array(y0[1], dtype=float))
    q, v = q0.copy(), v.copy()
    n_out = steps // every + 1
    Q, V, Qdd = (np.empty((n_out, model.n)) for _ in range(3))
    for first in range(0, steps, CHUNK):
        last = min(first + CHUNK, steps)
        if rates.chunk is not None:
            _rk4_steps(q, v, dt, first, last, every, *rates.chunk(first, last), Q, V, Qdd)
        else:
            for i in range(first, last):
                if i % every == 0:
                    Q[i // every], V[i // every], Qdd[i // every] = q, v, rates(i, 0, q[:, None], v[:, None])[:, 0]
                q, v = rk4_step(lambda s, q_, v_, i=i: rates(i, s, q_[:, None], v_[:, None])[:, 0], q, v, dt)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
            raise DivergenceError(float(t[last]), f"the RK4 integration of model {model.name} (dt = {dt:g} s)")
        if progress is not None:
            progress(first / steps)
    if steps % every == 0:
        Q[-1], V[-1], Qdd[-1] = q, v, rates(steps, 0, q[:, None], v[:, None])[:, 0]
    if not np.all(np.isfinite(Q)):
        raise DivergenceError(float(t[-1]), f"the RK4 integration of model {model.name} (dt = {dt:g} s)")
    if progress is not None:
        progress(1.0)
    wall = time.perf_counter() - started
    info = RunInfo("linear-rk4", steps, 4, 4 * steps, wall,
                   {"method": f"{model.name}, rk4", "dt_s": dt, "steps": steps, "wall_time_s": wall})
    return linear_result(model, train, t[::every], Q, V, Qdd, _start(model)[0], info)


def _rates(model, stage_t: np.ndarray):
    """q'' = M^-1 (f(t) - D q' - (K(t) + K_omega + sum_m k_m(t) a_m a_m^T) q) at the stage times ``stage_t``
    (steps x stages, each read at its one-sided limit, :data:`~gearcheck.shared.stepping.STAGE_SIDES`):
    ``rates(i, s, Q, V)`` for states as the columns of Q, V, the forcing f(t) = F(t) +
    sum_m a_m (k_m e_m + c_m e_m') acting on the last column alone -- one column is a run; the unit states
    beside a last zero one give a period's monodromy matrix and its particular response.  M^-1 is applied to
    each matrix once, not at every stage.  ``rates.chunk(first, last)``: the arrays of a run's compiled steps
    (:func:`_rk4_steps`), None where the stiffness K(t) varies (its stages then run in Python)."""
    M_inv = np.linalg.inv(model.M)
    K_omega = model.frame[1]
    A = model.mesh_rows
    MD, MA = M_inv @ model.damping, M_inv @ A.T
    MK = M_inv @ (model.matrix("K") + K_omega) if model.stiffness is None else None
    MF = M_inv @ model.matrix("F") if model.forcing is None else None
    sides = np.broadcast_to(stepping.STAGE_SIDES, stage_t.shape)
    errors = [m.transmission_error(stage_t, sides) for m in model.meshes]
    k_mesh = _along_last([m.k(stage_t, sides) for m in model.meshes], stage_t.shape)
    mesh_forcing = k_mesh * _along_last([e for e, _ in errors], stage_t.shape) + _along_last(
        [m.damping * de for m, (_, de) in zip(model.meshes, errors)], stage_t.shape)

    def rates(i, s, Q, V):
        ti, side = stage_t[i, s], stepping.STAGE_SIDES[s]
        stiffness = MK if MK is not None else M_inv @ (model.K_at(ti, side) + K_omega)
        out = -(MD @ V) - stiffness @ Q - MA @ (k_mesh[i, s][:, None] * (A @ Q))
        out[:, -1] += (MF if MF is not None else M_inv @ model.F_at(ti, side)) + MA @ mesh_forcing[i, s]
        return out

    def chunk(first, last):
        """The arrays of :func:`_rk4_steps` over steps ``first`` to ``last``: the matrices, the meshes' stiffness
        and the forcing M^-1 f(t) at the stage times."""
        times = stage_t[first:last]
        F = MF if MF is not None else np.array([model.F_at(t, side) for t, side in zip(
            times.ravel(), sides[first:last].ravel())]).reshape(
            *times.shape, model.n) @ M_inv.T
        return (MD, MK, MA, A, np.ascontiguousarray(k_mesh[first:last]), F + mesh_forcing[first:last] @ MA.T,
                np.empty(A.shape[0]), np.empty((4, model.n)))

    rates.chunk = chunk if MK is not None else None
    return rates


@njit(cache=True)
def _acceleration(r, s, q, v, MD, MK, MA, A, k_mesh, force, w, out):
    """``rates`` of :func:`_rates` for one run with K constant, into ``out``: q'' = force[r, s] - M^-1 D q'
    - M^-1 K q - M^-1 A^T w, w_m = k_m a_m.q at stage s of the chunk's step r."""
    n = q.size
    for m in range(A.shape[0]):
        x = 0.0
        for c in range(n):
            x += A[m, c] * q[c]
        w[m] = k_mesh[r, s, m] * x
    for i in range(n):
        x = force[r, s, i]
        for c in range(n):
            x -= MD[i, c] * v[c] + MK[i, c] * q[c]
        for m in range(A.shape[0]):
            x -= MA[i, m] * w[m]
        out[i] = x


@njit(cache=True)
def _rk4_steps(q, v, h, first, last, every, MD, MK, MA, A, k_mesh, force, w, acc, Q, V, Qdd):
    """Steps ``first`` to ``last`` of :func:`simulate_linear`'s RK4 (the stages of
    :func:`~gearcheck.lumped.time_solver.rk4_step`) compiled, q and v updated in place, the state of every
    ``every``-th step written to Q, V, Qdd; the drive (``k_mesh``, ``force``) is the chunk's."""
    terms = (MD, MK, MA, A, k_mesh, force, w)
    for i in range(first, last):
        r = i - first
        if i % every == 0:
            Q[i // every] = q
            V[i // every] = v
            _acceleration(r, 0, q, v, *terms, Qdd[i // every])
        _acceleration(r, 0, q, v, *terms, acc[0])
        q2, v2 = q + 0.5 * h * v, v + 0.5 * h * acc[0]
        _acceleration(r, 1, q2, v2, *terms, acc[1])
        q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * acc[1]
        _acceleration(r, 1, q3, v3, *terms, acc[2])
        q4, v4 = q + h * v3, v + h * acc[2]
        _acceleration(r, 2, q4, v4, *terms, acc[3])
        q[:] = q + h / 6.0 * (v + 2 * v2 + 2 * v3 + v4)
        v[:] = v + h / 6.0 * (acc[0] + 2 * acc[1] + 2 * acc[2] + acc[3])


def drive_period(model) -> float:
    """The shortest time over which every time-varying part of ``model`` repeats (each mesh's stiffness and
    transmission error, K(t), F(t)), at most :data:`PERIOD_LIMIT` times the longest of their periods;
    UnsupportedError when nothing varies, a forcing has no period, or the periods have no such common one."""
    periods = [m.stiffness.period for m in model.meshes if isinstance(m.stiffness, Periodic)]
    periods += [m.error.period for m in model.meshes if m.error is not None]
    periods += [model.stiffness.period] if model.stiffness is not None else []
    if model.forcing is not None:
        if getattr(model.forcing, "period", None) is None:
            raise UnsupportedError(f"model {model.name}: its forcing is a function of time without a period")
        periods.append(model.forcing.period)
    if not periods:
        raise UnsupportedError(f"model {model.name}: nothing in it varies with time")
    base = max(periods)
    for k in range(1, PERIOD_LIMIT + 1):
        if whole_cycles(k * base / np.array(periods)):
            return k * base
    raise UnsupportedError(f"model {model.name}: its periods {', '.join(f'{p:.6g}' for p in sorted(set(periods)))} s "
                           f"have no common period within {PERIOD_LIMIT} of the longest")


def periodic_start(model, dt: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(q, q', h, residual): the state the model's RK4 map at step h returns to after one drive period
    (:func:`drive_period`, h = T / ceil(T / dt)), found exactly: the map is affine, y(T) = Phi y0 + p, so the
    state solves (I - Phi) y0 = p, Phi and p from one pass over the period carrying the 2n unit states and the
    particular one side by side (:func:`_rates`); ``residual`` |y(T) - y0| / |y0| of the fixed point.  A mode
    that neither decays nor is forced away (a free rigid rotation, an undamped mode) leaves I - Phi singular:
    UnsupportedError."""
    T = drive_period(model)
    steps = max(1, math.ceil(T / dt - 1e-9))
    h, n = T / steps, model.n
    rates = _rates(model, (np.arange(steps)[:, None] + np.array(stepping.STAGE_OFFSETS)) * h)
    Q = np.hstack([np.eye(n), np.zeros((n, n + 1))])
    V = np.hstack([np.zeros((n, n)), np.eye(n), np.zeros((n, 1))])
    for i in range(steps):
        Q, V = rk4_step(lambda s, q_, v_, i=i: rates(i, s, q_, v_), Q, V, h)
    Phi, p = np.vstack([Q[:, :-1], V[:, :-1]]), np.concatenate([Q[:, -1], V[:, -1]])
    gap = np.eye(2 * n) - Phi
    if np.linalg.cond(gap) > 1.0 / SINGULAR:
        raise UnsupportedError(f"model {model.name}: a mode neither decays nor is driven over the period (a free "
                               "rotation, an undamped mode): no unique periodic state")
    y0 = np.linalg.solve(gap, p)
    residual = float(np.linalg.norm(Phi @ y0 + p - y0) / max(np.linalg.norm(y0), 1e-300))
    return y0[:n], y0[n:], h, residual


def _along_last(values: list, shape: tuple) -> np.ndarray:
    """Per-mesh arrays over the times of ``shape``, stacked with the meshes along the last axis."""
    return np.moveaxis(np.reshape(values, (len(values), *shape)), 0, -1)


def _start(model) -> tuple[np.ndarray, np.ndarray]:
    """(q, q') at t = 0: at rest, or the static state K_mean q = F (least squares where rigid modes leave it
    undetermined: the minimum-norm solution)."""
    zero = np.zeros(model.n)
    if model.start == "rest":
        return zero, zero
    K_omega = model.frame[1]
    q, *_ = np.linalg.lstsq(model.K_mean + K_omega, model.matrix("F"), rcond=None)
    return q, zero


def linear_result(model, train, t, q, v, qdd, q0, info) -> TimeResult:
    """The named signals of a run (see the module docstring); ``q0`` its starting state, whose mesh forces are
    the static ones the load factor divides by."""
    mapped = train is not None and bool(model.physical_map())
    signals = coordinate_signals(model.coordinates, model.descriptions, model.name, compared=not mapped)
    columns, static = [], {}
    if mapped:
        named, columns, static = _train_signals(model, train, t, q, v, qdd, q0, {s.name for s in signals})
        signals = signals + named
    values = np.empty((len(t), 3 * model.n + len(columns)))
    for k, x in enumerate((qdd, q, v)):  # per coordinate its acceleration, displacement and velocity
        values[:, k:3 * model.n:3] = x
    for j, column in enumerate(columns, start=3 * model.n):
        values[:, j] = column
    return TimeResult(model.name, model.name, np.asarray(t), signals, values, 0.0, info, static=static)


def _train_signals(model, train, t, q, v, qdd, q0, taken=frozenset()):
    """The train's signals the model has (but those named in ``taken``, its coordinates' own): a member's rotation
    signals (:func:`~gearcheck.shared.results.member_columns`) when its rotation is one of the model's coordinates,
    its translation signals when both its translations are, its axial ones when its axial coordinate is, its tilts
    when both its tilts are, and its meshes'."""
    labels = train.physical_dofs.labels()
    T, mapped = model.to_physical(labels)
    has = dict(zip(labels, mapped))
    motion = member_motion(train.spec, train.kin, train.physical_dofs, t, q @ T.T, v @ T.T, qdd @ T.T)
    by_name = {s.name: s for s in train_signals(train.spec)}
    signals, columns = [], []
    for j, (mid, member) in enumerate(train.spec.members.items()):
        u, w, th = (f"{mid}.{d}" for d in member.dofs[:3])
        wanted = {"translation": has.get(u) and has.get(w), "rotation": has.get(th),
                  "axial": member.axial and has.get(f"{mid}.{AXIAL}"),
                  "tilt": member.tilting and all(has.get(f"{mid}.{d}") for d in TILTS[member.frame])}
        if not any(wanted.values()):
            continue
        for group, named in member_columns(mid, motion(j)).items():
            for name, x in named.items() if wanted[group] else ():
                if name not in taken:
                    signals.append(by_name[name])
                    columns.append(x)
    static = {}
    for m in model.meshes:
        row = np.asarray(m.row, dtype=float)
        k = m.k(t, stepping.STAGE_SIDES[0])  # the drive of the step that starts at t, as the stages read it
        e, de = m.transmission_error(t, stepping.STAGE_SIDES[0])
        delta = q @ row
        force = k * (delta - e) + m.damping * (v @ row - de)
        static_force = m.k_mean * float(row @ q0)
        static[f"{m.id}.force"] = static_force
        signals += [by_name[f"{m.id}.{x}"] for x in ("force", "dte", "kv", "stiffness")]
        columns += [force, delta, force / static_force if static_force else np.full_like(force, np.nan), k]
    return signals, columns, static


def unmapped(model, train) -> list[str]:
    """The train's gated signals the model does not report."""
    have = set(_names(model, train))
    return [s.name for s in train_signals(train.spec) if s.compared and s.name not in have]


def _names(model, train) -> list[str]:
    one = np.zeros((1, model.n))
    return [s.name for s in _train_signals(model, train, np.zeros(1), one, one, one, one[0])[0]]

