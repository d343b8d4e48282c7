"""The 4-DOF model of Matejic, Blagojevic & Matejic (2021), as published and as derived.

Matejic M. S., Blagojevic M. Z., Matejic M. M.: "Dynamic behaviour of a planetary reducer
with double planet gears", Mech. Sci. 12, 983-991, 2021.  Carrier h in (torque M_h), one
double planet (gears f, g on one body), ring e held (meshes f, stiffness c1, damping k1),
ring b movable (meshes g, c2, k2).  Coordinates q = (y1, theta_h, theta_f, theta_b): y1 the
planet set's displacement, theta_h the carrier angle, theta_f the planet's angle relative to
the carrier (its absolute angle is theta_h + theta_f, Eq. 3), theta_b the ring b angle.
The paper writes c for stiffness and k for damping; so does this module.

Models (``MODELS``), every one built from the same
:class:`~gearcheck.train.published_parameters.PaperParameters`:

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
  joints the potential energy describes (:mod:`gearcheck.mbd_models.published_twin`, y1 tangential).

``planet_sets``: the paper's model has one planet although the reducer has three.  With
``planet_sets=1`` (default, literal) one planet's mass, inertia and mesh values enter; with
``planet_sets=N`` the N planets are lumped in phase (planet mass, inertia, c and k times N).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.lumped.linear_model import LinearModel
from gearcheck.lumped.linear_run import linear_modes
from gearcheck.train.published_parameters import DESCRIPTIONS, LABELS, PaperParameters, check_model
from gearcheck.shared.modal import ModalResult

FINDING = (
    "Matejic et al. (2021) write the potential energy as 1/2 c1 (y1 - u1)^2 + 1/2 c2 (y1 - u2)^2 (Eq. 4), "
    "with u1, u2 the rotations' mesh displacements, and their equations of motion (Eqs. 6-9) keep the "
    "coupling of y1 with the rotations; but the printed stiffness and damping matrices (Eqs. 11-12) have "
    "zeros in row and column 1 off the diagonal. Taken literally, the as-published model hangs y1 on a "
    "spring c1 + c2 to the ground that no torque can excite (its y1 acceleration is identically zero), "
    "adds a spurious y1 mode and shifts the others. A MuJoCo twin built from the paper's own bodies and "
    "joints, with the mesh coefficients taken from MuJoCo's Jacobians, agrees with the model derived from "
    "Eqs. 3-5 with the coupling kept (energy-derived) to 1e-6 in every natural frequency, and with the "
    "as-published matrices in none above the rigid-body mode. Smaller defects: Eq. 8 carries a stray "
    "factor r_g in its k1 term, and Eq. 3 gives the carrier m_h r_h^2 on top of its CAD inertia J_ch "
    "(46 % more carrier inertia; the 'energy-derived-axis' model and twin put the carrier's mass on its "
    "axis)."
)


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
        m_h, t_b = self.params.torques(t, load)
        out = np.zeros(np.shape(m_h) + (4,))
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
    check_model(model)
    p = source if isinstance(source, PaperParameters) else PaperParameters.from_spec(source, planet_sets)
    if model == "as-published":
        return as_published(p)
    if model == "energy-derived":
        return energy_derived(p)
    if model == "energy-derived-axis":
        return energy_derived(p, carrier_on_axis=True)
    return energy_derived(p, carrier_on_axis=True, collinear=True)


def natural_frequencies(model: FourDofModel) -> ModalResult:
    """Undamped modes of (C, M), rigid-body modes as 0 Hz, typed rigid or elastic."""
    modal = linear_modes(linear_model(model))
    modal.train = model.params.source
    return modal


def linear_model(model: FourDofModel, load: bool = True) -> LinearModel:
    """The 4-DOF model as any user's model is given to gearcheck: M q'' + B q' + C q = D(t) from rest
    (start-stop regime), ``load``: the output torque on theta_b with the mean input torque
    M_h = T_out / i, so the train's rigid rotation only sees the ripple (the paper's Eq. 13 has no load:
    load=False, then the whole train accelerates under M_h).  The rigid-body modes are kept: the
    accelerations contain their (constant) part.  Its coordinates are the paper's, not the train's
    (an empty map): it is compared with the twin of its own idealisation."""
    return LinearModel(model.name, list(LABELS), model.M, model.C, C=model.B,
                       forcing=lambda t: model.D(t, load), physical={}, start="rest", descriptions=DESCRIPTIONS,
                       source=f"{model.params.source} ({model.name})")
