"""Unit conversions, in one place: files and the command line speak rpm, mm, µm and degrees;
everything inside gearcheck is SI (m, kg, s, N, rad).

``SUFFIXES`` maps a train-file key suffix to its unit label and the factor that takes the value
to SI; the schema converts with it once, at loading.  :func:`checked_rpm` is the one check of a
speed given in rpm outside a train file.
"""

from __future__ import annotations

import math
from numbers import Real

from gearcheck.shared.errors import GearcheckError

RAD_S_PER_RPM = 2.0 * math.pi / 60.0
MAX_RPM = 1e6  # the fastest input speed accepted (gearcheck.train.schema.LIMITS says why)

SUFFIXES = {
    "_mm": ("mm", 1e-3),
    "_um": ("µm", 1e-6),
    "_urad": ("µrad", 1e-6),
    "_deg": ("deg", math.pi / 180.0),
    "_rpm": ("rpm", RAD_S_PER_RPM),
}


def rpm_to_rad_s(rpm):
    """Angular speed in rad/s of ``rpm`` revolutions per minute (scalars or arrays)."""
    return rpm * RAD_S_PER_RPM


def rad_s_to_rpm(omega: float) -> float:
    """Revolutions per minute of an angular speed ``omega`` in rad/s, to 12 significant digits: a
    speed means nothing beyond them, and an rpm value taken to rad/s and back then reads as typed
    (1823 rpm, not 1822.9999999999998)."""
    return float(f"{omega * 60.0 / (2.0 * math.pi):.12g}")


def checked_rpm(value, what: str = "speed", zero: bool = False) -> float:
    """``value`` as a float if it is a speed a train can turn at: a finite number of rpm, positive (or zero
    with ``zero``), at most :data:`MAX_RPM`; else a :class:`GearcheckError` that starts with ``what``."""
    number = isinstance(value, Real) and not isinstance(value, bool)
    shown = f"{value:g}" if number else repr(value)
    if not number or not math.isfinite(value) or value < 0 or (value == 0 and not zero):
        raise GearcheckError(f"{what} must be a {'number of rpm >= 0' if zero else 'positive number of rpm'}, "
                             f"got {shown}")
    if value > MAX_RPM:
        raise GearcheckError(f"{what} must be <= {MAX_RPM:g} rpm, got {shown}")
    return float(value)
