"""Shared fixtures: every preset as a parameter; a headless Chromium that loads a page and tells its console; demo-3p's
cross-check shared; the compiled kernels compiled once before xdist's workers start."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path
from types import SimpleNamespace

import pytest
from threadpoolctl import threadpool_limits

from gearcheck.api import compile_kernels, crosscheck
from gearcheck.cli import main
from gearcheck.train.loader import preset_names

os.environ.setdefault("GEARCHECK_DEBUG", "1")  # a fault of gearcheck's own raises in a test, with its traceback


@pytest.fixture(params=preset_names())
def preset(request):
    return request.param


@pytest.fixture(scope="session")
def demo_check():
    """demo-3p cross-checked over 0.05 s, one run for every test that reads it (a worker's tests share it)."""
    return crosscheck("demo-3p", duration=0.05)


@pytest.fixture
def refused(capsys):
    """``refused(argv)``: the command line, run in this process, refuses ``argv`` as bad input: exit status 2,
    nothing on stdout, one line on stderr (``gearcheck: error: ...``, no traceback), which it returns."""
    def run(argv) -> str:
        status = main([str(a) for a in argv])
        out, err = capsys.readouterr()
        assert status == 2 and out == "", (status, out, err)
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("gearcheck: error: ") and "Traceback" not in err, err
        return lines[0]
    return run


CHROMIUM = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--enable-logging=stderr", "--v=0", "--window-size=1200,900"]


@pytest.fixture
def browser(tmp_path):
    """``browse(page, *flags)`` runs headless Chromium on a file (``--dump-dom`` or ``--screenshot=PNG``) with a
    fresh profile; ``console(stderr)`` the page's console messages, script errors among them.  No Chromium is a
    failure, not a skip: CI installs it."""
    found = next((shutil.which(name) for name in CHROMIUM if shutil.which(name)), None)
    if found is None:
        pytest.fail(f"headless Chromium is needed and was not found (tried {', '.join(CHROMIUM)}): install it, e.g. "
                    "apt-get install -y chromium")

    def browse(page: Path, *args: str) -> subprocess.CompletedProcess:
        done = subprocess.run([found, *CHROMIUM_FLAGS, f"--user-data-dir={tmp_path / 'chromium-profile'}", *args,
                               page.as_uri()], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr[-2000:]
        return done

    def console(stderr: str) -> list[str]:
        return [line for line in stderr.splitlines() if ":CONSOLE" in line or "Uncaught" in line]

    return SimpleNamespace(browse=browse, console=console)


# The smoke subset (`pytest -m smoke`): a contributor's check in under a minute that touches every layer -- the
# train description, both solvers' modes and time runs, a cross-check, an operating history, order tracking, the
# command line's bad input, the generated files.  Listed here, in one place (tests/test_smoke.py checks each exists).
SMOKE = (
    "tests/test_kinematics.py::test_demo_ratio_is_one_plus_zr_over_zs",
    "tests/test_kinematics.py::test_mesh_frequency_and_planet_phases",
    "tests/test_modal.py::test_single_mesh_frequency_is_sqrt_k_over_m_eq",
    "tests/test_modal.py::test_mode_multiplicities_for_equally_spaced_planets[3]",
    "tests/test_mbd_modes.py::test_frequencies_and_types_match_lumped[demo-3p]",
    "tests/test_time_solver.py::test_rk4_converges_at_fourth_order_to_dop853",
    "tests/test_crosscheck.py::test_demo_presets_pass_with_default_tolerances",
    "tests/test_operating_history.py::test_clock_closed_forms",
    "tests/test_operating_history.py::test_constant_speed_is_the_limit_to_the_bit",
    "tests/test_operating_history.py::test_run_up_in_both_solvers",
    "tests/test_order_tracking.py::test_two_non_integer_orders_are_separated_with_a_bounded_error",
    "tests/test_front_door.py::test_simulate_returns_named_signals_with_pandas_export",
    "tests/test_bad_input.py::test_the_line_names_the_file",
    "tests/test_xml.py::test_xml_is_up_to_date_and_loads[demo-3p]",
    "tests/test_readme.py::test_generated_references_match_the_code",
    "tests/test_schemas.py::test_the_shipped_schemas_are_current",
)


def pytest_configure(config):
    config.addinivalue_line("markers", "smoke: the contributor's subset (pytest -m smoke), listed in conftest.SMOKE")
    if getattr(config.option, "numprocesses", None) and not hasattr(config, "workerinput"):
        compile_kernels()  # xdist's controller, before its workers start: they load the kernels from numba's cache
    if hasattr(config, "workerinput"):
        _share_the_cores(int(config.workerinput["workercount"]))


def _share_the_cores(workers: int) -> None:
    """An xdist worker's BLAS and OpenMP threads: its share of the cores (scikit-learn's conftest does the same).
    The workers already keep every core busy, and a BLAS thread that finds its core taken spins: with both cores
    busy, a 60-coordinate eigenproblem took 0.7-1.0 s on OpenBLAS's two threads and 0.02 s on one. The processes a
    test starts inherit the share."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1  # not on macOS
    share = max(1, cores // workers)
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[name] = str(share)
    threadpool_limits(limits=share)


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.nodeid in SMOKE:
            item.add_marker(pytest.mark.smoke)
