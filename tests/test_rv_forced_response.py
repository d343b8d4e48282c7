"""The RV reducer's steady forced response by harmonic methods and its sensitivity to design parameters
(Yang, Chen & Wang 2018, Eqs. 5-6 and 13-16): closed forms against finite differences, the paper's truncated
Eq. (15), a selection rule, and the quasi-static limit against the static solutions of frozen configurations."""

import functools

import numpy as np
import pytest

from gearcheck.compare.studies.sensitivity import NULL, field_sensitivity
from gearcheck.lumped.assembly import build_model, frozen_at
from gearcheck.lumped.forced_response import parametric_problem
from gearcheck.lumped.fourier_response import fourier_series_response, harmonic_balance_response
from gearcheck.train.loader import preset_text
from gearcheck.lumped.static import static_solution
from gearcheck.train.variants import chained, edited
from gearcheck.shared.errors import SolverError

TEXT = preset_text("rv-reducer")
GRIDS = {"mesh_grid": 1024, "eccentric_grid": 512, "alias": 1e-2}  # coarse and fast: the checks are relative
ECCENTRICITY, SHAFT = "stages[0].crank.eccentricity_mm", "operating.input_shaft_stiffness"
PINS, INERTIA = "stages[0].cycloid.contact.stiffness", "stages[0].sun.inertia"


@functools.cache  # a sensitivity that several tests read is computed once
def sensitivity(parameter, method):
    return field_sensitivity(TEXT, "preset:rv-reducer", parameter, (3, 2), method, **GRIDS)


@pytest.mark.parametrize("method", ["harmonic balance", "Fourier series"])
@pytest.mark.parametrize("parameter", [ECCENTRICITY, SHAFT, PINS, INERTIA])
def test_closed_form_sensitivity_matches_finite_differences(parameter, method):
    """dQ_h/dp and d mean/dp of every coordinate that carries 1e-3 of the largest: the differentiated harmonic
    equations against Richardson-extrapolated central differences of the whole response (step 3e-3), to 1e-6 of
    the coordinate's largest (measured 2e-9 to 5e-7; the Hill matrix's condition, 1e10 N/m beside 1e-3 kg·m²,
    needs iterative refinement for that).  The pins' stiffness moves one of the output's entries by 39 times its
    own relative change: the complex amplitude is smooth there, its modulus is not."""
    assert sensitivity(parameter, method).relative_error() < 1e-6


def test_equation_15_misses_what_the_eccentricity_does_to_the_forcing():
    """The eccentricity moves the stiffness variation and the static deflection, which Eq. (15) holds fixed:
    on the output's largest mesh harmonic (the 3rd, at 746 Hz) it gets the size wrong by more than half
    (measured: the wrong sign, -0.42 times the true derivative).  For an inertia the forcing -Delta K q_mean does
    not move and Eq. (15) is exact."""
    e = sensitivity(ECCENTRICITY, "Fourier series")
    carrier = build_model(edited("rv-reducer", [])).dofs("rv.carrier", "theta")
    row = int(np.argmax(np.abs(e.response.amplitudes[:, carrier]) * (e.response.harmonics[:, 1] == 0)))
    ratio = e.truncated[row, carrier] / e.closed_form[row, carrier]
    assert abs(ratio - 1.0) > 0.5
    inertia = sensitivity("stages[0].sun.inertia", "Fourier series")
    np.testing.assert_allclose(inertia.truncated, inertia.closed_form, rtol=1e-9, atol=1e-12 * np.nanmax(
        np.abs(inertia.closed_form)))


def test_the_suns_mass_is_invisible_to_in_phase_planets():
    """15 sun teeth over 3 planets: the meshes are in phase, their forces on the sun cancel at every harmonic
    (Parker 2000), so the sun's translation is not excited and nothing depends on its mass (to round-off against
    the sensitivity to its inertia)."""
    mass = sensitivity("stages[0].sun.mass", "harmonic balance").closed_form * 1.30
    inertia = sensitivity("stages[0].sun.inertia", "harmonic balance").closed_form * 4.44e-4
    assert np.nanmax(np.abs(mass)) < 1e-6 * np.nanmax(np.abs(inertia))


@pytest.fixture(scope="module")
def slow_eccentric():
    """Constant mesh stiffness and no rotating-frame terms: the eccentrics' 3.6 Hz is the only clock, far below
    the 696 Hz lowest mode, so the steady response is the static solutions of the frozen configurations."""
    model = build_model(edited("rv-reducer", [(r'stiffness = \{ model = "rectangular", mean = 2.68e8 \}',
                                               'stiffness = { model = "constant", mean = 2.68e8 }')]),
                        rotating_frame_terms=False)
    period = 2 * np.pi / abs(model.turning[-1].omega_eccentric)
    times = np.arange(32) / 32 * period
    static = np.array([static_solution(frozen_at(model, t)).q for t in times])
    return model, times, static, parametric_problem(model, eccentric_grid=512, alias=1e-2)


def test_harmonic_balance_reaches_the_quasi_static_limit(slow_eccentric):
    """Harmonic balance converges on the static solutions as harmonics are added.

    - From 20 to 60 harmonics the windups improve by a factor above 3, to within 1e-5 of their largest value
      (measured 3.5e-6 and 4.4e-6): Galerkin over the kinks the pins' contact switches put in the response.
    - A disc's translation lands within 5e-4 (measured 2.6e-4). That is the damping's real phase lag,
      omega c / k = 22.6 rad/s x 1.36e-5 s = 3e-4, which the statics lack; undamped it is 1.4e-4.

    The needle bearings' and pins' damping rows turn with the eccentrics as their stiffness does. With the
    damping matrix of t = 0 held instead, the windups would depart by 1.4e-3."""
    model, times, static, problem = slow_eccentric
    error = {}
    for H in (20, 60):
        q = harmonic_balance_response(problem, H).at(times)
        for name in ("rv.disc1.x", "rv.carrier.theta", "rv.crank1.theta"):
            i = model.dofs.labels().index(name)
            error[H, name] = np.sqrt(np.mean((q[:, i] - static[:, i]) ** 2)) / np.abs(static[:, i]).max()
    for name in ("rv.carrier.theta", "rv.crank1.theta"):
        assert error[60, name] < 1e-5 and error[60, name] < error[20, name] / 3
    assert error[60, "rv.disc1.x"] < 5e-4


def test_the_fourier_series_method_misses_the_mean(slow_eccentric):
    """The paper's method takes the mean deflection K_mean^-1 F; with a stiffness that varies by a third over a
    turn that is not the mean of the deflections: the output's windup comes out 16 % short."""
    model, _, static, problem = slow_eccentric
    i = model.dofs("rv.carrier", "theta")
    fs = fourier_series_response(problem, 8).mean[i]
    assert abs(fs / static[:, i].mean() - 1.0) > 0.1


@pytest.mark.parametrize("train, edit, reason", [
    ("demo-3p", (r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 100.0"), "backlash"),
    ("rv-reducer", (r"^contact = \{ (.*) \}$", r"contact = { \1, clearance_um = 3.0 }"), "has pin clearance:")])
def test_trains_the_harmonic_methods_cannot_hold_are_refused(train, edit, reason):
    """Backlash and the pins' clearance (a dead zone the part names) are contact nonlinearities: one line naming
    each."""
    with pytest.raises(SolverError, match=reason):
        parametric_problem(build_model(edited(train, [edit])))


def test_rows_that_turn_off_any_clock_are_refused_by_what_they_say():
    """A radial spline between two carriers that turn apart gives no clock the harmonic methods can sample (its
    ``clock_speed`` is None): refused in the words the element gives of itself, not by its type."""
    model = build_model(chained(2, radial_stiffness=1e8))
    (coupling,) = model.turning
    assert coupling.clock_speed is None
    with pytest.raises(SolverError, match="a radial coupling between frames that turn apart: use time marching"):
        parametric_problem(model)


def test_a_derivative_that_is_round_off_is_negligible_not_a_failed_check():
    """The RV reducer's sun mass (in-phase planets: nothing depends on it) is independent, not a check that
    fails; demo-3p's sun mass moves the harmonics (sequential phasing) but not the mean deflection (no centripetal
    load at the centre): that part's derivatives are round-off (3.9e-12 relative, the central difference's
    eps/step), and the closed form agrees with the differences where they are not (it read 13 before the null
    parts were set aside)."""
    assert sensitivity("stages[0].sun.mass", "harmonic balance").independent
    demo = field_sensitivity(preset_text("demo-3p"), "preset:demo-3p", "stages[0].sun.mass", None, "Fourier series")
    assert not demo.independent and demo.relative_error() < 1e-6
    mean = demo.difference.mean * demo.value / np.abs(demo.response.mean).max()
    assert np.abs(mean).max() < NULL < np.abs(demo.difference.amplitudes).max() * demo.value / np.abs(
        demo.response.amplitudes).max()
