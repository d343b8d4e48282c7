"""Teaching animations of a train's MuJoCo twin, rendered offscreen (``mujoco.Renderer``).

:func:`animate`: the twin running as :func:`~gearcheck.mbd_models.runner.simulate_mujoco` runs it (the
runner's own stepper: stiffness driven every step, coefficients turned with the carrier) in slow motion,
its vibration magnified; :func:`animate_mode`: one mode shape oscillating.  Frames go to a GIF (Pillow)
or an MP4 (ffmpeg).  Frame count: ``round(duration * fps)``, frame i at playback time i / fps (no +1:
the GIF loops without a repeated frame).  The same input gives the same bytes.

Magnification: every joint shows reference + magnify (q - reference), the reference being the rigid-body
motion: each hinge at its steady (static) angle turning at its kinematic speed (planets relative to their
carrier), each slide at zero.  Translations thus show the whole deflection, rotations the vibration.
"""

from __future__ import annotations

import io
import math
import os
import shutil
import subprocess
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import mujoco
import numpy as np
from PIL import Image, ImageDraw, ImageFont

from gearcheck.train.spec import TrainSpec
from gearcheck.mbd_models import linearise
from gearcheck.mbd_models.runner import _Stepper, static_state
from gearcheck.mbd_models.static_state import nominal_speeds
from gearcheck.mbd_models.twin import MbdModel, compile_train
from gearcheck.shared import stepping
from gearcheck.shared.errors import GearcheckError, SolverError
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.outputs import check_place, write_file
from gearcheck.shared.settings import MAX_STEPS

MODE_SIZE = 0.05  # a mode shape's largest point displacement, as a fraction of the model's extent
TRACE = (0.66, 0.76, 0.32, 0.2)  # mesh-force trace box: left, top, width, height (fractions of the frame)


def _twin(train) -> MbdModel:
    if isinstance(train, MbdModel):
        return train
    if isinstance(train, TrainSpec):
        return compile_train(train)
    raise GearcheckError(f"train must be a TrainSpec or a compiled MbdModel (load it with gearcheck.load), "
                         f"not {type(train).__name__}")


def check_output(path) -> Path:
    """``path`` as a Path, refused unless it ends in .gif, or in .mp4 with ffmpeg on PATH."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise GearcheckError(f"{path}: writing MP4 needs ffmpeg on PATH, which is missing; write a .gif instead")
    if suffix not in (".gif", ".mp4"):
        raise GearcheckError(f"{path}: an animation is written as .gif or .mp4, not {suffix or 'no suffix'!r}")
    check_place(path, "-o", folder=False)
    return path


def renderer(model: mujoco.MjModel, width: int, height: int) -> mujoco.Renderer:
    """An offscreen renderer, or a GearcheckError naming MUJOCO_GL when no OpenGL context can be made."""
    if width > model.vis.global_.offwidth or height > model.vis.global_.offheight:
        model.vis.global_.offwidth, model.vis.global_.offheight = max(width, 640), max(height, 480)
    try:
        return mujoco.Renderer(model, height, width)
    except Exception as exc:  # MuJoCo raises plain exceptions for a missing GL context
        raise GearcheckError(f"offscreen rendering failed ({exc}); set MUJOCO_GL=egl (GPU) or MUJOCO_GL=osmesa "
                             f"(software) before starting Python (MUJOCO_GL is {os.environ.get('MUJOCO_GL')!r})"
                             ) from None


OBLIQUE_ELEVATION = -35.0  # deg: a tilting train seen from the side, where its members' tilts show


def top_camera(model: mujoco.MjModel, spec: TrainSpec | None = None) -> mujoco.MjvCamera:
    """A free camera looking down the gear axis (z) at the whole train; obliquely, from OBLIQUE_ELEVATION, at a
    train whose members tilt (the tilts move the gears' rims along the axis, which the axis's view cannot show)."""
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = model.stat.center
    cam.lookat[2] = 0.0
    cam.distance = 1.6 * model.stat.extent
    tilting = spec is not None and any(stage.tilting for stage in spec.stages)
    cam.azimuth, cam.elevation = 90.0, OBLIQUE_ELEVATION if tilting else -90.0
    return cam


def _add_spokes(model: mujoco.MjModel, data: mujoco.MjData, scene: mujoco.MjvScene) -> None:
    """A bright bar on every body's rim (0.55 to 0.95 of its radius, along its x axis), so that rotation
    shows on a plain cylinder."""
    for body in range(1, model.nbody):
        geoms = range(model.body_geomadr[body], model.body_geomadr[body] + model.body_geomnum[body])
        radius = max((model.geom_size[g, 0] for g in geoms if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER),
                     default=0.0)
        if radius == 0.0 or scene.ngeom >= scene.maxgeom:
            continue
        x_axis = data.xmat[body].reshape(3, 3)[:, 0]
        top = max(data.geom_xpos[g][2] + model.geom_size[g, 1] for g in geoms)
        centre = data.xpos[body] + 0.75 * radius * x_axis
        centre[2] = top + 1e-3
        mujoco.mjv_initGeom(scene.geoms[scene.ngeom], mujoco.mjtGeom.mjGEOM_BOX,
                            np.array([0.2 * radius, 0.06 * radius, 1e-3]), centre, data.xmat[body],
                            np.array([1.0, 0.85, 0.1, 1.0], dtype=np.float32))
        scene.ngeom += 1


def _reference(mb: MbdModel, hinge0: np.ndarray, t: float) -> np.ndarray:
    """The rigid-body qpos at time t: hinges at ``hinge0`` plus their kinematic speed times t, slides at 0."""
    m = mb.model
    hinge = m.jnt_type == mujoco.mjtJoint.mjJNT_HINGE  # hinge and slide joints only: qpos and dof addresses coincide
    return np.where(hinge, hinge0 + nominal_speeds(mb) * t, 0.0)


@contextmanager
def stepping_model(mb: MbdModel, dt: float):
    """The model set up for the runner's RK4 stepping, put back afterwards."""
    m = mb.model
    saved = (m.tendon_stiffness.copy(), m.tendon_lengthspring.copy(), m.wrap_prm.copy(), m.tendon_damping.copy(),
             m.opt.timestep, m.opt.integrator)
    m.opt.timestep, m.opt.integrator = dt, mujoco.mjtIntegrator.mjINT_RK4
    try:
        yield
    finally:
        m.tendon_stiffness[:], m.tendon_lengthspring[:], m.wrap_prm[:], m.tendon_damping[:] = saved[:4]
        m.opt.timestep, m.opt.integrator = saved[4:]


class TwinPlayer:
    """The twin stepped by the runner's own stepper from its steady rotating state, frame by frame.

    ``advance(steps)`` samples the state at the current step (qpos kept in ``qpos``, mesh forces from
    :meth:`mesh_forces`) and runs ``steps`` RK4 steps.  Use inside ``with stepping_model(mb, mb.default_step)``."""

    def __init__(self, mb: MbdModel, n_frames: int):
        self.mb, self.dt = mb, mb.default_step
        spec = mb.spec
        self.static = static_state(mb)
        start = self.static if spec.operating.ramp == 0 else static_state(mb, 0.0)
        self.data = mujoco.MjData(mb.model)
        self.data.qpos[:], self.data.qvel[:] = start.qpos, start.qvel
        self.stepper = _Stepper(mb, self.data, self.dt, n_frames, False, False)
        self.step = 0
        self.qpos: list[np.ndarray] = []

    def advance(self, steps: int) -> None:
        dt, a, b, s = self.dt, self.step, self.step + steps, self.stepper
        self.qpos.append(self.data.qpos.copy())
        split = stepping.split_steps(dt, a, b, self.mb.excitation.switch_times(a * dt, b * dt))
        s.run(a, b, steps, s.drive.steps(dt * np.arange(a, b), dt), split)
        self.step = b
        if not np.all(np.isfinite(self.data.qpos)):
            raise SolverError(f"the MuJoCo model of {self.mb.spec.name} diverged at t = {b * dt:.4g} s")

    def mesh_forces(self) -> np.ndarray:
        """(frames, n_mesh) mesh forces (N) at the sampled states."""
        return self.stepper.reader.forces(self.stepper.forces[:self.stepper.j])[0]


def _font(height: int):
    return ImageFont.load_default(size=max(8, height // 26))


class Trace(NamedTuple):
    """A small chart at the frame's bottom right: ``values`` drawn up to sample ``n`` on the scale of all of them,
    ``label`` its quantity and unit ("mesh force [N]"), ``span`` the time the values cover (s)."""

    values: np.ndarray
    n: int
    label: str
    span: float


def _overlay(pixels: np.ndarray, lines: list[str], trace: Trace | None = None) -> Image.Image:
    """The frame with text lines at its top left and, optionally, a :class:`Trace` at its bottom right with its
    label, its scale (the largest and smallest value) and its time axis."""
    img = Image.fromarray(pixels)
    draw = ImageDraw.Draw(img)
    w, h = img.size
    font = _font(h)
    text = {"fill": (255, 255, 255), "font": font, "stroke_width": 1, "stroke_fill": (0, 0, 0)}
    y = 2
    for line in lines:
        draw.text((4, y), line, **text)
        y += font.size + 3
    if trace is not None:
        x0, y0, bw, bh = TRACE[0] * w, TRACE[1] * h, TRACE[2] * w, TRACE[3] * h
        draw.rectangle((x0, y0, x0 + bw, y0 + bh), fill=(20, 20, 30), outline=(200, 200, 200))
        values, n = trace.values, int(trace.n)
        lo, hi = float(values.min()), float(values.max())
        span = hi - lo if hi > lo else 1.0
        xs = x0 + 2 + (bw - 4) * np.arange(n) / max(len(values) - 1, 1)
        ys = y0 + bh - 2 - (bh - 4) * (values[:n] - lo) / span
        if n > 1:
            draw.line(list(zip(xs.tolist(), ys.tolist())), fill=(255, 90, 60), width=1)
        draw.ellipse((xs[-1] - 2, ys[-1] - 2, xs[-1] + 2, ys[-1] + 2), fill=(255, 220, 60))
        small = {**text, "font": _font(int(h * 0.75))}
        draw.text((x0, y0 - 2), trace.label, anchor="ld", **small)
        draw.text((x0 + 3, y0 + 2), f"{hi:.4g}", anchor="la", **small)
        draw.text((x0 + 3, y0 + bh - 2), f"{lo:.4g}", anchor="ld", **small)
        draw.text((x0 + bw - 3, y0 + bh - 2), f"{1e3 * trace.span:.3g} ms", anchor="rd", **small)
    return img


def _write(path: Path, frames: list[Image.Image], fps: float) -> Path:
    """The frames as a GIF (Pillow) or an MP4 (ffmpeg), written whole or not at all (:func:`write_file`)."""
    if path.suffix.lower() == ".gif":
        palette = frames[0].quantize(colors=255, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
        first, *rest = (f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames)
        sink = io.BytesIO()
        first.save(sink, format="GIF", save_all=True, append_images=rest, duration=round(1000 / fps), loop=0,
                   optimize=False)
        write_file(path, sink.getvalue())
        return path
    w, h = frames[0].size
    with tempfile.TemporaryDirectory() as folder:
        video = Path(folder) / "animation.mp4"
        cmd = ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}",
               "-r", f"{fps:g}", "-i", "-", "-pix_fmt", "yuv420p", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
               "-vcodec", "libx264", "-bitexact", str(video)]
        subprocess.run(cmd, input=b"".join(f.tobytes() for f in frames), check=True)
        write_file(path, video.read_bytes())
    return path


MAX_FPS = 120.0  # beyond any display's refresh
MAX_FRAMES = 1800  # two minutes at 15 fps: some 1 GB of 480 x 360 frames, all held until they are written
MAX_SIDE = 4096  # pixels: a 4K frame


def _frames(duration: float, fps: float, width: int, height: int) -> int:
    """The frame count of a ``duration`` s animation at ``fps`` of ``width`` x ``height`` pixels, each bounded."""
    if not (0 < duration < math.inf and 0 < fps <= MAX_FPS):
        raise GearcheckError(f"duration={duration!r}, fps={fps!r}: a positive playback length and a frame rate "
                             f"from 0 to {MAX_FPS:g} per second")
    for name, side in (("width", width), ("height", height)):
        if isinstance(side, bool) or not isinstance(side, (int, np.integer)) or not 16 <= side <= MAX_SIDE:
            raise GearcheckError(f"{name}={side!r}: a whole number of pixels from 16 to {MAX_SIDE}")
    frames = duration * fps
    if not frames < MAX_FRAMES + 0.5:
        raise GearcheckError(f"duration={duration:g} s at fps={fps:g} is {frames:.3g} frames, more than the "
                             f"{MAX_FRAMES} an animation holds in memory: shorten it or lower the frame rate")
    return max(1, round(frames))


def _factor(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < 1e12:
        raise GearcheckError(f"{name}={value!r}: a positive factor below 1e12")
    return float(value)


def animate(train, path, duration: float = 4.0, fps: float = 15.0, magnify: float = 1000.0,
            slow_motion: float = 100.0, width: int = 480, height: int = 360, mesh: int = 0,
            progress=None) -> Path:
    """Animate the MuJoCo twin of ``train`` (a TrainSpec or compiled MbdModel) turning; write ``path``.

    duration: playback length (s); fps: frames per playback second; slow_motion: playback time per
    simulated time (simulated span duration / slow_motion, frames every slow_motion / fps s rounded to whole
    steps); magnify: the joints' displacement from the rigid-body motion times this; mesh: which entry of
    ``spec.meshes`` the force overlay shows; progress: callable(fraction).  Returns the path written."""
    path = check_output(path)
    n = _frames(duration, fps, width, height)
    slow_motion, magnify = _factor("slow_motion", slow_motion), _factor("magnify", magnify)
    mb = _twin(train)
    if not 0 <= mesh < len(mb.spec.meshes):
        raise GearcheckError(f"mesh must be 0..{len(mb.spec.meshes) - 1}, got {mesh}")
    every = max(1, round(1.0 / (fps * slow_motion * mb.default_step)))
    if n * every > MAX_STEPS:
        raise GearcheckError(f"slow_motion={slow_motion:g}: {n} frames of {every} steps each is {n * every:.3g} "
                             f"steps, more than the {MAX_STEPS:.0e} gearcheck runs in one go: raise it")
    rend = renderer(mb.model, width, height)
    with stepping_model(mb, mb.default_step):
        player = TwinPlayer(mb, n)
        for i in range(n):
            player.advance(every)
            if progress is not None:
                progress(0.8 * (i + 1) / n)
    force = player.mesh_forces()[:, mesh]
    label = mb.spec.meshes[mesh].id
    shown, cam = mujoco.MjData(mb.model), top_camera(mb.model, mb.spec)
    hinge0 = player.static.qpos
    frames = []
    for i, q in enumerate(player.qpos):
        t = i * every * player.dt
        ref = _reference(mb, hinge0, t)
        shown.qpos[:] = ref + magnify * (q - ref)
        mujoco.mj_forward(mb.model, shown)
        rend.update_scene(shown, cam)
        _add_spokes(mb.model, shown, rend.scene)
        lines = [f"{mb.spec.name}  t = {1e3 * t:7.2f} ms", f"slow motion x{slow_motion:g}, deflection x{magnify:g}",
                 *(["(teeth overlap: the deflection magnified)"] if magnify > 1 else []),
                 f"mesh force {label}: {force[i]:.0f} N"]
        span = (len(force) - 1) * every * player.dt
        frames.append(_overlay(rend.render(), lines, Trace(force, i + 1, f"mesh force {label} [N]", span)))
        if progress is not None:
            progress(0.8 + 0.2 * (i + 1) / n)
    rend.close()
    return _write(path, frames, fps)


def mode_shape(mb: MbdModel, mode: int, solver: str = "mujoco", modal: ModalResult | None = None
               ) -> tuple[np.ndarray, float, str]:
    """(shape over MuJoCo's dofs, frequency Hz, type) of mode ``mode`` (1-based).

    solver "mujoco": the twin's own modes (:func:`linearise.modes`); "lumped": ``modal``, the lumped
    model's ModalResult (physical coordinates, labelled), mapped to the joints with the inverse of
    :func:`linearise.physical_coordinates`."""
    if solver == "mujoco":
        modal = linearise.modes(mb) if modal is None else modal
    elif solver != "lumped":
        raise GearcheckError(f"solver must be 'mujoco' or 'lumped', not {solver!r}")
    elif modal is None:
        raise GearcheckError("solver 'lumped' needs the lumped ModalResult (gearcheck.modes(train, 'lumped'))")
    if not 1 <= mode <= len(modal):
        raise GearcheckError(f"mode must be 1..{len(modal)}, got {mode}")
    shape = np.real(modal.shapes[:, mode - 1])
    if solver == "lumped":
        labels, T = linearise.physical_coordinates(mb)
        where = {name: i for i, name in enumerate(modal.dof_labels)}
        missing = [name for name in labels if name not in where]
        if missing:
            raise GearcheckError(f"the lumped mode shape has no coordinate {missing[0]!r}")
        shape = np.linalg.lstsq(T, shape[[where[name] for name in labels]], rcond=None)[0]
    return shape, float(modal.frequencies[mode - 1]), modal.types[mode - 1]


def _shape_scale(mb: MbdModel, shape: np.ndarray) -> float:
    """The factor that makes the largest point displacement of a member (centre move plus rim turn) MODE_SIZE
    of the model's extent."""
    m = mb.model
    labels, T = linearise.physical_coordinates(mb)
    phys = dict(zip(labels, T @ shape))
    biggest = 0.0
    for mid, member in mb.spec.members.items():
        body = mb.body[mid]
        rim = float(max(m.geom_rbound[m.body_geomadr[body]:m.body_geomadr[body] + m.body_geomnum[body]], default=0))
        a, b = ("radial", "tangential") if member.orbits else ("x", "y")
        shift = math.hypot(phys.get(f"{mid}.{a}", 0.0), phys.get(f"{mid}.{b}", 0.0))  # none of its own: torsional
        biggest = max(biggest, shift + rim * abs(phys[f"{mid}.theta"]))
    return MODE_SIZE * m.stat.extent / biggest if biggest > 0 else 0.0


def animate_mode(train, path, mode: int, solver: str = "mujoco", modal: ModalResult | None = None,
                 duration: float = 2.0, fps: float = 15.0, period: float = 1.0, width: int = 480, height: int = 360,
                 progress=None) -> Path:
    """Animate mode ``mode`` (1-based) of ``solver`` on the MuJoCo twin of ``train``; write ``path``.

    The train at rest (nominal configuration) moves as q0 + a shape sin(2 pi t / period), t the playback time,
    the amplitude a making the largest displacement 5 % of the train's size; frame i is at t = i / fps, so the
    frames repeat every ``round(period * fps)``.  solver "lumped" needs ``modal``, the lumped model's
    ModalResult (mbd_models does not compute lumped modes); for "mujoco" it is optional (the twin's own).
    Returns the path written."""
    path = check_output(path)
    n = _frames(duration, fps, width, height)
    period = _factor("period", period)
    mb = _twin(train)
    shape, freq, kind = mode_shape(mb, mode, solver, modal)
    amplitude = _shape_scale(mb, shape)
    rend = renderer(mb.model, width, height)
    shown, cam = mujoco.MjData(mb.model), top_camera(mb.model, mb.spec)
    per_period = period * fps
    frames = []
    for i in range(n):
        shown.qpos[:] = mb.model.qpos0 + amplitude * math.sin(2 * math.pi * (i % per_period) / per_period) * shape
        mujoco.mj_forward(mb.model, shown)
        rend.update_scene(shown, cam)
        _add_spokes(mb.model, shown, rend.scene)
        lines = [f"{mb.spec.name}  mode {mode} ({solver})", f"{freq:.1f} Hz, {kind}"]
        frames.append(_overlay(rend.render(), lines))
        if progress is not None:
            progress((i + 1) / n)
    rend.close()
    return _write(path, frames, fps)
