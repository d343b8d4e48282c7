"""Campbell diagram: natural frequencies of a turning train over a speed range, both solvers.

At each input speed the gyroscopic eigenproblem of each solver (:func:`gearcheck.api.modes` with a
speed; Cooley & Parker 2012): frequencies, growth rates and stability.  Mesh-frequency lines
(harmonics of every distinct mesh frequency, proportional to the speed) are drawn with their
crossings of the natural-frequency curves (the speeds where a mesh harmonic may excite a mode), and
speeds at which a mode grows (divergence or flutter) are shaded as instability zones.  The curves
are the modes ordered by frequency at each speed, so two modes that cross swap curves there.

A crossing is a resonance only if the harmonic reaches the mode.  Each crossing says ``excited`` True or False
from the lumped model turning at the crossing's speed: whether the line's phased mesh forces drive the mode that
crosses it (the mode of the damped model nearest the crossing's frequency; :func:`gearcheck.lumped.modal.
line_drives`), for any train.  With N equally spaced planets in one simple planetary stage this is Parker's (2000)
rule: harmonic l excites rotational modes only when l z_s / N is an integer, translational modes only when
l z_s +- 1 is a multiple of N, planet modes otherwise (``tests/test_modes_at_speed.py`` checks the crossings
against it; the forced-response test of the rule is ``tests/test_phasing.py``).  Without the lumped model's
drives (a train at rest; tip relief or a torque ripple, where they would count every mode), the rule decides
where it applies, and ``excited`` is None elsewhere.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gearcheck.shared.selection import chosen
from gearcheck.train.kinematics import kinematics
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.units import rpm_to_rad_s


@dataclass
class CampbellResult:
    train: str
    speeds_rpm: np.ndarray
    results: dict[str, list[ModalResult]]  # solver -> one modal result per speed
    mesh_lines: list[dict]  # {"mesh": ids, "harmonic": h, "hz_per_rpm": slope}
    crossings: list[dict] = field(default_factory=list)
    zones: list[dict] = field(default_factory=list)  # {"solver", "from_rpm", "to_rpm"}

    def frequencies(self, solver: str) -> np.ndarray:
        """(n_speeds, n_modes) in Hz."""
        return np.array([r.frequencies for r in self.results[solver]])

    @property
    def agreement(self) -> float | None:
        """The largest relative difference of the two solvers' elastic frequencies over all speeds."""
        if len(self.results) < 2:
            return None
        a, b = (self.frequencies(s) for s in self.results)
        elastic = a > 0
        return float(np.max(np.abs(a - b)[elastic] / a[elastic]))

    def plot(self, solvers=None):
        """The diagram as a :class:`matplotlib.figure.Figure` (no pyplot), of ``solvers`` (default: all)."""
        from gearcheck.compare.presentation.plots import campbell_figure

        shown = None if solvers is None else chosen("solvers", solvers, self.results, "a solver of this diagram")
        return campbell_figure(self, shown)

    def to_dict(self) -> dict:
        return {
            "train": self.train, "unit": "Hz", "speeds_rpm": self.speeds_rpm.tolist(),
            "solvers": {s: [{"speed_rpm": float(v), "stable": r.stable, "modes": _modes(r)}
                            for v, r in zip(self.speeds_rpm, rs)] for s, rs in self.results.items()},
            "max_relative_difference": self.agreement,
            "mesh_lines": self.mesh_lines, "crossings": self.crossings, "instability_zones": self.zones,
        }


def _modes(r: ModalResult) -> list[dict]:
    """One speed's modes as the diagram's file holds them: frequency, growth rate, stability, type."""
    if r.growth is None or r.stability is None:
        raise ValueError("a Campbell diagram holds modes at speed, each with its growth rate")
    return [{"frequency_hz": float(f), "growth_rate_1_s": float(g), "stability": st, "type": t}
            for f, g, st, t in zip(r.frequencies, r.growth, r.stability, r.types)]


def campbell(spec, speeds_rpm, modes_at, solvers=("lumped", "mujoco"), harmonics: int = 3,
             drives_at=None) -> CampbellResult:
    """The Campbell diagram of ``spec`` at ``speeds_rpm`` (ascending, >= 0); ``modes_at(solver, speed_rad_s)``
    gives one solver's :class:`ModalResult` at a speed; ``harmonics`` mesh harmonics are drawn;
    ``drives_at(speed_rad_s, lines)`` (optional: the lumped model's
    :meth:`~gearcheck.lumped.side.LumpedSide.drives_at_speed`) the modes' natural frequencies and which each line
    (mesh frequency at the train's speed, harmonic) drives, which decide each crossing's ``excited``."""
    speeds = np.asarray(speeds_rpm, dtype=float)
    results = {s: [modes_at(s, rpm_to_rad_s(v)) for v in speeds] for s in solvers}
    lines = _mesh_lines(spec, harmonics)
    out = CampbellResult(spec.name, speeds, results, lines)
    reference = solvers[0]
    f = out.frequencies(reference)
    excited = _excitation(spec, drives_at)
    for line in lines:
        excitation = line["hz_per_rpm"] * speeds
        for mode in range(f.shape[1]):
            gap = f[:, mode] - excitation
            for i in np.where((np.sign(gap[:-1]) * np.sign(gap[1:]) <= 0) & (gap[:-1] != gap[1:]))[0]:
                s = speeds[i] + (speeds[i + 1] - speeds[i]) * gap[i] / (gap[i] - gap[i + 1])
                if f[i, mode] > 0:
                    kind = results[reference][i].types[mode]
                    out.crossings.append({"speed_rpm": float(s), "frequency_hz": float(line["hz_per_rpm"] * s),
                                          "mode": mode + 1, "type": kind, "meshes": line["meshes"],
                                          "harmonic": line["harmonic"],
                                          "excited": excited(line, kind, float(s))})
    for solver, rs in results.items():
        unstable = np.array([not r.stable for r in rs])
        for start, stop in _runs(unstable):
            out.zones.append({"solver": solver, "from_rpm": float(speeds[start]), "to_rpm": float(speeds[stop])})
    return out


def _excitation(spec, drives_at):
    """excited(line, mode type, speed in rpm) of a crossing at the line's frequency there: whether the line drives
    the mode of the lumped model at that speed nearest that frequency (:func:`nearest_mode_driven`; ``drives_at``,
    given for a turning train; None for a line of no gear mesh, a cycloid stage's pin pass), else Parker's rule
    where it applies (:func:`phasing_rule`), else None."""
    if drives_at is None or not spec.operating.input_speed:
        phasing = phasing_rule(spec)
        return lambda line, kind, rpm: None if phasing is None else excites(line["harmonic"], kind, *phasing)
    own = kinematics(spec).mesh_frequency
    gears = {mesh.id for mesh in spec.meshes}  # a cycloid stage's pin pass is a line of no gear mesh: None

    def excited(line, kind, rpm):
        if line["meshes"][0] not in gears:
            return None
        natural, _, driven = drives_at(rpm_to_rad_s(rpm), [(own[line["meshes"][0]], line["harmonic"])])
        return nearest_mode_driven(natural, driven[:, 0], line["hz_per_rpm"] * rpm)

    return excited


def nearest_mode_driven(natural, driven, frequency: float) -> bool | None:
    """Whether the mode nearest ``frequency`` (Hz) among the modes ``natural`` (Hz) is ``driven``; None where the
    nearest is not clearly it (the next mode at most twice as far: a pair that has barely split, a crossing
    interpolated between two close modes) and the two are not driven alike."""
    distance = np.abs(np.asarray(natural, dtype=float) - frequency)
    order = np.argsort(distance, kind="stable")
    first = bool(driven[order[0]])
    if order.size > 1 and distance[order[1]] <= 2.0 * distance[order[0]] and bool(driven[order[1]]) != first:
        return None
    return first


def phasing_rule(spec) -> tuple[int, int] | None:
    """(N, z_s) of a train that is one simple planetary stage with N equally spaced planets (one sun, planets of
    one kind), for :func:`excites`; None where the rule does not apply."""
    if len(spec.stages) != 1 or spec.cycloids:
        return None
    stage = spec.stages[0]
    suns = [spec.members[c] for c in stage.centrals if spec.members[c].kind == "sun"]
    simple = all(spec.members[p].kind == "planet" and len(spec.members[p].gears) == 1 for p in stage.planets)
    if not stage.equally_spaced or len(suns) != 1 or len(suns[0].gears) != 1 or not simple:
        return None
    teeth = next(iter(suns[0].gears.values())).teeth
    return None if teeth is None else (len(stage.planets), teeth)  # an idealised sun has no teeth to phase


def excites(harmonic: int, kind: str, planets: int, sun_teeth: int) -> bool | None:
    """Whether mesh harmonic ``harmonic`` reaches a mode of type ``kind`` through the phases of ``planets``
    equally spaced planets on a sun of ``sun_teeth`` (Parker 2000): by l z_s mod N, 0 rotational, +-1
    translational, else planet modes; None for another type."""
    r = harmonic * sun_teeth % planets
    reach = {"rotational": r == 0, "translational": r in (1, planets - 1), "planet": r not in (0, 1, planets - 1)}
    return reach.get(kind)


def _mesh_lines(spec, harmonics: int) -> list[dict]:
    """Each distinct mesh frequency per rpm of the input, with the meshes that have it, times 1..harmonics (a train
    at rest: its lines turning; an idealised mesh has no mesh cycle, so no line)."""
    turning = spec if spec.operating.input_speed else spec.with_operating(input_speed=np.pi / 30.0)
    kin = kinematics(turning)
    per_rpm: dict[float, list[str]] = {}
    rpm = turning.operating.input_speed * 30.0 / np.pi
    for mesh_id, f in kin.mesh_frequency.items():
        if f == 0.0:
            continue
        key = round(f / rpm, 12)
        per_rpm.setdefault(key, []).append(mesh_id)
    return [{"meshes": sorted(ids), "harmonic": h, "hz_per_rpm": slope * h}
            for slope, ids in sorted(per_rpm.items()) for h in range(1, harmonics + 1)]


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of every run of True in ``mask``."""
    runs, start = [], None
    for i, flag in enumerate(mask):
        if flag and start is None:
            start = i
        if not flag and start is not None:
            runs.append((start, i - 1))
            start = None
    if start is not None:
        runs.append((start, len(mask) - 1))
    return runs
