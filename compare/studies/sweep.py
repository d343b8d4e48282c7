"""The sweep engine: speed sweeps, parameter studies and Monte Carlo, on local processes or a Dask cluster.

A *point* is one train file (the user's, with swept fields edited in its own units), one input speed, the
solvers to run and the run settings.  :func:`run_point` runs each solver on it (the same sides the cross-check
runs, :class:`~gearcheck.lumped.side.LumpedSide` and :class:`~gearcheck.mbd_models.side.MujocoSide`), from the
final state of the point at the neighbouring speed where the sweep continues (:mod:`gearcheck.compare.studies.
continuation`: its steady window starts once that start's mismatch has died away; ``start`` says how each point
started), else from the static state with the steady window found by the cross-check's rule
(:func:`gearcheck.compare.engine.align.steady_state` over the plan's mesh-force groups; without a steady state the
second half, flagged ``steady = "none"``); on the checked points (``checked``: every ``CHECK_EVERY``-th speed,
every point with a line in the half-power band of a mode it drives or with a mesh that unloads, or all) it runs each
solver again from the same state at its check step (2 h, or h / 2).  It reduces the window to a tidy table, one
row per (solver, quantity, metric, mesh, order), from the gated signals alone (the runs build no others):

* ``mean``, ``rms``, ``peak_to_peak`` of every quantity the cross-check gates, over the steady window;
* ``harmonic``: amplitude and phase of each of them at the mesh harmonics k f_mesh, k = 1..``harmonics``, of
  every distinct mesh frequency of the train (``mesh`` names its stages, e.g. ``I``), by the Hann-windowed
  projection the cross-check's spectra use, A = 2 |sum w x e^{-i 2 pi f t}| / sum w, phase of cos(2 pi f t +
  phase) with t the run's own time; ``resolved`` is False where the window cannot separate the line from
  its neighbours or from DC (T |f - f'| < 2, the Hann main lobe), and for a translation along the world's axes
  from its carrier sidebands (T f_carrier < 2: the response is periodic in the carrier's frame, and turned into
  the world's its lines move to k f_mesh +/- f_carrier; measured on hub-drive at 1080 rpm, I.sun.ay.world's first
  stage I line read 5.0 and 6.5 m/s^2 over 0.19 s and 0.07 s windows and 0.013 m/s^2 over 1.2 s).  The lines
  are projected with the jumps of a switching mesh stiffness and the kinks they cause taken out, each signal's
  where Newton's law puts them (:func:`gearcheck.compare.engine.line_projection.harmonics` at
  :meth:`~gearcheck.compare.engine.plan.TrainPlan.singularities`): a plain sum aliases them onto the lines, by the same
  amount in both solvers, which then agree on a wrong number -- the cross-check of two solvers cannot see an error
  they share. ``integration_error`` estimates the error of a statistic or line by its change on doubling the step
  (|X_h - X_2h|, or 2 |X_h - X_h/2|; for a line the change of its complex amplitude), which bounds it for any order p
  >= 1 in the asymptotic range: the solvers are fourth order, but what is read from their samples need not be (a
  peak-to-peak between samples, a line with its jumps and kinks projected out from extrapolated samples), and
  against runs at h / 8 on demo-3p the lines' errors are 0.008 to 1.5 of their change, median 0.08 (Richardson's
  fourth-order rule says a fifteenth) but 0.37 at the 90th percentile; a line whose estimate exceeds a tenth of it
  (:mod:`gearcheck.compare.studies.sweep_lines`) is left out of the peaks and drawn faint in the plots;
* ``natural_frequency``: the reference lumped model's gyroscopic natural frequencies at the point's speed
  (Cooley & Parker 2012), one row per elastic mode, so order plots overlay them (``solver`` "lumped").

The engine (:func:`execute`) hashes each point's canonical inputs (:attr:`Point.key`: the edited train file's
canonical TOML text and the digest of a torque CSV it reads, speed, solvers, settings, gearcheck's version, and the
key of the point it continues from), skips points whose ``KEY.parquet`` already lies in the cache folder (an
interrupted sweep resumes; a changed input is a new key), runs the others, a chain of continued points a unit of
work (the chains are the plan's, not the workers', so the table is the same on every backend), through a
:class:`concurrent.futures.Executor` (processes by default; in-process for one worker) or on a Dask distributed
cluster (``scheduler``: an address or a ``distributed.Client``; :mod:`gearcheck.compare.studies.point_backends`),
writes each finished point into the cache (at once in this process, as their chain ends from workers; whole or not
at all), and concatenates the points in index order with their inputs as columns (``point``, ``sample``, ``seed``,
``speed_rpm``, each swept field, ``key``). The table has a fixed schema and no time stamps, so the same inputs give
a byte-identical Parquet file.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import hashlib
import importlib.metadata
import importlib.util
import itertools
import json
import math
import os
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import tomli_w

from gearcheck.compare.studies import continuation as continued
from gearcheck.compare.studies import point_backends as backends
from gearcheck.compare.engine.align import STEADY_WINDOW_CYCLES, steady_state
from gearcheck.compare.studies.calibrate import FitParameter
from gearcheck.compare.studies.distributions import Distribution, draw_samples
from gearcheck.compare.engine.comparison import check_step
from gearcheck.compare.engine.line_projection import harmonics
from gearcheck.compare.engine.plan import TrainPlan
from gearcheck.compare.studies.sweep_lines import counted, measured
from gearcheck.train.loader import load_text, load_train, read_train_text
from gearcheck.lumped.side import LumpedSide
from gearcheck.train.files import MAX_DATA_BYTES, read_bytes
from gearcheck.train.spec import TrainSpec, beside
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared import parquet_bytes
from gearcheck.shared.blas import one_blas_thread
from gearcheck.shared.errors import GearcheckError, SolverError
from gearcheck.shared.selection import chosen
from gearcheck.shared.outputs import OutputDirectory, check_place
from gearcheck.shared.results import TimeResult, disc_names, train_signals, unit_schema
from gearcheck.shared.run_state import RunState
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import richardson_factor
from gearcheck.shared.units import checked_rpm, rad_s_to_rpm

FORMAT = 3  # of the table; part of every point's key
SOLVERS = ("lumped", "mujoco")
DURATION = 0.5  # s simulated per point and solver
HARMONICS = 3
STATISTICS = ("mean", "rms", "peak_to_peak")
MAX_POINTS = 100_000  # each point carries its edited train file (some 10 kB): 1 GB of points at most
MAX_REFINE = 64
MAX_HARMONICS = 20
CHECKS = ("subset", "all", "none")  # which points get the integration check
CHECK_EVERY = 8  # the subset: every CHECK_EVERY-th point, every point with a line near a mode it drives, ...
UNLOADED = 0.1  # ... and every point where a contact that can part (a mesh's, a disc's pins) unloads below this

KEY = "gearcheck.point"  # a point table's metadata: the point's key (Point.key), checked when read from the cache
POINT_SCHEMA = pa.schema([
    ("solver", pa.string()), ("quantity", pa.string()), ("kind", pa.string()), ("unit", pa.string()),
    ("metric", pa.string()), ("mesh", pa.string()), ("order", pa.int64()), ("frequency_hz", pa.float64()),
    ("amplitude", pa.float64()), ("phase_rad", pa.float64()), ("resolved", pa.bool_()),
    ("integration_error", pa.float64()), ("steady", pa.string()),
    ("steady_start_s", pa.float64()), ("dt_s", pa.float64()), ("start", pa.string()), ("checked", pa.string()),
    ("error", pa.string()),
])
"""The columns :func:`run_point` gives (what the cache holds per point)."""

COLUMNS = {  # every column of the sweep table: (unit, meaning)
    "point": ("", "index of the point in the sweep (the table's order)"),
    "sample": ("", "index of the point's parameter set: a grid combination or a Monte Carlo draw (0 without)"),
    "seed": ("", "Monte Carlo seed (null without)"),
    "speed_rpm": ("rpm", "input speed"),
    "solver": ("", "lumped or mujoco"),
    "quantity": ("", "a gated signal of the cross-check (modeK for a natural frequency)"),
    "kind": ("", "the signal's kind (acceleration, mesh_force, ...; the mode type for a natural frequency)"),
    "unit": ("", "unit of amplitude (Hz for a natural frequency)"),
    "metric": ("", "mean, rms, peak_to_peak, harmonic, natural_frequency or failed"),
    "mesh": ("", "stages of the mesh frequency of a harmonic"),
    "order": ("", "harmonic order k (mode number of a natural frequency, 0 for a statistic)"),
    "frequency_hz": ("Hz", "k f_mesh at this speed, or the natural frequency"),
    "amplitude": ("unit", "the statistic, or the harmonic's amplitude"),
    "phase_rad": ("rad", "phase of the harmonic, cos(2 pi f t + phase), t from the run's start"),
    "resolved": ("", "the steady window separates the line from its neighbours and from DC (and, for a translation "
                     "along the world's axes, from its carrier sidebands k f_mesh +/- f_carrier)"),
    "integration_error": ("unit", "estimate of the integration error of amplitude: its change on doubling the "
                                  "step (null where the point was not checked)"),
    "steady": ("", "detected, decayed or none (then the second half of the run); continued: the start's "
                   "mismatch decayed (see start)"),
    "steady_start_s": ("s", "start of the steady window"),
    "dt_s": ("s", "the solver's step"),
    "start": ("", "cold (from the static state), continued (from the previous speed's final state), or from the "
                  "static state because the continuation did not settle or the solvers' continuations parted"),
    "checked": ("", "why the point's integration error was estimated: all, every Nth (every Nth speed), "
                    "resonance (a line in the half-power band of a mode it drives), contact (a mesh with backlash "
                    "or tip relief unloads below a tenth of its mean force), or no"),
    "error": ("", "why a solver failed at this point (metric failed)"),
    "key": ("", "SHA-256 of the point's inputs and of the code that ran it: its cache file's name"),
}


@functools.lru_cache(maxsize=1)
def version() -> str:
    return importlib.metadata.version("gearcheck")


NUMERIC_LIBRARIES = ("numpy", "scipy", "mujoco", "numba", "pyarrow")  # whose arithmetic a point's bytes carry


@functools.lru_cache(maxsize=1)
def code_digest() -> str:
    """SHA-256 of the code that computes a point, part of its key: every Python file of the installed gearcheck
    (its name in the package and its bytes: an editable install maps subpackages to their own folders) and the
    versions of :data:`NUMERIC_LIBRARIES`.  A point cached by other code -- a checkout one commit on, a library
    upgraded -- is computed again, where a key holding the release alone would give its old bytes."""
    files = {}  # name -> path, the name as an install lays it out (gearcheck/lumped/time_solver.py)
    for package in ("gearcheck", "gearcheck.lumped", "gearcheck.mbd_models", "gearcheck.compare"):
        found = importlib.util.find_spec(package)  # found, not imported: compare does not import the front door
        if found is None or found.submodule_search_locations is None:
            raise RuntimeError(f"{package} is not an installed package")
        for root in map(Path, found.submodule_search_locations):
            for path in root.rglob("*.py"):
                files[f"{package.replace('.', '/')}/{path.relative_to(root).as_posix()}"] = path
    digest = hashlib.sha256()
    for name, path in sorted(files.items()):
        data = path.read_bytes()
        digest.update(f"{name}\0{len(data)}\0".encode() + data)
    for library in NUMERIC_LIBRARIES:
        digest.update(f"{library} {importlib.metadata.version(library)}\0".encode())
    return digest.hexdigest()


# ----------------------------------------------------------------------------- fields of the train file
@dataclass(frozen=True)
class Field:
    """A number of the train file by its path (``stages[0].mesh.ste[0].amplitude_um``, the calibration's
    addressing), in the file's own units; its messages name the Python argument that gave it, ``argument``
    (``fields=stages[0].sun.mass: ...``)."""

    path: str
    keys: tuple
    argument: str = "fields"

    @classmethod
    def parse(cls, path: str, argument: str = "fields") -> "Field":
        if "=" in path or not path:
            raise GearcheckError(f"{argument}={path!r}: not a field path such as stages[0].sun.mass")
        return cls(path, tuple(FitParameter.parse(path, argument).keys), argument)

    def check(self, document) -> float | int | None:
        """The field's value in ``document`` (None where its table exists but the file leaves it to its
        default); refused where there is no such table or the value is not a number."""
        node = document
        for i, k in enumerate(self.keys):
            last = i == len(self.keys) - 1
            if isinstance(k, int):
                if not isinstance(node, list) or not -len(node) <= k < len(node):
                    raise GearcheckError(f"{self.argument}={self.path}: no such field in the train file "
                                         f"(no element {k} there)")
            elif not isinstance(node, dict) or (k not in node and not last):
                raise GearcheckError(f"{self.argument}={self.path}: no such field in the train file ({k!r} is not "
                                     "there)")
            elif k not in node:
                return None
            node = node[k]
        if isinstance(node, bool) or not isinstance(node, (int, float)):
            raise GearcheckError(f"{self.argument}={self.path}: {node!r} is not a number")
        return node

    def set(self, document, value) -> None:
        node = document
        for k in self.keys[:-1]:
            node = node[k]
        node[self.keys[-1]] = value


def parse_values(text: str) -> tuple[str, list[float]]:
    """``FIELD=v1,v2,...`` or ``FIELD=A:B:N`` (N values from A to B) -> (FIELD, values), an entry of ``fields=``
    written as text."""
    path, eq, values = text.partition("=")
    if not eq or not values.strip():
        raise GearcheckError(f"fields={text!r}: give FIELD=v1,v2,... or FIELD=A:B:N")
    return path.strip(), _numbers(values, f"fields={text!r}", positive=False)


def parse_speeds(text: str) -> list[float]:
    """``A:B:N`` (N speeds from A to B rpm) or ``v1,v2,...``: every speed > 0; ``speeds=`` written as text."""
    return _numbers(text, f"speeds={text!r}", positive=True)


def _numbers(text: str, what: str, positive: bool) -> list[float]:
    text = str(text).strip()
    try:
        if ":" in text:
            parts = text.split(":")
            if len(parts) != 3:
                raise ValueError
            low, high, count = float(parts[0]), float(parts[1]), int(parts[2])
        else:
            values = [float(v) for v in text.split(",")]
    except ValueError:
        raise GearcheckError(f"{what}: must be A:B:N or v1,v2,... numbers") from None
    if ":" in text:
        if not (math.isfinite(low) and math.isfinite(high)):
            raise GearcheckError(f"{what}: A and B must be finite")
        if count < 1 or low > high or (count == 1) != (low == high) or count > MAX_POINTS:
            raise GearcheckError(f"{what}: an empty or reversed range (needs A < B and N >= 2, or A:A:1)")
        values = [low + (high - low) * i / max(count - 1, 1) for i in range(count)]
    if not values or not all(math.isfinite(v) for v in values):
        raise GearcheckError(f"{what}: every value must be a finite number")
    return [checked_rpm(v, f"{what}: every speed") for v in values] if positive else values


# ----------------------------------------------------------------------------- points
@dataclass(frozen=True)
class Point:
    """One run of the sweep: what :func:`run_point` needs, and nothing that varies between two runs."""

    index: int
    text: str  # the edited train file, canonical TOML
    source: str  # where it came from: its relative file references resolve from there
    speed_rpm: float | None  # None: the file's own
    solvers: tuple[str, ...]
    duration: float
    harmonics: int
    sample: int = 0
    values: tuple = ()  # ((field path, value), ...) of the swept fields
    seed: int | None = None
    extra: str = ""  # digest of files the train reads (a torque CSV)
    check: str = "subset"  # which points run an integration check (a second run at 2 h or h / 2): CHECKS
    refine: int = 1  # each solver's default step divided by this
    after: str = ""  # the key of the point whose final state this one goes on from ("": the static state)
    after_rpm: float | None = None  # that point's speed
    place: int = 0  # its place among its parameter set's speeds (every CHECK_EVERY-th is in the checked subset)

    @property
    def key(self) -> str:
        """SHA-256 of the point's canonical inputs: the edited train file's text and the files it reads, not
        where it lies, the key of the point it goes on from, not its index (the same run in two sweeps shares
        it), and the code that runs it (:func:`code_digest`)."""
        data = {"format": FORMAT, "gearcheck": version(), "code": code_digest(), "train": self.text,
                "speed_rpm": self.speed_rpm, "solvers": list(self.solvers), "duration_s": self.duration,
                "harmonics": self.harmonics, "files": self.extra, "integration_check": self.check,
                "refine": self.refine, "after": self.after, "after_rpm": self.after_rpm, "place": self.place,
                "checked_every": CHECK_EVERY if self.check == "subset" else None}
        return hashlib.sha256(json.dumps(data, sort_keys=True).encode("utf-8")).hexdigest()


@dataclass
class SweepPlan:
    train: str
    points: list[Point]
    fields: list[str]
    settings: dict


def plan_sweep(train, *, speeds=None, fields=None, distributions=None, samples: int | None = None, seed: int = 0,
               solvers=SOLVERS, duration: float = DURATION, harmonics: int = HARMONICS,
               integration_check: bool | str = "subset", refine: int = 1, continuation: bool = True) -> SweepPlan:
    """The points of a sweep, validated before anything runs (every edited train file loads, every speed is
    one the train can turn at).  ``fields``: {path: [values]} (a grid over all of them); ``distributions``:
    {path: "normal(mean, sd)" or Distribution} with ``samples`` draws seeded ``seed``; ``speeds`` in rpm
    (None: the file's); ``integration_check``: which points run each solver a second time for its integration
    error, "subset" (every ``CHECK_EVERY``-th point and every point with a line near a natural frequency), "all"
    (True) or "none" (False); ``refine``: each solver's default step divided by it; ``continuation``: each point
    at the speed after its neighbour's goes on from that one's final state
    (:mod:`gearcheck.compare.studies.continuation`); ``duration`` is then the longest a point runs.  Parameter
    sets are the outer loop, speeds the inner."""
    if isinstance(train, TrainSpec):
        raise GearcheckError("a sweep needs the train file (a preset name or a path), not a loaded TrainSpec: "
                             "it edits the file's numbers and hashes its text")
    solvers = _solvers(solvers)
    integration_check = _check_run_options(duration, harmonics, integration_check, refine, continuation)
    text, source = read_train_text(train)
    base = load_text(text, source)
    document = tomllib.loads(text)
    grid, laws = _varied_fields(document, fields, distributions, samples)
    speeds = _checked_speeds(speeds, list(grid) + list(laws))
    count = ((32 if samples is None else samples) if laws else math.prod(map(len, grid.values()))) * \
        (len(speeds) if speeds else 1)
    if count > MAX_POINTS:  # before the grid is built
        raise GearcheckError(f"{count} points: more than the {MAX_POINTS} a sweep holds")
    drawn = seed if laws else None  # a grid draws nothing: no seed
    if laws:
        sets = draw_samples(laws, 32 if samples is None else samples, seed)
    else:
        sets = [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())]
    common = dict(source=source, solvers=solvers, duration=float(duration), harmonics=harmonics, seed=drawn,
                  extra=_files_digest(document, source), check=integration_check, refine=refine)
    points = _points(document, base, sets, speeds, "distributions" if laws else "fields", common)
    if continuation:
        points = continued.link(points)
    settings = {"train": base.name, "source": source, "solvers": list(solvers), "duration_s": float(duration),
                "harmonics": harmonics, "integration_check": integration_check, "refine": refine,
                "continuation": continuation,
                "speeds_rpm": speeds,
                "grid": {f.path: [float(v) for v in vs] for f, vs in grid.items()},
                "distributions": {f.path: str(d) for f, d in laws.items()},
                "samples": len(sets) if laws else None, "seed": drawn, "gearcheck": version()}
    return SweepPlan(base.name, points, [f.path for f in list(grid) + list(laws)], settings)


def check_harmonics(harmonics) -> None:
    """Refuse a number of mesh harmonics per mesh frequency outside 1 to :data:`MAX_HARMONICS`."""
    if isinstance(harmonics, bool) or not isinstance(harmonics, int) or not 1 <= harmonics <= MAX_HARMONICS:
        raise GearcheckError(f"harmonics={harmonics!r}: needs an integer from 1 to {MAX_HARMONICS}")


def _check_run_options(duration, harmonics, integration_check, refine, continuation) -> str:
    """Refuse a setting of every point's runs that is out of its range; the integration check as one of
    :data:`CHECKS` (True: "all", False: "none")."""
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not (0 < duration < math.inf):
        raise GearcheckError(f"duration={duration!r}: needs a positive number of seconds")
    check_harmonics(harmonics)
    if isinstance(integration_check, bool):
        integration_check = "all" if integration_check else "none"
    if integration_check not in CHECKS:
        raise GearcheckError(f"integration_check={integration_check!r}: needs {', '.join(CHECKS)} (or True, False)")
    if isinstance(refine, bool) or not isinstance(refine, int) or not 1 <= refine <= MAX_REFINE:
        raise GearcheckError(f"refine={refine!r}: needs an integer from 1 to {MAX_REFINE}")
    if not isinstance(continuation, bool):
        raise GearcheckError(f"continuation={continuation!r}: needs True or False")
    return integration_check


def _varied_fields(document: dict, fields, distributions, samples) -> tuple[dict, dict]:
    """The study's fields, each found in the train file ``document``: (grid, laws), {Field: [values]} of a
    parameter study and {Field: Distribution} of a Monte Carlo; one of the two is empty."""
    fields = dict(fields or {})
    distributions = dict(distributions or {})
    if fields and distributions:
        raise GearcheckError("fields= (a grid) and distributions= (Monte Carlo): give one or the other")
    if samples is not None and not distributions:
        raise GearcheckError("samples=: Monte Carlo needs distributions=, the law of each field it draws")
    grid = {}
    for path, values in fields.items():
        f = Field.parse(path, "fields")
        grid[f] = _checked_values(path, values, f.check(document))
    laws = {}
    for path, law in distributions.items():
        f = Field.parse(path, "distributions")
        f.check(document)
        laws[f] = law if isinstance(law, Distribution) else Distribution.parse(law, f"distributions={path}")
    if len({f.path for f in list(grid) + list(laws)}) != len(grid) + len(laws):
        raise GearcheckError("a field is given twice")
    return grid, laws


def _checked_speeds(speeds, varied: list) -> list[float] | None:
    """``speeds`` (rpm) as floats, each a positive number of rpm no larger than any train turns at (whether this
    train can is :func:`_check_speed_ends`'s); None: the file's own speed.  The input speed is swept by them alone,
    not also as a varied field of ``varied``."""
    if speeds is None:
        return None
    speeds = [checked_rpm(float(s), "every speed of speeds=") for s in speeds]
    if not speeds:
        raise GearcheckError("speeds=[]: an empty list of speeds")
    if any(f.keys[:2] == ("operating", "input_speed_rpm") for f in varied):
        raise GearcheckError("operating.input_speed_rpm is swept by speeds=: give it there only")
    return speeds


def _points(document: dict, base, sets: list[dict], speeds, argument: str, common: dict) -> list[Point]:
    """The points of every parameter set of ``sets`` ({Field: value}, the outer loop) at every speed, each set's
    edited train file loaded (``base`` where nothing is edited) and turned at the slowest and fastest speed;
    ``argument`` (``fields`` or ``distributions``) names the sets in messages, ``common`` is what every point
    shares."""
    points: list[Point] = []
    for i, values in enumerate(sets):
        where = ", ".join(f"{f.path}={v!r}" for f, v in values.items())
        what = f"{argument}={where}" + (f" (sample {i})" if argument == "distributions" else "")
        canonical, spec = _edited_train(document, common["source"], base, values, what)
        if speeds and (i == 0 or values):  # bounds and pitch-line speed grow with the speed: the ends decide
            _check_speed_ends(spec, speeds, where)
        for place, speed in enumerate(speeds or [None]):
            points.append(Point(index=len(points), text=canonical, speed_rpm=speed, sample=i, place=place,
                                values=tuple((f.path, float(v)) for f, v in values.items()), **common))
    return points


def _edited_train(document: dict, source: str, base, values: dict, what: str):
    """(canonical TOML, loaded train) of ``document`` with ``values`` ({Field: value}) set; ``base`` where there
    are none.  A file that does not load is refused, its message after ``what``."""
    doc = copy.deepcopy(document)
    for f, v in values.items():
        f.set(doc, v)
    canonical = tomli_w.dumps(doc)
    try:
        return canonical, load_text(canonical, source) if values else base
    except GearcheckError as exc:
        raise GearcheckError(f"{what}: {exc}") from None


def _check_speed_ends(spec, speeds: list[float], where: str) -> None:
    """Refuse ``speeds`` whose slowest or fastest the train ``spec`` (edited as ``where`` says) cannot turn at."""
    for speed in sorted({min(speeds), max(speeds)}):
        try:
            load_train(spec, speed)
        except GearcheckError as exc:
            raise GearcheckError(f"speeds={speed:g}" + (f" ({where})" if where else "") + f": {exc}") from None


def check_quantities(train, quantities) -> None:
    """Refuse a quantity to plot that the train does not gate (before anything runs)."""
    spec = load_train(train)
    gated = [s.name for s in train_signals(spec) if s.compared]
    for q in quantities:
        if q not in gated:
            raise GearcheckError(f"quantities={q}: not a gated quantity of {spec.name} (e.g. "
                                 f"{', '.join(gated[:3])})")


def _solvers(solvers) -> tuple[str, ...]:
    if isinstance(solvers, str):
        solvers = SOLVERS if solvers == "both" else (solvers,)
    solvers = tuple(solvers)
    bad = [s for s in solvers if s not in SOLVERS]
    if bad or not solvers or len(set(solvers)) != len(solvers):
        raise GearcheckError(f"solver={', '.join(map(str, solvers)) or '(none)'}: choose lumped, mujoco or both")
    return solvers


def _checked_values(path: str, values, current) -> list:
    """The values of a grid field; a field the file holds as an integer (teeth, planets) stays one."""
    values = [values] if isinstance(values, (int, float)) else list(values)
    if not values:
        raise GearcheckError(f"fields={path}: an empty list of values")
    for v in values:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise GearcheckError(f"fields={path}={v!r}: every value must be a finite number")
    if isinstance(current, int) and all(float(v).is_integer() and abs(v) < 2**53 for v in values):
        return [int(v) for v in values]
    return [float(v) for v in values]


def _files_digest(document: dict, source: str) -> str:
    """SHA-256 of the files the train file reads that change its dynamics (a torque CSV)."""
    name = document.get("operating", {}).get("torque_csv")
    if not isinstance(name, str):
        return ""
    try:
        return hashlib.sha256(read_bytes(beside(source, name), "torque profile")).hexdigest()
    except GearcheckError:  # the train file's own check names the problem
        return ""


# ----------------------------------------------------------------------------- one point
def mesh_groups(spec, kin) -> list[tuple[str, float]]:
    """(label, Hz) of each distinct mesh frequency of the train, lowest first; the label names the stages of
    its meshes (``I``, ``II``; ``I+II`` where two stages share a frequency)."""
    groups: dict[float, list[str]] = {}
    exact: dict[float, float] = {}
    for mesh in spec.meshes:
        f = kin.mesh_frequency[mesh.id]
        key = round(f, 6)
        exact.setdefault(key, f)
        if mesh.stage not in groups.setdefault(key, []):
            groups[key].append(mesh.stage)
    return [("+".join(stages), exact[key]) for key, stages in sorted(groups.items())]


class _Rows:
    def __init__(self):
        self.columns = {name: [] for name in POINT_SCHEMA.names}

    def add(self, **values) -> None:
        for name in self.columns:
            self.columns[name].append(values.get(name))

    def table(self) -> pa.Table:
        return pa.table(self.columns, schema=POINT_SCHEMA)


def run_chain(chain: continued.Chain, each=None) -> list[tuple[str, bytes, float, float]]:
    """Run the points of ``chain`` in order, each going on from the one before
    (:mod:`gearcheck.compare.studies.continuation`): (key, table as Parquet bytes, wall time in s, CPU time of this
    process in s) of each, also given to ``each`` as it ends (a run in this process stores it at once).  A solver
    that fails on a point (it diverges, or refuses a step) gives one row ``metric = "failed"`` with the reason; the
    others still run, and the next point starts that solver from the static state.  The points run on one BLAS
    thread: the cores go to the workers, and a point's numbers are then the same to the last bit whichever backend
    runs it (a multi-threaded BLAS sums in another order)."""
    done, before = [], chain.before
    for point in chain.points:
        data, wall, cpu = run_point(point, before if point.after else None)
        done.append((point.key, data, wall, cpu))
        if each is not None:
            each(chain, done[-1:])
        before = data
    return done


@one_blas_thread
def run_point(point: Point, before: bytes | None = None) -> tuple[bytes, float, float]:
    """Run ``point`` (from ``before``, its predecessor's table, where it goes on from one): (its table as Parquet
    bytes, wall time in s, CPU time of this process in s); see :func:`run_chain`."""
    started, cpu = time.perf_counter(), time.process_time()
    spec = load_train(load_text(point.text, point.source), point.speed_rpm)
    lumped = LumpedSide(spec)
    model = lumped.model
    plan = TrainPlan.of(spec, lumped, point.duration)
    rows = _Rows()
    modal = lumped.modes_at_speed(spec.operating.input_speed)
    for k, (f, kind) in enumerate(zip(modal.frequencies, modal.types), start=1):
        if kind != "rigid" and f > 0:
            rows.add(solver="lumped", quantity=f"mode{k}", kind=kind, unit="Hz", metric="natural_frequency",
                     order=k, frequency_hz=float(f))
    lines = [(label, k, k * f) for label, f in mesh_groups(spec, model.kin) for k in range(1, point.harmonics + 1)]
    runs, failed = {}, {}
    skip = point.after and continued.started(before) == continued.PARTED_START
    for solver in point.solvers:
        side = lumped if solver == "lumped" else MujocoSide(spec)
        try:
            run = _steady_run(side, point, plan, lines, None if skip else before)
            runs[solver] = (side, dataclasses.replace(run, start=continued.PARTED_START + " at the previous speed")
                            if skip else run)
        except SolverError as exc:
            failed[solver] = str(exc)
    runs = _aligned(runs, point, plan, lines, failed)
    parting = _parting(spec, model.excitation)
    checked = _checked(point, lines, lumped.resonances([(f / k, k) for _, k, f in lines]),
                       any(_unloads(run, parting) for _, run in runs.values()))
    states = {}
    for solver in point.solvers:
        if solver in failed:
            rows.add(solver=solver, quantity="", metric="failed", error=failed[solver])
            continue
        side, run = runs[solver]
        try:
            check = _check_run(side, point, run) if checked != "no" else None
        except SolverError as exc:
            rows.add(solver=solver, quantity="", metric="failed", error=str(exc))
            continue
        reduce_run(run.result, plan, lines, rows, solver, run.steady, check, {"start": run.start, "checked": checked})
        states[solver] = continued.kept(run.state, run.rho, run.shapes)
    metadata = {KEY: point.key, continued.STATE: json.dumps(states, sort_keys=True),
                continued.START: next((run.start for _, run in runs.values()), "")}
    data = parquet_bytes.to_bytes(rows.table().replace_schema_metadata(metadata))
    return data, time.perf_counter() - started, time.process_time() - cpu


def _checked(point: Point, lines: list, resonances: list, unloads: bool) -> str:
    """Why ``point`` runs its integration check ("no": it does not): the sweep's ``check`` setting, and in the
    subset, its place among the speeds (every :data:`CHECK_EVERY`-th), a line in the half-power band of a mode
    of the damped model that it drives (|f - f_n| <= zeta_n f_n; ``resonances``, one (f_n, zeta_n) per line),
    where the response is amplified and most sensitive to the step, or a contact that ``unloads`` (a mesh's or a
    disc's pins, :func:`_unloads`), where the response is not the linear one whose modes say where it is
    sensitive.  A mode
    the line's mesh phasing leaves at rest is not amplified at its natural frequency, and does not make the point
    checked."""
    if point.check != "subset":
        return "all" if point.check == "all" else "no"
    if point.place % CHECK_EVERY == 0:
        return f"every {CHECK_EVERY}th"
    for (_, _, f), (natural, damping) in zip(lines, resonances):
        if np.any(np.abs(f - natural) <= damping * natural):
            return "resonance"
    return "contact" if unloads else "no"


def _parting(spec, excitation) -> list[str]:
    """The force signals of the contacts that can part: each mesh with backlash or tip relief, and each cycloid
    disc's largest pin force (its pins touch in compression only, with a clearance or without)."""
    meshes = [f"{mesh}.force" for j, mesh in enumerate(excitation.mesh_ids)
              if excitation.backlash[j] > 0 or j in excitation.relieved]
    return meshes + [f"{disc}.pin_force_max" for disc in disc_names(spec)]


def _unloads(run: "_SteadyRun", forces: list[str]) -> bool:
    """Whether one of the contacts' ``forces`` (:func:`_parting`) falls below :data:`UNLOADED` of its mean in the
    steady window of ``run``: the contact parts or nearly does, and the response is no longer linear in it."""
    result = run.result
    window = result.t >= run.steady[0]
    for name in forces:
        if name in result.names():
            force = result[name][window]
            if force.size and np.min(force) < UNLOADED * np.mean(force):
                return True
    return False


@dataclass
class _SteadyRun:
    """A point's run of one solver: the run, where its steady window starts and how it was found (the
    ``steady`` column), how it started (``start``), the state it ended in, its start's mismatch rho (continued
    runs), its mesh forces' steady waveforms, and the state it started from with its step (for the integration
    check)."""

    result: TimeResult
    steady: tuple[float, str]
    start: str
    state: RunState
    rho: float | None
    shapes: dict
    initial: RunState | None
    dt: float


def _steady_run(side, point: Point, plan, lines, before) -> _SteadyRun:
    """The point's run of ``side``: continued from ``before`` where the point goes on from its neighbour and that
    settles, else from the static state over the point's duration, its steady window found by the plan's rule."""
    dt = side.default_step() / point.refine
    names = tuple(_signal_names(plan.spec))
    settings = RunSettings(point.duration, dt=dt, signals=names)
    groups = plan.steady_groups(names)
    state, rho, shapes = continued.carried(before, side.solver)
    start = "cold"
    if state is not None and shapes is not None and point.speed_rpm and point.after_rpm:
        initial = state.at_speed(point.speed_rpm / point.after_rpm)
        found = continued.run_continued(side, settings, initial, rho, continued.window_length(plan, lines), groups,
                                        shapes)
        if found is not None:
            result, at, rho, final, shapes = found
            return _SteadyRun(result, (at, "continued"), "continued", final, rho, shapes, initial, dt)
        start = "cold: continuation did not settle"
    decays = _decays(plan, point)
    if decays is not None:  # the decay of the start reaches the steady state within the run: no test needed
        result, final = continued.run_over(side, settings, None, decays, point.duration)
        at, how = decays, "decayed"
    else:
        result, final = side.run_from(settings)
        series = [(np.stack([result[n] for n in forces], axis=1), cycle) for forces, cycle in groups]
        found_at, found_how = steady_state(result.t, series, plan.settle) if series else (None, None)
        at, how = (found_at, found_how) if found_at is not None and found_how else (0.5 * result.t[-1], "none")
    return _SteadyRun(result, (at, how), start, final, None, continued.waveforms(result, groups, at), None, dt)


def _decays(plan, point: Point) -> float | None:
    """Where a run of ``point`` from the static state reaches its steady state by the decay of its start (the plan's
    settle time, with ``STEADY_WINDOW_CYCLES`` of the slowest mesh cycle after it), that settle time; else None."""
    settle = plan.settle
    if settle is None or not math.isfinite(settle) or settle + STEADY_WINDOW_CYCLES * plan.cycle > point.duration:
        return None
    return settle


def _aligned(runs: dict, point: Point, plan, lines, failed: dict) -> dict:
    """The solvers' runs of a point ({solver: (side, run)}) over one steady window: where every one continued, the
    shorter runs extended to the longest's end and the window started at the latest of their steady starts, and
    kept where their waveforms agree within :data:`~gearcheck.compare.studies.continuation.PARTED`; else (some
    did not continue, or their continuations parted) every solver's run from the static state. Windows over other
    instants read other phases of a response that two incommensurate stages make quasi-periodic, and the solvers
    would differ by that (on the hub-drive sweep, each on its own window: 1e-4 median, 20 % at the 99th
    percentile over the lines that count). A run that fails on the way goes into ``failed``."""
    starts = {run.start for _, run in runs.values()}
    if len(runs) < 2 or "continued" not in starts:
        return runs
    why = "cold: continuation did not settle"
    if starts == {"continued"}:
        aligned = {}
        for solver, (side, run) in runs.items():
            try:
                aligned[solver] = (side, _extended(side, run, max(r.result.t[-1] for _, r in runs.values()),
                                                   max(r.steady[0] for _, r in runs.values()), plan))
            except SolverError as exc:
                failed[solver] = str(exc)
        shapes = [run.shapes for _, run in aligned.values()]
        if all(continued.mismatch(b, a) <= continued.PARTED for a, b in zip(shapes, shapes[1:])):
            return aligned
        runs, why = aligned, continued.PARTED_START
    cold = {}
    for solver, (side, run) in runs.items():
        try:
            cold[solver] = (side, run if run.start != "continued" else dataclasses.replace(
                _steady_run(side, point, plan, lines, None), start=why))
        except SolverError as exc:
            failed[solver] = str(exc)
    return cold


def _extended(side, run: _SteadyRun, end: float, start: float, plan) -> _SteadyRun:
    """``run`` (continued) gone on to ``end``, its steady window from ``start``."""
    names = tuple(run.result.names())
    # run_over sets each stretch's duration: the settings give its step and signals
    more, state = continued.run_over(side, RunSettings(run.dt, dt=run.dt, signals=names), run.state, run.state.t, end)
    result = run.result if more is None else continued.joined([run.result, more])
    return dataclasses.replace(run, result=result, state=state, steady=(start, "continued"),
                               shapes=continued.waveforms(result, plan.steady_groups(names), start))


def _signal_names(spec) -> list[str]:
    return [s.name for s in train_signals(spec) if s.compared]


def _check_run(side, point: Point, run: _SteadyRun):
    """The integration check of ``run``: the same run from the same state at the step 2 h (or h / 2)."""
    h = check_step(side, run.dt)
    names = tuple(run.result.names())
    start = 0.0 if run.initial is None else run.initial.t
    return continued.run_over(side, RunSettings(run.result.t[-1] - start, dt=h, signals=names), run.initial,
                              run.steady[0], run.result.t[-1])[0]


def reduce_run(result, plan, lines, rows: _Rows, solver: str, steady: tuple[float, str], check=None,
               columns=None) -> None:
    """The steady window of ``result`` reduced to statistics and mesh harmonics (rows of ``rows``), each with its
    integration error estimate from ``check``, the same run at 2 h or h / 2 (None: no estimate).  The harmonics are
    corrected for each quantity's jumps and changes of slope where Newton's law puts them (``plan.singularities``,
    :func:`gearcheck.compare.engine.line_projection.harmonics`).  ``steady``: (start, how) of the window; ``columns``:
    more columns of every row."""
    start, how = steady
    names = result.names(compared=True)
    freqs = np.array([f for _, _, f in lines])
    stats, full, fs, span = _window(result, names, start, freqs, plan.singularities)
    resolved = [bool(f < 0.45 * fs and f * span >= 2.0 and all(abs(f - g) * span >= 2.0 for g in freqs if g != f))
                for f in freqs]
    dt = float(result.info.get("dt_s", np.nan))
    if check is None:
        stat_error = dict.fromkeys(STATISTICS, np.full(len(names), np.nan))
        line_error = np.full(full.shape, np.nan)
    else:  # the estimate of compare.engine.integration_error, per statistic and line
        factor = richardson_factor(check.info["dt_s"] / dt, order=1)  # a bound: see the module docstring
        check_stats, check_full, _, _ = _window(check, names, start, freqs, plan.singularities)
        stat_error = {m: factor * np.abs(stats[m] - check_stats[m]) for m in STATISTICS}
        line_error = factor * np.abs(full - check_full)
    common = {"solver": solver, "steady": how, "steady_start_s": float(start), "dt_s": dt, **(columns or {})}
    for j, name in enumerate(names):
        s = result.signal(name)
        info = {"quantity": name, "kind": s.kind, "unit": s.unit, **common}
        for metric in STATISTICS:
            rows.add(**info, metric=metric, order=0, amplitude=float(stats[metric][j]),
                     integration_error=_number(stat_error[metric][j]))
        apart = span * _sideband_spacing(plan, s) >= 2.0
        for (label, k, f), value, error, ok in zip(lines, full[:, j], line_error[:, j], resolved):
            rows.add(**info, metric="harmonic", mesh=label, order=k, frequency_hz=float(f),
                     amplitude=float(abs(value)), phase_rad=float(np.angle(value)) if np.isfinite(value) else np.nan,
                     resolved=ok and apart, integration_error=_number(error))


def _sideband_spacing(plan, signal) -> float:
    """How far a translation read along the world's axes has its lines' neighbours: the gear train's response is
    periodic in the carrier's frame, so turned into the world's it moves from k f_mesh to k f_mesh +/- f_carrier
    (its stage's carrier frequency), which a window shorter than 2 / f_carrier cannot tell from the line (inf: no
    such neighbours)."""
    if signal.kind != "acceleration" or not signal.name.endswith(".world"):
        return math.inf
    f_carrier = plan._frequencies(signal.name)[1]
    return f_carrier if f_carrier > 0 else math.inf


def _window(result, names, start: float, freqs: np.ndarray, singularities):
    """(statistics {metric: per quantity}, complex harmonics at ``freqs`` (lines x quantities), sampling rate,
    window span) of ``result``'s quantities ``names`` over t >= ``start``, corrected for the jumps and changes of
    slope at ``singularities(names, t0, t1)`` (each quantity's own, :meth:`~gearcheck.compare.engine.plan.
    TrainPlan.singularities`)."""
    t = result.t
    window = t >= start
    tw = t[window]
    x = result.values[window][:, [result._index[n] for n in names]]
    fs = (t.size - 1) / (t[-1] - t[0])
    stats = {"mean": x.mean(axis=0), "rms": np.sqrt(np.mean(x**2, axis=0)), "peak_to_peak": np.ptp(x, axis=0)}
    singular = singularities(names, tw[0], tw[-1]) if tw.size > 1 else ((), ())
    return stats, harmonics(tw, x, freqs, fs, *singular), fs, (tw[-1] - tw[0] if tw.size > 1 else 0.0)


def _number(value) -> float | None:
    return float(value) if np.isfinite(value) else None


# ----------------------------------------------------------------------------- running many points
@dataclass
class Execution:
    tables: dict  # key -> Parquet bytes
    computed: int
    cached: int
    point_wall_s: list = field(default_factory=list)  # of the points computed here
    point_cpu_s: list = field(default_factory=list)
    backend: str = "in-process"


def execute(points, *, workers: int | None = None, scheduler=None, executor=None, cache=None,
            progress=None) -> Execution:
    """Run every point not in ``cache`` (a folder, or None) through the chosen backend, a chain of points
    (:func:`gearcheck.compare.studies.continuation.chains`) a unit of work; see the module doc.
    ``workers``: processes (default: the cores this process may use; 1 runs in this process);
    ``executor``: any :class:`concurrent.futures.Executor` (left running); ``scheduler``: a Dask scheduler's
    address or a ``distributed.Client``.  ``progress`` is called with the fraction of points done."""
    unique = list(dict.fromkeys(p.key for p in points))
    tables: dict[str, bytes] = {}
    cache = None if cache is None else Path(cache)
    if cache is not None:
        for key in unique:
            try:
                data = read_bytes(cache / f"{key}.parquet", "sweep cache file", MAX_DATA_BYTES)
            except GearcheckError:  # none yet, or not a file that it can be
                continue
            if _readable(data, key):
                tables[key] = data
    cached = len(tables)
    pending = continued.chains(list({p.key: p for p in points}.values()), tables)
    walls: list[float] = []
    cpus: list[float] = []

    def finished(chain: continued.Chain, results: list) -> None:
        for key, data, wall, cpu in results:
            if cache is not None:
                _store(cache / f"{key}.parquet", data)
            tables[key] = data
            walls.append(wall)
            cpus.append(cpu)
        if progress is not None:
            progress(len(tables) / len(unique))

    if progress is not None and unique:
        progress(len(tables) / len(unique))
    workers = _workers(workers)
    if scheduler is not None:
        backend = "dask"
        backends.run_dask(run_chain, pending, scheduler, finished)
    elif executor is not None:
        backend = type(executor).__name__
        backends.run_futures(executor, run_chain, pending, finished)
    elif workers == 1 or len(pending) <= 1:
        backend = "in-process"
        for chain in pending:
            run_chain(chain, finished)
    else:
        backend = f"processes ({min(workers, len(pending))})"
        backends.run_pool(run_chain, pending, min(workers, len(pending)), finished)
    return Execution(tables, len(tables) - cached, cached, walls, cpus, backend)


def _workers(workers) -> int:
    if workers is None:
        return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= 4096:
        raise GearcheckError(f"workers={workers!r}: needs an integer from 1 to 4096")
    return workers


def _readable(data: bytes, key: str) -> bool:
    """Whether ``data`` is a point's table, and the table of the point ``key`` (its inputs' hash, which every point
    table carries: a cache file renamed or copied over another is run again, never read as the other point)."""
    try:
        schema = parquet_bytes.read_table(data).schema
        return schema.equals(POINT_SCHEMA) and (schema.metadata or {}).get(KEY.encode()) == key.encode()
    except Exception:  # a damaged cache file is run again
        return False


def _store(path: Path, data: bytes) -> None:
    """Write a cache file whole or not at all (a temporary file renamed; the umask's permissions)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem[:16]}.{os.getpid()}.{os.urandom(4).hex()}.partial")
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        if tmp.exists():
            tmp.unlink()
        raise


# ----------------------------------------------------------------------------- the table
def assemble(plan: SweepPlan, tables: dict) -> pa.Table:
    """The sweep table: every point's rows, in point order, with the point's inputs as leading columns."""
    parts = []
    for p in plan.points:
        t = parquet_bytes.read_table(tables[p.key])
        n = t.num_rows
        inputs = {"point": pa.array([p.index] * n, pa.int64()), "sample": pa.array([p.sample] * n, pa.int64()),
                  "seed": pa.array([p.seed] * n, pa.int64()),
                  "speed_rpm": pa.array([_speed_of(p)] * n, pa.float64())}
        values = dict(p.values)
        inputs |= {name: pa.array([values[name]] * n, pa.float64()) for name in plan.fields}
        columns = inputs | {name: t.column(name) for name in POINT_SCHEMA.names}
        columns["key"] = pa.array([p.key] * n, pa.string())
        parts.append(pa.table(columns, schema=table_schema(plan)))
    if not parts:
        return table_schema(plan).empty_table()
    return pa.concat_tables(parts).combine_chunks()


_SPEEDS: dict[tuple[str, str], float] = {}


def _speed_of(point: Point) -> float:
    """The point's speed in rpm: its own, or its train file's."""
    if point.speed_rpm is not None:
        return point.speed_rpm
    key = (point.text, point.source)
    if key not in _SPEEDS:
        _SPEEDS[key] = rad_s_to_rpm(load_text(point.text, point.source).operating.input_speed)
    return _SPEEDS[key]


def table_schema(plan: SweepPlan) -> pa.Schema:
    """The sweep table's schema: its columns' units and descriptions in each field's metadata and, as one JSON
    object, in the schema's (``gearcheck.units``), with the sweep's settings (``gearcheck.sweep``)."""
    head = [pa.field("point", pa.int64()), pa.field("sample", pa.int64()), pa.field("seed", pa.int64()),
            pa.field("speed_rpm", pa.float64())] + [pa.field(name, pa.float64()) for name in plan.fields]
    units = COLUMNS | {f: ("file", "swept train-file field, in the file's own unit") for f in plan.fields}
    meta = {"gearcheck.sweep": json.dumps(plan.settings, sort_keys=True),
            "gearcheck.units": json.dumps({k: {"unit": u, "description": d} for k, (u, d) in units.items()},
                                          sort_keys=True)}
    return unit_schema(pa.schema(head + list(POINT_SCHEMA) + [pa.field("key", pa.string())], metadata=meta), units)


# ----------------------------------------------------------------------------- the result
@dataclass
class SweepResult:
    """A finished sweep: ``table`` (pyarrow; ``to_pandas()``), its plan, and how it ran."""

    plan: SweepPlan
    table: pa.Table
    computed: int
    cached: int
    wall_s: float
    point_wall_s: list
    point_cpu_s: list
    backend: str

    @property
    def train(self) -> str:
        return self.plan.train

    @property
    def settings(self) -> dict:
        return self.plan.settings

    def to_pandas(self):
        """The table as a DataFrame, its columns' units in ``attrs["units"]`` (``"unit"``: the row's ``unit``
        column; ``"file"``: the train file's own unit of a swept field)."""
        frame = self.table.to_pandas()
        units = {name: unit for name, (unit, _) in COLUMNS.items()}
        frame.attrs["units"] = units | dict.fromkeys(self.plan.fields, "file")
        return frame

    def plot(self, quantity: str | None = None):
        """The figure of one gated quantity (default: the first headline one) as a :class:`matplotlib.figure.Figure`
        (no pyplot): its order plot over a speed sweep, its study plot over a parameter study or a Monte Carlo."""
        from gearcheck.compare.presentation import sweep_plots

        frame = self.to_pandas()
        plotted = set(frame.loc[frame["metric"] == "harmonic", "quantity"])
        if quantity is None:
            quantity = self.headline()[0]
        else:
            [quantity] = chosen("quantity", quantity, sorted(plotted), f"a quantity of the sweep of {self.train}")
        if self.plan.fields:
            return sweep_plots.study_figure(frame, self.plan, [quantity])
        if frame["speed_rpm"].nunique() < 2:
            raise GearcheckError(f"the sweep of {self.train} has one speed and no swept field: nothing to plot")
        return sweep_plots.order_figure(frame, self.plan.train, quantity)

    def parquet(self) -> bytes:
        """The table as Parquet bytes: the same inputs give the same bytes."""
        return parquet_bytes.to_bytes(self.table)

    def checked_points(self) -> dict[str, int]:
        """How many points ran the integration check, by the reason their ``checked`` column gives, most first."""
        points = self.table.select(["point", "checked"]).to_pandas().dropna(subset=["checked"]).drop_duplicates("point")
        counts = points.loc[points["checked"] != "no", "checked"].value_counts(sort=False)
        return dict(sorted(((str(k), int(v)) for k, v in counts.items()), key=lambda kv: (-kv[1], kv[0])))

    def summary(self) -> dict:
        frame = self.to_pandas()
        peaks = []
        lines = frame[(frame["metric"] == "harmonic") & measured(frame)].dropna(subset=["amplitude"])
        harmonic = lines[counted(lines)]
        for (solver, quantity), rows in harmonic.groupby(["solver", "quantity"], sort=False):
            if quantity not in self.headline():
                continue
            top = rows.loc[rows["amplitude"].idxmax()]
            peaks.append({"solver": solver, "quantity": quantity, "mesh": top["mesh"], "order": int(top["order"]),
                          "amplitude": float(top["amplitude"]), "unit": top["unit"],
                          "speed_rpm": float(top["speed_rpm"]), "frequency_hz": float(top["frequency_hz"])})
        failed = frame[frame["metric"] == "failed"]
        steady = frame[frame["metric"] == "rms"].drop_duplicates(["point", "solver"])
        return {"train": self.train, "points": len(self.plan.points), "rows": self.table.num_rows,
                "settings": self.settings, "peaks": peaks,
                "no_steady_state": int((steady["steady"] == "none").sum()),
                "lines": int(len(lines)), "unconverged_lines": int(len(lines) - len(harmonic)),
                "failed": [{"point": int(r.point), "solver": r.solver, "error": r.error} for r in failed.itertuples()]}

    def headline(self) -> list[str]:
        """Carrier and ring accelerations (y, carrier frame) and the first sun and ring mesh forces of each stage.
        The carrier frame's: the response is periodic there, and its lines stand apart; read along the world's axes
        they move to k f_mesh +/- f_carrier, which no window shorter than 2 / f_carrier separates (0.4 s for a
        5 Hz carrier: those lines are flagged unresolved)."""
        spec = load_text(self.plan.points[0].text, self.plan.points[0].source)
        names = []
        for stage in spec.stages:
            for member in (stage.carrier, *[c for c in stage.centrals if spec.members[c].kind == "ring"]):
                names.append(f"{member}.ay.carrier")
            names += [f"{m.id}.force" for m in spec.meshes if m.stage == stage.name and m.planet_index == 0]
        present = set(self.table.column("quantity").to_pylist())
        return [n for n in names if n in present]

    def write(self, directory, quantities=None) -> list[Path]:
        """Write ``sweep.parquet``, ``sweep.json`` and the figures as the folder ``directory``, whole or not at
        all; returns the files written."""
        with OutputDirectory(directory, "directory") as place:
            names = self.write_files(place.path, quantities)
        return [Path(directory) / n for n in names]

    def write_files(self, folder: Path, quantities=None) -> list[str]:
        from gearcheck.compare.presentation import sweep_plots

        folder = Path(folder)
        (folder / "sweep.parquet").write_bytes(self.parquet())
        frame = self.to_pandas()
        quantities = list(quantities) if quantities else self.headline()
        present = set(frame["quantity"])
        missing = [q for q in quantities if q not in present]
        if missing:
            raise GearcheckError(f"quantities={missing[0]}: not a gated quantity of {self.train}")
        written = ["sweep.parquet"]
        for name, png in sweep_plots.figures(frame, self.plan, quantities).items():
            (folder / name).write_bytes(png)
            written.append(name)
        data = self.summary()
        data["figures"] = written[1:]
        data["timing"] = {"wall_s": self.wall_s, "computed": self.computed, "cached": self.cached,
                          "backend": self.backend, "point_wall_s": self.point_wall_s,
                          "point_cpu_s": self.point_cpu_s}
        (folder / "sweep.json").write_text(json.dumps(data, indent=2, default=_plain) + "\n", encoding="utf-8")
        return written + ["sweep.json"]


def _plain(value):
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.floating,)):
        return float(value)
    return str(value)


def sweep(train, *, speeds=None, fields=None, distributions=None, samples: int | None = None, seed: int = 0,
          solvers=SOLVERS, duration: float = DURATION, harmonics: int = HARMONICS,
          integration_check: bool | str = "subset", refine: int = 1, continuation: bool = True,
          workers: int | None = None, scheduler=None, executor=None, cache=None, progress=None) -> SweepResult:
    """Plan, run (resuming from ``cache``) and assemble a sweep; see :func:`plan_sweep` and :func:`execute`."""
    started = time.perf_counter()
    plan = plan_sweep(train, speeds=speeds, fields=fields, distributions=distributions, samples=samples,
                      seed=seed, solvers=solvers, duration=duration, harmonics=harmonics,
                      integration_check=integration_check, refine=refine, continuation=continuation)
    if cache is not None:
        check_place(Path(cache), "cache=")
    if scheduler is not None and executor is not None:
        raise GearcheckError("scheduler= runs on a Dask cluster: give it or an executor, not both")
    if scheduler is not None and workers is not None:
        raise GearcheckError("workers= counts local processes: a Dask cluster (scheduler=) has its own workers")
    run = execute(plan.points, workers=workers, scheduler=scheduler, executor=executor, cache=cache,
                  progress=progress)
    table = assemble(plan, run.tables)
    return SweepResult(plan, table, run.computed, run.cached, time.perf_counter() - started, run.point_wall_s,
                       run.point_cpu_s, run.backend)

