"""What the twin's members do, read from MuJoCo's own sensors: each member's
:class:`~gearcheck.shared.results.MemberMotion`, its nominal part taken from the twin's joints.

Every body carries ``framelinacc``, ``frameangacc``, ``framepos``, ``framexaxis``, ``framelinvel`` and
``frameangvel`` sensors, all in the world's frame (:mod:`gearcheck.mbd_models.mjcf_builder`).  The nominal motion
is the twin's own: every joint at its nominal speed (:func:`~gearcheck.mbd_models.static_state.nominal_speeds`)
from the reference configuration qpos0, in which every body turns about the world's z and every centre's place
about the stage axis (a planet's with its carrier, a cycloid disc's on its eccentric), each at the speed MuJoCo
gives it there (:func:`nominal_places`).

Per member, along its carrier's axes at the carrier's actual angle phi (its hinge's sensor, plus a planet's place
angle psi), p the centre's position and p_nom(t) its nominal place: displacement d = R(-phi) (p - p_nom), velocity
R(-phi) p', vibration velocity d' = R(-phi) (p' - p_nom') - phi' k x d, rotation theta = the x axis's angle less
the nominal angle, angular velocity the sensor's, less the nominal one for theta'; a tilting member's tilts about
the carrier's axes R(-phi) (-z_y, z_x) from its body's z axis (to first order in the tilt, as the models keep it).

The nominal motion enters through :func:`nominal_angle` alone: under an operating history every nominal speed is
lambda(t) times its own and every nominal angle its speed times Lambda(t) (the nominal clock both models read,
:class:`~gearcheck.train.history.Clock`).
"""

from __future__ import annotations

from typing import NamedTuple

import mujoco
import numpy as np

from gearcheck.mbd_models.static_state import nominal_speeds
from gearcheck.shared.results import MemberMotion


def nominal_angle(speed: float, t: np.ndarray, clock=None) -> tuple[np.ndarray, np.ndarray]:
    """(angle, angular velocity) at times ``t`` of whatever turns at ``speed`` (rad/s) in the twin's nominal
    motion -- a body, a centre's place about the stage axis --, the angle 0 at t = 0; ``clock`` an operating
    history's nominal clock."""
    if clock is None:
        return speed * t, np.full(np.shape(t), speed)
    return speed * clock.time(t), speed * clock.scale(t)


class NominalPlaces(NamedTuple):
    """The twin's nominal motion per member (``spec.members`` order), read from MuJoCo at qpos0 with every joint
    at its nominal speed."""

    speed: np.ndarray  # the body's angular velocity about z, rad/s
    place: np.ndarray  # (n_members, 3) the centre's world position at t = 0, m
    orbit: np.ndarray  # the angular velocity of that place about the stage axis, rad/s (0 on the axis)


def nominal_places(mb) -> NominalPlaces:
    """:class:`NominalPlaces` of the twin ``mb``: ``mj_forward`` at qpos0 with ``nominal_speeds``, each body's
    angular velocity w and its centre's place p and velocity p' from ``mj_objectVelocity``; the place turns about
    the axis at (p x p')_z / |p|^2 (p in the plane)."""
    m = mb.model
    d = mujoco.MjData(m)
    d.qvel[:] = nominal_speeds(mb)
    mujoco.mj_forward(m, d)
    n = len(mb.spec.members)
    speed, place, orbit = np.zeros(n), np.zeros((n, 3)), np.zeros(n)
    velocity = np.zeros(6)  # (angular, linear), world frame
    for j, mid in enumerate(mb.spec.members):
        body = mb.body[mid]
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, body, velocity, 0)
        p = d.xpos[body]
        radius2 = p[0] ** 2 + p[1] ** 2
        speed[j], place[j] = velocity[2], p
        orbit[j] = (p[0] * velocity[4] - p[1] * velocity[3]) / radius2 if radius2 > 0 else 0.0
    return NominalPlaces(speed, place, orbit)


def member_motion(mb, sensors: np.ndarray, t: np.ndarray):
    """A function j -> :class:`~gearcheck.shared.results.MemberMotion` of the j-th member of ``mb.spec.members``
    from the sampled ``sensors`` (n_t, nsensordata) at times ``t`` (module docstring)."""
    spec = mb.spec
    nominal = nominal_places(mb)
    members = list(spec.members.values())

    def read(name: str) -> np.ndarray:  # a sensor's components as contiguous rows (dim, n_t)
        adr, dim = mb.sensor[name]
        return np.ascontiguousarray(sensors[:, adr:adr + dim].T)

    def motion(j: int) -> MemberMotion:
        member = members[j]
        label, carrier = member.label, spec.members[spec.stage_of(member.id).carrier].label
        angle = read(f"{carrier}_angle")[0] + member.angle
        rate = read(f"{carrier}_angle_rate")[0]
        c, s = np.cos(angle), np.sin(angle)

        def along(x, y):  # world (x, y) -> the carrier's axes, time x 2
            return np.stack([c * x + s * y, -s * x + c * y], axis=-1)

        orbit, orbit_rate = nominal_angle(nominal.orbit[j], t, mb.excitation.clock)
        x0, y0, z0 = nominal.place[j]
        place = np.cos(orbit) * x0 - np.sin(orbit) * y0, np.sin(orbit) * x0 + np.cos(orbit) * y0
        position, velocity, linacc = read(f"{label}_pos"), read(f"{label}_linvel"), read(f"{label}_linacc")
        displacement = along(position[0] - place[0], position[1] - place[1])
        relative = (along(velocity[0] + orbit_rate * place[1], velocity[1] - orbit_rate * place[0])  # less w k x p
                    - rate[:, None] * displacement[:, ::-1] * [-1.0, 1.0])  # less phi' k x d
        xaxis = read(f"{label}_xaxis")
        turned, speed = nominal_angle(nominal.speed[j], t, mb.excitation.clock)
        theta = np.unwrap(np.arctan2(xaxis[1], xaxis[0]) - turned)
        theta -= 2 * np.pi * np.round(theta[0] / (2 * np.pi))
        omega = read(f"{label}_angvel")[2]
        axial = np.stack([linacc[2], position[2] - z0, velocity[2]], axis=-1) if member.axial else None
        tilt = None
        if member.tilting:  # the z axis (z_x, z_y, .) of a body tilted by phi: phi_x = -z_y, phi_y = z_x
            zaxis = read(f"{label}_zaxis")
            tilt = along(-zaxis[1], zaxis[0])
        return MemberMotion(angle, along(linacc[0], linacc[1]), read(f"{label}_angacc")[2], displacement,
                            along(velocity[0], velocity[1]), relative, theta, omega, omega - speed, axial, tilt)

    return motion
