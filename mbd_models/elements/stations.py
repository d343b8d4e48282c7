"""What holds a member on the housing (a support) or on its carrier's pin (a bearing) in the plane and in tilt,
shared by the two elements (:mod:`~gearcheck.mbd_models.elements.support`,
:mod:`~gearcheck.mbd_models.elements.bearing`).

Without stations the radial stiffness and damping act on the member's two slides: a spring at its centre of
mass, relative to its parent body (the world, or the carrier that carries a planet).  A tilting member's stations
share them along the axis: station i at p_i from the centre of mass is a fixed tendon per translation axis,
``<label>_station<i>_<axis>``, whose length is the displacement of the member's point there relative to the
parent's point there along that slide's axis, delta = u + phi x (p_i e_z) (Eritenel & Parker 2009's bearing at
an axial station), its coefficients MuJoCo's Jacobians at that point.  A tilting stiffness and damping act on the
member's tilt hinges, which are relative to the same parent.  A planet's misaligned pin (tilted by gamma in its
carrier) holds it at rest tilted by gamma: the hinges' springs are relaxed there (``springref``) and the stations'
tendons at the deflections that tilt gives them (their spring lengths).
"""

from __future__ import annotations

import mujoco
import numpy as np

from gearcheck.mbd_models.jacobians import named, point_row
from gearcheck.mbd_models.mjcf_text import LATE, Spring, fixed, member_axes, member_tilts

HEADER = ["Bearing stations are tendons <member>_station<i>_<axis> (the radial stiffness shared along the axis)."]


def stations(member, holder) -> tuple:
    """The stations that hold ``member`` on ``holder`` (its Support): those of a tilting member that translates."""
    return holder.stations if member.tilting and member_axes(member) else ()


def station_tendon(member, i: int, axis: str) -> str:
    return f"{member.label}_station{i + 1}_{axis}"


def station_names(spec) -> list[str]:
    """Every station tendon of the train, in the order the file writes them."""
    return [station_tendon(m, i, axis) for m in spec.members.values()
            for holder in (m.support, m.bearing) if holder is not None
            for i, _ in enumerate(stations(m, holder)) for axis in member_axes(m)]


def holding_springs(member, holder) -> dict:
    """{(member id, joint suffix): :class:`~gearcheck.mbd_models.mjcf_text.Spring`}: the radial stiffness on the
    slides when no station shares it, the tilting stiffness on the tilt hinges, relaxed at a misaligned pin's tilt
    (``holder.rest_tilt``, about the member's two translation axes)."""
    springs = {} if stations(member, holder) else {(member.id, a): Spring(holder.radial_stiffness,
                                                                          holder.radial_damping)
                                                   for a in member_axes(member)}
    springs.update({(member.id, t): Spring(holder.tilting_stiffness, holder.tilting_damping, rest)
                    for t, rest in zip(member_tilts(member), holder.rest_tilt)})
    return springs


def station_tendons(member, holder) -> list[str]:
    """A fixed tendon per station and translation axis over the member's slides and tilt hinges (coefficients
    late: :func:`station_rows`), relaxed where a misaligned pin's tilt gamma puts the station's point of the pin:
    gamma x (p e_z) = p (gamma_2, -gamma_1) along the two axes."""
    joints = [f"{member.label}_{j}" for j in member_axes(member) + member_tilts(member)]
    first, second = holder.rest_tilt
    return [line for i, st in enumerate(stations(member, holder))
            for axis, rest in zip(member_axes(member), (st.position * second, -st.position * first))
            for line in fixed(station_tendon(member, i, axis), [(j, LATE) for j in joints], st.radial_stiffness,
                              st.radial_damping, (rest, rest))]


def station_rows(member, holder, parent: str, model, data) -> list[tuple[str, np.ndarray]]:
    """(tendon, row) of every station of ``member``: the displacement of its point at p along its axis relative to
    the point of body ``parent`` (its label; "world": the housing) there, along each slide's axis."""
    body = named(model, mujoco.mjtObj.mjOBJ_BODY, member.label)
    reference = named(model, mujoco.mjtObj.mjOBJ_BODY, parent)
    rows = []
    for i, st in enumerate(stations(member, holder)):
        point = data.xpos[body] + st.position * data.xmat[body].reshape(3, 3)[:, 2]
        for axis in member_axes(member):
            slide = named(model, mujoco.mjtObj.mjOBJ_JOINT, f"{member.label}_{axis}")
            rows.append((station_tendon(member, i, axis),
                         point_row(model, data, body, reference, point, data.xaxis[slide])))
    return rows
