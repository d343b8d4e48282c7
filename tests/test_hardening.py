"""Hardening as a hostile user and a careless one would test it: a train file is data and runs no code, the files
it names stay beside it, every read is bounded, the output lock cannot be redirected, what a killed run leaves is
cleared, user code is walled in, every size has a bound, and a killed sweep leaves no process behind."""

from __future__ import annotations

import errno
import io
import os
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.engine.user_model import user_side
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.outputs import MARKER, OutputDirectory, lock_folder
from gearcheck.shared.trust import granted
from gearcheck.train.files import read_arrays
from gearcheck.train.loader import preset_text

DEMO = preset_text("demo-3p")
PLANTED = '''
import pathlib
pathlib.Path(__file__).with_name("RAN").write_text("the planted module ran")
def torque(t):
    return 100.0
def factory(spec):
    raise SystemExit(0)
'''


def train_with(folder: Path, operating: str = "", train: str = "") -> Path:
    """demo-3p in ``folder`` with a line added to [operating] and/or [train]."""
    text = DEMO.replace("[operating]\n", f"[operating]\n{operating}\n", 1)
    text = text.replace("[train]\n", f"[train]\n{train}\n", 1)
    path = folder / "train.toml"
    path.write_text(text, encoding="utf-8")
    return path


def refused(argv, capsys, *fragments) -> str:
    """Run the command line: exit 2, one line holding every fragment, no traceback."""
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("gearcheck: error: ") and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, err
    return err


# ----------------------------------------------------------------------------- data never runs code
@pytest.fixture
def planted(tmp_path, monkeypatch):
    """A module planted beside the train file, importable from the current folder (as ``python -m`` makes it)."""
    (tmp_path / "planted.py").write_text(PLANTED, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path
    sys.modules.pop("planted", None)


@pytest.mark.parametrize("operating, train, argv", [  # T: the train file
    ('torque_function = "planted:torque"', "", ["run", "T", "--duration", "0.002", "--out", "o"]),
    ('torque_function = "planted:torque"', "", ["crosscheck", "T", "--duration", "0.01", "--out", "o"]),
    ("", 'user_model = "planted.py:factory"', ["crosscheck", "T", "--model", "user", "--out", "o"]),
    ("", 'user_model = "planted:factory"', ["mac", "T", "--model", "user"]),
], ids=["run-torque-function", "crosscheck-torque-function", "user-model-file", "user-model-module"])
def test_a_planted_module_beside_a_train_file_stays_unimported(planted, operating, train, argv, capsys):
    path = train_with(planted, operating, train)
    for command in (["show", path], ["modes", path]):  # reading the file runs nothing
        assert main([str(a) for a in command]) == 0
    spec = gearcheck.load(path)
    assert spec.operating.torque_function or spec.user_model
    module = str(planted / "planted.py") if ".py:" in train else "planted"
    refused([path if a == "T" else a for a in argv], capsys, "is Python code named by a train file",
            f"--trust {module}")
    assert not (planted / "RAN").exists() and not (planted / "o").exists()


def test_python_minus_m_on_a_train_file_runs_nothing(planted):
    """``python -m gearcheck`` puts the current folder on the import path: the planted module is still not run."""
    path = train_with(planted, 'torque_function = "planted:torque"')
    done = subprocess.run([sys.executable, "-m", "gearcheck", "run", str(path), "--duration", "0.002", "--out", "o"],
                          capture_output=True, text=True, cwd=planted, timeout=300)
    assert done.returncode == 2 and "--trust planted" in done.stderr and "Traceback" not in done.stderr
    assert not (planted / "RAN").exists()


def test_trusted_code_runs_and_its_faults_are_one_line(planted, capsys):
    path = train_with(planted, 'torque_function = "planted:torque"')
    assert main(["run", str(path), "--duration", "0.002", "--out", "o", "--trust", "planted"]) == 0
    assert (planted / "RAN").exists() and (planted / "o" / "timeseries.parquet").exists()
    with granted(["planted"]):  # the Python face of --trust, undone after the block
        excitation = gearcheck.Train(path).lumped.model.excitation
        assert excitation.torque_function(np.array([0.0, 1e-3])).tolist() == [100.0, 100.0]
    assert "GEARCHECK_TRUST" not in os.environ
    for ref, trusted, said in [("math:ldexp", "math", ") raised TypeError: ldexp expected 2 arguments"),
                               ("builtins:str", "builtins", ") returned '"),
                               ("no_such_module:f", "no_such_module", "importing no_such_module failed"),
                               ("math:pi", "math", "math has no callable 'pi'")]:
        bad = train_with(planted, f'torque_function = "{ref}"')
        refused(["run", bad, "--duration", "0.002", "--out", "p", "--trust", trusted], capsys,
                f"{bad}: operating.torque_function: ", said)
        assert not (planted / "p").exists()
    user = train_with(planted, "", 'user_model = "planted.py:factory"')
    refused(["crosscheck", user, "--model", "user", "--out", "p", "--trust", "planted.py"], capsys,
            "building the model failed: SystemExit: 0")


# ----------------------------------------------------------------------------- paths named by a train file
def test_the_files_a_train_file_names_stay_in_its_folder(tmp_path, capsys):
    folder, outside = tmp_path / "train", tmp_path / "elsewhere"
    folder.mkdir()
    outside.mkdir()
    (outside / "profile.csv").write_text("0,1\n1,2\n", encoding="utf-8")
    (folder / "link.csv").symlink_to(outside / "profile.csv")
    for name in ("../elsewhere/profile.csv", str(outside / "profile.csv"), "link.csv", "/etc/hostname"):
        path = train_with(folder, f'torque_csv = "{name}"')
        refused(["show", path], capsys, "operating.torque_csv", "lies outside the train file's folder", "--data-root")
    path = train_with(folder, 'torque_csv = "link.csv"')
    assert main(["show", str(path), "--data-root", str(outside)]) == 0  # allowed by the user
    assert "GEARCHECK_DATA_ROOTS" not in os.environ
    refused(["show", path, "--data-root", str(tmp_path / "none")], capsys, "--data-root", "not a folder")
    refused(["show", path, "--data-root", ""], capsys, "--data-root '': not a folder")  # not the current folder


# ----------------------------------------------------------------------------- every read bounded
def test_a_fifo_or_a_device_is_refused_without_blocking(tmp_path, capsys):
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    done = subprocess.run([sys.executable, "-m", "gearcheck", "show", str(fifo)], capture_output=True, text=True,
                          timeout=120)  # a blocking read would wait for a writer forever
    assert done.returncode == 2 and "is not a regular file (a FIFO, device or socket)" in done.stderr
    path = train_with(tmp_path, 'torque_csv = "/dev/zero"')
    refused(["show", path, "--data-root", "/dev"], capsys, "/dev/zero: is not a regular file")
    refused(["crosscheck", "demo-3p", "--measurements", "/dev/zero", "--out", tmp_path / "o"], capsys,
            "/dev/zero: is not a regular file")


@pytest.mark.parametrize("argv", [["stiffness", "demo-3p", "-o"], ["animate", "demo-3p", "--duration", "0.2", "-o"],
                                  ["mjcf", "demo-3p", "-o"]], ids=["png", "gif", "xml"])
def test_an_output_file_that_is_a_device_or_fifo_is_never_replaced(argv, tmp_path, capsys):
    """As root, ``-o /dev/null`` replaced the device node with a PNG (found by the option probe): a file output
    must be a regular file or nothing.  A FIFO stands in for the device here."""
    fifo = tmp_path / ("out" + {"stiffness": ".png", "animate": ".gif", "mjcf": ".xml"}[argv[0]])
    os.mkfifo(fifo)
    refused(argv + [fifo], capsys, "is not a regular file (a device, FIFO or socket); gearcheck writes files")
    assert fifo.is_fifo() and sorted(p.name for p in tmp_path.iterdir()) == [fifo.name]


def npz_declaring(shape, dtype="<f8") -> bytes:
    """An .npz whose one member's header declares ``shape`` but holds 64 bytes."""
    header = {"descr": dtype, "fortran_order": False, "shape": shape}
    text = repr(header).encode("latin1")
    text += b" " * (-(len(text) + 11) % 64) + b"\n"
    member = b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text + bytes(64)
    sink = io.BytesIO()
    with zipfile.ZipFile(sink, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("K.npy", member)
    return sink.getvalue()


def test_an_archive_declaring_a_huge_array_is_refused_before_it_is_decompressed(tmp_path):
    path = tmp_path / "model.npz"
    path.write_bytes(npz_declaring((20000, 20000)))
    with pytest.raises(GearcheckError, match=r"model.npz: its arrays declare 3051.8 MiB, too large for a model file"):
        read_arrays(path, "model file")
    path.write_bytes(npz_declaring((2, 2), "|O"))
    with pytest.raises(GearcheckError, match="K: saved as Python objects"):
        read_arrays(path, "model file")


def test_complex_matrices_are_refused(tmp_path, capsys):
    good = tmp_path / "good.npz"
    gearcheck.export_model("demo-3p", good)
    data = dict(np.load(good))
    data["K"] = data["K"] * (1 + 1e-3j)
    np.savez(tmp_path / "complex.npz", **data)
    refused(["mac", "demo-3p", "--model", tmp_path / "complex.npz"], capsys, "complex.npz: K: holds complex numbers")


# ----------------------------------------------------------------------------- locks and leftovers
def test_a_planted_link_cannot_redirect_the_lock(tmp_path, monkeypatch, capsys):
    import tempfile

    monkeypatch.delenv("XDG_RUNTIME_DIR", raising=False)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "precious").write_text("root's own", encoding="utf-8")
    (tmp_path / f"gearcheck-{os.getuid()}").symlink_to(victim)  # the lock folder, planted as a link
    refused(["run", "demo-3p", "--duration", "0.001", "--out", tmp_path / "o"], capsys,
            "the folder for gearcheck's locks is not a private folder of this user")
    (tmp_path / f"gearcheck-{os.getuid()}").unlink()
    folder = lock_folder()
    assert folder.stat().st_mode & 0o777 == 0o700
    out = Path(os.path.realpath(tmp_path / "o"))
    import hashlib

    (folder / f"{hashlib.sha256(str(out).encode()).hexdigest()[:24]}.lock").symlink_to(victim / "precious")
    refused(["run", "demo-3p", "--duration", "0.001", "--out", out], capsys, "cannot take the output's lock")
    assert (victim / "precious").read_text(encoding="utf-8") == "root's own" and not out.exists()


def test_outputs_take_the_umasks_permissions(tmp_path):
    """Written through temporary files and folders (made 0600 and 0700), outputs end with the permissions any
    file the user makes has: 0644 and 0755 under the umask 022."""
    before = os.umask(0o022)
    try:
        assert main(["run", "demo-3p", "--duration", "0.002", "--out", str(tmp_path / "o")]) == 0
        assert main(["stiffness", "demo-3p", "-o", str(tmp_path / "k.png")]) == 0
    finally:
        os.umask(before)
    assert (tmp_path / "o").stat().st_mode & 0o777 == 0o755
    assert (tmp_path / "o" / "summary.json").stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "k.png").stat().st_mode & 0o777 == 0o644


def test_two_paths_to_one_folder_are_one_lock(tmp_path, capsys):
    (tmp_path / "real").mkdir()
    (tmp_path / "alias").symlink_to(tmp_path / "real")
    with OutputDirectory(tmp_path / "real" / "o"):
        refused(["run", "demo-3p", "--duration", "0.001", "--out", tmp_path / "alias" / "o"], capsys,
                "another gearcheck run (pid")


def test_what_a_killed_run_left_is_cleared_by_the_next(tmp_path, capsys):
    out = tmp_path / "o"
    for name in (".o.abcd1234.partial", ".o.efgh5678.previous"):
        (tmp_path / name).mkdir()
        (tmp_path / name / MARKER).write_text("", encoding="utf-8")
    (tmp_path / ".o.efgh5678.previous" / "kept").write_text("previous output", encoding="utf-8")
    (tmp_path / ".other.abcd1234.partial").mkdir()  # another output's: not this one's to touch
    with OutputDirectory(out):
        assert (out / "kept").read_text(encoding="utf-8") == "previous output"  # put back: out was gone
    err = capsys.readouterr().err
    assert "removed .o.abcd1234.partial, left by a killed run" in err and "put back o" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [".other.abcd1234.partial", "o"]


KILL_AT = (0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.9)  # of an uninterrupted run's time: the imports, the run, the writing


def test_sigkill_at_any_point_loses_nothing_the_next_run_cannot_recover(tmp_path):
    """The SIGKILL matrix: a run killed at any moment of its life (spread over the time an uninterrupted run takes,
    measured first) leaves the previous output (or a hidden copy of it, which the next run puts back) and hidden
    folders that the next run removes; the next run then succeeds."""
    out = tmp_path / "o"
    command = [sys.executable, "-m", "gearcheck", "run", "demo-3p", "--duration", "0.01", "--out", str(out)]
    lifetimes = []
    for _ in range(2):  # the shorter of two: the first may read cold files
        started = time.perf_counter()
        assert subprocess.run(command, capture_output=True, timeout=300).returncode == 0
        lifetimes.append(time.perf_counter() - started)
    previous = (out / "timeseries.parquet").read_bytes()
    killed = 0
    for delay in (fraction * min(lifetimes) for fraction in KILL_AT):
        run = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        killed += run.poll() is None  # not ended yet (a run faster than the measured ones may have)
        run.kill()
        run.wait(timeout=60)
        hidden = [p for p in tmp_path.iterdir() if p.name.startswith(".o.")]
        assert out.exists() or any(p.name.endswith(".previous") for p in hidden), (delay, hidden)
        done = subprocess.run(command, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == ["o"], delay
        assert (out / "timeseries.parquet").read_bytes() == previous  # the same input gives the same bytes
    assert killed >= len(KILL_AT) - 2, f"only {killed} of the runs were still going when killed"


# ----------------------------------------------------------------------------- user code walled in
class Garbage:
    """A side whose methods return what no side returns."""

    solver = "garbage"

    def __init__(self, spec):
        self.spec = spec

    def modes(self):
        return 42

    def run(self, settings, progress=None):
        return 1 / 0

    def stable_step(self):
        return float("nan")


def test_a_side_that_returns_garbage_is_one_line(capsys):
    side = gearcheck.Train("demo-3p").lumped
    with pytest.raises(GearcheckError, match=r"^model=Garbage: its modes\(\) returned 42, not a ModalResult$"):
        gearcheck.crosscheck("demo-3p", model=Garbage(side.spec))
    adopted = user_side(Garbage(side.spec), side.spec)
    with pytest.raises(GearcheckError, match=r"its run\(\) raised ZeroDivisionError: division by zero"):
        adopted.run(None)
    with pytest.raises(GearcheckError, match=r"its stable_step\(\) returned nan, not a positive step in s"):
        adopted.stable_step()


# ----------------------------------------------------------------------------- every size bounded
@pytest.mark.parametrize("argv, said", [
    (["animate", "demo-3p", "--fps", "1e9", "-o", "a.gif"], "--fps 1000000000.0: a positive playback length and a "
                                                             "frame rate from 0 to 120"),
    (["animate", "demo-3p", "--duration", "1e9", "-o", "a.gif"], "1.5e+10 frames, more than the 1800"),
    (["animate", "demo-3p", "--duration", "1e308", "-o", "a.gif"], "inf frames, more than the 1800"),
    (["pins", "rv-reducer", "--samples", "99999999999999999999", "-o", "p.png"],
     "--samples 99999999999999999999: a whole number of frozen times from 1 to 10000"),
    (["animate", "demo-3p", "--slow-motion", "1e-9", "-o", "a.gif"], "steps, more than the 2e+08"),
    (["sensitivity", "rv-reducer", "--parameter", "stages[0].sun.mass", "--orders", "100000", "100000"],
     "complex unknowns (coordinates times harmonics), more than the 20000"),
    (["sensitivity", "rv-reducer", "--parameter", "stages[0].sun.mass", "--orders", "0", "0"], "not all 0"),
    (["sweep", "demo-3p", "--set", "stages[0].sun.mass=1:2:100000", "--set", "stages[0].planet.mass=1:2:100000"],
     "10000000000 points: more than the 100000 a sweep holds"),
    (["crosscheck", "demo-3p", "--history", "h.sqlite", "--commit", "abc\ndef"], "commit id 'abc\\ndef': one line"),
    (["sweep", "demo-3p", "--speeds", "1000,1100", "--out", ""], "--out: give a path, not an empty string"),
], ids=["fps", "frames", "frames-inf", "pin-times", "steps", "orders", "orders-zero", "grid", "commit-newline",
        "empty-out"])
def test_every_size_has_a_bound(argv, said, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    needs_out = argv[0] in ("sweep", "sensitivity", "crosscheck") and "--out" not in argv
    refused(argv + ["--out", "o"] if needs_out else argv, capsys, said)
    assert list(tmp_path.iterdir()) == []


def test_a_long_run_is_said_before_it_starts(capsys):
    from gearcheck.shared.errors import LongRunWarning
    from gearcheck.shared.settings import RunSettings

    with pytest.warns(LongRunWarning, match=r"is 1.5e\+07 steps: a run of minutes"):
        assert RunSettings(0.15).check_work(1e-8, 10, "test model") == (15_000_000, 1)


def test_a_damaged_history_store_is_one_line(tmp_path, capsys):
    import sqlite3

    store = tmp_path / "h.sqlite"
    assert main(["crosscheck", "demo-3p", "--duration", "0.02", "--out", str(tmp_path / "o"), "--history", str(store),
                 "--commit", "c1"]) in (0, 1, 3)
    capsys.readouterr()
    con = sqlite3.connect(store)
    con.execute("UPDATE runs SET failures = '{not json'")
    con.commit()
    refused(["dashboard", store, "-o", tmp_path / "site"], capsys, "runs.failures of commit 'c1' is not a JSON list")
    con.execute("DROP TABLE metrics")
    con.commit()
    con.close()
    refused(["dashboard", store, "-o", tmp_path / "site"], capsys, "the table metrics is missing")
    assert not (tmp_path / "site").exists()


def test_a_full_disk_is_one_line_and_the_previous_output_stays(tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    assert main(["run", "demo-3p", "--duration", "0.002", "--out", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(out / "timeseries.parquet"))

    monkeypatch.setattr("pyarrow.parquet.write_table", full)
    capsys.readouterr()
    refused(["run", "demo-3p", "--duration", "0.002", "--out", out], capsys, "No space left on device",
            "the previous output stays")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o"]


def test_a_read_only_install_without_a_writable_home_still_compiles(tmp_path):
    """Where numba can cache beside neither the sources nor the user's cache folder, a private folder serves."""
    (tmp_path / "file").write_text("", encoding="utf-8")
    code = ("import os, pathlib; from gearcheck.shared.compiled_cache import ensure_cache_folder; "
            f"print(ensure_cache_folder(pathlib.Path({str(tmp_path / 'file' / 'src')!r})))")
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "file" / "cache"), "TMPDIR": str(tmp_path)}
    env.pop("NUMBA_CACHE_DIR", None)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert done.stdout.strip() == str(tmp_path / f"gearcheck-numba-{os.getuid()}"), done.stderr
    assert (tmp_path / f"gearcheck-numba-{os.getuid()}").stat().st_mode & 0o777 == 0o700


# ----------------------------------------------------------------------------- processes and caches
def _descendants(pid: int) -> set[int]:
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                parents[int(entry.name)] = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
    found, frontier = set(), {pid}
    while frontier:
        frontier = {child for child, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parent-death signal is Linux's")
def test_a_killed_sweep_leaves_no_worker_behind(tmp_path):
    script = ("import gearcheck\n"
              "gearcheck.sweep('demo-3p', speeds=[1000.0, 1100.0, 1200.0, 1300.0], solver='lumped', "
              "duration=5.0, workers=2, continuation=False)\n")  # four points for the pool, not one chain
    parent = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while len(_descendants(parent.pid)) < 3:  # the fork server and two workers
        assert time.monotonic() < deadline and parent.poll() is None
        time.sleep(0.1)
    workers = _descendants(parent.pid)  # the fork server, its workers and the resource tracker
    parent.kill()
    parent.wait()
    deadline = time.monotonic() + 30
    while any(Path(f"/proc/{pid}").exists() and "Z" not in (Path(f"/proc/{pid}") / "stat").read_text().split()[2]
              for pid in workers):
        assert time.monotonic() < deadline, "a process of the sweep outlived it"
        time.sleep(0.1)


def test_a_cache_file_is_only_read_as_its_own_point(tmp_path):
    fast = dict(solver="lumped", duration=0.03, workers=1, cache=tmp_path)
    first = gearcheck.sweep("demo-3p", speeds=[1000.0, 1500.0], **fast)
    a, b = sorted(tmp_path.glob("*.parquet"))
    a_bytes, b_bytes = a.read_bytes(), b.read_bytes()
    a.write_bytes(b_bytes)  # two valid cache files swapped
    b.write_bytes(a_bytes)
    again = gearcheck.sweep("demo-3p", speeds=[1000.0, 1500.0], **fast)
    assert (again.computed, again.cached) == (2, 0) and again.parquet() == first.parquet()


def test_a_fault_of_gearchecks_own_is_one_line_with_its_own_exit_status(monkeypatch, capsys):
    """The last net: an exception no input check foresaw is one line, exit 70 (not 2: it is no bad input)."""
    import gearcheck.cli as cli

    def broken(args):
        raise TypeError("unsupported operand type(s)")

    monkeypatch.delenv("GEARCHECK_DEBUG")
    monkeypatch.setitem(cli.COMMANDS["presets"].__dict__, "run", broken)
    assert main(["presets"]) == 70
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("gearcheck: error: internal error, TypeError: unsupported") and \
        "GEARCHECK_DEBUG=1 shows the traceback" in err
