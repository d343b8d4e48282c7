"""The lumped models as the cross-check sees them (:class:`gearcheck.shared.side.Side`).

* :class:`LumpedSide` -- the reference translational-torsional model of a train (Lin & Parker
  1999; several stages after Kiracofe & Parker 2007; mesh phasing after Parker & Lin 2004);
* :class:`LinearSide` -- any model given as matrices: a user's, in Python or in a file;
* :class:`PublishedSide` -- one of the 4-DOF models of Matejic et al. (2021), as published or as
  derived, as a model given as matrices.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cached_property

import numpy as np

from gearcheck.lumped.assembly import LumpedModel, build_model
from gearcheck.lumped.condensation import condense_massless
from gearcheck.lumped.linear_model import LinearModel
from gearcheck.lumped.linear_run import EXTRA_DOMINATED, linear_modes, linear_modes_at_speed, set_aside, simulate_linear
from gearcheck.lumped.linear_run import default_step as linear_default_step, periodic_start, step_limits, unmapped
from gearcheck.train.mesh_stiffness import MODELS
from gearcheck.lumped.modal import (drives_are_linear, line_drives, line_resonances, modes, modes_at_speed,
                                    settling_time)
from gearcheck.lumped.periodic_steady_state import periodic_steady_state
from gearcheck.lumped.published import four_dof_model, linear_model
from gearcheck.lumped.time_solver import default_step, simulate, stable_step, step_limits as model_step_limits
from gearcheck.shared import stepping
from gearcheck.shared.modal import ModalResult, slowest_decaying_mode
from gearcheck.shared.results import TimeResult
from gearcheck.shared.run_state import RunState
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.side import Side
from gearcheck.shared.units import rad_s_to_rpm


class LumpedSide(Side):
    """The reference lumped model of a train; ``method`` is the time integrator (see
    :func:`gearcheck.lumped.time_solver.simulate`)."""

    solver = "lumped"
    kind = "reference lumped model"
    order = stepping.ORDER  # RK4, the drive set at every stage, contact events located

    def __init__(self, spec, method: str = "rk4"):
        self.spec = spec
        self.method = method

    @cached_property
    def model(self) -> LumpedModel:
        return build_model(self.spec)

    @property
    def references(self) -> tuple[str, ...]:
        stiffness = [key for mesh in self.spec.meshes for key in MODELS[mesh.stiffness["model"]].references]
        return ("lin-parker-1999", "kiracofe-parker-2007", "parker-lin-2004", *stiffness)

    def modes(self) -> ModalResult:
        return modes(self.model)

    def modes_at_speed(self, input_speed: float) -> ModalResult:
        return modes_at_speed(self.model, input_speed)

    def physical_modes(self, modal: ModalResult) -> tuple[list[str], np.ndarray, np.ndarray]:
        """(coordinate labels, mass matrix, the shapes of ``modal``) in the train's physical coordinates (the
        model's own)."""
        return self.model.dofs.labels(), self.model.M, modal.shapes

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        return simulate(self.model, settings, method=self.method, progress=progress)

    def run_from(self, settings: RunSettings, state: RunState | None = None) -> tuple[TimeResult, RunState]:
        """From the deflections q and their rates v of ``state`` (the model's own coordinates)."""
        y0 = None if state is None else (state.coordinates[0], state.rates[0])
        result, (q, v) = simulate(self.model, settings, method=self.method, y0=y0, return_state=True)
        return result, RunState(float(result.t[-1]), (q,), (v,))

    def stable_step(self) -> float:
        return stable_step(self.model)

    def default_step(self) -> float:
        return default_step(self.model)

    def omega_max(self) -> float:
        return model_step_limits(self.model).omega_max

    def settling_time(self, fraction: float) -> float:
        return settling_time(self.model, fraction)

    def slowest_mode(self) -> tuple[float, float]:
        m = self.model
        return slowest_decaying_mode(m.M, m.C + m.G, m.K_mean + m.K_frame)

    def resonances(self, lines) -> list[tuple[np.ndarray, np.ndarray]]:
        """(natural frequencies in Hz, damping ratios) of the modes of the damped, rotating model at mean mesh
        stiffness that each line (mesh frequency in Hz, harmonic) drives
        (:func:`~gearcheck.lumped.modal.line_resonances`)."""
        return line_resonances(self.model, lines)

    def drives_at_speed(self, input_speed: float, lines) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:func:`~gearcheck.lumped.modal.line_drives` of the model turning at ``input_speed`` (rad/s), the lines at
        the train's own mesh frequencies (its excitation and static loads stay its own)."""
        return line_drives(self.model.at_speed(input_speed), lines)

    @property
    def drives_known(self) -> bool:
        """Whether :meth:`drives_at_speed` tells the modes each line drives, not every mode
        (:func:`~gearcheck.lumped.modal.drives_are_linear`)."""
        return drives_are_linear(self.model)

    def run_periodic(self, settings: RunSettings, check_step, progress=None) -> tuple[TimeResult, TimeResult, str]:
        steady = periodic_steady_state(self.model, dt=settings.dt)
        run = simulate(self.model, replace(settings, dt=steady.dt), method=self.method, y0=steady.y0,
                       progress=progress)
        check = simulate(self.model, replace(settings, dt=check_step(steady.dt), output_dt=None,
                                     signals=tuple(run.names(compared=True))), method=self.method,
                         y0=steady.y0)
        return run, check, steady.words("lumped")


class LinearSide(Side):
    """A model given as matrices (:class:`~gearcheck.lumped.linear_model.LinearModel`: a user's, or a
    published one) for the train ``spec``; validated against the train's coordinates when built, its massless
    coordinates condensed out (:func:`~gearcheck.lumped.condensation.condense_massless`).  Its modes are the
    train's: those its extra coordinates dominate are set aside (:func:`~gearcheck.lumped.linear_run.set_aside`)
    and named in its notes."""

    kind = "user model"

    def __init__(self, model: LinearModel, spec, references: tuple[str, ...] = ()):
        self.spec = spec
        self.train = build_model(spec)  # the train's coordinates and kinematics, which the model maps into
        self.linear = condense_massless(model.check(spec, self.train.physical_dofs.labels()))
        self.solver = model.name
        self.references = references
        self.driven = bool(self.linear.meshes) or self.linear.stiffness is not None or self.linear.forcing is not None

    @cached_property
    def _rest(self) -> tuple[ModalResult, list[float]]:
        modal, aside = set_aside(self.linear, linear_modes(self.linear, self.train))
        modal.train = self.spec.name
        return modal, aside

    def modes(self) -> ModalResult:
        return self._rest[0]

    def modes_at_speed(self, input_speed: float) -> ModalResult:
        return set_aside(self.linear, linear_modes_at_speed(self.linear, self.train, input_speed))[0]

    @property
    def notes(self) -> list[str]:
        """What was done to the model (its massless coordinates condensed) and which of its modes are set aside."""
        aside, extra = self._rest[1], self.linear.extra
        if not extra:
            return list(self.linear.notes)
        return [*self.linear.notes, f"{self.solver} has {len(extra)} coordinate{'s' if len(extra) > 1 else ''} mapped "
                f"to no coordinate of {self.spec.name} ({', '.join(extra)}), kept in its dynamics; {len(aside)} of its "
                f"modes have more than {EXTRA_DOMINATED:.0%} of their kinetic energy there"
                f"{': ' + ', '.join(f'{f:.6g} Hz' for f in aside) if aside else ''}, without counterpart in the "
                "reference: set aside, not compared."]

    def physical_modes(self, modal: ModalResult) -> tuple[list[str], np.ndarray | None, np.ndarray]:
        """(the train coordinates the model has, its mass matrix over them when they determine its own
        coordinates, else None; the shapes of ``modal`` over them)."""
        labels = self.train.physical_dofs.labels()
        T, mapped = self.linear.to_physical(labels)
        T = T[mapped]
        own = [i for i, c in enumerate(self.linear.coordinates) if c not in self.linear.extra]
        mass = None
        if len(own) == T.shape[0] and np.linalg.matrix_rank(T[:, own]) == T.shape[0]:
            T_inv = np.linalg.inv(T[:, own])
            mass = T_inv.T @ self.linear.M[np.ix_(own, own)] @ T_inv
        return [label for label, m in zip(labels, mapped) if m], mass, T @ modal.shapes

    def run_periodic(self, settings: RunSettings, check_step, progress=None) -> tuple[TimeResult, TimeResult, str]:
        """Its run and check from its periodic steady state (:func:`~gearcheck.lumped.linear_run.periodic_start`:
        the fixed point of its RK4 map over the drive's period, exact for a linear model)."""
        dt = linear_default_step(self.linear) if settings.dt is None else settings.dt
        q, v, h, residual = periodic_start(self.linear, dt)
        run = simulate_linear(self.linear, replace(settings, dt=h), self.train, progress, y0=(q, v))
        check = simulate_linear(self.linear, replace(settings, dt=check_step(h), output_dt=None), self.train,
                                y0=(q, v))
        run.train = check.train = self.spec.name
        return run, check, (f"{self.solver}: the fixed point of its RK4 map over the drive's period, solved as the "
                            f"linear system it is, residual {residual:.1e}")

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        result = simulate_linear(self.linear, settings, self.train, progress)
        result.train = self.spec.name
        return result

    def stable_step(self) -> float:
        return stepping.stable_step(step_limits(self.linear))

    def unmapped(self) -> list[str]:
        """The train's gated signals this model does not report."""
        return unmapped(self.linear, self.train)


class PublishedSide(LinearSide):
    """A 4-DOF model of Matejic et al. (2021) (``name`` one of
    :data:`gearcheck.train.published_parameters.MODELS`), from rest under the paper's excitation
    (``load``: with the output load on ring b), through the same door as any user's model."""

    kind = "published model"

    def __init__(self, spec, name: str, load: bool = True, planet_sets: int = 1):
        self.model = four_dof_model(spec, name, planet_sets)
        self.name, self.load, self.planet_sets = name, load, planet_sets
        super().__init__(linear_model(self.model, load), spec, ("matejic2021",))

    def operating(self) -> dict:
        """The paper's operating point, the chosen model and its load case."""
        p = self.model.params
        return {"input_speed_rpm": rad_s_to_rpm(p.input_speed),
                "output_torque_nm": p.output_torque if self.load else 0.0, "model": self.name, "load": self.load,
                "planet_sets": self.planet_sets}
