"""The cross-check engine: two models of one train, the reference a and the test b, compared.

Any pair of :class:`~gearcheck.shared.side.Side` objects, read by a comparison plan
(:mod:`gearcheck.compare.plan`):

1. natural frequencies of both, mode by mode;
2. time runs of both (each from its own static state, or from rest);
3. every signal the reference gates and the test has, put on one grid: anti-aliased resampling at
   the lower of the two output rates (:func:`gearcheck.compare.align.resample`), or the grid the two
   share, sample by sample;
4. the window: from the later of the two steady-state starts found by the mesh-cycle detector on
   the mesh forces (:func:`gearcheck.compare.align.steady_start`), or the whole record of a
   transient;
5. per signal, lag-aligned waveform metrics, spectral lines and a verdict against the tolerances;
   signals negligible in both runs (below ``NEGLIGIBLE`` of the largest of their kind, e.g.
   central-member translations that mesh phasing cancels, or below the plan's floor of what a
   solver resolves) are reported as such and not gated.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from gearcheck.compare.align import resample, sensor_filter, steady_start, uniform_grid
from gearcheck.compare.metrics import modal_metrics, spectral_metrics, waveform_metrics
from gearcheck.compare.tolerances import Tolerances
from gearcheck.shared.errors import SolverError
from gearcheck.shared.outputs import OutputDirectory
from gearcheck.shared.settings import RunSettings

NEGLIGIBLE = 1e-6
SIDE_SETTINGS = ("method", "dt_s", "steps", "rotating_frame_terms")  # what the report states of the reference run


@dataclass
class QuantityComparison:
    name: str
    kind: str
    unit: str
    description: str
    status: str  # pass | fail | negligible
    metrics: dict
    spectrum: list[dict]
    tolerance: float | None
    measured: list[dict] = field(default_factory=list)


@dataclass
class CrosscheckResult:
    """Everything a cross-check found; :func:`gearcheck.compare.report.write_report` writes it."""

    spec: object
    settings: dict
    modal: list[dict]
    modal_tolerance: float
    quantities: list[QuantityComparison]
    steady_start_s: float
    steady_found: bool
    results: tuple  # (reference TimeResult, test TimeResult)
    modal_results: tuple  # (reference ModalResult, test ModalResult)
    grid: np.ndarray
    series: dict  # quantity -> (a, b) on the grid
    wall_times: dict
    measurements: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # findings stated in plain words in the report
    references: list[str] = field(default_factory=list)  # keys of gearcheck.shared.citations.REFERENCES
    moved: list[str] | None = None  # metrics moved from a baseline (None: no baseline checked)

    @property
    def failures(self) -> list[str]:
        bad = [q.name for q in self.quantities if q.status == "fail"]
        bad += [f"mode {m['mode']}" for m in self.modal if m["rel_error"] > self.modal_tolerance]
        return bad

    @property
    def passed(self) -> bool:
        """Every tolerance met and, when a baseline was checked, nothing moved from it."""
        return not self.failures and not self.moved

    @property
    def verdict(self) -> str:
        return "PASS" if self.passed else "FAIL"

    def __getitem__(self, name: str) -> QuantityComparison:
        for q in self.quantities:
            if q.name == name:
                return q
        raise KeyError(f"no compared quantity {name!r}")

    def write(self, directory) -> dict:
        """Write report.json, report.md, report.html and the figures as the folder ``directory``, whole or
        not at all (:class:`~gearcheck.shared.outputs.OutputDirectory`); returns the report's data."""
        from gearcheck.compare.report import write_report

        with OutputDirectory(directory, "directory") as place:
            return write_report(self, place.path)


def compare(spec, reference, test, plan, settings: tuple[RunSettings, RunSettings], tolerances: Tolerances,
            sensor_band: tuple[float, float] | None = None, progress=None) -> CrosscheckResult:
    """Cross-check ``test`` against ``reference`` (two :class:`~gearcheck.shared.side.Side`) as ``plan`` reads
    them; ``settings`` the two runs' settings (the same duration; each side's own step by default).

    sensor_band: (low, high) Hz of an accelerometer chain applied to both runs' accelerations.
    progress: callable(fraction) over both runs.
    """
    wall = {}
    started = time.perf_counter()
    modes_a = reference.modes()
    wall["lumped_modes_s"] = time.perf_counter() - started
    started = time.perf_counter()
    modes_b = test.modes()
    wall["mujoco_modes_s"] = time.perf_counter() - started
    if len(modes_a) != len(modes_b):
        raise SolverError(f"the models have different numbers of modes ({len(modes_a)} {reference.solver}, "
                          f"{len(modes_b)} {test.solver})")
    modal_rows = modal_metrics(modes_a.frequencies, modes_b.frequencies, modes_a.types, modes_b.types,
                               modes_a.multiplicity)

    runs = []
    for i, (side, run_settings) in enumerate(zip((reference, test), settings)):
        report = (lambda f, i=i: progress(0.5 * (i + f))) if progress else None
        started = time.perf_counter()
        runs.append(side.run(run_settings, report))
        wall[("lumped_run_s", "mujoco_run_s")[i]] = time.perf_counter() - started
    a, b = runs

    names = [n for n in a.names(compared=True) if n in b]
    if plan.resample:
        fs = min(_rate(a.t), _rate(b.t))
        grid = uniform_grid(0.0, min(a.t[-1], b.t[-1]), fs)
        series = {n: (resample(a.t, a[n], grid), resample(b.t, b[n], grid)) for n in names}
    else:  # one shared step grid, sample by sample
        n_t = min(a.t.size, b.t.size)
        grid, fs = a.t[:n_t], 1.0 / a.info["dt_s"]
        series = {n: (a[n][:n_t], b[n][:n_t]) for n in names}
    if sensor_band is not None:
        low, high = sensor_band
        if not (0 < low < high < 0.5 * fs):
            raise SolverError(f"sensor band {low:g}-{high:g} Hz must lie inside (0, {0.5 * fs:.6g}) Hz")
        for n in names:
            if a.signal(n).kind in ("acceleration", "angular_acceleration"):
                series[n] = tuple(sensor_filter(x, fs, sensor_band) for x in series[n])

    found, t0 = False, 0.0
    if plan.detect_steady:
        forces = a.names("mesh_force", compared=True)
        starts = [steady_start(grid, np.stack([series[n][i] for n in forces], axis=1), plan.cycle) for i in (0, 1)]
        found = all(s is not None for s in starts)
        t0 = max(starts) if found else 0.5 * grid[-1]
    window = grid >= t0

    scale: dict[str, float] = {}
    for n in names:
        kind = a.signal(n).kind
        rms = max(float(np.sqrt(np.mean(x[window] ** 2))) for x in series[n])
        scale[kind] = max(scale.get(kind, 0.0), rms)
        for other, factor in plan.scale_from(n):
            scale[other] = max(scale.get(other, 0.0), rms * factor)

    comparisons = []
    for n in names:
        s = a.signal(n)
        xa, xb = series[n][0][window], series[n][1][window]
        metrics = waveform_metrics(xa, xb, fs, max_lag=plan.max_lag(n))
        lines = [(label, f) for label, f in plan.lines(n, xa.size / fs) if f < 0.45 * fs]
        tol = tolerances.lookup(n, s.kind, "nrmse")
        status = verdict(metrics, tol, max(NEGLIGIBLE * scale[s.kind], plan.floors.get(s.kind, 0.0)) / NEGLIGIBLE)
        comparisons.append(QuantityComparison(n, s.kind, s.unit, s.description, status, metrics,
                                              spectral_metrics(xa, xb, fs, lines), tol))

    run_settings = {
        "duration_s": settings[0].duration, **plan.operating,
        "lumped": {k: a.info[k] for k in SIDE_SETTINGS if k in a.info},
        "mujoco": {k: v for k, v in b.info.items() if k != "wall_time_s" and _plain(v)},
        "common_sample_rate_hz": fs, "steady_cycle_s": plan.cycle,
        "sensor_band_hz": list(sensor_band) if sensor_band else None,
        "tolerances": dict(sorted(tolerances.values.items())),
    }
    references = list(getattr(spec, "references", ())) + list(reference.references) + list(test.references)
    return CrosscheckResult(spec, run_settings, modal_rows, tolerances.lookup("modes", "frequency", "rel_error"),
                            comparisons, t0, found, (a, b), (modes_a, modes_b), grid, series, wall,
                            references=list(dict.fromkeys(references)))


def verdict(metrics: dict, tolerance: float | None, scale: float) -> str:
    """negligible (below NEGLIGIBLE x the largest of its kind in both solvers), pass or fail on NRMSE."""
    if max(metrics["reference"]["rms"], metrics["test"]["rms"]) < NEGLIGIBLE * scale:
        return "negligible"
    if tolerance is None or (metrics["nrmse"] is not None and metrics["nrmse"] <= tolerance):
        return "pass"
    return "fail"


def _plain(value) -> bool:
    return isinstance(value, (int, float, str, bool)) or value is None


def _rate(t: np.ndarray) -> float:
    return (t.size - 1) / (t[-1] - t[0])
