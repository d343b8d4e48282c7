"""What a member's motion looks like from outside: inertial accelerations and velocities, displacements from the
nominal places and rotations from the nominal angles, from rotating-frame coordinates.

The coordinates of a stage turn with its carrier at Omega (Lin & Parker 1999): a member's centre
moves q = (u, v) along the carrier's axes about its nominal place r0 (a planet's pin; a cycloid disc's
eccentric e(phi) besides), and the axes themselves turn with the carrier's actual angle phi = alpha + theta_c,
alpha the nominal one (as the README's physics notes say, the world-frame accelerations need it).  So the centre is
at R(alpha) (r0 + e) + R(phi) q: its displacement from the nominal place is q along the carrier's axes, whose rate
q' is the vibration velocity, and its inertial velocity along those axes is
R(-theta_c) (Omega k x r0 + w_H k x e) + q' + phi' k x q.  The inertial acceleration is
q'' + 2 Omega k x q' + Omega k x (Omega k x (q + r0)) - w_H^2 e.  Rotations are absolute: theta is the rotation
from the nominal angle, theta' + w the angular velocity.  Every model expressed in these coordinates, the
reference and a user's, reports its members this way.

The nominal motion enters through :func:`nominal_angle` alone: at constant speed every nominal angle is its speed
times t; under an operating history (its nominal clock, :class:`~gearcheck.train.history.Clock`) its speed times
Lambda(t), at lambda(t) times the speed, and the frames' angular acceleration Omega' = lambda' Omega adds
Omega' k x (q + r0) to the acceleration and lambda' w to the angular acceleration.
"""

from __future__ import annotations

import numpy as np

from gearcheck.shared.results import MemberMotion
from gearcheck.train.spec import AXIAL, TILTS


def nominal_angle(speed: float, t: np.ndarray, clock=None) -> tuple[np.ndarray, np.ndarray]:
    """(angle, angular velocity) at times ``t`` of whatever turns at ``speed`` (rad/s) in the train's nominal
    motion -- a member, a carrier's frame, an eccentric relative to its carrier --, the angle 0 at t = 0; ``clock``
    an operating history's nominal clock."""
    if clock is None:
        return speed * t, np.full(np.shape(t), speed)
    return speed * clock.time(t), speed * clock.scale(t)


def member_motion(spec, kin, dofs, t, q, v, qdd, rotating_frame_terms: bool = True, clock=None):
    """A function j -> :class:`~gearcheck.shared.results.MemberMotion` of the j-th member of ``spec.members``
    (module docstring), from q, q', q'' (n_t, n) over the coordinates ``dofs``
    (:class:`~gearcheck.lumped.assembly.DofMap`); ``kin`` the train's kinematics.  Without
    ``rotating_frame_terms`` the frame's terms are left out (Omega = 0) as the model leaves them out; ``clock`` an
    operating history's nominal clock."""
    members = list(spec.members.values())
    rate = None if clock is None else clock.rate(t)  # lambda

    def motion(j: int) -> MemberMotion:
        member = members[j]
        iu, iv, ith = dofs.of_member(member.id)[:3]
        carrier = f"{member.stage}.carrier"
        omega0 = kin.speeds[carrier] if rotating_frame_terms else 0.0
        omega = omega0 if clock is None else nominal_angle(omega0, t, clock)[1]
        theta_c, rate_c = q[:, dofs(carrier, "theta")], v[:, dofs(carrier, "theta")]
        u, w, du, dw = q[:, iu], q[:, iv], v[:, iu], v[:, iv]
        acc = np.stack([qdd[:, iu] - 2 * omega * dw - omega**2 * (u + member.radius),
                        qdd[:, iv] + 2 * omega * du - omega**2 * w], axis=-1)
        alpha = qdd[:, ith]
        if clock is not None:  # Omega' k x (q + r0), and each rotation's nominal acceleration lambda' w
            acc[:, 0] -= omega0 * rate * w
            acc[:, 1] += omega0 * rate * (u + member.radius)
            alpha = alpha + kin.speeds[member.id] * rate
        frame_speed = nominal_angle(omega0, t, clock)[1]
        place = np.zeros((t.size, 2))  # the nominal place's velocity along the nominal axes
        place[:, 1] = frame_speed * member.radius
        if member.eccentric:  # its nominal orbit e(phi) at the crank's absolute speed w_H
            ecc = member.eccentric
            w_h = kin.speeds[ecc.crank]
            phi = ecc.phase + nominal_angle(w_h - kin.speeds[carrier], t, clock)[0]
            unit = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
            acc -= ecc.eccentricity * w_h**2 * unit
            orbit = nominal_angle(w_h, t, clock)[1]
            place += ecc.eccentricity * orbit[:, None] * unit[:, ::-1] * [-1.0, 1.0]  # w_H k x e
        frame_rate = frame_speed + rate_c
        c, s = np.cos(theta_c), np.sin(theta_c)
        velocity = np.stack([c * place[:, 0] + s * place[:, 1] + du - frame_rate * w,
                             c * place[:, 1] - s * place[:, 0] + dw + frame_rate * u], axis=-1)
        speed = nominal_angle(kin.speeds[member.id], t, clock)[1]
        axial = None
        if member.axial:
            iz = dofs(member.id, AXIAL)
            axial = np.stack([qdd[:, iz], q[:, iz], v[:, iz]], axis=-1)
        tilt = q[:, [dofs(member.id, d) for d in TILTS[member.frame]]] if member.tilting else None
        return MemberMotion(nominal_angle(kin.speeds[carrier], t, clock)[0] + member.angle + theta_c, acc, alpha,
                            np.stack([u, w], axis=-1), velocity, np.stack([du, dw], axis=-1), q[:, ith],
                            speed + v[:, ith], v[:, ith], axial, tilt)

    return motion
