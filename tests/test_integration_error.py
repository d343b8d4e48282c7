"""The integration error the cross-check states, against the error itself.

Both solvers end their steps at the mesh-stiffness jumps, so RK4 keeps its fourth order on a
rectangular stiffness (with a jump inside a step it fell to about first order: the default step's
error in the dynamic mesh force was 5.4 % on demo-3p).  The cross-check's bound, rms(x_h - x_2h)
over the RMS of the signal, must be at least the true error, measured against a run at h / 8.
"""

import numpy as np
import pytest

import gearcheck
from gearcheck.compare.engine.comparison import integration_error
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.time_solver import default_step
from gearcheck.train.variants import chained

DURATION = 0.03
KINDS = ("mesh_force", "bearing_force", "acceleration", "angular_acceleration")


def runs(spec, solver, factors):
    h = default_step(build_model(spec))
    return {f: gearcheck.simulate(spec, solver, duration=DURATION, dt=h * f) for f in factors}


def gated(result):
    """The compared signals that are not negligible (1e-6 of the largest of their kind)."""
    names = []
    for kind in KINDS:
        kind_names = result.names(kind=kind, compared=True)
        largest = max((np.sqrt(np.mean(result[n] ** 2)) for n in kind_names), default=0.0)
        names += [n for n in kind_names if np.sqrt(np.mean(result[n] ** 2)) > 1e-6 * largest]
    return names


@pytest.mark.parametrize("solver", ["lumped", "mujoco"])
@pytest.mark.parametrize("train", ["demo-3p", "two-stage chain"])
def test_the_bound_is_at_least_the_error(train, solver):
    spec = gearcheck.load("demo-3p") if train == "demo-3p" else chained(2)
    r = runs(spec, solver, (2.0, 1.0, 0.125))
    start = 0.5 * DURATION
    worst = 0.0
    for name in gated(r[1.0]):
        bound = integration_error(r[1.0], r[2.0], name, start, r[1.0])
        error = integration_error(r[1.0], r[0.125], name, start, r[1.0]) / 2.0  # vs h/8: 2 rms(x_h - x_h/8)
        assert error <= bound, (name, error, bound)
        worst = max(worst, error)
    assert worst > 0.0


def test_fourth_order_with_steps_ended_at_the_jumps():
    """Halving the step divides the lumped model's error in the dynamic mesh forces by about 16."""
    r = runs(gearcheck.load("demo-3p"), "lumped", (1.0, 0.5, 0.25, 0.125))
    start = 0.5 * DURATION
    names = r[1.0].names(kind="mesh_force")
    errors = [max(integration_error(r[f], r[0.125], n, start, r[f]) / 2.0 for n in names) for f in (1.0, 0.5)]
    assert errors[0] / errors[1] > 10.0
