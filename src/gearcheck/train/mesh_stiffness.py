"""Mesh stiffness models: k as a function of the mesh position.

The mesh position xi is the number of mesh cycles elapsed (one cycle = one base pitch
of travel along the line of action); xi = 0 is the instant a new tooth pair enters
contact.  Every model is a class with a ``name``, a ``parameters`` table (the schema of
its keys in the train file's ``stiffness`` table, checked and converted to SI like any
other field), a ``mean`` and ``__call__(xi) -> k``; it is built from those parameters
and the mesh (:class:`gearcheck.train.spec.MeshSpec`: both gears and the operating geometry).
Both solvers call the same objects, so a new model is one new class registered in
:data:`MODELS`; ``references`` names the works its formulas come from.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np
from scipy.interpolate import CubicSpline

from gearcheck.train import helical_mesh, tooth_stiffness
from gearcheck.train.geometry import Gear, MeshGeometry
from gearcheck.train.schema import REQUIRED, Context, Integer, Number, Positive, Table, bound


def cycle_fraction(xi) -> np.ndarray:
    """frac(xi), the position within the mesh cycle: xi - floor(xi), which is exact and so equals np.mod(xi, 1.0)
    to the bit, in a fraction of its time."""
    xi = np.asarray(xi, dtype=float)
    return xi - np.floor(xi)


class MeshStiffness:
    """Base class; subclasses set ``name``, ``parameters`` and implement ``__call__``."""

    name = ""
    references: tuple[str, ...] = ()  # keys of gearcheck.shared.citations.REFERENCES
    needs_teeth = True  # built from tooth geometry (contact ratio, profiles): refused for an idealised mesh
    parameters = Table({"mean": Positive("mean mesh stiffness over a mesh cycle", "N/m", REQUIRED, bound("stiffness"))})

    def __init__(self, params: dict, mesh):
        self.mean = float(params["mean"])
        self.contact_ratio = mesh.geometry.contact_ratio

    def __call__(self, xi):
        raise NotImplementedError

    @property
    def pairs_low(self) -> int:
        """floor(eps): the tooth pairs in contact during the single-contact part of a cycle."""
        return math.floor(self.contact_ratio)

    @property
    def multi_fraction(self) -> float:
        """eps - floor(eps): the part of a cycle, from xi = 0, with one pair more in contact."""
        return self.contact_ratio - self.pairs_low

    @property
    def breaks(self) -> tuple[float, ...]:
        """Mesh positions in [0, 1) where k jumps: a pair enters contact (0) and one leaves (eps - floor(eps));
        none when the contact ratio is whole.  The solvers end their steps there."""
        return (0.0, self.multi_fraction) if self.multi_fraction > 0 else ()

    def pairs(self, xi):
        """Tooth pairs in contact at mesh position ``xi``, from the contact ratio."""
        return self.pairs_low + (cycle_fraction(xi) < self.multi_fraction)

    @property
    def maximum(self) -> float:
        """The largest stiffness over a cycle (what the time step must resolve); sampled unless a
        model knows it exactly."""
        return float(np.max(self(np.linspace(0.0, 1.0, 2001))))

    def __repr__(self) -> str:
        return f"{type(self).__name__}(mean={self.mean:.6g} N/m)"


class ConstantStiffness(MeshStiffness):
    """k(xi) = k_mean."""

    name = "constant"
    breaks = ()
    needs_teeth = False

    def __call__(self, xi):
        return np.full_like(np.asarray(xi, dtype=float), self.mean)


class RectangularStiffness(MeshStiffness):
    """Rectangular wave from the transverse contact ratio eps.

    The number of tooth pairs in contact is ceil(eps) during the first eps - floor(eps)
    of each cycle and floor(eps) for the rest; each pair carries k_mean/eps, so the
    cycle average is k_mean.
    """

    name = "rectangular"

    def __init__(self, params: dict, mesh):
        super().__init__(params, mesh)
        self.pair_stiffness = self.mean / self.contact_ratio

    def __call__(self, xi):
        return self.pair_stiffness * self.pairs(xi)


class EnergyMethodStiffness(MeshStiffness):
    """Weber's energy method on the involute teeth (Li et al. 2026, sec. 3.2): slices, Cornell foundation, Hertz.

    The pair stiffness along the path of contact comes from :mod:`gearcheck.train.tooth_stiffness`;
    k(xi) sums the pairs at distances (frac(xi) + j) p_b from the start of contact.  It is
    tabulated separately on the multi-pair part of the cycle, frac(xi) in [0, eps - floor(eps)),
    and on the rest, so the jumps where a pair enters (frac = 0) and leaves are exact; between
    grid points each part is a cubic spline (not-a-knot).  The pair stiffness is smooth along the
    path within a part, and so is the spline (twice continuously differentiable): a linear
    interpolant's kinks, 800 a cycle, cost a fixed-step RK4 its order (2 instead of 4, every kink
    an error of order h^2).  The mean is that of the spline.
    """

    name = "energy"
    references = ("weber-1949", "cornell-1981", "li2026")
    parameters = Table({
        "youngs_modulus": Number("Young's modulus of both gears", "Pa", 206e9, 1e6, False, 1e13),
        "poisson_ratio": Number("Poisson's ratio of both gears", "-", 0.3, 0.0, True, 0.5),
        "slices": Integer("slices per tooth in Weber's method", 100, minimum=4, maximum=10000),
        "tooth_load_per_width": Number("normal load per unit face width at which the load-dependent Hertz "
                                       "compliance is taken", "N/m", 1.0e5, 1.0, False, 1e10),
    })
    grid_points = 401  # per part of the cycle

    def __init__(self, params: dict, mesh):
        self.contact_ratio = mesh.geometry.contact_ratio
        pair = GearPair(mesh.central_gear, mesh.planet_gear, mesh.geometry)
        self._parts = _energy_splines(pair, self.grid_points, params["youngs_modulus"], params["poisson_ratio"],
                                      params["slices"], params["tooth_load_per_width"])
        self.mean = float(sum(part.integrate(*part.x[[0, -1]]) for part in self._parts))
        # the splines as the compiled evaluation takes them: two parts (the one part twice for a whole eps), split at
        # eps - floor(eps), where the rest's spline holds, so that k jumps there exactly
        both = (self._parts * 2)[:2]
        self._split = self.multi_fraction if len(self._parts) == 2 else math.inf
        self._breaks = np.stack([part.x for part in both])
        self._coefficients = np.stack([part.c for part in both])

    def __call__(self, xi):
        from gearcheck.train.compiled_excitation import spline_parts  # numba on first use, not when a file is read

        x = cycle_fraction(xi)
        k = np.empty(x.shape)
        spline_parts(np.ravel(x), self._split, self._breaks, self._coefficients, k.reshape(-1))
        return k

    @property
    def maximum(self) -> float:
        # each spline's largest value: at a node or where its derivative vanishes
        return float(max(np.max(part(np.concatenate([part.x, part.derivative().roots(extrapolate=False)])))
                         for part in self._parts))


class GearPair(NamedTuple):
    """What the energy method reads of a mesh (:func:`~gearcheck.train.tooth_stiffness.pair_stiffness_along_path`
    takes it for one); hashable, so meshes of equal gears share one table."""

    central_gear: Gear
    planet_gear: Gear
    geometry: MeshGeometry

    @property
    def internal(self) -> bool:
        return self.central_gear.internal


@functools.lru_cache(maxsize=64)
def _energy_splines(pair: GearPair, points: int, youngs_modulus: float, poisson_ratio: float, slices: int,
                    tooth_load_per_width: float) -> list[CubicSpline]:
    """k of :class:`EnergyMethodStiffness` as cubic splines over the parts of a cycle: k tabulated at ``points`` on
    the multi-pair part [0, eps - floor(eps)] and as many on the rest (the one part [0, 1] for a whole eps)."""
    eps, pitch = pair.geometry.contact_ratio, pair.geometry.base_pitch
    low = math.floor(eps)
    parts = [(lo, hi, n) for lo, hi, n in ((0.0, eps - low, low + 1), (eps - low, 1.0, low)) if hi > lo]
    grids = [np.linspace(lo, hi, points) for lo, hi, _ in parts]
    distances = [np.minimum((grid[:, None] + np.arange(n)[None, :]) * pitch, eps * pitch)
                 for grid, (_, _, n) in zip(grids, parts)]
    width = min(pair.central_gear.face_width, pair.planet_gear.face_width)
    flat = tooth_stiffness.pair_stiffness_along_path(
        pair, np.concatenate([d.ravel() for d in distances]), youngs_modulus, poisson_ratio, slices,
        tooth_load_per_width * width)
    ends = np.cumsum([0] + [d.size for d in distances])
    return [CubicSpline(grid, flat[a:b].reshape(d.shape).sum(axis=1))
            for grid, d, a, b in zip(grids, distances, ends, ends[1:])]


class ContactLineStiffness(MeshStiffness):
    """k(xi) = k_mean L(xi) / L_m: a stiffness per unit length of the lines of contact times their total
    length (Maatar & Velex 1996), for helical gears from the transverse and face contact ratios; for
    spur gears (eps_b = 0) the rectangular wave.  L is continuous and piecewise linear for a helical
    pair, with kinks where a line's end reaches a corner of the plane of action."""

    name = "contact-line"
    references = ("maatar-velex-1996",)

    def __init__(self, params: dict, mesh):
        super().__init__(params, mesh)
        g = mesh.geometry
        self.face_contact_ratio = g.face_contact_ratio
        self._line = (g.contact_ratio, g.face_contact_ratio, g.face_width, g.base_helix_angle)
        self._mean_length = helical_mesh.mean_contact_line_length(g.contact_ratio, g.face_width, g.base_helix_angle)

    def __call__(self, xi):
        return self.mean / self._mean_length * helical_mesh.contact_line_length(xi, *self._line)

    @property
    def breaks(self) -> tuple[float, ...]:
        """Where a line's end reaches a corner: frac of 0, eps_a, eps_b and eps_a + eps_b."""
        eps_a, eps_b = self.contact_ratio, self.face_contact_ratio
        return tuple(sorted({round(math.fmod(x, 1.0), 15) for x in (0.0, eps_a, eps_b, eps_a + eps_b)}))

    @property
    def maximum(self) -> float:
        return float(np.max(self(np.array(self.breaks))))


MODELS: dict[str, type[MeshStiffness]] = {
    cls.name: cls for cls in (ConstantStiffness, RectangularStiffness, EnergyMethodStiffness, ContactLineStiffness)}


def stiffness_model(mesh) -> MeshStiffness:
    """The stiffness object of a :class:`~gearcheck.train.spec.MeshSpec` (parameters already checked, SI)."""
    return MODELS[mesh.stiffness["model"]](mesh.stiffness, mesh)


def energy_stiffness_curve(mesh, points: int = 2001, **params):
    """(xi over one mesh cycle, k(xi) in N/m, pairs in contact) of the energy method for a
    :class:`~gearcheck.train.spec.MeshSpec`, whatever model its train file names; ``params`` override
    the model's defaults (SI names: ``youngs_modulus``, ``poisson_ratio``, ``slices``, ...)."""
    checked = EnergyMethodStiffness.parameters.parse(params, "stiffness", Context("energy_stiffness_curve"))
    model = EnergyMethodStiffness(checked, mesh)
    xi = np.linspace(0.0, 1.0, points)
    return xi, model(xi), model.pairs(xi)
