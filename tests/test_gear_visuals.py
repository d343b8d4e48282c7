"""The twin's visual gears: involute teeth from the train's geometry, meshing where they should, and no
effect at all on the twin's dynamics."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from gearcheck import mjcf
from gearcheck.train.geometry import reference_tooth_thickness
from gearcheck.train.loader import load_train, preset_names
from gearcheck.mbd_models import gear_visuals, linearise, mjcf_builder
from gearcheck.mbd_models.gear_visuals import gear_mesh, half_angle, phases, section, tooth_outline
from gearcheck.mbd_models.twin import compile_train


def gears():
    """Every distinct gear of every preset, and shifted / relieved variants of one external and one internal."""
    out = {}
    for name in preset_names():
        for member in load_train(name).members.values():
            for gname, gear in member.gears.items():
                out[f"{name}:{member.id}:{gname}"] = gear
    demo = load_train("demo-3p").members
    for key, gear in (("sun", demo["stage1.sun"].gears["sun"]), ("ring", demo["stage1.ring"].gears["ring"])):
        out[f"{key}+shift+relief"] = dataclasses.replace(gear, profile_shift=0.3, relief_amount=20e-6,
                                                         relief_length=1.5e-3, relief_power=2)
    return out


GEARS = gears()


def flanks(gear):
    """The involute flank points (r, phi) of tooth 0's flank at negative angles (r > r_b, tip centre excluded)."""
    r, phi = tooth_outline(gear)
    keep = (phi < 0) & (r >= gear.base_radius) & (np.abs(phi) < math.pi / gear.teeth - 1e-12)
    return r[keep], phi[keep]


@pytest.mark.parametrize("name", sorted(GEARS))
def test_flanks_are_involutes_of_the_base_circle(name):
    gear = GEARS[name]
    r, phi = flanks(gear)
    assert len(r) >= 3
    alpha = np.arccos(gear.base_radius / r)
    d = gear_visuals.relief(gear, r) / gear.base_radius  # tip relief turns the flank into the tooth by d/r_b
    # an involute leaves the base circle at one angle, phi - inv(alpha_r) (an internal gear's flank bounds the
    # space: phi + inv(alpha_r)), the same for every point of the flank: the half base thickness psi_b
    inv = np.tan(alpha) - alpha
    start = -(phi - inv - d) if not gear.internal else phi + math.pi / gear.teeth + inv - d
    assert np.allclose(start, gear_visuals.base_tooth_thickness(gear) / (2 * gear.base_radius), rtol=0, atol=1e-12)
    # the tooth (external) or space (internal) is the reference thickness wide on the reference circle
    half = half_angle(dataclasses.replace(gear, relief_amount=0.0), np.array([gear.pitch_radius]))[0]
    space = math.pi / gear.teeth - half if gear.internal else half
    assert space == pytest.approx(reference_tooth_thickness(gear) / (2 * gear.pitch_radius), rel=1e-12)
    # tip relief: none below its start, C_a at the tip
    assert gear_visuals.relief(gear, np.array([gear.tip_radius]))[0] == pytest.approx(gear.relief_amount)


@pytest.mark.parametrize("name", sorted(GEARS))
def test_teeth_tip_and_root_circles(name):
    gear = GEARS[name]
    r, phi = section(gear)
    assert r.max() == pytest.approx(max(gear.tip_radius, gear.root_radius), rel=1e-12)
    assert r.min() == pytest.approx(min(gear.tip_radius, gear.root_radius), rel=1e-12)
    assert np.all(np.diff(phi) >= 0) and phi[-1] - phi[0] < 2 * math.pi  # star-shaped (radial below r_b)
    tips = np.isclose(r, gear.tip_radius, rtol=1e-12) & np.isclose(np.mod(phi + 1e-9, 2 * math.pi / gear.teeth), 1e-9)
    assert tips.sum() == gear.teeth  # one tip centre per tooth, on its centre line
    spaces = np.isclose(np.mod(phi, 2 * math.pi / gear.teeth), math.pi / gear.teeth)
    assert spaces.sum() == gear.teeth and np.allclose(r[spaces], gear.root_radius, rtol=1e-12)
    if gear.internal:  # a ring's teeth point inward: tips inside the root circle
        assert gear.tip_radius < gear.root_radius


@pytest.mark.parametrize("name", sorted(GEARS))
def test_meshes_are_closed_and_outward(name):
    gear = GEARS[name]
    v, f = gear_mesh(gear)
    edges = {}
    for a, b, c in f:
        for e in ((a, b), (b, c), (c, a)):
            edges[e] = edges.get(e, 0) + 1
    assert all(n == 1 and edges.get((b, a)) == 1 for (a, b), n in edges.items())  # watertight, consistent
    volume = np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6
    r, phi = section(gear)
    inner = 0.5 * np.sum(r * np.roll(r, -1) * np.sin(np.diff(np.append(phi, phi[0] + 2 * math.pi))))
    rim = gear.root_radius + gear_visuals.RIM * gear.normal_module  # a polygon of one corner per tooth
    area = 0.5 * gear.teeth * rim**2 * math.sin(2 * math.pi / gear.teeth) - inner if gear.internal else inner
    assert volume == pytest.approx(area * gear.face_width, rel=2e-3)


def boundary(gear, rotation):
    """A callable r(phi) of the gear's tooth boundary turned by ``rotation`` (the section is star-shaped)."""
    r, phi = section(gear, 40)
    phi = phi + rotation
    order = np.argsort(np.mod(phi, 2 * math.pi))
    return lambda a: np.interp(np.mod(a, 2 * math.pi), np.mod(phi, 2 * math.pi)[order], r[order],
                               period=2 * math.pi)


def mesh_overlap(spec, mesh, rotations, shift=0.0):
    """Deepest interpenetration (modules) of a mesh's two gears as placed: planet tooth points against the
    central gear's boundary where it is involute."""
    planet, central = spec.members[mesh.planet], spec.members[mesh.central]
    name = lambda member, gear: next(n for n, g in member.gears.items() if g == gear)  # noqa: E731
    pr = rotations[mesh.planet, name(planet, mesh.planet_gear)] + shift
    cr = rotations[mesh.central, name(central, mesh.central_gear)]
    r, phi = section(mesh.planet_gear, 40)
    centre = planet.radius * np.array([math.cos(planet.angle), math.sin(planet.angle)])
    x = centre[0] + r * np.cos(phi + pr)
    y = centre[1] + r * np.sin(phi + pr)
    rc = np.hypot(x, y)
    edge = boundary(mesh.central_gear, cr)(np.arctan2(y, x))
    depth = (edge - rc) if not mesh.internal else (rc - edge)  # > 0: inside the central gear's metal
    # below the base circle the flank is drawn radial, fuller than a generated fillet: a mate's tip corner may
    # graze it in a still frame, so only the involute part counts
    depth = depth[rc >= mesh.central_gear.base_radius]
    return depth.max() / mesh.planet_gear.module


@pytest.mark.parametrize("preset", preset_names())
def test_teeth_mesh_as_placed(preset):
    spec = load_train(preset)
    rotations = phases(spec)
    for mesh in spec.meshes:
        depth = mesh_overlap(spec, mesh, rotations)
        assert depth < 0.02, f"{mesh.id}: teeth interpenetrate by {depth:.3f} modules"
        # in contact (zero backlash): turned half a pitch, a tooth sits in the mate's tooth
        half = math.pi / mesh.planet_gear.teeth
        assert mesh_overlap(spec, mesh, rotations, half) > 0.5


@pytest.mark.parametrize("preset", preset_names())
def test_visuals_leave_the_dynamics_unchanged(preset, monkeypatch):
    spec = load_train(preset)
    visual = compile_train(spec)
    monkeypatch.setattr(mjcf_builder, "VISUALS", False)
    bare = compile_train(spec)
    m = visual.model
    assert m.ngeom > 0 and bare.model.ngeom == 0
    assert np.all(m.geom_contype == 0) and np.all(m.geom_conaffinity == 0)
    assert np.array_equal(m.body_mass, bare.model.body_mass)
    assert np.array_equal(m.body_inertia, bare.model.body_inertia)
    M0, M1 = linearise.mass_matrix(bare), linearise.mass_matrix(visual)
    assert np.abs(M1 - M0).max() <= 1e-12 * np.abs(M0).max()
    f0, f1 = linearise.modes(bare).frequencies, linearise.modes(visual).frequencies
    assert np.allclose(f1, f0, rtol=1e-12, atol=1e-12 * max(f0))


RENDER = """
import json, os, sys
os.environ["MUJOCO_GL"] = "egl"
import mujoco, numpy as np
model = mujoco.MjModel.from_xml_string(sys.stdin.read())
data = mujoco.MjData(model)
mujoco.mj_forward(model, data)
renderer = mujoco.Renderer(model, 480, 640)
renderer.update_scene(data, camera="front")
np.save(sys.argv[1], renderer.render())
"""


def member_colours(image):
    """Share of the frame in each member's hue: sun orange, planet green, carrier blue, ring grey (unsaturated)."""
    from matplotlib.colors import rgb_to_hsv

    h, sat, v = rgb_to_hsv(image.reshape(-1, 3).astype(float) / 255).T
    lit, coloured = v > 0.25, sat > 0.2
    hue = {"sun": (0.03, 0.2), "planet": (0.25, 0.45), "carrier": (0.5, 0.72)}
    shares = {k: np.mean(lit & coloured & (h >= lo) & (h <= hi)) for k, (lo, hi) in hue.items()}
    return {**shares, "ring": float(np.mean(lit & (sat < 0.12)))}


@pytest.mark.parametrize("preset", preset_names())
def test_a_render_shows_the_members(preset, tmp_path):
    xml = mjcf(load_train(preset))
    out = tmp_path / "frame.npy"
    run = subprocess.run([sys.executable, "-c", RENDER, str(out)], input=xml, text=True, capture_output=True,
                         env={**os.environ, "MUJOCO_GL": "egl"}, timeout=120)
    if run.returncode != 0:
        pytest.skip(f"no offscreen OpenGL here: {run.stderr.strip().splitlines()[-1:]}")
    image = np.load(out)
    assert image.std() > 20  # not blank
    shares = member_colours(image)
    shown = {k for k, v in shares.items() if v > 0.01}
    assert len(shown) >= 3, json.dumps(shares)
    assert {"planet", "ring"} <= shown
