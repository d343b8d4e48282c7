"""Mode shapes of the two solvers paired by the modal assurance criterion (Allemang & Brown 1982).

The MuJoCo twin's modes, mapped from its joints to the train's physical coordinates by its own Jacobians,
span the same shapes as the lumped model's: for every preset each lumped mode lies in the MuJoCo modes of
its frequency group to 1e-6 (measured 1 - 1e-12), the kinetic energy is the same quadratic form in both
(the mapped mass matrices agree), and deliberately broken pairings are named: swapped modes, a missing one.
"""

from types import SimpleNamespace

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.engine.mode_pairing import pair_modes
from gearcheck.lumped.side import LumpedSide
from gearcheck.mbd_models.side import MujocoSide


@pytest.mark.parametrize("preset", gearcheck.presets())
def test_the_twins_modes_are_the_reference_modes(preset):
    spec = gearcheck.load(preset)
    lumped, mujoco = LumpedSide(spec), MujocoSide(spec)
    pairing = pair_modes(spec.name, lumped, mujoco)
    assert pairing.paired.min() >= 1.0 - 1e-6, pairing.paired
    assert pairing.findings == []
    np.testing.assert_allclose(mujoco.physical_modes(mujoco.modes())[1], lumped.model.M,
                               atol=1e-9 * lumped.model.M.max())


def broken(side, permutation=None, drop=None):
    """A side whose mode shapes were reordered (or one replaced by another's) after its frequencies."""
    labels, M, shapes = side.physical_modes(side.modes())
    shapes = shapes.copy()
    if permutation is not None:
        shapes = shapes[:, permutation]
    if drop is not None:
        shapes[:, drop] = shapes[:, drop + 1]
    return SimpleNamespace(solver="broken", modes=side.modes, physical_modes=lambda modal: (labels, M, shapes))


def test_swapped_and_missing_modes_are_named():
    spec = gearcheck.load("demo-3p")
    lumped = LumpedSide(spec)
    f = lumped.modes().frequencies
    singles = [i for i in range(len(f)) if lumped.modes().multiplicity[i] == 1 and f[i] > 0]
    a, b = singles[0], singles[1]
    order = np.arange(len(f))
    order[[a, b]] = order[[b, a]]
    findings = pair_modes(spec.name, lumped, broken(lumped, permutation=order)).findings
    assert len(findings) == 2 and all(line.startswith("swapped") for line in findings)
    assert f"lumped mode {a + 1} " in findings[0] and f"broken mode {b + 1} " in findings[0]
    last = singles[-1]
    findings = pair_modes(spec.name, lumped, broken(lumped, drop=last - 1)).findings
    assert any(line.startswith("missing") and f"mode {last} " in line for line in findings), findings


def test_the_mac_command(tmp_path, capsys):
    out = tmp_path / "mac"
    assert main(["mac", "demo-4p", "--out", str(out)]) == 0
    assert {p.name for p in out.iterdir()} >= {"mac.png", "mac.json"}
    assert "each lumped mode lies in its frequency group's mujoco modes" in capsys.readouterr().out
