"""Time response of the reference model: fixed-step RK4 and scipy's adaptive integrators.

Equation of motion (rotating frame, see :mod:`gearcheck.lumped.assembly`):

    M q'' = F_static + b_in T_in(t) + b_out T_out(t) - (C_b + G) q' - (K_b + K_frame) q
            - sum_m a_m [k_m(t) f(a_m.q - e_m(t)) + c_m (a_m.q' - e_m'(t))],

f the backlash dead zone.  The start is the static deflection under the mean load
(``ramp_s`` = 0) or the unloaded state with the load ramped in.

Time step: :mod:`gearcheck.shared.stepping` (the rule the MuJoCo runner follows too), from the
highest natural frequency of this model with every mesh at its cycle-maximum stiffness.
The drive is sampled at each RK4 stage's own time, t + h (0, 1/2, 1/2, 1), its right-hand limit at the
step's start and its left-hand one at the end (:data:`~gearcheck.shared.stepping.STAGE_SIDES`), as the
MuJoCo runner drives its stages: the textbook RK4, fourth order for a drive smooth over the step.  A step
inside which a mesh stiffness jumps is split there (:func:`~gearcheck.shared.stepping.split_steps`, as the
MuJoCo runner does), so the stiffness is smooth over every sub-step and RK4 keeps its order.

The RK4 steps run compiled (:mod:`gearcheck.lumped.compiled_steps`), a chunk of steps at a time: Python samples
the chunk's drive (and the rows of the turning elements at the stage times), vectorised, then checks the
chunk's samples for divergence and reports progress; ``method="rk4-stages"`` runs the same chunks stage by stage
through :meth:`_System.acceleration`, the reference the compiled steps are tested against.
"""

from __future__ import annotations

import time as clock

import numpy as np
from scipy.integrate import solve_ivp

from gearcheck.lumped.compiled_steps import Chunk, Output, kernel_groups, rk4_steps, switching_count
from gearcheck.lumped.frame_schedule import with_schedule
from gearcheck.lumped.member_motion import member_motion
from gearcheck.lumped.static import mean_load, static_solution
from gearcheck.shared import divergence, stepping
from gearcheck.shared.blas import one_blas_thread
from gearcheck.shared.contact_laws import deadzone
from gearcheck.shared.errors import DivergenceError, SolverError
from gearcheck.shared.events import (MAX_EVENTS, MIN_FRACTION, crossed_together, first_crossing, pair_switch,
                                     samples_between)
from gearcheck.shared.results import TimeResult, bearing_names, tilting_meshes, train_result, train_signals
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import STAGE_OFFSETS, STAGE_SIDES
from gearcheck.train.history import check_duration

CHUNK = 20000  # steps between divergence checks and progress reports
CHUNK_BYTES = 16 * 2**20  # at most this much drive per chunk (the tooth pairs take a lot per step)
ADAPTIVE_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


def step_limits(model, top: float = 1.0) -> stepping.StepLimits:
    """The RK4 step limits of the model with every mesh at its largest stiffness over a cycle, damping,
    gyroscopic and rotating-frame terms included, at ``top`` times the reference speed (an operating history's
    fastest)."""
    if top != 1.0:
        model = model.at_speed(top * model.spec.operating.input_speed)
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
        self.relieved_index = np.full(self.c.size, -1, dtype=np.int64)  # mesh -> its place among the relieved
        self.relieved_index[self.relieved] = np.arange(self.relieved.size)
        self.F0 = model.F_static
        self.b_in, self.b_out = model.b_input, model.b_output
        self.kernel = kernel_groups(self)
        pairs = self.exc.tooth_pairs(0.0)[0]
        self.switches = switching_count(self.kernel[1], self.kernel[2], 0 if pairs is None else pairs.shape[-1])

    def drive(self, t, side=0):
        """Excitation at times t: (k, e, de, T_in, T_out, pairs), arrays with time along axis 0; ``pairs``
        the relieved meshes' tooth pairs (k_j, e_j), or None; ``side`` the one-sided limit read where a mesh's
        drive jumps (:meth:`~gearcheck.train.excitation.Excitation.mesh_position`)."""
        k = self.exc.stiffness(t, side)
        e, de = self.exc.transmission_error(t)
        t_in, t_out = self.exc.torques(t)
        kp, ep = self.exc.tooth_pairs(t, side)
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

    def switching(self, q, v, t, e, de, pairs, s: int, span: float) -> tuple[np.ndarray, np.ndarray]:
        """The contact switching functions at one state and their rates
        (:func:`~gearcheck.lumped.compiled_steps._switching`'s, in its order): the backlash edges y - b and y + b, the
        tooth pairs' y - e_j, the pins' compressions; ``pairs`` at a (sub-)step's three samples, of length
        ``span``, t at sample ``s``."""
        y, dy = self.A @ q - e, self.A @ v - de
        g, rate = [], []
        for m in range(y.size):
            j = self.relieved_index[m]
            if j >= 0:
                for gaps in pairs[:, j, :, 1].T:
                    value, slope = pair_switch(y[m], dy[m], *gaps, s, span)
                    g.append(value)
                    rate.append(slope)
            elif self.has_backlash and self.b[m] > 0:
                g += [y[m] - self.b[m], y[m] + self.b[m]]
                rate += [dy[m], dy[m]]
        turning = [e.switching(t, q, v) for e in self.turning]
        return (np.concatenate([np.array(g, dtype=float)] + [x[0] for x in turning]),
                np.concatenate([np.array(rate, dtype=float)] + [x[1] for x in turning]))

    def acceleration(self, q, v, k, e, de, t_in, t_out, t=0.0, pairs=None):
        """q'' for one state (1-D) or many (time along axis 0, the torques then as columns)."""
        _, f = self.mesh_force(q, v, k, e, de, pairs)
        force = self.F0 + self.b_in * t_in + self.b_out * t_out - v @ self.D.T - q @ self.Kc.T - f @ self.A
        for coupling in self.turning:
            force = force + coupling.forces(t, q, v)
        return force * self.Minv

    def compiled_steps(self, q, v, chunk: Chunk, out: Output, located: np.ndarray) -> int:
        """:func:`~gearcheck.lumped.compiled_steps.rk4_steps` on this system (see :func:`_chunk`), the contact events
        it locates counted into ``located[0]``."""
        rows = chunk.lengths.size
        pairs = np.zeros((rows, 3, 0, 0, 2)) if chunk.pairs is None else np.ascontiguousarray(chunk.pairs)
        return rk4_steps(q, v, *self.kernel, chunk._replace(pairs=pairs), out, self.switches, located)


def initial_state(model) -> tuple[np.ndarray, np.ndarray]:
    """Static deflection under the mean load, or the unloaded state when the load is ramped; at rest and
    undeformed for an operating history that starts from rest."""
    history = model.spec.operating.history
    if history is not None and history.start == "rest":
        return np.zeros(model.n), np.zeros(model.n)
    scale = 0.0 if model.spec.operating.ramp > 0 else 1.0
    return static_solution(model, load_scale=scale).q, np.zeros(model.n)


def mechanical_energy(model, q, v) -> np.ndarray:
    """1/2 v'Mv + 1/2 q'(K_mean + K_frame)q - q'F: conserved for constant stiffness, no damping
    and constant load (the Coriolis forces do no work).  q, v with time along axis 0."""
    K = model.K_mean + model.K_frame
    F = mean_load(model)
    return 0.5 * np.einsum("ti,ij,tj->t", v, model.M, v) + 0.5 * np.einsum("ti,ij,tj->t", q, K, q) - q @ F


@one_blas_thread
def simulate(model, settings: RunSettings, method: str = "rk4", rtol: float = 1e-8, atol: float = 1e-14, y0=None,
             progress=None, return_state: bool = False) -> TimeResult:
    """Integrate ``model`` as ``settings`` ask.

    method: "rk4" (compiled steps, :mod:`gearcheck.lumped.compiled_steps`), "rk4-stages" (the same RK4 stage by
    stage in Python: the reference the compiled steps are tested against) or
    one of scipy's adaptive methods, whose largest step is then ``settings.dt``.
    The step defaults to :func:`default_step` and is checked against the stability limit.
    y0: optional (q, v) instead of the static start, at ``settings.start`` (which needs it).  progress:
    callable(fraction).  return_state: return (result, (q, v)), the state after the last step.
    """
    if method not in ("rk4", "rk4-stages") + ADAPTIVE_METHODS:
        raise SolverError(f"unknown method {method!r}: use rk4, rk4-stages or one of {', '.join(ADAPTIVE_METHODS)}")
    what = f"lumped model of {model.spec.name}"
    model = with_schedule(model)
    nominal = model.excitation.clock
    top = 1.0 if nominal is None else max(1.0, nominal.top(settings.duration))
    if nominal is not None:
        check_duration(model.spec.operating.history, settings.duration, what)
    settings.check_start(y0, model.spec.operating.history, what)
    limits = step_limits(model, top)
    frequency = top * model.excitation.frequency
    dt = stepping.default_step(limits, frequency) if settings.dt is None else settings.dt
    stepping.check_step(dt, limits, frequency, what)
    n_steps, every = settings.check_work(dt, len(train_signals(model.spec)) + 4 * model.n, what)
    q0, v0 = initial_state(model) if y0 is None else y0
    sys = _System(model)
    static = static_solution(model)
    scale = divergence.deflection_scale(static.mesh_deflection, sys.b)

    def runaway(t, q):
        divergence.check(t, q @ sys.A.T, scale, what)

    started = clock.perf_counter()
    if method in ("rk4", "rk4-stages"):
        t_out, q_out, v_out, sub_steps, located = _rk4(sys, q0, v0, dt, n_steps, every, progress, runaway,
                                                       method == "rk4-stages", settings.start)
        engine, stages, calls = "numba-rk4" if method == "rk4" else "python-rk4", 4, 4 * sub_steps
    else:
        t_out, q_out, v_out, calls = _adaptive(sys, q0, v0, dt, n_steps, every, method, rtol, atol, settings.start)
        runaway(t_out, q_out)
        engine, stages, located = f"scipy-{method}", None, None
    wall = clock.perf_counter() - started
    info = RunInfo(engine, n_steps, stages, calls, wall, {
        "method": method, "drive": "stages" if method.startswith("rk4") else "exact", "dt_s": dt, "steps": n_steps,
        "rhs_evaluations": calls, "wall_time_s": wall,  # sub-steps and located events included
        "rtol": rtol if method != "rk4" else None, "rotating_frame_terms": model.rotating_frame_terms,
        "contact_events_located": located})
    result = _result(model, sys, t_out, q_out, v_out, static, settings.settle_time(model.spec.operating.ramp), info,
                     settings.signals)
    return (result, (q_out[-1].copy(), v_out[-1].copy())) if return_state else result


def _chunk(sys, h, start, stop, t0: float = 0.0) -> Chunk:
    """The (sub-)steps of steps start..stop-1 (step i from t0 + i h) and their drive at their stage times
    (:class:`~gearcheck.lumped.compiled_steps.Chunk`): a step inside which a mesh stiffness jumps is split there
    (:func:`~gearcheck.shared.stepping.split_steps`)."""
    steps = np.arange(start, stop)
    lengths = np.full(steps.size, h)
    begins = t0 + steps * h
    ends = np.ones(steps.size, dtype=bool)
    split = stepping.split_steps(h, start, stop, sys.exc.switch_times(t0 + start * h, t0 + stop * h), t0)
    if split:
        parts, sub_begins, sub_lengths = stepping.sub_steps(t0, h, split)
        at = np.array(sorted(split)) - start
        counts = np.ones(steps.size, dtype=int)
        counts[at] = parts
        row = np.repeat(np.arange(steps.size), counts)
        lengths, begins = lengths[row], begins[row]
        first = np.cumsum(counts) - counts
        ends = np.zeros(row.size, dtype=bool)
        ends[first + counts - 1] = True
        inside = np.isin(row, at)  # the sub-steps of the split steps, in their order
        begins[inside], lengths[inside] = sub_begins, sub_lengths
    times = begins[:, None] + np.array(STAGE_OFFSETS)[None, :] * lengths[:, None]
    return Chunk(lengths, ends, times, *sys.drive(times, np.array(STAGE_SIDES)))


def _chunk_steps(sys) -> int:
    """Steps per chunk: ``CHUNK``, fewer where the tooth pairs make the per-step drive large, so that a chunk's
    drive stays within ``CHUNK_BYTES`` (with a quarter of its steps split at stiffness jumps)."""
    pairs = 0 if not sys.relieved.size else sys.exc.tooth_pairs(0.0)[0].size
    per_step = 10 * 3 * (3 * sys.c.size + 5 + 2 * pairs)  # 8 bytes a number, 1.25 sub-steps a step
    return int(max(64, min(CHUNK, CHUNK_BYTES // per_step)))


def _rk4(sys, q, v, h, n_steps, every, progress, runaway, stage_by_stage=False, t0: float = 0.0):
    """Fixed-step RK4 over n_steps from t0, sampling every ``every`` steps; ``runaway(t, q)`` checks each chunk's
    samples and its last state for divergence.  The compiled steps (:func:`~gearcheck.lumped.compiled_steps.
    rk4_steps`), or with ``stage_by_stage`` :func:`rk4_step` on :meth:`_System.acceleration` in Python.  Returns the
    samples' (t, q, v) and the sub-steps taken (steps split at stiffness jumps count each of theirs)."""
    n = q.size
    n_out = n_steps // every + 1
    t_out = np.empty(n_out)
    q_out = np.empty((n_out, n))
    v_out = np.empty((n_out, n))
    t_out[0], q_out[0], v_out[0] = t0, q, v
    q, v = q.copy(), v.copy()
    j, sub_steps = 1, 0
    located = np.zeros(1, dtype=np.int64)
    chunk = _chunk_steps(sys)
    for start in range(0, n_steps, chunk):
        stop = min(start + chunk, n_steps)
        steps = _chunk(sys, h, start, stop, t0)
        sub_steps += steps.lengths.size
        out = Output(start, every, q_out[j:], v_out[j:])
        steps_of = _python_steps if stage_by_stage else sys.compiled_steps
        written = steps_of(sys, q, v, steps, out, located) if stage_by_stage else steps_of(q, v, steps, out, located)
        t_out[j:j + written] = t0 + h * (every * (start // every + 1 + np.arange(written)))
        runaway(t_out[j:j + written], q_out[j:j + written])
        runaway(np.array([t0 + stop * h]), q[None])  # the chunk's last state, sampled or not
        j += written
        if progress is not None:
            progress(stop / n_steps)
    return t_out[:j], q_out[:j], v_out[:j], sub_steps + 2 * int(located[0]), int(located[0])


def stepper(model, dt: float, n_steps: int):
    """(a function (q, v) -> (q, v) at t = n_steps dt, from (q, v) at t = 0, by the compiled RK4 steps of
    :func:`simulate` (same drive sampling and splits), the sub-steps it takes); the drive is sampled once, for every
    call (a shooting method's many runs over one period)."""
    sys = _System(model)
    chunk = _chunk_steps(sys)
    chunks = [(start, _chunk(sys, dt, start, min(start + chunk, n_steps))) for start in range(0, n_steps, chunk)]
    none = np.empty((0, model.n))
    located = np.zeros(1, dtype=np.int64)

    def run(q, v):
        q, v = np.array(q, dtype=float), np.array(v, dtype=float)
        for start, steps in chunks:
            sys.compiled_steps(q, v, steps, Output(start, n_steps + 1, none, none), located)
        return q, v

    return run, sum(steps.lengths.size for _, steps in chunks)


def _python_steps(sys, q, v, chunk: Chunk, out: Output, located: np.ndarray) -> int:
    """:func:`~gearcheck.lumped.compiled_steps.rk4_steps` stage by stage in Python (the reference), its contact
    events located as there."""
    lengths, ends, times, k, e, de, tin, tout, pairs = chunk
    first_step, every, q_out, v_out = out
    step, written = first_step, 0
    for r, h in enumerate(lengths):
        drive = [x[r] for x in (times, k, e, de, tin, tout)] + [None if pairs is None else pairs[r]]
        start = q.copy(), v.copy()
        q[:], v[:] = _python_step(sys, drive, h, *start)
        no_pairs = np.zeros((3, 0, 0, 2))
        row_pairs = no_pairs if pairs is None else pairs[r]
        done, span = 0.0, h
        g0, r0 = sys.switching(*start, times[r, 0], e[r, 0], de[r, 0], row_pairs, 0, h)
        for _ in range(MAX_EVENTS if sys.switches else 0):
            theta, crossed = first_crossing(g0, r0, *sys.switching(q, v, times[r, 2], e[r, 2], de[r, 2], row_pairs, 2,
                                                                   h), span)
            if not MIN_FRACTION < theta < 1.0 - MIN_FRACTION:
                break
            at = done + theta * (1.0 - done)
            sub = [None if x is None else _between(x, done, at) for x in drive]
            q[:], v[:] = _python_step(sys, sub, (at - done) * h, *start)
            located[0] += 1
            g0, r0 = sys.switching(q, v, sub[0][2], sub[2][2], sub[3][2], no_pairs if pairs is None else sub[6], 2,
                                   (at - done) * h)
            crossed_together(g0, r0, (at - done) * h, crossed)
            start, done, span = (q.copy(), v.copy()), at, (1.0 - at) * h
            rest = [None if x is None else _between(x, done, 1.0) for x in drive]
            q[:], v[:] = _python_step(sys, rest, span, *start)
        if ends[r]:
            step += 1
            if step % every == 0:
                q_out[written], v_out[written] = q, v
                written += 1
    return written


def _python_step(sys, drive, h, q, v):
    """One RK4 step of :meth:`_System.acceleration` from (q, v), ``drive`` (times, k, e, de, tin, tout, pairs) at
    the stage samples."""
    times, k, e, de, tin, tout, pairs = drive

    def stage(s, q, v):
        return sys.acceleration(q, v, k[s], e[s], de[s], tin[s], tout[s], times[s], None if pairs is None else pairs[s])

    return rk4_step(stage, q, v, h)


def _between(x: np.ndarray, a: float, b: float) -> np.ndarray:
    """The three samples of ``x`` (axis 0) at the fractions a, (a + b)/2, b of its step
    (:func:`~gearcheck.shared.events.samples_between`)."""
    out = np.empty_like(x)
    samples_between(np.ascontiguousarray(x), a, b, out)
    return out


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


def _adaptive(sys, q0, v0, h, n_steps, every, method, rtol, atol, t0: float = 0.0):
    n = q0.size

    def rhs(t, y):
        k, e, de, tin, tout, pairs = sys.drive(t)
        return np.concatenate([y[n:], sys.acceleration(y[:n], y[n:], k, e, de, tin, tout, t, pairs)])

    t_eval = t0 + h * np.arange(0, n_steps + 1, every)
    sol = solve_ivp(rhs, (t0, t0 + n_steps * h), np.concatenate([q0, v0]), method=method, t_eval=t_eval,
                    max_step=h * every, rtol=rtol, atol=atol)
    if not sol.success:
        raise DivergenceError(float(sol.t[-1]) if sol.t.size else 0.0, sol.message)
    return sol.t, sol.y[:n].T, sol.y[n:].T, int(sol.nfev)


def _result(model, sys, t, q, v, static, settle, info, wanted=None) -> TimeResult:
    # outputs at t_n see the drive of the step that starts there (as the MuJoCo runner's sensors do)
    k, e, de, tin, tout, pairs = sys.drive(t, STAGE_SIDES[0])
    qdd = sys.acceleration(q, v, k, e, de, tin[:, None], tout[:, None], t, pairs)
    delta, force = sys.mesh_force(q, v, k, e, de, pairs)
    k = sys.contact_stiffness(q, k, e, pairs)
    spec, dofs = model.spec, model.dofs
    q_t, v_t, qdd_t = (q, v, qdd) if model.expansion is None else (x @ model.expansion.T for x in (q, v, qdd))
    motion = member_motion(spec, model.kin, model.physical_dofs, t, q_t, v_t, qdd_t, model.rotating_frame_terms,
                           model.excitation.clock)
    rows = {r.name: r for r in model.rows}
    bearings = [rows[name] for name in bearing_names(spec)]
    bearing_force = _row_forces(bearings, q, v, model.n)
    moments = _row_forces([rows[f"{mesh.id}.tilt"] for mesh in tilting_meshes(spec)], q, v, model.n)
    raw = {label: q[:, i] for i, label in enumerate(dofs.labels())}
    raw.update({f"{label}_dot": v[:, i] for i, label in enumerate(dofs.labels())})
    static_bearing = [static.row_forces[static.row_names.index(r.name)] for r in bearings]
    contacts = [e for e in model.turning if e.has_contacts]
    pins = np.concatenate([e.pin_forces(t, q, v) for e in contacts], axis=1) if contacts else None
    return train_result(spec, "lumped", t, motion, delta, force, k, static.mesh_force, static_bearing,
                        bearing_force, settle, info, raw, pins, wanted, moments)


def _row_forces(rows, q, v, n: int) -> np.ndarray:
    """(n_t, len(rows)) the spring-damper forces k (a.q - rest) + c a.q' of ``rows`` over the run."""
    a = np.array([r.a for r in rows]).reshape(len(rows), n)
    return ((q @ a.T) - [r.rest for r in rows]) * [r.stiffness for r in rows] + (v @ a.T) * [r.damping for r in rows]
