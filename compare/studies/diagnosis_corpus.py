"""A corpus of broken lumped models from independent formulations, and how often the diagnosis names the mistake.

Each case is one of :mod:`gearcheck.compare.studies.textbook_planetary`'s formulations of a preset (Lin & Parker
1999 translational-torsional, or torsional with the planet centres held), broken as the literature's slips break
it: a coupling dropped or its sign flipped, a stiffness or an inertia off by a factor, an inertia in another
radius convention (I = m r^2 with the pitch radius for the base radius: cos^2 alpha), a spring the train lacks,
a coefficient or entry times a power of a radius (N r_c k for N r_c^2 k), a planet sum written for another
planet count, the centripetal stiffness without the rigid-turn correction, the Coriolis terms left out, and pairs.
Its evidence (modes at rest with shapes; frequencies at speed for the translational-torsional form) is
diagnosed against gearcheck's reference (:func:`gearcheck.compare.engine.diagnosis.diagnose`); a hit is the
class heading the diagnosis naming the right term.  A case whose modes equal the unbroken formulation's has no
effect and is counted apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Callable

import numpy as np

from gearcheck.compare.engine.diagnosis import Candidate, Diagnosis, Evidence, diagnose
from gearcheck.compare.studies.textbook_planetary import Formulation, Stage, torsional, translational_torsional
from gearcheck.lumped.assembly import LumpedModel, build_model
from gearcheck.shared.modal import RIGID_TOLERANCE, generalized_modes, speed_modal_result
from gearcheck.train.loader import load_text, preset_text
from gearcheck.train.variants import edited_text

SIX_PLANETS = [(r"^planets = 3", "planets = 6"), (r"^teeth = 22", "teeth = 30"), (r"^teeth = 20", "teeth = 24"),
               (r"^teeth = 62 .*$", "teeth = 78"), (r'^name = "demo-3p"', 'name = "six-planet"')]  # 108 / 6 = 18
CLASSES = ("dropped coupling", "sign error", "stiffness", "inertia", "inertia convention", "extra spring",
           "radius power", "planet count", "rigid-turn correction", "gyroscopic", "pair")
TRAINS = ("demo-3p", "demo-4p", "six-planet")  # six-planet: demo-3p with 6 planets, z = 30/24/78
MATCH = 1e-3  # a fitted factor or stiffness within this (relative) of the one broken in is the right one
SAME_MODES = 1e-8  # relative residual of the broken modes in the unbroken eigenproblem: no effect below it


@dataclass
class Case:
    """One broken formulation: ``expected`` the right candidate's fields (two for a pair); a ``factor`` or
    ``stiffness`` matches to :data:`MATCH`, ``coordinates`` as a set, ``named`` a phrase of the term."""

    train: str
    shaft: bool  # the input held by its shaft; without, the train has one rigid-body mode
    formulation: str  # "translational-torsional" or "torsional"
    mistake: str  # one of CLASSES
    what: str
    expected: list[dict]
    broken: Formulation
    unbroken: Formulation = field(repr=False, default=None)


@dataclass
class Outcome:
    case: Case
    diagnosis: Diagnosis
    effect: bool
    hit: bool  # the right term heads the diagnosis
    in_class: bool  # the right term is in the first class (the head or a look-alike the evidence cannot tell)
    margin: float  # the runner-up's score less the best's
    rigid: tuple[int, int]  # zero frequencies: broken, unbroken
    rigid_reported: bool  # the counts are in the diagnosis, and a change is said in its lines


@cache
def text(train: str) -> str:
    """A train's file: a preset's, or six-planet's (demo-3p edited)."""
    return edited_text("demo-3p", SIX_PLANETS) if train == "six-planet" else preset_text(train)


def stage(train: str, shaft: bool = True) -> Stage:
    """A train's stage as the independent formulations read it."""
    return Stage.parse(text(train), shaft)


@cache
def reference(train: str, shaft: bool = True) -> LumpedModel:
    """gearcheck's reference of a train; without ``shaft`` its input shaft row removed (torque-driven)."""
    model = build_model(load_text(text(train), train))
    return model if shaft else replace(model, rows=[r for r in model.rows if r.name != "input_shaft"])


def _rows(f: Formulation, name: str, change: Callable[[np.ndarray, int], np.ndarray], label: str) -> Formulation:
    """A formulation with row ``name``'s coefficient of ``label`` changed (K rebuilt from the rows: a pair changes
    rows before entries)."""
    j = f.index(label)
    rows = [(n, k, change(a.copy(), j) if n == name else a) for n, k, a in f.rows]
    return replace(f, K=sum(k * np.outer(a, a) for _, k, a in rows), rows=rows)


def _stiffness(f: Formulation, name: str, factor: float) -> Formulation:
    rows = [(n, k * factor if n == name else k, a) for n, k, a in f.rows]
    return replace(f, K=sum(k * np.outer(a, a) for _, k, a in rows), rows=rows)


def _entry(f: Formulation, a: str, b: str, value: Callable[[float], float]) -> Formulation:
    K, i, j = f.K.copy(), f.index(a), f.index(b)
    K[i, j] = K[j, i] = value(K[i, j])
    return replace(f, K=K)


def _planet_share(f: Formulation, a: str, b: str, count: int, N: int) -> Formulation:
    """Entry (a, b)'s share from the planets' rows written for ``count`` planets."""
    share = f.planets[f.index(a), f.index(b)]
    return _entry(f, a, b, lambda x: x + share * (count / N - 1.0))


def _spring(f: Formulation, a: str, b: str | None, k: float) -> Formulation:
    v = np.zeros(len(f.labels))
    v[f.index(a)] = 1.0
    if b is not None:
        v[f.index(b)] = -1.0
    return replace(f, K=f.K + k * np.outer(v, v))


def _mass(f: Formulation, labels: list[str], factor: float) -> Formulation:
    M = f.M.copy()
    for label in labels:
        M[f.index(label), f.index(label)] *= factor
    return replace(f, M=M)


def _mesh(row: str) -> str:
    """gearcheck's name of a formulation's row (a mesh by its mesh id)."""
    return row if row == "input_shaft" else f"stage1.{row}"


def _both(one: tuple, two: tuple) -> tuple:
    """A pair's broken formulation and its two expected fields, from two (formulation change, expected)."""
    return (lambda f: two[0](one[0](f))), [one[1], two[1]]


def cases(trains: tuple[str, ...] = TRAINS) -> list[Case]:
    """The corpus: each class broken several ways in each train."""
    out = []
    for train in trains:
        for shaft in (True, False):
            given = stage(train, shaft)
            N, rs, rp, rc = given.planets, given.base["sun"], given.base["planet"], given.pin_circle
            other = N - 1 if N > 3 else N + 1  # a planet count the train does not have
            cos2 = math.cos(given.alpha) ** 2
            lp, tor = translational_torsional(given), torsional(given)
            textbook = translational_torsional(given, rigid_turn=False)

            def drop(row, label):
                return (lambda f: _rows(f, row, lambda a, j: np.where(np.arange(len(a)) == j, 0.0, a), label),
                        {"kind": "dropped coupling", "row": _mesh(row), "coordinate": f"stage1.{label}"})

            def flip(row, label):
                return (lambda f: _rows(f, row, lambda a, j: np.where(np.arange(len(a)) == j, -a, a), label),
                        {"kind": "sign error", "row": _mesh(row), "coordinate": f"stage1.{label}"})

            def power(a, b, member, r, p):
                return (lambda f: _entry(f, a, b, lambda x: x * r**p),
                        {"kind": "radius power", "coordinates": {f"stage1.{a}", f"stage1.{b}"},
                         "member": f"stage1.{member}", "factor": r**p})

            def count(a, b, n):
                return (lambda f: _planet_share(f, a, b, n, N),
                        {"kind": "planet count", "coordinates": {f"stage1.{a}", f"stage1.{b}"}, "factor": n / N})

            held = [  # (class, what, formulation, change, expected): the train as given, input on its shaft
                ("dropped coupling", "sun mesh of planet 2 without the sun's u_s", lp,
                 *drop("planet2.sun", "sun.theta")),
                ("dropped coupling", "ring mesh of planet 1 without eta_1", lp,
                 *drop("planet1.ring", "planet1.tangential")),
                ("dropped coupling", "bearing of planet 3 without u_c", lp,
                 *drop("planet3.bearing_tangential", "carrier.theta")),
                ("dropped coupling", "input shaft left out", lp, *drop("input_shaft", "sun.theta")),
                ("sign error", "ring mesh of planet 1: +xi sin alpha written -", lp,
                 *flip("planet1.ring", "planet1.radial")),
                ("sign error", "sun mesh of planet 2: the sun's x term's sign", lp, *flip("planet2.sun", "sun.x")),
                ("sign error", "bearing of planet 1: +u_c", lp, *flip("planet1.bearing_tangential", "carrier.theta")),
                ("sign error", "the ring's torsional support: its only coefficient (a a^T unchanged)", lp,
                 *flip("ring.support_theta", "ring.theta")),
                ("stiffness", "sun mesh of planet 2 at half its stiffness", lp,
                 lambda f: _stiffness(f, "planet2.sun", 0.5),
                 {"kind": "stiffness", "row": "stage1.planet2.sun", "factor": 0.5}),
                ("stiffness", "bearing of planet 1 ten times stiff", lp,
                 lambda f: _stiffness(f, "planet1.bearing_radial", 10.0),
                 {"kind": "stiffness", "row": "stage1.planet1.bearing_radial", "factor": 10.0}),
                ("stiffness", "ring's torsional support in N mm/rad", lp,
                 lambda f: _stiffness(f, "ring.support_theta", 1e3),
                 {"kind": "stiffness", "row": "stage1.ring.support_theta", "factor": 1e3}),
                ("inertia", "planet 1's mass times 1.5", lp,
                 lambda f: _mass(f, ["planet1.radial", "planet1.tangential"], 1.5),
                 {"kind": "inertia", "member": "stage1.planet1", "factor": 1.5}),
                ("inertia", "the carrier's inertia times 0.7", lp, lambda f: _mass(f, ["carrier.theta"], 0.7),
                 {"kind": "inertia", "member": "stage1.carrier", "coordinates": {"stage1.carrier.theta"},
                  "factor": 0.7}),
                ("inertia", "the sun's inertia times 2 (torsional)", tor, lambda f: _mass(f, ["sun.theta"], 2.0),
                 {"kind": "inertia", "member": "stage1.sun", "factor": 2.0}),
                ("inertia convention", "sun: I / r_p^2 for I / r_b^2", lp, lambda f: _mass(f, ["sun.theta"], cos2),
                 {"kind": "inertia", "member": "stage1.sun", "factor": cos2, "named": "cos^2 alpha"}),
                ("inertia convention", "ring: I / r_b^2 for I / r_p^2", lp,
                 lambda f: _mass(f, ["ring.theta"], 1.0 / cos2),
                 {"kind": "inertia", "member": "stage1.ring", "factor": 1.0 / cos2, "named": "1/cos^2 alpha"}),
                ("inertia convention", "sun: I / r_p^2 for I / r_b^2 (torsional)", tor,
                 lambda f: _mass(f, ["sun.theta"], cos2),
                 {"kind": "inertia", "member": "stage1.sun", "factor": cos2, "named": "cos^2 alpha"}),
                ("extra spring", "planet 1's radial motion to ground", lp,
                 lambda f: _spring(f, "planet1.radial", None, 1e8),
                 {"kind": "extra spring", "coordinates": {"stage1.planet1.radial"}, "stiffness": 1e8}),
                ("extra spring", "planets 1 and 2 radially coupled", lp,
                 lambda f: _spring(f, "planet1.radial", "planet2.radial", 5e7),
                 {"kind": "extra spring", "coordinates": {"stage1.planet1.radial", "stage1.planet2.radial"},
                  "stiffness": 5e7}),
                ("radius power", "K_cc = N r_c k_p for N r_c^2 k_p (torsional)", tor,
                 *power("carrier.theta", "carrier.theta", "carrier", rc, -1)),
                ("radius power", "K_sp of planet 2 without r_p (torsional)", tor,
                 *power("sun.theta", "planet2.theta", "planet2", rp, -1)),
                ("radius power", "sun mesh of planet 1 with r_s u_s", lp,
                 lambda f: _rows(f, "planet1.sun", lambda a, j: np.where(np.arange(len(a)) == j, a * rs, a),
                                 "sun.theta"),
                 {"kind": "radius power", "row": "stage1.planet1.sun", "coordinate": "stage1.sun.theta",
                  "factor": rs}),
                ("radius power", "K_uc,uc = N k_p r_c^2 in u", lp, *power("carrier.theta", "carrier.theta", "carrier",
                                                                          rc, 2)),
                ("planet count", f"K_cc (u) written {other} k_p", lp, *count("carrier.theta", "carrier.theta", other)),
                ("planet count", f"the sun's K_xx planet sum for {other} planets", lp, *count("sun.x", "sun.x", other)),
                ("planet count", f"K_ss = {other} k r_s^2 + k_shaft (torsional)", tor,
                 *count("sun.theta", "sun.theta", other)),
                ("planet count", f"K_rr = {other} k r_r^2 + k_rt (torsional)", tor,
                 *count("ring.theta", "ring.theta", other)),
                ("pair", "a dropped sun coupling and a flipped ring sign", lp,
                 *_both(drop("planet2.sun", "sun.theta"), flip("planet1.ring", "planet1.radial"))),
                ("pair", "N r_c k and a planet sum for another count", lp,
                 *_both(power("carrier.theta", "carrier.theta", "carrier", rc, -1), count("sun.x", "sun.x", other))),
                ("pair", "a dropped bearing coupling and a flipped sun sign", lp,
                 *_both(drop("planet3.bearing_tangential", "carrier.theta"), flip("planet2.sun", "sun.x"))),
            ]
            free = [  # the train torque-driven: one rigid-body mode
                ("extra spring", "a carrier torsional support the train has none of", lp,
                 lambda f: _spring(f, "carrier.theta", None, 1e6),
                 {"kind": "extra spring", "coordinates": {"stage1.carrier.theta"}, "stiffness": 1e6}),
                ("extra spring", "a torsional spring between sun and carrier", lp,
                 lambda f: _spring(f, "sun.theta", "carrier.theta", 1e4),
                 {"kind": "extra spring", "coordinates": {"stage1.sun.theta", "stage1.carrier.theta"},
                  "stiffness": 1e4}),
                ("radius power", "K_cc = N r_c k_p for N r_c^2 k_p", lp,
                 *power("carrier.theta", "carrier.theta", "carrier", rc, -1)),
                ("planet count", f"K_cc (u) written {other} k_p", lp, *count("carrier.theta", "carrier.theta", other)),
            ]
            at_speed = [  # seen only at speed
                ("rigid-turn correction", "textbook centripetal stiffness", textbook, None,
                 {"kind": "rigid-turn correction"}),
                ("gyroscopic", "Coriolis terms left out", lp, lambda f: replace(f, G=np.zeros_like(f.G)),
                 {"kind": "gyroscopic"}),
            ]
            for mistake, what, formulation, change, expected in (held if shaft else free) + at_speed:
                broken = formulation if change is None else change(formulation)
                unbroken = tor if formulation is tor else lp
                out.append(Case(train, shaft, "torsional" if formulation is tor else "translational-torsional",
                                mistake, what, expected if isinstance(expected, list) else [expected], broken,
                                unbroken))
    return out


def evidence(f: Formulation, at_speed: bool) -> Evidence:
    """A formulation's modes at rest with shapes and, ``at_speed``, its gyroscopic frequencies."""
    frequencies, shapes = generalized_modes(f.K, f.M)
    speed = (speed_modal_result("corpus", "textbook", f.M, f.G, f.K + f.Kc, f.labels, None, None, 0.0).frequencies
             if at_speed else None)
    return Evidence(list(f.labels), frequencies, shapes, f.M, speed)


def _matches(candidate, expected: dict) -> bool:
    for key, value in expected.items():
        got = candidate.term if key == "named" else getattr(candidate, key)
        if key == "named":
            ok = f"(= {value}" in got
        elif key in ("factor", "stiffness"):
            ok = got is not None and abs(got / value - 1.0) <= MATCH
        elif key == "coordinates":
            ok = set(got) == value
        else:
            ok = got == value
        if not ok:
            return False
    return True


def _rigid(f: Formulation) -> int:
    """Zero frequencies of the modes at rest (a negative stiffness's too, as the evidence gives it)."""
    w2 = np.linalg.eigvals(np.linalg.solve(f.M, f.K)).real
    return int(np.sum(w2 <= RIGID_TOLERANCE * np.max(np.abs(w2))))


def _effect(case: Case, speed: bool) -> bool:
    """The broken modes are not the unbroken formulation's (at rest: eigenpairs; at speed: frequencies)."""
    b, u = case.broken, case.unbroken
    w, X = generalized_modes(b.K, b.M)
    lam = (2.0 * np.pi * w) ** 2
    residual = np.linalg.norm(u.K @ X - u.M @ X * lam, axis=0) / np.maximum(np.linalg.norm(u.K @ X, axis=0), 1e-300)
    if np.max(residual) > SAME_MODES:
        return True
    if not speed:
        return False
    fb, fu = evidence(b, True).frequencies_at_speed, evidence(u, True).frequencies_at_speed
    return bool(np.any(np.abs(fb - fu) > 1e-9 * np.maximum(fb, fu)))


def _right(candidate: Candidate, expected: list[dict]) -> bool:
    if len(expected) == 1:
        return _matches(candidate, expected[0])
    return candidate.kind == "pair" and any(_matches(candidate.pair[0], a) and _matches(candidate.pair[1], b)
                                            for a, b in (expected, expected[::-1]))


def run(case: Case, shapes: bool = True) -> Outcome:
    """Diagnose one case against the reference; without ``shapes`` from its frequencies alone."""
    speed = case.formulation == "translational-torsional"
    given = evidence(case.broken, speed)
    if not shapes:
        given = replace(given, shapes=None, mass=None)
    diagnosis = diagnose(reference(case.train, case.shaft), given)
    best = diagnosis.best
    hit = _right(best, case.expected)
    in_class = any(_right(c, case.expected) for c in best.alike())
    rigid = (_rigid(case.broken), _rigid(case.unbroken))
    said = ("lost" if rigid[0] < rigid[1] else "gained") if rigid[0] != rigid[1] else None
    reported = (diagnosis.rigid_modes == {"evidence": rigid[0], "reference": rigid[1]}
                and (said is None or any(line.startswith(f"Rigid-body modes {said}") for line in diagnosis.lines())))
    margin = diagnosis.candidates[1].score - best.score if len(diagnosis.candidates) > 1 else math.inf
    return Outcome(case, diagnosis, _effect(case, speed) and not diagnosis.agrees, hit, in_class, margin, rigid,
                   reported)


def agreement(train: str, shaft: bool = True) -> dict[str, Candidate]:
    """The unbroken formulations diagnosed against the reference: the reference's own candidate (held where the
    formulation lacks coordinates), whose score parts are the frequency errors at rest and at speed and the mean
    1 - MAC of the shapes."""
    given, out = stage(train, shaft), {}
    for name, f, speed in (("translational-torsional", translational_torsional(given), True),
                           ("torsional", torsional(given), False)):
        out[name] = diagnose(reference(train, shaft), evidence(f, speed)).best
    return out


def table(outcomes: list[Outcome]) -> list[str]:
    """The hit-rate table by class (Markdown): cases, no effect, right term named first, hit rate over the cases
    with an effect, right term in the first class of look-alikes, median margin to the runner-up, rigid-body mode
    changes reported."""
    lines = ["| class | cases | no effect | named first | hit rate | in the first class | median margin "
             "| rigid modes lost/gained reported |",
             "|---|---|---|---|---|---|---|---|"]
    for name in (*CLASSES, "all"):
        group = [o for o in outcomes if name in (o.case.mistake, "all")]
        if not group:
            continue
        seen = [o for o in group if o.effect]
        hits = [o for o in seen if o.hit]
        changed = [o for o in group if o.rigid[0] != o.rigid[1]]
        margin = f"{np.median([o.margin for o in hits]):.3g}" if hits else "-"
        rate = f"{len(hits) / len(seen):.0%}" if seen else "-"
        lines.append(f"| {name} | {len(group)} | {len(group) - len(seen)} | {len(hits)}/{len(seen)} | {rate} | "
                     f"{sum(o.in_class for o in seen)}/{len(seen)} | {margin} | "
                     f"{sum(o.rigid_reported for o in changed)}/{len(changed)} |")
    return lines


def rates(outcomes: list[Outcome]) -> dict[str, float]:
    """Hit rate per class and overall, over the cases with an effect."""
    out = {}
    for name in (*CLASSES, "all"):
        seen = [o for o in outcomes if o.effect and name in (o.case.mistake, "all")]
        if seen:
            out[name] = sum(o.hit for o in seen) / len(seen)
    return out

