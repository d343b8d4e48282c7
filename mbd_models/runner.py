"""The MuJoCo runner: the train really turning, every mesh's stiffness driven every step.

At every stage of every RK4 step (fixed step h), from the stage's own state and at its own time:

* mesh stiffness k(t) from :meth:`gearcheck.train.excitation.Excitation.stiffness` (the nominal
  clock, as the lumped solver) into ``m.tendon_stiffness``; a static transmission error
  e(t) shifts the tendons' spring length (``m.tendon_lengthspring`` = e -/+ b); a mesh with tip relief
  gets the stiffness and spring length of its tooth pairs in contact at the tendon's length
  (:class:`_ToothContacts`);
* the input speed w_in into the ``input_shaft`` integrated-velocity servo (whose activation
  is the reference angle, 0 at t = 0) and its ``input_shaft_damper``, the load torque T_out(t) and
  any input torque into the ``output_load`` / ``input_torque`` motors;
* the mesh tendons' world-frame coefficients (slides, and tilts) turned to the carrier's current angle
  (:class:`~gearcheck.mbd_models.twin.TurningCoefficients`; the angle-0 values came from ``mj_jac``);
  an RV reducer's pin tendons set to the discs' current poses
  (:meth:`~gearcheck.mbd_models.elements.cycloid.CycloidTwin.refresh`);
* the damping correction, a generalized force J^T g with g = c (de/dt - m): a fixed tendon's
  velocity J qvel misses the part m = (dc/dphi) phi' q of its coefficients turning with the carrier,
  and the transmission error's rate de/dt belongs to the mesh's damping force too, so the mesh
  damping acts on the true deflection rate (and a tilting mesh's tilting damping on the true rate of its
  tilting deflection).

Integrator: RK4, because the mesh springs make the model stiff and no MuJoCo
integrator except ``discrete`` treats spring stiffness implicitly: Euler and
implicitfast are stable only for h < 2/omega_max and first-order accurate, RK4 is
stable to 2.83/omega_max and fourth-order accurate, so it matches the lumped RK4
solution with the same step.  MuJoCo's ``mj_RungeKutta`` holds model fields and controls
constant over its step, which costs the order wherever they move (a time-varying stiffness
or transmission error: order 2; the coefficients turning with a carrier and the damping
correction: order 1).  The runner therefore takes RK4's four stages itself, as
``mj_RungeKutta`` does (the same sums in the same order, ``mj_forward`` per stage), with
the fields above set at each stage (t, t + h/2, t + h/2, t + h).  A step inside which a mesh
stiffness jumps (on the nominal clock) is split there into sub-steps, as the lumped solver
does (:func:`gearcheck.shared.stepping.split_steps`): the stiffness is smooth over every
sub-step and RK4 keeps its fourth order.

Time step: from MuJoCo's own linearisation with every mesh at its cycle-maximum stiffness, damping
included (``MbdModel.limits``); the rule of :mod:`gearcheck.shared.stepping`, the same as the lumped
solver's.

Start: the steady rotating state at the nominal operating point of the MuJoCo model
itself (:func:`~gearcheck.mbd_models.static_state.static_state`): a Newton solve on MuJoCo's
forward dynamics for the deflections at which every body turns at its nominal speed with the
deflection pattern turning with its carrier.

Outputs: accelerations from MuJoCo's ``framelinacc``/``frameangacc`` sensors, displacements, velocities and
rotations from its ``framepos``/``framexaxis``/``framelinvel``/``frameangvel`` sensors less the twin's own
nominal motion (:mod:`gearcheck.mbd_models.member_motion`), mesh deflections from
its tendon lengths, mesh and bearing forces from its generalized forces
(:class:`~gearcheck.mbd_models.forces.ForceReader`); an RV reducer's pin forces from its pin tendons and its
needle bearings' forces from their actuators.

Engines: the loop above runs in C by default (:mod:`gearcheck.mbd_models.compiled`: the same model writes and
MuJoCo calls from a numba kernel, the drive computed in arrays a chunk of steps at a time; equal to the Python
loop to round-off); ``engine="python"`` keeps it in Python, and the "bodies" stiffness clock always does.
:func:`simulate_mujoco_many` runs several twins at once in threads.
"""

from __future__ import annotations

import concurrent.futures
import copy
import dataclasses
import math
import os
import time as clock

import mujoco
import numpy as np

from gearcheck.mbd_models import compiled
from gearcheck.mbd_models.elements import base as elements
from gearcheck.mbd_models.forces import ForceReader
from gearcheck.mbd_models.jacobians import tendon_rows
from gearcheck.mbd_models.member_motion import member_motion
from gearcheck.mbd_models.static_state import DampingCorrection, StaticState, static_state
from gearcheck.mbd_models.mjcf_text import ROTATION
from gearcheck.mbd_models.twin import MbdModel
from gearcheck.shared import divergence, stepping
from gearcheck.shared.errors import SolverError
from gearcheck.shared.events import (MAX_EVENTS, MIN_FRACTION, crossed_together, first_crossing, pair_switch,
                                     samples_between)
from gearcheck.shared.results import TimeResult, train_result, train_signals
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import STAGE_OFFSETS, STAGE_SIDES
from gearcheck.train.history import check_duration

CHUNK = 10000


# --------------------------------------------------------------------------- drive


class _Drive:
    """Excitation of one MbdModel as arrays over time: stiffness, controls, transmission error."""

    def __init__(self, mb: MbdModel):
        self.mb = mb
        self.exc = mb.excitation
        self.has_te = self.exc.has_transmission_error

    def controls(self, t: np.ndarray) -> np.ndarray:
        """Actuator controls at times t: w_in for the input servo and its damper, torques (ramp included)."""
        a, w_in = self.mb.actuator, self.mb.spec.operating.input_speed * self.exc.speed_scale(t)
        u = np.zeros(np.shape(t) + (self.mb.model.nu,))
        t_in, t_out = self.exc.torques(t)
        if "input_shaft" in a:
            u[..., a["input_shaft"]] = w_in  # the intvelocity servo integrates it into the reference angle
        if "input_shaft_damper" in a:
            u[..., a["input_shaft_damper"]] = w_in
        u[..., a["input_torque"]] = t_in
        u[..., a["output_load"]] = t_out
        return u

    def at(self, t: np.ndarray, side=0):
        """(k, u, e, de, pairs) at times t (e, de None without a transmission error; pairs, the relieved meshes'
        tooth pairs (k_j, e_j) along the last axis, None without tip relief); ``side`` the one-sided limit read
        where a mesh's drive jumps (:meth:`~gearcheck.train.excitation.Excitation.mesh_position`)."""
        e, de = self.exc.transmission_error(t) if self.has_te else (None, None)
        kp, ep = self.exc.tooth_pairs(t, side)
        pairs = None if kp is None else np.stack([kp, ep], axis=-1)
        return self.exc.stiffness(t, side), self.controls(t), e, de, pairs

    def steps(self, t0: np.ndarray, h):
        """(k, u, e, de, pairs) for steps starting at t0 (h one step length, or one per row), each with time along
        axes (0, 1): the step, its stage times t0 + h STAGE_OFFSETS (t, t + h/2, t + h) at STAGE_SIDES."""
        return self.at(t0[:, None] + np.reshape(h, (-1, 1)) * np.array(STAGE_OFFSETS)[None, :], np.array(STAGE_SIDES))


class _ToothContacts:
    """The relieved meshes' tooth pairs on MuJoCo's tendons: at each drive the pairs in contact at the tendon's
    present length L (a fixed tendon's sum of coefficient times joint position) set its stiffness, their sum
    K, and its spring length, e + S/K with S the sum of k_j e_j, so that MuJoCo's spring force over the step
    is sum_j k_j (L - e - e_j) over those pairs; none in contact: no spring."""

    def __init__(self, mb: MbdModel):
        m = mb.model
        self.relieved = mb.excitation.relieved
        self.tendons = mb.mesh_tendon[self.relieved]
        self.wraps = np.concatenate([np.arange(m.tendon_adr[t], m.tendon_adr[t] + m.tendon_num[t])
                                     for t in self.tendons])
        self.qadr = m.jnt_qposadr[m.wrap_objid[self.wraps]]
        self.starts = np.cumsum(np.concatenate([[0], m.tendon_num[self.tendons][:-1]]))

    def apply(self, m: mujoco.MjModel, d: mujoco.MjData, e, pairs) -> None:
        offset = 0.0 if e is None else e[self.relieved]
        length = np.add.reduceat(m.wrap_prm[self.wraps] * d.qpos[self.qadr], self.starts) - offset
        k, gap = pairs[..., 0], pairs[..., 1]
        touching = length[:, None] > gap
        total = np.sum(k * touching, axis=-1)
        moment = np.sum(k * np.where(touching, gap, 0.0), axis=-1)
        m.tendon_stiffness[self.tendons] = total
        m.tendon_lengthspring[self.tendons] = (offset + np.divide(moment, total, out=np.zeros_like(total),
                                                                  where=total > 0))[:, None]


# --------------------------------------------------------------------------- stepping


class _Stepper:
    """Steps one twin by classical RK4, MuJoCo's ``mj_RungeKutta`` written out so that each of its four stages is
    driven from its own state at its own time: turn the coefficients, set the stage (drive, tooth contacts,
    damping correction), ``mj_forward`` at a sampled step's first stage (``mj_forwardSkip`` without sensors at
    every other stage: nothing else reads them), then the state advanced by RK4's weights.  Samples go into
    preallocated rows: sensordata, the force reader's generalized forces, and optionally the stiffness used and
    MuJoCo's energy."""

    def __init__(self, mb: MbdModel, d: mujoco.MjData, h: float, n_samples: int, bodies: bool, energy: bool,
                 t0: float = 0.0):
        m = mb.model
        self.mb, self.m, self.d, self.h, self.t0 = mb, m, d, h, t0
        self.n_mesh = len(mb.mesh_tendon)
        self.drive = _Drive(mb)
        self.correction = DampingCorrection(mb, d)
        self.reader = ForceReader(mb, d, self.correction)
        self.lo_hi = np.stack([-mb.half_backlash, mb.half_backlash], axis=1)
        self.clock = _body_clock(mb) if bodies else None
        self.contacts = _ToothContacts(mb) if mb.excitation.relieved.size else None
        self.sensors = np.empty((n_samples, m.nsensordata))
        self.forces = np.empty((n_samples, self.reader.width))
        self.stiffness = np.empty((n_samples, self.n_mesh)) if bodies or self.contacts else None
        self.energy = np.empty((n_samples, 2)) if energy else None
        self.moving = list(zip(mb.moving_contacts, mb.moving_slices()))  # each with its columns in ``pins``
        self.pins = np.empty((n_samples, sum(len(c.tendons) for c in mb.moving_contacts))) if self.moving else None
        self.switches = mesh_switches(mb)
        self.located = 0
        self.j = 0

    def switching(self, drive, s: int, span: float) -> tuple[np.ndarray, np.ndarray]:
        """The contact switching functions of the present state and their rates
        (:func:`gearcheck.mbd_models.compiled._switching`'s, in its order), ``drive`` (k, u, e, de, pairs) at the
        three samples of a step of length ``span``, taken at sample ``s``."""
        m, d, sw, tc = self.m, self.d, self.switches, self.mb.turning
        self.mb.refresh(d.qpos)
        length = np.add.reduceat(m.wrap_prm[sw.wraps] * d.qpos[sw.qadr], sw.starts[:-1]) if sw.wraps.size else []
        speed = np.add.reduceat(m.wrap_prm[sw.wraps] * d.qvel[sw.dofs], sw.starts[:-1]) if sw.wraps.size else []
        speed = speed + tc.missing_rate(d.qpos[tc.carrier_qadr], d.qvel[tc.carrier_qadr], d.qpos[tc.joint_qadr],
                                        len(self.mb.mesh_tendon))[sw.tendons] if sw.wraps.size else speed
        _, _, e, de, pairs = drive
        g, rate = [], []
        for i, (t, j, b) in enumerate(zip(sw.tendons, sw.relieved, sw.half_backlash)):
            y, dy = length[i] - (0.0 if e is None else e[s][t]), speed[i] - (0.0 if de is None else de[s][t])
            if j >= 0:
                for gaps in pairs[:, j, :, 1].T:
                    value, slope = pair_switch(y, dy, *gaps, s, span)
                    g.append(value)
                    rate.append(slope)
            else:
                g += [y - b, y + b]
                rate += [dy, dy]
        for c, _ in self.moving:
            g += list(c.refresh(self.d))
            rate += list(c.speed)
        return np.array(g, dtype=float), np.array(rate, dtype=float)

    def step(self, h: float, drive, sample: bool) -> None:
        """One (sub-)step of length h (:meth:`rk4`), its contact events located as the compiled loop locates them
        (:func:`gearcheck.mbd_models.compiled._step`)."""
        if not self.switches.count:
            self.rk4(h, drive, sample)
            return
        g0, r0 = self.switching(drive, 0, h)
        self.rk4(h, drive, sample)
        done, span = 0.0, h
        for _ in range(MAX_EVENTS):
            theta, crossed = first_crossing(g0, r0, *self.switching(drive, 2, h), span)
            if not MIN_FRACTION < theta < 1.0 - MIN_FRACTION:
                break
            at = done + theta * (1.0 - done)
            self.d.qpos[:], self.d.qvel[:], self.d.act[:] = self.start
            self.rk4((at - done) * h, _part_of(drive, done, at), False)
            self.located += 1
            g0, r0 = self.switching(_part_of(drive, done, at), 2, (at - done) * h)
            crossed_together(g0, r0, (at - done) * h, crossed)
            done, span = at, (1.0 - at) * h
            self.rk4(span, _part_of(drive, done, 1.0), False)

    def set_stage(self, k, u, e, de, pairs=None) -> None:
        """Everything a stage sets from its own state: the mesh tendons' coefficients turned with their carriers,
        the contacts' tendons (an RV reducer's pins) at the bodies' poses, the drive (stiffness -- from the bodies'
        angles on the "bodies" clock --, controls, spring lengths, tooth contacts) and the damping correction."""
        self.mb.refresh(self.d.qpos)
        for c, _ in self.moving:
            c.refresh(self.d)
        if self.clock is not None:
            k = _body_stiffness(self.mb, self.clock, self.d.qpos)
        self.m.tendon_stiffness[:self.n_mesh] = k
        self.d.ctrl[:] = u
        if e is not None:
            self.m.tendon_lengthspring[:self.n_mesh] = e[:, None] + self.lo_hi
        if pairs is not None:
            self.contacts.apply(self.m, self.d, e, pairs)
        self.correction.apply(de)

    def sample(self) -> None:
        """Record the state just computed by ``mj_forward``."""
        j = self.j
        self.sensors[j] = self.d.sensordata
        self.reader.sample(self.forces[j])
        if self.stiffness is not None:
            self.stiffness[j] = self.m.tendon_stiffness[:self.n_mesh]
        if self.energy is not None:
            self.energy[j] = self.d.energy
        if self.pins is not None:
            for c, at in self.moving:
                self.pins[j, at] = c.pin_forces(self.d)
        self.j += 1

    def run(self, start: int, stop: int, every: int, values, split) -> None:
        """Steps start..stop-1 with the drive ``values`` (:meth:`_Drive.steps`), sampling the steps that begin on a
        multiple of ``every``; the steps in ``split`` (:func:`gearcheck.shared.stepping.split_steps`) are taken as
        RK4 sub-steps ended at their stiffness jumps, the drive sampled over each as over a whole step."""
        for i in range(stop - start):
            step = start + i
            sample = step % every == 0
            if step not in split:
                self.step(self.h, [None if x is None else x[i] for x in values], sample)
                continue
            _, starts, lengths = stepping.sub_steps(self.t0, self.h, {step: split[step]})
            for n, (rows, length) in enumerate(zip(zip(*(_rows(x) for x in self.drive.steps(starts, lengths))),
                                                   lengths)):
                self.step(length, rows, sample and n == 0)

    def rk4(self, h: float, drive, sample: bool) -> None:
        """One RK4 (sub-)step of length h, ``drive`` (k, u, e, de, pairs) at its stage times t, t + h/2, t + h."""
        m, d = self.m, self.d
        qpos0, qvel0, act0 = self.start = d.qpos.copy(), d.qvel.copy(), d.act.copy()
        rates = []
        for stage, s in enumerate(compiled.STAGE_TIMES):
            if stage:
                velocity, acceleration, activation = rates[-1]
                a = compiled.STAGE_ADVANCE[stage - 1]
                d.qpos[:] = qpos0
                mujoco.mj_integratePos(m, d.qpos, velocity * a, h)
                d.qvel[:] = qvel0 + acceleration * a * h
                d.act[:] = act0 + activation * a * h
            self.set_stage(*(None if x is None else x[s] for x in drive))
            if stage == 0 and sample:
                mujoco.mj_forward(m, d)
                self.sample()
            else:
                mujoco.mj_forwardSkip(m, d, mujoco.mjtStage.mjSTAGE_NONE, 1)  # no sensors: nothing reads them
            rates.append((d.qvel.copy(), d.qacc.copy(), d.act_dot.copy()))
        velocity, acceleration, activation = (sum(rate[x] * w for rate, w in zip(rates, RK4_WEIGHTS))
                                              for x in range(3))
        d.act[:] = act0 + activation * h
        d.qvel[:] = qvel0 + acceleration * h
        d.qpos[:] = qpos0
        mujoco.mj_integratePos(m, d.qpos, velocity, h)

    def finish(self, t_end: float) -> None:
        """Sample the final state (the drive of the step that would start there)."""
        self.sample_at(self.drive.at(np.array([t_end]), STAGE_SIDES[0]), 0)

    def sample_at(self, drive, row: int) -> None:
        """Sample the state in ``d`` with row ``row`` of ``drive`` (k, u, e, de, ...; None where absent) set as its
        stage: ``mj_forward``, then the sensors and the force reader's row."""
        self.set_stage(*(None if x is None else x[row] for x in drive))
        mujoco.mj_forward(self.m, self.d)
        self.sample()


RK4_WEIGHTS = (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0)


def moving_groups(mb: MbdModel) -> tuple:
    """Every registered kind of moving contact's compiled group (:data:`gearcheck.mbd_models.elements.base.GROUPS`)
    with the twin's contacts of that kind, empty where it has none (one compiled kernel serves every twin)."""
    return tuple(group.of([c for c in mb.moving_contacts if c.compiled is group], mb.model.nv)
                 for group in elements.GROUPS)


def mesh_switches(mb: MbdModel) -> compiled.MeshSwitches:
    """The mesh tendons whose contact law has kinks (a backlash's dead zone, a relieved mesh's tooth pairs) with
    their coefficients' addresses, and (``count``) how many switching functions the twin has with its pins."""
    m, exc = mb.model, mb.excitation
    place = {int(j): r for r, j in enumerate(exc.relieved)}
    meshes = [i for i in range(len(mb.mesh_tendon)) if i in place or mb.half_backlash[i] > 0]
    tendons = np.array([mb.mesh_tendon[i] for i in meshes], dtype=np.int64)
    wraps = [np.arange(m.tendon_adr[t], m.tendon_adr[t] + m.tendon_num[t]) for t in tendons]
    flat = np.concatenate(wraps).astype(np.int64) if wraps else np.zeros(0, dtype=np.int64)
    joints = m.wrap_objid[flat]
    pairs = exc.tooth_pairs(0.0)[0]
    relieved = np.array([place.get(i, -1) for i in meshes], dtype=np.int64)
    count = (2 * int(np.sum(relieved < 0)) + int(np.sum(relieved >= 0)) * (0 if pairs is None else pairs.shape[-1])
             + sum(len(c.tendons) for c in mb.moving_contacts))
    return compiled.MeshSwitches(tendons, flat, m.jnt_qposadr[joints].astype(np.int64),
                                 m.jnt_dofadr[joints].astype(np.int64),
                                 np.cumsum([0] + [w.size for w in wraps]).astype(np.int64), relieved,
                                 np.array([mb.half_backlash[i] for i in meshes], dtype=float), count)


def _part_of(drive, a: float, b: float) -> list:
    """The drive (k, u, e, de, pairs) of the part from fraction a to b of a step whose three samples are
    ``drive`` (:func:`~gearcheck.shared.events.samples_between`)."""
    out = []
    for x in drive:
        if x is None:
            out.append(None)
            continue
        part = np.empty_like(x)
        samples_between(np.ascontiguousarray(x), a, b, part)
        out.append(part)
    return out


def _rows(x):
    """The rows of an optional drive array (None: None for every row)."""
    return iter(lambda: None, 0) if x is None else x


class _CompiledStepper(_Stepper):
    """The stepper's contract with its step loop compiled (:func:`gearcheck.mbd_models.compiled.run_steps`): the
    drive of a chunk of steps (and of its split steps' sub-steps) computed here in arrays, then every step in C.
    Not for the "bodies" stiffness clock (its stiffness models are Python functions of the bodies' angles)."""

    def __init__(self, mb: MbdModel, d: mujoco.MjData, h: float, n_samples: int, bodies: bool, energy: bool,
                 t0: float = 0.0):
        super().__init__(mb, d, h, n_samples, bodies, energy, t0)
        m, n, tc, reader = self.m, self.n_mesh, mb.turning, self.reader
        lib = compiled.library()
        self.c = (lib.forward, lib.forward_skip, lib.integrate_pos, lib.passive, lib.kinematics, lib.com_pos, lib.jac)
        c = self.contacts
        none = np.zeros(0, dtype=np.int64)
        self.twin = (  # the kernel's groups of this twin, as run_steps takes them after the C functions
            compiled.Pointers(m._address, d._address, reader.probe._address, reader.joints_only._address),
            compiled.ModelViews(m.tendon_stiffness, m.tendon_lengthspring, m.wrap_prm,
                                reader.probe.tendon_stiffness[:n], reader.probe.tendon_lengthspring[:n],
                                m.tendon_damping),
            compiled.DataViews(d.qpos, d.qvel, d.act, d.qacc, d.act_dot, d.ctrl, d.qfrc_applied, d.sensordata,
                               d.qfrc_spring, d.qfrc_damper, d.energy, d.xpos, d.xmat, d.site_xpos, d.ten_length,
                               d.ten_velocity),
            compiled.Turning(tc._make(np.ascontiguousarray(x) for x in tc), np.ascontiguousarray(mb.corrected_damping),
                             np.ascontiguousarray(mb.half_backlash)),
            compiled.Contacts(none, none, none, np.zeros(1, dtype=np.int64)) if c is None else compiled.Contacts(
                *(np.ascontiguousarray(x, dtype=np.int64) for x in
                  (c.tendons, c.wraps, c.qadr, np.append(c.starts, len(c.wraps))))),
            compiled.Work(tendon_rows(m, mb.corrected), np.zeros(len(tc.wraps)), np.zeros(len(mb.corrected)),
                          np.zeros(len(mb.corrected))),
            compiled.Reader(np.ascontiguousarray(reader.dofs, dtype=np.int64),
                            np.ascontiguousarray(reader.slides, dtype=np.int64)),
            moving_groups(mb),
            compiled.Stages.of(m))
        self.outputs = compiled.Outputs(self.sensors, self.forces,
                                        np.zeros((0, n)) if self.stiffness is None else self.stiffness,
                                        np.zeros((0, 2)) if self.energy is None else self.energy,
                                        np.zeros((0, 0)) if self.pins is None else self.pins)
        self.flags = compiled.Flags(self.drive.has_te, self.contacts is not None, self.stiffness is not None,
                                    self.energy is not None, self.pins is not None)
        self.events = compiled.Events.of(self.switches, self._arrays(self.drive.steps(np.zeros(1), h), 1))

    def _arrays(self, values, rows: int) -> compiled.Drive:
        """(k, u, e, de, pairs) of :meth:`_Drive.steps` as contiguous arrays, the absent ones empty along their last
        axes."""
        empty = (np.zeros((rows, 3, self.n_mesh)), np.zeros((rows, 3, self.m.nu)), np.zeros((rows, 3, 0)),
                 np.zeros((rows, 3, 0)), np.zeros((rows, 3, 0, 0, 2)))
        return compiled.Drive(*(blank if x is None else np.ascontiguousarray(x) for x, blank in zip(values, empty)))

    def run(self, start, stop, every, values, split) -> None:
        rows = stop - start
        first, count = np.zeros(rows, dtype=np.int64), np.zeros(rows, dtype=np.int64)
        parts, starts, lengths = stepping.sub_steps(self.t0, self.h, split)
        at = np.array(sorted(split), dtype=np.int64) - start
        first[at], count[at] = np.cumsum(parts) - parts, parts
        sub = self.drive.steps(starts, lengths) if lengths.size else [None] * 5
        self.j = compiled.run_steps(self.c, *self.twin, self._arrays(values, rows),
                                    compiled.Split(first, count, lengths, self._arrays(sub, lengths.size)),
                                    self.flags, self.outputs, self.h, start, stop, every, self.j, self.switches,
                                    self.events)
        self.located = int(self.events.located[0])


def compiled_unsupported(mb: MbdModel, stiffness_clock: str = "nominal") -> str | None:
    """Why the compiled step loop cannot run ``mb`` (None: it can)."""
    if stiffness_clock != "nominal":
        return "the 'bodies' stiffness clock evaluates the stiffness models from the bodies' angles in Python"
    if any(m.torsional and m.orbits for m in mb.spec.members.values()):
        return "a torsional planet's mesh forces are read one mesh at a time in Python (ForceReader)"
    return compiled.unavailable()


# --------------------------------------------------------------------------- run


ENGINES = ("auto", "compiled", "python")


def simulate_mujoco(mb: MbdModel, settings: RunSettings, progress=None, stiffness_clock: str = "nominal",
                    initial_state=None, record_energy: bool = False, engine: str = "auto",
                    return_state: bool = False, static: StaticState | None = None) -> TimeResult:
    """Run the MuJoCo twin ``mb`` as ``settings`` ask; a :class:`TimeResult` with the lumped solver's signals.

    The step defaults to the model's own (``mb.default_step``) and is refused above the stability
    limit.  progress: callable(fraction).  stiffness_clock: "nominal" (k from the nominal mesh clock,
    like the lumped solver) or "bodies" (mesh position from the MuJoCo bodies' own rotation angles;
    transmission error stays on the nominal clock).  initial_state: optional (qpos, qvel) instead of
    the static start.  record_energy: enable ``mjENBL_ENERGY`` and return MuJoCo's kinetic and
    potential energy in ``raw``.  engine: "compiled" (the step loop in C,
    :mod:`gearcheck.mbd_models.compiled`; the same steps, equal to round-off), "python" (the loop in Python),
    or "auto" (compiled wherever :func:`compiled_unsupported` allows, else Python); the result's ``info``
    (:class:`~gearcheck.shared.run_info.RunInfo`) says which ran.  return_state: return (result, (qpos, qvel,
    act)), the state after the last step.  A run from ``settings.start`` > 0 goes on from the ``initial_state``
    (qpos, qvel, act) of a run that ended there (act, the input servo's reference angle, then carries on from it).
    static: the twin's :func:`~gearcheck.mbd_models.static_state.static_state` where the caller has it (every
    result holds its static forces; found here otherwise, 34 ms on hub-drive).
    """
    if stiffness_clock not in ("nominal", "bodies"):
        raise SolverError(f"stiffness_clock must be 'nominal' or 'bodies', not {stiffness_clock!r}")
    if engine not in ENGINES:
        raise SolverError(f"engine must be one of {', '.join(map(repr, ENGINES))}, not {engine!r}")
    unsupported = None if engine == "python" else compiled_unsupported(mb, stiffness_clock)
    if engine == "compiled" and unsupported:
        raise SolverError(f"the compiled MuJoCo runner cannot run {mb.spec.name}: {unsupported}")
    use_compiled = engine != "python" and not unsupported
    spec, m = mb.spec, mb.model
    what = f"MuJoCo model of {spec.name}"
    dt, n_steps, every, static, (qpos0, qvel0, act0) = prepare(mb, settings, initial_state, static)
    t0 = settings.start

    d = mujoco.MjData(m)
    saved = (m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.wrap_prm.copy(), m.opt.enableflags,
             m.opt.timestep, m.opt.integrator, m.tendon_damping.copy())
    m.opt.timestep = dt  # the step a viewer would take; the steppers take theirs explicitly
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    if record_energy:
        m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    d.qpos[:], d.qvel[:] = qpos0, qvel0
    if act0 is not None:
        d.act[:] = act0
    kind = _CompiledStepper if use_compiled else _Stepper
    stepper = kind(mb, d, dt, n_steps // every + 1, stiffness_clock == "bodies", record_energy, t0)
    scale = divergence.deflection_scale(static.mesh_deflection, mb.half_backlash)
    sub_steps = n_steps
    try:
        started = clock.perf_counter()
        for start in range(0, n_steps, CHUNK):
            stop = min(start + CHUNK, n_steps)
            j0 = stepper.j
            split = ({} if stiffness_clock == "bodies"
                     else stepping.split_steps(dt, start, stop,
                                               mb.excitation.switch_times(t0 + start * dt, t0 + stop * dt), t0))
            sub_steps += sum(inner.size for inner in split.values())
            stepper.run(start, stop, every, stepper.drive.steps(t0 + dt * np.arange(start, stop), dt), split)
            _check_divergence(stepper, j0, t0, stop * dt, every * dt, scale, what)
            if progress is not None:
                progress(stop / n_steps)
        stepper.finish(t0 + n_steps * dt)
        wall = clock.perf_counter() - started
    finally:
        m.tendon_stiffness[:], m.tendon_lengthspring[:], m.wrap_prm[:] = saved[0], saved[1], saved[2]
        m.opt.enableflags, m.opt.timestep, m.opt.integrator = saved[3], saved[4], saved[5]
        m.tendon_damping[:] = saved[6]
    t = t0 + dt * every * np.arange(stepper.j)
    loop = "compiled" if use_compiled else "python"
    sub_steps += 2 * stepper.located  # a located event takes its step again in two parts
    info = RunInfo(f"mujoco-{loop}", n_steps, 4, 4 * sub_steps, wall, {  # mj_forward at each of RK4's stages
        "method": "mujoco-rk4", "integrator": "RK4", "dt_s": dt, "steps": n_steps, "wall_time_s": wall,
        "omega_max_rad_s": mb.omega_max, "stable_step_s": stepping.stable_step(mb.limits),
        "stiffness_clock": stiffness_clock, "mujoco_version": mujoco.__version__,
        "static_newton_iterations": static.iterations, "static_residual": static.residual,
        "forward_evaluations": 4 * sub_steps, "engine": loop,  # sub-steps and located events included
        "contact_events_located": stepper.located})
    result = _result(mb, stepper, t, static, settings.settle_time(spec.operating.ramp), info, settings.signals)
    return (result, (d.qpos.copy(), d.qvel.copy(), d.act.copy())) if return_state else result


def prepare(mb: MbdModel, settings: RunSettings, initial_state=None, static: StaticState | None = None):
    """A run's step, its steps, the steps between samples, the twin's static state and the start (qpos, qvel, act;
    act None: the model's own), checked as :func:`simulate_mujoco` checks them."""
    spec, m = mb.spec, mb.model
    what = f"MuJoCo model of {spec.name}"
    nominal, history = mb.excitation.clock, spec.operating.history
    check_duration(history, settings.duration, what)
    settings.check_start(initial_state, history, what)
    frequency = mb.excitation.frequency * (1.0 if nominal is None else max(1.0, nominal.top(settings.duration)))
    dt = stepping.default_step(mb.limits, frequency) if settings.dt is None else settings.dt
    stepping.check_step(dt, mb.limits, frequency, what)
    n_steps, every = settings.check_work(dt, m.nsensordata + len(train_signals(spec)), what)
    static = static_state(mb) if static is None else static
    act0 = None
    if initial_state is None and history is not None and history.start == "rest":
        qpos0, qvel0 = m.qpos0.copy(), np.zeros(m.nv)  # every body at rest at its nominal place, undeformed
    elif initial_state is None:
        start = static if spec.operating.ramp == 0 else static_state(mb, 0.0)
        qpos0, qvel0 = start.qpos, start.qvel
    else:
        qpos0, qvel0, *rest = (np.asarray(x, dtype=float) for x in initial_state)
        act0 = rest[0] if rest else None
    return dt, n_steps, every, static, (qpos0, qvel0, act0)


def simulate_mujoco_many(twins, settings, threads: int | None = None, **options) -> list[TimeResult]:
    """Run several twins (variants: other speeds, parameters, trains) at once, each as :func:`simulate_mujoco`
    runs it with ``options``; their results in order.

    settings: one :class:`RunSettings` for all, or one per twin.  threads: how many run at a time (default: one
    per core, at most one per twin).  The compiled step loop releases the GIL, so its runs proceed in parallel
    (the Python engine's only interleave).  A run writes its model's fields (stiffness, coefficients, step), so a
    twin given twice runs on a copy of its compiled model (an RV reducer's twin, whose pin contacts hold their
    model, is refused twice).
    """
    twins = list(twins)
    runs = list(settings) if isinstance(settings, (list, tuple)) else [settings] * len(twins)
    if len(runs) != len(twins):
        raise SolverError(f"simulate_mujoco_many: {len(runs)} settings for {len(twins)} twins")
    seen, own = set(), []
    for mb in twins:
        if id(mb.model) in seen:
            if mb.moving_contacts:
                raise SolverError(f"simulate_mujoco_many: the twin of {mb.spec.name} is given twice; compile it "
                                  "once per run (an RV reducer's pin contacts hold their model)")
            mb = dataclasses.replace(mb, model=copy.copy(mb.model))
        seen.add(id(mb.model))
        own.append(mb)
    workers = max(1, min(len(own), threads or os.cpu_count() or 1))
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        jobs = [pool.submit(simulate_mujoco, mb, run, **options) for mb, run in zip(own, runs)]
        return [job.result() for job in jobs]


def _check_divergence(stepper: _Stepper, j0: int, t0: float, elapsed: float, interval: float, scale: float,
                      what: str) -> None:
    """Samples j0.. of the stepper (the first at t0) and its current state ``elapsed`` after t0, against
    :mod:`gearcheck.shared.divergence`."""
    mb, d, j = stepper.mb, stepper.d, stepper.j
    columns = [mb.sensor[f"{m.label}_deflection"][0] for m in mb.spec.meshes]
    state = d.ten_length[:len(mb.mesh_tendon)] if np.all(np.isfinite(d.qpos)) else np.full(len(columns), np.nan)
    deflection = np.vstack([stepper.sensors[j0:j][:, columns], state[None]])
    divergence.check(t0 + np.append(interval * np.arange(j0, j), elapsed), deflection, scale, what)


def _body_clock(mb: MbdModel):
    spec, kin = mb.spec, mb.kin
    rows = []
    for mesh in spec.meshes:
        carrier = spec.stage_of(mesh.planet).carrier
        rel = kin.speeds[mesh.central] - kin.speeds[carrier]
        rows.append((mb.qadr[mesh.central][ROTATION], mb.qadr[carrier][ROTATION],
                     math.copysign(1.0, rel) * (mesh.central_gear.teeth or 0) / (2 * math.pi)))
    return tuple(np.array(x) for x in zip(*rows))


def _body_stiffness(mb: MbdModel, info, qpos) -> np.ndarray:
    """k from the mesh position of the MuJoCo bodies: xi = sign z (theta_central - theta_carrier)/2pi - phase."""
    qc, qk, gain = info
    xi = gain * (qpos[qc] - qpos[qk]) - mb.excitation.phase
    return np.array([model(x) for model, x in zip(mb.excitation.models, xi)], dtype=float)


# --------------------------------------------------------------------------- result


def _result(mb: MbdModel, stepper: _Stepper, t, static: StaticState, settle, info, wanted=None) -> TimeResult:
    spec, S = mb.spec, stepper.sensors[:stepper.j]

    def series(name):
        adr, dim = mb.sensor[name]
        return S[:, adr:adr + dim]

    def columns(sensor, axis, labels):  # one axis of a sensor of each label, (n_t, labels)
        return S[:, [mb.sensor[f"{label}_{sensor}"][0] + axis for label in labels]]

    delta = columns("deflection", 0, [m.label for m in spec.meshes])
    mesh_force, mesh_moment, bearing_force = stepper.reader.forces(stepper.forces[:stepper.j])
    k = (mb.excitation.stiffness(t, STAGE_SIDES[0]) if stepper.stiffness is None
         else stepper.stiffness[:stepper.j])
    raw = {}
    for name, (adr, dim) in mb.sensor.items():
        if dim == 1:
            raw[name] = S[:, adr]
        else:
            for c_i, axis in zip(range(dim), "xyz"):
                raw[f"{name}_{axis}"] = S[:, adr + c_i]
    if stepper.energy is not None:  # MuJoCo's d.energy is (potential, kinetic)
        raw["energy_potential"] = stepper.energy[:stepper.j, 0]
        raw["energy_kinetic"] = stepper.energy[:stepper.j, 1]
    pins = [stepper.pins[:stepper.j, at] for at in mb.moving_slices()]
    by_disc = np.concatenate([c.per_disc(f) for c, f in zip(mb.moving_contacts, pins)], axis=1) if pins else None
    result = train_result(spec, "mujoco", t, member_motion(mb, S, t), delta, mesh_force, k, static.mesh_force,
                          static.bearing_force, bearing_force, settle, info, raw, by_disc, wanted, mesh_moment)
    for c, forces, at in zip(mb.moving_contacts, pins, mb.moving_slices()):
        result = c.with_signals(result, forces, series, static.pin_force[at])
    return result
