"""What the cross-check asks of a model: a :class:`Side`.

Every side has modes and time runs, both as named results; a few capabilities are optional, each with its
default here, and a side overrides the ones it has.  The reference lumped model, the MuJoCo twin, the
published 4-DOF models of Matejic et al. (2021) and their twin, a user's model and another solver's recording
all derive from it; the cross-check engine knows nothing else about them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

from gearcheck.shared.errors import UnsupportedError
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.results import TimeResult
from gearcheck.shared.run_state import RunState
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.units import rad_s_to_rpm

DISPLAY = {"lumped": "lumped", "mujoco": "MuJoCo"}  # how reports write the built-in solvers' names


def display_name(solver: str) -> str:
    """How reports write a side's name: the built-in solvers as "lumped" and "MuJoCo", any other as it is."""
    return DISPLAY.get(solver, solver)


class Side(ABC):
    """A model of the train ``spec`` as the cross-check sees it."""

    solver: str  # how reports name it: "lumped", "mujoco", "as-published", ...
    kind: str = "model"  # what it is, as every report says: "reference lumped model", "MuJoCo twin", "user model", ...
    spec: object  # the TrainSpec it models
    references: tuple[str, ...] = ()  # keys of gearcheck.shared.citations.REFERENCES its equations come from
    rerunnable: bool = True  # run() integrates anew at the settings asked (False: a recording, as it is)
    has_modes: bool = True  # modes() gives natural frequencies (False: a recording without a modes file)
    driven: bool = True  # its runs have something that moves them (False: matrices with no mesh rows, no varying
    #                      stiffness and no varying force: its runs would sit still, and only its modes compare)
    linear = None  # its matrices (a LinearModel) when it is a model given as matrices
    notes: tuple[str, ...] = ()  # what was done to it (coordinates condensed, modes set aside), as reports say it
    order = 1  # the order its runs converge at; 1 (not known) makes the change on doubling the step a bound

    @abstractmethod
    def modes(self) -> ModalResult:
        """Natural frequencies, mode shapes and types of the linear(ised) model."""

    @abstractmethod
    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        """A time run; ``progress`` is called with the fraction done."""

    @abstractmethod
    def stable_step(self) -> float:
        """The largest fixed step its runs accept (s)."""

    def default_step(self) -> float | None:
        """The step its runs take when none is asked (s), which a cross-check starts from a multiple of.
        Default None: it picks its own, and the cross-check leaves it to it."""
        return None

    def modes_at_speed(self, input_speed: float) -> ModalResult:
        """The gyroscopic modes of the train turning at ``input_speed`` (rad/s).  Default: unsupported."""
        raise UnsupportedError(f"{self.solver} has no modes at speed (modes_at_speed)")

    def physical_modes(self, modal: ModalResult) -> tuple[list[str], object, object]:
        """(coordinate labels, mass matrix or None, the shapes of ``modal``) in the train's physical coordinates,
        by which modes are paired.  Default: unsupported."""
        raise UnsupportedError(f"{self.solver} gives no mode shapes in the train's coordinates (physical_modes)")

    def unmapped(self) -> list[str]:
        """The train's gated signals its runs do not report.  Default: none."""
        return []

    def omega_max(self) -> float:
        """Its highest natural angular frequency (rad/s), every mesh at its stiffest: what sets the round-off
        floor of a plan that reads its runs.  Default: unsupported."""
        raise UnsupportedError(f"{self.solver} does not state its highest natural frequency (omega_max)")

    def settling_time(self, fraction: float) -> float | None:
        """How long its free vibration takes to fall to ``fraction`` of its start (s).  Default None: not known
        (no run is extended to reach its steady state)."""
        return None

    def slowest_mode(self) -> tuple[float, float] | None:
        """(frequency in Hz, damping ratio) of its slowest-decaying mode, the one a run from rest waits for.
        Default None: not known."""
        return None

    def run_periodic(self, settings: RunSettings, check_step, progress=None) -> tuple[TimeResult, TimeResult, str]:
        """A run started on its own periodic steady state (its step made a whole fraction of the drive's period),
        the same run from the same state at the step ``check_step(h)`` (its integration check), and how the state
        was found, in words.  Default: unsupported."""
        raise UnsupportedError(f"{self.solver} cannot start on its periodic steady state (run_periodic)")

    def run_from(self, settings: RunSettings, state: RunState | None = None) -> tuple[TimeResult, RunState]:
        """A run from ``state`` at ``settings.start`` (None: from its own start at 0), and the state it ends in, for
        the next run to go on from (:mod:`gearcheck.shared.run_state`).  Default: unsupported."""
        raise UnsupportedError(f"{self.solver} cannot go on from another run's state (run_from)")

    def operating(self) -> dict:
        """The operating point a report of its runs states.  Default: the train's input speed and output torque (the
        reference of an operating history, and the history in words)."""
        history = self.spec.operating.history
        return {"input_speed_rpm": rad_s_to_rpm(self.spec.operating.input_speed),
                "output_torque_nm": self.spec.operating.output_torque} | \
            ({} if history is None else {"operating_history": history.words()})
