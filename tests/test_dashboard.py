"""The regression dashboard: the history store, change points, the static site, and the site in headless
Chromium; the must-hold: a scratch repository whose middle commit stiffens the meshes by 30 % gets that
commit, and only that one, marked as a change point."""

from __future__ import annotations

import json
import os
import random
import re
import sqlite3
import subprocess
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from matplotlib.image import imread

import gearcheck
from gearcheck.compare.presentation import dashboard, history
from gearcheck.compare.presentation.report import to_dict
from gearcheck.train.loader import preset_text
from gearcheck.shared.errors import GearcheckError

DURATION = 0.02  # s: demo-3p reaches its steady state by 7.4 ms; each cross-check takes 1-3 s
STIFFNESS = ("mean = 8.0e8", "mean = 1.04e9")  # the demo's mesh stiffness, and 30 % more
MARKED = re.compile(r'<[^>]*class="change-point"[^>]*data-commit="([^"]+)"')


def git(repo: Path, *args: str, date: str | None = None) -> str:
    env = {**os.environ, "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}
    if date:
        env |= {"GIT_AUTHOR_DATE": date, "GIT_COMMITTER_DATE": date}
    done = subprocess.run(["git", *args], cwd=repo, env=env, capture_output=True, text=True)
    assert done.returncode == 0, f"git {' '.join(args)}: {done.stderr}"
    return done.stdout.strip()


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """Three commits of a train file in a scratch git repository (the middle one stiffens the meshes by
    30 %, the last touches another file), each cross-checked and recorded, and the dashboard rendered."""
    root = tmp_path_factory.mktemp("scratch")
    repo = root / "repo"
    repo.mkdir()
    git(repo, "init", "-q")
    git(repo, "config", "user.name", "gearcheck test")
    git(repo, "config", "user.email", "test@gearcheck.invalid")
    text = preset_text("demo-3p")
    assert text.count(STIFFNESS[0]) == 1
    train, store = repo / "demo.toml", root / "history.sqlite"
    edits = [(train, text, "the demo reducer"), (train, text.replace(*STIFFNESS), "mesh stiffness +30 %"),
             (repo / "NOTES.md", "notes, no physics\n", "notes")]
    commits, reports = [], []
    for day, (path, content, message) in enumerate(edits, start=1):
        path.write_text(content, encoding="utf-8")
        git(repo, "add", "-A")
        git(repo, "commit", "-q", "-m", message, date=f"2025-03-0{day}T12:00:00+01:00")
        commit, date = git(repo, "rev-parse", "HEAD"), git(repo, "show", "-s", "--format=%cI", "HEAD")
        data = json.loads(json.dumps(to_dict(gearcheck.crosscheck(train, duration=DURATION))))  # as report.json
        history.append(store, data, commit, date)
        commits.append(commit)
        reports.append(data)
    site = dashboard.render(store, root / "site")
    return SimpleNamespace(root=root, store=store, commits=commits, reports=reports, site=site)


def pages(site: Path) -> dict[str, str]:
    return {p.name: p.read_text(encoding="utf-8") for p in sorted(site.glob("*.html"))}


# ---------------------------------------------------------------- history store

def test_append_is_idempotent_and_reads_back(scratch, tmp_path):
    store, reports = tmp_path / "h.sqlite", scratch.reports
    for n, data in enumerate(reports):
        history.append(store, data, f"c{n}", f"2025-01-0{n + 1}T00:00:00Z")
    before = history.read(store)
    history.append(store, reports[2], "c0", machine="runner-7")  # c0 again: replaced, keeps its date
    after, runs = history.read(store), history.runs(store)
    assert history.commits(store) == ["c0", "c1", "c2"]
    per_run = [7 * len(d["quantities"]) + 3 * len(d["modes"]) + len(d["volatile"]["wall_time"])
               + len(d["volatile"]["cpu_time"]) for d in reports]
    assert len(runs) == 3 and len(after) == len(before) == sum(per_run)
    assert runs["machine"].tolist() == ["runner-7"] + [d["provenance"]["machine"] for d in reports[1:]]
    assert runs["date"].tolist() == ["2025-01-01T00:00:00Z", "2025-01-02T00:00:00Z", "2025-01-03T00:00:00Z"]
    physics = after[~after["item"].isin(history.TIMES)]
    c0, c2 = (physics.loc[physics["commit"] == c, "value"].tolist() for c in ("c0", "c2"))
    assert c0 == c2 != before.loc[(before["commit"] == "c0") & ~before["item"].isin(history.TIMES), "value"].tolist()
    history.append(store, reports[1], "c1")  # the same record again: nothing changes
    pd.testing.assert_frame_equal(history.read(store), after)

    q = reports[1]["quantities"][0]
    row = after[(after["commit"] == "c1") & (after["item"] == q["name"])].set_index("metric")
    assert row.loc["nrmse", "value"] == q["errors"]["nrmse"]["value"]
    assert row.loc["nrmse", "tolerance"] == q["tolerance_nrmse"]["value"] and row.loc["nrmse", "gated"]
    assert row.loc["reference.peak_to_peak", "value"] == q["reference"]["peak_to_peak"]["value"]
    assert row.loc["integration_error.test", "value"] == q["integration_error"]["test"]["value"]
    mode = reports[1]["modes"][3]
    row = after[(after["commit"] == "c1") & (after["item"] == f"mode {mode['mode']}")].set_index("metric")
    assert row.loc["reference.frequency", "value"] == mode["reference"]["value"]
    assert row.loc["rel_error", "status"] == mode["status"]
    assert set(after.loc[after["item"] == "wall_time", "metric"]) == set(reports[0]["volatile"]["wall_time"])
    assert set(after.loc[after["item"] == "cpu_time", "metric"]) == set(reports[0]["volatile"]["cpu_time"])
    cpu = after[(after["commit"] == "c1") & (after["item"] == "cpu_time")].set_index("metric")["value"]
    assert all(cpu[k] == v["value"] >= 0 for k, v in reports[1]["volatile"]["cpu_time"].items())
    assert after["order"].is_monotonic_increasing

    other = dict(reports[0], train=dict(reports[0]["train"], name="other"))
    history.append(store, other, "c1")  # a second train at a known commit: a record of its own
    assert len(history.runs(store)) == 4 and history.commits(store) == ["c0", "c1", "c2"]
    history.append(store, reports[0], "late", "2025-01-03T00:00:00Z")  # the same date as c2: after it
    history.append(store, reports[0], "west", "2024-12-31T23:00:00-02:00")  # 01:00 UTC: between c0 and c1
    assert history.commits(store) == ["c0", "west", "c1", "c2", "late"]
    assert history.read(store).drop_duplicates("commit")["commit"].tolist() == history.commits(store)


def test_a_failed_append_leaves_the_store_as_it_was(scratch, tmp_path):
    store = tmp_path / "h.sqlite"
    history.append(store, scratch.reports[0], "c0", "2025-01-01")
    snapshot = store.read_bytes()
    broken = json.loads(json.dumps(scratch.reports[1]))
    del broken["quantities"][5]["errors"]
    twice = json.loads(json.dumps(scratch.reports[1]))
    twice["quantities"].append(twice["quantities"][0])  # fails inside the transaction, on its last insert
    for args, reason in [((broken, "c1"), "malformed field 'errors'"), ((scratch.reports[1], " "), "commit id"),
                         (({"schema": "gearcheck.summary", "schema_version": 1}, "c1"),
                          "records gearcheck.crosscheck version 2 reports, not ('gearcheck.summary', 1)"),
                         ((scratch.reports[1], "c1", "yesterday"), "not an ISO 8601 date"),
                         ((twice, "c1"), "UNIQUE constraint failed")]:
        with pytest.raises(GearcheckError) as info:
            history.append(store, *args)
        assert reason in str(info.value) and "\n" not in str(info.value)
    assert store.read_bytes() == snapshot and history.commits(store) == ["c0"]


def test_a_version_1_store_is_brought_to_version_2_by_the_next_record(scratch, tmp_path):
    """Version 1 named the sides' metrics lumped.* and mujoco.* whatever they were: reading such a store is
    refused in one line saying how to upgrade it; recording a run renames them reference.* and test.*, the
    values kept."""
    store = tmp_path / "old.sqlite"
    history.append(store, scratch.reports[0], "c0")
    before = history.read(store)
    with sqlite3.connect(store) as con:  # what version 1 wrote
        con.execute("UPDATE metrics SET metric = replace(replace(metric, 'reference', 'lumped'), 'test', 'mujoco')")
        con.execute("UPDATE meta SET value = '1' WHERE key = 'schema_version'")
    with pytest.raises(GearcheckError, match="version 1; recording a run in it"):
        history.read(store)
    history.append(store, scratch.reports[1], "c1")
    after = history.read(store)
    old = after[after["commit"] == "c0"].reset_index(drop=True)
    pd.testing.assert_frame_equal(old, before.reset_index(drop=True))
    assert not after["metric"].str.match(r"(integration_error\.)?(lumped|mujoco)\b").any()  # timings keep solver names
    assert after["metric"].str.match(r"(integration_error\.)?(reference|test)\b").any()


def test_a_bad_store_is_one_line_naming_the_file(scratch, tmp_path):
    text = tmp_path / "notes.sqlite"
    text.write_text("not a database\n" * 100)
    other = tmp_path / "other.sqlite"
    with sqlite3.connect(other) as con:
        con.execute("CREATE TABLE t (x)")
    future = tmp_path / "future.sqlite"
    history.append(future, scratch.reports[0], "c0")
    with sqlite3.connect(future) as con:
        con.execute("UPDATE meta SET value = '3' WHERE key = 'schema_version'")
    for path, reason in [(text, "file is not a database"), (other, "not a gearcheck history store"),
                         (future, "version 3"), (tmp_path / "missing.sqlite", "no such file"),
                         (tmp_path, "is a folder")]:
        calls = {"read": lambda: history.read(path), "render": lambda: dashboard.render(path, tmp_path / "site"),
                 "append": lambda: history.append(path, scratch.reports[0], "c1")}
        if reason == "no such file":
            del calls["append"]  # appending makes a missing store
        for call in calls.values():
            with pytest.raises(GearcheckError) as info:
                call()
            message = str(info.value)
            assert reason in message and str(path) in message and "\n" not in message
    assert not (tmp_path / "site").exists()


# ---------------------------------------------------------------- change points

def test_change_points_on_synthetic_series():
    rng = random.Random(7)
    assert history.change_points([]) == [] and history.change_points([3.0]) == []
    assert history.change_points([1.0, 1.0, 1.3, 1.3], relative=0.01) == [2]
    assert history.change_points([1.0, 1.3], relative=0.01) == [1]  # a move at the latest commit: marked at once
    step = [1.0 + rng.gauss(0, 0.01) for _ in range(20)] + [1.2 + rng.gauss(0, 0.01) for _ in range(20)]
    assert history.change_points(step) == [20]  # noise 0.01, step 0.2: found at its commit, once
    noise = [1.0 + rng.gauss(0, 0.05) for _ in range(200)]
    assert history.change_points(noise) == []  # noise alone, far above every floor: nothing
    spike = [1.0] * 10 + [5.0] + [1.0] * 10
    assert history.change_points(spike) == []  # one outlier is not a step
    gated = [2.0e-5, 2.6e-5, 2.2e-5, 2.1e-5]
    assert history.change_points(gated, tolerance=0.01) == []  # far below a tenth of the tolerance
    assert history.change_points(gated + [3.0e-3], tolerance=0.01) == [4]
    assert history.change_points([1e-15, 7e-15, 3e-15, 9e-15]) == []  # round-off
    assert history.change_points([1.0, None, float("nan"), 1.5, 1.5]) == [3]  # gaps skipped, indices kept
    assert history.rule("wall_time", "s", None) is None and history.rule("cpu_time", "s", None) is None


# ---------------------------------------------------------------- the must-hold

def test_the_stiffened_commit_and_only_it_is_a_change_point(scratch):
    good, stiff, notes = scratch.commits
    assert [r["verdict"]["verdict"] for r in scratch.reports] == ["PASS"] * 3
    site = pages(scratch.site)
    assert set(site) == {"index.html", "preset-demo-3p.html"}
    marked = {name: set(MARKED.findall(text)) for name, text in site.items()}
    assert marked == {"index.html": {stiff}, "preset-demo-3p.html": {stiff}}
    preset = site["preset-demo-3p.html"]
    metrics = set(re.findall(r'class="change-point" data-commit="[0-9a-f]+" data-metric="([^"]+)"', preset))
    assert "mode 18 reference.frequency" in metrics  # a mesh-dominated mode: about sqrt(1.3)
    assert "stage1.planet1.sun.dte reference.rms" in metrics  # the same load on stiffer teeth
    assert not any(m.endswith(" nrmse") for m in metrics)  # both solvers moved together: the check still agrees
    assert f"&#9670; {stiff[:7]}</text>" in preset and preset.count('<svg') > 60
    for other in (good, notes):
        assert f'data-commit="{other}"' not in preset.replace(f'data-commit="{stiff}"', "")
    index = site["index.html"]
    assert "demo-3p" in index and ">PASS<" in index and f"<code>{notes[:7]}</code>" in index


def test_the_site_is_reproducible_and_written_whole(scratch, tmp_path, monkeypatch):
    again = dashboard.render(scratch.store, tmp_path / "again")
    assert {p.name: p.read_bytes() for p in again.iterdir()} == {p.name: p.read_bytes() for p in scratch.site.iterdir()}
    for text in pages(again).values():  # nothing from outside the page: no scripts, no links off the site
        assert "<script" not in text and "src=" not in text
        assert set(re.findall(r'href="([^"]+)"', text)) <= {p.name for p in again.glob("*.html")}
        assert set(re.findall(r"https?://[^\s\"']+", text)) <= {"http://www.w3.org/2000/svg"}

    write_text = Path.write_text

    def broken(path, text, **kwargs):  # the disk fills up after the front page
        if path.suffix == ".html" and path.name != "index.html":
            raise OSError("No space left on device")
        return write_text(path, text, **kwargs)

    monkeypatch.setattr(Path, "write_text", broken)
    with pytest.raises(OSError):
        dashboard.render(scratch.store, again)
    assert {p.name: p.read_bytes() for p in again.iterdir()} == {p.name: p.read_bytes() for p in scratch.site.iterdir()}
    assert [p.name for p in tmp_path.iterdir()] == ["again"]


# ---------------------------------------------------------------- headless Chromium

def test_the_console_check_can_fail(tmp_path, browser):
    page = tmp_path / "broken.html"
    page.write_text("<html><body><script>undefinedThing();</script></body></html>", encoding="utf-8")
    assert any("Uncaught ReferenceError" in m for m in browser.console(browser.browse(page, "--dump-dom").stderr))


@pytest.mark.parametrize("page", ["index.html", "preset-demo-3p.html"])
def test_the_pages_render_in_headless_chromium(scratch, page, browser):
    path = scratch.site / page
    dom = browser.browse(path, "--dump-dom")
    assert not browser.console(dom.stderr), browser.console(dom.stderr)
    assert dom.stdout.count("<svg") >= (1 if page == "index.html" else 60) and 'class="change-point"' in dom.stdout
    if page != "index.html":  # the timing trend in CPU time, steadier than the wall time on a shared runner
        assert "CPU time (s)" in dom.stdout and "Wall time (s)" not in dom.stdout
    shot = scratch.root / page.replace(".html", ".png")
    done = browser.browse(path, f"--screenshot={shot}")
    assert not browser.console(done.stderr), browser.console(done.stderr)
    pixels = imread(shot)[..., :3]
    assert pixels.shape[:2] == (900, 1200) and pixels.std() > 0.05

    def pixels_of(color: str) -> int:
        rgb = np.array([int(color[i:i + 2], 16) for i in (1, 3, 5)]) / 255
        return int(np.sum(np.abs(pixels - rgb).max(axis=-1) < 0.1))

    assert pixels_of(dashboard.STATUS_COLOR["PASS"]) > 200  # the verdict badges
    if page != "index.html":  # a line, a tolerance line, a change point
        for color in (dashboard.PALETTE[0], dashboard.TOLERANCE_COLOR, dashboard.CHANGE_COLOR):
            assert pixels_of(color) > 200, color
