"""MJCF text of a train: rigid bodies on joints, meshes as fixed tendons.

Bodies and joints (gravity off):

* every member on a stage's axis (sun, ring, carrier) is a child of the world at the stage's axis, with
  world-frame slide joints ``<label>_x``, ``<label>_y`` and a hinge ``<label>_rz`` (absolute rotation);
* every member on a pin of its carrier (planet, crankshaft) is a child body of its stage's carrier, placed at
  the carrier radius and angle psi_n, with slide joints ``<label>_radial`` and ``<label>_tangential`` along
  the carrier's radial and tangential axes and a hinge ``<label>_rz`` (rotation relative to the carrier).
  A compound planet is one body;
* a member that slides axially (every member of a helical stage) also has ``<label>_z`` (central members
  along the world's z, members on pins relative to their carrier);
* a member that tilts (every member of a tilting stage) also has two hinges through its centre of mass about its
  slides' axes, ``<label>_rx``, ``<label>_ry`` (central members) or ``<label>_rradial``, ``<label>_rtangential``
  (members on pins, relative to their carrier), after its slides and before its rotation's hinge, so that it spins
  about its own tilted axis and MuJoCo gives it its gyroscopic moments; its inertia about a diameter is its
  tilting inertia;
* every part of the train (:attr:`gearcheck.train.spec.TrainSpec.parts`) adds what its element
  (:mod:`gearcheck.mbd_models.elements`) writes: supports and bearings the stiffness and damping of their
  members' joints (and a tilting member's bearing stations as fixed tendons), meshes (first), couplings and
  splines fixed tendons, the drive its actuators, an RV reducer's
  cycloid-pin stage its discs, pins, sites, needle-bearing actuators and pin tendons.

Visuals (:mod:`gearcheck.mbd_models.gear_visuals`): every gear is an involute mesh asset (identical planets
share one), placed at its mesh phase, coloured by member, with a small marker box per body and a ``front``
camera; all visual geoms are contact-free and, with ``inertiafromgeom="false"`` and explicit inertials,
massless.  ``VISUALS = False`` writes the bodies bare (the same dynamics, to the last bit).

Every number is written with full precision (the shortest repr that round-trips), angles in
radian, so the text is deterministic and lossless (:mod:`gearcheck.mbd_models.mjcf_text`).

The text is written once, by :func:`document`, as a :class:`~gearcheck.mbd_models.mjcf_text.Template`: the numbers
that are not the description's (the step, the meshes' stiffness and damping, the tendons' coefficients from
MuJoCo's Jacobians, the pins' spring lengths) are slots, filled for the compile and again, with the compiled twin's
numbers, for the file.
"""

from __future__ import annotations

from gearcheck.mbd_models import gear_visuals
from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.mjcf_text import (
    RGBA,
    TIMESTEP,
    VISUAL,
    Template,
    central_body,
    gear_z,
    marker,
    member_axes,
    num,
    pin_body,
    plate,
    slot,
    vec,
)
from gearcheck.train.spec import TrainSpec

STAGE_SPACING = 0.12  # m along z between stages (visual only: stages do not touch)
VISUALS = True  # gear meshes, markers and camera; off, the bodies carry no geoms (same dynamics)


def _hook(spec: TrainSpec, name: str, *args) -> list:
    """Every part's answer to one element hook, in the parts' order, joined."""
    return [line for part in spec.parts for line in getattr(ELEMENTS[part.element], name)(part, *args)]


def _springs(spec: TrainSpec) -> dict:
    """{(member id, joint suffix): :class:`~gearcheck.mbd_models.mjcf_text.Spring`}: what every part puts on the
    members' joints, added."""
    springs = {}
    for part in spec.parts:
        for key, spring in ELEMENTS[part.element].joint_springs(part, spec).items():
            springs[key] = springs[key].plus(spring) if key in springs else spring
    return springs


# --------------------------------------------------------------------------- visuals


def _geoms(spec: TrainSpec, member, phase: dict, z: dict, meshes: dict) -> list[str]:
    """The member's visual geoms: its gear meshes (or the carrier's plate, or what a part draws of it) and a
    marker showing its rotation."""
    for part in spec.parts:
        drawn = ELEMENTS[part.element].visuals(part, spec, member)
        if drawn is not None:
            return drawn
    rgba = RGBA[member.kind]
    if member.kind == "carrier":
        stage = spec.stage_of(member.id)
        zc, h, tip = plate(spec, stage, z)
        module = max((gear_visuals.module(g) for p in stage.planets for g in spec.members[p].gears.values()),
                     default=0.005)
        radius = min([stage.carrier_radius + tip] + [ELEMENTS[p.element].bore(p, stage) for p in spec.parts])
        size, at = vec(radius, h), (0.5 * stage.carrier_radius, zc + h)
        return [f'<geom name="{member.label}_visual" type="cylinder" size="{size}" pos="{vec(0, 0, zc)}" '
                f'rgba="{rgba}" {VISUAL}/>', marker(member, *at, 2 * module)]
    lines = []
    for name, gear in member.gears.items():
        key = (member.id, name)
        lines.append(f'<geom name="{member.label}_{name}_visual" type="mesh" mesh="{meshes[gear]}" '
                     f'pos="{vec(0, 0, z[key])}" euler="{vec(0, 0, phase[key])}" rgba="{rgba}" {VISUAL}/>')
    name, gear = next(iter(member.gears.items()))
    size = gear_visuals.module(gear)
    r = gear.tip_radius + size if gear.internal else 0.5 * gear.root_radius
    return lines + [marker(member, r, z[member.id, name] + 0.5 * gear_visuals.face_width(gear), 0.8 * size)]


def mesh_names(spec: TrainSpec) -> dict:
    """The visual mesh asset of every distinct gear (identical planets share one), named after its first member."""
    names = {}
    for member in spec.members.values():
        for name, gear in member.gears.items():
            names.setdefault(gear, f"{member.label}_{name}")
    return names


def _assets(spec: TrainSpec) -> list[str]:
    gears = [f"    {gear_visuals.mesh_asset(name, gear)}" for gear, name in mesh_names(spec).items()]
    return ["  <asset>"] + gears + _hook(spec, "assets", spec) + ["  </asset>"]


def _camera(spec: TrainSpec) -> str:
    """A camera on the axis, in front of the first stage, framing the largest gear (narrow: little perspective)."""
    reach = max([g.root_radius + gear_visuals.RIM * gear_visuals.module(g, normal=True) if g.internal else g.tip_radius
                 for m in spec.members.values() for g in m.gears.values()] + _hook(spec, "reach"), default=0.1)
    return f'<camera name="front" pos="{vec(0, 0, 6.5 * reach)}" fovy="20"/>'


# --------------------------------------------------------------------------- bodies


def _worldbody(spec: TrainSpec, visuals: bool) -> list[str]:
    lines = ["  <worldbody>"]
    phase, z, meshes = (gear_visuals.phases(spec), gear_z(spec), mesh_names(spec)) if visuals else ({}, {}, {})
    springs = _springs(spec)

    def inner(member) -> list[str]:
        """The member's sites and visual geoms."""
        return _hook(spec, "sites", spec, member) + (_geoms(spec, member, phase, z, meshes) if visuals else [])

    if visuals:
        lines.append(f"    {_camera(spec)}")
    for i, stage in enumerate(spec.stages):
        zs = -STAGE_SPACING * i
        lines.append(f"    <!-- {stage.name}: carrier radius {num(stage.carrier_radius)} m, "
                     f"{len(stage.planets)} planets -->")
        for mid in stage.centrals:
            lines += central_body(spec.members[mid], springs, zs, "    ", inner(spec.members[mid]), [])
        on_pins = [m for m in spec.members.values() if m.stage == stage.name and m.frame == "pin"]
        children = [line for m in on_pins for line in pin_body(m, springs, "      ", inner(m))]
        carrier = spec.members[stage.carrier]
        lines += central_body(carrier, springs, zs, "    ", inner(carrier), children)
        lines += [line for part in spec.parts if getattr(part, "stage", None) == stage.name
                  for line in ELEMENTS[part.element].bodies(part, spec, zs, visuals, inner, springs)]
    lines.append("  </worldbody>")
    return lines


# --------------------------------------------------------------------------- sensors


def _sensors(spec: TrainSpec) -> list[str]:
    """Every body's linear and angular acceleration, position, x axis (its angle), linear and angular velocity (all
    in the world's frame) and a tilting body's z axis (its tilt), each carrier's angle and rate, the slides of the
    members on the stage axes and of those on pins; then what each part reads of itself."""
    lines = ["  <sensor>"]
    for member in spec.members.values():
        for kind, suffix in (("framelinacc", "linacc"), ("frameangacc", "angacc"), ("framepos", "pos"),
                             ("framexaxis", "xaxis"), ("framelinvel", "linvel"), ("frameangvel", "angvel")):
            lines.append(f'    <{kind} name="{member.label}_{suffix}" objtype="body" objname="{member.label}"/>')
        if member.tilting:
            lines.append(f'    <framezaxis name="{member.label}_zaxis" objtype="body" objname="{member.label}"/>')
    for stage in spec.stages:
        label = spec.members[stage.carrier].label
        lines.append(f'    <jointpos name="{label}_angle" joint="{label}_rz"/>')
        lines.append(f'    <jointvel name="{label}_angle_rate" joint="{label}_rz"/>')
    for member in spec.members.values():
        if not member.orbits:
            for axis in member_axes(member):
                lines.append(f'    <jointpos name="{member.label}_{axis}_pos" joint="{member.label}_{axis}"/>')
    for member in spec.members.values():
        if member.orbits:
            for axis in member_axes(member):
                lines.append(f'    <jointpos name="{member.label}_{axis}_pos" joint="{member.label}_{axis}"/>')
                lines.append(f'    <jointvel name="{member.label}_{axis}_vel" joint="{member.label}_{axis}"/>')
    return lines + _hook(spec, "sensors", spec) + ["  </sensor>"]


# --------------------------------------------------------------------------- document


def document(spec: TrainSpec, header: list[str]) -> Template:
    """The whole MJCF text, once: ``header`` comment, compiler, option (the step a slot) and headlight, the gears'
    visual meshes (when ``VISUALS``), bodies, the parts' tendons (their late numbers slots), actuators and
    sensors."""
    lines = ["<!--"] + [f"  {h}" for h in header] + ["-->", f'<mujoco model="{spec.name}">',
             '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
             f'  <option timestep="{slot(TIMESTEP)}" integrator="RK4" gravity="0 0 0">',
             '    <flag contact="disable" constraint="disable"/>', "  </option>",
             '  <visual><map znear="0.001"/><headlight ambient="0.4 0.4 0.4" diffuse="0.6 0.6 0.6"/></visual>']
    lines += (_assets(spec) if VISUALS else []) + _worldbody(spec, VISUALS)
    tendons = _hook(spec, "driven_tendons", spec) + _hook(spec, "tendons", spec)  # the driven ones first
    if tendons:
        lines += ["  <tendon>"] + tendons + ["  </tendon>"]
    lines += ["  <actuator>"] + _hook(spec, "actuators", spec) + ["  </actuator>"]
    lines += _sensors(spec) + ["</mujoco>"]
    return Template("\n".join(lines) + "\n")


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
    """The comment lines at the top of a generated file (``stiffness``: "mean" or "given"); the parts' own lines
    (each once) before the last."""
    lines = HEADER[:-1] + list(dict.fromkeys(_hook(spec, "header"))) + HEADER[-1:]
    return [line.format(name=spec.name, path=spec.path, stiffness=stiffness) for line in lines]
