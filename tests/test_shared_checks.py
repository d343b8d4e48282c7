"""The shared floor's message helpers: the did-you-mean hint and the speed check every entry point uses."""

import math

import numpy as np
import pytest

from gearcheck.shared.errors import GearcheckError, did_you_mean
from gearcheck.shared.units import MAX_RPM, checked_rpm

MEMBERS = ["stage1.sun", "stage1.ring", "stage1.carrier"]


@pytest.mark.parametrize("args, kwargs, hint", [
    (("stage1.sum", MEMBERS), {}, " (did you mean 'stage1.sun'?)"),
    (("xyz", MEMBERS), {}, ""),
    (("xyz", MEMBERS, "members"), {}, " (members: stage1.sun, stage1.ring, stage1.carrier)"),
    (("stage1.sum", MEMBERS, "members"), {}, " (did you mean 'stage1.sun'?)"),
    (("xyz", MEMBERS), {"n": 2, "cutoff": 0}, " (did you mean 'stage1.sun', 'stage1.ring'?)"),
    (("rectangle", {"constant": 1, "rectangular": 2}), {}, " (did you mean 'rectangular'?)"),  # a mapping's keys
])
def test_did_you_mean(args, kwargs, hint):
    assert did_you_mean(*args, **kwargs) == hint


@pytest.mark.parametrize("value, zero", [(1500, False), (0.5, False), (np.float64(60.0), False), (MAX_RPM, False),
                                         (0, True), (0.0, True), (2.5, True)])
def test_checked_rpm_takes_a_speed(value, zero):
    assert checked_rpm(value, zero=zero) == float(value)
    assert type(checked_rpm(value, zero=zero)) is float


@pytest.mark.parametrize("value, zero, message", [
    (0, False, "speed must be a positive number of rpm, got 0"),
    (-5, False, "speed must be a positive number of rpm, got -5"),
    (math.inf, False, "speed must be a positive number of rpm, got inf"),
    (math.nan, False, "speed must be a positive number of rpm, got nan"),
    ("1500", False, "speed must be a positive number of rpm, got '1500'"),
    (True, False, "speed must be a positive number of rpm, got True"),
    (None, True, "speed must be a number of rpm >= 0, got None"),
    (-1.0, True, "speed must be a number of rpm >= 0, got -1"),
    (2e6, False, "speed must be <= 1e+06 rpm, got 2e+06"),
    (2e6, True, "speed must be <= 1e+06 rpm, got 2e+06"),
])
def test_checked_rpm_refuses(value, zero, message):
    with pytest.raises(GearcheckError) as info:
        checked_rpm(value, zero=zero)
    assert str(info.value) == message


def test_checked_rpm_names_what():
    with pytest.raises(GearcheckError, match=r"^--speeds: every speed must be a positive number of rpm, got 0$"):
        checked_rpm(0.0, "--speeds: every speed")
