"""Shared fixtures: every preset as a parameter."""

from __future__ import annotations

import pytest

from gearcheck.lumped.loader import preset_names


@pytest.fixture(params=preset_names())
def preset(request):
    return request.param
