"""Where a train run's signals jump: at the stiffness switches of the meshes that feed them, as Newton's law says,
and nowhere else (:func:`gearcheck.shared.results.signal_jumps`), measured on both solvers' samples; and what
reading each signal's lines with its own switches alone gains (:meth:`gearcheck.compare.engine.plan.TrainPlan.
switches`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.compare.engine.line_projection import harmonics, singularities
from gearcheck.compare.engine.plan import TrainPlan
from gearcheck.compare.studies.sweep import mesh_groups
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide
from gearcheck.shared.results import signal_jumps, train_signals
from gearcheck.shared.settings import RunSettings
from gearcheck.train.loader import load_train
from gearcheck.train.variants import edited

TORSIONAL_PLANETS = (r"^\[stages.planet\]", "[stages.planet]\ntorsional = true")


@pytest.mark.parametrize("solver", ["lumped", "mujoco"])
@pytest.mark.parametrize("planets", ["on elastic bearings", "torsional"])
def test_signals_jump_and_kink_at_their_meshes_switches_as_newtons_law_says(planets, solver):
    """demo-3p's rectangular stiffness jumps by its whole value twice a mesh cycle, and its switches are known.  At
    each switch of mesh j that no other lies within four samples of, the jumps measured from three samples each
    side (a run at a quarter of the default step) are: mesh j's force Delta k delta (its deflection is continuous),
    every other mesh force none; the sun's angular acceleration r_b Delta F_j / I about its axis where j is a sun
    mesh, the ring's where j is a ring mesh, each none otherwise; the carrier's none while the planets' bearings
    are elastic (MuJoCo's 4.5e-4 of the sun's lever, its tendons' nominal geometry, which :func:`signal_jumps`
    keeps), and, once the planets ride their pins rigidly (torsional), r_c cos(alpha) Delta F_j / (I_c + sum m_p
    r_c^2) at every mesh's switch: the tangential share of the force at the pin, on the carrier and its planets'
    masses.  Each to 1e-3 of the largest jump of its kind; :func:`signal_jumps` says the same.  A planet's
    elastic bearing force k Delta x + c Delta v is continuous, and its slope changes by c Delta a: by c sin(alpha)
    Delta F_j / m_p radially and c cos(alpha) Delta F_j / m_p tangentially at its own meshes' switches, not at the
    other planets' (to 3 % of the change: a slope from three samples is good to 1.5 % here)."""
    spec = load_train("demo-3p") if planets == "on elastic bearings" else \
        edited("demo-3p", [TORSIONAL_PLANETS], "torsional")
    side = LumpedSide(spec) if solver == "lumped" else MujocoSide(spec)
    duration = 0.03
    meshes = [m.id for m in spec.meshes]
    centrals = ("stage1.sun", "stage1.ring", "stage1.carrier")
    bearings = [] if planets == "torsional" else \
        [(p, d) for p in spec.stages[0].planets for d in ("radial", "tangential")]
    names = [f"{m}.{q}" for m in meshes for q in ("force", "dte", "stiffness")] + [f"{c}.alpha" for c in centrals] + \
        [f"{p}.bearing_{d}.force" for p, d in bearings]
    run, _ = side.run_from(RunSettings(duration, dt=side.default_step() / 4, signals=tuple(names)))
    window = run.t >= duration / 2
    t = run.t[window]
    plan = TrainPlan.of(spec, LumpedSide(spec), duration)
    every = plan.switch_times(t[0], t[-1])
    stage = spec.stages[0]
    planets_inertia = sum(spec.members[p].mass for p in stage.planets) * stage.carrier_radius**2
    rule = signal_jumps(spec)
    for j, mesh in enumerate(spec.meshes):
        own = plan.switch_times(t[0], t[-1], [j])
        isolated = np.array([s for s in own if np.sum(np.abs(every - s) < 4 * (t[1] - t[0])) == 1])
        assert isolated.size >= 4
        times, measured, slopes = singularities(t, np.stack([run[n][window] for n in names], axis=1), isolated)
        jump, slope = dict(zip(names, measured.T)), dict(zip(names, slopes.T))
        force = jump[f"{mesh.id}.force"]
        for i, other in enumerate(meshes):
            delta = np.interp(times, t, run[f"{other}.dte"][window])
            expected = jump[f"{other}.stiffness"] * delta if i == j else 0.0
            assert np.abs(jump[f"{other}.force"] - expected).max() <= 1e-3 * np.abs(force).max()
            assert (j in rule[f"{other}.force"].meshes) == (i == j)
        tangential = stage.carrier_radius * math.cos(mesh.geometry.pressure_angle)
        for central in centrals:
            member = spec.members[central]
            if central == mesh.central:
                lever, inertia = mesh.central_gear.base_radius, member.inertia
            elif member.kind == "carrier" and planets == "torsional":
                lever, inertia = tangential, member.inertia + planets_inertia
            else:
                lever, inertia = 0.0, member.inertia
            moment = inertia * np.abs(jump[f"{central}.alpha"])
            assert np.abs(moment - lever * np.abs(force)).max() <= 1e-3 * mesh.central_gear.base_radius * \
                np.abs(force).max(), (mesh.id, central)
            assert (j in rule[f"{central}.alpha"].meshes) == (lever > 0 or member.kind == "carrier")
        angle = mesh.geometry.pressure_angle
        for planet, direction in bearings:
            bearing = spec.members[planet]
            scale = bearing.bearing.radial_damping * np.abs(force) / bearing.mass
            share = (math.sin(angle) if direction == "radial" else math.cos(angle)) if planet == mesh.planet else 0.0
            kink = np.abs(slope[f"{planet}.bearing_{direction}.force"])
            assert np.abs(kink - share * scale).max() <= 0.03 * scale.max(), (mesh.id, planet, direction)
            assert jump[f"{planet}.bearing_{direction}.force"] == pytest.approx(0.0, abs=1e-3 * np.abs(force).max())
            assert (j in rule[f"{planet}.bearing_{direction}.force"].kinks) == (planet == mesh.planet)


def test_lines_read_with_each_signals_own_switches_are_accurate_to_the_integration():
    """hub-drive at 1100 rpm, where 20 of the 724 switches of its 14 meshes in 0.15 s lie within three samples of
    another: read with every mesh's switches, such neighbours are measured as one jump at their mean instant, and
    a signal that does not jump at one of them takes a jump it does not have.  The lines of every gated signal
    (those at least a tenth of their quantity's largest) at the default step h, against the same run at h / 4, 90th
    percentile of the relative error: 3.3e-4 with each signal's own jumps and kinks, 3.3e-2 with a jump at every
    mesh's switch, when written."""
    spec = load_train("hub-drive", 1100.0)
    side = LumpedSide(spec)
    duration, start = 0.12, 0.06
    plan = TrainPlan.of(spec, side, duration)
    names = [s.name for s in train_signals(spec) if s.compared]
    freqs = np.array([k * f for _, f in mesh_groups(spec, side.model.kin) for k in (1, 2, 3)])
    h = side.default_step()
    runs = [side.run_from(RunSettings(duration, dt=h / d, signals=tuple(names)))[0] for d in (1, 4)]

    def lines(run, own: bool):
        window = run.t >= start - 1e-12
        t = run.t[window]
        x = np.stack([run[n][window] for n in names], axis=1)
        singular = plan.singularities(names, t[0], t[-1]) if own else (plan.switch_times(t[0], t[-1]),)
        return harmonics(t, x, freqs, 1.0 / (t[1] - t[0]), *singular)

    errors = {}
    for own in (True, False):
        reference = lines(runs[1], own)
        amplitude = np.abs(reference)
        counted = amplitude >= 0.1 * amplitude.max(axis=0)
        errors[own] = np.quantile(np.abs(lines(runs[0], own) - reference)[counted] / amplitude[counted], 0.9)
    assert errors[True] < 2e-3
    assert errors[False] > 10 * errors[True]
