"""Least-squares calibration of uncertain train parameters against measured amplitudes and natural frequencies.

A parameter is addressed by its path in the train file, in the file's own units
(``stages[0].mesh.ste[0].amplitude_um``, ``operating.output_torque``), with bounds.  The fit
minimises sum_i ((ln y_i(p) - ln m_i)/s_i)^2 over ln p, m_i the measured value and s_i its relative
uncertainty (``uncertainty``): relative errors, and positive parameters by construction.  y_i is

* for an amplitude, the lumped model's statistic of measurement i read through its measuring chain
  (:func:`gearcheck.compare.engine.measure.measure`), from a time run;
* for a natural frequency, the frequency of the model mode it is paired with
  (:mod:`gearcheck.compare.studies.measured_modes`), from the modes alone; a measured shape adds the residual
  (1 - MAC)/s_shape of its share in that mode (the updating residuals of Friswell & Mottershead 1995).

Parameter uncertainties come from the Jacobian at the optimum, cov(ln p) = (J^T J)^-1 with the residuals already
divided by s_i; they are the measurement uncertainties propagated, valid also when the fit is exactly determined
(as many measurements as parameters), where the residuals carry no information.  A fit of natural frequencies is
not convex (modes cross and swap order as parameters move): it runs from several starts
(:mod:`gearcheck.compare.studies.multistart`) and reports the distinct minima.

The honest protocol for a paper's table: fit on the measurements at one speed (``fit_speeds``; a natural
frequency's ``role``), then predict the others and report the prediction errors.
"""

from __future__ import annotations

import copy
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import tomli_w

from gearcheck.compare.engine.align import STEADY_THRESHOLD
from gearcheck.compare.engine.measure import MIN_CYCLES, measure
from gearcheck.compare.studies.measured_modes import Paired, label, pair
from gearcheck.compare.studies.multistart import MultiStart, multistart
from gearcheck.lumped.assembly import build_model
from gearcheck.train.kinematics import kinematics, require_mesh_cycle
from gearcheck.train.loader import load_text, load_train
from gearcheck.lumped.modal import modes, settling_time
from gearcheck.train.spec import beside, named_file
from gearcheck.lumped.time_solver import simulate
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.units import rad_s_to_rpm

SPEED_MATCH = 1e-6
MAX_STARTS = 1000  # every start is a whole fit: a thousand of a time-run fit's hundred runs is days
STARTS = 16  # the default number of starts of a fit that needs no time run: the file's values and a Latin
# hypercube of 15: cheap (a few ms an evaluation), and enough to reach the basins of a handful of parameters
LOG_STEP = 0.05  # finite-difference step in ln p: a peak of a simulated signal is only piecewise smooth
# in the parameters, so a 5 % step sees the trend, not the jitter of which sample is the largest


@dataclass
class FitParameter:
    """A number of a train file addressed by its path (``stages[0].sun.mass``), given by the Python argument
    ``argument``, which its messages name (``fit=stages[0].sun.mass: ...``; the command line names its flag
    instead: :func:`gearcheck.cli.as_flags`)."""

    path: str
    low: float
    high: float
    keys: list = field(default_factory=list)
    argument: str = "fit"

    @classmethod
    def parse(cls, text: str, argument: str = "fit") -> "FitParameter":
        """``PATH`` or ``PATH=LOW:HIGH`` (bounds in the file's units; default 1/100 to 100 times the file's
        value, which is the start; a value outside the bounds starts at their geometric mean)."""
        path, _, bounds = text.partition("=")
        keys = []
        for part in path.split("."):
            m = re.fullmatch(r"([A-Za-z_][\w\-]*)((?:\[\d+\])*)", part)
            if not m:
                raise GearcheckError(f"{argument}={text!r}: {part!r} is not a key or key[index]")
            keys.append(m.group(1))
            keys += [int(i) for i in re.findall(r"\[(\d+)\]", m.group(2))]
        low = high = math.nan
        if bounds:
            try:
                low, high = (float(b) for b in bounds.split(":"))
            except ValueError:
                raise GearcheckError(f"{argument}={text!r}: bounds must be LOW:HIGH numbers") from None
            if not (0 < low < high and math.isfinite(high)):
                raise GearcheckError(f"{argument}={text!r}: need 0 < LOW < HIGH")
        return cls(path, low, high, keys, argument)

    def get(self, document):
        node = document
        try:
            for k in self.keys:
                node = node[k]
        except (KeyError, IndexError, TypeError):
            raise GearcheckError(f"{self.argument}={self.path}: no such field in the train file") from None
        if isinstance(node, bool) or not isinstance(node, (int, float)):
            raise GearcheckError(f"{self.argument}={self.path}: {node!r} is not a number")
        if node <= 0:
            raise GearcheckError(f"{self.argument}={self.path}: the value {node} must be positive (it is varied "
                                 "in proportion)")
        return float(node)

    def set(self, document, value: float) -> None:
        node = document
        for k in self.keys[:-1]:
            node = node[k]
        node[self.keys[-1]] = value


REFERENCES = (("train", "measurements_file"), ("train", "user_model"), ("operating", "torque_csv"))  # named files


@dataclass
class Calibration:
    names: list[str]
    start: np.ndarray
    fitted: np.ndarray
    relative_uncertainty: np.ndarray  # standard uncertainty of each fitted value, relative
    entries: list[dict]  # the amplitudes
    speeds_rpm: list[float]
    used: list[bool]  # which amplitudes the fit used
    before: list[float]  # model statistics with the start values
    after: list[float]  # with the fitted values
    evaluations: int
    document: dict  # the calibrated train file, parsed
    source: str  # where the original came from (its relative file references are resolved from there)
    header: str
    frequencies: list[dict] = field(default_factory=list)  # the natural frequencies
    frequencies_before: list[Paired] = field(default_factory=list)
    frequencies_after: list[Paired] = field(default_factory=list)
    search: MultiStart | None = None  # the fits from every start, in ln p

    def _named_files(self) -> list[tuple[str, str, str, Path, str]]:
        """(table, key, the copy's name, the original, what follows the file) of each file the train file names
        (measurements, a user model, a torque table): the copy takes the original's name (its key's before it
        where two names meet)."""
        out = []
        for table, key in REFERENCES:
            named = named_file(self.document.get(table, {}).get(key))
            if named is not None:
                path = beside(self.source, named[0])
                copy_name = path.name if path.name not in {o[2] for o in out} else f"{key}-{path.name}"
                out.append((table, key, copy_name, path, named[1]))
        return out

    def files(self) -> dict[str, Path]:
        """The files the train file names by the names the calibrated file gives them, beside it (:meth:`text`),
        so that the calibrated file is whole in its folder (a train file names no file outside its folder unless
        the user allows it)."""
        return {copy_name: path for _, _, copy_name, path, _ in self._named_files()}

    def text(self) -> str:
        """The calibrated train file, naming the files of :meth:`files` by their names there."""
        doc = copy.deepcopy(self.document)
        for table, key, copy_name, _, rest in self._named_files():
            doc[table][key] = copy_name + rest
        return self.header + tomli_w.dumps(doc)

    def rows(self) -> list[dict]:
        """Every measurement against the model before and after the fit: the amplitudes, then the natural
        frequencies (with the model mode each is paired with after the fit, numbered from 1, and its MAC)."""
        out = []
        for entry, rpm, used, b, a in zip(self.entries, self.speeds_rpm, self.used, self.before, self.after):
            out.append(_row(entry, entry["quantity"], entry["metric"], rpm, b, a, used))
        for entry, b, a in zip(self.frequencies, self.frequencies_before, self.frequencies_after):
            row = _row({**entry, "value": entry["frequency_hz"]}, label(entry), "frequency_hz", None, b.frequency,
                       a.frequency, entry["role"] == "fit")
            out.append({**row, "model_mode": a.mode + 1, "mac": a.mac})
        return out

    @property
    def starts_at_best(self) -> int:
        """How many starts reached the best minimum."""
        return self.search.minima[0].starts


def _row(entry, quantity, metric, rpm, before, after, used) -> dict:
    m, published = entry["value"], entry.get("published_model")
    return {"quantity": quantity, "metric": metric, "speed_rpm": rpm, "measured": m, "published_model": published,
            "before": before, "after": after, "error_before": (before - m) / abs(m),
            "error_after": (after - m) / abs(m),
            "error_published_model": None if published is None else (published - m) / abs(m),
            "role": "fit" if used else "prediction"}


def _speeds(entries, default_rpm):
    out = []
    for e in entries:
        speed = e.get("speed")  # rad/s
        out.append(default_rpm if speed is None else rad_s_to_rpm(speed))
    return out


def default_starts(entries) -> int:
    """How many starts a fit takes unless told: :data:`STARTS` when it needs the modes alone, 1 (the file's values)
    when amplitudes need a time run per evaluation."""
    return 1 if entries else STARTS


def calibrate(text: str, source: str, entries: list[dict], fits: list[FitParameter], duration: float,
              fit_speeds: list[float] | None = None, progress=None, frequencies: list[dict] = (),
              starts: int | None = None) -> Calibration:
    """Fit ``fits`` of the train file ``text`` to the amplitude ``entries`` and the natural ``frequencies``
    (lumped solver) from ``starts`` starting points (default :func:`default_starts`)."""
    document = tomllib.loads(text)
    frequencies = list(frequencies)
    if not entries and not frequencies:
        raise GearcheckError("calibrate needs measurements: the train file's [[measurements]] or measurements=")
    base_spec = load_text(text, source)
    rpm = _speeds(entries, rad_s_to_rpm(base_spec.operating.input_speed))
    used = [fit_speeds is None or any(abs(r - f) <= SPEED_MATCH * f for f in fit_speeds) for r in rpm]
    if entries:
        _check_time_runs(base_spec, rpm, duration)
    if entries and not any(used) and fit_speeds is not None:
        raise GearcheckError(f"no measurement at the fit speeds {fit_speeds} rpm (have {sorted(set(rpm))})")
    fitted_frequencies = [i for i, e in enumerate(frequencies) if e["role"] == "fit"]
    if not any(used) and not fitted_frequencies:
        raise GearcheckError("nothing to fit: every natural frequency has role = 'predict'")
    count = default_starts(entries) if starts is None else starts
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_STARTS:
        raise GearcheckError(f"starts={count!r}: must be a whole number from 1 to {MAX_STARTS}")
    start = np.array([f.get(document) for f in fits])
    for i, (f, x0) in enumerate(zip(fits, start)):
        if math.isnan(f.low):
            f.low, f.high = x0 / 100, x0 * 100
        if not f.low <= x0 <= f.high:  # the file's value lies outside the bounds: start in their middle
            start[i] = math.sqrt(f.low * f.high)
    evaluations = 0

    def model(values, which) -> tuple[list[float], list[Paired]]:
        """The amplitudes ``which`` (the others NaN) and the paired natural frequencies at ``values``."""
        doc = tomllib.loads(text)
        for f, v in zip(fits, values):
            f.set(doc, float(v))
        spec = load_text(tomli_w.dumps(doc), source)
        out = [math.nan] * len(entries)
        for speed in sorted({rpm[i] for i in which}):
            lumped = build_model(load_train(spec, speed))
            result = simulate(lumped, RunSettings(duration))
            cycle = 1.0 / float(np.min(lumped.excitation.frequency))
            idx = [i for i in which if rpm[i] == speed]
            settle = settling_time(lumped, STEADY_THRESHOLD)
            for i, value in zip(idx, measure(result, [entries[i] for i in idx], cycle, settle)):
                out[i] = value
            counted()
        paired = []
        if frequencies:
            lumped = build_model(spec)
            paired = pair(frequencies, modes(lumped), lumped.dofs.labels(), lumped.M)
            counted()
        return out, paired

    def counted():
        nonlocal evaluations
        evaluations += 1
        if progress is not None:
            progress(evaluations)

    fit_idx = [i for i, u in enumerate(used) if u]
    measured = np.log([entries[i]["value"] for i in fit_idx]
                      + [frequencies[i]["frequency_hz"] for i in fitted_frequencies])
    sigma = np.array([entries[i]["uncertainty"] for i in fit_idx]
                     + [frequencies[i]["uncertainty"] for i in fitted_frequencies])
    shaped = [i for i in fitted_frequencies if frequencies[i]["shape"] is not None]
    shape_sigma = np.array([frequencies[i]["shape_uncertainty"] for i in shaped])

    def residual(log_values):
        amplitudes, paired = model(np.exp(log_values), fit_idx)
        y = [amplitudes[i] for i in fit_idx] + [paired[i].frequency for i in fitted_frequencies]
        mismatch = (np.log(np.maximum(y, 1e-300)) - measured) / sigma
        return np.concatenate([mismatch, [(1 - paired[i].mac) / s for i, s in zip(shaped, shape_sigma)]])

    low, high = np.log([f.low for f in fits]), np.log([f.high for f in fits])
    if fit_idx:  # time runs: a coarse step and tolerances (LOG_STEP)
        options = {"diff_step": LOG_STEP, "xtol": 1e-4, "ftol": 1e-6}
    else:  # smooth in ln p: central differences, which also make the uncertainties accurate to ~1e-8
        options = {"jac": "3-point", "xtol": 1e-12, "ftol": 1e-12, "gtol": 1e-12}
    search = multistart(residual, np.log(start), low, high, count,
                        x_scale=1.0, **options)
    solution = search.best
    fitted = np.exp(solution.x)
    J = solution.jac
    try:
        cov = np.linalg.inv(J.T @ J)
        rel_unc = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        rel_unc = np.full(len(fits), math.inf)
    everything = list(range(len(entries)))
    before, frequencies_before = model(start, everything)
    after, frequencies_after = model(fitted, everything)
    doc = tomllib.loads(text)
    for f, v in zip(fits, fitted):
        f.set(doc, float(v))
    header = (f"# Calibrated by `gearcheck calibrate` from {source}: "
              + ", ".join(f"{f.path} = {v:.6g}" for f, v in zip(fits, fitted))
              + ".\n# The original file carries the comments that document every value.\n")
    return Calibration([f.path for f in fits], start, fitted, rel_unc, entries, rpm, used, before, after,
                       evaluations, doc, source, header, frequencies, frequencies_before, frequencies_after, search)


def _check_time_runs(spec, rpm: list[float], duration: float) -> None:
    """Refuse amplitudes the train cannot simulate, or a run too short for a cycle of the slowest mesh."""
    require_mesh_cycle(spec, "a calibration (its time runs)")
    cycle = 1.0 / min(kinematics(spec).mesh_frequency.values()) * rad_s_to_rpm(spec.operating.input_speed) / min(rpm)
    if duration < MIN_CYCLES * cycle:
        raise GearcheckError(f"duration {duration:g} s is shorter than a cycle of the slowest mesh ({cycle:.4g} s), "
                             "the least a measured statistic needs")
