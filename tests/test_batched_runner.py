"""The batched MuJoCo runner (MJX, float64; here on JAX's CPU) against the CPU runner, world by world.

Each world takes the CPU runner's steps (RK4's stages driven at their own times, the sub-steps at stiffness jumps,
the backlash events located and the steps retaken in parts) with MJX's forward dynamics for MuJoCo's C library's,
which agree to round-off: every signal of each world within 1e-8 of the CPU runner's (over its peak), the same
contact events located (the same count of forward evaluations), and that difference under a hundredth of the
integration error (the change of the CPU run as its step halves).  hub-drive has backlash (events), a transmission
error and two turning carriers; demo-3p none of them.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import gearcheck
from gearcheck.mbd_models import batched
from gearcheck.mbd_models.batched import simulate_mujoco_batch
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_train

DURATION = 0.002
ROUND_OFF = 1e-8


def _worst(a, b) -> float:
    """The largest difference over every signal, over its peak (both runs' signals finite)."""
    for run in (a, b):
        bad = [n for n in run.names() if not np.all(np.isfinite(run[n]))]
        assert not bad, f"{run.info.engine}: not finite: {bad[:5]}"
    return max(float(np.max(np.abs(a[n] - b[n]))) / (float(np.max(np.abs(a[n]))) or 1.0) for n in a.names())


SPEEDS = {"hub-drive": (1010.0, 1388.0), "demo-3p": (900.0, 2500.0)}


@functools.cache
def runs(name: str):
    """Two worlds of ``name`` at two speeds: (twins, the CPU runner's results, the batched runner's)."""
    twins = [compile_train(load_train(name, s)) for s in SPEEDS[name]]
    settings = RunSettings(DURATION)
    return twins, [simulate_mujoco(mb, settings) for mb in twins], simulate_mujoco_batch(twins, settings)


@pytest.mark.parametrize("name", list(SPEEDS))
def test_each_world_is_the_cpu_runner_to_round_off(name):
    twins, cpu, batch = runs(name)
    for mb, a, b in zip(twins, cpu, batch):
        assert b.info.engine == "mujoco-batched"
        assert np.array_equal(a.t, b.t)
        assert b.info.settings["forward_evaluations"] == a.info.settings["forward_evaluations"]
        worst = _worst(a, b)
        assert worst < ROUND_OFF, (mb.spec.operating.input_speed, worst)
        halved = simulate_mujoco(mb, RunSettings(DURATION, dt=a.info.settings["dt_s"] / 2,
                                                 output_dt=a.info.settings["dt_s"]))
        assert worst < 1e-2 * _worst(a, halved)


def test_hub_drive_locates_backlash_events_in_every_world():
    _, cpu, batch = runs("hub-drive")
    for a, b in zip(cpu, batch):
        assert b.info.settings["contact_events_located"] == a.info.settings["contact_events_located"] > 0


def test_worlds_of_other_trains_or_unbatched_contacts_are_refused():
    hub, demo = (compile_train(load_train(n)) for n in ("hub-drive", "demo-3p"))
    with pytest.raises(SolverError, match="is not the first world's model"):
        simulate_mujoco_batch([hub, demo], RunSettings(DURATION))
    with pytest.raises(SolverError, match="pins"):
        simulate_mujoco_batch([compile_train(gearcheck.load("rv-reducer"))], RunSettings(DURATION))
    with pytest.raises(SolverError, match="2 settings for 1 worlds"):
        simulate_mujoco_batch([hub], [RunSettings(DURATION)] * 2)


def test_the_front_door_runs_each_speed_as_simulate_runs_it():
    batch = gearcheck.simulate_batch("demo-3p", [900.0, 2500.0], DURATION)
    for speed, b in zip((900.0, 2500.0), batch):
        assert _worst(gearcheck.simulate("demo-3p", "mujoco", DURATION, speed=speed), b) < ROUND_OFF
    for bad in ("1000", [], [1000, "fast"], [True]):
        with pytest.raises(gearcheck.GearcheckError, match="speeds must be"):
            gearcheck.simulate_batch("demo-3p", bad, DURATION)


def test_a_run_over_several_chunks_carries_its_state_across_them(monkeypatch):
    """Chunks of 256 steps: hub-drive's 4.6 ms (about 710 steps) runs as three, the last ending with the final
    sample (each within one bucket of slots, the shape the 2 ms runs compiled)."""
    monkeypatch.setattr(batched, "CHUNK", batched.BUCKET // 2)
    twins = [compile_train(load_train("hub-drive", s)) for s in SPEEDS["hub-drive"]]
    settings = RunSettings(0.0046)
    for mb, b in zip(twins, simulate_mujoco_batch(twins, settings)):
        a = simulate_mujoco(mb, settings)
        assert a.info.steps > 512 + 128
        assert b.info.settings["forward_evaluations"] == a.info.settings["forward_evaluations"]
        assert _worst(a, b) < ROUND_OFF
