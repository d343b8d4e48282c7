"""Time response of the reference model: fixed-step RK4 and scipy's adaptive integrators.

Equation of motion (rotating frame, see :mod:`gearcheck.lumped.assembly`):

    M q'' = F_static + b_in T_in(t) + b_out T_out(t) - (C_b + G) q' - (K_b + K_frame) q
            - sum_m a_m [k_m(t) f(a_m.q - e_m(t)) + c_m (a_m.q' - e_m'(t))],

f the backlash dead zone.  The start is the static deflection under the mean load
(``ramp_s`` = 0) or the unloaded state with the load ramped in.

Time step: :mod:`gearcheck.shared.stepping` (the rule the MuJoCo runner follows too), from the
highest natural frequency of this model with every mesh at its cycle-maximum stiffness.
The drive is sampled at t + h (eps, 1/2, 1 - eps) (:data:`~gearcheck.shared.stepping.STAGE_OFFSETS`).
By default (``drive="steps"``) RK4's first stage sees x(t + eps) and the other three
(4 x(t + h/2) + x(t + h - eps))/5, exactly as the MuJoCo runner drives its model
(:func:`~gearcheck.shared.stepping.per_step_drive`): exact for drives linear over a step.  A step
inside which a mesh stiffness jumps is split there (:func:`~gearcheck.shared.stepping.split_steps`, as
the MuJoCo runner does), so the stiffness is constant over every sub-step and RK4 keeps its order.
``drive="stages"`` is the textbook RK4 with the drive at each stage's own time.
"""

from __future__ import annotations

import time as clock

import numpy as np
from scipy.integrate import solve_ivp

from gearcheck.lumped.cycloid_rows import CycloidRows
from gearcheck.lumped.member_motion import member_motion
from gearcheck.lumped.static import mean_load, static_solution
from gearcheck.shared import divergence, stepping
from gearcheck.shared.contact_laws import deadzone
from gearcheck.shared.errors import DivergenceError, SolverError
from gearcheck.shared.results import TimeResult, bearing_names, train_result
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import STAGE_OFFSETS, per_step_drive, per_step_pairs

CHUNK = 20000
ADAPTIVE_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


def step_limits(model) -> stepping.StepLimits:
    """The RK4 step limits of the model with every mesh at its largest stiffness over a cycle, damping,
    gyroscopic and rotating-frame terms included."""
    K = model.K_b + model.K_mesh(model.excitation.max_stiffness) + model.K_frame
    return stepping.StepLimits.of(model.M, K, model.C + model.G)


def stable_step(model) -> float:
    return stepping.stable_step(step_limits(model))


def default_step(model) -> float:
    """:func:`gearcheck.shared.stepping.default_step` for this model."""
    return stepping.default_step(step_limits(model), model.excitation.frequency)


class _System:
    """Right-hand side pieces of one model, vectorised over time where possible."""

    def __init__(self, model):
        self.model = model
        self.exc = model.excitation
        self.Minv = 1.0 / np.diag(model.M)
        self.D = model.C_b + model.G
        self.Kc = model.K_b + model.K_frame
        self.turning = model.turning
        for coupling in self.turning:  # their t = 0 rows give way to the time-periodic forces
            for row in model.rows:
                if row.name in coupling.rows:
                    self.Kc = self.Kc - row.stiffness * np.outer(row.a, row.a)
                    self.D = self.D - row.damping * np.outer(row.a, row.a)
        self.A = model.mesh_rows
        self.c = model.mesh_damping
        self.b = 0.5 * self.exc.backlash
        self.has_backlash = bool(np.any(self.b > 0))
        self.relieved = self.exc.relieved
        self.has_relief = bool(self.relieved.size)
        self.F0 = model.F_static
        self.b_in, self.b_out = model.b_input, model.b_output

    def drive(self, t):
        """Excitation at times t: (k, e, de, T_in, T_out, pairs), arrays with time along axis 0; ``pairs``
        the relieved meshes' tooth pairs (k_j, e_j), or None."""
        k = self.exc.stiffness(t)
        e, de = self.exc.transmission_error(t)
        t_in, t_out = self.exc.torques(t)
        kp, ep = self.exc.tooth_pairs(t)
        return k, e, de, t_in, t_out, None if kp is None else np.stack([kp, ep], axis=-1)

    def mesh_force(self, q, v, k, e, de, pairs=None):
        """Mesh deflections and forces for one state (1-D) or many (time along axis 0); a relieved mesh's
        elastic force is that of its tooth pairs, sum_j k_j max(0, delta - e - e_j)."""
        delta = q @ self.A.T
        elastic = k * (deadzone(delta - e, self.b) if self.has_backlash else delta - e)
        if pairs is not None:
            r = self.relieved
            gap = (delta - e)[..., r, None] - pairs[..., 1]
            elastic[..., r] = np.sum(pairs[..., 0] * np.maximum(gap, 0.0), axis=-1)
        return delta, elastic + self.c * (v @ self.A.T - de)

    def contact_stiffness(self, q, k, e, pairs):
        """The mesh stiffness in effect: k, or for a relieved mesh the sum over its pairs in contact."""
        if pairs is None:
            return k
        k = k.copy()
        gap = (q @ self.A.T - e)[..., self.relieved, None] - pairs[..., 1]
        k[..., self.relieved] = np.sum(pairs[..., 0] * (gap > 0.0), axis=-1)
        return k

    def acceleration(self, q, v, k, e, de, t_in, t_out, t=0.0, pairs=None):
        """q'' for one state (1-D) or many (time along axis 0, the torques then as columns)."""
        _, f = self.mesh_force(q, v, k, e, de, pairs)
        force = self.F0 + self.b_in * t_in + self.b_out * t_out - v @ self.D.T - q @ self.Kc.T - f @ self.A
        for coupling in self.turning:
            force = force + coupling.forces(t, q, v)
        return force * self.Minv

    def load(self, k, e, de, t_in, t_out):
        """The state-independent part of the generalized force while every mesh is on its drive flank
        (delta - e > b, where the dead zone is delta - e - b): F0 + b T + A^T (k (e + b) + c de)."""
        force = self.F0 + np.multiply.outer(t_in, self.b_in) + np.multiply.outer(t_out, self.b_out)
        return force + (k * (e + self.b) + self.c * de) @ self.A

    def on_drive_flanks(self, q, e) -> bool:
        return bool(np.all(self.A @ q - e > self.b))


class _LinearStep:
    """One RK4 step of the linear model y' = J y + g(t), y = (q, v), written as a matrix map.

    With the mesh stiffness k the same at the three stage times, RK4 gives exactly
    y_{n+1} = P y_n + Q_1 g(t) + Q_2 g(t + h/2) + Q_3 g(t + h) with (hJ = Z)
    P = I + Z + Z^2/2 + Z^3/6 + Z^4/24,  Q_1 = h/6 (I + Z + Z^2/2 + Z^3/4),
    Q_2 = h/6 (4 I + 2 Z + Z^2/2),  Q_3 = h/6 I,
    so a step costs four matrix-vector products instead of four right-hand sides.  The maps
    are cached per stiffness vector (a rectangular stiffness takes a few values per cycle).
    With backlash the map holds while every mesh stays on its drive flank; a step that starts or
    ends off it, or crosses a stiffness switch, takes the stage-by-stage path.
    """

    def __init__(self, sys: _System, h: float):
        self.sys, self.h = sys, h
        self.cache: dict[bytes, tuple] = {}

    def maps(self, k: np.ndarray):
        key = k.tobytes()
        if key not in self.cache:
            s, n, h = self.sys, self.sys.Minv.size, self.h
            K = s.Kc + s.A.T @ (k[:, None] * s.A)
            D = s.D + s.A.T @ (s.c[:, None] * s.A)
            J = np.block([[np.zeros((n, n)), np.eye(n)], [-s.Minv[:, None] * K, -s.Minv[:, None] * D]])
            Z = h * J
            I = np.eye(2 * n)
            Z2 = Z @ Z
            Z3 = Z2 @ Z
            P = I + Z + Z2 / 2 + Z3 / 6 + Z3 @ Z / 24
            to_v = np.vstack([np.zeros((n, n)), np.diag(s.Minv)])  # g = (0, M^-1 F)
            Q1 = h / 6 * (I + Z + Z2 / 2 + Z3 / 4) @ to_v
            Q2 = h / 6 * (4 * I + 2 * Z + Z2 / 2) @ to_v
            Q3 = h / 6 * to_v
            self.cache[key] = (P, Q1, Q2, Q3, Q2 + Q3)
        return self.cache[key]


def initial_state(model) -> tuple[np.ndarray, np.ndarray]:
    """Static deflection under the mean load, or the unloaded state when the load is ramped."""
    scale = 0.0 if model.spec.operating.ramp > 0 else 1.0
    return static_solution(model, load_scale=scale).q, np.zeros(model.n)


def mechanical_energy(model, q, v) -> np.ndarray:
    """1/2 v'Mv + 1/2 q'(K_mean + K_frame)q - q'F: conserved for constant stiffness, no damping
    and constant load (the Coriolis forces do no work).  q, v with time along axis 0."""
    K = model.K_mean + model.K_frame
    F = mean_load(model)
    return 0.5 * np.einsum("ti,ij,tj->t", v, model.M, v) + 0.5 * np.einsum("ti,ij,tj->t", q, K, q) - q @ F


def simulate(model, settings: RunSettings, method: str = "rk4", rtol: float = 1e-8, atol: float = 1e-14, y0=None,
             progress=None, drive: str = "steps") -> TimeResult:
    """Integrate ``model`` as ``settings`` ask.

    method: "rk4" (matrix form of each step where the model is linear over it), "rk4-stages" (the
    same RK4, stage by stage everywhere: the reference the matrix form is tested against) or
    one of scipy's adaptive methods, whose largest step is then ``settings.dt``.
    drive: "steps" (default, like-for-like with the MuJoCo runner) or "stages" (see the module doc).
    The step defaults to :func:`default_step` and is checked against the stability limit.
    y0: optional (q, v) instead of the static start.  progress: callable(fraction).
    """
    if method not in ("rk4", "rk4-stages") + ADAPTIVE_METHODS:
        raise SolverError(f"unknown method {method!r}: use rk4, rk4-stages or one of {', '.join(ADAPTIVE_METHODS)}")
    if drive not in ("steps", "stages"):
        raise SolverError(f"drive must be 'steps' or 'stages', not {drive!r}")
    limits = step_limits(model)
    dt = stepping.default_step(limits, model.excitation.frequency) if settings.dt is None else settings.dt
    what = f"lumped model of {model.spec.name}"
    stepping.check_step(dt, limits, model.excitation.frequency, what)
    n_steps, every = settings.check_work(dt, len(model.spec.members) * 5 + len(model.spec.meshes) * 4 + 4 * model.n,
                                         what)
    q0, v0 = initial_state(model) if y0 is None else y0
    sys = _System(model)
    static = static_solution(model)
    scale = divergence.deflection_scale(static.mesh_deflection, sys.b)

    def runaway(t, q):
        divergence.check(t, q @ sys.A.T, scale, what)

    started = clock.perf_counter()
    if method in ("rk4", "rk4-stages"):
        t_out, q_out, v_out = _rk4(sys, q0, v0, dt, n_steps, every, progress, runaway, method == "rk4-stages", drive)
        evaluations = 4 * n_steps
    else:
        t_out, q_out, v_out, evaluations = _adaptive(sys, q0, v0, dt, n_steps, every, method, rtol, atol)
        runaway(t_out, q_out)
    wall = clock.perf_counter() - started
    info = {"method": method, "drive": drive if method.startswith("rk4") else "exact", "dt_s": dt, "steps": n_steps,
            "rhs_evaluations": evaluations, "wall_time_s": wall,
            "rtol": rtol if method != "rk4" else None, "rotating_frame_terms": model.rotating_frame_terms}
    return _result(model, sys, t_out, q_out, v_out, static, settings.settle_time(model.spec.operating.ramp), info)


def _rk4(sys, q, v, h, n_steps, every, progress, runaway, stage_by_stage=False, drive="steps"):
    """Fixed-step RK4 over n_steps, sampling every ``every`` steps; ``runaway(t, q)`` checks each chunk's
    samples and its last state for divergence."""
    n = q.size
    n_out = n_steps // every + 1
    t_out = np.empty(n_out)
    q_out = np.empty((n_out, n))
    v_out = np.empty((n_out, n))
    t_out[0], q_out[0], v_out[0] = 0.0, q, v
    acc = sys.acceleration
    # turning couplings (periodic) and tooth pairs (a force that depends on the contacts) are not linear
    linear = None if stage_by_stage or sys.turning or sys.has_relief else _LinearStep(sys, h)
    stages = np.array(STAGE_OFFSETS)
    y = np.concatenate([q, v])
    j = j0 = 1
    chunk = CHUNK // 10 if sys.has_relief else CHUNK  # the pairs' drive is (steps, 3, meshes, pairs, 2)
    for start in range(0, n_steps, chunk):
        stop = min(start + chunk, n_steps)
        times = (np.arange(start, stop)[:, None] + stages[None, :]) * h
        k, e, de, tin, tout, pairs = sys.drive(times)
        if drive == "steps":  # stages 2-4 all see the step's weighted drive (as MuJoCo's model fields)
            k, e, de, tin, tout = (per_step_drive(x) for x in (k, e, de, tin, tout))
            pairs = None if pairs is None else per_step_pairs(pairs)
        if linear is not None:
            load = sys.load(k, e, de, tin, tout)
            smooth = np.all(k[:, 0, :] == k[:, 1, :], axis=1) & np.all(k[:, 1, :] == k[:, 2, :], axis=1)
        split = stepping.split_steps(h, start, stop, sys.exc.switch_times(start * h, stop * h))
        for i in range(stop - start):
            mapped = None
            if start + i in split:
                y = _split_step(sys, y, (start + i) * h, h, split[start + i], drive)
            elif linear is not None and smooth[i]:
                P, Q1, Q2, Q3, Q23 = linear.maps(k[i, 0])
                if drive == "steps":
                    mapped = P @ y + Q1 @ load[i, 0] + Q23 @ load[i, 1]
                else:
                    mapped = P @ y + Q1 @ load[i, 0] + Q2 @ load[i, 1] + Q3 @ load[i, 2]
                if sys.has_backlash and not (sys.on_drive_flanks(y[:n], e[i, 0])
                                             and sys.on_drive_flanks(mapped[:n], e[i, 2])):
                    mapped = None
            if mapped is not None:
                y = mapped
            elif start + i not in split:  # stage by stage: a contact change
                t0 = (start + i) * h

                def stage(s, q, v, i=i, t0=t0):
                    return acc(q, v, k[i, s], e[i, s], de[i, s], tin[i, s], tout[i, s], t0 + 0.5 * s * h,
                               None if pairs is None else pairs[i, s])

                y = np.concatenate(rk4_step(stage, y[:n], y[n:], h))
            step = start + i + 1
            if step % every == 0:
                t_out[j], q_out[j], v_out[j] = step * h, y[:n], y[n:]
                j += 1
        runaway(np.append(t_out[j0:j], stop * h), np.vstack([q_out[j0:j], y[None, :n]]))
        j0 = j
        if progress is not None:
            progress(stop / n_steps)
    return t_out[:j], q_out[:j], v_out[:j]


def _split_step(sys, y, t0, h, inner, drive):
    """One step ended at the stiffness jumps ``inner`` inside it: RK4 sub-steps, each with its own drive."""
    n = y.size // 2
    q, v = y[:n], y[n:]
    for a, length in zip(*stepping.sub_steps(t0, h, inner)):
        k, e, de, tin, tout, pairs = sys.drive(a + length * np.array(STAGE_OFFSETS)[None, :])
        if drive == "steps":
            k, e, de, tin, tout = (per_step_drive(x) for x in (k, e, de, tin, tout))
            pairs = None if pairs is None else per_step_pairs(pairs)

        def stage(s, q, v, a=a, length=length, k=k[0], e=e[0], de=de[0], tin=tin[0], tout=tout[0],
                  pairs=None if pairs is None else pairs[0]):
            return sys.acceleration(q, v, k[s], e[s], de[s], tin[s], tout[s], a + 0.5 * s * length,
                                    None if pairs is None else pairs[s])

        q, v = rk4_step(stage, q, v, length)
    return np.concatenate([q, v])


def rk4_step(acceleration, q, v, h):
    """One classical RK4 step of q'' = acceleration(s, q, v), s = 0, 1, 1, 2 the stage's time
    t + s h/2 (the caller supplies the drive at those times); returns (q, v) at t + h."""
    k1 = acceleration(0, q, v)
    q2, v2 = q + 0.5 * h * v, v + 0.5 * h * k1
    k2 = acceleration(1, q2, v2)
    q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * k2
    k3 = acceleration(1, q3, v3)
    q4, v4 = q + h * v3, v + h * k3
    k4 = acceleration(2, q4, v4)
    return q + h / 6.0 * (v + 2 * v2 + 2 * v3 + v4), v + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def _adaptive(sys, q0, v0, h, n_steps, every, method, rtol, atol):
    n = q0.size

    def rhs(t, y):
        k, e, de, tin, tout, pairs = sys.drive(t)
        return np.concatenate([y[n:], sys.acceleration(y[:n], y[n:], k, e, de, tin, tout, t, pairs)])

    t_eval = h * np.arange(0, n_steps + 1, every)
    sol = solve_ivp(rhs, (0.0, n_steps * h), np.concatenate([q0, v0]), method=method, t_eval=t_eval,
                    max_step=h * every, rtol=rtol, atol=atol)
    if not sol.success:
        raise DivergenceError(float(sol.t[-1]) if sol.t.size else 0.0, sol.message)
    return sol.t, sol.y[:n].T, sol.y[n:].T, int(sol.nfev)


def _result(model, sys, t, q, v, static, settle, info) -> TimeResult:
    # outputs at t_n see the drive of the step that starts there (as the MuJoCo runner's sensors do)
    k, e, de, tin, tout, pairs = sys.drive(t + STAGE_OFFSETS[0] * info["dt_s"])
    qdd = sys.acceleration(q, v, k, e, de, tin[:, None], tout[:, None], t, pairs)
    delta, force = sys.mesh_force(q, v, k, e, de, pairs)
    k = sys.contact_stiffness(q, k, e, pairs)
    spec, dofs = model.spec, model.dofs
    acc, angle = member_motion(spec, model.kin, dofs, t, q, v, qdd, model.rotating_frame_terms)
    rows = {r.name: r for r in model.rows if r.kind == "bearing"}
    bearings = [rows[name] for name in bearing_names(spec)]
    a = np.array([r.a for r in bearings]).reshape(len(bearings), model.n)
    bearing_force = (q @ a.T) * [r.stiffness for r in bearings] + (v @ a.T) * [r.damping for r in bearings]
    raw = {label: q[:, i] for i, label in enumerate(dofs.labels())}
    raw.update({f"{label}_dot": v[:, i] for i, label in enumerate(dofs.labels())})
    static_bearing = [static.row_forces[static.row_names.index(r.name)] for r in bearings]
    cycloids = [e for e in model.turning if isinstance(e, CycloidRows)]
    pins = np.concatenate([e.pin_forces(t, q, v) for e in cycloids], axis=1) if cycloids else None
    return train_result(spec, "lumped", t, acc, angle, delta, force, k, static.mesh_force, static_bearing,
                        bearing_force, settle, info, raw, pins)
