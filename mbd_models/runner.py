"""The MuJoCo runner: the train really turning, every mesh's stiffness driven every step.

Per step (fixed step h, MuJoCo's RK4 integrator):

* mesh stiffness k(t) from :meth:`lumped.excitation.Excitation.stiffness` (the nominal
  clock, as the lumped solver) into ``m.tendon_stiffness``; a static transmission error
  e(t) shifts the tendons' spring length (``m.tendon_lengthspring`` = e -/+ b) and its
  rate enters as the generalized force J' c de/dt (``qfrc_applied``);
* the input speed w_in into the ``input_shaft`` integrated-velocity servo (whose activation
  is the reference angle, 0 at t = 0) and its ``input_shaft_damper``, the load torque T_out(t) and
  any input torque into the ``output_load`` / ``input_torque`` motors;
* the mesh tendons' world-frame slide coefficients rotated to the carrier's current
  angle (:meth:`MbdModel.refresh`; the angle-0 values came from ``mj_jac``).

Integrator: RK4, because the mesh springs make the model stiff and no MuJoCo
integrator except ``discrete`` treats spring stiffness implicitly: Euler and
implicitfast are stable only for h < 2/omega_max and first-order accurate, RK4 is
stable to 2.83/omega_max and fourth-order accurate, so it matches the lumped RK4
solution with the same step.  MuJoCo holds model fields and controls constant over a
step, so the runner calls ``mj_forward`` itself with the excitation at t_n (RK4's
first stage, which also gives the outputs at t_n) and then ``mj_RungeKutta`` with the
excitation at the weighted time of the remaining stages, (4 x(t+h/2) + x(t+h))/5:
the stage weights of RK4 (2/6, 2/6, 1/6) then integrate a linear-in-time drive
exactly over the step.

Time step: from the highest natural frequency of MuJoCo's own linearisation with every
mesh at its cycle-maximum stiffness (:func:`mbd_models.linearise.max_angular_frequency`);
the rule of :mod:`lumped.stepping`, the same as the lumped solver's.

Start: the steady rotating state at the nominal operating point of the MuJoCo model
itself (:func:`static_state`): a Newton solve on MuJoCo's forward dynamics for the
deflections at which every body turns at its nominal speed with the deflection pattern
turning with its carrier.
"""

from __future__ import annotations

import math
import time as clock
from dataclasses import dataclass

import mujoco
import numpy as np

from lumped.errors import DivergenceError, SolverError
from lumped import stepping
from lumped.excitation import STAGE_OFFSETS, STEP_WEIGHTS
from lumped.results import TimeResult
from lumped.static import deadzone

from .linearise import max_angular_frequency
from .mjcf_builder import MbdModel, compile_train

CHUNK = 10000
DIVERGENCE_FACTOR = 1e3  # |delta| beyond this times the static scale counts as runaway


# --------------------------------------------------------------------------- time step


def default_step(mb: MbdModel, omega_max: float | None = None) -> float:
    """:func:`lumped.stepping.default_step` for this model (omega_max: if already known)."""
    omega_max = max_angular_frequency(mb) if omega_max is None else omega_max
    return stepping.default_step(omega_max, mb.excitation.frequency)


# --------------------------------------------------------------------------- drive


class _Drive:
    """Excitation of one MbdModel as arrays over time: stiffness, spring lengths, controls."""

    def __init__(self, mb: MbdModel):
        self.mb = mb
        self.exc = mb.excitation
        self.nu = mb.model.nu
        self.w_in = mb.spec.operating.input_speed
        self.has_te = self.exc.has_transmission_error

    def controls(self, t: np.ndarray) -> np.ndarray:
        """Actuator controls at times t: reference angle w_in t, w_in for the damper, torques (ramp included)."""
        u = np.zeros((t.size, self.nu))
        a = self.mb.actuator
        t_in, t_out = self.exc.torques(t)
        if "input_shaft" in a:
            u[:, a["input_shaft"]] = self.w_in  # the intvelocity servo integrates it into the reference angle
        if "input_shaft_damper" in a:
            u[:, a["input_shaft_damper"]] = self.w_in
        u[:, a["input_torque"]] = t_in
        u[:, a["output_load"]] = t_out
        return u

    def arrays(self, t0: np.ndarray, h: float):
        """Values for steps starting at t0: (stage-1 rows, stage-2..4 rows), sampled at
        t0 + h STAGE_OFFSETS as the lumped RK4 samples them."""
        times = (t0[:, None] + h * np.array(STAGE_OFFSETS)[None, :]).ravel()
        k = self.exc.stiffness(times)
        u = self.controls(times)
        e, de = self.exc.transmission_error(times) if self.has_te else (None, None)

        def split(x):
            if x is None:
                return None, None
            first = x[0::3]
            later = STEP_WEIGHTS[0] * x[1::3] + STEP_WEIGHTS[1] * x[2::3]
            return first, later

        return split(k), split(u), split(e), split(de)


# --------------------------------------------------------------------------- static state


@dataclass
class StaticState:
    qpos: np.ndarray
    qvel: np.ndarray
    mesh_deflection: np.ndarray
    mesh_force: np.ndarray
    iterations: int
    residual: float


def _nominal(mb: MbdModel, q: np.ndarray):
    """State (qpos, qvel) and the steady-rotation acceleration of deflection q at t = 0.

    Every body turns at its nominal speed (planet hinges relative to their carrier),
    and a central member's world-frame deflection turns with its carrier: x' = Omega k x x,
    x'' = -Omega^2 x.
    """
    spec, kin = mb.spec, mb.kin
    qvel = np.zeros_like(q)
    target = np.zeros_like(q)
    for mid, member in spec.members.items():
        ix, iy, ir = mb.dadr[mid]
        omega = kin.speeds[f"{member.stage}.carrier"]
        if member.is_planet:
            qvel[ir] = kin.speeds[mid] - omega
        else:
            qvel[ix], qvel[iy] = -omega * q[iy], omega * q[ix]
            target[ix], target[iy] = -omega**2 * q[ix], -omega**2 * q[iy]
            qvel[ir] = kin.speeds[mid]
    return q.copy(), qvel, target


def _set_static_drive(mb: MbdModel, d: mujoco.MjData, load_scale: float) -> None:
    kin, a = mb.kin, mb.actuator
    d.ctrl[:] = 0.0
    if "input_shaft_damper" in a:
        d.ctrl[a["input_shaft_damper"]] = mb.spec.operating.input_speed
    if "input_shaft" not in a:
        d.ctrl[a["input_torque"]] = kin.input_torque * load_scale
    d.ctrl[a["output_load"]] = kin.output_torque * load_scale
    d.qfrc_applied[:] = 0.0


def static_state(mb: MbdModel, load_scale: float = 1.0, tol: float = 1e-13, max_iter: int = 40) -> StaticState:
    """Steady rotating equilibrium of the MuJoCo model under the mean load (times ``load_scale``).

    Newton's method on r(q) = qacc(q) - qacc_steady(q), with MuJoCo's forward dynamics
    evaluated at the nominal speeds, every mesh at its mean stiffness and the Jacobian
    dr/dq by central differences; minimum-norm steps where a free rotation makes it
    singular.  Backlash: solved first without it, then with every mesh on its drive flank.
    """
    m = mb.model
    d = mujoco.MjData(m)
    saved_k, saved_l = m.tendon_stiffness.copy(), m.tendon_lengthspring.copy()
    t = mb.mesh_tendon
    try:
        m.tendon_stiffness[t] = mb.excitation.mean_stiffness
        _set_static_drive(mb, d, load_scale)

        def residual(q):
            qpos, qvel, target = _nominal(mb, q)
            d.qpos[:], d.qvel[:] = qpos, qvel
            mb.refresh(d.qpos)
            mujoco.mj_forward(m, d)
            return d.qacc - target

        q = m.qpos0.copy()
        iterations, res = 0, math.inf
        for band in (False, True):
            # with backlash the loaded teeth sit on their drive flanks: a spring whose rest length is
            # +b (the dead band's upper edge) has the same force there and no flat zero-stiffness
            # region for Newton to wander in (the lumped static solution does the same)
            m.tendon_lengthspring[t, 0] = mb.half_backlash if band else 0.0
            m.tendon_lengthspring[t, 1] = mb.half_backlash if band else 0.0
            if band and not np.any(mb.half_backlash):
                break
            for _ in range(max_iter):
                iterations += 1
                r0 = residual(q)
                J = np.empty((m.nv, m.nv))
                h = 1e-7
                for j in range(m.nv):
                    dq = np.zeros(m.nv)
                    dq[j] = h
                    J[:, j] = (residual(q + dq) - residual(q - dq)) / (2 * h)
                step = np.linalg.lstsq(J, -r0, rcond=1e-12)[0]
                q = q + step
                res = float(np.max(np.abs(residual(q))))
                if np.max(np.abs(step)) < tol:
                    break
            else:
                raise SolverError(f"MuJoCo static state of {mb.spec.name}: Newton did not converge "
                                  f"(residual {res:.3g} m/s^2)")
        residual(q)
        delta = d.ten_length[t].copy()
        force = mb.excitation.mean_stiffness * deadzone(delta, mb.half_backlash)
        qpos, qvel, _ = _nominal(mb, q)
        return StaticState(qpos, qvel, delta, force, iterations, res)
    finally:
        m.tendon_stiffness[:] = saved_k
        m.tendon_lengthspring[:] = saved_l


# --------------------------------------------------------------------------- run


def simulate_mujoco(spec, duration: float, dt: float | None = None, output_dt: float | None = None,
                    settle: float | None = None, progress=None, stiffness_clock: str = "nominal",
                    initial_state=None, record_energy: bool = False, mb: MbdModel | None = None) -> TimeResult:
    """Run the MuJoCo model of ``spec`` for ``duration`` seconds; a :class:`TimeResult` like the lumped solver's.

    dt: RK4 step (default :func:`default_step`), refused above the stability limit.
    output_dt: sampling of the result (default every step).  settle: start of the
    steady-state window (default: the larger of the load ramp and half the duration).
    progress: callable(fraction).  stiffness_clock: "nominal" (k from the nominal mesh
    clock, like the lumped solver) or "bodies" (mesh position from the MuJoCo bodies'
    own rotation angles; transmission error stays on the nominal clock).
    initial_state: optional (qpos, qvel) instead of the static start.  record_energy:
    enable ``mjENBL_ENERGY`` and return MuJoCo's kinetic and potential energy in ``raw``.
    """
    if not (isinstance(duration, (int, float)) and duration > 0 and math.isfinite(duration)):
        raise SolverError(f"duration must be a positive number of seconds, got {duration!r}")
    if stiffness_clock not in ("nominal", "bodies"):
        raise SolverError(f"stiffness_clock must be 'nominal' or 'bodies', not {stiffness_clock!r}")
    mb = compile_train(spec) if mb is None else mb
    m = mb.model
    omega_max = max_angular_frequency(mb)
    if dt is None:
        dt = default_step(mb, omega_max)
    stepping.check_step(dt, omega_max, mb.excitation.frequency, f"MuJoCo model of {spec.name}")
    if output_dt is not None and not (output_dt > 0 and math.isfinite(output_dt)):
        raise SolverError(f"output_dt must be a positive number of seconds, got {output_dt!r}")
    every = 1 if output_dt is None else max(1, round(output_dt / dt))
    n_steps = every * max(1, math.ceil(duration / (dt * every) - 1e-9))  # ends on an output sample
    op = spec.operating
    load_scale = 0.0 if op.ramp > 0 else 1.0

    static = static_state(mb)
    if initial_state is None:
        start = static if load_scale == 1.0 else static_state(mb, load_scale)
        qpos0, qvel0 = start.qpos, start.qvel
    else:
        qpos0, qvel0 = (np.asarray(x, dtype=float) for x in initial_state)

    d = mujoco.MjData(m)
    saved = (m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.wrap_prm.copy(), m.opt.enableflags,
             m.opt.timestep, m.opt.integrator)
    m.opt.timestep = dt  # mj_RungeKutta steps by the model's own timestep
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    if record_energy:
        m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    d.qpos[:], d.qvel[:] = qpos0, qvel0
    d.time = 0.0
    try:
        started = clock.perf_counter()
        samples, energy = _loop(mb, d, dt, n_steps, every, progress, stiffness_clock, record_energy, static)
        wall = clock.perf_counter() - started
    finally:
        m.tendon_stiffness[:], m.tendon_lengthspring[:], m.wrap_prm[:] = saved[0], saved[1], saved[2]
        m.opt.enableflags, m.opt.timestep, m.opt.integrator = saved[3], saved[4], saved[5]
    sensordata, k_used = samples
    t = dt * every * np.arange(sensordata.shape[0])
    settle = max(op.ramp, 0.5 * duration) if settle is None else settle
    info = {"method": "mujoco-rk4", "integrator": "RK4", "dt_s": dt, "steps": n_steps, "wall_time_s": wall,
            "omega_max_rad_s": omega_max, "stable_step_s": stepping.stable_step(omega_max),
            "stiffness_clock": stiffness_clock, "mujoco_version": mujoco.__version__,
            "static_newton_iterations": static.iterations, "static_residual": static.residual,
            "forward_evaluations": 4 * n_steps}
    return _result(mb, t, sensordata, k_used, energy, static, settle, info)


def _loop(mb: MbdModel, d: mujoco.MjData, h: float, n_steps: int, every: int, progress, stiffness_clock: str,
          record_energy: bool, static: StaticState):
    """Step the model n_steps times; sample sensordata (and energy) every ``every`` steps, the first at t = 0."""
    m = mb.model
    drive = _Drive(mb)
    n_mesh = len(mb.mesh_tendon)
    n_out = n_steps // every + 1  # steps 0, every, 2 every, ... <= n_steps (as the lumped solver)
    record = np.empty((n_out, m.nsensordata))
    k_record = np.empty((n_out, n_mesh)) if stiffness_clock == "bodies" else None
    energy = np.empty((n_out, 2)) if record_energy else None
    # mesh tendons are the first tendons of the model (see mjcf_builder): a slice, not a gather
    assert np.array_equal(mb.mesh_tendon, np.arange(n_mesh))
    stiff = m.tendon_stiffness
    lengthspring = m.tendon_lengthspring
    ctrl, qpos, qvel, sens = d.ctrl, d.qpos, d.qvel, d.sensordata
    prm = m.wrap_prm
    # world-frame slide coefficients: [x; y] = A @ (cos phi, sin phi) per wrap, phi its carrier's angle
    widx = np.concatenate([mb.rot_wrap_x, mb.rot_wrap_y])
    A = np.stack([np.concatenate([mb.rot_c0x, mb.rot_c0y]), np.concatenate([-mb.rot_c0y, mb.rot_c0x])], axis=1)
    cadr2 = np.concatenate([mb.rot_carrier_qadr, mb.rot_carrier_qadr])
    single = len(set(cadr2.tolist())) == 1
    phi_adr = int(cadr2[0]) if len(cadr2) else 0
    cs = np.zeros(2)
    buf = np.zeros(len(widx))
    dot = np.dot
    cos, sin = math.cos, math.sin

    forward, rk = mujoco.mj_forward, mujoco.mj_RungeKutta
    b = mb.half_backlash
    lo_hi = np.stack([-b, b], axis=1)
    scale = float(np.max(np.abs(static.mesh_deflection))) + float(np.max(b, initial=0.0)) + 1e-6
    has_te = drive.has_te
    bodies = stiffness_clock == "bodies"
    fast = single and not has_te and not bodies and energy is None
    c_mesh = mb.mesh_damping
    # mesh damping on the true deflection rate: J qvel misses (dc/dphi) phi' q of the turning coefficients
    J = np.zeros((n_mesh, m.nv))
    tadr, tnum, objid = m.tendon_adr, m.tendon_num, m.wrap_objid
    w_idx = np.concatenate([np.arange(tadr[i], tadr[i] + tnum[i]) for i in range(n_mesh)])
    J[np.concatenate([np.full(tnum[i], i) for i in range(n_mesh)]), m.jnt_dofadr[objid[w_idx]]] = prm[w_idx]
    rot_rows, rot_dofs = mb.rot_tendon, m.jnt_dofadr[objid[widx]]  # the entries that turn with the carrier
    rot_q, rot_phi, nx = mb.rot_slide_qadr, cadr2, len(mb.rot_wrap_x)
    c_rot = np.zeros((n_mesh, len(rot_q)))  # mesh damping per rotating wrap
    c_rot[mb.rot_tendon, np.arange(len(rot_q))] = c_mesh[mb.rot_tendon]
    applied = d.qfrc_applied
    swapped = np.empty(len(rot_q))
    A_turned = np.concatenate([-A[nx:], A[:nx]])  # single carrier: the turned pairs (-c_y, c_x) = A_turned @ cs
    multiply = np.multiply

    def damping_correction(de):
        """Generalized force c (de/dt - missing rate) J for the STE rate and the turning coefficients:
        a pair c_x = a cos(phi) - b sin(phi), c_y = a sin(phi) + b cos(phi) turns as (-c_y, c_x) phi'."""
        coef = prm[widx]
        J[rot_rows, rot_dofs] = coef
        swapped[:nx], swapped[nx:] = -coef[nx:], coef[:nx]
        force = -(c_rot @ (swapped * qvel[rot_phi] * qpos[rot_q]))
        if de is not None:
            force += c_mesh * de
        applied[:] = force @ J

    clock_info = _body_clock(mb) if bodies else None
    j = 0
    countdown = 0  # steps until the next sample
    for start in range(0, n_steps, CHUNK):
        stop = min(start + CHUNK, n_steps)
        (k1, k2), (u1, u2), (e1, e2), (de1, de2) = drive.arrays(h * np.arange(start, stop), h)
        if fast:
            # the common case, kept lean: per step 3 array writes, 2 coefficient writes, the damping
            # correction of damping_correction() in its single-carrier form, 2 MuJoCo calls
            for i in range(stop - start):
                phi = qpos[phi_adr]
                cs[0] = cos(phi)
                cs[1] = sin(phi)
                dot(A, cs, out=buf)
                prm[widx] = buf
                J[rot_rows, rot_dofs] = buf
                dot(A_turned, cs, out=swapped)
                multiply(swapped, qpos[rot_q], out=swapped)
                dot(dot(c_rot, swapped) * -qvel[phi_adr], J, out=applied)
                stiff[:n_mesh] = k1[i]
                ctrl[:] = u1[i]
                forward(m, d)
                if countdown == 0:
                    record[j] = sens
                    j += 1
                    countdown = every
                countdown -= 1
                stiff[:n_mesh] = k2[i]
                ctrl[:] = u2[i]
                rk(m, d, 4)
        else:
            for i in range(stop - start):
                if single:
                    phi = qpos[phi_adr]
                    cs[0] = cos(phi)
                    cs[1] = sin(phi)
                    dot(A, cs, out=buf)
                    prm[widx] = buf
                else:
                    mb.refresh(qpos)
                if bodies:
                    k_now, k_later = _body_stiffness(mb, clock_info, qpos, qvel, h)
                    stiff[:n_mesh] = k_now
                else:
                    stiff[:n_mesh] = k1[i]
                ctrl[:] = u1[i]
                if has_te:
                    lengthspring[:n_mesh] = e1[i][:, None] + lo_hi
                damping_correction(de1[i] if has_te else None)
                forward(m, d)
                if countdown == 0:
                    record[j] = sens
                    if k_record is not None:
                        k_record[j] = k_now
                    if energy is not None:
                        energy[j] = d.energy
                    j += 1
                    countdown = every
                countdown -= 1
                stiff[:n_mesh] = k_later if bodies else k2[i]
                ctrl[:] = u2[i]
                if has_te:
                    lengthspring[:n_mesh] = e2[i][:, None] + lo_hi
                damping_correction(de2[i] if has_te else None)
                rk(m, d, 4)
        t_now = stop * h
        if not (np.all(np.isfinite(qpos)) and np.all(np.isfinite(qvel))):
            raise DivergenceError(t_now, "MuJoCo state became NaN or infinite")
        delta = d.ten_length[:n_mesh]
        if np.max(np.abs(delta), initial=0.0) > DIVERGENCE_FACTOR * scale:
            raise DivergenceError(t_now, f"mesh deflection {np.max(np.abs(delta)):.3g} m is over "
                                         f"{DIVERGENCE_FACTOR:g} times the static scale {scale:.3g} m: runaway energy")
        if progress is not None:
            progress(stop / n_steps)
    if j < n_out:  # the final state (n_steps is a multiple of every)
        t_end = np.array([n_steps * h + STAGE_OFFSETS[0] * h])
        mb.refresh(qpos)
        if bodies:
            k_now, _ = _body_stiffness(mb, clock_info, qpos, qvel, h)
            k_record[j] = k_now
            stiff[:n_mesh] = k_now
        else:
            stiff[:n_mesh] = mb.excitation.stiffness(t_end)[0]
        ctrl[:] = drive.controls(t_end)[0]
        e, de = mb.excitation.transmission_error(t_end)
        if has_te:
            lengthspring[:n_mesh] = e[0][:, None] + lo_hi
        damping_correction(de[0] if has_te else None)
        forward(m, d)
        record[j] = sens
        if energy is not None:
            energy[j] = d.energy
        j += 1
    return (record[:j], None if k_record is None else k_record[:j]), (None if energy is None else energy[:j])


def _body_clock(mb: MbdModel):
    spec, kin = mb.spec, mb.kin
    rows = []
    for mesh in spec.meshes:
        carrier = spec.stage_of(mesh.planet).carrier
        rel = kin.speeds[mesh.central] - kin.speeds[carrier]
        rows.append((mb.qadr[mesh.central][2], mb.qadr[carrier][2], mb.dadr[mesh.central][2], mb.dadr[carrier][2],
                     math.copysign(1.0, rel) * mesh.central_gear.teeth / (2 * math.pi)))
    qc, qk, vc, vk, gain = (np.array(x) for x in zip(*rows))
    return qc, qk, vc, vk, gain


def _body_stiffness(mb: MbdModel, info, qpos, qvel, h):
    """k from the mesh position of the MuJoCo bodies: xi = sign z (theta_central - theta_carrier)/2pi - phase."""
    qc, qk, vc, vk, gain = info
    xi = gain * (qpos[qc] - qpos[qk]) - mb.excitation.phase
    rate = gain * (qvel[vc] - qvel[vk])
    models = mb.excitation.models
    k_now = np.array([mdl(x) for mdl, x in zip(models, xi)], dtype=float)
    k_mid = np.array([mdl(x) for mdl, x in zip(models, xi + 0.5 * h * rate)], dtype=float)
    k_end = np.array([mdl(x) for mdl, x in zip(models, xi + h * rate)], dtype=float)
    return k_now, STEP_WEIGHTS[0] * k_mid + STEP_WEIGHTS[1] * k_end


# --------------------------------------------------------------------------- result


def _result(mb: MbdModel, t, S, k_used, energy, static: StaticState, settle, info) -> TimeResult:
    spec, exc = mb.spec, mb.excitation
    sensor = mb.sensor

    def series(name):
        adr, dim = sensor[name]
        return S[:, adr:adr + dim]

    members = list(spec.members)
    acc = np.empty((t.size, len(members), 3))
    angle = np.empty((t.size, len(members)))
    for jm, mid in enumerate(members):
        member = spec.members[mid]
        carrier = spec.members[spec.stage_of(mid).carrier]
        phi = series(f"{carrier.label}_angle")[:, 0] + member.angle
        lin = series(f"{member.label}_linacc")
        c, s = np.cos(phi), np.sin(phi)
        acc[:, jm, 0] = c * lin[:, 0] + s * lin[:, 1]
        acc[:, jm, 1] = -s * lin[:, 0] + c * lin[:, 1]
        acc[:, jm, 2] = series(f"{member.label}_angacc")[:, 2]
        angle[:, jm] = phi
    delta = np.column_stack([series(f"{m.label}_deflection")[:, 0] for m in spec.meshes])
    rate = np.column_stack([series(f"{m.label}_rate")[:, 0] for m in spec.meshes])
    # the true deflection rate: J qvel plus the turning coefficients' part (see MbdModel.coefficient_rate)
    wrap_carrier = np.concatenate([mb.rot_carrier_qadr, mb.rot_carrier_qadr])
    carrier_label = {mb.qadr[s.carrier][2]: spec.members[s.carrier].label for s in spec.stages}
    slide_label = {q: f"{spec.members[mid].label}_{axis}" for mid, qa in mb.qadr.items()
                   if not spec.members[mid].is_planet for q, axis in zip(qa[:2], ("x", "y"))}
    phi = np.column_stack([series(f"{carrier_label[q]}_angle")[:, 0] for q in wrap_carrier])
    phidot = np.column_stack([series(f"{carrier_label[q]}_angle_rate")[:, 0] for q in wrap_carrier])
    slide = np.column_stack([series(f"{slide_label[q]}_pos")[:, 0] for q in mb.rot_slide_qadr])
    rate = rate + mb.coefficient_rate(phi, phidot, slide)
    t_drive = t + STAGE_OFFSETS[0] * info["dt_s"]  # the drive of the step starting at each sample
    k = exc.stiffness(t_drive) if k_used is None else k_used
    e, de = exc.transmission_error(t_drive)
    force = k * deadzone(delta - e, mb.half_backlash) + mb.mesh_damping * (rate - de)
    names, bearing = [], []
    for mid, member in spec.members.items():
        if member.is_planet:
            for axis in ("radial", "tangential"):
                names.append(f"{mid}.bearing_{axis}")
                pos = series(f"{member.label}_{axis}_pos")[:, 0]
                vel = series(f"{member.label}_{axis}_vel")[:, 0]
                bearing.append(member.bearing.radial_stiffness * pos + member.bearing.radial_damping * vel)
    raw = {}
    for name, (adr, dim) in sensor.items():
        if dim == 1:
            raw[name] = S[:, adr]
        else:
            for c_i, axis in zip(range(dim), "xyz"):
                raw[f"{name}_{axis}"] = S[:, adr + c_i]
    if energy is not None:  # MuJoCo's d.energy is (potential, kinetic)
        raw["energy_potential"] = energy[:, 0]
        raw["energy_kinetic"] = energy[:, 1]
    return TimeResult(
        train=spec.name, solver="mujoco", t=t, members=members, acc_carrier=acc, carrier_angle=angle,
        mesh_ids=[m.id for m in spec.meshes], mesh_deflection=delta, mesh_force=force, mesh_stiffness=k,
        static_mesh_force=static.mesh_force, bearing_names=names,
        bearing_force=np.column_stack(bearing) if bearing else None, settle_time=settle, info=info, raw=raw,
    )
