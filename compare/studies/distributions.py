"""Stated parameter distributions for Monte Carlo sweeps, and their deterministic draws.

A distribution is written as the user states it, in the train file's own units of the field it varies:

* ``normal(mean, sd)`` -- Gaussian, sd > 0;
* ``uniform(low, high)`` -- flat on [low, high), low < high;
* ``lognormal(median, factor)`` -- ln X ~ N(ln median, ln factor): ``factor`` > 1 is the geometric standard
  deviation (about 68 % of the draws lie within median / factor .. median x factor), median > 0.

Draws are reproducible and prefix-stable: sample ``i`` of a sweep with seed ``s`` comes from its own
``numpy.random.Generator(PCG64(SeedSequence(s, spawn_key=(i,))))``, one draw per field in the order the fields
are given, so a sweep of 100 samples starts with the 50 of a sweep of 50 (and reuses their cached points).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from gearcheck.shared.errors import GearcheckError

KINDS = {"normal": ("mean", "sd"), "uniform": ("low", "high"), "lognormal": ("median", "factor")}
_NUMBER = r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*"
_PATTERN = re.compile(rf"\s*([a-z]+)\s*\({_NUMBER},{_NUMBER}\)\s*")


@dataclass(frozen=True)
class Distribution:
    kind: str  # normal | uniform | lognormal
    a: float  # mean, low or median
    b: float  # sd, high or factor

    @classmethod
    def parse(cls, text: str, what: str = "distribution") -> "Distribution":
        """``normal(mean, sd)``, ``uniform(low, high)`` or ``lognormal(median, factor)``; ``what`` starts the
        message of a bad one (the argument and field that gave it: ``distributions=stages[0].sun.mass``)."""
        m = _PATTERN.fullmatch(str(text))
        if not m or m.group(1) not in KINDS:
            raise GearcheckError(f"{what} {text!r}: a distribution is normal(mean, sd), uniform(low, high) or "
                                 "lognormal(median, factor)")
        kind, a, b = m.group(1), float(m.group(2)), float(m.group(3))
        if not (math.isfinite(a) and math.isfinite(b)):
            raise GearcheckError(f"{what} {text!r}: its numbers must be finite")
        if kind == "normal" and not b > 0:
            raise GearcheckError(f"{what} {text!r}: needs sd > 0")
        if kind == "uniform" and not a < b:
            raise GearcheckError(f"{what} {text!r}: needs low < high")
        if kind == "lognormal" and not (a > 0 and b > 1):
            raise GearcheckError(f"{what} {text!r}: needs median > 0 and factor > 1 (the geometric standard "
                                 "deviation)")
        return cls(kind, a, b)

    def draw(self, rng: np.random.Generator) -> float:
        if self.kind == "normal":
            return float(rng.normal(self.a, self.b))
        if self.kind == "uniform":
            return float(rng.uniform(self.a, self.b))
        return float(self.a * math.exp(math.log(self.b) * rng.standard_normal()))

    def __str__(self) -> str:
        return f"{self.kind}({self.a!r}, {self.b!r})"

    def label(self) -> str:
        """For figures: 6 significant digits."""
        return f"{self.kind}({self.a:.6g}, {self.b:.6g})"


def sample_generator(seed: int, index: int) -> np.random.Generator:
    """The generator of sample ``index`` of a sweep seeded ``seed`` (PCG64, its own stream)."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(index,))))


def draw_samples(distributions: dict, samples: int, seed: int) -> list[dict[str, float]]:
    """``samples`` draws of every field of ``distributions`` (field path -> :class:`Distribution`), in order."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise GearcheckError(f"seed={seed!r}: needs an integer >= 0")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or not 1 <= samples <= 1_000_000:
        raise GearcheckError(f"samples={samples!r}: needs an integer from 1 to 1000000")
    out = []
    for i in range(samples):
        rng = sample_generator(int(seed), i)
        out.append({path: d.draw(rng) for path, d in distributions.items()})
    return out
