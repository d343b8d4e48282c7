"""Order curves of a run-up against a stepped sweep, and what the run-up's rate does to a resonance peak.

Away from resonances a slow run-up's order curve is the steady response: :func:`against_sweep` reads the tracked
curve (dense: one point a block) at the stepped sweep's speeds by linear interpolation and gives the relative
differences, leaving out the speeds within ``band_rpm`` of a resonance (:func:`resonance_speeds`: where the order's
frequency equals a natural frequency).  Through a resonance a run-up lags and lowers the peak
(:mod:`gearcheck.compare.studies.resonance_passage` says by how much for a mode): :func:`sweep_effect` measures the
shift of the peak's speed and the ratio of its amplitude to a reference curve's (a slower run-up, or the steady
sweep), each peak located by a least-squares parabola through the top of the curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.compare.studies.order_tracking import OrderTrack, checked_array
from gearcheck.shared.errors import GearcheckError

PEAK_TOP = 0.005  # a peak's parabola runs through the samples within this fraction of its largest amplitude


def resonance_speeds(order: float, natural_hz) -> np.ndarray:
    """The input speeds (rpm) at which ``order`` excites each of ``natural_hz``: 60 f_n / order."""
    if not order > 0:
        raise GearcheckError(f"order: must be positive, got {order!r}")
    return 60.0 * checked_array("natural_hz", natural_hz) / order


@dataclass(frozen=True)
class SweepComparison:
    order: float
    speed_rpm: np.ndarray  # the stepped sweep's speeds compared: inside the run, away from the resonances
    steady: np.ndarray
    tracked: np.ndarray

    @property
    def relative(self) -> np.ndarray:
        """tracked / steady - 1 at each speed compared."""
        return self.tracked / self.steady - 1.0

    @property
    def worst(self) -> float:
        """The largest |relative difference| (NaN when no speed was compared)."""
        return float(np.max(np.abs(self.relative))) if self.speed_rpm.size else float("nan")


def against_sweep(track: OrderTrack, order: float, sweep_rpm, sweep_amplitude, resonances_rpm=(),
                  band_rpm: float = 0.0) -> SweepComparison:
    """``order``'s tracked amplitude against the steady amplitudes ``sweep_amplitude`` at the stepped sweep's speeds
    ``sweep_rpm``, at the speeds inside the run's blocks and farther than ``band_rpm`` from every speed of
    ``resonances_rpm``."""
    speed, amplitude = _monotone(*track.curve(order))
    sweep = checked_array("sweep_rpm", sweep_rpm)
    steady = checked_array("sweep_amplitude", sweep_amplitude)
    if steady.size != sweep.size:
        raise GearcheckError(f"sweep_amplitude: {steady.size} values for {sweep.size} speeds in sweep_rpm")
    if not band_rpm >= 0:
        raise GearcheckError(f"band_rpm: must be >= 0, got {band_rpm!r}")
    resonances = np.atleast_1d(np.asarray(resonances_rpm, dtype=float))
    keep = (sweep >= speed[0]) & (sweep <= speed[-1])
    if resonances.size:
        keep &= np.min(np.abs(sweep[:, None] - resonances[None, :]), axis=1) > band_rpm
    return SweepComparison(float(order), sweep[keep], steady[keep], np.interp(sweep[keep], speed, amplitude))


@dataclass(frozen=True)
class Peak:
    speed_rpm: float
    amplitude: float


def peak(speed_rpm, amplitude, within: tuple[float, float] | None = None) -> Peak:
    """The peak of a curve inside ``within`` (rpm; default: all of it): the vertex of the least-squares parabola
    through the samples next to the largest whose amplitude is within ``PEAK_TOP`` of it (at least three)."""
    speed, amplitude = _monotone(checked_array("speed_rpm", speed_rpm), checked_array("amplitude", amplitude))
    lo, hi = (speed[0], speed[-1]) if within is None else within
    inside = np.flatnonzero((speed >= lo) & (speed <= hi))
    if inside.size < 3:
        raise GearcheckError(f"within: fewer than 3 samples of the curve between {lo:g} and {hi:g} rpm")
    top = inside[np.argmax(amplitude[inside])]
    if top in (inside[0], inside[-1]):
        raise GearcheckError(f"within: the largest amplitude between {lo:g} and {hi:g} rpm is at its edge "
                             f"({speed[top]:.6g} rpm): no peak inside")
    first, last = top - 1, top + 1
    while first > inside[0] and amplitude[first - 1] >= (1.0 - PEAK_TOP) * amplitude[top]:
        first -= 1
    while last < inside[-1] and amplitude[last + 1] >= (1.0 - PEAK_TOP) * amplitude[top]:
        last += 1
    x = speed[first:last + 1] - speed[top]
    a, b, c = np.polyfit(x, amplitude[first:last + 1], 2)
    return Peak(float(speed[top] - 0.5 * b / a), float(c - 0.25 * b * b / a))


@dataclass(frozen=True)
class SweepEffect:
    peak: Peak
    reference: Peak

    @property
    def shift_rpm(self) -> float:
        """The peak's speed minus the reference's (> 0: later in a run-up)."""
        return self.peak.speed_rpm - self.reference.speed_rpm

    @property
    def ratio(self) -> float:
        """The peak's amplitude over the reference's (< 1: attenuated)."""
        return self.peak.amplitude / self.reference.amplitude


def sweep_effect(curve, reference, within: tuple[float, float] | None = None) -> SweepEffect:
    """The shift and ratio of the peak of ``curve`` against that of ``reference``, each a (speed in rpm, amplitude)
    pair (``OrderTrack.curve(order)``, or a steady sweep's table), both peaks inside ``within``."""
    return SweepEffect(peak(*curve, within=within), peak(*reference, within=within))


def _monotone(speed: np.ndarray, amplitude: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(speed, amplitude) ordered by increasing speed; GearcheckError unless the speed is strictly monotonic (a
    run-up or a run-down, not both)."""
    if speed.size != amplitude.size:
        raise GearcheckError(f"amplitude: {amplitude.size} values for {speed.size} speeds")
    step = np.diff(speed)
    if np.all(step < 0):
        return speed[::-1], amplitude[::-1]
    if not np.all(step > 0):
        raise GearcheckError("speed_rpm: must rise (a run-up) or fall (a run-down) strictly from block to block")
    return speed, amplitude
