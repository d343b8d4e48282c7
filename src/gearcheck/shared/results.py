"""The time-response result every model returns: one object, named signals, pandas export.

A :class:`TimeResult` holds the sample times and a set of named signals, each with a kind, a unit
and a description: ``result["stage1.ring.ay.world"]`` is an array over ``result.t``.  Whether the
cross-check gates a signal is part of the signal (``compared``).

A gear train's signals (:func:`train_result`, the same for the lumped solver and the MuJoCo twin):

* ``MEMBER.ax.world``, ``MEMBER.ay.world``: acceleration of the member's centre along the fixed
  x, y axes, as a housing-mounted accelerometer sees it (m/s^2);
* ``MEMBER.ax.carrier``, ``MEMBER.ay.carrier``: the same vector along the axes that turn with the
  member's stage carrier (for planets: radial, tangential);
* ``MEMBER.alpha``: angular acceleration (rad/s^2, absolute: planar motion); ``MEMBER.az`` along the
  stage axis (a member that slides axially);
* ``MESH.force`` (N), ``MESH.dte`` (m, the dynamic transmission error: the mesh deflection along the
  line of action, positive in compression), ``MESH.kv`` (F / F_static) and ``MESH.stiffness`` (N/m);
* ``PLANET.bearing_radial.force``, ``PLANET.bearing_tangential.force`` (N);
* the members' motion, last (:func:`motion_signals`), every member's, none gated:
  ``MEMBER.x.world``, ``.y.world``, ``.x.carrier``, ``.y.carrier`` the displacement of its centre from
  its nominal place (the stage axis, a planet's pin, a disc's eccentric) (m); ``MEMBER.vx.world``,
  ``.vy.world``, ``.vx.carrier``, ``.vy.carrier`` the inertial velocity of its centre (m/s, nominal
  motion included, like the accelerations); ``MEMBER.vx.relative``, ``.vy.relative`` the vibration
  velocity, the rate of the carrier-axes displacement (m/s); ``MEMBER.theta`` the rotation from its
  nominal angle (rad), ``MEMBER.omega`` its absolute angular velocity and ``MEMBER.omega.relative``
  the rate of ``theta`` (rad/s); ``MEMBER.z`` and ``MEMBER.vz`` along the stage axis (axial members).

Planets' accelerations, Kv and the stiffness are recorded but not gated: the cross-check sees the
planets through their meshes and bearings.

A linear model's run (:func:`coordinate_signals`) has ``NAME.acceleration``, ``NAME.velocity`` and
``NAME`` for each of its own coordinates.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from gearcheck.shared.errors import GearcheckError, SolverError, did_you_mean
from gearcheck.shared.outputs import OutputDirectory
from gearcheck.shared.selection import chosen


@dataclass(frozen=True)
class Signal:
    name: str
    kind: str  # acceleration | angular_acceleration | velocity | displacement | angle | mesh_force | dte | ...
    unit: str
    description: str
    compared: bool = True  # gated by the cross-check


@dataclass
class TimeResult:
    """Time series of one run: ``values[:, j]`` is signal ``signals[j]`` at the times ``t``."""

    train: str
    solver: str
    t: np.ndarray
    signals: list[Signal]
    values: np.ndarray  # (n_t, n_signals)
    settle_time: float = 0.0
    info: Mapping = field(default_factory=dict)  # the run's RunInfo (a recording's: where it came from)
    raw: dict = field(default_factory=dict)  # solver-specific extra series (coordinates, sensors)
    static: dict = field(default_factory=dict)  # signal name -> its value in the static equilibrium

    def __post_init__(self):
        self._index = {s.name: j for j, s in enumerate(self.signals)}

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[:, self._position(name)]

    def _position(self, name: str) -> int:
        """The column of signal ``name``; KeyError naming the closest signals."""
        try:
            return self._index[name]
        except (KeyError, TypeError):
            raise KeyError(f"{self.solver} result of {self.train} has no signal {name!r}"
                           + did_you_mean(str(name), self._index, n=3)) from None

    def __contains__(self, name: str) -> bool:
        return name in self._index

    def signal(self, name: str) -> Signal:
        return self.signals[self._position(name)]

    def names(self, kind: str | None = None, compared: bool | None = None) -> list[str]:
        """Signal names, optionally of one kind and/or only those the cross-check gates (or not)."""
        return [s.name for s in self.signals
                if (kind is None or s.kind == kind) and (compared is None or s.compared == compared)]

    def select(self, kind: str) -> np.ndarray:
        """Every signal of ``kind`` as columns (time along axis 0), in :meth:`names` order."""
        return self.values[:, [self._index[n] for n in self.names(kind)]]

    @property
    def steady(self) -> np.ndarray:
        return self.t >= self.settle_time

    def to_dataframe(self, names=None) -> pd.DataFrame:
        """Time and the signals ``names`` (default: all) as columns, their units in ``attrs["units"]``."""
        names = [s.name for s in self.signals] if names is None else list(names)
        frame = pd.DataFrame({"t": self.t, **{n: self[n] for n in names}})
        frame.attrs["units"] = {"t": "s"} | {n: self.signal(n).unit for n in names}
        return frame

    def to_xarray(self, names=None):
        """The signals ``names`` (default: all) as an :class:`xarray.Dataset` over the coordinate ``t`` (s), each
        variable with its ``unit``, ``kind`` and ``description`` in its attrs (``pip install xarray``)."""
        try:
            import xarray as xr
        except ImportError:
            raise GearcheckError("to_xarray needs xarray: pip install xarray (or gearcheck[xarray])") from None
        names = [s.name for s in self.signals] if names is None else list(names)
        variables = {}
        for name in names:
            s = self.signal(name)
            variables[name] = ("t", self[name], {"unit": s.unit, "kind": s.kind, "description": s.description})
        return xr.Dataset(variables, coords={"t": ("t", self.t, {"unit": "s", "description": "time"})},
                          attrs={"train": self.train, "solver": self.solver})

    def plot(self, signals=None):
        """A :class:`matplotlib.figure.Figure` (no pyplot) of ``signals`` (a name or several; default: those the
        cross-check gates) against time, one panel per kind of signal."""
        from gearcheck.shared.figures import time_figure

        if signals is None:
            return time_figure(self, self.names(compared=True) or self.names())
        return time_figure(self, chosen("signals", signals, self._index, f"a signal of {self.solver} {self.train}"))

    def summary(self) -> dict:
        """Steady-state mean, RMS, peak-to-peak and largest magnitude of every signal (JSON-ready, SI)."""
        w = self.steady
        stats = {}
        for s in self.signals:
            x = self[s.name][w]
            stats[s.name] = {"unit": s.unit, "mean": float(np.mean(x)), "rms": float(np.sqrt(np.mean(x**2))),
                             "peak_to_peak": float(np.ptp(x)), "max_abs": float(np.max(np.abs(x)))}
        return {"train": self.train, "solver": self.solver, "settle_time_s": self.settle_time,
                "samples": int(w.sum()), "info": dict(self.info), "series": stats}

    def write(self, directory, fmt: str = "parquet") -> list[Path]:
        """Write ``timeseries.parquet`` (or ``.csv``), ``raw.parquet`` (if any) and ``summary.json`` as the folder
        ``directory``, whole or not at all (:class:`~gearcheck.shared.outputs.OutputDirectory`); returns the
        files' paths."""
        with OutputDirectory(directory, "directory") as place:
            names = [p.name for p in self.write_files(place.path, fmt)]
        return [Path(directory) / name for name in names]

    def write_files(self, out: Path, fmt: str = "parquet") -> list[Path]:
        """Write the files into the existing folder ``out``: Parquet (full precision, compressed, each column's
        unit and description in the file's metadata: ``units_of``) or CSV (9 significant digits)."""
        if fmt not in SERIES_FORMATS:
            raise SolverError(f"format {fmt!r}: choose {' or '.join(SERIES_FORMATS)}")
        columns = {"t": ("s", "time")} | {s.name: (s.unit, s.description) for s in self.signals}
        written = [_write_table(self.to_dataframe(), out / f"timeseries.{fmt}", columns)]
        if self.raw:
            raw = {"t": ("s", "time")} | {name: ("", f"{self.solver} coordinate or sensor") for name in self.raw}
            written.append(_write_table(pd.DataFrame({"t": self.t, **self.raw}), out / f"raw.{fmt}", raw))
        written.append(out / "summary.json")
        written[-1].write_text(json.dumps(self.summary(), indent=2, sort_keys=True) + "\n")
        return written


SERIES_FORMATS = ("parquet", "csv")
UNITS_KEY = b"gearcheck.units"


def _write_table(frame: pd.DataFrame, path: Path, columns: dict) -> Path:
    """One table as Parquet (its columns' units and descriptions in the schema metadata) or CSV."""
    if path.suffix == ".csv":
        frame.to_csv(path, index=False, float_format="%.9g")
        return path
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(frame, preserve_index=False)
    meta = {UNITS_KEY: json.dumps({k: {"unit": u, "description": d} for k, (u, d) in columns.items()}).encode()}
    pq.write_table(with_field_units(table, columns).replace_schema_metadata({**(table.schema.metadata or {}), **meta}),
                   path, compression="zstd")
    return path


def with_field_units(table, columns: dict):
    """``table`` with its schema's fields carrying their units (:func:`unit_schema`)."""
    import pyarrow as pa

    return pa.Table.from_arrays(table.columns, schema=unit_schema(table.schema, columns))


def unit_schema(schema, columns: dict):
    """``schema`` with each field of ``columns`` ({name: (unit, description)}) carrying its ``unit`` and
    ``description`` in its own metadata, where pyarrow, polars and DuckDB users see them."""
    import pyarrow as pa

    fields = [f.with_metadata({**(f.metadata or {}), b"unit": columns[f.name][0].encode(),
                               b"description": columns[f.name][1].encode()}) if f.name in columns else f
              for f in schema]
    return pa.schema(fields, metadata=schema.metadata)


def units_of(path) -> dict:
    """The units and descriptions a gearcheck Parquet file holds for its columns."""
    import pyarrow.parquet as pq

    return json.loads(pq.read_schema(path).metadata[UNITS_KEY])


def bearing_names(spec) -> list[str]:
    """``MEMBER.bearing_radial`` and ``MEMBER.bearing_tangential`` of every member borne on a carrier pin (a
    planet, an RV reducer's crankshaft), in member order, each station's (``.station1`` ...) where a tilting
    member's bearing has stations; a torsional planet rides its pin rigidly and has none (its bearing's force is a
    constraint force, not reported)."""
    names = []
    for mid, m in spec.members.items():
        if m.orbits and m.bearing is not None:
            stations = [f".station{i + 1}" for i in range(len(m.bearing.stations))] if m.tilting else []
            names += [f"{mid}.bearing_{axis}{at}" for at in stations or [""] for axis in ("radial", "tangential")]
    return names


def coordinate_signals(coordinates, descriptions: dict, model: str, compared: bool = True) -> list[Signal]:
    """The signals of a model's own coordinates, three per coordinate: ``NAME.acceleration`` (gated when
    ``compared``), ``NAME`` itself and ``NAME.velocity``.  A coordinate whose last part names an angle (theta...)
    is a rotation (rad), any other a translation (m)."""
    signals = []
    for name in coordinates:
        angular = name.rsplit(".", 1)[-1].startswith("theta")
        prefix, unit = ("angular_", "rad") if angular else ("", "m")
        what = descriptions.get(name, name)
        signals += [Signal(f"{name}.acceleration", f"{prefix}acceleration", f"{unit}/s^2",
                           f"{what}: acceleration ({model})", compared),
                    Signal(name, "coordinate", unit, what, compared=False),
                    Signal(f"{name}.velocity", f"{prefix}velocity", f"{unit}/s", f"{what}: velocity ({model})",
                           compared=False)]
    return signals


def tilting_meshes(spec) -> list:
    """The meshes of tilting stages, whose tilting moments :func:`train_result` takes (in ``spec.meshes`` order)."""
    tilting = {stage.name for stage in spec.stages if stage.tilting}
    return [mesh for mesh in spec.meshes if mesh.stage in tilting]


def train_signals(spec) -> list[Signal]:
    """The signals of a gear train run, in the order :func:`train_result` holds them."""
    signals = acceleration_signals(spec)
    for mesh in spec.meshes:
        signals += [Signal(f"{mesh.id}.force", "mesh_force", "N", f"{mesh.id} mesh force"),
                    Signal(f"{mesh.id}.dte", "dte", "m", f"{mesh.id} dynamic transmission error"),
                    Signal(f"{mesh.id}.kv", "dynamic_factor", "1", f"{mesh.id} dynamic load factor F/F_static", False),
                    Signal(f"{mesh.id}.stiffness", "mesh_stiffness", "N/m", f"{mesh.id} mesh stiffness", False)]
    for mesh in tilting_meshes(spec):
        signals.append(Signal(f"{mesh.id}.moment", "mesh_moment", "N·m", f"{mesh.id} mesh tilting moment across "
                              "the face"))
        if mesh.contact_width:  # (an idealised mesh's face has no width)
            signals.append(Signal(f"{mesh.id}.khb", "face_load_factor", "1", f"{mesh.id} face load factor: "
                                  "largest load per unit face width over the mean, 1 + 6|M|/(F w)", False))
    signals += [Signal(f"{name}.force", "bearing_force", "N", f"{name} force") for name in bearing_names(spec)]
    for disc in disc_names(spec):
        signals += [Signal(f"{disc}.pin_force_max", "pin_force", "N", f"{disc}: largest pin contact force"),
                    Signal(f"{disc}.pins_loaded", "pin_count", "1", f"{disc}: pins in contact", False)]
    for mid, member in spec.members.items():
        signals += motion_signals(mid, member)
    return signals


OWN_MESH_KINDS = frozenset({"mesh_force", "dynamic_factor", "mesh_stiffness", "mesh_moment", "face_load_factor"})
ACCELERATION_KINDS = frozenset({"acceleration", "angular_acceleration"})
SMOOTH_KINDS = frozenset({"dte", "displacement", "angle", "tilt", "pin_count"})


class Jumps(NamedTuple):
    """Where a signal jumps: at the stiffness switches of ``meshes`` (indices into ``spec.meshes``) and, if
    ``corners``, at an operating history's corners; and where its slope may jump while it stays continuous: at the
    switches of ``kinks`` and at the corners (None: nowhere, a smooth signal)."""

    meshes: tuple[int, ...]
    corners: bool
    kinks: tuple[int, ...] | None


def signal_jumps(spec) -> dict[str, Jumps]:
    """Where each signal of :func:`train_signals` jumps and where it kinks, from Newton's law and the parts that join
    the members.  A member's acceleration jumps where a force on it does: at its meshes' switches, and at those of
    the members it is rigidly tied to (a torsional planet rides its carrier's pin), not through an elastic part;
    and at an operating history's corners, where the frames' angular acceleration Omega' = lambda' Omega does.  A
    mesh force k(t) delta + c delta' jumps where its own k does (delta and delta' are continuous), and so do its Kv,
    stiffness, tilting moment and face load factor.  A damper's force c (v_a - v_b) has a slope that jumps where
    the acceleration of a member it joins does: so a mesh's or a bearing's force, or a pin's, kinks where its
    members' accelerations jump, and a member's acceleration where those of the members joined to it do (its
    parts' forces); a velocity kinks where its member's acceleration jumps.  A deflection, a position and a tilt
    angle are smooth (their rates are continuous).  Another kind of signal may jump and kink at every switch.

    One jump Newton's law does not give is kept too: a carrier's angular acceleration at its planets' switches.
    MuJoCo's twin carries each planet in its carrier's frame and sets its mesh force along a tendon of the nominal
    geometry, while its mass matrix follows the planet's displaced place, so the carrier takes a torque of the
    force's jump times a lever of the order of the planet's displacement (on demo-3p 14 um, 4.5e-4 of the sun's
    lever; the lumped model's carrier does not jump).  Small as it is, on the carrier's small lines it aliases."""
    carrier_of = {mid: f"{m.stage}.carrier" for mid, m in spec.members.items() if m.orbits}
    carried: dict[str, list[str]] = {}
    for mid, carrier in carrier_of.items():
        carried.setdefault(carrier, []).append(mid)
    groups = {mid: {mid} for mid in spec.members}
    for mid, carrier in carrier_of.items():
        if spec.members[mid].torsional and carrier in groups:
            group = groups[mid] | groups[carrier]
            for m in group:
                groups[m] = group
    meshes_of: dict[str, set[int]] = {mid: set() for mid in spec.members}
    for j, mesh in enumerate(spec.meshes):
        for m in groups[mesh.central] | groups[mesh.planet]:
            meshes_of[m].add(j)
    joined: dict[str, set[str]] = {mid: {mid} for mid in spec.members}
    for part in spec.parts:
        members = [m for m in part.joined() if m in joined]
        for m in members:
            joined[m].update(members)

    def jumping(members) -> tuple[int, ...]:  # the meshes at whose switches an acceleration of ``members`` jumps
        return tuple(sorted(set().union(*(meshes_of[m] for m in members))))

    own = {f"{mesh.id}.": j for j, mesh in enumerate(spec.meshes)}
    bearings = {f"{part.member}.bearing_": part.joined() for part in spec.parts if part.element == "bearing"}
    everything = tuple(range(len(spec.meshes)))
    out = {}
    for s in train_signals(spec):
        member = next((m for m in spec.members if s.name.startswith(f"{m}.")), None)
        mesh = next((j for prefix, j in own.items() if s.name.startswith(prefix)), None)
        bearing = next((pair for prefix, pair in bearings.items() if s.name.startswith(prefix)), None)
        if s.kind in SMOOTH_KINDS:
            out[s.name] = Jumps((), False, None)
        elif s.kind in OWN_MESH_KINDS and mesh is not None:
            out[s.name] = Jumps((mesh,), False, jumping(spec.meshes[mesh].joined()))
        elif s.kind in ACCELERATION_KINDS and member is not None:
            turning = carried.get(member, []) if s.kind == "angular_acceleration" else []
            out[s.name] = Jumps(jumping([member] + turning), True, jumping(joined[member]))
        elif s.kind == "bearing_force" and bearing is not None:
            out[s.name] = Jumps((), False, jumping(bearing))
        elif s.kind == "pin_force" and member is not None:
            out[s.name] = Jumps((), False, jumping(joined[member]))
        elif s.kind in ("velocity", "angular_velocity") and member is not None:
            out[s.name] = Jumps((), False, jumping([member]))
        else:
            out[s.name] = Jumps(everything, True, everything)
    return out


def acceleration_signals(spec) -> list[Signal]:
    """Every member's accelerations, the first signals of a train run: the central members' gated."""
    return [s for mid, member in spec.members.items() for s in member_accelerations(mid, member)]


def member_accelerations(mid: str, member) -> list[Signal]:
    """A member's accelerations, gated for a central member."""
    gated = not member.orbits
    signals = [Signal(f"{mid}.a{axis}.{frame}", "acceleration", "m/s^2", f"{mid} acceleration along {axis} ({frame} "
                      "frame)", gated and not member.torsional)  # a torsional member's: zero, reported, not compared
               for frame in ("world", "carrier") for axis in "xy"]
    signals.append(Signal(f"{mid}.alpha", "angular_acceleration", "rad/s^2", f"{mid} angular acceleration", gated))
    if member.axial:
        signals.append(Signal(f"{mid}.az", "acceleration", "m/s^2", f"{mid} acceleration along the stage axis",
                              gated and not member.torsional))
    if member.tilting:  # a tilt is compared as an angle: the body's angular acceleration holds its spin's turning
        signals += [Signal(f"{mid}.tilt_{axis}.{frame}", "tilt", "rad", f"{mid} tilt about {axis} ({frame} frame)",
                           gated) for frame in ("world", "carrier") for axis in "xy"]
    return signals


def motion_signals(mid: str, member) -> list[Signal]:
    """A member's displacements and velocities (module docstring), none gated."""
    signals = []
    for frame in ("world", "carrier"):
        signals += [Signal(f"{mid}.{axis}.{frame}", "displacement", "m",
                           f"{mid} centre's displacement from its nominal place along {axis} ({frame} frame)", False)
                    for axis in "xy"]
    for frame in ("world", "carrier"):
        signals += [Signal(f"{mid}.v{axis}.{frame}", "velocity", "m/s", f"{mid} velocity along {axis} ({frame} frame)",
                           False) for axis in "xy"]
    signals += [Signal(f"{mid}.v{axis}.relative", "velocity", "m/s",
                       f"{mid} vibration velocity along {axis}: rate of its carrier-frame displacement", False)
                for axis in "xy"]
    signals += [Signal(f"{mid}.theta", "angle", "rad", f"{mid} rotation from its nominal angle", False),
                Signal(f"{mid}.omega", "angular_velocity", "rad/s", f"{mid} angular velocity", False),
                Signal(f"{mid}.omega.relative", "angular_velocity", "rad/s",
                       f"{mid} angular velocity less its nominal one: rate of theta", False)]
    if member.axial:
        signals += [Signal(f"{mid}.z", "displacement", "m", f"{mid} displacement along the stage axis", False),
                    Signal(f"{mid}.vz", "velocity", "m/s", f"{mid} velocity along the stage axis", False)]
    return signals


def disc_names(spec) -> list[str]:
    """An RV reducer's cycloid discs, stage by stage (the order of :func:`train_result`'s pin forces)."""
    return [mid for mid, member in spec.members.items() if member.frame == "eccentric"]


class MemberMotion(NamedTuple):
    """One member's motion over a run as a solver reports it to :func:`train_result`: arrays over time, a vector
    (time x 2) along the axes of the member's carrier, which make the angle ``angle`` with the world's
    (world = R(angle) carrier); for planets its radial and tangential axes."""

    angle: np.ndarray  # rad, of the carrier's axes
    acceleration: np.ndarray  # inertial acceleration of the centre, m/s^2 (time x 2)
    alpha: np.ndarray  # angular acceleration, rad/s^2
    displacement: np.ndarray  # the centre from its nominal place, m (time x 2)
    velocity: np.ndarray  # inertial velocity of the centre, m/s (time x 2)
    relative_velocity: np.ndarray  # d/dt of ``displacement`` (time x 2)
    theta: np.ndarray  # rotation from the nominal angle, rad
    omega: np.ndarray  # absolute angular velocity, rad/s
    omega_relative: np.ndarray  # d/dt of ``theta``
    axial: np.ndarray | None = None  # along the stage axis: acceleration, displacement, velocity (time x 3)
    tilt: np.ndarray | None = None  # tilts about the carrier's axes (time x 2), rad: members that tilt


def train_result(spec, solver: str, t, motion, mesh_deflection, mesh_force, mesh_stiffness, static_mesh_force,
                 static_bearing_force, bearing_force, settle_time, info, raw, pin_force=None,
                 wanted=None, mesh_moment=None) -> TimeResult:
    """The named signals of a gear train run, from what every solver of a train computes.

    motion: j -> :class:`MemberMotion` of the j-th member of ``spec.members`` (axial for members that slide),
    asked once per member, and only of members with a signal kept; mesh arrays (n_t, n_mesh) in ``spec.meshes``
    order; bearing_force (n_t, n_bearing) in :func:`bearing_names` order; the static forces of the meshes and
    bearings are the run's ``static`` values; pin_force (n_t, n_disc, Z_p) every pin contact's force, discs in
    :func:`disc_names` order (an RV reducer's); mesh_moment (n_t, n) the tilting moments of the
    :func:`tilting_meshes`, whose face load factors follow from them: the load per unit width of a face w wide
    under a force F and a moment M is F/w + 12 M z / w^3, z from its centre.  ``wanted``: the names of the signals
    to keep (None: all), in :func:`train_signals`' order."""
    signals = [s for s in train_signals(spec) if wanted is None or s.name in wanted]
    if wanted is not None and len(signals) != len(set(wanted)):
        missing = sorted(set(wanted) - {s.name for s in signals})
        raise SolverError(f"signals: {spec.name} has no signal {missing[0]!r}")
    values = np.empty((len(t), len(signals)), order="F")  # written and read a signal at a time
    at = {s.name: j for j, s in enumerate(signals)}

    def put(columns: dict) -> None:
        for name, x in columns.items():
            if name in at:
                values[:, at[name]] = x

    for j, (mid, member) in enumerate(spec.members.items()):  # member by member: small temporaries
        own = member_accelerations(mid, member) + motion_signals(mid, member)
        if any(s.name in at for s in own):
            for group in member_columns(mid, motion(j)).values():
                put(group)
    for i, mesh in enumerate(spec.meshes):
        put({f"{mesh.id}.force": mesh_force[:, i], f"{mesh.id}.dte": mesh_deflection[:, i],
             f"{mesh.id}.kv": mesh_force[:, i] / static_mesh_force[i], f"{mesh.id}.stiffness": mesh_stiffness[:, i]})
    forces = {mesh.id: mesh_force[:, i] for i, mesh in enumerate(spec.meshes)}
    for i, mesh in enumerate(tilting_meshes(spec)):
        moment = mesh_moment[:, i]
        put({f"{mesh.id}.moment": moment})
        if mesh.contact_width:
            put({f"{mesh.id}.khb": 1.0 + 6.0 * np.abs(moment) / (np.abs(forces[mesh.id]) * mesh.contact_width)})
    put({f"{name}.force": bearing_force[:, i] for i, name in enumerate(bearing_names(spec))})
    for i, disc in enumerate(disc_names(spec)):
        put({f"{disc}.pin_force_max": pin_force[:, i].max(axis=-1), f"{disc}.pins_loaded": (pin_force[:, i] > 0).sum(
            axis=-1)})
    static = {f"{mesh.id}.force": float(f) for mesh, f in zip(spec.meshes, static_mesh_force)
              if f"{mesh.id}.force" in at}
    static.update({f"{name}.force": float(f) for name, f in zip(bearing_names(spec), static_bearing_force)
                   if f"{name}.force" in at})
    return TimeResult(spec.name, solver, np.asarray(t), signals, values, settle_time, info, raw, static)


def member_columns(mid: str, m: MemberMotion) -> dict[str, dict[str, np.ndarray]]:
    """The named signals of member ``mid`` from its motion ``m``, by what they need of it: ``"translation"`` (its
    centre's accelerations, displacements and velocities along the world's and the carrier's axes),
    ``"rotation"`` (alpha, theta, omega, omega.relative), ``"axial"`` (az, z, vz) and ``"tilt"`` (tilt_x, tilt_y
    along the world's and the carrier's axes) when ``m`` has them."""
    c, s = np.cos(m.angle), np.sin(m.angle)
    translation: dict[str, np.ndarray] = {}
    tilt: dict[str, np.ndarray] = {}
    vectors = [("a{}", m.acceleration, translation), ("{}", m.displacement, translation),
               ("v{}", m.velocity, translation)] + ([("tilt_{}", m.tilt, tilt)] if m.tilt is not None else [])
    for name, vector, out in vectors:
        x, y = (f"{mid}.{name.format(axis)}" for axis in "xy")
        out[f"{x}.world"] = c * vector[:, 0] - s * vector[:, 1]
        out[f"{y}.world"] = s * vector[:, 0] + c * vector[:, 1]
        out[f"{x}.carrier"], out[f"{y}.carrier"] = vector[:, 0], vector[:, 1]
    translation[f"{mid}.vx.relative"], translation[f"{mid}.vy.relative"] = m.relative_velocity.T
    rotation = {f"{mid}.alpha": m.alpha, f"{mid}.theta": m.theta, f"{mid}.omega": m.omega,
                f"{mid}.omega.relative": m.omega_relative}
    axial = {} if m.axial is None else {f"{mid}.{name}": m.axial[:, k] for k, name in enumerate(("az", "z", "vz"))}
    return {"translation": translation, "rotation": rotation, "axial": axial, "tilt": tilt}
