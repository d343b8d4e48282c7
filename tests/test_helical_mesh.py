"""Contact-line length, thin-slice and ISO helical stiffness, and quasi-static tip relief
(train.helical_mesh) against closed forms derived by hand.

Measured: the slice model equals k_pair cos(beta_b) L(xi) for a constant k_pair at any slice count
(to 1e-12), and converges as 1/n^2 for a k_pair varying along the path; Maatar & Velex's printed A_k, B_k agree with
the FFT of the closed form to 1e-9 with tau = xi (xi = 0: a line enters at the plane's corner).
"""

from __future__ import annotations

import math
from functools import partial
from types import SimpleNamespace

import numpy as np
import pytest

import gearcheck
from gearcheck.train import iso6336
from gearcheck.train.helical_mesh import (
    contact_force,
    contact_line_fourier,
    contact_line_length,
    contact_pairs,
    contact_table,
    loaded_transmission_error,
    mean_contact_line_length,
    relief_separation,
    slice_stiffness,
)

PITCH, WIDTH, K0 = 0.01, 0.03, 1.4e10  # transverse base pitch m, face width m, pair stiffness N/m^2


def helix(eps_b):
    """Base helix angle giving overlap ratio eps_b at PITCH and WIDTH."""
    return math.atan(eps_b * PITCH / WIDTH)


def constant(value):
    return lambda s: np.full_like(s, value)


def exact_mean(function, eps_a, eps_b):
    """Cycle mean of a piecewise-linear function of xi: trapezoid rule on a grid holding every kink."""
    kinks = np.mod([0.0, eps_a, eps_b, eps_a + eps_b], 1.0)
    xi = np.unique(np.concatenate([np.linspace(0.0, 1.0, 1001), kinks]))
    return np.trapezoid(function(xi), xi)


def printed_maatar_velex(eps_a, eps_b, k):
    """A_k, B_k as printed by Maatar & Velex (1996)."""
    a, b, d = (2 * np.pi * k * e for e in (eps_a, eps_b, eps_a + eps_b))
    den = 2 * eps_a * eps_b * np.pi**2 * k**2
    return (np.cos(b) + np.cos(a) - np.cos(d) - 1) / den, (np.sin(b) + np.sin(a) - np.sin(d)) / den


def fft_coefficients(samples, mean, harmonics):
    x = np.fft.rfft(samples) / samples.size
    return 2 * x[1:harmonics + 1].real / mean, -2 * x[1:harmonics + 1].imag / mean


@pytest.mark.parametrize("eps_a, eps_b", [(1.55, 1.3), (1.3, 0.4), (1.9, 2.7), (1.62, 0.0)])
def test_mean_contact_line_length_is_eps_a_b_over_cos_beta_b(eps_a, eps_b):
    length = partial(contact_line_length, eps_a=eps_a, eps_b=eps_b, face_width=WIDTH, base_helix_angle=helix(eps_b))
    if eps_b > 0:  # continuous and piecewise linear: the trapezoid rule with the kinks is exact
        assert exact_mean(length, eps_a, eps_b) == pytest.approx(eps_a * WIDTH / math.cos(helix(eps_b)), rel=1e-12)
    else:
        assert np.mean(length(np.arange(100000) / 100000)) == pytest.approx(eps_a * WIDTH, rel=1e-12)
    assert mean_contact_line_length(eps_a, WIDTH, helix(eps_b)) == eps_a * WIDTH / math.cos(helix(eps_b))


def test_spur_limit_is_the_rectangular_wave():
    eps_a = 1.62
    xi = np.linspace(-2.0, 2.0, 4001)
    pairs = 1 + (np.mod(xi, 1.0) < 0.62)
    assert np.array_equal(contact_line_length(xi, eps_a, 0.0, WIDTH, 0.0), WIDTH * pairs)
    # a vanishing overlap converges to it away from the jumps, and its harmonics to the square wave's
    far = np.abs(np.mod(xi + 0.5, 1.0) - 0.5) > 1e-3
    far &= np.abs(np.mod(xi - 0.62 + 0.5, 1.0) - 0.5) > 1e-3
    thin = contact_line_length(xi, eps_a, 1e-6, WIDTH, helix(1e-6))
    np.testing.assert_allclose(thin[far], WIDTH * pairs[far], rtol=1e-9)
    k = np.arange(1, 21)
    a, b = contact_line_fourier(eps_a, 0.0, 20)
    np.testing.assert_allclose(a, np.sin(2 * np.pi * k * eps_a) / (np.pi * k * eps_a), atol=1e-15)
    np.testing.assert_allclose(b, (1 - np.cos(2 * np.pi * k * eps_a)) / (np.pi * k * eps_a), atol=1e-15)


@pytest.mark.parametrize("eps_b", [1.0, 2.0, 3.0])
def test_whole_overlap_ratio_gives_constant_length(eps_b):
    xi = np.linspace(0.0, 1.0, 997)
    length = contact_line_length(xi, 1.47, eps_b, WIDTH, helix(eps_b))
    np.testing.assert_allclose(length, 1.47 * WIDTH / math.cos(helix(eps_b)), rtol=1e-12)
    assert np.max(np.abs(contact_line_fourier(1.47, eps_b, 50))) < 1e-15


@pytest.mark.parametrize("eps_a, eps_b", [(1.55, 1.3), (1.3, 0.4), (1.9, 2.7), (1.5, 0.5)])
def test_fourier_series_matches_closed_form_and_printed_maatar_velex(eps_a, eps_b):
    """Derived, printed and FFT coefficients agree with tau = xi; from the instant a line leaves
    (tau = xi - eps_a - eps_b) B_k changes sign, and from the trapezoid's centre it vanishes."""
    n, harmonics, beta_b = 2**16, 12, helix(eps_b)
    mean = mean_contact_line_length(eps_a, WIDTH, beta_b)
    x = np.arange(n) / n
    a, b = contact_line_fourier(eps_a, eps_b, harmonics)
    a_printed, b_printed = printed_maatar_velex(eps_a, eps_b, np.arange(1, harmonics + 1))
    np.testing.assert_allclose(a, a_printed, atol=1e-14)
    np.testing.assert_allclose(b, b_printed, atol=1e-14)
    a_fft, b_fft = fft_coefficients(contact_line_length(x, eps_a, eps_b, WIDTH, beta_b), mean, harmonics)
    np.testing.assert_allclose(a_fft, a, atol=1e-9)
    np.testing.assert_allclose(b_fft, b, atol=1e-9)
    a_exit, b_exit = fft_coefficients(contact_line_length(x + eps_a + eps_b, eps_a, eps_b, WIDTH, beta_b), mean,
                                      harmonics)
    np.testing.assert_allclose((a_exit, b_exit), (a, -b), atol=1e-9)
    centred = contact_line_length(x + (eps_a + eps_b) / 2, eps_a, eps_b, WIDTH, beta_b)
    assert np.max(np.abs(fft_coefficients(centred, mean, harmonics)[1])) < 1e-9


def test_slices_add_up_to_the_contact_line_model():
    """Constant k_pair: the slices' exact parts of each contact line add up to k_pair cos(beta_b) L(xi) for any
    number of slices; a k_pair varying along the path is sampled at each part's middle (the midpoint rule),
    so the error falls as 1/n^2."""
    eps_a, eps_b = 1.55, 1.3
    xi = np.linspace(0.0, 1.0, 4001)
    exact = K0 * math.cos(helix(eps_b)) * contact_line_length(xi, eps_a, eps_b, WIDTH, helix(eps_b))
    for n in (1, 3, 8, 64):
        np.testing.assert_allclose(slice_stiffness(xi, eps_a, eps_b, PITCH, WIDTH, constant(K0), n), exact,
                                   rtol=1e-12, atol=1e-9 * K0 * WIDTH)
    def curved(s):
        return K0 * (1.0 + 0.5 * np.sin(np.pi * s / (eps_a * PITCH)))

    reference = slice_stiffness(xi, eps_a, eps_b, PITCH, WIDTH, curved, 4096)
    counts = np.array([8, 16, 32, 64])
    errors = [np.max(np.abs(slice_stiffness(xi, eps_a, eps_b, PITCH, WIDTH, curved, n) - reference)) for n in counts]
    assert np.polyfit(np.log(counts), np.log(errors), 1)[0] == pytest.approx(-2.0, abs=0.2)
    spur = slice_stiffness(xi, eps_a, 0.0, PITCH, WIDTH, constant(K0), 7)
    np.testing.assert_allclose(spur, K0 * contact_line_length(xi, eps_a, 0.0, WIDTH, 0.0), rtol=1e-14)


def spur_mesh(z1, z2, x1, x2, eps, width):
    gear = partial(SimpleNamespace, dedendum=1.25, pressure_angle=math.radians(20.0), face_width=width,
                   helix_angle=0.0, normal_pressure_angle=math.radians(20.0))
    return SimpleNamespace(central_gear=gear(teeth=z2, profile_shift=x2), planet_gear=gear(teeth=z1, profile_shift=x1),
                           internal=False, geometry=SimpleNamespace(contact_ratio=eps))


def single(z1, z2, x1, x2, beta):
    return iso6336.single_stiffness_of(z1, x1, z2, x2, beta)


def test_iso_helical_reduces_to_the_spur_module_and_applies_z_n_and_cos_beta():
    assert iso6336.mean_stiffness_of(single(21, 47, 0.2, -0.1, 0.0), 1.63, 0.04) == pytest.approx(
        iso6336.mean_mesh_stiffness(spur_mesh(21, 47, 0.2, -0.1, 1.63, 0.04)), rel=1e-14)
    beta, alpha = math.radians(25.0), math.radians(20.0)
    cos_bb2 = 1 - (math.sin(beta) * math.cos(alpha)) ** 2
    virtual = [z / (cos_bb2 * math.cos(beta)) for z in (21, 47)]
    assert single(21, 47, 0.2, -0.1, beta) == pytest.approx(
        math.cos(beta) * single(*virtual, 0.2, -0.1, 0.0), rel=1e-14)
    ring = single(21, math.inf, 0.0, 0.0, beta) / single(21, math.inf, 0.0, 0.0, 0.0)
    assert math.cos(beta) < ring < 1.0  # cos(beta) lowers c', the larger z_n1 raises it back a little


@pytest.mark.parametrize("beta_deg, eps_a", [(0.0, 1.2), (15.0, 1.45), (25.0, 1.6), (35.0, 1.95)])
def test_contact_line_mean_from_iso_single_stiffness_against_iso_mean(beta_deg, eps_a):
    """k_pair = c' per unit face width (k_per_length = c' cos(beta_b)): model mean c' eps_a b, ISO's
    c' (0.75 eps_a + 0.25) b; ratio eps_a / (0.75 eps_a + 0.25) in [1, 8/7) for 1 <= eps_a < 2."""
    beta = math.radians(beta_deg)
    beta_b = math.asin(math.sin(beta) * math.cos(math.radians(20.0)))
    eps_b = WIDTH * math.tan(beta_b) / PITCH
    c_single = single(23, 71, 0.1, 0.0, beta)
    model = exact_mean(lambda xi: c_single * math.cos(beta_b) * contact_line_length(xi, eps_a, eps_b, WIDTH, beta_b),
                       eps_a, eps_b) if eps_b else c_single * eps_a * WIDTH
    ratio = model / iso6336.mean_stiffness_of(c_single, eps_a, WIDTH)
    assert 1.0 <= ratio < 8 / 7
    assert ratio == pytest.approx(eps_a / (0.75 * eps_a + 0.25), rel=1e-12)


def test_the_helical_presets_mean_stiffnesses_are_iso_6336s():
    """helical-planetary's sun and ring meshes carry ISO 6336-1 method B's c_gamma_alpha b to the 3 digits
    written in the file (Mo et al. 2024 print 5e9 and 8e9 N/m, 17 and 21 times these: see the preset)."""
    spec = gearcheck.load("helical-planetary")
    for mesh in spec.meshes:
        assert mesh.stiffness["mean"] == pytest.approx(iso6336.mean_mesh_stiffness(mesh), rel=2e-3), mesh.id


@pytest.mark.parametrize("shape, power", [("linear", 1), ("parabolic", 2)])
def test_relief_separation_at_both_tips(shape, power):
    path = 0.016
    s = np.array([0.0, 0.002, 0.004, 0.008, 0.013, 0.016])
    e = relief_separation(s, path, 12e-6, 0.005, 20e-6, 0.004, shape)
    expected = [20e-6, 20e-6 * 0.5**power, 0.0, 0.0, 12e-6 * 0.4**power, 12e-6]
    np.testing.assert_allclose(e, expected, rtol=1e-12, atol=1e-20)


def two_pair_case(load):
    """Spur eps_a = 1.6 at xi = 0.25: pair A (s = 0.25 p) in the driven gear's linear relief, pair B
    (s = 1.25 p) unrelieved; k_pair rises along the path."""
    path = 1.6 * PITCH
    def k_pair(s):
        return K0 * (1 + s / path)

    relief = partial(relief_separation, path_length=path, amount_driver=0.0, length_driver=0.0,
                     amount_driven=20e-6, length_driven=0.6 * PITCH)
    k, e = contact_pairs(0.25, 1.6, 0.0, PITCH, WIDTH, k_pair, 1, relief)
    return loaded_transmission_error(load, k, e), WIDTH * k_pair(np.array([0.25, 1.25]) * PITCH), 20e-6 * 0.35 / 0.6


@pytest.mark.parametrize("load", [3000.0, 20000.0])
def test_a_relieved_pair_sheds_load_as_two_springs_solved_by_hand(load):
    result, (k_a, k_b), e_a = two_pair_case(load)
    if load <= k_b * e_a:  # A's gap stays open
        delta, loads = load / k_b, [0.0, load]
    else:
        delta = (load + k_a * e_a) / (k_a + k_b)
        loads = [k_a * (delta - e_a), k_b * delta]
    assert result.approach == pytest.approx(delta, rel=1e-13)
    np.testing.assert_allclose(result.pair_loads, loads, rtol=1e-13, atol=1e-9)
    assert result.unloaded == 0.0
    assert result.stiffness == pytest.approx(k_b if load <= k_b * e_a else k_a + k_b, rel=1e-14)


def test_without_relief_loaded_te_is_load_over_mesh_stiffness():
    xi = np.linspace(0.0, 1.0, 501)
    def k_pair(s):
        return K0 * (0.6 + 0.4 * np.sin(np.pi * s / (1.55 * PITCH)))

    k, e = contact_pairs(xi, 1.55, 1.3, PITCH, WIDTH, k_pair, 20)
    result = loaded_transmission_error(8000.0, k, e)
    mesh = slice_stiffness(xi, 1.55, 1.3, PITCH, WIDTH, k_pair, 20)
    np.testing.assert_allclose(result.approach, 8000.0 / mesh, rtol=1e-13)
    np.testing.assert_allclose(result.stiffness, mesh, rtol=1e-13)
    np.testing.assert_allclose(loaded_transmission_error(0.0, k, e).stiffness, mesh, rtol=1e-13)  # tied gaps


def test_long_linear_relief_optimum_is_the_single_pair_deflection():
    """Spur, constant pair stiffness k, eps_a = 1.6, equal linear reliefs C over (eps_a - 1) p_bt from
    each tip (to the single-contact points).  Single-pair zone: delta = F/k.  Double zone, w in [0, 1)
    across it: gaps C (1 - w) and C w, both closed at delta = (F/k + C)/2; for C > F/k the entering
    pair opens near w = 0, where delta falls to F/k.  So ptp = |C - F/k| / 2: the optimum is C* = F/k,
    found by a sweep to within half its step."""
    eps_a, load = 1.6, 5000.0
    path, reach = eps_a * PITCH, (eps_a - 1) * PITCH
    single = load / (K0 * WIDTH)
    xi = np.unique(np.concatenate([np.linspace(0.0, 1.0, 2001), [0.3]]))
    amounts = np.linspace(0.0, 2 * single, 41)[1:]
    ptp = []
    for amount in amounts:
        relief = partial(relief_separation, path_length=path, amount_driver=amount, length_driver=reach,
                         amount_driven=amount, length_driven=reach)
        delta = loaded_transmission_error(load, *contact_pairs(xi, eps_a, 0.0, PITCH, WIDTH, constant(K0), 1,
                                                                relief)).approach
        ptp.append(np.ptp(delta))
    np.testing.assert_allclose(ptp, np.abs(amounts - single) / 2, rtol=1e-9, atol=1e-15)
    assert abs(amounts[np.argmin(ptp)] - single) <= (amounts[1] - amounts[0]) / 2 + 1e-18


def test_loads_balance_and_approach_grows_with_load():
    xi = np.linspace(0.0, 1.0, 301)
    path = 1.55 * PITCH
    relief = partial(relief_separation, path_length=path, amount_driver=15e-6, length_driver=0.4 * path,
                     amount_driven=10e-6, length_driven=0.3 * path, shape="parabolic")
    k, e = contact_pairs(xi, 1.55, 1.3, PITCH, WIDTH, constant(K0), 16, relief)
    loads = np.array([0.0, 500.0, 5e3, 5e4, 5e5])[:, None]
    result = loaded_transmission_error(loads, k, e)
    np.testing.assert_allclose(result.pair_loads.sum(axis=-1), np.broadcast_to(loads, (5, xi.size)),
                               rtol=1e-12, atol=1e-9)
    assert np.all(np.diff(result.approach, axis=0) > 0)
    assert np.array_equal(result.approach[0], result.unloaded) and np.array_equal(result.unloaded, e.min(axis=-1))
    np.testing.assert_allclose(result.stiffness[1:], np.where(result.pair_loads > 0, k, 0).sum(axis=-1)[1:],
                               rtol=1e-12)
    np.testing.assert_allclose(result.stiffness[0], np.where(e == e.min(axis=-1, keepdims=True), k, 0).sum(-1),
                               rtol=1e-12)  # unloaded: the pairs that touch first, towards more load
    force, stiffness = contact_force(contact_table(k, e), result.approach)  # the table inverts the solve
    np.testing.assert_allclose(force, np.broadcast_to(loads, force.shape), rtol=1e-10, atol=1e-8)
    np.testing.assert_allclose(stiffness, result.stiffness, rtol=1e-12)


def test_contact_force_on_many_approach_position_pairs_matches_the_sum():
    xi = np.linspace(0.0, 1.0, 64, endpoint=False)
    relief = partial(relief_separation, path_length=1.55 * PITCH, amount_driver=15e-6, length_driver=0.005,
                     amount_driven=10e-6, length_driven=0.004)
    k, e = contact_pairs(xi, 1.55, 1.3, PITCH, WIDTH, constant(K0), 10, relief)
    table = contact_table(k, e)
    rng = np.random.default_rng(0)
    rows, delta = rng.integers(0, xi.size, 5000), rng.uniform(-5e-6, 40e-6, 5000)
    force, stiffness = contact_force(table.at(rows), delta)
    reach = delta[:, None] - e[rows]
    np.testing.assert_allclose(force, np.sum(k[rows] * np.maximum(reach, 0.0), axis=-1), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(stiffness, np.sum(np.where(reach >= 0, k[rows], 0.0), axis=-1), rtol=1e-12)


def trapezoids(xi, eps_a, eps_b):
    """The lines' shares of the face summed, as contact_line_length's docstring defines them, in numpy: a row of
    lines per sample."""
    u = np.mod(xi, 1.0)[..., None] + np.arange(math.floor(eps_a + eps_b) + 1)
    if eps_b == 0.0:
        return (u < eps_a).sum(axis=-1).astype(float)
    return ((np.clip(u, 0.0, eps_b) - np.clip(u - eps_a, 0.0, eps_b)) / eps_b).sum(axis=-1)


@pytest.mark.parametrize("eps_a, eps_b", [(1.55, 0.0), (1.4, 0.7), (2.3, 2.9), (0.6, 0.4), (1.8, 4.9), (1.2, 8.3)])
def test_the_compiled_contact_lines_are_the_formula_in_numpy(eps_a, eps_b):
    """The compiled sum over the lines (both solvers call it at every stage time) is numpy's evaluation of the
    trapezoids to the bit below 8 lines, where numpy adds one by one too (every edge: the corners, whole cycles, both
    signs, huge positions, the infinities and NaN), and within a few rounding errors of numpy's pairwise sum above."""
    rng = np.random.default_rng(int(10 * eps_a + eps_b))
    kinks = np.mod([0.0, eps_a, eps_b, eps_a + eps_b], 1.0)
    edges = (kinks + np.arange(-3, 4)[:, None]).ravel()
    xi = np.concatenate([rng.uniform(-1e3, 1e3, 20000), rng.uniform(-2, 2, 20000), edges,
                         np.nextafter(edges, np.inf), np.nextafter(edges, -np.inf),
                         [0.0, -0.0, 5e-324, -5e-324, 1 - 2**-53, 2.0**60, -2.0**60, 1e20, -3e19, np.inf, -np.inf,
                          np.nan]])
    beta = helix(eps_b)
    with np.errstate(invalid="ignore"):
        expected = WIDTH / math.cos(beta) * trapezoids(xi, eps_a, eps_b)
    length = contact_line_length(xi.reshape(-1, 2), eps_a, eps_b, WIDTH, beta)
    assert length.shape == (xi.size // 2, 2)
    if math.floor(eps_a + eps_b) + 1 < 8:
        assert np.array_equal(length.ravel(), expected, equal_nan=True)
    else:
        np.testing.assert_allclose(length.ravel(), expected, rtol=8 * np.finfo(float).eps, atol=0.0)


@pytest.mark.parametrize("call, message", [
    (lambda: contact_line_length(0.0, 0.4, 0.5, WIDTH, helix(0.5)), "below 1"),
    (lambda: contact_line_length(0.0, 1.5, -0.1, WIDTH, 0.1), "negative"),
    (lambda: contact_line_length(0.0, 1.5, 0.5, -WIDTH, helix(0.5)), "face width"),
    (lambda: contact_line_length(0.0, 1.5, 0.5, WIDTH, 0.0), "disagree"),
    (lambda: contact_line_fourier(1.5, 0.5, 0), "harmonic"),
    (lambda: slice_stiffness(0.0, 1.5, 0.5, PITCH, WIDTH, constant(K0), 0), "slices"),
    (lambda: slice_stiffness(0.0, 1.5, 0.5, -PITCH, WIDTH, constant(K0), 4), "positive"),
    (lambda: relief_separation(0.0, 0.016, -1e-5, 0.004, 0.0, 0.0), "negative"),
    (lambda: relief_separation(0.0, 0.016, 1e-5, 0.0, 0.0, 0.0), "needs a relief length"),
    (lambda: relief_separation(0.02, 0.016, 1e-5, 0.004, 0.0, 0.0), "outside"),
    (lambda: relief_separation(0.0, 0.016, 1e-5, 0.004, 0.0, 0.0, "cubic"), "shape"),
    (lambda: loaded_transmission_error(-1.0, [1e8, 1e8], [0.0, 1e-6]), "load"),
    (lambda: loaded_transmission_error(1.0, [0.0, 0.0], [0.0, 1e-6]), "no tooth pair"),
    (lambda: contact_table([-1e8, 1e8], [0.0, 0.0]), ">= 0"),
])
def test_impossible_inputs_raise_value_error(call, message):
    with pytest.raises(ValueError, match=message):
        call()
