"""Natural frequencies of the reference lumped model at mean mesh stiffness.

* :func:`modes`: K_mean q = omega^2 M q without the rotating-frame terms (as in Lin & Parker 1999,
  section 3), classified by the central members' coordinates (:func:`gearcheck.shared.modal.mode_types`);
* :func:`modes_at_speed`: the gyroscopic eigenproblem (M s^2 + Omega G s + K_mean + K_Omega) x = 0 of the
  train turning at a speed (Cooley & Parker 2012): complex s, frequency splitting of the degenerate
  modes, divergence and flutter where the centripetal softening wins;
* :func:`settling_time`: how long the damped free vibration of a start lasts.
"""

from __future__ import annotations

from gearcheck.train.spec import AXIAL, ROTATION
from gearcheck.shared import modal as shared
from gearcheck.shared.modal import ModalResult, modal_result
from gearcheck.shared.units import rad_s_to_rpm


def central_coordinates(spec, labels) -> tuple[list[int], list[int]]:
    """Indices, among the coordinate ``labels`` (``member.dof``), of the central members' translations and of
    their rotations (a helical mesh's axial force goes with its torque, Eritenel & Parker 2009: the axial
    slides count with the rotations); labels of no member of ``spec`` are neither."""
    named = [(i, label.rsplit(".", 1)) for i, label in enumerate(labels) if "." in label]
    central = [(i, dof) for i, (member, dof) in named if member in spec.members and spec.members[member].central]
    turning = (ROTATION, AXIAL)
    return [i for i, d in central if d not in turning], [i for i, d in central if d in turning]


def _central(model) -> tuple[list[int], list[int]]:
    return central_coordinates(model.spec, model.dofs.labels())


def modes(model) -> ModalResult:
    """Natural frequencies of a :class:`~gearcheck.lumped.assembly.LumpedModel` at mean mesh stiffness."""
    return modal_result(model.spec.name, "lumped", model.K_mean, model.M, model.dofs.labels(), *_central(model))


def modes_at_speed(model, input_speed: float) -> ModalResult:
    """The undamped modes of the train turning with its input at ``input_speed`` (rad/s, 0 allowed: then
    the modes of :func:`modes`), every mesh at its mean stiffness."""
    at = model.at_speed(input_speed)
    return shared.speed_modal_result(model.spec.name, "lumped", at.M, at.G, at.K_mean + at.K_centripetal,
                                     model.dofs.labels(), *_central(model), rad_s_to_rpm(input_speed))


def settling_time(model, fraction: float) -> float:
    """The time the free vibration of the damped, rotating model at mean mesh stiffness takes to fall to
    ``fraction`` (its slowest-decaying mode): how long a run from the static state needs before its
    start has died away."""
    return shared.settling_time(model.M, model.C + model.G, model.K_mean + model.K_frame, fraction)
