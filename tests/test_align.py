"""Alignment on synthetic signals: resampling, steady-state detection, lag and amplitude."""

import numpy as np
import pytest

from gearcheck.compare.engine.align import estimate_lag, resample, steady_start, uniform_grid
from gearcheck.compare.engine.metrics import spectral_amplitude, waveform_metrics

FS = 50_000.0


def test_resampler_passes_a_tone_below_and_rejects_one_above_nyquist():
    t = np.arange(0, 0.2, 1 / FS)
    grid = uniform_grid(0.0, t[-1], 5_000.0)  # new Nyquist 2.5 kHz
    inside = resample(t, np.sin(2 * np.pi * 400.0 * t), grid)
    assert spectral_amplitude(inside[100:-100], 5_000.0, [400.0])[0] == pytest.approx(1.0, rel=2e-3)
    # 4.6 kHz would alias to 400 Hz on the new grid if it were decimated without filtering
    outside = resample(t, np.sin(2 * np.pi * 4_600.0 * t), grid)
    assert np.max(np.abs(outside[100:-100])) < 1e-3
    naive = np.interp(grid, t, np.sin(2 * np.pi * 4_600.0 * t))
    assert spectral_amplitude(naive, 5_000.0, [400.0])[0] > 0.5  # what the filter prevents


def test_lag_and_amplitude_ratio_recovered():
    t = np.arange(0, 0.1, 1 / FS)
    f = 417.0

    def wave(time):
        return np.sin(2 * np.pi * f * time) + 0.3 * np.sin(2 * np.pi * 3 * f * time + 0.4)

    lag = 37.3e-6  # 1.865 samples: sub-sample refinement needed
    a = 2.0 + wave(t)
    b = 2.0 + 1.1 * wave(t - lag)
    assert estimate_lag(a, b, FS, 0.5 / f) == pytest.approx(lag, rel=2e-2)
    m = waveform_metrics(a, b, FS, 0.5 / f)
    assert m["lag_s"] == pytest.approx(lag, rel=2e-2)
    assert m["correlation"] > 0.9999  # the lag is removed, not counted as an amplitude error
    assert m["rel_peak_to_peak"] == pytest.approx(0.1, abs=2e-3)
    assert m["nrmse_ac"] == pytest.approx(0.1, abs=3e-3)


def test_steady_state_detector_finds_the_end_of_a_decaying_transient():
    t = np.arange(0, 0.2, 1 / FS)
    f = 500.0
    tau = 0.01  # transient e^{-t/tau}: below the 2e-3 threshold after ~ tau ln(1/2e-3) = 0.062 s
    x = np.sin(2 * np.pi * f * t) + 2.0 * np.exp(-t / tau) * np.sin(2 * np.pi * 173.0 * t)
    start = steady_start(t, x, 1 / f)
    assert start is not None
    assert 0.04 < start < 0.08
    never = np.sin(2 * np.pi * f * t) * (1 + 0.5 * t / t[-1])  # amplitude keeps growing
    assert steady_start(t, never, 1 / f) is None
