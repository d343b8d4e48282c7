"""An RV reducer's cycloid-pin stage in the twin's MJCF (Yang, Chen & Wang 2018).

Each crankshaft rides on the carrier at its planet's place like a planet (its bearing on the carrier pin; the
builder writes it with the stage's pin members) and carries one eccentric-centre site per disc; each disc is a
child of the world in polar joints about the stage axis (``_orbit`` hinge, ``_radial`` slide, ``_rz`` hinge about
its centre) with one bore-centre site per crank; the pins are sites of the world (or of the pin wheel, a central
member on its support); each needle bearing is a pair of site actuators between an eccentric's and a bore's centre,
each pin contact a compression-only fixed tendon over the disc's (and the pin wheel's) joints, whose coefficients
the runner sets every step (:class:`CycloidTwin`, the contacts at run time).  In the discs' polar joints the rigid
mechanism's motion -- the disc orbiting at the cranks' speed w_H while it turns with the carrier -- is linear in
time; MuJoCo carries the orbits' centrifugal loads itself.

Needle bearings are MuJoCo's own exact spring-dampers (site actuators, see the builder).  Pin contacts are
fixed tendons, compression only by a dead band, whose coefficients and spring lengths :meth:`CycloidTwin.refresh`
sets from the twin's own poses before every step (Yang, Chen & Wang 2018 write the same contacts in the carrier
frame):

* the disc's conjugate eccentric angle phi* = phase + w - Z_c (theta - w), theta the disc's rotation and w the
  pin wheel's (the disc rolls its pitch circle Z_c e inside the wheel's, Z_p e), places the pitch point
  P = O + Z_p e e(phi*) and the conjugate centre c* = O + e e(phi*), O the wheel's centre;
* pin i's normal n_i runs from P to its centre C_i (Willis), its compression is delta_i = n_i . (c - c*) - g
  (c the disc's centre, g the clearance), and its tendon coefficients are n_i . (J_disc(P) - J_wheel(P)) from
  ``mj_jac``; the upper edge of the dead band is the tendon length less delta_i, so MuJoCo's spring force is
  k max(delta_i, 0); the contact damping is on while the pin touches.

The coefficients are those of d delta_i / dq on the conjugate family, and the rigid mechanism rolls the disc
about P, so every coefficient row is orthogonal to its motion: with that motion linear in the joints, the
rigid orbit never shows as a deflection within a step either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import mujoco
import numba
import numpy as np

from gearcheck.mbd_models import gear_visuals
from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element, compiled_group
from gearcheck.mbd_models.mjcf_text import (
    LATE,
    RGBA,
    VISUAL,
    central_body,
    cylinder,
    fixed,
    gear_z,
    inertial,
    joint,
    marker,
    member_joints,
    plate,
    site,
    vec,
)
from gearcheck.shared.compiled_cache import ensure_cache_folder
from gearcheck.shared.results import Signal, TimeResult

ensure_cache_folder(Path(__file__).parent)  # before the cached kernels below are defined
PIN_BAND = 1.0  # m: a pin tendon's dead band reaches this far below contact (compression only)
HEADER = [
    "Cycloid pin contacts are compression-only fixed tendons (length = compression) with the coefficients of",
    "t = 0 and no damping here (the runner follows the discs every step and damps a pin while it touches);",
    "needle bearings are site actuators with an affine spring-damper bias.",
]


def disc_z(spec, cyc) -> list[float]:
    """Axial offset (m, from the stage) of each cycloid disc's mid-plane: side by side behind the carrier's plate
    (visual only: the model is planar, and every point of a needle bearing or pin contact lies in its disc's
    plane)."""
    zc, h, _ = plate(spec, spec.stage_of(cyc.cranks[0]), gear_z(spec))
    t = cyc.geometry.contact_length
    return [zc - h - t * (1.0 + 1.5 * j) for j in range(len(cyc.discs))]


def eccentric_site(crank, j: int) -> str:
    return f"{crank.label}_eccentric{j + 1}"


def bore_site(disc, k: int) -> str:
    return f"{disc.label}_bore{k + 1}"


def pin_site(stage, i: int) -> str:
    return f"{stage.name}_pin{i + 1}"


def pin_tendon(disc, i: int) -> str:
    return f"{disc.label}_pin{i + 1}"


def needle_actuator(crank, disc, axis: str) -> str:
    """Named as the reference model names the needle bearing's rows (``stage.crankK.discJ.needle_x``)."""
    return f"{crank.label}_{disc.label.rsplit('_', 1)[1]}_needle_{axis}"


def profile_mesh(stage) -> str:
    return f"{stage.name}_disc_profile"


def pin_list(spec) -> list[tuple]:
    """(cycloid-pin stage, disc member, pin index) of every pin contact, in the order of their tendons."""
    return [(cyc, spec.members[disc], i) for cyc in spec.cycloids for disc in cyc.discs
            for i in range(cyc.geometry.pins)]


def pin_joints(spec, cyc, disc) -> list[str]:
    """The joints that move a pin contact: the disc's and the pin wheel's (when it is a body)."""
    wheel = cyc.pin_wheel
    joints = [f"{disc.label}_{a}" for a in member_joints(disc)]
    return joints + ([f"{spec.members[wheel].label}_{a}" for a in member_joints(spec.members[wheel])] if wheel else [])


@ELEMENTS.register("cycloid")
class Cycloid(Element):
    def contacts(self, spec, model) -> "CycloidTwin":
        return CycloidTwin(spec, model)

    def header(self, cyc) -> list[str]:
        return HEADER

    def assets(self, cyc, spec) -> list[str]:
        return [f"    {gear_visuals.disc_asset(profile_mesh(spec.stage_of(cyc.cranks[0])), cyc.geometry)}"]

    def bore(self, cyc, stage) -> float:
        """Inside the pins, which show round the carrier."""
        return cyc.geometry.pin_circle_radius - cyc.geometry.pin_radius if stage.name == cyc.stage else math.inf

    def reach(self, cyc) -> list[float]:
        return [cyc.geometry.pin_circle_radius + cyc.geometry.pin_radius]

    def sites(self, cyc, spec, member) -> list[str]:
        """The points of the stage's bearings on a member: a crankshaft's eccentric centres (each in its disc's
        plane, at e along the disc's phase), a disc's bore centres (at the cranks' places)."""
        if member.id in cyc.cranks:
            e = cyc.geometry.eccentricity
            return [site(eccentric_site(member, j), (e * math.cos(phase), e * math.sin(phase), z))
                    for j, (phase, z) in enumerate(zip(cyc.phases, disc_z(spec, cyc)))]
        if member.id in cyc.discs:
            radius = spec.stage_of(member.id).carrier_radius
            places = [spec.members[c].angle for c in cyc.cranks]
            return [site(bore_site(member, k), (radius * math.cos(psi), radius * math.sin(psi), 0.0))
                    for k, psi in enumerate(places)]
        return []

    def visuals(self, cyc, spec, member) -> list[str] | None:
        if member.id in cyc.cranks:
            return _crank_geoms(spec, cyc, member)
        if member.id in cyc.discs:
            return _disc_geoms(spec, cyc, member)
        if member.id == cyc.pin_wheel:
            g = cyc.geometry
            return [marker(member, g.pin_circle_radius + 2 * g.pin_radius, 0.0, g.pin_radius)]
        return None

    def bodies(self, cyc, spec, z_stage: float, visuals: bool, inner, springs: dict) -> list[str]:
        """The discs and the pin wheel (a central member on its support, or its pins on the world)."""
        lines = []
        for disc, z in zip(cyc.discs, disc_z(spec, cyc)):
            lines += _disc_body(cyc, spec.members[disc], z_stage + z, "    ", inner(spec.members[disc]))
        if cyc.pin_wheel:
            wheel = spec.members[cyc.pin_wheel]
            return lines + central_body(wheel, springs, z_stage, "    ", _pins(spec, cyc, 0.0, visuals) + inner(wheel),
                                        [])
        return lines + [f"    {line}" for line in _pins(spec, cyc, z_stage, visuals)]

    def tendons(self, cyc, spec) -> list[str]:
        """One fixed tendon per pin and disc (:func:`pin_list` order): its length is the pin's compression plus
        its spring length's upper edge; the dead band from there down by ``PIN_BAND`` makes it compression only.
        Its coefficients and spring length are late numbers (those of t = 0, :meth:`CycloidTwin.written`).  No
        damping here: the runner turns the contact damping on while the pin touches."""
        lines = []
        k = cyc.pin_stiffness(spec.operating.output_torque)
        for disc in cyc.discs:
            disc = spec.members[disc]
            for i in range(cyc.geometry.pins):
                lines += fixed(pin_tendon(disc, i), [(j, LATE) for j in pin_joints(spec, cyc, disc)], k, 0.0, LATE)
        return lines

    def actuators(self, cyc, spec) -> list[str]:
        """Every needle bearing as two ``general`` actuators with a site transmission from the eccentric's centre
        relative to the bore's (its x, y components in the bore's frame) and an affine bias -k L - c L': MuJoCo's
        isotropic spring-damper between the two points, exact at every evaluation."""
        lines = []
        n = cyc.needle
        for crank, disc, j, k in _needles(spec, cyc):
            for axis, gear in (("x", "1 0 0 0 0 0"), ("y", "0 1 0 0 0 0")):
                lines.append(f'    <general name="{needle_actuator(crank, disc, axis)}" '
                             f'site="{eccentric_site(crank, j)}" refsite="{bore_site(disc, k)}" gear="{gear}" '
                             f'gainprm="0" biastype="affine" '
                             f'biasprm="{vec(0, -n.radial_stiffness, -n.radial_damping)}" '
                             'ctrllimited="false" forcelimited="false"/>')
        return lines

    def sensors(self, cyc, spec) -> list[str]:
        lines = []
        for crank, disc, _, _ in _needles(spec, cyc):
            for axis in "xy":
                name = needle_actuator(crank, disc, axis)
                lines.append(f'    <actuatorfrc name="{name}_force" actuator="{name}"/>')
        return lines


def _needles(spec, cyc) -> list[tuple]:
    """(crank member, disc member, eccentric j, crank k) of every needle bearing of ``cyc``."""
    return [(spec.members[crank], spec.members[disc], j, k) for j, disc in enumerate(cyc.discs)
            for k, crank in enumerate(cyc.cranks)]


def _crank_geoms(spec, cyc, crank) -> list[str]:
    """A crankshaft's shaft and eccentrics, and a marker."""
    zs, stage = disc_z(spec, cyc), spec.stage_of(crank.id)
    e, t, shaft = cyc.geometry.eccentricity, cyc.geometry.contact_length, 0.2 * stage.carrier_radius
    lines = [cylinder(f"{crank.label}_shaft", "crank", shaft, (0, 0, 0), (0, 0, zs[-1] - 0.5 * t))]
    for j, (phase, z) in enumerate(zip(cyc.phases, zs)):
        centre = (e * math.cos(phase), e * math.sin(phase))
        lines.append(cylinder(f"{crank.label}_eccentric{j + 1}_visual", "crank", shaft + e, (*centre, z - 0.45 * t),
                              (*centre, z + 0.45 * t)))
    return lines + [marker(crank, shaft, zs[-1] - 0.5 * t, 0.25 * shaft)]


def _disc_geoms(spec, cyc, disc) -> list[str]:
    """A cycloid disc's profile at the conjugate pose of its eccentric's phase (the profile's frame turned by
    -phase/Z_c), and a marker."""
    phase = cyc.phases[cyc.discs.index(disc.id)]
    r = cyc.geometry.pin_circle_radius - cyc.geometry.pin_radius - 2 * cyc.geometry.eccentricity
    return [f'<geom name="{disc.label}_visual" type="mesh" mesh="{profile_mesh(spec.stage_of(disc.id))}" '
            f'euler="{vec(0, 0, -phase / cyc.geometry.lobes)}" rgba="{RGBA["disc"]}" {VISUAL}/>',
            marker(disc, 0.9 * r, 0.5 * cyc.geometry.contact_length, 0.01 * r)]


def _pins(spec, cyc, z: float, visuals: bool) -> list[str]:
    """The pins' centre sites (and cylinders), at the offset ``z`` of their body (the pin wheel or the world)."""
    g, zs, stage = cyc.geometry, disc_z(spec, cyc), spec.stage_of(cyc.cranks[0])
    half = 0.5 * abs(zs[-1] - zs[0]) + 0.5 * g.contact_length
    mid = z + 0.5 * (zs[0] + zs[-1])
    kind = "pin_wheel" if cyc.pin_wheel else "ring"
    lines = []
    for i in range(g.pins):
        angle = 2 * math.pi * i / g.pins
        x, y = g.pin_circle_radius * math.cos(angle), g.pin_circle_radius * math.sin(angle)
        lines.append(site(pin_site(stage, i), (x, y, mid)))
        if visuals:
            lines.append(cylinder(f"{pin_site(stage, i)}_visual", kind, g.pin_radius, (x, y, mid - half),
                                  (x, y, mid + half)))
    return lines


def _disc_body(cyc, disc, z: float, indent: str, inner: list[str]) -> list[str]:
    """A cycloid disc, a free planar body in polar joints about the stage axis: ``_orbit`` (a hinge on the axis),
    ``_radial`` (a slide along its eccentric), ``_rz`` (a hinge about its centre; its rotation is the sum of the
    two hinges').  Its nominal motion, the orbit at the cranks' speed while it turns with the carrier, is linear
    in time in these joints; its centre starts on its eccentric, at e along the eccentric's phase."""
    e, phase = cyc.geometry.eccentricity, cyc.phases[cyc.discs.index(disc.id)]
    c, s = math.cos(phase), math.sin(phase)
    orbit, radial, rotation = member_joints(disc)
    lines = [f'{indent}<body name="{disc.label}" pos="{vec(e * c, e * s, z)}">', f"{indent}  {inertial(disc)}"]
    lines += [f"{indent}  {joint(f'{disc.label}_{orbit}', 'hinge', (0, 0, 1), pos=(-e * c, -e * s, 0))}",
              f"{indent}  {joint(f'{disc.label}_{radial}', 'slide', (c, s, 0))}",
              f"{indent}  {joint(f'{disc.label}_{rotation}', 'hinge', (0, 0, 1))}"]
    return lines + [f"{indent}  {g}" for g in inner] + [f"{indent}</body>"]


ORIGIN = np.zeros(3)  # the stage axis, where a fixed pin wheel's centre lies


@dataclass(frozen=True)
class _Stage:
    """One cycloid-pin stage's pins in the compiled model, arrays over its discs (the order of its tendons)."""

    rows: slice  # its pin tendons among all
    bodies: np.ndarray  # (N,) disc body ids
    wheel: int  # the pin wheel's body id, -1: the pins are on the world
    phases: np.ndarray  # (N,)
    lobes: int
    eccentricity: float
    pitch_radius: float  # Z_p e
    sites: np.ndarray  # (Z_p,) pin site ids
    dofs: np.ndarray  # (N, n) the dofs of each disc's tendons' joints (the disc's, then the wheel's)
    qadr: np.ndarray  # (N, n) their qpos addresses
    wraps: np.ndarray  # (N, Z_p, n) indices into wrap_prm
    jacobian: np.ndarray  # (N, 2, n) work space: J_disc(P) - J_wheel(P) on those dofs


# ------------------------------------------------------------------------- the compiled runner's group
class Pins(NamedTuple):
    """Per pin tendon (in its rows' order): tendon, stiffness, damping, clearance, pin site, ``wrap_prm`` entries."""

    tendons: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    clearance: np.ndarray
    site: np.ndarray
    wraps: np.ndarray


class Discs(NamedTuple):
    """Per cycloid disc: body, pin wheel (-1: none), phase, lobes, eccentricity, pitch radius, first pin row, pins,
    and its tendons' dofs (their number, and the dofs and qpos addresses, padded)."""

    body: np.ndarray
    wheel: np.ndarray
    phase: np.ndarray
    lobes: np.ndarray
    eccentricity: np.ndarray
    pitch_radius: np.ndarray
    first: np.ndarray
    count: np.ndarray
    ndof: np.ndarray
    dofs: np.ndarray
    qadr: np.ndarray


class PinWork(NamedTuple):
    """Work space of the pin contacts: a Jacobian, the contact point, G, each row's compression, length and rate
    of length (its coefficients held)."""

    jacobian: np.ndarray
    point: np.ndarray
    G: np.ndarray
    delta: np.ndarray
    length: np.ndarray
    speed: np.ndarray


class CompiledPins(NamedTuple):
    """An RV reducer's pin contacts as the compiled runner takes them (:meth:`of`)."""

    pins: Pins
    discs: Discs
    work: PinWork

    @classmethod
    def of(cls, contacts, nv: int) -> "CompiledPins":
        """The twin's pin contacts (its ``CycloidTwin``, or none: empty arrays of the same types) as flat arrays for
        :func:`refresh_pins`, every contact's tendons in their order."""
        rows, discs, stages, offset = [], [], [], 0
        for c in contacts:  # each contact's stages, with where its tendons start among all
            stages += [(g, offset) for g in c.stages]
            offset += len(c.tendons)
        width = max([g.dofs.shape[1] for g, _ in stages], default=6)
        for g, offset in stages:
            for i, body in enumerate(g.bodies):
                first = offset + g.rows.start + i * len(g.sites)
                dofs, qadr = np.full(width, -1), np.full(width, -1)
                dofs[:g.dofs.shape[1]], qadr[:g.dofs.shape[1]] = g.dofs[i], g.qadr[i]
                discs.append((body, g.wheel, g.phases[i], g.lobes, g.eccentricity, g.pitch_radius, first,
                              len(g.sites), g.dofs.shape[1], dofs, qadr))
                for p, pin_site in enumerate(g.sites):
                    wraps = np.full(width, -1)
                    wraps[:g.dofs.shape[1]] = g.wraps[i, p]
                    rows.append((pin_site, wraps))
        i64, f64 = np.int64, np.float64
        n_pins = len(rows)

        def joined(name: str, kind) -> np.ndarray:
            return np.concatenate([np.asarray(getattr(c, name), dtype=kind) for c in contacts] + [np.zeros(0, kind)])

        pins = Pins(joined("tendons", i64), joined("stiffness", f64), joined("damping", f64), joined("clearance", f64),
                    np.array([r[0] for r in rows], dtype=i64),
                    np.array([r[1] for r in rows], dtype=i64).reshape(n_pins, width))
        columns = list(zip(*discs)) if discs else [[]] * 11
        types = (i64, i64, f64, f64, f64, f64, i64, i64, i64, i64, i64)
        disc = tuple(np.array(column, dtype=kind) for column, kind in zip(columns, types))
        disc = Discs(*disc[:9], *(x.reshape(len(discs), width) for x in disc[9:]))
        work = PinWork(np.zeros((3, nv)), np.zeros(3), np.zeros((2, width)), np.zeros(n_pins), np.zeros(n_pins),
                       np.zeros(n_pins))
        return cls(pins, disc, work)


class CycloidTwin:
    """The pin contacts and needle bearings of a compiled twin's cycloid-pin stages."""

    compiled = CompiledPins

    def __init__(self, spec, model: mujoco.MjModel):
        m, self.spec, self.model = model, spec, model
        pins = pin_list(spec)
        T, B, S, J, A = (mujoco.mjtObj.mjOBJ_TENDON, mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_SITE,
                         mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_ACTUATOR)
        self.names = [f"{disc.id}.pin{i + 1}" for _, disc, i in pins]
        self.tendons = np.array([mujoco.mj_name2id(m, T, pin_tendon(disc, i)) for _, disc, i in pins], dtype=int)
        torque = spec.operating.output_torque
        self.stiffness = np.array([cyc.pin_stiffness(torque) for cyc, _, _ in pins])
        self.damping = np.array([cyc.contact_damping for cyc, _, _ in pins])
        self.clearance = np.array([cyc.clearance for cyc, _, _ in pins])
        self.stages = []
        row = 0
        for cyc in spec.cycloids:
            stage, g, discs = spec.stage_of(cyc.cranks[0]), cyc.geometry, [spec.members[disc] for disc in cyc.discs]
            rows = slice(row, row + g.pins * len(discs))
            joints = np.array([[mujoco.mj_name2id(m, J, name) for name in pin_joints(spec, cyc, disc)]
                               for disc in discs])
            tendons = self.tendons[rows].reshape(len(discs), g.pins)
            wraps = m.tendon_adr[tendons][..., None] + np.arange(joints.shape[1])
            assert np.array_equal(m.wrap_objid[wraps], np.broadcast_to(joints[:, None, :], wraps.shape))
            self.stages.append(_Stage(
                rows, np.array([mujoco.mj_name2id(m, B, disc.label) for disc in discs]),
                mujoco.mj_name2id(m, B, spec.members[cyc.pin_wheel].label) if cyc.pin_wheel else -1,
                np.array(cyc.phases), g.lobes, g.eccentricity, g.pitch_radius,
                np.array([mujoco.mj_name2id(m, S, pin_site(stage, i)) for i in range(g.pins)]),
                m.jnt_dofadr[joints], m.jnt_qposadr[joints], wraps, np.empty((len(discs), 2, joints.shape[1]))))
            row = rows.stop
        needles = [needle for cyc in spec.cycloids for needle in _needles(spec, cyc)]
        self.needle_names = [f"{crank.id}.{disc.id.split('.')[-1]}.needle" for crank, disc, _, _ in needles]
        self.needles = np.array([[mujoco.mj_name2id(m, A, needle_actuator(crank, disc, axis)) for axis in "xy"]
                                 for crank, disc, _, _ in needles], dtype=int)
        self.contacts = np.ones(len(self.tendons), dtype=bool)  # the static contact set at t = 0, once solved
        self._jac = np.zeros((3, m.nv))
        n = len(self.tendons)
        self._delta, self._length, self._band = np.empty(n), np.empty(n), np.empty((n, 2))
        self.speed = np.empty(n)  # each pin tendon's rate of length at the last refresh, its coefficients held

    def refresh(self, d: mujoco.MjData, touching: np.ndarray | None = None, gaps: bool = True) -> np.ndarray:
        """Coefficients, spring lengths, stiffness and damping of every pin tendon at ``d.qpos`` (its kinematics
        computed here); returns the compressions delta_i (m).  ``touching`` None: compression only, damped while
        touching (a run); else linear springs, damped, on the pins ``touching`` and none on the others (the
        static contact set: the static solution, the linearisation).  ``gaps`` False: without the clearance."""
        m, jac = self.model, self._jac
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        delta, length = self._delta, self._length
        xpos, xmat, qpos = d.xpos, d.xmat, d.qpos
        for g in self.stages:
            c = xpos[g.bodies]
            if g.wheel >= 0:
                centre, w = xpos[g.wheel], math.atan2(xmat[g.wheel, 3], xmat[g.wheel, 0])
            else:
                centre, w = ORIGIN, 0.0
            rotation = xmat[g.bodies]
            phi = g.phases + (1 + g.lobes) * w - g.lobes * np.arctan2(rotation[:, 3], rotation[:, 0])
            u = np.array([np.cos(phi), np.sin(phi)]).T
            pitch = c.copy()
            pitch[:, :2] = centre[:2] + g.pitch_radius * u
            n = d.site_xpos[g.sites, :2] - pitch[:, None, :2]
            n /= np.sqrt((n * n).sum(axis=2))[..., None]
            delta[g.rows] = (n @ (c[:, :2] - centre[:2] - g.eccentricity * u)[..., None]).ravel()
            for i, (body, point, dofs) in enumerate(zip(g.bodies, pitch, g.dofs)):
                mujoco.mj_jac(m, d, jac, None, point, body)
                g.jacobian[i] = jac[:2, dofs]
                if g.wheel >= 0:
                    mujoco.mj_jac(m, d, jac, None, point, g.wheel)
                    g.jacobian[i] -= jac[:2, dofs]
            coef = n @ g.jacobian
            m.wrap_prm[g.wraps] = coef
            length[g.rows] = (coef @ qpos[g.qadr][..., None]).ravel()
            self.speed[g.rows] = (coef @ d.qvel[g.dofs][..., None]).ravel()
        if gaps:
            delta -= self.clearance
        t, band = self.tendons, self._band
        band[:, 1] = length - delta
        if touching is None:
            band[:, 0] = band[:, 1] - PIN_BAND
            m.tendon_stiffness[t] = self.stiffness
            m.tendon_damping[t] = self.damping * (delta > 0.0)
        else:
            band[:, 0] = band[:, 1]
            m.tendon_stiffness[t] = self.stiffness * touching
            m.tendon_damping[t] = self.damping * touching
        m.tendon_lengthspring[t] = band
        return delta.copy()

    def freeze(self, d: mujoco.MjData, every: bool = False) -> None:
        """The pins as linear springs at ``d.qpos`` on the static contact set of t = 0 (or on every pin: the
        stiffest the twin can be), their coefficients MuJoCo's Jacobians there (the linearisation)."""
        self.refresh(d, np.ones_like(self.contacts) if every else self.contacts)

    def undamp(self) -> None:
        """The pins' and the needle bearings' damping off in the model (the undamped modes)."""
        self.model.tendon_damping[self.tendons] = 0.0
        self.model.actuator_biasprm[self.needles.ravel(), 2] = 0.0

    def written(self) -> tuple[dict, dict]:
        """The coefficients [(joint, coefficient)] and spring lengths of its tendons as the model holds them, by
        tendon name (what the model's file writes)."""
        m, spec = self.model, self.spec
        coefficients, bands = {}, {}
        for (cyc, disc, i), t in zip(pin_list(spec), self.tendons):
            coefficients[pin_tendon(disc, i)] = [(name, float(m.wrap_prm[m.tendon_adr[t] + w]))
                                                 for w, name in enumerate(pin_joints(spec, cyc, disc))]
            bands[pin_tendon(disc, i)] = tuple(m.tendon_lengthspring[t])
        return coefficients, bands

    def per_disc(self, forces: np.ndarray) -> np.ndarray:
        """(n_t, discs, Z_p) of the pins' forces (n_t, tendons), disc by disc."""
        return np.concatenate([forces[:, g.rows].reshape(len(forces), len(g.bodies), -1) for g in self.stages],
                              axis=1)

    def with_signals(self, result: TimeResult, forces: np.ndarray, series, static_forces: np.ndarray) -> TimeResult:
        """``result`` with every pin contact force ``STAGE.discJ.pinI.force`` (the load distribution) and the needle
        bearings' forces ``STAGE.crankK.discJ.needle_x.force`` and ``..._y`` (the spring-damper force from the bore
        to the eccentric, along the bore's axes, which turn with the disc: the carrier's up to the disc's
        vibration), named as the reference model names their rows; reported, not gated.  ``series(name)``: a
        sensor's samples."""
        signals = [Signal(f"{name}.force", "pin_force", "N", f"{name} contact force", False) for name in self.names]
        columns = list(forces.T)
        for name, actuators in zip(self.needle_names, self.needles):
            for axis, actuator in zip("xy", actuators):
                label = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, int(actuator))
                signals.append(Signal(f"{name}_{axis}.force", "bearing_force", "N", f"{name} force along {axis}",
                                      False))
                columns.append(-series(f"{label}_force")[:, 0])
        static_values = {f"{name}.force": float(f) for name, f in zip(self.names, static_forces)}
        return TimeResult(result.train, result.solver, result.t, result.signals + signals,
                          np.column_stack([result.values] + columns), result.settle_time, result.info, result.raw,
                          {**result.static, **static_values})

    def pin_forces(self, d: mujoco.MjData) -> np.ndarray:
        """Every pin's contact force (N, >= 0 apart from damping), as MuJoCo's tendons carry it after
        ``mj_forward``: k (L - L_top) above the dead band's upper edge plus the damping c L'."""
        m, t = self.model, self.tendons
        compression = d.ten_length[t] - m.tendon_lengthspring[t, 1]
        return m.tendon_stiffness[t] * np.maximum(compression, 0.0) + m.tendon_damping[t] * d.ten_velocity[t]


# ------------------------------------------------------------------------- the compiled runner's functions
@numba.njit(cache=True)
def refresh_pins(cycloid, at):
    """``CycloidTwin.refresh(d)`` (a run's compression-only contacts): every pin tendon's coefficients, spring
    lengths, stiffness and damping at the discs' present poses, from MuJoCo's kinematics and Jacobians; ``at`` =
    (kinematics, com_pos, jac, m, d, model, data) (:data:`~gearcheck.mbd_models.elements.base.REFRESH`)."""
    kinematics, com_pos, jac, m, d, model, data = at
    if cycloid.discs.body.size == 0:
        return
    stiffness, lengthspring, wrap_prm, damping_model = (model.tendon_stiffness, model.tendon_lengthspring,
                                                        model.wrap_prm, model.tendon_damping)
    qpos, qvel, xpos, xmat, site_xpos = data.qpos, data.qvel, data.xpos, data.xmat, data.site_xpos
    tendons, k_pin, c_pin, clearance, site, wraps = cycloid.pins
    body, wheel, phase, lobes, ecc, pitch_radius, first, count, ndof, dofs, qadr = cycloid.discs
    jacobian, point, G, delta, length, speed = cycloid.work
    kinematics(m, d)
    com_pos(m, d)
    for i in range(body.size):
        b, wh = body[i], wheel[i]
        cx, cy = xpos[b, 0], xpos[b, 1]
        if wh >= 0:
            ox, oy = xpos[wh, 0], xpos[wh, 1]
            w = math.atan2(xmat[wh, 3], xmat[wh, 0])
        else:
            ox, oy, w = 0.0, 0.0, 0.0
        phi = phase[i] + (1 + lobes[i]) * w - lobes[i] * math.atan2(xmat[b, 3], xmat[b, 0])
        ux, uy = math.cos(phi), math.sin(phi)
        point[0] = ox + pitch_radius[i] * ux
        point[1] = oy + pitch_radius[i] * uy
        point[2] = xpos[b, 2]
        jac(m, d, jacobian.ctypes.data, 0, point.ctypes.data, b)
        for r in range(2):
            for k in range(ndof[i]):
                G[r, k] = jacobian[r, dofs[i, k]]
        if wh >= 0:
            jac(m, d, jacobian.ctypes.data, 0, point.ctypes.data, wh)
            for r in range(2):
                for k in range(ndof[i]):
                    G[r, k] -= jacobian[r, dofs[i, k]]
        vx, vy = cx - ox - ecc[i] * ux, cy - oy - ecc[i] * uy
        for p in range(first[i], first[i] + count[i]):
            nx, ny = site_xpos[site[p], 0] - point[0], site_xpos[site[p], 1] - point[1]
            size = math.sqrt(nx * nx + ny * ny)
            nx /= size
            ny /= size
            delta[p] = nx * vx + ny * vy
            total = 0.0
            rate = 0.0
            for k in range(ndof[i]):
                coef = nx * G[0, k] + ny * G[1, k]
                wrap_prm[wraps[p, k]] = coef
                total += coef * qpos[qadr[i, k]]
                rate += coef * qvel[dofs[i, k]]
            length[p] = total
            speed[p] = rate
    for p in range(tendons.size):
        t = tendons[p]
        compression = delta[p] - clearance[p]
        top = length[p] - compression
        lengthspring[t, 0] = top - PIN_BAND
        lengthspring[t, 1] = top
        stiffness[t] = k_pin[p]
        damping_model[t] = c_pin[p] * (compression > 0.0)


@numba.njit(cache=True)
def pin_forces_into(cycloid, at, n):
    """:meth:`CycloidTwin.pin_forces` in the compiled runner: each pin tendon's force at the data's state into
    ``out`` from column n on, ``at`` = (out, model, data); returns the column after them."""
    out, model, data = at
    stiffness, lengthspring, damping = model.tendon_stiffness, model.tendon_lengthspring, model.tendon_damping
    tendons, ten_length, ten_velocity = cycloid.pins.tendons, data.ten_length, data.ten_velocity
    for p in range(tendons.size):
        t = tendons[p]
        compression = ten_length[t] - lengthspring[t, 1]
        out[n + p] = stiffness[t] * max(compression, 0.0) + damping[t] * ten_velocity[t]
    return n + tendons.size


@numba.njit(cache=True)
def pin_switching(cycloid, at, n):
    """Every pin's compression (its clearance off) into g from index n on and its rate into ``rate``, ``at`` =
    (g, rate), as :func:`refresh_pins` last found them: the pins' switching functions in the compiled runner;
    returns the index after them."""
    g, rate = at
    delta, speed, clearance = cycloid.work.delta, cycloid.work.speed, cycloid.pins.clearance
    for p in range(delta.size):
        g[n] = delta[p] - clearance[p]
        rate[n] = speed[p]
        n += 1
    return n


compiled_group(CompiledPins, refresh_pins, pin_switching, pin_forces_into)
