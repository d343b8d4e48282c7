"""Static transmission error of every mesh, unloaded and loaded, from its tooth pairs and their tip relief.

Over one mesh cycle, with the pairs of :class:`gearcheck.train.tooth_pairs.ToothPairs` on thin slices
across the face (one for spur gears):

* the unloaded static transmission error is the smallest gap (the pair that touches first);
* the loaded static transmission error is the mesh approach delta under the mesh's static load F,
  sum_j k_j max(0, delta - e_j) = F (Harris 1958), pairs in a relief zone taking less of the load;
* the loaded mesh stiffness is the sum of the stiffnesses of the pairs in contact.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gearcheck.train import helical_mesh
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.static import static_solution
from gearcheck.train.tooth_pairs import ToothPairs
from gearcheck.shared.errors import GearcheckError

HELICAL_SLICES = 400  # slices across a helical face: the slice model's TE error is O(1/n), 1 % of its ripple here


@dataclass(frozen=True)
class StaticTransmissionError:
    """One mesh over one cycle: positions ``xi`` (cycles), ``unloaded`` and ``loaded`` TE and ``stiffness``."""

    mesh: str
    load: float  # N, the static mesh force
    mean_stiffness: float  # N/m
    xi: np.ndarray
    unloaded: np.ndarray  # m
    loaded: np.ndarray  # m
    stiffness: np.ndarray  # N/m

    @property
    def mean_deflection(self) -> float:
        """F / k_mean: the relief that cancels the load's mean deflection (a classical design value)."""
        return self.load / self.mean_stiffness

    def to_dict(self) -> dict:
        return {"mesh": self.mesh, "load_n": self.load, "mean_stiffness_n_per_m": self.mean_stiffness,
                "mean_deflection_m": self.mean_deflection, "loaded_peak_to_peak_m": float(np.ptp(self.loaded)),
                "unloaded_peak_to_peak_m": float(np.ptp(self.unloaded)), "xi": self.xi.tolist(),
                "unloaded_m": self.unloaded.tolist(), "loaded_m": self.loaded.tolist(),
                "stiffness_n_per_m": self.stiffness.tolist()}


def mesh_static_transmission_error(mesh, load: float, mean_stiffness: float, points: int = 401,
                                   slices: int | None = None) -> StaticTransmissionError:
    """The unloaded and loaded static TE of ``mesh`` under ``load`` (N) over one mesh cycle; ``slices`` across a
    helical face (default ``HELICAL_SLICES``)."""
    xi = np.linspace(0.0, 1.0, points)
    pairs = ToothPairs(mesh, mean_stiffness, slices or HELICAL_SLICES)
    contact = helical_mesh.loaded_transmission_error(load, *pairs(xi))
    return StaticTransmissionError(mesh.id, float(load), float(mean_stiffness), xi, contact.unloaded,
                                   contact.approach, contact.stiffness)


def static_loads(spec) -> list[tuple]:
    """(mesh, static load N, mean stiffness N/m) of every mesh (mean mesh stiffness load sharing)."""
    model = build_model(spec)
    static = static_solution(model)
    return [(mesh, abs(float(f)), float(k))
            for mesh, f, k in zip(spec.meshes, static.mesh_force, model.excitation.mean_stiffness)]


def static_transmission_error(spec, points: int = 401, slices: int | None = None) -> list[StaticTransmissionError]:
    """Every mesh's static TE under the train's static load."""
    return [mesh_static_transmission_error(mesh, load, k, points, slices) for mesh, load, k in static_loads(spec)]


def relieved(mesh, amount: float):
    """``mesh`` with every tip relief it has (a gear with a relief length) set to ``amount`` (m)."""
    def gear(g):
        return replace(g, relief_amount=amount) if g.relief_length > 0 else g

    return replace(mesh, central_gear=gear(mesh.central_gear), planet_gear=gear(mesh.planet_gear))


def relief_sweep(spec, amounts, points: int = 401, slices: int | None = None) -> dict:
    """Loaded static TE peak-to-peak of the first planet's meshes whose gears carry a tip relief, with the
    relief amount set to each of ``amounts`` (m; the lengths and shapes as the train gives them)."""
    # one planet's meshes: every planet's mesh with a central gear has the same curve over its own cycle
    meshes = [(m, load, k) for m, load, k in static_loads(spec) if m.planet_index == 0
              and (m.central_gear.relief_length > 0 or m.planet_gear.relief_length > 0)]
    if not meshes:
        raise GearcheckError(f"{spec.path}: no gear has a tip_relief to sweep (give one a tip_relief with its "
                             "length_mm)")
    out = {"amounts_m": [float(a) for a in amounts], "meshes": {}}
    for mesh, load, k in meshes:
        ptp = [float(np.ptp(mesh_static_transmission_error(relieved(mesh, a), load, k, points, slices).loaded))
               for a in amounts]
        out["meshes"][mesh.id] = {"loaded_peak_to_peak_m": ptp, "mean_deflection_m": load / k,
                                  "best_amount_m": float(amounts[int(np.argmin(ptp))])}
    return out
