"""The reference model of a train as a model given as matrices: what a user's own model is compared with,
in the very form gearcheck reads a user's model (:mod:`gearcheck.lumped.linear_model`), and written as a
``.mat`` or ``.npz`` file a MATLAB user can open to see every convention (coordinates, signs, rows).

Only the linear reference exports: a train with backlash, tip relief or a coupling across turning frames
is refused (their forces are not a matrix times the state).  The forcing is exact in Python
(:class:`DriveForcing`); a file holds it as ``F_samples`` over the drive's period (transmission error,
ripple, eccentricities, a repeated torque profile: :func:`gearcheck.train.periods.common_period`); a forcing
that never repeats (a load ramp, an aperiodic torque) cannot be written.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.io

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.linear_model import LinearModel, Mesh, Periodic
from gearcheck.shared.errors import GearcheckError, SolverError
from gearcheck.shared.outputs import write_file
from gearcheck.train.periods import common_period, drive_frequencies

SAMPLES = 1 << 15  # samples of a mesh's stiffness over its cycle
SUB_SAMPLES = 16  # points a sample averages
FORCING_SAMPLES = 128  # samples of the forcing per cycle of its fastest term: linear interpolation to ~1e-4
MAX_FORCING_SAMPLES = 1 << 18  # samples of the forcing over the drive's period, at most (n of them: ~40 MB at n=20)
PERIOD_MESH_PERIODS = 1024  # the longest drive period a file holds, in periods of the slowest time-varying mesh


@dataclass(frozen=True)
class DriveForcing:
    """F(t) of the reference, exact (``function``), with the times over the drive's ``period`` a file samples it
    at (``times``), or ``aperiodic``: why it has none."""

    function: Callable
    period: float | None = None
    times: np.ndarray | None = None
    aperiodic: str = ""

    def __call__(self, t):
        return self.function(t)


def reference_linear_model(spec, samples: int = SAMPLES) -> LinearModel:
    """gearcheck's lumped model of ``spec`` as a :class:`LinearModel` over the train's coordinates: each mesh with
    its stiffness held over ``samples`` cells of its cycle and its transmission error sampled over the drive's
    period; the torques' variation (ripple, a profile, a ramp) as an exact :class:`DriveForcing`."""
    model = build_model(spec)
    exc = model.excitation
    why = [("backlash", bool(np.any(exc.backlash > 0))), ("tip relief", bool(exc.relieved.size)),
           ("a coupling across turning frames", bool(model.turning))]
    refused = [name for name, present in why if present]
    if refused:
        raise GearcheckError(f"{spec.name}: the reference model is not linear ({', '.join(refused)}): it cannot be "
                             "given as matrices")
    clock = _drive_clock(exc)
    errors = _transmission_errors(exc, clock, spec.name) if exc.has_transmission_error else None
    meshes = []
    for j, mesh in enumerate(spec.meshes):
        period = 1.0 / exc.frequency[j]
        # held samples: each the mean over its own cell (a jump moves to a cell edge, at most period / samples),
        # shifted by the sub-sampling's residue so that their mean is the exact mean stiffness the modes use
        cells = (np.arange(samples)[:, None] + (np.arange(SUB_SAMPLES) + 0.5) / SUB_SAMPLES) * period / samples
        k = exc.stiffness(cells)[..., j].mean(axis=1)
        k += exc.mean_stiffness[j] - k.mean()
        meshes.append(Mesh(mesh.id, model.mesh_rows[j], Periodic(period, samples=k, interpolation="hold"),
                           float(model.mesh_damping[j]), None if errors is None else errors[j]))

    def forcing(t):
        t_in, t_out = exc.torques(t)
        return model.F_static + model.b_input * t_in + model.b_output * t_out

    constant = not (spec.operating.ramp > 0 or spec.operating.torque_varies)
    shaft = spec.operating.input_shaft_stiffness is not None  # the shaft spring carries the mean input torque
    F = forcing(0.0) if constant else (model.F_static + model.b_output * model.kin.output_torque
                                       + (0.0 if shaft else model.b_input * model.kin.input_torque))
    drive = None if constant else (DriveForcing(forcing, aperiodic=clock) if isinstance(clock, str)
                                   else DriveForcing(forcing, *clock))
    return LinearModel(f"{spec.name} reference", model.dofs.labels(), model.M, model.K_b, C=model.C_b, G=model.G,
                       K_omega=model.K_frame, F=F, forcing=drive, meshes=meshes, source=f"{spec.name} (reference)")


def _drive_clock(exc) -> tuple[float, np.ndarray] | str:
    """(the drive's period, the times over it at :data:`FORCING_SAMPLES` per cycle of its fastest term), or why
    it has none: no period (a ramp, incommensurate terms), or one too long to sample."""
    frequencies, _, aperiodic = drive_frequencies(exc)
    if aperiodic:
        return f"{' and '.join(aperiodic)} never repeats"
    try:
        period = common_period(exc, PERIOD_MESH_PERIODS)
    except SolverError:
        return (f"its terms at {', '.join(f'{f:.6g}' for f in np.unique(frequencies))} Hz have no common period "
                f"within {PERIOD_MESH_PERIODS} periods of its slowest time-varying mesh")
    fastest = float(frequencies.max())
    count = FORCING_SAMPLES * max(1, round(period * fastest))
    if count > MAX_FORCING_SAMPLES:
        return (f"it repeats only after {period:.6g} s, {count} samples at {FORCING_SAMPLES} "
                f"per cycle of its fastest term ({fastest:.6g} Hz), more than {MAX_FORCING_SAMPLES}")
    return period, np.arange(count) * period / count


def _transmission_errors(exc, clock, name: str) -> list[Periodic]:
    """Each mesh's static transmission error sampled over the drive's period (its harmonics of the mesh
    frequency and its gears' eccentricities repeat together only over that)."""
    if isinstance(clock, str):
        raise GearcheckError(f"{name}: its transmission error cannot be sampled over a period: {clock}")
    period, times = clock
    e, _ = exc.transmission_error(times)
    return [Periodic(period, samples=e[:, j]) for j in range(e.shape[1])]


def write_matrix_file(model: LinearModel, path) -> None:
    """Write ``model`` as ``path`` (.mat or .npz, the layout :mod:`gearcheck.lumped.matrix_file` reads)."""
    path = Path(path)
    matlab = path.suffix == ".mat"
    data = {"coordinates": np.array(model.coordinates, dtype=object if matlab else str), "M": model.M, "K": model.K,
            "name": model.name, "start": model.start, "reduction": model.reduction, "units": "SI"}
    for name in ("C", "G", "K_omega", "G_per_speed", "K_omega_per_speed2", "F"):
        if getattr(model, name) is not None:
            data[name] = getattr(model, name)
    if model.G_per_speed is not None or model.K_omega_per_speed2 is not None:
        data["speed_of"] = model.speed_of
    if model.physical is not None:
        labels = list(model.physical)
        data["physical_labels"] = np.array(labels, dtype=object if matlab else str)
        data["physical"] = np.array([[model.physical[label].get(c, 0.0) for c in model.coordinates]
                                     for label in labels])
    periods = set()
    if model.forcing is not None:
        period, F = _forcing_samples(model)
        periods.add(period)
        data.update(F=F.mean(axis=0), F_samples=F.T if matlab else F)
    errors = [m.error for m in model.meshes if m.error is not None]
    if errors:
        if len(errors) < len(model.meshes) or any(e.samples is None for e in errors):
            raise GearcheckError(f"{model.name}: a model file holds every mesh's transmission error as samples, or "
                                 "none")
        periods |= {e.period for e in errors}
        data["mesh_error"] = np.array([e.samples for e in errors])
    if periods:
        data["period"] = _one(periods, model.name, "period of the forcing and transmission errors")
    if model.meshes:
        data["mesh_ids"] = np.array([m.id for m in model.meshes], dtype=object if matlab else str)
        data["mesh_rows"] = model.mesh_rows
        data["mesh_stiffness"] = np.array([m.stiffness.samples for m in model.meshes])
        data["mesh_period"] = np.array([m.stiffness.period for m in model.meshes])
        data["mesh_damping"] = np.array([m.damping for m in model.meshes])
        data["mesh_interpolation"] = _one({m.stiffness.interpolation for m in model.meshes}, model.name,
                                          "interpolation of the mesh stiffness samples")
    buffer = io.BytesIO()
    if path.suffix == ".npz":
        np.savez(buffer, **data)
    elif matlab:
        scipy.io.savemat(buffer, data, do_compression=True)
    else:
        raise GearcheckError(f"{path}: a model file is .mat or .npz")
    write_file(path, buffer.getvalue())


def _one(values: set, name: str, what: str):
    """The one value of ``values``; a model file has one of each."""
    if len(values) > 1:
        raise GearcheckError(f"{name}: a model file has one {what}, not {len(values)} ({', '.join(map(str, values))})")
    return values.pop()


def _forcing_samples(model: LinearModel) -> tuple[float, np.ndarray]:
    """(period, the (N, n) samples of F over it) of a periodic forcing; refused for one that never repeats."""
    forcing = model.forcing
    if isinstance(forcing, Periodic):
        return forcing.period, forcing.over_period()
    if isinstance(forcing, DriveForcing) and forcing.period is not None:
        return forcing.period, np.array([forcing(t) for t in forcing.times])
    why = forcing.aperiodic if isinstance(forcing, DriveForcing) else "it is a function of time without a period"
    raise GearcheckError(f"{model.name}: a model file holds a constant or periodic forcing only: {why}")
