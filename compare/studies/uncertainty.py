"""Monte Carlo of calibrate-then-predict: the band of a prediction over stated parameter distributions.

A calibrated prediction (:func:`gearcheck.compare.studies.calibrate.calibrate`: fit some train-file numbers on the
measurements at one speed, predict another speed) still rests on the numbers that were neither measured nor
fitted.  :func:`uncertainty_study` draws those from stated distributions (``normal``, ``uniform``,
``lognormal`` of :mod:`gearcheck.compare.studies.distributions`, in the train file's own units), and in every sample
repeats the whole protocol: the same least-squares fit at the fit speed, from the same start and within the
same bounds, then the lumped model's statistic of every measurement at the prediction speed through its
measuring chain (:func:`gearcheck.compare.engine.measure.measure`).  One row per sample: the drawn values, the fitted
values, the fit's residuals at the fit speed and the predictions.

* Draws are deterministic and prefix-stable: sample ``i`` of seed ``s`` draws from its own generator
  (:func:`gearcheck.compare.studies.distributions.draw_samples`), whatever the number of workers, so the table depends
  on the seed alone.
* ``scale_damping``: a drawn ``X_stiffness`` (a bearing's ``radial_stiffness``, a support's
  ``torsional_stiffness``, ``input_shaft_stiffness``) scales its sibling ``X_damping`` by sqrt(k / k_file), so
  the damping ratio the file chose stays (c = 2 zeta sqrt(k m)); mesh damping given as a ratio follows the mesh
  stiffness by itself.
* The run's duration follows each sample's start-up decay (:func:`gearcheck.lumped.modal.settling_time`): a
  sample whose free vibration takes longer to decay than the file's runs longer by as much, so its steady
  window keeps at least the length the nominal window has (``duration`` minus the file's decay time).
* A sample the solver or the loader refuses (a drawn value out of a field's range, say) is a row with its
  ``error`` and no numbers; a distribution or field that cannot be used is refused before any run.

:func:`band` and :func:`drivers` reduce the table: percentiles with their Monte Carlo standard errors, and
Spearman rank correlations and standardised rank-regression coefficients of each drawn number with each
prediction (which uncertain numbers drive the spread).
"""

from __future__ import annotations

import math
import time
import tomllib
from dataclasses import dataclass

import numpy as np
import pandas as pd
import tomli_w

from gearcheck.compare.studies import point_backends as backends
from gearcheck.compare.studies.calibrate import SPEED_MATCH, FitParameter, calibrate
from gearcheck.compare.studies.distributions import Distribution, draw_samples
from gearcheck.compare.studies.sweep import Field
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_text, load_train
from gearcheck.lumped.modal import settling_time
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.units import checked_rpm, rad_s_to_rpm

NOMINAL = -1  # the ``sample`` of the row with the file's own values (``nominal=True``)
STEADY_FRACTION = 2e-3  # the calibration's decay threshold (gearcheck.compare.engine.align.STEADY_THRESHOLD)


def _label(entry) -> str:
    return f"{entry['quantity']}.{entry['metric']}"


def _rpm(entry, default: float) -> float:
    speed = entry.get("speed")
    return default if speed is None else rad_s_to_rpm(speed)


@dataclass(frozen=True)
class _Task:
    """What one sample needs (picklable: it travels to a worker process)."""

    sample: int
    seed: int | None
    values: tuple  # ((path, value), ...) drawn; empty for the nominal sample
    text: str
    source: str
    entries: tuple
    fits: tuple  # the ``fits`` texts, parsed afresh per sample (FitParameter keeps state)
    fit_speed: float
    predict_speed: float
    duration: float
    window: float
    scale_damping: bool


def _sample_text(task: _Task) -> str:
    document = tomllib.loads(task.text)
    for path, value in task.values:
        value = float(value)
        field = Field.parse(path, "distributions")
        old = field.check(document)
        field.set(document, value)
        if task.scale_damping and old and path.endswith("_stiffness"):
            sibling = Field.parse(path[: -len("_stiffness")] + "_damping", "distributions")
            try:
                c = sibling.check(document)
            except GearcheckError:
                c = None
            if c:
                sibling.set(document, c * math.sqrt(value / old))
    return tomli_w.dumps(document)


def _settle(text: str, source: str, speeds) -> float:
    spec = load_text(text, source)
    return max(settling_time(build_model(load_train(spec, rpm)), STEADY_FRACTION) for rpm in speeds)


def run_sample(task: _Task) -> dict:
    """One row: draw applied, fit at ``fit_speed``, prediction at ``predict_speed``."""
    row = {"sample": task.sample, "seed": task.seed}
    for path, value in task.values:
        row[f"sampled:{path}"] = value
    try:
        text = _sample_text(task)
        settle = _settle(text, task.source, (task.fit_speed, task.predict_speed))
        duration = max(task.duration, settle + task.window)
        fits = [FitParameter.parse(f, "fits") for f in task.fits]
        result = calibrate(text, task.source, list(task.entries), fits, duration, [task.fit_speed])
    except GearcheckError as exc:
        row["error"] = str(exc).splitlines()[0]
        return row
    for f, value, rel in zip(fits, result.fitted, result.relative_uncertainty):
        row[f"fitted:{f.path}"] = float(value)
        row[f"fit_uncertainty:{f.path}"] = float(rel)
    row["at_bound"] = ", ".join(f.path for f, v in zip(fits, result.fitted)
                                if not f.low * (1 + 1e-6) < v < f.high * (1 - 1e-6))
    cost = 0.0
    for entry, rpm, used, after in zip(result.entries, result.speeds_rpm, result.used, result.after):
        m = entry["value"]
        if used:
            row[f"fit_error:{_label(entry)}"] = (after - m) / abs(m)
            cost += ((math.log(max(after, 1e-300)) - math.log(m)) / entry["uncertainty"]) ** 2
        elif abs(rpm - task.predict_speed) <= SPEED_MATCH * task.predict_speed:
            row[f"predicted:{_label(entry)}"] = after
            row[f"prediction_error:{_label(entry)}"] = (after - m) / abs(m)
    row["fit_cost"] = cost
    row["runs"] = result.evaluations
    row["settle_s"] = settle
    row["duration_s"] = duration
    row["error"] = ""
    return row


def _parse_distributions(distributions: dict, document: dict, fit_paths: set) -> dict[str, Distribution]:
    if not isinstance(distributions, dict) or not distributions:
        raise GearcheckError("distributions: need at least one FIELD -> distribution, e.g. "
                             "{'stages[0].mesh.damping.ratio': 'uniform(0.03, 0.17)'}")
    out = {}
    for path, law in distributions.items():
        field = Field.parse(str(path), "distributions")
        field.check(document)
        if path in fit_paths:
            raise GearcheckError(f"distributions={path}: it is also fitted (fits=); a field is either drawn or "
                                 "fitted")
        out[path] = law if isinstance(law, Distribution) else Distribution.parse(law, f"distributions={path}")
    return out


def uncertainty_study(text: str, source: str, entries: list[dict], distributions: dict, fits: list[str],
                      fit_speed: float, predict_speed: float, duration: float, samples: int, seed: int = 0,
                      workers: int = 1, progress=None, nominal: bool = False, scale_damping: bool = True,
                      window: float | None = None, first: int = 0) -> pd.DataFrame:
    """Monte Carlo of calibrate-then-predict over ``distributions`` of a train file's numbers.

    ``text``/``source``: the train file (as :func:`gearcheck.train.loader.read_train_text` gives it);
    ``entries``: its measurements (``spec.measurements``: speeds in rad/s); ``distributions``: field path ->
    ``"lognormal(2e9, 1.6)"`` (or a :class:`~gearcheck.compare.studies.distributions.Distribution`), in the file's
    units; ``fits``: ``PATH=LOW:HIGH`` as ``gearcheck calibrate --fit`` takes them, fitted on the measurements at
    ``fit_speed`` rpm; the measurements at ``predict_speed`` rpm are predicted.  ``duration`` s per run (longer
    where a sample's start-up decays more slowly, see the module's notes; ``window`` the least steady window,
    default ``duration`` minus the file's own decay time).  ``samples`` draws of ``seed``, run on ``workers``
    processes (1: in this process); ``progress(done, total, row)`` after each sample; ``nominal`` adds a first
    row (``sample`` = -1) with the file's own values, which is the plain calibration (``samples`` may then be 0);
    ``first``: run samples ``first`` .. ``first + samples - 1`` of the seed's sequence (a study in chunks gives the
    same rows).

    Returns one row per sample, in sample order: ``sample``, ``seed``, ``sampled:PATH``, ``fitted:PATH``,
    ``fit_uncertainty:PATH`` (relative), ``at_bound`` (the fitted paths that ended on a bound),
    ``fit_error:QUANTITY.METRIC`` ((model - measured)/measured at the fit speed), ``fit_cost`` (the fit's sum of
    squared weighted log residuals), ``predicted:QUANTITY.METRIC`` (SI) and ``prediction_error:...`` at the
    prediction speed, ``runs`` (lumped runs of the fit), ``settle_s``, ``duration_s`` and ``error`` ("" when the
    sample ran).  ``attrs`` holds the inputs, the measured and published-model values by label, and ``wall_s``.
    """
    started = time.perf_counter()
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise GearcheckError(f"{source}: not TOML ({exc})") from None
    fit_texts = [str(f) for f in fits]
    parsed_fits = [FitParameter.parse(f, "fits") for f in fit_texts]
    for f in parsed_fits:
        f.get(document)
    laws = _parse_distributions(distributions, document, {f.path for f in parsed_fits})
    fit_speed, predict_speed = checked_rpm(fit_speed, "fit_speed"), checked_rpm(predict_speed, "predict_speed")
    _check_runs(duration, workers)
    default_rpm = rad_s_to_rpm(load_text(text, source).operating.input_speed)
    chosen = _chosen_entries(entries, default_rpm, fit_speed, predict_speed)
    if window is None:
        window = _nominal_window(text, source, duration, (fit_speed, predict_speed))
    if isinstance(first, bool) or not isinstance(first, int) or first < 0:
        raise GearcheckError(f"first {first!r}: needs an integer >= 0")
    if samples == 0 and nominal and not isinstance(samples, bool):  # the plain calibration alone
        draws = []
    else:
        draws = draw_samples(laws, first + samples, seed)[first:]
    common = dict(text=text, source=source, entries=tuple(chosen), fits=tuple(fit_texts), fit_speed=float(fit_speed),
                  predict_speed=float(predict_speed), duration=float(duration), window=float(window),
                  scale_damping=scale_damping)
    tasks = [_Task(NOMINAL, int(seed), (), **common)] if nominal else []
    tasks += [_Task(first + i, int(seed), tuple(d.items()), **common) for i, d in enumerate(draws)]
    rows = _run_tasks(tasks, workers, progress)
    frame = _table(tasks, rows, laws, document if nominal else None)
    frame.attrs.update({
        "source": source, "fits": fit_texts, "distributions": {p: str(d) for p, d in laws.items()},
        "fit_speed": float(fit_speed), "predict_speed": float(predict_speed), "duration": float(duration),
        "window": float(window), "seed": int(seed), "samples": int(samples), "first": int(first),
        "measured": {f"{_label(e)}@{_rpm(e, default_rpm):g}": e["value"] for e in chosen},
        "published_model": {f"{_label(e)}@{_rpm(e, default_rpm):g}": e.get("published_model") for e in chosen},
        "wall_s": time.perf_counter() - started,
    })
    return frame


def _check_runs(duration, workers) -> None:
    """Refuse a duration per run that is not a number > 0, or a number of workers that is not an integer >= 1."""
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 0 < duration < math.inf:
        raise GearcheckError(f"duration {duration!r}: needs a number > 0")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise GearcheckError(f"workers {workers!r}: needs an integer >= 1")


def _chosen_entries(entries, default_rpm: float, fit_speed: float, predict_speed: float) -> list:
    """The measurements at the fit speed or the prediction speed (an entry without a speed is at
    ``default_rpm``, the file's); refused where either speed has none."""

    def at(e, rpm):
        return abs(_rpm(e, default_rpm) - rpm) <= SPEED_MATCH * rpm

    chosen = [e for e in entries if at(e, fit_speed) or at(e, predict_speed)]
    if not any(at(e, fit_speed) for e in chosen):
        raise GearcheckError(f"fit_speed {fit_speed:g} rpm: no measurement at that speed")
    if not any(at(e, predict_speed) for e in chosen):
        raise GearcheckError(f"predict_speed {predict_speed:g} rpm: no measurement at that speed")
    return chosen


def _nominal_window(text: str, source: str, duration: float, speeds) -> float:
    """The steady window the file's own model keeps at ``speeds`` in runs of ``duration``: what is left after its
    start-up decay; refused where nothing is left."""
    window = duration - _settle(text, source, speeds)
    if window <= 0:
        raise GearcheckError(f"duration {duration:g} s: shorter than the start-up decay of the file's model "
                             f"({duration - window:.4g} s); give a longer one")
    return window


def _run_tasks(tasks: list[_Task], workers: int, progress) -> dict[int, dict]:
    """Every task's row by its sample, run in this process (``workers`` 1) or on a pool; ``progress(done, total,
    row)`` after each."""
    rows: dict[int, dict] = {}

    def finished(task, row):
        rows[task.sample] = row
        if progress is not None:
            progress(len(rows), len(tasks), row)

    if workers == 1:
        for task in tasks:
            finished(task, run_sample(task))
    else:
        backends.run_pool(run_sample, tasks, min(workers, len(tasks)), finished)
    return rows


def _table(tasks: list[_Task], rows: dict[int, dict], laws: dict, document: dict | None) -> pd.DataFrame:
    """The rows in sample order, the drawn fields' columns first; with the train file's ``document``, the nominal
    row's drawn columns hold its own values (NaN where it leaves a field to its default)."""
    frame = pd.DataFrame([rows[t.sample] for t in tasks])
    if document is not None:
        for path in laws:
            value = Field.parse(path, "distributions").check(document)
            frame.loc[frame["sample"] == NOMINAL, f"sampled:{path}"] = math.nan if value is None else float(value)
    leading = ["sample", "seed"] + [f"sampled:{p}" for p in laws]
    return frame.reindex(columns=leading + [c for c in frame.columns if c not in leading])


# ----------------------------------------------------------------------------- reductions
def band(values, levels=(5.0, 50.0, 95.0), resamples: int = 2000, seed: int = 0) -> pd.DataFrame:
    """Percentiles ``levels`` of ``values`` (NaN dropped) with their Monte Carlo standard errors, by a bootstrap
    of ``resamples`` (deterministic for ``seed``): one row per level (``level``, ``value``, ``standard_error``)."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if x.size < 2:
        raise GearcheckError(f"band: needs at least 2 finite values, got {x.size}")
    rng = np.random.Generator(np.random.PCG64(seed))
    boot = np.percentile(x[rng.integers(0, x.size, (resamples, x.size))], levels, axis=1)
    return pd.DataFrame({"level": list(levels), "value": np.percentile(x, levels),
                         "standard_error": boot.std(axis=1, ddof=1)})


def _ranks(x: np.ndarray) -> np.ndarray:
    return pd.Series(x).rank().to_numpy()


def drivers(frame: pd.DataFrame, outputs: list[str], inputs: list[str] | None = None) -> pd.DataFrame:
    """Which drawn numbers (or other ``inputs`` columns, such as ``fitted:PATH``) drive each output: per
    (parameter, output) the Spearman rank correlation ``spearman``, the standardised rank-regression coefficient
    ``srrc`` (all inputs at once: the share of the output's rank variance an input carries alone is about
    srrc^2), the regression's ``r2`` and ``r2_adjusted`` (1 - (1 - r2)(n - 1)/(n - p - 1): about 0 where the
    inputs explain no more than p random columns would).  Samples that failed are left out; |spearman| below
    about 2/sqrt(n) is indistinguishable from none."""
    params = inputs if inputs is not None else [c for c in frame.columns if c.startswith("sampled:")]
    ok = frame[(frame["sample"] != NOMINAL) & (frame["error"] == "")]
    rows = []
    for out in outputs:
        y = ok[out].to_numpy(dtype=float)
        keep = np.isfinite(y)
        ry = _ranks(y[keep])
        X = np.column_stack([_ranks(ok[p].to_numpy(dtype=float)[keep]) for p in params])
        Xs = (X - X.mean(axis=0)) / X.std(axis=0)
        ys = (ry - ry.mean()) / ry.std()
        coef, *_ = np.linalg.lstsq(np.column_stack([np.ones(len(ys)), Xs]), ys, rcond=None)
        fitted = np.column_stack([np.ones(len(ys)), Xs]) @ coef
        r2 = 1.0 - float(np.sum((ys - fitted) ** 2) / np.sum(ys**2))
        n = len(ys)
        r2_adjusted = 1.0 - (1.0 - r2) * (n - 1) / (n - len(params) - 1) if n > len(params) + 1 else math.nan
        for j, p in enumerate(params):
            rho = float(np.corrcoef(Xs[:, j], ys)[0, 1])
            rows.append({"parameter": p.removeprefix("sampled:"), "output": out, "spearman": rho,
                         "srrc": float(coef[j + 1]), "r2": r2, "r2_adjusted": r2_adjusted,
                         "n": n})
    return pd.DataFrame(rows)
