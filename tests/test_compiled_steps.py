"""The compiled RK4 steps against the same RK4 stage by stage in Python, and no Python per step."""

from types import SimpleNamespace

import numpy as np
import pytest

from gearcheck.lumped import time_solver
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.compiled_steps import kernel_groups
from gearcheck.lumped.elements.base import Turning
from gearcheck.train.loader import load_train
from gearcheck.train.variants import chained, edited
from gearcheck.shared.settings import RunSettings

LIGHT_BACKLASH = [(r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 40.0\n"
                   "ste = [{ harmonic = 1, amplitude_um = 5.0 }]"), (r"^output_torque = .*", "output_torque = 30.0")]

CASES = {
    **{name: (lambda name=name: load_train(name)) for name in
       ("demo-3p", "demo-4p", "double-planet", "helical-planetary", "hub-drive", "rv-reducer")},
    "backlash, light load": lambda: edited("demo-3p", LIGHT_BACKLASH, "light backlash"),
    "tip relief": lambda: edited("helical-planetary", [(r"amount_um = 0.0", "amount_um = 15.0")], "relief"),
    "radial splines": lambda: chained(3, 1e8),
}


def coordinates(run, model):
    labels = model.dofs.labels()
    return np.array([run.raw[label] for label in labels]).T, np.array([run.raw[label + "_dot"] for label in labels]).T


@pytest.mark.parametrize("case", list(CASES))
def test_compiled_steps_equal_stage_by_stage_rk4(case):
    """The compiled steps are the stage-by-stage RK4 (same drive sampling, splits at stiffness jumps, dead zone, tooth
    pairs, turning couplings, cycloid needles and pin contacts, the same contact events located) to round-off: the
    largest state difference over a run, relative to the largest state, is below 1e-11 (measured at most 5e-15) and
    the mesh forces agree to 1e-10 of their peak (measured at most 2e-13)."""
    model = build_model(CASES[case]())
    settings = RunSettings(0.002)
    compiled = time_solver.simulate(model, settings)
    reference = time_solver.simulate(model, settings, method="rk4-stages")
    assert compiled.info["steps"] == reference.info["steps"] > 100
    assert compiled.info["contact_events_located"] == reference.info["contact_events_located"]
    assert compiled.info.rhs_calls == reference.info.rhs_calls
    np.testing.assert_array_equal(compiled.t, reference.t)
    for a, b in zip(coordinates(compiled, model), coordinates(reference, model)):
        assert np.max(np.abs(a - b)) <= 1e-11 * np.max(np.abs(b))
    fa, fb = compiled.select("mesh_force"), reference.select("mesh_force")
    np.testing.assert_allclose(fa, fb, rtol=0, atol=1e-10 * np.abs(fb).max())
    if case == "backlash, light load":  # the teeth did leave their drive flanks, and each time the step ended there
        e, _ = model.excitation.transmission_error(reference.t)
        assert np.any(reference.select("dte") - e < 20e-6)
        assert reference.info["contact_events_located"] > 0


@pytest.mark.parametrize("case", ["rv-reducer", "backlash, light load", "tip relief", "radial splines"])
def test_no_python_per_step(case, monkeypatch):
    """The compiled path calls the Python right-hand side once (for the outputs, vectorised over the samples) and
    samples the drive once per chunk, whatever the train."""
    model = build_model(CASES[case]())
    calls = {"acceleration": 0, "chunk": 0}
    acceleration, chunk = time_solver._System.acceleration, time_solver._chunk

    def counted_acceleration(*args, **kwargs):
        calls["acceleration"] += 1
        return acceleration(*args, **kwargs)

    def counted_chunk(*args, **kwargs):
        calls["chunk"] += 1
        return chunk(*args, **kwargs)

    monkeypatch.setattr(time_solver._System, "acceleration", counted_acceleration)
    monkeypatch.setattr(time_solver, "_chunk", counted_chunk)
    run = time_solver.simulate(model, RunSettings(0.003))
    per_chunk = time_solver._chunk_steps(time_solver._System(model))
    assert calls == {"acceleration": 1, "chunk": -(-run.info["steps"] // per_chunk)}


def test_chunks_hold_a_bounded_drive():
    """A relieved helical mesh has 80 tooth-pair slices: its chunks are shorter, within CHUNK_BYTES."""
    relief = time_solver._System(build_model(CASES["tip relief"]()))
    plain = time_solver._System(build_model(load_train("demo-3p")))
    assert time_solver._chunk_steps(plain) == time_solver.CHUNK
    steps = time_solver._chunk_steps(relief)
    assert steps < time_solver.CHUNK
    chunk = time_solver._chunk(relief, 1e-6, 0, steps)
    assert sum(x.nbytes for x in (chunk.k, chunk.e, chunk.de, chunk.tin, chunk.tout, chunk.pairs)) <= \
        time_solver.CHUNK_BYTES


def test_turning_elements_of_unknown_kind_are_refused():
    class Uncompiled(Turning):  # a turning element that names no compiled group
        rows = ()

    with pytest.raises(TypeError, match="no compiled form of the turning element Uncompiled"):
        kernel_groups(SimpleNamespace(turning=[Uncompiled()]))
