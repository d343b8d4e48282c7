"""The compiled MuJoCo twin of a train: one compile, MuJoCo's own mesh coefficients, named indices.

:func:`compile_train` writes the MJCF (:mod:`gearcheck.mbd_models.mjcf_builder`) with every mesh
tendon over its nine joints and compiles it once.  The tendon coefficients are then taken from
MuJoCo itself, d . (Jp_central(p) - Jp_planet(p)): the translation Jacobians (``mujoco.mj_jac``)
of the two bodies at the pitch point p, projected on the line of action d of the train
description (:func:`gearcheck.train.line_of_action.line_of_action`, given in the carrier frame and
placed in the world with the carrier body's pose), and written into the compiled model's
``wrap_prm`` and into the text's slots (below).  The mesh damping c = 2 zeta sqrt(k_mean m_eq),
m_eq = 1/(r_A^2/I_A + r_B^2/I_B), takes r_A, r_B from those coefficients on the two gears' hinges
and I from the compiled bodies.  Last, the default step comes from MuJoCo's own linearisation
(:mod:`gearcheck.mbd_models.linearise`) and is written into the model and the text, so the file
runs stably in MuJoCo's viewer.

The coefficients of the world-frame slides (central members and the carrier) depend on the
carrier's angle; :class:`TurningCoefficients` keeps their angle-0 values so that the runner can turn
them every step.

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
from gearcheck.train.line_of_action import line_of_action
from gearcheck.train.spec import TrainSpec
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import group_order
from gearcheck.mbd_models.elements.mesh import mesh_joints
from gearcheck.mbd_models.mjcf_builder import document, header
from gearcheck.mbd_models.mjcf_text import AXES, ROTATION, LateValues, member_axes
from gearcheck.mbd_models.static_state import static_state
from gearcheck.shared import stepping

PLACEHOLDER_STEP = 1e-5  # s, the compiled model's step until its own default is known


class TurningCoefficients(NamedTuple):
    """The mesh tendons' world-frame slide coefficients, which turn with their carrier (a named tuple of contiguous
    arrays: the compiled kernels take it as it is, inside :class:`~gearcheck.mbd_models.compiled.Turning`).

    Per wrap (x wraps of every mesh, then their y wraps): ``wraps`` the index into ``wrap_prm``;
    ``base`` (2n, 2) such that the coefficient is base @ (cos phi, sin phi), phi the angle of the
    carrier at qpos address ``carrier_qadr``; ``tendon`` the mesh it belongs to; ``slide_qadr`` and
    ``slide_dof`` the slide it multiplies."""

    wraps: np.ndarray
    base: np.ndarray
    carrier_qadr: np.ndarray
    tendon: np.ndarray
    slide_qadr: np.ndarray
    slide_dof: np.ndarray

    def values(self, phi) -> np.ndarray:
        """The coefficients at carrier angles ``phi`` (one per wrap, or one scalar for all)."""
        return self.base[:, 0] * np.cos(phi) + self.base[:, 1] * np.sin(phi)

    def derivatives(self, phi) -> np.ndarray:
        """d(coefficient)/d(phi): an (x, y) pair a cos - b sin, a sin + b cos turns as (-y, x)."""
        return self.base[:, 1] * np.cos(phi) - self.base[:, 0] * np.sin(phi)

    def missing_rate(self, phi, phidot, slide, n_mesh: int) -> np.ndarray:
        """The part of each mesh's deflection rate that a fixed tendon's J qvel misses: its turning
        coefficients give d/dt (c(phi) q) = c q' + (dc/dphi) phi' q.  Arguments per wrap (time along
        axis 0 allowed): carrier angle, its rate, the slide's position.  Returns one rate per mesh."""
        terms = self.derivatives(phi) * phidot * slide
        out = np.zeros(np.shape(terms)[:-1] + (n_mesh,))
        for t in range(n_mesh):
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
    moving_contacts: tuple = ()  # contacts whose tendons follow the bodies every step (an RV reducer's pins)

    @property
    def omega_max(self) -> float:
        return self.limits.omega_max

    @property
    def default_step(self) -> float:
        return stepping.default_step(self.limits, self.excitation.frequency)

    def moving_slices(self) -> list[slice]:
        """Where each of :attr:`moving_contacts`' tendons lie in arrays over all of them, in their order."""
        stops = np.cumsum([len(c.tendons) for c in self.moving_contacts], dtype=int)
        return [slice(int(stop) - len(c.tendons), int(stop)) for c, stop in zip(self.moving_contacts, stops)]

    def refresh(self, qpos: np.ndarray) -> None:
        """Turn the world-frame slide coefficients of every mesh tendon to the carriers' angles in ``qpos``."""
        self.model.wrap_prm[self.turning.wraps] = self.turning.values(qpos[self.turning.carrier_qadr])

    def mesh_jacobian(self) -> np.ndarray:
        """(n_mesh, nv) coefficients of every mesh tendon as the model holds them now."""
        m = self.model
        J = np.zeros((len(self.mesh_tendon), m.nv))
        for j, t in enumerate(self.mesh_tendon):
            wraps = np.arange(m.tendon_adr[t], m.tendon_adr[t] + m.tendon_num[t])
            J[j, m.jnt_dofadr[m.wrap_objid[wraps]]] = m.wrap_prm[wraps]
        return J


def _id(model, kind, name: str) -> int:
    i = mujoco.mj_name2id(model, kind, name)
    if i < 0:
        raise KeyError(f"no {kind} named {name!r} in the MuJoCo model")
    return i


def mesh_jacobian_row(spec: TrainSpec, kin: Kinematics, model: mujoco.MjModel, data: mujoco.MjData,
                      mesh) -> np.ndarray:
    """d . (Jp_central(p) - Jp_planet(p)) over all dofs, at ``data``'s current configuration.

    ``data`` must have its kinematics computed (``mj_kinematics`` and ``mj_comPos``, or
    ``mj_forward``).  p is the pitch point and d the line of action of the train
    description, both given in the carrier frame and placed in the world with the
    carrier body's current pose in ``data``.
    """
    stage = spec.stage_of(mesh.planet)
    planet = spec.members[mesh.planet]
    loa = line_of_action(mesh, planet.angle, stage.carrier_radius, kin.flanks[mesh.id])
    carrier_label = spec.members[stage.carrier].label
    carrier = _id(model, mujoco.mjtObj.mjOBJ_BODY, carrier_label)
    central = _id(model, mujoco.mjtObj.mjOBJ_BODY, spec.members[mesh.central].label)
    planet_body = _id(model, mujoco.mjtObj.mjOBJ_BODY, planet.label)
    R = data.xmat[carrier].reshape(3, 3)
    # the stage axis: the carrier frame's origin less the carrier's own slide displacement
    slides = [_id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{carrier_label}_{a}")
              for a in member_axes(spec.members[stage.carrier])]  # none: a torsional carrier stays on the axis
    shift = [data.qpos[model.jnt_qposadr[j]] for j in slides]
    origin = data.xpos[carrier] - np.array(shift + [0.0] * (3 - len(shift)))
    point = origin + rows_combined((loa.pitch_point[0], loa.pitch_point[1], 0.0), R.T)
    direction = rows_combined((loa.direction[0], loa.direction[1], loa.axial), R.T)
    jac_c = np.zeros((3, model.nv))
    jac_p = np.zeros((3, model.nv))
    mujoco.mj_jac(model, data, jac_c, None, point, central)
    mujoco.mj_jac(model, data, jac_p, None, point, planet_body)
    return rows_combined(direction, jac_c - jac_p)


def rows_combined(weights, rows: np.ndarray) -> np.ndarray:
    """sum_i weights[i] rows[i], added in index order.

    Written out rather than as a matrix product: BLAS picks its kernel (and with it the order of the
    additions and the use of fused multiply-adds) by processor and environment, and the coefficients
    written into the MJCF must come out the same to the last bit on every machine.
    """
    total = weights[0] * rows[0]
    for weight, row in zip(weights[1:], rows[1:]):
        total = total + weight * row
    return total


def _mesh_damping(spec, mesh, model, row, k_mean) -> float:
    if mesh.damping_coefficient is not None:
        return float(mesh.damping_coefficient)
    if not mesh.damping_ratio:
        return 0.0
    inv = 0.0
    for mid in (mesh.central, mesh.planet):
        label = spec.members[mid].label
        arm = row[model.jnt_dofadr[_id(model, mujoco.mjtObj.mjOBJ_JOINT, label + "_rz")]]
        inv += arm**2 / model.body_inertia[_id(model, mujoco.mjtObj.mjOBJ_BODY, label)][2]
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


def compile_train(spec: TrainSpec, stiffness="mean") -> MbdModel:
    """Compile the MuJoCo twin of ``spec`` (once), with its mesh coefficients from MuJoCo's Jacobians.

    stiffness: "mean" (default), "max" (cycle maximum) or one value per mesh (N/m): the tendons'
    constant stiffness in the file (the runner drives k(t) every step whatever it is).
    """
    kin = kinematics(spec)
    exc = Excitation(spec, kin)
    k = _stiffness_values(spec, exc, stiffness)
    joints = [mesh_joints(spec, mesh) for mesh in spec.meshes]
    stiffness_label = "mean" if isinstance(stiffness, str) and stiffness == "mean" else "given"
    text = document(spec, header(spec, stiffness_label))  # written once; its late numbers are slots
    values = LateValues(PLACEHOLDER_STEP, stiffness={mesh.label: value for mesh, value in zip(spec.meshes, k)})
    model = mujoco.MjModel.from_xml_string(text.fill(values))  # coefficients 0, no mesh damping, a placeholder step

    # MuJoCo's own coefficients at the reference configuration, into the compiled model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    damping = []
    for t, (mesh, names, k_mean) in enumerate(zip(spec.meshes, joints, exc.mean_stiffness)):
        row = mesh_jacobian_row(spec, kin, model, data, mesh)
        dofs = {name: int(model.jnt_dofadr[_id(model, mujoco.mjtObj.mjOBJ_JOINT, name)]) for name in names}
        coefs = sorted(((name, float(row[dofs[name]])) for name in names), key=lambda c: dofs[c[0]])
        adr = model.tendon_adr[t]
        for i, (name, value) in enumerate(coefs):
            assert model.wrap_objid[adr + i] == _id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
            model.wrap_prm[adr + i] = value
        damping.append(_mesh_damping(spec, mesh, model, row, float(k_mean)))
        values.coefficients[mesh.label], values.damping[mesh.label] = coefs, damping[-1]
    model.tendon_damping[:len(spec.meshes)] = damping

    mb = _indices(spec, kin, exc, model)
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


def _indices(spec, kin, exc, model) -> MbdModel:
    """Named indices of the compiled model (its xml and step limits are filled in by the caller)."""
    J, B, T, A, S = (mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_TENDON,
                     mujoco.mjtObj.mjOBJ_ACTUATOR, mujoco.mjtObj.mjOBJ_SENSOR)
    body, qadr, dadr = {}, {}, {}
    for mid, member in spec.members.items():
        body[mid] = _id(model, B, member.label)
        joints = {a: _id(model, J, f"{member.label}_{a}") for a in member_axes(member) + (ROTATION,)}
        qadr[mid] = {a: int(model.jnt_qposadr[j]) for a, j in joints.items()}
        dadr[mid] = {a: int(model.jnt_dofadr[j]) for a, j in joints.items()}
    mesh_tendon = np.array([_id(model, T, m.label) for m in spec.meshes], dtype=int)
    assert np.array_equal(mesh_tendon, np.arange(len(spec.meshes))), "mesh tendons must come first"
    actuator = {name: i for name in ("input_shaft", "input_shaft_damper", "input_torque", "output_load")
                if (i := mujoco.mj_name2id(model, A, name)) >= 0}
    sensor = {mujoco.mj_id2name(model, S, i): (int(model.sensor_adr[i]), int(model.sensor_dim[i]))
              for i in range(model.nsensor)}
    # world-frame slide pairs in every mesh tendon: x wraps, then y wraps
    x_wraps, y_wraps, carrier, tendon, slide_x, slide_y = [], [], [], [], [], []
    for t, mesh in enumerate(spec.meshes):
        adr, n = model.tendon_adr[t], model.tendon_num[t]
        wrap_of = {int(model.wrap_objid[adr + i]): adr + i for i in range(n)}
        stage = spec.stage_of(mesh.planet)
        for mid in (mesh.central, stage.carrier):
            if spec.members[mid].torsional:  # no world-frame slides
                continue
            label = spec.members[mid].label
            x_wraps.append(wrap_of[_id(model, J, label + "_x")])
            y_wraps.append(wrap_of[_id(model, J, label + "_y")])
            carrier.append(qadr[stage.carrier][ROTATION])
            tendon.append(t)
            slide_x.append(mid)
            slide_y.append(mid)
    wraps = np.array(x_wraps + y_wraps, dtype=int)
    c0x, c0y = model.wrap_prm[x_wraps].copy(), model.wrap_prm[y_wraps].copy()
    base = np.stack([np.concatenate([c0x, c0y]), np.concatenate([-c0y, c0x])], axis=1)
    x, y = AXES["axis"]
    slide_qadr = np.array([qadr[mid][x] for mid in slide_x] + [qadr[mid][y] for mid in slide_y], dtype=int)
    slide_dof = np.array([dadr[mid][x] for mid in slide_x] + [dadr[mid][y] for mid in slide_y], dtype=int)
    carrier_qadr = np.array(carrier + carrier, dtype=int)
    turning = TurningCoefficients(wraps, base, carrier_qadr, np.array(tendon + tendon, dtype=int), slide_qadr,
                                  slide_dof)
    return MbdModel(spec, kin, exc, "", model, None, body, qadr, dadr, mesh_tendon,
                    model.tendon_damping[mesh_tendon].copy(), model.tendon_lengthspring[mesh_tendon, 1].copy(),
                    actuator, sensor, turning)
