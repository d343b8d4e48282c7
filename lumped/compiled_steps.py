"""Compiled RK4 steps of the reference model (numba): no Python per step.

:func:`rk4_steps` takes a chunk of (sub-)steps whose drive Python has already sampled, vectorised over the
chunk, and runs RK4 through them in compiled code.  Its right-hand side is that of
:meth:`gearcheck.lumped.time_solver._System.acceleration`, written out over sparse rows:

    M q'' = F0 + b_in T_in + b_out T_out - D v - K_c q - A^T f_mesh + F_turning(t, q, v),

* ``K_c``, ``D``: the constant stiffness and damping (bearings, supports, couplings, the rotating frame's
  terms; the t = 0 rows of turning elements removed), compressed sparse rows;
* mesh m: f = k_m g(a_m.q - e_m) + c_m (a_m.v - e_m'), g the backlash dead zone (or the identity), or for a
  relieved mesh sum_j k_j max(0, a_m.q - e_m - e_j) over its tooth pairs;
* the turning elements, whose rows move with time, at each stage's own time: the radial couplings between
  frames (:meth:`gearcheck.lumped.elements.coupling.TurningCoupling.forces`) and the cycloid stages' needle bearings,
  compression-only pin contacts and orbit loads (:meth:`gearcheck.lumped.elements.cycloid.CycloidRows.forces`; the
  pins' normals and arms from one sine and cosine per disc by the angle-addition formulas, as
  :func:`gearcheck.train.cycloid.pin_contacts` states them).

It takes the model and the chunk in named groups (numba passes named tuples of arrays as structs):
:class:`Matrices`, :class:`Meshes`, :class:`Couplings` and :class:`Discs` built once per model
(:func:`kernel_groups`), :class:`Chunk` per chunk of steps, :class:`Output` where the samples go.

numba (``@njit(cache=True)``, compiled on the first call and cached on disk) is the one compiled dependency:
a step is a loop over a few hundred numbers with branches (dead zones, contacts) that numpy cannot vectorise
over time, and that Python runs 10-100 times slower than compiled code.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit



class Sparse(NamedTuple):
    """A matrix as compressed sparse rows (its exact non-zeros)."""

    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray

    @classmethod
    def of(cls, matrix: np.ndarray) -> "Sparse":
        matrix = np.asarray(matrix, dtype=float)
        rows, cols = np.nonzero(matrix)
        indptr = np.zeros(matrix.shape[0] + 1, dtype=np.int64)
        np.add.at(indptr, rows + 1, 1)
        return cls(np.cumsum(indptr), cols.astype(np.int64), np.ascontiguousarray(matrix[rows, cols]))


# ---------------------------------------------------------------------------------------------- the kernel's groups
class Matrices(NamedTuple):
    """The linear part, M q'' = load + b_in T_in + b_out T_out - D v - K q: ``minv`` the inverse of the diagonal
    M, ``load`` F0 less the cycloid loads the static load holds, K (``K_c``) and D as sparse rows."""

    minv: np.ndarray
    load: np.ndarray
    b_in: np.ndarray
    b_out: np.ndarray
    K: Sparse
    D: Sparse


class Meshes(NamedTuple):
    """The meshes: their ``rows`` a_m (sparse), ``damping`` c_m, ``half_backlash``, whether any has ``backlash``,
    and ``relieved``, each mesh's place among the relieved meshes' tooth pairs (-1: not relieved)."""

    rows: Sparse
    damping: np.ndarray
    half_backlash: np.ndarray
    backlash: bool
    relieved: np.ndarray


class Couplings(NamedTuple):
    """Radial couplings between turning frames: ``index`` (T, 4) the (a_x, a_y, b_x, b_y) coordinates, ``values``
    (T, 4) their (Omega_a, Omega_b, stiffness, damping)."""

    index: np.ndarray
    values: np.ndarray

    @classmethod
    def of(cls, couplings) -> "Couplings":
        return cls(np.array([[*e.a, *e.b] for e in couplings], dtype=np.int64).reshape(-1, 4),
                   np.array([[e.omega_a, e.omega_b, e.stiffness, e.damping] for e in couplings],
                            dtype=float).reshape(-1, 4))


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


GROUPS = {"couplings": Couplings, "discs": Discs}  # the compiled groups a turning element names (Turning.compiled)


def kernel_groups(system) -> tuple[Matrices, Meshes, Couplings, Discs]:
    """The groups of a model's right-hand side (:class:`gearcheck.lumped.time_solver._System`) that
    :func:`rk4_steps` takes after q and v, each turning element in the group it names; TypeError for one that
    names none."""
    members = {name: [] for name in GROUPS}
    for e in system.turning:
        if e.compiled not in members:
            raise TypeError(f"no compiled form of the turning element {type(e).__name__}")
        members[e.compiled].append(e)
    static_load = sum((e.static_load for e in members["discs"]), np.zeros(system.Minv.size))
    return (Matrices(system.Minv, system.F0 - static_load, system.b_in, system.b_out, Sparse.of(system.Kc),
                     Sparse.of(system.D)),
            Meshes(Sparse.of(system.A), system.c, system.b, system.has_backlash, system.relieved_index),
            *(GROUPS[name].of(elements) for name, elements in members.items()))


class Chunk(NamedTuple):
    """A chunk of sub-steps and their drive: sub-step r spans [times[r, 0], times[r, 0] + lengths[r]] and ends a
    whole step when ``ends[r]``; ``times`` (sub-steps, 3) its stage times t, t + h/2, t + h; the drive (mesh
    stiffness ``k``, transmission error ``e`` and its rate ``de``, torques ``tin`` and ``tout``, the relieved
    meshes' tooth pairs ``pairs`` (k_j, e_j) or None) with time along axes (0, 1): the stage times of
    :data:`~gearcheck.shared.stepping.STAGE_OFFSETS`."""

    lengths: np.ndarray
    ends: np.ndarray
    times: np.ndarray
    k: np.ndarray
    e: np.ndarray
    de: np.ndarray
    tin: np.ndarray
    tout: np.ndarray
    pairs: np.ndarray | None


class Output(NamedTuple):
    """Where the steps go: after whole step ``first_step + i + 1`` that is a multiple of ``every``, the state goes
    to the next rows of ``q`` and ``v``."""

    first_step: int
    every: int
    q: np.ndarray
    v: np.ndarray


# ---------------------------------------------------------------------------------------------- the kernel
@njit(cache=True)
def rk4_steps(q, v, matrices, meshes, couplings, discs, chunk, out):
    """Classical RK4 through the sub-steps of ``chunk`` (:class:`Chunk`, its ``pairs`` an array), q and v updated
    in place.  The drive of sub-step r at its stage times ``times[r]`` (t, t + h/2, t + h) is ``[r, 0|1|2]`` of the
    drive arrays (stages 2 and 3 both see index 1); the turning elements (:class:`Couplings`, :class:`Discs`) are
    placed at ``times[r]``.  Returns the samples written to ``out`` (:class:`Output`).

    One function, the right-hand side written out in the loop over the four stages (a call per stage costs more
    than the stage itself on a small train)."""
    minv, F0, b_in, b_out = matrices.minv, matrices.load, matrices.b_in, matrices.b_out
    kp, ki, kx = matrices.K
    dp, di, dx = matrices.D
    (ap, ai, ax), c, half, backlash, relieved = meshes
    coupling_index, coupling = couplings
    disc_index, wheel_index, crank_index, crank_place, cranks, pin_place, pins, disc = discs
    lengths, ends, times, k, e, de, tin, tout, pairs = chunk
    first_step, every, q_out, v_out = out
    n = q.size
    Q, V, acc = np.empty((4, n)), np.empty((4, n)), np.empty((4, n))  # each stage's state and q''
    time_index = (0, 1, 1, 2)
    step = first_step
    written = 0
    for r in range(lengths.size):
        h = lengths[r]
        advance = (0.5 * h, 0.5 * h, h)
        Q[0] = q
        V[0] = v
        for stage in range(4):
            s = time_index[stage]
            x, u, out = Q[stage], V[stage], acc[stage]
            ti, to = tin[r, s], tout[r, s]
            for i in range(n):
                f = F0[i] + b_in[i] * ti + b_out[i] * to
                for p in range(kp[i], kp[i + 1]):
                    f -= kx[p] * x[ki[p]]
                for p in range(dp[i], dp[i + 1]):
                    f -= dx[p] * u[di[p]]
                out[i] = f
            for m in range(c.size):  # meshes
                d = 0.0
                rate = 0.0
                for p in range(ap[m], ap[m + 1]):
                    d += ax[p] * x[ai[p]]
                    rate += ax[p] * u[ai[p]]
                y = d - e[r, s, m]
                j = relieved[m]
                if j >= 0:  # tooth pairs
                    elastic = 0.0
                    for pair in range(pairs.shape[3]):
                        gap = y - pairs[r, s, j, pair, 1]
                        if gap > 0.0:
                            elastic += pairs[r, s, j, pair, 0] * gap
                elif backlash:  # dead zone
                    b = half[m]
                    elastic = k[r, s, m] * (y - b if y > b else (y + b if y < -b else 0.0))
                else:
                    elastic = k[r, s, m] * y
                f = elastic + c[m] * (rate - de[r, s, m])
                for p in range(ap[m], ap[m + 1]):
                    out[ai[p]] -= ax[p] * f
            t = times[r, s]
            for w in range(coupling.shape[0]):  # radial couplings between turning frames
                wa, wb, kc, cc = coupling[w, 0], coupling[w, 1], coupling[w, 2], coupling[w, 3]
                i0, i1, i2, i3 = coupling_index[w, 0], coupling_index[w, 1], coupling_index[w, 2], coupling_index[w, 3]
                phi = (wb - wa) * t
                cs, sn = np.cos(phi), np.sin(phi)
                va0, va1 = u[i0] - wa * x[i1], u[i1] + wa * x[i0]
                vb0, vb1 = u[i2] - wb * x[i3], u[i3] + wb * x[i2]
                p0 = kc * (x[i0] - (cs * x[i2] - sn * x[i3])) + cc * (va0 - (cs * vb0 - sn * vb1))
                p1 = kc * (x[i1] - (sn * x[i2] + cs * x[i3])) + cc * (va1 - (sn * vb0 + cs * vb1))
                out[i0] -= p0
                out[i1] -= p1
                out[i2] += cs * p0 + sn * p1
                out[i3] += -sn * p0 + cs * p1
            for d in range(disc.shape[0]):  # cycloid discs
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
                K1, rc, pitch, kp_, cp_, gap = disc[d, 3], disc[d, 4], disc[d, 5], disc[d, 10], disc[d, 11], disc[d, 12]
                rel = disc[d, 2] * t - phi  # pin 0's angle relative to the eccentric
                cw, sw = np.cos(rel), np.sin(rel)
                wx, wy, wt = wheel_index[d, 0], wheel_index[d, 1], wheel_index[d, 2]
                for i in range(pins[d]):  # pin contacts, compression only
                    ci, si = pin_place[d, i, 0], pin_place[d, i, 1]
                    cr, sr = ci * cw - si * sw, si * cw + ci * sw
                    norm = np.sqrt(1 + K1 * K1 - 2 * K1 * cr)
                    ex, ey = (cr - K1) / norm, sr / norm
                    nx, ny = cp * ex - sp * ey, sp * ex + cp * ey
                    arm = rc * ey
                    dp_ = nx * x[dx_] + ny * x[dy] + arm * x[dth] - gap
                    if wx >= 0:
                        dp_ -= nx * x[wx] + ny * x[wy] + pitch * ey * x[wt]
                    if not dp_ > 0.0:
                        continue
                    rp = nx * u[dx_] + ny * u[dy] + arm * u[dth]
                    if wx >= 0:
                        rp -= nx * u[wx] + ny * u[wy] + pitch * ey * u[wt]
                    f = kp_ * dp_ + cp_ * rp
                    out[dx_] -= f * nx
                    out[dy] -= f * ny
                    out[dth] -= f * arm
                    if wx >= 0:
                        out[wx] += f * nx
                        out[wy] += f * ny
                        out[wt] += f * pitch * ey
            for i in range(n):
                out[i] *= minv[i]
            if stage < 3:
                a = advance[stage]
                for i in range(n):
                    Q[stage + 1, i] = q[i] + a * u[i]
                    V[stage + 1, i] = v[i] + a * out[i]
        sixth = h / 6.0
        for i in range(n):
            q[i] = q[i] + sixth * (V[0, i] + 2 * V[1, i] + 2 * V[2, i] + V[3, i])
            v[i] = v[i] + sixth * (acc[0, i] + 2 * acc[1, i] + 2 * acc[2, i] + acc[3, i])
        if ends[r]:
            step += 1
            if step % every == 0:
                q_out[written] = q
                v_out[written] = v
                written += 1
    return written
