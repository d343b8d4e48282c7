"""MuJoCo's interactive viewer on a train's twin, the runner's stepper driving the mesh stiffness live."""

from __future__ import annotations

import os
import time

from gearcheck.compare.presentation.animate import TwinPlayer, _reference, _twin, stepping_model
from gearcheck.shared.errors import GearcheckError


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def live_view(train, slow_motion: float = 100.0, magnify: float = 1000.0, fps: float = 30.0) -> None:
    """Open ``mujoco.viewer.launch_passive`` on the twin of ``train`` (TrainSpec or MbdModel) and run it until the
    window closes: every 1/fps s of wall time the runner's stepper advances 1/(fps slow_motion) s of simulated
    time, and the viewer shows the state with its deflection from the rigid-body motion times ``magnify``
    (as :func:`gearcheck.compare.presentation.animate.animate`).  Raises GearcheckError where there is no display."""
    if not has_display():
        raise GearcheckError("no display: $DISPLAY and $WAYLAND_DISPLAY are unset, so the live viewer cannot open; "
                             "use gearcheck animate TRAIN -o FILE.gif")
    import mujoco.viewer

    mb = _twin(train)
    every = max(1, round(1.0 / (fps * slow_motion * mb.default_step)))
    shown = mujoco.MjData(mb.model)
    with stepping_model(mb, mb.default_step), mujoco.viewer.launch_passive(mb.model, shown) as viewer:
        player = TwinPlayer(mb, 1)
        while viewer.is_running():
            started = time.perf_counter()
            player.stepper.j = 0  # keep one sample row: the live view records nothing
            player.qpos.clear()
            player.advance(every)
            ref = _reference(mb, player.static.qpos, player.step * player.dt)
            with viewer.lock():
                shown.qpos[:] = ref + magnify * (player.data.qpos - ref)
                mujoco.mj_forward(mb.model, shown)
            viewer.sync()
            time.sleep(max(0.0, 1.0 / fps - (time.perf_counter() - started)))
