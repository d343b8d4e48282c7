"""The validated train description (``TrainSpec``) built from a parsed train file.

This is the single source both models are built from.  It holds the members (sun,
ring, carrier, planets of every stage), their gears, supports and bearings, the
meshes with their operating geometry, the interstage couplings, an RV reducer's
cycloid-pin stages and the operating point, all in SI units.  Every geometric rule
of a planetary stage is checked here with an error that names the file and the field.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace
from math import gcd
from pathlib import Path
from typing import ClassVar

import numpy as np

from gearcheck.train.expression import Expression
from gearcheck.train.cycloid import CycloidGeometry, cycloid_problem, min_curvature_radius, palmgren_stiffness
from gearcheck.train.files import read_text, read_toml
from gearcheck.train.history import History, parse_history
from gearcheck.train.history_file import number_row
from gearcheck.train.geometry import (Gear, MeshGeometry, gear_problem, helix_problem, idealised_mesh_geometry,
                                      mesh_geometry, mesh_problem)
from gearcheck.train.mesh_stiffness import MODELS
from gearcheck.train.parts import Part, train_parts
from gearcheck.train.schema import Context, parse_measurements_file
from gearcheck.train.torsional import check_torsional_couplings, torsional_members
from gearcheck.train.tilting import tilting_stage
from gearcheck.shared.errors import GearcheckError, TrainFileError, TrainNote, did_you_mean, shown
from gearcheck.shared.trust import inside_roots

MIN_TEETH = 6
MAX_BACKLASH = 0.5  # modules: beyond, the backlash is more than the tooth space leaves
MAX_TOLERANCE = 1e6  # a relative error of a million is no tolerance
MAX_ERROR = 0.1  # modules: a transmission error or an eccentricity that large is a broken or misplaced gear
CENTRE_DISTANCE_TOLERANCE = 1e-6  # m: sun-planet and ring-planet operating centre distances must match
CARRIER_RADIUS_TOLERANCE = 1e-6  # m: a stated carrier radius must be the operating centre distance
CYCLOID_FIELDS = {"lobes": "cycloid.lobes", "pins": "cycloid.pins", "eccentricity": "crank.eccentricity_mm",
                  "pin_circle_radius": "cycloid.pin_circle_radius_mm", "pin_radius": "cycloid.pin_radius_mm",
                  "contact_length": "cycloid.thickness_mm"}  # the train file's keys of the geometry's fields
HOLDABLE = ("sun", "ring", "carrier", "pin_wheel")  # members on the housing's axis: held, coupled, input, output


@dataclass(frozen=True)
class Station:
    """A bearing station of a tilting member: its axial position from the member's centre of mass (m) and its
    share of the support's radial stiffness and damping."""

    position: float
    radial_stiffness: float
    radial_damping: float


@dataclass(frozen=True)
class Support:
    """A member's support on the housing (central members) or bearing on its carrier's pin (planets).  A tilting
    member's tilt is held by ``tilting_stiffness`` and by its ``stations`` along the axis, over which the radial
    stiffness and damping are shared (none: all at the centre of mass); a misaligned seat (a planet's pin in the
    carrier, a central member's seat in the housing) holds it at its ``rest_tilt``."""

    radial_stiffness: float
    radial_damping: float = 0.0
    torsional_stiffness: float = 0.0
    torsional_damping: float = 0.0
    axial_stiffness: float = 0.0
    axial_damping: float = 0.0
    tilting_stiffness: float = 0.0
    tilting_damping: float = 0.0
    stations: tuple[Station, ...] = ()
    rest_tilt: tuple[float, float] = (0.0, 0.0)  # a misaligned seat's tilt: a planet's pin about its radial and
    # tangential axes, a central member's seat about the housing's x and y


@dataclass(frozen=True)
class Eccentric:
    """The eccentric that carries a member on it (a cycloid disc): the crankshaft it turns with, its angle from
    the carrier's x axis at t = 0 (in the carrier's frame) and its eccentricity."""

    crank: str
    phase: float
    eccentricity: float


# Where a member's two translations are measured, by the frame its centre is carried in: "axis", on the stage's
# axis (sun, ring, carrier, pin wheel), along the axes that turn with the stage's carrier; "pin", on a pin of
# the carrier (planets, crankshafts), along the carrier's radial and tangential axes at the pin; "eccentric", on
# the eccentrics of the crankshafts (cycloid discs), along the carrier's axes like a central member.
TRANSLATIONS = {"axis": ("x", "y"), "pin": ("radial", "tangential"), "eccentric": ("x", "y")}
ROTATION = "theta"  # absolute, about the stage axis
AXIAL = "z"  # translation along the stage axis (absolute, like the others)
# A tilting member's two tilts: small rotations (right-hand rule) about its two translation axes
TILTS = {"axis": ("tilt_x", "tilt_y"), "pin": ("tilt_radial", "tilt_tangential")}
FRAMES = {"sun": "axis", "ring": "axis", "carrier": "axis", "pin_wheel": "axis", "planet": "pin", "crank": "pin",
          "disc": "eccentric"}


@dataclass(frozen=True)
class Member:
    """A rigid body of the train: a central member (sun, ring, carrier, pin wheel), a planet, or an RV
    reducer's crankshaft or cycloid disc."""

    id: str  # "stage1.sun", "stage1.planet2"
    stage: str
    kind: str  # sun | ring | carrier | planet | crank | disc | pin_wheel
    mass: float
    inertia: float
    support: Support | None = None  # central members: support on the housing
    bearing: Support | None = None  # planets: bearing on the carrier pin
    gears: dict[str, Gear] = field(default_factory=dict)
    angle: float = 0.0  # planets: angle psi_n on the carrier circle
    radius: float = 0.0  # planets: carrier radius (position of the centre)
    axial: bool = False  # slides along its stage's axis (every member of a helical stage)
    reference_radius: float = 0.0  # where its rotation is read as a tangential motion (see below)
    eccentric: Eccentric | None = None  # on an eccentric (frame "eccentric"): the one that carries it
    torsional: bool = False  # rotation only: translations held (on the axis) or riding the carrier's pin (planets)
    tilting: bool = False  # tilts about its two translation axes (every member of a tilting stage)
    tilting_inertia: float = 0.0  # about a diameter through its centre of mass, kg m^2

    # reference_radius: a gear's pitch radius (a compound planet's first gear), a carrier's pin circle, a crankshaft's
    # eccentricity, a cycloid disc's rolling circle and a pin wheel's pin circle

    @property
    def is_planet(self) -> bool:
        return self.kind == "planet"

    @property
    def frame(self) -> str:
        """Where its translations are measured (:data:`TRANSLATIONS`)."""
        return FRAMES[self.kind]

    @property
    def central(self) -> bool:
        """On the stage axis (sun, ring, carrier, pin wheel): the members whose motion types the modes (Lin & Parker
        1999); planets, crankshafts and cycloid discs are the planetary components (Yang, Chen & Wang 2018,
        Section 3.2)."""
        return self.frame == "axis"

    @property
    def orbits(self) -> bool:
        """Sits on a pin of its carrier (a planet, an RV reducer's crankshaft): its translations are along the
        carrier's radial and tangential axes at its place."""
        return self.frame == "pin"

    @property
    def dofs(self) -> tuple[str, ...]:
        """Its degrees of freedom, defined here once for both models and the result names: two translations
        (:data:`TRANSLATIONS`), the absolute rotation ``theta``, ``z`` along the stage axis when it slides
        axially, and its two tilts (:data:`TILTS`) when it tilts."""
        return (TRANSLATIONS[self.frame] + (ROTATION,) + ((AXIAL,) if self.axial else ())
                + (TILTS[self.frame] if self.tilting else ()))

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The dofs the models keep as free coordinates: all of :attr:`dofs`, or the rotation alone for a torsional
        member, whose translations are held (on the stage axis) or follow its carrier's pin (on a pin)."""
        return (ROTATION,) if self.torsional else self.dofs

    @property
    def label(self) -> str:
        return self.id.replace(".", "_")


@dataclass(frozen=True)
class MeshSpec(Part):
    """A central gear meshing with one planet gear."""

    element: ClassVar[str] = "mesh"
    id: str  # "stage1.planet2.ring"
    stage: str
    central: str  # member id
    planet: str  # member id
    central_gear: Gear
    planet_gear: Gear
    geometry: MeshGeometry
    stiffness: dict  # model name and its parameters
    damping_ratio: float | None
    damping_coefficient: float | None
    backlash: float  # total backlash 2b along the line of action
    ste: tuple[tuple[int, float, float], ...]  # (harmonic, amplitude m, phase rad)
    planet_index: int
    axial_centre: float = 0.0  # a tilting stage: its centre of stiffness from the members' centres of mass, m
    contact_width: float = 0.0  # a tilting stage: the length of the two faces' overlap, m
    stated_tilt: tuple = (None, None)  # a tilting stage: its tilting stiffness and centre as the file states them

    def tilting_stiffness(self, mean_stiffness: float) -> float:
        """Its stiffness against the gears' relative tilt across the face, N m/rad: as stated, or its mean stiffness
        spread evenly over the contact width, k w^2/12 (slices of k/w dz at z in [-w/2, w/2] about the centre)."""
        stated = self.stated_tilt[0]
        return mean_stiffness * self.contact_width**2 / 12.0 if stated is None else stated

    @property
    def internal(self) -> bool:
        return self.central_gear.internal

    @property
    def label(self) -> str:
        stage, planet, central = self.id.split(".")
        return f"{stage}_{planet}_{central}_mesh"

    def joined(self) -> tuple[str, ...]:
        return self.central, self.planet


@dataclass(frozen=True)
class Coupling(Part):
    """Central members of two stages joined in torsion and, with a radial stiffness, in both translations."""

    element: ClassVar[str] = "coupling"
    name: str
    kind: str
    a: str
    b: str
    torsional_stiffness: float
    torsional_damping: float
    radial_stiffness: float
    radial_damping: float

    def joined(self) -> tuple[str, ...]:
        return self.a, self.b

    def speed_rows(self, spec, index: dict) -> list:
        """Rigid in torsion: both members turn together."""
        row = np.zeros(len(index))
        row[index[self.a]], row[index[self.b]] = 1.0, -1.0
        return [(row, self.name)]

    def turning_frequencies(self, spec, speeds: dict) -> list[float]:
        """A radial coupling between stages whose carriers turn at different speeds turns at their difference."""
        wa, wb = (speeds[f"{spec.members[m].stage}.carrier"] for m in (self.a, self.b))
        if not (self.radial_stiffness or self.radial_damping) or abs(wa - wb) <= 1e-12 * max(abs(wa), abs(wb), 1.0):
            return []
        return [abs(wb - wa) / (2 * math.pi)]


@dataclass(frozen=True)
class Ripple:
    member: str  # "input" | "output"
    order: float | None
    frequency: float | None  # Hz
    amplitude: float
    phase: float


@dataclass(frozen=True)
class Operating:
    input_speed: float  # rad/s
    output_torque: float  # N·m, from input_torque times the ratio when that was given
    input_shaft_stiffness: float | None
    input_shaft_damping: float
    ripple: tuple[Ripple, ...]
    torque_function: str | None
    torque_profile: tuple[tuple[float, ...], tuple[float, ...]] | None  # (times, torques) from torque_csv
    ramp: float
    input_torque: float | None = None  # N·m, as the train file gave it
    torque_expression: str | None = None  # of t in s, N·m (gearcheck.train.expression)
    history: History | None = None  # speed or torque and load as functions of time (gearcheck.train.history)

    @property
    def torque_varies(self) -> bool:
        """Whether a torque varies in time beyond the start-up ramp (ripple, a table, a function, an expression, a
        history)."""
        return bool(self.ripple or self.torque_function or self.torque_expression or self.torque_profile is not None
                    or self.history is not None)

    @property
    def aperiodic_torque(self) -> str | None:
        """The added input torque that has no period (a function or an expression), in words; None if none."""
        if self.torque_function:
            return f"the torque function {self.torque_function}"
        return f"the torque expression {self.torque_expression!r}" if self.torque_expression else None


@dataclass(frozen=True)
class CycloidStage(Part):
    """An RV reducer's cycloid-pin stage on a planetary stage's carrier: one crankshaft per planet, splined to
    it and borne in the carrier; one eccentric per disc on every crankshaft; discs that orbit on the
    eccentrics and mesh with the pin wheel's pins (Yang, Chen & Wang 2018; geometry in
    :mod:`gearcheck.train.cycloid`)."""

    element: ClassVar[str] = "cycloid"
    stage: str  # the planetary stage whose carrier it rides on
    geometry: CycloidGeometry
    phases: tuple[float, ...]  # rad: each disc's eccentric from the cranks' first eccentric
    cranks: tuple[str, ...]  # member ids, crank k at planet k's place
    discs: tuple[str, ...]
    pin_wheel: str | None  # member id; None: rigid and fixed
    spline: Support  # planet to crank: radial (bending) and torsional
    needle: Support  # eccentric to disc, radial
    contact_stiffness: float | None  # N/m per pin contact; None: Palmgren's law at the rated load
    contact_damping: float
    clearance: float  # m

    def joined(self) -> tuple[str, ...]:
        """The cranks' eccentrics on the discs' needle bearings, the discs on the pins."""
        return self.cranks + self.discs + ((self.pin_wheel,) if self.pin_wheel else ())

    def speed_rows(self, spec, index: dict) -> list:
        """An RV reducer's rigid constraints: each planet turns with its crank; each disc translates relative to
        the carrier (its eccentric bores on several cranks lock its rotation to the carrier's); and the disc rolls
        on the pins (one tooth fewer): w_H - w_w + Z_c (w_d - w_w) = 0, w_H the crank's absolute speed, w_d the
        disc's and w_w the pin wheel's (0 when it is fixed)."""
        stage, out = spec.stage_of(self.cranks[0]), []
        for planet, crank in zip(stage.planets, self.cranks):
            row = np.zeros(len(index))
            row[index[planet]], row[index[crank]] = 1.0, -1.0
            out.append((row, f"{crank}.spline"))
            row = np.zeros(len(index))
            row[index[crank]] += 1.0
            row[index[self.discs[0]]] += self.geometry.lobes
            if self.pin_wheel:
                row[index[self.pin_wheel]] -= 1.0 + self.geometry.lobes
            out.append((row, f"{crank}.pins"))
        for disc in self.discs:
            row = np.zeros(len(index))
            row[index[disc]], row[index[stage.carrier]] = 1.0, -1.0
            out.append((row, f"{disc}.orbit"))
        return out

    def frequencies(self, speeds: dict) -> dict[str, float]:
        """The pin pass: the contact pattern moves on by one pin per pin pitch of the eccentric's turn."""
        wheel = speeds[self.pin_wheel] if self.pin_wheel else 0.0
        return {f"{self.stage}.pins": self.geometry.pins * abs(speeds[self.cranks[0]] - wheel) / (2 * math.pi)}

    def turning_frequencies(self, spec, speeds: dict) -> list[float]:
        """The eccentrics turn in the carrier with the cranks."""
        return [abs(speeds[self.cranks[0]] - speeds[spec.stage_of(self.cranks[0]).carrier]) / (2 * math.pi)]

    def dead_zones(self) -> list[str]:
        """The pins' clearance, when there is one."""
        return ["pin clearance"] if self.clearance > 0 else []

    def describe(self, spec, kin, touching: set[str]) -> dict:
        """Its geometry and margins, the pin-pass frequency, the pin contacts' stiffness, how many touch at rest
        and the clearance."""
        g = self.geometry
        return {
            "discs": len(self.discs), "cranks": len(self.cranks), "lobes": g.lobes, "pins": g.pins,
            "eccentricity_m": g.eccentricity, "pin_circle_radius_m": g.pin_circle_radius, "pin_radius_m": g.pin_radius,
            "K1": g.K1, "min_curvature_radius_m": min_curvature_radius(g),
            "eccentric_phases_deg": [math.degrees(a) for a in self.phases],
            "pin_frequency_hz": kin.mesh_frequency[f"{self.stage}.pins"],
            "pin_stiffness_n_per_m": self.pin_stiffness(spec.operating.output_torque),
            "pins_touching_at_rest": sum(name.startswith(f"{self.stage}.disc") for name in touching),
            "clearance_m": self.clearance,
        }

    def pin_stiffness(self, output_torque: float) -> float:
        """The stiffness of one pin contact: as given, or Palmgren's line contact linearised at the largest
        pin force F_max = 4 T_c / (Z_p r_c) of a rigid disc carrying T_c about its centre: its share of the
        output torque times Z_c / Z_p (the pins' arms about the pin wheel's centre are Z_p / Z_c times those
        about the disc's; the input's share of the reaction, 1/ratio, neglected)."""
        if self.contact_stiffness is not None:
            return self.contact_stiffness
        g = self.geometry
        torque = abs(output_torque) / len(self.discs) * g.lobes / g.pins
        return palmgren_stiffness(4.0 * torque / (g.pins * g.rolling_radius), g.contact_length)


@dataclass(frozen=True)
class Stage:
    name: str
    carrier_radius: float
    planet_angles: tuple[float, ...]
    equally_spaced: bool
    centrals: tuple[str, ...]  # member ids of sun/ring gears
    planets: tuple[str, ...]
    carrier: str
    helical: bool = False  # a gear with a helix: every member of the stage has an axial degree of freedom
    idealised: bool = False  # no teeth: base radii and a pressure angle (see _idealised_gear)
    tilting: bool = False  # every member of the stage tilts (see gearcheck.train.tilting)


@dataclass(frozen=True)
class TrainSpec:
    """A validated gear train in SI units."""

    name: str
    description: str
    source: str
    path: str  # file it was read from ("preset:NAME" for presets)
    input: str
    output: str
    held: tuple[str, ...]
    members: dict[str, Member]
    stages: tuple[Stage, ...]
    meshes: tuple[MeshSpec, ...]
    couplings: tuple[Coupling, ...]
    cycloids: tuple[CycloidStage, ...]  # an RV reducer's second stage, on its first stage's carrier
    operating: Operating
    text_hash: str = ""
    references: tuple[str, ...] = ()  # keys of gearcheck.shared.citations.REFERENCES
    measurements: tuple[dict, ...] = ()  # measured reference values, SI (see schema.MEASUREMENT)
    natural_frequencies: tuple[dict, ...] = ()  # measured ones of train.measurements_file, which calibrate fits
    tolerances: dict = field(default_factory=dict)  # cross-check tolerance overrides, flat keys
    user_model: str | None = None  # a user's model of the train (a file path or module:factory), --model user

    def member(self, member_id: str) -> Member:
        return self.members[member_id]

    def stage_of(self, member_id: str) -> Stage:
        name = self.members[member_id].stage
        return next(s for s in self.stages if s.name == name)

    @property
    def parts(self) -> tuple:
        """Every part that joins the members, in the order both models build them
        (:func:`~gearcheck.train.parts.train_parts`)."""
        return train_parts(self)

    def with_operating(self, **changes) -> "TrainSpec":
        """A copy with operating-point fields replaced (e.g. ``input_speed``)."""
        return replace(self, operating=replace(self.operating, **changes))


def build_spec(data: dict, source: str, text_hash: str = "") -> TrainSpec:
    """Turn a schema-checked document into a :class:`TrainSpec`, applying the geometric rules."""
    fail = lambda path, msg: TrainFileError(source, path, msg)  # noqa: E731
    members: dict[str, Member] = {}
    stages: list[Stage] = []
    meshes: list[MeshSpec] = []
    cycloids: list[CycloidStage] = []
    names = [s["name"] for s in data["stages"]]
    for i, name in enumerate(names):
        if names.index(name) != i:
            raise fail(f"stages[{i}].name", f"duplicate stage name {name!r}")

    for i, st in enumerate(data["stages"]):
        path = f"stages[{i}]"
        stage_members, stage, stage_meshes, stage_cycloids = _build_stage(st, path, fail)
        members.update(stage_members)
        stages.append(stage)
        meshes.extend(stage_meshes)
        cycloids.extend(stage_cycloids)

    train = data["train"]
    for key in ("input", "output"):
        if train[key] not in members:
            raise fail(f"train.{key}", f"no member {train[key]!r}{did_you_mean(train[key], members, 'members')}")
    for j, ref in enumerate(train["held"]):
        if ref in train["held"][:j]:
            raise fail(f"train.held[{j}]", f"{ref} is held twice")
        if ref not in members:
            raise fail(f"train.held[{j}]", f"no member {ref!r}{did_you_mean(ref, members, 'members')}")
        if members[ref].kind not in HOLDABLE:
            raise fail(f"train.held[{j}]", f"{ref} is a {members[ref].kind}; only a sun, ring, carrier or pin wheel "
                                           "can be held")
        if members[ref].support.torsional_stiffness <= 0.0:
            raise fail(f"train.held[{j}]", f"{ref} is held but its support.torsional_stiffness is 0; "
                                           "a held member is held by a support stiffness")
        if ref in (train["input"], train["output"]):
            raise fail(f"train.held[{j}]", f"{ref} cannot be both held and the input or output")
    if train["input"] == train["output"]:
        raise fail("train.output", "the output must differ from the input")

    couplings = []
    for j, c in enumerate(data["couplings"]):
        for key in ("from", "to"):
            if c[key] not in members:
                raise fail(f"couplings[{j}].{key}", f"no member {c[key]!r}{did_you_mean(c[key], members, 'members')}")
            if members[c[key]].kind not in HOLDABLE:
                raise fail(f"couplings[{j}].{key}", f"{c[key]} is a {members[c[key]].kind}; a coupling joins "
                                                    "central members (sun, ring, carrier, pin wheel)")
        if members[c["from"]].stage == members[c["to"]].stage:
            raise fail(f"couplings[{j}]", "a coupling joins members of different stages")
        check_torsional_couplings(c, members, f"couplings[{j}]", fail)
        couplings.append(Coupling(c["name"], c["kind"], c["from"], c["to"], c["torsional_stiffness"],
                                  c["torsional_damping"], c["radial_stiffness"], c["radial_damping"]))

    op = data["operating"]
    ripples = []
    for j, r in enumerate(op["ripple"]):
        if (r["order"] is None) == (r["frequency_hz"] is None):
            raise fail(f"operating.ripple[{j}]", "give exactly one of order or frequency_hz")
        ripples.append(Ripple(r["member"], r["order"], r["frequency_hz"], r["amplitude"], r["phase"]))
    profile = _torque_profile(op["torque_csv"], source, fail) if op["torque_csv"] is not None else None
    if op["input_torque"] is not None and op["output_torque"] is not None:
        raise fail("operating.input_torque", "give input_torque or output_torque, not both")
    for cyc in cycloids:
        if cyc.contact_stiffness is None and not (op["output_torque"] or op["input_torque"]):
            raise fail(f"stages[{names.index(cyc.stage)}].cycloid.contact.stiffness",
                       "missing: give it, or a load (operating.output_torque) to linearise Palmgren's law at")
    if op["torque_expression"] is not None:
        try:
            Expression(op["torque_expression"], "")(0.0)  # its grammar, and a finite value at the start
        except GearcheckError as exc:
            raise fail("operating.torque_expression", str(exc).removeprefix(": ")) from None
    operating = Operating(op["input_speed"], op["output_torque"] or 0.0, op["input_shaft_stiffness"],
                          op["input_shaft_damping"], tuple(ripples), op["torque_function"], profile, op["ramp_s"],
                          op["input_torque"], op["torque_expression"])
    if op["history"] is not None:
        operating = with_history(operating, parse_history(op["history"], source, lambda name: beside(source, name),
                                                          fail), fail)

    _note_idealised(stages)
    _note_undamped(members)
    return TrainSpec(
        name=train["name"], description=train["description"], source=train["source"], path=source,
        input=train["input"], output=train["output"], held=tuple(train["held"]), members=members,
        stages=tuple(stages), meshes=tuple(meshes), couplings=tuple(couplings), cycloids=tuple(cycloids),
        operating=operating, text_hash=text_hash, references=tuple(train["references"]),
        **_measurements(data, source, fail),
        tolerances=flat_tolerances(data["tolerances"] or {}, lambda key, msg: fail(f"tolerances.{key}", msg)),
        user_model=_user_model(train["user_model"], source, fail),
    )


def _note_idealised(stages: list[Stage]) -> None:
    """A note naming the idealised stages and what they skip and lack."""
    for i, stage in enumerate(stages):
        if stage.idealised:
            warnings.warn(f"stages[{i}] ({stage.name}) is idealised (base radii, no teeth): the involute and assembly "
                          "checks are skipped, the speeds follow from the base radii, and its meshes have no mesh "
                          "cycle (constant stiffness, no mesh frequency or phase: modes only)", TrainNote,
                          stacklevel=2)


def _note_undamped(members: dict) -> None:
    """A note (:class:`~gearcheck.shared.errors.TrainNote`) naming the supports and bearings that are stiff in a
    direction and have no damping in it: their damping defaults to 0, and the modes that live in them then decay
    only through the meshes' damping (a cross-check may wait long for its steady state)."""
    undamped = []
    for mid, m in members.items():
        for what, support in (("support", m.support), ("bearing", m.bearing)):
            for direction in ("radial", "torsional", "axial") if support is not None else ():
                if getattr(support, f"{direction}_stiffness") > 0 and getattr(support, f"{direction}_damping") == 0:
                    undamped.append(f"{f'{m.stage}.{m.kind}' if m.orbits else mid} {what} {direction}")
    if undamped:
        warnings.warn(f"no damping in {', '.join(dict.fromkeys(undamped))} (damping defaults to 0): the modes that "
                      "live there decay only through the meshes; a bearing is commonly given a damping ratio of "
                      "1-5 %, c = 2 zeta sqrt(k m)", TrainNote, stacklevel=2)


MAX_KEY_DEPTH = 16  # dotted parts of a tolerance key: the longest quantity name and its metric have 6


def flat_tolerances(table: dict, fail) -> dict[str, float]:
    """``[tolerances]`` entries as flat ``KIND.METRIC`` keys (TOML dotted keys arrive nested),
    each a positive finite number."""
    flat = {}

    def walk(node, prefix, depth):
        for key, value in node.items():
            name = f"{prefix}.{key}" if prefix else key
            if isinstance(value, dict):
                if depth >= MAX_KEY_DEPTH:
                    raise fail(name[:80] + "...", f"a key of more than {MAX_KEY_DEPTH} dotted parts names no quantity")
                walk(value, name, depth + 1)
            elif isinstance(value, bool) or not isinstance(value, (int, float)) or not -math.inf < value < math.inf \
                    or not 0 < value <= MAX_TOLERANCE:
                raise fail(name, f"must be a positive number up to {MAX_TOLERANCE:g}, got {shown(value)}")
            elif "." not in name:
                raise fail(name, "expected KIND.METRIC or QUANTITY.METRIC")
            else:
                flat[name] = float(value)

    walk(table, "", 1)
    return flat


def with_history(operating: Operating, history: History, fail) -> Operating:
    """The operating point a history runs from.  Its reference speed (lambda = 1): the speed history's initial
    speed for a steady start, else the train file's input speed.  A prescribed speed drives the input through the
    input shaft; a prescribed torque drives the input member itself, so the input shaft is not used (said in
    :meth:`History.words`).  With a load history the mean load is its initial value for a steady start, else its
    largest magnitude (what the dynamic factors are taken against)."""
    speed = operating.input_speed
    if history.driven_by == "speed" and history.start == "steady":
        speed = float(history.speed(0.0)) * 2.0 * math.pi / 60.0
    elif not speed:
        raise fail("operating.input_speed_rpm", "0, but a history from rest scales the train's kinematics from a "
                                                "reference speed: give the speed it is to be compared at")
    if history.driven_by == "speed" and operating.input_shaft_stiffness is None:
        raise fail("operating.history", "a prescribed speed drives the input through its shaft: give "
                                        "operating.input_shaft_stiffness (or prescribe the input torque instead)")
    changes = {"input_speed": speed, "history": history, "input_torque": None}
    if history.driven_by == "torque":
        changes.update(input_shaft_stiffness=None, input_shaft_damping=0.0)
    if history.load is not None:
        values = history.load(np.union1d(history.load.corners, [0.0]))
        changes["output_torque"] = abs(float(values[0])) if history.start == "steady" \
            else float(np.max(np.abs(values)))
    return replace(operating, **changes)


def with_profiles(spec: TrainSpec, speed: str | None = None, torque: str | None = None, load: str | None = None,
                  start: str | None = None) -> TrainSpec:
    """``spec`` under the operating history of command-line profiles (``--speed-profile`` and the others): each a
    table file (CSV or Parquet, :mod:`gearcheck.train.history_file`) or inline points ``T:V,T:V,...`` (s and rpm
    or N·m); the train's own ``[operating.history]`` is replaced.  Unchanged without any."""
    given = {"speed": speed, "torque": torque, "load": load}
    if not any(given.values()):
        if start is not None:
            raise GearcheckError("--start applies to an operating history: give --speed-profile or --torque-profile")
        return spec
    raw = {f"{name}_{kind}": None for name in given for kind in ("points", "file", "expression")}
    raw.update(start=start, until_s=None)
    for name, value in given.items():
        if value is None:
            continue
        if Path(value).suffix.lower() in (".csv", ".parquet"):
            raw[f"{name}_file"] = value
        else:
            try:
                raw[f"{name}_points"] = [[float(x) for x in pair.split(":")] for pair in value.split(",")]
            except ValueError:
                raise GearcheckError(f"--{name}-profile {value!r}: a .csv or .parquet file, or points "
                                     "T:V,T:V,... (s and rpm or N·m)") from None

    def fail(field, message):
        option = field.removeprefix("operating.history.").split("_")[0]
        return GearcheckError(f"--{option}-profile: {message}" if option in given else f"{field}: {message}")

    history = parse_history(raw, "command line", Path, fail)
    return replace(spec, operating=with_history(spec.operating, history, fail))


def beside(source: str, name: str) -> Path:
    """The file ``name`` that the train file ``source`` names: relative to the train file (presets and their
    edited variants: the presets folder), and inside its folder or a folder the user allows
    (:func:`~gearcheck.shared.trust.inside_roots`); GearcheckError otherwise."""
    home = Path(__file__).parent / "presets" if source.startswith("preset:") else Path(source).parent
    path = home / name
    if not inside_roots(path, home):
        raise GearcheckError(f"{name!r} lies outside the train file's folder {home.resolve()}; a train file "
                             "names files beside it, unless you allow a folder: --data-root DIR "
                             "(gearcheck.allow_data(DIR) in Python)")
    return path


def named_file(value: str | None) -> tuple[str, str] | None:
    """(the file, what follows it) of a train file's value that names a file: ``data.csv`` is ("data.csv", ""),
    ``model.py:factory`` ("model.py", ":factory"); None for no value or ``module:factory``."""
    if value is None:
        return None
    where, colon, rest = value.rpartition(":")
    if not colon:
        return value, ""
    return (where, f":{rest}") if where.endswith(".py") else None


def _user_model(name: str | None, source: str, fail) -> str | None:
    """train.user_model: a file of matrices or ``file.py:factory``, named relative to the train file, or
    ``module:factory`` as given (code: run only when trusted, :mod:`gearcheck.shared.trust`)."""
    named = named_file(name)
    if named is None:
        return name
    try:
        return f"{beside(source, named[0])}{named[1]}"
    except GearcheckError as exc:
        raise fail("train.user_model", str(exc)) from None


def _measurements(data: dict, source: str, fail) -> dict:
    """Inline [[measurements]] plus those of train.measurements_file, and that file's [[natural_frequencies]],
    checked: the TrainSpec's ``measurements`` and ``natural_frequencies``."""

    entries, frequencies = list(data["measurements"]), []
    name = data["train"]["measurements_file"]
    if name is not None:
        try:
            path = beside(source, name)
            document = read_toml(path, "measurements file")
        except TrainFileError:
            raise
        except GearcheckError as exc:
            raise fail("train.measurements_file", str(exc)) from None
        found = parse_measurements_file(document, str(path))
        entries += found["measurements"]
        frequencies = found["natural_frequencies"]
    return {"measurements": tuple(entries), "natural_frequencies": tuple(frequencies)}


def _torque_profile(name: str, source: str, fail):
    """Read a two-column CSV (time s, torque N·m; a header line allowed) next to the train file."""
    try:
        path = beside(source, name)
        lines = read_text(path, "torque profile").splitlines()
    except GearcheckError as exc:
        raise fail("operating.torque_csv", str(exc)) from None
    if lines and not number_row(lines[0]):
        lines = lines[1:]  # a header line
    try:
        data = np.loadtxt(lines, delimiter=",", ndmin=2)
    except ValueError as exc:
        raise fail("operating.torque_csv", f"{path}: {exc}") from None
    if data.ndim != 2 or data.shape[1] != 2 or data.shape[0] < 2:
        raise fail("operating.torque_csv", f"{path} needs two columns (time, torque) and at least two rows")
    if not np.all(np.isfinite(data)) or np.any(np.diff(data[:, 0]) <= 0):
        raise fail("operating.torque_csv", f"{path}: times must increase strictly and all values be finite")
    return tuple(data[:, 0]), tuple(data[:, 1])


def _gear(name: str, raw: dict, stage: dict, internal: bool, path: str, fail) -> Gear:
    def pick(key, unit_key):
        value = raw.get(key)
        if value is None:
            value = stage.get(key)
        if value is None:
            raise fail(f"{path}.{unit_key}", "missing required field (give it on the gear or the stage)")
        return value

    teeth = raw["teeth"]
    if teeth is None:
        return _idealised_gear(name, raw, stage, internal, path, fail)
    if teeth < MIN_TEETH:
        raise fail(f"{path}.teeth", f"an involute gear needs at least {MIN_TEETH} teeth, got {teeth}")
    beta = raw["helix_angle"]
    if beta is None:  # the stage's angle is the planets'; a sun's helix runs the other way
        beta = -stage["helix_angle"] if not internal and name.startswith("sun") else stage["helix_angle"]
    normal_module = pick("module", "module_mm")
    normal_alpha = pick("pressure_angle", "pressure_angle_deg")
    module = normal_module / math.cos(beta)  # transverse (ISO 21771): m_t = m_n / cos(beta)
    alpha = normal_alpha if beta == 0.0 else math.atan(math.tan(normal_alpha) / math.cos(beta))
    _check_small(raw["eccentricity"], MAX_ERROR, normal_module, f"{path}.eccentricity_um", "eccentricity", fail)
    _check_small(raw["installation_error"], MAX_ERROR, normal_module, f"{path}.installation_error_um",
                 "installation error", fail)
    relief = raw["tip_relief"] or {"amount": 0.0, "length": 0.0, "shape": "linear"}
    _check_small(relief["amount"], MAX_ERROR, normal_module, f"{path}.tip_relief.amount_um", "tip relief", fail)
    base = raw["base_radius"] if raw["base_radius"] is not None else 0.5 * module * teeth * math.cos(alpha)
    pitch = 0.5 * module * teeth
    if not 0.5 * pitch < base < pitch:  # cos a between 0.5 and 1: pressure angles of 0 to 60 deg
        raise fail(f"{path}.base_radius_mm", f"base radius {base * 1e3:.4g} mm does not fit the pitch radius "
                                             f"{pitch * 1e3:.4g} mm (it must lie between half of it and all of it)")
    return Gear(
        name=name, teeth=teeth, module=module, pressure_angle=alpha, face_width=pick("face_width", "face_width_mm"),
        addendum=pick("addendum_coefficient", "addendum_coefficient"),
        dedendum=pick("dedendum_coefficient", "dedendum_coefficient"),
        profile_shift=raw["profile_shift"], internal=internal, base_radius=base,
        eccentricity=raw["eccentricity"], eccentricity_phase=raw["eccentricity_phase"], helix_angle=beta,
        installation_error=raw["installation_error"], installation_error_phase=raw["installation_error_phase"],
        axial_offset=raw["axial_offset"],
        relief_amount=relief["amount"], relief_length=relief["length"],
        relief_power=2 if relief["shape"] == "parabolic" else 1,
    )


TOOTH_FIELDS = ("module_mm", "addendum_coefficient", "dedendum_coefficient", "tip_relief")  # an idealised gear has none


def _idealised_gear(name: str, raw: dict, stage: dict, internal: bool, path: str, fail) -> Gear:
    """A gear as published modal models give it (Lin & Parker 1999): a base radius, a pressure angle (and a helix
    angle), no teeth, module or tooth geometry."""
    if raw["base_radius"] is None:
        raise fail(f"{path}.teeth", "missing required field (an idealised gear gives base_radius_mm instead)")
    for key in TOOTH_FIELDS:
        if raw.get(key.removesuffix("_mm")) is not None:
            raise fail(f"{path}.{key}", "an idealised gear (no teeth) has no tooth geometry: give teeth, or remove it")
    if raw["profile_shift"]:
        raise fail(f"{path}.profile_shift", "an idealised gear (no teeth) has no tooth geometry: give teeth, or "
                                            "remove it")
    beta = raw["helix_angle"]
    if beta is None:
        beta = -stage["helix_angle"] if not internal and name.startswith("sun") else stage["helix_angle"]
    normal_alpha = raw["pressure_angle"] if raw["pressure_angle"] is not None else stage["pressure_angle"]
    alpha = normal_alpha if beta == 0.0 else math.atan(math.tan(normal_alpha) / math.cos(beta))
    face = raw["face_width"] if raw["face_width"] is not None else stage["face_width"]
    return Gear(name=name, teeth=None, module=None, pressure_angle=alpha, face_width=face or 0.0, addendum=None,
                dedendum=None, profile_shift=0.0, internal=internal, base_radius=raw["base_radius"],
                eccentricity=raw["eccentricity"], eccentricity_phase=raw["eccentricity_phase"], helix_angle=beta,
                installation_error=raw["installation_error"], installation_error_phase=raw["installation_error_phase"],
                axial_offset=raw["axial_offset"])


def _body(raw: dict, radius: float, path: str, fail, gear: Gear | None = None) -> tuple[float, float]:
    """(mass, inertia) of a member: as given, or from ``density`` as an annulus (a gear's default from its
    bore to its pitch circle over its face width; a ring's from its pitch circle out); ``radius`` is the
    one ``inertia_over_r2`` refers to."""
    if raw["inertia"] is not None and raw["inertia_over_r2"] is not None:
        raise fail(f"{path}.inertia", "give inertia or inertia_over_r2, not both")
    mass = raw["mass"]
    inertia = raw["inertia"] if raw["inertia_over_r2"] is None else raw["inertia_over_r2"] * radius**2
    if mass is not None and inertia is not None:
        return mass, inertia
    if raw["density"] is None:
        missing = "mass" if mass is None else "inertia"
        raise fail(f"{path}.{missing}", f"missing: give {missing}"
                   + (" (or inertia_over_r2)" if missing == "inertia" else "") + ", or a density to derive it from")
    pitch = gear.pitch_radius if gear is not None else None
    inner = raw["inner_radius"]
    outer = raw["outer_radius"]
    if gear is not None and gear.internal:
        inner = pitch if inner is None else inner
        if outer is None:
            raise fail(f"{path}.outer_radius_mm", "a ring's mass from its density needs its outer radius")
    elif gear is not None:
        inner, outer = inner or 0.0, pitch if outer is None else outer
    elif outer is None or raw["thickness"] is None:
        raise fail(f"{path}.{'outer_radius_mm' if outer is None else 'thickness_mm'}",
                   "a carrier's mass from its density needs its outer radius and thickness")
    inner = inner or 0.0
    if not inner < outer:
        raise fail(f"{path}.inner_radius_mm", f"must be less than the outer radius {outer * 1e3:.6g} mm, got "
                                              f"{inner * 1e3:.6g} mm")
    width = raw["thickness"] if raw["thickness"] is not None else gear.face_width
    annulus_mass = raw["density"] * math.pi * (outer**2 - inner**2) * width
    mass = annulus_mass if mass is None else mass
    return mass, inertia if inertia is not None else 0.5 * mass * (outer**2 + inner**2)


def _support(raw: dict) -> Support:
    k, c = raw["radial_stiffness"], raw["radial_damping"]
    stations = tuple(Station(s["position"], s["share"] * k, s["share"] * c) for s in raw["stations"])
    return Support(k, c, raw.get("torsional_stiffness", 0.0), raw.get("torsional_damping", 0.0),
                   raw["axial_stiffness"], raw["axial_damping"], raw["tilting_stiffness"], raw["tilting_damping"],
                   stations, tuple(raw.get("tilt") or (0.0, 0.0)))


def _merge_mesh(stage_mesh: dict | None, gear_mesh: dict | None) -> dict:
    merged: dict = {"stiffness": None, "damping": None, "backlash": None, "ste": []}
    for layer in (stage_mesh, gear_mesh):
        if layer:
            for key, value in layer.items():
                if value is not None and value != []:
                    merged[key] = value
    return merged


def _build_stage(st: dict, path: str, fail):
    """A stage's members, its :class:`Stage`, its meshes and its cycloid-pin stage (an RV reducer's; none
    otherwise), every geometric rule checked."""
    name, n = st["name"], st["planets"]
    planet_gears = _planet_gears(st, path, fail)
    centrals = _central_gears(st, planet_gears, path, fail)
    idealised = _check_idealised(st, centrals, planet_gears, path, fail)
    rv = _check_rv_layout(st, centrals, path, fail)
    geoms = _mesh_geometries(centrals, planet_gears, path, fail)
    carrier_radius = _centre_distance(centrals, planet_gears, geoms, path, fail)
    angles, equally = _planet_angles(st, n, path, fail)
    if not idealised:  # an idealised stage's planets may sit anywhere: there are no teeth to assemble
        _check_assembly(centrals, planet_gears, angles, equally, n, path, fail)
    _check_carrier_radius(st["carrier_radius"], carrier_radius, path, fail)
    _check_collision(planet_gears, angles, carrier_radius, path, fail)
    members = _stage_members(st, centrals, planet_gears, angles, carrier_radius, rv, path, fail)
    planet_ids = tuple(f"{name}.planet{k + 1}" for k in range(n))
    cycloids = (_cycloid_stage(st, members, angles, carrier_radius, path, fail),) if rv else ()
    meshes = _stage_meshes(st, centrals, planet_gears, geoms, planet_ids, path, fail)
    helical = any(g.helix_angle for g in list(planet_gears.values()) + [c[0] for c in centrals.values()])
    if st["tilting"] and rv:
        raise fail(f"{path}.tilting", "an RV reducer's stage does not tilt here (its cycloid discs and pins are "
                                      "planar): remove it")
    if helical:
        _check_helical(st, centrals, meshes, path, fail)
    elif st["tilting"]:
        _check_axial(st, centrals, path, fail, "a tilting stage needs it > 0: its members move along the axis (a "
                                               "tilting carrier carries its planets' pins with it)")
    if helical and rv:
        raise fail(f"{path}.helix_angle_deg", "an RV reducer's first stage is modelled with spur gears")
    if helical or st["tilting"]:  # the axial degree of freedom of every member (Eritenel & Parker 2009)
        members = {mid: replace(m, axial=True) for mid, m in members.items()}
    members = torsional_members(st, centrals, members, rv, path, fail)
    members, meshes = tilting_stage(st, centrals, members, meshes, path, fail)
    stage = Stage(name, carrier_radius, angles, equally, tuple(f"{name}.{k}" for k in centrals), planet_ids,
                  f"{name}.carrier", helical, idealised, st["tilting"])
    return members, stage, meshes, cycloids


def _check_idealised(st: dict, centrals: dict, planet_gears: dict, path: str, fail) -> bool:
    """Whether the stage is idealised (no gear has teeth; see :func:`_idealised_gear`); a stage of toothed and
    idealised gears is refused, naming the first idealised one."""
    gears = [(planet_gears[n], q) for n, q in _planet_paths(planet_gears, path).items()] + \
        [(g, f"{path}.{key}") for key, (g, _, _) in centrals.items()]
    idealised = [p for g, p in gears if g.idealised]
    if not idealised:
        return False
    if len(idealised) < len(gears):
        raise fail(f"{idealised[0]}.teeth", "missing: the stage's other gears have teeth (an idealised stage gives "
                                            "none: base radii and a pressure angle only)")
    if st["module"] is not None:
        raise fail(f"{path}.module_mm", "an idealised stage (no teeth) has no module: remove it, or give teeth")
    if st["crank"] is not None or st["cycloid"] is not None:
        raise fail(f"{path}.crank", "an RV reducer's stage needs teeth (its pins and lobes are counted)")
    return True


def _planet_gears(st: dict, path: str, fail) -> dict[str, Gear]:
    """The planet's gear, or a compound planet's gears by name."""
    planet_raw = st["planet"]
    if planet_raw["gears"] is not None and planet_raw["gears"]:
        if planet_raw["teeth"] is not None:
            raise fail(f"{path}.planet.teeth", "give teeth on each of planet.gears, not on the planet")
        return {g: _gear(g, raw, st, False, f"{path}.planet.gears.{g}", fail) for g, raw in planet_raw["gears"].items()}
    return {"planet": _gear("planet", planet_raw, st, False, f"{path}.planet", fail)}


def _central_gears(st: dict, planet_gears: dict, path: str, fail) -> dict[str, tuple[Gear, str, dict]]:
    """Central gears (sun, ring, sun_*, ring_*) by key: (gear, the planet gear it meshes, its table)."""
    central_keys = [k for k in st if (k in ("sun", "ring") or k.startswith(("sun_", "ring_"))) and st[k] is not None]
    if not central_keys:
        raise fail(path, "a stage needs at least one central gear (sun or ring)")
    centrals = {}
    for key in central_keys:
        raw = st[key]
        gpath = f"{path}.{key}"
        gear = _gear(key, raw, st, key.startswith("ring"), gpath, fail)
        if raw["planet_gear"] is None:
            if len(planet_gears) > 1:
                raise fail(f"{gpath}.planet_gear", f"missing required field for compound planets "
                                                   f"(one of {', '.join(planet_gears)})")
            pg = next(iter(planet_gears))
        else:
            pg = raw["planet_gear"]
            if pg not in planet_gears:
                raise fail(f"{gpath}.planet_gear", f"no planet gear {pg!r} (have {', '.join(planet_gears)})")
        centrals[key] = (gear, pg, raw)
    return centrals


def _check_rv_layout(st: dict, centrals: dict, path: str, fail) -> bool:
    """Whether the stage is an RV reducer's first stage (crankshafts in place of planet pins, and no ring: the
    cranks set the planets' spin), its tables checked either way."""
    planet_raw = st["planet"]
    rv = st["crank"] is not None or st["cycloid"] is not None
    if rv:
        for key in ("crank", "cycloid"):
            if st[key] is None:
                raise fail(f"{path}.{key}", "missing: an RV reducer's stage needs both [crank] and [cycloid]")
        rings = [key for key in centrals if key.startswith("ring")]
        if rings:
            raise fail(f"{path}.{rings[0]}", "an RV reducer's planets are turned by their crankshafts: a ring "
                                             "would lock them (remove the ring, or the crank and cycloid tables)")
        if planet_raw["bearing"] is not None:
            raise fail(f"{path}.planet.bearing", "an RV reducer's planets sit on their crankshafts (give the "
                                                 "crank's bearing and spline instead)")
    elif planet_raw["bearing"] is None:
        raise fail(f"{path}.planet.bearing", "missing required field")
    return rv


def _planet_paths(planet_gears: dict, path: str) -> dict[str, str]:
    return {name: f"{path}.planet" if name == "planet" else f"{path}.planet.gears.{name}" for name in planet_gears}


def _mesh_geometries(centrals: dict, planet_gears: dict, path: str, fail) -> dict:
    """Every gear an involute gear, every central gear's pair with its planet gear an involute mesh: the operating
    geometry of each pair by central key."""
    planet_paths = _planet_paths(planet_gears, path)
    for gear, gpath in [(planet_gears[n], p) for n, p in planet_paths.items()] + \
            [(g, f"{path}.{key}") for key, (g, _, _) in centrals.items()]:
        problem = None if gear.idealised else gear_problem(gear)
        if problem:
            raise fail(f"{gpath}.{problem[0]}", problem[1])
    geoms = {}
    for key, (gear, pg, _) in centrals.items():
        planet = planet_gears[pg]
        if gear.idealised:
            problem = helix_problem(gear, planet)
            if problem:
                raise fail(f"{path}.{key}.helix_angle_deg", f"meshing {key} with the planet: {problem}")
            try:
                geoms[key] = idealised_mesh_geometry(gear, planet)
            except ValueError as exc:
                raise fail(f"{path}.{key}.base_radius_mm", str(exc)) from None
            continue
        if gear.internal and gear.teeth <= planet.teeth:
            raise fail(f"{path}.{key}.teeth", f"a ring needs more teeth than its planet gear ({planet.teeth}), "
                                              f"got {gear.teeth}")
        try:
            geoms[key] = mesh_geometry(gear, planet)
        except ValueError as exc:
            raise fail(f"{path}.{key}.profile_shift", f"no operating geometry with the planet: {exc}") from None
        problem = mesh_problem(gear, planet, geoms[key])
        if problem:
            where = f"{path}.{key}" if problem[0] == "central" else planet_paths[pg]
            raise fail(f"{where}.{problem[1]}", f"meshing {key} with the planet: {problem[2]}")
    return geoms


def _centre_distance(centrals: dict, planet_gears: dict, geoms: dict, path: str, fail) -> float:
    """The operating centre distance, which every central gear's pair must share (ring teeth consistent with sun
    and planet): the carrier radius."""
    first, *others = centrals
    a0 = geoms[first].centre_distance
    for key in others:
        a = geoms[key].centre_distance
        if abs(a - a0) > CENTRE_DISTANCE_TOLERANCE:
            g, pg, _ = centrals[key]
            if g.idealised:
                raise fail(f"{path}.{key}.base_radius_mm", f"{key} meets the planet at centre distance {a * 1e3:.4f} "
                                                           f"mm but {first} at {a0 * 1e3:.4f} mm: the base radii "
                                                           "must close (r_b,sun + r_b,planet = r_b,ring - "
                                                           "r_b,planet at one pressure angle)")
            hint = ""
            if g.internal and not centrals[first][0].internal and len(planet_gears) == 1:
                zs, zp = centrals[first][0].teeth, planet_gears[pg].teeth
                hint = f"; with zero profile shifts the ring needs z_s + 2 z_p = {zs + 2 * zp} teeth"
            raise fail(f"{path}.{key}.teeth", f"{key} with {g.teeth} teeth meets the planet at centre distance "
                                              f"{a * 1e3:.4f} mm but {first} at {a0 * 1e3:.4f} mm{hint}")
    return a0


def _check_carrier_radius(stated: float | None, a0: float, path: str, fail) -> None:
    """A stated carrier radius must be the operating centre distance ``a0``."""
    if stated is not None and abs(stated - a0) > CARRIER_RADIUS_TOLERANCE:
        raise fail(f"{path}.carrier_radius_mm", f"{stated * 1e3:.6g} mm, but the gears mesh at an operating centre "
                                                f"distance of {a0 * 1e3:.6g} mm: the pins must sit there (change the "
                                                "teeth or profile shifts, or the radius)")


def _planet_angles(st: dict, n: int, path: str, fail) -> tuple[tuple[float, ...], bool]:
    """The planets' angles on the carrier and whether they are equally spaced."""
    if st["planet_angles"] is None:
        return tuple(2.0 * math.pi * k / n for k in range(n)), True
    if len(st["planet_angles"]) != n:
        raise fail(f"{path}.planet_angles_deg", f"has {len(st['planet_angles'])} angles for {n} planets")
    angles = tuple(st["planet_angles"])
    spacing = [((angles[k] - angles[0]) - 2 * math.pi * k / n) for k in range(n)]
    return angles, max(abs(s) for s in spacing) < 1e-12


def _stage_members(st: dict, centrals: dict, planet_gears: dict, angles, carrier_radius: float, rv: bool,
                   path: str, fail) -> dict[str, Member]:
    """The central members, the carrier and the planets (an RV reducer's planets bear on their cranks)."""
    name, planet_raw = st["name"], st["planet"]
    members: dict[str, Member] = {}
    for key, (gear, _, raw) in centrals.items():
        mid = f"{name}.{key}"
        members[mid] = Member(mid, name, "ring" if gear.internal else "sun",
                              *_body(raw, gear.base_radius, f"{path}.{key}", fail, gear),
                              support=_support(raw["support"]), gears={key: gear}, reference_radius=gear.pitch_radius)
    carrier_raw = st["carrier"]
    carrier_id = f"{name}.carrier"
    members[carrier_id] = Member(carrier_id, name, "carrier",
                                 *_body(carrier_raw, carrier_radius, f"{path}.carrier", fail),
                                 support=_support(carrier_raw["support"]), reference_radius=carrier_radius)
    first_planet_gear = next(iter(planet_gears.values()))
    planet_mass, planet_inertia = _body(planet_raw, first_planet_gear.base_radius, f"{path}.planet", fail,
                                        first_planet_gear)
    for k, psi in enumerate(angles):
        pid = f"{name}.planet{k + 1}"
        members[pid] = Member(pid, name, "planet", planet_mass, planet_inertia,
                              bearing=None if rv else _support(planet_raw["bearing"]), gears=dict(planet_gears),
                              angle=psi, radius=carrier_radius, reference_radius=first_planet_gear.pitch_radius)
    return members


def _stage_meshes(st: dict, centrals: dict, planet_gears: dict, geoms: dict, planet_ids, path: str,
                  fail) -> list[MeshSpec]:
    """Every central gear's mesh with every planet, its stiffness model, damping, backlash and transmission error
    checked (a central gear's [mesh] over the stage's)."""
    name = st["name"]
    layers = [(st["mesh"], f"{path}.mesh")] + [(c[2]["mesh"], f"{path}.{k}.mesh") for k, c in centrals.items()]
    idealised = any(gear.idealised for gear, _, _ in centrals.values())
    for layer, lpath in layers:
        if layer and layer["stiffness"] is not None:
            _check_stiffness(layer["stiffness"], f"{lpath}.stiffness", fail)
        if layer and idealised:
            _check_idealised_mesh(layer, lpath, fail)
    meshes = []
    for key, (gear, pg, raw) in centrals.items():
        mesh = _merge_mesh(st["mesh"], raw["mesh"])
        mpath = f"{path}.{key}.mesh"
        if mesh["stiffness"] is None:
            raise fail(f"{mpath}.stiffness", "missing required field (give it here or in the stage's [mesh])")
        damping = mesh["damping"] or {"ratio": None, "coefficient": None}
        if damping["ratio"] is not None and damping["coefficient"] is not None:
            raise fail(f"{mpath}.damping", "give ratio or coefficient, not both")
        ste = tuple((s["harmonic"], s["amplitude"], s["phase"]) for s in mesh["ste"])
        if not gear.idealised:  # an idealised gear has no module to measure backlash by
            _check_small(mesh["backlash"] or 0.0, MAX_BACKLASH, gear.module, f"{mpath}.backlash_um", "backlash",
                         fail)
        if mesh["backlash"] and (gear.relief_amount or planet_gears[pg].relief_amount):
            raise fail(f"{mpath}.backlash_um", "a mesh with tip relief is modelled on its drive flanks only: give "
                                               "it no backlash")
        for j, (_, amplitude, _) in enumerate(ste):
            _check_small(amplitude, MAX_ERROR, gear.module, f"{mpath}.ste[{j}].amplitude_um",
                         "transmission error amplitude", fail)
        for k, pid in enumerate(planet_ids):
            meshes.append(MeshSpec(
                id=f"{pid}.{key}", stage=name, central=f"{name}.{key}", planet=pid, central_gear=gear,
                planet_gear=planet_gears[pg], geometry=geoms[key], stiffness=dict(mesh["stiffness"]),
                damping_ratio=damping["ratio"], damping_coefficient=damping["coefficient"],
                backlash=mesh["backlash"] or 0.0, ste=ste, planet_index=k,
                stated_tilt=(mesh.get("tilting_stiffness"), mesh.get("centre_offset")),
            ))
    return meshes


def _check_idealised_mesh(mesh: dict, path: str, fail) -> None:
    """A [mesh] table of an idealised stage (no teeth): a stiffness model that needs no tooth geometry, and no
    transmission error (harmonics of a mesh cycle it does not have)."""
    model = MODELS[mesh["stiffness"]["model"]] if mesh["stiffness"] is not None else None
    if model is not None and model.needs_teeth:
        toothless = ", ".join(name for name, m in MODELS.items() if not m.needs_teeth)
        raise fail(f"{path}.stiffness.model", f"{model.name!r} needs tooth geometry; an idealised mesh (no teeth) "
                                              f"needs {toothless}")
    if mesh["ste"]:
        raise fail(f"{path}.ste", "an idealised mesh (no teeth) has no mesh cycle for transmission error harmonics")


def _cycloid_stage(st: dict, members: dict, angles, carrier_radius: float, path: str, fail) -> CycloidStage:
    """Crankshaft, disc and pin-wheel members of an RV reducer's stage (added to ``members``) and its
    cycloid-pin stage, its geometry checked."""
    name, crank, cyc = st["name"], st["crank"], st["cycloid"]
    geometry = CycloidGeometry(lobes=cyc["lobes"], pins=cyc["pins"], eccentricity=crank["eccentricity"],
                               pin_circle_radius=cyc["pin_circle_radius"], pin_radius=cyc["pin_radius"],
                               contact_length=cyc["thickness"])
    problem = cycloid_problem(geometry)
    if problem:
        field_name, message = problem
        raise fail(f"{path}.{CYCLOID_FIELDS[field_name]}", message)
    n_discs = cyc["discs"]
    if cyc["phases"] is None:
        phases = tuple(2.0 * math.pi * j / n_discs for j in range(n_discs))
    else:
        if len(cyc["phases"]) != n_discs:
            raise fail(f"{path}.cycloid.phases_deg", f"has {len(cyc['phases'])} angles for {n_discs} discs")
        phases = tuple(cyc["phases"])
    cranks = []
    for k, psi in enumerate(angles):
        cid = f"{name}.crank{k + 1}"
        cranks.append(cid)
        members[cid] = Member(cid, name, "crank", crank["mass"], crank["inertia"],
                              bearing=Support(crank["bearing"]["radial_stiffness"], crank["bearing"]["radial_damping"]),
                              angle=psi, radius=carrier_radius, reference_radius=geometry.eccentricity)
    discs = []
    for j in range(n_discs):
        did = f"{name}.disc{j + 1}"
        discs.append(did)
        members[did] = Member(did, name, "disc", cyc["mass"], cyc["inertia"], reference_radius=geometry.rolling_radius,
                              eccentric=Eccentric(cranks[0], phases[j], geometry.eccentricity))
    wheel = None
    if st["pin_wheel"] is not None:
        wheel = f"{name}.pin_wheel"
        raw = st["pin_wheel"]
        members[wheel] = Member(wheel, name, "pin_wheel", raw["mass"], raw["inertia"],
                                support=_support(raw["support"]), reference_radius=geometry.pin_circle_radius)
    spline = crank["spline"]
    contact = cyc["contact"]
    return CycloidStage(
        name, geometry, phases, tuple(cranks), tuple(discs), wheel,
        Support(spline["radial_stiffness"], spline["radial_damping"], spline["torsional_stiffness"],
                spline["torsional_damping"]),
        Support(cyc["bearing"]["radial_stiffness"], cyc["bearing"]["radial_damping"]),
        contact["stiffness"], contact["damping"], contact["clearance"])


SPUR_ONLY_STIFFNESS = {"rectangular": "its wave counts tooth pairs from the transverse contact ratio alone",
                       "energy": "its energy method slices spur teeth"}


def _check_helical(st: dict, centrals, meshes, path: str, fail) -> None:
    """A helical stage's members move axially: each needs an axial support (else its axial motion is free and
    the meshes' axial forces push it away), and its meshes a stiffness model that sees the helix."""
    _check_axial(st, centrals, path, fail, "a helical stage needs it > 0: the meshes' axial forces act on every "
                                           "member", "a helical stage needs it > 0: the sun and ring meshes push "
                                                     "each planet axially")
    for mesh in meshes:
        model = mesh.stiffness["model"]
        if model in SPUR_ONLY_STIFFNESS:
            key = mesh.central.split(".")[-1]
            raise fail(f"{path}.{key}.mesh.stiffness.model", f"{model!r} is for spur gears "
                                                            f"({SPUR_ONLY_STIFFNESS[model]}); a helical mesh "
                                                            "needs 'contact-line' or 'constant'")


def _check_axial(st: dict, centrals, path: str, fail, why: str, planet_why: str | None = None) -> None:
    """Every member of a stage whose members slide axially has an axial support or bearing (else that motion is
    free): refused naming the first without, and ``why`` (``planet_why`` for the planets' bearing)."""
    for key in list(centrals) + ["carrier"]:
        if not st[key]["support"]["axial_stiffness"]:
            raise fail(f"{path}.{key}.support.axial_stiffness", why)
    if not st["planet"]["bearing"]["axial_stiffness"]:
        raise fail(f"{path}.planet.bearing.axial_stiffness", planet_why or why)


def _check_small(value: float, limit: float, module: float, path: str, what: str, fail) -> None:
    """A deviation from the perfect mesh (backlash, transmission error, eccentricity) well below the
    teeth: at ``limit`` modules the teeth would leave each other's flanks or hit the mate's tip."""
    if value > limit * module:
        raise fail(path, f"{what} {value * 1e6:.4g} µm is over {limit:g} of the module {module * 1e3:.4g} mm: "
                         "no tooth pair stays on its flanks")


def _check_stiffness(params: dict, path: str, fail):
    """Check a ``stiffness`` table against its model's parameter table; store SI values in place."""
    name = params["model"]
    if name not in MODELS:
        raise fail(f"{path}.model", f"must be one of {', '.join(MODELS)}; got {name!r}{did_you_mean(name, MODELS)}")
    values = {k: v for k, v in params.items() if k != "model"}
    checked = MODELS[name].parameters.parse(values, path, Context(fail("", "").source))
    params.clear()
    params.update({"model": name, **checked})


def _assembly_number(a: tuple[Gear, Gear], b: tuple[Gear, Gear]) -> tuple[int, int]:
    """Numerator and denominator of the planet-spacing condition for central gears a, b.

    Each argument is (central gear, planet gear it meshes).  A planet can be placed at
    angle psi when psi/(2 pi) * (z_A z_b +/- z_B z_a) / gcd(z_a, z_b) is an integer:
    '+' for a sun and a ring, '-' for two gears of the same kind.  Simple planets
    (z_a = z_b) reduce this to the classical (z_s + z_r) psi / (2 pi) integer.
    """
    (ga, pa), (gb, pb) = a, b
    sign = 1 if ga.internal != gb.internal else -1
    num = ga.teeth * pb.teeth + sign * gb.teeth * pa.teeth
    return abs(num), gcd(pa.teeth, pb.teeth)


def _check_assembly(centrals, planet_gears, angles, equally, n, path, fail):
    keys = list(centrals)
    for i in range(len(keys)):
        for j in range(i + 1, len(keys)):
            ga, pa, _ = centrals[keys[i]]
            gb, pb, _ = centrals[keys[j]]
            num, den = _assembly_number((ga, planet_gears[pa]), (gb, planet_gears[pb]))
            for k, psi in enumerate(angles):
                count = psi / (2 * math.pi) * num / den
                if abs(count - round(count)) > 1e-6:
                    if equally:
                        simple = len(planet_gears) == 1 and ga.internal != gb.internal
                        formula = (f"(z_s + z_r)/N = {num // den}/{n}" if simple
                                   else f"{num}/({den}·{n})")
                        raise fail(f"{path}.planets", f"{n} equally spaced planets cannot be assembled: "
                                                      f"{formula} is not an integer")
                    raise fail(f"{path}.planet_angles_deg[{k}]",
                               f"planet at {math.degrees(psi):.4f} deg cannot mesh with both "
                               f"{keys[i]} and {keys[j]}: psi/360·{num}/{den} = {count:.4f} is not an integer")


def _check_collision(planet_gears, angles, carrier_radius, path, fail):
    tip = max(g.tip_radius for g in planet_gears.values())
    order = sorted(angles)
    n = len(order)
    if n < 2:
        return
    for k in range(n):
        gap = (order[(k + 1) % n] - order[k]) % (2 * math.pi) or 2 * math.pi
        chord = 2.0 * carrier_radius * math.sin(gap / 2.0)
        if chord <= 2.0 * tip:
            raise fail(f"{path}.planets", f"adjacent planets collide: centre spacing {chord * 1e3:.3f} mm "
                                          f"<= tip diameter {2 * tip * 1e3:.3f} mm")
