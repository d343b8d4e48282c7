"""Monte Carlo of calibrate-then-predict (gearcheck.compare.studies.uncertainty) on demo-3p with synthetic measurements.

The 'measurements' are the model's own rms ring acceleration with a 2.5 um transmission error (the only
excitation: constant mesh stiffness) at 1500 and 1200 rpm; each sample draws the mesh damping ratio and the
planet bearings' stiffness, fits the transmission error at 1500 rpm and predicts 1200 rpm.  Runs of 0.05 s keep
the module under half a minute.
"""

import math

import numpy as np
import pandas as pd
import pytest

from gearcheck.compare.studies.calibrate import FitParameter, calibrate
from gearcheck.compare.engine.measure import measure
from gearcheck.compare.studies.uncertainty import NOMINAL, band, drivers, uncertainty_study
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_text, load_train, preset_text
from gearcheck.lumped.time_solver import simulate
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.settings import RunSettings

BASE = preset_text("demo-3p").replace("damping = { ratio = 0.05 }", "damping = { ratio = 0.05 }\n"
                                      "ste = [{ harmonic = 1, amplitude_um = 1.0 }]").replace(
    'model = "rectangular"', 'model = "constant"')  # the transmission error alone excites: it is identifiable
FIT = "stages[0].mesh.ste[0].amplitude_um=0.1:10"
LAWS = {"stages[0].mesh.damping.ratio": "uniform(0.03, 0.08)",
        "stages[0].planet.bearing.radial_stiffness": "lognormal(2e8, 1.5)"}
DURATION = 0.05


@pytest.fixture(scope="module")
def entries():
    truth = load_text(BASE.replace("amplitude_um = 1.0", "amplitude_um = 2.5"), "synthetic")
    out = []
    for rpm in (1500.0, 1200.0):
        model = build_model(load_train(truth, rpm))
        probe = {"quantity": "stage1.ring.ay.world", "metric": "rms", "value": 1.0, "speed": rpm * math.pi / 30,
                 "uncertainty": 0.1, "sensor_band_hz": None}
        value = measure(simulate(model, RunSettings(DURATION)), [probe], 1 / model.excitation.frequency.min())[0]
        out.append({**probe, "value": value})
    return out


def study(entries, **kw):
    args = dict(distributions=LAWS, fits=[FIT], fit_speed=1500.0, predict_speed=1200.0, duration=DURATION,
                samples=2, seed=7)
    return uncertainty_study(BASE, "synthetic", entries, **{**args, **kw})


@pytest.fixture(scope="module")
def frame(entries):
    calls = []
    out = study(entries, nominal=True, progress=lambda done, total, row: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
    return out


def test_one_row_per_sample_each_fitted_at_the_fit_speed(frame):
    assert frame["sample"].tolist() == [NOMINAL, 0, 1]
    assert (frame["error"] == "").all()
    assert frame["runs"].min() > 0
    # every sample's own calibration reaches the 1500 rpm measurement (synthetic: it is reachable)
    assert frame["fit_error:stage1.ring.ay.world.rms"].abs().max() < 0.01
    assert frame["fit_cost"].max() < 1e-2
    # the draws stay in their laws and differ; so do the fitted values and the 1200 rpm predictions
    ratios = frame.loc[frame["sample"] >= 0, "sampled:stages[0].mesh.damping.ratio"]
    assert ratios.between(0.03, 0.08).all() and ratios.nunique() == 2
    assert frame["fitted:stages[0].mesh.ste[0].amplitude_um"].nunique() == 3
    assert frame["predicted:stage1.ring.ay.world.rms"].nunique() == 3
    assert frame.attrs["measured"]["stage1.ring.ay.world.rms@1200"] > 0
    # the nominal row carries the file's own values
    nominal = frame[frame["sample"] == NOMINAL].iloc[0]
    assert nominal["sampled:stages[0].mesh.damping.ratio"] == 0.05
    assert nominal["sampled:stages[0].planet.bearing.radial_stiffness"] == 2e8


def test_nominal_row_is_the_plain_calibration(frame, entries):
    plain = calibrate(BASE, "synthetic", entries, [FitParameter.parse(FIT)], DURATION, fit_speeds=[1500.0])
    nominal = frame[frame["sample"] == NOMINAL].iloc[0]
    assert nominal["duration_s"] == DURATION
    assert nominal["fitted:stages[0].mesh.ste[0].amplitude_um"] == pytest.approx(plain.fitted[0], rel=1e-12)
    assert nominal["predicted:stage1.ring.ay.world.rms"] == pytest.approx(plain.after[1], rel=1e-12)
    assert plain.fitted[0] == pytest.approx(2.5, rel=0.01)


def test_deterministic_for_a_seed_whatever_the_workers_and_chunks(frame, entries):
    again = study(entries, samples=1, first=1, workers=2)
    assert again["sample"].tolist() == [1]
    pd.testing.assert_frame_equal(again.reset_index(drop=True),
                                  frame[frame["sample"] == 1].reset_index(drop=True)[again.columns])


@pytest.mark.parametrize("laws, fits, message", [
    ({"stages[0].mesh.damping.ratio": "uniform(0.1, 0.05)"}, [FIT],
     r"distributions=stages\[0\]\.mesh\.damping\.ratio 'uniform\(0.1, 0.05\)': needs low < high"),
    ({"stages[0].mesh.damping.ratio": "beta(1, 2)"}, [FIT], r"stages\[0\]\.mesh\.damping\.ratio 'beta\(1, 2\)'"),
    ({"stages[0].mesh.damping.ratio": "lognormal(0.05, 0.5)"}, [FIT], r"needs median > 0 and factor > 1"),
    ({"stages[0].sunn.mass": "uniform(1, 2)"}, [FIT], r"distributions=stages\[0\]\.sunn\.mass: no such field"),
    ({"stages[0].mesh.ste[0].amplitude_um": "uniform(1, 2)"}, [FIT], r"it is also fitted \(fits=\)"),
    ({}, [FIT], r"distributions: need at least one"),
    (LAWS, ["stages[0].mesh.ste[0].amplitude_um=5:1"],
     r"^fits='stages\[0\]\.mesh\.ste\[0\]\.amplitude_um=5:1': need 0 < LOW < HIGH"),
])
def test_bad_input_is_refused_in_one_line(entries, laws, fits, message):
    with pytest.raises(GearcheckError, match=message) as info:
        study(entries, distributions=laws, fits=fits)
    assert "\n" not in str(info.value)


def test_bad_speeds_and_workers_are_refused(entries):
    with pytest.raises(GearcheckError, match=r"predict_speed 1000 rpm: no measurement"):
        study(entries, predict_speed=1000.0)
    with pytest.raises(GearcheckError, match=r"^fit_speed must be a positive number of rpm, got -606$"):
        study(entries, fit_speed=-606)
    with pytest.raises(GearcheckError, match=r"workers 0"):
        study(entries, workers=0)
    with pytest.raises(GearcheckError, match=r"samples=0: needs an integer"):
        study(entries, samples=0)


def test_band_and_drivers():
    rng = np.random.Generator(np.random.PCG64(1))
    a, b = rng.uniform(0, 1, 200), rng.uniform(0, 1, 200)
    table = pd.DataFrame({"sample": range(200), "sampled:a": a, "sampled:b": b, "error": "",
                          "predicted:y": np.exp(3 * a) + 0.05 * b})
    d = drivers(table, ["predicted:y"]).set_index("parameter")
    assert d.loc["a", "spearman"] > 0.95 and abs(d.loc["b", "spearman"]) < 0.3
    assert d.loc["a", "r2"] > 0.9 and d.loc["a", "r2_adjusted"] > 0.9
    only_b = drivers(table, ["predicted:y"], ["sampled:b"])
    assert only_b["parameter"].tolist() == ["b"] and abs(only_b.loc[0, "r2_adjusted"]) < 0.05
    q = band(a, (5, 50, 95))
    assert q["value"].tolist() == pytest.approx(np.percentile(a, (5, 50, 95)).tolist())
    assert (q["standard_error"] > 0).all() and (q["standard_error"] < 0.05).all()
    pd.testing.assert_frame_equal(q, band(a, (5, 50, 95)))
    with pytest.raises(GearcheckError, match="at least 2"):
        band([1.0])
