"""The front door: load a train, its modes, a time run of either solver, its MuJoCo model, a cross-check.

Every function takes a train as a preset name (``"hub-drive"``), the path of a train file, or a
loaded :class:`~gearcheck.train.spec.TrainSpec`.  Bad input raises a
:class:`~gearcheck.shared.errors.GearcheckError` whose message names the file, field or argument.
The studies of one train are methods of a :class:`~gearcheck.session.Train` session, which keeps its two models;
``modes``, ``simulate``, ``campbell``, ``mode_pairing`` (``Train.mac``), ``harmonic_response``, ``sweep`` and
``mjcf`` here are those methods on a new session.
"""

from __future__ import annotations

from pathlib import Path

from gearcheck.compare.studies.campbell import CampbellResult
from gearcheck.compare.engine.crosscheck import crosscheck
from gearcheck.compare.engine.mode_pairing import ModePairing
from gearcheck.compare.engine.measurements import load_measurements_file
from gearcheck.compare.presentation.dashboard import render
from gearcheck.compare.presentation.report import write_report
from gearcheck.compare.studies.calibrate import Calibration, FitParameter
from gearcheck.compare.studies.calibrate import calibrate as fit_train
from gearcheck.compare.studies.runup import RunUp, run_up
from gearcheck.compare.studies.sensitivity import field_sensitivity
from gearcheck.lumped.export import reference_linear_model, write_matrix_file
from gearcheck.lumped.linear_run import simulate_linear
from gearcheck.session import SOLVERS, Train
from gearcheck.train.compiled_excitation import compile_now as compile_transmission_error
from gearcheck.train.loader import load_train, preset_names, read_train_text
from gearcheck.train.spec import TrainSpec, with_profiles
from gearcheck.train.schema import parse_measurements_file
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.results import TimeResult
from gearcheck.shared.settings import RunSettings

__all__ = ["SOLVERS", "calibrate", "campbell", "crosscheck", "dashboard", "describe", "export_model",
           "harmonic_response", "load", "mjcf", "mode_pairing", "pin_loads",
           "modes", "preset_data", "presets", "runup", "sensitivity", "simulate", "simulate_batch", "sweep",
           "write_report"]


def presets() -> list[str]:
    """The names of the shipped trains."""
    return preset_names()


def load(train: str | Path | TrainSpec, speed: float | None = None, *, speed_profile: str | None = None,
         torque_profile: str | None = None, load_profile: str | None = None, start: str | None = None) -> TrainSpec:
    """A validated train.

    Parameters
    ----------
    train : str, path or TrainSpec
        A preset name, the path of a train file (TOML), or a train already loaded.
    speed : float, optional
        Input speed in rpm, replacing the train's.
    speed_profile, torque_profile, load_profile : str, optional
        An operating history replacing the train's (:mod:`gearcheck.train.history`): the input speed (rpm) or the
        input torque (N·m), and the output load (N·m), each a CSV or Parquet table (time, value, units in the
        header) or points ``"T:V,T:V,..."``, as ``--speed-profile`` and the others take them.
    start : {"steady", "rest"}, optional
        Where a history starts (default: at rest from 0 rpm or under a torque, else in the steady state).

    Returns
    -------
    TrainSpec
        The train in SI units: members, stages, meshes, couplings, operating point, measurements.
    """
    return with_profiles(load_train(train, speed), speed_profile, torque_profile, load_profile, start)


def preset_data(name: str) -> Path:
    """The path of a data file shipped with the presets (``hub-drive-table1.toml``,
    ``double-planet-initiation-torque.csv``), as a train file or a profile names it."""
    path = Path(__file__).parent / "train" / "presets" / "data" / name
    if not path.is_file():
        raise GearcheckError(f"no preset data file {name!r}; there are: "
                             + ", ".join(sorted(p.name for p in path.parent.iterdir() if p.is_file())))
    return path


def runup(train, start_rpm: float, stop_rpm: float, duration: float, *, solver: str = "both", quantities=None,
          harmonics: int = 3, output_dt: float | None = None, progress=None) -> RunUp:
    """A run-up through a linear speed ramp, each solver's mesh orders tracked (``gearcheck runup``).

    Parameters
    ----------
    train : str, path or TrainSpec
        The train (its input driven through its shaft; the run starts in the steady state at ``start_rpm``).
    start_rpm, stop_rpm, duration : float
        The ramp: from ``start_rpm`` to ``stop_rpm`` in ``duration`` seconds.
    solver : {"both", "lumped", "mujoco"}
    quantities : list of str, optional
        Gated signals to track (default: all).
    harmonics : int
        Mesh harmonics per mesh frequency (orders k f_mesh / f_in of the input).
    output_dt : float, optional
        Sampling of the runs in s (default: twice what order tracking needs at the top speed; a train whose mesh
        stiffness switches is read to its stepped sweep's accuracy only when sampled near the solvers' step).

    Returns
    -------
    RunUp
        ``tracks[(solver, quantity)]`` (:class:`~gearcheck.compare.studies.order_tracking.OrderTrack`: amplitude and
        phase of each order against speed), ``table()``, ``agreement()``, ``parting()``, ``waterfalls``, costs.
    """
    solvers = tuple(SOLVERS) if solver == "both" else (solver,)
    if any(s not in SOLVERS for s in solvers):
        raise GearcheckError(f"solver={solver!r}: one of both, {', '.join(SOLVERS)}")
    return run_up(load_train(train), start_rpm, stop_rpm, duration, solvers, quantities, harmonics, progress,
                  output_dt)


def modes(train, solver: str = "lumped", speed: float | None = None) -> ModalResult:
    """Natural frequencies, mode shapes, Lin & Parker mode types and energy shares at mean mesh stiffness.

    Parameters
    ----------
    train : str, path or TrainSpec
        The train.
    solver : {"lumped", "mujoco"}
        The reference lumped model, or MuJoCo's linearisation of the twin.
    speed : float, optional
        Input speed in rpm (0 allowed).  Without it, the modes of the train at rest (Lin & Parker
        1999); with it, the gyroscopic modes of the train turning at that speed (Cooley & Parker
        2012): complex eigenvalues, each mode's growth rate and stability.

    Returns
    -------
    ModalResult
        ``frequencies`` (Hz), ``shapes``, ``types``, ``multiplicity``, ``fractions`` (kinetic energy in
        central translation, central rotation, planets); at a speed also ``growth`` (1/s), ``stability``
        and ``stable``; ``to_dataframe()``, ``to_dict()``, ``plot()``.
    """
    return Train(train).modes(solver, speed)


def campbell(train, speeds, solver: str = "both", harmonics: int = 3) -> CampbellResult:
    """The Campbell diagram: the gyroscopic modes of both solvers (or one) over a range of input speeds.

    Parameters
    ----------
    train : str, path or TrainSpec
        The train.
    speeds : sequence of float
        Input speeds in rpm, ascending, >= 0.
    solver : {"both", "lumped", "mujoco"}
    harmonics : int
        Mesh harmonics drawn as excitation lines.

    Returns
    -------
    CampbellResult
        ``frequencies(solver)`` (speeds x modes, Hz), ``crossings`` of mesh harmonics with modes (each
        ``excited`` when the line's phased mesh forces reach the mode in the lumped model at that speed),
        instability ``zones``, ``agreement`` of the two solvers; ``to_dict()``; ``plot()``.
    """
    return Train(train).campbell(speeds, solver, harmonics)


def mode_pairing(train, model=None, against: str = "lumped") -> ModePairing:
    """The lumped model's and the MuJoCo twin's mode shapes paired by the modal assurance criterion; with
    ``model`` (as :func:`crosscheck` takes it), that model's against ``against``: a model with fewer
    coordinates against the reference reduced to them (held or condensed, as it declares).

    Returns
    -------
    ModePairing
        ``mac`` (reference modes x twin modes), ``paired`` (each mode's share in its frequency group's twin
        modes: 1 is the same shape), ``findings`` (swapped, missing, spurious modes), ``notes`` (what was
        reduced, condensed or set aside, in sentences), ``to_dict()``; ``plot()``.
    """
    return Train(train).mac(model, against)


def simulate(train, solver: str = "lumped", duration: float = 0.2, *, speed: float | None = None,
             dt: float | None = None, output_dt: float | None = None, settle: float | None = None,
             method: str = "rk4", progress=None) -> TimeResult:
    """A time run of the train at its operating point.

    Parameters
    ----------
    train : str, path or TrainSpec
        The train.
    solver : {"lumped", "mujoco"}
        The reference lumped model (RK4 in the rotating carrier frame) or the MuJoCo twin.
    duration : float
        Simulated time in s.
    speed : float, optional
        Input speed in rpm.
    dt : float, optional
        Fixed step in s (default: 20 steps per period of the highest natural frequency, a whole
        fraction of the mesh period); a step RK4 cannot run stably is refused.
    output_dt : float, optional
        Sampling of the result in s (default: every step).
    settle : float, optional
        Start of the steady window in s (default: half the duration, or the load ramp).
    method : str
        The lumped solver's integrator: "rk4" (default), "rk4-stages", or scipy's "RK45", "DOP853",
        "Radau", "BDF", "LSODA" (then ``dt`` is their largest step).
    progress : callable or True, optional
        Called with the fraction done; True: a progress bar (``tqdm.auto``: a widget in Jupyter).

    Returns
    -------
    TimeResult
        Named signals, ``result["stage1.ring.ay.world"]``; ``to_dataframe()``, ``plot()``, ``summary()``,
        ``write(directory)``.
    """
    return Train(train, speed).simulate(solver, duration, dt=dt, output_dt=output_dt, settle=settle, method=method,
                                        progress=progress)


def simulate_batch(train, speeds, duration: float = 0.2, *, dt: float | None = None, output_dt: float | None = None,
                   settle: float | None = None, progress=None) -> list[TimeResult]:
    """Time runs of the MuJoCo twin at several input speeds at once: the batched runner, MJX in float64, its
    worlds stepped together on a GPU where JAX has one (CPU otherwise); each equal to :func:`simulate`'s
    "mujoco" run at that speed to round-off (``pip install 'gearcheck[gpu]'``, and JAX's CUDA build on a GPU).

    Parameters
    ----------
    train : str, path or TrainSpec
        The train.
    speeds : sequence of float
        Input speeds in rpm, one world each.
    duration, dt, output_dt, settle
        As :func:`simulate` (the default step is each speed's own).
    progress : callable, optional
        Called with the fraction done.

    Returns
    -------
    list of TimeResult
        One per speed, in order; ``info.settings["device"]`` names the device that ran them.
    """
    from gearcheck.mbd_models.batched import simulate_mujoco_batch
    from gearcheck.mbd_models.twin import compile_train

    if (isinstance(speeds, (str, bytes)) or not hasattr(speeds, "__len__") or not len(speeds)
            or not all(isinstance(s, (int, float)) and not isinstance(s, bool) for s in speeds)):
        raise GearcheckError(f"speeds must be a non-empty sequence of input speeds in rpm, not {speeds!r}")
    twins = [compile_train(load_train(train, float(speed))) for speed in speeds]
    return simulate_mujoco_batch(twins, RunSettings(duration, dt=dt, output_dt=output_dt, settle=settle), progress)


def sweep(train, *, speeds=None, fields=None, distributions=None, samples: int | None = None, seed: int = 0,
          solver: str = "both", duration: float = 0.5, harmonics: int = 3, integration_check: bool | str = "subset",
          refine: int = 1, continuation: bool = True, workers: int | None = None, scheduler=None, executor=None,
          cache=None, progress=None):
    """A speed sweep, a parameter study or a Monte Carlo: many runs of one train, reduced to one table.

    Each point (a train file with swept fields edited, at one speed) runs each solver and reduces the
    steady state to the mean, RMS and peak-to-peak of every gated quantity and its amplitude and phase at
    the mesh harmonics, each with an estimate of its integration error (the change on doubling the step),
    beside the lumped model's natural frequencies at that speed
    (:mod:`gearcheck.compare.studies.sweep`).  Points are cached by a hash of their inputs, so an interrupted sweep
    resumes, and the same inputs give the same table, byte for byte.  Worker processes start fresh (forkserver)
    and never run the calling script again, so a script needs no ``if __name__ == "__main__":`` guard.

    Parameters
    ----------
    train : str or path
        A preset name or the path of a train file (its numbers are edited: not a loaded TrainSpec).
    speeds : sequence of float, optional
        Input speeds in rpm, each > 0 (default: the train's own).
    fields : dict, optional
        A parameter study: ``{"stages[0].sun.mass": [1.0, 1.2], ...}``, values in the file's own units
        (the addressing of ``gearcheck calibrate``); the grid over all of them.
    distributions : dict, optional
        A Monte Carlo: ``{"stages[0].mesh.ste[0].amplitude_um": "lognormal(10, 1.5)", ...}`` with
        ``normal(mean, sd)``, ``uniform(low, high)`` or ``lognormal(median, factor)``.
    samples : int, optional
        Monte Carlo draws (default 32), each from its own PCG64 stream of ``seed``.
    seed : int
        Monte Carlo seed.
    solver : {"both", "lumped", "mujoco"}
    duration : float
        Simulated time of a run from the static state in s, and the longest a continued point runs.
    harmonics : int
        Mesh harmonics per mesh frequency.
    integration_check : {"subset", "all", "none"} or bool
        Which points run each solver a second time, at twice its step, for the integration error estimates:
        "subset" (default) every 8th speed, every point with a line in the half-power band of a mode it
        drives and every point where a mesh with backlash or tip relief or a cycloid disc's pins unload (the
        table's ``checked`` column says which and why), "all" (True), or "none" (False).
    refine : int
        Each solver's default step divided by this (1 to 64): for lines whose integration error estimate is
        too large to read them.
    continuation : bool
        Start each point from the final state of the point at the neighbouring speed (default), so that it
        settles in a fraction of a run from the static state; where it does not settle the point runs from the
        static state and its table says so (:mod:`gearcheck.compare.studies.continuation`).
    workers : int, optional
        Local processes (default: the cores available; 1 runs in this process).
    scheduler : str or distributed.Client, optional
        A Dask scheduler's address (``tcp://host:8786``) or a client: the points run on that cluster.
    executor : concurrent.futures.Executor, optional
        Any executor of your own instead.
    cache : path, optional
        Folder of finished points (``KEY.parquet``); None: no cache.
    progress : callable or True, optional
        Called with the fraction of points done; True: a progress bar (``tqdm.auto``: a widget in Jupyter).

    Returns
    -------
    SweepResult
        ``table`` (pyarrow), ``to_pandas()``, ``plot()``, ``summary()``, ``write(directory)`` (``sweep.parquet``,
        ``sweep.json``, order plots or a study plot), ``computed``/``cached`` point counts, ``wall_s``.
    """
    return Train(train).sweep(speeds=speeds, fields=fields, distributions=distributions, samples=samples, seed=seed,
                              solver=solver, duration=duration, harmonics=harmonics,
                              integration_check=integration_check, refine=refine, continuation=continuation,
                              workers=workers,
                              scheduler=scheduler, executor=executor, cache=cache, progress=progress)


def export_model(train, path) -> None:
    """Write the reference lumped model of ``train`` as a file of matrices (``.mat`` or ``.npz``), the layout a
    user's own model is read in (:mod:`gearcheck.lumped.matrix_file`): every coordinate, sign and row of
    gearcheck's conventions, to compare with or to start from."""
    write_matrix_file(reference_linear_model(load(train)), path)


def harmonic_response(train, method: str = "harmonic balance", orders=None, speed: float | None = None):
    """The steady forced response of the reference model by harmonic balance or by the Fourier-series method of
    Yang, Chen & Wang (2018), on ``orders`` harmonics of each clock (one mesh group, and an RV reducer's
    eccentrics; default 3 and 2): a :class:`~gearcheck.lumped.fourier_response.HarmonicResponse` over the
    model's coordinates
    (``.at(t)``, ``.harmonic(h)``).  Trains with backlash, tip relief, transmission error or a varying torque
    are refused (time marching holds them)."""
    return Train(train, speed).harmonic_response(method, orders)


def sensitivity(train, parameter: str, method: str = "Fourier series", orders=None, speed: float | None = None):
    """d|Q_h|/dp of the steady response of ``train`` (a preset name or a train file) to the number at
    ``parameter`` (``stages[0].crank.eccentricity_mm``), in closed form with its finite-difference check and,
    for the Fourier-series method, the paper's Eq. (15) beside it
    (:class:`~gearcheck.compare.studies.sensitivity.FieldSensitivity`)."""
    if isinstance(train, TrainSpec):
        raise GearcheckError("sensitivity needs the train file (a preset name or a path), not a loaded TrainSpec: "
                             "it moves a number of the file")
    return field_sensitivity(*read_train_text(train), parameter, orders, method, speed)


def mjcf(train, speed: float | None = None) -> str:
    """The MuJoCo model (MJCF text) of the train, deterministic, loadable in MuJoCo's viewer."""
    return Train(train, speed).mjcf()


def compile_kernels() -> None:
    """Compile the solvers' numba kernels now, or load them from numba's disk cache: a few steps of demo-3p in each
    solver and in its exported linear model (a user's model's run).  A process about to start others that run
    gearcheck (a test session before its workers) calls it once, so that they read the cache instead of each
    compiling (about 30 s of CPU in a fresh environment)."""
    train = Train("demo-3p")
    for solver in SOLVERS:
        train.simulate(solver, duration=0.003)
    simulate_linear(reference_linear_model(train.spec), RunSettings(0.003))
    compile_transmission_error()  # demo-3p has none


def describe(train) -> dict:
    """What a train derives from its file (``gearcheck show``): speeds, ratio, gear radii, every mesh's contact
    ratio, frequency, phase, stiffness and damping, an RV reducer's cycloid-pin stage; JSON-ready."""
    return Train(train).describe()


def pin_loads(train, times=None, *, span: str = "pitch", samples: int = 16, stage: str | None = None):
    """An RV reducer's static pin forces (``gearcheck pins``): a
    :class:`~gearcheck.lumped.pin_loads.PinLoads` of every disc and pin over one pin pitch or eccentric turn."""
    return Train(train).pin_loads(times, span=span, samples=samples, stage=stage)


def calibrate(train, fit, *, measurements=None, duration: float = 0.6, fit_speed=None, starts: int | None = None,
              progress=None) -> Calibration:
    """Least-squares fit of train-file numbers to measured amplitudes and natural frequencies (``gearcheck
    calibrate``).

    Parameters
    ----------
    train : str or path
        A preset name or the path of a train file (the calibrated file is this text with the fitted values).
    fit : list of str
        Train-file fields in their own units with optional bounds, ``"stages[0].mesh.ste[0].amplitude_um=0.05:20"``.
    measurements : path or dict, optional
        A TOML file of ``[[measurements]]`` (amplitudes) and ``[[natural_frequencies]]``, or such a file's content
        as a dict (``{"natural_frequencies": [{"frequency_hz": 148.95, "mode": 1}]}``); default the train file's
        own ``[[measurements]]`` and its ``measurements_file``'s.
    duration : float
        Simulated time per run, s (amplitudes only).
    fit_speed : list of float, optional
        Fit only the amplitudes measured at these speeds (rpm); the others are predicted.
    starts : int, optional
        How many starting points the fit runs from (the file's values, then a Latin hypercube in ln p within the
        bounds); default 16 when every measurement is a natural frequency, 1 when amplitudes need time runs.
    progress : callable, optional
        Called with the number of model evaluations done.

    Returns
    -------
    Calibration
        The fitted values, their uncertainty, the measured against predicted values, the minima the starts reached,
        the calibrated text.
    """
    text, source = read_train_text(train)
    if isinstance(measurements, dict):
        found = parse_measurements_file(measurements, "measurements=")
        entries, frequencies = found["measurements"], found["natural_frequencies"]
    elif measurements:
        found = load_measurements_file(measurements)
        entries, frequencies = found["measurements"], found["natural_frequencies"]
    else:
        spec = load(train)
        entries, frequencies = list(spec.measurements), list(spec.natural_frequencies)
    return fit_train(text, source, entries, [FitParameter.parse(f) for f in fit], duration, fit_speed, progress,
                     frequencies, starts)


def dashboard(store, out) -> Path:
    """The regression dashboard (``gearcheck dashboard``): a static site of the history store ``store`` written
    into the folder ``out``; returns its path."""
    return render(store, out)
