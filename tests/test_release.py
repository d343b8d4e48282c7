"""Release hygiene: the license the metadata states is the file shipped, the citation and the changelog name the
installed version, type checkers are told the package carries its own annotations, and ``dir(gearcheck)`` shows
the front door only, each of its names imported on first use."""

from __future__ import annotations

import importlib.metadata
import importlib.resources
import re
from pathlib import Path

import pytest

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


def test_every_public_name_resolves_on_first_use_and_no_other():
    """The front door imports its names when first asked for (PEP 562): each of ``__all__`` and each package
    beneath resolves, the lazy table lists ``__all__`` exactly, and an unknown name is an AttributeError."""
    lazy = {name for names in gearcheck._DEFINED_IN.values() for name in names}
    assert lazy | {"__version__"} == set(gearcheck.__all__) and len(lazy) == len(gearcheck.__all__) - 1
    for name in [*gearcheck.__all__, *gearcheck._PACKAGES]:
        assert getattr(gearcheck, name) is not None, name
    assert gearcheck.crosscheck is gearcheck.api.crosscheck and gearcheck.Train is gearcheck.session.Train
    with pytest.raises(AttributeError, match="no attribute 'nothing_here'"):
        gearcheck.nothing_here
