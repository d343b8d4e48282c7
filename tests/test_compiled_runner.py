"""The MuJoCo runner's compiled step loop (``engine="compiled"``, the default) against its Python loop.

The compiled loop does the Python loop's steps (the same model writes, the same MuJoCo calls, RK4's stages in the
same order) in C, so the two agree to round-off, far inside the integration error: the compiled loop within 1e-9
of the Python loop (the largest difference over every signal of a 4 ms run at the default step, over the peak of
the signals of its unit), 1e-8 on the RV reducer, whose pin contacts sum in another order.  Both loops are
MuJoCo's ``mj_RungeKutta`` with every stage driven at its own time; where nothing moves within a step, they are
``mj_RungeKutta`` itself.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import gearcheck
from gearcheck.train.variants import chained, edited
from gearcheck.mbd_models import compiled, runner
from gearcheck.mbd_models.runner import simulate_mujoco, simulate_mujoco_many
from gearcheck.mbd_models.static_state import static_state
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared import stepping
from gearcheck.shared.errors import SolverError
from gearcheck.shared.settings import RunSettings

DURATION = 0.004
ROUND_OFF = 1e-9
TRAINS = ["demo-3p", "hub-drive", "double-planet", "chained-2", "helical-15um", "rv-reducer"]


def train(name: str):
    if name == "chained-2":
        return chained(2)
    if name == "helical-15um":  # tip relief: the tooth pairs in contact at the tendons' own lengths
        return edited("helical-planetary", [(r"amount_um = 0.0", "amount_um = 15.0")], "15 um")
    return gearcheck.load(name)


@pytest.fixture(scope="module")
def twins():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = compile_train(train(name))
        return cache[name]

    return get


def difference(a, b) -> float:
    """Largest |a - b| over every signal, over the peak of all signals of its unit in ``a``."""
    assert [s.name for s in a.signals] == [s.name for s in b.signals]
    np.testing.assert_array_equal(a.t, b.t)
    units = np.array([s.unit for s in a.signals])
    peak = np.max(np.abs(a.values), axis=0)
    scale = np.array([max(peak[units == u].max(), 1e-300) for u in units])
    return float(np.max(np.abs(a.values - b.values) / scale))


@pytest.mark.parametrize("name", TRAINS)
def test_the_compiled_loop_repeats_the_python_loop(twins, name):
    """demo-3p: rectangular stiffness (split steps); hub-drive: transmission error, backlash, two stages;
    double-planet: torque ripple; chained: two carriers; helical, 15 um: tip relief; rv-reducer: pin contacts
    that follow the discs (MuJoCo's Jacobians every step), needle bearings.  Where both loops locate the same
    contact events they agree to round-off (measured at most 4e-10); locating an event is a decision, and one
    whose crossing falls within round-off of a threshold (a step's end, or the instant of another event) may go
    one way in one loop and the other in the other: then they agree within 5 % of the integration error (the
    difference between the runs at h and h/2; measured on the tip relief, 280 and 279 events: 2.6e-6 against
    8.6e-5)."""
    mb = twins(name)
    settings = RunSettings(DURATION)
    fast = simulate_mujoco(mb, settings, record_energy=True)
    slow = simulate_mujoco(mb, settings, record_energy=True, engine="python")
    assert fast.info.engine == "mujoco-compiled" and slow.info.engine == "mujoco-python"
    # 4 a sub-step: split steps count more, and a located contact event 8 (its step taken again in two parts)
    events = fast.info["contact_events_located"], slow.info["contact_events_located"]
    assert fast.info.rhs_calls - 8 * events[0] == slow.info.rhs_calls - 8 * events[1] >= 4 * fast.info.steps
    round_off = 10 * ROUND_OFF if mb.moving_contacts else ROUND_OFF
    if events[0] != events[1]:
        assert abs(events[0] - events[1]) <= 2
        finer = simulate_mujoco(mb, RunSettings(DURATION, dt=mb.default_step / 2, output_dt=mb.default_step))
        round_off = 0.05 * difference(finer, fast)
    assert difference(slow, fast) < round_off
    assert fast.raw.keys() == slow.raw.keys()
    for key in ("energy_kinetic", "energy_potential"):
        np.testing.assert_allclose(fast.raw[key], slow.raw[key], rtol=round_off, atol=round_off * np.ptp(slow.raw[key]))
    for key in slow.static:
        assert fast.static[key] == slow.static[key]


def test_sub_steps_end_each_split_step_at_its_jumps():
    """Steps 2 and 5 of a 0.5 s step from t = 10 s, split at their inner instants: the sub-steps of each split step in
    step order, from the step's start or a jump to the next jump or the step's end (the layout both solvers step)."""
    counts, starts, lengths = stepping.sub_steps(10.0, 0.5, {5: np.array([12.75]), 2: np.array([11.1, 11.3])})
    np.testing.assert_array_equal(counts, [3, 2])
    np.testing.assert_allclose(starts, [11.0, 11.1, 11.3, 12.5, 12.75], rtol=0, atol=1e-12)
    np.testing.assert_allclose(lengths, [0.1, 0.2, 0.2, 0.25, 0.25], rtol=0, atol=1e-12)
    assert stepping.sub_steps(0.0, 1.0, {})[1].size == 0


def test_sampling_every_few_steps_and_through_split_steps(twins):
    """Samples every third step (some of them split at a stiffness jump) and the run's model left as it was.  The
    steps between samples go without MuJoCo's sensors, which feed nothing back: against the same steps sampled at
    every one (and given the twin's static state), MuJoCo's sensors at every third step and the final state are the
    same to the bit, in both loops."""
    mb = twins("demo-3p")
    m = mb.model
    before = (m.tendon_stiffness.copy(), m.wrap_prm.copy(), m.opt.timestep, m.tendon_lengthspring.copy())
    settings = RunSettings(DURATION, output_dt=3 * mb.default_step)
    fast, slow = simulate_mujoco(mb, settings), simulate_mujoco(mb, settings, engine="python")
    assert fast.t.size == fast.info["steps"] // 3 + 1
    split = stepping.split_steps(mb.default_step, 0, fast.info["steps"],
                                        mb.excitation.switch_times(0.0, DURATION * 2))
    assert any(step % 3 == 0 for step in split)  # some sampled steps are split
    assert difference(slow, fast) < ROUND_OFF
    dt = mb.default_step
    steps = 3 * (fast.info["steps"] // 3)
    for engine in ("compiled", "python"):
        runs = [simulate_mujoco(mb, RunSettings(steps * dt, dt, output_dt=every * dt), engine=engine,
                                return_state=True, static=static_state(mb) if every == 1 else None)
                for every in (1, 3)]
        (dense, end), (thinned, thinned_end) = runs
        for x, y in zip(end, thinned_end):
            np.testing.assert_array_equal(x, y)
        for key, series in dense.raw.items():  # MuJoCo's sensors as sampled
            np.testing.assert_array_equal(series[::3], thinned.raw[key])
    np.testing.assert_array_equal(m.tendon_stiffness, before[0])
    np.testing.assert_array_equal(m.wrap_prm, before[1])
    assert m.opt.timestep == before[2]
    np.testing.assert_array_equal(m.tendon_lengthspring, before[3])


def test_progress_and_chunks(twins, monkeypatch):
    """Runs longer than a chunk go chunk by chunk (progress reported after each), as the Python loop does."""
    monkeypatch.setattr(runner, "CHUNK", 300)
    mb = twins("demo-3p")
    seen = []
    fast = simulate_mujoco(mb, RunSettings(DURATION), progress=seen.append)
    assert len(seen) == -(-fast.info["steps"] // 300) and seen[-1] == 1.0
    assert difference(simulate_mujoco(mb, RunSettings(DURATION), engine="python"), fast) < ROUND_OFF


def test_what_the_compiled_loop_does_not_run(twins):
    mb = twins("demo-3p")
    with pytest.raises(SolverError, match="'bodies' stiffness clock"):
        simulate_mujoco(mb, RunSettings(DURATION), stiffness_clock="bodies", engine="compiled")
    run = simulate_mujoco(mb, RunSettings(0.0005), stiffness_clock="bodies")
    assert run.info.engine == "mujoco-python"
    with pytest.raises(SolverError, match="engine must be one of"):
        simulate_mujoco(mb, RunSettings(DURATION), engine="rollout")
    assert runner.compiled_unsupported(mb) is None and compiled.unavailable() is None


@pytest.mark.parametrize("name", ["demo-3p", "rv-reducer"])
def test_with_nothing_moving_a_step_is_mujocos_own_rk4(twins, name):
    """The stage loop written out is ``mj_RungeKutta``: with the model fields held (no stage setting), a step from
    a moving state lands on MuJoCo's own step to the last bits."""
    mb = twins(name)
    m = mb.model
    d = mujoco.MjData(m)
    start = static_state(mb)
    d.qpos[:], d.qvel[:] = start.qpos, start.qvel
    d.qvel[:] += 1e-3 * np.sin(np.arange(m.nv))  # a vibration on top of the turning
    stepper = runner._Stepper(mb, d, mb.default_step, 1, False, False)
    drive = [None if x is None else x[0] for x in stepper.drive.steps(np.array([0.0]), mb.default_step)]
    stepper.set_stage(*(None if x is None else x[0] for x in drive))
    ours = mujoco.MjData(m)
    for field in ("qpos", "qvel", "act", "ctrl", "qfrc_applied"):
        getattr(ours, field)[:] = getattr(d, field)
    mujoco.mj_forward(m, d)
    m.opt.timestep = mb.default_step
    mujoco.mj_RungeKutta(m, d, 4)
    stepper.d, stepper.set_stage = ours, lambda *args: None
    stepper.rk4(mb.default_step, drive, False)
    np.testing.assert_allclose(ours.qpos, d.qpos, rtol=0, atol=1e-15 * np.max(np.abs(d.qpos)))
    np.testing.assert_allclose(ours.qvel, d.qvel, rtol=0, atol=1e-14 * np.max(np.abs(d.qvel)))
    np.testing.assert_array_equal(ours.act, d.act)


def test_many_twins_at_once(twins):
    """Variants in threads (the compiled loop releases the GIL): each result the single run's, bit for bit; a twin
    given twice runs on a copy."""
    assert compiled.run_steps.targetoptions["nogil"]
    one, two = twins("demo-3p"), twins("chained-2")
    settings = RunSettings(0.002)
    alone = [simulate_mujoco(mb, settings) for mb in (one, two)]
    together = simulate_mujoco_many([one, two, one], settings, threads=2)
    for result, reference in zip(together, alone + alone[:1]):
        np.testing.assert_array_equal(result.values, reference.values)
        assert result.info.engine == "mujoco-compiled"
    slower = simulate_mujoco_many([one], [RunSettings(0.002, dt=one.default_step / 2)])
    assert slower[0].info["dt_s"] == one.default_step / 2
    with pytest.raises(SolverError, match="2 settings for 1 twins"):
        simulate_mujoco_many([one], [settings, settings])
    rv = twins("rv-reducer")
    with pytest.raises(SolverError, match="given twice"):
        simulate_mujoco_many([rv, rv], settings)
