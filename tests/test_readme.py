"""The README documents the train file field by field (generated from the schema) and gives
exactly two fresh-machine commands, the second of which is what .ci/run runs."""

import re
from pathlib import Path

from lumped.schema import markdown_reference

ROOT = Path(__file__).resolve().parent.parent


def test_field_reference_matches_the_schema():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"<!-- schema:begin -->\n(.*?)<!-- schema:end -->", text, flags=re.S)
    assert block, "README lost its schema markers"
    assert block.group(1) == markdown_reference(), (
        "README field reference is stale: python -m lumped.schema --update-readme")


def test_two_setup_commands_and_ci_runs_the_test_one():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    setup = text.split("## Set-up on a fresh machine", 1)[1].split("\n## ", 1)[0]
    commands = re.findall(r"```\n(.*?)\n```", setup, flags=re.S)
    assert len(commands) == 2
    assert "gearcheck crosscheck" in commands[0]
    assert "pytest" in commands[1]
    assert commands[1] in (ROOT / ".ci" / "run").read_text(encoding="utf-8")
