"""Nominal (rigid-body) kinematics and statics of a train.

* speeds: every member's nominal angular velocity from the rigid mesh and coupling
  constraints (Willis' equation falls out for each stage), the input turning at the
  operating speed and held members at rest;
* loaded flanks: which side of the teeth carries the nominal torque, from a rigid
  torsional statics solve with the load torque on the output;
* mesh frequencies z_C |w_C - w_carrier| / 2 pi and mesh phases (Parker & Lin 2004).

The speeds follow from the lines of action (base radii and pitch points), never from tooth counts, so an idealised
stage (no teeth) turns like a toothed one with the same base radii.  An idealised mesh has no mesh cycle: its
frequency and phase are 0 (its stiffness is constant).  At input speed 0 (modal work) every member is at rest and
the ratio is that of the train turning.

These are properties of the train description, shared by both models.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.train.geometry import base_tooth_thickness
from gearcheck.train.line_of_action import lever, line_of_action
from gearcheck.shared.errors import TrainFileError
from gearcheck.shared.units import rad_s_to_rpm

MAX_PITCH_LINE_SPEED = 300.0  # m/s


@dataclass(frozen=True)
class Kinematics:
    speeds: dict[str, float]  # rad/s, absolute, positive counter-clockwise
    flanks: dict[str, int]  # mesh id -> +1/-1
    mesh_frequency: dict[str, float]  # Hz; an RV reducer's pin contacts under "STAGE.pins"
    mesh_phase: dict[str, float]  # cycles; mesh position xi = f t - phase
    ratio: float  # input speed / output speed
    input_torque: float  # N·m on the input member (power balance), signed
    output_torque: float  # N·m on the output member, signed (opposes its rotation)


def _torsional_rows(spec):
    """Rigid torsional constraint rows over the members' absolute rotations (flank +1)."""
    index = {mid: i for i, mid in enumerate(spec.members)}
    rows, labels = [], []
    for mesh in spec.meshes:
        stage = spec.stage_of(mesh.planet)
        planet = spec.members[mesh.planet]
        loa = line_of_action(mesh, planet.angle, stage.carrier_radius, +1)
        row = np.zeros(len(index))
        e_t = np.array([-math.sin(planet.angle), math.cos(planet.angle)])
        row[index[mesh.central]] += lever(loa.pitch_point, np.zeros(2), loa.direction)
        row[index[mesh.planet]] -= lever(loa.pitch_point, loa.planet_centre, loa.direction)
        row[index[stage.carrier]] -= stage.carrier_radius * float(e_t @ loa.direction)
        rows.append(row)
        labels.append(mesh.id)
    for part in spec.parts:  # the other parts' rigid constraints (couplings, an RV reducer's cycloid stage)
        for row, label in part.speed_rows(spec, index):
            rows.append(row)
            labels.append(label)
    return np.array(rows), labels, index


def kinematics(spec) -> Kinematics:
    rows, labels, index = _torsional_rows(spec)
    n = len(index)
    fixed = {index[m] for m in spec.held}
    fixed.add(index[spec.input])
    free = [i for i in range(n) if i not in fixed]

    # --- speeds: rows @ w = 0 with w_input given, held = 0
    w_in = spec.operating.input_speed
    w_ref = w_in or 1.0  # at rest (modal work), the ratio of the train turning at 1 rad/s
    w = np.zeros(n)
    w[index[spec.input]] = w_ref
    A = rows[:, free]
    rhs = -rows @ w
    sol, *_ = np.linalg.lstsq(A, rhs, rcond=None)
    rank = np.linalg.matrix_rank(A)
    if rank < len(free):
        idle = _free_members(A, free, index)
        raise TrainFileError(spec.path, "train", f"the train is not a one-degree-of-freedom mechanism: "
                                                 f"{', '.join(idle)} can turn freely with the input and held "
                                                 "members fixed (hold it or couple it)")
    if not _consistent(A, rhs):
        raise _locked(spec, rows, labels, free, rhs, index)
    w[free] = sol
    w_out = float(w[index[spec.output]])
    if abs(w_out) < 1e-12 * abs(w_ref):
        raise TrainFileError(spec.path, "train.output", f"{spec.output} does not turn when the input turns")
    ratio = w_ref / w_out
    speeds = {mid: float(w[i]) * (w_in / w_ref) + 0.0 for mid, i in index.items()}  # + 0.0: at rest no -0
    for mesh in spec.meshes:
        v = abs(speeds[mesh.central] - speeds[f"{mesh.stage}.carrier"]) * mesh.geometry.central_pitch_radius
        if v > MAX_PITCH_LINE_SPEED:
            raise TrainFileError(spec.path, "operating.input_speed_rpm",
                                 f"the {mesh.central} mesh would run at a pitch-line speed of {v:.4g} m/s: "
                                 f"gears are refused above {MAX_PITCH_LINE_SPEED:g} m/s (the fastest turbo gears "
                                 "run at about 200 m/s)")

    # --- statics: output load against grounded input and held members (unit stiffness rows)
    load = spec.operating.output_torque
    t_out = -math.copysign(load if load > 0 else 1.0, w_out)
    K = rows[:, free].T @ rows[:, free]
    torque = np.zeros(len(free))
    torque[free.index(index[spec.output])] = t_out
    theta = np.linalg.solve(K, torque)
    forces = rows[:, free] @ theta
    flanks = {label: (1 if f >= 0 else -1) for label, f in zip(labels, forces) if label in {m.id for m in spec.meshes}}

    # --- mesh frequencies and phases
    freq, phase = {}, {}
    for mesh in spec.meshes:
        carrier = f"{mesh.stage}.carrier"
        rel = speeds[mesh.central] - speeds[carrier]
        z = mesh.central_gear.teeth or 0  # an idealised mesh: no mesh cycle
        freq[mesh.id] = z * abs(rel) / (2 * math.pi)
        psi = spec.members[mesh.planet].angle
        phase[mesh.id] = (math.copysign(1.0, rel) * z * psi / (2 * math.pi) + _sun_ring_offset(spec, mesh)) % 1.0

    for part in spec.parts:  # the other parts' periodic contacts (an RV reducer's pins)
        freq.update(part.frequencies(speeds))

    t_in = -t_out / ratio if load > 0 else 0.0
    return Kinematics(speeds, flanks, freq, phase, ratio, t_in, t_out if load > 0 else 0.0)


def require_mesh_cycle(spec, what: str) -> None:
    """Refuse ``what`` (a time run, a cross-check, ...) on a train without a mesh cycle to run over: one at rest
    (input speed 0: modal work only) or with an idealised stage (no teeth: no mesh frequency, phase or tooth
    pairs), naming the field."""
    if spec.operating.input_speed == 0.0:
        raise TrainFileError(spec.path, "operating.input_speed_rpm", f"0: {what} needs the train turning (at rest "
                                                                     "only modes, campbell and mac apply; give a "
                                                                     "speed)")
    for i, stage in enumerate(spec.stages):
        if stage.idealised:
            raise TrainFileError(spec.path, f"stages[{i}].planet.teeth", f"missing: {what} needs the teeth of "
                                                                        f"idealised stage {stage.name} (its mesh "
                                                                        "cycle); its modes need none")


def _sun_ring_offset(spec, mesh) -> float:
    """Phase of a ring-planet mesh relative to the sun-planet mesh of the same simple planet.

    Parker & Lin 2004 (conference version DETC2003/PTG-48067, Eqs. 13-21), with the
    mesh position counted from the start of contact as in :mod:`gearcheck.train.mesh_stiffness`
    (sun mesh: contact starts at the planet tip; ring mesh: at the ring tip, the planet
    driving the ring in the carrier frame).  At the reference instant a sun-planet pair
    is at the pitch point P1, so the sun mesh is B1P1/p into its cycle; the ring contact
    nearest after the ring's start of contact B2 is B2Q3 along, so the ring mesh is
    B2Q3/p into its cycle.  Standard (unshifted) planets give the published rule
    gamma_rs = 0 for odd and 1/2 for even planet tooth counts (measured at the pitch
    points).  Compound planets: 0 (the angle between their two gears is a design choice).
    """
    if not mesh.internal or mesh.central_gear.idealised:
        return 0.0
    suns = [m for m in spec.meshes if m.planet == mesh.planet and not m.internal]
    if len(suns) != 1 or suns[0].planet_gear != mesh.planet_gear:
        return 0.0
    planet, ring = mesh.planet_gear, mesh.central_gear
    a1, a2 = suns[0].geometry.pressure_angle, mesh.geometry.pressure_angle
    p = planet.base_pitch
    rpb, rrb = planet.base_radius, ring.base_radius
    b1p1 = math.sqrt(planet.tip_radius**2 - rpb**2) - rpb * math.tan(a1)
    b2p2 = rrb * math.tan(a2) - math.sqrt(ring.tip_radius**2 - rrb**2)
    q2b2 = rpb * math.tan(a1) + rpb * (math.pi - a1 - a2) + rpb * math.tan(a2) - b2p2 - base_tooth_thickness(planet)
    b2q3 = p * (1.0 - (q2b2 / p) % 1.0)
    return -(b2q3 - b1p1) / p


def _consistent(A, rhs) -> bool:
    sol = np.linalg.lstsq(A, rhs, rcond=None)[0]
    return bool(np.linalg.norm(A @ sol - rhs) <= 1e-9 * max(1.0, np.linalg.norm(rhs)))


def _locked(spec, rows, labels, free, rhs, index) -> TrainFileError:
    """The error of a locked train, naming the couplings without which it turns: the members each joins
    turn at different speeds in the train without it."""
    culprits = []
    for j, c in enumerate(spec.couplings):
        keep = [i for i, label in enumerate(labels) if label != c.name]
        if _consistent(rows[keep][:, free], rhs[keep]):
            w = np.zeros(len(index))
            w[index[spec.input]] = spec.operating.input_speed
            w[free] = np.linalg.lstsq(rows[keep][:, free], rhs[keep], rcond=None)[0]
            culprits.append(f"{c.name} (couplings[{j}]) joins {c.a} and {c.b}, which turn at "
                            f"{rad_s_to_rpm(w[index[c.a]]):.6g} and {rad_s_to_rpm(w[index[c.b]]):.6g} rpm without it")
    if culprits:
        return TrainFileError(spec.path, "couplings", "the train is locked: " + "; ".join(culprits)
                              + " (a torsional coupling cannot join members turning at different speeds)")
    return TrainFileError(spec.path, "train.held", "the train is locked: the input cannot turn with the held "
                                                   "members fixed")


def _free_members(A, free, index):
    names = {i: mid for mid, i in index.items()}
    _, s, vt = np.linalg.svd(A)
    null = vt[np.sum(s > 1e-9 * s[0]):]
    moving = np.where(np.abs(null).max(axis=0) > 1e-9)[0]
    return [names[free[i]] for i in moving]
