"""MJCF generation: the train as rigid bodies on joints, meshes as fixed tendons.

Bodies and joints (all planar, gravity off):

* every central member (sun, ring, carrier) of every stage is a child of the world at
  the stage's axis, with world-frame slide joints ``<label>_x``, ``<label>_y`` and a
  hinge ``<label>_rz`` (absolute rotation); its support is the joints' stiffness and
  damping (radial on the slides, torsional on the hinge);
* every planet is a child body of its stage's carrier, placed at the carrier radius
  and angle psi_n, with slide joints ``<label>_radial`` and ``<label>_tangential``
  along the carrier's radial and tangential axes and a hinge ``<label>_rz`` (rotation
  relative to the carrier); its bearing is the slides' stiffness and damping.
  A compound planet is one body;
* interstage couplings are fixed tendons (torsion, and x/y when radial stiffness is given);
* the input shaft is an ``intvelocity`` actuator (kp = shaft stiffness) on the input hinge:
  its activation, the reference angle, integrates the control w_in inside MuJoCo's RK4
  stages (a ``position`` actuator fed w_in t held constant over each step biased the input
  speed by O(kp w_in h^2 / I) per unit time, enough to shift a lightly loaded mesh's mean
  damping force by 5 %); plus a ``velocity`` actuator (kv = shaft damping) whose control is
  w_in, so the shaft damping acts on the twist rate only;
  load and input torques are ``motor`` actuators with gear 1.

Meshes: each mesh is a ``<fixed>`` tendon whose length is the mesh deflection

    delta = (u_central(p) - u_planet(p)) . d     (positive = teeth compressed),

with p the pitch point and d the unit line-of-action direction from the train
description (:func:`lumped.contact.line_of_action`, given in the carrier frame and
rotated into the world by the carrier's angle).  The joint coefficients are NOT
written from a formula: they are d . (Jp_central - Jp_planet), the translation
Jacobians of MuJoCo's own bodies at p (``mujoco.mj_jac``) in a compiled skeleton of
the same model.  A backlash b = backlash/2 is the two-valued spring length "-b b"
(a dead band).  The coefficients of world-frame slides (central members and the
carrier) depend on the carrier angle; :class:`MbdModel` keeps the indices and the
angle-0 values so the runner can rotate them every step (see :meth:`MbdModel.refresh`).

Mesh damping: c = 2 zeta sqrt(k_mean m_eq), m_eq = 1/(r_A^2/I_A + r_B^2/I_B) with
r_A, r_B the tendon's own coefficients on the two gears' hinges and I the bodies' polar
inertias in the compiled model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from lumped.contact import line_of_action
from lumped.excitation import Excitation
from lumped.kinematics import Kinematics, kinematics
from lumped.spec import TrainSpec

STAGE_SPACING = 0.12  # m along z between stages (visual only: all motion is planar)
RGBA = {
    "sun": "0.95 0.6 0.1 1",
    "ring": "0.6 0.6 0.65 0.35",
    "carrier": "0.2 0.4 0.85 0.6",
    "planet": "0.2 0.75 0.3 1",
}
CENTRAL_AXES = ("x", "y")
PLANET_AXES = ("radial", "tangential")


def num(x) -> str:
    """A float written with full precision (shortest repr that round-trips)."""
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


def vec(*xs) -> str:
    return " ".join(num(x) for x in xs)


# --------------------------------------------------------------------------- bodies


def _joint(name: str, kind: str, axis, stiffness: float = 0.0, damping: float = 0.0) -> str:
    attrs = [f'name="{name}"', f'type="{kind}"', f'axis="{vec(*axis)}"', 'pos="0 0 0"']
    if stiffness:
        attrs.append(f'stiffness="{num(stiffness)}"')
    if damping:
        attrs.append(f'damping="{num(damping)}"')
    return f"<joint {' '.join(attrs)}/>"


def _inertial(member) -> str:
    polar = member.inertia
    return (f'<inertial pos="0 0 0" mass="{num(member.mass)}" '
            f'diaginertia="{vec(0.5 * polar, 0.5 * polar, polar)}"/>')


def _visual_radius(spec: TrainSpec, member) -> float:
    if member.kind == "carrier":
        return spec.stage_of(member.id).carrier_radius
    return max(g.pitch_radius for g in member.gears.values())


def _visual_halfwidth(member) -> float:
    if member.gears:
        return 0.5 * max(g.face_width for g in member.gears.values())
    return 0.005


def _geom(spec: TrainSpec, member, z: float = 0.0) -> str:
    r = _visual_radius(spec, member)
    h = _visual_halfwidth(member) if member.kind != "carrier" else 0.005
    return (f'<geom name="{member.label}_visual" type="cylinder" size="{vec(r, h)}" pos="{vec(0, 0, z)}" '
            f'rgba="{RGBA[member.kind]}" contype="0" conaffinity="0" group="1"/>')


def _central_body(spec, member, z_stage: float, indent: str, children: list[str]) -> list[str]:
    s = member.support
    lines = [f'{indent}<body name="{member.label}" pos="{vec(0, 0, z_stage)}">',
             f"{indent}  {_inertial(member)}",
             f"{indent}  {_joint(member.label + '_x', 'slide', (1, 0, 0), s.radial_stiffness, s.radial_damping)}",
             f"{indent}  {_joint(member.label + '_y', 'slide', (0, 1, 0), s.radial_stiffness, s.radial_damping)}",
             f"{indent}  {_joint(member.label + '_rz', 'hinge', (0, 0, 1), s.torsional_stiffness, s.torsional_damping)}"]
    z_geom = -2.0 * max((_visual_halfwidth(spec.members[p]) for p in spec.stage_of(member.id).planets),
                        default=0.01) if member.kind == "carrier" else 0.0
    lines.append(f"{indent}  {_geom(spec, member, z_geom)}")
    lines += children
    lines.append(f"{indent}</body>")
    return lines


def _planet_body(spec, member, indent: str) -> list[str]:
    b = member.bearing
    c, s = math.cos(member.angle), math.sin(member.angle)
    return [f'{indent}<body name="{member.label}" pos="{vec(member.radius * c, member.radius * s, 0)}">',
            f"{indent}  {_inertial(member)}",
            f"{indent}  {_joint(member.label + '_radial', 'slide', (c, s, 0), b.radial_stiffness, b.radial_damping)}",
            f"{indent}  {_joint(member.label + '_tangential', 'slide', (-s, c, 0), b.radial_stiffness, b.radial_damping)}",
            f"{indent}  {_joint(member.label + '_rz', 'hinge', (0, 0, 1))}",
            f"{indent}  {_geom(spec, member)}",
            f"{indent}</body>"]


def _worldbody(spec: TrainSpec) -> list[str]:
    lines = ["  <worldbody>"]
    for i, stage in enumerate(spec.stages):
        z = -STAGE_SPACING * i
        lines.append(f"    <!-- {stage.name}: carrier radius {num(stage.carrier_radius)} m, "
                     f"{len(stage.planets)} planets -->")
        for mid in stage.centrals:
            lines += _central_body(spec, spec.members[mid], z, "    ", [])
        planets = []
        for pid in stage.planets:
            planets += _planet_body(spec, spec.members[pid], "      ")
        lines += _central_body(spec, spec.members[stage.carrier], z, "    ", planets)
    lines.append("  </worldbody>")
    return lines


# --------------------------------------------------------------------------- tendons


def _fixed(name: str, coefs: list[tuple[str, float]], stiffness: float, damping: float,
           springlength: tuple[float, float] = (0.0, 0.0)) -> list[str]:
    attrs = [f'name="{name}"', f'stiffness="{num(stiffness)}"', f'springlength="{vec(*springlength)}"']
    if damping:
        attrs.append(f'damping="{num(damping)}"')
    lines = [f"    <fixed {' '.join(attrs)}>"]
    lines += [f'      <joint joint="{j}" coef="{num(c)}"/>' for j, c in coefs]
    lines.append("    </fixed>")
    return lines


def _coupling_tendons(spec: TrainSpec) -> list[str]:
    lines = []
    for c in spec.couplings:
        a, b = spec.members[c.a].label, spec.members[c.b].label
        lines += _fixed(f"coupling_{c.name}_torsion", [(a + "_rz", 1.0), (b + "_rz", -1.0)],
                        c.torsional_stiffness, c.torsional_damping)
        if c.radial_stiffness or c.radial_damping:
            for axis in CENTRAL_AXES:
                lines += _fixed(f"coupling_{c.name}_{axis}", [(f"{a}_{axis}", 1.0), (f"{b}_{axis}", -1.0)],
                                c.radial_stiffness, c.radial_damping)
    return lines


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
    carrier = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, spec.members[stage.carrier].label)
    central = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, spec.members[mesh.central].label)
    planet_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, planet.label)
    R = data.xmat[carrier].reshape(3, 3)
    # the stage axis: the carrier frame's origin less the carrier's own slide displacement
    jx = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, spec.members[stage.carrier].label + "_x")
    jy = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, spec.members[stage.carrier].label + "_y")
    origin = data.xpos[carrier] - np.array([data.qpos[model.jnt_qposadr[jx]], data.qpos[model.jnt_qposadr[jy]], 0.0])
    point = origin + R @ np.array([loa.pitch_point[0], loa.pitch_point[1], 0.0])
    direction = R @ np.array([loa.direction[0], loa.direction[1], 0.0])
    jac_c = np.zeros((3, model.nv))
    jac_p = np.zeros((3, model.nv))
    mujoco.mj_jac(model, data, jac_c, None, point, central)
    mujoco.mj_jac(model, data, jac_p, None, point, planet_body)
    return direction @ (jac_c - jac_p)


@dataclass
class _MeshTendon:
    name: str
    coefs: list[tuple[str, float]]
    damping: float
    backlash: float


def _mesh_tendons(spec: TrainSpec, kin: Kinematics, skeleton: mujoco.MjModel, stiffness: np.ndarray) -> list[_MeshTendon]:
    """Mesh tendon coefficients from the skeleton model's own Jacobians at its reference configuration."""
    data = mujoco.MjData(skeleton)
    mujoco.mj_forward(skeleton, data)
    names = [mujoco.mj_id2name(skeleton, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(skeleton.njnt)]
    dof_joint = skeleton.dof_jntid
    out = []
    for mesh, k_mean in zip(spec.meshes, stiffness):
        row = mesh_jacobian_row(spec, kin, skeleton, data, mesh)
        keep = set(np.nonzero(row)[0])
        # world-frame slides always come in (x, y) pairs: their coefficients rotate with the carrier
        for mid in (mesh.central, spec.stage_of(mesh.planet).carrier):
            for axis in CENTRAL_AXES:
                keep.add(skeleton.jnt_dofadr[names.index(f"{spec.members[mid].label}_{axis}")])
        coefs = [(names[dof_joint[i]], float(row[i])) for i in sorted(keep)]
        damping = _mesh_damping(spec, mesh, skeleton, row, names, float(k_mean))
        out.append(_MeshTendon(mesh.label, coefs, damping, 0.5 * mesh.backlash))
    return out


def _mesh_damping(spec, mesh, model, row, names, k_mean) -> float:
    if mesh.damping_coefficient is not None:
        return float(mesh.damping_coefficient)
    if not mesh.damping_ratio:
        return 0.0
    inv = 0.0
    for mid in (mesh.central, mesh.planet):
        label = spec.members[mid].label
        arm = row[model.jnt_dofadr[names.index(label + "_rz")]]
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, label)
        inv += arm**2 / model.body_inertia[body][2]
    return 2.0 * mesh.damping_ratio * math.sqrt(k_mean / inv)


# --------------------------------------------------------------------------- actuators, sensors


def _actuators(spec: TrainSpec) -> list[str]:
    op = spec.operating
    joint_in = spec.members[spec.input].label + "_rz"
    joint_out = spec.members[spec.output].label + "_rz"
    lines = ["  <actuator>"]
    if op.input_shaft_stiffness is not None:
        # integrated-velocity servo: its activation (the reference angle) integrates the control w_in
        # inside MuJoCo's own RK4 stages, so the turning reference is exact at every stage
        lines.append(f'    <intvelocity name="input_shaft" joint="{joint_in}" kp="{num(op.input_shaft_stiffness)}" '
                     f'actlimited="false" ctrllimited="false" forcelimited="false"/>')
        if op.input_shaft_damping:
            lines.append(f'    <velocity name="input_shaft_damper" joint="{joint_in}" '
                         f'kv="{num(op.input_shaft_damping)}" ctrllimited="false" forcelimited="false"/>')
    lines.append(f'    <motor name="input_torque" joint="{joint_in}" gear="1" ctrllimited="false" '
                 f'forcelimited="false"/>')
    lines.append(f'    <motor name="output_load" joint="{joint_out}" gear="1" ctrllimited="false" '
                 f'forcelimited="false"/>')
    lines.append("  </actuator>")
    return lines


def _sensors(spec: TrainSpec) -> list[str]:
    lines = ["  <sensor>"]
    for mid, member in spec.members.items():
        lines.append(f'    <framelinacc name="{member.label}_linacc" objtype="body" objname="{member.label}"/>')
        lines.append(f'    <frameangacc name="{member.label}_angacc" objtype="body" objname="{member.label}"/>')
    for stage in spec.stages:
        label = spec.members[stage.carrier].label
        lines.append(f'    <jointpos name="{label}_angle" joint="{label}_rz"/>')
        lines.append(f'    <jointvel name="{label}_angle_rate" joint="{label}_rz"/>')
    for mid, member in spec.members.items():
        if not member.is_planet:
            for axis in CENTRAL_AXES:
                lines.append(f'    <jointpos name="{member.label}_{axis}_pos" joint="{member.label}_{axis}"/>')
    for mesh in spec.meshes:
        lines.append(f'    <tendonpos name="{mesh.label}_deflection" tendon="{mesh.label}"/>')
        lines.append(f'    <tendonvel name="{mesh.label}_rate" tendon="{mesh.label}"/>')
    for mid, member in spec.members.items():
        if member.is_planet:
            for axis in PLANET_AXES:
                lines.append(f'    <jointpos name="{member.label}_{axis}_pos" joint="{member.label}_{axis}"/>')
                lines.append(f'    <jointvel name="{member.label}_{axis}_vel" joint="{member.label}_{axis}"/>')
    lines.append("  </sensor>")
    return lines


# --------------------------------------------------------------------------- document


def _document(spec: TrainSpec, body: list[str], tendons: list[str], timestep: float, header: list[str],
              sensors: bool = True) -> str:
    lines = ["<!--"] + [f"  {h}" for h in header] + ["-->", f'<mujoco model="{spec.name}">',
             '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
             f'  <option timestep="{num(timestep)}" integrator="RK4" gravity="0 0 0">',
             '    <flag contact="disable"/>', "  </option>",
             '  <visual><map znear="0.001"/></visual>']
    lines += body
    if tendons:
        lines += ["  <tendon>"] + tendons + ["  </tendon>"]
    lines += _actuators(spec) + (_sensors(spec) if sensors else []) + ["</mujoco>"]
    return "\n".join(lines) + "\n"


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


def build_mjcf(spec: TrainSpec, stiffness="mean", timestep: float | None = None) -> str:
    """Deterministic MJCF text of ``spec`` (byte-identical for identical input).

    stiffness: "mean" (default), "max" (cycle maximum) or one value per mesh (N/m),
    written as the tendons' constant stiffness.  timestep: the ``<option timestep>``;
    by default the runner's default step of this model (RK4, 20 points per period of
    the highest natural frequency at maximum mesh stiffness), so the file runs stably
    in MuJoCo's viewer.
    """
    kin = kinematics(spec)
    exc = Excitation(spec, kin)
    k = _stiffness_values(spec, exc, stiffness)
    body = _worldbody(spec)
    couplings = _coupling_tendons(spec)
    skeleton = mujoco.MjModel.from_xml_string(_document(spec, body, couplings, 1e-5, [], sensors=False))
    mesh_lines = []
    for tendon, k_mesh in zip(_mesh_tendons(spec, kin, skeleton, exc.mean_stiffness), k):
        b = tendon.backlash
        mesh_lines += _fixed(tendon.name, tendon.coefs, k_mesh, tendon.damping, (-b, b))
    tendons = mesh_lines + couplings
    if timestep is None:
        from .runner import default_step

        timestep = default_step(compile_train(spec, _xml=_document(spec, body, tendons, 1e-5, [])))
    header = [
        f"gearcheck MuJoCo model of train {spec.name!r} ({spec.path}), generated by mbd_models.mjcf_builder.",
        "Meshes are fixed tendons: length = mesh deflection along the line of action (positive = compressed).",
        "Outside the gearcheck runner (mbd_models.runner) the meshes have their constant "
        + ("mean" if isinstance(stiffness, str) and stiffness == "mean" else "given") + " stiffness,",
        "the input reference and load torque are not driven, and the coefficients of the world-frame slides",
        "in the mesh tendons are those of carrier angle 0 (the runner rotates them with the carrier every step).",
        "Units SI; angles in radian; integrator RK4 at the model's default step.",
    ]
    return _document(spec, body, tendons, timestep, header)


# --------------------------------------------------------------------------- compiled model


def _id(model, kind, name: str) -> int:
    i = mujoco.mj_name2id(model, kind, name)
    if i < 0:
        raise KeyError(f"no {kind} named {name!r} in the MuJoCo model")
    return i


@dataclass
class MbdModel:
    """A compiled MuJoCo model of a train and the named indices the runner needs."""

    spec: TrainSpec
    kin: Kinematics
    excitation: Excitation
    xml: str
    model: mujoco.MjModel
    body: dict[str, int]  # member id -> body id
    qadr: dict[str, tuple[int, int, int]]  # member id -> qpos addresses (x|radial, y|tangential, rz)
    dadr: dict[str, tuple[int, int, int]]  # member id -> dof addresses
    mesh_tendon: np.ndarray  # tendon id per spec.meshes entry
    mesh_damping: np.ndarray
    half_backlash: np.ndarray
    actuator: dict[str, int]
    sensor: dict[str, tuple[int, int]]  # name -> (address, dimension)
    # coefficient refresh of world-frame slides: wrap indices of x and y, angle-0 values,
    # and the qpos address of the carrier angle that turns them
    rot_wrap_x: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    rot_wrap_y: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    rot_c0x: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rot_c0y: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rot_carrier_qadr: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    rot_tendon: np.ndarray = field(default_factory=lambda: np.zeros(0, int))  # per wrap, x wraps then y
    rot_slide_qadr: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    def refresh(self, qpos: np.ndarray) -> None:
        """Rotate the world-frame slide coefficients of every mesh tendon to the carriers' angles in ``qpos``."""
        phi = qpos[self.rot_carrier_qadr]
        c, s = np.cos(phi), np.sin(phi)
        prm = self.model.wrap_prm
        prm[self.rot_wrap_x] = self.rot_c0x * c - self.rot_c0y * s
        prm[self.rot_wrap_y] = self.rot_c0x * s + self.rot_c0y * c

    def coefficient_rate(self, phi, phidot, slide):
        """The part of each mesh's deflection rate that a fixed tendon's J qvel misses: its world-frame
        slide coefficients turn with the carrier, d/dt (c(phi) q) = c q' + (dc/dphi) phi' q.  Arguments
        per rotating wrap (x wraps, then y wraps; time along axis 0 allowed): carrier angle, its rate,
        the slide's position.  Returns one rate per mesh (m/s)."""
        c0x = np.concatenate([self.rot_c0x, self.rot_c0x])
        c0y = np.concatenate([self.rot_c0y, self.rot_c0y])
        nx = len(self.rot_wrap_x)
        sign = np.concatenate([np.zeros(nx), np.ones(nx)])  # x: c0x cos - c0y sin; y: c0x sin + c0y cos
        s, c = np.sin(phi), np.cos(phi)
        dc = np.where(sign == 0, -c0x * s - c0y * c, c0x * c - c0y * s)
        terms = dc * phidot * slide
        n_mesh = len(self.mesh_tendon)
        out = np.zeros(np.shape(terms)[:-1] + (n_mesh,))
        for t in range(n_mesh):
            out[..., t] = terms[..., self.rot_tendon == t].sum(axis=-1)
        return out


def compile_train(spec: TrainSpec, stiffness="mean", _xml: str | None = None) -> MbdModel:
    """Compile :func:`build_mjcf`'s model and collect its named indices."""
    xml = _xml if _xml is not None else build_mjcf(spec, stiffness)
    model = mujoco.MjModel.from_xml_string(xml)
    kin = kinematics(spec)
    exc = Excitation(spec, kin)
    J, B, T, A, S = (mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_TENDON,
                     mujoco.mjtObj.mjOBJ_ACTUATOR, mujoco.mjtObj.mjOBJ_SENSOR)
    body, qadr, dadr = {}, {}, {}
    for mid, member in spec.members.items():
        body[mid] = _id(model, B, member.label)
        axes = PLANET_AXES if member.is_planet else CENTRAL_AXES
        joints = [_id(model, J, f"{member.label}_{a}") for a in axes + ("rz",)]
        qadr[mid] = tuple(int(model.jnt_qposadr[j]) for j in joints)
        dadr[mid] = tuple(int(model.jnt_dofadr[j]) for j in joints)
    mesh_tendon = np.array([_id(model, T, m.label) for m in spec.meshes], dtype=int)
    actuator = {}
    for name in ("input_shaft", "input_shaft_damper", "input_torque", "output_load"):
        i = mujoco.mj_name2id(model, A, name)
        if i >= 0:
            actuator[name] = i
    sensor = {}
    for i in range(model.nsensor):
        sensor[mujoco.mj_id2name(model, S, i)] = (int(model.sensor_adr[i]), int(model.sensor_dim[i]))
    mb = MbdModel(spec, kin, exc, xml, model, body, qadr, dadr, mesh_tendon,
                  model.tendon_damping[mesh_tendon].copy(), model.tendon_lengthspring[mesh_tendon, 1].copy(),
                  actuator, sensor)
    # world-frame slide pairs in every mesh tendon
    wx, wy, cx, cy, ca, tt, qx, qy = [], [], [], [], [], [], [], []
    for mesh, t in zip(spec.meshes, mesh_tendon):
        adr, n = model.tendon_adr[t], model.tendon_num[t]
        joint_at = {int(model.wrap_objid[adr + i]): adr + i for i in range(n)}
        stage = spec.stage_of(mesh.planet)
        for mid in (mesh.central, stage.carrier):
            label = spec.members[mid].label
            ix, iy = joint_at[_id(model, J, label + "_x")], joint_at[_id(model, J, label + "_y")]
            wx.append(ix)
            wy.append(iy)
            cx.append(model.wrap_prm[ix])
            cy.append(model.wrap_prm[iy])
            ca.append(qadr[stage.carrier][2])
            tt.append(int(t))
            qx.append(qadr[mid][0])
            qy.append(qadr[mid][1])
    mb.rot_wrap_x, mb.rot_wrap_y = np.array(wx, int), np.array(wy, int)
    mb.rot_c0x, mb.rot_c0y = np.array(cx, float), np.array(cy, float)
    mb.rot_carrier_qadr = np.array(ca, int)
    mb.rot_tendon = np.array(tt + tt, int)
    mb.rot_slide_qadr = np.array(qx + qy, int)
    return mb
