"""Shared fixtures: presets and train variants built from TOML text."""

from __future__ import annotations

import re

import pytest

from lumped.loader import load_text, preset_names, preset_text


def preset_variant(name: str, **replacements: str):
    """A preset with literal text replacements applied (``old=new`` pairs as a dict)."""
    text = preset_text(name)
    for old, new in replacements.items():
        assert old in text, f"{old!r} not in preset {name}"
        text = text.replace(old, new)
    return load_text(text, f"variant-of-{name}")


def text_variant(name: str, pairs: list[tuple[str, str]]):
    text = preset_text(name)
    for old, new in pairs:
        if not re.search(old, text, flags=re.M):
            raise AssertionError(f"{old!r} not in preset {name}")
        text = re.sub(old, new, text, flags=re.M)
    return load_text(text, f"variant-of-{name}")


@pytest.fixture(params=preset_names())
def preset(request):
    return request.param
