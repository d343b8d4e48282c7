"""The compiled MuJoCo twin of a train: one compile, MuJoCo's own mesh coefficients, named indices.

:func:`compile_train` writes the MJCF (:mod:`gearcheck.mbd_models.mjcf_builder`) with every mesh
tendon over the joints that move its pitch point and compiles it once.  The tendon coefficients are then
taken from MuJoCo itself, d . (Jp_central(p) - Jp_planet(p)): the translation Jacobians (``mujoco.mj_jac``)
of the two bodies at the pitch point p, projected on the line of action d of the train
description (:func:`gearcheck.train.line_of_action.line_of_action`, given in the carrier frame and
placed in the world with the carrier body's pose), and written into the compiled model's
``wrap_prm`` and into the text's slots (below).  The mesh damping c = 2 zeta sqrt(k_mean m_eq),
m_eq = 1/(r_A^2/I_A + r_B^2/I_B), takes r_A, r_B from those coefficients on the two gears' hinges
and I from the compiled bodies.  Last, the default step comes from MuJoCo's own linearisation
(:mod:`gearcheck.mbd_models.linearise`) and is written into the model and the text, so the file
runs stably in MuJoCo's viewer.

Every part's late coefficients come the same way (:meth:`~gearcheck.mbd_models.elements.base.Element.late_rows`):
in a tilting stage the meshes' rows at their centres of stiffness with the members' tilts in them, the meshes'
tilting tendons (rotational Jacobians; their stiffness the mesh's tilting stiffness and their damping the mesh's in
the same proportion, :mod:`gearcheck.mbd_models.elements.mesh`) and the bearing stations' tendons
(:mod:`gearcheck.mbd_models.elements.stations`).

The coefficients of the world-frame joints (central members' and the carrier's slides, and their tilts in a
tilting stage) in the meshes' tendons depend on the carrier's angle; :class:`TurningCoefficients` keeps their
angle-0 values so that the runner can turn them every step.

An RV reducer's cycloid-pin stage (:mod:`gearcheck.mbd_models.elements.cycloid`) adds the splines between planets
and crankshafts, its needle bearings and one pin tendon per pin and disc, whose coefficients of t = 0 come
from MuJoCo's Jacobians likewise; its pins touching at t = 0, which the linearisation takes, are those of the
twin's own static equilibrium (:func:`gearcheck.mbd_models.static_state.static_state`), solved here once.

One pass.  The text is written once (:func:`~gearcheck.mbd_models.mjcf_builder.document`), as a
:class:`~gearcheck.mbd_models.mjcf_text.Template` whose late numbers -- the step, the meshes' stiffness, damping
and coefficients, the pins' coefficients and spring lengths -- are slots.  Filled with placeholders (coefficients
0, no mesh damping, ``PLACEHOLDER_STEP``) it is compiled, once; the numbers found above go into the compiled model
and into :class:`~gearcheck.mbd_models.mjcf_text.LateValues`, and the file is the same template filled with them.
The file compiled anew gives the twin's model to the bit but for ``tendon_invweight0``, which MuJoCo derives from
the coefficients at compile time for tendon limits, friction loss and equalities (the twin has none)
(``tests/test_twin_text.py``).  Until this design the text was rendered twice, the second time only to write those
numbers; medians of 15 compiles (ms, a shared 2-core machine):

    preset               compile_train  of it, writing the text   MuJoCo's compile
                         before  after  before (2 x)  after (1 x + 2 fills)
    demo-3p               19.4   15.0   4.1 + 4.1     4.3 + 0.1       3.6
    demo-4p               20.9   16.1   4.2 + 4.2     4.4 + 0.1       3.7
    double-planet         51.4   36.9  15.3 + 15.4   15.9 + 0.2      12.1
    helical-planetary     47.0   36.9  13.5 + 13.5   14.7 + 0.2      11.7
    hub-drive             44.0   34.3  10.4 + 11.0   11.1 + 0.3       8.4
    rv-reducer            75.8   70.9   5.1 + 5.4     5.4 + 0.5       5.0  (static state 46)

MuJoCo's own ``MjSpec`` would make the model the one description, but its ``to_xml`` (MuJoCo 4.0.0) cannot write
the file: it drops the comments, reorders attributes and writes every number to 6 significant digits (the step
3.3560532813411436e-06 as 3.35605e-06), so the file would neither match ``xml/`` nor hold the twin's numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import mujoco
import numpy as np

from gearcheck.train.excitation import Excitation
from gearcheck.train.kinematics import Kinematics, kinematics
from gearcheck.train.spec import TrainSpec
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import group_order
from gearcheck.mbd_models.elements.mesh import tilt_joints, tilt_tendon
from gearcheck.mbd_models.jacobians import named
from gearcheck.mbd_models.jacobians import tendon_rows
from gearcheck.mbd_models.mjcf_builder import document, header
from gearcheck.mbd_models.mjcf_text import ROTATION, LateValues, member_axes, member_joints, world_pairs
from gearcheck.mbd_models.static_state import static_state
from gearcheck.shared import stepping

PLACEHOLDER_STEP = 1e-5  # s, the compiled model's step until its own default is known
JOINT, BODY, TENDON = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_TENDON


class TurningCoefficients(NamedTuple):
    """The coefficients of the world-frame joints in the tendons that turn with their carrier (a named tuple of
    contiguous arrays: the compiled kernels take it as it is, inside :class:`~gearcheck.mbd_models.compiled.Turning`):
    a central member's or a carrier's slides along the world's x and y and, when it tilts, its tilts about them, in
    a mesh's tendon and its tilting tendon.  Each such pair (:func:`~gearcheck.mbd_models.mjcf_text.world_pairs`)
    turns as a vector.  Per wrap (the first joints of every pair, then their second joints): ``wraps`` the index
    into ``wrap_prm``; ``base`` (2n, 2) such that the coefficient is base @ (cos phi, sin phi), phi the angle of
    the carrier at qpos address ``carrier_qadr``; ``tendon`` the tendon it belongs to (one of the corrected
    tendons, :attr:`MbdModel.corrected`, which are the model's first); ``joint_qadr`` and ``joint_dof`` the joint
    it multiplies."""

    wraps: np.ndarray
    base: np.ndarray
    carrier_qadr: np.ndarray
    tendon: np.ndarray
    joint_qadr: np.ndarray
    joint_dof: np.ndarray

    def values(self, phi) -> np.ndarray:
        """The coefficients at carrier angles ``phi`` (one per wrap, or one scalar for all)."""
        return self.base[:, 0] * np.cos(phi) + self.base[:, 1] * np.sin(phi)

    def derivatives(self, phi) -> np.ndarray:
        """d(coefficient)/d(phi): a pair (a cos - b sin, a sin + b cos) turns as (-second, first)."""
        return self.base[:, 1] * np.cos(phi) - self.base[:, 0] * np.sin(phi)

    def missing_rate(self, phi, phidot, q, n_tendon: int) -> np.ndarray:
        """The part of each tendon's deflection rate that a fixed tendon's J qvel misses: its turning
        coefficients give d/dt (c(phi) q) = c q' + (dc/dphi) phi' q.  Arguments per wrap (time along
        axis 0 allowed): carrier angle, its rate, the joint's position.  Returns one rate per tendon 0..n-1."""
        terms = self.derivatives(phi) * phidot * q
        out = np.zeros(np.shape(terms)[:-1] + (n_tendon,))
        for t in range(n_tendon):
            out[..., t] = terms[..., self.tendon == t].sum(axis=-1)
        return out


@dataclass
class MbdModel:
    """A compiled MuJoCo model of a train and the named indices the runner needs."""

    spec: TrainSpec
    kin: Kinematics
    excitation: Excitation
    xml: str
    model: mujoco.MjModel
    limits: stepping.StepLimits  # of MuJoCo's linearisation, every mesh at its cycle-maximum stiffness
    body: dict[str, int]  # member id -> body id
    qadr: dict[str, dict[str, int]]  # member id -> {joint suffix: qpos address} (:func:`member_axes`, then rz)
    dadr: dict[str, dict[str, int]]  # member id -> {joint suffix: dof address}
    mesh_tendon: np.ndarray  # tendon id per spec.meshes entry (the first tendons of the model)
    mesh_damping: np.ndarray
    half_backlash: np.ndarray
    actuator: dict[str, int]
    sensor: dict[str, tuple[int, int]]  # name -> (address, dimension)
    turning: TurningCoefficients
    tilt_tendon: np.ndarray  # the tilting meshes' tilting tendons (the next tendons of the model)
    tilt_damping: np.ndarray
    moving_contacts: tuple = ()  # contacts whose tendons follow the bodies every step (an RV reducer's pins)

    @property
    def omega_max(self) -> float:
        return self.limits.omega_max

    @property
    def default_step(self) -> float:
        return stepping.default_step(self.limits, self.excitation.frequency)

    @property
    def corrected(self) -> np.ndarray:
        """The tendons whose damping the runner corrects (:class:`~gearcheck.mbd_models.static_state.
        DampingCorrection`), the model's first: the meshes' (their turning coefficients and a transmission error's
        rate) and the meshes' tilting tendons (their turning coefficients)."""
        return np.concatenate([self.mesh_tendon, self.tilt_tendon])

    @property
    def corrected_damping(self) -> np.ndarray:
        return np.concatenate([self.mesh_damping, self.tilt_damping])

    def moving_slices(self) -> list[slice]:
        """Where each of :attr:`moving_contacts`' tendons lie in arrays over all of them, in their order."""
        stops = np.cumsum([len(c.tendons) for c in self.moving_contacts], dtype=int)
        return [slice(int(stop) - len(c.tendons), int(stop)) for c, stop in zip(self.moving_contacts, stops)]

    def refresh(self, qpos: np.ndarray) -> None:
        """Turn the world-frame coefficients of every turning tendon to the carriers' angles in ``qpos``."""
        self.model.wrap_prm[self.turning.wraps] = self.turning.values(qpos[self.turning.carrier_qadr])

    def joint_dofs(self, members, suffixes) -> list[int]:
        """The dof addresses of ``members``' joints (:func:`~gearcheck.mbd_models.mjcf_text.member_joints`) whose
        suffixes are among ``suffixes``, member by member."""
        return [int(self.model.jnt_dofadr[named(self.model, JOINT, f"{m.label}_{a}")])
                for m in members for a in member_joints(m) if a in suffixes]

    def mesh_jacobian(self) -> np.ndarray:
        """(n_mesh, nv) coefficients of every mesh tendon as the model holds them now."""
        return tendon_rows(self.model, self.mesh_tendon)


def _write_row(model: mujoco.MjModel, name: str, row: np.ndarray) -> list[tuple[str, float]]:
    """The fixed tendon ``name``'s coefficients, each its joint's entry of ``row`` (over all dofs), into
    ``wrap_prm``; returns them as (joint, coefficient) for the text."""
    t = named(model, TENDON, name)
    wraps = range(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t])
    coefs = []
    for w in wraps:
        joint = int(model.wrap_objid[w])
        model.wrap_prm[w] = row[model.jnt_dofadr[joint]]
        coefs.append((mujoco.mj_id2name(model, JOINT, joint), float(model.wrap_prm[w])))
    return coefs


def _mesh_damping(spec, mesh, model, row, k_mean) -> float:
    if mesh.damping_coefficient is not None:
        return float(mesh.damping_coefficient)
    if not mesh.damping_ratio:
        return 0.0
    inv = 0.0
    for mid in (mesh.central, mesh.planet):
        label = spec.members[mid].label
        arm = row[model.jnt_dofadr[named(model, JOINT, label + "_rz")]]
        inv += arm**2 / model.body_inertia[named(model, BODY, label)][2]
    return 2.0 * mesh.damping_ratio * math.sqrt(k_mean / inv)


def _stiffness_values(spec: TrainSpec, exc: Excitation, stiffness) -> np.ndarray:
    if isinstance(stiffness, str):
        if stiffness == "mean":
            return exc.mean_stiffness.copy()
        if stiffness == "max":
            return exc.max_stiffness.copy()
        raise ValueError(f"stiffness must be 'mean', 'max' or an array of N/m per mesh, not {stiffness!r}")
    values = np.asarray(stiffness, dtype=float)
    if values.shape != (len(spec.meshes),):
        raise ValueError(f"stiffness needs one value per mesh ({len(spec.meshes)}), got shape {values.shape}")
    return values


def _tilting(spec: TrainSpec, exc: Excitation) -> list[tuple]:
    """(mesh, its tilting tendon, its mean stiffness) of every mesh of a tilting stage, in the meshes' order."""
    return [(mesh, tilt_tendon(mesh), float(k)) for mesh, k in zip(spec.meshes, exc.mean_stiffness)
            if tilt_joints(spec, mesh)]


def check_unconstrained(model: mujoco.MjModel, name: str) -> None:
    """Refuse a twin with a constraint.  Every force of a twin is a spring or damper of its joints and tendons, a
    control or an applied force, so its document disables MuJoCo's constraint stage (collision, making and solving
    the constraints: nothing to do, yet some 0.4 us of a 4-11 us evaluation); an equality, a limit or a friction
    loss that a part brought would be ignored without a word."""
    kinds = {"equality": model.neq, "limited joint": int(model.jnt_limited.sum()),
             "limited tendon": int(model.tendon_limited.sum()),
             "friction loss": int((model.dof_frictionloss > 0).sum() + (model.tendon_frictionloss > 0).sum())}
    found = [f"{count} {kind}" for kind, count in kinds.items() if count]
    if found:
        raise RuntimeError(f"the MuJoCo twin of {name} has {', '.join(found)}: its constraint stage is disabled "
                           "(mjcf_builder.document), so it would be ignored")


def compile_train(spec: TrainSpec, stiffness="mean") -> MbdModel:
    """Compile the MuJoCo twin of ``spec`` (once), with its tendons' coefficients from MuJoCo's Jacobians.

    stiffness: "mean" (default), "max" (cycle maximum) or one value per mesh (N/m): the tendons'
    constant stiffness in the file (the runner drives k(t) every step whatever it is).
    """
    kin = kinematics(spec)
    exc = Excitation(spec, kin)
    k = _stiffness_values(spec, exc, stiffness)
    tilting = _tilting(spec, exc)
    stiffness_label = "mean" if isinstance(stiffness, str) and stiffness == "mean" else "given"
    text = document(spec, header(spec, stiffness_label))  # written once; its late numbers are slots
    values = LateValues(PLACEHOLDER_STEP, stiffness={mesh.label: value for mesh, value in zip(spec.meshes, k)})
    values.stiffness.update({name: mesh.tilting_stiffness(k_mean) for mesh, name, k_mean in tilting})
    model = mujoco.MjModel.from_xml_string(text.fill(values))  # coefficients 0, no mesh damping, a placeholder step
    check_unconstrained(model, spec.name)

    # MuJoCo's own coefficients at the reference configuration, into the compiled model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for part in spec.parts:
        for name, row in ELEMENTS[part.element].late_rows(part, spec, kin, model, data):
            values.coefficients[name] = _write_row(model, name, row)
    rows = tendon_rows(model, range(len(spec.meshes)))
    damping = {mesh.label: _mesh_damping(spec, mesh, model, row, float(k_mean))
               for mesh, row, k_mean in zip(spec.meshes, rows, exc.mean_stiffness)}
    # a tilting tendon's damping: the mesh's in the proportion of their stiffnesses
    damping.update({name: damping[mesh.label] * mesh.tilting_stiffness(k_mean) / k_mean
                    for mesh, name, k_mean in tilting})
    for name, c in damping.items():
        model.tendon_damping[named(model, TENDON, name)] = c
    values.damping.update(damping)

    mb = _indices(spec, kin, exc, model, [name for _, name, _ in tilting])
    kinds = dict.fromkeys(part.element for part in spec.parts)
    contacts = (ELEMENTS[kind].contacts(spec, model) for kind in kinds)
    mb.moving_contacts = tuple(sorted((c for c in contacts if c is not None), key=group_order))
    for c in mb.moving_contacts:  # the contacts of t = 0, as MuJoCo's own Jacobians give them
        c.refresh(data)
        values.coefficients.update(c.written()[0])
    mb.limits = linearise.step_limits(mb)
    model.opt.timestep = mb.default_step
    if mb.moving_contacts:  # which touch at t = 0: those of the twin's own static equilibrium
        touching = static_state(mb).contacts
        for c, at in zip(mb.moving_contacts, mb.moving_slices()):
            c.contacts = touching[at]
            values.band.update(c.written()[1])
    values.timestep = model.opt.timestep
    mb.xml = text.fill(values)
    return mb


def _turning(spec, model, tendons, qadr) -> TurningCoefficients:
    """The world-frame joints' wraps in ``tendons`` ((tendon id, mesh) each), pair by pair
    (:func:`~gearcheck.mbd_models.mjcf_text.world_pairs` of the mesh's central member and carrier)."""
    first, second, carrier, tendon = [], [], [], []
    for t, mesh in tendons:
        adr, n = model.tendon_adr[t], model.tendon_num[t]
        wrap_of = {int(model.wrap_objid[adr + i]): adr + i for i in range(n)}
        stage = spec.stage_of(mesh.planet)
        for mid in (mesh.central, stage.carrier):
            label = spec.members[mid].label
            for a, b in world_pairs(spec.members[mid]):
                ja, jb = named(model, JOINT, f"{label}_{a}"), named(model, JOINT, f"{label}_{b}")
                if ja in wrap_of:
                    first.append((wrap_of[ja], ja))
                    second.append((wrap_of[jb], jb))
                    carrier.append(qadr[stage.carrier][ROTATION])
                    tendon.append(t)
    wraps, joints = (np.array([w for w, _ in first + second], dtype=int),
                     np.array([j for _, j in first + second], dtype=int))
    c0a, c0b = model.wrap_prm[wraps[:len(first)]].copy(), model.wrap_prm[wraps[len(first):]].copy()
    base = np.stack([np.concatenate([c0a, c0b]), np.concatenate([-c0b, c0a])], axis=1)
    return TurningCoefficients(wraps, base, np.array(carrier + carrier, dtype=int),
                               np.array(tendon + tendon, dtype=int), model.jnt_qposadr[joints].astype(int),
                               model.jnt_dofadr[joints].astype(int))


def _indices(spec, kin, exc, model, tilt_names) -> MbdModel:
    """Named indices of the compiled model (its xml and step limits are filled in by the caller)."""
    A, S = mujoco.mjtObj.mjOBJ_ACTUATOR, mujoco.mjtObj.mjOBJ_SENSOR
    body, qadr, dadr = {}, {}, {}
    for mid, member in spec.members.items():
        body[mid] = named(model, BODY, member.label)
        joints = {a: named(model, JOINT, f"{member.label}_{a}") for a in member_axes(member) + (ROTATION,)}
        qadr[mid] = {a: int(model.jnt_qposadr[j]) for a, j in joints.items()}
        dadr[mid] = {a: int(model.jnt_dofadr[j]) for a, j in joints.items()}
    mesh_tendon = np.array([named(model, TENDON, m.label) for m in spec.meshes], dtype=int)
    assert np.array_equal(mesh_tendon, np.arange(len(spec.meshes))), "mesh tendons must come first"
    tilt_tendon = np.array([named(model, TENDON, name) for name in tilt_names], dtype=int)
    assert np.array_equal(tilt_tendon, len(mesh_tendon) + np.arange(len(tilt_names))), "tilting tendons come next"
    actuator = {name: i for name in ("input_shaft", "input_shaft_damper", "input_torque", "output_load")
                if (i := mujoco.mj_name2id(model, A, name)) >= 0}
    sensor = {mujoco.mj_id2name(model, S, i): (int(model.sensor_adr[i]), int(model.sensor_dim[i]))
              for i in range(model.nsensor)}
    tilting = [mesh for mesh in spec.meshes if tilt_joints(spec, mesh)]
    turning = _turning(spec, model, list(enumerate(spec.meshes)) + list(zip(tilt_tendon, tilting)), qadr)
    return MbdModel(spec, kin, exc, "", model, None, body, qadr, dadr, mesh_tendon,
                    model.tendon_damping[mesh_tendon].copy(), model.tendon_lengthspring[mesh_tendon, 1].copy(),
                    actuator, sensor, turning, tilt_tendon, model.tendon_damping[tilt_tendon].copy())
