"""The MuJoCo models as the cross-check sees them (:class:`gearcheck.shared.side.Side`).

* :class:`MujocoSide` -- the twin of a train: bodies on joints, meshes as driven tendons;
* :class:`PublishedTwinSide` -- the twin of the 4-DOF idealisation of Matejic et al. (2021), built
  with the kinematics the chosen 4-DOF model claims.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cached_property

import numpy as np

from gearcheck.train.published_parameters import KINEMATICS, PaperParameters, check_model
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.published_twin import PublishedTwin, build_twin, simulate_twin, twin_modes
from gearcheck.mbd_models.periodic_state import periodic_state
from gearcheck.mbd_models.runner import simulate_mujoco
from gearcheck.mbd_models.static_state import StaticState, static_state
from gearcheck.mbd_models.twin import MbdModel, compile_train
from gearcheck.shared import stepping
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.results import TimeResult
from gearcheck.shared.run_state import RunState
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.side import Side


class MujocoSide(Side):
    """The MuJoCo twin of a train (``stiffness_clock``: see
    :func:`gearcheck.mbd_models.runner.simulate_mujoco`)."""

    solver = "mujoco"
    kind = "MuJoCo twin"
    order = stepping.ORDER  # RK4, the drive set at every stage, contact events located
    references = ("todorov-2012",)

    def __init__(self, spec, stiffness_clock: str = "nominal"):
        self.spec = spec
        self.stiffness_clock = stiffness_clock

    @cached_property
    def model(self) -> MbdModel:
        return compile_train(self.spec)

    @cached_property
    def static(self) -> StaticState:
        """The twin's static state, found once for all its runs."""
        return static_state(self.model)

    def modes(self) -> ModalResult:
        return linearise.modes(self.model)

    def modes_at_speed(self, input_speed: float) -> ModalResult:
        turning = self.spec.operating.input_speed or not input_speed  # a twin at rest: one turning at that speed
        model = self.model if turning else compile_train(self.spec.with_operating(input_speed=input_speed))
        return linearise.modes_at_speed(model, input_speed)

    def physical_modes(self, modal: ModalResult) -> tuple[list[str], np.ndarray, np.ndarray]:
        """(coordinate labels, mass matrix, the shapes of ``modal``) in the train's physical coordinates, mapped
        from MuJoCo's joints by its own Jacobians (:func:`gearcheck.mbd_models.linearise.physical_coordinates`)."""
        labels, T = linearise.physical_coordinates(self.model)
        T_inv = np.linalg.inv(T)
        return labels, T_inv.T @ linearise.mass_matrix(self.model) @ T_inv, T @ modal.shapes

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        return simulate_mujoco(self.model, settings, progress=progress, stiffness_clock=self.stiffness_clock,
                               static=self.static)

    def run_from(self, settings: RunSettings, state: RunState | None = None) -> tuple[TimeResult, RunState]:
        """From the joints' positions, the input servo's reference angle and the joints' velocities of ``state``."""
        initial = None if state is None else (state.coordinates[0], state.rates[0], state.coordinates[1])
        result, (qpos, qvel, act) = simulate_mujoco(self.model, settings, stiffness_clock=self.stiffness_clock,
                                                    initial_state=initial, return_state=True, static=self.static)
        return result, RunState(float(result.t[-1]), (qpos, act), (qvel,))

    def stable_step(self) -> float:
        return stepping.stable_step(self.model.limits)

    def default_step(self) -> float:
        return self.model.default_step

    def omega_max(self) -> float:
        return self.model.omega_max

    def settling_time(self, fraction: float) -> float:
        return linearise.settling_time(self.model, fraction)

    def run_periodic(self, settings: RunSettings, check_step, progress=None) -> tuple[TimeResult, TimeResult, str]:
        steady = periodic_state(self.model, dt=settings.dt, static=self.static)
        options = {"initial_state": steady.initial_state, "stiffness_clock": self.stiffness_clock,
                   "static": self.static}
        run = simulate_mujoco(self.model, replace(settings, dt=steady.dt), progress=progress, **options)
        check = simulate_mujoco(self.model, replace(settings, dt=check_step(steady.dt), output_dt=None,
                                                    signals=tuple(run.names(compared=True))), **options)
        return run, check, steady.words("MuJoCo")


class PublishedTwinSide(Side):
    """The MuJoCo twin of the 4-DOF model ``name`` of Matejic et al. (2021); ``y1`` and ``carrier_mass``
    override the kinematics that model claims (:data:`~gearcheck.train.published_parameters.KINEMATICS`).
    A run needs its step: the 4-DOF models and their twin are compared on one time grid."""

    solver = "mujoco"
    kind = "MuJoCo twin of a published model"
    references = ("todorov-2012", "matejic2021")

    def __init__(self, spec, name: str, load: bool = True, planet_sets: int = 1, y1: str | None = None,
                 carrier_mass: str | None = None):
        check_model(name)
        self.spec, self.name, self.load, self.planet_sets = spec, name, load, planet_sets
        default_y1, default_mass = KINEMATICS[name]
        self.y1, self.carrier_mass = y1 or default_y1, carrier_mass or default_mass

    @cached_property
    def model(self) -> PublishedTwin:
        return build_twin(PaperParameters.from_spec(self.spec, self.planet_sets), self.y1, self.carrier_mass)

    def modes(self) -> ModalResult:
        return twin_modes(self.model)

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        return simulate_twin(self.model, settings, self.name, self.load)

    def stable_step(self) -> float:
        return stepping.undamped_stable_step(self.modes().frequencies)
