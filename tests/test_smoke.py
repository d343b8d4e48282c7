"""The smoke subset (conftest.SMOKE) names tests that exist, so `pytest -m smoke` cannot quietly shrink."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("smoke_conftest", ROOT / "tests" / "conftest.py")
_conftest = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_conftest)
SMOKE = _conftest.SMOKE


def test_every_smoke_test_exists():
    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-n", "0", "-m", "smoke",
                           "-p", "no:cacheprovider"], cwd=ROOT, capture_output=True, text=True)
    collected = {line.strip() for line in done.stdout.splitlines() if "::" in line}
    assert collected == set(SMOKE), sorted(set(SMOKE) ^ collected)
