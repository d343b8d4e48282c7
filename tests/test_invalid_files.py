"""Every file in tests/data/invalid/ fails through the CLI with its expected one-line message
(first line: ``# expect: ...``), exit status 2 and no traceback."""

import subprocess
import sys
from pathlib import Path

import pytest

INVALID = sorted((Path(__file__).parent / "data" / "invalid").glob("*.toml"))


def test_corpus_is_large_enough():
    assert len(INVALID) >= 20


@pytest.mark.parametrize("path", INVALID, ids=[p.stem for p in INVALID])
def test_invalid_train_file(path):
    expected = path.read_text().splitlines()[0].removeprefix("# expect: ")
    run = subprocess.run([sys.executable, "-m", "gearcheck", "show", str(path)], capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stdout == ""
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert "Traceback" not in run.stderr
    assert lines[0].startswith(f"gearcheck: error: {path}: ")
    assert expected in lines[0]
