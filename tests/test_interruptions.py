"""Interrupted and concurrent runs: an output folder holds a complete output or nothing, never a part.

A cross-check is signalled (SIGTERM or SIGINT) while it writes its report: the moment its temporary
folder beside --out appears, then a little later.  Afterwards --out holds the previous complete report,
or the new complete one, or (with no previous one) nothing; no partial folder is left; the exit status
is the conventional one.  A second run into a folder that a first is writing is refused at once.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gearcheck.cli import main
from gearcheck.shared.outputs import MARKER, OutputDirectory

REPORT = {"report.json", "report.md", "report.html", "time_histories.png", "spectra.png", "natural_frequencies.png",
          "errors.png", MARKER}
COMMAND = [sys.executable, "-m", "gearcheck", "crosscheck", "demo-3p", "--duration", "0.01", "--out"]
ATTEMPTS = (0.0, 0.3, 0.0, 0.1, 0.0, 0.05)  # s from the partial folder's appearance to the signal


def complete(out: Path) -> bool:
    """Every report file there, the JSON whole, every PNG ending in its IEND chunk."""
    if {p.name for p in out.iterdir()} != REPORT:
        return False
    json.loads((out / "report.json").read_text())
    return all((out / name).read_bytes().endswith(b"IEND\xaeB`\x82") for name in REPORT if name.endswith(".png"))


def interrupted_run(out: Path, signum: int, delay: float) -> int:
    """Start a cross-check into ``out``, signal it ``delay`` s after its partial folder appears."""
    # a shell's background job (CI started with &) ignores SIGINT, and a child inherits that: give it the default
    run = subprocess.Popen(COMMAND + [str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while run.poll() is None and not list(out.parent.glob(f".{out.name}.*.partial")):
        assert time.monotonic() < deadline
        time.sleep(0.002)
    time.sleep(delay)
    if run.poll() is None:
        run.send_signal(signum)
    _, err = run.communicate(timeout=120)
    assert "Traceback" not in err, err
    return run.returncode


@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_run_interrupted_while_writing_leaves_the_previous_output_or_the_new_one(signum, code, tmp_path):
    out = tmp_path / "out"
    assert subprocess.run(COMMAND + [str(out)], capture_output=True).returncode == 0
    outcomes = []
    for delay in ATTEMPTS:  # until one lands inside the write phase (a loaded machine may signal late)
        if "previous" in outcomes:
            break
        previous = {name: (out / name).read_bytes() for name in REPORT - {MARKER}}
        rc = interrupted_run(out, signum, delay)
        assert rc in (0, code)
        assert complete(out)
        assert not list(tmp_path.glob(".out.*")), "a partial or previous folder was left"
        kept = all((out / name).read_bytes() == data for name, data in previous.items())
        outcomes.append("new" if not kept else "previous")
        if rc == code and not kept:  # signalled after the new output was in place: it is the whole new one
            assert json.loads((out / "report.json").read_text())["verdict"]["passed"]
    assert "previous" in outcomes, outcomes  # the interruption did land inside the write phase


def test_a_first_run_interrupted_while_writing_leaves_nothing(tmp_path):
    out = tmp_path / "deep" / "out"
    rc = interrupted_run(out, signal.SIGTERM, 0.0)
    assert rc in (0, 143)
    if rc == 0 or out.exists():  # done, or signalled after its output was in place (held until then): whole
        assert complete(out)
    else:
        assert not (tmp_path / "deep").exists(), "the folders a failed run made were left"


def test_a_second_run_into_the_same_folder_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    with OutputDirectory(out):
        assert main(["run", "demo-3p", "--duration", "0.001", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--out {out}: another gearcheck run (pid " in err
    assert not out.exists()
    assert main(["run", "demo-3p", "--duration", "0.001", "--out", str(out)]) == 0  # the lock went with the first
    assert (out / "timeseries.parquet").exists()


def test_a_closed_pipe_ends_the_program_quietly(tmp_path):
    """`gearcheck mjcf TRAIN | head -1` with more output than a pipe holds: no BrokenPipeError, the
    program ends on SIGPIPE as other command-line tools do."""
    from gearcheck.train.variants import chained_text

    train = tmp_path / "chain.toml"
    train.write_text(chained_text(12), encoding="utf-8")
    run = subprocess.Popen([sys.executable, "-m", "gearcheck", "mjcf", str(train)], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE)
    first = run.stdout.readline()
    run.stdout.close()
    err = run.stderr.read().decode()
    run.wait(timeout=60)
    assert first == b"<!--\n"
    assert "Traceback" not in err and "BrokenPipe" not in err, err
    assert run.returncode == -signal.SIGPIPE


def test_a_folder_that_is_no_earlier_output_is_never_replaced(tmp_path, capsys):
    """An output folder is replaced whole by the next run into it, so a folder holding anything gearcheck
    did not write (a project, the current directory) is refused; an empty one is used."""
    project = tmp_path / "project"
    project.mkdir()
    (project / "notes.txt").write_text("mine")
    assert main(["run", "demo-3p", "--duration", "0.001", "--out", str(project)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds files that gearcheck did not write (notes.txt, ...)" in err
    assert [p.name for p in project.iterdir()] == ["notes.txt"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["run", "demo-3p", "--duration", "0.001", "--out", str(empty)]) == 0
    assert (empty / MARKER).exists() and (empty / "timeseries.parquet").exists()
