"""Tilting stages: the train file's ``tilting`` flag, checked, and what it adds to the members and meshes.

Every member of a tilting stage gains two tilts, small rotations about its two translation axes
(:data:`~gearcheck.train.spec.TILTS`), beside its translations, rotation and axial motion (which it has even with
spur gears: a tilting carrier carries its planets' pins along the axis): the 3-D model of Eritenel & Parker (2009),
whose members' centres of mass lie in the stage's plane.  What holds a tilt is the
member's support (a central member on the housing) or bearing (a planet on its carrier's pin): a tilting stiffness,
and the bearing stations along the axis over which the radial stiffness is shared, which a radial spring at an
axial distance p from the centre of mass turns into a moment p F and a tilting stiffness p^2 k.  A planet's pin may
be misaligned in the carrier (``pin_tilts_urad``), a central member's seat in the housing (its support's
``tilt_urad``): the bearing or support then holds the member at that tilt, and the meshes meet a tilted gear, whose
load moves along the face.  A mesh acts at its
centre of stiffness, the middle of the two faces' overlap (a gear's face may be offset axially from its member's
centre of mass), and resists the members' relative tilt across the face by its slices; a published model may state
its tilting stiffness and its centre of stiffness instead.

A stage that does not tilt keeps its members and meshes as they are: a tilting key given there is set aside with
a note, where a file may keep it to switch the flag on and off.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

from gearcheck.shared.errors import TrainNote

FLAG = "tilting"
SHARE_TOLERANCE = 1e-9  # the stations' shares of a support must sum to 1 within it
TILTING = ("tilting_stiffness", "tilting_damping", "stations")  # of a Support


def tilting_stage(st: dict, centrals: dict, members: dict, meshes: list, path: str, fail):
    """(members, meshes) of the stage ``st``: tilting members with their tilting inertias and every tilt held,
    and meshes with their centres of stiffness and contact widths, when the stage tilts (its layout and axial
    supports checked by the stage); as they are otherwise (a tilting key given there noted and set aside)."""
    holders = _holders(st, centrals, path)
    if not st[FLAG]:
        return _set_aside(members, meshes, holders, path, st["name"], st["planet"]["pin_tilts"]), meshes
    pins = st["planet"]["pin_tilts"]
    if pins and len(pins) != st["planets"]:
        raise fail(f"{path}.planet.pin_tilts_urad", f"needs one pair per planet ({st['planets']}), got {len(pins)}")
    out = {}
    for mid, member in members.items():
        raw, raw_path, support_path = holders[mid]
        if member.torsional:
            raise fail(f"{raw_path}.torsional", "a tilting stage's members move in three dimensions; a torsional "
                                                "member only turns: remove one of the two flags")
        _check_held(member.support if member.support is not None else member.bearing, support_path, fail)
        out[mid] = replace(member, tilting=True,
                           tilting_inertia=_tilting_inertia(member, raw, f"{raw_path}.tilting_inertia", fail))
        if member.is_planet and pins:
            pin = pins[int(mid.rsplit(".planet", 1)[1]) - 1]
            out[mid] = replace(out[mid], bearing=replace(member.bearing, rest_tilt=tuple(pin)))
    return out, [_placed(mesh, path, fail) for mesh in meshes]


def _holders(st: dict, centrals: dict, path: str) -> dict:
    """member id -> (its raw table, that table's path, its support's or bearing's path); the planets share one."""
    name = st["name"]
    out = {f"{name}.{key}": (raw, f"{path}.{key}", f"{path}.{key}.support") for key, (_, _, raw) in centrals.items()}
    out[f"{name}.carrier"] = (st["carrier"], f"{path}.carrier", f"{path}.carrier.support")
    for k in range(st["planets"]):
        out[f"{name}.planet{k + 1}"] = (st["planet"], f"{path}.planet", f"{path}.planet.bearing")
    return out


def _set_aside(members: dict, meshes: list, holders: dict, path: str, name: str, st_pins) -> dict:
    """The members of a stage that does not tilt, with any tilting key of their supports set aside (noted)."""
    out, ignored = dict(members), [f"{path}.planet.pin_tilts_urad"] if st_pins else []
    for mid, (raw, raw_path, support_path) in holders.items():
        member = members[mid]
        if raw.get("tilting_inertia") is not None:
            ignored.append(f"{raw_path}.tilting_inertia")
        for attr in ("support", "bearing"):
            support = getattr(member, attr)
            if support is not None and (any(getattr(support, key) for key in TILTING) or any(support.rest_tilt)):
                ignored.append(f"{support_path}'s tilting stiffness, stations and tilt")
                out[mid] = replace(out[mid], **{attr: replace(support, tilting_stiffness=0.0, tilting_damping=0.0,
                                                                 stations=(), rest_tilt=(0.0, 0.0))})
    if any(value is not None for mesh in meshes for value in mesh.stated_tilt):
        ignored.append(f"{path}'s mesh tilting_stiffness and centre_offset_mm")
    if ignored:
        warnings.warn(f"{path} ({name}): {', '.join(dict.fromkeys(ignored))} ignored: the stage does not tilt "
                      "(give it `tilting = true`)", TrainNote, stacklevel=4)
    return out


def _check_held(support, path: str, fail) -> None:
    """A tilting member's support or bearing holds both tilts: a tilting stiffness, or stations at two axial
    positions at least; its stations' shares sum to 1."""
    if support is None:
        return
    if support.stations:
        total = sum(s.radial_stiffness for s in support.stations) / support.radial_stiffness
        if abs(total - 1.0) > SHARE_TOLERANCE:
            raise fail(f"{path}.stations", f"the shares sum to {total:.12g}, not 1")
    if support.tilting_stiffness <= 0.0 and len({s.position for s in support.stations}) < 2:
        raise fail(f"{path}.tilting_stiffness", "a tilting stage needs it > 0, or stations at two axial positions: "
                                                "nothing else holds the member's tilt")


def _tilting_inertia(member, raw: dict, path: str, fail) -> float:
    """As given, or I/2 + m w^2/12 about a diameter of a uniform annulus of polar inertia I, mass m and width w
    (its thickness, a gear's face width; 0 for a carrier given neither: a thin disc).  A given one below I/2 is
    refused: a rigid body's inertias about two perpendicular diameters add up to at least its polar one."""
    given = raw.get("tilting_inertia")
    if given is not None:
        if given < 0.5 * member.inertia:
            raise fail(path, f"{given:.6g} kg·m² is below half the polar inertia ({0.5 * member.inertia:.6g} kg·m²), "
                             "which no rigid body has")
        return given
    width = raw.get("thickness")
    if width is None:
        width = max((g.face_width for g in member.gears.values()), default=0.0)
    return 0.5 * member.inertia + member.mass * width**2 / 12.0


def _placed(mesh, path: str, fail):
    """``mesh`` with its centre of stiffness and contact width: the overlap of the two gears' faces, each
    face_width long about its axial offset (an idealised mesh without faces: width 0, its tilting stiffness and
    centre as stated)."""
    gears = (mesh.central_gear, mesh.planet_gear)
    key = mesh.id.split(".")[-1]
    stiffness, centre = mesh.stated_tilt
    if not all(g.face_width for g in gears):  # an idealised gear without a face: the file states the mesh's tilt
        if stiffness is None:
            raise fail(f"{path}.{key}.mesh.tilting_stiffness", "an idealised mesh without face widths needs it "
                                                                "(no face to derive it from)")
        return replace(mesh, axial_centre=centre or 0.0, contact_width=0.0)
    faces = [(g.axial_offset - 0.5 * g.face_width, g.axial_offset + 0.5 * g.face_width) for g in gears]
    low, high = max(f[0] for f in faces), min(f[1] for f in faces)
    if not high > low or not math.isfinite(high - low):
        raise fail(f"{path}.{key}.axial_offset_mm", f"the faces of {mesh.central_gear.name} and the planet's "
                                                    f"{mesh.planet_gear.name} do not overlap "
                                                    "(a tilting mesh needs face widths that meet)")
    if centre is not None and not low <= centre <= high:
        raise fail(f"{path}.{key}.mesh.centre_offset_mm", f"{centre * 1e3:.6g} mm is off the faces' overlap, "
                                                          f"{low * 1e3:.6g} to {high * 1e3:.6g} mm")
    return replace(mesh, axial_centre=0.5 * (low + high) if centre is None else centre, contact_width=high - low)
