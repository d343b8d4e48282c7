"""The README documents the train file field by field (generated from the schema) and gives
exactly two fresh-machine commands, the second of which is what .ci/run runs."""

import re
from pathlib import Path

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
