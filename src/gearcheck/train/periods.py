"""The period of a train's drive: the shortest time after which every time-varying part of it repeats.

Every time-varying part of the drive (mesh stiffness variation and transmission error at the mesh frequencies and
their harmonics, eccentricities at the members' rotation frequencies in the carrier frame, torque ripple, a torque
profile repeated, the parts' periodic contacts and their connections turning in the carrier frames) has a
frequency; when all of them are whole multiples of one 1/T (within ``PERIOD_TOLERANCE`` cycles over T) and T is at
most ``MAX_MESH_PERIODS`` periods of the slowest time-varying mesh, the steady response is T-periodic.  The period
is the train's, not a solver's: both sides shoot for their periodic steady state over it
(:mod:`gearcheck.lumped.periodic_steady_state`, :mod:`gearcheck.mbd_models.periodic_state`).
"""

from __future__ import annotations

import numpy as np

from gearcheck.shared.errors import SolverError
from gearcheck.train.excitation import Excitation

PERIOD_TOLERANCE = 1e-9  # cycles over the common period by which a frequency may miss a whole number
MAX_MESH_PERIODS = 64  # the longest common period sought, in periods of the slowest time-varying mesh


def drive_frequencies(excitation: Excitation) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(frequencies of the time-varying drive in Hz, those of the time-varying meshes, what has no period): the
    excitation's periodic terms (:meth:`~gearcheck.train.excitation.Excitation.periodic_terms`), the parts'
    periodic contacts (:meth:`~gearcheck.train.parts.Part.frequencies`) and their turning connections
    (:meth:`~gearcheck.train.parts.Part.turning_frequencies`) at the nominal speeds."""
    drive, meshes, aperiodic = excitation.periodic_terms()
    spec, speeds = excitation.spec, excitation.kin.speeds
    parts = [f for part in spec.parts for f in (*part.frequencies(speeds).values(),
                                                *part.turning_frequencies(spec, speeds))]
    f = np.concatenate([drive, np.array(parts, dtype=float)])
    return f[f > 0], meshes[meshes > 0], aperiodic


def common_period(excitation: Excitation, max_mesh_periods: int = MAX_MESH_PERIODS) -> float:
    """The shortest T over which every frequency of :func:`drive_frequencies` completes whole cycles (within
    ``PERIOD_TOLERANCE`` cycles), at most ``max_mesh_periods`` periods of the slowest time-varying mesh (or of the
    slowest frequency when no mesh varies); :class:`SolverError` when there is none."""
    f, meshes, aperiodic = drive_frequencies(excitation)
    name = excitation.spec.name
    if aperiodic:
        raise SolverError(f"{name}: no periodic steady state to shoot for: {' and '.join(aperiodic)} "
                          "not periodic; time-march with a settle time (RunSettings.settle) instead")
    if f.size == 0:
        raise SolverError(f"{name}: nothing in the drive varies with time: the steady state is the static "
                          "solution (gearcheck.lumped.static.static_solution)")
    base = float(meshes.min() if meshes.size else f.min())
    for p in range(1, max_mesh_periods + 1):
        cycles = f * (p / base)
        if whole_cycles(cycles) and np.all(np.round(cycles) >= 1):
            return p / base
    listed = ", ".join(f"{x:.10g}" for x in np.unique(np.round(f, 9)))
    raise SolverError(f"{name}: the drive's frequencies {listed} Hz have no common period within "
                      f"{max_mesh_periods} periods of the slowest time-varying mesh ({base:.10g} Hz; tolerance "
                      f"{PERIOD_TOLERANCE:g} cycles): no periodic steady state to shoot for (incommensurate "
                      "excitation); time-march with a settle time (RunSettings.settle) instead")


def whole_cycles(cycles) -> bool:
    """Whether every entry of ``cycles`` is a whole number within ``PERIOD_TOLERANCE`` (relative above one)."""
    cycles = np.asarray(cycles, dtype=float)
    return bool(np.all(np.abs(cycles - np.round(cycles)) <= PERIOD_TOLERANCE * np.maximum(1.0, cycles)))
