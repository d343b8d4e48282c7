"""How the cross-check reads the reference's signals: what a comparison plan says.

A plan answers, for one pair of runs: are the two put on one grid by anti-aliased resampling or
compared sample by sample on the grid they share; is there a steady state to detect and with which
cycle; how far to search for a lag and which spectral lines to measure in each signal; what sets the
negligibility scale of each kind; below which floor a solver cannot resolve a kind; and which
operating-point settings the report states.

Each plan is built from the reference side, the one whose runs it reads (:meth:`TrainPlan.of`,
:meth:`TransientPlan.of`):

* :class:`TrainPlan` -- a gear train in steady operation: resampled onto the lower of the two
  output rates, steady window from each stage's mesh forces over its own mesh cycle or from the
  decay of the reference's free vibration (:func:`gearcheck.compare.engine.align.steady_state`),
  lags within half a mesh period, mesh harmonics and carrier sidebands, translational scale also from r alpha of every
  central member, and MuJoCo's round-off floor of absolute angles (:func:`round_off_floor`);
* :class:`TransientPlan` -- a start-stop transient on one shared step grid (the 4-DOF models of
  Matejic et al. 2021 and their twin): the whole record, lags within one step, lines at the natural
  frequencies.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from gearcheck.compare.engine.align import STEADY_CYCLES, STEADY_THRESHOLD, STEADY_WINDOW_CYCLES
from gearcheck.compare.engine.metrics import spectral_lines
from gearcheck.shared.results import signal_jumps, train_signals
from gearcheck.shared.stepping import transient_step
from gearcheck.train.excitation import Excitation
from gearcheck.train.kinematics import kinematics


@dataclass(frozen=True)
class TrainPlan:
    spec: object
    mesh_frequency: dict[str, float]  # mesh id -> Hz
    stage_frequencies: dict[str, tuple[float, float]]  # stage -> (slowest mesh frequency, carrier frequency) Hz
    floors: dict[str, float]  # kind -> the smallest amplitude a solver resolves
    settle: float | None = None  # s: the reference's free vibration decays to the steady threshold
    operating: dict = field(default_factory=dict)  # the operating point the report states
    resample: bool = True
    detect_steady: bool = True
    switch_times: object = None  # (t0, t1) -> the instants in between at which a mesh stiffness jumps

    @classmethod
    def of(cls, spec, reference, duration: float) -> "TrainPlan":
        """The plan of ``spec`` for runs of ``duration`` s of the side ``reference``: its highest natural
        frequency sets the round-off floor, the decay of its free vibration the earliest steady state.  Under an
        operating history the run is a transient by design: no steady state is sought, the whole run compared."""
        kin = kinematics(spec)
        stages = {}
        for stage in spec.stages:
            f_mesh = min(kin.mesh_frequency[m.id] for m in spec.meshes if m.stage == stage.name)
            stages[stage.name] = (f_mesh, abs(kin.speeds[stage.carrier]) / (2 * math.pi))
        return cls(spec, dict(kin.mesh_frequency), stages, round_off_floor(spec, kin, reference.omega_max(), duration),
                   reference.settling_time(STEADY_THRESHOLD), reference.operating(),
                   detect_steady=spec.operating.history is None, switch_times=Excitation(spec, kin).switch_times)

    def steady_groups(self, names) -> list[tuple[list[str], float]]:
        """The mesh-force signals among ``names`` with the cycle over which they repeat in steady state: all
        of them over the common period of their meshes when its mesh frequencies are in small-integer ratios
        (:func:`common_period`), else each stage's over its own slowest mesh cycle (an RV reducer's pin pass has
        no mesh-force signal: its frequency does not set the cycle)."""
        forces = [n for n in names if n.endswith(".force") and n.rsplit(".", 1)[0] in self.mesh_frequency]
        period = common_period([self.mesh_frequency[n.rsplit(".", 1)[0]] for n in forces])
        if period is not None:
            return [(forces, period)]
        groups = []
        for stage, (f_mesh, _) in self.stage_frequencies.items():
            forces = [n for n in names if n.startswith(f"{stage}.") and n.endswith(".force")
                      and n.rsplit(".", 1)[0] in self.mesh_frequency]
            if forces:
                groups.append((forces, 1.0 / f_mesh))
        return groups

    @functools.cached_property
    def _jumps(self) -> dict:
        return signal_jumps(self.spec)

    def singularities(self, names, t0: float, t1: float) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """:func:`signal_singularities` of ``names`` in this plan's runs."""
        return signal_singularities(self._jumps, self.switch_times, names, t0, t1)

    def needed_duration(self) -> float | None:
        """The shortest run whose steady state the decay of the free vibration guarantees."""
        return None if self.settle is None or math.isinf(self.settle) else \
            self.settle + STEADY_WINDOW_CYCLES * self.cycle

    def detectable(self, duration: float) -> bool:
        """Whether a run of ``duration`` s holds enough cycles for the cycle test of its steady state
        (:func:`~gearcheck.compare.engine.align.steady_start`: ``STEADY_CYCLES`` + 1 of each group of the train's
        compared mesh forces); a shorter one finds a steady state only by the decay of its free vibration."""
        names = [s.name for s in train_signals(self.spec) if s.compared]
        return all(duration >= (STEADY_CYCLES + 1) * cycle for _, cycle in self.steady_groups(names))

    @property
    def cycle(self) -> float:
        """The period of the slowest mesh: the cycle of the steady-state test and of the plots."""
        return 1.0 / min(f for f, _ in self.stage_frequencies.values())

    @property
    def cycle_of(self) -> str:
        """What :attr:`cycle` is the cycle of, in words: "the stage2 mesh" (each stage's meshes have their own)."""
        return f"the {min(self.stage_frequencies, key=lambda stage: self.stage_frequencies[stage][0])} mesh"

    def _frequencies(self, name: str) -> tuple[float, float]:
        f_mesh, f_carrier = self.stage_frequencies.get(name.split(".")[0], next(iter(self.stage_frequencies.values())))
        mesh = name.rsplit(".", 1)[0]
        return self.mesh_frequency.get(mesh, f_mesh), f_carrier

    def max_lag(self, name: str) -> float:
        return 0.5 / self._frequencies(name)[0]

    def lines(self, name: str, duration: float) -> list[tuple[str, float]]:
        return spectral_lines(*self._frequencies(name), duration)

    def scale_from(self, name: str) -> list[tuple[str, float]]:
        """An angular acceleration alpha of a central member sets the translational scale r alpha."""
        member = name.rsplit(".", 1)[0]
        if name.endswith(".alpha") and not self.spec.members[member].orbits:
            return [("acceleration", central_radius(self.spec, member))]
        return []


def signal_singularities(rule: dict, switch_times, names, t0: float,
                         t1: float) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """For each of ``names``, the instants in (t0, t1) at which it may jump, and those at which only its slope may,
    by ``rule`` (:func:`~gearcheck.shared.results.signal_jumps`; every switch for a signal it does not know) and
    ``switch_times`` (:meth:`~gearcheck.train.excitation.Excitation.switch_times`): the ``switches`` and ``kinks`` of
    :func:`~gearcheck.compare.engine.line_projection.harmonics`.  Read with its own switches alone, a signal's
    jumps stay apart: at hub-drive's step, 20 of the 724 switches of all its meshes in 0.15 s at 1100 rpm lie
    within three samples of another, where they can only be measured together, and a signal that does not jump at
    one of them would take the other's jump."""
    found: dict = {}

    def at(meshes, corners: bool) -> np.ndarray:
        if (meshes, corners) not in found:
            found[meshes, corners] = switch_times(t0, t1, meshes, corners)
        return found[meshes, corners]

    switches, kinks = [], []
    for name in names:
        where = rule.get(name)
        switches.append(at(None, True) if where is None else at(where.meshes, where.corners))
        kinks.append(at(None, True) if where is None else np.empty(0) if where.kinks is None else
                     at(where.kinks, True))
    return switches, kinks


@dataclass(frozen=True)
class TransientPlan:
    frequencies: np.ndarray  # the reference's natural frequencies, Hz
    dt: float  # the shared step
    operating: dict = field(default_factory=dict)
    floors: dict = field(default_factory=dict)
    resample: bool = False
    detect_steady: bool = False
    switch_times: object = None

    @classmethod
    def of(cls, reference, test) -> "TransientPlan":
        """The plan of a start-stop transient of ``reference`` and ``test`` from rest: the reference's natural
        frequencies, one step that resolves both sides' highest (:func:`gearcheck.shared.stepping.transient_step`),
        the reference's operating point and both sides' counts of rigid modes."""
        modes = reference.modes(), test.modes()
        dt = transient_step(np.concatenate([m.frequencies for m in modes]))
        rigid = {name: m.types.count("rigid") for name, m in zip(("lumped", "mujoco"), modes)}
        return cls(modes[0].frequencies, dt, {**reference.operating(), "rigid_modes": rigid})

    @property
    def cycle(self) -> float:
        elastic = self.frequencies[self.frequencies > 0]
        return 1.0 / float(elastic.min())

    @property
    def cycle_of(self) -> str:
        return f"mode {int(np.argmax(self.frequencies > 0)) + 1}"

    def max_lag(self, name: str) -> float:
        return self.dt

    def lines(self, name: str, duration: float) -> list[tuple[str, float]]:
        return [(f"mode {i + 1}", float(f)) for i, f in enumerate(self.frequencies) if f > 0]

    def scale_from(self, name: str) -> list[tuple[str, float]]:
        return []


MAX_DENOMINATOR = 64  # mesh frequencies in ratios p/q with q up to this have a common period worth waiting for


def common_period(frequencies) -> float | None:
    """The shortest time in which every frequency (Hz) completes whole cycles, when their ratios to the
    lowest are fractions with denominators up to ``MAX_DENOMINATOR`` (to 1e-9); None otherwise."""
    f = sorted({float(x) for x in frequencies if x > 0})
    if not f:
        return None
    denominator = 1
    for x in f[1:]:
        ratio = Fraction(x / f[0]).limit_denominator(MAX_DENOMINATOR)
        if abs(float(ratio) * f[0] - x) > 1e-9 * x:
            return None
        denominator = math.lcm(denominator, ratio.denominator)
    return denominator / f[0]


def central_radius(spec, member: str) -> float:
    """Where a member's rotation is read as a tangential motion (:attr:`~gearcheck.train.spec.Member.
    reference_radius`: a central gear's pitch radius, a carrier's pin circle, a cycloid disc's rolling circle, a
    pin wheel's pin circle)."""
    return spec.members[member].reference_radius


def round_off_floor(spec, kin, omega_max: float, duration: float) -> dict[str, float]:
    """Accelerations below which a solver integrating absolute angles (MuJoCo: the carrier turns by
    Omega t radians) cannot resolve anything: a position known to eps Omega t r, seen through the
    stiffest mode, is an acceleration of omega_max^2 eps Omega t r (and omega_max^2 eps Omega t for
    angles), and a tilt is known to eps Omega t.  The lumped model integrates small vibrations about nominal
    motion and has no such floor."""
    turn = max(abs(w) for w in kin.speeds.values()) * duration
    radius = max(central_radius(spec, mid) for mid, m in spec.members.items() if not m.orbits)
    angular = omega_max ** 2 * np.finfo(float).eps * turn
    return {"angular_acceleration": angular, "acceleration": angular * radius,
            "tilt": np.finfo(float).eps * turn}
