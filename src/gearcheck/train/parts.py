"""The parts that join a train's members, each a kind of element that both models build
(:class:`gearcheck.shared.elements.Registry`).

:func:`train_parts` lists them in the one order both models build them: the meshes, supports of the members
on the housing, bearings of the members on carrier pins, interstage couplings, splines, the drive and the
cycloid-pin stages.  The meshes (:class:`~gearcheck.train.spec.MeshSpec`), couplings
(:class:`~gearcheck.train.spec.Coupling`) and cycloid-pin stages (:class:`~gearcheck.train.spec.CycloidStage`)
are parts as the train file describes them (:class:`~gearcheck.train.spec.TrainSpec` holds them); the others
are written here from the members that carry them, the splines from the cycloid-pin stages.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar


class Part:
    """What every part gives the train's nominal kinematics (:mod:`gearcheck.train.kinematics`), the harmonic
    methods and ``gearcheck show``; by default nothing."""

    def speed_rows(self, spec, index: dict) -> list:
        """(row, label) of each rigid constraint on the members' absolute speeds (``index``: member id ->
        column) that the part imposes: row . w = 0."""
        return []

    def frequencies(self, speeds: dict) -> dict[str, float]:
        """Frequencies (Hz) of the part's periodic contacts at the members' nominal ``speeds`` (rad/s), named."""
        return {}

    def turning_frequencies(self, spec, speeds: dict) -> list[float]:
        """Frequencies (Hz) at which the part's connections turn in the carrier frames of the members it joins at
        the members' nominal ``speeds`` (rad/s): its forces there repeat with them."""
        return []

    def dead_zones(self) -> list[str]:
        """The part's clearances that its contacts cross before they touch (a load that depends on the contact
        set), named."""
        return []

    def joined(self) -> tuple[str, ...]:
        """The members whose motion its forces depend on and act on (member ids)."""
        return ()

    def describe(self, spec, kin, touching: set[str]) -> dict:
        """What ``gearcheck show`` prints of the part, in its stage (``stage``) under its kind: derived from
        ``spec``, its kinematics ``kin`` and the names of the contacts ``touching`` at rest in the reference
        model."""
        return {}


@dataclass(frozen=True)
class SupportPart(Part):
    """A central member on the housing: radial springs along both translations, torsion, and axial."""

    element: ClassVar[str] = "support"
    member: str
    support: object  # gearcheck.train.spec.Support
    axial: bool

    def joined(self) -> tuple[str, ...]:
        return (self.member,)

    def turning_frequencies(self, spec, speeds: dict) -> list[float]:
        """A seat misaligned in the housing (``Support.rest_tilt``) turns in its member's carrier frame at -Omega."""
        omega = speeds[f"{spec.members[self.member].stage}.carrier"]
        return [abs(omega) / (2 * math.pi)] if any(self.support.rest_tilt) and omega else []


@dataclass(frozen=True)
class BearingPart(Part):
    """A member on a pin of its carrier (planet, crankshaft): isotropic in the plane, and axial."""

    element: ClassVar[str] = "bearing"
    member: str
    carrier: str
    bearing: object  # gearcheck.train.spec.Support
    axial: bool

    def joined(self) -> tuple[str, ...]:
        return self.member, self.carrier


@dataclass(frozen=True)
class SplinePart(Part):
    """An RV reducer's planet on its crankshaft, both at the same pin: bending and torsion."""

    element: ClassVar[str] = "spline"
    planet: str
    crank: str
    spline: object  # gearcheck.train.spec.Support

    def joined(self) -> tuple[str, ...]:
        return self.planet, self.crank


@dataclass(frozen=True)
class DrivePart(Part):
    """The drive: torques on the input and output members and, when the input is driven by angle, the input
    shaft, a torsional spring-damper between the input member and the drive's reference angle."""

    element: ClassVar[str] = "drive"
    member: str  # the input
    output: str
    stiffness: float | None  # the input shaft's; None: the input is driven by torque
    damping: float

    def joined(self) -> tuple[str, ...]:
        """The input member on its shaft (the output's torque is prescribed)."""
        return (self.member,)


def train_parts(spec) -> tuple:
    """Every part of ``spec`` (a :class:`~gearcheck.train.spec.TrainSpec`), in build order."""
    supports = [SupportPart(mid, m.support, m.axial) for mid, m in spec.members.items() if m.support is not None]
    bearings = [BearingPart(mid, spec.stage_of(mid).carrier, m.bearing, m.axial) for mid, m in spec.members.items()
                if m.bearing is not None]
    splines = [SplinePart(planet, crank, cyc.spline) for cyc in spec.cycloids
               for planet, crank in zip(spec.stage_of(cyc.cranks[0]).planets, cyc.cranks)]
    op = spec.operating
    drive = DrivePart(spec.input, spec.output, op.input_shaft_stiffness, op.input_shaft_damping)
    return (*spec.meshes, *supports, *bearings, *spec.couplings, *splines, drive, *spec.cycloids)
