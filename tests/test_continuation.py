"""Runs that go on from another run's state, and a sweep's speed continuation built on them."""

import io

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import gearcheck
from gearcheck.compare.engine.align import STEADY_THRESHOLD
from gearcheck.compare.engine.plan import TrainPlan
from gearcheck.compare.studies import continuation as continued
from gearcheck.compare.studies import sweep as sw
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.errors import GearcheckError, SolverError
from gearcheck.shared.modal import damped_modes
from gearcheck.shared.run_state import RunState
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_text, load_train
from gearcheck.train.variants import edited_text


@pytest.mark.parametrize("kind, tolerance", [(LumpedSide, 1e-10), (MujocoSide, 1e-8)])
def test_a_run_split_in_two_is_the_whole_run(kind, tolerance):
    """Two runs, the second from the first's final state at its end time, give the samples of one run over both:
    to round-off on the lumped model (t0 + i h against (n + i) h), to the constraint solver's tolerance on the
    twin (its warm start is not part of the state)."""
    side = kind(load_train("demo-3p", 1000.0))
    h = side.default_step()
    whole, end = side.run_from(RunSettings(600 * h, dt=h))
    first, state = side.run_from(RunSettings(300 * h, dt=h))
    second, last = side.run_from(RunSettings(300 * h, dt=h, start=state.t), state)
    assert second.t[0] == pytest.approx(300 * h, rel=1e-12) and second.t[-1] == pytest.approx(whole.t[-1], rel=1e-12)
    for name in whole.names(compared=True):
        scale = np.ptp(whole[name]) or 1.0
        assert np.max(np.abs(second[name] - whole[name][300:])) <= tolerance * scale, name
    for a, b in zip(last.coordinates + last.rates, end.coordinates + end.rates):
        assert np.max(np.abs(a - b)) <= tolerance * max(np.max(np.abs(b)), 1e-30)


def test_a_state_is_kept_to_the_bit_and_carried_to_another_speed():
    state = RunState(0.1 / 3, (np.array([1 / 3, -2e-300]), np.array([np.pi])), (np.array([np.e, 7.0]),))
    back = RunState.from_text(state.to_text())
    assert back.t == state.t and all(np.array_equal(a, b) for a, b in zip(back.coordinates + back.rates,
                                                                          state.coordinates + state.rates))
    faster = state.at_speed(1.25)  # the drive's phase w t kept: t / r; the rates r times
    assert faster.t * 1.25 == pytest.approx(state.t, rel=1e-15)
    assert np.array_equal(faster.coordinates[0], state.coordinates[0]) and np.allclose(faster.rates[0],
                                                                                       1.25 * state.rates[0])
    with pytest.raises(GearcheckError, match="not a run's final state"):
        RunState.from_text('{"t": "0x1p-3", "coordinates": ["@@"], "rates": []}')


def test_a_run_from_a_later_start_needs_the_state_it_goes_on_from():
    spec = load_train("demo-3p", 1000.0)
    for side in (LumpedSide(spec), MujocoSide(spec)):
        with pytest.raises(SolverError, match="start=0.01 s only from a state it is given"):
            side.run_from(RunSettings(0.001, start=0.01))
    with pytest.raises(SolverError, match="start must be a number of seconds >= 0"):
        RunSettings(0.01, start=-1.0)
    history = gearcheck.load("demo-3p", speed_profile="0:1000, 0.01:1200")
    side = LumpedSide(history)
    _, state = side.run_from(RunSettings(0.001))
    with pytest.raises(SolverError, match="runs its operating history from t = 0"):
        side.run_from(RunSettings(0.001, start=state.t), state)


def _away_from_jumps(t, switches, h):
    """The samples of ``t`` more than two steps from every stiffness jump (where two runs on grids shifted against
    each other disagree by the jump itself)."""
    i = np.searchsorted(switches, t)
    after = np.abs(switches[np.minimum(i, switches.size - 1)] - t)
    before = np.abs(switches[np.maximum(i - 1, 0)] - t)
    return (after > 2 * h) & (before > 2 * h)


@pytest.mark.parametrize("solver", ["lumped", "mujoco"])
def test_a_continued_point_is_on_the_steady_state_of_a_run_from_rest(solver):
    """A point at 1020 rpm continued from 1000 rpm: over its steady window it is the run of the same speed from the
    static state, at the same instants (every excitation runs on w t), to the steady threshold of the mesh forces'
    fluctuation -- its start's mismatch has died away as the continuation's rule says."""
    plan = sw.plan_sweep("demo-3p", speeds=[1000.0, 1020.0], solvers=(solver,), integration_check="none")
    first, point = plan.points
    assert point.after == first.key and point.after_rpm == 1000.0
    before, _, _ = sw.run_point(first)
    spec = load_train(load_text(point.text, point.source), point.speed_rpm)
    lumped = LumpedSide(spec)
    side = lumped if solver == "lumped" else MujocoSide(spec)
    train_plan = TrainPlan.of(spec, lumped, point.duration)
    lines = [(label, k, k * f) for label, f in sw.mesh_groups(spec, lumped.model.kin) for k in (1, 2, 3)]
    switch_times = lumped.model.excitation.switch_times
    run = sw._steady_run(side, point, train_plan, lines, before)
    assert run.start == "continued" and run.steady[1] == "continued"
    start = run.steady[0]
    assert run.result.t[-1] - start >= continued.window_length(train_plan, lines) - 1e-12
    assert run.result.t[-1] < 0.6 * point.duration + first.duration  # it ran less than a point from rest
    cold = side.run(RunSettings(run.result.t[-1] + run.dt, dt=run.dt))
    t = run.result.t[run.result.t >= start]
    keep = _away_from_jumps(t, switch_times(t[0] - 1e-3, t[-1] + 1e-3), run.dt)
    for forces, _ in train_plan.steady_groups(run.result.names(compared=True)):
        for name in forces:
            x = run.result[name][run.result.t >= start][keep]
            y = np.interp(t, cold.t, cold[name])[keep]
            assert np.max(np.abs(x - y)) <= STEADY_THRESHOLD * np.ptp(y), name


def test_chains_resume_to_the_same_bytes_and_say_how_each_point_started(tmp_path):
    speeds = [1000.0, 1010.0, 1020.0, 1400.0]  # 1400 rpm is more than 10 % on: a new chain, from rest
    options = dict(speeds=speeds, solvers=("lumped",), integration_check="subset", workers=1)
    whole = sw.sweep("demo-3p", cache=tmp_path / "cache", **options)
    frame = whole.to_pandas().query("metric == 'rms'").drop_duplicates(["point", "solver"])
    assert frame.set_index("speed_rpm")["start"].to_dict() == {1000.0: "cold", 1010.0: "continued",
                                                               1020.0: "continued", 1400.0: "cold"}
    third = whole.plan.points[2]
    (tmp_path / "cache" / f"{third.key}.parquet").unlink()  # an interrupted chain: its last point to run again
    resumed = sw.sweep("demo-3p", cache=tmp_path / "cache", **options)
    assert resumed.computed == 1 and resumed.parquet() == whole.parquet()
    table = pq.read_table(io.BytesIO((tmp_path / "cache" / f"{third.key}.parquet").read_bytes()))
    assert set(__import__("json").loads(table.schema.metadata[continued.STATE.encode()])) == {"lumped"}
    assert sw.sweep("demo-3p", workers=2, **{k: v for k, v in options.items() if k != "workers"}).parquet() == \
        whole.parquet()


def test_a_point_whose_continuation_cannot_settle_in_its_duration_runs_from_rest():
    frame = sw.sweep("demo-3p", speeds=[1000.0, 1010.0], solvers=("lumped",), duration=0.01, workers=1,
                     integration_check="none").to_pandas().query("metric == 'rms'").drop_duplicates(["point"])
    assert list(frame["start"]) == ["cold", "cold: continuation did not settle"]


def test_the_checked_subset_is_every_eighth_speed_and_every_line_in_the_band_of_a_mode_it_drives():
    """demo-3p from 670 to 1010 rpm: its first three stage harmonics lie in a half-power band at every speed but
    710-850 rpm; up to 690 rpm the third in that of a rotational mode it drives (513 Hz), from 870 rpm only in bands
    of modes the planets' phasing leaves at rest (Parker 2000), which are not checked."""
    speeds = np.linspace(670.0, 1010.0, 18).tolist()
    frame = sw.sweep("demo-3p", speeds=speeds, solvers=("lumped",), duration=0.06, workers=1).to_pandas()
    rows = frame[frame["metric"] == "harmonic"]
    reasons, undriven = set(), 0
    for point, lines in rows.groupby("point"):
        side = LumpedSide(load_train("demo-3p", speeds[point]))
        frequencies = lines[["frequency_hz", "order"]].drop_duplicates().itertuples(index=False)
        clocks = [(f / k, k) for f, k in frequencies]
        near = any(np.any(np.abs(f * k - natural) <= damping * natural)
                   for (f, k), (natural, damping) in zip(clocks, side.resonances(clocks)))
        natural, damping = damped_modes(side.model.M, side.model.C + side.model.G,
                                        side.model.K_mean + side.model.K_frame)
        undriven += not near and any(np.any(np.abs(f * k - natural) <= damping * natural) for f, k in clocks)
        expected = "every 8th" if point % 8 == 0 else "resonance" if near else "no"
        reasons.add(expected)
        assert set(lines["checked"]) == {expected}, point
        assert lines["integration_error"].notna().all() == (expected != "no")
    assert reasons == {"every 8th", "resonance", "no"} and undriven >= 5
    with pytest.raises(GearcheckError, match="integration_check='some': needs subset, all, none"):
        sw.plan_sweep("demo-3p", speeds=[1000.0], integration_check="some")


def test_a_point_where_a_mesh_with_backlash_unloads_is_checked():
    """hub-drive's meshes (backlash 150 and 200 um) stay loaded at 1000 rpm and part from about 1200 rpm, where a mesh's
    force, its damping's included, falls below a tenth of its mean and below zero: there the response is not the
    linear one whose modes place the checks, and the point is checked ("contact"); at 1000 rpm, whose lines lie
    off the bands of the modes they drive, it is not."""
    speeds = [990.0, 1000.0, 1440.0, 1450.0]
    frame = sw.sweep("hub-drive", speeds=speeds, solvers=("lumped",), duration=0.15, workers=1).to_pandas()
    points = frame[frame["metric"] == "rms"].drop_duplicates("point").sort_values("point")
    assert list(points["checked"]) == ["every 8th", "no", "contact", "contact"]
    for rpm, parts in ((1000.0, False), (1450.0, True)):
        spec = load_train("hub-drive", rpm)
        run = gearcheck.simulate(spec, "lumped", duration=0.15)
        window = run.t >= 0.075  # the second half, the sweep's window where no steady state is found
        lowest = min(np.min(run[f"{m.id}.force"][window]) / np.mean(run[f"{m.id}.force"][window]) for m in spec.meshes)
        assert (lowest < 0.0) == parts and (lowest < sw.UNLOADED) == parts, (rpm, lowest)


def test_a_point_where_a_cycloid_discs_pins_unload_is_checked(tmp_path):
    """The RV reducer under an output load that reverses (a 40 Hz ripple of 1.5 times the mean): at 1200 rpm its
    lines lie off the bands of the modes, and its meshes have neither backlash nor tip relief, but a disc's largest
    pin force falls below a tenth of its mean (its pins touch in compression only, and all let go as the load
    passes through zero): the point is checked ("contact")."""
    text = edited_text("rv-reducer", [(r"^\[\[stages\]\]", "[[operating.ripple]]\nmember = \"output\"\n"
                                       "frequency_hz = 40.0\namplitude = 1.5\n\n[[stages]]")])
    path = tmp_path / "rv-reversing.toml"
    path.write_text(text)
    frame = sw.sweep(str(path), speeds=[1190.0, 1200.0], solvers=("lumped",), duration=0.1, workers=1).to_pandas()
    points = frame[frame["metric"] == "rms"].drop_duplicates("point").sort_values("point")
    assert list(points["checked"]) == ["every 8th", "contact"]
    spec = load_train(str(path), 1200.0)
    excitation = LumpedSide(spec).model.excitation
    assert not np.any(excitation.backlash > 0) and not excitation.relieved.size
    run = gearcheck.simulate(spec, "lumped", duration=0.1)
    window = run.t >= 0.05  # its second half, after the start's decay
    for disc in ("rv.disc1", "rv.disc2"):
        force = run[f"{disc}.pin_force_max"][window]
        assert np.min(force) < sw.UNLOADED * np.mean(force) and np.min(run[f"{disc}.pins_loaded"][window]) == 0


def test_a_translation_along_the_worlds_axes_is_unresolved_where_its_carrier_sidebands_are():
    """demo-3p's response is periodic in the carrier's frame; along the world's axes its lines sit at k f_mesh +/-
    f_carrier, which a window shorter than 2 / f_carrier cannot separate: those lines are flagged, the carrier
    frame's are not, and the sweep's headline quantities are the carrier frame's."""
    result = sw.sweep("demo-3p", speeds=[1500.0], solvers=("lumped",), duration=0.1, workers=1,
                      integration_check="none")
    frame = result.to_pandas()
    lines = frame[frame["metric"] == "harmonic"]
    window = 0.1 - float(frame.loc[frame["metric"] == "rms", "steady_start_s"].iloc[0])
    f_carrier = abs(LumpedSide(load_train("demo-3p", 1500.0)).model.kin.speeds["stage1.carrier"]) / (2 * np.pi)
    assert window * f_carrier < 2
    assert not lines.loc[lines["quantity"] == "stage1.ring.ay.world", "resolved"].any()
    assert lines.loc[lines["quantity"] == "stage1.ring.ay.carrier", "resolved"].any()
    assert all(q.endswith(".ay.carrier") or q.endswith(".force") for q in result.headline())


def test_a_line_at_an_unchecked_speed_is_read_by_its_checked_neighbours():
    """Speeds 1..5, checked at 1, 3 and 5: the line's relative estimate there is 1 %, 30 % and 2 %; at 2 and 4 it
    takes the larger of its neighbours' (30 %: not counted); without any check every line counts."""
    from gearcheck.compare.studies.sweep_lines import counted

    rows = pd.DataFrame({"sample": 0, "solver": "lumped", "quantity": "q", "mesh": "I", "order": 1,
                         "speed_rpm": [1.0, 2.0, 3.0, 4.0, 5.0], "amplitude": 10.0, "resolved": True,
                         "steady": "continued", "integration_error": [0.1, np.nan, 3.0, np.nan, 0.2]})
    assert list(counted(rows)) == [True, False, False, False, True]
    rows.loc[2, "integration_error"] = 0.5  # 5 %: every line within a tenth
    assert counted(rows).all()
    assert counted(rows.assign(integration_error=np.nan)).all()
    rows.loc[1, "integration_error"] = 2.0  # its own estimate, 20 %, rules
    assert list(counted(rows)) == [True, False, True, True, True]


def test_both_solvers_read_a_continued_point_over_one_window():
    frame = sw.sweep("demo-3p", speeds=[1000.0, 1010.0, 1020.0], workers=1, integration_check="none").to_pandas()
    runs = frame[frame["metric"] == "rms"].drop_duplicates(["point", "solver"]).set_index(["point", "solver"])
    for point in (1, 2):
        assert runs.loc[(point, "lumped"), "start"] == runs.loc[(point, "mujoco"), "start"] == "continued"
        assert runs.loc[(point, "lumped"), "steady_start_s"] == runs.loc[(point, "mujoco"), "steady_start_s"]


def test_where_contacts_part_the_solvers_continuations_both_run_from_rest():
    """hub-drive above 1800 rpm, where backlash opens and closes in every mesh cycle: continued from 1850 rpm, the
    two solvers' chains reach waveforms further apart than the steady threshold allows (two orbits), so the point
    runs both from rest and says so, and the point after it runs from rest without trying."""
    frame = sw.sweep("hub-drive", speeds=[1850.0, 1860.0, 1870.0], workers=1, integration_check="none").to_pandas()
    starts = frame[frame["metric"] == "rms"].drop_duplicates(["point"])["start"].tolist()
    assert starts == ["cold", continued.PARTED_START, continued.PARTED_START + " at the previous speed"]
    lines = frame[(frame["metric"] == "harmonic") & (frame["quantity"] == "I.planet1.sun.force")]
    pairs = lines.pivot_table(index=["point", "mesh", "order"], columns="solver", values="amplitude")
    strong = pairs[pairs["lumped"] > 0.1 * pairs["lumped"].max()]
    # from rest the solvers agree to 1 % (contacts make the lines sensitive to the step), where the continued
    # chains' waveforms had parted by tens of per cent
    assert np.all(np.abs(strong["mujoco"] - strong["lumped"]) <= 0.02 * strong["lumped"])
