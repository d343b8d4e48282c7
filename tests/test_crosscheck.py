"""The cross-check end to end: demo presets pass, a broken twin fails by name, reports are
reproducible byte for byte, baselines hold."""

import dataclasses
import math
import json
from pathlib import Path

import pytest
from threadpoolctl import threadpool_limits

import gearcheck
from gearcheck import crosscheck
from gearcheck.cli import main, settling_line
from gearcheck.compare.engine.baseline import BASELINE_DIR
from gearcheck.compare.engine.comparison import MAX_REFINEMENTS, compare
from gearcheck.compare.engine.plan import TrainPlan
from gearcheck.compare.engine.tolerances import Tolerances
from gearcheck.compare.presentation.report import to_dict
from gearcheck.train.loader import load_train, preset_names
from gearcheck.train.variants import edited
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.settings import RunSettings

DURATION = "0.05"


def test_demo_presets_pass_with_default_tolerances(demo_check):
    for name, result in (("demo-3p", demo_check), ("demo-4p", crosscheck("demo-4p", duration=0.05))):
        assert result.passed, result.failures
        assert result.steady_found
        gated = [q for q in result.quantities if q.status == "pass"]
        assert len(gated) >= 20
        # mesh phasing: demo-4p's central members cannot translate (22 l +/- 1 is never a multiple of 4)
        if name == "demo-4p":
            assert {q.name for q in result.quantities if q.status == "negligible"} >= {
                "stage1.sun.ax.world", "stage1.ring.ay.world", "stage1.carrier.ax.carrier"}


def test_a_twin_with_a_wrong_planet_inertia_fails_by_name():
    """The engine given a MuJoCo side whose planets are 1.3 times too heavy in rotation."""
    spec = load_train("demo-3p")
    members = {k: dataclasses.replace(m, inertia=1.3 * m.inertia) if m.is_planet else m
               for k, m in spec.members.items()}
    reference = LumpedSide(spec)
    plan = TrainPlan.of(spec, reference, 0.05)
    result = compare(spec, reference, MujocoSide(dataclasses.replace(spec, members=members)), plan,
                     (RunSettings(0.05),) * 2, Tolerances())
    assert not result.passed
    failures = set(result.failures)
    assert any(f.startswith("mode ") for f in failures)  # the natural frequencies moved
    assert "stage1.planet1.sun.force" in failures  # and the planets' mesh forces with them


def _strip_volatile(path: Path) -> bytes:
    if path.name == "report.json":
        data = json.loads(path.read_text())
        data.pop("volatile")
        return json.dumps(data).encode()
    if path.suffix in (".md", ".html"):
        return "\n".join(line for line in path.read_text().splitlines() if "Run: " not in line).encode()
    return path.read_bytes()


def test_reports_identical_across_runs(tmp_path, capsys):
    for run in ("a", "b"):
        assert main(["crosscheck", "demo-3p", "--duration", DURATION, "--out", str(tmp_path / run)]) == 0
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert {"report.json", "report.md", "report.html", "time_histories.png", "spectra.png",
            "natural_frequencies.png", "errors.png"} <= set(files)
    for name in files:
        assert _strip_volatile(tmp_path / "a" / name) == _strip_volatile(tmp_path / "b" / name), name
    # the volatile parts are exactly one field / one line
    md = (tmp_path / "a" / "report.md").read_text().splitlines()
    assert sum("Run: " in line for line in md) == 1
    data = json.loads((tmp_path / "a" / "report.json").read_text())
    assert data["schema"] == "gearcheck.crosscheck" and data["schema_version"] == 2
    assert data["quantities"][0]["reference"]["rms"]["unit"] == "m/s^2"
    assert data["provenance"]["mujoco_version"] and data["provenance"]["train_sha256"]
    # a report asked for its numbers only: the same report.json, no figure, and its pages say so
    assert main(["crosscheck", "demo-3p", "--duration", DURATION, "--no-figures", "--out", str(tmp_path / "c")]) == 0
    assert sorted(p.name for p in (tmp_path / "c").iterdir()) == [".gearcheck", "report.html", "report.json",
                                                                  "report.md"]
    assert _strip_volatile(tmp_path / "c" / "report.json") == _strip_volatile(tmp_path / "a" / "report.json")
    for page in ("report.md", "report.html"):
        text = (tmp_path / "c" / page).read_text()
        assert "Not drawn: the report was asked for its numbers only" in text and ".png" not in text, page


def test_a_reports_numbers_do_not_depend_on_the_machines_blas_threads():
    """A multi-threaded BLAS splits a product's sums by the machine's cores: the time runs and the comparison run
    on one BLAS thread, so that a report is the same to the last bit on any machine (on two threads, before, 1103
    numbers of hub-drive's README report differed at 1e-15, and this train's too)."""
    def numbers(threads: int) -> str:
        with threadpool_limits(limits=threads):  # the caller's (or the machine's) setting
            data = to_dict(crosscheck("demo-3p", duration=0.05))
        data.pop("volatile")
        return json.dumps(data, sort_keys=True)

    assert numbers(1) == numbers(2)


def test_all_presets_against_their_shipped_baselines(tmp_path, capsys):
    """CI's regression dashboard: every preset cross-checked, nothing moved from the shipped baselines
    (package data: this also fails when the installed package lacks them)."""
    # double-planet cannot settle from rest in the baselines' 0.05 s (its 145 Hz mode, damping ratio 0.28 %, rings
    # for 2.5 s): both of its runs start on their periodic steady states, and it is decided like the others
    # the baselines' duration; no figures: the numbers are the same (test_reports_identical_across_runs)
    assert main(["crosscheck", "--all", "--baseline", "--no-figures", "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert {r["train"] for r in summary["trains"]} == set(preset_names())
    assert all(r["moved"] == 0 and r["failed"] == 0 for r in summary["trains"])
    assert {r["train"]: r["status"] for r in summary["trains"]} == {name: "PASS" for name in preset_names()}
    assert summary["verdict"] == "PASS"
    assert (tmp_path / "summary.html").read_text().count("report.html") == len(summary["trains"])
    text = (tmp_path / "summary.md").read_text()
    assert f"**overall: PASS (0 failed, 0 inconclusive, {len(preset_names())} passed of {len(preset_names())} " \
           "trains)**" in text
    assert text.count("every quantity and mode within tolerance") == len(preset_names())
    assert "(0.05)" in text  # the worst NRMSE beside its tolerance
    # a helical train's axial motion is compared: each central member's acceleration along the stage axis (its
    # helix pushes it at the mesh frequency), both solvers within a tenth of its tolerance (measured 1e-4 of 0.05)
    helical = json.loads((tmp_path / "helical-planetary" / "report.json").read_text())
    axial = [q for q in helical["quantities"] if q["name"].endswith(".az")]
    assert sorted(q["name"] for q in axial) == ["stage1.carrier.az", "stage1.ring.az", "stage1.sun.az"]
    assert all(q["status"] == "pass" and q["errors"]["nrmse"]["value"] < 0.1 * q["tolerance_nrmse"]["value"]
               for q in axial)


def test_a_baseline_rewritten_without_a_duration_keeps_its_own(tmp_path):
    path = tmp_path / "demo-3p.json"
    path.write_text((BASELINE_DIR / "demo-3p.json").read_text())
    crosscheck("demo-3p", baseline=path, update_baseline=True)
    assert json.loads(path.read_text())["duration_s"] == json.loads((BASELINE_DIR / "demo-3p.json").read_text())[
        "duration_s"]


def test_a_moved_metric_is_flagged(tmp_path, capsys):
    baseline = json.loads((BASELINE_DIR / "demo-3p.json").read_text())
    baseline["quantities"]["stage1.ring.ay.world"]["reference_rms"] *= 1.2
    baseline["modes"][0]["test_hz"] *= 1.001
    path = tmp_path / "moved.json"
    path.write_text(json.dumps(baseline))
    assert main(["crosscheck", "demo-3p", "--duration", DURATION, "--baseline", str(path),
                 "--out", str(tmp_path / "out")]) == 1
    out = capsys.readouterr().out
    assert "stage1.ring.ay.world reference_rms" in out and "mode 1 test_hz" in out


def test_a_version_1_baseline_is_read_with_its_sides_renamed(tmp_path, capsys):
    """Version 1 keyed the sides lumped_* and mujoco_*: such a baseline is still checked, unmoved."""
    text = (BASELINE_DIR / "demo-3p.json").read_text()
    old = text.replace('"reference_', '"lumped_').replace('"test_', '"mujoco_').replace('"baseline_version": 2',
                                                                                          '"baseline_version": 1')
    assert old != text and '"reference_' not in old
    path = tmp_path / "old.json"
    path.write_text(old)
    assert main(["crosscheck", "demo-3p", "--baseline", str(path), "--out", str(tmp_path / "out")]) == 0
    assert "moved" not in capsys.readouterr().out


def test_measured_values_appear_as_a_third_column(tmp_path, capsys):
    measurements = tmp_path / "measured.toml"
    measurements.write_text('[[measurements]]\nquantity = "stage1.ring.ay.world"\nmetric = "rms"\n'
                            'value = 100.0\nspeed_rpm = 1500.0\nsource = "made up for the test"\n')
    assert main(["crosscheck", "demo-3p", "--duration", DURATION, "--measurements", str(measurements),
                 "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "report.json").read_text())
    (row,) = data["measurements"]
    assert row["measured"] == {"value": 100.0, "unit": "m/s^2"}
    assert row["error_reference"]["value"] == pytest.approx(row["reference"]["value"] / 100.0 - 1.0)
    assert "Measured reference values" in (tmp_path / "out" / "report.md").read_text()


def test_tolerances_from_the_train_file_and_a_file(tmp_path, capsys):
    """A mesh-force tolerance tighter than the integration error cannot be decided: those quantities are
    unresolved, by name, and the verdict INCONCLUSIVE (exit 3), not PASS; the steps were refined first."""
    from gearcheck.train.variants import edited

    strict = edited("demo-3p", [(r"^\[\[stages\]\]", "[tolerances]\nmesh_force.nrmse = 1e-9\n\n[[stages]]")])
    assert strict.tolerances == {"mesh_force.nrmse": 1e-9}
    result = crosscheck(strict, duration=0.05)
    assert result.verdict == "INCONCLUSIVE" and not result.failures
    assert "stage1.planet1.sun.force (integration error)" in result.unresolved
    assert result["stage1.ring.ay.world"].status == "pass"
    assert any(f"Steps halved {MAX_REFINEMENTS}x" in note for note in result.notes)  # in one go, as far as allowed
    loose = tmp_path / "tol.toml"
    loose.write_text("[tolerances]\n\"stage1.planet1.sun.force.nrmse\" = 0.5\n")
    from gearcheck.compare.engine.tolerances import Tolerances

    tol = Tolerances.for_train(strict, loose)
    assert tol.lookup("stage1.planet1.sun.force", "mesh_force", "nrmse") == 0.5
    assert tol.lookup("stage1.planet2.sun.force", "mesh_force", "nrmse") == 1e-9


def test_sensor_band_filters_both_solvers_alike(demo_check):
    """A 100-1000 Hz accelerometer chain keeps the 406 Hz mesh line and removes the 2 kHz resonance
    content: the filtered ring acceleration is smaller and the solvers still agree."""
    plain = demo_check
    band = crosscheck("demo-3p", duration=0.05, sensor_band=(100.0, 1000.0))
    q0, q1 = plain["stage1.ring.ay.world"], band["stage1.ring.ay.world"]
    assert q1.metrics["reference"]["rms"] < 0.5 * q0.metrics["reference"]["rms"]
    assert band.passed and q1.metrics["nrmse"] < 0.01
    force0, force1 = plain["stage1.planet1.sun.force"], band["stage1.planet1.sun.force"]
    assert force1.metrics["reference"]["rms"] == force0.metrics["reference"]["rms"]  # forces unfiltered


def test_spectral_lines_of_a_switching_stiffness_are_read_from_each_runs_own_samples():
    """demo-3p's rectangular stiffness makes the carrier's angular acceleration kink at every switch (and the twin's
    jump a little: :func:`gearcheck.shared.results.signal_jumps`).  Read from each run's own samples with its jumps
    and kinks projected exactly (as the sweep reads its lines), its mesh harmonics agree between the solvers within
    a fifth of the quantity's tolerance (0.17 measured; 0.24 with a jump read at every switch and no kink); read
    from the anti-aliased common grid they came out 7 to 12 tolerances apart, three lines flagged fail on a passing
    quantity."""
    result = crosscheck("demo-3p", duration=0.1)
    carrier = result["stage1.carrier.alpha"]
    assert carrier.status == "pass"
    assert max(abs(line["rel_error"]) for line in carrier.spectrum if line["rel_error"] is not None) \
        < 0.25 * carrier.tolerance


def test_a_lightly_damped_first_train_is_decided_from_its_periodic_steady_states():
    """A user's first train as the README's example would give it: demo-3p's stage with 5 planets (21/24/69) and
    no support or bearing damping.  Its slowest mode (1483 Hz, damping ratio 2e-5) would ring for 32 s, so the
    cross-check starts both runs on their periodic steady states: the lumped model's over its mesh period, the
    twin's over the 69 mesh periods in which its carrier turns once (ring of 69 teeth held).  It passes, where it
    used to be INCONCLUSIVE with "run at least 6.9 s"; the note names the slow mode."""
    result = crosscheck(edited("demo-3p", FIRST_TRAIN, "5 planets, undamped supports"))
    assert result.verdict == "PASS" and result.steady_how == "periodic", (result.failures, result.unresolved)
    assert any("1483 Hz" in note and "damping ratio" in note for note in result.notes)


FIRST_TRAIN = [(r"^planets = 3", "planets = 5"), (r"^teeth = 22", "teeth = 21"), (r"^teeth = 20", "teeth = 24"),
               (r"^teeth = 62 .*$", "teeth = 69"), (r"radial_damping = [0-9.]+", "radial_damping = 0.0")]


def test_a_train_that_cannot_settle_says_so_when_shown():
    """``gearcheck show`` (and ``describe``) states the slowest-decaying mode and how long a start takes to die away;
    past a practical run it says what the cross-check does instead and names the supports without damping
    (gearcheck adds none); a well-damped preset settles within the run."""
    info = gearcheck.describe(edited("demo-3p", FIRST_TRAIN, "5 planets, undamped supports"))["settling"]
    assert info["slowest_mode_hz"] == pytest.approx(1483, abs=1) and info["damping_ratio"] < 1e-4
    assert info["settle_s"] == pytest.approx(math.log(500) * info["time_constant_s"]) and info["settle_s"] > 10
    members = ["stage1.sun", "stage1.ring", "stage1.carrier"] + [f"stage1.planet{i}" for i in range(1, 6)]
    assert sorted(info["undamped_supports"]) == sorted(f"{m} radial" for m in members)
    line = settling_line(info)
    assert "periodic steady states" in line and "stage1.planet5" in line
    preset = gearcheck.describe("demo-3p")["settling"]
    assert preset["undamped_supports"] == [] and preset["settle_s"] < 0.1
    assert "note" not in settling_line(preset)
