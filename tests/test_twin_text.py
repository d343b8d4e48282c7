"""The twin in one pass: its MJCF text is written once, with slots for the numbers known once compiled, and the file
it writes is the compiled twin."""

import mujoco
import numpy as np
import pytest

import gearcheck
from gearcheck.mbd_models import mjcf_text, twin
from gearcheck.mbd_models.mjcf_text import LATE, LateValues, Template, fixed
from gearcheck.train.loader import preset_names


def test_the_text_is_written_once_and_filled_twice(monkeypatch):
    documents, fills = [], []
    document, fill = twin.document, Template.fill
    monkeypatch.setattr(twin, "document", lambda *a: documents.append(1) or document(*a))
    monkeypatch.setattr(Template, "fill", lambda self, values: fills.append(1) or fill(self, values))
    mb = twin.compile_train(gearcheck.load("rv-reducer"))
    assert (len(documents), len(fills)) == (1, 2)
    assert mjcf_text.SLOT not in mb.xml and mjcf_text.KEY not in mb.xml


@pytest.mark.parametrize("name", preset_names())
def test_the_file_compiles_to_the_twin(name):
    """Every number of the model compiled from the written file is the twin's, but tendon_invweight0 (MuJoCo's, from
    the coefficients at compile time, for tendon constraints: the twin has none)."""
    mb = twin.compile_train(gearcheck.load(name))
    model, again = mb.model, mujoco.MjModel.from_xml_string(mb.xml)
    assert model.neq == 0 and not model.tendon_limited.any() and not model.tendon_frictionloss.any()
    arrays = [k for k in dir(model) if not k.startswith("_") and isinstance(getattr(model, k, None), np.ndarray)]
    differ = [k for k in arrays if not np.array_equal(getattr(model, k), getattr(again, k))]
    assert differ == ["tendon_invweight0"]
    assert model.opt.timestep == again.opt.timestep


@pytest.mark.parametrize("name", ["demo-3p", "rv-reducer"])
def test_the_twin_runs_without_mujocos_constraint_stage_to_the_same_bits(name):
    """The twin has no constraint (every force a joint's or a tendon's spring and damper, a control or an applied
    force), so its document disables the constraint stage: a step with the stage on gives the same state to the
    bit.  A constraint that a part brought would be refused, not ignored."""
    mb = twin.compile_train(gearcheck.load(name))
    model = mb.model
    assert model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    states = []
    for flags in (model.opt.disableflags, model.opt.disableflags & ~int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)):
        model.opt.disableflags = flags
        data = mujoco.MjData(model)
        data.qvel[:] = np.linspace(-1.0, 1.0, model.nv)  # moving, so that every force acts
        data.ctrl[:] = 1.0
        for _ in range(20):
            mujoco.mj_step(model, data)
        states.append(np.concatenate([data.qpos, data.qvel, data.qacc]))
    assert np.array_equal(states[0], states[1])
    limited = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint name="j" type="hinge" range="-1 1"/><geom size="0.1"/></body></worldbody>'
        '<equality><joint joint1="j"/></equality></mujoco>')
    with pytest.raises(RuntimeError, match="1 equality, 1 limited joint: its constraint stage is disabled"):
        twin.check_unconstrained(limited, "a train")


def test_late_numbers_are_slots_filled_by_name():
    text = Template("\n".join(fixed("m", [("a", LATE), ("b", LATE)], LATE, LATE, (-0.5, 0.5))
                              + fixed("p", [("a", 1.0)], 2.0, 0.0, LATE)))
    values = LateValues(1e-5, stiffness={"m": 3.0})
    assert text.fill(values) == ('    <fixed name="m" stiffness="3.0" springlength="-0.5 0.5">\n'
                                 '      <joint joint="a" coef="0"/>\n      <joint joint="b" coef="0"/>\n    </fixed>\n'
                                 '    <fixed name="p" stiffness="2.0" springlength="0 0">\n'
                                 '      <joint joint="a" coef="1.0"/>\n    </fixed>')
    values.coefficients["m"], values.damping["m"], values.band["p"] = [("a", 0.25), ("b", -1.5)], 7.0, (-1.0, 0.125)
    filled = text.fill(values)
    assert 'springlength="-0.5 0.5" damping="7.0">' in filled and 'coef="-1.5"' in filled
    assert 'springlength="-1.0 0.125"' in filled
    values.coefficients["m"] = [("a", 0.25)]  # given, a tendon's coefficients must cover every joint
    with pytest.raises(KeyError):
        text.fill(values)
