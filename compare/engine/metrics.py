"""Error metrics between a reference signal a (lumped) and a test signal b (MuJoCo).

All metrics are computed on the common, steady, lag-aligned window:

* ``mean``, ``rms`` = sqrt(mean(x^2)), ``peak_to_peak`` = max - min, ``peak`` = max |x|, per solver;
* relative errors ``rel_rms``, ``rel_peak_to_peak``, ``rel_peak`` = (b - a)/|a|;
* ``nrmse`` = rms(b - a)/rms(a): the normalised RMS error of the aligned waveforms;
* ``nrmse_ac`` = rms((b - mean b) - (a - mean a))/rms(a - mean a): the same for the fluctuation;
* ``correlation``: Pearson correlation of the fluctuations;
* ``lag_s``: the delay of b behind a that maximises their cross-correlation (removed before
  the waveform metrics, reported on its own);
* spectral amplitudes |X(f)| at the mesh harmonics and carrier sidebands from a
  Hann-windowed projection, A(f) = 2 |sum w_n x_n e^{-i 2 pi f t_n}| / sum w_n, and their
  relative errors.  A line is reported only when the window resolves it (T > 4/spacing).
"""

from __future__ import annotations

import numpy as np

from gearcheck.compare.engine.align import estimate_lag, shift_signal
from gearcheck.compare.engine.line_projection import harmonics


def _stats(x: np.ndarray) -> dict[str, float]:
    return {"mean": float(np.mean(x)), "rms": float(np.sqrt(np.mean(x**2))),
            "peak_to_peak": float(np.ptp(x)), "peak": float(np.max(np.abs(x)))}


def _rel(b: float, a: float) -> float | None:
    return (b - a) / abs(a) if a != 0 else None


def statistics(a: np.ndarray, b: np.ndarray) -> dict:
    """Each signal's mean, rms, peak-to-peak and peak (``reference``, ``test``) and their relative differences."""
    sa, sb = _stats(a), _stats(b)
    return {"reference": sa, "test": sb, "rel_rms": _rel(sb["rms"], sa["rms"]),
            "rel_peak_to_peak": _rel(sb["peak_to_peak"], sa["peak_to_peak"]), "rel_peak": _rel(sb["peak"], sa["peak"])}


def waveform_metrics(a: np.ndarray, b: np.ndarray, fs: float, max_lag: float) -> dict:
    lag = estimate_lag(a, b, fs, max_lag)
    aligned = shift_signal(b, lag, fs)
    trim = int(np.ceil(abs(lag) * fs)) + 1
    a_w, b_w = (a[trim:-trim], aligned[trim:-trim]) if a.size > 2 * trim + 8 else (a, aligned)
    metrics = statistics(a_w, b_w)
    da, db = a_w - np.mean(a_w), b_w - np.mean(b_w)
    rms_a, rms_da = metrics["reference"]["rms"], float(np.sqrt(np.mean(da**2)))
    metrics |= {
        "nrmse": float(np.sqrt(np.mean((b_w - a_w) ** 2)) / rms_a) if rms_a > 0 else None,
        "nrmse_ac": float(np.sqrt(np.mean((db - da) ** 2)) / rms_da) if rms_da > 0 else None,
        "correlation": float(np.corrcoef(da, db)[0, 1]) if rms_da > 0 and np.std(db) > 0 else None,
        "lag_s": lag,
    }
    return metrics


def spectral_amplitude(x: np.ndarray, fs: float, frequencies) -> np.ndarray:
    """Amplitude of the tone at each frequency (Hann-windowed projection) of samples at the rate ``fs``."""
    return np.abs(harmonics(np.arange(x.size) / fs, x, frequencies, np.inf)[:, 0])


def spectral_lines(f_mesh: float, f_carrier: float, duration: float, harmonics: int = 4) -> list[tuple[str, float]]:
    """Mesh harmonics k f_m and, when the window resolves them, sidebands k f_m +/- f_c."""
    lines = [(f"{k}x mesh", k * f_mesh) for k in range(1, harmonics + 1)]
    if f_carrier > 0 and duration * f_carrier > 4.0:
        for k in range(1, harmonics):
            lines.append((f"{k}x mesh - carrier", k * f_mesh - f_carrier))
            lines.append((f"{k}x mesh + carrier", k * f_mesh + f_carrier))
    return lines


def spectral_metrics(amp_a, amp_b, lines) -> list[dict]:
    """Line by line, the reference's and the test's amplitudes (at the lines' frequencies) and their relative
    difference."""
    return [{"line": name, "frequency_hz": float(f), "reference": float(x), "test": float(y),
             "rel_error": _rel(float(y), float(x))} for (name, f), x, y in zip(lines, amp_a, amp_b)]


def modal_metrics(fa, fb, types_a, types_b, multiplicity) -> list[dict]:
    """Frequency-by-frequency comparison of reference (a) and test (b) natural frequencies (Hz),
    with each side's mode types and the reference's multiplicities."""
    rows = []
    for i, (a, b) in enumerate(zip(fa, fb)):
        rel = abs(b - a) / a if a > 0 else abs(b - a)
        rows.append({"mode": i + 1, "reference_hz": float(a), "test_hz": float(b), "type": types_a[i],
                     "test_type": types_b[i], "multiplicity": multiplicity[i], "rel_error": float(rel)})
    return rows
