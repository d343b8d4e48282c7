"""A linear lumped model given as matrices: the way in for a model gearcheck did not build.

A user's model (written in Python, or exported from MATLAB as a file of matrices) is

    M q'' + (C + G + sum_m c_m a_m a_m^T) q' + (K(t) + K_omega + sum_m k_m(t) a_m a_m^T) q = F(t)

over its own coordinates q: M its mass matrix, C its damping, G its gyroscopic matrix (skew), K(t) its
stiffness (mean K, optionally periodic over a mesh cycle), K_omega its speed-dependent stiffness
(centripetal softening, circulatory terms), F(t) its forcing (mean F), and
each mesh m a deflection row a_m (the mesh's compression along its line of action) with a periodic
stiffness k_m(t) and a damping c_m -- the usual structure of a gear model (Lin & Parker 1999; Kahraman
1994).  ``physical`` says what its coordinates are in the train's: each of gearcheck's physical
coordinates (``stage1.sun.x``, ``stage1.planet1.tangential``, ``stage1.ring.theta``, ...) as a
combination of the model's coordinates.  Through that map the model reports the train's named signals,
computed from its own motion and its own meshes.

G and K_omega are given at the train's operating speed (``G``, ``K_omega``) or, as rotordynamics codes
hand them out, per unit speed (``G_per_speed`` per rad/s, ``K_omega_per_speed2`` per (rad/s)^2, of the speed
of ``speed_of``: ``"input"`` or a member id such as ``"stage1.carrier"``); :meth:`LinearModel.frame_terms`
gives both at any speed, G scaling with it and K_omega with its square (Cooley & Parker 2012).

Train coordinates the model lacks (a reduced model: a ring eliminated, translations left out) are, in the
reference it is compared with, held at zero (``reduction="held"``) or statically condensed out
(``"condensed"``, Guyan 1965).  Coordinates of the model that map to no train coordinate (a motor, a
coupling, a generator) are extra coordinates: kept in its dynamics, and the modes they dominate set aside
in comparisons (:mod:`gearcheck.lumped.side`).

:meth:`LinearModel.check` validates it as the loader validates a train file: one line per error,
naming the source, the field and the value.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from gearcheck.shared.errors import TrainFileError, did_you_mean
from gearcheck.shared.stepping import LIMIT_CYCLES
from gearcheck.train.kinematics import kinematics

SYMMETRY_TOLERANCE = 1e-9  # relative asymmetry of M, K, C accepted as round-off
MEAN_TOLERANCE = 1e-6  # relative difference accepted between a given mean and the mean of the samples
UNIT_SLIP = 100.0  # a mass or inertia this many times off the train's own is taken for a unit slip
START = ("static", "rest")
INTERPOLATIONS = ("linear", "hold")
REDUCTIONS = ("held", "condensed")  # what the reference does with the train coordinates a model lacks
SPEED_FORMS = (("G", "G_per_speed"), ("K_omega", "K_omega_per_speed2"))  # (at the operating speed, per unit speed)


@dataclass(frozen=True)
class Periodic:
    """A quantity periodic in ``period`` (s): ``samples`` (N, ...) at t = i period / N, linearly interpolated
    (``interpolation="linear"``: a smooth quantity) or each held until the next (``"hold"``: a quantity with
    jumps, such as the stiffness of a mesh as its tooth pairs come and go); or a Fourier series
    ``mean_value`` + sum_h ``cos[h]`` cos(2 pi orders[h] t / period) + ``sin[h]`` sin(...)."""

    period: float
    samples: np.ndarray | None = None
    interpolation: str = "linear"
    mean_value: np.ndarray | None = None
    orders: np.ndarray | None = None
    cos: np.ndarray | None = None
    sin: np.ndarray | None = None

    @property
    def mean(self) -> np.ndarray:
        return self.samples.mean(axis=0) if self.samples is not None else self.mean_value

    def __call__(self, t, side=0) -> np.ndarray:
        """The value at time ``t`` (s), or at each of an array of times (along the leading axes); ``side`` (+1, -1
        or 0, broadcast with t) the right-hand or left-hand limit of held samples that change at t,
        :data:`~gearcheck.shared.stepping.LIMIT_CYCLES` of a period on."""
        t = np.asarray(t, dtype=float)
        if self.samples is not None:
            n = len(self.samples)
            x = ((t / self.period + np.multiply(side, LIMIT_CYCLES)) % 1.0) * n
            i = np.floor(x).astype(int) % n
            if self.interpolation == "hold":
                return self.samples[i]
            w = (x - np.floor(x))[(...,) + (None,) * (self.samples.ndim - 1)]
            return (1.0 - w) * self.samples[i] + w * self.samples[(i + 1) % n]
        phase = 2.0 * math.pi * np.multiply.outer(t, np.asarray(self.orders)) / self.period
        return self.mean_value + np.tensordot(np.cos(phase), self.cos, 1) + np.tensordot(np.sin(phase), self.sin, 1)

    def rate(self) -> "Periodic":
        """The time derivative: exact for a series; of samples, their central differences (second order),
        linearly interpolated."""
        if self.samples is None:
            w = (2.0 * math.pi * np.asarray(self.orders, dtype=float) / self.period).reshape(
                (-1,) + (1,) * (np.ndim(self.cos) - 1))
            return Periodic(self.period, mean_value=np.zeros_like(self.mean_value), orders=self.orders,
                            cos=w * self.sin, sin=-w * self.cos)
        n = len(self.samples)
        return Periodic(self.period, samples=(np.roll(self.samples, -1, 0) - np.roll(self.samples, 1, 0)) * n
                        / (2.0 * self.period))

    def over_period(self, points: int = 64) -> np.ndarray:
        """Values over one period: the samples themselves, or the series at ``points`` phases."""
        if self.samples is not None:
            return self.samples
        return self(np.arange(points) * self.period / points)


@dataclass(frozen=True)
class Mesh:
    """A mesh of the model: deflection ``row`` . q along the line of action (m), stiffness k(t) (N/m, a
    :class:`Periodic` of scalars or a constant), damping (N s/m) and static transmission error e(t) (m, a
    :class:`Periodic` of scalars, or None): the mesh's force is k (row . q - e) + c (row . q' - e').  ``id`` is
    the train's mesh id (``stage1.planet1.sun``): the model then reports that mesh's force and transmission
    error."""

    id: str
    row: np.ndarray
    stiffness: Periodic | float
    damping: float = 0.0
    error: Periodic | None = None

    def transmission_error(self, t, side=0) -> tuple[np.ndarray, np.ndarray]:
        """(e, e') at time ``t`` (s) or at each of an array of times (``side``: :meth:`Periodic.__call__`): zero
        when the mesh has none."""
        if self.error is None:
            return np.zeros(np.shape(t)), np.zeros(np.shape(t))
        return self.error(t, side), self._error_rate(t, side)

    @cached_property
    def _error_rate(self) -> Periodic:
        return self.error.rate()

    def k(self, t, side=0) -> np.ndarray:
        """The stiffness at time ``t`` (s), or at each of an array of times (``side``: :meth:`Periodic.__call__`)."""
        if isinstance(self.stiffness, Periodic):
            return self.stiffness(t, side)
        return np.full(np.shape(t), float(self.stiffness))

    @property
    def k_mean(self) -> float:
        return float(self.stiffness.mean) if isinstance(self.stiffness, Periodic) else float(self.stiffness)

    @property
    def k_max(self) -> float:
        s = self.stiffness
        return float(np.max(s.over_period())) if isinstance(s, Periodic) else float(s)


@dataclass
class LinearModel:
    """M q'' + (C + G + mesh damping) q' + (K(t) + K_omega + mesh stiffness) q = F(t) over ``coordinates``.

    G, K_omega: at the train's operating speed; or G_per_speed (per rad/s), K_omega_per_speed2 (per
    (rad/s)^2) of the speed of ``speed_of`` ("input" or a member id), one form of each.
    stiffness: K(t) (a :class:`Periodic` of matrices whose mean is K), or None (K constant).
    forcing: F(t) (a :class:`Periodic` whose mean is F, or any callable of t), or None (F constant).
    physical: train coordinate label -> {model coordinate: coefficient}; None: the model's coordinates are
    the train's own labels.  start: "static" (from K_mean q = F) or "rest" (q = q' = 0).
    reduction: "held" or "condensed", what the reference does with the train coordinates the model lacks.
    descriptions: coordinate -> what it is (reports).  notes: what was done to the model (reports show them).
    """

    name: str
    coordinates: list[str]
    M: np.ndarray
    K: np.ndarray
    C: np.ndarray | None = None
    G: np.ndarray | None = None
    K_omega: np.ndarray | None = None
    G_per_speed: np.ndarray | None = None
    K_omega_per_speed2: np.ndarray | None = None
    speed_of: str = "input"
    F: np.ndarray | None = None
    stiffness: Periodic | None = None
    forcing: Periodic | Callable | None = None
    meshes: list[Mesh] = field(default_factory=list)
    physical: dict[str, dict[str, float]] | None = None
    start: str = "static"
    reduction: str = "held"
    descriptions: dict[str, str] = field(default_factory=dict)
    source: str = ""  # the file or factory it came from: error messages name it
    notes: list[str] = field(default_factory=list)
    operating_speed: float | None = None  # rad/s, the input speed G and K_omega are at (set by check with a train)
    speed_ratio: float = 1.0  # the speed of speed_of over the input speed (set by check with a train)

    @property
    def n(self) -> int:
        return len(self.coordinates)

    def matrix(self, name: str) -> np.ndarray:
        """A matrix or vector by its field name, zeros when not given."""
        value = getattr(self, name)
        if value is not None:
            return np.asarray(value, dtype=float)
        return np.zeros(self.n) if name == "F" else np.zeros((self.n, self.n))

    @property
    def mesh_rows(self) -> np.ndarray:
        return np.array([m.row for m in self.meshes], dtype=float).reshape(len(self.meshes), self.n)

    def _mesh_sum(self, values) -> np.ndarray:
        A = self.mesh_rows
        return (A.T * np.asarray(values, dtype=float)) @ A

    @property
    def K_mean(self) -> np.ndarray:
        """The stiffness of the modes: K with every mesh at its mean stiffness."""
        return self.matrix("K") + self._mesh_sum([m.k_mean for m in self.meshes])

    @property
    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """(G, K_omega) at the operating speed (:meth:`frame_terms`)."""
        return self.frame_terms(self.operating_speed)

    @property
    def damping(self) -> np.ndarray:
        """Everything that multiplies q': C + G + the meshes' damping."""
        return self.matrix("C") + self.frame[0] + self._mesh_sum([m.damping for m in self.meshes])

    def K_peak(self) -> np.ndarray:
        """A stiffness no less than K(t) + K_omega's symmetric part at any time (the stable step's bound)."""
        K = self.matrix("K")
        if self.stiffness is not None:
            over = self.stiffness.over_period()
            worst = max(range(len(over)), key=lambda i: np.linalg.eigvalsh(0.5 * (over[i] + over[i].T))[-1])
            K = over[worst]
        K_omega = self.frame[1]
        return K + 0.5 * (K_omega + K_omega.T) + self._mesh_sum([m.k_max for m in self.meshes])

    @property
    def massless(self) -> list[int]:
        """Indices of the coordinates without mass: their row and column of M exactly zero."""
        M = np.asarray(self.M, dtype=float)
        return [i for i in range(self.n) if not M[i].any() and not M[:, i].any()]

    @property
    def extra(self) -> list[str]:
        """The coordinates that map to no train coordinate (a motor, a coupling, a generator) in a model that maps
        some; none in a model that maps none (one compared by its own signals, as the published 4-DOF models)."""
        used = {c for combination in self.physical_map().values() for c in combination}
        return [c for c in self.coordinates if c not in used] if used else []

    def frame_terms(self, input_speed: float) -> tuple[np.ndarray, np.ndarray]:
        """(G, K_omega) with the train's input at ``input_speed`` (rad/s): G_per_speed Omega and
        K_omega_per_speed2 Omega^2 (Omega the speed of ``speed_of``), or G and K_omega scaled from the operating
        speed they are given at, G with the speed and K_omega with its square (Cooley & Parker 2012)."""
        if input_speed is None:
            if self.G_per_speed is not None or self.K_omega_per_speed2 is not None:
                raise self._error("G_per_speed", "per unit speed: needs the train's operating speed (check(spec))")
            return self.matrix("G"), self.matrix("K_omega")
        omega = self.speed_ratio * input_speed
        if self.G_per_speed is not None:
            G = omega * self.matrix("G_per_speed")
        else:
            G = self._scaled("G", input_speed, 1)
        if self.K_omega_per_speed2 is not None:
            K_omega = omega * omega * self.matrix("K_omega_per_speed2")
        else:
            K_omega = self._scaled("K_omega", input_speed, 2)
        return G, K_omega

    def _scaled(self, name: str, input_speed: float, power: int) -> np.ndarray:
        A = self.matrix(name)
        if not A.any() or input_speed == self.operating_speed:
            return A
        if not self.operating_speed:
            raise self._error(name, f"given at the operating speed, which is {self.operating_speed}: give it per unit "
                              f"speed ({dict(SPEED_FORMS)[name]})")
        return (input_speed / self.operating_speed) ** power * A

    def F_at(self, t: float, side: int = 0) -> np.ndarray:
        """The forcing at time t (``side``: :meth:`Periodic.__call__`; a callable forcing is read at t itself)."""
        if self.forcing is None:
            return self.matrix("F")
        return np.asarray(self.forcing(t, side) if isinstance(self.forcing, Periodic) else self.forcing(t), dtype=float)

    def K_at(self, t: float, side: int = 0) -> np.ndarray:
        return self.matrix("K") if self.stiffness is None else self.stiffness(t, side)

    # -- validation ---------------------------------------------------------------------------------------

    def check(self, spec=None, labels: list[str] | None = None) -> "LinearModel":
        """Validate shapes, symmetry, positive definiteness of M, the periodic parts against their means and,
        given the train (``spec``, its coordinate ``labels``), the map and the units; returns self."""
        n = self.n
        if n == 0 or len(set(self.coordinates)) != n:
            raise self._error("coordinates", f"{n} names with {n - len(set(self.coordinates))} repeated: need at "
                              "least one, each once")
        for name in ("M", "K", "C", "G", "K_omega", "G_per_speed", "K_omega_per_speed2", "F"):
            self._check_array(name, (n,) if name == "F" else (n, n), required=name in ("M", "K"))
        for at_speed, per_speed in SPEED_FORMS:
            if getattr(self, at_speed) is not None and getattr(self, per_speed) is not None:
                raise self._error(per_speed, f"given with {at_speed}: give {at_speed} at the operating speed or "
                                  f"{per_speed} per unit speed, not both")
        M = self.matrix("M")
        for name in ("M", "K", "C"):
            self._check_symmetric(name, +1)
        self._check_symmetric("G", -1)
        self._check_symmetric("G_per_speed", -1)
        massive = [i for i in range(n) if i not in self.massless]
        if not massive:
            raise self._error("M", "all zero: the model needs mass or inertia")
        lowest = np.linalg.eigvalsh(M[np.ix_(massive, massive)])[0]
        if lowest <= 0:
            raise self._error("M", f"not positive definite (eigenvalue {lowest:.4g}): every coordinate needs mass "
                              "or inertia, or none (a row and column of exact zeros: condensed)")
        if self.stiffness is not None:
            self._check_periodic("stiffness", self.stiffness, (n, n), "K")
        if isinstance(self.forcing, Periodic):
            self._check_periodic("forcing", self.forcing, (n,), "F")
        for j, mesh in enumerate(self.meshes):
            self._check_mesh(j, mesh)
        if self.start not in START:
            raise self._error("start", f"{self.start!r}: choose {' or '.join(START)}")
        if self.reduction not in REDUCTIONS:
            raise self._error("reduction", f"{self.reduction!r}: choose {' or '.join(REDUCTIONS)}")
        if spec is not None:
            self._check_map(spec, labels)
            self._set_speed(spec)
        return self

    def _set_speed(self, spec) -> None:
        """The operating speed G and K_omega are at, and the speed ``speed_of`` names over the input's."""
        self.operating_speed = spec.operating.input_speed
        if self.speed_of != "input":
            carriers = [m for m in spec.members if m.endswith(".carrier")]
            member = carriers[0] if self.speed_of == "carrier" and len(carriers) == 1 else self.speed_of
            if member not in spec.members:
                raise self._error("speed_of", f"{self.speed_of!r}: 'input' or a member of {spec.name} "
                                  f"({', '.join(spec.members)})")
            if not self.operating_speed:
                raise self._error("speed_of", f"{self.speed_of!r}: {spec.name} does not turn (input speed 0), so no "
                                  "ratio of speeds: give the per-unit-speed forms per rad/s of the input")
            self.speed_ratio = kinematics(spec).speeds[member] / self.operating_speed

    def _error(self, field_name: str, message: str) -> TrainFileError:
        return TrainFileError(self.source or self.name, field_name, message)

    def _check_array(self, name: str, shape: tuple, required: bool) -> None:
        value = getattr(self, name)
        if value is None:
            if required:
                raise self._error(name, "missing")
            return
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise self._error(name, "not a numeric array") from None
        if array.shape != shape:
            raise self._error(name, f"shape {array.shape}, expected {shape} ({self.n} coordinates)")
        bad = np.argwhere(~np.isfinite(array))
        if bad.size:
            raise self._error(name, f"entry {tuple(int(i) for i in bad[0])} is {array[tuple(bad[0])]}")
        setattr(self, name, array)

    def _check_symmetric(self, name: str, sign: int) -> None:
        A = getattr(self, name)
        if A is None:
            return
        scale = np.max(np.abs(A)) or 1.0
        gap = np.abs(A - sign * A.T)
        if gap.max() > SYMMETRY_TOLERANCE * scale:
            i, j = np.unravel_index(np.argmax(gap), A.shape)
            what = "symmetric" if sign > 0 else "skew-symmetric (a gyroscopic matrix)"
            raise self._error(name, f"not {what}: [{self.coordinates[i]}, {self.coordinates[j]}] = {A[i, j]:.6g} "
                              f"against [{self.coordinates[j]}, {self.coordinates[i]}] = {A[j, i]:.6g}")

    def _check_periodic(self, name: str, p: Periodic, shape: tuple, mean_of: str) -> None:
        if not (isinstance(p.period, (int, float)) and math.isfinite(p.period) and p.period > 0):
            raise self._error(f"{name}.period", f"{p.period!r}: needs a positive period in s")
        if p.interpolation not in INTERPOLATIONS:
            raise self._error(f"{name}.interpolation", f"{p.interpolation!r}: choose {' or '.join(INTERPOLATIONS)}")
        values = p.over_period()
        if values.shape[1:] != shape or not np.all(np.isfinite(values)):
            raise self._error(name, f"values of shape {values.shape[1:]} (expected {shape}) or not finite")
        if p.samples is not None:
            target = self.matrix(mean_of)
            gap = np.max(np.abs(p.mean - target))
            if gap > MEAN_TOLERANCE * (np.max(np.abs(target)) or 1.0):
                raise self._error(mean_of, f"is not the mean of the {name} samples (largest difference {gap:.4g}): "
                                  f"{mean_of} must be their mean over the period")

    def _check_mesh(self, j: int, mesh: Mesh) -> None:
        where = f"meshes[{j}]"
        row = np.asarray(mesh.row, dtype=float)
        if row.shape != (self.n,) or not np.all(np.isfinite(row)) or not np.any(row):
            raise self._error(f"{where}.row", f"{mesh.id}: needs {self.n} finite coefficients, not all zero")
        if isinstance(mesh.stiffness, Periodic):
            values = np.asarray(mesh.stiffness.over_period(), dtype=float)
            if not (mesh.stiffness.period > 0 and np.all(np.isfinite(values))):
                raise self._error(f"{where}.stiffness", f"{mesh.id}: needs a positive period and finite values")
        if mesh.error is not None and not (isinstance(mesh.error, Periodic) and mesh.error.period > 0
                                           and np.all(np.isfinite(mesh.error.over_period()))
                                           and np.shape(mesh.error.over_period())[1:] == ()):
            raise self._error(f"{where}.error", f"{mesh.id}: needs a Periodic of finite scalars (m) with a positive "
                              "period")
        if not mesh.k_mean > 0 or mesh.damping < 0 or not math.isfinite(mesh.damping):
            raise self._error(f"{where}", f"{mesh.id}: mean stiffness {mesh.k_mean:.4g} N/m must be > 0 and damping "
                              f"{mesh.damping:.4g} N s/m >= 0")

    def _check_map(self, spec, labels: list[str]) -> None:
        known = set(labels)
        mesh_ids = {m.id for m in spec.meshes}
        for mesh in self.meshes:
            if mesh.id not in mesh_ids:
                raise self._error("meshes", f"{mesh.id!r} is not a mesh of {spec.name} ({', '.join(sorted(mesh_ids))})")
        for label, combination in self.physical_map().items():
            if label not in known:
                raise self._error("physical", f"{label!r} is not a coordinate of {spec.name}"
                                  + did_you_mean(label, labels, n=3, cutoff=0))
            for coordinate, coefficient in combination.items():
                if coordinate not in self.coordinates:
                    raise self._error(f"physical.{label}", f"{coordinate!r} is not one of the model's coordinates")
                if not math.isfinite(coefficient) or coefficient == 0:
                    raise self._error(f"physical.{label}", f"coefficient {coefficient!r} of {coordinate}")
        self._check_units(spec)

    def physical_map(self) -> dict[str, dict[str, float]]:
        if self.physical is not None:
            return self.physical
        return {c: {c: 1.0} for c in self.coordinates}

    def _check_units(self, spec) -> None:
        """A coordinate that is one train coordinate (coefficient +-1) must carry that member's mass (a
        translation) or inertia (a rotation) within UNIT_SLIP: a factor 1000 or 1e6 is a unit slip."""
        for label, combination in self.physical_map().items():
            if len(combination) != 1:
                continue
            (coordinate, coefficient), = combination.items()
            if abs(coefficient) != 1.0:
                continue
            member_id, dof = label.rsplit(".", 1)
            member = spec.members[member_id]
            expected, what = (member.inertia, "inertia (kg m^2)") if dof == "theta" else (member.mass, "mass (kg)")
            i = self.coordinates.index(coordinate)
            if i in self.massless:  # condensed out, not a unit slip
                continue
            ratio = self.M[i, i] / expected
            if not 1.0 / UNIT_SLIP <= ratio <= UNIT_SLIP:
                raise self._error(f"M[{coordinate}]", f"{self.M[i, i]:.6g} but {member_id}'s {what} is {expected:.6g} "
                                  f"(x {ratio:.3g}): a unit slip? (SI throughout: kg, m, rad, N, s)")

    # -- the map to the train's coordinates -----------------------------------------------------------------

    def to_physical(self, labels: list[str]) -> tuple[np.ndarray, list[bool]]:
        """(T, mapped): physical = T q over the train's coordinate ``labels``; mapped[i] says whether label i
        is one of the model's (the others are held: zero rows)."""
        T = np.zeros((len(labels), self.n))
        index = {c: j for j, c in enumerate(self.coordinates)}
        rows = self.physical_map()
        for i, label in enumerate(labels):
            for coordinate, coefficient in rows.get(label, {}).items():
                T[i, index[coordinate]] = coefficient
        return T, [label in rows for label in labels]
