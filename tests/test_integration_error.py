"""The integration error the cross-check states, against the error itself.

Both solvers end their steps at the mesh-stiffness jumps and locate their contact events, so RK4 keeps its fourth
order, and the cross-check states Richardson's estimate, rms(x_h - x_2h) / 15 over the RMS of the signal.  Here it
is held against the error measured by a run at h / 16, at the cross-check's first step (twice the default), on a
rectangular stiffness (demo-3p), a two-stage chain, and the hub drive at 1823 rpm, where backlash opens and closes
in every mesh cycle.
"""

import numpy as np
import pytest

import gearcheck
from gearcheck.compare.engine.comparison import ASYMPTOTIC, FIRST_STEP_FACTOR, first_steps
from gearcheck.compare.studies.convergence import ROUND_OFF, estimate_tracking
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.settings import RunSettings
from gearcheck.train.variants import chained

DURATION = 0.03
KINDS = ("mesh_force", "bearing_force", "acceleration", "angular_acceleration")
TRACKS = (0.5, 1.5)  # estimate / error: Richardson's estimate is exact in the asymptotic range (1.0)


def gated(result):
    """The compared signals that are not negligible (1e-6 of the largest of their kind)."""
    names = []
    for kind in KINDS:
        kind_names = result.names(kind=kind, compared=True)
        largest = max((np.sqrt(np.mean(result[n] ** 2)) for n in kind_names), default=0.0)
        names += [n for n in kind_names if np.sqrt(np.mean(result[n] ** 2)) > 1e-6 * largest]
    return names


def train(name):
    return {"demo-3p": lambda: gearcheck.load("demo-3p"), "two-stage chain": lambda: chained(2),
            "hub-drive 1823 rpm": lambda: gearcheck.load("hub-drive", speed=1823.0)}[name]()


@pytest.mark.parametrize("solver", ["lumped", "mujoco"])
@pytest.mark.parametrize("name", ["demo-3p", "two-stage chain", "hub-drive 1823 rpm"])
def test_the_estimate_tracks_the_error(name, solver):
    spec = train(name)
    side = LumpedSide(spec) if solver == "lumped" else MujocoSide(spec)
    h = first_steps((side, side), (RunSettings(DURATION),) * 2)[0]
    assert h == pytest.approx(FIRST_STEP_FACTOR * side.default_step())
    names = gated(side.run(RunSettings(DURATION, dt=h)))
    table = estimate_tracking(side, h, DURATION, 0.5 * DURATION, names)
    tracked = {n: (estimate, error) for n, (estimate, error) in table.items() if error > ROUND_OFF}
    assert len(tracked) >= 0.5 * len(names)
    for n, (estimate, error) in tracked.items():
        assert TRACKS[0] <= estimate / error <= TRACKS[1], (n, estimate, error)


def test_fourth_order_with_steps_ended_at_the_jumps():
    """Halving the step divides the lumped model's error in the dynamic mesh forces by about 16."""
    side = LumpedSide(gearcheck.load("demo-3p"))
    h = side.default_step()
    names = side.run(RunSettings(DURATION, dt=h)).names(kind="mesh_force")
    errors = [max(e for _, e in estimate_tracking(side, f * h, DURATION, 0.5 * DURATION, names).values())
              for f in (1.0, 0.5)]
    assert errors[0] / errors[1] > 12.0


class Scrambled(LumpedSide):
    """The lumped model, whose integration checks (a run at twice the step of the run before it) come back with
    their mesh forces shifted by half a mesh cycle: runs that do not converge with the step, as those of a
    response sensitive to its start do not."""

    solver = "mujoco"  # stands in for the twin: both sides are the lumped model
    last_run = float("inf")  # the step of the run before

    def run(self, settings, progress=None):
        result = super().run(settings, progress)
        h = result.info["dt_s"]
        if h > 1.5 * self.last_run:
            shift = round(0.5 / (max(self.model.kin.mesh_frequency.values()) * h))
            for name in result.names(kind="mesh_force"):
                result[name][:] = np.roll(result[name], shift)
        self.last_run = h
        return result


def test_runs_that_do_not_converge_with_the_step_get_the_change_itself():
    """Where doubling the step moves the mesh forces by more than ``ASYMPTOTIC`` of them, Richardson's fourth-order
    rule (a fifteenth of the change) does not apply: the change itself is that side's estimate, the mesh forces
    are unresolved, and the report says why; the side that converges keeps Richardson's estimate."""
    spec = gearcheck.load("demo-3p")
    scrambled = Scrambled(spec)
    result = gearcheck.crosscheck(spec, duration=DURATION, sides=lambda s: LumpedSide(spec) if s == "lumped"
                                  else scrambled)
    force = result["stage1.planet1.sun.force"]
    assert force.status == "unresolved" and force.metrics["integration_error"]["test"] > force.tolerance
    assert force.metrics["integration_error"]["reference"] < 0.1 * force.tolerance
    (note,) = [note for note in result.notes if note.startswith("MuJoCo's runs at h and 2h differ by")]
    assert float(note.split(" differ by ")[1].split(" %")[0]) > 100 * ASYMPTOTIC
    assert not any(note.startswith("lumped's runs at h and 2h") for note in result.notes)
