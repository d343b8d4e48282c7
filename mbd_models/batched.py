"""The MuJoCo runner batched: many worlds of one twin (a sweep's speeds) stepped at once by MJX, on a GPU where
JAX has one, in float64.

MJX is MuJoCo's own pipeline written in JAX (``mujoco-mjx``: the same kinematics, tendons, passive forces,
actuators and sensors as the C library; on hub-drive its ``forward`` gives the C library's accelerations to
6e-16 of their size).  Each world steps as :mod:`gearcheck.mbd_models.runner` steps one twin: classical RK4 with
its four stages written out, each driven from its own state at its own time (the mesh stiffness, controls and
transmission error's spring lengths from the drive, the mesh tendons' coefficients turned to the carrier's angle,
the damping correction J^T g in ``qfrc_applied``); a step inside which a mesh stiffness jumps is taken as RK4
sub-steps ended there; a backlash's edges crossed inside a step are located on the cubic Hermite interpolant of
the switching functions and the step is taken again in parts (Hairer, Norsett & Wanner 1993, sec. II.6), at most
:data:`~gearcheck.shared.events.MAX_EVENTS` a step.  The worlds' steps run as one ``lax.scan`` over sub-step
slots: each world has its own list of sub-steps (its own step, splits and length of run), padded with steps of
length zero, which leave a state as it is.  Every world takes its whole step; those with a contact event are
gathered, a :data:`GROUP` of the worlds at a time, and retake theirs in parts, the others waiting for none of it.
RK4's stages run as one loop and the parts of a retaken step as another, so that one forward dynamics is compiled.

The drive (the excitation's functions of time) is computed on the host, as the CPU runner computes it (its
``_Drive``), a chunk of steps at a time.  The device returns the states at the sampled steps, and the host takes
the samples there as the CPU runner takes them: the stage set, MuJoCo's C ``mj_forward``, its sensors and the force
reader's rows (:class:`~gearcheck.mbd_models.forces.ForceReader`), then each world's
:class:`~gearcheck.shared.results.TimeResult` as the CPU runner builds it.  (Samples taken on the device with MJX's
sensors came back, in two of three CI runs, with a hub-drive world's accelerations not finite at some samples, which
no rerun reproduced.)

Precision: float64 (``jax_enable_x64``, set for the whole process when the runner is first used).  The twin's
joints really turn (about 105 rad in 0.5 s at 2000 rpm), which float32 resolves to about 1e-5 rad, some 10 % of a
mesh deflection: MuJoCo Warp, float32 only, is not used.

Not batched (refused with the reason, :func:`batched_unsupported`): an RV reducer's moving pin contacts, tip
relief's tooth pairs, torsional planets (their mesh forces are read one mesh at a time), joints other than hinges
and slides, tendons other than fixed ones or with armature; the stiffness runs on the nominal clock.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import io
import math
import re
import time as clock

import mujoco
import numpy as np

from gearcheck.mbd_models import runner
from gearcheck.mbd_models.jacobians import tendon_rows
from gearcheck.mbd_models.twin import MbdModel
from gearcheck.shared import divergence, stepping
from gearcheck.shared.errors import SolverError
from gearcheck.shared.events import APART, MAX_EVENTS, MIN_FRACTION, SIMULTANEOUS, hermite
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings

CHUNK = 4096  # steps of every world computed on the host and sent to the device at once, at most
WORLD_STEPS = 2**18  # and world-steps (a chunk's drive and states: about 450 MB on hub-drive)
_HERMITE = hermite.py_func  # the event numerics' cubic, on JAX's arrays
GROUP = 0.25  # the fraction of the worlds whose steps with contact events are retaken together
BUCKET = 512  # a chunk's slots and samples are padded to a multiple of this
_TIMESTEP = re.compile(r' timestep="[^"]*"')


def _mjx():
    """MJX, imported without the line it prints where MuJoCo Warp is not installed (not used here)."""
    with contextlib.redirect_stdout(io.StringIO()):
        from mujoco import mjx
    return mjx


def available() -> str | None:
    """Why the batched runner cannot run here (None: it can): JAX and MJX are the optional ``gpu`` extra."""
    try:
        import jax  # noqa: F401
        _mjx()
    except ImportError as exc:
        return f"the batched MuJoCo runner needs JAX and MJX (pip install 'gearcheck[gpu]'): {exc}"
    return None


def device() -> str:
    """The device JAX computes on, in words (the card's name on a GPU)."""
    import jax
    d = jax.devices()[0]
    return f"{d.platform}: {getattr(d, 'device_kind', d)}"


def batched_unsupported(mb: MbdModel) -> str | None:
    """Why the batched runner cannot run ``mb`` (None: it can)."""
    m = mb.model
    if mb.moving_contacts:
        return "its moving contacts (an RV reducer's pins) are not batched"
    if mb.excitation.relieved.size:
        return "tip relief's tooth pairs are not batched"
    if any(member.torsional and member.orbits for member in mb.spec.members.values()):
        return "a torsional planet's mesh forces are read one mesh at a time"
    if np.any(m.wrap_type != int(mujoco.mjtWrap.mjWRAP_JOINT)) or np.any(m.tendon_armature):
        return "only fixed tendons without armature are batched"
    kinds = set(m.jnt_type.tolist()) - {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}
    if kinds:
        return "only hinges and slides are batched"
    return None


@dataclasses.dataclass
class _World:
    """One world's run on the host: its twin, step, samples and the CPU runner's stepper (drive, force reader,
    sample rows) that its samples go into."""

    mb: MbdModel
    settings: RunSettings
    dt: float
    n_steps: int
    every: int
    static: object
    stepper: runner._Stepper
    sub_steps: int = 0
    located: int = 0


def _same_model(twins) -> None:
    """The worlds share one compiled model: their MJCF alike but for the step a viewer takes."""
    first = _TIMESTEP.sub("", twins[0].xml)
    for mb in twins[1:]:
        if _TIMESTEP.sub("", mb.xml) != first:
            raise SolverError(f"simulate_mujoco_batch: the twin of {mb.spec.name} is not the first world's model "
                              "(worlds may differ in their operating point only)")


def simulate_mujoco_batch(twins, settings, progress=None, initial_states=None) -> list:
    """Run several worlds of one twin (the same train at other operating points: a sweep's speeds) at once with
    MJX, each as :func:`gearcheck.mbd_models.runner.simulate_mujoco` runs it on the "nominal" clock; their
    :class:`~gearcheck.shared.results.TimeResult` in order, ``info.engine`` "mujoco-batched".

    settings: one :class:`RunSettings` for all, or one per world.  initial_states: optional (qpos, qvel, act) per
    world (None: its static start).  progress: callable(fraction)."""
    why = available()
    if why:
        raise SolverError(why)
    twins = list(twins)
    if not twins:
        return []
    runs = list(settings) if isinstance(settings, (list, tuple)) else [settings] * len(twins)
    if len(runs) != len(twins):
        raise SolverError(f"simulate_mujoco_batch: {len(runs)} settings for {len(twins)} worlds")
    for mb in twins:
        why = batched_unsupported(mb)
        if why:
            raise SolverError(f"the batched MuJoCo runner cannot run {mb.spec.name}: {why}")
    _same_model(twins)
    starts = initial_states or [None] * len(twins)
    began = clock.perf_counter()
    worlds = []
    for mb, run, state in zip(twins, runs, starts):
        dt, n_steps, every, static, (qpos, qvel, act) = runner.prepare(mb, run, state)
        d = mujoco.MjData(mb.model)
        d.qpos[:], d.qvel[:] = qpos, qvel
        if act is not None:
            d.act[:] = act
        stepper = runner._Stepper(mb, d, dt, n_steps // every + 1, False, False, run.start)
        worlds.append(_World(mb, run, dt, n_steps, every, static, stepper))
    started = clock.perf_counter()
    timing = _program(worlds[0]).run(worlds, progress)
    wall = clock.perf_counter() - started
    timing.update(prepare_s=started - began, loop_s=wall)
    results = []
    for i, w in enumerate(worlds):
        mb, s = w.mb, w.stepper
        t = w.settings.start + w.dt * w.every * np.arange(s.j)
        columns = [mb.sensor[f"{mesh.label}_deflection"][0] for mesh in mb.spec.meshes]
        divergence.check(t, s.sensors[:s.j][:, columns],
                         divergence.deflection_scale(w.static.mesh_deflection, mb.half_backlash),
                         f"MuJoCo model of {mb.spec.name} at {mb.spec.operating.input_speed * 30 / math.pi:.6g} rpm "
                         f"(world {i})")
        info = RunInfo("mujoco-batched", w.n_steps, 4, 4 * w.sub_steps, wall, {
            "method": "mujoco-rk4", "integrator": "RK4", "dt_s": w.dt, "steps": w.n_steps, "wall_time_s": wall,
            "omega_max_rad_s": mb.omega_max, "stable_step_s": stepping.stable_step(mb.limits),
            "stiffness_clock": "nominal", "mujoco_version": mujoco.__version__, "engine": "batched",
            "worlds": len(worlds), "device": device(), "forward_evaluations": 4 * w.sub_steps,
            "contact_events_located": w.located,
            "static_newton_iterations": w.static.iterations, "static_residual": w.static.residual,
            "timing_s": timing})
        results.append(runner._result(mb, s, t, w.static, w.settings.settle_time(mb.spec.operating.ramp), info,
                                      w.settings.signals))
    return results


def _sample(stepper: runner._Stepper, states, drive) -> None:
    """The CPU runner's samples at the device's ``states`` (qpos, qvel, act; one row a sample), each with the drive
    of its step's first stage (k, u, e, de; e and de None without a transmission error): the stage set and
    ``mj_forward`` by MuJoCo's C library, the sensors and the force reader's row as the CPU runner takes them, on its
    twin's model, whose fields are restored after."""
    m, d = stepper.m, stepper.d
    saved = m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.wrap_prm.copy()
    try:
        for row, (qpos, qvel, act) in enumerate(zip(*states)):
            d.qpos[:], d.qvel[:], d.act[:] = qpos, qvel, act
            stepper.sample_at(drive, row)
    finally:
        m.tendon_stiffness[:], m.tendon_lengthspring[:], m.wrap_prm[:] = saved


_PROGRAMS: dict = {}  # compiled programs by twin's model (its MJCF but for the step), the latest used last
KEPT = 4  # programs kept for later runs (each holds its model on the device and its compiled chunks)


def _program(world: _World) -> "_Program":
    key = _TIMESTEP.sub("", world.mb.xml)
    program = _PROGRAMS.pop(key, None) or _Program(world)
    _PROGRAMS[key] = program
    while len(_PROGRAMS) > KEPT:
        del _PROGRAMS[next(iter(_PROGRAMS))]
    return program


class _Program:
    """The device side of one twin: its models in MJX, the worlds' stepping in JAX (compiled once per shape of a
    chunk), and the host's drive and samples around it."""

    def __init__(self, world: _World):
        import jax
        jax.config.update("jax_enable_x64", True)
        mjx = _mjx()

        self.jax, self.mjx = jax, mjx
        mb = world.mb
        m = mb.model
        self.n_mesh = len(mb.mesh_tendon)
        self.n_corr = len(mb.corrected)
        self.nu = m.nu
        # the program's own copy of the model, kept as long as it is (the twin's model is written by every run),
        # without sensors: the samples are taken on the host
        self.host = copy.copy(m)
        self.host.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_SENSOR
        self.model = mjx.put_model(self.host)
        self.data = mjx.make_data(self.model)
        tc = mb.turning
        jnp = jax.numpy
        self.tc = dict(wraps=jnp.array(tc.wraps), base=jnp.array(tc.base), carrier=jnp.array(tc.carrier_qadr),
                       tendon=jnp.array(tc.tendon), joint_qadr=jnp.array(tc.joint_qadr),
                       joint_dof=jnp.array(tc.joint_dof))
        correction = world.stepper.correction  # its damping per turning wrap, as the CPU runner applies it
        self.J0 = jnp.array(tendon_rows(m, mb.corrected))
        self.c_wrap = jnp.array(correction.c_wrap)
        self.c = jnp.array(correction.c)
        self.half = len(tc.wraps) // 2
        self.wrap_prm = jnp.array(m.wrap_prm)
        self.lo_hi = jnp.array(np.stack([-mb.half_backlash, mb.half_backlash], axis=1))
        self.lengthspring = jnp.array(m.tendon_lengthspring)
        self.stiffness = jnp.array(m.tendon_stiffness)
        sw = runner.mesh_switches(mb)
        self.n_switch = sw.count
        segment = np.repeat(np.arange(len(sw.tendons)), np.diff(sw.starts))
        self.sw = dict(wraps=jnp.array(sw.wraps), qadr=jnp.array(sw.qadr), dofs=jnp.array(sw.dofs),
                       segment=jnp.array(segment), tendons=jnp.array(sw.tendons),
                       half=jnp.array(sw.half_backlash), count=len(sw.tendons))
        self._chunk = jax.jit(self._scan)

    # ------------------------------------------------------------------ one world's physics (vmapped)

    def _coefficients(self, qpos):
        """wrap_prm with the turning tendons' coefficients at the carriers' angles (``MbdModel.refresh``)."""
        tc = self.tc
        phi = qpos[tc["carrier"]]
        return self.wrap_prm.at[tc["wraps"]].set(tc["base"][:, 0] * self.jax.numpy.cos(phi)
                                                   + tc["base"][:, 1] * self.jax.numpy.sin(phi))

    def _correction(self, wrap_prm, qpos, qvel, de):
        """The damping correction's generalized force J^T g and its g (``DampingCorrection.apply``)."""
        jnp, tc, n = self.jax.numpy, self.tc, self.half
        coef = wrap_prm[tc["wraps"]]
        J = self.J0.at[tc["tendon"], tc["joint_dof"]].set(coef)
        turned = jnp.concatenate([-coef[n:], coef[:n]])
        g = -(self.c_wrap @ (turned * qvel[tc["carrier"]] * qpos[tc["joint_qadr"]]))
        g = g.at[:self.n_mesh].add(self.c[:self.n_mesh] * de)
        return g @ J

    def _set(self, model, qpos, qvel, act, k, u, e, de):
        """The model and data of a stage (``_Stepper.set_stage``)."""
        wrap_prm = self._coefficients(qpos)
        n = self.n_mesh
        stiffness = self.stiffness.at[:n].set(k)
        lengths = self.lengthspring.at[:n].set(e[:, None] + self.lo_hi)
        mx = model.replace(tendon_stiffness=stiffness, tendon_lengthspring=lengths)
        dx = self.data.replace(qpos=qpos, qvel=qvel, act=act, ctrl=u,
                               qfrc_applied=self._correction(wrap_prm, qpos, qvel, de))
        return mx, dx, wrap_prm

    def _rate(self, qpos, qvel, act, drive):
        mx, dx, wrap_prm = self._set(self.model, qpos, qvel, act, *drive)
        dx = _forward(self.mjx, mx, dx, wrap_prm)
        return dx.qacc, dx.act_dot

    def _rk4(self, state, h, drive):
        """One RK4 (sub-)step of length h, the drive (k, u, e, de) at its stage times t, t + h/2, t + h; its four
        stages one loop (one forward dynamics to compile)."""
        jax, jnp = self.jax, self.jax.numpy
        qpos0, qvel0, act0 = state
        stages = [jnp.stack([x[s] for s in (0, 1, 1, 2)]) for x in drive]
        advance = jnp.asarray((0.0, 0.5, 0.5, 1.0))
        weights = jnp.asarray(runner.RK4_WEIGHTS)

        def stage(carry, inputs):
            (velocity, acceleration, activation), total = carry
            a, weight, stage_drive = inputs
            qpos, qvel, act = qpos0 + velocity * a * h, qvel0 + acceleration * a * h, act0 + activation * a * h
            qacc, act_dot = self._rate(qpos, qvel, act, stage_drive)
            rate = (qvel, qacc, act_dot)
            return (rate, tuple(t + r * weight for t, r in zip(total, rate))), None

        zero = (jnp.zeros_like(qvel0), jnp.zeros_like(qvel0), jnp.zeros_like(act0))
        (_, (velocity, acceleration, activation)), _ = jax.lax.scan(stage, (zero, zero), (advance, weights, stages))
        return qpos0 + velocity * h, qvel0 + acceleration * h, act0 + activation * h

    def _switching(self, state, e, de):
        """The backlash edges' switching functions y -/+ b and their rates (``_Stepper.switching``)."""
        jnp, sw, tc = self.jax.numpy, self.sw, self.tc
        qpos, qvel, _ = state
        wrap_prm = self._coefficients(qpos)
        segments = sw["count"]
        length = self.jax.ops.segment_sum(wrap_prm[sw["wraps"]] * qpos[sw["qadr"]], sw["segment"], segments)
        speed = self.jax.ops.segment_sum(wrap_prm[sw["wraps"]] * qvel[sw["dofs"]], sw["segment"], segments)
        turned = tc["base"][:, 1] * jnp.cos(qpos[tc["carrier"]]) - tc["base"][:, 0] * jnp.sin(qpos[tc["carrier"]])
        missing = self.jax.ops.segment_sum(turned * qvel[tc["carrier"]] * qpos[tc["joint_qadr"]], tc["tendon"],
                                           self.n_corr)[:self.n_mesh]
        speed = speed + missing[sw["tendons"]]
        y = length - e[sw["tendons"]]
        dy = speed - de[sw["tendons"]]
        b = sw["half"]
        return (jnp.stack([y - b, y + b], axis=1).reshape(-1), jnp.stack([dy, dy], axis=1).reshape(-1))

    def _first_crossing(self, g0, r0, g1, r1, span):
        """:func:`gearcheck.shared.events.first_crossing` over every function at once: (fraction, function)."""
        jnp, lax = self.jax.numpy, self.jax.lax
        G0, R0, G1, R1 = g0, r0 * span, g1, r1 * span
        skip = (G0 * G1 > 0.0) & (jnp.minimum(jnp.abs(G0), jnp.abs(G1)) > APART * (jnp.abs(R0) + jnp.abs(R1)))
        a3, a2 = 2 * G0 + R0 - 2 * G1 + R1, -3 * G0 - 2 * R0 + 3 * G1 - R1
        disc = a2 * a2 - 3 * a3 * R0
        root = jnp.sqrt(jnp.maximum(disc, 0.0))
        safe3 = jnp.where(a3 != 0.0, a3, 1.0)
        turn1 = jnp.where(a3 != 0.0, (-a2 - root) / (3 * safe3), -R0 / jnp.where(a2 != 0.0, 2 * a2, 1.0))
        turn2 = jnp.where(a3 != 0.0, (-a2 + root) / (3 * safe3), 2.0)
        heading = (G0 * R0 < 0.0) & (disc >= 0.0)
        end = jnp.full_like(G0, 2.0)
        for turn in (turn1, turn2):
            dips = heading & (0.0 < turn) & (turn < jnp.minimum(end, 1.0)) & (_HERMITE(G0, R0, G1, R1, turn) * G0 < 0.0)
            end = jnp.where(dips, turn, end)
        end = jnp.where(G0 * G1 < 0.0, 1.0, end)
        searched = ~skip & (end <= 1.0)
        end = jnp.where(searched, end, 1.0)

        def unsettled(carry):
            return ~jnp.all(carry[5]) & (carry[6] < 60)

        def illinois(carry):
            a, b, fa, fb, side, done, i = carry
            theta = (a * fb - b * fa) / jnp.where(fb - fa != 0.0, fb - fa, 1.0)
            f = _HERMITE(G0, R0, G1, R1, theta)
            flip = f * fb < 0.0
            a_new, fa_new = jnp.where(flip, b, a), jnp.where(flip, fb, jnp.where(side == 1, 0.5 * fa, fa))
            stop = (f == 0.0) | (jnp.abs(theta - a_new) < 1e-12)
            keep = lambda new, old: jnp.where(done, old, new)
            return (keep(a_new, a), keep(theta, b), keep(fa_new, fa), keep(f, fb),
                    keep(jnp.where(flip, 0, 1), side), done | stop, i + 1)

        zero = jnp.zeros_like(G0)
        a, b, fa, fb, *_ = lax.while_loop(unsettled, illinois, (zero, end, G0, _HERMITE(G0, R0, G1, R1, end),
                                                                 jnp.zeros(G0.shape, dtype=jnp.int32), ~searched,
                                                                 jnp.asarray(0)))
        root = jnp.where(fb * G0 <= 0.0, b, a)
        root = jnp.where(searched, root, 2.0)
        which = jnp.argmin(root)
        return root[which], which

    def _part_of(self, drive, a, b):
        """The drive of the part from fraction a to b of a step (:func:`gearcheck.shared.events.samples_between`)."""
        jnp = self.jax.numpy
        out = []
        for x in drive:
            rows = []
            for s in range(3):
                t = a + 0.5 * s * (b - a)
                w0, w1, w2 = 2.0 * (t - 0.5) * (t - 1.0), -4.0 * t * (t - 1.0), 2.0 * t * (t - 0.5)
                rows.append(w0 * x[0] + w1 * x[1] + w2 * x[2])
            out.append(jnp.stack(rows))
        return out

    def _first(self, state, h, drive):
        """One world's whole (sub-)step and its first contact event, if any (``_Stepper.step``): (the state at the
        step's end, the switching functions and rates at its start, the crossing's fraction and function)."""
        _, _, e, de = drive
        end = self._rk4(state, h, drive)
        g0, r0 = self._switching(state, e[0], de[0])
        return (end, g0, r0, *self._first_crossing(g0, r0, *self._switching(end, e[2], de[2]), h))

    def _events(self, start, end, g0, r0, theta, crossed, h, drive):
        """One world's step retaken in parts at its contact events, the first at ``theta`` (``_Stepper.step``): the
        state after it and how many events it located.  One RK4 call a pass (one to compile): the part up to an
        event, then the rest after it, while the rest holds another."""
        jnp, lax = self.jax.numpy, self.jax.lax
        _, _, e, de = drive

        def going(c):  # phase 0: the next part ends at the step's end; 1: at an event; 2: done
            return c[7] != 2

        def part(c):
            origin, _, a, b, g0, r0, n, phase, _ = c
            piece = self._part_of(drive, a, b)
            new = self._rk4(origin, (b - a) * h, piece)
            # reached an event (phase 1): go on from it, its functions crossed at their kinks
            g, r = self._switching(new, piece[2][2], piece[3][2])
            g = g.at[c[8]].set(0.0)
            g = jnp.where(jnp.abs(g) <= SIMULTANEOUS * jnp.abs(r) * (b - a) * h, 0.0, g)
            # reached the step's end (phase 0): a crossing on the way?
            theta, crossed = self._first_crossing(g0, r0, *self._switching(new, e[2], de[2]), (1.0 - a) * h)
            found = _found(theta, n)
            at = a + theta * (1.0 - a)
            event = phase == 1
            pick = lambda x, y: self.jax.tree_util.tree_map(lambda u, v: jnp.where(event, u, v), x, y)
            return (pick(new, origin), new, jnp.where(event, b, a), jnp.where(event, 1.0, jnp.where(found, at, b)),
                    pick(g, g0), pick(r, r0), n + (~event & found), jnp.where(event, 0, jnp.where(found, 1, 2)),
                    jnp.where(event, c[8], crossed))

        found = _found(theta, 0)
        out = lax.while_loop(going, part, (start, end, jnp.asarray(0.0), jnp.where(found, theta, 1.0), g0, r0,
                                           found.astype(jnp.int64), jnp.where(found, 1, 2), crossed))
        return out[1], out[6]

    def _slot(self, state, h, drive):
        """Every world's (sub-)step of one slot: the whole step of all, then the steps of those with a contact
        event retaken in parts, gathered a group of :data:`GROUP` (a fraction of the worlds) at a time, so that
        the worlds without one wait for no retaken part.  The states after it and the events located."""
        jax, jnp = self.jax, self.jax.numpy
        worlds = h.shape[0]
        located = jnp.zeros(worlds, dtype=jnp.int64)
        if not self.n_switch:
            return jax.vmap(self._rk4)(state, h, drive), located
        end, g0, r0, theta, crossed = jax.vmap(self._first)(state, h, drive)
        size = max(1, int(math.ceil(GROUP * worlds)))
        events = jax.vmap(self._events)

        def pending(c):
            return jnp.any(c[1])

        def group(c):
            end, need, located = c
            at = jnp.nonzero(need, size=size, fill_value=0)[0]
            kept = jnp.where(jnp.arange(size) < jnp.sum(need), at, worlds)  # past the end: dropped when written
            pick = lambda x: jax.tree_util.tree_map(lambda y: y[at], x)
            new, n = events(pick(state), pick(end), g0[at], r0[at], theta[at], crossed[at], h[at], pick(drive))
            end = jax.tree_util.tree_map(lambda old, x: old.at[kept].set(x, mode="drop"), end, new)
            return end, need.at[kept].set(False, mode="drop"), located.at[kept].add(n, mode="drop")

        end, _, located = jax.lax.while_loop(pending, group, (end, _found(theta, 0), located))
        return end, located

    # ------------------------------------------------------------------ the worlds together

    def _scan(self, state, h, drive, take):
        """The worlds' slots of one chunk: ``h`` (slots, worlds), ``drive`` four arrays (slots, worlds, 3, ...),
        ``take`` (worlds, samples) the slots whose first stage is sampled; the state after them, the states at the
        sampled slots' starts, and the events located per world."""
        jax, jnp = self.jax, self.jax.numpy

        def body(carry, slot):
            state, located = carry
            h, drive = slot
            new, n = self._slot(state, h, drive)
            return (new, located + n), state

        (state, located), before = jax.lax.scan(body, (state, jnp.zeros(h.shape[1], dtype=jnp.int64)), (h, drive))
        worlds = jnp.arange(h.shape[1])[:, None]
        return state, [x[take, worlds] for x in before], located  # the sampled slots' states (worlds, samples, .)

    def _layout(self, w: _World, start: int, stop: int, final: bool):
        """One world's sub-steps over its steps start..stop-1 (none past its run), the final sample's zero-length
        step after its last: (starts, lengths, sampled)."""
        stop = min(stop, w.n_steps)
        t0, h = w.settings.start, w.dt
        if stop <= start:
            starts, lengths, sampled = np.empty(0), np.empty(0), np.zeros(0, dtype=bool)
        else:
            split = stepping.split_steps(h, start, stop, w.mb.excitation.switch_times(t0 + start * h, t0 + stop * h),
                                         t0)
            steps = np.arange(start, stop)
            counts = np.ones(steps.size, dtype=np.int64)
            parts, sub_starts, sub_lengths = stepping.sub_steps(t0, h, split)
            at = np.array(sorted(split), dtype=np.int64) - start
            counts[at] = parts
            first = np.cumsum(counts) - counts
            starts, lengths = t0 + h * np.repeat(steps, counts), np.full(int(counts.sum()), h)
            inside = np.repeat(counts > 1, counts)
            starts[inside], lengths[inside] = sub_starts, sub_lengths
            sampled = np.zeros(starts.size, dtype=bool)
            sampled[first] = steps % w.every == 0
            w.sub_steps += starts.size
        if final:
            starts = np.append(starts, t0 + w.n_steps * h)
            lengths = np.append(lengths, 0.0)
            sampled = np.append(sampled, True)
        return starts, lengths, sampled

    def run(self, worlds: list[_World], progress=None) -> dict:
        """Step ``worlds`` over their runs, their samples into their steppers; the seconds spent on the host's
        drive and on the device (its compiling included), and the slots stepped."""
        jnp = self.jax.numpy
        timing = {"drive_s": 0.0, "device_s": 0.0, "samples_s": 0.0, "slots": 0}
        state = tuple(jnp.array(np.stack([getattr(w.stepper.d, name) for w in worlds]))
                      for name in ("qpos", "qvel", "act"))
        total = max(w.n_steps for w in worlds)
        chunk = min(CHUNK, max(BUCKET, WORLD_STEPS // len(worlds) // BUCKET * BUCKET))
        for start in range(0, total + 1, chunk):
            stop = start + chunk
            began = clock.perf_counter()
            layouts = [self._layout(w, start, stop, start <= w.n_steps < stop) for w in worlds]
            slots = _bucket(max(len(lay[0]) for lay in layouts))  # few shapes: each is compiled once
            samples = _bucket(max(int(lay[2].sum()) for lay in layouts))
            h = np.zeros((slots, len(worlds)))
            drive = [np.zeros((slots, len(worlds), 3, n)) for n in (self.n_mesh, self.nu, self.n_mesh, self.n_mesh)]
            take = np.zeros((len(worlds), samples), dtype=np.int64)
            counts = []
            for i, (w, (starts, lengths, sampled)) in enumerate(zip(worlds, layouts)):
                if not starts.size:
                    counts.append(0)
                    continue
                k, u, e, de, _ = w.stepper.drive.steps(starts, lengths)
                h[:starts.size, i] = lengths
                for target, values in zip(drive, (k, u, e, de)):
                    if values is not None:
                        target[:starts.size, i] = values
                where = np.flatnonzero(sampled)
                take[i, :where.size] = where
                counts.append(where.size)
            sent = clock.perf_counter()
            timing["drive_s"] += sent - began
            with _turning_tendons():
                state, picked, located = self._chunk(state, jnp.array(h), [jnp.array(x) for x in drive],
                                                     jnp.array(take))
            picked, located = [np.array(x) for x in picked], np.array(located)
            timing["device_s"] += clock.perf_counter() - sent
            timing["slots"] += slots
            began = clock.perf_counter()
            for i, (w, count) in enumerate(zip(worlds, counts)):
                slots_taken = take[i, :count]
                _sample(w.stepper, [x[i, :count] for x in picked],
                        [x[slots_taken, i, 0] if w.stepper.drive.has_te or j < 2 else None
                         for j, x in enumerate(drive)])
                w.located += int(located[i])
                w.sub_steps += 2 * int(located[i])
            timing["samples_s"] += clock.perf_counter() - began
            if progress is not None:
                progress(min(1.0, stop / total))
        final = [np.array(x) for x in state]
        for i, w in enumerate(worlds):
            w.stepper.d.qpos[:], w.stepper.d.qvel[:], w.stepper.d.act[:] = final[0][i], final[1][i], final[2][i]
        return timing


_COEFFICIENTS: list = []  # while a stage is traced: the fixed tendons' coefficients it turned (:func:`_forward`)


def _forward(mjx, model, data, wrap_prm):
    """MJX's ``forward`` with the fixed tendons' coefficients ``wrap_prm`` (traced: they turn with the carriers).
    MJX holds ``wrap_prm`` as a static field of its model, so they go to :func:`_turning_tendons` beside it."""
    _COEFFICIENTS.append(wrap_prm)
    try:
        return mjx.forward(model, data)
    finally:
        _COEFFICIENTS.pop()


@contextlib.contextmanager
def _turning_tendons():
    """MJX's ``smooth.tendon`` with the coefficients that :func:`_forward` passes: MJX's own ``tendon`` runs with
    every coefficient zero, then the fixed tendons' lengths and moments are added as MJX computes them (the sum of
    coefficient times joint position; the coefficients at the joints' dofs).  Every twin's tendons are fixed
    (:func:`batched_unsupported`)."""
    import jax
    from mujoco.mjx._src import smooth

    original = smooth.tendon

    def tendon(m, d):
        if not _COEFFICIENTS:
            return original(m, d)
        wrap_prm = _COEFFICIENTS[-1]
        d = original(m.replace(wrap_prm=np.zeros(m.nwrap)), d)
        tendon_id = np.repeat(np.arange(m.ntendon), m.tendon_num)
        qadr, dofadr = m.jnt_qposadr[m.wrap_objid], m.jnt_dofadr[m.wrap_objid]
        length = jax.ops.segment_sum(wrap_prm * d.qpos[qadr], tendon_id, m.ntendon)
        moment = d._impl.ten_J.at[tendon_id, dofadr].add(wrap_prm)
        return d.replace(ten_length=d.ten_length + length).tree_replace({"_impl.ten_J": moment})

    smooth.tendon = tendon
    try:
        yield
    finally:
        smooth.tendon = original


def _found(theta, located):
    """A crossing inside a step's part (not at its ends), while the step has events left to locate."""
    return (MIN_FRACTION < theta) & (theta < 1.0 - MIN_FRACTION) & (located < MAX_EVENTS)


def _bucket(n: int) -> int:
    """n rounded up to a multiple of :data:`BUCKET` (at least one)."""
    return max(1, -(-n // BUCKET)) * BUCKET
