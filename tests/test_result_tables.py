"""Results as tables other tools read: a cross-check as a tidy frame (one row per quantity, side and metric), a
time result as an xarray Dataset with units, a mistyped signal or quantity name answered with the closest, and a
run that keeps only the signals asked."""

from __future__ import annotations

import numpy as np
import pytest
from tqdm import tqdm

import gearcheck
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_train


def test_a_crosscheck_is_one_tidy_table(demo_check):
    frame = demo_check.to_dataframe()
    assert list(frame.columns) == ["quantity", "kind", "side", "metric", "value", "unit", "tolerance", "status"]
    assert frame.attrs == {"train": "demo-3p", "verdict": demo_check.verdict, "solvers": ["lumped", "mujoco"]}
    per_quantity = 2 * 5 + 7  # each side: mean, rms, peak-to-peak, peak, integration error; 7 comparisons
    assert len(frame) == per_quantity * len(demo_check.quantities) + 3 * len(demo_check.modal)
    assert not frame.duplicated(["quantity", "side", "metric"]).any()
    q = demo_check.quantities[3]
    row = frame.set_index(["quantity", "side", "metric"])
    assert row.loc[(q.name, "both", "nrmse"), "value"] == q.metrics["nrmse"]
    assert row.loc[(q.name, "both", "nrmse"), "tolerance"] == q.tolerance
    assert row.loc[(q.name, "mujoco", "rms"), "value"] == q.metrics["test"]["rms"]
    assert row.loc[(q.name, "lumped", "rms"), "unit"] == q.unit and row.loc[(q.name, "both", "lag"), "unit"] == "s"
    mode = demo_check.modal[0]
    assert row.loc[("mode 1", "mujoco", "frequency"), "value"] == mode["test_hz"]
    assert row.loc[("mode 1", "both", "rel_error"), "tolerance"] == demo_check.modal_tolerance
    gated = frame[frame["tolerance"].notna()]  # every gated metric within its tolerance in a PASS
    assert demo_check.verdict == "PASS" and (gated["value"].abs() <= gated["tolerance"]).all()


def test_a_time_result_is_an_xarray_dataset_with_units(demo_check):
    run = demo_check.results[0]
    data = run.to_xarray(["stage1.planet1.sun.force", "stage1.ring.ay.world"])
    assert data["t"].attrs["unit"] == "s" and np.array_equal(data["t"].values, run.t)
    force = data["stage1.planet1.sun.force"]
    assert force.dims == ("t",) and np.array_equal(force.values, run["stage1.planet1.sun.force"])
    assert force.attrs == {"unit": "N", "kind": "mesh_force", "description": run.signal(force.name).description}
    assert data.attrs == {"train": "demo-3p", "solver": "lumped"}
    assert len(run.to_xarray().data_vars) == len(run.signals)


def test_a_mistyped_name_is_answered_with_the_closest(demo_check):
    run = demo_check.results[1]
    with pytest.raises(KeyError, match=r"no signal 'stage1\.sun\.alfa' \(did you mean 'stage1\.sun\.alpha'"):
        run["stage1.sun.alfa"]
    with pytest.raises(KeyError, match=r"no compared quantity 'stage1\.ring\.ay\.wrld' \(did you mean "
                                       r"'stage1\.ring\.ay\.world'"):
        demo_check["stage1.ring.ay.wrld"]


def test_progress_true_draws_a_bar_and_closes_it(capsys):
    """``progress=True`` in the front door: tqdm's bar (a text bar outside Jupyter) labelled with the function and
    the train, run to 100 % and closed; a callable still gets the fractions."""
    gearcheck.simulate("demo-3p", duration=0.005, progress=True)
    err = capsys.readouterr().err
    assert "simulate demo-3p: 100%" in err and err.endswith("\n")
    seen = []
    gearcheck.simulate("demo-3p", duration=0.005, progress=seen.append)
    assert seen and seen[-1] == pytest.approx(1.0) and seen == sorted(seen)
    with pytest.raises(gearcheck.GearcheckError):  # a refused call leaves no bar open
        gearcheck.Train("demo-3p").simulate(duration=-1.0, progress=True)
    assert "simulate demo-3p:" in capsys.readouterr().err and not list(tqdm._instances)


@pytest.mark.parametrize("side", [LumpedSide, MujocoSide])
def test_a_run_keeps_only_the_signals_asked_each_as_the_full_run_has_it(side):
    spec = load_train("demo-3p")
    runner = side(spec)
    full = runner.run(RunSettings(0.002))
    kept = ("stage1.ring.ay.world", "stage1.planet1.sun.force", "stage1.carrier.alpha")
    some = runner.run(RunSettings(0.002, signals=kept))
    assert some.names() == [n for n in full.names() if n in kept] and some.values.shape == (full.t.size, 3)
    for name in kept:
        assert np.array_equal(some[name], full[name])
    assert set(some.static) == {"stage1.planet1.sun.force"}
    with pytest.raises(SolverError, match="signals: demo-3p has no signal 'stage1.ring.jerk'"):
        runner.run(RunSettings(0.002, signals=("stage1.ring.jerk",)))
