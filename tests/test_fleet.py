"""CI fleets: one crosscheck command over a team's train files (a list, a folder, a pattern) gives a report each,
one summary headed by the overall verdict, one JUnit file and one history append; a bad train among them stops
the command before anything is run or written."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import pytest

from gearcheck.cli import main
from gearcheck.compare.presentation import history
from gearcheck.compare.presentation.summary import overall, overall_line
from gearcheck.train.files import report_folders, train_list
from gearcheck.train.loader import preset_text


def _fleet(root):
    """demo-3p twice under different names, in two folders, under one file name."""
    for folder, name in (("a", "left"), ("b", "right")):
        (root / folder).mkdir()
        text = preset_text("demo-3p").replace('name = "demo-3p"', f'name = "{name}"', 1)
        assert f'name = "{name}"' in text
        (root / folder / "train.toml").write_text(text, encoding="utf-8")
    return [str(root / "a" / "train.toml"), str(root / "b" / "train.toml")]


def test_a_fleet_is_named_by_files_folders_and_patterns_each_train_once(tmp_path, monkeypatch):
    files = _fleet(tmp_path)
    (tmp_path / "c").mkdir()
    monkeypatch.chdir(tmp_path)
    assert train_list(["a", "b/train.toml"]) == ["a/train.toml", "b/train.toml"]
    assert train_list(["*/train.toml", "a/train.toml", "./a/train.toml"]) == ["a/train.toml", "b/train.toml"]
    assert train_list(["**/*.toml", "demo-3p"]) == ["a/train.toml", "b/train.toml", "demo-3p"]
    assert train_list([files[1]]) == [files[1]]
    assert report_folders(["demo-3p", "a/train.toml", "b/train.toml", "c/x.toml"]) == [
        "demo-3p", "a-train", "b-train", "x"]
    assert report_folders(["a.toml", "./a.toml"]) == ["a-1", "a-2"]


@pytest.mark.parametrize("items, words", [
    (["c"], "TRAIN c: a folder with no .toml train file in it"),
    (["nothing/*.toml"], "TRAIN 'nothing/*.toml': the pattern matches no file"),
])
def test_a_folder_or_pattern_that_names_no_train_is_refused(tmp_path, monkeypatch, capsys, items, words):
    (tmp_path / "c").mkdir()
    monkeypatch.chdir(tmp_path)
    assert main(["crosscheck", *items, "--out", "out"]) == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_bad_train_in_a_fleet_stops_it_before_anything_is_written(tmp_path, capsys):
    files = _fleet(tmp_path)
    bad = tmp_path / "a" / "bad.toml"
    bad.write_text(preset_text("demo-3p").replace("mass = ", "mass = -", 1), encoding="utf-8")
    assert main(["crosscheck", files[0], str(bad), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_trains_of_one_name_cannot_share_a_history(tmp_path, capsys):
    files = _fleet(tmp_path)
    (tmp_path / "b" / "train.toml").write_text((tmp_path / "a" / "train.toml").read_text(), encoding="utf-8")
    assert main(["crosscheck", *files, "--history", str(tmp_path / "h.sqlite"), "--out", str(tmp_path / "o")]) == 2
    assert "another train of the fleet has its name 'left'" in capsys.readouterr().err


def test_the_overall_verdict_is_the_worst_of_the_trains():
    rows = [{"status": "PASS"}, {"status": "INCONCLUSIVE"}, {"status": "PASS"}]
    assert overall(rows) == "INCONCLUSIVE" and overall(rows + [{"status": "FAIL"}]) == "FAIL"
    assert overall(rows[:1]) == "PASS"
    assert overall_line(rows) == "overall: INCONCLUSIVE (0 failed, 1 inconclusive, 2 passed of 3 trains)"


def test_a_fleet_crosscheck_writes_a_report_each_one_summary_one_junit_one_history_append(tmp_path, capsys):
    files = _fleet(tmp_path)
    out, junit, store = tmp_path / "out", tmp_path / "junit.xml", tmp_path / "history.sqlite"
    status = main(["crosscheck", *files, "--duration", "0.05", "--out", str(out), "--junit", str(junit),
                   "--history", str(store), "--commit", "a" * 40])
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert [r["train"] for r in summary["trains"]] == ["left", "right"]
    assert [r["folder"] for r in summary["trains"]] == ["a-train", "b-train"]
    assert (out / "a-train" / "report.md").exists() and (out / "b-train" / "report.html").exists()
    verdicts = [r["status"] for r in summary["trains"]]
    assert verdicts[0] == verdicts[1]  # the same train under two names
    assert summary["verdict"] == overall(summary["trains"])
    assert status == {"PASS": 0, "FAIL": 1, "INCONCLUSIVE": 3}[summary["verdict"]]
    assert f"{overall_line(summary['trains'])} (summary: {out / 'summary.md'})" in printed
    suites = ET.parse(junit).getroot().findall("testsuite")
    assert sorted(s.get("name") for s in suites) == ["left", "right"]
    assert sorted(history.runs(store)["train"]) == ["left", "right"]
    text = (out / "summary.md").read_text()
    assert "# gearcheck cross-check of 2 trains" in text and "(a-train/report.md)" in text
