"""The MuJoCo runner's step loop compiled: MuJoCo's own C functions called from a numba kernel, no Python per step.

:func:`run_steps` does, step for step, what :class:`gearcheck.mbd_models.runner._Stepper` does in Python (the
same operations in the same order): classical RK4, the stage loop of MuJoCo's ``mj_RungeKutta`` written out so
that every stage gets its own drive.  At each of the four stages, from that stage's own state, it turns the mesh
tendons' world-frame coefficients with their carriers (``wrap_prm``), sets an RV reducer's pin tendons to
the discs' poses, drives the stage (mesh stiffness, controls, spring lengths of a transmission error and a
backlash, the relieved meshes' tooth pairs in contact, the damping correction J^T g into ``qfrc_applied``) with
the excitation at the stage's time (t, t + h/2, t + h/2, t + h), and calls ``mj_forward`` at a sampled step's
first stage, ``mj_forwardSkip`` without sensors at every other stage (``mj_RungeKutta`` computes them at every
step's first; they feed nothing back, and cost 10 % of a hub-drive step); the state then advances by RK4's weights
(``mj_integratePos`` for the positions).  A step inside which a mesh stiffness jumps is taken as RK4 sub-steps
ended there.  The drive itself -- the excitation functions of the train at every stage time -- is computed
beforehand in arrays, a chunk of steps at a time, by the runner.  Every force law stays MuJoCo's: the kernel only
writes the model fields and the data that the Python loop writes, and calls MuJoCo's C functions on the compiled
model through its C library (``ctypes``), with the GIL released, so several twins run at once in threads
(:func:`gearcheck.mbd_models.runner.simulate_mujoco_many`).

The moving contacts (an RV reducer's pins) come in their element's compiled form, beside the element's bodies
and tendons: a group per kind (:mod:`gearcheck.mbd_models.elements.cycloid`: ``CompiledPins``), every registered
kind's group in one tuple, and its functions on the hooks :data:`~gearcheck.mbd_models.elements.base.REFRESH`,
:data:`~gearcheck.mbd_models.elements.base.SWITCHING` and :data:`~gearcheck.mbd_models.elements.base.RECORD`,
which the kernel calls without naming a kind.  The kernel is compiled on first use and cached by numba next to
its file, without numba's reference-counted runtime (``_nrt=False``; it allocates nothing): a call that passes
tens of arrays otherwise counts references to each with atomic instructions, about 3 us of hub-drive's 34 us step.
Even without the counts, a call passes every array of its groups as several machine words: the functions called
once a stage or a step (the stage's drive and :func:`_set_stage`, :func:`_refresh`, :func:`_sample`,
:func:`_step`, the switching functions) are inlined into their callers; :func:`_rk4`, called from three places,
stays a function.
"""

from __future__ import annotations

import ctypes
import math
import os
from glob import glob
from pathlib import Path
from typing import NamedTuple

import mujoco
import numba
import numpy as np

from gearcheck.mbd_models.elements import base
from gearcheck.mbd_models.twin import TurningCoefficients
from gearcheck.shared.compiled_cache import ensure_cache_folder
from gearcheck.shared.events import (MAX_EVENTS, MIN_FRACTION, crossed_together, first_crossing, pair_switch,
                                     samples_between)

ensure_cache_folder(Path(__file__).parent)  # before the cached kernels below are defined
_LIBRARY_NAMES = ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll")
STAGE_TIMES = (0, 1, 1, 2)  # RK4's stages at the drive's stage times t, t + h/2, t + h
STAGE_ADVANCE = (0.5, 0.5, 1.0)  # stage i + 1 starts from the step's start advanced by this times h along stage i
refresh_moving, moving_switching, record_moving = base.REFRESH.each, base.SWITCHING.each, base.RECORD.each


class _MuJoCoC:
    """MuJoCo's C functions the kernel calls, from the library the Python bindings load."""

    def __init__(self):
        folder = os.path.dirname(mujoco.__file__)
        paths = [p for pattern in _LIBRARY_NAMES for p in sorted(glob(os.path.join(folder, pattern)))]
        if not paths:
            raise OSError(f"no MuJoCo C library next to the Python bindings in {folder}")
        lib = ctypes.CDLL(paths[0])
        pair = [ctypes.c_void_p, ctypes.c_void_p]
        self.forward = lib.mj_forward
        self.forward.argtypes, self.forward.restype = pair, None
        self.forward_skip = lib.mj_forwardSkip  # (m, d, skipstage, skipsensor)
        self.forward_skip.argtypes, self.forward_skip.restype = pair + [ctypes.c_int, ctypes.c_int], None
        self.integrate_pos = lib.mj_integratePos  # (m, qpos, qvel, dt)
        self.integrate_pos.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_double]
        self.integrate_pos.restype = None
        self.passive = lib.mj_passive
        self.passive.argtypes, self.passive.restype = pair, None
        self.kinematics = lib.mj_kinematics
        self.kinematics.argtypes, self.kinematics.restype = pair, None
        self.com_pos = lib.mj_comPos
        self.com_pos.argtypes, self.com_pos.restype = pair, None
        self.jac = lib.mj_jac  # (m, d, jacp, jacr, point, body)
        self.jac.argtypes = pair + [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int]
        self.jac.restype = None


_C: _MuJoCoC | None = None
_C_ERROR: str | None = None


def library() -> _MuJoCoC | None:
    """MuJoCo's C functions, or None where its library cannot be loaded (:func:`unavailable` says why)."""
    global _C, _C_ERROR
    if _C is None and _C_ERROR is None:
        try:
            _C = _MuJoCoC()
        except (OSError, AttributeError) as exc:
            _C_ERROR = str(exc)
    return _C


def unavailable() -> str | None:
    """Why the compiled loop cannot run here, or None."""
    library()
    return _C_ERROR


# ---------------------------------------------------------------------------------------------- the kernel's groups
class Pointers(NamedTuple):
    """Addresses of the mjModel, the mjData, and the force reader's mesh probe and joints-only probe (mjModels)."""

    model: int
    data: int
    probe: int
    joints_only: int


class ModelViews(NamedTuple):
    """Views of the model fields the loop writes (the probe's: its mesh fields)."""

    tendon_stiffness: np.ndarray
    tendon_lengthspring: np.ndarray
    wrap_prm: np.ndarray
    probe_stiffness: np.ndarray
    probe_lengthspring: np.ndarray
    tendon_damping: np.ndarray


class DataViews(NamedTuple):
    """Views of the mjData fields the loop reads or writes."""

    qpos: np.ndarray
    qvel: np.ndarray
    act: np.ndarray
    qacc: np.ndarray
    act_dot: np.ndarray
    ctrl: np.ndarray
    qfrc_applied: np.ndarray
    sensordata: np.ndarray
    qfrc_spring: np.ndarray
    qfrc_damper: np.ndarray
    energy: np.ndarray
    xpos: np.ndarray
    xmat: np.ndarray
    site_xpos: np.ndarray
    ten_length: np.ndarray
    ten_velocity: np.ndarray


class Turning(NamedTuple):
    """The turning tendons' world-frame coefficients (``MbdModel.turning``), the corrected tendons' damping
    (``MbdModel.corrected_damping``) and the meshes' half backlash."""

    coefficients: TurningCoefficients
    damping: np.ndarray
    half_backlash: np.ndarray


class Contacts(NamedTuple):
    """The relieved meshes' tooth contacts (``_ToothContacts``): tendons, ``wrap_prm`` entries and qpos addresses
    of their coefficients, and each tendon's first coefficient (one more at the end)."""

    tendons: np.ndarray
    wraps: np.ndarray
    qadr: np.ndarray
    starts: np.ndarray


class MeshSwitches(NamedTuple):
    """The mesh tendons whose contact law has kinks, for event location: tendons, their ``wrap_prm`` entries with
    the qpos and dof addresses of their coefficients, each tendon's first entry (one more at the end), its mesh's
    place among the relieved meshes (-1: a backlash's dead zone) and half backlash."""

    tendons: np.ndarray
    wraps: np.ndarray
    qadr: np.ndarray
    dofs: np.ndarray
    starts: np.ndarray
    relieved: np.ndarray
    half_backlash: np.ndarray
    count: int  # switching functions: these tendons' and the pins'


class Work(NamedTuple):
    """Work space of the damping correction and the switching functions: the corrected tendons' Jacobian, the
    turned coefficients, g, each corrected tendon's deflection rate from its coefficients' turning."""

    jacobian: np.ndarray
    coef: np.ndarray
    g: np.ndarray
    turning_rate: np.ndarray


class Reader(NamedTuple):
    """The force reader's dofs and slides (``ForceReader``)."""

    dofs: np.ndarray
    slides: np.ndarray


class Drive(NamedTuple):
    """The drive at each (sub-)step's stage times (axis 1: t, t + h/2, t + h, as
    :meth:`gearcheck.mbd_models.runner._Drive.steps` gives it), a row per (sub-)step: mesh stiffness, controls,
    transmission error and its rate, the relieved meshes' tooth pairs; the absent ones empty along their last
    axes."""

    k: np.ndarray
    u: np.ndarray
    e: np.ndarray
    de: np.ndarray
    pairs: np.ndarray


class Split(NamedTuple):
    """The split steps' sub-steps: step i is split when ``count[i - start] > 0``, into the sub-steps ``first``.. of
    ``lengths`` and ``drive``."""

    first: np.ndarray
    count: np.ndarray
    lengths: np.ndarray
    drive: Drive


class Stages(NamedTuple):
    """RK4's work space: the state at the step's start (``qpos0``, ``qvel0``, ``act0``), each stage's derivatives
    (``qvel``, ``qacc``, ``act_dot``, one row per stage) and their weighted sums (``velocity``, ``acceleration``,
    ``activation``)."""

    qpos0: np.ndarray
    qvel0: np.ndarray
    act0: np.ndarray
    qvel: np.ndarray
    qacc: np.ndarray
    act_dot: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    activation: np.ndarray

    @classmethod
    def of(cls, m: mujoco.MjModel) -> "Stages":
        return cls(np.zeros(m.nq), np.zeros(m.nv), np.zeros(m.na), np.zeros((4, m.nv)), np.zeros((4, m.nv)),
                   np.zeros((4, m.na)), np.zeros(m.nv), np.zeros(m.nv), np.zeros(m.na))


class Flags(NamedTuple):
    """What the loop drives and records besides the mesh stiffness and the sensors."""

    transmission_error: bool
    tooth_pairs: bool
    record_stiffness: bool
    record_energy: bool
    moving_contacts: bool


class Outputs(NamedTuple):
    """The sampled rows: sensordata, the force reader's forces, and (possibly empty) stiffness, energy, the moving
    contacts' forces (``MbdModel.moving_slices``)."""

    sensors: np.ndarray
    forces: np.ndarray
    stiffness: np.ndarray
    energy: np.ndarray
    contact_forces: np.ndarray


# ---------------------------------------------------------------------------------------------- the kernel
@numba.njit(inline="always", _nrt=False)
def _copy(dst, src):
    """dst[:] = src, element by element (an array assignment would need numba's reference-counted runtime)."""
    for i in range(src.size):
        dst[i] = src[i]


@numba.njit(cache=True, inline="always", _nrt=False)
def _refresh(qpos, wrap_prm, coefficients, coef):
    """The world-frame coefficients (:class:`TurningCoefficients`) turned to the carriers' angles
    (``MbdModel.refresh``).  A carrier's cosine and sine are taken once for the run of wraps that follow it (the
    wraps come carrier by carrier): a twin has one carrier per stage and tens of turning wraps."""
    wraps, base, carrier_qadr = coefficients.wraps, coefficients.base, coefficients.carrier_qadr
    turned, cos, sin = -1, 1.0, 0.0
    for w in range(wraps.size):
        if carrier_qadr[w] != turned:
            turned = carrier_qadr[w]
            phi = qpos[turned]
            cos, sin = math.cos(phi), math.sin(phi)
        coef[w] = base[w, 0] * cos + base[w, 1] * sin
        wrap_prm[wraps[w]] = coef[w]


@numba.njit(inline="always", _nrt=False)
def _turning_rates(qpos, qvel, turning, coef, out):
    """Per corrected tendon (``MbdModel.corrected``: the meshes', then their tilting tendons'), the part of its
    deflection rate that its J qvel misses, its coefficients c(phi) turning with their carrier:
    d/dt (c q) = c q' + (dc/dphi) phi' q (``TurningCoefficients.missing_rate``), ``coef`` the coefficients at qpos."""
    wraps, _, carrier_qadr, tendon, joint_qadr, _ = turning.coefficients
    half = wraps.size // 2
    out[:] = 0.0
    for w in range(wraps.size):
        turned = -coef[w + half] if w < half else coef[w - half]  # dc/dphi: a pair (a, b) turns as (-b, a)
        out[tendon[w]] += turned * qvel[carrier_qadr[w]] * qpos[joint_qadr[w]]


@numba.njit(cache=True, inline="always", _nrt=False)
def _set_stage(k, u, e, de, pairs, has_te, has_pairs, model, data, turning, contacts, work):
    """``_Stepper.set_stage``: stiffness, controls, spring lengths, tooth contacts, damping correction."""
    stiffness, lengthspring, wrap_prm = model.tendon_stiffness, model.tendon_lengthspring, model.wrap_prm
    qpos, qvel, ctrl, applied = data.qpos, data.qvel, data.ctrl, data.qfrc_applied
    (wraps, base, carrier_qadr, tendon, joint_qadr, joint_dof), damping, half_backlash = turning
    rel_tendons, rel_wraps, rel_qadr, rel_starts = contacts
    J, coef, g, _ = work
    n = k.size
    for i in range(n):
        stiffness[i] = k[i]
    for i in range(u.size):
        ctrl[i] = u[i]
    if has_te:
        for i in range(n):
            lengthspring[i, 0] = e[i] - half_backlash[i]
            lengthspring[i, 1] = e[i] + half_backlash[i]
    if has_pairs:  # _ToothContacts.apply
        for r in range(rel_tendons.size):
            t = rel_tendons[r]
            offset = e[t] if has_te else 0.0
            length = 0.0
            for w in range(rel_starts[r], rel_starts[r + 1]):
                length += wrap_prm[rel_wraps[w]] * qpos[rel_qadr[w]]
            length -= offset
            total = 0.0
            moment = 0.0
            for p in range(pairs.shape[1]):
                if length > pairs[r, p, 1]:
                    total += pairs[r, p, 0]
                    moment += pairs[r, p, 0] * pairs[r, p, 1]
            stiffness[t] = total
            spring = offset + (moment / total if total > 0 else 0.0)
            lengthspring[t, 0] = spring
            lengthspring[t, 1] = spring
    # DampingCorrection.apply: g = c (de/dt - m) (de/dt on the meshes only), qfrc_applied = J^T g
    for w in range(wraps.size):
        coef[w] = wrap_prm[wraps[w]]
        J[tendon[w], joint_dof[w]] = coef[w]
    _turning_rates(qpos, qvel, turning, coef, g)
    for i in range(g.size):
        g[i] *= -damping[i]
    if has_te:
        for i in range(n):
            g[i] += damping[i] * de[i]
    applied[:] = 0.0
    for i in range(g.size):  # row by row (J is C-ordered); each applied[v] still sums over i in order
        gi = g[i]
        for v in range(applied.size):
            applied[v] += gi * J[i, v]


@numba.njit(cache=True, inline="always", _nrt=False)
def _sample(j, passive, pointers, model, data, reader, outputs, flags, moving):
    """``_Stepper.sample``: sensordata, the force reader's generalized forces (``ForceReader.sample``), and
    optionally the stiffness used, MuJoCo's energy and the moving contacts' forces, into row ``j``."""
    stiffness, lengthspring = model.tendon_stiffness, model.tendon_lengthspring
    probe_stiffness, probe_lengthspring = model.probe_stiffness, model.probe_lengthspring
    sensordata, spring, damper, energy, applied = (data.sensordata, data.qfrc_spring, data.qfrc_damper, data.energy,
                                                   data.qfrc_applied)
    dofs, slides = reader
    sensors, forces, used, energies, contact_forces = outputs
    _copy(sensors[j], sensordata)
    n = probe_stiffness.size
    for i in range(n):
        probe_stiffness[i] = stiffness[i]
        probe_lengthspring[i, 0] = lengthspring[i, 0]
        probe_lengthspring[i, 1] = lengthspring[i, 1]
    passive(pointers.probe, pointers.data)
    nd = dofs.size
    for i in range(nd):
        forces[j, i] = spring[dofs[i]] + damper[dofs[i]]
        forces[j, nd + i] = applied[dofs[i]]
    passive(pointers.joints_only, pointers.data)
    for i in range(slides.size):
        forces[j, 2 * nd + i] = spring[slides[i]] + damper[slides[i]]
    if flags.record_stiffness:
        for i in range(n):
            used[j, i] = stiffness[i]
    if flags.record_energy:
        energies[j, 0] = energy[0]
        energies[j, 1] = energy[1]
    if flags.moving_contacts:
        record_moving(moving, (contact_forces[j], model, data), 0)


@numba.njit(cache=True, inline="always", _nrt=False)
def _drive_stage(s, r, drive, kinematics, com_pos, jac, pointers, model, data, turning, contacts, work, moving,
                 flags):
    """Everything a stage sets from its own state: the moving contacts' tendons, the turned coefficients, the drive
    of row ``r`` at stage time ``s``."""
    if flags.moving_contacts:
        refresh_moving(moving, (kinematics, com_pos, jac, pointers.model, pointers.data, model, data))
    _refresh(data.qpos, model.wrap_prm, turning.coefficients, work.coef)
    _set_stage(drive.k[r, s], drive.u[r, s], drive.e[r, s], drive.de[r, s], drive.pairs[r, s],
               flags.transmission_error, flags.tooth_pairs, model, data, turning, contacts, work)


@numba.njit(cache=True, _nrt=False)
def _rk4(c, pointers, model, data, turning, contacts, work, reader, moving, stages, drive, r, h, flags, outputs,
         sample, j):
    """One RK4 (sub-)step of length h with the drive of row ``r`` at its stage times, MuJoCo's ``mj_RungeKutta``
    written out (the same sums in the same order) with each stage driven from its own state; the first stage
    sampled into row j when ``sample``.  Returns the next row."""
    forward, forward_skip, integrate_pos, passive, kinematics, com_pos, jac = c
    m, d = pointers.model, pointers.data
    qpos, qvel, act, qacc, act_dot = data.qpos, data.qvel, data.act, data.qacc, data.act_dot
    qpos0, qvel0, act0, V, A, AD, velocity, acceleration, activation = stages
    _copy(qpos0, qpos)
    _copy(qvel0, qvel)
    _copy(act0, act)
    for stage in range(4):
        if stage > 0:
            a = STAGE_ADVANCE[stage - 1]
            _copy(qpos, qpos0)
            for i in range(qvel.size):
                velocity[i] = V[stage - 1, i] * a
            integrate_pos(m, qpos.ctypes.data, velocity.ctypes.data, h)
            for i in range(qvel.size):
                qvel[i] = qvel0[i] + A[stage - 1, i] * a * h
            for i in range(act.size):
                act[i] = act0[i] + AD[stage - 1, i] * a * h
        _drive_stage(STAGE_TIMES[stage], r, drive, kinematics, com_pos, jac, pointers, model, data, turning,
                     contacts, work, moving, flags)
        if stage == 0 and sample:
            forward(m, d)
            _sample(j, passive, pointers, model, data, reader, outputs, flags, moving)
            j += 1
        else:
            forward_skip(m, d, 0, 1)  # mjSTAGE_NONE, no sensors: nothing reads them
        _copy(V[stage], qvel)
        _copy(A[stage], qacc)
        _copy(AD[stage], act_dot)
    velocity[:] = 0.0
    acceleration[:] = 0.0
    activation[:] = 0.0
    for stage in range(4):
        weight = 1.0 / 6.0 if stage == 0 or stage == 3 else 1.0 / 3.0
        for i in range(qvel.size):
            velocity[i] += V[stage, i] * weight
            acceleration[i] += A[stage, i] * weight
        for i in range(act.size):
            activation[i] += AD[stage, i] * weight
    for i in range(act.size):
        act[i] = act0[i] + activation[i] * h
    for i in range(qvel.size):
        qvel[i] = qvel0[i] + acceleration[i] * h
    _copy(qpos, qpos0)
    integrate_pos(m, qpos.ctypes.data, velocity.ctypes.data, h)
    return j


@numba.njit(cache=True, _nrt=False)
def _switching(c, pointers, model, data, turning, work, moving, switches, drive, r, s, span, flags, g, rate, motion,
               measure):
    """The contact switching functions of the twin's state into g and their rates into ``rate``: each mesh
    tendon's backlash edges (L - e - b, L - e + b) or tooth pairs (L - e - e_j; -1 for a padded pair), L the
    tendon's length with its coefficients turned to the state's carrier angles, and each pin's compression (its
    coefficients and kinematics at the state); the drive of row ``r`` at sample ``s`` (0 or 2) of a step of length
    ``span``.  A mesh's rate includes what its coefficients' turning adds (:func:`_turning_rates`).  The tendons'
    L and rate go into ``motion`` (2, tendons) when ``measure``; without it they are read from there, measured at
    this same state (the end of the step before: a step's start needs what its predecessor's end measured)."""
    qpos, qvel, wrap_prm = data.qpos, data.qvel, model.wrap_prm
    tendons, wraps, qadr, dofs, starts, relieved, half, _ = switches
    if measure:
        _refresh(qpos, wrap_prm, turning.coefficients, work.coef)
        _turning_rates(qpos, qvel, turning, work.coef, work.turning_rate)
        for i in range(tendons.size):
            length = 0.0
            speed = work.turning_rate[tendons[i]]
            for w in range(starts[i], starts[i + 1]):
                length += wrap_prm[wraps[w]] * qpos[qadr[w]]
                speed += wrap_prm[wraps[w]] * qvel[dofs[w]]
            motion[0, i] = length
            motion[1, i] = speed
    n = 0
    for i in range(tendons.size):
        t = tendons[i]
        length, speed = motion[0, i], motion[1, i]
        if flags.transmission_error:
            length -= drive.e[r, s, t]
            speed -= drive.de[r, s, t]
        j = relieved[i]
        if j >= 0:
            for pair in range(drive.pairs.shape[3]):
                gaps = drive.pairs[r, :, j, pair, 1]
                g[n], rate[n] = pair_switch(length, speed, gaps[0], gaps[1], gaps[2], s, span)
                n += 1
        else:
            g[n], g[n + 1] = length - half[i], length + half[i]
            rate[n], rate[n + 1] = speed, speed
            n += 2
    if flags.moving_contacts:
        refresh_moving(moving, (c[4], c[5], c[6], pointers.model, pointers.data, model, data))
        moving_switching(moving, (g, rate), n)


@numba.njit(cache=True, _nrt=False)
def _restart(stages, data) -> None:
    """The state back at the start of the last step (RK4's ``qpos0``, ``qvel0``, ``act0``)."""
    _copy(data.qpos, stages.qpos0)
    _copy(data.qvel, stages.qvel0)
    _copy(data.act, stages.act0)


@numba.njit(cache=True, _nrt=False)
def _part_of(drive, r, a, b, part) -> None:
    """Row 0 of ``part`` (a :class:`Drive` of one row): the drive of the part from fraction a to b of row r of
    ``drive`` (:func:`~gearcheck.shared.events.samples_between`)."""
    samples_between(drive.k[r], a, b, part.k[0])
    samples_between(drive.u[r], a, b, part.u[0])
    samples_between(drive.e[r], a, b, part.e[0])
    samples_between(drive.de[r], a, b, part.de[0])
    samples_between(drive.pairs[r], a, b, part.pairs[0])


@numba.njit(cache=True, inline="always", _nrt=False)
def _step(c, pointers, model, data, turning, contacts, work, reader, moving, stages, drive, r, h, flags, outputs,
          sample, j, switches, events):
    """One (sub-)step of length h with the drive of row ``r`` (:func:`_rk4`), its contact events located where
    ``switches`` has any (:mod:`gearcheck.shared.events`: the step taken again to the first crossing of a switching
    function, :func:`_switching`, and on from there; counted into ``events.located[0]``).  Returns the next row."""
    g0, r0, g1, r1, part, located, motion, carried = events
    # a part's row, the samples at a step's ends, sampling and measuring, typed as r, s, sample and measure are:
    # literals would compile _rk4 and _switching once more for each
    first, start, end, unsampled, measure = np.int64(0), np.int64(0), np.int64(2), np.bool_(False), np.bool_(True)
    if g0.size:
        _switching(c, pointers, model, data, turning, work, moving, switches, drive, r, start, h, flags, g0, r0,
                   motion, not carried[0])
        carried[0] = False
    j = _rk4(c, pointers, model, data, turning, contacts, work, reader, moving, stages, drive, r, h, flags, outputs,
             sample, j)
    if not g0.size:
        return j
    done, span = 0.0, h
    for _ in range(MAX_EVENTS):
        _switching(c, pointers, model, data, turning, work, moving, switches, drive, r, end, h, flags, g1, r1, motion,
                   measure)
        theta, crossed = first_crossing(g0, r0, g1, r1, span)
        if not MIN_FRACTION < theta < 1.0 - MIN_FRACTION:
            carried[0] = True  # the step's end, where the next step starts, measured
            break
        at = done + theta * (1.0 - done)  # the crossing, a fraction of the whole step
        _restart(stages, data)
        _part_of(drive, r, done, at, part)
        _rk4(c, pointers, model, data, turning, contacts, work, reader, moving, stages, part, first, (at - done) * h,
             flags, outputs, unsampled, j)
        located[0] += 1
        _switching(c, pointers, model, data, turning, work, moving, switches, part, first, end, (at - done) * h,
                   flags, g0, r0, motion, measure)
        crossed_together(g0, r0, (at - done) * h, crossed)
        done, span = at, (1.0 - at) * h
        _part_of(drive, r, done, 1.0, part)
        _rk4(c, pointers, model, data, turning, contacts, work, reader, moving, stages, part, first, span, flags,
             outputs, unsampled, j)
    return j


class Events(NamedTuple):
    """Work space of the event location: switching functions and rates at a step's two ends, the drive of a part
    of a step (a :class:`Drive` of one row), the count of events located, the mesh tendons' lengths and rates
    last measured (2, tendons) and whether they are those of the present state (``carried[0]``: a step's end
    measured them, and the next step starts there)."""

    g0: np.ndarray
    r0: np.ndarray
    g1: np.ndarray
    r1: np.ndarray
    part: Drive
    located: np.ndarray
    motion: np.ndarray
    carried: np.ndarray

    @classmethod
    def of(cls, switches: MeshSwitches, part: Drive) -> "Events":
        count = switches.count
        return cls(np.zeros(count), np.zeros(count), np.zeros(count), np.zeros(count), part,
                   np.zeros(1, dtype=np.int64), np.zeros((2, switches.tendons.size)), np.zeros(1, dtype=np.bool_))


@numba.njit(nogil=True, cache=True, _nrt=False)
def run_steps(c, pointers, model, data, turning, contacts, work, reader, moving, stages, drive, split, flags,
              outputs, h, start, stop, every, j, switches, events):
    """Steps start..stop-1 of one twin, sampling those that begin on a multiple of ``every`` into rows j.. of
    ``outputs``; returns the next row.  ``c``: MuJoCo's C functions (forward, forward_skip, integrate_pos, passive,
    kinematics, com_pos, jac); then the twin in the groups above, ``moving`` every registered kind of moving
    contact's group (:data:`gearcheck.mbd_models.elements.base.GROUPS`), ``drive`` one row per step, ``split`` the
    split steps' sub-steps, ``switches`` and ``events`` the contact events' location (:func:`_step`)."""
    first, count, lengths = split.first, split.count, split.lengths
    events.carried[0] = False  # the state may have been set since the last call
    for step in range(start, stop):
        i = step - start
        sample = step % every == 0
        if count[i] > 0:
            for s in range(first[i], first[i] + count[i]):
                j = _step(c, pointers, model, data, turning, contacts, work, reader, moving, stages, split.drive, s,
                          lengths[s], flags, outputs, sample and s == first[i], j, switches, events)
            continue
        j = _step(c, pointers, model, data, turning, contacts, work, reader, moving, stages, drive, i, h, flags,
                  outputs, sample, j, switches, events)
    return j
