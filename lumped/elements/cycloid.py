"""An RV reducer's cycloid-pin stage in the reference model: rows that turn with the eccentrics.

Coordinates are those of the stage's carrier frame (turning at Omega, see :mod:`gearcheck.lumped.assembly`):
crank k has (radial, tangential, theta) at its place psi_k on the carrier like a planet, disc j and the pin
wheel have (x, y, theta) along the carrier's axes, every rotation absolute.  Disc j's eccentric points along
e(phi_j), phi_j(t) = phase_j + (w_H - Omega) t in the carrier frame (the first disc's along the carrier's x
axis at t = 0); pin i sits at beta_i(t) = 2 pi i / Z_p + (w_w - Omega) t on the pin circle.

* Needle bearing of crank k in disc j: the eccentric's centre minus the disc's bore, two rows (x, y),
      d = u_Hk + e theta_Hk e_perp(phi_j) - u_j - r_H theta_j e_t(psi_k),
  the bore sitting at r_H e_r(psi_k) from the disc's centre whatever phi_j (Yang, Chen & Wang 2018 print this
  block on a non-rotation matrix and with the eccentric frozen; see the audit in the documentation).
* Pin contact i of disc j, compression only: the common normal passes through the pitch point (Willis),
      delta = n . (u_j - u_w) + l theta_j - (C_i x n) theta_w - clearance,
  n and l from :func:`gearcheck.train.cycloid.pin_contacts`; force k max(delta, 0) + c delta' while it
  touches.
* The disc's nominal orbit e(phi_j) at the crank's absolute speed w_H: its centrifugal load
  m e w_H^2 e(phi_j(t)) on the disc, written in the carrier frame (the frame's own terms act on the
  vibration only).

The rows depend on time, and the pins' contact set on the state: the modal and static analyses take the rows
of t = 0 with the contact set of the static solution (like a turning coupling), the time solver calls
:meth:`CycloidRows.forces` at every stage.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
from numba import njit

from gearcheck.lumped.elements import ELEMENTS
from gearcheck.lumped.elements.base import Build, Contribution, Row, Turning, compiled_group
from gearcheck.lumped.static import mean_load
from gearcheck.shared.errors import SolverError
from gearcheck.train.cycloid import pin_contacts


@ELEMENTS.register("cycloid")
def cycloid_element(cyc, build: Build) -> Contribution:
    """The stage's turning rows, placed in the finished model at t = 0 with the static contact set."""
    spec, dofs, kin = build.spec, build.dofs, build.kin
    stage = spec.stage_of(cyc.cranks[0])
    omega = kin.speeds[stage.carrier]
    wheel = kin.speeds[cyc.pin_wheel] if cyc.pin_wheel else 0.0
    element = CycloidRows(
        stage.name, build.n, np.array([dofs.indices(c) for c in cyc.cranks]),
        np.array([dofs.indices(d) for d in cyc.discs]), dofs.indices(cyc.pin_wheel) if cyc.pin_wheel else None,
        np.array([spec.members[c].angle for c in cyc.cranks]), np.array(cyc.phases),
        kin.speeds[cyc.cranks[0]] - omega, wheel - omega, kin.speeds[cyc.cranks[0]], cyc.geometry,
        stage.carrier_radius, cyc.needle.radial_stiffness, cyc.needle.radial_damping,
        cyc.pin_stiffness(spec.operating.output_torque), cyc.contact_damping, cyc.clearance,
        spec.members[cyc.discs[0]].mass, gap_load=np.zeros(build.n))

    def place(model):
        unplaced = replace(model, turning=model.turning + [element], F_static=model.F_static + element.static_load)
        return element.place(unplaced, 0.0)
    return Contribution(place=place)


class Discs(NamedTuple):
    """Cycloid discs, one row per disc of every cycloid stage: ``index`` (D, 3) its (x, y, theta), ``wheel`` (D, 3)
    its pin wheel's (-1: fixed), ``crank_index`` (D, M, 3) its stage's cranks, ``crank_place`` (D, M, 2) cos and sin
    of their places psi_k (padded), ``cranks`` (D,) their number, ``pin_place`` (D, Z, 2) cos and sin of
    2 pi i / Z_p (padded), ``pins`` (D,) Z_p, and ``values`` (D, 14): phase, w_H - Omega, w_w - Omega, K1, r_c,
    Z_p e, e, m e w_H^2, needle k and c, pin k and c, clearance, and the carrier radius."""

    index: np.ndarray
    wheel: np.ndarray
    crank_index: np.ndarray
    crank_place: np.ndarray
    cranks: np.ndarray
    pin_place: np.ndarray
    pins: np.ndarray
    values: np.ndarray

    @classmethod
    def of(cls, cycloids) -> "Discs":
        discs = [(e, j) for e in cycloids for j in range(len(e.disc))]
        most_cranks = max((len(e.crank) for e in cycloids), default=0)
        most_pins = max((e.geometry.pins for e in cycloids), default=0)
        index = np.zeros((len(discs), 3), dtype=np.int64)
        wheel = np.full((len(discs), 3), -1, dtype=np.int64)
        crank_index = np.zeros((len(discs), most_cranks, 3), dtype=np.int64)
        crank_place = np.zeros((len(discs), most_cranks, 2))
        cranks = np.zeros(len(discs), dtype=np.int64)
        pin_place = np.zeros((len(discs), most_pins, 2))
        pins = np.zeros(len(discs), dtype=np.int64)
        values = np.zeros((len(discs), 14))
        for d, (e, j) in enumerate(discs):
            g = e.geometry
            index[d] = e.disc[j]
            if e.wheel is not None:
                wheel[d] = e.wheel
            cranks[d] = len(e.crank)
            crank_index[d, :cranks[d]] = e.crank
            crank_place[d, :cranks[d]] = np.stack([np.cos(e.psi), np.sin(e.psi)], axis=-1)
            angles = 2 * np.pi * np.arange(g.pins) / g.pins
            pin_place[d, :g.pins] = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
            pins[d] = g.pins
            values[d] = (e.phases[j], e.omega_eccentric, e.omega_pins, g.K1, g.rolling_radius, g.pitch_radius,
                         g.eccentricity, e.disc_mass * g.eccentricity * e.omega_orbit**2, e.needle_stiffness,
                         e.needle_damping, e.pin_stiffness, e.pin_damping, e.clearance, e.carrier_radius)
        return cls(index, wheel, crank_index, crank_place, cranks, pin_place, pins, values)


@dataclass(frozen=True)
class CycloidRows(Turning):
    """The time-periodic rows and loads of one cycloid-pin stage (see the module docstring)."""

    has_contacts = True
    smooth = False
    compiled = Discs
    words = "a cycloid-pin stage"

    stage: str
    n: int  # coordinates of the model
    crank: np.ndarray  # (M, 3) indices of each crank's radial, tangential, theta
    disc: np.ndarray  # (N, 3) indices of each disc's x, y, theta
    wheel: np.ndarray | None  # (3,) indices of the pin wheel's x, y, theta; None: fixed
    psi: np.ndarray  # (M,) crank places on the carrier
    phases: np.ndarray  # (N,) eccentric phases at t = 0
    omega_eccentric: float  # w_H - Omega, rad/s
    omega_pins: float  # w_w - Omega
    omega_orbit: float  # w_H, the orbit's absolute speed
    geometry: object  # CycloidGeometry
    carrier_radius: float
    needle_stiffness: float
    needle_damping: float
    pin_stiffness: float
    pin_damping: float
    clearance: float
    disc_mass: float
    rows: tuple[str, ...] = ()  # names of its rows in the model, those of time placed_at (forces() in time)
    placed_at: float = 0.0
    gap_load: np.ndarray | None = None  # (n,) sum of k gap a over the pins touching at placed_at

    @property
    def clock_speed(self) -> float:
        """Its rows turn with the eccentrics in the carrier: |w_H - Omega|."""
        return abs(self.omega_eccentric)

    @property
    def static_load(self) -> np.ndarray:
        """(n,) the loads of time ``placed_at`` that the model's static load holds: the orbit loads and the
        pins' gap terms (a row k (a.q - gap) is the row k a.q and the load k gap a)."""
        return self.orbit_force(self.placed_at) + self.gap_load

    # ------------------------------------------------------------------ geometry at times t
    def eccentric_angles(self, t) -> np.ndarray:
        """(..., N) phi_j(t)."""
        return self.phases + self.omega_eccentric * np.asarray(t, dtype=float)[..., None]

    def pin_angles(self, t) -> np.ndarray:
        """(...,) angle of pin 0 on the pin circle in the carrier frame."""
        return self.omega_pins * np.asarray(t, dtype=float)

    def needle_coefficients(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients (..., N, M, 2, 3) of the needle rows on the crank's and on the disc's coordinates."""
        phi = self.eccentric_angles(t)[..., :, None]  # (..., N, 1)
        e = self.geometry.eccentricity
        c, s = np.cos(self.psi), np.sin(self.psi)
        shape = np.broadcast_shapes(phi.shape, self.psi.shape) + (2, 3)
        on_crank = np.zeros(shape)
        on_crank[..., 0, 0], on_crank[..., 1, 0] = c, s  # radial axis e_r
        on_crank[..., 0, 1], on_crank[..., 1, 1] = -s, c  # tangential axis e_t
        on_crank[..., 0, 2], on_crank[..., 1, 2] = -e * np.sin(phi), e * np.cos(phi)
        on_disc = np.zeros(shape)
        on_disc[..., 0, 0] = on_disc[..., 1, 1] = -1.0
        on_disc[..., 0, 2], on_disc[..., 1, 2] = self.carrier_radius * s, -self.carrier_radius * c
        return on_crank, on_disc

    def pin_coefficients(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients (..., N, Z_p, 3) of the pin rows on the disc's and on the pin wheel's coordinates."""
        phi = self.eccentric_angles(t)
        contacts = pin_contacts(self.geometry, phi, self.pin_angles(t)[..., None])
        return contacts.disc_row, contacts.wheel_row

    def orbit_force(self, t) -> np.ndarray:
        """(..., n) the discs' centrifugal loads of their nominal orbits."""
        phi = self.eccentric_angles(t)
        scale = self.disc_mass * self.geometry.eccentricity * self.omega_orbit**2
        out = np.zeros(np.shape(phi)[:-1] + (self.n,))
        out[..., self.disc[:, 0]] = scale * np.cos(phi)
        out[..., self.disc[:, 1]] = scale * np.sin(phi)
        return out

    # ------------------------------------------------------------------ rows and forces
    def needle_rows(self, t: float) -> list[tuple[str, np.ndarray]]:
        """The needle bearings' rows at one time, named."""
        on_crank, on_disc = self.needle_coefficients(t)
        out = []
        for j, disc in enumerate(self.disc):
            for k, crank in enumerate(self.crank):
                for axis, name in enumerate("xy"):
                    a = np.zeros(self.n)
                    a[crank] += on_crank[j, k, axis]
                    a[disc] += on_disc[j, k, axis]
                    out.append((f"{self.stage}.crank{k + 1}.disc{j + 1}.needle_{name}", a))
        return out

    def pin_rows(self, t: float) -> list[tuple[str, np.ndarray]]:
        """Every pin contact's row at one time, named (disc j, pin i)."""
        on_disc, on_wheel = self.pin_coefficients(t)
        a = np.zeros(on_disc.shape[:2] + (self.n,))
        for j, disc in enumerate(self.disc):
            a[j][:, disc] += on_disc[j]
            if self.wheel is not None:
                a[j][:, self.wheel] += on_wheel[j]
        return list(zip(_pin_names(self.stage, *a.shape[:2]), a.reshape(-1, self.n)))

    def switching(self, t: float, q, v) -> tuple[np.ndarray, np.ndarray]:
        """Every pin's compression (disc by disc, pin by pin), the contact made where it turns positive, and its
        rate without its normal's turning."""
        return self.pin_deflections(t, q).ravel(), (self.pin_deflections(t, v) + self.clearance).ravel()

    def pin_deflections(self, t, q) -> np.ndarray:
        """(..., N, Z_p) compression of every pin contact (negative: apart), time along axis 0 allowed."""
        return self._pins(self.pin_coefficients(t), q, np.zeros_like(np.asarray(q, dtype=float)))[0]

    def pin_forces(self, t, q, v) -> np.ndarray:
        """(..., N, Z_p) normal force of every pin contact, N (0 where apart)."""
        return self._pins(self.pin_coefficients(t), q, v)[1]

    def _pins(self, coefficients, q, v):
        on_disc, on_wheel = coefficients
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        delta = np.einsum("...jik,...jk->...ji", on_disc, q[..., self.disc]) - self.clearance
        rate = np.einsum("...jik,...jk->...ji", on_disc, v[..., self.disc])
        if self.wheel is not None:
            delta = delta + np.einsum("...jik,...k->...ji", on_wheel, q[..., self.wheel])
            rate = rate + np.einsum("...jik,...k->...ji", on_wheel, v[..., self.wheel])
        return delta, np.where(delta > 0.0, self.pin_stiffness * delta + self.pin_damping * rate, 0.0)

    def forces(self, t, q, v) -> np.ndarray:
        """Generalized forces (time along axis 0 allowed) of the needle bearings, the pin contacts and the
        orbit loads, less :attr:`static_load` (which the model's static load holds)."""
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        out = self.orbit_force(t) - self.static_load
        on_crank, on_disc = self.needle_coefficients(t)
        d = (np.einsum("...jkal,...kl->...jka", on_crank, q[..., self.crank])
             + np.einsum("...jkal,...jl->...jka", on_disc, q[..., self.disc]))
        rate = (np.einsum("...jkal,...kl->...jka", on_crank, v[..., self.crank])
                + np.einsum("...jkal,...jl->...jka", on_disc, v[..., self.disc]))
        f = self.needle_stiffness * d + self.needle_damping * rate  # (..., N, M, 2)
        out[..., self.crank] -= np.einsum("...jka,...jkal->...kl", f, on_crank)
        out[..., self.disc] -= np.einsum("...jka,...jkal->...jl", f, on_disc)
        coefficients = self.pin_coefficients(t)
        p = self._pins(coefficients, q, v)[1]  # (..., N, Z_p)
        out[..., self.disc] -= np.einsum("...ji,...jik->...jk", p, coefficients[0])
        if self.wheel is not None:
            out[..., self.wheel] -= np.einsum("...ji,...jik->...k", p, coefficients[1])
        return out

    # ------------------------------------------------------------------ the element in the model
    def without_frame_terms(self) -> "CycloidRows":
        return replace(self, omega_orbit=0.0)

    def held_load(self, n: int) -> np.ndarray:
        return self.gap_load

    def contact_set(self, model) -> np.ndarray:
        names = {r.name for r in model.rows if r.kind == "contact"}
        return np.array([name in names for name, _ in self.pin_rows(self.placed_at)])

    def place(self, model, t: float, touching=None):
        """``model`` with this stage's rows and loads of time ``t`` in place of those it had; the pins of
        ``touching`` in contact, or those of the static solution."""
        rows = [r for r in model.rows if r.name not in self.rows]
        needles = [Row(name, "bearing", a, self.needle_stiffness, self.needle_damping)
                   for name, a in self.needle_rows(t)]
        pins = self.pin_rows(t)
        base = replace(model, rows=rows + needles,
                       F_static=model.F_static - self.static_load + self.orbit_force(t))  # gaps: below
        A = np.array([a for _, a in pins])
        touching = self._static_contact_set(base, A) if touching is None else np.asarray(touching, dtype=bool)
        contacts = [Row(name, "contact", a, self.pin_stiffness, self.pin_damping)
                    for (name, a), on in zip(pins, touching) if on]
        gap_load = self.pin_stiffness * self.clearance * A[touching].sum(axis=0)  # a row k (a.q - gap)
        placed = replace(self, rows=tuple(r.name for r in needles + contacts), placed_at=t, gap_load=gap_load)
        return replace(base, rows=base.rows + contacts, F_static=base.F_static + gap_load,
                       turning=[placed if e is self else e for e in model.turning])

    def _static_contact_set(self, model, A: np.ndarray) -> np.ndarray:
        """Which pins (rows ``A``, of the time the rows are placed at) touch in the static equilibrium under the
        mean load (active set, from all of them touching)."""
        K0 = model.K_b + model.K_mesh(model.excitation.mean_stiffness) + model.K_frame
        F = mean_load(model)
        active = np.ones(len(A), dtype=bool)
        for _ in range(len(A) + 1):
            K = K0 + self.pin_stiffness * A[active].T @ A[active]
            q = np.linalg.lstsq(K, F + self.pin_stiffness * self.clearance * A[active].sum(axis=0), rcond=None)[0]
            touching = A @ q - self.clearance > 0.0
            if np.array_equal(touching, active):
                return active
            active = touching
        raise SolverError(f"{self.stage}: the static pin contact set did not settle")  # pragma: no cover


@functools.lru_cache(maxsize=64)
def _pin_names(stage: str, discs: int, pins: int) -> tuple[str, ...]:
    """The pin rows' names, disc by disc (built once: a harmonic method places the rows at every sample)."""
    return tuple(f"{stage}.disc{j + 1}.pin{i + 1}" for j in range(discs) for i in range(pins))


# ------------------------------------------------------------------------- the compiled steps' form
@njit(inline="always")
def pin(d, i, x, t, discs):
    """Pin i of disc d at state x, time t: (compression, normal x, normal y, arm on the disc, arm on the wheel)."""
    disc_index, wheel_index, _, _, _, pin_place, _, disc = discs
    dx_, dy, dth = disc_index[d, 0], disc_index[d, 1], disc_index[d, 2]
    phi = disc[d, 0] + disc[d, 1] * t
    cp, sp = np.cos(phi), np.sin(phi)
    rel = disc[d, 2] * t - phi  # pin 0's angle relative to the eccentric
    cw, sw = np.cos(rel), np.sin(rel)
    K1, rc, pitch = disc[d, 3], disc[d, 4], disc[d, 5]
    ci, si = pin_place[d, i, 0], pin_place[d, i, 1]
    cr, sr = ci * cw - si * sw, si * cw + ci * sw
    norm = np.sqrt(1 + K1 * K1 - 2 * K1 * cr)
    ex, ey = (cr - K1) / norm, sr / norm
    nx, ny = cp * ex - sp * ey, sp * ex + cp * ey
    arm = rc * ey
    compression = nx * x[dx_] + ny * x[dy] + arm * x[dth] - disc[d, 12]
    wx, wy, wt = wheel_index[d, 0], wheel_index[d, 1], wheel_index[d, 2]
    if wx >= 0:
        compression -= nx * x[wx] + ny * x[wy] + pitch * ey * x[wt]
    return compression, nx, ny, arm, pitch * ey


@njit(inline="always")
def disc_forces(discs, at) -> None:
    """The compiled steps' form of :meth:`CycloidRows.forces`: every disc's orbit load, needle bearings and pin
    contacts at ``at`` = (x, u, t, out), state (x, u) and time t, added into ``out``
    (:mod:`gearcheck.lumped.compiled_steps`)."""
    x, u, t, out = at
    disc_index, wheel_index, crank_index, crank_place, cranks, _, pins, disc = discs
    for d in range(disc.shape[0]):
        dx_, dy, dth = disc_index[d, 0], disc_index[d, 1], disc_index[d, 2]
        phi = disc[d, 0] + disc[d, 1] * t
        cp, sp = np.cos(phi), np.sin(phi)
        out[dx_] += disc[d, 7] * cp  # the orbit's centrifugal load
        out[dy] += disc[d, 7] * sp
        ecc, kn, cn, radius = disc[d, 6], disc[d, 8], disc[d, 9], disc[d, 13]
        for kk in range(cranks[d]):  # needle bearings, x and y
            c0, c1, c2 = crank_index[d, kk, 0], crank_index[d, kk, 1], crank_index[d, kk, 2]
            ck, sk = crank_place[d, kk, 0], crank_place[d, kk, 1]
            for axis in range(2):
                if axis == 0:
                    a0, a1, a2, b0, b1, b2 = ck, -sk, -ecc * sp, -1.0, 0.0, radius * sk
                else:
                    a0, a1, a2, b0, b1, b2 = sk, ck, ecc * cp, 0.0, -1.0, -radius * ck
                dn = a0 * x[c0] + a1 * x[c1] + a2 * x[c2] + b0 * x[dx_] + b1 * x[dy] + b2 * x[dth]
                rn = a0 * u[c0] + a1 * u[c1] + a2 * u[c2] + b0 * u[dx_] + b1 * u[dy] + b2 * u[dth]
                f = kn * dn + cn * rn
                out[c0] -= f * a0
                out[c1] -= f * a1
                out[c2] -= f * a2
                out[dx_] -= f * b0
                out[dy] -= f * b1
                out[dth] -= f * b2
        kp_, cp_ = disc[d, 10], disc[d, 11]
        wx, wy, wt = wheel_index[d, 0], wheel_index[d, 1], wheel_index[d, 2]
        for i in range(pins[d]):  # pin contacts, compression only
            compression, nx, ny, arm, wheel_arm = pin(d, i, x, t, discs)
            if not compression > 0.0:
                continue
            rp = nx * u[dx_] + ny * u[dy] + arm * u[dth]
            if wx >= 0:
                rp -= nx * u[wx] + ny * u[wy] + wheel_arm * u[wt]
            f = kp_ * compression + cp_ * rp
            out[dx_] -= f * nx
            out[dy] -= f * ny
            out[dth] -= f * arm
            if wx >= 0:
                out[wx] += f * nx
                out[wy] += f * ny
                out[wt] += f * wheel_arm


@njit(inline="always")
def pin_switching(discs, at, n) -> int:
    """Every pin's compression at ``at`` = (x, u, t, g, rate), state (x, u) and time t, into g from index n on, and
    its rate into ``rate`` (its normal's turning left out): the pins' switching functions
    (:mod:`gearcheck.lumped.compiled_steps`); returns the index after them."""
    x, u, t, g, rate = at
    disc_index, wheel_index, _, _, _, _, pins, _ = discs
    for d in range(pins.size):
        dx_, dy_, dth = disc_index[d, 0], disc_index[d, 1], disc_index[d, 2]
        wx, wy, wt = wheel_index[d, 0], wheel_index[d, 1], wheel_index[d, 2]
        for i in range(pins[d]):
            compression, nx, ny, arm, wheel_arm = pin(d, i, x, t, discs)
            g[n] = compression
            rate[n] = nx * u[dx_] + ny * u[dy_] + arm * u[dth]
            if wx >= 0:
                rate[n] -= nx * u[wx] + ny * u[wy] + wheel_arm * u[wt]
            n += 1
    return n


compiled_group(Discs, disc_forces, pin_switching, lambda discs: int(np.sum(discs.pins)))
