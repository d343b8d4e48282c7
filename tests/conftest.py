"""Shared fixtures: every preset as a parameter; a headless Chromium that loads a page and tells its console."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path
from types import SimpleNamespace

import pytest

from gearcheck.train.loader import preset_names

os.environ.setdefault("GEARCHECK_DEBUG", "1")  # a fault of gearcheck's own raises in a test, with its traceback


@pytest.fixture(params=preset_names())
def preset(request):
    return request.param


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
