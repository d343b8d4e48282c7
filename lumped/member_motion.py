"""What a member's motion looks like from outside: inertial accelerations from rotating-frame coordinates.

The coordinates of a stage turn with its carrier at Omega (Lin & Parker 1999): a member's centre
moves q = (u, v) along the carrier's axes about its nominal place r0 (a planet's pin), so its
inertial acceleration along those axes is q'' + 2 Omega k x q' + Omega k x (Omega k x (q + r0)), and
the axes themselves turn with the carrier's actual angle (nominal plus its vibration).  Every model
expressed in these coordinates, the reference and a user's, reports its members this way.
"""

from __future__ import annotations

import numpy as np

from gearcheck.train.spec import AXIAL


def member_motion(spec, kin, dofs, t, q, v, qdd, rotating_frame_terms: bool = True,
                  clock=None) -> tuple[np.ndarray, np.ndarray]:
    """(acc, angle): acc (n_t, n_members, 4) the inertial acceleration of each member's centre along its carrier's axes,
    its angular acceleration and its acceleration along the stage axis (0 for a member that does not slide: the
    axis is the frame's axis of rotation, so no frame term enters it), angle (n_t, n_members) the angle of those
    axes (world = R(angle) carrier), from q, q', q'' (n_t, n) over the coordinates ``dofs``
    (:class:`~gearcheck.lumped.assembly.DofMap`); ``kin`` the train's kinematics; ``clock`` an operating history's
    nominal clock (:class:`~gearcheck.train.history.Clock`: each speed lambda(t) times its own, each nominal angle
    the speed times Lambda(t), and the frames' angular acceleration Omega' adding Omega' k x (q + r0))."""
    members = list(spec.members)
    scale, rate, nominal = (np.ones_like(t), np.zeros_like(t), t) if clock is None else \
        (clock.scale(t), clock.rate(t), clock.time(t))
    acc = np.zeros((t.size, len(members), 4))
    angle = np.empty((t.size, len(members)))
    for j, mid in enumerate(members):
        member = spec.members[mid]
        iu, iv, ith = dofs.of_member(mid)[:3]
        carrier = f"{member.stage}.carrier"
        omega = kin.speeds[carrier] * scale if rotating_frame_terms else 0.0
        euler = kin.speeds[carrier] * rate if rotating_frame_terms else 0.0
        acc[:, j, 0] = qdd[:, iu] - 2 * omega * v[:, iv] - omega**2 * (q[:, iu] + member.radius)
        acc[:, j, 1] = qdd[:, iv] + 2 * omega * v[:, iu] - omega**2 * q[:, iv]
        acc[:, j, 2] = qdd[:, ith]
        if clock is not None:
            acc[:, j, 0] -= euler * q[:, iv]
            acc[:, j, 1] += euler * (q[:, iu] + member.radius)
            acc[:, j, 2] += kin.speeds[mid] * rate
        if member.axial:
            acc[:, j, 3] = qdd[:, dofs(mid, AXIAL)]
        angle[:, j] = kin.speeds[carrier] * nominal + member.angle + q[:, dofs(carrier, "theta")]
        if member.eccentric:  # its nominal orbit e(phi) at the crank's absolute speed w_H
            ecc = member.eccentric
            w_h = kin.speeds[ecc.crank]
            phi = ecc.phase + (w_h - kin.speeds[carrier]) * t
            acc[:, j, 0] -= ecc.eccentricity * w_h**2 * np.cos(phi)
            acc[:, j, 1] -= ecc.eccentricity * w_h**2 * np.sin(phi)
    return acc, angle
