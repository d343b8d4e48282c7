"""Torsional members: the train file's ``torsional`` flags, checked, and what they set aside.

A torsional member keeps its rotation only (the purely torsional level of Kahraman 1994 and of Lin & Parker's
1999 reduction): a member on the stage axis has its translations held at zero, a planet rides rigidly on its
carrier's pin (its centre moves with the pin, r_c theta_c along the tangent when the carrier turns).  Its
support's translational stiffness and damping (a planet's bearing) then act on nothing: they are set aside here
with a note, where a file may keep them to switch the flag on and off.  Both models read the flag through
:attr:`gearcheck.train.spec.Member.coordinates`.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

from gearcheck.shared.errors import TrainNote

FLAG = "torsional"
TRANSLATIONAL = ("radial_stiffness", "radial_damping", "axial_stiffness", "axial_damping")  # of a Support


def torsional_members(st: dict, centrals: dict, members: dict, rv: bool, path: str, fail) -> dict:
    """``members`` of the stage ``st`` with their ``torsional`` flags (a member's own, else the stage's), a
    torsional member's support without its translational terms and a torsional planet without its bearing
    (noted when they were given).  An RV reducer's stage has no torsional level: a flag there is refused."""
    name = st["name"]
    raws = {f"{name}.{key}": (raw, f"{path}.{key}") for key, (_, _, raw) in centrals.items()}
    raws[f"{name}.carrier"] = (st["carrier"], f"{path}.carrier")
    own = {mid: raw[FLAG] for mid, (raw, _) in raws.items()}
    planet_flag = st["planet"][FLAG]
    if rv:
        given = [(f"{path}.{FLAG}", st[FLAG])] + [(f"{p}.{FLAG}", raw[FLAG]) for raw, p in raws.values()] \
            + [(f"{path}.planet.{FLAG}", planet_flag)]
        for field, value in given:
            if value:
                raise fail(field, "an RV reducer's stage has no torsional level (its cranks, discs and pins move "
                                  "in the plane): remove it")
        return members
    out, ignored = dict(members), []
    for mid, member in members.items():
        flag = planet_flag if member.is_planet else own[mid]
        if not (st[FLAG] if flag is None else flag):
            continue
        support = member.support
        if support is not None:
            if any(getattr(support, d) for d in TRANSLATIONAL):
                ignored.append(f"{mid}'s support")
            support = replace(support, **dict.fromkeys(TRANSLATIONAL, 0.0))
        if member.bearing is not None:
            ignored.append("the planets' bearing")
        out[mid] = replace(member, torsional=True, support=support, bearing=None)
    if ignored:
        what = ", ".join(dict.fromkeys(ignored))
        warnings.warn(f"{path} ({name}): the translational stiffness and damping of {what} ignored: torsional "
                      "members have no translations for them to act on", TrainNote, stacklevel=3)
    return out


def check_torsional_couplings(coupling: dict, members: dict, path: str, fail) -> None:
    """A coupling's radial stiffness or damping in a train with torsional members is refused: the translations it
    would join across the stages are held or ride a pin (give the torsional coupling alone)."""
    if not any(m.torsional for m in members.values()):
        return
    for key in ("radial_stiffness", "radial_damping"):
        if coupling[key]:
            raise fail(f"{path}.{key}", f"{coupling[key]:g} in a train with torsional members: a torsional train's "
                                        "couplings are torsional only; remove it")
