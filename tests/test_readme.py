"""The README documents the train file field by field (generated from the schema), gives a first train file that
passes its first cross-check, and gives exactly two fresh-machine commands, the second of which is what .ci/run
runs."""

import re
from pathlib import Path

import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.shared.errors import TrainNote
from gearcheck.train.docs import BLOCKS, block

ROOT = Path(__file__).resolve().parent.parent


def test_generated_references_match_the_code():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for name, make in BLOCKS.items():
        assert block(text, name) == make(), f"README {name} reference is stale: python -m gearcheck.train.docs"


def test_two_setup_commands_and_ci_runs_the_test_one():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    setup = text.split("## Set-up on a fresh machine", 1)[1].split("\n## ", 1)[0]
    commands = re.findall(r"```\n(.*?)\n```", setup, flags=re.S)
    assert len(commands) == 2
    assert "gearcheck crosscheck" in commands[0]
    assert "pytest" in commands[1]
    assert commands[1] in (ROOT / ".ci" / "run").read_text(encoding="utf-8")


def first_train() -> str:
    """The README's first train file, as a new user copies it."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    found = re.search(r"<!-- first-train:begin -->\n```toml\n(.*?)```\n<!-- first-train:end -->", text, flags=re.S)
    assert found, "README: the first train file's block is missing"
    return found[1]


def test_the_first_train_file_of_the_readme_passes_its_first_crosscheck(tmp_path, capsys):
    """A new user copies the README's example and cross-checks it: a PASS, with nothing to note."""
    path = tmp_path / "my-reducer.toml"
    path.write_text(first_train(), encoding="utf-8")
    assert main(["crosscheck", str(path), "--out", str(tmp_path / "out")]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("my-reducer: PASS") and "note" not in captured.err
    spec = gearcheck.load(path)
    assert spec.held == ("stage1.ring",) and len(spec.meshes) == 8
    assert {mesh.stiffness["model"] for mesh in spec.meshes} == {"energy"}


def test_a_support_left_without_damping_is_noted_at_load(tmp_path):
    """Damping defaults to 0: the load says where, once per stage's table (the four planets share one)."""
    path = tmp_path / "undamped.toml"
    path.write_text(first_train().replace(", radial_damping = 500.0", ""), encoding="utf-8")
    with pytest.warns(TrainNote) as notes:
        gearcheck.load(path)
    assert [str(n.message).split(" (")[0] for n in notes] == [
        "no damping in stage1.sun support radial, stage1.planet bearing radial"]
