"""A gear mesh: a ``<fixed>`` tendon over the joints that move its pitch point (the central member's and the
carrier's slides and hinges, the planet's slides and hinge, and their axial slides in a helical stage), whose
length is the mesh deflection.  Its coefficients are not written from a formula here: they are late numbers, taken
by :func:`gearcheck.mbd_models.twin.compile_train` from MuJoCo's own Jacobians, as are its damping (from them and
the compiled inertias) and its stiffness (compile_train's argument).  A backlash b = backlash/2 is the
two-valued spring length "-b b" (a dead band)."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import LATE, fixed, member_joints


def mesh_joints(spec, mesh) -> list[str]:
    """The joints whose motion moves ``mesh``'s pitch point on either gear: the central member's slides
    and hinge, the carrier's (which carries the planet), the planet's slides and hinge."""
    members = (mesh.central, spec.stage_of(mesh.planet).carrier, mesh.planet)
    return [f"{spec.members[mid].label}_{a}" for mid in members for a in member_joints(spec.members[mid])]


@ELEMENTS.register("mesh")
class Mesh(Element):
    def tendons(self, mesh, spec) -> list[str]:
        b = 0.5 * mesh.backlash
        return fixed(mesh.label, [(j, LATE) for j in mesh_joints(spec, mesh)], LATE, LATE, (-b, b))

    def sensors(self, mesh, spec) -> list[str]:
        return [f'    <tendonpos name="{mesh.label}_deflection" tendon="{mesh.label}"/>',
                f'    <tendonvel name="{mesh.label}_rate" tendon="{mesh.label}"/>']
