"""A train as a session: its two models built once, every study of it a method.

``gearcheck.Train("hub-drive")`` loads and validates the train; the reference lumped model and the compiled
MuJoCo twin are built the first time a method needs them and kept, so modes, runs, a Campbell diagram, the mode
pairing, an animation and the MJCF text of one session share them (the separation of model, solver and
simulation of PyBaMM's ``Simulation``, Sulzer et al. 2021).  The functions of :mod:`gearcheck.api` are these
methods on a new session.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path

from gearcheck.compare.engine.comparison import CrosscheckResult
from gearcheck.compare.engine.crosscheck import crosscheck
from gearcheck.compare.engine.mode_pairing import ModePairing, pair_modes
from gearcheck.compare.engine.model_pair import SOLVERS, resolve_model
from gearcheck.compare.studies.campbell import CampbellResult, campbell
from gearcheck.compare.studies.sensitivity import lattice
from gearcheck.lumped import time_solver
from gearcheck.lumped.describe import describe
from gearcheck.lumped.forced_response import parametric_problem
from gearcheck.lumped.fourier_response import fourier_series_response, harmonic_balance_response
from gearcheck.lumped.pin_loads import PinLoads, pin_loads
from gearcheck.lumped.side import LumpedSide
from gearcheck.lumped.transmission_error import relief_sweep, static_transmission_error
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.progress import shows_progress
from gearcheck.shared.results import TimeResult
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.units import checked_rpm, rpm_to_rad_s
from gearcheck.train.kinematics import require_mesh_cycle
from gearcheck.train.loader import load_train
from gearcheck.train.spec import TrainSpec

MAX_STIFFNESS_CYCLES = 100  # a stiffness repeats every mesh cycle: more shows nothing new (2000 points a cycle)


class Train:
    """A train (a preset name, the path of a train file, or a TrainSpec) at its operating point, or at ``speed``
    (rpm, replacing the train's), with its lumped model and MuJoCo twin built once, on first use."""

    def __init__(self, train: str | Path | TrainSpec, speed: float | None = None):
        self.source, self.speed = train, speed
        self.spec = load_train(train, speed)

    def __repr__(self) -> str:
        return f"Train({self.spec.name!r})"

    @cached_property
    def lumped(self) -> LumpedSide:
        """The reference lumped model (Lin & Parker 1999), built on first use."""
        return LumpedSide(self.spec)

    @cached_property
    def mujoco(self) -> MujocoSide:
        """The MuJoCo twin, compiled on first use."""
        return MujocoSide(self.spec)

    def side(self, solver: str, method: str = "rk4"):
        """The session's side of ``solver`` ("lumped" or "mujoco"); ``method`` the lumped time integrator."""
        if solver not in SOLVERS:
            raise GearcheckError(f"unknown solver {solver!r}; choose one of {', '.join(SOLVERS)}")
        if solver == "mujoco":
            if method != "rk4":
                raise GearcheckError(f"method {method!r} applies to the lumped solver only")
            return self.mujoco
        if method == self.lumped.method:
            return self.lumped
        side = LumpedSide(self.spec, method)
        side.model = self.lumped.model  # the same built model, another integrator
        return side

    def modes(self, solver: str = "lumped", speed: float | None = None) -> ModalResult:
        """Natural frequencies, shapes and Lin & Parker mode types at mean mesh stiffness; at ``speed`` (rpm) the
        gyroscopic modes (Cooley & Parker 2012).  See :func:`gearcheck.modes`."""
        side = self.side(solver)
        return side.modes() if speed is None else side.modes_at_speed(rpm_to_rad_s(checked_rpm(speed, zero=True)))

    @shows_progress
    def simulate(self, solver: str = "lumped", duration: float = 0.2, *, dt: float | None = None,
                 output_dt: float | None = None, settle: float | None = None, method: str = "rk4", y0=None,
                 progress=None) -> TimeResult:
        """A time run at the session's operating point.  See :func:`gearcheck.simulate`; ``y0``: the lumped
        model's start (q, q_dot) over its coordinates (``lumped.model.dofs.labels()``) instead of the static
        one, e.g. the end of another run (a sweep that follows one branch of a nonlinear response)."""
        require_mesh_cycle(self.spec, "a time run")
        settings, side = RunSettings(duration, dt, output_dt, settle), self.side(solver, method)
        if y0 is None:
            return side.run(settings, progress)
        if solver != "lumped":
            raise GearcheckError(f"y0 applies to the lumped solver only, not {solver!r}")
        return time_solver.simulate(side.model, settings, method=method, y0=y0, progress=progress)

    def crosscheck(self, **options) -> CrosscheckResult:
        """Both solvers compared, on the session's models (at another ``speed``, new ones); ``options`` those of
        :func:`gearcheck.crosscheck`."""
        return crosscheck(self.spec, sides=None if options.get("speed") is not None else self.side, **options)

    def campbell(self, speeds, solver: str = "both", harmonics: int = 3) -> CampbellResult:
        """The Campbell diagram over ``speeds`` (rpm, ascending).  See :func:`gearcheck.campbell`."""
        solvers = tuple(SOLVERS) if solver == "both" else (solver,)
        sides = {s: self.side(s) for s in solvers}
        speeds = [checked_rpm(v, zero=True) for v in speeds]
        if len(speeds) < 2 or any(b <= a for a, b in zip(speeds, speeds[1:])):
            raise GearcheckError(f"speeds: give at least two speeds in ascending order, got {list(speeds)}")
        return campbell(self.spec, speeds, lambda s, w: sides[s].modes_at_speed(w), solvers, harmonics,
                        self.lumped.drives_at_speed if self.lumped.drives_known else None)

    def mac(self, model=None, against: str = "lumped") -> ModePairing:
        """The two solvers' mode shapes paired by the modal assurance criterion (Allemang & Brown 1982); with
        ``model`` (a user's), that model's against ``against``.  See :func:`gearcheck.mode_pairing`."""
        pair = resolve_model(self.spec, "general" if model is None else model, against, sides=self.side)
        return pair_modes(self.spec.name, pair.reference, pair.test)

    def harmonic_response(self, method: str = "harmonic balance", orders=None):
        """The steady forced response of the lumped model by harmonic balance or the Fourier-series method of
        Yang, Chen & Wang (2018).  See :func:`gearcheck.harmonic_response`."""
        methods = {"harmonic balance": harmonic_balance_response, "Fourier series": fourier_series_response}
        if method not in methods:
            raise GearcheckError(f"method {method!r}: one of {', '.join(methods)}")
        require_mesh_cycle(self.spec, "a forced response")
        problem = parametric_problem(self.lumped.model)
        return methods[method](problem, lattice(problem, orders))

    def ste(self, slices: int | None = None) -> list:
        """The static transmission error of every mesh over one mesh cycle, unloaded and under the train's load
        (:func:`gearcheck.lumped.transmission_error.static_transmission_error`; ``slices``: face-width slices
        of a helical mesh)."""
        require_mesh_cycle(self.spec, "the static transmission error")
        return static_transmission_error(self.spec, slices=slices)

    def relief_sweep(self, amounts, slices: int | None = None) -> dict:
        """The loaded static transmission error's peak-to-peak of the first planet's relieved meshes at each tip
        relief amount of ``amounts`` (m) (:func:`gearcheck.lumped.transmission_error.relief_sweep`)."""
        require_mesh_cycle(self.spec, "a relief sweep")
        return relief_sweep(self.spec, amounts, slices=slices)

    @shows_progress
    def sweep(self, *, speeds=None, fields=None, distributions=None, samples: int | None = None, seed: int = 0,
              solver: str = "both", duration: float = 0.5, harmonics: int = 3,
              integration_check: bool | str = "subset", refine: int = 1, continuation: bool = True,
              workers: int | None = None, scheduler=None, executor=None, cache=None, progress=None):
        """A speed sweep, parameter study or Monte Carlo of the train file (each point builds its own models, in
        its own process); ``speeds`` default to the session's.  See :func:`gearcheck.sweep`."""
        from gearcheck.compare.studies.sweep import sweep

        if speeds is None and self.speed is not None:
            speeds = [self.speed]
        # at speeds of its own a sweep's train turns; its stages still need teeth
        require_mesh_cycle(self.spec if speeds is None else self.spec.with_operating(input_speed=1.0), "a sweep")
        return sweep(self.source, speeds=speeds, fields=fields, distributions=distributions, samples=samples,
                     seed=seed, solvers=solver, duration=duration, harmonics=harmonics,
                     integration_check=integration_check, refine=refine, continuation=continuation,
                     workers=workers, scheduler=scheduler,
                     executor=executor, cache=cache, progress=progress)

    def animate(self, path, mode: int | None = None, solver: str = "mujoco", **options) -> Path:
        """A GIF or MP4 of the twin: turning, its vibration magnified; with ``mode`` (1-based), mode ``mode`` of
        ``solver`` oscillating.  ``options``: those of :func:`gearcheck.compare.presentation.animate.animate` or
        :func:`~gearcheck.compare.presentation.animate.animate_mode`."""
        from gearcheck.compare.presentation.animate import animate, animate_mode

        if mode is None:
            require_mesh_cycle(self.spec, "an animation of the running twin (--mode animates a mode)")
            return animate(self.mujoco.model, path, **options)
        return animate_mode(self.mujoco.model, path, mode, solver, self.modes(solver), **options)

    def mjcf(self) -> str:
        """The MuJoCo model (MJCF text) of the twin, deterministic, loadable in MuJoCo's viewer."""
        return self.mujoco.model.xml

    def describe(self) -> dict:
        """What the train derives from its file, JSON-ready: speeds and ratio, every gear's radii, every mesh's
        contact ratio, frequency, phase, stiffness and damping, an RV reducer's cycloid-pin stage."""
        return describe(self.spec)

    def pin_loads(self, times=None, *, span: str = "pitch", samples: int = 16, stage: str | None = None) -> PinLoads:
        """An RV reducer's static pin forces, every disc and pin, at ``times`` (s) or ``samples`` frozen times over
        one ``span`` ("pitch" or "turn"; Yang, Chen & Wang 2018).  See :func:`gearcheck.lumped.pin_loads.pin_loads`."""
        return pin_loads(self.lumped.model, times, span=span, samples=samples, stage=stage)

    def stiffness(self, cycles: int = 2):
        """A Figure of every central gear's mesh stiffness with its first planet over ``cycles`` mesh cycles (1 to
        ``MAX_STIFFNESS_CYCLES``), beside its mean (the model the train file names)."""
        from gearcheck.compare.presentation.plots import mesh_stiffness_figure

        if isinstance(cycles, bool) or not isinstance(cycles, int) or not 1 <= cycles <= MAX_STIFFNESS_CYCLES:
            raise GearcheckError(f"cycles={cycles!r}: a whole number of mesh cycles from 1 to {MAX_STIFFNESS_CYCLES}")
        return mesh_stiffness_figure(self.spec, cycles)

    def view(self, slow_motion: float = 100.0, magnify: float = 1000.0) -> None:
        """MuJoCo's viewer on the twin, running ``slow_motion`` times slower than real time with its deflection
        magnified ``magnify`` times, until the window closes (needs a display)."""
        from gearcheck.compare.presentation.live_view import live_view

        require_mesh_cycle(self.spec, "the viewer's running twin")
        live_view(self.mujoco.model, slow_motion=slow_motion, magnify=magnify)
