"""A run-up: the train driven through a linear speed ramp in both solvers, each run turned into order curves.

The input speed rises linearly from ``start_rpm`` to ``stop_rpm`` over ``duration`` (an operating history,
:mod:`gearcheck.train.history`; the run starts in the steady state at ``start_rpm``), each solver samples its run
finely enough for the highest mesh harmonic at the top speed, and every gated quantity is order-tracked
(:func:`~gearcheck.compare.studies.order_tracking.order_track`) against the input shaft's nominal angle at the
mesh orders: harmonic k of a mesh frequency f_mesh is order k f_mesh / f_in of the input, whatever the speed.  The
same amplitudes a stepped sweep reads at its speeds (:mod:`gearcheck.compare.studies.sweep`), from one run: the
order curves of the two solvers are compared with each other, and (:func:`against_sweep_table`) with a sweep.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from gearcheck.compare.studies.order_curves import against_sweep, resonance_speeds
from gearcheck.compare.studies.order_tracking import (MIN_SAMPLES_PER_CYCLE, OrderTrack, Waterfall, order_track,
                                                      waterfall)
from gearcheck.compare.engine.line_projection import jumps, step_series
from gearcheck.compare.engine.model_pair import SOLVERS
from gearcheck.compare.engine.plan import signal_singularities
from gearcheck.compare.studies.sweep import check_harmonics, mesh_groups
from gearcheck.shared.errors import GearcheckError, did_you_mean
from gearcheck.shared.results import signal_jumps, train_signals
from gearcheck.shared.settings import RunSettings
from gearcheck.train.excitation import Excitation
from gearcheck.train.history import History, Series
from gearcheck.train.kinematics import kinematics
from gearcheck.train.spec import with_history

OVERSAMPLING = 2  # samples a cycle of the highest harmonic at the top speed, over what order tracking needs
REVS_PER_BLOCK = 1.0  # one input revolution a block: mesh orders lie tens apart, so no leakage between them
OVERLAP = 0.75
SIGNIFICANT = 0.05  # a sweep comparison reads an order where it is above this fraction of its largest amplitude
PARTING = 1e-3  # the two solvers' order curves "part" where they differ by more than this of the largest
WATERFALL_BLOCKS = 60  # time blocks of the waterfall over the run


@dataclass
class RunUp:
    """Order curves of a run-up: ``tracks[(solver, quantity)]`` over ``orders`` ((mesh label, harmonic, order))."""

    train: str
    start_rpm: float
    stop_rpm: float
    duration: float
    orders: list[tuple[str, int, float]]
    tracks: dict[tuple[str, str], OrderTrack]
    units: dict[str, str]
    waterfalls: dict[str, Waterfall] = field(default_factory=dict)  # solver -> the first quantity's map
    backlash: tuple[str, ...] = ()  # the meshes with a backlash, whose teeth can separate
    switching: bool = False  # a mesh stiffness switches (see run_up)
    output_dt: float = 0.0  # the sampling of the runs, s
    wall_s: dict[str, float] = field(default_factory=dict)
    cpu_s: dict[str, float] = field(default_factory=dict)

    @property
    def rate_rpm_s(self) -> float:
        return (self.stop_rpm - self.start_rpm) / self.duration

    def table(self) -> pd.DataFrame:
        """One row per solver, quantity, order and block: speed, amplitude, phase."""
        rows = []
        for (solver, quantity), track in self.tracks.items():
            for label, k, order in self.orders:
                j = track.column(order)
                rows.append(pd.DataFrame({
                    "solver": solver, "quantity": quantity, "mesh": label, "harmonic": k, "order": order,
                    "speed_rpm": track.speed_rpm, "time_s": track.time_s,
                    "amplitude": track.amplitude[:, j], "phase_rad": track.phase[:, j], "unit": self.units[quantity]}))
        return pd.concat(rows, ignore_index=True)

    def agreement(self) -> dict[str, float]:
        """Per quantity, the largest difference of the two solvers' order curves (complex, block by block) over the
        largest amplitude of that quantity's orders in the reference's run."""
        return {q: float(np.max(d)) if d.size else 0.0 for q, d in self._differences().items()}

    def parting(self, threshold: float = PARTING) -> dict[str, float | None]:
        """Per quantity, the speed (rpm) of the first block where the two solvers' order curves differ by more than
        ``threshold`` of the largest amplitude (None: nowhere); where a train's teeth bounce, two runs that agree to
        round-off before part after an impact (a sensitive dependence that both solvers share)."""
        out = {}
        for q, d in self._differences().items():
            over = np.flatnonzero(d > threshold)
            out[q] = float(self.tracks[("lumped", q)].speed_rpm[over[0]]) if over.size else None
        return out

    def _differences(self) -> dict[str, np.ndarray]:
        """Per quantity, block by block, the largest difference of the two solvers' orders over the largest order
        amplitude of the reference's run (empty without both solvers)."""
        if {s for s, _ in self.tracks} != {"lumped", "mujoco"}:
            return {}
        out = {}
        for quantity in sorted({q for _, q in self.tracks}):
            a, b = (self.tracks[(s, quantity)].complex_amplitude for s in ("lumped", "mujoco"))
            scale = float(np.max(np.abs(a)))
            out[quantity] = np.max(np.abs(a - b), axis=1) / scale if scale > 0 else np.zeros(a.shape[0])
        return out


def run_up(train, start_rpm: float, stop_rpm: float, duration: float, solvers=("lumped", "mujoco"),
           quantities=None, harmonics: int = 3, progress=None, output_dt: float | None = None) -> RunUp:
    """Run ``train`` (a TrainSpec) up from ``start_rpm`` to ``stop_rpm`` over ``duration`` s in each of ``solvers``
    and order-track ``quantities`` (default: every gated quantity) at the first ``harmonics`` mesh harmonics,
    sampled every ``output_dt`` s (default: :data:`OVERSAMPLING` times what order tracking needs at the top speed).

    A mesh whose stiffness switches makes its force jump, and each jump rings the modes far above the tracked
    orders: at the default sampling those alias onto the lines (demo-3p's rectangular meshes: the first mesh order
    of a sun-mesh force read 13-67 N against the stepped sweep's 51-54 N), so the jumps of a mesh's own signals,
    where Newton's law puts them (:func:`~gearcheck.compare.engine.plan.signal_singularities`: its force at its
    switches, its deflection nowhere), are taken out and added back exactly
    (:func:`gearcheck.compare.engine.line_projection.jumps`), and
    sampling near the solvers' step (``output_dt``) reads such trains to the sweep's (within 3 % on demo-3p at
    1e-5 s).  :attr:`RunUp.switching` says whether a train's stiffness switches."""
    if not 0 < start_rpm < stop_rpm:
        raise GearcheckError(f"--from/--to: a run-up needs 0 < from < to, got {start_rpm:g} and {stop_rpm:g} rpm")
    check_harmonics(harmonics)
    known = [signal.name for signal in train_signals(train)]
    for name in quantities or ():
        if name not in known:
            raise GearcheckError(f"--quantity {name!r}: not a signal of {train.name}" + did_you_mean(str(name), known))
    speed = Series.of_points([[0.0, start_rpm], [duration, stop_rpm]], f"run-up {start_rpm:g}-{stop_rpm:g} rpm")
    spec = replace(train, operating=with_history(train.operating, History(speed), _fail))
    kin = kinematics(spec)
    excitation, rule, meshes = Excitation(spec, kin), signal_jumps(spec), {mesh.id for mesh in spec.meshes}
    nominal = excitation.clock
    f_in = abs(kin.speeds[spec.input]) / (2 * np.pi)
    orders = [(label, k, k * f / f_in) for label, f in mesh_groups(spec, kin) for k in range(1, harmonics + 1)]
    top_hz = max(order for *_, order in orders) * stop_rpm / 60.0
    if output_dt is None:
        output_dt = 1.0 / (OVERSAMPLING * MIN_SAMPLES_PER_CYCLE * top_hz)
    tracks, units, wall, cpu, maps = {}, {}, {}, {}, {}
    for solver in solvers:
        started, cpu_started = time.perf_counter(), time.process_time()
        result = SOLVERS[solver](spec).run(RunSettings(duration=duration, output_dt=output_dt), progress)
        wall[solver], cpu[solver] = time.perf_counter() - started, time.process_time() - cpu_started
        angle = f_in * nominal.time(result.t)  # revolutions of the input shaft on the nominal clock
        names = result.names(compared=True) if quantities is None else list(quantities)
        maps[solver] = waterfall(result.t, result[names[0]], angle, duration / WATERFALL_BLOCKS, overlap=0.5,
                                 max_hz=1.1 * top_hz)
        # a mesh's own signals jump where Newton's law says, as the sweep reads them (its force at its switches, its
        # deflection nowhere): those jumps taken exactly.  A member's acceleration jumps too, and kinks where other
        # meshes switch; at the default sampling a jump measured beside those kinks reads them (demo-3p, 2500 rpm/s:
        # the sun's 2x translation line 0.75 -> 5.7 from the stepped sweep's), and even at 1e-5 s its jumps and kinks
        # taken out leave the sun's and ring's lines 10-26 % from the sweep's (26-115 % left in): left in
        own = [name for name in names if name.rsplit(".", 1)[0] in meshes]
        switches = dict(zip(own, signal_singularities(rule, excitation.switch_times, own, result.t[0],
                                                      result.t[-1])[0]))
        for name in names:
            units[name] = result.signal(name).unit
            x = result[name]
            times, sizes = jumps(result.t, x[:, None], switches.get(name, ()))
            tracks[(solver, name)] = order_track(
                result.t, x - step_series(result.t, times, sizes)[:, 0], angle, [o for *_, o in orders],
                revs_per_block=REVS_PER_BLOCK, overlap=OVERLAP, steps=(f_in * nominal.time(times), sizes[:, 0]))
    return RunUp(spec.name, start_rpm, stop_rpm, duration, orders, tracks, units, maps,
                 tuple(m.id for m in spec.meshes if m.backlash > 0), any(m.breaks for m in excitation.models),
                 output_dt, wall, cpu)


def sweep_line(table: pd.DataFrame, solver: str, quantity: str, mesh: str, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(speeds in rpm, amplitudes) of harmonic ``k`` of ``mesh``'s frequency of ``quantity`` in a sweep table,
    by speed."""
    lines = table[(table["metric"] == "harmonic") & (table["solver"] == solver) & (table["quantity"] == quantity)
                  & (table["mesh"] == mesh) & (table["order"] == k)].sort_values("speed_rpm")
    return lines["speed_rpm"].to_numpy(), lines["amplitude"].to_numpy()


def contact_kept(table: pd.DataFrame, backlash, solver: str = "lumped") -> pd.Series:
    """Per speed of a sweep table: whether its steady state was found and the teeth of every mesh with a backlash
    (``backlash``: their ids) stay in contact there (each mesh force's mean above half its peak-to-peak).  Where
    teeth separate the response depends on its history: each stepped point lands on the branch its cold start finds,
    a run-up follows its own.  A mesh without backlash never separates (its force may pull: a linear model)."""
    rows = table[table["solver"] == solver]
    steady = rows.groupby("speed_rpm")["steady"].first() != "none"
    forces = rows[(rows["kind"] == "mesh_force") & rows["metric"].isin(("mean", "peak_to_peak"))
                  & rows["quantity"].isin([f"{m}.force" for m in backlash])]
    if forces.empty:
        return steady
    wide = forces.pivot_table(index=["speed_rpm", "quantity"], columns="metric", values="amplitude")
    kept = (wide["mean"] > 0.5 * wide["peak_to_peak"]).groupby(level="speed_rpm").all()
    return steady & kept.reindex(steady.index, fill_value=False)


def sweep_differences(run: RunUp, table: pd.DataFrame, natural_hz, band_rpm: float, solver: str = "lumped"):
    """The run-up's order curves against a stepped sweep's harmonic amplitudes (a sweep table,
    :mod:`gearcheck.compare.studies.sweep`: rows with metric "harmonic"): per quantity and order, (quantity, mesh
    label, harmonic, order, relative differences |tracked - steady| / steady) at the sweep's speeds where the
    comparison means something -- the order significant there (above :data:`SIGNIFICANT` of its largest), farther
    than ``band_rpm`` from the speeds at which its frequency meets a natural frequency (``natural_hz``: there the
    run-up's rate shifts and lowers the peak, :mod:`gearcheck.compare.studies.resonance_passage`), the teeth in
    contact (:func:`contact_kept`)."""
    kept = contact_kept(table, run.backlash, solver)
    for (s, quantity), track in run.tracks.items():
        if s != solver:
            continue
        for label, k, order in run.orders:
            speed, steady = sweep_line(table, solver, quantity, label, k)
            if not speed.size:
                continue
            use = (steady > SIGNIFICANT * steady.max()) & kept.reindex(speed, fill_value=False).to_numpy(bool)
            if not use.any():
                yield quantity, label, k, order, np.zeros(0)
                continue
            comparison = against_sweep(track, order, speed[use], steady[use], resonance_speeds(order, natural_hz),
                                       band_rpm)
            yield quantity, label, k, order, np.abs(comparison.relative)


def against_sweep_table(run: RunUp, table: pd.DataFrame, natural_hz, band_rpm: float,
                        solver: str = "lumped") -> pd.DataFrame:
    """:func:`sweep_differences` per quantity and order: how many speeds compared, the median and the largest."""
    return pd.DataFrame([{"quantity": q, "mesh": label, "harmonic": k, "order": order, "speeds_compared": int(d.size),
                          "median": float(np.median(d)) if d.size else None,
                          "largest": float(d.max()) if d.size else None}
                         for q, label, k, order, d in sweep_differences(run, table, natural_hz, band_rpm, solver)])


def _fail(field: str, message: str) -> GearcheckError:
    return GearcheckError(f"{field}: {message}")
