"""The reference model of a train as a model given as matrices: what a user's own model is compared with,
in the very form gearcheck reads a user's model (:mod:`gearcheck.lumped.linear_model`), and written as a
``.mat`` or ``.npz`` file a MATLAB user can open to see every convention (coordinates, signs, rows).

Only the linear reference exports: a train with backlash, tip relief or a coupling across turning frames
is refused (their forces are not a matrix times the state).  The forcing is exact in Python (any
callable); a file holds it when it is constant (no transmission error, ripple or load ramp).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import scipy.io

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.linear_model import LinearModel, Mesh, Periodic
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.outputs import write_file

SAMPLES = 4096  # samples of a mesh's stiffness over its cycle
SUB_SAMPLES = 16  # points a sample averages


def reference_linear_model(spec, samples: int = SAMPLES) -> LinearModel:
    """gearcheck's lumped model of ``spec`` as a :class:`LinearModel` over the train's coordinates."""
    model = build_model(spec)
    exc = model.excitation
    why = [("backlash", bool(np.any(exc.backlash > 0))), ("tip relief", bool(exc.relieved.size)),
           ("a coupling across turning frames", bool(model.turning))]
    refused = [name for name, present in why if present]
    if refused:
        raise GearcheckError(f"{spec.name}: the reference model is not linear ({', '.join(refused)}): it cannot be "
                             "given as matrices")
    meshes = []
    for j, mesh in enumerate(spec.meshes):
        period = 1.0 / exc.frequency[j]
        # held samples: each the mean over its own cell (a jump moves to a cell edge, at most period / samples),
        # shifted by the sub-sampling's residue so that their mean is the exact mean stiffness the modes use
        cells = (np.arange(samples)[:, None] + (np.arange(SUB_SAMPLES) + 0.5) / SUB_SAMPLES) * period / samples
        k = exc.stiffness(cells)[..., j].mean(axis=1)
        k += exc.mean_stiffness[j] - k.mean()
        meshes.append(Mesh(mesh.id, model.mesh_rows[j], Periodic(period, samples=k, interpolation="hold"),
                           float(model.mesh_damping[j])))
    constant = not (exc.has_transmission_error or spec.operating.ramp > 0 or spec.operating.torque_varies)

    def forcing(t):
        t_in, t_out = exc.torques(t)
        e, de = exc.transmission_error(t)
        k = exc.stiffness(t)
        return (model.F_static + model.b_input * t_in + model.b_output * t_out
                + model.mesh_rows.T @ (k * e + model.mesh_damping * de))

    shaft = spec.operating.input_shaft_stiffness is not None  # the shaft spring carries the mean input torque
    F = forcing(0.0) if constant else (model.F_static + model.b_output * model.kin.output_torque
                                       + (0.0 if shaft else model.b_input * model.kin.input_torque))
    return LinearModel(f"{spec.name} reference", model.dofs.labels(), model.M, model.K_b, C=model.C_b, G=model.G,
                       K_omega=model.K_frame, F=F, forcing=None if constant else forcing, meshes=meshes,
                       source=f"{spec.name} (reference)")


def write_matrix_file(model: LinearModel, path) -> None:
    """Write ``model`` as ``path`` (.mat or .npz, the layout :mod:`gearcheck.lumped.matrix_file` reads)."""
    path = Path(path)
    if callable(model.forcing) and not isinstance(model.forcing, Periodic):
        raise GearcheckError(f"{model.name}: its forcing varies in time (transmission error, ripple or a load ramp); "
                             "a model file holds a constant or periodic forcing only")
    matlab = path.suffix == ".mat"
    data = {"coordinates": np.array(model.coordinates, dtype=object if matlab else str), "M": model.M, "K": model.K,
            "name": model.name, "start": model.start, "units": "SI"}
    for name in ("C", "G", "K_omega", "F"):
        if getattr(model, name) is not None:
            data[name] = getattr(model, name)
    if model.meshes:
        data["mesh_ids"] = np.array([m.id for m in model.meshes], dtype=object if matlab else str)
        data["mesh_rows"] = model.mesh_rows
        data["mesh_stiffness"] = np.array([m.stiffness.samples for m in model.meshes])
        data["mesh_period"] = np.array([m.stiffness.period for m in model.meshes])
        data["mesh_damping"] = np.array([m.damping for m in model.meshes])
    buffer = io.BytesIO()
    if path.suffix == ".npz":
        np.savez(buffer, **data)
    elif matlab:
        scipy.io.savemat(buffer, data, do_compression=True)
    else:
        raise GearcheckError(f"{path}: a model file is .mat or .npz")
    write_file(path, buffer.getvalue())
