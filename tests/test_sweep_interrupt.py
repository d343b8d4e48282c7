"""Ctrl-C on a sweep that runs on 2 local worker processes, as a terminal sends it: SIGINT to the command's
whole process group (the command, its fork server, its resource tracker and its workers).  The command runs in
a session of its own, so the signal reaches nothing of pytest's.  Whether it comes while the workers start or
while they run points, the command must end at once with status 130 and one line on stderr, keep the points it
finished in the cache (whole files only), leave the previous output as it was and no process behind; the next
run resumes from the cache and writes the table an uninterrupted run writes, byte for byte."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from gearcheck.compare.studies import point_backends as backends
from gearcheck.compare.studies import sweep as sw
from gearcheck.shared.outputs import MARKER

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX sessions and /proc")

POINTS = 6  # demo-3p, lumped, 0.1 s: half a second a point, so the sweep is still running when interrupted
SWEEP = ["sweep", "demo-3p", "--speeds", f"1000:2000:{POINTS}", "--solver", "lumped", "--duration", "0.1"]
PREVIOUS = {MARKER: b"gearcheck output\n", "previous.txt": b"the previous sweep\n"}


# ``python -m gearcheck`` with Ctrl-C handled as in a terminal's foreground job: a test run started in the
# background (``cmd &`` in a script) inherits SIGINT ignored, and Python keeps an ignored SIGINT ignored
FOREGROUND = ("import runpy, signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
              "sys.argv[0] = 'gearcheck'; runpy.run_module('gearcheck', run_name='__main__', alter_sys=True)")


def _start(cwd: Path, *args: str) -> subprocess.Popen:
    """``python -m gearcheck sweep ...`` in a new session: its process group is its own, and so is its session
    id, which every process it starts inherits."""
    return subprocess.Popen([sys.executable, "-c", FOREGROUND, *SWEEP, *args], cwd=cwd, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
                            env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))


def _session(sid: int) -> dict[int, str]:
    """{pid: command line} of the live (not zombie) processes of session ``sid``."""
    found = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            fields = Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()
            if int(fields[3]) == sid and fields[0] not in ("Z", "X"):
                found[int(entry)] = Path(f"/proc/{entry}/cmdline").read_bytes().replace(b"\0", b" ").decode()[:120]
        except (OSError, IndexError, ValueError):  # gone meanwhile
            continue
    return found


def _finish(process: subprocess.Popen, timeout: float = 120) -> tuple[str, str]:
    try:
        return process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        out, err = process.communicate()
        pytest.fail(f"the command did not end within {timeout:g} s:\n{err[-2000:]}")


def _interrupted(tmp_path: Path, ready) -> tuple[Path, Path]:
    """Run the sweep on 2 workers into an earlier output, Ctrl-C it once ``ready(cache, session)`` is true, and
    check how it ended; returns (out, cache)."""
    out, cache = tmp_path / "out", tmp_path / "cache"
    out.mkdir()  # a previous output, which an interrupted run must leave as it was
    for name, data in PREVIOUS.items():
        (out / name).write_bytes(data)
    run = _start(tmp_path, "--workers", "2", "--cache", str(cache), "--out", str(out))
    try:
        deadline = time.monotonic() + 120
        while run.poll() is None and not ready(cache, _session(run.pid)) and time.monotonic() < deadline:
            time.sleep(0.02)
        assert run.poll() is None, f"the sweep ended (status {run.returncode}) before the moment to interrupt it"
        running = _session(run.pid)
        assert ready(cache, running), "the moment to interrupt did not come within 120 s"
        os.killpg(run.pid, signal.SIGINT)  # Ctrl-C: the whole foreground group
        stdout, stderr = _finish(run, timeout=60)
        assert run.returncode == 130, f"status {run.returncode}, stderr:\n{stderr}"
        assert stderr.splitlines() == ["gearcheck: interrupted"], stderr  # one line, no traceback
        assert "wrote" not in stdout
        left = _session(run.pid)
        deadline = time.monotonic() + 10  # the fork server and resource tracker end when the command is gone
        while left and time.monotonic() < deadline:
            time.sleep(0.05)
            left = _session(run.pid)
        assert not left, f"processes left behind: {left} (running at the signal: {running})"
    finally:
        for pid in _session(run.pid):  # only after a failure: no stray process outlives the test
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
    assert sorted(p.name for p in tmp_path.iterdir()) in (["out"], ["cache", "out"])  # no half-made folder beside
    assert {p.name: p.read_bytes() for p in out.iterdir()} == PREVIOUS
    for path in sorted(cache.iterdir()) if cache.exists() else []:  # whole points only: no temporary file
        assert re.fullmatch(r"[0-9a-f]{64}\.parquet", path.name), path.name
        assert pq.read_table(path).schema.equals(sw.POINT_SCHEMA), path.name
    return out, cache


def test_ctrl_c_while_the_workers_start_ends_cleanly(tmp_path):
    """The fork server is importing gearcheck (a second or two) when Ctrl-C comes: neither it nor a worker it
    starts may print a traceback, and no worker may start after the command is gone."""
    def forkserver_up(cache, session):
        return any("multiprocessing.forkserver" in command for command in session.values())

    _, cache = _interrupted(tmp_path, forkserver_up)
    assert len(list(cache.glob("*.parquet"))) < POINTS


def test_ctrl_c_on_two_worker_processes_ends_cleanly_and_the_sweep_resumes(tmp_path):
    out, cache = _interrupted(tmp_path, lambda cache, session: any(cache.glob("*.parquet")))
    cached = sorted(cache.iterdir())
    assert 1 <= len(cached) < POINTS, f"{len(cached)} of {POINTS} points cached: the sweep was not interrupted"
    stamps = {p.name: p.stat().st_mtime_ns for p in cached}

    resumed = _start(tmp_path, "--workers", "2", "--cache", str(cache), "--out", str(out))
    stdout, stderr = _finish(resumed)
    assert resumed.returncode == 0, stderr
    assert f"{POINTS - len(cached)} run, {len(cached)} from the cache" in stdout
    assert {p.name: p.stat().st_mtime_ns for p in cache.iterdir() if p.name in stamps} == stamps
    assert len(list(cache.glob("*.parquet"))) == POINTS

    whole = _start(tmp_path, "--workers", "2", "--no-cache", "--out", str(tmp_path / "whole"))
    stdout, stderr = _finish(whole)
    assert whole.returncode == 0, stderr
    assert (out / "sweep.parquet").read_bytes() == (tmp_path / "whole" / "sweep.parquet").read_bytes()


def test_an_interrupted_pool_has_closed_its_wake_up_pipe_when_it_returns():
    """The pool's manager thread closes its wake-up pipe as it ends, and Python 3.11's exit hook writes to every
    pipe not yet closed: an interrupted pool must have waited for that thread before the command goes on to exit,
    or the two race (a traceback of EBADF after "gearcheck: interrupted", seen in CI)."""
    from concurrent.futures import process

    def finished(point, result):
        raise KeyboardInterrupt  # Ctrl-C while the first result is handled

    with pytest.raises(KeyboardInterrupt):
        backends.run_pool(abs, [1, -2, 3, -4], 2, finished)
    assert all(wakeup._closed for wakeup in process._threads_wakeups.values())
