"""Cross-check a train: the whole workflow, the same from Python and from the command line.

:func:`crosscheck` loads the train (a preset name, a file or a TrainSpec), resolves the two models that
``model=`` names (:func:`gearcheck.compare.engine.model_pair.resolve_model`), runs the engine
(:func:`gearcheck.compare.engine.comparison.compare`) as the reference's plan reads the runs, attaches the
measured values (the train's own ``[[measurements]]`` and any given) and checks or rewrites a baseline.
Errors name the parameters (``model=...``, ``duration``).
"""

from __future__ import annotations

from pathlib import Path

from gearcheck.compare.engine.baseline import baseline_path, check_settings, compare_to_baseline, read_baseline
from gearcheck.compare.engine.baseline import write_baseline
from gearcheck.compare.engine.comparison import CrosscheckResult, compare
from gearcheck.compare.engine.measure import MIN_CYCLES
from gearcheck.compare.engine.measurements import attach, check_quantities, load_measurements
from gearcheck.compare.engine.model_pair import MODELS, resolve_model
from gearcheck.compare.engine.tolerances import Tolerances
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.progress import shows_progress
from gearcheck.shared.units import rad_s_to_rpm
from gearcheck.train.kinematics import require_mesh_cycle
from gearcheck.train.loader import load_train

__all__ = ["MODELS", "crosscheck"]


@shows_progress
def crosscheck(train, *, speed: float | None = None, duration: float | None = None, model="general",
               against: str = "lumped", results=None, columns=None, modes=None, dt_lumped: float | None = None,
               dt_mujoco: float | None = None, tolerances=None, measurements=None,
               sensor_band: tuple[float, float] | None = None, baseline=None, update_baseline: bool = False,
               progress=None, sides=None) -> CrosscheckResult:
    """Cross-check a train's lumped model against its MuJoCo twin, or the model ``model`` names.

    Parameters
    ----------
    train : str, path or TrainSpec
        A preset name (``"hub-drive"``), the path of a train file, or a loaded train.
    speed : float, optional
        Input speed in rpm (default: the train's).
    duration : float, optional
        Simulated time in s (default: the baseline's when one is checked, else 0.1 s; 0.02 s for a
        published 4-DOF ``model``).
    model : str, path, LinearModel or side
        What is checked (:func:`~gearcheck.compare.engine.model_pair.resolve_model`): ``"general"`` (the lumped
        model against its MuJoCo twin); a 4-DOF model of Matejic et al. (2021) (``"as-published"``,
        ``"energy-derived"``, ``"energy-derived-axis"``, ``"consistent"``) against the twin of its idealisation;
        or a user's model against ``against``: a LinearModel, a ``.mat``/``.npz`` file of matrices,
        ``"module:factory"`` / ``"file.py:factory"``, a side, or ``"user"`` (the train file's ``train.user_model``).
    against : str
        What a user's model is checked against: ``"lumped"`` (the reference model) or ``"mujoco"`` (the twin).
    results, columns, modes : path, optional
        Another solver's results as the user's model (:mod:`gearcheck.compare.engine.recorded`): its time series
        (``.csv``, ``.parquet``, ``.mat``), the column map (a TOML file or a dict) naming gearcheck's signals
        in it, and optionally its natural frequencies and mode shapes (``.npz``, ``.mat``, ``.csv``).
    dt_lumped, dt_mujoco : float, optional
        Fixed steps of the two solvers (default: each from its own highest natural frequency).
    tolerances : path or dict, optional
        Overrides of the default tolerances, after the train file's own ``[tolerances]``: a TOML file
        with a ``[tolerances]`` table, or a dict ``{"KIND.METRIC": value}``.
    measurements : path or list of dict, optional
        Measured values shown beside both solvers, in addition to the train's own.
    sensor_band : (float, float), optional
        Band (Hz) of an accelerometer chain applied to both solvers' accelerations.
    baseline : path or "shipped", optional
        A stored baseline to compare with (``"shipped"``: the one shipped for this preset); its speed
        and duration must match, which is checked before anything runs.
    update_baseline : bool
        Rewrite ``baseline`` with this run instead of comparing (over the duration it was taken over, unless
        ``duration`` says otherwise).
    progress : callable or True, optional
        Called with the fraction done; True: a progress bar (``tqdm.auto``: a widget in Jupyter).
    sides : callable, optional
        The lumped model and the twin already built for this train at this speed (``"lumped"``/``"mujoco"`` ->
        side, as :meth:`gearcheck.Train.side`); default: built here.

    Returns
    -------
    CrosscheckResult
        ``.verdict`` ("PASS", "FAIL" or "INCONCLUSIVE"), ``.failures``, ``.unresolved``, ``.quantities``
        (``result[name]``), ``.measurements``, ``.moved`` (metrics moved from the baseline), ``.write(directory)``.
    """
    spec = load_train(train, speed)
    require_mesh_cycle(spec, "a cross-check (its time runs)")
    pair = resolve_model(spec, model, against, results, columns, modes, sides)
    _check_band(sensor_band)
    tol = Tolerances.for_train(spec, tolerances)
    path = baseline_path(baseline, spec.name)
    # a baseline rewritten without a duration keeps the one it was taken over
    keep = update_baseline and duration is None and path is not None and path.exists()
    stored = read_baseline(path) if path is not None and (not update_baseline or keep) else None
    duration = pair.duration(stored) if duration is None else duration
    if stored is not None and not update_baseline:  # before the run: a mismatch is refused at once
        check_settings(stored, duration, rad_s_to_rpm(spec.operating.input_speed))
    plan = pair.plan(spec, duration)
    settings = pair.settings(duration, plan, {"lumped": dt_lumped, "mujoco": dt_mujoco})
    entries = _entries(spec, measurements, pair.quantities(spec), tol)  # before the runs: a wrong name is refused
    _check_duration(duration, plan, spec.name)
    result = compare(spec, pair.reference, pair.test, plan, settings, tol, sensor_band, progress)
    result.notes = pair.notes() + result.notes
    pair.diagnose(spec, result)
    attach(result, entries)
    if path is not None and update_baseline:
        write_baseline(result, path)
    elif stored is not None:
        result.moved = compare_to_baseline(result, stored)
    return result


def _entries(spec, measurements, quantities: list[str], tol: Tolerances) -> list[dict]:
    """The measured values shown beside both solvers (the train's own and ``measurements``), their names and the
    tolerances' checked against the compared ``quantities``."""
    entries = list(spec.measurements)
    if measurements is not None:
        entries += load_measurements(measurements) if isinstance(measurements, (str, Path)) else list(measurements)
    tol.check(quantities)
    check_quantities(entries, quantities)
    return entries


def _check_band(sensor_band) -> None:
    if sensor_band is not None and not 0 < sensor_band[0] < sensor_band[1]:
        raise GearcheckError(f"sensor band {sensor_band[0]:g} {sensor_band[1]:g} Hz: needs 0 < LOW < HIGH")


def _check_duration(duration: float, plan, name: str) -> None:
    if duration < MIN_CYCLES * plan.cycle:
        raise GearcheckError(f"duration {duration:g} s is shorter than a cycle of {plan.cycle:.4g} s (the slowest mesh "
                             f"of {name}, or its lowest mode), the least a comparison needs")
