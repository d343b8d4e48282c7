"""A single-stage planetary written from the papers' equations in plain numpy, independent of gearcheck's assembly.

Two formulations of a preset's stage (sun input, ring held, carrier output, N equally spaced planets), read from
its TOML file, for the diagnosis corpus (:mod:`gearcheck.compare.studies.diagnosis_corpus`):

* :func:`translational_torsional`: Lin & Parker (1999): central members x, y, u and planets xi (radial), eta
  (tangential), u, with u = r theta (r a gear's base radius, the carrier's pin circle), in the carrier's frame;
  the mesh and bearing deflections of their Eqs. (1)-(3), M = diag(m, m, I/r^2), G = 2 m Omega [[0, -1], [1, 0]]
  on each member's translations, and the centripetal stiffness -m Omega^2 on every translation with, optionally,
  the planets' rigid-turn term m Omega^2 (u_c^2/2 + u_c s_t) (s_t a bearing's tangential deflection) that makes
  a rigid turn force-free (gearcheck's README);
* :func:`torsional`: Kahraman (1994)-style rotational coordinates theta_s, theta_r, theta_c, theta_n, the
  planet centres held, the carrier on the planet bearings' tangential stiffness, K written entry by entry.

Both come back in gearcheck's coordinates (:class:`Formulation`: theta = u / r); a formulation is a set of
matrices a test breaks as the literature's slips break them.
"""

from __future__ import annotations

import importlib.resources
import math
import tomllib
from dataclasses import dataclass, field

import numpy as np

RPM = 2.0 * math.pi / 60.0


@dataclass
class Stage:
    """A preset's stage, from its TOML file: masses (kg), inertias (kg m^2), base radii and the pin circle (m),
    stiffnesses (N/m, N m/rad), the carrier's speed (rad/s)."""

    name: str
    planets: int
    mass: dict[str, float]
    inertia: dict[str, float]
    base: dict[str, float]
    pitch: dict[str, float]
    pin_circle: float
    alpha: float
    k_mesh: float
    k_bearing: float
    k_support: dict[str, float]
    k_ring_torsion: float
    k_shaft: float
    carrier_speed: float

    @classmethod
    def preset(cls, name: str, shaft: bool = True) -> Stage:
        """The stage of a preset; without ``shaft`` the input is free (a torque-driven train: one rigid mode)."""
        return cls.parse((importlib.resources.files("gearcheck.train.presets") / f"{name}.toml").read_text(), shaft)

    @classmethod
    def parse(cls, text: str, shaft: bool = True) -> Stage:
        """The stage of a train file's text (one stage, sun in, ring held, carrier out)."""
        raw = tomllib.loads(text)
        name = raw["train"]["name"]
        stage, op = raw["stages"][0], raw["operating"]
        module, alpha = stage["module_mm"] * 1e-3, math.radians(stage["pressure_angle_deg"])
        teeth = {g: stage[g]["teeth"] for g in ("sun", "ring", "planet")}
        pitch = {g: 0.5 * module * z for g, z in teeth.items()}
        members = ("sun", "ring", "carrier", "planet")
        return cls(name, stage["planets"], {m: stage[m]["mass"] for m in members},
                   {m: stage[m]["inertia"] for m in members}, {g: r * math.cos(alpha) for g, r in pitch.items()},
                   pitch, pitch["sun"] + pitch["planet"], alpha, stage["mesh"]["stiffness"]["mean"],
                   stage["planet"]["bearing"]["radial_stiffness"],
                   {m: stage[m]["support"]["radial_stiffness"] for m in ("sun", "ring", "carrier")},
                   stage["ring"]["support"]["torsional_stiffness"], op["input_shaft_stiffness"] if shaft else 0.0,
                   op["input_speed_rpm"] * RPM * teeth["sun"] / (teeth["sun"] + teeth["ring"]))

    @property
    def psi(self) -> np.ndarray:
        return 2.0 * np.pi * np.arange(self.planets) / self.planets


@dataclass
class Formulation:
    """Matrices over ``labels`` (gearcheck's names): M, K at rest, G and the centripetal stiffness Kc at the
    carrier's speed; ``planets``: the planets' share of K (the papers' sums over the planets); ``rows``: named
    deflections (name, k, a) where the formulation has them."""

    labels: list[str]
    M: np.ndarray
    K: np.ndarray
    G: np.ndarray
    Kc: np.ndarray
    planets: np.ndarray
    rows: list[tuple[str, float, np.ndarray]] = field(default_factory=list)

    def index(self, label: str) -> int:
        return self.labels.index(f"stage1.{label}")


def _labels(N: int, translations: bool) -> list[str]:
    central = [("sun", "x", "y"), ("ring", "x", "y"), ("carrier", "x", "y")]
    planets = [(f"planet{n + 1}", "radial", "tangential") for n in range(N)]
    return [f"stage1.{m}.{d}" for m, *t in central + planets for d in ((*t, "theta") if translations else ("theta",))]


def translational_torsional(stage: Stage, rigid_turn: bool = True) -> Formulation:
    """Lin & Parker (1999) in u = r theta, mapped to gearcheck's theta (D = diag(r) on the rotations): M, G, Kc as
    D (.) D, rows as a D."""
    N, a = stage.planets, stage.alpha
    labels = _labels(N, True)
    n = len(labels)
    at = {label.removeprefix("stage1."): i for i, label in enumerate(labels)}

    def row(**c):
        v = np.zeros(n)
        for key, value in c.items():
            v[at[key.replace("__", ".")]] = value
        return v

    k, kp = stage.k_mesh, stage.k_bearing
    radius = {"sun": stage.base["sun"], "ring": stage.base["ring"], "carrier": stage.pin_circle,
              "planet": stage.base["planet"]}
    rows = [(f"{m}.support_{d}", stage.k_support[m], row(**{f"{m}__{d}": 1.0}))
            for m in ("sun", "ring", "carrier") for d in ("x", "y")]
    rows.append(("ring.support_theta", stage.k_ring_torsion, row(ring__theta=1.0 / radius["ring"])))  # theta = u/r
    if stage.k_shaft:
        rows.append(("input_shaft", stage.k_shaft, row(sun__theta=1.0 / radius["sun"])))
    for i, psi in enumerate(stage.psi):
        p = f"planet{i + 1}"
        ps, pr = psi - a, psi + a  # Lin & Parker's psi_sn, psi_rn
        rows.append((f"{p}.sun", k, row(sun__x=-math.sin(ps), sun__y=math.cos(ps), sun__theta=1.0,
                                        **{f"{p}__radial": -math.sin(a), f"{p}__tangential": -math.cos(a),
                                           f"{p}__theta": 1.0})))
        rows.append((f"{p}.ring", k, row(ring__x=-math.sin(pr), ring__y=math.cos(pr), ring__theta=1.0,
                                         **{f"{p}__radial": math.sin(a), f"{p}__tangential": -math.cos(a),
                                            f"{p}__theta": -1.0})))
        rows.append((f"{p}.bearing_radial", kp, row(carrier__x=-math.cos(psi), carrier__y=-math.sin(psi),
                                                     **{f"{p}__radial": 1.0})))
        rows.append((f"{p}.bearing_tangential", kp, row(carrier__x=math.sin(psi), carrier__y=-math.cos(psi),
                                                         carrier__theta=-1.0, **{f"{p}__tangential": 1.0})))
    M, G, Kc = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    D = np.ones(n)
    W = stage.carrier_speed
    for label, i in at.items():
        member, dof = label.split(".")
        kind = "planet" if member.startswith("planet") else member
        m = stage.mass[kind]
        if dof == "theta":
            M[i, i], D[i] = stage.inertia[kind] / radius[kind] ** 2, radius[kind]
        else:
            M[i, i], Kc[i, i] = m, -m * W**2
    for member in ("sun", "ring", "carrier", *(f"planet{i + 1}" for i in range(N))):
        x, y = (at[f"{member}.{d}"] for d in (("radial", "tangential") if member.startswith("planet") else "xy"))
        m = stage.mass["planet" if member.startswith("planet") else member]
        G[x, y], G[y, x] = -2.0 * m * W, 2.0 * m * W
    if rigid_turn:
        uc = row(carrier__theta=1.0)
        for name, _, s_t in rows:
            if name.endswith("bearing_tangential"):
                Kc += stage.mass["planet"] * W**2 * (np.outer(uc, uc) + np.outer(uc, s_t) + np.outer(s_t, uc))
    rows = [(name, kr, v * D) for name, kr, v in rows]
    K = sum(kr * np.outer(v, v) for _, kr, v in rows)
    P = sum(kr * np.outer(v, v) for name, kr, v in rows if name.startswith("planet"))
    return Formulation(labels, D * M * D[:, None], K, D * G * D[:, None], D * Kc * D[:, None], P, rows)


def torsional(stage: Stage) -> Formulation:
    """Rotational coordinates only, the planet centres held: K entry by entry (Kahraman 1994's torsional form,
    the carrier held by the planet bearings' tangential stiffness k_p r_c^2)."""
    N, k, kp = stage.planets, stage.k_mesh, stage.k_bearing
    rs, rr, rp, rc = stage.base["sun"], stage.base["ring"], stage.base["planet"], stage.pin_circle
    n = 3 + N
    K, M = np.zeros((n, n)), np.diag([stage.inertia[m] for m in ("sun", "ring", "carrier")]
                                     + [stage.inertia["planet"]] * N)
    K[0, 0] = N * k * rs**2 + stage.k_shaft
    K[1, 1] = N * k * rr**2 + stage.k_ring_torsion
    K[2, 2] = N * kp * rc**2
    for p in range(3, n):
        K[p, p] = 2.0 * k * rp**2
        K[0, p] = K[p, 0] = k * rs * rp
        K[1, p] = K[p, 1] = -k * rr * rp
    P = K - np.diag([stage.k_shaft, stage.k_ring_torsion] + [0.0] * (n - 2))  # all but the shaft and support
    zero = np.zeros((n, n))
    return Formulation(_labels(N, False), M, K, zero, zero, P)
