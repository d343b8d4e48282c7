"""Declarative schema of the train file (TOML).

The schema is data: each field knows its type, unit, bounds, default and a one-line
documentation string.  One walker (:func:`parse`) checks a parsed TOML document
against it, converts suffixed units (``_mm``, ``_um``, ``_deg``, ``_rpm``) to SI once,
fills defaults and returns plain dictionaries keyed by the SI names (the suffix
dropped).  The README's field reference is generated from the same objects
(:func:`markdown_reference`), so documentation and validation cannot drift apart.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from gearcheck.shared.citations import REFERENCES
from gearcheck.shared.errors import TrainFileError, did_you_mean, shown
from gearcheck.shared.units import MAX_RPM, RAD_S_PER_RPM, SUFFIXES

REQUIRED = object()


class Context:
    """Where the document came from, for error messages."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, path: str, message: str) -> TrainFileError:
        return TrainFileError(self.source, path, message)


def _si_name(key: str) -> tuple[str, float]:
    for suffix, (_, factor) in SUFFIXES.items():
        if key.endswith(suffix):
            return key[: -len(suffix)], factor
    return key, 1.0


@dataclass(frozen=True)
class Number:
    """A real number in [minimum, maximum] (``minimum`` exclusive when ``strict``), in the file's unit.

    Every number of a train file is bounded: past the bounds it is no gear train any more, and the
    solvers' arithmetic overflows (:data:`LIMITS` says why each bound is where it is)."""

    doc: str
    unit: str = ""
    default: Any = REQUIRED
    minimum: float | None = None
    strict: bool = False
    maximum: float | None = None

    def parse(self, value, path: str, ctx: Context) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ctx.fail(path, f"must be a number, got {shown(value)}")
        try:
            value = float(value)
        except OverflowError:  # a TOML integer past the largest float
            raise ctx.fail(path, f"must be finite, got {shown(value)}") from None
        unit = f" {self.unit}" if self.unit not in ("", "-") else ""
        if not math.isfinite(value):
            raise ctx.fail(path, f"must be finite, got {value}")
        if self.minimum is not None:
            if self.strict and value <= self.minimum:
                raise ctx.fail(path, f"must be > {self.minimum:g}{unit}, got {value:g}")
            if not self.strict and value < self.minimum:
                raise ctx.fail(path, f"must be >= {self.minimum:g}{unit}, got {value:g}")
        if self.maximum is not None and value > self.maximum:
            raise ctx.fail(path, f"must be <= {self.maximum:g}{unit}, got {value:g}")
        return value

    def type_name(self) -> str:
        return "number"

    def range_text(self) -> str:
        low = "" if self.minimum is None else f"{self.minimum:g} {'<' if self.strict else '≤'} "
        high = "" if self.maximum is None else f" ≤ {self.maximum:g}"
        return f"{low}x{high}" if low or high else ""


LIMITS = {
    # name: (upper bound in SI, why); fields state it in their own unit with bound()
    "length": (20.0, "m: the largest gear rims are about 15 m across"),
    "module": (0.1, "m: the coarsest gears made (mill girth gears) have modules of about 0.05 m"),
    "displacement": (0.01, "m: an eccentricity, error or backlash of a centimetre is no gear mesh"),
    "mass": (1e6, "kg: a thousand tonnes, beyond any geared machine's single part"),
    "density": (3e4, "kg/m³: beyond the densest metal (osmium, 22 600)"),
    "inertia": (1e8, "kg·m²: a million kilograms at a 10 m radius"),
    "stiffness": (1e18, "N/m or N·m/rad: a steel block of 1 m² section and 0.2 µm length; 'rigid' is 1e16"),
    "damping": (1e12, "N·s/m or N·m·s/rad: critical damping of the stiffest part on the lightest one"),
    "speed": (MAX_RPM * RAD_S_PER_RPM, "rad/s (a million rpm): pitch-line speeds past 300 m/s are refused separately"),
    "torque": (1e9, "N·m: a hundred times the largest wind-turbine gearbox"),
    "frequency": (1e7, "Hz: far above any mesh harmonic"),
    "time": (1e4, "s: a ramp of hours is no start-up"),
    "teeth": (1000, "no cylindrical gear has more"),
    "planets": (32, "no planetary stage has more; they must also fit on the carrier circle"),
}


FLOORS = {
    # name: (lower bound in SI, why): below it the solvers' steps (sqrt(m/k)) and matrices degenerate
    "mass": (1e-9, "kg: a microgram, lighter than any gear of the finest module allowed"),
    "inertia": (1e-18, "kg·m²: a microgram at a micrometre"),
}


def floor(name: str) -> float:
    """The lower bound :data:`FLOORS` sets for a quantity, in SI."""
    return FLOORS[name][0]


def bound(name: str, unit_in_si: float = 1.0) -> float:
    """The upper bound :data:`LIMITS` sets for a quantity, in a unit worth ``unit_in_si`` SI units."""
    return LIMITS[name][0] / unit_in_si


MM, UM = 1e-3, 1e-6
MAX_TILT_URAD = 1e4  # a misalignment past 10 mrad is no small tilt (its sine and angle part by 2e-5)
MIN_MODULE_MM = 0.01  # the finest gears made (watches) have modules of about 0.05 mm


def Positive(doc: str, unit: str = "", default=REQUIRED, maximum: float | None = None) -> Number:
    return Number(doc, unit, default, minimum=0.0, strict=True, maximum=maximum)


def NonNegative(doc: str, unit: str = "", default=0.0, maximum: float | None = None) -> Number:
    return Number(doc, unit, default, minimum=0.0, maximum=maximum)


@dataclass(frozen=True)
class Integer:
    doc: str
    default: Any = REQUIRED
    minimum: int | None = None
    unit: str = ""
    maximum: int | None = None

    def parse(self, value, path: str, ctx: Context) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ctx.fail(path, f"must be an integer, got {shown(value)}")
        if self.minimum is not None and value < self.minimum:
            raise ctx.fail(path, f"must be an integer >= {self.minimum}, got {shown(value)}")
        if self.maximum is not None and value > self.maximum:
            raise ctx.fail(path, f"must be an integer <= {self.maximum}, got {shown(value)}")
        return value

    def type_name(self) -> str:
        return "integer"

    def range_text(self) -> str:
        low = "" if self.minimum is None else f"{self.minimum} ≤ "
        high = "" if self.maximum is None else f" ≤ {self.maximum}"
        return f"{low}n{high}" if low or high else ""


@dataclass(frozen=True)
class Text:
    doc: str
    default: Any = REQUIRED
    choices: tuple[str, ...] | None = None
    pattern: str | None = None
    unit: str = ""

    def parse(self, value, path: str, ctx: Context) -> str:
        if not isinstance(value, str):
            raise ctx.fail(path, f"must be a string, got {shown(value)}")
        if self.choices is not None and value not in self.choices:
            raise ctx.fail(path, f"must be one of {', '.join(self.choices)}; got {shown(value)}"
                                 + did_you_mean(value, self.choices))
        if self.pattern is not None and not re.fullmatch(self.pattern, value):
            raise ctx.fail(path, f"{shown(value)} is not of the form {self.pattern}")
        return value

    def type_name(self) -> str:
        return "string"


@dataclass(frozen=True)
class Flag:
    doc: str
    default: Any = REQUIRED
    unit: str = ""

    def parse(self, value, path: str, ctx: Context) -> bool:
        if not isinstance(value, bool):
            raise ctx.fail(path, f"must be true or false, got {shown(value)}")
        return value

    def type_name(self) -> str:
        return "boolean"


@dataclass(frozen=True)
class ListOf:
    item: Any
    doc: str
    default: Any = REQUIRED
    min_length: int = 0
    unit: str = ""
    max_length: int | None = None
    increasing: bool = False

    def parse(self, value, path: str, ctx: Context) -> list:
        if not isinstance(value, list):
            raise ctx.fail(path, f"must be a list, got {shown(value)}")
        if len(value) < self.min_length or (self.max_length is not None and len(value) > self.max_length):
            count = (f"{self.min_length}" if self.max_length == self.min_length
                     else f"at least {self.min_length}" if self.max_length is None
                     else f"{self.min_length} to {self.max_length}")
            raise ctx.fail(path, f"needs {count} entries, got {len(value)}")
        items = [self.item.parse(v, f"{path}[{i}]", ctx) for i, v in enumerate(value)]
        if self.increasing and any(b <= a for a, b in zip(items, items[1:])):
            raise ctx.fail(path, f"must increase, got {shown(value, 80)}")
        return items

    def type_name(self) -> str:
        return f"list of {self.item.type_name()}"


@dataclass(frozen=True)
class Table:
    """A TOML table with named fields; ``patterns`` admits extra keys matching a regex."""

    fields: dict[str, Any]
    doc: str = ""
    default: Any = REQUIRED
    patterns: tuple[tuple[str, Any], ...] = ()
    unit: str = ""
    open: bool = False  # extra keys are passed through unchecked (validated by a plug-in)
    pattern_label: str = "NAME"  # how pattern keys are shown in the documentation

    def parse(self, value, path: str, ctx: Context) -> dict:
        if not isinstance(value, dict):
            raise ctx.fail(path, f"must be a table, got {shown(value)}")
        out: dict[str, Any] = {}
        for key, raw in value.items():
            sub = f"{path}.{key}" if path else key
            spec = self.fields.get(key) or self._pattern_field(key)
            if spec is None:
                if self.open:
                    out[key] = raw
                    continue
                raise ctx.fail(sub, "unknown key" + did_you_mean(key, self.fields))
            name, factor = _si_name(key)
            parsed = spec.parse(raw, sub, ctx)
            out[name] = _scale(parsed, factor)
        for key, spec in self.fields.items():
            name, factor = _si_name(key)
            if name in out:
                continue
            if spec.default is REQUIRED:
                sub = f"{path}.{key}" if path else key
                raise ctx.fail(sub, "missing required field")
            if spec.default is not None:
                out[name] = _scale(_default(spec, f"{path}.{key}", ctx), factor)
            else:
                out[name] = None
        return out

    def _pattern_field(self, key: str):
        for regex, spec in self.patterns:
            if re.fullmatch(regex, key):
                return spec
        return None

    def type_name(self) -> str:
        return "table"


@dataclass(frozen=True)
class TableList:
    """A TOML array of tables (``[[name]]``)."""

    table: Table
    doc: str = ""
    default: Any = REQUIRED
    min_length: int = 0
    unit: str = ""

    def parse(self, value, path: str, ctx: Context) -> list[dict]:
        if not isinstance(value, list):
            raise ctx.fail(path, f"must be an array of tables ([[{path}]]), got {shown(value)}")
        if len(value) < self.min_length:
            raise ctx.fail(path, f"needs at least {self.min_length} entries, got {len(value)}")
        return [self.table.parse(v, f"{path}[{i}]", ctx) for i, v in enumerate(value)]

    def type_name(self) -> str:
        return "array of tables"


def _default(spec, path: str, ctx: Context):
    if isinstance(spec, Table):
        return spec.parse({}, path, ctx)
    if isinstance(spec, (TableList, ListOf)):
        return list(spec.default)
    return spec.default


def _scale(value, factor: float):
    if factor == 1.0 or value is None:
        return value
    if isinstance(value, list):
        return [_scale(v, factor) for v in value]
    return value * factor


# --------------------------------------------------------------------------------------
# The train file
# --------------------------------------------------------------------------------------

GEOMETRY = {
    "teeth": Integer("number of teeth (ring: internal teeth); omit, giving `base_radius_mm`, for an idealised gear "
                     "(see *Idealised stages*)", None, minimum=1, maximum=int(bound("teeth"))),
    "module_mm": Number("normal module m_n (a spur gear's module); defaults to the stage's module", "mm", None,
                        MIN_MODULE_MM, False, bound("module", MM)),
    "pressure_angle_deg": Number("normal pressure angle; defaults to the stage's", "deg", None, 0.0, True, 45.0),
    "face_width_mm": Number("face width; defaults to the stage's", "mm", None, MIN_MODULE_MM, False,
                            bound("length", MM)),
    "helix_angle_deg": Number("signed helix angle (positive: right hand); defaults to the stage's planets' angle, "
                              "negated for a sun", "deg", None, -45.0, False, 45.0),
    "addendum_coefficient": NonNegative("addendum h_a* in modules; defaults to the stage's", "-", None, 3.0),
    "dedendum_coefficient": NonNegative("dedendum h_f* in modules; defaults to the stage's", "-", None, 3.0),
    "profile_shift": Number("profile shift coefficient x (ring: positive moves the teeth outward)", "-", 0.0,
                            -3.0, False, 3.0),
    "base_radius_mm": Positive("base radius; derived from module, teeth and pressure angle unless given (an "
                               "idealised gear's only size)", "mm", None, bound("length", MM)),
    "eccentricity_um": NonNegative("eccentricity (run-out) of the gear's pitch circle", "µm", 0.0,
                                   bound("displacement", UM)),
    "eccentricity_phase_deg": Number("angle of the eccentricity at t = 0, in the member's own frame", "deg", 0.0,
                                     -3600.0, False, 3600.0),
    "installation_error_um": NonNegative("installation (position) error: offset of the gear's centre from its "
                                         "nominal place, fixed to its mount (the housing for a sun or ring, the "
                                         "carrier for a planet)", "µm", 0.0, bound("displacement", UM)),
    "installation_error_phase_deg": Number("direction of the installation error at t = 0, like the eccentricity's",
                                           "deg", 0.0, -3600.0, False, 3600.0),
    "axial_offset_mm": Number("axial position of the gear's face centre from its member's centre of mass (a "
                              "tilting stage: it places the mesh's centre of stiffness)", "mm", 0.0,
                              -bound("length", MM), False, bound("length", MM)),
    "tip_relief": Table(
        {
            "amount_um": NonNegative("material removed at the tip, normal to the flank (C_a)", "µm", REQUIRED,
                                     bound("displacement", UM)),
            "length_mm": Positive("roll length of the relief along the line of action, from the tip inward (L_a)",
                                  "mm", REQUIRED, bound("length", MM)),
            "shape": Text("how the relief grows towards the tip: (d/L_a)^1 or ^2", "linear", ("linear", "parabolic")),
        },
        "tip relief (profile modification) of the gear's teeth",
        default=None,
    ),
}

TORSIONAL = Flag("rotation only (Kahraman 1994's purely torsional level): a central member's translations are "
                 "held at zero, a planet rides rigidly on its carrier's pin; its support's or bearing's translational "
                 "stiffness and damping are ignored with a note (default: the stage's `torsional`)", None)

BODY = {
    "torsional": TORSIONAL,
    "mass": Number("mass; from `density` when not given", "kg", None, floor("mass"), False, bound("mass")),
    "inertia": Number("polar moment of inertia about the rotation axis", "kg·m²", None, floor("inertia"), False,
                      bound("inertia")),
    "inertia_over_r2": Number("I/r² with r the base radius (carrier: carrier radius); give this or `inertia`", "kg",
                              None, floor("mass"), False, bound("mass")),
    "density": Positive("material density: mass and inertia of an annulus, m = rho pi (r_o² - r_i²) b, "
                        "I = m (r_o² + r_i²)/2, wherever `mass` or `inertia` is not given (a given mass keeps "
                        "the annulus's radius of gyration)", "kg/m³", None,
                        bound("density")),
    "inner_radius_mm": NonNegative("inner radius of that annulus: a gear's bore (default 0), a ring's default its "
                                   "pitch radius", "mm", None, bound("length", MM)),
    "outer_radius_mm": Positive("outer radius of that annulus: a gear's default its pitch radius; a ring and a "
                                "carrier need it", "mm", None, bound("length", MM)),
    "thickness_mm": Positive("axial length of that annulus: a gear's default its face width; a carrier needs it "
                             "(its plates together)", "mm", None, bound("length", MM)),
    "tilting_inertia": Number("moment of inertia about a diameter through the centre of mass (a tilting stage); "
                              "default I/2 + m w²/12 with w the thickness (a gear's face width), exact for an "
                              "annulus", "kg·m²", None, floor("inertia"), False, bound("inertia")),
}

STATION = Table(
    {
        "position_mm": Number("axial position of the bearing station from the member's centre of mass", "mm",
                              REQUIRED, -bound("length", MM), False, bound("length", MM)),
        "share": Number("its share of the radial stiffness and damping (the shares sum to 1)", "-", REQUIRED, 0.0,
                        True, 1.0),
    },
    "a bearing station along the axis (a tilting stage)",
)


def _tilting(what: str) -> dict:
    """The keys of a support or bearing that hold a tilting member's tilt (Eritenel & Parker 2009's 3-D model)."""
    return {
        "tilting_stiffness": NonNegative(f"tilting stiffness {what} (a tilting stage: this, or stations at two "
                                         "positions, holds each tilt)", "N·m/rad", 0.0, bound("stiffness")),
        "tilting_damping": NonNegative(f"tilting damping {what}", "N·m·s/rad", 0.0, bound("damping")),
        "stations": TableList(STATION, "bearing stations along the axis over which the radial stiffness and damping "
                                       "are shared (a tilting stage; default: all at the centre of mass)",
                              default=()),
    }


SUPPORT = Table(
    {
        "radial_stiffness": Positive("stiffness of the bearing/support in x and in y (isotropic; rolling bearings "
                                     "1e8-1e9)", "N/m", REQUIRED, bound("stiffness")),
        "radial_damping": NonNegative("damping of the bearing/support in x and y (0 is noted at load; a damping "
                                      "ratio of 1-5 %: c = 2 zeta sqrt(k m), some hundreds to thousands)", "N·s/m",
                                      0.0, bound("damping")),
        "torsional_stiffness": NonNegative("torsional stiffness to the housing (0 = free rotation; a held member "
                                           "needs it, e.g. 1e7-1e9)", "N·m/rad", 0.0, bound("stiffness")),
        "torsional_damping": NonNegative("torsional damping to the housing", "N·m·s/rad", 0.0, bound("damping")),
        "axial_stiffness": NonNegative("axial stiffness to the housing (helical stages need it)", "N/m", 0.0,
                                       bound("stiffness")),
        "axial_damping": NonNegative("axial damping to the housing", "N·s/m", 0.0, bound("damping")),
        **_tilting("to the housing"),
        "tilt_urad": ListOf(Number("tilt", "µrad", REQUIRED, -MAX_TILT_URAD, False, MAX_TILT_URAD),
                            "misalignment of its seat in the housing, [about x, about y] (a tilting stage): the "
                            "support holds the member there", (), min_length=2, max_length=2, unit="µrad"),
    },
    "support of a central member (sun, ring, carrier) on the housing",
)

PLANET_BEARING = Table(
    {
        "radial_stiffness": Positive("stiffness of the planet bearing, radial and tangential (1e8-1e9)", "N/m",
                                     REQUIRED, bound("stiffness")),
        "radial_damping": NonNegative("damping of the planet bearing (0 is noted at load)", "N·s/m", 0.0,
                                      bound("damping")),
        "axial_stiffness": NonNegative("axial stiffness of the planet on its pin (helical stages need it)", "N/m",
                                       0.0, bound("stiffness")),
        "axial_damping": NonNegative("axial damping of the planet bearing", "N·s/m", 0.0, bound("damping")),
        **_tilting("of the planet on its pin"),
    },
    "planet bearing on the carrier pin (an RV reducer's planets sit on their crankshafts instead)",
    default=None,
)

STIFFNESS = Table(
    {
        "model": Text("mesh stiffness model; its parameters are listed under *Mesh stiffness models*",
                      "rectangular"),
    },
    "time-varying mesh stiffness model and its parameters (checked by the model's own table)",
    default=None,
    open=True,
)

DAMPING = Table(
    {
        "ratio": NonNegative("damping ratio ζ: c = 2ζ·sqrt(k_mean·m_eq), m_eq of the gear pair (at most critical: "
                             "measured mesh damping ratios are 0.02-0.17)", "-", None, 1.0),
        "coefficient": NonNegative("mesh damping coefficient (instead of ratio)", "N·s/m", None, bound("damping")),
    },
    "mesh damping",
    default=None,
)

STE = Table(
    {
        "harmonic": Integer("harmonic of the mesh frequency", minimum=1, maximum=1000),
        "amplitude_um": NonNegative("amplitude along the line of action", "µm", REQUIRED, bound("displacement", UM)),
        "phase_deg": Number("phase of this harmonic (added to the mesh phase)", "deg", 0.0, -3600.0, False, 3600.0),
    },
    "static transmission error harmonic",
)

MESH = Table(
    {
        "stiffness": STIFFNESS,
        "damping": DAMPING,
        "backlash_um": NonNegative("total backlash 2b along the line of action (dead zone ±b)", "µm", None,
                                   bound("displacement", UM)),
        "ste": TableList(STE, "static transmission error: harmonic series at the mesh frequency", default=()),
        "tilting_stiffness": Positive("the mesh's stiffness against the gears' relative tilt across the face (a "
                                      "tilting stage; default k_mean w²/12, its mean stiffness spread evenly over "
                                      "the w of the faces' overlap)", "N·m/rad", None, bound("stiffness")),
        "centre_offset_mm": Number("axial position of the mesh's centre of stiffness from the members' centres of "
                                   "mass (a tilting stage; default the middle of the faces' overlap, which it must "
                                   "lie in)", "mm", None, -bound("length", MM), False, bound("length", MM)),
    },
    "mesh properties; a stage-level [stages.mesh] gives defaults for its central gears",
    default=None,
)

CENTRAL_GEAR = Table(
    {
        **GEOMETRY,
        **BODY,
        "support": SUPPORT,
        "planet_gear": Text("name of the planet gear it meshes with (compound planets)", None),
        "mesh": MESH,
    },
    "a central gear: sun (external) or ring (internal)",
    default=None,
)

CARRIER = Table({**BODY, "support": SUPPORT}, "the planet carrier")

PLANET_GEAR = Table({k: v for k, v in GEOMETRY.items()}, "one gear of a compound planet")

PLANET = Table(
    {
        **{k: v for k, v in GEOMETRY.items() if k != "teeth"},
        "teeth": Integer("teeth of a simple planet (omit when `gears` is given, or for an idealised planet)", None, 1,
                         maximum=int(bound("teeth"))),
        **BODY,
        "bearing": PLANET_BEARING,
        "pin_tilts_urad": ListOf(ListOf(Number("tilt", "µrad", REQUIRED, -MAX_TILT_URAD, False, MAX_TILT_URAD),
                                        "[about the planet's radial axis, about its tangential axis]", min_length=2,
                                        max_length=2, unit="µrad"),
                                 "misalignment of each planet's pin in the carrier (a tilting stage), one pair per "
                                 "planet: its bearing's rest tilt", (), unit="µrad"),
        "gears": Table({}, "compound planet: named gears, e.g. [stages.planet.gears.f]", None,
                       patterns=((r"[A-Za-z][A-Za-z0-9_]*", PLANET_GEAR),), pattern_label="NAME"),
    },
    "the planets of the stage (all identical)",
)

def _bearing(doc: str) -> Table:
    return Table(
        {
            "radial_stiffness": Positive("stiffness in each of two perpendicular directions (isotropic)", "N/m",
                                         REQUIRED, bound("stiffness")),
            "radial_damping": NonNegative("damping in each of those directions", "N·s/m", 0.0, bound("damping")),
        },
        doc,
    )


CRANK = Table(
    {
        "mass": Number("mass of one crankshaft", "kg", REQUIRED, floor("mass"), False, bound("mass")),
        "inertia": Number("polar moment of inertia of one crankshaft about its axis", "kg·m²", REQUIRED,
                          floor("inertia"), False, bound("inertia")),
        "eccentricity_mm": Positive("eccentricity e of its eccentrics: the radius of the cycloid discs' orbit", "mm",
                                    REQUIRED, bound("length", MM)),
        "bearing": _bearing("the crankshaft's support bearings in the carrier, taken together"),
        "spline": Table(
            {
                "radial_stiffness": Positive("bending stiffness between planet and crankshaft, radial and "
                                             "tangential", "N/m", REQUIRED, bound("stiffness")),
                "radial_damping": NonNegative("damping of that bending", "N·s/m", 0.0, bound("damping")),
                "torsional_stiffness": Positive("torsional stiffness between planet and crankshaft", "N·m/rad",
                                                REQUIRED, bound("stiffness")),
                "torsional_damping": NonNegative("torsional damping", "N·m·s/rad", 0.0, bound("damping")),
            },
            "the planet's connection to its crankshaft (spline and shaft)",
        ),
    },
    "RV reducer: one crankshaft per planet, at the planet's place on the carrier, carrying the planet and one "
    "eccentric per cycloid disc ([stages.crank]); needs [stages.cycloid]",
    default=None,
)

CYCLOID = Table(
    {
        "discs": Integer("number of cycloid discs", 2, 1, maximum=8),
        "phases_deg": ListOf(Number("angle", "deg", REQUIRED, -3600.0, False, 3600.0),
                             "angle of each disc's eccentric from the first disc's (default equally spaced)", None,
                             unit="deg"),
        "lobes": Integer("teeth (lobes) of each disc, Z_c", REQUIRED, 3, maximum=int(bound("teeth"))),
        "pins": Integer("pins of the pin wheel, Z_p = Z_c + 1", REQUIRED, 4, maximum=int(bound("teeth"))),
        "pin_circle_radius_mm": Positive("radius of the circle of the pin centres, R_p", "mm", REQUIRED,
                                         bound("length", MM)),
        "pin_radius_mm": Positive("radius of a pin (or of its roller), r_rp", "mm", REQUIRED, bound("length", MM)),
        "thickness_mm": Positive("thickness of a disc: the length of each pin contact", "mm", REQUIRED,
                                 bound("length", MM)),
        "mass": Number("mass of one disc", "kg", REQUIRED, floor("mass"), False, bound("mass")),
        "inertia": Number("polar moment of inertia of one disc", "kg·m²", REQUIRED, floor("inertia"), False,
                          bound("inertia")),
        "bearing": _bearing("the needle (turning-arm) bearing between each eccentric and its disc"),
        "contact": Table(
            {
                "stiffness": Positive("stiffness of one pin contact along its normal (default: Palmgren's line "
                                      "contact linearised at the largest pin force of the rated load)", "N/m", None,
                                      bound("stiffness")),
                "damping": NonNegative("damping of one pin contact while it touches", "N·s/m", 0.0,
                                       bound("damping")),
                "clearance_um": NonNegative("gap between each pin and the disc profile at the nominal position "
                                            "(profile modification)", "µm", 0.0, bound("displacement", UM)),
            },
            "the pin contacts: compression only, one per pin and disc",
            default={},
        ),
    },
    "RV reducer: the cycloid-pin stage driven by the cranks' eccentrics, its discs turning with the carrier "
    "([stages.cycloid]); needs [stages.crank]",
    default=None,
)

PIN_WHEEL = Table(
    {
        "mass": Number("mass of the pin wheel with its pins", "kg", REQUIRED, floor("mass"), False, bound("mass")),
        "inertia": Number("polar moment of inertia of the pin wheel", "kg·m²", REQUIRED, floor("inertia"), False,
                          bound("inertia")),
        "support": SUPPORT,
    },
    "the pin wheel (the housing's pins) on a support; without this table it is rigid and fixed",
    default=None,
)

STAGE = Table(
    {
        "name": Text("stage name, used in member references (`stage1.sun`)", REQUIRED, pattern=r"[A-Za-z0-9_\-]+"),
        "planets": Integer("number of planets", minimum=1, maximum=int(bound("planets"))),
        "carrier_radius_mm": Positive("radius of the planet pins: checked against the operating centre distance "
                                      "the gears mesh at, which it must be (to 1 µm)", "mm", None,
                                      bound("length", MM)),
        "planet_angles_deg": ListOf(Number("angle", "deg", REQUIRED, -3600.0, False, 3600.0),
                                    "planet angles (default: equally spaced)", None,
                                    unit="deg"),
        "module_mm": Number("default normal module of the stage's gears", "mm", None, MIN_MODULE_MM, False,
                            bound("module", MM)),
        "pressure_angle_deg": Number("default normal pressure angle", "deg", 20.0, 0.0, True, 45.0),
        "helix_angle_deg": Number("signed helix angle of the planets (positive: right hand); suns get its negative, "
                                  "rings the same; each member gains an axial degree of freedom", "deg", 0.0, -45.0,
                                  False, 45.0),
        "face_width_mm": Number("default face width", "mm", None, MIN_MODULE_MM, False, bound("length", MM)),
        "addendum_coefficient": NonNegative("default addendum coefficient h_a*", "-", 1.0, 3.0),
        "dedendum_coefficient": NonNegative("default dedendum coefficient h_f*", "-", 1.25, 3.0),
        "torsional": Flag("every member of the stage rotation only (see the members' `torsional`), unless a member "
                          "says otherwise", False),
        "tilting": Flag("every member of the stage tilts: two small rotations about its translation axes beside "
                        "its translations, rotation and axial motion (Eritenel & Parker 2009's 3-D model); each "
                        "tilt needs a tilting stiffness or bearing stations", False),
        "mesh": MESH,
        "carrier": CARRIER,
        "planet": PLANET,
        "sun": CENTRAL_GEAR,
        "ring": CENTRAL_GEAR,
        "crank": CRANK,
        "cycloid": CYCLOID,
        "pin_wheel": PIN_WHEEL,
    },
    "a planetary stage ([[stages]]); extra central gears may be named sun_* or ring_*",
    patterns=((r"(sun|ring)_[A-Za-z0-9_]+", CENTRAL_GEAR),),
    pattern_label="sun_NAME / ring_NAME",
)

RIPPLE = Table(
    {
        "member": Text("which torque it modulates", REQUIRED, ("input", "output")),
        "order": Positive("frequency as a multiple of that member's rotation frequency", "-", None, 1e4),
        "frequency_hz": Positive("frequency (instead of order)", "Hz", None, bound("frequency")),
        "amplitude": NonNegative("amplitude as a fraction of the mean torque", "-", REQUIRED, 100.0),
        "phase_deg": Number("phase", "deg", 0.0, -3600.0, False, 3600.0),
    },
    "harmonic torque ripple ([[operating.ripple]])",
)

def _points(what: str, unit: str, maximum: float) -> ListOf:
    pair = ListOf(Number(f"time (s) or {what} ({unit})", "", REQUIRED, -maximum, False, maximum),
                  f"(time s, {what} {unit})", REQUIRED, 2, max_length=2)
    return ListOf(pair, f"{what} history as (time s, {unit}) points from 0 s on, joined by straight lines, the last "
                        "held", None, 1, unit=f"s, {unit}", max_length=1_000_000)


HISTORY_START = ("steady", "rest")  # where an operating history starts

HISTORY = Table(
    {
        "speed_points": _points("input speed", "rpm", bound("speed", RAD_S_PER_RPM) / RAD_S_PER_RPM),
        "speed_file": Text("CSV or Parquet file (relative to the train file) of time, input speed: the header's "
                           "unit suffixes (time_s, speed_rpm, speed_rad_s) or s and rpm", None),
        "speed_expression": Text("input speed in rpm as an expression of t in s (grammar of torque_expression); "
                                 "needs until_s", None),
        "torque_points": _points("input torque", "N·m", bound("torque")),
        "torque_file": Text("CSV or Parquet file of time, input torque (time_s, torque_Nm or torque_kNm)", None),
        "torque_expression": Text("input torque in N·m as an expression of t in s; needs until_s", None),
        "load_points": _points("output load", "N·m", bound("torque")),
        "load_file": Text("CSV or Parquet file of time, output load torque (opposing the output's rotation)", None),
        "load_expression": Text("output load torque in N·m as an expression of t in s", None),
        "start": Text("steady: from the steady state at the initial speed; rest: everything at rest, undeformed "
                      "(default: rest when the history starts at 0 rpm or from a torque, else steady)", None,
                      HISTORY_START),
        "until_s": Positive("where a history given by expressions ends", "s", None, bound("time")),
    },
    "operating history: a prescribed input speed (through the input shaft) or input torque (the speed follows "
    "from the rigid train), and the output load, as functions of time ([operating.history])",
    default=None,
)

OPERATING = Table(
    {
        "input_speed_rpm": NonNegative("nominal input speed (positive = counter-clockwise seen from +z); 0 for "
                                       "modal work only (modes, campbell, mac): a time run needs the train turning",
                                       "rpm", REQUIRED, bound("speed", RAD_S_PER_RPM)),
        "output_torque": NonNegative("load torque on the output member, opposing its rotation (default 0, or "
                                     "from `input_torque`)", "N·m", None, bound("torque")),
        "input_torque": NonNegative("torque the input delivers, instead of `output_torque`: the load is this times "
                                    "the ratio (losses aside)", "N·m", None, bound("torque")),
        "input_shaft_stiffness": Positive(
            "torsional stiffness of the input shaft to a reference turning at the nominal speed "
            "(omit for a torque-driven input with a rigid-body mode)", "N·m/rad", None, bound("stiffness")),
        "input_shaft_damping": NonNegative("damping of the input shaft", "N·m·s/rad", 0.0, bound("damping")),
        "ripple": TableList(RIPPLE, "torque ripple harmonics", default=()),
        "torque_function": Text("Python `module:function` f(t) -> N·m added to the input torque: code, run only "
                                "with `--trust MODULE` (a table or `ripple` needs none)", None,
                                pattern=r"[A-Za-z_][\w.]*:[A-Za-z_]\w*"),
        "torque_expression": Text("f(t) -> N·m added to the input torque, written as an expression of t in s: "
                                  "numbers, + - * / **, comparisons, sin cos tan exp log sqrt abs tanh sign floor "
                                  "min max, pi, e (data, not code: no --trust)", None),
        "torque_csv": Text("CSV file (relative to the train file) of time [s], torque [N·m] added to the input "
                           "torque, repeated with the file's period", None),
        "ramp_s": NonNegative("duration of the smooth start-up ramp of the load torque (0 = start at the "
                              "static deflection)", "s", 0.0, bound("time")),
        "history": HISTORY,
    },
    "operating point",
)

COUPLING = Table(
    {
        "name": Text("coupling name", REQUIRED, pattern=r"[A-Za-z0-9_\-]+"),
        "kind": Text("what it is (ring: two stages' rings joined into one, by a stiff coupling)", "spline",
                     ("spline", "shaft", "ring")),
        "from": Text("first member (`stage1.carrier`)", REQUIRED),
        "to": Text("second member (`stage2.sun`)", REQUIRED),
        "torsional_stiffness": Positive("torsional stiffness", "N·m/rad", REQUIRED, bound("stiffness")),
        "torsional_damping": NonNegative("torsional damping", "N·m·s/rad", 0.0, bound("damping")),
        "radial_stiffness": NonNegative("radial stiffness in x and y (0 = torsional only)", "N/m", 0.0,
                                        bound("stiffness")),
        "radial_damping": NonNegative("radial damping", "N·s/m", 0.0, bound("damping")),
    },
    "a coupling between members of different stages ([[couplings]])",
)

MEASUREMENT = Table(
    {
        "quantity": Text("a cross-check quantity name (`stage1.ring.ay.world`, see README)"),
        "metric": Text("which statistic of the steady window", REQUIRED, ("peak", "rms", "peak_to_peak")),
        "value": Number("the measured value, in the quantity's SI unit", "", REQUIRED, -1e12, False, 1e12),
        "speed_rpm": Positive("input speed the value was measured at (attached only at that speed)", "rpm", None,
                              bound("speed", RAD_S_PER_RPM)),
        "sensor_band_hz": ListOf(Positive("frequency", "Hz", REQUIRED, bound("frequency")),
                                 "band [low, high] of the measuring chain, applied to "
                                 "both solvers' series before the statistic", None, 2, unit="Hz", max_length=2,
                                 increasing=True),
        "uncertainty": Positive("relative standard uncertainty of the value (calibration weights)", "-", 0.1, 10.0),
        "published_model": Number("the value the source's own model gave (shown beside both solvers)", "", None,
                                  -1e12, False, 1e12),
        "source": Text("where the value comes from", ""),
    },
    "a measured reference value ([[measurements]])",
)

MAX_MODES = 10000  # a lumped train's coordinates: 32 planets of 6 stages with every axis are under 2000
MODE_TYPES = ("rotational", "translational", "planet", "mixed", "elastic")  # gearcheck.shared.modal.mode_types

NATURAL_FREQUENCY = Table(
    {
        "frequency_hz": Positive("the measured natural frequency", "Hz", REQUIRED, bound("frequency")),
        "mode": Integer("the model mode it is, numbered as `gearcheck modes` lists them (1: the lowest)", None, 1,
                        maximum=MAX_MODES),
        "type": Text("the type of the model mode it is (Lin & Parker 1999), with `order`", None, MODE_TYPES),
        "order": Integer("which frequency of that type, counted from the lowest (a multiple one once)", None, 1,
                         maximum=MAX_MODES),
        "shape": Table({}, "the measured mode shape over the train's coordinates (`stage.member.dof`), compared "
                           "by MAC; alone, it pairs with the model mode of largest MAC", None,
                       patterns=((r"[\w\-]+(\.[\w\-]+)+", Number("shape amplitude", "", REQUIRED, -1e12, False,
                                                                    1e12)),), pattern_label="COORDINATE"),
        "uncertainty": Positive("relative standard uncertainty of the frequency (calibration weights)", "-", 0.01,
                                10.0),
        "shape_uncertainty": Positive("standard uncertainty of the MAC of the shape (calibration weights)", "-", 0.1,
                                      1.0),
        "role": Text("fit: the calibration fits it; predict: held out, its model value is predicted", "fit",
                     ("fit", "predict")),
        "published_model": Positive("the value the source's own model gave", "Hz", None, bound("frequency")),
        "source": Text("where the value comes from", ""),
    },
    "a measured natural frequency ([[natural_frequencies]])",
)

MEASUREMENTS_FILE = Table({"measurements": TableList(MEASUREMENT, "measured values", default=()),
                           "natural_frequencies": TableList(NATURAL_FREQUENCY, "measured natural frequencies",
                                                            default=())},
                          "a measurements file")

TRAIN_TABLE = Table(
    {
        "name": Text("train name", REQUIRED, pattern=r"[A-Za-z0-9_\-]+"),
        "description": Text("one-line description"),
        "source": Text("where the train comes from, in words (paper, design, table)", ""),
        "references": ListOf(Text("key", REQUIRED, tuple(REFERENCES)),
                             "the works the train comes from: keys of gearcheck's reference table (see README: "
                             "references)", ()),
        "input": Text("input member, `STAGE.MEMBER`", REQUIRED),
        "output": Text("output member", REQUIRED),
        "held": ListOf(Text("member", REQUIRED),
                       "members held by their torsional support stiffness: each needs "
                       "`support.torsional_stiffness` > 0, so that its vibration is still modelled", ()),
        "measurements_file": Text("a TOML file of [[measurements]] and [[natural_frequencies]] (relative to the "
                                  "train file): the amplitudes shown in every cross-check, both used by calibrate",
                                  None),
        "user_model": Text("your own model of this train, checked by `crosscheck --model user`: a .mat or .npz "
                           "file of matrices (relative to the train file), or `module:factory` or "
                           "`file.py:factory` (code, run only with `--trust`)", None),
    },
    "identification and power flow",
)

TRAIN = Table(
    {
        "train": TRAIN_TABLE,
        "operating": OPERATING,
        "stages": TableList(STAGE, "planetary stages", min_length=1),
        "couplings": TableList(COUPLING, "interstage couplings", default=()),
        "measurements": TableList(MEASUREMENT, "measured reference values shown beside both solvers", default=()),
        "tolerances": Table({}, "cross-check tolerances, `KIND.METRIC = value` or `QUANTITY.METRIC = value` "
                                "(see README: tolerances)", None, open=True),
    },
    "a gear train file",
)


def parse(document: dict, source: str) -> dict:
    """Validate a TOML document against :data:`TRAIN`; return SI dictionaries."""
    return TRAIN.parse(document, "", Context(source))


def parse_measurements_file(document: dict, source: str) -> dict:
    """Validate a measurements file against :data:`MEASUREMENTS_FILE`: ``measurements`` (amplitudes) and
    ``natural_frequencies``, at least one entry in all, each natural frequency paired one way: ``mode``, ``type``
    with ``order``, or a ``shape`` alone (which ``type`` may narrow); a shape given with the others is compared
    with the mode they pair."""
    ctx = Context(source)
    parsed = MEASUREMENTS_FILE.parse(document, "", ctx)
    if not parsed["measurements"] and not parsed["natural_frequencies"]:
        raise ctx.fail("measurements", "missing required field (or [[natural_frequencies]])")
    for i, entry in enumerate(parsed["natural_frequencies"]):
        path = f"natural_frequencies[{i}]"
        if entry["mode"] is not None and entry["type"] is not None:
            raise ctx.fail(f"{path}.mode", f"{entry['mode']} pairs by number, type by type and order: give one")
        if entry["order"] is not None and entry["type"] is None:
            raise ctx.fail(f"{path}.order", f"{entry['order']} counts within a type: give type")
        if entry["mode"] is None and entry["type"] is None and entry["shape"] is None:
            raise ctx.fail(path, "needs mode, type (with order) or shape, to pair it with a model mode")
        if entry["shape"] is not None and not any(entry["shape"].values()):
            raise ctx.fail(f"{path}.shape", "is zero everywhere")
        entry["where"] = f"{source}: {path}"
    return parsed


def markdown_reference(root: Table = TRAIN) -> str:
    """The field-by-field reference of the train file (or of another file, ``root``), as a Markdown table."""
    rows = ["| field | type | unit | default | range | meaning |", "|---|---|---|---|---|---|"]
    seen: dict[int, str] = {}

    def walk(table: Table, prefix: str):
        items = list(table.fields.items()) + [(f"<{table.pattern_label}>", spec) for _, spec in table.patterns]
        for key, spec in items:
            path = f"{prefix}.{key}" if prefix else key
            inner = spec.table if isinstance(spec, TableList) else spec
            if isinstance(inner, Table) and id(inner) in seen:
                rows.append(_row(path, spec, f"same fields as `{seen[id(inner)]}`"))
                continue
            if isinstance(inner, Table):
                seen[id(inner)] = path
                rows.append(_row(f"[[{path}]]" if inner is not spec else path, spec))
                walk(inner, path)
            else:
                rows.append(_row(path, spec))

    walk(root, "")
    return "\n".join(rows) + "\n"


def _row(path: str, spec, note: str = "") -> str:
    if spec.default is REQUIRED:
        default = "**required**"
    elif spec.default is None:
        default = "—"
    elif isinstance(spec.default, tuple):
        default = "[]"
    else:
        default = f"`{spec.default}`" if not isinstance(spec.default, float) else f"`{spec.default:g}`"
    doc = spec.doc or getattr(getattr(spec, "table", None), "doc", "")
    if note:
        doc = f"{doc}; {note}"
    if getattr(spec, "choices", None):
        doc += " (" + ", ".join(spec.choices) + ")"
    item = spec.item if isinstance(spec, ListOf) else spec
    bounds = item.range_text() if hasattr(item, "range_text") else ""
    return f"| `{path}` | {spec.type_name()} | {spec.unit or '-'} | {default} | {bounds} | {doc} |"

