"""Does the RV reducer's pin contact set move in the steady state?  Time marching with compression-only pins
against time marching with the pins held to harmonic balance's static contact pattern per eccentric angle.

Harmonic balance takes, at each eccentric angle of its grid, the pins that touch in the static solution under
the mean load, as bilateral springs.  This script marches the preset both ways for 0.16 s and compares the last
40 ms of each with harmonic balance on the (30, 4) lattice, as rms(harmonic - time) over the time response's AC
content, and counts how often a compression-only pin departs from the static pattern.  About 5 minutes on one core.
"""

import math
from dataclasses import fields, replace

import numpy as np

import gearcheck
from gearcheck.lumped import CycloidRows, harmonic_balance_response, parametric_problem, simulate
from gearcheck.shared import RunSettings

DURATION, WINDOW, GRID = 0.16, 0.04, 2048
COORDINATES = ("rv.sun.theta", "rv.carrier.theta", "rv.crank1.theta", "rv.planet1.tangential", "rv.disc1.x")

model = gearcheck.Train("rv-reducer").lumped.model
contacts: dict = {}
balance = harmonic_balance_response(parametric_problem(model, eccentric_grid=GRID, contacts=contacts), (30, 4))
stage = next(e for e in model.turning if isinstance(e, CycloidRows))
omega = abs(stage.omega_eccentric)
pattern = np.array([sets[0] for _, sets in sorted(contacts.items())])  # (GRID, discs x pins), angle 2 pi j / GRID


def static_pattern(t):
    return pattern[np.rint(omega * np.asarray(t) / (2 * math.pi / GRID)).astype(int) % GRID]


class HeldPins(CycloidRows):
    """The pins of the static pattern at the eccentric angle of time t, bilateral."""

    def forces(self, t, q, v):
        self.now = t
        return super().forces(t, q, v)

    def _pins(self, coefficients, q, v):
        delta, _ = super()._pins(coefficients, q, np.zeros_like(v))
        rate, _ = super()._pins(coefficients, v, np.zeros_like(v))  # the rows on v, less the clearance
        held = static_pattern(self.now).reshape(delta.shape)
        return delta, np.where(held, self.pin_stiffness * delta + self.pin_damping * (rate + self.clearance), 0.0)


held = replace(model, turning=[HeldPins(**{f.name: getattr(e, f.name) for f in fields(e)})
                               if isinstance(e, CycloidRows) else e for e in model.turning])
labels = model.dofs.labels()
for name, marched in (("compression-only pins", model), ("static pattern held", held)):
    run = simulate(marched, RunSettings(duration=DURATION), method="rk4-stages")
    window = run.t > DURATION - WINDOW
    q = balance.at(run.t[window])
    gaps = [np.sqrt(np.mean((q[:, labels.index(c)] - run.raw[c][window]) ** 2)) / np.std(run.raw[c][window])
            for c in COORDINATES]
    print(f"{name:>22}: " + "  ".join(f"{c} {g:.4f}" for c, g in zip(COORDINATES, gaps)))
    if marched is model:
        state = np.column_stack([run.raw[c] for c in labels])[window]
        touching = stage.pin_deflections(run.t[window], state).reshape(window.sum(), -1) > 0
        departs = touching != static_pattern(run.t[window])
        print(f"{'':>22}  samples with a pin off the static pattern: {departs.any(axis=1).mean():.3f}, "
              f"pins off per sample: {departs.sum(axis=1).mean():.3f}")
