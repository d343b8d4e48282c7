"""A MuJoCo twin of the 4-DOF idealisation of Matejic, Blagojevic & Matejic (2021).

Built from bodies and joints, not from the paper's matrices (it uses the paper's parameter table,
:class:`gearcheck.train.published_parameters.PaperParameters`, never the 4-DOF models' M, B, C):

* ``carrier`` -- child of the world on the axis, hinge ``theta_h`` about z, then a slide
  ``y1`` (in the carrier's frame, so it turns with the carrier).  Mass m_h, polar inertia
  J_ch about its centre of mass, which sits on the axis (``carrier_mass="axis"``) or at the
  planet radius r_h (``"pitch"``, as Eq. 3 of the paper has it: m_h r_h^2 + J_ch);
* ``planet`` -- one double planet, child of the carrier at (r_h, 0), hinge ``theta_f`` (relative
  to the carrier), mass m_f + m_g, inertia J_cf + J_cg;
* ``ring_b`` -- child of the world, hinge ``theta_b``; ring e is the ground (no body);
* the two meshes are ``<fixed>`` tendons with stiffness c1, c2 and damping k1, k2.  Their joint
  coefficients are d . (J_planet(p) - J_ring(p)) from ``mujoco.mj_jac`` at the contact points
  p = (r_h + r_f, 0) (ring e) and (r_h + r_g, 0) (ring b) of a compiled skeleton, with d the
  mesh direction: the tangent y at the contact (the paper's deflections have no pressure angle).

The paper's y1 is ambiguous: "displacement ... in the radial direction" whose kinetic energy
(Eq. 3) has no cross term with r_h theta_h (radial), yet "collinear with the angular
displacements but in the opposite direction" in the potential energy (Eq. 4).  ``y1`` picks one:

* ``"tangential"`` -- the slide runs along -y (opposite to r_h theta_h), so the tangential
  projection gives the y1 coefficient -1 from the Jacobian itself.  A physical rigid-body
  system; its kinetic energy has the cross term -m r_h y1' theta_h'.
* ``"radial"`` -- the slide runs along +x (the paper's text and Eq. 3), and the mesh direction is
  d = y - x: tangential for the rotations (whose contact-point velocities are along y) and
  counting y1 along the line of action with coefficient -1, which is what Eq. 4 does.  Not a
  physical mesh direction: the paper's assumption made explicit.

Linearisation as in :mod:`gearcheck.mbd_models.linearise`: M from ``mj_fullM``, K from central
differences of ``qfrc_passive``, both at q = 0, at rest.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np

from gearcheck.train.published_parameters import LABELS, PaperParameters, four_dof_result
from gearcheck.shared.errors import DivergenceError
from gearcheck.shared.modal import ModalResult, modal_result
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import transient_step
from gearcheck.mbd_models.jacobians import rows_combined

FD_STEP = 1e-6
CONTACT_BODIES = {"e": ("planet", None), "b": ("planet", "ring_b")}


@dataclass
class PublishedTwin:
    params: PaperParameters
    y1: str
    carrier_mass: str
    xml: str
    model: mujoco.MjModel
    dof: dict  # label -> dof index
    coefficients: dict  # mesh ("e", "b") -> {label: coefficient}


def _inertial(mass: float, polar: float, pos=(0.0, 0.0, 0.0)) -> str:
    # a thin disc: Ixx = Iyy = Izz/2 satisfies the triangle inequality; only Izz matters (planar)
    return (f'<inertial pos="{pos[0]!r} {pos[1]!r} {pos[2]!r}" mass="{mass!r}" '
            f'diaginertia="{polar / 2!r} {polar / 2!r} {polar!r}"/>')


def _xml(p: PaperParameters, y1: str, carrier_mass: str, tendons: str = "") -> str:
    slide_axis = "0 -1 0" if y1 == "tangential" else "1 0 0"
    carrier_pos = (0.0, 0.0, 0.0) if carrier_mass == "axis" else (p.r_h, 0.0, 0.0)
    return f"""<mujoco model="matejic2021-4dof-{y1}-{carrier_mass}">
  <compiler angle="radian" autolimits="true"/>
  <option gravity="0 0 0" integrator="RK4" timestep="1e-6"/>
  <worldbody>
    <body name="carrier" pos="0 0 0">
      <joint name="theta_h" type="hinge" axis="0 0 1" pos="0 0 0"/>
      <joint name="y1" type="slide" axis="{slide_axis}" pos="0 0 0"/>
      {_inertial(p.m_h, p.J_ch, carrier_pos)}
      <body name="planet" pos="{p.r_h!r} 0 0">
        <joint name="theta_f" type="hinge" axis="0 0 1" pos="0 0 0"/>
        {_inertial(p.m_p, p.J_p)}
      </body>
    </body>
    <body name="ring_b" pos="0 0 0">
      <joint name="theta_b" type="hinge" axis="0 0 1" pos="0 0 0"/>
      {_inertial(p.m_b, p.J_cb)}
    </body>
  </worldbody>
{tendons}</mujoco>
"""


def _coefficients(model: mujoco.MjModel, p: PaperParameters, y1: str) -> dict:
    """d . (J_planet - J_ring) at each contact point, per joint, from mj_jac at q = 0."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    d = np.array([0.0, 1.0, 0.0]) if y1 == "tangential" else np.array([-1.0, 1.0, 0.0])
    out = {}
    for mesh, radius in (("e", p.r_h + p.r_f), ("b", p.r_h + p.r_g)):
        point = np.array([radius, 0.0, 0.0])
        row = np.zeros(model.nv)
        for body, sign in ((CONTACT_BODIES[mesh][0], 1.0), (CONTACT_BODIES[mesh][1], -1.0)):
            if body is None:  # ring e: the ground
                continue
            jacp = np.zeros((3, model.nv))
            mujoco.mj_jac(model, data, jacp, None, point, mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body))
            row += sign * rows_combined(d, jacp)
        out[mesh] = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, int(model.dof_jntid[i])): float(row[i])
                     for i in range(model.nv) if abs(row[i]) > 1e-15}
    return out


def build_twin(params: PaperParameters, y1: str = "radial", carrier_mass: str = "pitch") -> PublishedTwin:
    """Compile the twin.  Defaults: the paper's own kinematics (Eq. 3 as printed)."""
    if y1 not in ("radial", "tangential"):
        raise ValueError(f"y1 must be 'radial' or 'tangential', got {y1!r}")
    if carrier_mass not in ("axis", "pitch"):
        raise ValueError(f"carrier_mass must be 'axis' or 'pitch', got {carrier_mass!r}")
    skeleton = mujoco.MjModel.from_xml_string(_xml(params, y1, carrier_mass))
    coefs = _coefficients(skeleton, params, y1)
    lines = ["  <tendon>"]
    for mesh, (k, c) in (("e", (params.c1, params.k1)), ("b", (params.c2, params.k2))):
        lines.append(f'    <fixed name="mesh_{mesh}" stiffness="{k!r}" damping="{c!r}" springlength="0">')
        for joint, coef in coefs[mesh].items():
            lines.append(f'      <joint joint="{joint}" coef="{coef!r}"/>')
        lines.append("    </fixed>")
    lines.append("  </tendon>\n")
    xml = _xml(params, y1, carrier_mass, "\n".join(lines))
    model = mujoco.MjModel.from_xml_string(xml)
    dof = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, int(model.dof_jntid[i])): i for i in range(model.nv)}
    return PublishedTwin(params, y1, carrier_mass, xml, model, dof, coefs)


def _order(twin: PublishedTwin) -> list[int]:
    return [twin.dof[label] for label in LABELS]


def linearise(twin: PublishedTwin) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, K, C) at q = 0 over (y1, theta_h, theta_f, theta_b): mj_fullM and central differences of
    qfrc_passive in qpos (K) and in qvel (C)."""
    m = twin.model
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    K = np.zeros((m.nv, m.nv))
    Cd = np.zeros((m.nv, m.nv))
    for j in range(m.nv):
        for target, store in (("qpos", K), ("qvel", Cd)):
            forces = []
            for sign in (1.0, -1.0):
                d.qpos[:] = 0.0
                d.qvel[:] = 0.0
                getattr(d, target)[j] = sign * FD_STEP
                mujoco.mj_forward(m, d)
                forces.append(d.qfrc_passive.copy())
            store[:, j] = -(forces[0] - forces[1]) / (2 * FD_STEP)
    idx = _order(twin)
    sel = np.ix_(idx, idx)
    return M[sel], 0.5 * (K + K.T)[sel], 0.5 * (Cd + Cd.T)[sel]


def twin_modes(twin: PublishedTwin) -> ModalResult:
    """Natural frequencies (Hz, rigid-body modes as 0) of the linearised twin, typed rigid or elastic."""
    M, K, _ = linearise(twin)
    return modal_result(twin.params.source, "mujoco", K, M, LABELS)


def simulate_twin(twin: PublishedTwin, settings: RunSettings, model: str, load: bool = True):
    """From rest, MuJoCo's RK4 at the step ``settings.dt`` (default: the twin's own
    :func:`~gearcheck.shared.stepping.transient_step`); the paper's torques (M_h, T_b)
    (:meth:`~gearcheck.train.published_parameters.PaperParameters.torques`) applied as qfrc_applied on
    theta_h and theta_b, held over each step.  Records qpos, qvel and qacc of every state (after mj_forward);
    ``model`` names the 4-DOF model whose kinematics the twin has (for the signals' descriptions)."""
    m = twin.model
    dt = transient_step(twin_modes(twin).frequencies) if settings.dt is None else settings.dt
    m.opt.timestep = dt
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(m)
    steps, _ = settings.grid(dt)
    idx = _order(twin)
    ih, ib = twin.dof["theta_h"], twin.dof["theta_b"]
    t = np.arange(steps + 1) * dt
    m_h, t_b = twin.params.torques(t, load)
    q, v, a = (np.zeros((steps + 1, 4)) for _ in range(3))
    started = time.perf_counter()
    for i in range(steps + 1):
        d.qfrc_applied[:] = 0.0
        d.qfrc_applied[ih] = m_h[i]
        d.qfrc_applied[ib] = t_b[i]
        mujoco.mj_forward(m, d)
        q[i], v[i], a[i] = d.qpos[idx], d.qvel[idx], d.qacc[idx]
        if i < steps:
            mujoco.mj_step(m, d)
    if not np.all(np.isfinite(q)):
        raise DivergenceError(float(t[np.argmax(~np.isfinite(q).all(axis=1))]), "the MuJoCo 4-DOF twin")
    wall = time.perf_counter() - started
    info = RunInfo("mujoco-step", steps, 4, 5 * steps, wall,  # the sampling mj_forward, then mj_step's own and RK4's 3
                   {"method": "mujoco-rk4", "integrator": "RK4", "dt_s": dt, "steps": steps, "y1": twin.y1,
                    "carrier_mass": twin.carrier_mass, "mujoco_version": mujoco.__version__})
    return four_dof_result(twin.params.source, "mujoco", model, t, q, v, a, info)
