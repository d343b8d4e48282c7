"""Natural frequencies of the reference lumped model at mean mesh stiffness.

K_mean q = omega^2 M q without the rotating-frame terms (as in Lin & Parker 1999, section 3),
classified by the central members' coordinates (:func:`gearcheck.shared.modal.mode_types`).
"""

from __future__ import annotations

from gearcheck.shared import modal as shared
from gearcheck.shared.modal import ModalResult, modal_result


def modes(model) -> ModalResult:
    """Natural frequencies of a :class:`~gearcheck.lumped.assembly.LumpedModel` at mean mesh stiffness."""
    central = [(i, dof) for i, (member, dof) in enumerate(model.dofs.names)
               if not model.spec.members[member].is_planet]
    return modal_result(model.spec.name, "lumped", model.K_mean, model.M, model.dofs.labels(),
                        [i for i, d in central if d != "theta"], [i for i, d in central if d == "theta"])


def settling_time(model, fraction: float) -> float:
    """The time the free vibration of the damped, rotating model at mean mesh stiffness takes to fall to
    ``fraction`` (its slowest-decaying mode): how long a run from the static state needs before its
    start has died away."""
    return shared.settling_time(model.M, model.C + model.G, model.K_mean + model.K_frame, fraction)
