"""A gear mesh: a ``<fixed>`` tendon over the joints that move its pitch point (the central member's and the
carrier's slides and hinges, the planet's slides and hinge, their axial slides in a helical stage and their tilts
in a tilting one), whose length is the mesh deflection.  Its coefficients are not written from a formula here:
they are late numbers, MuJoCo's own Jacobians at the pitch point (:func:`mesh_jacobian_row`, taken by
:func:`gearcheck.mbd_models.twin.compile_train`), as are its damping (from them and the compiled inertias) and its
stiffness (compile_train's argument).  A backlash b = backlash/2 is the two-valued spring length "-b b" (a dead
band).

In a tilting stage the pitch point is the mesh's centre of stiffness, moved along the axis by its
``axial_centre``, and a second tendon ``<label>_tilt`` resists the two gears' relative tilt across the face
(Eritenel & Parker 2009): slices of stiffness k/w dz at z in [-w/2, w/2] about the centre deflect by
g + z h, and sum k_j (g + z_j h)(g + z_j h)^T = k g g^T + k w^2/12 h h^T, h = (phi_central - phi_planet) .
(e_z x n) the rate at which the slices' deflection grows along the face (phi the gears' rotation vectors, n the
normal line of action).  Its stiffness is the mean mesh stiffness times w^2/12, or as the train file states it
(:meth:`~gearcheck.train.spec.MeshSpec.tilting_stiffness`), and its damping the mesh's in the same proportion,
constant (not driven); its coefficients are MuJoCo's rotational Jacobians (:func:`mesh_tilt_row`)."""

from __future__ import annotations

import mujoco
import numpy as np

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.jacobians import named, point_row, rotation_row, rows_combined
from gearcheck.mbd_models.mjcf_text import LATE, fixed, member_axes, member_joints, member_tilts
from gearcheck.train.line_of_action import line_of_action

BODY, JOINT = mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_JOINT


def mesh_joints(spec, mesh) -> list[str]:
    """The joints whose motion moves ``mesh``'s pitch point on either gear: the central member's slides
    and hinge, the carrier's (which carries the planet), the planet's slides and hinge."""
    members = (mesh.central, spec.stage_of(mesh.planet).carrier, mesh.planet)
    return [f"{spec.members[mid].label}_{a}" for mid in members for a in member_joints(spec.members[mid])]


def tilt_tendon(mesh) -> str:
    """The name of a tilting mesh's tilting tendon."""
    return f"{mesh.label}_tilt"


def tilt_joints(spec, mesh) -> list[str]:
    """The tilt hinges that turn either gear: the central member's, the carrier's and the planet's."""
    members = (mesh.central, spec.stage_of(mesh.planet).carrier, mesh.planet)
    return [f"{spec.members[mid].label}_{a}" for mid in members for a in member_tilts(spec.members[mid])]


def _placed(spec, kin, model, data, mesh):
    """(central body, planet body, pitch point, normal line of action n, stage axis), world frame: the train
    description's pitch point (moved along the axis to the centre of stiffness) and line of action, given in the
    carrier frame, placed with the carrier body's pose in ``data``."""
    stage = spec.stage_of(mesh.planet)
    planet = spec.members[mesh.planet]
    loa = line_of_action(mesh, planet.angle, stage.carrier_radius, kin.flanks[mesh.id])
    carrier_label = spec.members[stage.carrier].label
    carrier = named(model, BODY, carrier_label)
    R = data.xmat[carrier].reshape(3, 3)
    # the stage axis: the carrier frame's origin less the carrier's own slide displacement
    slides = [named(model, JOINT, f"{carrier_label}_{a}")
              for a in member_axes(spec.members[stage.carrier])]  # none: a torsional carrier stays on the axis
    shift = [data.qpos[model.jnt_qposadr[j]] for j in slides]
    origin = data.xpos[carrier] - np.array(shift + [0.0] * (3 - len(shift)))
    point = origin + rows_combined((loa.pitch_point[0], loa.pitch_point[1], mesh.axial_centre), R.T)
    direction = rows_combined((loa.direction[0], loa.direction[1], loa.axial), R.T)
    central = named(model, BODY, spec.members[mesh.central].label)
    return central, named(model, BODY, planet.label), point, direction, R[:, 2]


def mesh_jacobian_row(spec, kin, model, data, mesh) -> np.ndarray:
    """n . (Jp_central(p) - Jp_planet(p)) over all dofs, at ``data``'s current configuration (its kinematics
    computed: ``mj_kinematics`` and ``mj_comPos``, or ``mj_forward``), p the pitch point and n the line of action
    (:func:`_placed`)."""
    central, planet, point, direction, _ = _placed(spec, kin, model, data, mesh)
    return point_row(model, data, central, planet, point, direction)


def mesh_tilt_row(spec, kin, model, data, mesh) -> np.ndarray:
    """(e_z x n) . (Jr_central - Jr_planet) over all dofs, as :func:`mesh_jacobian_row`: the rate along the face
    at which the slices' deflection grows."""
    central, planet, _, direction, axis = _placed(spec, kin, model, data, mesh)
    return rotation_row(model, data, central, planet, np.cross(axis, direction))


HEADER = [
    "A tilting stage's members tilt on hinges inside their spin hinges; its meshes act at their centres of stiffness",
    "and each has a tilting tendon <mesh>_tilt (k_mean w^2/12, or as stated), whose world-frame tilt",
    "coefficients are also those of carrier angle 0.",
]


@ELEMENTS.register("mesh")
class Mesh(Element):
    def header(self, mesh) -> list[str]:
        return HEADER if mesh.contact_width else []

    def driven_tendons(self, mesh, spec) -> list[str]:
        b = 0.5 * mesh.backlash
        return fixed(mesh.label, [(j, LATE) for j in mesh_joints(spec, mesh)], LATE, LATE, (-b, b))

    def tendons(self, mesh, spec) -> list[str]:
        joints = tilt_joints(spec, mesh)
        return fixed(tilt_tendon(mesh), [(j, LATE) for j in joints], LATE, LATE) if joints else []

    def late_rows(self, mesh, spec, kin, model, data) -> list[tuple[str, np.ndarray]]:
        rows = [(mesh.label, mesh_jacobian_row(spec, kin, model, data, mesh))]
        if tilt_joints(spec, mesh):
            rows.append((tilt_tendon(mesh), mesh_tilt_row(spec, kin, model, data, mesh)))
        return rows

    def sensors(self, mesh, spec) -> list[str]:
        return [f'    <tendonpos name="{mesh.label}_deflection" tendon="{mesh.label}"/>',
                f'    <tendonvel name="{mesh.label}_rate" tendon="{mesh.label}"/>']
