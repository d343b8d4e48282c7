"""The cross-check engine: two models of one train, the reference a and the test b, compared.

Any pair of :class:`~gearcheck.shared.side.Side` objects, read by a comparison plan
(:mod:`gearcheck.compare.engine.plan`):

1. natural frequencies of both, mode by mode (a reduced test model's against the reference reduced alike,
   :mod:`gearcheck.compare.engine.reduction`);
2. time runs of both (each from its own static state, or from rest), each twice: at its step h and,
   for the integration error, at 2 h (at h / 2 where 2 h would be unstable);
3. every signal the reference gates and the test has, put on one grid: anti-aliased resampling at
   the lower of the two output rates (:func:`gearcheck.compare.engine.align.resample`), or the grid the two
   share, sample by sample;
4. the window: the steady state (:func:`gearcheck.compare.engine.align.steady_state`: every stage's mesh
   forces steady over their own cycle, or the free vibration of the start decayed), or the whole
   record of a transient.  A run too short to reach it is extended once, to at most
   ``EXTENSION_FACTOR`` times the duration asked for; without a steady state the verdict is
   INCONCLUSIVE;
5. per signal, lag-aligned waveform metrics, spectral lines and a verdict against the tolerances (each run's
   mean, rms, peak-to-peak and peak, and its lines, from its own samples over the window: the anti-aliasing
   filter rings at a jump, and inflated the peak-to-peak of demo-3p's mesh forces by 3 %);
   signals negligible in both runs (below ``NEGLIGIBLE`` of the largest of their kind, e.g.
   central-member translations that mesh phasing cancels, or so small that the plan's round-off
   floor of a solver is more than the tolerance's share of them) are reported as such and not gated;
6. per signal and solver, an estimate of the integration error: the NRMSE of the run against its
   step-doubled twin over 2^p - 1 (:func:`integration_error`, Richardson's estimate for both solvers'
   order p = 4, which holds between the contact events both locate; where doubling the step moves the
   mesh forces by more than ``ASYMPTOTIC`` of their fluctuation, the runs are outside the asymptotic range and the
   change itself is the estimate).  A side that picks its own step
   starts at ``FIRST_STEP_FACTOR`` times its default step (where its check at twice that is stable),
   and the steps are halved as many times as the estimates' h^p law says they must be (at most
   ``MAX_REFINEMENTS``, in one go) until the two solvers' estimates together are within
   ``TARGET_FRACTION`` of every gated tolerance: the largest such step of the sequence.  A quantity
   whose estimates reach its tolerance is *unresolved* (the comparison cannot tell at that
   tolerance, and the verdict is INCONCLUSIVE).
"""

from __future__ import annotations

import logging
import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from gearcheck.compare.engine.align import (
    STEADY_THRESHOLD,
    STEADY_WINDOW_CYCLES,
    resample,
    sensor_filter,
    steady_state,
    uniform_grid,
)
from gearcheck.compare.engine.line_projection import harmonics
from gearcheck.compare.engine.metrics import modal_metrics, spectral_amplitude, spectral_metrics, statistics
from gearcheck.compare.engine.metrics import waveform_metrics
from gearcheck.compare.engine.mode_pairing import pair_modes
from gearcheck.compare.engine.reduction import reduced_reference
from gearcheck.compare.engine.tolerances import Tolerances
from gearcheck.shared.blas import one_blas_thread
from gearcheck.shared.errors import SolverError, UnsupportedError, did_you_mean
from gearcheck.shared.selection import chosen
from gearcheck.shared.outputs import OutputDirectory
from gearcheck.shared.settings import RunSettings
from gearcheck.shared.run_info import RunInfo
from gearcheck.shared.side import display_name
from gearcheck.shared.stepping import ORDER, richardson_factor
from gearcheck.train.spec import TrainSpec

NEGLIGIBLE = 1e-6
ROUND_OFF = 1e-9  # a quantity below this share of the largest of its kind is held at zero (round-off)
SECOND_ORDER = 1e-3  # ... and one the other side moves by less than this share, its second-order motion
COMPARED = (("rel_rms", "1"), ("rel_peak_to_peak", "1"), ("rel_peak", "1"), ("nrmse", "1"), ("nrmse_ac", "1"),
            ("correlation", "1"), ("lag_s", "s"))  # the metrics that compare the two sides of a quantity
TARGET_FRACTION = 0.5  # the steps keep both solvers' integration error estimates within this part of a tolerance
FIRST_STEP_FACTOR = 2  # a side's first step in default steps (20 per period of its highest mode: 10)
MAX_REFINEMENTS = 3  # halvings of the first steps to get there
ASYMPTOTIC = 0.25  # Richardson's estimate where doubling the step moves the mesh forces' ripple by less than this
EXTENSION_FACTOR = 8  # a run is extended to its steady state up to this multiple of the duration asked for
SENSED = ("acceleration", "angular_acceleration")  # the kinds an accelerometer chain (sensor_band) filters
SIDE_SETTINGS = ("method", "dt_s", "steps", "rotating_frame_terms")  # what the report states of the reference run

log = logging.getLogger(__name__)


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
    second_order: float | None = None  # negligible as :func:`second_order`: the moving side's share of its kind

    @property
    def error_ratio(self) -> float:
        """The integration error estimate over the tolerance (0 without a tolerance)."""
        return error_estimate(self.metrics) / self.tolerance if self.tolerance else 0.0


@dataclass
class CrosscheckResult:
    """Everything a cross-check found; :func:`gearcheck.compare.presentation.report.write_report` writes it."""

    spec: TrainSpec
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
    wall_times: dict  # s, by step (``Clock``)
    cpu_times: dict  # s, by step: this process's CPU time, its threads included
    measurements: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # findings stated in plain words in the report
    references: list[str] = field(default_factory=list)  # keys of gearcheck.shared.citations.REFERENCES
    moved: list[str] | None = None  # metrics moved from a baseline (None: no baseline checked)
    steady_how: str | None = None  # detected | decayed | transient | None (no steady state)
    settle_s: float | None = None  # the reference's free vibration decay time (steady-state runs)
    solvers: tuple = ("lumped", "mujoco")  # the reference's and the test's names
    kinds: tuple = ("reference lumped model", "MuJoCo twin")  # what each is (Side.kind)
    diagnosis: object | None = None  # a user's model: the term of the reference that best explains its modes

    @property
    def failures(self) -> list[str]:
        bad = [q.name for q in self.quantities if q.status == "fail"]
        bad += [f"mode {m['mode']}" for m in self.modal if m["rel_error"] > self.modal_tolerance]
        return bad

    @property
    def unresolved(self) -> list[str]:
        """Why the comparison cannot decide: no steady state, or quantities whose integration error estimates
        reach their tolerance."""
        reasons = [] if self.steady_found else ["no steady state"]
        return reasons + [f"{q.name} (integration error)" for q in self.quantities if q.status == "unresolved"]

    @property
    def verdict(self) -> str:
        """FAIL (a tolerance exceeded or a baseline metric moved), INCONCLUSIVE (nothing failed, but the run
        reached no steady state or a quantity is unresolved) or PASS."""
        if self.failures or self.moved:
            return "FAIL"
        return "INCONCLUSIVE" if self.unresolved else "PASS"

    @property
    def solver_names(self) -> tuple[str, ...]:
        """The reference's and the test's names as reports write them."""
        return tuple(display_name(name) for name in self.solvers)

    @property
    def passed(self) -> bool:
        return self.verdict == "PASS"

    def __getitem__(self, name: str) -> QuantityComparison:
        for q in self.quantities:
            if q.name == name:
                return q
        raise KeyError(f"no compared quantity {name!r}" + did_you_mean(str(name), [q.name for q in self.quantities],
                                                                       n=3))

    def to_dataframe(self) -> pd.DataFrame:
        """The cross-check as a tidy table, one row per quantity (or mode), side and metric: ``quantity``,
        ``kind``, ``side`` (each solver's name for its own statistics, "both" for what compares them), ``metric``,
        ``value``, ``unit``, ``tolerance`` (where the metric is gated), ``status``; the verdict, train and solvers
        in ``attrs``."""
        rows: list[tuple] = []
        for q in self.quantities:
            for side, key in zip(self.solvers, ("reference", "test")):
                rows += [(q.name, q.kind, side, stat, value, q.unit, None, q.status)
                         for stat, value in q.metrics[key].items()]
                rows.append((q.name, q.kind, side, "integration_error", q.metrics["integration_error"][key], "1", None,
                             q.status))
            for metric, unit in COMPARED:
                rows.append((q.name, q.kind, "both", metric.removesuffix("_s"), q.metrics[metric], unit,
                             q.tolerance if metric == "nrmse" else None, q.status))
        for m in self.modal:
            status = "pass" if m["rel_error"] <= self.modal_tolerance else "fail"
            name = f"mode {m['mode']}"
            rows += [(name, "natural_frequency", side, "frequency", m[key], "Hz", None, status)
                     for side, key in zip(self.solvers, ("reference_hz", "test_hz"))]
            rows.append((name, "natural_frequency", "both", "rel_error", m["rel_error"], "1", self.modal_tolerance,
                         status))
        frame = pd.DataFrame(rows, columns=["quantity", "kind", "side", "metric", "value", "unit", "tolerance",
                                            "status"])
        frame["value"] = frame["value"].astype(float)
        frame["tolerance"] = frame["tolerance"].astype(float)
        frame.attrs |= {"train": self.spec.name, "verdict": self.verdict, "solvers": list(self.solvers)}
        return frame

    def plot(self, quantities=None):
        """Both sides' steady time histories of ``quantities`` (a name or several; default: the report's headline
        ones) as a :class:`matplotlib.figure.Figure` (no pyplot)."""
        from gearcheck.compare.presentation.plots import time_histories_figure

        names = None if quantities is None else chosen("quantities", quantities, [q.name for q in self.quantities],
                                                        f"a compared quantity of {self.spec.name}")
        return time_histories_figure(self, names)

    def write(self, directory, figures: bool = True) -> dict:
        """Write report.json, report.md, report.html and the figures (none with ``figures=False``) as the folder
        ``directory``, whole or not at all (:class:`~gearcheck.shared.outputs.OutputDirectory`); returns the
        report's data."""
        from gearcheck.compare.presentation.report import write_report

        with OutputDirectory(directory, "directory") as place:
            return write_report(self, place.path, figures)


@one_blas_thread
def compare(spec, reference, test, plan, settings: tuple[RunSettings, RunSettings], tolerances: Tolerances,
            sensor_band: tuple[float, float] | None = None, progress=None) -> CrosscheckResult:
    """Cross-check ``test`` against ``reference`` (two :class:`~gearcheck.shared.side.Side`) as ``plan`` reads
    them; ``settings`` the two runs' settings (the same duration; each side's own step when ``dt`` is None,
    and then refined as the integration error requires).

    sensor_band: (low, high) Hz of an accelerometer chain applied to both runs' accelerations.
    progress: callable(fraction) over the runs.
    """
    clock = Clock()
    modal_reference = reference
    with clock.step(f"{_label(reference, 0)}_modes_s"):
        modes_a = reference.modes()
    with clock.step(f"{_label(test, 1)}_modes_s"):
        modes_b = test.modes() if test.has_modes else None
    reduction = None
    if modes_b is not None:  # a reduced model's modes against the reference reduced alike
        modal_reference, modes_a, reduction = reduced_reference(reference, test, (modes_a, modes_b))
    modal_rows = [] if modes_b is None else _modal_rows(spec, modal_reference, test, modes_a, modes_b)
    if reduction and test.driven:
        reduction = f"{reduction[:-1]}; its time histories are compared with the full reference's."
    told = [*test.notes] + ([reduction] if reduction else [])  # what was done to the test and the reference
    modal_tolerance = tolerances.lookup("modes", "frequency", "rel_error")
    assert modal_tolerance is not None  # the defaults hold it, and a tolerances file only overrides them
    references = list(dict.fromkeys(list(spec.references) + list(reference.references) + list(test.references)))
    if not test.driven:
        return _modal_only(spec, reference, test, plan, tolerances, modal_rows, modal_tolerance, (modes_a, modes_b),
                           clock, references, told)

    asked = settings[0].duration
    adjustable = [s.dt is None for s in settings]
    duration, notes = asked, _Notes(told)
    steps = first_steps((reference, test), settings)
    refinements, extended, best = 0, False, None
    needed = plan.needed_duration() if plan.detect_steady else None
    rerunnable = reference.rerunnable and test.rerunnable
    periodic = False
    if rerunnable and needed is not None and needed > EXTENSION_FACTOR * asked:
        periodic = _periodic_note(plan, reference, needed, asked, notes)
    elif rerunnable and needed is not None and asked < needed and not plan.detectable(asked):
        duration, extended = needed, True  # a run of the duration asked could only be thrown away and extended
        notes.append(_extended_note(asked, needed, plan))
    while True:
        runs = [replace(s, duration=duration, dt=dt) for s, dt in zip(settings, steps)]
        log.info("%s: %.4g s simulated, steps %s, %s", spec.name, duration,
                 ", ".join("derived" if dt is None else f"{dt:.4g} s" for dt in steps),
                 "from the periodic steady states" if periodic else "from the static states")
        try:
            attempt = _Attempt.of((reference, test), runs, plan, tolerances, sensor_band, clock, progress, periodic)
        except (UnsupportedError, SolverError) as exc:
            if not periodic:
                raise
            notes.append(f"They could not: {exc}.  Both runs start from their static states instead.")
            periodic = False
            continue
        if (attempt.how is None and not extended and needed is not None
                and duration < needed <= EXTENSION_FACTOR * asked and rerunnable):
            notes.append(_extended_note(duration, needed, plan))
            duration, extended = needed, True
            continue
        if best is not None and attempt.worst >= best.worst:
            why = "the response does not converge with the step" if attempt.drifting else "round-off, not truncation"
            notes.append(f"Halving the steps did not lower the integration error estimate ({best.worst:.2g} -> "
                         f"{attempt.worst:.2g} of a tolerance: {why}); the coarser run is reported.")
            break
        best = attempt
        order = min(side.order for side, free in zip((reference, test), adjustable) if free) if any(adjustable) else 0
        order = min(order, 1) if attempt.drifting else order  # the worst are bounds, not Richardson's estimates
        halvings = min(_halvings(attempt.worst, order), MAX_REFINEMENTS - refinements)
        if halvings > 0 and any(adjustable):
            steps = [run.info["dt_s"] / 2**halvings if free else dt
                     for run, free, dt in zip(attempt.runs, adjustable, steps)]
            refinements += halvings
            notes.append(f"Steps halved {halvings}x ({refinements}x in all): the two solvers' integration error "
                         f"estimates reached {attempt.worst:.2g} of a tolerance (target {TARGET_FRACTION:g}; they fall "
                         f"as h^{order}).")
            continue
        break
    (a, b), (a_check, b_check), grid, fs, series = best.runs, best.checks, best.grid, best.fs, best.series
    if best.starts:
        notes.append("Periodic steady states found by " + "; ".join(best.starts) + ".")
    for side in (reference, test):
        if side.rerunnable and side.order == 1:
            notes.append(f"The order of convergence of {display_name(side.solver)} is not known to gearcheck: its "
                         "integration error estimate is the change on doubling its step, a bound for any order.")
    for solver, change in best.drifting:
        name = display_name(solver)
        notes.append(f"{name[:1].upper() + name[1:]}'s runs at h and 2h differ by {100 * change:.3g} % of their mesh "
                     "forces' fluctuation over the window: the response does not converge with the step (it is "
                     "sensitive to its start, as a vibro-impact response can be), outside the asymptotic range "
                     "Richardson's estimate presumes; the change itself is that solver's integration error estimate.")
    t0, how, comparisons, duration = best.t0, best.how, best.comparisons, a.t[-1]
    held = [q for q in comparisons if q.second_order is not None]
    if held:
        notes.append("Held at zero by one solver and moved by the other by less than "
                     f"{SECOND_ORDER:g} of the largest of its kind (second order in the vibration, which a linear "
                     "model leaves out), so not compared: "
                     + ", ".join(f"{q.name} ({q.second_order:.2g})" for q in held) + ".")
    if plan.detect_steady and how is None:
        notes.append("No steady state in this run" + (
            f": the free vibration of its start decays to {STEADY_THRESHOLD:g} in {plan.settle:.4g} s"
            f"{_slow_mode_words(reference)}; run at least {needed:.4g} s (--duration), or add damping where that "
            "mode lives." if needed is not None else ": the reference model has a mode that does not decay."))

    run_settings = {
        "duration_s": asked, "simulated_s": duration, **plan.operating,
        "reference": {k: a.info[k] for k in SIDE_SETTINGS if k in a.info},
        "test": {k: v for k, v in b.info.items() if k != "wall_time_s" and _plain(v)},
        "common_sample_rate_hz": fs, "steady_cycle_s": plan.cycle, "steady_cycle_of": plan.cycle_of,
        "integration_check_steps_s": [c.info["dt_s"] if c is not None else None for c in (a_check, b_check)],
        "sensor_band_hz": list(sensor_band) if sensor_band else None,
        "tolerances": dict(sorted(tolerances.values.items())),
    }
    return CrosscheckResult(spec, run_settings, modal_rows, modal_tolerance,
                            comparisons, t0, how in ("detected", "decayed", "transient", "periodic"), (a, b),
                            (modes_a, modes_b),
                            grid, series, clock.wall, clock.cpu, notes=notes, references=references,
                            steady_how=how, settle_s=plan.settle if plan.detect_steady else None,
                            solvers=(reference.solver, test.solver), kinds=(reference.kind, test.kind))


def _modal_only(spec, reference, test, plan, tolerances, modal_rows, modal_tolerance, modal_results, clock,
                references, told) -> CrosscheckResult:
    """The cross-check of a side that nothing drives (``Side.driven`` False): its modes against the reference's,
    the time-domain part skipped with the reason and what to add; ``told``: the notes already made."""
    notes = _Notes(told)
    notes.append(f"{display_name(test.solver)} has nothing that drives it: no mesh rows, no time-varying stiffness, "
                 "no time-varying force. Its runs would sit at their static state, so only its modes are compared; "
                 "give its meshes as mesh rows (or its stiffness and forcing as functions of time) for the "
                 "time-domain comparison.")
    settings = {"duration_s": 0.0, "simulated_s": 0.0, **plan.operating, "reference": {}, "test": {},
                "common_sample_rate_hz": 0.0, "steady_cycle_s": plan.cycle, "steady_cycle_of": plan.cycle_of,
                "integration_check_steps_s": [None, None], "sensor_band_hz": None,
                "tolerances": dict(sorted(tolerances.values.items()))}
    return CrosscheckResult(spec, settings, modal_rows, modal_tolerance, [], 0.0, True, (None, None), modal_results,
                            np.zeros(0), {}, clock.wall, clock.cpu, notes=notes, references=references,
                            steady_how="modes only", solvers=(reference.solver, test.solver),
                            kinds=(reference.kind, test.kind))


@dataclass
class _Attempt:
    """Both sides run at one duration and pair of steps, with their checks, aligned and compared."""

    runs: tuple
    checks: tuple
    grid: np.ndarray
    fs: float
    series: dict
    t0: float
    how: str | None
    comparisons: list
    starts: list  # how each side found its periodic steady state, where the runs start there
    drifting: list  # (solver, change) of the sides whose runs at h and 2h are outside the asymptotic range

    @property
    def worst(self) -> float:
        """The largest integration error estimate over its tolerance among the gated quantities."""
        return max((q.error_ratio for q in self.comparisons if q.status != "negligible"), default=0.0)

    @classmethod
    def of(cls, sides, settings, plan, tolerances, sensor_band, clock, progress, periodic=False) -> "_Attempt":
        """Both sides run (from their periodic steady states where ``periodic``: steady from the start) and
        compared."""
        starts: list[str] = []
        (a, a_check), (b, b_check) = _run_pairs(sides, settings, clock, progress, periodic, starts)
        names = [n for n in a.names(compared=True) if n in b]
        grid, fs, series = _common_grid(a, b, names, plan, sensor_band)
        t0: float = 0.0
        how: str | None = "periodic" if periodic else "transient"
        if plan.detect_steady and not periodic:
            groups = [(np.stack([series[n][i] for n in forces], axis=1), cycle)
                      for forces, cycle in plan.steady_groups(names) for i in (0, 1)]
            start, how = steady_state(grid, groups, plan.settle)
            t0 = 0.5 * grid[-1] if start is None else start
        forces = [n for n in names if a.signal(n).kind == "mesh_force"]
        orders, drifting = [], []
        for side, run, check in zip(sides, (a, b), (a_check, b_check)):
            change = 0.0 if check is None or side.order == 1 else step_change(run, check, forces, t0)
            orders.append(1 if change > ASYMPTOTIC else side.order)
            if change > ASYMPTOTIC:
                drifting.append((side.solver, change))
        errors = {n: tuple(None if check is None else integration_error(run, check, n, t0, a, p)
                           for run, check, p in zip((a, b), (a_check, b_check), orders)) for n in names}
        # statistics and lines from each run's own samples, but for the signals a sensor chain filters
        sensed = set() if sensor_band is None else {n for n in names if a.signal(n).kind in SENSED}
        own = {n: (a, b, t0) for n in names if n not in sensed}
        comparisons = _quantities(a, names, series, grid >= t0, fs, plan, tolerances, errors, own)
        return cls((a, b), (a_check, b_check), grid, fs, series, t0, how, comparisons, starts, drifting)


def _extended_note(duration: float, needed: float, plan) -> str:
    return (f"The run was extended from {duration:.6g} s to {needed:.6g} s to reach its steady state: the free "
            f"vibration of its start decays to {STEADY_THRESHOLD:g} in {plan.settle:.4g} s, plus "
            f"{STEADY_WINDOW_CYCLES} mesh cycles to compare.")


def _modal_rows(spec, reference, test, modes_a, modes_b) -> list[dict]:
    """Mode by mode; a test model with fewer modes (fewer coordinates: a torsional model) mode by mode with
    its partner by shape (:func:`gearcheck.compare.engine.mode_pairing.pair_modes`)."""
    if len(modes_a) == len(modes_b):
        return modal_metrics(modes_a.frequencies, modes_b.frequencies, modes_a.types, modes_b.types,
                             modes_a.multiplicity)
    try:
        partner = pair_modes(spec.name, reference, test, (modes_a, modes_b)).mac.argmax(axis=0)
    except UnsupportedError as exc:
        raise SolverError(f"the models have different numbers of modes ({len(modes_a)} {reference.solver}, "
                          f"{len(modes_b)} {test.solver}) and no mode shapes to pair them by: {exc}") from None
    return modal_metrics(modes_a.frequencies[partner], modes_b.frequencies, [modes_a.types[i] for i in partner],
                         modes_b.types, [modes_a.multiplicity[i] for i in partner])


class Clock:
    """Wall and CPU time of a cross-check's steps, by name.  The CPU time is this process's, its threads included
    (MuJoCo's runs): what a step costs, steady where the wall time of a shared CI runner is not."""

    def __init__(self):
        self.wall: dict[str, float] = {}
        self.cpu: dict[str, float] = {}

    @contextmanager
    def step(self, name: str):
        wall, cpu = time.perf_counter(), time.process_time()
        yield
        self.wall[name] = time.perf_counter() - wall
        self.cpu[name] = time.process_time() - cpu
        log.info("%s: %.3g s wall, %.3g s CPU", name.removesuffix("_s").replace("_", " "), self.wall[name],
                 self.cpu[name])


def _label(side, i: int) -> str:
    """A side's name in the timings: gearcheck's two solvers by name (the keys the history keeps), any other side
    as the reference (``i`` 0) or the test (1)."""
    return side.solver if side.solver in ("lumped", "mujoco") else ("reference", "test")[i]


class _Notes(list):
    """A cross-check's findings, each logged as it is made (the command line's ``-v``)."""

    def append(self, note: str) -> None:
        log.info("%s", " ".join(note.split()))
        super().append(note)


def _log_work(label: str, run) -> None:
    """What a run did, at the command line's ``-v``: its engine, step, steps and right-hand-side calls."""
    info = run.info
    if isinstance(info, RunInfo):  # a recording's is the file's description
        log.info("%s: %s, dt %.4g s, %d steps, %d right-hand-side calls", label, info.engine, info["dt_s"],
                 info.steps, info.rhs_calls)


def _run_pairs(sides, settings, clock, progress, periodic=False, starts=None):
    """Each side's run and its integration check (2 h, or h / 2 where 2 h is beyond its stable step), both from
    the side's periodic steady state where ``periodic`` (how each was found appended to ``starts``); a recorded
    side (``rerunnable`` False) has no check."""
    pairs = []
    for i, (side, run_settings) in enumerate(zip(sides, settings)):
        label = _label(side, i)
        # progress over both sides: a run counts 1, its check (at most twice the step) 0.5
        report = (lambda f, i=i: progress((1.5 * i + f) / 3.0)) if progress else None
        if periodic:
            if i == 1 and run_settings.dt is not None and run_settings.dt == settings[0].dt:
                # the step the reference made a whole fraction of its period: a twin whose period is a multiple
                # of it keeps it, and the two runs sample the same instants (as two free runs on one step do)
                run_settings = replace(run_settings, dt=pairs[0][0].info["dt_s"])
            with clock.step(f"{label}_run_s"):
                run, check, how = side.run_periodic(run_settings, lambda h, side=side: check_step(side, h), report)
            starts.append(how)
            pairs.append((run, check))
            continue
        with clock.step(f"{label}_run_s"):
            run = side.run(run_settings, report)
        _log_work(label, run)
        if not side.rerunnable:
            pairs.append((run, None))
            continue
        check_dt = check_step(side, run.info["dt_s"])
        report = (lambda f, i=i: progress((1.5 * i + 1.0 + 0.5 * f) / 3.0)) if progress else None
        with clock.step(f"{label}_check_s"):
            check = side.run(replace(run_settings, dt=check_dt, output_dt=None,
                                     signals=tuple(run.names(compared=True)) or None), report)
        _log_work(f"{label} check", check)
        pairs.append((run, check))
    return pairs


def _slow_mode_words(side) -> str:
    """", its slowest mode ... decaying in ..." of ``side``, or nothing where it does not say."""
    mode = side.slowest_mode()
    if mode is None:
        return ""
    frequency, zeta = mode
    return (f" (its slowest-decaying mode: {frequency:.4g} Hz, damping ratio {100 * zeta:.3g} %, time constant "
            f"{1.0 / (2 * math.pi * frequency * zeta):.3g} s)")


def _periodic_note(plan, reference, needed: float, asked: float, notes: list) -> bool:
    """Note why both runs start on their periodic steady states; True."""
    notes.append(f"The free vibration of the start decays to {STEADY_THRESHOLD:g} only after {plan.settle:.4g} s"
                 f"{_slow_mode_words(reference)}, beyond {EXTENSION_FACTOR} times the {asked:.4g} s asked for: both "
                 "runs start on their own periodic steady states, each solver shooting on its own runs.")
    return True


def first_steps(sides, settings) -> list[float | None]:
    """The steps a cross-check first runs ``sides`` at: a step asked for in ``settings`` as it is.  Where both sides
    pick their own, ``FIRST_STEP_FACTOR`` times the smaller of their default steps (the default where the check
    at twice that would be unstable) for both, so that their samples fall at the same instants and alias alike (at
    two rates the discontinuous accelerations of contact alias differently in each, and the NRMSE counts it).
    Else a side that picks takes its default step (None: it picks by its own rule)."""
    defaults = [side.default_step() if s.dt is None else None for side, s in zip(sides, settings)]
    known = [d for d in defaults if d is not None]
    if len(sides) == 2 and len(known) == 2:
        h = min(known)
        if all(2 * FIRST_STEP_FACTOR * h <= side.stable_step() for side in sides):
            h *= FIRST_STEP_FACTOR
        return [h, h]
    return [s.dt if s.dt is not None else h for s, h in zip(settings, defaults)]


def _halvings(worst: float, order: int) -> int:
    """How many halvings of the steps bring estimates at ``worst`` of a tolerance within ``TARGET_FRACTION``
    (they fall as h^order; none for order 0: no side picks its step)."""
    if worst <= TARGET_FRACTION or order == 0:
        return 0
    return math.ceil(math.log2(worst / TARGET_FRACTION) / order)


def check_step(side, h: float) -> float:
    """The step of the integration check of ``side``'s run at step ``h``: 2 h, or h / 2 where 2 h is beyond
    the side's stable step."""
    return 2 * h if 2 * h <= side.stable_step() else 0.5 * h


def _common_grid(a, b, names, plan, sensor_band):
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
            if a.signal(n).kind in SENSED:
                series[n] = tuple(sensor_filter(x, fs, sensor_band) for x in series[n])
    return grid, fs, series


def _quantities(a, names, series, window, fs, plan, tolerances, errors, own) -> list[QuantityComparison]:
    """Each quantity compared over ``window``; ``own``: name -> (the two runs, the window's start) for the
    quantities whose statistics and lines are read from each run's own samples."""
    scale: dict[str, float] = {}
    for n in names:
        kind = a.signal(n).kind
        rms = max(float(np.sqrt(np.mean(x[window] ** 2))) for x in series[n])
        scale[kind] = max(scale.get(kind, 0.0), rms)
        for other, factor in plan.scale_from(n):
            scale[other] = max(scale.get(other, 0.0), rms * factor)
    comparisons = []
    lines = {n: [(label, f) for label, f in plan.lines(n, np.count_nonzero(window) / fs) if f < 0.45 * fs]
             for n in names}
    projected = _own_lines(names, lines, plan, own)
    for n in names:
        s = a.signal(n)
        xa, xb = series[n][0][window], series[n][1][window]
        metrics = waveform_metrics(xa, xb, fs, max_lag=plan.max_lag(n))
        if n in own and all(_uniform(run.t) for run in own[n][:2]):
            metrics |= statistics(*(run[n][run.t >= own[n][2]] for run in own[n][:2]))
        metrics["integration_error"] = {"reference": errors[n][0], "test": errors[n][1]}
        tol = tolerances.lookup(n, s.kind, "nrmse")
        floor = plan.floors.get(s.kind, 0.0) / (tol or 1.0)  # round-off a tolerance's share of the signal
        kind_scale = max(NEGLIGIBLE * scale[s.kind], floor) / NEGLIGIBLE
        status = verdict(metrics, tol, kind_scale)
        freqs = [f for _, f in lines[n]]
        amp_a, amp_b = projected.get(n) or (spectral_amplitude(xa, fs, freqs), spectral_amplitude(xb, fs, freqs))
        spectrum = spectral_metrics(amp_a, amp_b, lines[n])
        comparisons.append(QuantityComparison(n, s.kind, s.unit, s.description, status, metrics, spectrum, tol,
                                              second_order=second_order(metrics, kind_scale)))
    return comparisons


def _own_lines(names, lines: dict, plan, own: dict) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """name -> both sides' amplitudes at its lines' frequencies (``lines``: name -> (label, Hz)), from each run's
    own uniform samples over its steady window (``own``: name -> the two runs and the window's start), the jumps of
    a switching mesh stiffness and the kinks they cause projected exactly, each signal's own
    (:meth:`~gearcheck.compare.engine.plan.TrainPlan.singularities`,
    :func:`~gearcheck.compare.engine.line_projection.harmonics`, as the sweep reads its lines): a jump sampled at a
    step aliases onto every line, which the anti-aliased common
    grid would smear instead.  The quantities that share their runs and lines are projected together.  A name not
    in it (a signal a sensor chain filters, a recording, no switches) takes the common grid's series."""
    if plan.switch_times is None:
        return {}
    groups: dict[tuple, list[str]] = {}
    for n in names:
        if n in own and all(_uniform(run.t) for run in own[n][:2]):
            key = (id(own[n][0]), id(own[n][1]), own[n][2], tuple(f for _, f in lines[n]))
            groups.setdefault(key, []).append(n)
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for (_, _, start, freqs), group in groups.items():
        amplitudes = []
        for run in own[group[0]][:2]:
            window = run.t >= start
            t = run.t[window]
            x = np.column_stack([run[n][window] for n in group])
            amplitudes.append(np.abs(harmonics(t, x, freqs, _rate(t), *plan.singularities(group, t[0], t[-1]))))
        out.update({n: (amplitudes[0][:, j], amplitudes[1][:, j]) for j, n in enumerate(group)})
    return out


def _uniform(t: np.ndarray) -> bool:
    """Samples at one rate (a run's own steps), not a recording's times."""
    step = np.diff(t)
    return t.size > 2 and float(np.max(np.abs(step - step.mean()))) <= 1e-9 * float(step.mean())


def integration_error(run, check, name: str, start: float, reference, order: int = ORDER) -> float | None:
    """An estimate of ``run``'s integration error in ``name`` over t >= ``start``, relative to the RMS of the
    ``reference`` run's signal there (the denominator of the cross-check's NRMSE): Richardson's for a side of
    ``order`` p, rms(x_h - x_2h) / (2^p - 1) when ``check`` took twice the step, rms(x_h - x_h/2) 2^p / (2^p - 1)
    when it took half (each from samples at the same times; :func:`gearcheck.shared.stepping.richardson_factor`).
    For p = 1 (a side whose order is not known, or runs outside the asymptotic range) that is the change itself: a
    bound for a converging run."""
    change = _change(run, check, name, start)
    x_ref = reference[name][reference.t >= start]
    scale = float(np.sqrt(np.mean(x_ref**2))) if x_ref.size else 0.0
    if change is None or scale == 0.0:
        return None
    return richardson_factor(check.info["dt_s"] / run.info["dt_s"], order) * change / scale


def step_change(run, check, names, start: float) -> float:
    """The largest change of ``names`` between ``run`` and its ``check`` over t >= ``start``, relative to each one's
    fluctuation in ``run`` (the RMS about its mean: a mesh force's static load would hide a ripple that does not
    converge; 0 without any)."""
    out = 0.0
    for name in names:
        change, x = _change(run, check, name, start), run[name][run.t >= start]
        scale = float(np.std(x)) if x.size else 0.0
        if change is not None and scale > 0.0:
            out = max(out, change / scale)
    return out


def _change(run, check, name: str, start: float) -> float | None:
    """rms(x_coarse - x_fine) of ``name`` over t >= ``start``, from the samples the two runs share."""
    coarse, fine = (check, run) if check.info["dt_s"] > run.info["dt_s"] else (run, check)
    k = round(coarse.info["dt_s"] / fine.info["dt_s"])
    n = min(fine.t[::k].size, coarse.t.size)
    window = coarse.t[:n] >= start
    if not np.any(window):
        return None
    return float(np.sqrt(np.mean((coarse[name][:n][window] - fine[name][::k][:n][window]) ** 2)))


def verdict(metrics: dict, tolerance: float | None, scale: float) -> str:
    """negligible (below NEGLIGIBLE x the largest of its kind in both solvers, or :func:`second_order`);
    unresolved (the two solvers' integration error estimates together reach the tolerance); else pass or fail on
    NRMSE."""
    if max(metrics["reference"]["rms"], metrics["test"]["rms"]) < NEGLIGIBLE * scale \
            or second_order(metrics, scale) is not None:
        return "negligible"
    if tolerance is not None and error_estimate(metrics) >= tolerance:
        return "unresolved"
    if tolerance is None or (metrics["nrmse"] is not None and metrics["nrmse"] <= tolerance):
        return "pass"
    return "fail"


def second_order(metrics: dict, scale: float) -> float | None:
    """The share of ``scale`` (the largest of its kind) by which one side moves a quantity that the other holds at
    zero (below ROUND_OFF of it), where that share is below SECOND_ORDER; else None.  A linear model's zero against
    a nonlinear one's motion of second order in the vibration (a 3-D twin's carrier moved along its axis by its
    tilts times its planets' deflections, where the linear model's first order cancels over the planets): the
    two models' difference in kind, not in accuracy, and not compared."""
    low, high = sorted((metrics["reference"]["rms"], metrics["test"]["rms"]))
    if low < ROUND_OFF * scale and NEGLIGIBLE * scale <= high < SECOND_ORDER * scale:
        return high / scale
    return None


def error_estimate(metrics: dict) -> float:
    """The two solvers' integration error estimates together (what integration alone could put into the NRMSE)."""
    errors = metrics.get("integration_error") or {}
    return sum(e for e in errors.values() if e is not None)


def _plain(value) -> bool:
    return isinstance(value, (int, float, str, bool)) or value is None


def _rate(t: np.ndarray) -> float:
    return (t.size - 1) / (t[-1] - t[0])
