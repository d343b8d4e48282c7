"""Run-ups: both solvers through a speed ramp, their mesh orders tracked (``gearcheck runup``)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.studies.runup import run_up


def test_mesh_orders_and_the_two_solvers_order_curves():
    """demo-3p (sun 22 in, ring 62 held): the mesh order of the input is z_s z_r / (z_s + z_r) = 16.238..., and the
    two solvers' order curves of a 1500 -> 3000 rpm run-up agree (measured 1e-6 of each quantity's largest)."""
    run = run_up(gearcheck.load("demo-3p"), 1500, 3000, 0.2, quantities=["stage1.planet1.sun.force",
                                                                          "stage1.ring.ay.world"], harmonics=2)
    assert [(m, k) for m, k, _ in run.orders] == [("stage1", 1), ("stage1", 2)]
    assert np.allclose([o for *_, o in run.orders], [22 * 62 / 84, 2 * 22 * 62 / 84], rtol=1e-12)
    assert max(run.agreement().values()) < 1e-4
    track = run.tracks[("lumped", "stage1.planet1.sun.force")]
    assert track.speed_rpm[0] < 1700 and track.speed_rpm[-1] > 2800  # blocks over the whole ramp
    table = run.table()
    assert set(table["solver"]) == {"lumped", "mujoco"} and np.all(table["amplitude"] >= 0)


def test_runup_command_writes_its_files(tmp_path, capsys):
    out = tmp_path / "runup"
    assert main(["runup", "demo-3p", "--from", "1500", "--to", "2000", "--duration", "0.1", "--solver", "lumped",
                 "--quantity", "stage1.planet1.sun.force", "--out", str(out)]) == 0
    names = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert names == ["order_stage1.planet1.sun.force.png", "orders.csv", "runup.json", "waterfall.png"]
    summary = json.loads((out / "runup.json").read_text())
    assert summary["rate_rpm_per_s"] == pytest.approx(5000.0)
    assert "lumped" in capsys.readouterr().out


@pytest.mark.parametrize("options, fragment", [
    (["--from", "2000", "--to", "1500"], "0 < from < to"),
    (["--from", "1500", "--to", "2000", "--against", "nowhere.parquet"], "nowhere.parquet"),
])
def test_runup_bad_input_one_line(tmp_path, capsys, options, fragment):
    assert main(["runup", "demo-3p", "--duration", "0.1", "--out", str(tmp_path / "o"), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0], err
    assert not (tmp_path / "o").exists()


def test_runup_against_a_stepped_sweep(tmp_path, capsys):
    """demo-3p has no backlash: a run-up's mesh orders are its stepped sweep's amplitudes away from the resonances
    (measured within 1.0 % at 2500 rpm/s), its rectangular meshes' jumps taken exactly and the runs sampled near the
    step; runup.json says how many speeds were compared."""
    sweep = tmp_path / "sweep"
    assert main(["sweep", "demo-3p", "--speeds", "1600:2400:5", "--solver", "lumped", "--duration", "0.1",
                 "--no-integration-check", "--workers", "1", "--out", str(sweep)]) == 0
    out = tmp_path / "runup"
    assert main(["runup", "demo-3p", "--from", "1500", "--to", "2500", "--duration", "0.4", "--solver", "lumped",
                 "--quantity", "stage1.planet1.sun.force", "--harmonics", "1", "--output-dt", "1e-5", "--against",
                 str(sweep / "sweep.parquet"), "--out", str(out)]) == 0
    compared = json.loads((out / "runup.json").read_text())["against_sweep"]
    assert compared["speeds_in_contact"] == compared["speeds"] == 5
    (order,) = compared["orders"]
    assert order["speeds_compared"] >= 3 and order["largest"] < 0.05, order
    # a mesh's deflection is continuous where its stiffness switches (Newton: its force jumps, its deflection does
    # not): read without a jump, its three orders at the default sampling are the sweep's within 0.6 % (measured
    # 0.17, 0.40 and 0.25 %); measured as if it jumped, a jump of sampling noise took them 0.20, 9.5 and 0.97 % away
    out = tmp_path / "runup-dte"
    assert main(["runup", "demo-3p", "--from", "1500", "--to", "2500", "--duration", "0.4", "--solver", "lumped",
                 "--quantity", "stage1.planet1.sun.dte", "--against", str(sweep / "sweep.parquet"),
                 "--out", str(out)]) == 0
    orders = json.loads((out / "runup.json").read_text())["against_sweep"]["orders"]
    assert len(orders) == 3 and all(o["speeds_compared"] >= 2 and o["largest"] < 0.006 for o in orders), orders
