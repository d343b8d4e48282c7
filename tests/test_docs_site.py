"""The documentation site builds from the repository with no warning (a broken link or reference, a malformed
docstring, a missing page is an error: ``-W``), and its front page renders in headless Chromium.

The test builds without executing the teaching notebooks (``GEARCHECK_DOCS_EXECUTE=off``, some 20 s);
``.ci/run`` builds the whole site, notebooks executed, before the tests (``tests/test_notebooks.py`` runs them
too)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from matplotlib.image import imread

ROOT = Path(__file__).resolve().parents[1]
pytest.importorskip("sphinx", reason="the documentation site needs the test extra (sphinx, myst-nb, numpydoc, furo)")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "GEARCHECK_DOCS_EXECUTE": "off"}
    done = subprocess.run([sys.executable, "-m", "sphinx", "-E", "-W", "--keep-going", "-q", "-b", "html",
                           str(ROOT / "docs"), str(out)], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-4000:]
    assert "WARNING" not in done.stderr, done.stderr[-4000:]
    return out


def test_the_site_has_every_part_the_users_need(site):
    pages = {p.relative_to(site).as_posix() for p in site.rglob("*.html")}
    for page in ("index.html", "getting-started.html", "model-file.html", "train-file.html", "api.html", "physics.html",
                 "rv-reducer/README.html", "helical-planetary/audit.html", "ci/README.html", "developer.html",
                 "teaching/notebooks/campbell.html", "teaching/notebooks/mesh_phasing.html"):
        assert page in pages, page
    model_file = (site / "model-file.html").read_text(encoding="utf-8")  # the layout, variable by variable
    assert all(name in model_file for name in ("mesh_error", "F_samples", "physical_labels", "-v7"))
    train_file = (site / "train-file.html").read_text(encoding="utf-8")
    assert "Your first train file" in train_file and "train.held" in train_file
    api = (site / "api.html").read_text(encoding="utf-8")
    assert "gearcheck.crosscheck" in api and "progress" in api
    teaching = (site / "teaching" / "README.html").read_text(encoding="utf-8")
    assert 'href="notebooks/campbell.html"' in teaching  # the repository's links lead to the executed pages


def test_the_front_page_renders_in_headless_chromium(site, browser, tmp_path):
    page = site / "index.html"
    dom = browser.browse(page, "--dump-dom")
    assert not browser.console(dom.stderr), browser.console(dom.stderr)
    assert "cross-verifies lumped-parameter dynamic models" in dom.stdout
    shot = tmp_path / "front.png"
    done = browser.browse(page, f"--screenshot={shot}")
    assert not browser.console(done.stderr), browser.console(done.stderr)
    pixels = imread(shot)[..., :3]
    assert pixels.shape[:2] == (900, 1200) and pixels.std() > 0.05
