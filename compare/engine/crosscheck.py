"""Cross-check a train: the whole workflow, the same from Python and from the command line.

:func:`crosscheck` loads the train (a preset name, a file or a TrainSpec), picks the two models
(``model="general"``: gearcheck's lumped model against its MuJoCo twin; a 4-DOF model name of
Matejic et al. 2021: that model against the MuJoCo twin of its own idealisation), runs the engine
(:func:`gearcheck.compare.engine.comparison.compare`), attaches the measured values (the train's own
``[[measurements]]`` and any given) and checks or rewrites a baseline.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gearcheck.compare.engine.align import STEADY_THRESHOLD
from gearcheck.compare.engine.baseline import BASELINE_DIR, check_settings, compare_to_baseline, read_baseline, write_baseline
from gearcheck.compare.engine.diagnosis import diagnose_side
from gearcheck.compare.engine.comparison import CrosscheckResult, compare
from gearcheck.compare.engine.measure import MIN_CYCLES
from gearcheck.compare.engine.measurements import attach, check_quantities, load_measurements
from gearcheck.compare.engine.plan import TrainPlan, TransientPlan
from gearcheck.compare.engine.recorded import RecordedSide
from gearcheck.compare.engine.tolerances import Tolerances
from gearcheck.compare.engine.user_model import user_side
from gearcheck.train.loader import load_train
from gearcheck.lumped.matrix_file import SUFFIXES
from gearcheck.lumped.modal import settling_time
from gearcheck.lumped.published import FINDING
from gearcheck.train.published_parameters import LABELS
from gearcheck.train.published_parameters import MODELS as PUBLISHED_MODELS
from gearcheck.lumped.side import LumpedSide, PublishedSide
from gearcheck.lumped.time_solver import step_limits
from gearcheck.mbd_models.side import MujocoSide, PublishedTwinSide
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.results import train_signals
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.stepping import transient_step
from gearcheck.shared.units import rad_s_to_rpm

MODELS = ("general",) + PUBLISHED_MODELS
AGAINST = ("lumped", "mujoco")
USER = "user"  # the model the train file registers (train.user_model)
GENERAL_DURATION = 0.1  # s, default simulated time of a train
PUBLISHED_DURATION = 0.02  # s, of the 4-DOF models' start-stop transient


def crosscheck(train, *, speed: float | None = None, duration: float | None = None, model="general",
               against: str = "lumped", results=None, columns=None, modes=None, dt_lumped: float | None = None,
               dt_mujoco: float | None = None, tolerances=None, measurements=None,
               sensor_band: tuple[float, float] | None = None, baseline=None, update_baseline: bool = False,
               progress=None) -> CrosscheckResult:
    """Cross-check a train's lumped model against its MuJoCo twin.

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
        ``"general"`` (gearcheck's lumped model against its MuJoCo twin); a 4-DOF model of Matejic et al.
        (2021) against the twin of its own idealisation: ``"as-published"``, ``"energy-derived"``,
        ``"energy-derived-axis"``, ``"consistent"``; or a user's model, checked against ``against``: a
        :class:`~gearcheck.lumped.linear_model.LinearModel`, a ``.mat``/``.npz`` file of matrices,
        ``"module:factory"`` / ``"file.py:factory"``, a side (:mod:`gearcheck.compare.engine.user_model`), or
        ``"user"``: the one the train file registers (``train.user_model``).
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
        Rewrite ``baseline`` with this run instead of comparing.
    progress : callable, optional
        Called with the fraction done.

    Returns
    -------
    CrosscheckResult
        ``.verdict`` ("PASS", "FAIL" or "INCONCLUSIVE"), ``.failures``, ``.unresolved``, ``.quantities`` (``result[name]``),
        ``.measurements``, ``.moved`` (metrics moved from the baseline), ``.write(directory)``.
    """
    if against not in AGAINST:
        raise GearcheckError(f"--against {against!r}: choose {' or '.join(AGAINST)}")
    spec = load_train(train, speed)
    if results is not None:
        if not (isinstance(model, str) and model == "general"):
            raise GearcheckError("--results gives the model checked: leave --model out")
        if columns is None:
            raise GearcheckError("--results needs --columns, the map of its columns to gearcheck's signals")
        user = RecordedSide(spec, results, columns, modes)
        duration = user.duration if duration is None else duration
    elif isinstance(model, str) and model == USER:
        if spec.user_model is None:
            raise GearcheckError(f"--model user: {spec.name} registers no user_model (train.user_model in its file)")
        user = user_side(spec.user_model, spec)
    elif isinstance(model, str) and model in MODELS:
        user = None
    elif isinstance(model, str) and ":" not in model and Path(model).suffix not in SUFFIXES:
        if Path(model).suffix:
            raise GearcheckError(f"--model {model}: a model file is {' or '.join(SUFFIXES)}, "
                                 f"not {Path(model).suffix!r}")
        raise GearcheckError(f"unknown model {model!r}: choose one of {', '.join(MODELS)}, or give your own: a model "
                             f"file ({' or '.join(SUFFIXES)}), module:factory or file.py:factory")
    else:
        user = user_side(model, spec)
    if sensor_band is not None and not 0 < sensor_band[0] < sensor_band[1]:
        raise GearcheckError(f"sensor band {sensor_band[0]:g} {sensor_band[1]:g} Hz: needs 0 < LOW < HIGH")
    tol = Tolerances.for_train(spec, tolerances)
    path = _baseline_path(baseline, spec.name)
    stored = read_baseline(path) if path is not None and not update_baseline else None
    if duration is None:
        default = PUBLISHED_DURATION if model in PUBLISHED_MODELS else GENERAL_DURATION
        duration = default if stored is None else stored["duration_s"]
    if stored is not None:  # before the run: a mismatch is refused at once
        check_settings(stored, duration, rad_s_to_rpm(spec.operating.input_speed))
    if model == "general" or user is not None:
        lumped = LumpedSide(spec)
        reference, test = lumped, MujocoSide(spec)
        settings = (RunSettings(duration, dt_lumped), RunSettings(duration, dt_mujoco))
        notes = []
        if user is not None:
            reference = lumped if against == "lumped" else test
            test = user
            settings = (settings[0 if against == "lumped" else 1], RunSettings(duration))
            missing = user.unmapped() if hasattr(user, "unmapped") else []
            if missing:
                notes.append(f"{user.solver} does not report {len(missing)} of the train's gated quantities "
                             f"(not compared): {', '.join(missing)}.")
        plan = TrainPlan.of(spec, lumped.model.kin, step_limits(lumped.model).omega_max, duration,
                            settling_time(lumped.model, STEADY_THRESHOLD))
    else:
        reference, test = PublishedSide(spec, model), PublishedTwinSide(spec, model)
        modes_a, modes_b = reference.modes(), test.modes()
        dt = transient_step(np.concatenate([modes_a.frequencies, modes_b.frequencies]))
        p = reference.model.params
        operating = {"input_speed_rpm": rad_s_to_rpm(p.input_speed),
                     "output_torque_nm": p.output_torque if reference.load else 0.0, "model": model,
                     "load": reference.load, "planet_sets": reference.planet_sets,
                     "rigid_modes": {"lumped": modes_a.types.count("rigid"), "mujoco": modes_b.types.count("rigid")}}
        plan = TransientPlan(modes_a.frequencies, dt, operating)
        settings = (RunSettings(duration, dt),) * 2
        notes = [FINDING]
    entries = list(spec.measurements)
    if measurements is not None:
        entries += load_measurements(measurements) if isinstance(measurements, (str, Path)) else list(measurements)
    quantities = ([f"{label}.acceleration" for label in LABELS] if model in PUBLISHED_MODELS
                  else [s.name for s in train_signals(spec) if s.compared])
    tol.check(quantities)
    check_quantities(entries, quantities)  # before the runs: a wrong name is refused at once
    if duration < MIN_CYCLES * plan.cycle:
        raise GearcheckError(f"duration {duration:g} s is shorter than a cycle of {plan.cycle:.4g} s (the slowest mesh "
                             f"of {spec.name}, or its lowest mode), the least a comparison needs")
    result = compare(spec, reference, test, plan, settings, tol, sensor_band, progress)
    result.notes = notes + result.notes
    if user is not None and result.modal_results[1] is not None and hasattr(user, "physical_modes"):
        result.diagnosis = diagnose_side(lumped.model, user, result.modal_results[1])
        result.notes += [f"Diagnosis: {line}" for line in result.diagnosis.lines()]
    attach(result, entries)
    if path is not None and update_baseline:
        write_baseline(result, path)
    elif stored is not None:
        result.moved = compare_to_baseline(result, stored)
    return result


def _baseline_path(baseline, name: str) -> Path | None:
    if baseline is None:
        return None
    if str(baseline) == "shipped":
        return BASELINE_DIR / f"{name}.json"
    return Path(baseline)
