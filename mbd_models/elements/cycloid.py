"""An RV reducer's cycloid-pin stage in the twin's MJCF (Yang, Chen & Wang 2018).

Each crankshaft rides on the carrier at its planet's place like a planet (its bearing on the carrier pin; the
builder writes it with the stage's pin members) and carries one eccentric-centre site per disc; each disc is a
child of the world in polar joints about the stage axis (``_orbit`` hinge, ``_radial`` slide, ``_rz`` hinge about
its centre) with one bore-centre site per crank; the pins are sites of the world (or of the pin wheel, a central
member on its support); each needle bearing is a pair of site actuators between an eccentric's and a bore's centre,
each pin contact a compression-only fixed tendon over the disc's (and the pin wheel's) joints, whose coefficients
the runner sets every step (:mod:`gearcheck.mbd_models.cycloid_twin`).
"""

from __future__ import annotations

import math

from gearcheck.mbd_models import gear_visuals
from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element, TendonValues
from gearcheck.mbd_models.mjcf_text import (
    RGBA,
    VISUAL,
    central_body,
    cylinder,
    fixed,
    gear_z,
    inertial,
    joint,
    marker,
    member_joints,
    plate,
    site,
    vec,
)

PIN_BAND = 1.0  # m: a pin tendon's dead band reaches this far below contact (compression only)
HEADER = [
    "Cycloid pin contacts are compression-only fixed tendons (length = compression) with the coefficients of",
    "t = 0 and no damping here (the runner follows the discs every step and damps a pin while it touches);",
    "needle bearings are site actuators with an affine spring-damper bias.",
]


def disc_z(spec, cyc) -> list[float]:
    """Axial offset (m, from the stage) of each cycloid disc's mid-plane: side by side behind the carrier's plate
    (visual only: the model is planar, and every point of a needle bearing or pin contact lies in its disc's
    plane)."""
    zc, h, _ = plate(spec, spec.stage_of(cyc.cranks[0]), gear_z(spec))
    t = cyc.geometry.contact_length
    return [zc - h - t * (1.0 + 1.5 * j) for j in range(len(cyc.discs))]


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


def profile_mesh(stage) -> str:
    return f"{stage.name}_disc_profile"


def pin_list(spec) -> list[tuple]:
    """(stage, disc member, pin index) of every pin contact, in the order of their tendons."""
    return [(stage, spec.members[disc], i) for stage in spec.stages if stage.cycloid
            for disc in stage.cycloid.discs for i in range(stage.cycloid.geometry.pins)]


def pin_joints(spec, disc) -> list[str]:
    """The joints that move a pin contact: the disc's and the pin wheel's (when it is a body)."""
    wheel = spec.stage_of(disc.id).cycloid.pin_wheel
    joints = [f"{disc.label}_{a}" for a in member_joints(disc)]
    return joints + ([f"{spec.members[wheel].label}_{a}" for a in member_joints(spec.members[wheel])] if wheel else [])


def needle_list(spec) -> list[tuple]:
    """(stage, crank member, disc member, eccentric j, crank k) of every needle bearing."""
    return [(stage, spec.members[crank], spec.members[disc], j, k) for stage in spec.stages if stage.cycloid
            for j, disc in enumerate(stage.cycloid.discs) for k, crank in enumerate(stage.cycloid.cranks)]


@ELEMENTS.register("cycloid")
class Cycloid(Element):
    def header(self, cyc) -> list[str]:
        return HEADER

    def assets(self, cyc, spec) -> list[str]:
        return [f"    {gear_visuals.disc_asset(profile_mesh(spec.stage_of(cyc.cranks[0])), cyc.geometry)}"]

    def bore(self, cyc, stage) -> float:
        """Inside the pins, which show round the carrier."""
        return cyc.geometry.pin_circle_radius - cyc.geometry.pin_radius if stage.name == cyc.stage else math.inf

    def reach(self, cyc) -> list[float]:
        return [cyc.geometry.pin_circle_radius + cyc.geometry.pin_radius]

    def sites(self, cyc, spec, member) -> list[str]:
        """The points of the stage's bearings on a member: a crankshaft's eccentric centres (each in its disc's
        plane, at e along the disc's phase), a disc's bore centres (at the cranks' places)."""
        if member.id in cyc.cranks:
            e = cyc.geometry.eccentricity
            return [site(eccentric_site(member, j), (e * math.cos(phase), e * math.sin(phase), z))
                    for j, (phase, z) in enumerate(zip(cyc.phases, disc_z(spec, cyc)))]
        if member.id in cyc.discs:
            radius = spec.stage_of(member.id).carrier_radius
            places = [spec.members[c].angle for c in cyc.cranks]
            return [site(bore_site(member, k), (radius * math.cos(psi), radius * math.sin(psi), 0.0))
                    for k, psi in enumerate(places)]
        return []

    def visuals(self, cyc, spec, member) -> list[str] | None:
        if member.id in cyc.cranks:
            return _crank_geoms(spec, cyc, member)
        if member.id in cyc.discs:
            return _disc_geoms(spec, cyc, member)
        if member.id == cyc.pin_wheel:
            g = cyc.geometry
            return [marker(member, g.pin_circle_radius + 2 * g.pin_radius, 0.0, g.pin_radius)]
        return None

    def bodies(self, cyc, spec, z_stage: float, visuals: bool, inner, springs: dict) -> list[str]:
        """The discs and the pin wheel (a central member on its support, or its pins on the world)."""
        lines = []
        for disc, z in zip(cyc.discs, disc_z(spec, cyc)):
            lines += _disc_body(cyc, spec.members[disc], z_stage + z, "    ", inner(spec.members[disc]))
        if cyc.pin_wheel:
            wheel = spec.members[cyc.pin_wheel]
            return lines + central_body(wheel, springs, z_stage, "    ", _pins(spec, cyc, 0.0, visuals) + inner(wheel),
                                        [])
        return lines + [f"    {line}" for line in _pins(spec, cyc, z_stage, visuals)]

    def tendons(self, cyc, spec, values: TendonValues) -> list[str]:
        """One fixed tendon per pin and disc (:func:`pin_list` order): its length is the pin's compression plus
        its spring length's upper edge; the dead band from there down by ``PIN_BAND`` makes it compression only.
        No damping here: the runner turns the contact damping on while the pin touches."""
        lines = []
        k = cyc.pin_stiffness(spec.operating.output_torque)
        for disc in cyc.discs:
            disc = spec.members[disc]
            for i in range(cyc.geometry.pins):
                name = pin_tendon(disc, i)
                coefs = values.coefficients.get(name) or [(j, 0.0) for j in pin_joints(spec, disc)]
                lines += fixed(name, coefs, k, 0.0, values.band.get(name, (0.0, 0.0)))
        return lines

    def actuators(self, cyc, spec) -> list[str]:
        """Every needle bearing as two ``general`` actuators with a site transmission from the eccentric's centre
        relative to the bore's (its x, y components in the bore's frame) and an affine bias -k L - c L': MuJoCo's
        isotropic spring-damper between the two points, exact at every evaluation."""
        lines = []
        n = cyc.needle
        for crank, disc, j, k in _needles(spec, cyc):
            for axis, gear in (("x", "1 0 0 0 0 0"), ("y", "0 1 0 0 0 0")):
                lines.append(f'    <general name="{needle_actuator(crank, disc, axis)}" '
                             f'site="{eccentric_site(crank, j)}" refsite="{bore_site(disc, k)}" gear="{gear}" '
                             f'gainprm="0" biastype="affine" biasprm="{vec(0, -n.radial_stiffness, -n.radial_damping)}" '
                             'ctrllimited="false" forcelimited="false"/>')
        return lines

    def sensors(self, cyc, spec) -> list[str]:
        lines = []
        for crank, disc, _, _ in _needles(spec, cyc):
            for axis in "xy":
                name = needle_actuator(crank, disc, axis)
                lines.append(f'    <actuatorfrc name="{name}_force" actuator="{name}"/>')
        return lines


def _needles(spec, cyc) -> list[tuple]:
    return [(spec.members[crank], spec.members[disc], j, k) for j, disc in enumerate(cyc.discs)
            for k, crank in enumerate(cyc.cranks)]


def _crank_geoms(spec, cyc, crank) -> list[str]:
    """A crankshaft's shaft and eccentrics, and a marker."""
    zs, stage = disc_z(spec, cyc), spec.stage_of(crank.id)
    e, t, shaft = cyc.geometry.eccentricity, cyc.geometry.contact_length, 0.2 * stage.carrier_radius
    lines = [cylinder(f"{crank.label}_shaft", "crank", shaft, (0, 0, 0), (0, 0, zs[-1] - 0.5 * t))]
    for j, (phase, z) in enumerate(zip(cyc.phases, zs)):
        centre = (e * math.cos(phase), e * math.sin(phase))
        lines.append(cylinder(f"{crank.label}_eccentric{j + 1}_visual", "crank", shaft + e, (*centre, z - 0.45 * t),
                              (*centre, z + 0.45 * t)))
    return lines + [marker(crank, shaft, zs[-1] - 0.5 * t, 0.25 * shaft)]


def _disc_geoms(spec, cyc, disc) -> list[str]:
    """A cycloid disc's profile at the conjugate pose of its eccentric's phase (the profile's frame turned by
    -phase/Z_c), and a marker."""
    phase = cyc.phases[cyc.discs.index(disc.id)]
    r = cyc.geometry.pin_circle_radius - cyc.geometry.pin_radius - 2 * cyc.geometry.eccentricity
    return [f'<geom name="{disc.label}_visual" type="mesh" mesh="{profile_mesh(spec.stage_of(disc.id))}" '
            f'euler="{vec(0, 0, -phase / cyc.geometry.lobes)}" rgba="{RGBA["disc"]}" {VISUAL}/>',
            marker(disc, 0.9 * r, 0.5 * cyc.geometry.contact_length, 0.01 * r)]


def _pins(spec, cyc, z: float, visuals: bool) -> list[str]:
    """The pins' centre sites (and cylinders), at the offset ``z`` of their body (the pin wheel or the world)."""
    g, zs, stage = cyc.geometry, disc_z(spec, cyc), spec.stage_of(cyc.cranks[0])
    half = 0.5 * abs(zs[-1] - zs[0]) + 0.5 * g.contact_length
    mid = z + 0.5 * (zs[0] + zs[-1])
    kind = "pin_wheel" if cyc.pin_wheel else "ring"
    lines = []
    for i in range(g.pins):
        angle = 2 * math.pi * i / g.pins
        x, y = g.pin_circle_radius * math.cos(angle), g.pin_circle_radius * math.sin(angle)
        lines.append(site(pin_site(stage, i), (x, y, mid)))
        if visuals:
            lines.append(cylinder(f"{pin_site(stage, i)}_visual", kind, g.pin_radius, (x, y, mid - half),
                                  (x, y, mid + half)))
    return lines


def _disc_body(cyc, disc, z: float, indent: str, inner: list[str]) -> list[str]:
    """A cycloid disc, a free planar body in polar joints about the stage axis: ``_orbit`` (a hinge on the axis),
    ``_radial`` (a slide along its eccentric), ``_rz`` (a hinge about its centre; its rotation is the sum of the
    two hinges').  Its nominal motion, the orbit at the cranks' speed while it turns with the carrier, is linear
    in time in these joints; its centre starts on its eccentric, at e along the eccentric's phase."""
    e, phase = cyc.geometry.eccentricity, cyc.phases[cyc.discs.index(disc.id)]
    c, s = math.cos(phase), math.sin(phase)
    orbit, radial, rotation = member_joints(disc)
    lines = [f'{indent}<body name="{disc.label}" pos="{vec(e * c, e * s, z)}">', f"{indent}  {inertial(disc)}"]
    lines += [f"{indent}  {joint(f'{disc.label}_{orbit}', 'hinge', (0, 0, 1), pos=(-e * c, -e * s, 0))}",
              f"{indent}  {joint(f'{disc.label}_{radial}', 'slide', (c, s, 0))}",
              f"{indent}  {joint(f'{disc.label}_{rotation}', 'hinge', (0, 0, 1))}"]
    return lines + [f"{indent}  {g}" for g in inner] + [f"{indent}</body>"]
