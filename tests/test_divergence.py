"""The divergence rule both solvers share: the first sample not finite or past FACTOR times the static scale."""

import numpy as np
import pytest

from gearcheck.shared import divergence
from gearcheck.shared.errors import DivergenceError


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, -1.001e3, 1.001e3])
def test_the_first_sample_not_finite_or_past_the_factor_is_named(bad):
    t = np.array([0.0, 1.0, 2.0, 3.0])
    deflection = np.array([[0.5, -1.0], [999.0, -1000.0], [1.0, bad], [np.nan, 1e9]])
    with pytest.raises(DivergenceError) as caught:
        divergence.check(t, deflection, 1.0, "model")
    assert caught.value.time == 2.0


def test_deflections_within_the_factor_pass_and_no_mesh_is_no_divergence():
    divergence.check(np.array([0.0, 1.0]), np.array([[1000.0, -1000.0], [0.0, 0.0]]), 1.0, "model")
    divergence.check(np.array([0.0]), np.empty((1, 0)), 1.0, "model")
