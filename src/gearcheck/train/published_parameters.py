"""The parameters of the 4-DOF model of Matejic, Blagojevic & Matejic (2021), read from a train.

Matejic M. S., Blagojevic M. Z., Matejic M. M.: "Dynamic behaviour of a planetary reducer with
double planet gears", Mech. Sci. 12, 983-991, 2021.  Carrier h in (torque M_h), one double
planet (gears f, g on one body), ring e held (meshes f, stiffness c1, damping k1), ring b movable
(meshes g, c2, k2).  Coordinates q = (y1, theta_h, theta_f, theta_b).  The paper writes c for
stiffness and k for damping; so does this module.

This is description, not equations: the lumped 4-DOF models (:mod:`gearcheck.lumped.published`)
and their MuJoCo twin (:mod:`gearcheck.mbd_models.published_twin`) are both built from it.

``KINEMATICS`` states, per model, the kinematics it claims, which its twin is built with: the
paper's y1 is radial in the kinetic energy (Eq. 3) and its carrier mass sits at the planet radius
r_h; ``energy-derived-axis`` puts the carrier's mass on its axis; ``consistent`` also takes y1 along
the tangent, as the potential energy (Eq. 4) assumes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gearcheck.train.excitation import Excitation
from gearcheck.train.kinematics import kinematics
from gearcheck.train.mesh_stiffness import stiffness_model
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.results import TimeResult, coordinate_signals

MODELS = ("as-published", "energy-derived", "energy-derived-axis", "consistent")
LABELS = ("y1", "theta_h", "theta_f", "theta_b")
KINEMATICS = {  # model -> (y1 direction, where the carrier's mass sits)
    "as-published": ("radial", "pitch"),
    "energy-derived": ("radial", "pitch"),
    "energy-derived-axis": ("radial", "axis"),
    "consistent": ("tangential", "axis"),
}


def check_model(model: str) -> None:
    if model not in MODELS:
        raise GearcheckError(f"unknown 4-DOF model {model!r}; choose one of {', '.join(MODELS)}")


@dataclass(frozen=True)
class PaperParameters:
    """Table 1 quantities of the paper, in SI, read from a :class:`~gearcheck.train.spec.TrainSpec`."""

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
    history: object = None  # the spec's operating history (gearcheck.train.history.History): M_h(t), T_b(t)

    @classmethod
    def from_spec(cls, spec, planet_sets: int = 1) -> "PaperParameters":
        """Read the paper's parameters from a one-stage, two-ring, compound-planet train.

        Ring e = the held ring, ring b = the output ring, carrier = the input; gears f and g are
        the planet gears those rings mesh with.  Mesh stiffness is the stiffness model's mean,
        mesh damping must be given as a coefficient (the paper's k1, k2).
        """
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
        return cls(
            m_h=carrier.mass, m_p=n * planet.mass, J_ch=carrier.inertia, J_p=n * planet.inertia,
            J_cb=spec.members[ring_b].inertia, m_b=spec.members[ring_b].mass, r_h=stage.carrier_radius,
            r_f=mesh_e.planet_gear.pitch_radius, r_g=mesh_b.planet_gear.pitch_radius,
            r_b=mesh_b.central_gear.pitch_radius,
            c1=n * stiffness_model(mesh_e).mean, c2=n * stiffness_model(mesh_b).mean,
            k1=n * mesh_e.damping_coefficient, k2=n * mesh_b.damping_coefficient,
            input_torque=kin.input_torque, output_torque=kin.output_torque,
            input_speed=spec.operating.input_speed, ripple=tuple(Excitation(spec, kin).ripple), planet_sets=n,
            source=spec.name, history=_torque_history(spec),
        )

    @property
    def ratio(self) -> float:
        """theta_h / theta_b of the rigid train (both meshes undeformed, y1 = 0)."""
        return self.r_b * self.r_f / (self.r_h * (self.r_f - self.r_g))

    def torques(self, t, load: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(M_h(t) on the carrier, T_b(t) on ring b), Eq. 13 with the spec's ripple; with ``load`` also the
        output torque on ring b with its ripple (the paper's D has none)."""
        t = np.asarray(t, dtype=float)
        m_h = np.full_like(t, self.input_torque)
        t_b = np.full_like(t, self.output_torque if load else 0.0)
        h = self.history
        for member, amp, omega, phase in self.ripple:
            if h is not None and (member == "input" or h.load is not None):
                continue  # a history's torques replace the mean torques and their ripple
            wave = amp * np.cos(omega * t + phase)
            if member == "input":
                m_h = m_h + self.input_torque * wave
            elif load:
                t_b = t_b + self.output_torque * wave
        if h is not None:
            m_h = h.torque(t)
            if h.load is not None:
                t_b = np.copysign(1.0, self.output_torque) * h.load(t) * load
        return m_h, t_b


def _torque_history(spec):
    """The spec's operating history, which must prescribe the torque: the 4-DOF models are driven by M_h (Eq. 13)."""
    history = spec.operating.history
    if history is not None and history.driven_by != "torque":
        raise GearcheckError(f"{spec.name}: the published 4-DOF models are driven by the carrier torque M_h "
                             "(Matejic et al. 2021, Eq. 13): give a torque history, not a speed history")
    return history


DESCRIPTIONS = {"y1": "planet-set displacement y1 (Matejic et al. 2021)", "theta_h": "carrier h angle",
                "theta_f": "planet angle relative to the carrier", "theta_b": "ring b angle"}


def four_dof_result(train: str, solver: str, model: str, t, q, v, a, info) -> TimeResult:
    """The named signals of a 4-DOF run (:func:`gearcheck.shared.results.coordinate_signals`) for
    q = (y1, theta_h, theta_f, theta_b), its velocity v and acceleration a, with time along axis 0.  The regime is
    a transient from rest: there is no steady window (settle time 0)."""
    columns = [x for j in range(len(LABELS)) for x in (a[:, j], q[:, j], v[:, j])]
    return TimeResult(train, solver, np.asarray(t), coordinate_signals(LABELS, DESCRIPTIONS, model),
                      np.column_stack(columns), 0.0, info)
