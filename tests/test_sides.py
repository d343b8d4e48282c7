"""The sides of a cross-check: optional capabilities with their defaults, ``model=`` resolved in one place, the
plan read from the reference side, errors naming the Python parameter and the command line's flag."""

from types import SimpleNamespace

import pytest

import gearcheck
from gearcheck.cli import COMMANDS, FLAGS, as_flags, main
from gearcheck.compare.engine.align import STEADY_THRESHOLD
from gearcheck.compare.engine.model_pair import ModelPair, PublishedPair, UserPair, resolve_model
from gearcheck.compare.engine.plan import TrainPlan, TransientPlan, round_off_floor
from gearcheck.compare.engine.user_model import AdoptedSide, user_side
from gearcheck.compare.studies.sensitivity import sensitivity_map
from gearcheck.lumped.export import reference_linear_model
from gearcheck.lumped.side import LinearSide, LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.errors import UnsupportedError
from gearcheck.shared.side import Side
from gearcheck.train.kinematics import kinematics
from gearcheck.train.loader import read_train_text

SPEC = gearcheck.load("demo-3p")


class Bare(Side):
    """A side with nothing but what every side has."""

    solver = "bare"

    def __init__(self, spec):
        self.spec = spec

    def modes(self):
        return LumpedSide(self.spec).modes()

    def run(self, settings, progress=None):
        raise AssertionError("not run here")

    def stable_step(self):
        return 1e-5


def test_a_side_without_an_optional_capability_gets_its_default():
    side = Bare(SPEC)
    with pytest.raises(UnsupportedError, match=r"^bare has no modes at speed \(modes_at_speed\)$"):
        side.modes_at_speed(100.0)
    with pytest.raises(UnsupportedError, match=r"^bare gives no mode shapes .*\(physical_modes\)$"):
        side.physical_modes(side.modes())
    with pytest.raises(UnsupportedError, match=r"\(omega_max\)$"):
        TrainPlan.of(SPEC, side, 0.05)  # it cannot be the reference of a train's plan
    assert side.unmapped() == [] and side.settling_time(0.01) is None and side.linear is None
    assert side.rerunnable and side.has_modes and side.references == ()
    assert side.operating() == {"input_speed_rpm": pytest.approx(1500.0),
                                "output_torque_nm": SPEC.operating.output_torque}


def test_a_side_without_mode_shapes_is_refused_by_name_where_shapes_are_needed():
    """The published 4-DOF twin has no mode shapes in the train's coordinates: pairing its modes says so."""
    with pytest.raises(UnsupportedError, match=r"mujoco gives no mode shapes .*\(physical_modes\)"):
        gearcheck.mode_pairing("double-planet", model="energy-derived")


def test_a_foreign_side_object_is_adopted_with_the_capabilities_it_has():
    lumped = LumpedSide(SPEC)
    foreign = SimpleNamespace(solver="mine", modes=lumped.modes, run=lumped.run, stable_step=lumped.stable_step,
                              physical_modes=lumped.physical_modes, rerunnable=False)
    side = user_side(foreign, SPEC)
    assert isinstance(side, AdoptedSide) and side.solver == "mine" and side.references == ()
    assert side.physical_modes(side.modes())[0] == lumped.model.dofs.labels()  # its own
    assert side.rerunnable is False  # its own
    with pytest.raises(UnsupportedError, match="mine has no modes at speed"):  # the default
        side.modes_at_speed(0.0)
    assert user_side(lumped, SPEC) is lumped  # a Side is taken as it is


def test_model_names_its_pair():
    model = reference_linear_model(SPEC)
    general = resolve_model(SPEC)
    assert type(general) is ModelPair
    assert (type(general.reference), type(general.test)) == (LumpedSide, MujocoSide)
    user = resolve_model(SPEC, model, against="mujoco")
    assert isinstance(user, UserPair) and isinstance(user.reference, MujocoSide) and isinstance(user.test, LinearSide)
    double = gearcheck.load("double-planet")
    published = resolve_model(double, "consistent")
    assert isinstance(published, PublishedPair)
    plan = published.plan(double, 0.02)
    assert isinstance(plan, TransientPlan) and plan.operating["model"] == "consistent"
    assert published.settings(0.02, plan, {})[0].dt == plan.dt


def test_the_plan_comes_from_the_reference_side_when_mujoco_is_the_reference():
    """A user's model against the twin: the round-off floor from the twin's highest frequency and the steady
    state from the decay of the twin's free vibration, not the lumped model's."""
    pair = resolve_model(SPEC, reference_linear_model(SPEC), against="mujoco")
    plan = pair.plan(SPEC, 0.05)
    twin, lumped = MujocoSide(SPEC), LumpedSide(SPEC)
    assert plan.settle == twin.settling_time(STEADY_THRESHOLD) != lumped.settling_time(STEADY_THRESHOLD)
    assert plan.floors == round_off_floor(SPEC, kinematics(SPEC), twin.omega_max(), 0.05)
    assert plan.floors != TrainPlan.of(SPEC, lumped, 0.05).floors
    # the two decays describe one train: they agree to well within a mesh cycle
    assert abs(plan.settle - lumped.settling_time(STEADY_THRESHOLD)) < 0.1 * plan.cycle


@pytest.mark.parametrize("call, message", [
    (lambda: gearcheck.crosscheck("demo-3p", model="model.txt"), "model=model.txt: a model file is .mat or .npz"),
    (lambda: gearcheck.crosscheck("demo-3p", model="as-published", results="x.csv"),
     "results= gives the model checked: leave model= out"),
    (lambda: gearcheck.crosscheck("demo-3p", results="x.csv"), "results= needs columns="),
    (lambda: gearcheck.crosscheck("demo-3p", against="abaqus"), "against='abaqus': choose lumped or mujoco"),
    (lambda: gearcheck.crosscheck("demo-3p", model="user"), "model=user: demo-3p registers no user_model"),
    (lambda: gearcheck.crosscheck("demo-3p", model="no_such_module_xyz:f"),
     "model=no_such_module_xyz:f: importing no_such_module_xyz failed"),
    (lambda: gearcheck.sweep("demo-3p", solver="euler"), "solver=euler: choose lumped, mujoco or both"),
    (lambda: gearcheck.sweep("demo-3p", harmonics=0), "harmonics=0: needs an integer from 1 to 20"),
    (lambda: gearcheck.sensitivity("demo-3p", "stages[0].sun.mass", method="euler"), "method='euler': one of"),
])
def test_library_errors_name_the_python_parameter(call, message):
    with pytest.raises(gearcheck.GearcheckError) as caught:
        call()
    assert str(caught.value).startswith(message) and "--" not in str(caught.value)


def test_the_command_line_names_its_flags(tmp_path, capsys):
    assert as_flags("model=a.npz: x; leave model= out (duration=)") == \
        "--model a.npz: x; leave --model out (--duration)"
    assert as_flags("duration=-1: must be > 0") == "--duration -1: must be > 0"
    assert as_flags("input_speed=3") == "input_speed=3"  # only whole parameter names
    renamed = {"fields": "--set", "distributions": "--vary", "parameters": "--parameter", "quantities": "--quantity"}
    assert all(flag == renamed.get(name, "--" + name.replace("_", "-")) for name, flag in FLAGS.items())
    assert set(FLAGS.values()) <= {flag for command in COMMANDS.values() for flags, _ in command.arguments
                                   for flag in flags}
    # a key of a train-file path is no parameter, whatever its name
    assert as_flags("fields=stages[0].mesh.stiffness.model=x: y") == "--set stages[0].mesh.stiffness.model=x: y"
    assert as_flags("samples=: Monte Carlo needs distributions=, the law") == \
        "--samples: Monte Carlo needs --vary, the law"
    assert as_flags("workers= counts local processes: a Dask cluster (scheduler=) has its own workers") == \
        "--workers counts local processes: a Dask cluster (--scheduler) has its own workers"
    assert main(["crosscheck", "demo-3p", "--results", str(tmp_path / "x.csv"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err == "gearcheck: error: --results needs --columns, the map of its columns to gearcheck's signals\n"


SWEEP = ["sweep", "demo-3p", "--solver", "lumped", "--duration", "0.03"]
STUDIES = [  # a library call of a study, the same request on the command line, what each says first
    (lambda tmp: gearcheck.sweep("demo-3p", fields={"stages[9].sun.mass": [1.0, 2.0]}),
     SWEEP + ["--set", "stages[9].sun.mass=1,2"],
     "fields=stages[9].sun.mass: no such field", "--set stages[9].sun.mass: no such field"),
    (lambda tmp: gearcheck.sweep("demo-3p", fields={"stages[0].sun.mas": [1.0]}),
     SWEEP + ["--set", "stages[0].sun.mas=1"],
     "fields=stages[0].sun.mas=1.0: preset:demo-3p: stages[0].sun.mas: unknown key",
     "--set stages[0].sun.mas=1.0: preset:demo-3p: stages[0].sun.mas: unknown key"),
    (lambda tmp: gearcheck.Train("demo-3p").sweep(distributions={"stages[0].sun.mass": "normal(1,0)"}),
     SWEEP + ["--vary", "stages[0].sun.mass=normal(1,0)"],
     "distributions=stages[0].sun.mass 'normal(1,0)': needs sd > 0",
     "--vary stages[0].sun.mass 'normal(1,0)': needs sd > 0"),
    (lambda tmp: gearcheck.sweep("demo-3p", fields={"stages[0].sun.mass": [1.0]},
                                 distributions={"stages[0].sun.inertia": "normal(1,0.1)"}),
     SWEEP + ["--set", "stages[0].sun.mass=1", "--vary", "stages[0].sun.inertia=normal(1,0.1)"],
     "fields= (a grid) and distributions= (Monte Carlo): give one or the other",
     "--set (a grid) and --vary (Monte Carlo): give one or the other"),
    (lambda tmp: gearcheck.sweep("demo-3p", samples=5), SWEEP + ["--samples", "5"],
     "samples=: Monte Carlo needs distributions=", "--samples: Monte Carlo needs --vary"),
    (lambda tmp: gearcheck.sweep("demo-3p", speeds=[1000], fields={"operating.input_speed_rpm": [1000]}),
     SWEEP + ["--speeds", "1000", "--set", "operating.input_speed_rpm=1000"],
     "operating.input_speed_rpm is swept by speeds=: give it there only",
     "operating.input_speed_rpm is swept by --speeds: give it there only"),
    (lambda tmp: gearcheck.sweep("demo-3p", speeds=[900000.0]), SWEEP + ["--speeds", "900000"],
     "speeds=900000: speed 900000 rpm for demo-3p", "--speeds 900000: speed 900000 rpm for demo-3p"),
    (lambda tmp: gearcheck.sweep("demo-3p", solver="lumped", cache=tmp / "file"),
     SWEEP + ["--cache", "TMP/file"], "cache=TMP/file: exists and is not a folder",
     "--cache TMP/file: exists and is not a folder"),
    (lambda tmp: gearcheck.calibrate("hub-drive", ["stages[0].nothing"]),
     ["calibrate", "hub-drive", "--fit", "stages[0].nothing"],
     "fit=stages[0].nothing: no such field", "--fit stages[0].nothing: no such field"),
    (lambda tmp: gearcheck.calibrate("hub-drive", ["x..y"]), ["calibrate", "hub-drive", "--fit", "x..y"],
     "fit='x..y': '' is not a key or key[index]", "--fit 'x..y': '' is not a key or key[index]"),
    (lambda tmp: gearcheck.sensitivity("rv-reducer", "stages[0].crank.nothing"),
     ["sensitivity", "rv-reducer", "--parameter", "stages[0].crank.nothing"],
     "parameter=stages[0].crank.nothing: no such field", "--parameter stages[0].crank.nothing: no such field"),
    (lambda tmp: sensitivity_map(*read_train_text("rv-reducer"), ["stages[0].crank.nothing"], [100.0, 1000.0],
                                 "rv.carrier.theta"),
     ["sensitivity", "rv-reducer", "--parameter", "stages[0].crank.nothing", "--speeds", "100:1000:2"],
     "parameters=stages[0].crank.nothing: no such field", "--parameter stages[0].crank.nothing: no such field"),
    (lambda tmp: gearcheck.sensitivity("demo-3p", "stages[0].sun.mass", orders=(3, 2)),
     ["sensitivity", "demo-3p", "--parameter", "stages[0].sun.mass", "--orders", "3", "2"],
     "orders=(3, 2): give 1 whole non-negative number", "--orders (3, 2): give 1 whole non-negative number"),
]


@pytest.mark.parametrize("call, argv, library, command_line", STUDIES,
                         ids=[f"{s[1][0]} {s[3].split(':')[0]}" for s in STUDIES])
def test_a_study_names_the_python_argument_and_its_command_the_flag(tmp_path, capsys, call, argv, library,
                                                                    command_line):
    (tmp_path / "file").write_text("not a folder")
    with pytest.raises(gearcheck.GearcheckError) as caught:
        call(tmp_path)
    message = str(caught.value).replace(str(tmp_path), "TMP")
    assert message.startswith(library) and "--" not in message, message
    out = tmp_path / "out"
    argv = [a.replace("TMP", str(tmp_path)) for a in argv] + ["--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.replace(str(tmp_path), "TMP")
    assert err.startswith("gearcheck: error: " + command_line) and err.count("\n") == 1, err
    assert [p.name for p in tmp_path.iterdir()] == ["file"]  # nothing written: no output, no cache
