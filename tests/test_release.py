"""Release hygiene: the license the metadata states is the file shipped, the citation and the changelog name the
installed version, type checkers are told the package carries its own annotations, and ``dir(gearcheck)`` shows
the front door only."""

from __future__ import annotations

import importlib.metadata
import importlib.resources
import re
from pathlib import Path

import gearcheck

ROOT = Path(__file__).resolve().parent.parent


def test_the_license_is_mit_in_the_metadata_and_in_the_file():
    meta = importlib.metadata.metadata("gearcheck")
    assert meta["License-Expression"] == "MIT"
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License\n")


def test_the_citation_and_the_changelog_name_the_installed_version():
    version = gearcheck.__version__
    cff = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert re.search(r"^cff-version: 1\.2\.0$", cff, re.M) and re.search(rf"^version: {re.escape(version)}$", cff, re.M)
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert "## [Unreleased]" in changelog and f"## [{version}] - " in changelog


def test_the_package_tells_type_checkers_it_is_typed():
    assert importlib.resources.files("gearcheck").joinpath("py.typed").is_file()


def test_dir_shows_the_front_door_and_its_packages_only():
    names = dir(gearcheck)
    assert set(gearcheck.__all__) <= set(names) and {"lumped", "mbd_models", "compare", "train", "shared"} <= set(names)
    assert not {"os", "metadata", "util", "Path", "ensure_cache_folder"} & set(names)
