"""Teaching animations (gearcheck.compare.presentation.animate) and the live viewer's no-display error, headless.

Rendering runs in one subprocess with MUJOCO_GL=egl (unless set): MuJoCo picks its OpenGL backend when it
is first imported, which this test process did long before."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

import gearcheck
from gearcheck.compare.presentation import animate as anim
from gearcheck.compare.presentation.live_view import live_view
from gearcheck.mbd_models.twin import compile_train
from gearcheck.shared.errors import GearcheckError

SCRIPT = """
import sys
import gearcheck
from gearcheck.compare.presentation.animate import animate, animate_mode
spec, out = gearcheck.load("demo-3p"), sys.argv[1]
for name in ("a", "b"):
    animate(spec, f"{out}/{name}.gif", duration=8 / 15, fps=15, width=160, height=120)
animate_mode(spec, f"{out}/mode.gif", mode=2, duration=1.0, fps=8, period=0.5, width=160, height=120)
"""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    out = tmp_path_factory.mktemp("animate")
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(out)], env=env, capture_output=True, text=True,
                         timeout=300)
    if run.returncode and "MUJOCO_GL" in run.stderr:  # a missing library is a failure, not a skip: CI has EGL
        pytest.fail(f"no offscreen OpenGL here (install Mesa's EGL, e.g. apt-get install libegl1 libgl1-mesa-dri): "
                    f"{run.stderr.strip().splitlines()[-1]}")
    assert run.returncode == 0, run.stderr
    return out


def frames(path) -> list[np.ndarray]:
    with Image.open(path) as im:
        out = []
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB"), dtype=float))
    return out


def test_frame_count_is_duration_times_fps_and_frames_are_not_blank(rendered):
    shots = frames(rendered / "a.gif")
    assert len(shots) == 8  # round(duration * fps), no +1
    assert shots[0].shape == (120, 160, 3)
    assert all(f.std() > 10 for f in shots)


def test_the_gears_move_between_frames(rendered):
    shots = frames(rendered / "a.gif")
    middle = (slice(42, 88), slice(32, 104))  # the train, clear of the text (top) and the force trace (bottom right)
    for a, b in zip(shots, shots[1:]):
        assert np.abs(a[middle] - b[middle]).mean() > 0.5


def test_same_input_same_bytes(rendered):
    assert (rendered / "a.gif").read_bytes() == (rendered / "b.gif").read_bytes()


def test_mode_frames_differ_and_repeat_after_one_period(rendered):
    shots = frames(rendered / "mode.gif")
    assert len(shots) == 8
    assert np.abs(shots[1] - shots[0]).mean() > 0.05
    assert np.array_equal(shots[4], shots[0]) and np.array_equal(shots[5], shots[1])  # 0.5 s period at 8 fps


def test_lumped_mode_maps_onto_the_twins_joints():
    spec = gearcheck.load("demo-3p")
    mb = compile_train(spec)
    lumped, f_l, type_l = anim.mode_shape(mb, 1, "lumped", gearcheck.modes(spec, "lumped"))
    twin, f_m, type_m = anim.mode_shape(mb, 1, "mujoco")
    assert type_l == type_m and f_l == pytest.approx(f_m, rel=0.02)
    assert abs(lumped @ twin) / (np.linalg.norm(lumped) * np.linalg.norm(twin)) > 0.99


def test_lumped_mode_needs_its_modal_result():
    with pytest.raises(GearcheckError, match="lumped ModalResult"):
        anim.mode_shape(compile_train(gearcheck.load("demo-3p")), 1, "lumped")


def test_mp4_without_ffmpeg_and_bad_suffix_are_one_line_errors(monkeypatch):
    monkeypatch.setattr(anim.shutil, "which", lambda name: None)
    with pytest.raises(GearcheckError, match="ffmpeg.*gif") as err:
        anim.check_output("x.mp4")
    assert "\n" not in str(err.value)
    with pytest.raises(GearcheckError, match=".gif or .mp4"):
        anim.check_output("x.avi")


def test_live_view_without_a_display_says_so_in_one_line(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(GearcheckError, match="^no display: .*gearcheck animate") as err:
        live_view(gearcheck.load("demo-3p"))
    assert "\n" not in str(err.value)


def test_the_force_trace_has_its_label_scale_and_time_axis():
    """The inset is a chart, not a squiggle: its label and unit above it, its largest and smallest values at its
    left corners, the time it covers at its right; drawn on a black frame, text appears in each of those places
    and nowhere without the trace."""
    black = np.zeros((360, 480, 3), dtype=np.uint8)
    x0, y0, bw, bh = (int(f * s) for f, s in zip(anim.TRACE, (480, 360, 480, 360)))
    trace = anim.Trace(np.array([4019.0, 5444.0, 4500.0]), 3, "mesh force stage1.planet1.sun [N]", 0.0394)
    drawn = np.asarray(anim._overlay(black, [], trace))
    bare = np.asarray(anim._overlay(black, []))
    places = {"label": drawn[y0 - 12:y0 - 2, x0:x0 + bw // 2], "largest": drawn[y0 + 3:y0 + 12, x0 + 3:x0 + 30],
              "smallest": drawn[y0 + bh - 12:y0 + bh - 3, x0 + 3:x0 + 30],
              "time": drawn[y0 + bh - 12:y0 + bh - 3, x0 + bw - 40:x0 + bw - 3]}
    for name, patch in places.items():
        assert (patch.min(axis=-1) > 200).sum() > 5, name  # white text
    assert not bare.any()
