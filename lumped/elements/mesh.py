"""A gear mesh (spur, helical or relieved): one row along its line of action, driven by the excitation's
time-varying stiffness, transmission error and backlash (DESIGN.md 4)."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution
from gearcheck.train.line_of_action import lever, line_of_action
from gearcheck.train.spec import AXIAL, ROTATION


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
    return Contribution(mesh=(a, _damping(spec, mesh, a, dofs, build.mean_stiffness[mesh.id])))


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
