"""The physical quantities both solvers are compared on, extracted from a TimeResult.

Names: ``MEMBER.ax.world`` / ``MEMBER.ay.world`` (acceleration of the member's centre
along the fixed axes, as a housing accelerometer sees it), ``MEMBER.ax.carrier`` /
``MEMBER.ay.carrier`` (the same vector along the axes turning with the stage's carrier),
``MEMBER.alpha`` (angular acceleration), ``MESH.force`` and ``MESH.dte`` (mesh force and
dynamic transmission error along the line of action, positive in compression),
``BEARING.force``.  Central members only: planets are seen through their meshes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Quantity:
    name: str
    kind: str  # acceleration | angular_acceleration | mesh_force | dte | bearing_force
    unit: str
    description: str


def extract(spec, result) -> dict[str, tuple[Quantity, np.ndarray]]:
    """Every comparable quantity of ``result`` as (Quantity, series on result.t)."""
    out: dict[str, tuple[Quantity, np.ndarray]] = {}
    for mid, member in spec.members.items():
        if member.is_planet:
            continue
        for frame in ("world", "carrier"):
            acc = result.acceleration(mid, frame)
            for axis in ("x", "y"):
                q = Quantity(f"{mid}.a{axis}.{frame}", "acceleration", "m/s^2",
                             f"{mid} acceleration along {axis} ({frame} frame)")
                out[q.name] = (q, acc[f"a{axis}"].to_numpy())
        q = Quantity(f"{mid}.alpha", "angular_acceleration", "rad/s^2", f"{mid} angular acceleration")
        out[q.name] = (q, result.acceleration(mid, "carrier")["alpha"].to_numpy())
    for j, mesh in enumerate(result.mesh_ids):
        q = Quantity(f"{mesh}.force", "mesh_force", "N", f"{mesh} mesh force")
        out[q.name] = (q, result.mesh_force[:, j])
        q = Quantity(f"{mesh}.dte", "dte", "m", f"{mesh} dynamic transmission error")
        out[q.name] = (q, result.mesh_deflection[:, j])
    for j, name in enumerate(result.bearing_names):
        q = Quantity(f"{name}.force", "bearing_force", "N", f"{name} force")
        out[q.name] = (q, result.bearing_force[:, j])
    return out
