"""The spectral lines of a sampled signal that jumps, against its Fourier series in closed form: a pulse train
(the force of a mesh whose stiffness switches) plus a fast cosine, sampled with a step that divides its period,
where the plain windowed sum aliases the jumps onto the lines and the jump-corrected projection does not."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.compare.engine.line_projection import harmonics, jumps, singularities

F = 270.0  # Hz, the "mesh" frequency
DUTY = 0.37  # of the pulse: +1 on [0, DUTY / F) of each period, -1 elsewhere
OFFSET = 0.21  # periods: where the pulses start


def pulse_lines(k: np.ndarray) -> np.ndarray:
    """Complex amplitudes A e^{i phase} of the pulse train at k F: the train is 2 p - 1, p the pulse of height 1,
    p(t) = DUTY + sum 2 sin(pi k DUTY) / (pi k) cos(2 pi k F (t - t0) - pi k DUTY)."""
    t0 = OFFSET / F
    return 4.0 * np.sin(np.pi * k * DUTY) / (np.pi * k) * np.exp(-1j * (np.pi * k * DUTY + 2 * np.pi * k * F * t0))


def signal(steps_per_period: int, cycles: float = 40.3):
    h = 1.0 / (F * steps_per_period)
    t = 0.0137 + h * np.arange(int(cycles * steps_per_period))
    phase = (F * t - OFFSET) % 1.0
    pulse = np.where(phase < DUTY, 1.0, -1.0)
    fast = 0.8 * np.cos(2 * np.pi * 13.3 * F * t + 0.4)  # 13.3 F: ten samples a period at 133 steps
    n = np.arange(math.floor(F * t[0] - OFFSET), math.ceil(F * t[-1] - OFFSET) + 1)
    switches = np.sort(np.concatenate([(n + OFFSET) / F, (n + OFFSET + DUTY) / F]))
    return t, pulse + fast, switches[(switches > t[0]) & (switches < t[-1])], 1.0 / h


@pytest.mark.parametrize("steps", [133, 266, 532])
def test_jump_corrected_lines_match_the_fourier_series(steps):
    t, x, switches, fs = signal(steps)
    k = np.arange(1, 4)
    exact = pulse_lines(k)
    plain = harmonics(t, x, k * F, fs)[:, 0]
    corrected = harmonics(t, x, k * F, fs, switches)[:, 0]
    plain_error = np.max(np.abs(plain - exact))
    corrected_error = np.max(np.abs(corrected - exact))
    # the plain sum aliases the jumps onto the lines: of order (jump) x (lines per step) ~ 2 x 1/steps
    assert plain_error > 0.1 / steps
    # corrected: what is left is the window's leakage and the extrapolation of the fast cosine, far below
    assert corrected_error < 2e-4 and corrected_error < plain_error / 50


def test_the_plain_error_halves_with_the_step_and_the_corrected_one_does_not_grow():
    errors = []
    for steps in (133, 266, 532):
        t, x, switches, fs = signal(steps)
        k = np.arange(1, 4)
        errors.append((np.max(np.abs(harmonics(t, x, k * F, fs)[:, 0] - pulse_lines(k))),
                       np.max(np.abs(harmonics(t, x, k * F, fs, switches)[:, 0] - pulse_lines(k)))))
    plain = np.array([e[0] for e in errors])
    assert plain[0] / plain[2] > 2.5  # first order in the step
    assert max(e[1] for e in errors) < plain[2] / 20


def test_the_jumps_are_measured_from_the_samples():
    t, x, switches, fs = signal(133)
    times, sizes = jumps(t, x[:, None], switches)
    assert times == pytest.approx(switches[(switches > t[3]) & (switches < t[-4])], abs=1e-12)
    expected = np.where(np.isclose(((times * F - OFFSET) % 1.0), 0.0, atol=1e-6) |
                        np.isclose(((times * F - OFFSET) % 1.0), 1.0, atol=1e-6), 2.0, -2.0)
    # less the fast cosine's extrapolation: a quadratic through three samples misses it by at most A (w h)^3 on
    # each side of a switch less than one step away
    omega_h = 2 * np.pi * 13.3 * F / fs
    assert sizes[:, 0] == pytest.approx(expected, abs=2 * 0.8 * omega_h**3)


def test_a_smooth_signal_is_left_as_the_plain_projection_gives_it():
    t, _, switches, fs = signal(133)
    smooth = np.cos(2 * np.pi * F * t + 0.3) + 0.2 * np.cos(2 * np.pi * 3 * F * t)
    plain = harmonics(t, smooth, [F, 2 * F, 3 * F], fs)
    corrected = harmonics(t, smooth, [F, 2 * F, 3 * F], fs, switches)
    # the spurious "jumps" of a smooth signal are its cubic remainder, (w h)^3 ~ 1e-4 of it, each one projected
    # over one step: the lines move by a few millionths of their size
    assert np.max(np.abs(corrected - plain)) < 1e-5


def test_each_column_is_corrected_at_its_own_switches():
    """Switches given column by column: each column's lines are those of a call on that column alone with its own
    switches (to round-off: a product over several columns sums in another order); a column whose switches are
    not given keeps its jumps in the plain sum (the pulse train's lines at the step of 133 samples a period err by
    the aliased jumps), and one array serves every column."""
    t, x, switches, fs = signal(133)
    columns = np.stack([x, 2.0 * x, np.cos(2 * np.pi * F * t)], axis=1)
    own = [switches, switches, np.empty(0)]
    lines = [F, 2 * F, 3 * F]
    together = harmonics(t, columns, lines, fs, own)
    for j in range(3):
        alone = harmonics(t, columns[:, j], lines, fs, own[j])[:, 0]
        assert together[:, j] == pytest.approx(alone, rel=1e-13, abs=1e-15)
    assert np.max(np.abs(together[:, 0] - pulse_lines(np.arange(1, 4)))) < 1e-3
    assert np.max(np.abs(harmonics(t, x, lines, fs)[:, 0] - pulse_lines(np.arange(1, 4)))) > 1e-2
    shared = harmonics(t, columns[:, :2], lines, fs, switches)
    assert shared.ravel() == pytest.approx(together[:, :2].ravel(), rel=1e-13)
    with pytest.raises(ValueError, match="2 arrays of switches for 3 columns"):
        harmonics(t, columns, lines, fs, own[:2])


def test_a_kink_alone_takes_no_jump_whatever_lies_beyond_the_window_edge():
    """Instants are measured in groups (closer than three samples), and a group of kinks alone changes the slope and
    takes no jump, to the bit, even where a switch lies past it among the samples left out at the window's end (a
    cubic, so the two sides' quadratic extrapolations do not meet by themselves)."""
    t = np.linspace(0.0, 1.0, 101)
    x = t**3 + 2.0 * np.maximum(t - 0.5, 0.0) + (t >= 0.995)
    times, sizes, slopes = singularities(t, x[:, None], [0.995], [0.25, 0.5])
    assert times.tolist() == [0.25, 0.5]
    assert sizes.tolist() == [[0.0], [0.0]]
    assert slopes[:, 0] == pytest.approx([0.0, 2.0], abs=1e-3)
    times, sizes, _ = singularities(t, x[:, None], [0.5], [0.25])  # a switch of its own: its jump is measured
    assert sizes[1, 0] == pytest.approx(0.0, abs=1e-5) and sizes[1, 0] != 0.0
