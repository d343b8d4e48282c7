"""docs/seed-coverage.md, the table of every table and figure of the four seed papers, cannot rot: every status is
one of the page's own, the summary counts are the table's, every test it names exists, every file it names exists,
every ``gearcheck`` command line it gives parses with the command line's own parser (a bare command name in the
prose must be a command), and the documentation site's index includes the page."""

from __future__ import annotations

import ast
import re
import shlex
from collections import Counter
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "seed-coverage.md"
SEEDS = ("000", "002", "003", "004")
STATUSES = ("reproduced", "shown not reproducible", "photograph or drawing (nothing to compute)", "missing")
ITEM = re.compile(r"^(000|002|003|004) (Fig\.|Table|Eqs?\.|Appendix|§)")
TEST_REFERENCE = re.compile(r"\b(tests/[\w/]+\.py)::(\w+)")
PATH_REFERENCE = re.compile(r"(?<![\w/.-])((?:docs|src|examples|lumped|mbd_models|compare|bench|tests)/[\w./-]+)")


def text() -> str:
    return PAGE.read_text(encoding="utf-8")


def table_rows() -> list[list[str]]:
    """Every row of every Markdown table on the page, as stripped cells (no cell holds a '|')."""
    return [[cell.strip() for cell in line.strip().strip("|").split("|")]
            for line in text().splitlines() if line.lstrip().startswith("|")]


def items() -> list[list[str]]:
    """The rows of the per-seed tables: item, what it shows, status, evidence."""
    return [row for row in table_rows() if ITEM.match(row[0])]


@cache
def functions(path: str) -> frozenset[str]:
    tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
    return frozenset(node.name for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)))


def test_every_item_has_four_cells_and_a_known_status():
    rows = items()
    assert len(rows) > 50
    for row in rows:
        assert len(row) == 4, row[0]
        assert row[2] in STATUSES, f"{row[0]}: status {row[2]!r}"
        assert row[1] and row[3], f"{row[0]}: what it shows and the evidence must be given"
    names = [row[0] for row in rows]
    assert len(names) == len(set(names)), [n for n, k in Counter(names).items() if k > 1]
    assert {name[:3] for name in names} == set(SEEDS)


def test_the_summary_counts_are_the_tables():
    header = next(row for row in table_rows() if row[0] == "seed")
    assert tuple(header) == ("seed", *STATUSES, "items")
    summary = {row[0]: [int(n) for n in row[1:]] for row in table_rows() if row[0] in (*SEEDS, "all")}
    counted = Counter((row[0][:3], row[2]) for row in items())
    for seed in SEEDS:
        expected = [counted[seed, status] for status in STATUSES]
        assert summary[seed] == expected + [sum(expected)], seed
    assert summary["all"] == [sum(summary[s][i] for s in SEEDS) for i in range(len(STATUSES) + 1)]


def test_every_test_named_exists():
    references = TEST_REFERENCE.findall(text())
    assert len(references) > 30
    for path, name in references:
        assert (ROOT / path).is_file(), path
        assert name.startswith("test_") and name in functions(path), f"{path}::{name} is no test function"


def test_every_file_named_exists():
    paths = {p.rstrip(".,;:") for p in PATH_REFERENCE.findall(text())}
    assert any(p.startswith("docs/") for p in paths)
    missing = sorted(p for p in paths if not (ROOT / p).exists())
    assert not missing, missing


def test_every_gearcheck_command_parses():
    from gearcheck.cli import COMMANDS, _parser

    commands = [span for span in re.findall(r"`([^`]+)`", text()) if span.startswith("gearcheck ")]
    assert len(commands) > 15
    names = set(COMMANDS)
    for command in commands:
        argv = shlex.split(command)[1:]
        assert argv[0] in names, f"{command}: no such command"
        if len(argv) == 1:  # a command named in the prose, not a command line
            continue
        try:
            args = _parser().parse_args(argv)
        except (Exception, SystemExit) as exc:  # the parser raises GearcheckError with its one line
            pytest.fail(f"{command}: {exc}")
        assert args.command == argv[0]


def test_every_python_script_named_exists():
    for script in re.findall(r"`python (\S+\.py)", text()):
        assert (ROOT / script).is_file(), script


def test_the_page_is_in_the_sites_index():
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    toctrees = re.findall(r"```\{toctree\}(.*?)```", index, flags=re.DOTALL)
    assert any(re.search(r"^seed-coverage$", tree, flags=re.MULTILINE) for tree in toctrees)
