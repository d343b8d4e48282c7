"""The lumped models as the cross-check sees them (:class:`gearcheck.shared.side.Side`).

* :class:`LumpedSide` -- the reference translational-torsional model of a train (Lin & Parker
  1999; several stages after Kiracofe & Parker 2007; mesh phasing after Parker & Lin 2004);
* :class:`PublishedSide` -- one of the 4-DOF models of Matejic et al. (2021), as published or as
  derived.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from gearcheck.lumped.assembly import LumpedModel, build_model
from gearcheck.lumped.mesh_stiffness import MODELS
from gearcheck.lumped.modal import modes, modes_at_speed
from gearcheck.lumped.published import FourDofModel, four_dof_model, natural_frequencies
from gearcheck.lumped.published import simulate as simulate_4dof
from gearcheck.lumped.time_solver import simulate, stable_step
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.results import TimeResult
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import undamped_stable_step


class LumpedSide:
    """The reference lumped model of a train; ``method`` is the time integrator (see
    :func:`gearcheck.lumped.time_solver.simulate`)."""

    solver = "lumped"

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

    def stable_step(self) -> float:
        return stable_step(self.model)


class PublishedSide:
    """A 4-DOF model of Matejic et al. (2021) (``name`` one of
    :data:`gearcheck.lumped.published_parameters.MODELS`), from rest under the paper's excitation
    (``load``: with the output load on ring b)."""

    references = ("matejic2021",)

    def __init__(self, spec, name: str, load: bool = True, planet_sets: int = 1):
        self.spec = spec
        self.solver = name
        self.load = load
        self.planet_sets = planet_sets

    @cached_property
    def model(self) -> FourDofModel:
        return four_dof_model(self.spec, self.solver, self.planet_sets)

    def modes(self) -> ModalResult:
        return natural_frequencies(self.model)

    def run(self, settings: RunSettings, progress=None) -> TimeResult:
        return simulate_4dof(self.model, settings, self.load)

    def stable_step(self) -> float:
        return undamped_stable_step(self.modes().frequencies)
