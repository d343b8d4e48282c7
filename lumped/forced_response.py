"""The reference model as a parametric problem: its steady forced response by harmonic methods.

A train whose stiffness varies with at most two clocks -- the mesh position of one group of meshes with a common
mesh frequency, and an RV reducer's eccentric angle in its carrier (or a second mesh group) -- is

    M q'' + (C + G) q' + (K_b + K_frame + sum_m k_m(theta_1) a_m a_m^T + K_cycloid(theta_2)) q = F,

the mean load F, the damping of t = 0.  The stiffness is a sum of functions of one clock each, so each clock's
part is sampled on its own and the lattice of :mod:`gearcheck.lumped.fourier_response` needs no common period
(an RV reducer's mesh and pin-pass frequencies are the 69th and 39th harmonics of the cranks' turn, and the
two-clock lattice holds them without a 69 x 9-harmonic fundamental).  What the harmonic methods cannot hold is
refused: backlash and tip relief (contact nonlinearity), transmission error and torque ripple (forcing not in
F), pin clearance (a load that depends on the contact set).  The rows of a cycloid stage turn with the
eccentrics with their damping, and the discs' orbit loads m e w_H^2 e(phi) with them (periodic C and F).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from gearcheck.lumped.assembly import LumpedModel, contact_sets, frozen_at, sum_outer
from gearcheck.lumped.fourier_response import ParametricProblem, grid_angles
from gearcheck.lumped.static import mean_load
from gearcheck.shared.errors import SolverError

SAME_FREQUENCY = 1e-9  # relative: meshes whose frequencies agree this well run on one clock


def parametric_problem(model: LumpedModel, mesh_grid: int = 4096, eccentric_grid: int = 2048,
                       alias: float = 2e-3, contacts: dict | None = None) -> ParametricProblem:
    """The steady forced problem of ``model`` at its operating point (see the module docstring): each clock's
    stiffness sampled at ``mesh_grid`` or ``eccentric_grid`` points per turn (an eccentric sample is a static
    solve for the pins' contact set), ``alias`` the aliasing accepted
    (:class:`~gearcheck.lumped.fourier_response.ParametricProblem`).  ``contacts``: a dict the pins' contact
    sets of each eccentric sample are recorded in, or taken from where it holds them (a derivative by
    differences of two problems is one at a fixed contact pattern)."""
    _check_linear(model)
    turning = model.turning  # every one on a clock (_check_linear)
    exc = model.excitation
    varies = exc.max_stiffness > exc.mean_stiffness * (1 + 1e-12)
    groups = _mesh_groups(exc.frequency, varies)
    clocks = [("mesh", 2 * math.pi * exc.frequency[g[0]], g) for g in groups]
    if turning:
        if len({round(e.clock_speed, 9) for e in turning}) > 1:
            raise SolverError(f"{model.spec.name}: {', '.join(dict.fromkeys(e.words for e in turning))} on clocks of "
                              "different speeds need more than two clocks; use time marching")
        clocks.append(("turning", turning[0].clock_speed, None))
    if not clocks or len(clocks) > 2:
        raise SolverError(f"{model.spec.name}: the harmonic methods take one or two clocks, this train has "
                          f"{len(clocks)} (mesh groups {len(groups)}, turning elements {len(turning)}); use time "
                          "marching")
    owned = {name for e in turning for name in e.rows}
    base = replace(model, rows=[r for r in model.rows if r.name not in owned])
    K_const = base.K_b + model.K_frame + model.K_mesh(np.where(varies, 0.0, exc.mean_stiffness))
    contacts = {} if contacts is None else contacts
    parts = [_mesh_part(model, omega, group, mesh_grid) if kind == "mesh" else _turning_part(model, omega, contacts)
             for kind, omega, group in clocks]  # each angle -> (K, C) of its rows
    F = mean_load(model) - sum((e.static_load for e in turning), np.zeros(model.n))
    orbit = None
    if turning:
        omega = clocks[-1][1]
        orbit = lambda theta: sum(e.orbit_force(theta[-1] / omega) for e in turning)  # noqa: E731
    return ParametricProblem(model.M, base.C + model.G,
                             lambda theta: K_const + sum(p(a)[0] for p, a in zip(parts, theta)),
                             tuple(omega for _, omega, _ in clocks), F,
                             grid=tuple(mesh_grid if kind == "mesh" else eccentric_grid for kind, _, _ in clocks),
                             separable=True, alias=alias,
                             C_of=(lambda theta: sum(p(a)[1] for p, a in zip(parts, theta))) if turning else None,
                             F_of=orbit)


def _check_linear(model: LumpedModel) -> None:
    exc, spec = model.excitation, model.spec
    reasons = []
    if np.any(exc.backlash > 0):
        reasons.append("backlash")
    if exc.relieved.size:
        reasons.append("tip relief")
    if exc.has_transmission_error:
        reasons.append("transmission error")
    if spec.operating.torque_varies:
        reasons.append("a torque that varies")
    reasons.extend(dict.fromkeys(e.words for e in model.turning if e.clock_speed is None))
    reasons.extend(dict.fromkeys(zone for part in spec.parts for zone in part.dead_zones()))  # each named once
    if reasons:
        raise SolverError(f"{spec.name}: the harmonic methods solve a linear problem with constant load; this train "
                          f"has {', '.join(reasons)}: use time marching")


def _mesh_groups(frequencies, varies) -> list[list[int]]:
    """The meshes whose stiffness ``varies``, in groups of one mesh frequency, in order of first appearance."""
    groups: list[list[int]] = []
    for j, f in enumerate(frequencies):
        if not varies[j]:
            continue
        for g in groups:
            if abs(frequencies[g[0]] - f) <= SAME_FREQUENCY * f:
                g.append(j)
                break
        else:
            groups.append([j])
    return groups


def _mesh_part(model: LumpedModel, omega: float, group: list[int], grid: int):
    """(K, C) of the meshes of one group as a function of their clock's angle (their damping is constant: in
    the problem's C).  The stiffness at the ``grid`` angles the problem samples is taken in one call (each
    sample the same number as alone)."""
    rows = model.mesh_rows[group]
    zero = np.zeros((model.n, model.n))
    angles = grid_angles(grid)
    sampled = dict(zip(angles.tolist(), model.excitation.stiffness(angles / omega)[:, group]))

    def part(theta: float) -> tuple[np.ndarray, np.ndarray]:
        k = sampled.get(theta)
        if k is None:
            k = model.excitation.stiffness(np.array([theta / omega]))[0][group]
        return rows.T @ (k[:, None] * rows), zero
    return part


def _turning_part(model: LumpedModel, omega: float, contacts: dict):
    """(K, C) of the turning elements' rows (a cycloid stage's needle bearings and pins, of the static contact set
    or of ``contacts``) at their clock's angle: the rows turn with it, their damping with them."""
    cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}

    def part(theta: float) -> tuple[np.ndarray, np.ndarray]:
        key = round(float(theta), 12)
        if key not in cache:
            frozen = frozen_at(model, theta / omega, contacts.get(key))
            contacts.setdefault(key, contact_sets(frozen))
            names = {name for e in frozen.turning for name in e.rows}
            rows = [r for r in frozen.rows if r.name in names]
            cache[key] = tuple(sum_outer(rows, attr, model.n) for attr in ("stiffness", "damping"))
        return cache[key]
    return part
