"""Tolerances of the cross-check, per quantity kind and metric, overridable per quantity.

Keys are ``KIND.METRIC`` (``mesh_force.nrmse``) or ``QUANTITY.METRIC``
(``stage1.ring.ay.world.nrmse``); the most specific key wins.  Defaults and why:

* ``frequency.rel_error`` 1e-6: both models linearise the same physics exactly, so
  natural frequencies must agree to round-off and finite-difference error;
* ``mesh_force.nrmse`` and ``dte.nrmse`` 0.01: the two integrators at their default steps
  (issue 3's acceptance level);
* ``acceleration.nrmse`` and ``angular_acceleration.nrmse`` 0.05: accelerations weight the
  high-frequency content where the two time discretisations differ most;
* ``bearing_force.nrmse`` 0.02.

Overrides come from a ``[tolerances]`` table in a TOML file (``--tolerances``).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

from lumped.errors import GearcheckError

DEFAULTS = {
    "frequency.rel_error": 1e-6,
    "mesh_force.nrmse": 0.01,
    "dte.nrmse": 0.01,
    "acceleration.nrmse": 0.05,
    "angular_acceleration.nrmse": 0.05,
    "bearing_force.nrmse": 0.02,
}


class Tolerances:
    def __init__(self, overrides: dict[str, float] | None = None):
        self.values = dict(DEFAULTS)
        self.values.update(overrides or {})

    def lookup(self, quantity: str, kind: str, metric: str) -> float | None:
        return self.values.get(f"{quantity}.{metric}", self.values.get(f"{kind}.{metric}"))

    @classmethod
    def from_file(cls, path: str | Path) -> "Tolerances":
        try:
            data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise GearcheckError(f"{path}: cannot read tolerances: {exc}") from None
        table = data.get("tolerances")
        if not isinstance(table, dict) or set(data) != {"tolerances"}:
            raise GearcheckError(f"{path}: expected a single [tolerances] table")
        overrides = {}
        for key, value in _flatten(table).items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or value <= 0:
                raise GearcheckError(f"{path}: tolerances.{key}: must be a positive number, got {value!r}")
            if key.count(".") < 1:
                raise GearcheckError(f"{path}: tolerances.{key}: expected KIND.METRIC or QUANTITY.METRIC")
            overrides[key] = float(value)
        return cls(overrides)


def _flatten(table: dict, prefix: str = "") -> dict:
    """TOML dotted keys (``mesh_force.nrmse = 0.02``) arrive nested; join them back."""
    flat = {}
    for key, value in table.items():
        name = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict):
            flat.update(_flatten(value, name))
        else:
            flat[name] = value
    return flat
