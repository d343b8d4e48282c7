"""A gear mesh (spur, helical or relieved): one row along its line of action, driven by the excitation's
time-varying stiffness, transmission error and backlash (DESIGN.md 4).  In a tilting stage the row is taken at the
mesh's centre of stiffness with the members' tilts in it, and a second, constant row resists their relative tilt
across the face: slices of stiffness k/w dz at z in [-w/2, w/2] about the centre give
sum k_j (g + z_j h)(g + z_j h)^T = k g g^T + k w^2/12 h h^T, h the rate at which the slices' deflection grows along
the face (Eritenel & Parker 2009's mesh tilting stiffness; the mean stiffness, its variation left to the centre
row)."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row
from gearcheck.train.line_of_action import lever, line_of_action
from gearcheck.train.spec import AXIAL, ROTATION, TILTS


@ELEMENTS.register("mesh")
def mesh_row(mesh, build: Build) -> Contribution:
    """delta = (u_central(p) - u_planet(p)) . d with u(p) = translation + theta k x (p - centre) (+ z e_z), and
    its damping."""
    spec, dofs = build.spec, build.dofs
    stage = spec.stage_of(mesh.planet)
    planet = spec.members[mesh.planet]
    loa = line_of_action(mesh, planet.angle, stage.carrier_radius, build.kin.flanks[mesh.id])
    d = loa.direction
    e_r = np.array([math.cos(planet.angle), math.sin(planet.angle)])
    e_t = np.array([-e_r[1], e_r[0]])
    a = np.zeros(build.n)
    c, p = mesh.central, mesh.planet
    cx, cy = spec.members[c].dofs[:2]
    radial, tangential = planet.dofs[:2]
    a[dofs(c, cx)] += d[0]
    a[dofs(c, cy)] += d[1]
    a[dofs(c, ROTATION)] += lever(loa.pitch_point, np.zeros(2), d)
    a[dofs(p, radial)] -= float(d @ e_r)
    a[dofs(p, tangential)] -= float(d @ e_t)
    a[dofs(p, ROTATION)] -= lever(loa.pitch_point, loa.planet_centre, d)
    if planet.axial:  # the normal line of action's axial part (Eritenel & Parker 2009)
        a[dofs(c, AXIAL)] += loa.axial
        a[dofs(p, AXIAL)] -= loa.axial
    k_mean = build.mean_stiffness[mesh.id]
    damping = _damping(spec, mesh, a, dofs, k_mean)
    if not planet.tilting:
        return Contribution(mesh=(a, damping))
    # the tilts: a rotation phi moves the flank's point p (at the centre of stiffness) by phi x (p - centre), which
    # changes delta by phi . ((p - centre) x n); across the face, by phi . (e_z x n) per unit length (the tilt row)
    n = np.array([d[0], d[1], loa.axial])
    frame = (np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    sides = ((c, np.zeros(2), 1.0, frame), (p, loa.planet_centre, -1.0, (e_r, e_t)))
    tilt = np.zeros(build.n)
    for member, centre, sign, axes in sides:
        arm = np.append(loa.pitch_point - centre, mesh.axial_centre)
        _add_tilts(a, dofs, spec.members[member], axes, sign * np.cross(arm, n))
        _add_tilts(tilt, dofs, spec.members[member], axes, sign * np.cross([0.0, 0.0, 1.0], n))
    k_tilt = mesh.tilting_stiffness(k_mean)
    row = Row(f"{mesh.id}.tilt", "mesh", tilt, k_tilt, damping * k_tilt / k_mean)  # damping spread like stiffness
    return Contribution(rows=[row], mesh=(a, damping))


def _add_tilts(a: np.ndarray, dofs, member, axes, moment: np.ndarray) -> None:
    """Add to row ``a`` the component of ``moment`` (a 3-vector) along each of ``member``'s tilt axes (``axes``: its
    two translation axes in the carrier frame, in the order of its tilts)."""
    for tilt, axis in zip(TILTS[member.frame], axes):
        a[dofs(member.id, tilt)] += float(moment[:2] @ axis)


def _damping(spec, mesh, row, dofs, k_mean) -> float:
    """c = 2 zeta sqrt(k m_eq), m_eq = 1/(r_b1^2/I_1 + r_b2^2/I_2): the equivalent mass of the
    gear pair's torsional motion along the line of action (the arms are the row's own levers).

    Li et al. (2026) print c = 2 zeta sqrt(k / (1/m_s^2 + 1/m_p^2)), which is not even a damping
    coefficient dimensionally (sqrt(N/m kg^2) = kg sqrt(N/m)); the critical damping of a spring k
    between two inertias is 2 sqrt(k m_eq) with 1/m_eq = 1/m_s + 1/m_p, m = I/r_b^2."""
    if mesh.damping_coefficient is not None:
        return mesh.damping_coefficient
    if not mesh.damping_ratio:
        return 0.0
    inv = 0.0
    for member in (mesh.central, mesh.planet):
        arm = row[dofs(member, ROTATION)]
        inv += arm**2 / spec.members[member].inertia
    return 2.0 * mesh.damping_ratio * math.sqrt(k_mean / inv)
