"""Every file in tests/data/invalid/ fails through the CLI with its expected one-line message
(first line: ``# expect: ...``), exit status 2 and no traceback: each through the command line's ``main`` in this
process (the ``refused`` fixture), and one through a ``python -m gearcheck`` process of its own, whose exit status
is the one the shell sees."""

import subprocess
import sys
from pathlib import Path

import pytest

INVALID = sorted((Path(__file__).parent / "data" / "invalid").glob("*.toml"))


def test_corpus_is_large_enough():
    assert len(INVALID) >= 20


def _expected(path: Path) -> str:
    return path.read_text().splitlines()[0].removeprefix("# expect: ")


@pytest.mark.parametrize("path", INVALID, ids=[p.stem for p in INVALID])
def test_invalid_train_file(path, refused):
    line = refused(["show", path])
    assert line.startswith(f"gearcheck: error: {path}: ") and _expected(path) in line, line


def test_an_invalid_train_file_ends_the_process_with_status_2():
    path = INVALID[0]
    run = subprocess.run([sys.executable, "-m", "gearcheck", "show", str(path)], capture_output=True, text=True)
    assert run.returncode == 2 and run.stdout == ""
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert lines[0].startswith(f"gearcheck: error: {path}: ") and _expected(path) in lines[0], lines[0]
