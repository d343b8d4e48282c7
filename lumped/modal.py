"""Natural frequencies of the reference lumped model at mean mesh stiffness.

K_mean q = omega^2 M q without the rotating-frame terms (as in Lin & Parker 1999, section 3),
classified by the central members' coordinates (:func:`gearcheck.shared.modal.mode_types`).
"""

from __future__ import annotations

from gearcheck.shared.modal import ModalResult, modal_result


def modes(model) -> ModalResult:
    """Natural frequencies of a :class:`~gearcheck.lumped.assembly.LumpedModel` at mean mesh stiffness."""
    central = [(i, dof) for i, (member, dof) in enumerate(model.dofs.names)
               if not model.spec.members[member].is_planet]
    return modal_result(model.spec.name, "lumped", model.K_mean, model.M, model.dofs.labels(),
                        [i for i, d in central if d != "theta"], [i for i, d in central if d == "theta"])
