"""Helical (and spur) mesh stiffness from the lines of contact, and quasi-static tip relief.

Mesh position xi as in :mod:`gearcheck.train.mesh_stiffness`: mesh cycles elapsed, one cycle =
one transverse base pitch p_bt of travel along the path of contact.  The plane of action is a
rectangle eps_a p_bt long and b wide; a tooth's line of contact crosses it at the base helix angle
beta_b, spanning eps_b = b tan(beta_b) / p_bt pitches, and moves one pitch per cycle.  At xi = 0 a
new line enters the plane at its corner (face edge z = 0, start of contact); the face point z
enters eps_b z/b cycles later.  Lengths in m, stiffnesses in N/m (per unit face width: N/m^2),
normal to the flanks.  Pure functions on plain numbers, vectorised over xi.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


def _check_ratios(eps_a: float, eps_b: float) -> None:
    _require(eps_a > 0.0, f"transverse contact ratio eps_a = {eps_a} is not positive")
    _require(eps_a + eps_b >= 1.0, f"total contact ratio eps_a + eps_b = {eps_a + eps_b} is below 1: the teeth "
                                   "lose contact")
    _require(eps_b >= 0.0, f"overlap ratio eps_b = {eps_b} is negative")


def _check_line(eps_b: float, face_width: float, base_helix_angle: float) -> None:
    _require(face_width > 0.0, f"face width {face_width} m is not positive")
    _require(0.0 <= base_helix_angle < math.pi / 2, f"base helix angle {base_helix_angle} rad is not in [0, pi/2)")
    _require((eps_b > 0.0) == (base_helix_angle > 0.0),
             f"overlap ratio {eps_b} and base helix angle {base_helix_angle} rad disagree on whether it is helical")


def contact_line_length(xi, eps_a: float, eps_b: float, face_width: float, base_helix_angle: float):
    """Total length L(xi) of the lines of contact in the plane of action, m (Maatar & Velex 1996).

    A line entered xi + j cycles ago (j = 0, 1, ...) covers the face points z/b = t with
    0 <= xi + j - eps_b t < eps_a; that share of the face, clip(u, 0, eps_b) - clip(u - eps_a, 0, eps_b)
    over eps_b with u = xi + j, is a trapezoid in u (the box [0, eps_a) smeared over eps_b).  A
    line over face width w is w / cos(beta_b) long.  eps_b = 0: the spur rectangular wave.
    """
    from gearcheck.train.compiled_excitation import contact_line_shares  # numba on first use, not at import

    _check_ratios(eps_a, eps_b)
    _check_line(eps_b, face_width, base_helix_angle)
    xi = np.asarray(xi, dtype=float)
    shares = np.empty(xi.shape)
    contact_line_shares(np.ravel(xi), float(eps_a), float(eps_b), math.floor(eps_a + eps_b) + 1, shares.reshape(-1))
    return face_width / math.cos(base_helix_angle) * shares


def mean_contact_line_length(eps_a: float, face_width: float, base_helix_angle: float) -> float:
    """L_m = eps_a b / cos(beta_b), m: each trapezoid has area eps_a (Maatar & Velex 1996)."""
    _require(eps_a > 0.0, f"transverse contact ratio eps_a = {eps_a} is not positive")
    _require(face_width > 0.0, f"face width {face_width} m is not positive")
    _require(0.0 <= base_helix_angle < math.pi / 2, f"base helix angle {base_helix_angle} rad is not in [0, pi/2)")
    return eps_a * face_width / math.cos(base_helix_angle)


def contact_line_fourier(eps_a: float, eps_b: float, harmonics: int):
    """(A_k, B_k), k = 1..harmonics, with L(xi) = L_m [1 + sum A_k cos(2 pi k xi) + B_k sin(2 pi k xi)].

    The trapezoid is the box [0, eps_a) convolved with the box (1/eps_b) [0, eps_b), so its transform
    at k is eps_a sinc(k eps_a) sinc(k eps_b) exp(-i pi k (eps_a + eps_b)) and
    A_k - i B_k = 2 sinc(k eps_a) sinc(k eps_b) exp(-i pi k (eps_a + eps_b)) (sinc x = sin(pi x)/(pi x)).
    Expanded, this is Maatar & Velex's (1996) printed A_k and B_k, sign for sign, with tau = xi.
    """
    _check_ratios(eps_a, eps_b)
    _require(harmonics >= 1, f"harmonics = {harmonics}: need at least one")
    k = np.arange(1, harmonics + 1)
    amplitude = 2.0 * np.sinc(k * eps_a) * np.sinc(k * eps_b)
    phase = np.pi * k * (eps_a + eps_b)
    return amplitude * np.cos(phase), amplitude * np.sin(phase)


def contact_pairs(xi, eps_a: float, eps_b: float, base_pitch: float, face_width: float,
                  pair_stiffness_per_width: Callable, slices: int = 1, separation: Callable | None = None):
    """(k_j, e_j) of every slice-and-pair j at each mesh position: shape xi.shape + (slices * ceil(eps_a + eps_b),).

    Thin-slice model (Velex & Maatar 1996; Eritenel & Parker 2012): the face is cut into ``slices`` slices
    of width b/n.  A tooth's contact line, entered u cycles ago, covers the face points t = z/b with
    0 <= u - eps_b t < eps_a; its part inside slice i, a fraction f of the slice's width (exact, so k is
    continuous in xi and the slices add up to the contact-line model), sits at the middle of that part,
    t_m, which is s = (u - eps_b t_m) p_bt from the start of contact.  The pair's stiffness is
    f (b/n) k_pair(s), k_pair per unit face width (ISO 6336-1's convention; per unit contact-line length
    that is k_pair cos(beta_b)), and its gap ``separation(s)`` (m, e.g. a partial of
    :func:`relief_separation`; zero if None).  Pairs out of contact: k_j = 0, e_j = inf.  Spur gears
    (eps_b = 0): whole slices, the rectangular wave.  Both callables get arrays of s (m).
    """
    _check_ratios(eps_a, eps_b)
    _require(base_pitch > 0.0 and face_width > 0.0, f"base pitch {base_pitch} m, face width {face_width} m: "
             "both must be positive")
    _require(int(slices) == slices and slices >= 1, f"slices = {slices}: need a positive whole number")
    xi = np.asarray(xi, dtype=float)
    u = np.mod(xi, 1.0)[..., None, None] + np.arange(math.ceil(eps_a + eps_b))  # (..., 1, teeth)
    lo, hi = np.arange(slices)[:, None] / slices, (np.arange(slices)[:, None] + 1) / slices  # slice edges in t
    if eps_b > 0.0:
        first, last = np.maximum((u - eps_a) / eps_b, lo), np.minimum(u / eps_b, hi)
    else:
        inside = (u >= 0) & (u < eps_a)
        first, last = np.where(inside, lo, 1.0), np.where(inside, hi, 0.0)
    fraction = np.clip((last - first) * slices, 0.0, 1.0)
    inside = fraction > 0.0
    s = (u - eps_b * 0.5 * (first + last))[inside] * base_pitch
    shape = xi.shape + (slices * u.shape[-1],)
    k = np.zeros(np.broadcast_shapes(u.shape, lo.shape))
    k[inside] = fraction[inside] * face_width / slices * np.asarray(pair_stiffness_per_width(s), dtype=float)
    e = np.full(k.shape, np.inf)
    e[inside] = 0.0 if separation is None else np.asarray(separation(s), dtype=float)
    return k.reshape(shape), e.reshape(shape)


def slice_stiffness(xi, eps_a: float, eps_b: float, base_pitch: float, face_width: float,
                    pair_stiffness_per_width: Callable, slices: int):
    """Mesh stiffness k(xi) = sum over slices and pairs of f (b/n) k_pair(s), N/m (thin-slice model).

    With constant k_pair it is k_pair cos(beta_b) L(xi), the contact-line model, for any n (the slices'
    parts of each line add up to the line); otherwise the midpoint rule within each slice, O(1/n^2).
    """
    return contact_pairs(xi, eps_a, eps_b, base_pitch, face_width, pair_stiffness_per_width, slices)[0].sum(axis=-1)


def relief_separation(s, path_length: float, amount_driver: float, length_driver: float,
                      amount_driven: float, length_driven: float, shape: str = "linear"):
    """Initial separation e(s) >= 0 (m) of a tooth pair at s from the start of the path of contact.

    The driven gear's tip meets the driver's root at s = 0, the driver's tip leaves at s = path_length;
    within a relief length L_a of its tip end, at distance d from it, a flank is relieved by
    C_a ((L_a - d) / L_a)^k, k = 1 (linear) or 2 (parabolic) (e.g. Tavakoli & Houser 1986).
    """
    power = {"linear": 1, "parabolic": 2}.get(shape)
    _require(power is not None, f"relief shape {shape!r} is neither 'linear' nor 'parabolic'")
    _require(path_length > 0.0, f"path of contact length {path_length} m is not positive")
    for name, amount, length in (("driver", amount_driver, length_driver), ("driven", amount_driven, length_driven)):
        _require(amount >= 0.0 and length >= 0.0, f"{name} relief amount {amount} m, length {length} m: negative")
        _require(amount == 0.0 or length > 0.0, f"{name} relief amount {amount} m needs a relief length > 0")
    s = np.asarray(s, dtype=float)
    _require(not np.any((s < -1e-12 * path_length) | (s > (1 + 1e-12) * path_length)),
             f"contact positions outside the path of contact [0, {path_length}] m")

    def relief(d, amount, length):
        return amount * np.clip(1.0 - d / length, 0.0, None) ** power if amount > 0.0 else np.zeros_like(d)

    return relief(s, amount_driven, length_driven) + relief(path_length - s, amount_driver, length_driver)


class ContactTable(NamedTuple):
    """Per mesh position (leading axes) the pairs sorted by separation e_1 <= e_2 <= ... (inf: out of
    contact) with cumulative stiffness K_m = sum_{i<=m} k_i and moment S_m = sum_{i<=m} k_i e_i, so that
    F(delta) = K_m delta - S_m while e_m < delta <= e_{m+1}."""

    separation: np.ndarray
    stiffness: np.ndarray
    moment: np.ndarray

    def at(self, index) -> ContactTable:
        """The rows of the mesh positions ``index`` (any numpy index into the leading axes)."""
        return ContactTable(*(a[index] for a in self))


def contact_table(stiffness, separation) -> ContactTable:
    """The :class:`ContactTable` of pair stiffnesses k_j (N/m) and separations e_j (m), last axis the pairs."""
    k, e = np.broadcast_arrays(np.asarray(stiffness, dtype=float), np.asarray(separation, dtype=float))
    _require(not np.any(np.isnan(k) | np.isnan(e) | (k < 0.0)), "pair stiffnesses must be >= 0, separations not NaN")
    closed = (k > 0.0) & np.isfinite(e)
    _require(bool(np.all(closed.any(axis=-1))), "a mesh position has no tooth pair in contact")
    e = np.where(closed, e, np.inf)
    order = np.argsort(e, axis=-1, kind="stable")
    e, k = np.take_along_axis(e, order, -1), np.take_along_axis(np.where(closed, k, 0.0), order, -1)
    return ContactTable(e, np.cumsum(k, axis=-1), np.cumsum(k * np.where(np.isfinite(e), e, 0.0), axis=-1))


def contact_force(table: ContactTable, approach):
    """(F, dF/ddelta) = (sum_j k_j max(0, delta - e_j), sum of k_j over e_j <= delta: the derivative
    towards more load), vectorised over the approach delta (m) broadcast against the table's mesh positions."""
    delta = np.asarray(approach, dtype=float)
    shape = np.broadcast_shapes(delta.shape, table.separation.shape[:-1])
    e, big_k, moment = (np.broadcast_to(a, shape + a.shape[-1:]) for a in table)
    delta = np.broadcast_to(delta, shape)
    closed = np.sum(e <= delta[..., None], axis=-1)
    last = np.maximum(closed - 1, 0)[..., None]
    k = np.where(closed > 0, np.take_along_axis(big_k, last, -1)[..., 0], 0.0)
    return k * delta - np.where(closed > 0, np.take_along_axis(moment, last, -1)[..., 0], 0.0), k


class LoadedContact(NamedTuple):
    approach: np.ndarray  # delta, m: the loaded static transmission error (mesh approach)
    pair_loads: np.ndarray  # N, per slice-and-pair, in the input's order
    unloaded: np.ndarray  # min_j e_j, m: the unloaded static transmission error
    stiffness: np.ndarray  # dF/ddelta towards more load, N/m: sum of k_j over e_j <= delta


def loaded_transmission_error(load, stiffness, separation) -> LoadedContact:
    """Quasi-static loaded TE: delta solving sum_j k_j max(0, delta - e_j) = F (Harris 1958).

    F(delta) is piecewise linear and increasing; with the pairs sorted by e, pair m+1 closes at
    F_m = K_m e_{m+1} - S_m, so delta = (F + S_m) / K_m for the m with F_{m-1} <= F < F_m, exactly.
    ``load`` (N, >= 0) broadcasts against the mesh positions (leading axes of k_j and e_j).
    """
    load = np.asarray(load, dtype=float)
    _require(not np.any(np.isnan(load) | (load < 0.0)), "the mesh load must be >= 0 N")
    table = contact_table(stiffness, separation)
    e, big_k, moment = table
    following = e[..., 1:]
    closing = np.where(np.isfinite(following),
                       big_k[..., :-1] * np.where(np.isfinite(following), following, 0.0) - moment[..., :-1], np.inf)
    shape = np.broadcast_shapes(load.shape, e.shape[:-1])
    m = np.sum(np.broadcast_to(closing, shape + closing.shape[-1:]) <= np.broadcast_to(load, shape)[..., None], -1)
    k_m = np.take_along_axis(np.broadcast_to(big_k, shape + e.shape[-1:]), m[..., None], -1)[..., 0]
    s_m = np.take_along_axis(np.broadcast_to(moment, shape + e.shape[-1:]), m[..., None], -1)[..., 0]
    approach = (load + s_m) / k_m
    k, e_in = np.broadcast_arrays(np.asarray(stiffness, dtype=float), np.asarray(separation, dtype=float))
    gap = np.where((k > 0.0) & np.isfinite(e_in), e_in, np.inf)
    return LoadedContact(approach, k * np.maximum(approach[..., None] - gap, 0.0), e[..., 0], k_m)
