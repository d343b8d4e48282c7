"""MJCF text of a train: rigid bodies on joints, meshes as fixed tendons.

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
* in a helical stage every member also slides along the stage axis: ``<label>_z`` (central members
  along the world's z, with the support's axial stiffness; planets relative to their carrier, with
  the bearing's axial stiffness);
* interstage couplings are fixed tendons (torsion, and x/y when radial stiffness is given);
* the input shaft is an ``intvelocity`` actuator (kp = shaft stiffness) on the input hinge:
  its activation, the reference angle, integrates the control w_in inside MuJoCo's RK4
  stages (a ``position`` actuator fed w_in t held constant over each step biased the input
  speed by O(kp w_in h^2 / I) per unit time, enough to shift a lightly loaded mesh's mean
  damping force by 5 %); plus a ``velocity`` actuator (kv = shaft damping) whose control is
  w_in, so the shaft damping acts on the twist rate only;
  load and input torques are ``motor`` actuators with gear 1.

Meshes: each mesh is a ``<fixed>`` tendon over the nine joints that move its pitch point (the
central member's and the carrier's slides and hinges, the planet's slides and hinge; twelve with the
axial slides of a helical stage), whose length
is the mesh deflection.  The coefficients are not written from a formula here: they are given,
taken by :func:`gearcheck.mbd_models.twin.compile_train` from MuJoCo's own Jacobians.  A backlash
b = backlash/2 is the two-valued spring length "-b b" (a dead band).

Visuals (:mod:`gearcheck.mbd_models.gear_visuals`): every gear is an involute mesh asset (identical planets
share one), placed at its mesh phase, coloured by member, with a small marker box per body and a ``front``
camera; all visual geoms are contact-free and, with ``inertiafromgeom="false"`` and explicit inertials,
massless.  ``VISUALS = False`` writes the bodies bare (the same dynamics, to the last bit).

Every number is written with full precision (the shortest repr that round-trips), angles in
radian, so the text is deterministic and lossless.
"""

from __future__ import annotations

import math

from gearcheck.lumped.spec import TrainSpec
from gearcheck.mbd_models import gear_visuals

STAGE_SPACING = 0.12  # m along z between stages (visual only: stages do not touch)
RGBA = {
    "sun": "0.95 0.6 0.1 1",
    "ring": "0.62 0.62 0.68 1",
    "carrier": "0.2 0.4 0.85 1",
    "planet": "0.2 0.75 0.3 1",
}
MARKER_RGBA = "0.1 0.1 0.1 1"
VISUALS = True  # gear meshes, markers and camera; off, the bodies carry no geoms (same dynamics)
VISUAL = 'contype="0" conaffinity="0" group="1"'  # visual geoms: no contact (no mass: explicit inertials)
CENTRAL_AXES = ("x", "y")
PLANET_AXES = ("radial", "tangential")
AXIAL = "z"


def axial(spec: TrainSpec, member) -> bool:
    """Whether ``member`` slides along its stage's axis (every member of a helical stage does)."""
    return spec.stage_of(member.id).helical


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


def _gear_z(spec: TrainSpec) -> dict[tuple[str, str], float]:
    """Axial offset (m, in the body) of every gear: a compound planet's gears side by side, each central gear
    at the offset of the planet gear it meshes with."""
    z = {}
    for mid, member in spec.members.items():
        if member.is_planet:
            step = 1.5 * max(g.face_width for g in member.gears.values())
            for i, name in enumerate(member.gears):
                z[mid, name] = (i - 0.5 * (len(member.gears) - 1)) * step
    for mesh in spec.meshes:
        planet = spec.members[mesh.planet]
        name = next(n for n, g in planet.gears.items() if g == mesh.planet_gear)
        central = next(n for n, g in spec.members[mesh.central].gears.items() if g == mesh.central_gear)
        z.setdefault((mesh.central, central), z[mesh.planet, name])
    return z


def _geoms(spec: TrainSpec, member, phase: dict, z: dict, meshes: dict) -> list[str]:
    """The member's visual geoms: its gear meshes (or the carrier's plate) and a marker showing its rotation."""
    rgba = RGBA[member.kind]
    if member.kind == "carrier":
        stage = spec.stage_of(member.id)
        back = min((z[p, n] - 0.5 * g.face_width for p in stage.planets for n, g in spec.members[p].gears.items()),
                   default=0.0)
        tip = max((g.tip_radius for p in stage.planets for g in spec.members[p].gears.values()), default=0.01)
        h = max(0.25 * tip, 0.002)
        zc = back - 2 * h
        module = max((g.module for p in stage.planets for g in spec.members[p].gears.values()), default=0.005)
        size, marker = vec(stage.carrier_radius + tip, h), (0.5 * stage.carrier_radius, zc + h)
        return [f'<geom name="{member.label}_visual" type="cylinder" size="{size}" pos="{vec(0, 0, zc)}" '
                f'rgba="{rgba}" {VISUAL}/>', _marker(member, *marker, 2 * module)]
    lines = []
    for name, gear in member.gears.items():
        key = (member.id, name)
        lines.append(f'<geom name="{member.label}_{name}_visual" type="mesh" mesh="{meshes[gear]}" '
                     f'pos="{vec(0, 0, z[key])}" euler="{vec(0, 0, phase[key])}" rgba="{rgba}" {VISUAL}/>')
    name, gear = next(iter(member.gears.items()))
    r = gear.tip_radius + gear.module if gear.internal else 0.5 * gear.root_radius
    return lines + [_marker(member, r, z[member.id, name] + 0.5 * gear.face_width, 0.8 * gear.module)]


def _marker(member, r: float, z: float, size: float) -> str:
    """A small box on the member's +x axis (body frame): it turns with the body."""
    return (f'<geom name="{member.label}_marker" type="box" size="{vec(size, size, size)}" pos="{vec(r, 0, z)}" '
            f'rgba="{MARKER_RGBA}" {VISUAL}/>')


def mesh_names(spec: TrainSpec) -> dict:
    """The visual mesh asset of every distinct gear (identical planets share one), named after its first member."""
    names = {}
    for member in spec.members.values():
        for name, gear in member.gears.items():
            names.setdefault(gear, f"{member.label}_{name}")
    return names


def _assets(spec: TrainSpec) -> list[str]:
    return ["  <asset>"] + [f"    {gear_visuals.mesh_asset(name, gear)}" for gear, name in mesh_names(spec).items()] + [
        "  </asset>"]


def _joints(spec, member, support, joints, indent: str) -> list[str]:
    """The body's joints, (suffix, type, axis, stiffness, damping) each, and its axial slide in a helical stage."""
    if axial(spec, member):
        joints = joints + [(AXIAL, "slide", (0, 0, 1), support.axial_stiffness, support.axial_damping)]
    return [f"{indent}  {_joint(f'{member.label}_{name}', kind, axis, k, c)}" for name, kind, axis, k, c in joints]


def _central_body(spec, member, z_stage: float, indent: str, visuals: list[str], children: list[str]) -> list[str]:
    s = member.support
    lines = [f'{indent}<body name="{member.label}" pos="{vec(0, 0, z_stage)}">', f"{indent}  {_inertial(member)}"]
    lines += _joints(spec, member, s, [("x", "slide", (1, 0, 0), s.radial_stiffness, s.radial_damping),
                                       ("y", "slide", (0, 1, 0), s.radial_stiffness, s.radial_damping),
                                       ("rz", "hinge", (0, 0, 1), s.torsional_stiffness, s.torsional_damping)], indent)
    lines += [f"{indent}  {g}" for g in visuals]
    lines += children
    lines.append(f"{indent}</body>")
    return lines


def _planet_body(spec, member, indent: str, visuals: list[str]) -> list[str]:
    b = member.bearing
    c, s = math.cos(member.angle), math.sin(member.angle)
    lines = [f'{indent}<body name="{member.label}" pos="{vec(member.radius * c, member.radius * s, 0)}">',
             f"{indent}  {_inertial(member)}"]
    lines += _joints(spec, member, b, [("radial", "slide", (c, s, 0), b.radial_stiffness, b.radial_damping),
                                       ("tangential", "slide", (-s, c, 0), b.radial_stiffness, b.radial_damping),
                                       ("rz", "hinge", (0, 0, 1), 0.0, 0.0)], indent)
    return lines + [f"{indent}  {g}" for g in visuals] + [f"{indent}</body>"]


def _camera(spec: TrainSpec) -> str:
    """A camera on the axis, in front of the first stage, framing the largest gear (narrow: little perspective)."""
    reach = max((g.root_radius + gear_visuals.RIM * g.normal_module if g.internal else g.tip_radius
                 for m in spec.members.values() for g in m.gears.values()), default=0.1)
    return f'<camera name="front" pos="{vec(0, 0, 6.5 * reach)}" fovy="20"/>'


def _worldbody(spec: TrainSpec, visuals: bool) -> list[str]:
    lines = ["  <worldbody>"]
    phase, z, meshes = (gear_visuals.phases(spec), _gear_z(spec), mesh_names(spec)) if visuals else ({}, {}, {})

    def geoms(member) -> list[str]:
        return _geoms(spec, member, phase, z, meshes) if visuals else []

    if visuals:
        lines.append(f"    {_camera(spec)}")
    for i, stage in enumerate(spec.stages):
        zs = -STAGE_SPACING * i
        lines.append(f"    <!-- {stage.name}: carrier radius {num(stage.carrier_radius)} m, "
                     f"{len(stage.planets)} planets -->")
        for mid in stage.centrals:
            lines += _central_body(spec, spec.members[mid], zs, "    ", geoms(spec.members[mid]), [])
        planets = []
        for pid in stage.planets:
            planets += _planet_body(spec, spec.members[pid], "      ", geoms(spec.members[pid]))
        carrier = spec.members[stage.carrier]
        lines += _central_body(spec, carrier, zs, "    ", geoms(carrier), planets)
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


def coupling_tendons(spec: TrainSpec) -> list[str]:
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


def mesh_joints(spec: TrainSpec, mesh) -> list[str]:
    """The joints whose motion moves ``mesh``'s pitch point on either gear: the central member's slides
    and hinge, the carrier's (which carries the planet), the planet's slides and hinge."""
    joints = []
    for mid in (mesh.central, spec.stage_of(mesh.planet).carrier, mesh.planet):
        member = spec.members[mid]
        axes = (PLANET_AXES if member.is_planet else CENTRAL_AXES) + ("rz",) + ((AXIAL,) if axial(spec, member) else ())
        joints += [f"{member.label}_{a}" for a in axes]
    return joints


def mesh_tendons(spec: TrainSpec, coefficients, stiffness, damping) -> list[str]:
    """One fixed tendon per mesh: ``coefficients[j]`` is a list of (joint, coefficient) in dof order."""
    lines = []
    for mesh, coefs, k, c in zip(spec.meshes, coefficients, stiffness, damping):
        b = 0.5 * mesh.backlash
        lines += _fixed(mesh.label, coefs, k, c, (-b, b))
    return lines


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


def document(spec: TrainSpec, tendons: list[str], timestep: float, header: list[str]) -> str:
    """The whole MJCF text: ``header`` comment, compiler, option and headlight, the gears' visual meshes (when ``VISUALS``),
    bodies, ``tendons``, actuators, sensors."""
    lines = ["<!--"] + [f"  {h}" for h in header] + ["-->", f'<mujoco model="{spec.name}">',
             '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
             f'  <option timestep="{num(timestep)}" integrator="RK4" gravity="0 0 0">',
             '    <flag contact="disable"/>', "  </option>",
             '  <visual><map znear="0.001"/><headlight ambient="0.4 0.4 0.4" diffuse="0.6 0.6 0.6"/></visual>']
    lines += (_assets(spec) if VISUALS else []) + _worldbody(spec, VISUALS)
    if tendons:
        lines += ["  <tendon>"] + tendons + ["  </tendon>"]
    lines += _actuators(spec) + _sensors(spec) + ["</mujoco>"]
    return "\n".join(lines) + "\n"


HEADER = [
    "gearcheck MuJoCo model of train {name!r} ({path}), generated by `gearcheck mjcf`.",
    "Meshes are fixed tendons: length = mesh deflection along the line of action (positive = compressed).",
    "Outside the gearcheck runner (gearcheck.mbd_models.runner) the meshes have their constant {stiffness} "
    "stiffness,",
    "the input reference and load torque are not driven, and the coefficients of the world-frame slides",
    "in the mesh tendons are those of carrier angle 0 (the runner rotates them with the carrier every step).",
    "Units SI; angles in radian; integrator RK4 at the model's default step.",
]


def header(spec: TrainSpec, stiffness: str) -> list[str]:
    """The comment lines at the top of a generated file (``stiffness``: "mean" or "given")."""
    return [line.format(name=spec.name, path=spec.path, stiffness=stiffness) for line in HEADER]
