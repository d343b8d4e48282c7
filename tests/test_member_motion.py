"""Every member's displacements, velocities and rotations, in both solvers (lumped.member_motion,
mbd_models.member_motion): each velocity is the rate of its displacement, the two solvers agree on them, and a run
writes and draws them."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.compare.engine.tolerances import DEFAULTS
from gearcheck.shared.results import motion_signals, units_of

DURATION = 0.003  # s: 900 steps of demo-3p, 1900 of the helical stage
RATES = (("x.carrier", "vx.relative"), ("y.carrier", "vy.relative"), ("theta", "omega.relative"), ("z", "vz"))


@pytest.fixture(scope="module", params=["demo-3p", "helical-planetary"])  # the helical stage's members slide axially
def runs(request):
    return {solver: gearcheck.simulate(request.param, solver, DURATION) for solver in ("lumped", "mujoco")}


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


@pytest.mark.parametrize("solver", ["lumped", "mujoco"])
def test_each_velocity_is_the_rate_of_its_displacement(runs, solver):
    """Central differences of the samples, (x_{i+1} - x_{i-1}) / 2h, are x' + h^2 x'''/6 + O(h^4), and the second
    difference of the velocity, v_{i+1} - 2 v_i + v_{i-1}, is h^2 x''' + O(h^4): so their RMS over the run is
    bounded by a quarter of its RMS (2/3 of the bound where the motion is smooth; a jump of the acceleration inside
    (t_{i-1}, t_{i+1}), a mesh stiffness step, costs at most the whole quarter there), up to the round-off of
    samples of the pitch circles' size, 1e-8 of the fastest such velocity of the train.  Measured: at most 0.85
    of the bound on demo-3p (its stiffness steps), 0.672 on the helical stage."""
    run = runs[solver]
    h = run.t[1] - run.t[0]
    assert np.allclose(np.diff(run.t), h, rtol=1e-9)  # sampled every step
    members = [name.removesuffix(".theta") for name in run.names("angle")]
    for displacement, velocity in RATES:
        pairs = [(f"{m}.{displacement}", f"{m}.{velocity}") for m in members if displacement != "z" or f"{m}.z" in run]
        scale = max((np.abs(run[v]).max() for _, v in pairs), default=0.0)
        for x_name, v_name in pairs:
            x, v = run[x_name], run[v_name]
            error = rms((x[2:] - x[:-2]) / (2 * h) - v[1:-1])
            bound = rms(v[2:] - 2 * v[1:-1] + v[:-2]) / 4 + 1e-8 * scale
            assert error <= bound, (x_name, error, bound)


def test_the_two_solvers_agree_on_every_members_motion(runs):
    """Lumped against MuJoCo over the steady half of the run, per member: the RMS of the difference of each vector
    (displacement, velocity, vibration velocity; world and carrier axes) over the RMS of the member's vibration
    (its displacement, its vibration velocity: the nominal motion is exact on both sides), and of each rotation
    and axial signal over the RMS of its vibration; a member that does not move (a symmetric train's sun) on the
    scale of the train's, 1e-6 of its largest.  Tolerance: the cross-check's for the displacements it gates
    (``dte.nrmse``, 0.01).  The lumped model is linear in the rotations and MuJoCo's kinematics are exact, so they
    differ by terms of second order, of the relative order of the carrier's wind-up theta_c: a planet's nominal
    place turned by it lies r_c theta_c^2 / 2 further out in MuJoCo and moves out at r_c theta_c theta_c'.
    Measured: at most 2.4e-3 (demo-3p, theta_c 4.1e-3 rad) and 1.6e-3 (the helical stage, 8.4e-4 rad); the
    integration errors are below 1e-5."""
    a, b = runs["lumped"], runs["mujoco"]
    steady = a.steady
    spec = gearcheck.load(a.train)

    def vector(run, mid, stem, frame):
        return np.stack([run[f"{mid}.{stem.format(axis)}.{frame}"][steady] for axis in "xy"], axis=-1)

    vibration = {(mid, stem): rms(np.linalg.norm(vector(a, mid, stem, frame), axis=-1)) for mid in spec.members
                 for stem, frame in (("{}", "carrier"), ("v{}", "relative"))}
    floor = {stem: 1e-6 * max(x for (_, s), x in vibration.items() if s == stem) for stem in ("{}", "v{}")}
    errors = {}
    for mid, member in spec.members.items():
        for stem, frames in (("{}", ("world", "carrier")), ("v{}", ("world", "carrier", "relative"))):
            for frame in frames:
                error = rms(np.linalg.norm(vector(a, mid, stem, frame) - vector(b, mid, stem, frame), axis=-1))
                errors[f"{mid}.{stem.format('')}.{frame}"] = error / max(vibration[mid, stem], floor[stem])
        scalars = [("theta", "theta"), ("omega", "omega.relative"), ("omega.relative", "omega.relative")]
        for name, scale in scalars + ([("z", "z"), ("vz", "vz")] if member.axial else []):
            x, y = a[f"{mid}.{name}"][steady], b[f"{mid}.{name}"][steady]
            errors[f"{mid}.{name}"] = rms(x - y) / rms(a[f"{mid}.{scale}"][steady])
    assert max(errors.values()) < DEFAULTS["dte.nrmse"], sorted(errors.items(), key=lambda item: item[1])[-3:]


def test_a_run_writes_and_draws_the_motion(tmp_path):
    assert main(["run", "demo-3p", "--solver", "mujoco", "--duration", "0.002", "--out", str(tmp_path)]) == 0
    table = pd.read_parquet(tmp_path / "timeseries.parquet")
    units = units_of(tmp_path / "timeseries.parquet")
    spec = gearcheck.load("demo-3p")
    for mid, member in spec.members.items():
        for signal in motion_signals(mid, member):
            assert signal.name in table.columns and units[signal.name]["unit"] == signal.unit
    assert units["stage1.ring.vy.relative"]["unit"] == "m/s" and units["stage1.carrier.theta"]["unit"] == "rad"
    run = gearcheck.simulate(spec, "lumped", 0.001)
    shown = ["stage1.carrier.theta", "stage1.carrier.omega.relative", "stage1.sun.x.world", "stage1.sun.vx.world"]
    fig = run.plot(shown)
    assert [ax.get_ylabel() for ax in fig.axes] == ["angle [rad]", "angular velocity [rad/s]", "displacement [m]",
                                                    "velocity [m/s]"]
    np.testing.assert_array_equal(fig.axes[2].lines[0].get_xydata(), np.c_[run.t, run["stage1.sun.x.world"]])
