"""Assembly of the reference lumped-parameter model from a :class:`TrainSpec`.

Formulation: translational-torsional, each stage in the frame that turns with its
carrier's nominal speed Omega (Lin & Parker 1999; Kiracofe & Parker 2007 for several
stages).  Coordinates are small vibrations about nominal
motion: central members (sun, ring, carrier) have x, y along the rotating frame's axes
and theta; planets have radial, tangential (absolute displacement components along
the carrier's radial and tangential directions at the planet) and theta.  All
rotations are absolute angles in rad.

Every elastic connection is a row: a scalar deflection delta = a . q with stiffness
k (constant, or k(t) for a mesh) and damping c, so

    M q'' + (C + Omega G) q' + (K_b + K_m(t) + K_frame) q = F(t),
    K_b = sum k a a^T,  C = sum c a a^T,  K_m(t) = sum_meshes k(t) a a^T,

with G the Coriolis terms of each member's translations and K_frame the stiffness-like
terms of the rotating frame:

* the planets' centripetal potential -1/2 m Omega^2 |r|^2 written in the coordinates in which
  the bearing and the mesh are linear: the carrier's translation c and rotation theta_c and the
  planet's offset s from its pin in carrier axes, r = c + R(theta_c)(r_c e_r + s).  To second
  order, and expressed back in absolute coordinates, it is Lin & Parker's (1999, Eq. 4)
  softening -m Omega^2 of every translation plus m Omega^2 (r_c^2 theta_c^2 / 2 + r_c theta_c s_t),
  s_t the bearing's tangential deflection.  Lin & Parker keep only the softening: then a rigid
  turn of the mechanism (each planet moving r_c theta_c with its pin) is not force-free, its
  stiffness is negative, and a train whose input is driven by a torque (no shaft holding it)
  drifts away until the planets' softening carries the load instead of their bearings;
  MuJoCo, whose planets are children of the carrier, has the exact potential;
* circulatory terms of the supports' damping: a support damps the member's velocity
  relative to the housing, q' + Omega k x q in rotating coordinates, so -c Omega k x q
  appears beside -c q' (whirl damping), and a rotating member with torsional damping to the
  housing feels the drag torque -c w_nominal (in F_static).

Each member's coordinates are its :attr:`~gearcheck.train.spec.Member.dofs`; every part of the train
(:attr:`~gearcheck.train.spec.TrainSpec.parts`) is built by the element of its kind
(:mod:`gearcheck.lumped.elements`).  A new kind of part is a new element; nothing here is specific to a part
or a stage layout.  A train with torsional members is assembled over all of these coordinates and then reduced to
its free ones (:func:`gearcheck.lumped.constraints.torsional`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, DofMap, Row
from gearcheck.lumped.constraints import torsional
from gearcheck.lumped.elements.bearing import carrier_tilts, pin_rows
from gearcheck.train.excitation import Excitation
from gearcheck.train.kinematics import Kinematics, kinematics
from gearcheck.train.spec import AXIAL, ROTATION, TILTS, TrainSpec

__all__ = ["DofMap", "LumpedModel", "Row", "build_model", "contact_sets", "frozen_at"]


@dataclass
class LumpedModel:
    """Matrices and rows of the reference model at one operating point."""

    spec: TrainSpec
    kin: Kinematics
    dofs: DofMap
    M: np.ndarray
    G: np.ndarray  # gyroscopic matrix, already multiplied by each frame's Omega
    K_centripetal: np.ndarray  # the centripetal potential's stiffness (symmetric, ~ Omega^2)
    K_circulatory: np.ndarray  # the supports' damping seen from the rotating frame (skew, ~ c Omega)
    rows: list[Row]  # constant rows (bearings, supports, couplings, shaft)
    mesh_rows: np.ndarray  # (n_mesh, n) line-of-action rows
    mesh_damping: np.ndarray  # (n_mesh,)
    F_static: np.ndarray  # constant forces (planet centripetal load, drag of rotating members)
    b_input: np.ndarray  # generalized force of a unit torque on the input
    b_output: np.ndarray
    excitation: Excitation
    rotating_frame_terms: bool = True
    turning: list = field(default_factory=list)  # elements whose rows move with time (elements.base.Turning)
    # per unit of the speed scale's rate lambda' (a speed history, :mod:`gearcheck.lumped.frame_schedule`): the Euler
    # terms of the frames' angular acceleration and the loads that accelerate the rigid train; the part of F_static
    # that goes with Omega^2
    K_euler: np.ndarray | None = None
    F_inertia: np.ndarray | None = None
    F_centripetal: np.ndarray | None = None
    F_rest: np.ndarray | None = None  # the part of F_static that connections made with an offset (Row.rest) exert
    expansion: np.ndarray | None = None  # T: the train's coordinates are T q where some are tied (constraints)
    train_dofs: DofMap | None = None  # the train's coordinates, where they are not the model's (``expansion``)

    @property
    def n(self) -> int:
        return len(self.dofs)

    @property
    def physical_dofs(self) -> DofMap:
        """The train's physical coordinates: :attr:`dofs`, or those its coordinates are tied to (``expansion``)."""
        return self.dofs if self.train_dofs is None else self.train_dofs

    @property
    def K_frame(self) -> np.ndarray:
        """Every stiffness-like term of the rotating frame."""
        return self.K_centripetal + self.K_circulatory

    def at_speed(self, input_speed: float) -> "LumpedModel":
        """The rotating-frame terms at another input speed (rad/s; 0 allowed): Coriolis and circulatory
        terms scale with the speed, centripetal ones with its square; nothing else depends on it.  For
        modal analysis (the excitation and the static loads stay those of the train's own speed).  A train at
        rest has no such terms to scale: they are built at ``input_speed``."""
        if not self.spec.operating.input_speed:
            return build_model(self.spec.with_operating(input_speed=input_speed)) if input_speed else self
        r = input_speed / self.spec.operating.input_speed
        return replace(self, G=r * self.G, K_centripetal=r * r * self.K_centripetal,
                       K_circulatory=r * self.K_circulatory)

    @property
    def K_b(self) -> np.ndarray:
        return sum_outer(self.rows, "stiffness", self.n)

    @property
    def C_b(self) -> np.ndarray:
        return sum_outer(self.rows, "damping", self.n)

    def K_mesh(self, k: np.ndarray) -> np.ndarray:
        return self.mesh_rows.T @ (k[:, None] * self.mesh_rows)

    @property
    def K_mean(self) -> np.ndarray:
        """Stiffness with every mesh at its mean stiffness (no rotating-frame softening)."""
        return self.K_b + self.K_mesh(self.excitation.mean_stiffness)

    @property
    def C(self) -> np.ndarray:
        return self.C_b + self.mesh_rows.T @ (self.mesh_damping[:, None] * self.mesh_rows)

    def without_rotating_frame_terms(self) -> "LumpedModel":
        zero = np.zeros_like(self.M)
        turning = [e.without_frame_terms() for e in self.turning]
        held = sum((e.held_load(self.n) for e in turning), np.zeros(self.n) if self.F_rest is None else self.F_rest)
        return replace(self, G=zero, K_centripetal=zero, K_circulatory=zero, F_static=held, K_euler=zero,
                       F_centripetal=np.zeros(self.n),
                       rotating_frame_terms=False, turning=turning)


def sum_outer(rows, attr: str, n: int, chunk_bytes: int = 1 << 23) -> np.ndarray:
    """sum_r value_r a_r a_r^T over the rows whose ``attr`` (stiffness or damping) is non-zero, added in the rows'
    order as one outer product at a time would be: numpy reduces the stacked terms row by row (the same bits,
    without a Python step per row), at most ``chunk_bytes`` of them at a time after the sum so far."""
    kept = [r for r in rows if getattr(r, attr)]
    out = np.zeros((n, n))
    step = max(1, chunk_bytes // (8 * n * n))
    for start in range(0, len(kept), step):
        part = kept[start:start + step]
        a = np.array([r.a for r in part])
        terms = np.array([getattr(r, attr) for r in part])[:, None, None] * (a[:, :, None] * a[:, None, :])
        out = np.add.reduce(np.concatenate([out[None], terms]), axis=0)
    return out


def build_model(spec: TrainSpec, rotating_frame_terms: bool = True) -> LumpedModel:
    """Assemble M, G, K_Omega, rows and force maps of ``spec`` (Lin & Parker 1999 form)."""
    kin = kinematics(spec)
    dofs = DofMap()
    for mid, member in spec.members.items():
        dofs.add(mid, member.dofs)
    n = len(dofs)
    M = np.zeros((n, n))
    G = np.zeros((n, n))
    K_cent = np.zeros((n, n))
    K_circ = np.zeros((n, n))
    K_euler = np.zeros((n, n))
    F = np.zeros(n)
    F_cent = np.zeros(n)
    F_inertia = np.zeros(n)
    for mid, member in spec.members.items():
        u, v = member.dofs[:2]
        iu, iv, ith = dofs(mid, u), dofs(mid, v), dofs(mid, ROTATION)
        M[iu, iu] = M[iv, iv] = member.mass
        M[ith, ith] = member.inertia
        if member.axial:  # along the axis of rotation: no frame terms
            M[dofs(mid, AXIAL), dofs(mid, AXIAL)] = member.mass
        carrier = f"{member.stage}.carrier"
        omega = kin.speeds[carrier]
        # Coriolis 2 m Omega k x q', Euler Omega' k x q and centripetal -m Omega^2 q of the translations (rotating
        # frame; the Euler terms per unit lambda', Omega' = lambda' Omega)
        G[iu, iv] -= 2.0 * member.mass * omega
        G[iv, iu] += 2.0 * member.mass * omega
        K_euler[iu, iv] -= member.mass * omega
        K_euler[iv, iu] += member.mass * omega
        K_cent[iu, iu] = K_cent[iv, iv] = -member.mass * omega**2
        F_inertia[ith] -= member.inertia * kin.speeds[mid]  # -J w: the torque that accelerates its rotation
        if member.tilting:
            _tilt_terms(member, [dofs(mid, d) for d in TILTS[member.frame]], omega, kin.speeds[mid], M, G, K_cent,
                        K_euler)
        if member.orbits:
            F_cent[iu] += member.mass * member.radius * omega**2  # centripetal load of the nominal orbit
            F_inertia[iv] -= member.mass * member.radius * omega  # -m r_c Omega: the orbit's tangential inertia
            # m Omega^2 (r_c^2 theta_c^2 / 2 + r_c theta_c s_t): the potential in carrier coordinates
            e_c = dofs.unit((carrier, ROTATION, 1.0))
            s_r, s_t = pin_rows(spec, dofs, mid)
            K_cent += member.mass * omega**2 * member.radius * (
                member.radius * np.outer(e_c, e_c) + np.outer(e_c, s_t) + np.outer(s_t, e_c))
            # the Euler load -m Omega' r_c along the turned tangent, in carrier coordinates: m Omega' r_c theta_c s_r
            K_euler += member.mass * omega * member.radius * (np.outer(e_c, s_r) + np.outer(s_r, e_c))
            if member.tilting:
                _orbit_tilt_terms(spec, dofs, member, omega, K_cent, K_euler)
        elif member.support:  # (its circulatory damping: the support's element)
            F[ith] -= member.support.torsional_damping * kin.speeds[mid]  # drag of a turning member

    excitation = Excitation(spec, kin)
    build = Build(spec, kin, dofs, dict(zip((m.id for m in spec.meshes), excitation.mean_stiffness)))
    parts = [ELEMENTS[part.element](part, build) for part in spec.parts]
    rows = [row for p in parts for row in p.rows]
    F_rest = sum((r.stiffness * r.rest * r.a for r in rows if r.rest), np.zeros(n))  # offsets' loads: k rest a
    meshes = [p.mesh for p in parts if p.mesh is not None]
    mesh_rows = np.array([a for a, _ in meshes]).reshape(len(meshes), n)
    damping = np.array([c for _, c in meshes])
    b_in = dofs.unit((spec.input, ROTATION, 1.0))
    b_out = dofs.unit((spec.output, ROTATION, 1.0))
    model = LumpedModel(spec, kin, dofs, M, G, K_cent, K_circ, rows, mesh_rows, damping, F + F_cent + F_rest, b_in,
                        b_out,
                        excitation, turning=[e for p in parts for e in p.turning], K_euler=K_euler,
                        F_inertia=F_inertia, F_centripetal=F_cent, F_rest=F_rest)
    for p in parts:
        if p.place:
            model = p.place(model)
    model = torsional(model)
    return model if rotating_frame_terms else model.without_rotating_frame_terms()


def _tilt_terms(member, tilts: list[int], omega: float, spin: float, M, G, K_cent, K_euler) -> None:
    """A tilting member's inertia and its tilts' frame terms, into M, G, K_cent and K_euler.

    An axisymmetric body spinning at ``spin`` with small tilts w = phi_1 + i phi_2 about fixed axes obeys
    I_d w'' - i J spin w' = moment (Euler's equations to first order; I_d its tilting inertia, J its polar one);
    in axes turning at ``omega`` (w = e^{i omega t} v) this is
    I_d v'' + i (2 I_d omega - J spin) v' + (J spin omega - I_d omega^2) v = moment,
    the gyroscopic moment and the frame's Coriolis and centripetal terms of a rotor (the translations' terms with
    I_d for m and the spin's own term J spin besides); the Euler term of a turning frame is i I_d omega' v."""
    i1, i2 = tilts
    inertia = member.tilting_inertia
    M[i1, i1] = M[i2, i2] = inertia
    gyroscopic = 2.0 * inertia * omega - member.inertia * spin
    G[i1, i2] -= gyroscopic
    G[i2, i1] += gyroscopic
    K_cent[i1, i1] = K_cent[i2, i2] = member.inertia * spin * omega - inertia * omega**2
    K_euler[i1, i2] -= inertia * omega
    K_euler[i2, i1] += inertia * omega


def _orbit_tilt_terms(spec, dofs, member, omega: float, K_cent, K_euler) -> None:
    """The orbit's potential and Euler load where the carrier tilts, into K_cent and K_euler.

    A carrier tilt phi (components phi_r, phi_t about the orbiting member's radial and tangential axes) turns its
    pin r_c e_r to r_c (cos phi_t e_r - sin phi_t e_z) and the member's offset s from the pin with it.  Written in
    those coordinates, in which the bearing is linear (as the planar orbit's terms are), the centripetal potential
    -1/2 m Omega^2 |r_perp|^2 gains 1/2 m Omega^2 r_c^2 phi_t^2 - m Omega^2 r_c phi_t s_z, and the Euler load
    -m Omega' r_c e_t does work m Omega' r_c phi_r s_z; with s_z = z - z_c + r_c phi_t (the pin's axial motion)
    they are -1/2 m r_c^2 Omega^2 phi_t^2 - m r_c Omega^2 phi_t (z - z_c) and -m Omega' r_c phi_r s_z."""
    carrier = f"{member.stage}.carrier"
    phi_r, phi_t = carrier_tilts(spec, dofs, member.id)
    s_z = dofs.unit((member.id, AXIAL, 1.0), (carrier, AXIAL, -1.0)) + member.radius * phi_t
    m, r = member.mass, member.radius
    K_cent -= m * r * omega**2 * (np.outer(phi_t, s_z) + np.outer(s_z, phi_t) - r * np.outer(phi_t, phi_t))
    K_euler -= m * r * omega * (np.outer(phi_r, s_z) + np.outer(s_z, phi_r))


def frozen_at(model: LumpedModel, t: float, touching=None) -> LumpedModel:
    """The model frozen at time ``t``: the rows, loads and static contact sets of its elements with contacts
    (cycloid-pin stages) those of ``t`` (the modal and static analyses of that configuration; the meshes stay at
    their mean).  ``touching``: the contact sets to take instead, one boolean array per such element (as
    :func:`contact_sets` gives them)."""
    elements = [e for e in model.turning if e.has_contacts]
    for element, sets in zip(elements, touching or [None] * len(elements)):
        model = element.place(model, t, sets)
    return model


def contact_sets(model: LumpedModel) -> list[np.ndarray]:
    """Which contacts touch, per element with contacts, in the configuration ``model`` is placed at."""
    return [e.contact_set(model) for e in model.turning if e.has_contacts]
