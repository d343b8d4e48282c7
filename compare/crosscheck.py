"""Run both solvers on one train and operating point, align their outputs, measure the errors.

The lumped model is the reference a, the MuJoCo twin the test b.  Steps:

1. natural frequencies of both, mode by mode;
2. time responses over the same duration from their own static deflections;
3. every comparable quantity (:mod:`compare.quantities`) resampled onto one uniform grid
   (anti-aliased, :func:`compare.align.resample`) at the lower of the two output rates;
4. the steady window: from the later of the two steady-state starts found by the
   mesh-cycle detector on the mesh forces (:func:`compare.align.steady_start`);
5. per quantity, lag-aligned waveform metrics, spectral lines and a verdict against the
   tolerances; quantities that are negligible in both solvers (below ``NEGLIGIBLE`` of the
   largest of their kind, e.g. central-member translations that mesh phasing cancels) are
   reported as such and not gated (for translational accelerations the scale also counts
   r alpha of every central member, so that accelerations cancelled by phasing are seen as
   negligible against the rotations), and so are accelerations below the round-off floor of
   MuJoCo's absolute angles (:func:`round_off_floor`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from lumped import build_model
from lumped.errors import SolverError
from lumped.modal import modes
from lumped.time_solver import max_angular_frequency, simulate

from .align import resample, sensor_filter, steady_start, uniform_grid
from .metrics import modal_metrics, spectral_lines, spectral_metrics, waveform_metrics
from .quantities import extract
from .tolerances import Tolerances

NEGLIGIBLE = 1e-6


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
    spec: object
    settings: dict
    modal: list[dict]
    modal_tolerance: float
    quantities: list[QuantityComparison]
    steady_start_s: float
    steady_found: bool
    results: tuple  # (lumped TimeResult, mujoco TimeResult)
    modal_results: tuple
    grid: np.ndarray
    series: dict  # quantity -> (a, b) on the grid
    wall_times: dict
    measurements: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # findings stated in plain words in the report

    @property
    def failures(self) -> list[str]:
        bad = [q.name for q in self.quantities if q.status == "fail"]
        bad += [f"mode {m['mode']}" for m in self.modal if m["rel_error"] > self.modal_tolerance]
        return bad

    @property
    def passed(self) -> bool:
        return not self.failures


def _stage_frequencies(spec, kin):
    out = {}
    for stage in spec.stages:
        f_mesh = min(kin.mesh_frequency[m.id] for m in spec.meshes if m.stage == stage.name)
        out[stage.name] = (f_mesh, abs(kin.speeds[stage.carrier]) / (2 * math.pi))
    return out


def crosscheck(spec, duration: float = 0.1, tolerances: Tolerances | None = None, dt_lumped=None, dt_mujoco=None,
               sensor_band: tuple[float, float] | None = None, mujoco_hook=None, progress=None) -> CrosscheckResult:
    """Compare the lumped model of ``spec`` with its MuJoCo twin.

    tolerances: default :meth:`Tolerances.for_train`.  sensor_band: (low, high) Hz of an
    accelerometer chain applied to both solvers' accelerations.  mujoco_hook: optional
    callable(spec) -> spec applied to the MuJoCo side only (a test hook, to prove that the
    cross-check catches a model that differs).
    """
    from mbd_models import mujoco_modes, simulate_mujoco

    tolerances = tolerances or Tolerances.for_train(spec)
    mj_spec = mujoco_hook(spec) if mujoco_hook else spec
    model = build_model(spec)
    kin = model.kin
    wall = {}

    started = time.perf_counter()
    lumped_modes = modes(model)
    wall["lumped_modes_s"] = time.perf_counter() - started
    started = time.perf_counter()
    mujoco_modal = mujoco_modes(mj_spec)
    wall["mujoco_modes_s"] = time.perf_counter() - started
    if len(lumped_modes) != len(mujoco_modal):
        raise SolverError(f"the models have different numbers of modes ({len(lumped_modes)} lumped, "
                          f"{len(mujoco_modal)} MuJoCo)")
    modal_rows = modal_metrics(lumped_modes.frequencies, mujoco_modal.frequencies, lumped_modes.types,
                               mujoco_modal.types, lumped_modes.multiplicity)

    report = (lambda f: progress(0.5 * f)) if progress else None
    a = simulate(model, duration, dt=dt_lumped, progress=report)
    wall["lumped_run_s"] = a.info["wall_time_s"]
    report = (lambda f: progress(0.5 + 0.5 * f)) if progress else None
    b = simulate_mujoco(mj_spec, duration, dt=dt_mujoco, progress=report)
    wall["mujoco_run_s"] = b.info["wall_time_s"]

    qa, qb = extract(spec, a), extract(mj_spec, b)
    names = [n for n in qa if n in qb]
    fs = min(_rate(a.t), _rate(b.t))
    grid = uniform_grid(0.0, min(a.t[-1], b.t[-1]), fs)
    series = {n: (resample(a.t, qa[n][1], grid), resample(b.t, qb[n][1], grid)) for n in names}
    if sensor_band is not None:
        low, high = sensor_band
        if not (0 < low < high < 0.5 * fs):
            raise SolverError(f"sensor band {low:g}-{high:g} Hz must lie inside (0, {0.5 * fs:.6g}) Hz")
        for n in names:
            if qa[n][0].kind in ("acceleration", "angular_acceleration"):
                series[n] = tuple(sensor_filter(x, fs, sensor_band) for x in series[n])

    stage_freq = _stage_frequencies(spec, kin)
    cycle = 1.0 / min(f for f, _ in stage_freq.values())
    forces = [n for n in names if qa[n][0].kind == "mesh_force"]
    starts = [steady_start(grid, np.stack([series[n][i] for n in forces], axis=1), cycle) for i in (0, 1)]
    found = all(s is not None for s in starts)
    t0 = max(starts) if found else 0.5 * grid[-1]
    window = grid >= t0

    scale: dict[str, float] = {}
    for n in names:
        kind = qa[n][0].kind
        rms = max(float(np.sqrt(np.mean(x[window] ** 2))) for x in series[n])
        scale[kind] = max(scale.get(kind, 0.0), rms)
        if kind == "angular_acceleration":  # r alpha: the translational scale a rotation sets
            member = n.rsplit(".", 1)[0]
            scale["acceleration"] = max(scale.get("acceleration", 0.0), rms * _radius(spec, member))

    floor = round_off_floor(spec, model, duration)
    comparisons = []
    for n in names:
        q = qa[n][0]
        xa, xb = series[n][0][window], series[n][1][window]
        member_stage = n.split(".")[0]
        f_mesh, f_carrier = stage_freq.get(member_stage, next(iter(stage_freq.values())))
        if q.kind in ("mesh_force", "dte"):
            f_mesh = kin.mesh_frequency[n.rsplit(".", 1)[0]]
        metrics = waveform_metrics(xa, xb, fs, max_lag=0.5 / f_mesh)
        lines = spectral_lines(f_mesh, f_carrier, xa.size / fs)
        lines = [(name, f) for name, f in lines if f < 0.45 * fs]
        spectrum = spectral_metrics(xa, xb, fs, lines)
        tol = tolerances.lookup(n, q.kind, "nrmse")
        status = verdict(metrics, tol, max(NEGLIGIBLE * scale[q.kind], floor.get(q.kind, 0.0)) / NEGLIGIBLE)
        comparisons.append(QuantityComparison(n, q.kind, q.unit, q.description, status, metrics, spectrum, tol))

    settings = {
        "duration_s": duration, "input_speed_rpm": spec.operating.input_speed * 60 / (2 * math.pi),
        "output_torque_nm": spec.operating.output_torque,
        "lumped": {k: a.info.get(k) for k in ("method", "dt_s", "steps", "rotating_frame_terms")},
        "mujoco": {k: v for k, v in b.info.items() if k not in ("wall_time_s",) and _plain(v)},
        "common_sample_rate_hz": fs, "steady_cycle_s": cycle,
        "sensor_band_hz": list(sensor_band) if sensor_band else None,
        "tolerances": dict(sorted(tolerances.values.items())),
    }
    return CrosscheckResult(spec, settings, modal_rows, tolerances.lookup("modes", "frequency", "rel_error"),
                            comparisons, t0, found, (a, b), (lumped_modes, mujoco_modal), grid, series, wall)


def round_off_floor(spec, model, duration: float) -> dict[str, float]:
    """Accelerations below which a solver integrating absolute angles (MuJoCo: the carrier turns by
    Omega t radians) cannot resolve anything: a position known to eps Omega t r, seen through the
    stiffest mode, is an acceleration of omega_max^2 eps Omega t r (and omega_max^2 eps Omega t for
    angles).  The lumped model integrates small vibrations about nominal motion and has no such floor."""
    turn = max(abs(w) for w in model.kin.speeds.values()) * duration
    radius = max(_radius(spec, mid) for mid, m in spec.members.items() if not m.is_planet)
    angular = max_angular_frequency(model) ** 2 * np.finfo(float).eps * turn
    return {"angular_acceleration": angular, "acceleration": angular * radius}


def verdict(metrics: dict, tolerance: float | None, scale: float) -> str:
    """negligible (below NEGLIGIBLE x the largest of its kind in both solvers), pass or fail on NRMSE."""
    if max(metrics["reference"]["rms"], metrics["test"]["rms"]) < NEGLIGIBLE * scale:
        return "negligible"
    if tolerance is None or (metrics["nrmse"] is not None and metrics["nrmse"] <= tolerance):
        return "pass"
    return "fail"


def _radius(spec, member: str) -> float:
    """Pitch radius of a central gear, carrier radius of a carrier."""
    m = spec.members[member]
    if m.kind == "carrier":
        return spec.stage_of(member).carrier_radius
    return next(iter(m.gears.values())).pitch_radius


def _plain(value) -> bool:
    return isinstance(value, (int, float, str, bool)) or value is None


def _rate(t: np.ndarray) -> float:
    return (t.size - 1) / (t[-1] - t[0])
