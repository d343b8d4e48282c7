"""Static pin loads of a cycloid-pin stage: the force on every pin of every disc over a pin pitch or a turn.

At each time t the model is frozen (its eccentrics, pins and static contact set those of t) and solved for its
static equilibrium under the mean load; a touching pin's force is its stiffness times its compression,
F_i = k (n_i . u_j + l_i theta_j), the rows of Yang, Chen & Wang (2018, Appendix, K_cr) summed over the pins that
touch.  Beside it: the rigid-disc load share of the same disc torque, F_i = F_max l_i / r_c with
F_max = T r_c / sum l^2 -> 4 T / (Z_p r_c) (the classical distribution of cycloid-drive design).

Checks that come with it: the pins' torque on the discs about the pin wheel's centre balances the output and
input torques, -T_out (1 - 1/i) for a lossless train of ratio i; the torque of each disc about its own centre is
Z_c / Z_p of its share of that (every pin's arm about the disc centre is r_c / (Z_p e) of its arm about the
wheel centre).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.lumped.assembly import frozen_at
from gearcheck.train.cycloid import (
    classical_peak_force,
    pin_contacts,
    rigid_disc_load_share,
)
from gearcheck.lumped.elements.cycloid import CycloidRows
from gearcheck.lumped.static import static_solution
from gearcheck.shared.errors import GearcheckError

SPANS = ("pitch", "turn")


@dataclass(frozen=True)
class PinLoads:
    """Static pin forces at frozen times: arrays (T, N, Z_p) over times, discs and pins (carrier frame)."""

    stage: str
    geometry: object  # CycloidGeometry
    times: np.ndarray  # (T,) s
    eccentric_angles: np.ndarray  # (T, N) phi_j in the carrier frame
    pin_angles: np.ndarray  # (T, Z_p) each pin's place on the pin circle in the carrier frame
    relative_angles: np.ndarray  # (T, N, Z_p) varphi = pin angle - eccentric angle, in [0, 2 pi)
    forces: np.ndarray  # (T, N, Z_p) N, 0 where the pin does not touch
    arms: np.ndarray  # (T, N, Z_p) l, arm of the normal about the disc centre
    wheel_arms: np.ndarray  # (T, N, Z_p) a, arm of the normal about the pin wheel's centre
    classical: np.ndarray  # (T, N, Z_p) rigid-disc share of each disc's own torque
    output_torque: float  # N m on the output (signed)
    ratio: float  # input speed / output speed

    @property
    def loaded(self) -> np.ndarray:
        return self.forces > 0.0

    @property
    def loaded_count(self) -> np.ndarray:
        """(T, N) pins in contact per disc."""
        return self.loaded.sum(axis=-1)

    @property
    def peak_force(self) -> np.ndarray:
        """(T, N) the largest pin force of each disc, N."""
        return self.forces.max(axis=-1)

    @property
    def disc_torque(self) -> np.ndarray:
        """(T, N) sum F_i l_i: the torque on each disc about its centre from everything but the pins."""
        return np.sum(self.forces * self.arms, axis=-1)

    @property
    def wheel_torque(self) -> np.ndarray:
        """(T,) -sum F_i a_i over all discs: the pins' torque on the discs about the pin wheel's centre."""
        return -np.sum(self.forces * self.wheel_arms, axis=(-2, -1))

    @property
    def expected_wheel_torque(self) -> float:
        """-T_out (1 - 1/i): what the pin wheel must hold for the output torque and the input's T_out / i."""
        return -self.output_torque * (1.0 - 1.0 / self.ratio)

    @property
    def torque_balance_error(self) -> np.ndarray:
        """(T,) relative error of :attr:`wheel_torque` against :attr:`expected_wheel_torque`."""
        return self.wheel_torque / self.expected_wheel_torque - 1.0

    @property
    def classical_peak(self) -> np.ndarray:
        """(T, N) 4 |T_j| / (Z_p r_c) of each disc's torque."""
        return classical_peak_force(self.geometry, self.disc_torque)

    @property
    def peak_ratio(self) -> np.ndarray:
        """(T, N) peak force over the classical 4 T / (Z_p r_c)."""
        return self.peak_force / self.classical_peak

    def summary(self) -> dict:
        """Extremes over the times and discs, for a report."""
        return {
            "times": len(self.times),
            "loaded_pins_min": int(self.loaded_count.min()),
            "loaded_pins_max": int(self.loaded_count.max()),
            "peak_force_n": float(self.peak_force.max()),
            "classical_peak_n": float(self.classical_peak.mean()),
            "rigid_share_peak_n": float(self.classical.max()),
            "peak_ratio_min": float(self.peak_ratio.min()),
            "peak_ratio_max": float(self.peak_ratio.max()),
            "disc_torque_nm": float(np.abs(self.disc_torque).mean()),
            "wheel_torque_nm": float(self.wheel_torque.mean()),
            "expected_wheel_torque_nm": float(self.expected_wheel_torque),
            "torque_balance_error_max": float(np.abs(self.torque_balance_error).max()),
        }


def cycloid_element(model, stage: str | None = None) -> CycloidRows:
    """The model's cycloid-pin stage ``stage`` (by name; the only one when None)."""
    found = [e for e in model.turning if isinstance(e, CycloidRows)]
    if stage is not None:
        found = [e for e in found if e.stage == stage]
    if len(found) != 1:
        names = ", ".join(e.stage for e in model.turning if isinstance(e, CycloidRows)) or "none"
        if stage or not found:
            raise GearcheckError(f"{model.spec.name} has no cycloid-pin stage {stage or ''}(its cycloid stages: "
                                 f"{names})".replace("  ", " "))
        raise GearcheckError(f"{model.spec.name} has several cycloid-pin stages ({names}): name one")
    return found[0]


def span_period(element: CycloidRows, span: str = "pitch") -> float:
    """Seconds of one pin pitch passing a disc's eccentric (``pitch``: the contact pattern repeats) or of one
    eccentric turn in the carrier frame (``turn``: the whole frozen configuration repeats, the pins having moved
    on by one pitch)."""
    if span not in SPANS:
        raise GearcheckError(f"span {span!r}: one of {', '.join(SPANS)}")
    rate = element.omega_pins - element.omega_eccentric if span == "pitch" else element.omega_eccentric
    if rate == 0.0:
        raise GearcheckError("the eccentrics do not turn: the train has no speed")
    pins = element.geometry.pins if span == "pitch" else 1
    return 2.0 * math.pi / (pins * abs(rate))


MAX_TIMES = 10_000  # frozen times: each is a static contact solution (some milliseconds)


def pin_loads(model, times=None, *, span: str = "pitch", samples: int = 16, stage: str | None = None) -> PinLoads:
    """Static pin forces of every disc and pin at ``times`` (s), by default ``samples`` times evenly over one
    ``span`` (:func:`span_period`) from t = 0: each time frozen and solved statically under the mean load."""
    element = cycloid_element(model, stage)
    if times is None:
        if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or not 1 <= samples <= MAX_TIMES:
            raise GearcheckError(f"samples={samples!r}: a whole number of frozen times from 1 to {MAX_TIMES}")
        times = np.arange(samples) * span_period(element, span) / samples
    times = np.atleast_1d(np.asarray(times, dtype=float))
    if times.ndim != 1 or not 1 <= times.size <= MAX_TIMES or not np.all(np.isfinite(times)):
        raise GearcheckError(f"times: 1 to {MAX_TIMES} finite times in s, got {times.size}")
    g = element.geometry
    n_discs, n_pins = len(element.disc), g.pins
    where = {f"{element.stage}.disc{j + 1}.pin{i + 1}": (j, i) for j in range(n_discs) for i in range(n_pins)}
    forces = np.zeros((len(times), n_discs, n_pins))
    for k, t in enumerate(times):
        frozen = frozen_at(model, float(t))
        q = static_solution(frozen).q
        for row in frozen.rows:
            if row.kind == "contact" and row.name in where:
                forces[(k,) + where[row.name]] = max(row.stiffness * float(row.a @ q), 0.0)
    phi = element.eccentric_angles(times)  # (T, N)
    wheel = element.pin_angles(times)  # (T,)
    contacts = pin_contacts(g, phi, wheel[:, None])
    torque = np.sum(forces * contacts.arm, axis=-1)
    classical = rigid_disc_load_share(g, torque, phi, wheel[:, None])
    return PinLoads(
        stage=element.stage, geometry=g, times=times, eccentric_angles=phi,
        pin_angles=np.mod(2 * np.pi * np.arange(n_pins) / n_pins + wheel[:, None], 2 * np.pi),
        relative_angles=contacts.relative_angle, forces=forces, arms=contacts.arm, wheel_arms=contacts.wheel_arm,
        classical=classical, output_torque=float(model.kin.output_torque), ratio=float(model.kin.ratio))
