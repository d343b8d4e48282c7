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
:class:`Matrices` and :class:`Meshes`, and a tuple of every turning element kind's group, built once per model
(:func:`kernel_groups`); :class:`Chunk` per chunk of steps, :class:`Output` where the samples go.  A turning
element kind keeps its group and its compiled forces in its own file, beside its rows, and registers them
(:func:`gearcheck.lumped.elements.base.compiled_group`: the radial couplings'
:class:`~gearcheck.lumped.elements.coupling.Couplings`, the cycloid discs'
:class:`~gearcheck.lumped.elements.cycloid.Discs`); the kernel calls every kind's functions once per stage through
the hooks :data:`~gearcheck.lumped.elements.base.FORCES` and :data:`~gearcheck.lumped.elements.base.SWITCHING`,
naming none.

numba (``@njit(cache=True)``, compiled on the first call and cached on disk) is the one compiled dependency:
a step is a loop over a few hundred numbers with branches (dead zones, contacts) that numpy cannot vectorise
over time, and that Python runs 10-100 times slower than compiled code.  :func:`_rk4` and :func:`_switching` are
functions of their own, compiled without numba's reference-counted runtime (``_nrt=False``: they allocate
nothing), so a call passes its tens of arrays without atomic reference counts; inlined at each of their three
call sites they made one function that took numba 89 s to compile, and the counts cost half the step (hub-drive:
5.6 -> 2.7 us a step in the kernel).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np
from numba import njit

from gearcheck.lumped.elements import base
from gearcheck.shared.compiled_cache import ensure_cache_folder
from gearcheck.shared.events import (MAX_EVENTS, MIN_FRACTION, crossed_together, first_crossing, pair_switch,
                                     samples_between)

ensure_cache_folder(Path(__file__).parent)  # before the cached kernels below are defined


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


def kernel_groups(system) -> tuple[Matrices, Meshes, tuple]:
    """The groups of a model's right-hand side (:class:`gearcheck.lumped.time_solver._System`) that
    :func:`rk4_steps` takes after q and v: the matrices, the meshes, and every registered kind of turning element
    in its group (:data:`gearcheck.lumped.elements.base.GROUPS`, empty where the model has none of it, so that one
    compiled kernel serves every model); TypeError for a turning element with no compiled form."""
    for e in system.turning:
        if e.compiled not in base.GROUPS:
            raise TypeError(f"no compiled form of the turning element {type(e).__name__}")
    static_load = sum((e.static_load for e in system.turning), np.zeros(system.Minv.size))
    return (Matrices(system.Minv, system.F0 - static_load, system.b_in, system.b_out, Sparse.of(system.Kc),
                     Sparse.of(system.D)),
            Meshes(Sparse.of(system.A), system.c, system.b, system.has_backlash, system.relieved_index),
            tuple(group.of([e for e in system.turning if e.compiled is group]) for group in base.GROUPS))


class Chunk(NamedTuple):
    """A chunk of sub-steps and their drive: sub-step r spans [times[r, 0], times[r, 0] + lengths[r]] and ends a
    whole step when ``ends[r]``; ``times`` (sub-steps, 3) its stage times t, t + h/2, t + h; the drive (mesh
    stiffness ``k``, transmission error ``e`` and its rate ``de``, torques ``tin`` and ``tout``, the relieved
    meshes' tooth pairs ``pairs`` (k_j, e_j) or None) with time along axes (0, 1): the stage times of
    :data:`~gearcheck.shared.stepping.STAGE_OFFSETS`, read at :data:`~gearcheck.shared.stepping.STAGE_SIDES`."""

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
STAGE_TIMES = (0, 1, 1, 2)  # RK4's stages at the drive's samples t, t + h/2, t + h
turning_forces, turning_switching = base.FORCES.each, base.SWITCHING.each  # numba calls functions, not attributes


@njit(inline="always", _nrt=False)
def _acceleration(x, u, out, t, ti, to, k, e, de, pairs, matrices, meshes, turning):
    """q'' into ``out`` at state (x, u), time t, torques ti and to, the meshes' k, e, de and tooth pairs."""
    minv, F0, b_in, b_out = matrices.minv, matrices.load, matrices.b_in, matrices.b_out
    kp, ki, kx = matrices.K
    dp, di, dx = matrices.D
    (ap, ai, ax), c, half, backlash, relieved = meshes
    n = x.size
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
        y = d - e[m]
        j = relieved[m]
        if j >= 0:  # tooth pairs
            elastic = 0.0
            for pair in range(pairs.shape[1]):
                gap = y - pairs[j, pair, 1]
                if gap > 0.0:
                    elastic += pairs[j, pair, 0] * gap
        elif backlash:  # dead zone
            b = half[m]
            elastic = k[m] * (y - b if y > b else (y + b if y < -b else 0.0))
        else:
            elastic = k[m] * y
        f = elastic + c[m] * (rate - de[m])
        for p in range(ap[m], ap[m + 1]):
            out[ai[p]] -= ax[p] * f
    turning_forces(turning, (x, u, t, out))
    for i in range(n):
        out[i] *= minv[i]


@njit(cache=True, _nrt=False)
def _rk4(q, v, h, times, k, e, de, tin, tout, pairs, Q, V, acc, matrices, meshes, turning):
    """One classical RK4 step of length h in place, the drive given at the stage samples (axis 0: t, t + h/2,
    t + h; stages 2 and 3 both see the middle one)."""
    n = q.size
    advance = (0.5 * h, 0.5 * h, h)
    for i in range(n):  # element by element: an array assignment would need numba's reference-counted runtime
        Q[0, i] = q[i]
        V[0, i] = v[i]
    for stage in range(4):
        s = STAGE_TIMES[stage]
        _acceleration(Q[stage], V[stage], acc[stage], times[s], tin[s], tout[s], k[s], e[s], de[s], pairs[s],
                      matrices, meshes, turning)
        if stage < 3:
            a = advance[stage]
            for i in range(n):
                Q[stage + 1, i] = q[i] + a * V[stage, i]
                V[stage + 1, i] = v[i] + a * acc[stage, i]
    sixth = h / 6.0
    for i in range(n):
        q[i] = q[i] + sixth * (V[0, i] + 2 * V[1, i] + 2 * V[2, i] + V[3, i])
        v[i] = v[i] + sixth * (acc[0, i] + 2 * acc[1, i] + 2 * acc[2, i] + acc[3, i])


@njit(cache=True, _nrt=False)
def _switching(x, u, t, e, de, pairs, s, span, meshes, turning, g, rate) -> None:
    """The contact switching functions at state (x, u), time t into g and their rates of change into ``rate``,
    each changing sign where a contact law has a kink: a backlash's two edges (y - b, y + b), a relieved mesh's
    tooth pairs (y - e_j; -1 for a padded pair), then the turning elements' (the pins' compressions; a pin's rate
    leaves out its normal's turning).  ``pairs``: the tooth pairs at the three samples of a (sub-)step of length
    ``span``, t at sample ``s`` (their gaps' rates from the three)."""
    (ap, ai, ax), c, half, backlash, relieved = meshes
    n = 0
    for m in range(c.size):
        j = relieved[m]
        if j < 0 and not (backlash and half[m] > 0.0):
            continue
        y = -e[m]
        dy = -de[m]
        for p in range(ap[m], ap[m + 1]):
            y += ax[p] * x[ai[p]]
            dy += ax[p] * u[ai[p]]
        if j >= 0:
            for pair in range(pairs.shape[2]):
                g[n], rate[n] = pair_switch(y, dy, pairs[0, j, pair, 1], pairs[1, j, pair, 1], pairs[2, j, pair, 1], s,
                                            span)
                n += 1
        else:
            g[n], g[n + 1] = y - half[m], y + half[m]
            rate[n], rate[n + 1] = dy, dy
            n += 2
    turning_switching(turning, (x, u, t, g, rate), n)


def switching_count(meshes: Meshes, turning: tuple, pairs_per_mesh: int) -> int:
    """How many switching functions :func:`_switching` writes."""
    relieved = meshes.relieved >= 0
    edges = 2 * int(np.sum(~relieved & (meshes.half_backlash > 0))) if meshes.backlash else 0
    return edges + int(np.sum(relieved)) * pairs_per_mesh + base.switch_count(turning)


@njit(inline="always")
def _part_of(chunk, r, a, b, part) -> None:
    """The drive of the part from fraction a to b of sub-step r (:func:`~gearcheck.shared.events.samples_between`,
    each of ``part``'s arrays: times, k, e, de, tin, tout, pairs)."""
    _, _, times, k, e, de, tin, tout, pairs = chunk
    samples_between(times[r], a, b, part[0])
    samples_between(k[r], a, b, part[1])
    samples_between(e[r], a, b, part[2])
    samples_between(de[r], a, b, part[3])
    samples_between(tin[r], a, b, part[4])
    samples_between(tout[r], a, b, part[5])
    samples_between(pairs[r], a, b, part[6])


@njit(cache=True)
def rk4_steps(q, v, matrices, meshes, turning, chunk, out, switches, located):
    """Classical RK4 through the sub-steps of ``chunk`` (:class:`Chunk`, its ``pairs`` an array, empty along its
    last axes without tip relief), q and v updated in place.  The drive of sub-step r at its stage times
    ``times[r]`` (t, t + h/2, t + h) is ``[r, 0|1|2]`` of the drive arrays (stages 2 and 3 both see index 1); the
    turning elements (``turning``: their groups, :func:`kernel_groups`) are placed at the stage times.
    ``switches``, the number of switching functions (:func:`switching_count`; 0: none), enables contact-event
    location (counted into ``located[0]``): where a switching function (:func:`_switching`) crosses zero within a step
    (:func:`first_crossing`), the step is taken again, ended at the crossing, with the drive interpolated
    quadratically from its three samples, and the rest of the step follows, itself checked; at most ``MAX_EVENTS``
    a step.  A kink left inside a step costs an error of order h^2 there; ended at it, RK4 keeps its order.
    Returns the samples written to ``out`` (:class:`Output`)."""
    lengths, ends, times, k, e, de, tin, tout, pairs = chunk
    first_step, every, q_out, v_out = out
    n = q.size
    Q, V, acc = np.empty((4, n)), np.empty((4, n)), np.empty((4, n))  # each stage's state and q''
    g0, g1, r0, r1 = np.empty(switches), np.empty(switches), np.empty(switches), np.empty(switches)
    part = (np.empty(3), np.empty(k.shape[1:]), np.empty(e.shape[1:]), np.empty(de.shape[1:]), np.empty(3),
            np.empty(3), np.empty(pairs.shape[1:]))  # the drive of a part of a step: times, k, e, de, tin, tout, pairs
    step = first_step
    written = 0
    start, end = np.int64(0), np.int64(2)  # the samples at a step's ends, as int64: literals 0 and 2 would
    for r in range(lengths.size):           # each compile _switching once more
        h = lengths[r]
        _rk4(q, v, h, times[r], k[r], e[r], de[r], tin[r], tout[r], pairs[r], Q, V, acc, matrices, meshes, turning)
        if switches > 0:
            done, span = 0.0, h
            _switching(Q[0], V[0], times[r, 0], e[r, 0], de[r, 0], pairs[r], start, h, meshes, turning, g0, r0)
            for _ in range(MAX_EVENTS):
                _switching(q, v, times[r, 2], e[r, 2], de[r, 2], pairs[r], end, h, meshes, turning, g1, r1)
                theta, crossed = first_crossing(g0, r0, g1, r1, span)
                if not MIN_FRACTION < theta < 1.0 - MIN_FRACTION:
                    break
                at = done + theta * (1.0 - done)  # the crossing, a fraction of the whole sub-step
                q[:] = Q[0]
                v[:] = V[0]
                _part_of(chunk, r, done, at, part)
                _rk4(q, v, (at - done) * h, part[0], part[1], part[2], part[3], part[4], part[5], part[6], Q, V, acc,
                     matrices, meshes, turning)
                located[0] += 1
                _switching(q, v, part[0][2], part[2][2], part[3][2], part[6], end, (at - done) * h, meshes,
                           turning, g0, r0)
                crossed_together(g0, r0, (at - done) * h, crossed)
                done, span = at, (1.0 - at) * h
                _part_of(chunk, r, done, 1.0, part)
                _rk4(q, v, span, part[0], part[1], part[2], part[3], part[4], part[5], part[6], Q, V, acc, matrices,
                     meshes, turning)
        if ends[r]:
            step += 1
            if step % every == 0:
                q_out[written] = q
                v_out[written] = v
                written += 1
    return written
