"""The 4-DOF model of Matejic, Blagojevic & Matejic (2021), as published and as derived.

Matejic M. S., Blagojevic M. Z., Matejic M. M.: "Dynamic behaviour of a planetary reducer
with double planet gears", Mech. Sci. 12, 983-991, 2021.  Carrier h in (torque M_h), one
double planet (gears f, g on one body), ring e held (meshes f, stiffness c1, damping k1),
ring b movable (meshes g, c2, k2).  Coordinates q = (y1, theta_h, theta_f, theta_b): y1 the
planet set's displacement, theta_h the carrier angle, theta_f the planet's angle relative to
the carrier (its absolute angle is theta_h + theta_f, Eq. 3), theta_b the ring b angle.
The paper writes c for stiffness and k for damping; so does this module.

Models (``MODELS``), every one built from the same :class:`PaperParameters`:

* ``as-published`` -- M, B, C, D exactly as printed in Eqs. 10, 11, 12, 13.  Row and column 1
  of B and C carry only their diagonal (k1 + k2, c1 + c2): the y1-rotation coupling that
  Eqs. 4-6 contain is dropped, so y1 hangs on a spring c1 + c2 to the ground and the
  rotations do not feel y1.
* ``energy-derived`` -- Lagrange's equations (Eq. 1) applied to Eqs. 3, 4, 5 as printed.  Eq. 4
  is 1/2 c1 (y1 - u1)^2 + 1/2 c2 (y1 - u2)^2 with u1 = r_f (th_h + th_f) + r_h th_h and
  u2 = r_g (th_h + th_f) + r_h th_h - r_b th_b, so C = c1 a1 a1^T + c2 a2 a2^T with
  a1 = (1, -(r_f + r_h), -r_f, 0), a2 = (1, -(r_g + r_h), -r_g, r_b), and B the same with k
  (Eq. 5's cross terms read y1 where Eq. 6 has dy1/dt: taken as dy1/dt).  M = Eq. 10 (Eq. 3 gives
  exactly Eq. 10).  Two rigid-body modes: the train's rotation and a second mechanism (y1 and
  the planet rolling on ring e) that nothing restrains, since the paper has no planet bearing.
* ``energy-derived-axis`` -- as ``energy-derived`` with the carrier's mass on its axis: Eq. 3
  gives the carrier m_h (dy1^2 + r_h^2 dth_h^2) + J_ch dth_h^2, i.e. puts m_h at the planet radius
  on top of J_ch, which Table 1 takes from the CAD model (about the carrier axis, so it already
  contains the carrier's mass distribution).  Here the carrier contributes J_ch only to M_22
  (and m_h to M_11: the carrier still moves with y1 as in Eq. 3).
* ``consistent`` -- y1 collinear with the tangential motion in the kinetic energy as well (the
  paper's own assumption for Eq. 4, "y1 collinear with the angular displacements but in the
  opposite direction"): the planet centre moves r_h th_h - y1 along the tangent, so
  M_12 = -m_p r_h; carrier mass on its axis.  This is the kinetic energy of rigid bodies on the
  joints the potential energy describes (:mod:`mbd_models.published_twin`, y1 tangential).

``planet_sets``: the paper's model has one planet although the reducer has three.  With
``planet_sets=1`` (default, literal) one planet's mass, inertia and mesh values enter; with
``planet_sets=N`` the N planets are lumped in phase (planet mass, inertia, c and k times N).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .errors import GearcheckError, SolverError
from .modal import generalized_modes
from .time_solver import rk4_step

MODELS = ("as-published", "energy-derived", "energy-derived-axis", "consistent")
LABELS = ("y1", "theta_h", "theta_f", "theta_b")
UNITS = ("m", "rad", "rad", "rad")


@dataclass(frozen=True)
class PaperParameters:
    """Table 1 quantities of the paper, in SI, read from a :class:`~lumped.spec.TrainSpec`."""

    m_h: float  # carrier mass
    m_p: float  # planet body mass, m_f + m_g
    J_ch: float  # carrier inertia about its axis
    J_p: float  # planet inertia, J_cf + J_cg
    J_cb: float  # ring b inertia
    m_b: float  # ring b mass (not in the paper's model; the MuJoCo twin needs a positive mass)
    r_h: float  # carrier radius ("mutual distance")
    r_f: float  # pitch radius of planet gear f (meshes ring e)
    r_g: float  # pitch radius of planet gear g (meshes ring b)
    r_b: float  # pitch radius of ring b
    c1: float  # mesh stiffness f-e
    c2: float  # mesh stiffness g-b
    k1: float  # mesh damping f-e
    k2: float  # mesh damping g-b
    input_torque: float  # mean M_h, N m (power balance with the output load)
    output_torque: float  # load on ring b, N m, signed (opposes ring b's rotation)
    input_speed: float  # rad/s (sets the ripple frequencies)
    ripple: tuple = field(default=())  # (member, amplitude, omega rad/s, phase) of the spec's ripple
    planet_sets: int = 1
    source: str = ""

    @classmethod
    def from_spec(cls, spec, planet_sets: int = 1) -> "PaperParameters":
        """Read the paper's parameters from a one-stage, two-ring, compound-planet train.

        Ring e = the held ring, ring b = the output ring, carrier = the input; gears f and g are
        the planet gears those rings mesh with.  Mesh stiffness is the stiffness model's mean,
        mesh damping must be given as a coefficient (the paper's k1, k2).
        """
        from .kinematics import kinematics
        from .mesh_stiffness import stiffness_model

        if len(spec.stages) != 1:
            raise GearcheckError(f"{spec.name}: the 4-DOF model of Matejic et al. needs one stage, "
                                 f"got {len(spec.stages)}")
        stage = spec.stages[0]
        if spec.input != stage.carrier:
            raise GearcheckError(f"{spec.name}: the 4-DOF model needs the carrier as input, got {spec.input}")
        rings = [c for c in stage.centrals if spec.members[c].kind == "ring"]
        held = [c for c in rings if c in spec.held]
        if len(rings) != 2 or len(held) != 1 or spec.output not in rings or spec.output in held:
            raise GearcheckError(f"{spec.name}: the 4-DOF model needs two rings, one held (e) and one the "
                                 f"output (b); got rings {rings}, held {list(spec.held)}, output {spec.output}")
        ring_e, ring_b = held[0], spec.output
        mesh_e = next(m for m in spec.meshes if m.central == ring_e and m.planet_index == 0)
        mesh_b = next(m for m in spec.meshes if m.central == ring_b and m.planet_index == 0)
        for mesh in (mesh_e, mesh_b):
            if mesh.damping_coefficient is None:
                raise GearcheckError(f"{spec.name}: {mesh.central} mesh damping must be a coefficient "
                                     "(the paper's k1, k2), not a ratio")
        n = int(planet_sets)
        if n < 1:
            raise GearcheckError(f"planet_sets must be >= 1, got {planet_sets}")
        carrier = spec.members[stage.carrier]
        planet = spec.members[stage.planets[0]]
        kin = kinematics(spec)
        ripple = []
        for r in spec.operating.ripple:
            member = spec.input if r.member == "input" else spec.output
            omega = 2 * math.pi * r.frequency if r.frequency is not None else r.order * abs(kin.speeds[member])
            ripple.append((r.member, r.amplitude, omega, r.phase))
        t_out = kin.output_torque
        return cls(
            m_h=carrier.mass, m_p=n * planet.mass, J_ch=carrier.inertia, J_p=n * planet.inertia,
            J_cb=spec.members[ring_b].inertia, m_b=spec.members[ring_b].mass, r_h=stage.carrier_radius,
            r_f=mesh_e.planet_gear.pitch_radius, r_g=mesh_b.planet_gear.pitch_radius,
            r_b=mesh_b.central_gear.pitch_radius,
            c1=n * stiffness_model(mesh_e).mean, c2=n * stiffness_model(mesh_b).mean,
            k1=n * mesh_e.damping_coefficient, k2=n * mesh_b.damping_coefficient,
            input_torque=-t_out / kin.ratio if t_out else 0.0, output_torque=t_out,
            input_speed=spec.operating.input_speed, ripple=tuple(ripple), planet_sets=n, source=spec.name,
        )

    @property
    def ratio(self) -> float:
        """theta_h / theta_b of the rigid train (both meshes undeformed, y1 = 0)."""
        return self.r_b * self.r_f / (self.r_h * (self.r_f - self.r_g))


@dataclass(frozen=True)
class FourDofModel:
    """M q'' + B q' + C q = D(t) over q = (y1, theta_h, theta_f, theta_b)."""

    name: str
    params: PaperParameters
    M: np.ndarray
    B: np.ndarray
    C: np.ndarray
    labels: tuple = LABELS

    def D(self, t, load: bool = True) -> np.ndarray:
        """Generalized forces, Eq. 13: (0, M_h(t), 0, 0); with ``load`` also the output torque on
        theta_b (the paper's D has none)."""
        p = self.params
        t = np.asarray(t, dtype=float)
        m_h = np.full_like(t, p.input_torque)
        t_b = np.full_like(t, p.output_torque if load else 0.0)
        for member, amp, omega, phase in p.ripple:
            wave = amp * np.cos(omega * t + phase)
            if member == "input":
                m_h = m_h + p.input_torque * wave
            elif load:
                t_b = t_b + p.output_torque * wave
        out = np.zeros(t.shape + (4,))
        out[..., 1] = m_h
        out[..., 3] = t_b
        return out


def mesh_rows(p: PaperParameters) -> tuple[np.ndarray, np.ndarray]:
    """a1, a2 with Eq. 4's deflections y1 - u1 = a1 . q and y1 - u2 = a2 . q."""
    a1 = np.array([1.0, -(p.r_f + p.r_h), -p.r_f, 0.0])
    a2 = np.array([1.0, -(p.r_g + p.r_h), -p.r_g, p.r_b])
    return a1, a2


def as_published(p: PaperParameters) -> FourDofModel:
    """Eqs. 10, 11, 12 written out entry by entry as printed."""
    m_h, m_f_g, J_ch, J_fg, J_cb = p.m_h, p.m_p, p.J_ch, p.J_p, p.J_cb
    r_h, r_f, r_g, r_b = p.r_h, p.r_f, p.r_g, p.r_b
    c1, c2, k1, k2 = p.c1, p.c2, p.k1, p.k2
    # Eq. 10 (m_f + m_g and J_cf + J_cg always appear as sums)
    M = np.array([
        [m_h + m_f_g, 0.0, 0.0, 0.0],
        [0.0, m_h * r_h**2 + J_ch + m_f_g * r_h**2 + J_fg, J_fg, 0.0],
        [0.0, J_fg, J_fg, 0.0],
        [0.0, 0.0, 0.0, J_cb],
    ])
    # Eq. 11
    B = np.array([
        [k1 + k2, 0.0, 0.0, 0.0],
        [0.0, k1 * (r_f + r_h)**2 + k2 * (r_g + r_h)**2, k1 * r_f * (r_f + r_h) + k2 * r_g * (r_g + r_h),
         -(k2 * r_b * (r_g + r_h))],
        [0.0, k1 * (r_f**2 + r_f * r_h) + k2 * (r_g**2 + r_g * r_h), k1 * r_f**2 + k2 * r_g**2, -k2 * r_b * r_g],
        [0.0, -k2 * (r_b * r_g + r_b * r_h), -k2 * r_b * r_g, k2 * r_b**2],
    ])
    # Eq. 12
    C = np.array([
        [c1 + c2, 0.0, 0.0, 0.0],
        [0.0, c1 * (r_f + r_h)**2 + c2 * (r_g + r_h)**2, c1 * (r_f + r_h) * r_f + c2 * (r_g + r_h) * r_g,
         -(c2 * r_b * (r_g + r_h))],
        [0.0, c1 * (r_f**2 + r_f * r_h) + c2 * (r_g**2 + r_g * r_h), c1 * r_f**2 + c2 * r_g**2, -c2 * r_b * r_g],
        [0.0, -c2 * (r_b * r_g + r_b * r_h), -c2 * r_b * r_g, c2 * r_b**2],
    ])
    return FourDofModel("as-published", p, M, B, C)


def energy_derived(p: PaperParameters, carrier_on_axis: bool = False, collinear: bool = False,
                   name: str | None = None) -> FourDofModel:
    """Lagrange's equations of Eqs. 3-5: M = d2 E_k/dq'dq', B = d2 Phi/dq'dq', C = d2 E_p/dq dq.

    carrier_on_axis: drop m_h r_h^2 from M_22 (J_ch is about the carrier axis).
    collinear: the kinetic energy with y1 along the tangent at the planet (opposite to
    r_h theta_h), as Eq. 4 assumes: the planet's centre velocity is r_h th_h' - y1'.
    """
    a1, a2 = mesh_rows(p)
    C = p.c1 * np.outer(a1, a1) + p.c2 * np.outer(a2, a2)
    B = p.k1 * np.outer(a1, a1) + p.k2 * np.outer(a2, a2)
    m_all = p.m_h + p.m_p
    M = np.zeros((4, 4))
    M[0, 0] = m_all  # every body moves with y1 (Eq. 3)
    carrier_r2 = 0.0 if carrier_on_axis else p.m_h * p.r_h**2
    M[1, 1] = carrier_r2 + p.J_ch + p.m_p * p.r_h**2 + p.J_p
    M[1, 2] = M[2, 1] = M[2, 2] = p.J_p
    M[3, 3] = p.J_cb
    if collinear:
        # planet: 1/2 m_p (r_h th_h' - y1')^2; carrier (on its axis or at r_h): its centre moves y1'
        # (and r_h th_h' when placed at r_h, along the same tangent)
        M[0, 1] = M[1, 0] = -p.m_p * p.r_h - (0.0 if carrier_on_axis else p.m_h * p.r_h)
    if name is None:
        name = "consistent" if collinear else ("energy-derived-axis" if carrier_on_axis else "energy-derived")
    return FourDofModel(name, p, M, B, C)


def four_dof_model(source, model: str = "as-published", planet_sets: int = 1) -> FourDofModel:
    """The chosen 4-DOF model (``MODELS``) of a TrainSpec or PaperParameters."""
    p = source if isinstance(source, PaperParameters) else PaperParameters.from_spec(source, planet_sets)
    if model == "as-published":
        return as_published(p)
    if model == "energy-derived":
        return energy_derived(p)
    if model == "energy-derived-axis":
        return energy_derived(p, carrier_on_axis=True)
    if model == "consistent":
        return energy_derived(p, carrier_on_axis=True, collinear=True)
    raise GearcheckError(f"unknown 4-DOF model {model!r}; choose one of {', '.join(MODELS)}")


@dataclass(frozen=True)
class FourDofModes:
    model: str
    frequencies: np.ndarray  # Hz, ascending, rigid-body modes as 0
    shapes: np.ndarray  # columns, mass-normalised
    rigid: int  # number of rigid-body (zero-frequency) modes


def natural_frequencies(model: FourDofModel) -> FourDofModes:
    """Undamped modes of (C, M) (:func:`lumped.modal.generalized_modes`: rigid-body modes as 0 Hz)."""
    frequencies, shapes = generalized_modes(model.C, model.M)
    return FourDofModes(model.name, frequencies, shapes, int(np.sum(frequencies == 0)))


@dataclass
class FourDofResponse:
    model: str
    t: np.ndarray
    q: np.ndarray  # (n_t, 4)
    v: np.ndarray
    a: np.ndarray
    info: dict

    def acceleration(self, label: str) -> np.ndarray:
        return self.a[:, LABELS.index(label)]


def max_angular_frequency(model: FourDofModel) -> float:
    return float(2 * math.pi * natural_frequencies(model).frequencies.max())


def simulate(model: FourDofModel, duration: float, dt: float | None = None, load: bool = True,
             points_per_period: float = 40.0) -> FourDofResponse:
    """Start-stop regime: from rest (q = q' = 0) under D(t), fixed-step classical RK4.

    load: apply the output torque on theta_b with the mean input torque M_h = T_out/i, so the
    train's rigid rotation only sees the ripple (the paper's Eq. 13 has no load: load=False,
    then the whole train accelerates under M_h).  Either way the rigid-body modes are kept: the
    accelerations contain their (constant) part.  dt defaults to the shortest natural period
    over ``points_per_period``.
    """
    if duration <= 0:
        raise SolverError(f"duration must be > 0, got {duration}")
    if dt is None:
        dt = 2 * math.pi / max_angular_frequency(model) / points_per_period
    steps = int(math.ceil(duration / dt - 1e-9))
    Minv = np.linalg.inv(model.M)
    A_q, A_v = -Minv @ model.C, -Minv @ model.B

    def accel(t, q, v):
        return A_q @ q + A_v @ v + Minv @ model.D(t, load)

    t = np.arange(steps + 1) * dt
    q = np.zeros((steps + 1, 4))
    v = np.zeros((steps + 1, 4))
    a = np.zeros((steps + 1, 4))
    qi, vi = np.zeros(4), np.zeros(4)
    for i in range(steps):
        a[i] = accel(t[i], qi, vi)
        qi, vi = rk4_step(lambda s, q_, v_, ti=t[i]: accel(ti + 0.5 * s * dt, q_, v_), qi, vi, dt)
        q[i + 1], v[i + 1] = qi, vi
    a[-1] = accel(t[-1], qi, vi)
    if not np.all(np.isfinite(q)):
        raise SolverError(f"{model.name}: the RK4 integration diverged (dt = {dt:g} s)")
    return FourDofResponse(model.name, t, q, v, a, {"method": "rk4", "dt_s": dt, "steps": steps, "load": load})
