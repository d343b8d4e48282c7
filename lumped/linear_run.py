"""Modes and time runs of a :class:`~gearcheck.lumped.linear_model.LinearModel`, with the train's named signals.

* :func:`linear_modes` -- K_mean x = omega^2 M x (typed like the reference's modes when the model's
  coordinates are the train's), and :func:`linear_modes_at_speed`, the gyroscopic problem with G and
  K_omega (Cooley & Parker 2012); :func:`set_aside` parts the modes that the model's extra coordinates (a
  motor, a coupling: mapped to no train coordinate) dominate from the train's;
* :func:`simulate_linear` -- fixed-step classical RK4 from the static state (or from rest), the
  stiffness, meshes and forcing evaluated at each stage's time;
* :func:`linear_result` -- what the run reports: every coordinate and its acceleration, and, through
  the model's map to the train's coordinates, the train's signals the model has (member accelerations
  in carrier and world axes from :func:`~gearcheck.lumped.member_motion.member_motion`, its meshes'
  force, transmission error, load factor and stiffness).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from gearcheck.lumped.member_motion import member_motion
from gearcheck.lumped.modal import central_coordinates
from gearcheck.lumped.time_solver import rk4_step
from gearcheck.shared import stepping
from gearcheck.shared.errors import DivergenceError
from gearcheck.shared.modal import ModalResult, modal_result, multiplicities, speed_modal_result
from gearcheck.shared.results import TimeResult, coordinate_signals, train_signals
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.units import rad_s_to_rpm
from gearcheck.train.spec import AXIAL

CHUNK = 2000  # steps between progress reports
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


def simulate_linear(model, settings: RunSettings, train=None, progress=None) -> TimeResult:
    """Fixed-step RK4 of the model; ``train`` (spec, kin, dofs of the train, or None) names its signals.
    The step defaults to :func:`default_step`; a step beyond RK4's stability limit is refused."""
    started = time.perf_counter()
    limits = step_limits(model)
    dt = default_step(model) if settings.dt is None else settings.dt
    stepping.check_step(dt, limits, [], f"model {model.name}")
    steps, every = settings.check_work(dt, 3 * model.n, f"model {model.name}")
    M_inv = np.linalg.inv(model.M)
    D = model.damping
    K_omega = model.frame[1]
    A = model.mesh_rows
    t = np.arange(steps + 1) * dt
    stage_t = t[:, None] + np.array(stepping.STAGE_OFFSETS) * dt  # where every fixed-step solver samples its drive
    errors = [m.transmission_error(stage_t) for m in model.meshes]
    k_mesh = _along_last([m.k(stage_t) for m in model.meshes], stage_t.shape)
    e_mesh = _along_last([e for e, _ in errors], stage_t.shape)
    c_de = _along_last([m.damping * de for m, (_, de) in zip(model.meshes, errors)], stage_t.shape)

    def acceleration(ti, s, q, v, k, e, damping_rate):
        stiffness_force = (model.K_at(ti) + K_omega) @ q + A.T @ (k * (A @ q - e) - damping_rate)
        return M_inv @ (model.F_at(ti) - D @ v - stiffness_force)

    q0, v = _start(model)
    q = q0
    n_out = steps // every + 1
    Q, V, Qdd = (np.empty((n_out, model.n)) for _ in range(3))
    for i in range(steps + 1):
        if i % every == 0:
            j = i // every
            Q[j], V[j], Qdd[j] = q, v, acceleration(t[i], 0, q, v, k_mesh[i, 0], e_mesh[i, 0], c_de[i, 0])
        if i == steps:
            break
        q, v = rk4_step(lambda s, q_, v_, i=i: acceleration(stage_t[i, s], s, q_, v_, k_mesh[i, s], e_mesh[i, s],
                                                            c_de[i, s]), q, v, dt)
        if i % CHUNK == 0:
            if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                raise DivergenceError(float(t[i + 1]), f"the RK4 integration of model {model.name} (dt = {dt:g} s)")
            if progress is not None:
                progress(i / steps)
    if not np.all(np.isfinite(Q)):
        raise DivergenceError(float(t[-1]), f"the RK4 integration of model {model.name} (dt = {dt:g} s)")
    if progress is not None:
        progress(1.0)
    wall = time.perf_counter() - started
    info = RunInfo("linear-rk4", steps, 4, 4 * steps, wall,
                   {"method": f"{model.name}, rk4", "dt_s": dt, "steps": steps, "wall_time_s": wall})
    return linear_result(model, train, t[::every], Q, V, Qdd, q0, info)


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
    signals, columns = coordinate_signals(model.coordinates, model.descriptions, model.name,
                                          compared=not mapped), []
    for j in range(model.n):
        columns += [qdd[:, j], q[:, j]]
    static = {}
    if mapped:
        named, values, static = _train_signals(model, train, t, q, v, qdd, q0)
        signals, columns = signals + named, columns + values
    return TimeResult(model.name, model.name, np.asarray(t), signals, np.column_stack(columns), 0.0, info,
                      static=static)


def _train_signals(model, train, t, q, v, qdd, q0):
    """The train's signals the model has: a member's angular acceleration when its rotation is one of the
    model's coordinates, its translational accelerations when both its translations are, and its meshes'."""
    labels = train.physical_dofs.labels()
    T, mapped = model.to_physical(labels)
    has = dict(zip(labels, mapped))
    acc, angle = member_motion(train.spec, train.kin, train.physical_dofs, t, q @ T.T, v @ T.T, qdd @ T.T)
    by_name = {s.name: s for s in train_signals(train.spec)}
    signals, columns = [], []
    for j, (mid, member) in enumerate(train.spec.members.items()):
        u, w, th = (f"{mid}.{d}" for d in member.dofs[:3])
        if has.get(u) and has.get(w):
            c, s = np.cos(angle[:, j]), np.sin(angle[:, j])
            world = (c * acc[:, j, 0] - s * acc[:, j, 1], s * acc[:, j, 0] + c * acc[:, j, 1])
            for axis, x_world, x_carrier in zip("xy", world, acc[:, j, :2].T):
                signals += [by_name[f"{mid}.a{axis}.world"], by_name[f"{mid}.a{axis}.carrier"]]
                columns += [x_world, x_carrier]
        if has.get(th):
            signals.append(by_name[f"{mid}.alpha"])
            columns.append(acc[:, j, 2])
        if member.axial and has.get(f"{mid}.{AXIAL}"):
            signals.append(by_name[f"{mid}.az"])
            columns.append(acc[:, j, 3])
    static = {}
    for m in model.meshes:
        row = np.asarray(m.row, dtype=float)
        k = m.k(t)
        e, de = m.transmission_error(t)
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

