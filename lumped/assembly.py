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

A new member type or DOF (axial, eccentric shaft) adds entries to the DOF map and new rows;
nothing here is specific to a stage layout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from gearcheck.lumped.cycloid_rows import CycloidRows
from gearcheck.train.excitation import Excitation
from gearcheck.train.kinematics import Kinematics, kinematics
from gearcheck.train.line_of_action import lever, line_of_action
from gearcheck.train.spec import TrainSpec
from gearcheck.lumped.static import mean_load
from gearcheck.shared.errors import SolverError

CENTRAL_DOFS = ("x", "y", "theta")
PLANET_DOFS = ("radial", "tangential", "theta")
AXIAL_DOF = "z"  # members of a helical stage: translation along the stage axis (absolute, like the others)


def member_dofs(spec: TrainSpec, member) -> tuple[str, ...]:
    """The coordinates of ``member``: two translations and a rotation, and z in a helical stage."""
    planar = PLANET_DOFS if member.orbits else CENTRAL_DOFS
    return planar + (AXIAL_DOF,) if spec.stage_of(member.id).helical else planar


@dataclass(frozen=True)
class Row:
    """One elastic connection: deflection a . q, stiffness, damping."""

    name: str
    kind: str  # mesh | bearing | support | coupling | shaft
    a: np.ndarray
    stiffness: float
    damping: float


@dataclass
class DofMap:
    """Named coordinates: (member id, dof name) -> index."""

    names: list[tuple[str, str]] = field(default_factory=list)
    _index: dict[tuple[str, str], int] = field(default_factory=dict)

    def add(self, member: str, dofs) -> None:
        for d in dofs:
            self._index[(member, d)] = len(self.names)
            self.names.append((member, d))

    def __call__(self, member: str, dof: str) -> int:
        return self._index[(member, dof)]

    def __len__(self) -> int:
        return len(self.names)

    def of_member(self, member: str) -> list[int]:
        return [i for i, (m, _) in enumerate(self.names) if m == member]

    def labels(self) -> list[str]:
        return [f"{m}.{d}" for m, d in self.names]


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
    turning: list = field(default_factory=list)  # TurningCoupling: radial couplings across frames

    @property
    def n(self) -> int:
        return len(self.dofs)

    @property
    def K_frame(self) -> np.ndarray:
        """Every stiffness-like term of the rotating frame."""
        return self.K_centripetal + self.K_circulatory

    def at_speed(self, input_speed: float) -> "LumpedModel":
        """The rotating-frame terms at another input speed (rad/s; 0 allowed): Coriolis and circulatory
        terms scale with the speed, centripetal ones with its square; nothing else depends on it.  For
        modal analysis (the excitation and the static loads stay those of the train's own speed)."""
        r = input_speed / self.spec.operating.input_speed
        return replace(self, G=r * self.G, K_centripetal=r * r * self.K_centripetal,
                       K_circulatory=r * self.K_circulatory)

    @property
    def K_b(self) -> np.ndarray:
        return _sum_outer(self.rows, "stiffness", self.n)

    @property
    def C_b(self) -> np.ndarray:
        return _sum_outer(self.rows, "damping", self.n)

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
        turning = [replace(e, omega_orbit=0.0) if isinstance(e, CycloidRows) else e for e in self.turning]
        gaps = sum((e.gap_load for e in turning if isinstance(e, CycloidRows)), np.zeros(self.n))
        return replace(self, G=zero, K_centripetal=zero, K_circulatory=zero, F_static=gaps,
                       rotating_frame_terms=False, turning=turning)


@dataclass(frozen=True)
class TurningCoupling:
    """A radial coupling between members whose frames turn at different speeds (a ring shared by two
    stages, a radial spline between stages): member b's frame turns by phi = (Omega_b - Omega_a) t
    relative to a's, so the coupling's rows are periodic in time.  Its rows in ``rows`` are those of
    t = 0, when every frame coincides (what the modal and static analyses use, like MuJoCo's
    linearisation at its initial configuration); the time solver replaces them by
    :meth:`forces` at every stage."""

    a: tuple[int, int]  # (x, y) coordinates of member a
    b: tuple[int, int]
    omega_a: float
    omega_b: float
    stiffness: float
    damping: float
    rows: tuple[str, str]  # names of its t = 0 rows

    def forces(self, t, q, v) -> np.ndarray:
        """Generalized forces (time along axis 0 allowed) of the spring-damper between the two centres,
        acting on world-frame displacement and velocity and resolved in each member's own axes."""
        phi = (self.omega_b - self.omega_a) * np.asarray(t, dtype=float)
        c, s = np.cos(phi), np.sin(phi)
        ua = np.stack([q[..., self.a[0]], q[..., self.a[1]]], axis=-1)
        ub = np.stack([q[..., self.b[0]], q[..., self.b[1]]], axis=-1)
        # world velocities in own axes: u' + Omega k x u
        va = np.stack([v[..., self.a[0]] - self.omega_a * ua[..., 1], v[..., self.a[1]] + self.omega_a * ua[..., 0]],
                      axis=-1)
        vb = np.stack([v[..., self.b[0]] - self.omega_b * ub[..., 1], v[..., self.b[1]] + self.omega_b * ub[..., 0]],
                      axis=-1)
        # b's vectors in a's axes: R(phi) x
        rot = lambda x: np.stack([c * x[..., 0] - s * x[..., 1], s * x[..., 0] + c * x[..., 1]], axis=-1)  # noqa
        pull = self.stiffness * (ua - rot(ub)) + self.damping * (va - rot(vb))  # force on b, in a's axes
        on_b = np.stack([c * pull[..., 0] + s * pull[..., 1], -s * pull[..., 0] + c * pull[..., 1]], axis=-1)
        out = np.zeros(np.shape(q))
        out[..., self.a[0]] -= pull[..., 0]
        out[..., self.a[1]] -= pull[..., 1]
        out[..., self.b[0]] += on_b[..., 0]
        out[..., self.b[1]] += on_b[..., 1]
        return out


def _sum_outer(rows, attr, n):
    out = np.zeros((n, n))
    for r in rows:
        value = getattr(r, attr)
        if value:
            out += value * np.outer(r.a, r.a)
    return out


def build_model(spec: TrainSpec, rotating_frame_terms: bool = True) -> LumpedModel:
    """Assemble M, G, K_Omega, rows and force maps of ``spec`` (Lin & Parker 1999 form)."""
    kin = kinematics(spec)
    dofs = DofMap()
    for mid, member in spec.members.items():
        dofs.add(mid, member_dofs(spec, member))
    n = len(dofs)
    M = np.zeros((n, n))
    G = np.zeros((n, n))
    K_cent = np.zeros((n, n))
    K_circ = np.zeros((n, n))
    F = np.zeros(n)
    for mid, member in spec.members.items():
        u, v = (PLANET_DOFS if member.orbits else CENTRAL_DOFS)[:2]
        iu, iv, ith = dofs(mid, u), dofs(mid, v), dofs(mid, "theta")
        M[iu, iu] = M[iv, iv] = member.mass
        M[ith, ith] = member.inertia
        if AXIAL_DOF in member_dofs(spec, member):  # along the axis of rotation: no frame terms
            M[dofs(mid, AXIAL_DOF), dofs(mid, AXIAL_DOF)] = member.mass
        carrier = f"{member.stage}.carrier"
        omega = kin.speeds[carrier]
        # Coriolis 2 m Omega k x q' and centripetal -m Omega^2 q of the translations (rotating frame)
        G[iu, iv] -= 2.0 * member.mass * omega
        G[iv, iu] += 2.0 * member.mass * omega
        K_cent[iu, iu] = K_cent[iv, iv] = -member.mass * omega**2
        if member.orbits:
            F[iu] += member.mass * member.radius * omega**2  # centripetal load of the nominal orbit
            # m Omega^2 (r_c^2 theta_c^2 / 2 + r_c theta_c s_t): the potential in carrier coordinates
            e_c = _unit(n, (dofs(carrier, "theta"), 1.0))
            s_t = _pin_rows(spec, dofs, mid)[1]
            K_cent += member.mass * omega**2 * member.radius * (
                member.radius * np.outer(e_c, e_c) + np.outer(e_c, s_t) + np.outer(s_t, e_c))
        elif member.support:
            c = member.support.radial_damping  # damping relative to the housing: -c (q' + Omega k x q)
            K_circ[iu, iv] -= c * omega
            K_circ[iv, iu] += c * omega
            F[ith] -= member.support.torsional_damping * kin.speeds[mid]  # drag of a turning member

    rows, turning = _coupling_rows(spec, dofs, kin)
    rows = _support_rows(spec, dofs) + _bearing_rows(spec, dofs) + _spline_rows(spec, dofs) + rows
    if spec.operating.input_shaft_stiffness is not None:
        a = np.zeros(n)
        a[dofs(spec.input, "theta")] = 1.0
        rows.append(Row("input_shaft", "shaft", a, spec.operating.input_shaft_stiffness,
                        spec.operating.input_shaft_damping))

    mesh_rows = np.array([_mesh_row(spec, dofs, kin, mesh) for mesh in spec.meshes])
    excitation = Excitation(spec, kin)
    damping = np.array([_mesh_damping(spec, mesh, row, dofs, k)
                        for mesh, row, k in zip(spec.meshes, mesh_rows, excitation.mean_stiffness)])
    b_in = np.zeros(n)
    b_in[dofs(spec.input, "theta")] = 1.0
    b_out = np.zeros(n)
    b_out[dofs(spec.output, "theta")] = 1.0
    model = LumpedModel(spec, kin, dofs, M, G, K_cent, K_circ, rows, mesh_rows, damping, F, b_in, b_out, excitation,
                        turning=turning)
    for stage in spec.stages:
        if stage.cycloid:
            model = _with_cycloid(model, stage)
    return model if rotating_frame_terms else model.without_rotating_frame_terms()


def _unit(n: int, *entries) -> np.ndarray:
    a = np.zeros(n)
    for i, value in entries:
        a[i] += value
    return a


def _support_rows(spec, dofs) -> list[Row]:
    n = len(dofs)
    rows = []
    for mid, m in spec.members.items():
        if m.support is None:
            continue
        s = m.support
        rows.append(Row(f"{mid}.support_x", "support", _unit(n, (dofs(mid, "x"), 1.0)), s.radial_stiffness,
                        s.radial_damping))
        rows.append(Row(f"{mid}.support_y", "support", _unit(n, (dofs(mid, "y"), 1.0)), s.radial_stiffness,
                        s.radial_damping))
        if s.torsional_stiffness or s.torsional_damping:
            rows.append(Row(f"{mid}.support_theta", "support", _unit(n, (dofs(mid, "theta"), 1.0)),
                            s.torsional_stiffness, s.torsional_damping))
        if AXIAL_DOF in member_dofs(spec, m):
            rows.append(Row(f"{mid}.support_z", "support", _unit(n, (dofs(mid, AXIAL_DOF), 1.0)), s.axial_stiffness,
                            s.axial_damping))
    return rows


def _pin_rows(spec, dofs, pid) -> tuple[np.ndarray, np.ndarray]:
    """Planet centre minus its carrier's pin point, along the planet's radial and tangential axes."""
    n = len(dofs)
    p = spec.members[pid]
    c = f"{p.stage}.carrier"
    cs, sn = math.cos(p.angle), math.sin(p.angle)
    radial = _unit(n, (dofs(pid, "radial"), 1.0), (dofs(c, "x"), -cs), (dofs(c, "y"), -sn))
    tangential = _unit(n, (dofs(pid, "tangential"), 1.0), (dofs(c, "x"), sn), (dofs(c, "y"), -cs),
                       (dofs(c, "theta"), -p.radius))
    return radial, tangential


def _bearing_rows(spec, dofs) -> list[Row]:
    """Planet bearing: an isotropic spring-damper between the planet centre and its pin."""
    rows = []
    for stage in spec.stages:
        for pid in stage.planets + (stage.cycloid.cranks if stage.cycloid else ()):
            b = spec.members[pid].bearing
            if b is None:  # an RV reducer's planet: on its crank
                continue
            radial, tangential = _pin_rows(spec, dofs, pid)
            rows.append(Row(f"{pid}.bearing_radial", "bearing", radial, b.radial_stiffness, b.radial_damping))
            rows.append(Row(f"{pid}.bearing_tangential", "bearing", tangential, b.radial_stiffness,
                            b.radial_damping))
            if stage.helical:
                axial = _unit(len(dofs), (dofs(pid, AXIAL_DOF), 1.0), (dofs(stage.carrier, AXIAL_DOF), -1.0))
                rows.append(Row(f"{pid}.bearing_axial", "bearing", axial, b.axial_stiffness, b.axial_damping))
    return rows


def _spline_rows(spec, dofs) -> list[Row]:
    """An RV reducer's planet on its crankshaft: bending along the carrier's radial and tangential axes (both
    members at the same place) and torsion."""
    rows = []
    for stage in spec.stages:
        if not stage.cycloid:
            continue
        s = stage.cycloid.spline
        for planet, crank in zip(stage.planets, stage.cycloid.cranks):
            for dof, k, c in (("radial", s.radial_stiffness, s.radial_damping),
                              ("tangential", s.radial_stiffness, s.radial_damping),
                              ("theta", s.torsional_stiffness, s.torsional_damping)):
                a = _unit(len(dofs), (dofs(planet, dof), 1.0), (dofs(crank, dof), -1.0))
                rows.append(Row(f"{crank}.spline_{dof}", "coupling", a, k, c))
    return rows


def _with_cycloid(model: LumpedModel, stage) -> LumpedModel:
    """The model with a cycloid-pin stage among its turning elements, placed at t = 0 (:func:`frozen_at`)."""
    spec, dofs, kin, cyc = model.spec, model.dofs, model.kin, stage.cycloid
    omega = kin.speeds[stage.carrier]
    wheel = kin.speeds[cyc.pin_wheel] if cyc.pin_wheel else 0.0
    index = lambda mid, names: np.array([dofs(mid, d) for d in names])  # noqa: E731
    element = CycloidRows(
        stage.name, model.n, np.array([index(c, PLANET_DOFS) for c in cyc.cranks]),
        np.array([index(d, CENTRAL_DOFS) for d in cyc.discs]),
        index(cyc.pin_wheel, CENTRAL_DOFS) if cyc.pin_wheel else None,
        np.array([spec.members[c].angle for c in cyc.cranks]), np.array(cyc.phases),
        kin.speeds[cyc.cranks[0]] - omega, wheel - omega, kin.speeds[cyc.cranks[0]], cyc.geometry,
        stage.carrier_radius, cyc.needle.radial_stiffness, cyc.needle.radial_damping,
        cyc.pin_stiffness(spec.operating.output_torque), cyc.contact_damping, cyc.clearance,
        spec.members[cyc.discs[0]].mass, gap_load=np.zeros(model.n))
    unplaced = replace(model, turning=model.turning + [element], F_static=model.F_static + element.static_load)
    return _place(unplaced, element, 0.0)


def frozen_at(model: LumpedModel, t: float, touching=None) -> LumpedModel:
    """The model frozen at time ``t``: its cycloid stages' rows, orbit loads and static pin contact sets those
    of ``t`` (the modal and static analyses of that configuration; the meshes stay at their mean).  ``touching``:
    the contact sets to take instead, one boolean array (N * Z_p,) per cycloid stage (as :func:`contact_sets`
    gives them)."""
    elements = [e for e in model.turning if isinstance(e, CycloidRows)]
    for element, sets in zip(elements, touching or [None] * len(elements)):
        model = _place(model, element, t, sets)
    return model


def contact_sets(model: LumpedModel) -> list[np.ndarray]:
    """Which pins touch, per cycloid stage, in the configuration ``model`` is placed at."""
    names = {r.name for r in model.rows if r.kind == "contact"}
    return [np.array([name in names for name, _ in e.pin_rows(e.placed_at)])
            for e in model.turning if isinstance(e, CycloidRows)]


def _place(model: LumpedModel, element: CycloidRows, t: float, touching=None) -> LumpedModel:
    """``model`` with ``element``'s rows and loads of time ``t`` in place of those it had; the pins of
    ``touching`` in contact, or those of the static solution."""
    rows = [r for r in model.rows if r.name not in element.rows]
    needles = [Row(name, "bearing", a, element.needle_stiffness, element.needle_damping)
               for name, a in element.needle_rows(t)]
    pins = element.pin_rows(t)
    base = replace(model, rows=rows + needles,
                   F_static=model.F_static - element.static_load + element.orbit_force(t))  # gaps: below
    A = np.array([a for _, a in pins])
    touching = _static_contact_set(base, A, element) if touching is None else np.asarray(touching, dtype=bool)
    contacts = [Row(name, "contact", a, element.pin_stiffness, element.pin_damping)
                for (name, a), on in zip(pins, touching) if on]
    gap_load = element.pin_stiffness * element.clearance * A[touching].sum(axis=0)  # a row k (a.q - gap)
    placed = replace(element, rows=tuple(r.name for r in needles + contacts), placed_at=t, gap_load=gap_load)
    return replace(base, rows=base.rows + contacts, F_static=base.F_static + gap_load,
                   turning=[placed if e is element else e for e in model.turning])


def _static_contact_set(model: LumpedModel, A: np.ndarray, element) -> np.ndarray:
    """Which pins (rows ``A``, of the time the rows are placed at) touch in the static equilibrium under the mean
    load (active set, from all of them touching)."""
    K0 = model.K_b + model.K_mesh(model.excitation.mean_stiffness) + model.K_frame
    F = mean_load(model)
    active = np.ones(len(A), dtype=bool)
    for _ in range(len(A) + 1):
        K = K0 + element.pin_stiffness * A[active].T @ A[active]
        q = np.linalg.lstsq(K, F + element.pin_stiffness * element.clearance * A[active].sum(axis=0),
                            rcond=None)[0]
        touching = A @ q - element.clearance > 0.0
        if np.array_equal(touching, active):
            return active
        active = touching
    raise SolverError(f"{element.stage}: the static pin contact set did not settle")  # pragma: no cover


def _coupling_rows(spec, dofs, kin) -> tuple[list[Row], list[TurningCoupling]]:
    n = len(dofs)
    rows, turning = [], []
    for c in spec.couplings:
        rows.append(Row(f"{c.name}.torsion", "coupling",
                        _unit(n, (dofs(c.a, "theta"), 1.0), (dofs(c.b, "theta"), -1.0)),
                        c.torsional_stiffness, c.torsional_damping))
        if c.radial_stiffness or c.radial_damping:
            for axis in ("x", "y"):
                rows.append(Row(f"{c.name}.{axis}", "coupling",
                                _unit(n, (dofs(c.a, axis), 1.0), (dofs(c.b, axis), -1.0)),
                                c.radial_stiffness, c.radial_damping))
            wa = kin.speeds[f"{spec.members[c.a].stage}.carrier"]
            wb = kin.speeds[f"{spec.members[c.b].stage}.carrier"]
            if abs(wa - wb) > 1e-12 * max(abs(wa), abs(wb), 1.0):
                turning.append(TurningCoupling((dofs(c.a, "x"), dofs(c.a, "y")), (dofs(c.b, "x"), dofs(c.b, "y")),
                                               wa, wb, c.radial_stiffness, c.radial_damping,
                                               (f"{c.name}.x", f"{c.name}.y")))
    return rows, turning


def _mesh_row(spec, dofs, kin, mesh) -> np.ndarray:
    """delta = (u_central(p) - u_planet(p)) . d with u(p) = translation + theta k x (p - centre) (+ z e_z)."""
    stage = spec.stage_of(mesh.planet)
    planet = spec.members[mesh.planet]
    loa = line_of_action(mesh, planet.angle, stage.carrier_radius, kin.flanks[mesh.id])
    d = loa.direction
    e_r = np.array([math.cos(planet.angle), math.sin(planet.angle)])
    e_t = np.array([-e_r[1], e_r[0]])
    a = np.zeros(len(dofs))
    c = mesh.central
    a[dofs(c, "x")] += d[0]
    a[dofs(c, "y")] += d[1]
    a[dofs(c, "theta")] += lever(loa.pitch_point, np.zeros(2), d)
    p = mesh.planet
    a[dofs(p, "radial")] -= float(d @ e_r)
    a[dofs(p, "tangential")] -= float(d @ e_t)
    a[dofs(p, "theta")] -= lever(loa.pitch_point, loa.planet_centre, d)
    if stage.helical:  # the normal line of action's axial part (Eritenel & Parker 2009)
        a[dofs(c, AXIAL_DOF)] += loa.axial
        a[dofs(p, AXIAL_DOF)] -= loa.axial
    return a


def _mesh_damping(spec, mesh, row, dofs, k_mean) -> float:
    """c = 2 zeta sqrt(k m_eq), m_eq = 1/(r_b1^2/I_1 + r_b2^2/I_2): the equivalent mass of the
    gear pair's torsional motion along the line of action (the arms are the row's own levers).

    Li et al. (2026) print c = 2 zeta sqrt(k / (1/m_s^2 + 1/m_p^2)), which is not even a damping
    coefficient dimensionally (sqrt(N/m kg^2) = kg sqrt(N/m)); the critical damping of a spring k
    between two inertias is 2 sqrt(k m_eq) with 1/m_eq = 1/m_s + 1/m_p, m = I/r_b^2."""
    if mesh.damping_coefficient is not None:
        return mesh.damping_coefficient
    if not mesh.damping_ratio:
        return 0.0
    inv = 0.0
    for member in (mesh.central, mesh.planet):
        arm = row[dofs(member, "theta")]
        inv += arm**2 / spec.members[member].inertia
    return 2.0 * mesh.damping_ratio * math.sqrt(k_mean / inv)
