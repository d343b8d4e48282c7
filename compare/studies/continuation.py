"""Speed continuation of a sweep: each point started from its neighbour's final state, not from the static state.

A point started from the static state waits for its start to die away (the plan's settle time, 0.31 s on
hub-drive, 62 % of a 0.5 s point).  Started from the point at the neighbouring speed, carried over to the same
phase of every excitation (:meth:`gearcheck.shared.run_state.RunState.at_speed`), it starts off its own steady
state only by the change of that state between the two speeds, and waits only for that to die away.

How long that is: the free vibration decays as each solver's model's slowest mode does, so a start off the
steady state by a fraction rho of the response's fluctuation settles to the steady-state threshold theta
(:data:`gearcheck.compare.engine.align.STEADY_THRESHOLD`) in the time the model's own free vibration takes to fall
to theta / rho (:meth:`gearcheck.shared.side.Side.settling_time`; a start from the static state is off by the
whole fluctuation, rho = 1: the plan's settle time).  rho is measured, not assumed: the largest change of a mesh
force's steady waveform between the two points -- its average over its mesh cycle at the same phases of the drive,
every harmonic of the cycle in it -- over half its peak-to-peak at the neighbour (:func:`mismatch`).  (Measured on
the three mesh harmonics a sweep keeps, rho missed most of the start's mismatch on demo-3p: 7.7e-4 where the start
was off by 1.1e-2.)  A point runs until it holds
that settle time and then its window (:func:`window_length`), in segments: a guess from the neighbour's own rho,
extended where the measured rho asks for more.  Where rho reaches 1 (the neighbour's state is no better than the
static one: a jump between orbits under backlash near a resonance) or the run would outgrow the point's duration,
the point is run again from the static state, and its table says so (``start`` = "cold: continuation did not
settle").

Both solvers read a continued point over one window, and their continued waveforms must agree within
:data:`PARTED` (each within the steady threshold of its steady state): where contacts open and close (backlash
near a resonance), two chains that differ by their integration errors can reach two different orbits, which a
cross-check of the solvers would read as a disagreement between them (hub-drive above 1380 rpm: waveforms apart
by up to 0.27 of half their peak-to-peak, where from rest they agree to 2.6e-4).  Such a point runs every solver
from rest (``start`` = "cold: the solvers' continuations parted"), and the point after it too, without trying
(contacts that part two chains at one speed mostly do at the next: "... parted at the previous speed"); the
one after that tries again.

A chain is at most :data:`CHAIN_POINTS` points of one parameter set at neighbouring speeds (at most
:data:`MAX_SPEED_STEP` apart), so the sweep's table does not depend on how many workers share its chains: the
chains are the plan's, each the same run on any backend, and a resumed chain goes on from its last cached
point's final state (kept, losslessly, in that point's cache file) to the same bits.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass

import numpy as np

from gearcheck.compare.engine.align import STEADY_THRESHOLD, STEADY_WINDOW_CYCLES
from gearcheck.shared import parquet_bytes
from gearcheck.shared.results import TimeResult
from gearcheck.shared.run_state import RunState
from gearcheck.shared.settings import RunSettings

CHAIN_POINTS = 16  # points of a chain: the first starts from the static state
MAX_SPEED_STEP = 0.1  # neighbours further apart (relative to the slower) start a new chain
STATE = "gearcheck.state"  # a point table's metadata: {solver: [final state (RunState text), rho, waveforms]}
PARTED = 2 * STEADY_THRESHOLD  # two solvers' continued waveforms further apart than this are on two orbits
START = "gearcheck.start"  # a point table's metadata: how the point started (its rows' ``start``)
PARTED_START = "cold: the solvers' continuations parted"


def link(points: list) -> list:
    """``points`` (in the sweep's order) with each one that continues its predecessor marked so (``after``: the
    predecessor's key, ``after_rpm``: its speed): consecutive points of one parameter set at speeds at most
    :data:`MAX_SPEED_STEP` apart, at most :data:`CHAIN_POINTS` to a chain."""
    linked, length = [], 0
    for p in points:
        prev = linked[-1] if linked else None
        near = (prev is not None and prev.sample == p.sample and p.speed_rpm is not None and prev.speed_rpm is not None
                and max(p.speed_rpm, prev.speed_rpm) <= (1 + MAX_SPEED_STEP) * min(p.speed_rpm, prev.speed_rpm))
        length = length + 1 if near and length < CHAIN_POINTS else 1
        linked.append(dataclasses.replace(p, after=prev.key, after_rpm=prev.speed_rpm) if length > 1 else p)
    return linked


@dataclass(frozen=True)
class Chain:
    """Points that go on from one another (the first from ``before``, its predecessor's table, or from the static
    state where that is None): one unit of work of the sweep's backends."""

    points: tuple
    before: bytes | None = None

    @property
    def key(self) -> str:
        return self.points[0].key


def chains(points: list, tables: dict) -> list[Chain]:
    """The work left of ``points``: each chain's points from its first whose table is not in ``tables`` (key ->
    Parquet bytes) on, started from its predecessor's table."""
    runs: list[list] = []
    for p in points:
        if p.after and runs and runs[-1][-1].key == p.after:
            runs[-1].append(p)
        else:
            runs.append([p])
    work = []
    for run in runs:
        left = next((i for i, p in enumerate(run) if p.key not in tables), None)
        if left is not None:
            work.append(Chain(tuple(run[left:]), tables[run[left - 1].key] if left else None))
    return work


def carried(before: bytes | None, solver: str) -> tuple[RunState | None, float | None, dict | None]:
    """(final state, rho, steady waveforms of the mesh forces, :func:`waveforms`) of ``solver`` at the point whose
    table is ``before``; (None, None, None) where there is none to go on from (no predecessor, or the solver failed
    there)."""
    kept = json.loads(_metadata(before).get(STATE.encode(), b"{}")).get(solver)
    if kept is None:
        return None, None, None
    state, rho, shapes = kept
    return RunState.from_text(state), rho, {name: (p2p, np.array(w)) for name, (p2p, w) in shapes.items()}


def started(before: bytes | None) -> str | None:
    """How the point whose table is ``before`` started (None: no such point)."""
    return _metadata(before).get(START.encode(), b"").decode() or None


def _metadata(before: bytes | None) -> dict:
    """The schema metadata of the point table ``before`` (empty where there is none)."""
    return {} if before is None else parquet_bytes.metadata(before)


BINS = 64  # phases of a mesh cycle at which a waveform is averaged


def waveforms(run: TimeResult, groups, start: float) -> dict:
    """The steady waveform of every mesh force of ``groups`` ((forces, cycle) of the plan's steady-state test):
    its average over the whole cycles of ``run`` that end with it, from ``start`` on, at :data:`BINS` phases of the
    cycle counted from t = 0 (the same phases of the drive at every speed), with its peak-to-peak there:
    {name: (peak-to-peak, waveform)}.  It holds every harmonic of the cycle, where the sweep's lines hold three."""
    t = run.t
    shapes = {}
    for forces, cycle in groups:
        window = t >= start
        whole = math.floor((t[-1] - t[window][0]) / cycle + 1e-3)  # two grids a step apart: the same cycles
        if whole >= 1:
            window &= t >= t[-1] - whole * cycle - 1e-12
        phase = np.minimum((np.mod(t[window] / cycle, 1.0) * BINS).astype(np.int64), BINS - 1)
        counts = np.maximum(np.bincount(phase, minlength=BINS), 1)
        for name in forces:
            x = run[name][window]
            shapes[name] = (float(np.ptp(x)), np.bincount(phase, x, minlength=BINS) / counts)
    return shapes


def kept(state: RunState, rho: float | None, shapes: dict) -> list:
    """What a point's table keeps of a solver's run for the next point to go on from (:func:`carried`)."""
    return [state.to_text(), rho, {name: [p2p, w.tolist()] for name, (p2p, w) in shapes.items()}]


def mismatch(now: dict, before: dict) -> float:
    """rho: the largest change of a mesh force's steady waveform between two points, over half its peak-to-peak at
    the earlier point (infinite where a force cannot be compared)."""
    rho = 0.0
    for name, (p2p, w) in before.items():
        if name not in now or not p2p > 0:
            return math.inf
        rho = max(rho, float(np.max(np.abs(now[name][1] - w))) / (0.5 * p2p))
    return rho if np.isfinite(rho) else math.inf


def window_length(plan, lines: list) -> float:
    """How long a continued point's steady window lasts: every line resolved (2 / the closest spacing of two lines
    or of a line and DC, the Hann window's main lobe) and ``STEADY_WINDOW_CYCLES`` of the slowest mesh cycle, the
    window the plan's decay rule asks of a run from the static state."""
    freqs = sorted({f for _, _, f in lines})
    spacing = min([freqs[0]] + [b - a for a, b in zip(freqs, freqs[1:])]) if freqs else math.inf
    return max(2.0 / spacing, STEADY_WINDOW_CYCLES * plan.cycle)


def settle_after(side, rho: float | None) -> float:
    """The time a start off the steady state by ``rho`` takes to settle to the steady threshold: the time the
    side's own free vibration takes to fall to theta / rho (0 where rho <= theta; the lumped model's and the twin's
    differ by 0.2 % on hub-drive)."""
    if rho is None or rho <= STEADY_THRESHOLD:
        return 0.0
    return side.settling_time(STEADY_THRESHOLD / min(rho, 1.0))


def joined(results: list[TimeResult]) -> TimeResult:
    """Runs that go on from one another as one run (each one's first sample, its predecessor's last, dropped)."""
    first = results[0]
    if len(results) == 1:
        return first
    t = np.concatenate([first.t] + [r.t[1:] for r in results[1:]])
    values = np.concatenate([first.values] + [r.values[1:] for r in results[1:]])
    return TimeResult(first.train, first.solver, t, first.signals, values, first.settle_time, first.info)


def run_over(side, settings: RunSettings, state: RunState | None, dense: float, end: float):
    """(run, final state) of ``side`` from ``state`` (None: its own start at t = 0) to ``end`` (at the step and with
    the signals of ``settings``) sampled at every step from ``dense`` on, and before that only where it starts and
    ends: a point's settling stretch, which nothing reads, takes no memory.  The run is None where ``end`` is not a
    step away."""
    results, now, t = [], state, 0.0 if state is None else state.t
    for stop, sparse in ((dense, True), (end, False)):
        steps = round((stop - t) / settings.dt)
        if steps > 0:
            span = steps * settings.dt  # whole steps: sampled once at the end, the sparse stretch ends on its step
            result, now = side.run_from(dataclasses.replace(settings, duration=span, start=t,
                                                            output_dt=span if sparse else None), now)
            results.append(result)
            t = now.t
    return (joined(results) if results else None), now


def run_continued(side, settings: RunSettings, state: RunState, rho_guess: float | None, window: float, groups,
                  before: dict):
    """The continued run of ``side`` from ``state`` (already at the point's speed), at the step and with the signals
    of ``settings``: (run, its steady start, rho, the state it ended in, its waveforms), or None where it does not
    settle within ``settings.duration``.  ``window``: how long the steady window must be; ``groups``: the plan's
    steady-state groups; ``before``: the neighbour's waveforms.  The run waits the settle time of ``rho_guess`` (the
    neighbour's rho) sampled sparsely, then holds the window; where the rho it measures there asks for longer, it
    goes on to that settle time and a window after it."""
    t0 = state.t
    start = t0 + settle_after(side, rho_guess)
    results, now = [], state
    while True:
        if start + window - t0 > settings.duration:
            return None
        result, now = run_over(side, settings, now, start, start + window)
        if result is not None:
            results.append(result)
        run = joined(results)
        shapes = waveforms(run, groups, start)
        rho = mismatch(shapes, before)
        if rho >= 1.0:
            return None
        if t0 + settle_after(side, rho) <= start + 1e-12:
            return run, start, rho, now, shapes
        start = t0 + settle_after(side, rho)
