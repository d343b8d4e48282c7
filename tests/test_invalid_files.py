"""Every file in tests/data/invalid/ fails through the CLI with its expected one-line message
(first line: ``# expect: ...``), exit status 2 and no traceback: each through the command line's ``main`` in this
process, and one through a ``python -m gearcheck`` process of its own, whose exit status is the one the shell sees."""

import subprocess
import sys
from pathlib import Path

import pytest

from gearcheck.cli import main

INVALID = sorted((Path(__file__).parent / "data" / "invalid").glob("*.toml"))


def test_corpus_is_large_enough():
    assert len(INVALID) >= 20


def _said_once(path: Path, status: int, stdout: str, stderr: str) -> None:
    expected = path.read_text().splitlines()[0].removeprefix("# expect: ")
    assert status == 2
    assert stdout == ""
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    assert lines[0].startswith(f"gearcheck: error: {path}: ")
    assert expected in lines[0]


@pytest.mark.parametrize("path", INVALID, ids=[p.stem for p in INVALID])
def test_invalid_train_file(path, capsys):
    status = main(["show", str(path)])
    _said_once(path, status, *capsys.readouterr())


def test_an_invalid_train_file_ends_the_process_with_status_2():
    path = INVALID[0]
    run = subprocess.run([sys.executable, "-m", "gearcheck", "show", str(path)], capture_output=True, text=True)
    _said_once(path, run.returncode, run.stdout, run.stderr)
