"""A user's own model, checked by gearcheck: a purely torsional model of a single-stage planetary train.

Written as an engineer would write it from Lin & Parker (1999) with every translation held: the sun,
ring, carrier and planets only turn, each planet's centre rides on its pin (tangential motion
r_c theta_c), and each mesh compresses along its line of action by

    sun-planet n:   delta = r_bs theta_s + r_bp theta_n - r_c cos(alpha) theta_c
    ring-planet n:  delta = r_br theta_r - r_bp theta_n - r_c cos(alpha) theta_c

(alpha the operating pressure angle).  The mesh stiffness k(t) is the train's own (a description of the
gears, like the masses); everything else, the matrices and their map to gearcheck's coordinates, is
derived here.  Run it:

    gearcheck crosscheck demo-3p --model examples/torsional_user_model.py:torsional_model
    gearcheck mac demo-3p --model examples/torsional_user_model.py:torsional_model
"""

import numpy as np

from gearcheck import Excitation, LinearModel, Mesh, Periodic, kinematics

SAMPLES = 4096  # of each mesh's stiffness over its cycle


def torsional_model(spec) -> LinearModel:
    stage = spec.stages[0].name
    sun, ring, carrier = (spec.members[f"{stage}.{m}"] for m in ("sun", "ring", "carrier"))
    planets = [m for m in spec.members.values() if m.is_planet]
    names = [m.id for m in (sun, ring, carrier, *planets)]
    coordinates = [f"{name}.theta" for name in names]
    n, r_c = len(names), spec.stages[0].carrier_radius
    M = np.diag([sun.inertia, ring.inertia, carrier.inertia + sum(p.mass for p in planets) * r_c**2,
                 *(p.inertia for p in planets)])
    K = np.diag([m.support.torsional_stiffness if m.support else 0.0 for m in (sun, ring, carrier, *planets)])
    K[names.index(spec.input), names.index(spec.input)] += spec.operating.input_shaft_stiffness or 0.0
    kin = kinematics(spec)
    exc = Excitation(spec, kin)
    meshes = []
    for j, mesh in enumerate(spec.meshes):
        row = np.zeros(n)
        central = names.index(mesh.central)
        sign = -1.0 if mesh.central_gear.internal else 1.0
        row[central] = mesh.central_gear.base_radius
        row[names.index(mesh.planet)] = sign * mesh.planet_gear.base_radius
        row[names.index(carrier.id)] = -r_c * np.cos(mesh.geometry.pressure_angle)
        period = 1.0 / kin.mesh_frequency[mesh.id]
        k = exc.stiffness(np.arange(SAMPLES) * period / SAMPLES + 0.5 * period / SAMPLES)[:, j]
        k += exc.mean_stiffness[j] - k.mean()  # held samples move a jump by up to a sample: keep the exact mean
        m_eq = 1.0 / sum(row[i] ** 2 / M[i, i] for i in np.flatnonzero(row))  # the mesh's effective mass
        meshes.append(Mesh(mesh.id, row, Periodic(period, samples=k, interpolation="hold"),
                           2.0 * mesh.damping_ratio * np.sqrt(k.mean() * m_eq)))
    F = np.zeros(n)
    F[names.index(spec.output)] = kin.output_torque
    if spec.operating.input_shaft_stiffness is None:
        F[names.index(spec.input)] = kin.input_torque
    physical = {c: {c: 1.0} for c in coordinates}
    physical.update({f"{p.id}.tangential": {f"{carrier.id}.theta": r_c} for p in planets})
    return LinearModel("torsional", coordinates, M, K, F=F, meshes=meshes, physical=physical,
                       source="torsional_user_model.py")
