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
* an RV reducer's cycloid-pin stage (Yang, Chen & Wang 2018): each crankshaft is a child of the carrier at its
  planet's place, like a planet (its support bearing the slides' stiffness), carrying one eccentric-centre site
  per disc; its planet, with no bearing, is tied to it by spline tendons (radial, tangential, torsion); each
  disc is a child of the world in polar joints about the stage axis (``_orbit`` hinge, ``_radial`` slide,
  ``_rz`` hinge about its centre) with one bore-centre site per crank; the pins are sites of the world (or of
  the pin wheel, a central member on its support); each needle bearing is a pair of site actuators between an
  eccentric's and a bore's centre, each pin contact a compression-only fixed tendon over the disc's (and the
  pin wheel's) joints, whose coefficients the runner sets every step
  (:mod:`gearcheck.mbd_models.cycloid_twin`);
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

from gearcheck.train.spec import TrainSpec
from gearcheck.mbd_models import gear_visuals

STAGE_SPACING = 0.12  # m along z between stages (visual only: stages do not touch)
RGBA = {
    "sun": "0.95 0.6 0.1 1",
    "ring": "0.62 0.62 0.68 1",
    "carrier": "0.2 0.4 0.85 1",
    "planet": "0.2 0.75 0.3 1",
    "crank": "0.75 0.25 0.25 1",
    "disc": "0.55 0.35 0.75 0.9",
    "pin_wheel": "0.62 0.62 0.68 1",
}
MARKER_RGBA = "0.1 0.1 0.1 1"
VISUALS = True  # gear meshes, markers and camera; off, the bodies carry no geoms (same dynamics)
VISUAL = 'contype="0" conaffinity="0" group="1"'  # visual geoms: no contact (no mass: explicit inertials)
# The joints that realise a member's two translations (:attr:`gearcheck.train.spec.Member.dofs`), by the frame that
# carries it: world-frame slides on the stage axis, slides along the carrier's radial and tangential axes on a pin,
# and on an eccentric polar joints about the stage axis (a hinge, and a slide along the eccentric)
AXES = {"axis": ("x", "y"), "pin": ("radial", "tangential"), "eccentric": ("orbit", "radial")}
ROTATION = "rz"  # the hinge of the member's rotation theta
AXIAL = "z"  # the slide along the stage axis
PIN_BAND = 1.0  # m: a pin tendon's dead band reaches this far below contact (compression only)


def member_axes(member) -> tuple[str, str]:
    """The names of a member's first two joints (:data:`AXES`; its rotation is ``rz``)."""
    return AXES[member.frame]


def member_joints(member) -> tuple[str, ...]:
    """The suffixes of all of a member's joints, one per degree of freedom in the order of its ``dofs``."""
    return member_axes(member) + (ROTATION,) + ((AXIAL,) if member.axial else ())


def num(x) -> str:
    """A float written with full precision (shortest repr that round-trips)."""
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


def vec(*xs) -> str:
    return " ".join(num(x) for x in xs)


# --------------------------------------------------------------------------- bodies


def _joint(name: str, kind: str, axis, stiffness: float = 0.0, damping: float = 0.0, pos=(0.0, 0.0, 0.0)) -> str:
    attrs = [f'name="{name}"', f'type="{kind}"', f'axis="{vec(*axis)}"', f'pos="{vec(*pos)}"']
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
    """The member's visual geoms: its gear meshes (or the carrier's plate, or a cycloid stage's shapes) and a
    marker showing its rotation."""
    rgba = RGBA[member.kind]
    if member.kind in CYCLOID_VISUALS:
        return CYCLOID_VISUALS[member.kind](spec, member)
    if member.kind == "carrier":
        stage = spec.stage_of(member.id)
        zc, h, tip = _plate(spec, stage, z)
        module = max((g.module for p in stage.planets for g in spec.members[p].gears.values()), default=0.005)
        radius = stage.carrier_radius + tip
        if stage.cycloid:  # inside the pins, which show round it
            radius = min(radius, stage.cycloid.geometry.pin_circle_radius - stage.cycloid.geometry.pin_radius)
        size, marker = vec(radius, h), (0.5 * stage.carrier_radius, zc + h)
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


def _plate(spec: TrainSpec, stage, z: dict) -> tuple[float, float, float]:
    """(axial offset of its centre, half thickness, the planets' tip radius) of a carrier's plate behind the
    planets (``z``: :func:`_gear_z`)."""
    back = min((z[p, n] - 0.5 * g.face_width for p in stage.planets for n, g in spec.members[p].gears.items()),
               default=0.0)
    tip = max((g.tip_radius for p in stage.planets for g in spec.members[p].gears.values()), default=0.01)
    h = max(0.25 * tip, 0.002)
    return back - 2 * h, h, tip


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
    discs = [f"    {gear_visuals.disc_asset(_profile_mesh(stage), stage.cycloid.geometry)}" for stage in spec.stages
             if stage.cycloid]
    return ["  <asset>"] + [f"    {gear_visuals.mesh_asset(name, gear)}" for gear, name in mesh_names(spec).items()] + (
        discs + ["  </asset>"])


def _joints(spec, member, support, joints, indent: str) -> list[str]:
    """The body's joints, (suffix, type, axis, stiffness, damping) each, and its axial slide in a helical stage."""
    if member.axial:
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
    """A planet or an RV reducer's crankshaft on its carrier; its bearing (none for an RV reducer's planet, which
    sits on its crankshaft) is the slides' stiffness and damping."""
    b = member.bearing
    k, damping = (b.radial_stiffness, b.radial_damping) if b else (0.0, 0.0)
    c, s = math.cos(member.angle), math.sin(member.angle)
    lines = [f'{indent}<body name="{member.label}" pos="{vec(member.radius * c, member.radius * s, 0)}">',
             f"{indent}  {_inertial(member)}"]
    lines += _joints(spec, member, b, [("radial", "slide", (c, s, 0), k, damping),
                                       ("tangential", "slide", (-s, c, 0), k, damping),
                                       ("rz", "hinge", (0, 0, 1), 0.0, 0.0)], indent)
    return lines + [f"{indent}  {g}" for g in visuals] + [f"{indent}</body>"]


# --------------------------------------------------------------------------- cycloid stage


def disc_z(spec: TrainSpec, stage) -> list[float]:
    """Axial offset (m, from the stage) of each cycloid disc's mid-plane: side by side behind the carrier's plate
    (visual only: the model is planar, and every point of a needle bearing or pin contact lies in its disc's
    plane)."""
    zc, h, _ = _plate(spec, stage, _gear_z(spec))
    t = stage.cycloid.geometry.contact_length
    return [zc - h - t * (1.0 + 1.5 * j) for j in range(len(stage.cycloid.discs))]


def eccentric_site(crank, j: int) -> str:
    return f"{crank.label}_eccentric{j + 1}"


def bore_site(disc, k: int) -> str:
    return f"{disc.label}_bore{k + 1}"


def pin_site(stage, i: int) -> str:
    return f"{stage.name}_pin{i + 1}"


def pin_tendon(disc, i: int) -> str:
    return f"{disc.label}_pin{i + 1}"


def needle_actuator(crank, disc, axis: str) -> str:
    """Named as the reference model names the needle bearing's rows (``stage.crankK.discJ.needle_x``)."""
    return f"{crank.label}_{disc.label.rsplit('_', 1)[1]}_needle_{axis}"


def _site(name: str, pos) -> str:
    return f'<site name="{name}" pos="{vec(*pos)}" size="0.001" group="4"/>'


def _profile_mesh(stage) -> str:
    return f"{stage.name}_disc_profile"


def _cylinder(name: str, kind: str, radius: float, a, b) -> str:
    return (f'<geom name="{name}" type="cylinder" size="{num(radius)}" fromto="{vec(*a, *b)}" '
            f'rgba="{RGBA[kind]}" {VISUAL}/>')


def _sites(spec: TrainSpec, member) -> list[str]:
    """The points of a cycloid stage's bearings on a member: a crankshaft's eccentric centres (each in its disc's
    plane, at e along the disc's phase), a disc's bore centres (at the cranks' places)."""
    stage = spec.stage_of(member.id)
    cyc = stage.cycloid
    if member.kind == "crank":
        e = cyc.geometry.eccentricity
        return [_site(eccentric_site(member, j), (e * math.cos(phase), e * math.sin(phase), z))
                for j, (phase, z) in enumerate(zip(cyc.phases, disc_z(spec, stage)))]
    if member.kind == "disc":
        places = [spec.members[c].angle for c in cyc.cranks]
        return [_site(bore_site(member, k), (stage.carrier_radius * math.cos(psi), stage.carrier_radius * math.sin(psi),
                                             0.0)) for k, psi in enumerate(places)]
    return []


def _crank_geoms(spec: TrainSpec, crank) -> list[str]:
    """A crankshaft's shaft and eccentrics, and a marker."""
    stage = spec.stage_of(crank.id)
    cyc, zs = stage.cycloid, disc_z(spec, stage)
    e, t, shaft = cyc.geometry.eccentricity, cyc.geometry.contact_length, 0.2 * stage.carrier_radius
    lines = [_cylinder(f"{crank.label}_shaft", "crank", shaft, (0, 0, 0), (0, 0, zs[-1] - 0.5 * t))]
    for j, (phase, z) in enumerate(zip(cyc.phases, zs)):
        centre = (e * math.cos(phase), e * math.sin(phase))
        lines.append(_cylinder(f"{crank.label}_eccentric{j + 1}_visual", "crank", shaft + e, (*centre, z - 0.45 * t),
                               (*centre, z + 0.45 * t)))
    return lines + [_marker(crank, shaft, zs[-1] - 0.5 * t, 0.25 * shaft)]


def _disc_geoms(spec: TrainSpec, disc) -> list[str]:
    """A cycloid disc's profile at the conjugate pose of its eccentric's phase (the profile's frame turned by
    -phase/Z_c), and a marker."""
    cyc = spec.stage_of(disc.id).cycloid
    phase = cyc.phases[cyc.discs.index(disc.id)]
    r = cyc.geometry.pin_circle_radius - cyc.geometry.pin_radius - 2 * cyc.geometry.eccentricity
    return [f'<geom name="{disc.label}_visual" type="mesh" mesh="{_profile_mesh(spec.stage_of(disc.id))}" '
            f'euler="{vec(0, 0, -phase / cyc.geometry.lobes)}" rgba="{RGBA["disc"]}" {VISUAL}/>',
            _marker(disc, 0.9 * r, 0.5 * cyc.geometry.contact_length, 0.01 * r)]


def _pin_wheel_geoms(spec: TrainSpec, wheel) -> list[str]:
    g = spec.stage_of(wheel.id).cycloid.geometry
    return [_marker(wheel, g.pin_circle_radius + 2 * g.pin_radius, 0.0, g.pin_radius)]


CYCLOID_VISUALS = {"crank": _crank_geoms, "disc": _disc_geoms, "pin_wheel": _pin_wheel_geoms}


def _pins(spec: TrainSpec, stage, z: float, visuals: bool) -> list[str]:
    """The pins' centre sites (and cylinders), at the offset ``z`` of their body (the pin wheel or the world)."""
    g, zs = stage.cycloid.geometry, disc_z(spec, stage)
    half = 0.5 * abs(zs[-1] - zs[0]) + 0.5 * g.contact_length
    mid = z + 0.5 * (zs[0] + zs[-1])
    kind = "pin_wheel" if stage.cycloid.pin_wheel else "ring"
    lines = []
    for i in range(g.pins):
        angle = 2 * math.pi * i / g.pins
        x, y = g.pin_circle_radius * math.cos(angle), g.pin_circle_radius * math.sin(angle)
        lines.append(_site(pin_site(stage, i), (x, y, mid)))
        if visuals:
            lines.append(_cylinder(f"{pin_site(stage, i)}_visual", kind, g.pin_radius, (x, y, mid - half),
                                   (x, y, mid + half)))
    return lines


def _disc_body(spec: TrainSpec, disc, z: float, indent: str, inner: list[str]) -> list[str]:
    """A cycloid disc, a free planar body in polar joints about the stage axis: ``_orbit`` (a hinge on the axis),
    ``_radial`` (a slide along its eccentric), ``_rz`` (a hinge about its centre; its rotation is the sum of the
    two hinges').  Its nominal motion, the orbit at the cranks' speed while it turns with the carrier, is linear
    in time in these joints; its centre starts on its eccentric, at e along the eccentric's phase."""
    cyc = spec.stage_of(disc.id).cycloid
    e, phase = cyc.geometry.eccentricity, cyc.phases[cyc.discs.index(disc.id)]
    c, s = math.cos(phase), math.sin(phase)
    lines = [f'{indent}<body name="{disc.label}" pos="{vec(e * c, e * s, z)}">', f"{indent}  {_inertial(disc)}"]
    lines += [f"{indent}  {_joint(f'{disc.label}_orbit', 'hinge', (0, 0, 1), pos=(-e * c, -e * s, 0))}",
              f"{indent}  {_joint(f'{disc.label}_radial', 'slide', (c, s, 0))}",
              f"{indent}  {_joint(f'{disc.label}_rz', 'hinge', (0, 0, 1))}"]
    return lines + [f"{indent}  {g}" for g in inner] + [f"{indent}</body>"]


def _cycloid_bodies(spec: TrainSpec, stage, zs: float, visuals: bool, geoms) -> list[str]:
    """The discs and the pin wheel (a central member on its support, or its pins on the world)."""
    lines = []
    for disc, z in zip(stage.cycloid.discs, disc_z(spec, stage)):
        member = spec.members[disc]
        lines += _disc_body(spec, member, zs + z, "    ", _sites(spec, member) + geoms(member))
    if stage.cycloid.pin_wheel:
        wheel = spec.members[stage.cycloid.pin_wheel]
        return lines + _central_body(spec, wheel, zs, "    ", _pins(spec, stage, 0.0, visuals) + geoms(wheel), [])
    return lines + [f"    {line}" for line in _pins(spec, stage, zs, visuals)]


def _camera(spec: TrainSpec) -> str:
    """A camera on the axis, in front of the first stage, framing the largest gear (narrow: little perspective)."""
    reach = max([g.root_radius + gear_visuals.RIM * g.normal_module if g.internal else g.tip_radius
                 for m in spec.members.values() for g in m.gears.values()]
                + [s.cycloid.geometry.pin_circle_radius + s.cycloid.geometry.pin_radius for s in spec.stages
                   if s.cycloid], default=0.1)
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
        for pid in stage.planets + (stage.cycloid.cranks if stage.cycloid else ()):
            member = spec.members[pid]
            planets += _planet_body(spec, member, "      ", _sites(spec, member) + geoms(member))
        carrier = spec.members[stage.carrier]
        lines += _central_body(spec, carrier, zs, "    ", geoms(carrier), planets)
        if stage.cycloid:
            lines += _cycloid_bodies(spec, stage, zs, visuals, geoms)
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
            for axis in member_axes(spec.members[c.a]):
                lines += _fixed(f"coupling_{c.name}_{axis}", [(f"{a}_{axis}", 1.0), (f"{b}_{axis}", -1.0)],
                                c.radial_stiffness, c.radial_damping)
    return lines


def mesh_joints(spec: TrainSpec, mesh) -> list[str]:
    """The joints whose motion moves ``mesh``'s pitch point on either gear: the central member's slides
    and hinge, the carrier's (which carries the planet), the planet's slides and hinge."""
    joints = []
    for mid in (mesh.central, spec.stage_of(mesh.planet).carrier, mesh.planet):
        member = spec.members[mid]
        joints += [f"{member.label}_{a}" for a in member_joints(member)]
    return joints


def mesh_tendons(spec: TrainSpec, coefficients, stiffness, damping) -> list[str]:
    """One fixed tendon per mesh: ``coefficients[j]`` is a list of (joint, coefficient) in dof order."""
    lines = []
    for mesh, coefs, k, c in zip(spec.meshes, coefficients, stiffness, damping):
        b = 0.5 * mesh.backlash
        lines += _fixed(mesh.label, coefs, k, c, (-b, b))
    return lines


def spline_tendons(spec: TrainSpec) -> list[str]:
    """An RV reducer's planet on its crankshaft: radial, tangential (both on the same pin of the carrier) and
    torsional springs between their joints."""
    lines = []
    for stage in spec.stages:
        if stage.cycloid:
            s = stage.cycloid.spline
            for planet, crank in zip(stage.planets, stage.cycloid.cranks):
                p, c = spec.members[planet].label, spec.members[crank].label
                for axis, k, damping in (("radial", s.radial_stiffness, s.radial_damping),
                                         ("tangential", s.radial_stiffness, s.radial_damping),
                                         ("rz", s.torsional_stiffness, s.torsional_damping)):
                    lines += _fixed(f"{c}_spline_{axis}", [(f"{p}_{axis}", 1.0), (f"{c}_{axis}", -1.0)], k, damping)
    return lines


def pin_list(spec: TrainSpec) -> list[tuple]:
    """(stage, disc member, pin index) of every pin contact, in the order of their tendons."""
    return [(stage, spec.members[disc], i) for stage in spec.stages if stage.cycloid
            for disc in stage.cycloid.discs for i in range(stage.cycloid.geometry.pins)]


def pin_joints(spec: TrainSpec, disc) -> list[str]:
    """The joints that move a pin contact: the disc's and the pin wheel's (when it is a body)."""
    wheel = spec.stage_of(disc.id).cycloid.pin_wheel
    joints = [f"{disc.label}_{a}" for a in member_joints(disc)]
    return joints + ([f"{spec.members[wheel].label}_{a}" for a in member_joints(spec.members[wheel])] if wheel else [])


def pin_tendons(spec: TrainSpec, coefficients, springlengths) -> list[str]:
    """One fixed tendon per pin and disc (:func:`pin_list` order): its length is the pin's compression plus
    ``springlengths[j][1]``; the dead band from there down by ``PIN_BAND`` makes it compression only.  No damping
    here: the runner turns the contact damping on while the pin touches."""
    lines = []
    for (stage, disc, i), coefs, band in zip(pin_list(spec), coefficients, springlengths):
        k = stage.cycloid.pin_stiffness(spec.operating.output_torque)
        lines += _fixed(pin_tendon(disc, i), coefs, k, 0.0, band)
    return lines


def needle_list(spec: TrainSpec) -> list[tuple]:
    """(stage, crank member, disc member, eccentric j, crank k) of every needle bearing."""
    return [(stage, spec.members[crank], spec.members[disc], j, k) for stage in spec.stages if stage.cycloid
            for j, disc in enumerate(stage.cycloid.discs) for k, crank in enumerate(stage.cycloid.cranks)]


def _needles(spec: TrainSpec) -> list[str]:
    """Every needle bearing as two ``general`` actuators with a site transmission from the eccentric's centre
    relative to the bore's (its x, y components in the bore's frame) and an affine bias -k L - c L': MuJoCo's
    isotropic spring-damper between the two points, exact at every evaluation."""
    lines = []
    for stage, crank, disc, j, k in needle_list(spec):
        n = stage.cycloid.needle
        for axis, gear in (("x", "1 0 0 0 0 0"), ("y", "0 1 0 0 0 0")):
            lines.append(f'    <general name="{needle_actuator(crank, disc, axis)}" site="{eccentric_site(crank, j)}" '
                         f'refsite="{bore_site(disc, k)}" gear="{gear}" gainprm="0" biastype="affine" '
                         f'biasprm="{vec(0, -n.radial_stiffness, -n.radial_damping)}" ctrllimited="false" '
                         'forcelimited="false"/>')
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
    lines += _needles(spec)
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
        if not member.orbits:
            for axis in member_axes(member):
                lines.append(f'    <jointpos name="{member.label}_{axis}_pos" joint="{member.label}_{axis}"/>')
    for mesh in spec.meshes:
        lines.append(f'    <tendonpos name="{mesh.label}_deflection" tendon="{mesh.label}"/>')
        lines.append(f'    <tendonvel name="{mesh.label}_rate" tendon="{mesh.label}"/>')
    for mid, member in spec.members.items():
        if member.orbits:
            for axis in member_axes(member):
                lines.append(f'    <jointpos name="{member.label}_{axis}_pos" joint="{member.label}_{axis}"/>')
                lines.append(f'    <jointvel name="{member.label}_{axis}_vel" joint="{member.label}_{axis}"/>')
    for _, crank, disc, _, _ in needle_list(spec):
        for axis in "xy":
            name = needle_actuator(crank, disc, axis)
            lines.append(f'    <actuatorfrc name="{name}_force" actuator="{name}"/>')
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


CYCLOID_HEADER = [
    "Cycloid pin contacts are compression-only fixed tendons (length = compression) with the coefficients of",
    "t = 0 and no damping here (the runner follows the discs every step and damps a pin while it touches);",
    "needle bearings are site actuators with an affine spring-damper bias.",
]


def header(spec: TrainSpec, stiffness: str) -> list[str]:
    """The comment lines at the top of a generated file (``stiffness``: "mean" or "given")."""
    lines = HEADER[:-1] + (CYCLOID_HEADER if any(stage.cycloid for stage in spec.stages) else []) + HEADER[-1:]
    return [line.format(name=spec.name, path=spec.path, stiffness=stiffness) for line in lines]
