"""The sweep engine: speed sweeps, parameter grids and Monte Carlo reduced to one tidy Parquet table; the
harmonic projection against a signal of known amplitude and phase; byte-identical tables from the same
inputs, whether run in this process, on local processes or on a Dask LocalCluster; a cache that resumes an
interrupted sweep; bad input refused with one line and nothing written."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pyarrow.parquet as pq
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.studies import point_backends
from gearcheck.compare.studies import sweep as sw
from gearcheck.compare.studies.distributions import Distribution, draw_samples
from gearcheck.compare.engine.line_projection import harmonics
from gearcheck.compare.engine.plan import TrainPlan
from gearcheck.compare.studies.sweep_lines import counted
from gearcheck.compare.presentation.sweep_plots import crossings
from gearcheck.train.kinematics import kinematics
from gearcheck.shared.errors import GearcheckError, SolverError

FAST = {"solvers": ("lumped",), "duration": 0.03}  # demo-3p: ~0.15 s a point
SPEEDS = [1000.0, 1500.0, 2000.0]


def test_the_harmonic_projection_recovers_amplitude_and_phase():
    fs, f1 = 20000.0, 270.0
    t = np.arange(4000) / fs + 0.013  # a window that starts anywhere and holds no whole number of cycles
    x = 5.0 + 2.0 * np.cos(2 * np.pi * f1 * t + 0.7) + 0.5 * np.cos(2 * np.pi * 2 * f1 * t - 2.0)
    z = harmonics(t, np.stack([x, -x], axis=1), np.array([f1, 2 * f1, 3 * f1, 12000.0]), fs)
    assert abs(z[0, 0]) == pytest.approx(2.0, rel=2e-3) and np.angle(z[0, 0]) == pytest.approx(0.7, abs=2e-3)
    assert abs(z[1, 0]) == pytest.approx(0.5, rel=5e-3) and np.angle(z[1, 0]) == pytest.approx(-2.0, abs=5e-3)
    assert abs(z[2, 0]) < 1e-3 and np.isnan(z[3, 0])  # no third harmonic; above Nyquist: not measured
    assert np.angle(z[0, 1]) == pytest.approx(0.7 - math.pi, abs=2e-3)


def test_a_speed_sweep_gives_one_tidy_table(tmp_path):
    result = gearcheck.sweep("demo-3p", speeds=SPEEDS, solver="lumped", duration=0.03, workers=1, cache=tmp_path)
    frame = result.to_pandas()
    assert list(frame.columns[:4]) == ["point", "sample", "seed", "speed_rpm"] and frame.columns[-1] == "key"
    assert frame["point"].is_monotonic_increasing and sorted(set(frame["point"])) == [0, 1, 2]
    assert set(frame["metric"]) == {"mean", "rms", "peak_to_peak", "harmonic", "natural_frequency"}
    harmonic = frame[frame["metric"] == "harmonic"]
    gated = [s.name for s in gearcheck.simulate("demo-3p", duration=0.002).signals if s.compared]
    assert list(dict.fromkeys(harmonic["quantity"])) == gated
    for speed in SPEEDS:  # the lines are the mesh harmonics at that speed
        f_mesh = kinematics(gearcheck.load("demo-3p", speed)).mesh_frequency["stage1.planet1.sun"]
        rows = harmonic[(harmonic["speed_rpm"] == speed) & (harmonic["quantity"] == "stage1.sun.ax.carrier")]
        assert rows["frequency_hz"].to_numpy() == pytest.approx([f_mesh, 2 * f_mesh, 3 * f_mesh], rel=1e-12)
        assert set(rows["mesh"]) == {"stage1"} and rows["resolved"].all()
        world = harmonic[(harmonic["speed_rpm"] == speed) & (harmonic["quantity"] == "stage1.sun.ax.world")]
        assert not world["resolved"].any()  # 0.03 s cannot tell k f_mesh from k f_mesh +/- f_carrier
    modes = frame[(frame["metric"] == "natural_frequency") & (frame["point"] == 1)]
    assert modes["frequency_hz"].min() == pytest.approx(gearcheck.modes("demo-3p", speed=1500.0).frequencies[0])
    assert (frame.loc[frame["metric"] == "rms", "steady"] != "none").all()
    peaks = result.summary()["peaks"]
    assert {p["quantity"] for p in peaks} == set(result.headline()) and len(peaks) == 4


def test_each_line_carries_its_integration_error_and_the_stiffness_switches_do_not_alias(tmp_path):
    """demo-3p's rectangular mesh stiffness makes its forces and accelerations jump twice a mesh cycle: the lines
    at the default step h, corrected for the jumps, against the same run at h / 8 (its error 4096 times smaller)."""
    from gearcheck.train.loader import load_train
    from gearcheck.lumped.side import LumpedSide
    from gearcheck.shared.settings import RunSettings

    duration = 0.05
    frame = sw.sweep("demo-3p", speeds=[1000.0], solvers=("lumped",), duration=duration, workers=1).to_pandas()
    lines = frame[(frame["metric"] == "harmonic") & frame["resolved"]]
    assert (lines["integration_error"] >= 0).all()
    side = LumpedSide(load_train("demo-3p", 1000.0))
    fine = side.run(RunSettings(duration, dt=lines["dt_s"].iloc[0] / 8))
    window = fine.t >= lines["steady_start_s"].iloc[0]
    t = fine.t[window]
    plan = TrainPlan.of(side.spec, side, duration)
    worst, plain_worst = 0.0, 0.0
    for quantity, rows in lines.groupby("quantity"):
        f = rows["frequency_hz"].to_numpy()
        reference = harmonics(t, fine[quantity][window], f, np.inf, *plan.singularities([quantity], t[0], t[-1]))[:, 0]
        plain = harmonics(t[::8], fine[quantity][window][::8], f, np.inf)[:, 0]  # the sum at the step h, uncorrected
        got = rows["amplitude"].to_numpy() * np.exp(1j * rows["phase_rad"].to_numpy())
        counts = counted(rows).to_numpy()
        error = np.abs(got - reference)
        # the error estimate (the change on doubling the step) tracks the error of the lines that count
        assert np.all(error[counts] <= 2.0 * rows["integration_error"].to_numpy()[counts] + 1e-9 * np.abs(got).max())
        worst = max(worst, float(np.max(error[counts] / np.abs(reference[counts]))))
        plain_worst = max(plain_worst, float(np.max(np.abs(plain - reference)[counts] / np.abs(reference[counts]))))
    assert plain_worst > 10 * worst  # the plain sum errs by the aliased jumps (4.3 against 0.02 when written)
    assert counted(lines).mean() > 0.8


def test_refine_divides_the_step_and_the_estimates_shrink_with_it():
    coarse, fine = (sw.sweep("demo-3p", speeds=[1000.0], refine=n, workers=1, **FAST).to_pandas() for n in (1, 2))
    rows = [f[(f["metric"] == "harmonic") & f["resolved"]].set_index(["quantity", "order"]) for f in (coarse, fine)]
    assert rows[1]["dt_s"].iloc[0] == pytest.approx(rows[0]["dt_s"].iloc[0] / 2, rel=1e-12)
    assert fine["key"].iloc[0] != coarse["key"].iloc[0]
    largest = rows[0]["amplitude"].groupby(level="quantity").transform("max")
    lines = rows[0].index[rows[0]["amplitude"] >= 0.1 * largest]  # lines well above round-off
    ratio = (rows[1]["integration_error"] / rows[0]["integration_error"]).loc[lines]
    assert ratio.median() < 0.25  # at least second order: halving the step quarters the change on doubling it


def test_reproducible_and_resumable_from_the_cache(tmp_path):
    first = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path / "a", **FAST)
    again = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path / "b", **FAST)
    assert first.parquet() == again.parquet()  # byte for byte, not only the same numbers
    resumed = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path / "a", **FAST)
    assert (resumed.computed, resumed.cached) == (0, 3) and resumed.parquet() == first.parquet()
    files = sorted((tmp_path / "a").glob("*.parquet"))
    files[1].unlink()
    partial = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path / "a", **FAST)
    assert (partial.computed, partial.cached) == (1, 2) and partial.parquet() == first.parquet()
    longer = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path / "a", solvers=("lumped",), duration=0.04)
    assert longer.computed == 3  # a changed input is a new key
    with ThreadPoolExecutor(1) as executor:  # any executor of the user's
        assert sw.sweep("demo-3p", speeds=SPEEDS, executor=executor, **FAST).parquet() == first.parquet()


def test_a_point_cached_by_other_code_is_computed_again(tmp_path, monkeypatch):
    """The key holds the code (the package's Python files and the numeric libraries' versions), not only the
    release: after an edit of the solvers in a checkout, or a library's upgrade, the cache gives no old bytes."""
    first = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path, **FAST)
    assert len(sw.code_digest()) == 64
    monkeypatch.setattr(sw, "code_digest", lambda: "0" * 64)
    other = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path, **FAST)
    assert (other.computed, other.cached) == (3, 0)
    assert set(other.to_pandas()["key"]).isdisjoint(first.to_pandas()["key"])
    assert len(list(tmp_path.glob("*.parquet"))) == 6


def test_an_interrupted_sweep_keeps_its_finished_points(tmp_path):
    def stop_at(share):
        def stop(fraction):
            if fraction >= share:
                raise KeyboardInterrupt
        return stop

    with pytest.raises(KeyboardInterrupt):
        sw.sweep("demo-3p", speeds=SPEEDS, workers=1, cache=tmp_path, progress=stop_at(0.3), **FAST)
    assert len(list(tmp_path.glob("*.parquet"))) == 1 and not list(tmp_path.glob(".*"))
    done = sw.sweep("demo-3p", speeds=SPEEDS + [2500.0], workers=1, cache=tmp_path, **FAST)
    assert done.cached == 1 and done.computed == 3


def test_processes_and_a_dask_local_cluster_give_the_same_table(tmp_path):
    distributed = pytest.importorskip("distributed")
    alone = sw.sweep("demo-3p", speeds=SPEEDS, workers=1, **FAST)
    pool = sw.sweep("demo-3p", speeds=SPEEDS, workers=2, **FAST)
    assert pool.backend == "processes (2)" and pool.parquet() == alone.parquet()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_dask = sw.sweep("demo-3p", speeds=SPEEDS, scheduler=cluster.scheduler_address, cache=tmp_path, **FAST)
        assert on_dask.backend == "dask" and on_dask.computed == 3
        assert on_dask.parquet() == alone.parquet()
        assert len(list(tmp_path.glob("*.parquet"))) == 3  # the client writes the cache as points arrive
        with distributed.Client(cluster, set_as_default=False) as client:  # a client of the user's, left open
            assert sw.sweep("demo-3p", speeds=SPEEDS[:2], scheduler=client, **FAST).parquet() == \
                sw.sweep("demo-3p", speeds=SPEEDS[:2], workers=1, **FAST).parquet()
            assert client.status == "running"


def test_a_script_without_the_main_guard_runs_on_worker_processes(tmp_path):
    """Workers start fresh (forkserver) and must not run the calling script again."""
    script = tmp_path / "study.py"
    script.write_text("import gearcheck\nprint('body')\nr = gearcheck.sweep('demo-3p', speeds=[1000, 2000], "
                      "solver='lumped', duration=0.03, workers=2)\nprint(r.backend, r.computed)\n")
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:2] == ["body", "processes (2) 2"]


def test_a_parameter_grid_over_train_file_fields(tmp_path):
    result = sw.sweep("demo-3p", speeds=[1200.0, 1800.0], fields={"stages[0].sun.mass": [0.9, 1.2],
                      "stages[0].mesh.stiffness.mean": [6e8]}, workers=1, **FAST)
    frame = result.to_pandas()
    assert list(frame.columns[4:6]) == ["stages[0].sun.mass", "stages[0].mesh.stiffness.mean"]
    points = frame.drop_duplicates("point")
    assert points[["stages[0].sun.mass", "speed_rpm"]].values.tolist() == [[0.9, 1200], [0.9, 1800], [1.2, 1200],
                                                                           [1.2, 1800]]
    assert points["sample"].tolist() == [0, 0, 1, 1]
    first_mode = frame[(frame["quantity"] == "mode1") & (frame["speed_rpm"] == 1200)]["frequency_hz"].to_numpy()
    assert first_mode[0] != first_mode[1]  # the edited numbers reach the model
    written = result.write(tmp_path / "out")
    assert [p.name for p in written] == ["sweep.parquet", "study.png", "sweep.json"]


def test_monte_carlo_draws_are_seeded_and_prefix_stable():
    laws = {"a": Distribution.parse("normal(10, 1)"), "b": Distribution.parse("lognormal(2, 1.5)"),
            "c": Distribution.parse("uniform(-1, 1)")}
    five, three = draw_samples(laws, 5, 7), draw_samples(laws, 3, 7)
    assert three == five[:3] and draw_samples(laws, 5, 7) == five and draw_samples(laws, 5, 8) != five
    many = draw_samples(laws, 2000, 1)
    b = np.log([d["b"] for d in many])
    assert np.median([d["b"] for d in many]) == pytest.approx(2.0, rel=0.05) and np.std(b) == pytest.approx(
        math.log(1.5), rel=0.05)
    assert all(-1 <= d["c"] < 1 for d in many)
    result = sw.sweep("demo-3p", distributions={"stages[0].sun.mass": "normal(0.9757, 0.05)"}, samples=3, seed=11,
                      workers=1, **FAST)
    points = result.to_pandas().drop_duplicates("point")
    drawn = [d["stages[0].sun.mass"] for d in draw_samples({"stages[0].sun.mass": Distribution.parse(
        "normal(0.9757, 0.05)")}, 3, 11)]
    assert points["stages[0].sun.mass"].tolist() == drawn and points["seed"].tolist() == [11] * 3
    assert points["speed_rpm"].tolist() == [gearcheck.load("demo-3p").operating.input_speed * 30 / math.pi] * 3


def test_a_solver_that_fails_on_a_point_is_a_row(monkeypatch):
    from gearcheck.lumped.side import LumpedSide

    def refuse(self, settings, state=None):
        raise SolverError("diverged at t = 0.01 s: test")

    monkeypatch.setattr(LumpedSide, "run_from", refuse)
    frame = sw.sweep("demo-3p", speeds=[1000.0], workers=1, **FAST).to_pandas()
    failed = frame[frame["metric"] == "failed"]
    assert failed["error"].tolist() == ["diverged at t = 0.01 s: test"]


def test_crossings_of_a_line_with_modes():
    speeds = np.array([0.0, 1000.0, 2000.0])
    modes = np.array([[100.0, 500.0], [100.0, 500.0], [100.0, 500.0]])
    assert crossings(speeds, modes, 0.3 * speeds) == [(pytest.approx(1000 / 3), 0), (pytest.approx(5000 / 3), 1)]


def test_the_sweep_command_writes_table_plots_and_summary(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", "demo-3p", "--speeds", "1000:2000:3", "--solver", "lumped", "--duration", "0.03",
            "--workers", "1", "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "demo-3p: 3 points (3 run, 0 from the cache" in printed and "largest harmonic stage1 x" in printed
    assert "integration check on 1 of 3 points (1 every 8th; the checked column)" in printed
    names = sorted(p.name for p in out.iterdir())
    assert "sweep.parquet" in names and "sweep.json" in names and "order_stage1.ring.ay.carrier.png" in names
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.suffix in (".parquet", ".png")}
    assert len(list((tmp_path / "sweep.cache").glob("*.parquet"))) == 3
    assert main(argv) == 0
    assert "(0 run, 3 from the cache" in capsys.readouterr().out
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.suffix in (".parquet", ".png")} == before
    schema = pq.read_schema(out / "sweep.parquet")
    assert b"gearcheck.sweep" in schema.metadata and schema.field("amplitude").type == "double"
    units = json.loads(schema.metadata[b"gearcheck.units"])
    for name in ("amplitude", "frequency_hz", "speed_rpm"):  # each field carries its unit and description itself
        field = schema.field(name)
        assert field.metadata == {b"unit": units[name]["unit"].encode(),
                                  b"description": units[name]["description"].encode()}


@pytest.mark.parametrize("args, message", [
    (["--set", "stages[0].sun.mas=1,2"], "--set stages[0].sun.mas=1.0: preset:demo-3p: stages[0].sun.mas: unknown key"),
    (["--set", "stages[9].sun.mass=1,2"], "--set stages[9].sun.mass: no such field in the train file"),
    (["--set", "stages[0].sun.mass=-1"], "--set stages[0].sun.mass=-1.0: preset:demo-3p: stages[0].sun.mass"),
    (["--set", "stages[0].sun=1"], "--set stages[0].sun: {"),
    (["--set", "stages[0].sun.mass="], "--set 'stages[0].sun.mass=': give FIELD=v1,v2"),
    (["--vary", "stages[0].sun.mass=gauss(1,2)"], "--vary stages[0].sun.mass 'gauss(1,2)': a distribution is"),
    (["--vary", "stages[0].sun.mass=normal(1,0)"], "needs sd > 0"),
    (["--vary", "stages[0].sun.mass=uniform(2,1)"], "needs low < high"),
    (["--vary", "stages[0].sun.mass=lognormal(1,0.5)"], "needs median > 0 and factor > 1"),
    (["--vary", "stages[0].sun.mass=normal(0.5,10)", "--samples", "20"], "(sample "),
    (["--speeds", "0:1000:3"], "--speeds '0:1000:3': every speed must be a positive number of rpm, got 0"),
    (["--speeds=-5"], "--speeds '-5': every speed must be a positive number of rpm, got -5"),
    (["--speeds", "2000:1000:3"], "--speeds '2000:1000:3': an empty or reversed range"),
    (["--speeds", "1000:2000:0"], "an empty or reversed range"),
    (["--speeds", "fast"], "--speeds 'fast': must be A:B:N or v1,v2"),
    (["--speeds", "1e9"], "--speeds '1e9': every speed must be <= 1e+06 rpm, got 1e+09"),
    (["--set", "stages[0].sun.mass=1", "--vary", "stages[0].sun.inertia=normal(1,0.1)"], "give one or the other"),
    (["--samples", "5"], "--samples: Monte Carlo needs --vary"),
    (["--vary", "stages[0].sun.mass=normal(1,0.01)", "--samples", "0"], "--samples 0: needs an integer"),
    (["--workers", "0"], "--workers 0: needs an integer from 1"),
    (["--harmonics", "0"], "--harmonics 0: needs an integer from 1 to 20"),
    (["--refine", "0"], "--refine 0: needs an integer from 1 to 64"),
    (["--quantity", "stage1.nothing"], "--quantity stage1.nothing: not a gated quantity of demo-3p"),
    (["--scheduler", "tcp://127.0.0.1:9"], "--scheduler tcp://127.0.0.1:9: cannot reach the Dask scheduler"),
    (["--scheduler", "nowhere"], "--scheduler 'nowhere': give the scheduler's address"),
    (["--cache", "OUT/cache"], "cache: inside --out"),
    (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "--workers counts local processes"),
])
def test_bad_sweep_input_is_one_line_and_nothing_written(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.setattr(point_backends, "CONNECT_TIMEOUT", "1s")
    out = tmp_path / "out"
    args = [a.replace("OUT", str(out)) for a in args]
    status = main(["sweep", "demo-3p", "--solver", "lumped", "--duration", "0.03", "--out", str(out), *args])
    err = capsys.readouterr().err
    assert status == 2
    assert err.startswith("gearcheck: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert message in err
    assert list(tmp_path.iterdir()) == []  # neither the output nor a cache


def test_the_api_refuses_what_it_cannot_sweep():
    with pytest.raises(GearcheckError, match="not a loaded TrainSpec"):
        gearcheck.sweep(gearcheck.load("demo-3p"))
    with pytest.raises(GearcheckError, match="solver=euler: choose"):
        gearcheck.sweep("demo-3p", solver="euler")
    with pytest.raises(GearcheckError, match="operating.input_speed_rpm is swept by speeds=: give it there only"):
        gearcheck.sweep("demo-3p", speeds=[1000], fields={"operating.input_speed_rpm": [1000, 2000]})


def test_ctrl_c_in_the_command_leaves_the_cache_and_no_table(tmp_path, capsys, monkeypatch):
    calls = []
    original = sw.run_point

    def interrupted_second(point, before=None):
        calls.append(point.index)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return original(point, before)

    monkeypatch.setattr(sw, "run_point", interrupted_second)
    out = tmp_path / "sweep"
    status = main(["sweep", "demo-3p", "--speeds", "1000:2000:3", "--solver", "lumped", "--duration", "0.03",
                   "--workers", "1", "--out", str(out)])
    assert status == 130 and "interrupted" in capsys.readouterr().err
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == ["sweep.cache"]
    assert len(list((tmp_path / "sweep.cache").glob("*.parquet"))) == 1
