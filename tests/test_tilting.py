"""Tilting members (issue 30): the train description and the reference lumped model in three dimensions.

Checked against what holds independently of the assembly: Eritenel & Parker's (2009) mode structure of a 3-D
planetary (rotational-axial modes, degenerate translational-tilting pairs, planet modes of multiplicity N - 3),
the limit of no helix and no offsets (today's planar model, to the bit, beside uncoupled tilts), the moment balance
of a loaded helical planet computed by vector mechanics from the line of action, and the annulus's tilting inertia by
quadrature.  The two solvers' agreement is in ``test_tilting_twin.py``.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import tplquad

import gearcheck
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.modal import modes
from gearcheck.lumped.static import static_solution
from gearcheck.shared.errors import TrainFileError, TrainNote
from gearcheck.train.kinematics import kinematics
from gearcheck.train.line_of_action import line_of_action
from gearcheck.train.loader import load_train
from gearcheck.train.spec import TILTS
from gearcheck.train.variants import edited

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "helical-tilting.toml"
TILT = (r"^planets = (\d)", r"planets = \1\ntilting = true")
HELD = (r"^(support|bearing) = \{ (.*) \}$",
        r"\1 = { \2, axial_stiffness = 5.0e8, axial_damping = 500.0, tilting_stiffness = 2.0e5 }")
HELIX = [(r"^face_width_mm = 40.0$", "face_width_mm = 40.0\nhelix_angle_deg = 15.0"),
         (r'model = "rectangular"', 'model = "constant"')]


def tilting(*pairs, base="demo-3p"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TrainNote)
        return edited(base, [TILT, HELD, *pairs], "tilting")


def test_every_member_of_a_tilting_stage_has_six_dofs():
    spec = load_train(EXAMPLE)
    for member in spec.members.values():
        assert member.tilting and member.dofs[-2:] == TILTS[member.frame] and len(member.dofs) == 6
    assert all(m.contact_width == pytest.approx(16e-3) and m.axial_centre == 0.0 for m in spec.meshes)
    assert build_model(spec).n == 6 * len(spec.members)


@pytest.mark.parametrize("planets", [3, 4])
def test_mode_structure_is_eritenel_parkers(planets):
    """A 3-D planetary of N equally spaced planets: 12 rotational-axial modes (each central member's rotation and
    axial motion, the planets' six coordinates alike), 12 degenerate translational-tilting pairs, and 6 planet modes
    of multiplicity N - 3 (Eritenel & Parker 2009); 6 (3 + N) in all.  (With equal sun and ring mesh stiffnesses
    the planets' in-phase rocking about their radial axes would decouple from the central members by accident,
    a rotational-axial mode in which they do not move: the ring's mesh is made stiffer.)"""
    four = [(r"^planets = 3", "planets = 4"), (r"^teeth = 22", "teeth = 30"), (r"^teeth = 20", "teeth = 24"),
            (r"^teeth = 62 .*$", "teeth = 78")] if planets == 4 else []
    ring = (r"^(\[stages.ring\])", '\\1\nmesh = { stiffness = { model = "constant", mean = 1.1e9 } }')
    result = modes(build_model(tilting(*four, *HELIX, ring)))
    types = result.types
    assert len(types) == 6 * (3 + planets)
    assert types.count("rotational") == 12
    assert types.count("translational") == 24
    assert types.count("planet") == 6 * (planets - 3)
    pairs = [f for f, t in zip(result.frequencies, types) if t == "translational"]
    assert np.allclose(pairs[::2], pairs[1::2], rtol=1e-9)


def test_no_helix_and_no_offsets_is_the_planar_model_to_the_bit():
    """Without a helix, stations or offsets nothing couples a tilt to the transverse plane: the planar coordinates'
    matrices are today's, bit for bit, and the planar model's frequencies are among the tilting model's."""
    planar, tilted = build_model(load_train("demo-3p")), build_model(tilting())
    index = [tilted.dofs(m, d) for m, d in planar.dofs.names]
    others = [i for i in range(tilted.n) if i not in index]
    for name in ("M", "K_b", "K_mean", "C", "G", "K_centripetal", "K_circulatory"):
        a, b = getattr(planar, name), getattr(tilted, name)
        assert b[np.ix_(index, index)].tobytes() == a.tobytes(), name
        assert not np.any(b[np.ix_(index, others)]), name
    f_planar, f_tilted = modes(planar).frequencies, modes(tilted).frequencies
    assert all(np.min(np.abs(f_tilted - f) / f) < 1e-12 for f in f_planar)


def test_stations_and_offsets_couple_translation_and_tilt():
    """A carrier on two stations at p1, p2 sharing k: its (x, tilt_y) block is k [[1, p], [p, p^2]] summed (the
    station at p deflects by x + p tilt_y), so the tilting stiffness is sum s_i k p_i^2 about the stations."""
    pairs = [(r"^support = \{ radial_stiffness = 1.0e9, radial_damping = 2000.0, (axial_stiffness = .*) \}$",
              r"support = { radial_stiffness = 1.0e9, radial_damping = 2000.0, \1, stations = "
              "[{ position_mm = -30.0, share = 0.25 }, { position_mm = 50.0, share = 0.75 }] }")]
    model = build_model(tilting(*pairs))
    i = [model.dofs("stage1.carrier", d) for d in ("x", "tilt_y", "y", "tilt_x")]
    rows = [r for r in model.rows if r.name.startswith("stage1.carrier.support_") and "station" in r.name]
    K = sum(r.stiffness * np.outer(r.a, r.a) for r in rows)[np.ix_(i, i)]
    k, s, p = 1.0e9, np.array([0.25, 0.75]), np.array([-0.03, 0.05])
    expected = k * np.array([[s.sum(), s @ p], [s @ p, s @ p**2]])
    assert np.allclose(K[:2, :2], expected, rtol=1e-12) and not np.any(K[:2, 2:])
    assert np.allclose(K[2:, 2:], expected * [[1, -1], [-1, 1]], rtol=1e-12)  # y - p tilt_x


def test_a_loaded_helical_planet_is_in_moment_balance():
    """The helix's axial forces act at the pitch points, off the planet's axis: by vector mechanics the moment of
    every force on a planet (the meshes' F n at their points, the meshes' tilting moments, the bearing stations'
    forces at p e_z) about its centre vanishes in the static state: the rows' tilt coefficients are the arms."""
    stations = (r"^bearing = \{ radial_stiffness = 2.0e8, radial_damping = 500.0, (.*) \}$",
                r"bearing = { radial_stiffness = 2.0e8, radial_damping = 500.0, \1, stations = "
                "[{ position_mm = -12.0, share = 0.5 }, { position_mm = 12.0, share = 0.5 }] }")
    spec = tilting(*HELIX, stations, (r"^(\[stages.sun\])", "\\1\naxial_offset_mm = 3.0"))
    model = build_model(spec, rotating_frame_terms=False)
    static = static_solution(model)
    kin, planet = kinematics(spec), spec.members["stage1.planet1"]
    e_r = np.array([math.cos(planet.angle), math.sin(planet.angle), 0.0])
    e_t = np.array([-e_r[1], e_r[0], 0.0])
    e_z = np.array([0.0, 0.0, 1.0])
    moment = np.zeros(3)
    forces = dict(zip(static.row_names, static.row_forces))
    for mesh, force in zip(spec.meshes, static.mesh_force):
        if mesh.planet != planet.id:
            continue
        loa = line_of_action(mesh, planet.angle, spec.stages[0].carrier_radius, kin.flanks[mesh.id])
        n = np.array([*loa.direction, loa.axial])
        arm = np.array([*(loa.pitch_point - loa.planet_centre), mesh.axial_centre])
        moment += np.cross(arm, force * n) + forces[f"{mesh.id}.tilt"] * np.cross(e_z, n)
    for i, station in enumerate(planet.bearing.stations):
        f_r, f_t = forces[f"{planet.id}.bearing_radial.station{i + 1}"], forces[f"{planet.id}.bearing_tangential"
                                                                                 f".station{i + 1}"]
        moment += np.cross(station.position * e_z, -f_r * e_r - f_t * e_t)
    moment -= forces[f"{planet.id}.bearing_tilt_radial"] * e_r + forces[f"{planet.id}.bearing_tilt_tangential"] * e_t
    scale = max(abs(f) for f in static.mesh_force) * spec.members["stage1.planet1"].reference_radius
    assert np.abs(moment[:2]).max() < 1e-9 * scale
    assert np.abs(static.q[model.dofs(planet.id, "tilt_tangential")]) > 0  # the helix does tilt it


def test_tilting_inertia_is_the_annulus_about_a_diameter():
    """Given a density, a gear is an annulus (r_i, r_o, w): its inertia about a diameter, by quadrature over the
    annulus, is the default I/2 + m w^2/12."""
    spec = tilting((r"^mass = 0.9757 .*$", "density = 7850.0\ninner_radius_mm = 10.0"), (r"^inertia = 5.802e-4", ""))
    sun = spec.members["stage1.sun"]
    r_o, r_i, w, rho = sun.gears["sun"].pitch_radius, 0.01, 0.04, 7850.0
    # about the x axis: (y^2 + z^2) rho dV, y = r sin(phi), dV = r dr dphi dz
    about_x = tplquad(lambda r, phi, z: rho * r * ((r * math.sin(phi))**2 + z**2), -w / 2, w / 2, 0.0, 2 * math.pi,
                      r_i, r_o)[0]
    assert sun.tilting_inertia == pytest.approx(about_x, rel=1e-10)


def test_a_stage_that_does_not_tilt_notes_and_sets_aside_its_tilting_keys():
    with pytest.warns(TrainNote, match=r"tilting stiffness, stations and tilt ignored: the stage does not tilt"):
        spec = edited("demo-3p", [HELD])
    assert all(m.support is None or m.support.tilting_stiffness == 0 for m in spec.members.values())
    assert build_model(spec).n == build_model(load_train("demo-3p")).n


@pytest.mark.parametrize("pairs, expected", [
    ([(r"^(support = \{ radial_stiffness = 1.0e8, .*), tilting_stiffness = 2.0e5 \}$", r"\1 }")],
     r"stages\[0\].sun.support.tilting_stiffness: a tilting stage needs it > 0, or stations at two axial positions"),
    ([(r"^(bearing = \{.*), tilting_stiffness = 2.0e5 \}$",
       r"\1, stations = [{ position_mm = -5.0, share = 0.5 }, { position_mm = 5.0, share = 0.4 }] }")],
     r"stages\[0\].planet.bearing.stations: the shares sum to 0.9, not 1"),
    ([(r"^(bearing = \{.*), tilting_stiffness = 2.0e5 \}$", r"\1, stations = [{ position_mm = 5.0, share = 1.0 }] }")],
     r"stages\[0\].planet.bearing.tilting_stiffness: a tilting stage needs it > 0, or stations at two"),
    ([(r"^\[stages.carrier\]", "[stages.carrier]\ntorsional = true")],
     r"stages\[0\].carrier.torsional: a tilting stage's members move in three dimensions"),
    ([(r"^\[stages.sun\]", "[stages.sun]\naxial_offset_mm = 45.0")],
     r"stages\[0\].sun.axial_offset_mm: the faces of sun and the planet's planet do not overlap"),
    ([(r"^(\[stages.carrier\])", "\\1\ntilting_inertia = 1.0e-3")],
     r"stages\[0\].carrier.tilting_inertia: 0.001 kg·m² is below half the polar inertia \(0.009625 kg·m²\)"),
    ([(r"^(bearing = \{ radial_stiffness = 2.0e8, radial_damping = 500.0), axial_stiffness = 5.0e8", r"\1")],
     r"stages\[0\].planet.bearing.axial_stiffness: a tilting stage needs it > 0"),
], ids=["unheld", "shares", "one station", "torsional", "faces apart", "inertia", "axial"])
def test_bad_tilting_input_names_the_field(pairs, expected):
    with pytest.raises(TrainFileError, match=expected):
        tilting(*pairs)


def test_an_rv_reducer_does_not_tilt():
    with pytest.raises(TrainFileError, match=r"stages\[0\].tilting: an RV reducer's stage does not tilt"):
        edited("rv-reducer", [(r'^name = "rv"', 'name = "rv"\ntilting = true')])


def test_a_misaligned_pin_loads_the_face_as_iso_6336s_k_h_beta():
    """A planet held rigidly at its pin's tilt gamma meets untilted central gears across a face w: the slices'
    deflection grows by F_beta_y / w = |gamma . (e_z x n)| along the face, and the face load factor 1 + 6|M|/(F w)
    is ISO 6336-1's K_H_beta = 1 + F_beta_y c_gamma / (2 F_m / b) for a linear load distribution (c_gamma = k/w,
    F_m/b = F/w), with F_beta_y from the line of action's geometry alone."""
    stiff = (r"tilting_stiffness = 2.0e5", "tilting_stiffness = 1.0e13")
    gamma = np.array([40e-6, -25e-6])
    pins = (r"^\[stages.planet\]", "[stages.planet]\npin_tilts_urad = [[40.0, -25.0], [0.0, 0.0], [0.0, 0.0]]")
    spec = tilting(stiff, pins)
    assert spec.members["stage1.planet1"].bearing.rest_tilt == pytest.approx(tuple(gamma))
    model = build_model(spec, rotating_frame_terms=False)
    static = static_solution(model)
    forces = dict(zip(static.row_names, static.row_forces))
    kin, planet = kinematics(spec), spec.members["stage1.planet1"]
    tilt = static.q[[model.dofs(planet.id, d) for d in TILTS["pin"]]]
    assert tilt == pytest.approx(gamma, rel=1e-6)  # held at the pin's tilt
    e_r = np.array([math.cos(planet.angle), math.sin(planet.angle)])
    e_t = np.array([-e_r[1], e_r[0]])
    for j, mesh in enumerate(spec.meshes):
        loa = line_of_action(mesh, planet.angle, spec.stages[0].carrier_radius, kin.flanks[mesh.id])
        slope = 0.0 if mesh.planet != planet.id else abs(gamma @ [np.cross([0, 0, 1], [*loa.direction, 0])[:2] @ e
                                                                  for e in (e_r, e_t)])
        force, width = static.mesh_force[j], mesh.contact_width
        khb_iso = 1.0 + (width * slope) * (model.excitation.mean_stiffness[j] / width) / (2.0 * force / width)
        khb = 1.0 + 6.0 * abs(forces[f"{mesh.id}.tilt"]) / (force * width)
        assert khb == pytest.approx(khb_iso, rel=1e-5), mesh.id
        assert (khb > 1.05) == (mesh.planet == planet.id)


def test_pin_tilts_are_one_pair_per_planet():
    with pytest.raises(TrainFileError, match=r"stages\[0\].planet.pin_tilts_urad: needs one pair per planet \(3\), "
                                             r"got 1"):
        tilting((r"^\[stages.planet\]", "[stages.planet]\npin_tilts_urad = [[40.0, 0.0]]"))
    with pytest.raises(TrainFileError, match=r"stages\[0\].planet.pin_tilts_urad\[0\]: needs 2 entries, got 3"):
        tilting((r"^\[stages.planet\]", "[stages.planet]\npin_tilts_urad = [[40.0, 0.0, 1.0]]"))


def test_a_published_mesh_states_its_tilting_stiffness_and_centre():
    """A model from a paper may give the mesh's tilting stiffness and centre of stiffness instead of the face: they
    replace k w^2/12 and the overlap's middle (the damping spread like the stiffness); a centre off the face is
    refused."""
    stated = (r"^(\[stages.mesh\])", "\\1\ntilting_stiffness = 4.0e4\ncentre_offset_mm = 6.0")
    model = build_model(tilting(stated))
    mesh = model.spec.meshes[0]
    assert (mesh.axial_centre, mesh.contact_width) == (pytest.approx(6e-3), pytest.approx(40e-3))
    row = next(r for r in model.rows if r.name == f"{mesh.id}.tilt")
    assert row.stiffness == 4.0e4 and row.damping == pytest.approx(model.mesh_damping[0] * 4.0e4 / 8.0e8)
    default = next(r for r in build_model(tilting()).rows if r.name == f"{mesh.id}.tilt")
    assert default.stiffness == pytest.approx(8.0e8 * 0.04**2 / 12)
    with pytest.raises(TrainFileError, match=r"stages\[0\].sun.mesh.centre_offset_mm: 25 mm is off the faces' "
                                             r"overlap, -20 to 20 mm"):
        tilting((r"^(\[stages.mesh\])", "\\1\ncentre_offset_mm = 25.0"))


def test_the_mesh_tilting_stiffness_is_the_thin_slices_moment():
    """Cut the face into n thin slices (the thin-slice model of the helical mesh, Velex & Maatar 1996): over a mesh
    cycle every slice has the same mean stiffness k_mean/n, so the slices' second moment about the face centre,
    sum k_i z_i^2, averages k_mean b^2/12 (1 - 1/n^2) and their centre of stiffness the face centre: the tilting row's
    k_mean w^2/12.  Within the cycle the contact lines sweep the face, and the moment varies about that mean (the
    centre row carries the variation of k; the tilting row keeps the mean)."""
    from gearcheck.train.helical_mesh import contact_pairs

    eps_a, eps_b, pitch, b, n = 1.605, 1.246, 2.566e-3, 16e-3, 200
    xi = (np.arange(4096) + 0.5) / 4096
    k = contact_pairs(xi, eps_a, eps_b, pitch, b, lambda s: np.full(np.shape(s), 1.4e10), n)[0]
    k = k.reshape(xi.size, n, -1).sum(axis=-1)  # each slice's stiffness over the cycle
    z = ((np.arange(n) + 0.5) / n - 0.5) * b
    k_mean = k.sum(axis=1).mean()
    assert np.allclose(k.mean(axis=0), k_mean / n, rtol=1e-6)
    assert (k @ z).mean() == pytest.approx(0.0, abs=1e-9 * k_mean * b)
    assert (k @ z**2).mean() == pytest.approx(k_mean * b**2 / 12 * (1 - 1 / n**2), rel=1e-6)
    assert np.ptp(k @ z**2) / (k @ z**2).mean() > 0.05  # it does move within the cycle


def test_a_seat_misaligned_in_the_housing_loads_the_turning_frame_in_both_step_paths():
    """A ring seat tilted in the housing: its rows' rest turns at -Omega in the carrier's frame (a load of the
    carrier's period, a part on the train's clock), the compiled steps equal to the stage-by-stage path."""
    seat = (r"^(support = \{ radial_stiffness = 1.0e9, radial_damping = 2000.0, torsional.*) \}$",
            r"\1, tilt_urad = [40.0, -25.0] }")
    spec = tilting(seat)
    assert spec.members["stage1.ring"].support.rest_tilt == pytest.approx((40e-6, -25e-6))
    kin = kinematics(spec)
    carrier_hz = abs(kin.speeds["stage1.carrier"]) / (2 * math.pi)
    assert any(part.turning_frequencies(spec, kin.speeds) == [pytest.approx(carrier_hz)] for part in spec.parts)
    runs = [gearcheck.simulate(spec, solver="lumped", duration=4e-3, method=m) for m in ("rk4", "rk4-stages")]
    tilt = [run["stage1.ring.tilt_x.world"] for run in runs]
    assert np.abs(tilt[0] - tilt[1]).max() < 1e-9 * np.abs(tilt[1]).max()
    assert np.abs(tilt[1]).max() > 20e-6  # held near its seat's tilt
