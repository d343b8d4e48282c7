"""Forced response of systems with periodic / quasi-periodic stiffness: the Fourier series method against its
closed form, harmonic balance against time marching, where the former departs from the latter, and the
closed-form response sensitivities against finite differences."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gearcheck.lumped.fourier_response import (
    ParametricProblem,
    fourier_series_response,
    harmonic_balance_response,
    hill_operator,
)
from gearcheck.lumped.response_sensitivity import (
    fourier_series_sensitivity,
    harmonic_balance_sensitivity,
    parameter_derivative,
)
from gearcheck.shared.errors import SolverError

GOLDEN = (1 + 5**0.5) / 2


def one_dof(eps, omega, m=1.0, c=0.1, k=1.0, F=1.0, phase=0.0):
    """m x'' + c x' + k (1 + eps cos(omega t + phase)) x = F."""
    return ParametricProblem(np.eye(1) * m, np.eye(1) * c, lambda th: np.array([[k * (1 + eps * np.cos(th[0]))]]),
                             (omega,), np.array([F]), phases=(phase,))


ROWS = np.array([[1, 0, 0], [1, -1, 0], [0, 1, -1], [0, 0, 1], [1, 0, -1]], float)  # deflection of each spring
BASE = dict(m2=1.5, k2=3.0, d2=0.6, c=0.05, ecc=0.2)  # mass, mesh-2 mean and variation, damping, "eccentricity"
W2, PHASES = 0.45, (0.3, 1.1)


def three_dof_data(**changes):
    """(M, C, K_of, F) of a 3-DOF chain: a support, mesh 1 on theta_1, mesh 2 on theta_2, a support, and a spring
    that varies with both angles.  ``ecc`` enters mesh 1's mean and variation and the load nonlinearly; all data
    are analytic in the parameters, so complex steps give their exact derivatives."""
    p = {**BASE, **changes}

    def K_of(th):
        a, b = th
        k = [1.0, 2 * (1 + p["ecc"] ** 2) * (1 + p["ecc"] * np.cos(a) + 0.1 * np.sin(2 * a)),
             p["k2"] + p["d2"] * np.cos(b), 0.8, 0.5 * (1 + 0.1 * np.cos(a) * np.cos(b))]
        return ROWS.T @ (np.asarray(k)[:, None] * ROWS)

    M = np.diag([1.0, p["m2"], 0.8])
    C = p["c"] * (np.eye(3) + ROWS.T @ ROWS)
    return M, C, K_of, np.array([1 / (1 + p["ecc"]), 0.0, 0.5])


def three_dof(ratio=GOLDEN, grid=16, **changes):
    M, C, K_of, F = three_dof_data(**changes)
    return ParametricProblem(M, C, K_of, (ratio * W2, W2), F, phases=PHASES, grid=grid)


def three_dof_derivative(name, ratio=GOLDEN, step=1e-30):
    """The problem and the exact derivatives of its data with respect to parameter ``name`` (complex step)."""
    M, C, K_of, F = three_dof_data(**{name: BASE[name] + 1j * step})
    return three_dof(ratio), parameter_derivative(three_dof(ratio), M.imag / step, C.imag / step,
                                                   lambda th: K_of(th).imag / step, F.imag / step)


def march(problem, duration, window, samples=4000):
    """Steady state by time marching (DOP853, rtol 1e-10) from the static deflection at rest: q on ``samples``
    uniform times over the last ``window`` seconds, endpoint excluded."""
    n, omegas = problem.n, np.asarray(problem.omegas)
    M_inv = np.linalg.inv(problem.M)

    def rate(t, y):
        K = problem.K_of(tuple(omegas * t + np.asarray(problem.phases)))
        return np.r_[y[n:], M_inv @ (problem.F - problem.C @ y[n:] - K @ y[:n])]

    q0 = np.linalg.solve(problem.K_mean, problem.F)
    t = duration - window + window * np.arange(samples) / samples
    run = solve_ivp(rate, (0, duration), np.r_[q0, np.zeros(n)], method="DOP853", rtol=1e-10,
                    atol=1e-12 * np.abs(q0).max(), t_eval=t)
    return run.t, run.y[:n].T


def rms(x):
    return np.sqrt(np.mean(np.square(x), axis=0))


def relative_rms(q, reference):
    """RMS difference over the RMS of the reference's fluctuation, per coordinate."""
    return rms(q - reference) / rms(reference - reference.mean(axis=0))


def flat(response):
    return np.concatenate([response.mean, response.amplitudes.ravel()])


# ---------------------------------------------------------------------------------------------- the two solvers


def constant_three_dof():
    M, C, K_of, F = three_dof_data()
    K = K_of((0.0, 0.0))
    return ParametricProblem(M, C, lambda th: K, (GOLDEN * W2, W2), F)


@pytest.mark.parametrize("problem, orders", [(one_dof(0.0, 0.7), 4), (constant_three_dof(), (3, 3))],
                         ids=["1dof", "3dof"])
def test_constant_stiffness_has_no_harmonics(problem, orders):
    static = np.linalg.solve(problem.K_mean, problem.F)
    for response in fourier_series_response(problem, orders), harmonic_balance_response(problem, orders):
        assert np.abs(response.amplitudes).max() <= 1e-15 * np.abs(static).max()  # uncoupled blocks, zero forcing
        np.testing.assert_allclose(response.mean, static, rtol=1e-13)


@pytest.mark.parametrize("omega, c, phase", [(0.3, 0.1, 0.0), (0.95, 0.02, 1.3), (1.7, 0.0, -2.0)])
def test_fourier_series_amplitude_is_the_closed_form(omega, c, phase):
    """Q_1 = -eps k q_mean e^{i phase} / (k - omega^2 m + i omega c), all other harmonics zero; FFT round-off only."""
    m, k, eps, F = 1.3, 2.0, 0.25, 0.7
    response = fourier_series_response(one_dof(eps, omega, m, c, k, F, phase), 5)
    q = F / k
    exact = -eps * k * q * np.exp(1j * phase) / (k - omega**2 * m + 1j * omega * c)
    assert response.harmonic(1)[0] == pytest.approx(exact, rel=1e-13)
    assert not response.amplitudes[1:].any()
    assert response.mean[0] == pytest.approx(q, rel=1e-14)
    t = np.linspace(0, 20, 7)
    np.testing.assert_allclose(response.at(t)[:, 0], q + np.real(exact * np.exp(1j * omega * t)), rtol=1e-13)


def test_harmonic_balance_tends_to_the_fourier_series_method_as_eps_squared():
    """The dropped product Delta K Delta q is O(eps^2), and the difference is even in eps (eps -> -eps is a half-period
    shift): halving eps quarters it to O(eps^2), measured 4.003 and 4.0009."""
    diff = [np.linalg.norm(flat(harmonic_balance_response(one_dof(eps, 0.7), 8))
                           - flat(fourier_series_response(one_dof(eps, 0.7), 8))) for eps in (0.04, 0.02, 0.01)]
    assert diff[0] / diff[1] == pytest.approx(4, rel=5e-3)
    assert diff[1] / diff[2] == pytest.approx(4, rel=2e-3)


def test_harmonic_balance_is_the_time_marched_steady_state_one_dof():
    """eps = 0.4, zeta = 0.05, omega = 0.7 omega_n: harmonic balance with 12 harmonics against DOP853 marched for
    600 s (transient e^{-30}), Fourier-analysed over the last 10 periods.  They agree to 4e-11; asserted: 1 %."""
    problem = one_dof(0.4, 0.7)
    period = 2 * np.pi / 0.7
    t, q = march(problem, 600, 10 * period)
    balanced = harmonic_balance_response(problem, 12)
    assert relative_rms(balanced.at(t), q)[0] < 1e-2
    marched = 2 * np.exp(-1j * np.outer(balanced.frequencies[:3], t)) @ q[:, 0] / len(t)
    np.testing.assert_allclose(marched, balanced.amplitudes[:3, 0], atol=1e-3 * abs(marched[0]))
    assert relative_rms(fourier_series_response(problem, 12).at(t), q)[0] > 0.1  # the dropped product matters here


@pytest.mark.parametrize("ratio", [23 / 13, GOLDEN], ids=["23/13", "golden"])
def test_harmonic_balance_is_the_time_marched_steady_state_two_frequencies(ratio):
    """3 DOF, two mesh frequencies (ratio 23/13 as in the RV reducer, or the golden ratio: no common period),
    zeta 4-6 %: the (8, 8) lattice against DOP853 marched for 700 s, compared over the last 300 s (transient below
    e^{-14} there).  Agreement 1-3e-7; asserted: 1 %.  The Fourier series method is 8-24 % off."""
    problem = three_dof(ratio)
    t, q = march(problem, 700, 300)
    assert relative_rms(harmonic_balance_response(problem, (8, 8)).at(t), q).max() < 1e-2
    assert relative_rms(fourier_series_response(problem, (8, 8)).at(t), q).max() > 0.05


def test_the_fourier_series_method_misses_the_superharmonic_parametric_resonance():
    """omega = omega_n / 2 (the h = 4 tongue of omega = 2 omega_n / h), eps = 0.3, zeta = 0.01: Delta K Delta q
    puts eps^2 forcing at 2 omega = omega_n, which the Fourier series method drops (Delta K has no 2nd harmonic).
    The fluctuation is 6.5 times what it predicts; harmonic balance tracks time marching (5e-9; asserted 1 %)."""
    problem = one_dof(0.3, 0.5, c=0.02)
    t, q = march(problem, 2000, 10 * 2 * np.pi / 0.5)
    series = fourier_series_response(problem, 12).at(t)
    assert rms(q - q.mean(axis=0))[0] > 5 * rms(series - series.mean(axis=0))[0]
    assert relative_rms(harmonic_balance_response(problem, 12).at(t), q)[0] < 1e-2


def test_unconverged_stiffness_harmonics_are_refused():
    square = ParametricProblem(np.eye(1), 0.1 * np.eye(1), lambda th: np.array([[1 + 0.1 * np.sign(np.cos(th[0]))]]),
                               (0.7,), np.ones(1))
    with pytest.raises(SolverError, match="not converged"):
        fourier_series_response(square, 3)
    loose = ParametricProblem(square.M, square.C, square.K_of, square.omegas, square.F, grid=256, tol=0.01)
    assert abs(fourier_series_response(loose, 3).harmonic(1)[0]) > 0  # accepted once the truncation is stated


def test_a_separable_stiffness_is_sampled_on_its_axes_only():
    """K = K_1(theta_1) + K_2(theta_2): 2 g + 4 samples instead of g^2 give the same harmonics (to round-off);
    a stiffness with a mixed term is refused."""
    M, C, K_of, F = three_dof_data()
    calls = []

    def separable(th):
        calls.append(th)
        return K_of((th[0], 0.0)) + K_of((0.0, th[1])) - K_of((0.0, 0.0))

    torus = ParametricProblem(M, C, separable, (GOLDEN * W2, W2), F, phases=PHASES, grid=16)
    on_torus = torus.stiffness_harmonics
    del calls[:]
    on_axes = replace(torus, separable=True).stiffness_harmonics
    assert len(calls) == 2 * 16 + 4 and on_axes.keys() == on_torus.keys()
    for h, K_h in on_torus.items():
        np.testing.assert_allclose(on_axes[h], K_h, atol=1e-14 * np.abs(torus.K_mean).max())
    with pytest.raises(SolverError, match="not separable"):
        replace(three_dof(), separable=True).stiffness_harmonics


def test_a_forty_dof_chain_stays_sparse_on_a_289_point_lattice():
    """40 DOF, springs alternately on theta_1 and theta_2: five stiffness harmonics, each tridiagonal, so the Hill
    operator has at most 5 P (3n - 2) entries on the P = 17 x 17 lattice.  (It solves in 1.7 s with one BLAS thread;
    solved here on 13 x 13 to keep the file quick.)"""
    n, P = 40, 17 * 17
    rows = np.eye(n) - np.eye(n, k=1)

    def K_of(th):
        return rows.T @ ((1 + 0.2 * np.cos(np.resize(th, n)))[:, None] * rows)

    problem = ParametricProblem(np.eye(n), 0.02 * K_of((np.pi / 2, np.pi / 2)), K_of, (GOLDEN * W2, W2), np.ones(n),
                                separable=True)
    assert len(problem.stiffness_harmonics) == 5
    assert hill_operator(problem, (8, 8)).nnz <= 5 * P * (3 * n - 2)
    response = harmonic_balance_response(problem, (6, 6))
    assert response.amplitudes.shape == (13 * 13 // 2, n) and np.isfinite(response.amplitudes).all()


# ----------------------------------------------------------------------------------------------- sensitivities


def central_difference(response_at, x):
    """d/dx by central differences, Richardson-extrapolated (error O(h^4) ~ 1e-12 with h = 1e-3 |x|)."""
    h = 1e-3 * abs(x)
    d = [(response_at(x + s) - response_at(x - s)) / (2 * s) for s in (h, h / 2)]
    return (4 * d[1] - d[0]) / 3


PARAMETERS = ["m2", "k2", "d2", "c", "ecc"]  # a mass, a mean stiffness, a stiffness variation, damping, both


@pytest.mark.parametrize("name", PARAMETERS)
@pytest.mark.parametrize("method", ["fourier series", "harmonic balance"])
def test_sensitivities_match_finite_differences(name, method):
    """dQ_h and d|Q_h| of every harmonic and coordinate, and d mean, to 1e-6 of their largest (measured 1e-12 to
    1e-9, the finite differences' own error)."""
    orders = (6, 6)
    if method == "fourier series":
        solve, sensitivity = fourier_series_response, fourier_series_sensitivity
    else:
        solve, sensitivity = harmonic_balance_response, harmonic_balance_sensitivity
    problem, derivative = three_dof_derivative(name)
    exact = sensitivity(problem, derivative, orders)
    fd = central_difference(lambda x: flat(solve(three_dof(**{name: x}), orders)), BASE[name])
    assert np.abs(flat(exact.derivative) - fd).max() <= 1e-6 * np.abs(fd).max()
    significant = np.abs(exact.response.amplitudes) > 1e-6 * np.abs(exact.response.amplitudes).max()
    fd_modulus = central_difference(lambda x: np.abs(solve(three_dof(**{name: x}), orders).amplitudes), BASE[name])
    assert np.abs(exact.d_modulus - fd_modulus)[significant].max() <= 1e-6 * np.abs(fd_modulus).max()


@pytest.mark.parametrize("name", PARAMETERS)
def test_eq15_is_exact_only_where_the_forcing_does_not_depend_on_the_parameter(name):
    """Masses and damping leave A = -Delta K q_mean alone: Eq. (15) is exact.  A mean stiffness moves q_mean, a
    variation moves Delta K (Eq. 15 then gives zero), the eccentricity moves both and the load."""
    problem, derivative = three_dof_derivative(name)
    true = fourier_series_sensitivity(problem, derivative, (6, 6)).derivative.amplitudes
    eq15 = fourier_series_sensitivity(problem, derivative, (6, 6), truncated=True).derivative.amplitudes
    error = np.abs(eq15 - true).max() / np.abs(true).max()
    if name in ("m2", "c"):
        assert error < 1e-12
    else:
        assert error > 0.1
    if name == "d2":
        assert not eq15.any()  # Lambda does not contain Delta K


@pytest.mark.parametrize("r", [0.3, 0.5, 0.9, 1.2, 2.0])
def test_eq15_over_the_true_derivative_is_one_over_two_minus_r_squared(r):
    """1 DOF, xi = k_mean with Delta k held: Q = -Delta k F / (k L), L = k - omega^2 m + i omega c, so
    dQ/dk = Delta k F (L + k) / (k L)^2 while Eq. (15) keeps -L^-1 (dL/dk) Q = Delta k F / (k L^2): the ratio is
    k / (L + k) = 1 / (2 - r^2 + 2 i zeta r), 1 / (2 - r^2) undamped as in the paper; round-off only."""
    m, k, dk, F = 2.0, 5.0, 0.4, 1.0
    omega = r * np.sqrt(k / m)
    for c in (0.0, 0.3):
        zeta = c / (2 * np.sqrt(k * m))
        problem = ParametricProblem(np.eye(1) * m, np.eye(1) * c, lambda th: np.array([[k + dk * np.cos(th[0])]]),
                                    (omega,), np.array([F]))
        derivative = parameter_derivative(problem, dK_of=lambda th: np.ones((1, 1)))
        true, eq15 = (fourier_series_sensitivity(problem, derivative, 1, truncated=t) for t in (False, True))
        ratio = eq15.derivative.amplitudes[0, 0] / true.derivative.amplitudes[0, 0]
        assert ratio == pytest.approx(1 / (2 - r**2 + 2j * zeta * r), rel=1e-12)
        if c == 0:
            assert eq15.d_modulus[0, 0] / true.d_modulus[0, 0] == pytest.approx(1 / (2 - r**2), rel=1e-12)


def test_a_turning_load_is_a_force_harmonic():
    """A load f cos(omega t) on a constant spring: both methods give the forced oscillator's exact amplitude
    f / (k - omega^2 m + i omega c) (to round-off), and time-varying damping C(t) = c (1 + cos omega t) on a
    static deflection alone exerts no force (harmonic balance's mean and harmonics stay those of the statics)."""
    m, c, k, f, w = 1.0, 0.1, 1.0, 0.3, 0.7
    problem = replace(one_dof(0.0, w, m, c, k), F_of=lambda th: np.array([f * np.cos(th[0])]))
    exact = f / (k - w * w * m + 1j * w * c)
    for solve in (fourier_series_response, harmonic_balance_response):
        r = solve(problem, 3)
        assert r.harmonic(1)[0] == pytest.approx(exact, rel=1e-12)
        assert abs(r.harmonic(2)[0]) < 1e-14 and r.mean[0] == pytest.approx(1.0 / k, rel=1e-12)
    still = replace(one_dof(0.0, w, m, c, k), C_of=lambda th: np.array([[c * np.cos(th[0])]]))
    r = harmonic_balance_response(still, 3)
    assert r.mean[0] == pytest.approx(1.0 / k, rel=1e-12) and np.abs(r.amplitudes).max() < 1e-14


def test_a_cross_of_two_boxes_is_a_lattice_and_nests():
    """The union of boxes is ordered like a box (row P-1-j is minus row j, h = 0 in the centre), and a box inside
    another adds nothing: the same response to the last digit."""
    from gearcheck.lumped.fourier_response import harmonic_lattice

    cross = harmonic_lattice(((3, 1), (1, 3)))
    assert len(cross) == 7 * 3 + 3 * 7 - 3 * 3
    np.testing.assert_array_equal(cross[::-1], -cross)
    assert not cross[len(cross) // 2].any()
    problem = three_dof(GOLDEN)
    box, nested = (harmonic_balance_response(problem, orders) for orders in ((4, 4), ((4, 4), (2, 3))))
    np.testing.assert_array_equal(nested.amplitudes, box.amplitudes)


def test_a_cross_holds_each_clocks_high_harmonics_at_a_fraction_of_the_box():
    """3 DOF, frequency ratio the golden number: the cross ((8, 3), (3, 8)), 104 lattice points, against DOP853
    marched 700 s, to 1 % as the (8, 8) box's 289 points do; the (3, 3) box, which both contain, is coarser."""
    problem = three_dof(GOLDEN)
    t, q = march(problem, 700, 300)
    error = {str(o): relative_rms(harmonic_balance_response(problem, o).at(t), q).max()
             for o in (((8, 3), (3, 8)), (3, 3))}
    assert error["((8, 3), (3, 8))"] < 1e-2 and error["((8, 3), (3, 8))"] < error["(3, 3)"] / 3
