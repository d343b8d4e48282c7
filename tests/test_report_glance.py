"""Reports read at a glance: a verdict banner that counts every status, failing rows first, spectral lines
flagged against their tolerance, a plot of every failing quantity, spectra that reach every stage's mesh
harmonics and the natural frequencies, measured values explained, and the same as JUnit XML; long series drawn as
their envelope per pixel column."""

from __future__ import annotations

import math
import copy
import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

import gearcheck
from gearcheck.compare.presentation.envelope import COLUMNS, envelope
from gearcheck.compare.presentation.junit import junit_xml, write_junit
from gearcheck.compare.presentation.plots import (MAX_FAILING, _png, failing_figure, headline_quantities,
                                                  spectra_figure, spectrum_range, time_histories_figure)
from gearcheck.compare.presentation.report import (LINE_NEGLIGIBLE, LINE_SHARE, MISS, STATUSES, calibration,
                                                   line_status)
from gearcheck.train.kinematics import kinematics

ROOT = Path(__file__).resolve().parents[1]
TORSIONAL = f"{ROOT / 'examples' / 'torsional_user_model.py'}:torsional_model"
DURATION = 0.05


@pytest.fixture(scope="module")
def failing(tmp_path_factory):
    """demo-3p against a purely torsional user's model: quantities fail, one is unresolved (the user's model, of an
    order gearcheck does not know, is held to the change on doubling its step); its six modes agree with the
    reference reduced alike (translations held, planets on their pins)."""
    result = gearcheck.crosscheck("demo-3p", duration=DURATION, model=TORSIONAL)
    out = tmp_path_factory.mktemp("failing")
    return result, result.write(out), out


@pytest.fixture(scope="module")
def hub(tmp_path_factory):
    """hub-drive (two stages, Table 1 of Li et al. 2026 at its 606 rpm): too short for a steady state."""
    result = gearcheck.crosscheck("hub-drive", duration=DURATION)
    out = tmp_path_factory.mktemp("hub")
    return result, result.write(out), out


def banner_counts(text: str) -> dict[str, dict[str, int]]:
    """The counts the banner states, by group and status."""
    words = {"fail": "fail", "inconclusive (unresolved)": "unresolved", "pass": "pass",
             "not gated (negligible)": "negligible"}
    counts = {}
    for group, body in re.findall(r"(quantities|modes): ([^;<]+)", text):
        counts[group] = {words[w]: int(n) for n, w in re.findall(r"(\d+) ([a-z ()]+?)(?:,|$)", body.strip())}
    return counts


def tables(markdown: str) -> dict[str, list[list[str]]]:
    """Every Markdown table by its section title: its rows as cells, the header first."""
    out, title = {}, None
    for line in markdown.splitlines():
        if line.startswith("## "):
            title = line[3:]
        elif line.startswith("|") and not line.startswith("|---"):
            out.setdefault(title, []).append([c.strip() for c in line.strip("|").split("|")])
    return out


@pytest.mark.parametrize("which", ["failing", "hub"])
def test_the_banner_counts_every_status(which, request):
    result, data, out = request.getfixturevalue(which)
    expected = {"quantities": {k: sum(q.status == k for q in result.quantities) for k in STATUSES},
                "modes": {"fail": sum(m["status"] == "fail" for m in data["modes"]),
                          "pass": sum(m["status"] == "pass" for m in data["modes"])}}
    assert data["verdict"]["counts"]["quantities"] == expected["quantities"]
    md = (out / "report.md").read_text()
    first = next(line for line in md.splitlines() if line.startswith("Verdict: "))
    assert first.startswith(f"Verdict: **{result.verdict}** — ")
    assert banner_counts(first) == expected
    page = (out / "report.html").read_text()
    block = re.search(r'<div class="banner (\w+)"><span class="verdict">(\w+)</span>([^<]*)', page)
    assert block[1] == block[2] == result.verdict
    assert banner_counts(block[3]) == expected


def test_the_failing_run_counts_what_failed(failing):
    result, data, _ = failing
    counts = data["verdict"]["counts"]
    assert result.verdict == "FAIL"
    assert counts["quantities"]["fail"] == 14 and counts["quantities"]["unresolved"] == 1
    assert counts["modes"] == {"fail": 0, "pass": 6}


def test_failing_rows_come_first_in_every_table(failing):
    result, data, out = failing
    found = tables((out / "report.md").read_text())
    with_status = [t for t in found.values() if t[0][-1] == "status"]
    assert len(with_status) == 3  # modes, quantities, spectral lines
    for header, *rows in with_status:
        ranks = [STATUSES.index(r[-1]) for r in rows]
        assert ranks == sorted(ranks)
    quantities = found["Time-domain quantities (steady window)"][1:]
    assert [r[-1] for r in quantities[:15]] == ["fail"] * 14 + ["unresolved"]
    order = [q["name"] for q in data["quantities"]]  # stable within a status
    for status in STATUSES:
        names = [r[0] for r in quantities if r[-1] == status]
        assert names == [n for n in order if n in names]


def test_every_spectral_line_is_flagged_against_its_tolerance(failing, hub):
    for result, data, out in (failing, hub):
        for q, row in zip(result.quantities, data["quantities"]):
            for line, entry in zip(q.spectrum, row["spectrum"]):
                rel, rms = line["rel_error"], q.metrics["reference"]["rms"]
                assert entry["status"] == line_status(line, q.status, q.tolerance, rms)
                small = max(abs(line["reference"]), abs(line["test"])) < LINE_NEGLIGIBLE * math.sqrt(2) * rms
                if q.status != "negligible" and rel is not None and q.tolerance is not None and not small:
                    carries = entry["nrmse_part"]["value"] >= LINE_SHARE * q.tolerance
                    assert (entry["status"] == "fail") == (abs(rel) > q.tolerance and carries)
                    assert entry["nrmse_part"]["value"] == pytest.approx(
                        abs(line["test"] - line["reference"]) / (math.sqrt(2) * rms), rel=1e-12)
        md = (out / "report.md").read_text()
        assert "A line is flagged fail when its relative amplitude error exceeds its quantity's NRMSE tolerance and " \
               "the line carries at least 10% of that tolerance" in md
        assert "advisory" in md
        for q in result.quantities:  # advisory: a quantity passes or fails on its NRMSE alone, whatever its lines
            if q.status in ("pass", "fail"):
                assert (q.status == "fail") == (q.metrics["nrmse"] > q.tolerance)
    spectral = tables((failing[2] / "report.md").read_text())["Spectral lines (Hann-windowed amplitude)"]
    assert spectral[1][-1] == "fail" and 'class="fail"' in (failing[2] / "report.html").read_text()


def test_a_failing_quantity_gets_its_plot(failing, hub):
    result, data, out = failing
    assert (out / "failing.png").stat().st_size > 10_000
    assert "![failing.png](failing.png)" in (out / "report.md").read_text()
    page = (out / "report.html").read_text()
    assert 'id="failing.png"' in page and '<a href="#failing.png">' in page
    fig = failing_figure(result)
    fails = [q for q in result.quantities if q.status == "fail"]
    worst = sorted(fails, key=lambda q: q.metrics["nrmse"] / q.tolerance, reverse=True)[:MAX_FAILING]
    titles = [ax.get_title(loc="left") for ax in fig.axes[::2]]
    assert [t.split(":")[0] for t in titles] == [q.name for q in worst]
    assert f"{len(fails)} failing quantities; the {MAX_FAILING} worst" in fig.get_suptitle()
    # nothing fails in the hub's run: no such figure
    assert failing_figure(hub[0]) is None and not (hub[2] / "failing.png").exists()


def test_the_spectra_reach_every_stage_and_the_natural_frequencies(hub):
    result = hub[0]
    kin = kinematics(result.spec)
    fig = spectra_figure(result)
    low, high = fig.axes[0].get_xlim()
    assert fig.axes[0].get_xscale() == "log"
    nyquist = 0.5 * result.settings["common_sample_rate_hz"]
    for stage in result.spec.stages:
        meshes = [kin.mesh_frequency[m.id] for m in result.spec.meshes if m.stage == stage.name]
        assert low < min(meshes) and 3 * max(meshes) < high, stage.name
    modal = gearcheck.modes(result.spec)
    elastic = [f for f, kind in zip(modal.frequencies, modal.types) if kind != "rigid" and f < nyquist]
    assert low < min(elastic) and max(elastic) < high <= nyquist
    assert max(elastic) > 7000  # hub-drive's highest mode, far beyond the 6 x 31.6 Hz the spectra used to stop at


def test_a_long_series_is_drawn_as_its_envelope_with_every_peak():
    """A long series is drawn as the smallest and largest sample of each column, in order, its ends kept: a
    one-sample spike stays (a subsampling would drop it), every point drawn is a sample, and on a logarithmic axis
    the columns are logarithmic; a short series is drawn as it is."""
    x = np.linspace(0.0, 0.5, 92_600)
    y = np.sin(2 * np.pi * 31.6 * x) + 1e-3 * np.cos(2 * np.pi * 7000 * x)
    y[31_337], y[50_001] = 7.0, -5.0
    ex, ey = envelope(x, y)
    assert ex.size <= 2 * COLUMNS + 2 and np.all(np.diff(ex) > 0) and set(zip(ex, ey)) <= set(zip(x, y))
    assert (ey.max(), ey.min()) == (7.0, -5.0) and (ex[0], ey[0], ex[-1], ey[-1]) == (x[0], y[0], x[-1], y[-1])
    f = np.linspace(1.0, 10_000.0, 50_000)
    amplitude = 1.0 / f
    amplitude[10] = 50.0  # at 3 Hz: a column of its own on a logarithmic axis, one among 25 on a linear one
    lf, la = envelope(f, amplitude, log=True)
    assert la.max() == 50.0 and np.sum(lf < 10.0) > 2 * np.sum(envelope(f, amplitude)[0] < 10.0)
    assert all(np.array_equal(a, b) for a, b in zip(envelope(x[:500], y[:500]), (x[:500], y[:500])))


def test_the_spectra_draw_the_range_shown_and_draw_again_byte_for_byte(hub):
    result = hub[0]
    rng = spectrum_range(result)
    fig = spectra_figure(result)
    for line in fig.axes[0].get_lines():
        drawn = np.asarray(line.get_xdata())
        if drawn.size > 2:  # the spectra, not the marks
            assert drawn.size <= 2 * COLUMNS + 2 and rng.high <= drawn[-1]  # one sample beyond each end at most
            assert np.sum(drawn < rng.low) <= 1 and np.sum(drawn > rng.high) <= 1
    assert _png(fig) == _png(spectra_figure(result))


def test_measured_values_are_explained(hub):
    result, data, out = hub
    assert len(data["measurements"]) == 2 and data["calibration"] is None
    md = (out / "report.md").read_text()
    assert "the train file's own parameters (preset:hub-drive), which are not calibrated" in md
    assert "docs/hub-drive-calibration/" in md
    for row in data["measurements"]:
        errors = row["error_reference"]["value"], row["error_test"]["value"]
        if min(map(abs, errors)) > MISS:  # both solvers miss Table 1 alike: the model, not the solvers
            assert f"{row['quantity']} {row['metric']}: both solvers miss the test by the same amount" in md
    assert "it is the model, its parameters, not the solvers, that disagrees with the test" in md


def test_a_calibrated_train_file_is_recognised():
    spec = gearcheck.load(ROOT / "docs" / "hub-drive-calibration" / "fit" / "hub-drive-calibrated.toml")
    found = calibration(spec)
    assert found["from"] == "preset:hub-drive"
    assert [f.split(" = ")[0] for f in found["fitted"]] == ["stages[0].mesh.ste[0].amplitude_um",
                                                           "operating.output_torque"]
    assert calibration(gearcheck.load("hub-drive")) is None


def test_junit_counts_match_the_reports(failing, hub, tmp_path):
    path = tmp_path / "junit.xml"
    write_junit([failing[0], hub[1]], path)  # a result and a report dict alike
    root = ET.parse(path).getroot()
    assert root.tag == "testsuites"
    suites = root.findall("testsuite")
    assert [s.get("name") for s in suites] == ["demo-3p", "hub-drive"]
    for suite, (result, data, _) in zip(suites, (failing, hub)):
        for key in ("name", "tests", "failures", "errors", "skipped", "time"):
            assert suite.get(key) is not None, key
        cases = suite.findall("testcase")
        assert all(c.get("name") and c.get("classname") and c.get("time") for c in cases)
        assert int(suite.get("tests")) == len(cases) == len(data["quantities"]) + len(data["modes"]) + 1
        counts = data["verdict"]["counts"]
        assert int(suite.get("failures")) == len(suite.findall("testcase/failure")) == \
            counts["quantities"]["fail"] + counts["modes"]["fail"]
        no_steady = 0 if data["steady_state"]["detected"] else 1
        assert int(suite.get("errors")) == len(suite.findall("testcase/error")) == \
            counts["quantities"]["unresolved"] + no_steady
        assert suite.get("skipped") == "0"
    for key in ("tests", "failures", "errors", "skipped"):
        assert int(root.get(key)) == sum(int(s.get(key)) for s in suites)
    failure = root.find("testsuite/testcase[@name='stage1.planet1.sun.force']/failure")
    nrmse = failing[0]["stage1.planet1.sun.force"].metrics["nrmse"]
    assert failure.get("message") == f"NRMSE {nrmse:.6g} > tolerance 0.01"
    error = root.find("testsuite/testcase[@name='stage1.carrier.alpha']/error")
    assert error.get("type") == "Unresolved" and "cannot decide" in error.get("message")
    assert root.find("testsuite[@name='hub-drive']/testcase[@name='steady state']/error") is not None


def test_junit_is_reproducible_but_for_its_times_and_reports_a_moved_baseline(hub):
    data = hub[1]
    again = copy.deepcopy(data)
    again["volatile"]["wall_time"] = {k: {"value": 2 * v["value"] + 1, "unit": "s"}
                                      for k, v in data["volatile"]["wall_time"].items()}
    untimed = [re.sub(r' time="[^"]*"', "", junit_xml(d)) for d in ([data], [again])]
    assert untimed[0] == untimed[1] and junit_xml([data]) != junit_xml([again])
    assert junit_xml([data]) == junit_xml([json.loads(json.dumps(data))])
    assert ET.fromstring(junit_xml([data])).find(".//testcase[@name='baseline']") is None  # none was checked
    again["verdict"]["moved_from_baseline"] = ["II.carrier.ay.world reference_rms: 1 -> 2"]
    suite = ET.fromstring(junit_xml([again])).find("testsuite")
    failure = suite.find("testcase[@name='baseline']/failure")
    assert failure.get("message") == "1 metrics moved from the baseline" and "reference_rms" in failure.text
    assert int(suite.get("tests")) == len(suite.findall("testcase"))


def test_the_failing_report_renders_in_headless_chromium(failing, browser, tmp_path):
    """report.html loads with no console message, holds its banner and every figure, and draws: the screenshot
    is not blank and shows the FAIL banner's red."""
    _, _, out = failing
    dom = browser.browse(out / "report.html", "--dump-dom")
    assert not browser.console(dom.stderr), browser.console(dom.stderr)
    assert "FAIL" in dom.stdout and dom.stdout.count("<img") >= 4
    shot = tmp_path / "report.png"
    done = browser.browse(out / "report.html", f"--screenshot={shot}")
    assert not browser.console(done.stderr), browser.console(done.stderr)
    pixels = imread(shot)[..., :3]
    assert pixels.shape[:2] == (900, 1200) and pixels.std() > 0.05
    red = np.sum((pixels[..., 0] > 0.6) & (pixels[..., 1] < 0.35) & (pixels[..., 2] < 0.35))
    assert red > 500, red


def test_the_headline_plots_leave_out_negligible_quantities_and_name_their_cycle(hub):
    """demo-4p's held ring and carrier accelerations are both solvers' round-off (negligible): drawn, a flat line
    beside MuJoCo's 1e-8 m/s^2 looks like a disagreement, so the headline plots skip them; a two-stage train's
    plot names the mesh whose cycles it shows (the slower stage's)."""
    result = gearcheck.crosscheck("demo-4p", duration=DURATION)
    negligible = {q.name for q in result.quantities if q.status == "negligible"}
    assert {"stage1.ring.ay.world", "stage1.carrier.ay.world"} <= negligible
    names = headline_quantities(result)
    assert names == ["stage1.planet1.sun.force", "stage1.planet1.ring.force"]
    hub_result = hub[0]
    kin = kinematics(hub_result.spec)
    slowest = {stage.name: min(kin.mesh_frequency[m.id] for m in hub_result.spec.meshes if m.stage == stage.name)
               for stage in hub_result.spec.stages}
    stage = min(slowest, key=slowest.get)
    assert hub_result.settings["steady_cycle_of"] == f"the {stage} mesh"
    title = time_histories_figure(hub_result).texts[0].get_text()
    assert f"last 4 cycles of the {stage} mesh ({slowest[stage]:.4g} Hz)" in title
