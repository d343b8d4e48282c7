"""What ``model=`` means: the two sides a cross-check compares, resolved here for every caller (:func:`resolve_model`).

* ``"general"``: gearcheck's lumped model, the reference, against its MuJoCo twin (:class:`ModelPair`);
* a 4-DOF model of Matejic et al. (2021) (``"as-published"``, ...): that model against the twin of its own
  idealisation, a start-stop transient on one step grid (:class:`PublishedPair`);
* a user's model (:func:`gearcheck.compare.engine.user_model.user_side`), ``"user"`` (the one the train file
  registers) or another solver's results (``results=``, :class:`~gearcheck.compare.engine.recorded.RecordedSide`):
  the test, against the lumped model or the twin (``against=``; :class:`UserPair`, :class:`RecordedPair`).

A pair builds its plan from its reference side and states its runs' settings, default duration, compared
quantities and notes.  Errors name the parameters (``model=...``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gearcheck.compare.engine.diagnosis import diagnose_side
from gearcheck.compare.engine.plan import TrainPlan, TransientPlan
from gearcheck.compare.engine.recorded import RecordedSide
from gearcheck.compare.engine.user_model import user_side
from gearcheck.lumped.matrix_file import SUFFIXES
from gearcheck.lumped.published import FINDING
from gearcheck.lumped.side import LumpedSide, PublishedSide
from gearcheck.mbd_models.side import MujocoSide, PublishedTwinSide
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.results import train_signals
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.side import Side
from gearcheck.train.published_parameters import LABELS
from gearcheck.train.published_parameters import MODELS as PUBLISHED_MODELS

MODELS = ("general",) + PUBLISHED_MODELS
SOLVERS = {"lumped": LumpedSide, "mujoco": MujocoSide}  # the built-in sides, what a user's model is checked against
USER = "user"  # the model the train file registers (train.user_model)
GENERAL_DURATION = 0.1  # s, default simulated time of a train
PUBLISHED_DURATION = 0.02  # s, of the 4-DOF models' start-stop transient


@dataclass(frozen=True)
class ModelPair:
    """gearcheck's lumped model (the reference) against its MuJoCo twin."""

    reference: Side
    test: Side

    def duration(self, stored: dict | None) -> float:
        """The simulated time when none is asked: the stored baseline's, else the default."""
        return GENERAL_DURATION if stored is None else stored["duration_s"]

    def plan(self, spec, duration: float) -> TrainPlan:
        """How the comparison reads the runs, from the reference side."""
        return TrainPlan.of(spec, self.reference, duration)

    def settings(self, duration: float, plan, steps: dict) -> tuple[RunSettings, RunSettings]:
        """The two runs' settings; ``steps`` the fixed steps asked of the built-in solvers by name (None: their own)."""
        return RunSettings(duration, steps[self.reference.solver]), RunSettings(duration, steps[self.test.solver])

    def quantities(self, spec) -> list[str]:
        return [s.name for s in train_signals(spec) if s.compared]

    def notes(self) -> list[str]:
        missing = self.test.unmapped()
        return [f"{self.test.solver} does not report {len(missing)} of the train's gated quantities (not compared): "
                f"{', '.join(missing)}."] if missing else []

    def diagnose(self, spec, result) -> None:
        """Nothing to diagnose: the twin is derived from the train, not a model given to gearcheck."""


@dataclass(frozen=True)
class UserPair(ModelPair):
    """A user's model (the test, run at its own step) against the lumped model or the twin; its modes diagnosed
    against the lumped model of ``lumped`` (:func:`gearcheck.compare.engine.diagnosis.diagnose_side`), the
    reference itself where that is the lumped side, so that the model is built once."""

    lumped: LumpedSide

    def settings(self, duration: float, plan, steps: dict) -> tuple[RunSettings, RunSettings]:
        return RunSettings(duration, steps[self.reference.solver]), RunSettings(duration)

    def diagnose(self, spec, result) -> None:
        """Attach the diagnosis of the user's modes to ``result`` and its lines to the notes."""
        if result.modal_results[1] is not None:
            result.diagnosis = diagnose_side(self.lumped.model, self.test, result.modal_results[1])
            result.notes += [f"Diagnosis: {line}" for line in result.diagnosis.lines()]


class RecordedPair(UserPair):
    """Another solver's results against the lumped model or the twin: by default over the recorded span."""

    def duration(self, stored: dict | None) -> float:
        return self.test.duration


class PublishedPair(ModelPair):
    """A 4-DOF model of Matejic et al. (2021) against the twin of its idealisation: a start-stop transient from
    rest, both on the step of the plan."""

    def duration(self, stored: dict | None) -> float:
        return PUBLISHED_DURATION if stored is None else stored["duration_s"]

    def plan(self, spec, duration: float) -> TransientPlan:
        return TransientPlan.of(self.reference, self.test)

    def settings(self, duration: float, plan, steps: dict) -> tuple[RunSettings, RunSettings]:
        return (RunSettings(duration, plan.dt),) * 2

    def quantities(self, spec) -> list[str]:
        return [f"{label}.acceleration" for label in LABELS]

    def notes(self) -> list[str]:
        return [FINDING]


def resolve_model(spec, model="general", against: str = "lumped", results=None, columns=None,
                  modes=None, sides=None) -> ModelPair:
    """The sides that ``model`` names for the train ``spec`` (module docstring); ``against`` what a user's model
    is checked against, ``"lumped"`` or ``"mujoco"``; ``results``, ``columns``, ``modes``: another solver's
    results as the user's model (:class:`~gearcheck.compare.engine.recorded.RecordedSide`); ``sides``: the
    built-in sides already built (a callable ``"lumped"``/``"mujoco"`` -> side, a session's), else built here."""
    if against not in SOLVERS:
        raise GearcheckError(f"against={against!r}: choose {' or '.join(SOLVERS)}")
    built = sides or (lambda solver: SOLVERS[solver](spec))

    def with_lumped(test: Side) -> tuple[Side, Side, LumpedSide]:
        """(the reference, ``test``, the lumped side: the reference where it is the lumped side)."""
        reference = built(against)
        return reference, test, reference if against == "lumped" else built("lumped")

    named = model if isinstance(model, str) else None
    if results is not None:
        if named != "general":
            raise GearcheckError("results= gives the model checked: leave model= out")
        if columns is None:
            raise GearcheckError("results= needs columns=, the map of its columns to gearcheck's signals")
        return RecordedPair(*with_lumped(RecordedSide(spec, results, columns, modes)))
    if named == "general":
        return ModelPair(built("lumped"), built("mujoco"))
    if named in PUBLISHED_MODELS:
        return PublishedPair(PublishedSide(spec, named), PublishedTwinSide(spec, named))
    if named == USER:
        if spec.user_model is None:
            raise GearcheckError(f"model=user: {spec.name} registers no user_model (train.user_model in its file)")
        return UserPair(*with_lumped(user_side(spec.user_model, spec, from_file=True)))
    if named is not None and ":" not in named and Path(named).suffix not in SUFFIXES:
        if Path(named).suffix:
            raise GearcheckError(f"model={named}: a model file is {' or '.join(SUFFIXES)}, "
                                 f"not {Path(named).suffix!r}")
        raise GearcheckError(f"unknown model {named!r}: choose one of {', '.join(MODELS)}, or give your own: a model "
                             f"file ({' or '.join(SUFFIXES)}), module:factory or file.py:factory")
    return UserPair(*with_lumped(user_side(model, spec)))
