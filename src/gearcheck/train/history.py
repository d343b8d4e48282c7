"""Operating histories: input speed, input torque and output load as functions of time, given as data.

A train file's ``[operating.history]`` (or ``--speed-profile``, ``--torque-profile``, ``--load-profile``) gives
each as points (time s, value), a two-column table file (CSV or Parquet, :mod:`gearcheck.train.history_file`) or,
for the torques, an expression of t (:mod:`gearcheck.train.expression`).  Points are joined by straight lines and
the last value is held.  Either the speed is prescribed (through the input shaft, whose reference end turns at
it) or the input torque is, and then the speed follows from the rigid train's equation of motion.

Both solvers read the same **nominal clock** (:class:`Clock`): every nominal speed is lambda(t) times its value at
the reference operating point (the kinematics are linear in the input speed), and every nominal angle is the
reference speed times Lambda(t) = int_0^t lambda, so the mesh cycles, the transmission error and the ripple of an
order follow the integrated angle.  At constant speed lambda = 1 and Lambda(t) = t exactly: the constant-speed
runs are the limit, to the bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.shared.errors import GearcheckError
from gearcheck.train.expression import Expression
from gearcheck.train.history_file import read_history_table
from gearcheck.train.schema import HISTORY_START, LIMITS
from gearcheck.shared.units import MAX_RPM

CLOCK_STEPS = 4096  # RK4 steps of the rigid train's speed over a torque history (Hermite-interpolated between)
MAX_POINTS = 1_000_000  # a history's points: a minute sampled at 16 kHz


@dataclass(frozen=True)
class Series:
    """One quantity of time: points joined by straight lines (the last value held), or an expression of t."""

    label: str  # where it was given: the train file and field, or the command-line option
    times: tuple[float, ...] | None = None
    values: tuple[float, ...] | None = None
    expression: str | None = None

    def __call__(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        if self.expression is not None:
            return Expression(self.expression, self.label)(t)
        return np.interp(t, self.times, self.values)

    @property
    def corners(self) -> np.ndarray:
        """The times where its slope jumps (its points)."""
        return np.asarray(self.times if self.times is not None else (), dtype=float)

    @property
    def end(self) -> float | None:
        """Its last point's time (None for an expression)."""
        return None if self.times is None else self.times[-1]

    @classmethod
    def of_points(cls, points, label: str) -> "Series":
        """From (time, value) pairs: times from 0 on, strictly increasing, values finite."""
        data = np.asarray(points, dtype=float)
        if data.ndim != 2 or data.shape[1] != 2 or not 1 <= data.shape[0] <= MAX_POINTS:
            raise GearcheckError(f"{label}: needs 1 to {MAX_POINTS} (time s, value) pairs")
        if not np.all(np.isfinite(data)):
            raise GearcheckError(f"{label}: every time and value must be finite")
        if data[0, 0] != 0.0 or np.any(np.diff(data[:, 0]) <= 0):
            raise GearcheckError(f"{label}: times must start at 0 s and increase strictly, got "
                                 f"{', '.join(f'{x:g}' for x in data[:4, 0])}{', ...' if len(data) > 4 else ''}")
        if data.shape[0] == 1:
            data = np.vstack([data, [1.0, data[0, 1]]])
        return cls(label, tuple(map(float, data[:, 0])), tuple(map(float, data[:, 1])))

    @classmethod
    def of_expression(cls, text: str, label: str) -> "Series":
        Expression(text, label)(np.zeros(1))  # its grammar, and a finite value at the start
        return cls(label, expression=text)


@dataclass(frozen=True)
class History:
    """What drives the train in time: a prescribed input ``speed`` (rad/s) or input ``torque`` (N·m), optionally
    the output ``load`` (N·m, opposing the output's rotation), from ``start`` ("steady": the steady state at the
    initial speed; "rest": everything at rest, undeformed).  ``until``: the end of a history given by expressions
    (runs may not go past a torque history's end, where the speed would no longer be known)."""

    speed: Series | None = None
    torque: Series | None = None
    load: Series | None = None
    start: str = "steady"
    until: float | None = None

    @property
    def driven_by(self) -> str:
        return "speed" if self.speed is not None else "torque"

    @property
    def corners(self) -> np.ndarray:
        """The times at which a given torque's slope jumps (their points)."""
        return np.concatenate([s.corners for s in (self.torque, self.load) if s is not None] + [np.zeros(0)])

    @property
    def end(self) -> float | None:
        """The history's last given time (None where everything given is held or analytic)."""
        ends = [s.end for s in (self.speed, self.torque, self.load) if s is not None and s.end is not None]
        return self.until if self.until is not None else (max(ends) if ends else None)

    def words(self) -> str:
        """The history in one sentence (run information, reports)."""
        given = [f"{name} from {s.label}" for name, s in (("input speed", self.speed), ("input torque", self.torque),
                                                          ("output load", self.load)) if s is not None]
        return f"{' and '.join(given)}, starting {'from rest' if self.start == 'rest' else 'in steady state'}"


class Clock:
    """The nominal clock: lambda(t), the nominal speeds over their reference values, piecewise cubic in time
    (``coef[k]`` its Taylor coefficients about ``knots[k]``; held constant past the last knot), its rate and its
    integral Lambda(t), and the times at which Lambda reaches given values (lambda >= 0: Lambda never decreases)."""

    def __init__(self, knots, coef, corners=()):
        self.knots = np.ascontiguousarray(knots, dtype=float)
        coef = np.asarray(coef, dtype=float)
        end = coef[-1] @ (self.knots[-1] - self.knots[-2]) ** np.arange(4)
        self.coef = np.ascontiguousarray(np.vstack([coef, [end, 0.0, 0.0, 0.0]]))  # held past the last knot
        if np.any(self.coef[:, 0] < -1e-12) or end < -1e-12:
            raise GearcheckError("the nominal speed may not turn backwards (a history's speed must stay >= 0)")
        h = np.diff(self.knots)
        steps = np.einsum("kj,kj->k", coef, h[:, None] ** np.arange(1, 5) / np.arange(1, 5))
        self.integral = np.concatenate([[0.0], np.cumsum(steps)])  # Lambda at each knot
        self.corners = np.asarray(corners, dtype=float)

    @classmethod
    def piecewise_linear(cls, times, values) -> "Clock":
        t, y = np.asarray(times, dtype=float), np.asarray(values, dtype=float)
        coef = np.zeros((t.size - 1, 4))
        coef[:, 0], coef[:, 1] = y[:-1], np.diff(y) / np.diff(t)
        return cls(t, coef, t[1:-1] if t.size > 2 else ())

    @classmethod
    def hermite(cls, times, values, slopes) -> "Clock":
        """The cubic through (t_k, y_k) with slopes y'_k at both ends of every interval (C1)."""
        t, y, d = (np.asarray(x, dtype=float) for x in (times, values, slopes))
        h = np.diff(t)
        dy = np.diff(y) / h
        coef = np.stack([y[:-1], d[:-1], (3 * dy - 2 * d[:-1] - d[1:]) / h, (d[:-1] + d[1:] - 2 * dy) / h**2], 1)
        return cls(t, coef)

    def _at(self, t):
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, self.knots.size - 1)
        return k, t - self.knots[k]

    def scale(self, t) -> np.ndarray:
        """lambda(t)."""
        k, s = self._at(t)
        c = self.coef[k]
        return c[..., 0] + s * (c[..., 1] + s * (c[..., 2] + s * c[..., 3]))

    def rate(self, t) -> np.ndarray:
        """d lambda/dt."""
        k, s = self._at(t)
        c = self.coef[k]
        return c[..., 1] + s * (2 * c[..., 2] + s * 3 * c[..., 3])

    def time(self, t) -> np.ndarray:
        """Lambda(t) = int_0^t lambda: the nominal angle of a member over its reference speed."""
        k, s = self._at(t)
        c = self.coef[k]
        return self.integral[k] + s * (c[..., 0] + s * (c[..., 1] / 2 + s * (c[..., 2] / 3 + s * c[..., 3] / 4)))

    def times_at(self, values, t0: float, t1: float) -> np.ndarray:
        """The first times in [t0, t1] at which Lambda reaches each of ``values`` (bisection to round-off: Lambda
        is monotone)."""
        lo = np.full(np.shape(values), float(t0))
        hi = np.full(np.shape(values), float(t1))
        for _ in range(64):
            mid = 0.5 * (lo + hi)
            below = self.time(mid) < values
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        return hi

    def top(self, t_end: float) -> float:
        """The largest lambda over [0, t_end] (sampled at the knots, the end and 64 points between knots)."""
        t = np.union1d(self.knots[self.knots <= t_end], np.linspace(0.0, t_end, 64 * self.knots.size))
        return float(np.max(self.scale(t)))


def speed_clock(history: History, reference: float) -> Clock:
    """The clock of a prescribed input speed (rpm) over the ``reference`` input speed (rad/s)."""
    s, per_rpm = history.speed, 2.0 * np.pi / 60.0
    if s.expression is not None:  # sampled at 8192 intervals: straight lines between
        t = np.linspace(0.0, history.end, 8193)
        return Clock.piecewise_linear(t, s(t) * per_rpm / reference)
    return Clock.piecewise_linear(s.times, np.asarray(s.values) * per_rpm / reference)


def torque_clock(power, corners, inertia: float, drag: float, lambda0: float, end: float) -> Clock:
    """The clock of a torque-driven train, its rigid motion: inertia lambda' = power(t) + drag lambda, ``inertia``
    the rigid train's kinetic energy over lambda^2/2, ``power(t)`` the torques' power at the reference speeds,
    ``drag`` the reference drag power; integrated by RK4 over [0, end] in :data:`CLOCK_STEPS` steps (the torques'
    ``corners`` among the knots) and interpolated by Hermite cubics with the equation's own slopes."""
    corners = np.asarray(corners, dtype=float)
    corners = corners[(corners > 0) & (corners < end)]
    knots = np.union1d(np.linspace(0.0, end, CLOCK_STEPS + 1), corners)

    def rate(t, lam):
        return (power(t) + drag * lam) / inertia

    lam = np.empty(knots.size)
    lam[0] = lambda0
    for k, (a, b) in enumerate(zip(knots[:-1], knots[1:])):
        h, y = b - a, lam[k]
        k1 = rate(a, y)
        k2 = rate(a + h / 2, y + h / 2 * k1)
        k3 = rate(a + h / 2, y + h / 2 * k2)
        k4 = rate(b, y + h * k3)
        lam[k + 1] = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    backwards = np.flatnonzero(lam < -1e-9 * max(1.0, float(np.max(np.abs(lam)))))
    if backwards.size:
        raise GearcheckError(f"under its torque history the rigid train would turn backwards from t = "
                             f"{knots[backwards[0]]:.4g} s: the load outweighs the input torque (ramp the load in "
                             "with the torque: a load history)")
    clock = Clock.hermite(knots, lam, rate(knots, lam))
    clock.corners = corners
    return clock


def check_duration(history: History | None, duration: float, what: str) -> None:
    """A run of ``duration`` s may not outlast a torque history (where the speed would be unknown)."""
    if history is None or history.driven_by == "speed" or history.end is None:
        return
    if duration > history.end * (1 + 1e-12):
        raise GearcheckError(f"{what}: the run lasts {duration:g} s but the torque history ends at "
                             f"{history.end:g} s (give points up to the run's end, or until_s)")


def parse_history(raw: dict, source: str, locate, fail) -> History:
    """The :class:`History` of a schema-checked ``operating.history`` table; ``locate(name)`` the path of a file it
    names, ``fail(field, message)`` the error for a field."""
    def series(name: str, quantity: str) -> Series | None:
        given = [key for key in (f"{name}_points", f"{name}_file", f"{name}_expression") if raw[key] is not None]
        if len(given) > 1:
            raise fail(f"operating.history.{given[1]}", f"give one of {', '.join(given)}")
        if not given:
            return None
        key = given[0]
        label = f"--{name}-profile" if source == "command line" else f"{source}: operating.history.{key}"
        try:
            if key.endswith("_points"):
                series = Series.of_points(raw[key], label)
            elif key.endswith("_expression"):
                if raw["until_s"] is None:
                    raise GearcheckError("an expression needs operating.history.until_s, where the history ends")
                series = Series.of_expression(raw[key], label)
            else:
                table = read_history_table(locate(raw[key]), quantity, f"{label} = {raw[key]!r}")
                series = Series.of_points(table, f"{label} = {raw[key]!r}")
            _check_bounds(series, quantity, raw["until_s"])
            return series
        except GearcheckError as exc:  # said of the field: the label's place, then the file's name if any
            raise fail(f"operating.history.{key}", str(exc).removeprefix(label).lstrip(" =:")) from None

    speed, torque, load = series("speed", "speed"), series("torque", "torque"), series("load", "torque")
    if (speed is None) == (torque is None):
        raise fail("operating.history", "give the input speed (speed_points, speed_file or speed_expression) or the "
                                        "input torque (torque_...), one of the two")
    if speed is not None and np.any(speed(np.union1d(speed.corners, [0.0])) < 0):
        raise fail("operating.history.speed", "the input speed must stay >= 0 rpm (turn the train the other way "
                                              "round in the train file instead)")
    initial = None if speed is None else float(speed(0.0))
    if raw["start"] is not None and raw["start"] not in HISTORY_START:
        raise fail("operating.history.start", f"{raw['start']!r}: one of {', '.join(HISTORY_START)}")
    start = raw["start"] or ("rest" if torque is not None or initial == 0.0 else "steady")
    if start == "rest" and initial:
        raise fail("operating.history.start", f"rest, but the speed history starts at {initial:g} rpm")
    if start == "steady" and initial == 0.0:
        raise fail("operating.history.start", "steady, but the speed history starts at 0 rpm: start = \"rest\"")
    return History(speed, torque, load, start, raw["until_s"])


def _check_bounds(series: Series, quantity: str, until: float | None) -> None:
    """A history's times within the train file's bound on a time, its values within that on a speed (rpm) or a
    torque (N·m) (:data:`gearcheck.train.schema.LIMITS` says why); an expression's sampled over its span."""
    limit, unit = (MAX_RPM, "rpm") if quantity == "speed" else (LIMITS["torque"][0], "N·m")
    if series.times is not None:
        times, values = np.asarray(series.times), np.asarray(series.values)
    else:
        times = np.linspace(0.0, until, 1001)
        values = series(times)
    if times[-1] > LIMITS["time"][0]:
        raise GearcheckError(f"{series.label}: times must be <= {LIMITS['time'][0]:g} s, got {times[-1]:g}")
    if np.max(np.abs(values)) > limit:
        raise GearcheckError(f"{series.label}: values must be within ±{limit:g} {unit}, got "
                             f"{values[np.argmax(np.abs(values))]:g}")
