"""The MJCF vocabulary that the twin's builder and its element files write with.

Every number is written with full precision (the shortest repr that round-trips), angles in radian, so the text
is deterministic and lossless.  A member's joints realise its degrees of freedom
(:attr:`gearcheck.train.spec.Member.dofs`) by the frame that carries it (:data:`AXES`).

A few numbers of the text are not the description's: the meshes' stiffness (the argument of
:func:`gearcheck.mbd_models.twin.compile_train`) and what is known only once the twin is compiled (the tendons'
coefficients from MuJoCo's Jacobians, the meshes' damping, the pins' spring lengths, the default step).  Where an
element writes one of those it writes :data:`LATE`, and the text holds a slot for it (:func:`slot`): the text is
written once, as a :class:`Template`, and filled from :class:`LateValues`, with placeholders for the compile and
with the compiled twin's numbers for the file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

from gearcheck.mbd_models.gear_visuals import face_width
from gearcheck.train.spec import AXIAL as AXIAL_DOF
from gearcheck.train.spec import ROTATION as ROTATION_DOF
from gearcheck.train.spec import TILTS, TRANSLATIONS

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
VISUAL = 'contype="0" conaffinity="0" group="1"'  # visual geoms: no contact (no mass: explicit inertials)
# The joints that realise a member's two translations, by the frame that carries it: world-frame slides on the
# stage axis, slides along the carrier's radial and tangential axes on a pin, and on an eccentric polar joints
# about the stage axis (a hinge, and a slide along the eccentric)
AXES = {"axis": ("x", "y"), "pin": ("radial", "tangential"), "eccentric": ("orbit", "radial")}
ROTATION = "rz"  # the hinge of the member's rotation theta
AXIAL = "z"  # the slide along the stage axis
# The hinges of a tilting member's two tilts (:data:`gearcheck.train.spec.TILTS`), about the axes of its two
# translations' slides, through its centre of mass
TILT = {"axis": ("rx", "ry"), "pin": ("rradial", "rtangential")}


def _joint_names(member) -> dict[str, str]:
    """Each of the member's :attr:`~gearcheck.train.spec.Member.dofs` -> the suffix of the joint that realises it."""
    names = dict(zip(TRANSLATIONS[member.frame], AXES[member.frame]))
    names.update({ROTATION_DOF: ROTATION, AXIAL_DOF: AXIAL})
    names.update(zip(TILTS.get(member.frame, ()), TILT.get(member.frame, ())))
    return {dof: names[dof] for dof in member.dofs}


def _body_order(member) -> tuple[str, ...]:
    """The suffixes of all the joints a member's body may have, in their order on the body: its slides, then
    its rotation and axial slide (a member that does not tilt, as ever), or its slides, its tilts and then its
    rotation (a tilting member: it spins about its own tilted axis, so MuJoCo gives it its gyroscopic moments)."""
    slides = AXES[member.frame]
    if member.tilting:
        return slides + (AXIAL,) + TILT[member.frame] + (ROTATION,)
    return slides + (ROTATION, AXIAL)


def member_joints(member) -> tuple[str, ...]:
    """The suffixes of all of a member's joints, one per free coordinate (its
    :attr:`~gearcheck.train.spec.Member.coordinates`), in their order on its body (MuJoCo's order of their dofs):
    a torsional member has its hinge alone, and sits on its parent (the world, or its carrier's pin)."""
    own = {_joint_names(member)[d] for d in member.coordinates}
    return tuple(j for j in _body_order(member) if j in own)


def member_axes(member) -> tuple[str, ...]:
    """The suffixes of a member's joints of its two translations (:data:`AXES`; none for a torsional member)."""
    return tuple(j for j in member_joints(member) if j in AXES[member.frame])


def member_tilts(member) -> tuple[str, ...]:
    """The suffixes of a member's tilt hinges (:data:`TILT`; none unless it tilts and is not torsional)."""
    return tuple(j for j in member_joints(member) if j in TILT.get(member.frame, ()))


def world_pairs(member) -> list[tuple[str, str]]:
    """The member's pairs of joints along and about the world's x and y (a central member's slides, and its tilts
    when it tilts): a deflection pattern that turns with its carrier turns each pair as a vector."""
    if member.frame != "axis" or member.torsional:
        return []
    return [AXES["axis"]] + ([TILT["axis"]] if member.tilting else [])


def num(x) -> str:
    """A float written with full precision (shortest repr that round-trips)."""
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


def vec(*xs) -> str:
    return " ".join(num(x) for x in xs)


# --------------------------------------------------------------------------- numbers known once compiled


class _Late:
    def __repr__(self) -> str:
        return "LATE"


LATE = _Late()  # a number that the text takes from compile_train, not from the description: written as a slot
SLOT = "\0"  # brackets a slot's key in the rendered text (XML cannot hold it, so no text is ever taken for a slot)
KEY = "\1"  # separates the parts of a slot's key (field, tendon, joint): XML cannot hold it either
TIMESTEP, STIFFNESS, COEF, DAMPING, SPRINGLENGTH = "timestep", "stiffness", "coef", "damping", "springlength"


def slot(*key: str) -> str:
    """The slot of a late number in the text: its field (:data:`TIMESTEP`, :data:`STIFFNESS`, :data:`COEF`,
    :data:`DAMPING`, :data:`SPRINGLENGTH`), then the tendon's name and, for a coefficient, the joint's."""
    return SLOT + KEY.join(key) + SLOT


def _number(x, *key: str) -> str:
    return slot(*key) if x is LATE else num(x)


@dataclass
class LateValues:
    """The numbers that fill a :class:`Template`'s slots: the step, and by tendon name the stiffness, the joint
    coefficients [(joint, coefficient)], the damping and the spring length (dead band).  A tendon's coefficients
    are 0 until given, and then every one of its joints must have one; no damping is 0 (no attribute), no spring
    length (0, 0)."""

    timestep: float
    stiffness: dict = field(default_factory=dict)
    coefficients: dict = field(default_factory=dict)
    damping: dict = field(default_factory=dict)
    band: dict = field(default_factory=dict)

    def text(self, name: str, tendon: str = "", joint: str = "") -> str:
        """What the text writes in the slot of key (``name``, ``tendon``, ``joint``)."""
        if name == TIMESTEP:
            return num(self.timestep)
        if name == STIFFNESS:
            return num(self.stiffness[tendon])
        if name == COEF:
            coefs = self.coefficients.get(tendon)
            return num(dict(coefs)[joint] if coefs else 0.0)
        if name == DAMPING:
            c = self.damping.get(tendon, 0.0)
            return f' damping="{num(c)}"' if c else ""
        if name == SPRINGLENGTH:
            return vec(*self.band.get(tendon, (0.0, 0.0)))
        raise KeyError(f"no late number {name!r} in the MJCF text")


class Template:
    """MJCF text written once, with a slot for every late number: :meth:`fill` writes the text they make."""

    def __init__(self, text: str):
        self.pieces = text.split(SLOT)  # text, key, text, ..., text
        self.keys = [tuple(key.split(KEY)) for key in self.pieces[1::2]]

    def fill(self, values: LateValues) -> str:
        pieces = self.pieces.copy()
        pieces[1::2] = [values.text(*key) for key in self.keys]
        return "".join(pieces)


class Spring(NamedTuple):
    """What the parts put on a joint: a spring-damper, relaxed at the joint position ``rest`` (MuJoCo's
    ``springref``: a misaligned pin's tilt)."""

    stiffness: float = 0.0
    damping: float = 0.0
    rest: float = 0.0

    def plus(self, other: "Spring") -> "Spring":
        """Both springs on one joint: k1 (q - r1) + k2 (q - r2) = (k1 + k2) (q - r), r their stiffness-weighted rest."""
        k = self.stiffness + other.stiffness
        rest = (self.stiffness * self.rest + other.stiffness * other.rest) / k if k else 0.0
        return Spring(k, self.damping + other.damping, rest)


def joint(name: str, kind: str, axis, spring: Spring = Spring(), pos=(0.0, 0.0, 0.0)) -> str:
    attrs = [f'name="{name}"', f'type="{kind}"', f'axis="{vec(*axis)}"', f'pos="{vec(*pos)}"']
    if spring.stiffness:
        attrs.append(f'stiffness="{num(spring.stiffness)}"')
    if spring.damping:
        attrs.append(f'damping="{num(spring.damping)}"')
    if spring.rest:
        attrs.append(f'springref="{num(spring.rest)}"')
    return f"<joint {' '.join(attrs)}/>"


def inertial(member) -> str:
    """At the centre of mass, the polar inertia about the body's z; about a diameter the tilting inertia of a
    tilting member (else half the polar inertia, which no joint of a member that does not tilt sees)."""
    polar = member.inertia
    diameter = member.tilting_inertia if member.tilting else 0.5 * polar
    return (f'<inertial pos="0 0 0" mass="{num(member.mass)}" '
            f'diaginertia="{vec(diameter, diameter, polar)}"/>')


def site(name: str, pos) -> str:
    return f'<site name="{name}" pos="{vec(*pos)}" size="0.001" group="4"/>'


def cylinder(name: str, kind: str, radius: float, a, b) -> str:
    return (f'<geom name="{name}" type="cylinder" size="{num(radius)}" fromto="{vec(*a, *b)}" '
            f'rgba="{RGBA[kind]}" {VISUAL}/>')


def marker(member, r: float, z: float, size: float) -> str:
    """A small box on the member's +x axis (body frame): it turns with the body."""
    return (f'<geom name="{member.label}_marker" type="box" size="{vec(size, size, size)}" pos="{vec(r, 0, z)}" '
            f'rgba="{MARKER_RGBA}" {VISUAL}/>')


def fixed(name: str, coefs: list[tuple[str, float]], stiffness: float, damping: float,
          springlength: tuple[float, float] = (0.0, 0.0)) -> list[str]:
    """A ``<fixed>`` tendon: length sum coef q_joint, spring-damper with a dead band ``springlength``.  Any of the
    numbers (a coefficient, the stiffness, the damping, the spring length) may be :data:`LATE`: a slot under the
    tendon's name (and the joint's) that :class:`LateValues` fills."""
    attrs = [f'name="{name}"', f'stiffness="{_number(stiffness, STIFFNESS, name)}"',
             f'springlength="{slot(SPRINGLENGTH, name) if springlength is LATE else vec(*springlength)}"']
    if damping is LATE:
        attrs[-1] += slot(DAMPING, name)  # the attribute itself: written only where the damping is not 0
    elif damping:
        attrs.append(f'damping="{num(damping)}"')
    lines = [f"    <fixed {' '.join(attrs)}>"]
    lines += [f'      <joint joint="{j}" coef="{_number(c, COEF, name, j)}"/>' for j, c in coefs]
    lines.append("    </fixed>")
    return lines


def _joints(member, springs: dict, first: tuple, second: tuple, indent: str) -> list[str]:
    """The body's joints in their order (:func:`member_joints`), with the springs its parts put on them: its
    translations' slides along the unit vectors ``first`` and ``second``, its tilts' hinges about them, its axial
    slide and its rotation's hinge along the stage axis."""
    kinds = dict(zip(AXES[member.frame], (("slide", first), ("slide", second))))
    kinds.update(zip(TILT.get(member.frame, ()), (("hinge", first), ("hinge", second))))
    kinds.update({AXIAL: ("slide", (0, 0, 1)), ROTATION: ("hinge", (0, 0, 1))})
    return [f"{indent}  {joint(f'{member.label}_{name}', *kinds[name], springs.get((member.id, name), Spring()))}"
            for name in member_joints(member)]


def central_body(member, springs: dict, z_stage: float, indent: str, visuals: list[str],
                 children: list[str]) -> list[str]:
    """A member on the stage axis: a child of the world with world-frame slides and a hinge."""
    lines = [f'{indent}<body name="{member.label}" pos="{vec(0, 0, z_stage)}">', f"{indent}  {inertial(member)}"]
    lines += _joints(member, springs, (1, 0, 0), (0, 1, 0), indent)
    lines += [f"{indent}  {g}" for g in visuals]
    lines += children
    lines.append(f"{indent}</body>")
    return lines


def pin_body(member, springs: dict, indent: str, visuals: list[str]) -> list[str]:
    """A member on a pin of its carrier (a planet, an RV reducer's crankshaft): a child of the carrier at its place,
    with slides along the carrier's radial and tangential axes and a hinge relative to the carrier."""
    c, s = math.cos(member.angle), math.sin(member.angle)
    lines = [f'{indent}<body name="{member.label}" pos="{vec(member.radius * c, member.radius * s, 0)}">',
             f"{indent}  {inertial(member)}"]
    lines += _joints(member, springs, (c, s, 0), (-s, c, 0), indent)
    return lines + [f"{indent}  {g}" for g in visuals] + [f"{indent}</body>"]


def gear_z(spec) -> dict[tuple[str, str], float]:
    """Axial offset (m, in the body) of every gear: a compound planet's gears side by side, each central gear
    at the offset of the planet gear it meshes with."""
    z = {}
    for mid, member in spec.members.items():
        if member.is_planet:
            step = 1.5 * max(face_width(g) for g in member.gears.values())
            for i, name in enumerate(member.gears):
                z[mid, name] = (i - 0.5 * (len(member.gears) - 1)) * step
    for mesh in spec.meshes:
        planet = spec.members[mesh.planet]
        name = next(n for n, g in planet.gears.items() if g == mesh.planet_gear)
        central = next(n for n, g in spec.members[mesh.central].gears.items() if g == mesh.central_gear)
        z.setdefault((mesh.central, central), z[mesh.planet, name])
    return z


def plate(spec, stage, z: dict) -> tuple[float, float, float]:
    """(axial offset of its centre, half thickness, the planets' tip radius) of a carrier's plate behind the
    planets (``z``: :func:`gear_z`)."""
    back = min((z[p, n] - 0.5 * face_width(g) for p in stage.planets for n, g in spec.members[p].gears.items()),
               default=0.0)
    tip = max((g.tip_radius for p in stage.planets for g in spec.members[p].gears.values()), default=0.01)
    h = max(0.25 * tip, 0.002)
    return back - 2 * h, h, tip
