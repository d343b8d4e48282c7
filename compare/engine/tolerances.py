"""Tolerances of the cross-check, per quantity kind and metric, overridable per quantity.

Keys are ``KIND.METRIC`` (``mesh_force.nrmse``) or ``QUANTITY.METRIC``
(``stage1.ring.ay.world.nrmse``); the most specific key wins.  Defaults and why:

* ``frequency.rel_error`` 1e-6: both models linearise the same physics exactly, so
  natural frequencies must agree to round-off and finite-difference error;
* ``mesh_force.nrmse`` and ``dte.nrmse`` 0.01: the two integrators at their default steps;
* ``acceleration.nrmse`` and ``angular_acceleration.nrmse`` 0.05: accelerations weight the
  high-frequency content where the two time discretisations differ most;
* ``bearing_force.nrmse`` and ``pin_force.nrmse`` (an RV reducer's largest pin force per disc) 0.02;
* ``tilt.nrmse`` and ``mesh_moment.nrmse`` 0.01: a tilting member's tilts are angles and a mesh's tilting
  moment a spring's force, read like the mesh deflections and forces.

Overrides come from the train file's ``[tolerances]`` table and then from a ``[tolerances]``
table in a TOML file given with ``--tolerances`` (or a dict from Python; these win).
"""

from __future__ import annotations

from pathlib import Path

from gearcheck.train.files import read_toml
from gearcheck.train.spec import flat_tolerances
from gearcheck.shared.errors import GearcheckError, TrainFileError, did_you_mean

METRICS = ("nrmse", "rel_error")
DEFAULTS = {
    "frequency.rel_error": 1e-6,
    "mesh_force.nrmse": 0.01,
    "dte.nrmse": 0.01,
    "acceleration.nrmse": 0.05,
    "angular_acceleration.nrmse": 0.05,
    "bearing_force.nrmse": 0.02,
    "pin_force.nrmse": 0.02,
    "tilt.nrmse": 0.01,
    "mesh_moment.nrmse": 0.01,
}


class Tolerances:
    def __init__(self, overrides: dict[str, float] | None = None):
        self.values = dict(DEFAULTS)
        self.values.update(overrides or {})

    def lookup(self, quantity: str, kind: str, metric: str) -> float | None:
        return self.values.get(f"{quantity}.{metric}", self.values.get(f"{kind}.{metric}"))

    def check(self, quantities) -> None:
        """Refuse a key that names no kind and none of ``quantities`` (the cross-check's), or no metric."""
        kinds = {key.rsplit(".", 1)[0] for key in DEFAULTS}
        known = kinds | set(quantities)
        for key in self.values:
            name, _, metric = key.rpartition(".")
            if metric not in METRICS:
                raise GearcheckError(f"tolerance {key!r}: the metric must be one of {', '.join(METRICS)}")
            if name not in known:
                hint = did_you_mean(name, sorted(known)) or f" (kinds: {', '.join(sorted(kinds))})"
                raise GearcheckError(f"tolerance {key!r}: {name!r} is neither a kind nor a compared quantity{hint}")

    @classmethod
    def for_train(cls, spec, extra=None) -> "Tolerances":
        """Defaults, then the train file's [tolerances], then ``extra``: the path of a TOML file with a
        [tolerances] table, or a dict of flat keys."""
        overrides = dict(spec.tolerances)
        if isinstance(extra, dict):
            overrides.update(flat_tolerances(extra, lambda key, msg: GearcheckError(f"tolerances: {key}: {msg}")))
        elif extra is not None:
            overrides.update(read_tolerances(extra))
        return cls(overrides)


def read_tolerances(path: str | Path) -> dict[str, float]:
    data = read_toml(path, "tolerances file")
    if not isinstance(data.get("tolerances"), dict) or set(data) != {"tolerances"}:
        raise GearcheckError(f"{path}: expected a single [tolerances] table")
    return flat_tolerances(data["tolerances"], lambda key, msg: TrainFileError(str(path), f"tolerances.{key}", msg))
