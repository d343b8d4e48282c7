"""The RV reducer of Yang, Chen & Wang (2018) against gearcheck's model of it: Table 3's natural frequencies,
the Appendix's stiffness blocks entry by entry, and the static pin loads of the cycloid stage.

Numbers checked against are computed independently here (a spring-by-spring model in the paper's fixed frame,
a two-inertia torsional model by hand, the paper's printed matrices) or are the audit's standalone numbers at
the precision they were printed with."""

import math
from dataclasses import replace
from unittest import mock

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.optimize import brentq, fsolve

from gearcheck.compare.presentation import plots
from gearcheck.lumped.assembly import build_model, frozen_at
from gearcheck.train.cycloid import pin_contacts
from gearcheck.train.loader import load_text, preset_text
from gearcheck.lumped.modal import modes
from gearcheck.lumped.pin_loads import (
    cycloid_element,
    pin_loads,
    span_period,
)
from gearcheck.lumped.static import static_solution
from gearcheck.shared.errors import TrainFileError

TEST = (148.95, 387.88, 681.47)  # Table 3, experiment (Hz)
PAPER = (154.56, 396.09, 697.16)  # Table 3, analytical model (Hz)
TEXT = preset_text("rv-reducer")
PAPER_LAYOUT = TEXT.replace("planets = 3", "planets = 4").replace("discs = 2", "discs = 3")

# Tables 1-2 as printed (SI), and the reading of the geometry column (base radii of m 1.5, z 15/69; e; r_c; r_H)
J_S, J_P, M_P, J_H, M_H, J_C, M_C, J_O = 4.44e-4, 1.01e-3, 0.88, 7.56e-5, 0.40, 2.09e-2, 2.76, 0.106
K_S, K_ST, K_A, K_HT, K_HB, K_CB, K_SP, K_PIN = 4.19e7, 1.16e4, 2.33e8, 6.99e4, 9.84e8, 9.76e8, 2.68e8, 8.35e8
E, R_C, R_H, Z_P, Z_C, RATIO = 2.2e-3, 85.8e-3, 63.5e-3, 40, 39, 185
R_BS, R_BP = 0.75e-3 * 15 * math.cos(math.radians(20)), 0.75e-3 * 69 * math.cos(math.radians(20))
ALPHA = math.acos((R_BS + R_BP) / R_H)  # operating pressure angle, 21.205 deg
R_PIN, K_O = 118e-3, 3.0e9  # estimates (pin circle, output main bearings)


@pytest.fixture(scope="module")
def model():
    return build_model(load_text(TEXT, "preset:rv-reducer"))


@pytest.fixture(scope="module")
def paper_layout():
    """The paper's 4 planets and 3 discs, assembled with the planet-collision check switched off: the stiffness
    model of a reducer that cannot be built (4 planets of 69 teeth collide on a 63.5 mm circle)."""
    with mock.patch("gearcheck.train.spec._check_collision"):
        return build_model(load_text(PAPER_LAYOUT, "paper layout, collision check off"))


def frequencies(model, j_plate=0.0, j_input=0.0):
    M = model.M.copy()
    for member, extra in (("rv.carrier", j_plate), ("rv.sun", j_input)):
        i = model.dofs(member, "theta")
        M[i, i] += extra
    return modes(replace(model, M=M)).frequencies


def plate_for(model, target, j_input=0.0):
    return brentq(lambda j: frequencies(model, j, j_input)[0] - target, 1e-3, 1e3, xtol=1e-12)


def plate_and_input_for(model, f1, f2):
    x = fsolve(lambda x: [frequencies(model, x[0], x[1] * 1e-3)[0] - f1,
                          frequencies(model, x[0], x[1] * 1e-3)[1] - f2], [plate_for(model, f1), 1.0])
    return x[0], x[1] * 1e-3


# ---------------------------------------------------------------------------------------------------------------
# Table 3


def test_the_papers_layout_cannot_be_built():
    """Section 3.3's 4 planets and 3 discs: the 69-tooth planets (tip diameter 106.6 mm) sit 89.8 mm apart."""
    with pytest.raises(TrainFileError, match=r"adjacent planets collide: centre spacing 89\.803 mm <= tip "
                                             r"diameter 106\.629 mm"):
        load_text(PAPER_LAYOUT, "paper layout")


def test_the_preset_lowest_mode_is_table_3s_third(model):
    """The published parameters (3 cranks, 2 discs, no test rig) put the lowest mode, the whole train against the
    sun's shaft, within 0.5 % of the paper's model's mode 3 (697.16 Hz) and nothing near its 154.56 or 396.09 Hz."""
    f = frequencies(model)
    assert abs(f[0] / PAPER[2] - 1) < 0.005
    assert f[0] > 1.7 * PAPER[1]


def test_the_modes_against_the_audits_standalone_model(model, paper_layout):
    """The audit's spring-by-spring model printed 695.9 / 755.9 / 771.2 / 1189.1 Hz (3 cranks, 2 discs) and
    668.1 / 759.0 / 759.1 / 1474.6 Hz (the paper's 4 and 3), from the rounded base radii 10.57 / 48.63 mm and the
    pins of the other torque sign loaded: agreement to 3e-4 (those two differences move the modes by up to 0.13 Hz);
    the lowest mode, which neither touches, to the printed 0.05 Hz."""
    for m, printed in ((model, (695.9, 755.9, 771.2, 1189.1)), (paper_layout, (668.1, 759.0, 759.1, 1474.6))):
        f = frequencies(m)[:4]
        assert np.allclose(f, printed, rtol=3e-4, atol=0), f
        assert abs(f[0] - printed[0]) <= 0.075
    assert abs(frequencies(model)[0] - 695.9) <= 0.05


def standalone_stiffness(contacts, cranks=3, discs=2):
    """K of the reducer in the paper's frame (fixed x, y for every body; order sun, planets, cranks, discs,
    output), spring by spring from the relative displacements: delta = v . q, K = sum k v v^T."""
    nb = 2 + 2 * cranks + discs
    n = 3 * nb
    planet, crank, disc, out = (lambda i: 3 + 3 * i), (lambda i: 3 + 3 * (cranks + i)), \
        (lambda j: 3 + 3 * (2 * cranks + j)), 3 * (nb - 1)
    K = np.zeros((n, n))

    def spring(k, *entries):
        v = np.zeros(n)
        for index, value in entries:
            v[index] += value
        K[:] += k * np.outer(v, v)

    for c in (0, 1):
        spring(K_S, (c, 1.0))
        spring(K_O, (out + c, 1.0))
    spring(K_ST, (2, 1.0))
    k1 = Z_P * E / R_PIN
    for i in range(cranks):
        psi = 2 * math.pi * i / cranks
        er, et = np.array([math.cos(psi), math.sin(psi)]), np.array([-math.sin(psi), math.cos(psi)])
        nn = math.sin(ALPHA) * er + math.cos(ALPHA) * et
        spring(K_SP, (0, nn[0]), (1, nn[1]), (2, R_BS), (planet(i), -nn[0]), (planet(i) + 1, -nn[1]),
               (planet(i) + 2, R_BP))
        for c in (0, 1):
            spring(K_A, (planet(i) + c, 1.0), (crank(i) + c, -1.0))
            spring(K_HB, (crank(i) + c, 1.0), (out + c, -1.0), (out + 2, -R_H * et[c]))
        spring(K_HT, (planet(i) + 2, 1.0), (crank(i) + 2, -1.0))
        for j in range(discs):
            phi = 2 * math.pi * j / discs
            ep = (-math.sin(phi), math.cos(phi))
            for c in (0, 1):
                spring(K_CB, (crank(i) + c, 1.0), (crank(i) + 2, E * ep[c]), (disc(j) + c, -1.0),
                       (disc(j) + 2, -R_H * et[c]))
    for j, pin in contacts:
        phi = 2 * math.pi * j / discs
        f = 2 * math.pi * pin / Z_P - phi
        s = math.sqrt(1 + k1 * k1 - 2 * k1 * math.cos(f))
        local = np.array([(math.cos(f) - k1) / s, math.sin(f) / s])
        nx = math.cos(phi) * local[0] - math.sin(phi) * local[1]
        ny = math.sin(phi) * local[0] + math.cos(phi) * local[1]
        spring(K_PIN, (disc(j), nx), (disc(j) + 1, ny), (disc(j) + 2, R_C * math.sin(f) / s))
    return K


def test_the_assembled_stiffness_is_the_spring_by_spring_model(model):
    """gearcheck's K (carrier frame at t = 0, planets and cranks radial/tangential) turned into the paper's fixed
    frame equals the standalone model with the same touching pins, entry by entry (1e-9 of the largest); those
    pins sit on the side that reacts the counter-clockwise torque the housing holds (arm l < 0)."""
    contacts = []
    for row in model.rows:
        if row.kind == "contact":
            _, d, p = row.name.split(".")
            contacts.append((int(d[4:]) - 1, int(p[3:]) - 1))
    K = standalone_stiffness(contacts)
    labels = model.dofs.labels()
    T = np.zeros((len(labels), len(labels)))  # q_paper = T q_gearcheck

    def where(body, c):
        kind, number = body.rstrip("0123456789"), int(body[len(body.rstrip("0123456789")):] or 0)
        start = {"sun": 0, "planet": 3 + 3 * (number - 1), "crank": 12 + 3 * (number - 1),
                 "disc": 21 + 3 * (number - 1), "carrier": 27}[kind]
        return start + c

    for k, label in enumerate(labels):
        _, body, dof = label.split(".")
        if dof in ("radial", "tangential"):
            psi = 2 * math.pi * (int(body[-1]) - 1) / 3
            axis = (math.cos(psi), math.sin(psi)) if dof == "radial" else (-math.sin(psi), math.cos(psi))
            T[where(body, 0), k], T[where(body, 1), k] = axis
        else:
            T[where(body, {"x": 0, "y": 1, "theta": 2}[dof]), k] = 1.0
    assert np.allclose(T.T @ K @ T, model.K_mean, rtol=0, atol=1e-9 * np.abs(K).max())
    arms = [pin_contacts(model.turning[-1].geometry, math.pi * j, 0.0).arm[i] for j, i in contacts]
    assert all(a < 0.2 * R_C for a in arms) and sum(a < 0 for a in arms) >= len(arms) - 2


def test_what_it_would_take_to_reach_the_papers_column(model, paper_layout):
    """An unprinted output inertia puts mode 1 at 154.56 Hz: 6.49 kg m^2 (3 cranks, 2 discs) or 10.0 (the paper's
    layout), the audit's numbers; about 1.3e-3 kg m^2 more on the input then brings mode 2 to 396.09 Hz, and mode 3
    becomes the untouched sun-translation mode, more than 8 % above the paper's 697.16 Hz."""
    assert plate_for(model, PAPER[0]) == pytest.approx(6.49, abs=0.01)
    assert plate_for(paper_layout, PAPER[0]) == pytest.approx(10.0, abs=0.05)
    for m, sun_translation in ((model, 756.0), (paper_layout, 759.1)):
        j_plate, j_input = plate_and_input_for(m, PAPER[0], PAPER[1])
        assert j_input == pytest.approx(1.3e-3, rel=0.03)
        f = frequencies(m, j_plate, j_input)
        assert f[:2] == pytest.approx(PAPER[:2], rel=1e-7)
        assert f[2] == pytest.approx(sun_translation, abs=0.1) and f[2] > 1.08 * PAPER[2]


def test_added_inertia_on_two_coordinates_cannot_bring_a_third_mode_to_681_hz(model):
    """Adding inertia on r coordinates lowers no eigenvalue past the r-th one below it (Cauchy interlacing), so with
    any inertia plate and any motor inertia the third mode stays at or above the unloaded lowest mode (695.87 Hz),
    above the test's third mode: Table 3's three test modes are not the first three natural frequencies of the
    printed model plus the rig's two unknown inertias."""
    f0 = frequencies(model)[0]
    assert f0 > TEST[2]
    for j_plate in (0.0, 0.1, 0.3, 1.0, 7.0, 100.0):
        assert frequencies(model, j_plate)[1] >= f0 * (1 - 1e-12)
        for j_input in (1e-4, 1.4e-3, 1e-2, 1.0):
            assert frequencies(model, j_plate, j_input)[2] >= f0 * (1 - 1e-12)


def hand_torsional_model(j_plate):
    """Two inertias on two springs (reflected to the output): the sun's shaft k_st i^2 holds the input side, whose
    inertia is the rigid mechanism's kinetic energy (sun x 185, planets and cranks x 39 turning and r_H orbiting,
    discs turning x 1 and orbiting at r_c); it drives the output and plate through the train's torsional
    stiffness, the crank bearings, needles and pins in series (k Z_p r_c^2 / 4 per disc)."""
    j_in = J_S * RATIO**2 + 3 * (J_P + J_H) * Z_C**2 + 3 * (M_P + M_H) * R_H**2 + 2 * (J_C + M_C * R_C**2)
    k_train = 1 / (1 / (3 * K_HB * R_H**2) + 1 / (6 * K_CB * R_H**2) + 1 / (2 * K_PIN * Z_P * R_C**2 / 4))
    K = np.array([[K_ST * RATIO**2 + k_train, -k_train], [-k_train, k_train]])
    return np.sqrt(eigh(K, np.diag([j_in, J_O + j_plate]), eigvals_only=True)) / (2 * np.pi)


def test_the_calibrated_prediction(model):
    """The honest protocol: the plate calibrated on the test's mode 1 (7.00 kg m^2) leaves one more torsional mode
    below 1 kHz, the input side against k_st at 702.6 Hz: 3.1 % above the test's mode 3, the bias of the paper's
    own column, and within 2 % of the hand two-inertia model calibrated the same way (its series train stiffness
    is 17 % stiff: the discs' translation on their needles softens the pins, so its plate is within 20 %).  That
    mode hardly depends on the calibration (0.1 % for the plate anywhere in 3-30 kg m^2); nothing lies near the
    test's 387.88 Hz."""
    j = plate_for(model, TEST[0])
    f = frequencies(model, j)
    assert j == pytest.approx(7.0, abs=0.01)
    assert 0.025 < f[1] / TEST[2] - 1 < 0.04
    assert f[1] > 1.8 * TEST[1]
    j_hand = brentq(lambda x: hand_torsional_model(x)[0] - TEST[0], 0.1, 100)
    assert j / j_hand == pytest.approx(1, abs=0.2)
    assert f[1] / hand_torsional_model(j_hand)[1] == pytest.approx(1, abs=0.02)
    spread = [frequencies(model, x)[1] for x in (3.0, 30.0)]
    assert max(spread) / min(spread) - 1 < 1e-3
    assert f[2:4] == pytest.approx(frequencies(model)[1:3], rel=1e-9)  # the sun translation pair: untouched


def test_a_plate_in_the_train_file_is_the_added_inertia(model):
    """Raising the carrier's inertia in the train file by J gives the modes of the added-inertia model."""
    text = TEXT.replace("inertia = 0.106", "inertia = 7.106")
    assert text != TEXT
    f = modes(build_model(load_text(text, "with plate"))).frequencies
    assert f == pytest.approx(frequencies(model, 7.0), rel=1e-9)


# ---------------------------------------------------------------------------------------------------------------
# Appendix


def block(K, model, a, a_dofs, b, b_dofs):
    return K[np.ix_([model.dofs(a, d) for d in a_dofs], [model.dofs(b, d) for d in b_dofs])]


CENTRAL, PLANET = ("x", "y", "theta"), ("radial", "tangential", "theta")


def group(model, pattern):
    return sum((r.stiffness * np.outer(r.a, r.a) for r in model.rows if pattern in r.name), np.zeros((model.n,) * 2))


def disc_frame(phi):
    """blockdiag(R(phi), 1): the paper's disc coordinates (x_c from the pin wheel's centre to the disc's) to ours."""
    R = np.eye(3)
    R[:2, :2] = [[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]]
    return R


def test_sun_planet_mesh_blocks_are_the_papers(model):
    """K_s1^i, K_s2^i and K_pp (Appendix) are gearcheck's mesh row outer products, entry by entry, with
    psi_si = psi_i + 90 deg - alpha, alpha_s the operating pressure angle (21.205 deg) and r_s, r_p the base radii."""
    k = model.excitation.mean_stiffness
    assert model.spec.meshes[0].geometry.pressure_angle == pytest.approx(ALPHA, abs=1e-9)
    sa, ca = math.sin(ALPHA), math.cos(ALPHA)
    for i, row in enumerate(model.mesh_rows):
        Km = k[i] * np.outer(row, row)
        psi = 2 * math.pi * i / 3 + math.pi / 2 - ALPHA
        c, s = math.cos(psi), math.sin(psi)
        planet = f"rv.planet{i + 1}"
        s1 = k[i] * np.array([[c * c, c * s, R_BS * c], [c * s, s * s, R_BS * s], [R_BS * c, R_BS * s, R_BS**2]])
        s2 = k[i] * np.array([[-c * sa, -c * ca, R_BP * c], [-s * sa, -s * ca, R_BP * s],
                              [-R_BS * sa, -R_BS * ca, R_BS * R_BP]])
        pp = k[i] * np.array([[sa * sa, sa * ca, -R_BP * sa], [sa * ca, ca * ca, -R_BP * ca],
                              [-R_BP * sa, -R_BP * ca, R_BP**2]])
        tol = 1e-12 * k[i]
        assert np.allclose(block(Km, model, "rv.sun", CENTRAL, "rv.sun", CENTRAL), s1, rtol=0, atol=tol)
        assert np.allclose(block(Km, model, "rv.sun", CENTRAL, planet, PLANET), s2, rtol=0, atol=tol)
        assert np.allclose(block(Km, model, planet, PLANET, planet, PLANET), pp, rtol=0, atol=tol)


def test_crank_support_block_no_reading_of_the_print_fits(model):
    """K_35 = (K_H2^1 ... K_H2^M)^T with K_H2^i = k_Hb P^T: read strictly, crank i's block is k_Hb P, whose sine
    terms have the wrong sign (psi clockwise); read as a plain stack it is k_Hb P^T, whose -r_H couples the crank's
    rotation with the output's y instead of its tangential slide with the output's rotation.  gearcheck's block is
    k_Hb [[-c, -s, 0], [s, -c, -r_H], [0, 0, 0]]: the strict reading with psi -> -psi."""
    for i in range(3):
        psi = 2 * math.pi * i / 3
        c, s = math.cos(psi), math.sin(psi)
        ours = block(model.K_b, model, f"rv.crank{i + 1}", PLANET, "rv.carrier", CENTRAL)
        mirrored = K_HB * np.array([[-c, -s, 0], [s, -c, -R_H], [0, 0, 0]])
        assert np.allclose(ours, mirrored, rtol=0, atol=1e-9 * K_HB)
        printed = K_HB * np.array([[-c, s, 0], [-s, -c, -R_H], [0, 0, 0]])  # k_Hb P
        assert np.allclose(ours, printed, rtol=0, atol=1e-9 * K_HB) == (i == 0)  # at psi = 0 the sines vanish
        assert not np.allclose(ours, printed.T, rtol=0, atol=1e-3 * K_HB)  # -r_H in the wrong place at every psi


@pytest.mark.parametrize("t", [0.0, 0.0123, 0.1])
def test_self_blocks_and_the_missing_output_supports(model, t):
    """K_H1 = N k_cb diag(1, 1, e^2), K_H2 = k_Hb diag(1, 1, 0), K_HH = K_H1 + K_H2 + K_p (K_p = diag(k_a, k_a, k_H),
    which the paper never writes out), K_c = M k_cb diag(1, 1, r_H^2), K_55 = M k_Hb diag(1, 1, r_H^2) at every
    frozen time; gearcheck's output block adds the main bearings k_o that the text names and K_55 leaves out (k_ot
    is 0 in both: the test's free inertia plate)."""
    m = frozen_at(model, t)
    needles, bearings = group(m, "needle"), group(m, ".bearing_")
    tol = 1e-9 * K_O
    for i in range(3):
        crank = f"rv.crank{i + 1}"
        assert np.allclose(block(needles, m, crank, PLANET, crank, PLANET), 2 * K_CB * np.diag([1, 1, E * E]),
                           rtol=0, atol=tol)
        assert np.allclose(block(bearings, m, crank, PLANET, crank, PLANET), K_HB * np.diag([1, 1, 0]), rtol=0,
                           atol=tol)
        assert np.allclose(block(m.K_b, m, crank, PLANET, crank, PLANET),
                           2 * K_CB * np.diag([1, 1, E * E]) + K_HB * np.diag([1, 1, 0]) + np.diag([K_A, K_A, K_HT]),
                           rtol=0, atol=tol)
    for j in range(2):
        disc = f"rv.disc{j + 1}"
        assert np.allclose(block(needles, m, disc, CENTRAL, disc, CENTRAL), 3 * K_CB * np.diag([1, 1, R_H**2]),
                           rtol=0, atol=tol)
    k55 = 3 * K_HB * np.diag([1, 1, R_H**2])
    assert np.allclose(block(bearings, m, "rv.carrier", CENTRAL, "rv.carrier", CENTRAL), k55, rtol=0, atol=tol)
    assert np.allclose(block(m.K_b, m, "rv.carrier", CENTRAL, "rv.carrier", CENTRAL), k55 + np.diag([K_O, K_O, 0]),
                       rtol=0, atol=tol)


@pytest.mark.parametrize("t", [0.0, 0.0123, 0.1])
def test_crank_disc_block_is_a_rotation_the_papers_is_not(model, t):
    """K_Hi^cj in the paper's disc frame (x_c along the eccentric) with psi = psi_i - phi_j(t): gearcheck's block is
    the printed one with its (2,1) entry's sign reversed, every other entry (row 3 included: (0, -e, -r_H e cos psi))
    as printed; its 2x2 part is k_cb times a rotation (det k_cb^2), the printed one's determinant is
    k_cb^2 cos 2 psi.  psi turns with the crank relative to the carrier: the block varies in time."""
    m = frozen_at(model, t)
    element = m.turning[-1]
    phis = element.eccentric_angles(t)
    for i in range(3):
        for j in range(2):
            psi = 2 * math.pi * i / 3 - phis[j]
            c, s = math.cos(psi), math.sin(psi)
            ours = block(m.K_b, m, f"rv.crank{i + 1}", PLANET, f"rv.disc{j + 1}", CENTRAL) @ disc_frame(phis[j])
            printed = K_CB * np.array([[-c, -s, 0], [-s, -c, -R_H], [0, -E, -R_H * E * c]])
            corrected = printed.copy()
            corrected[1, 0] = -corrected[1, 0]
            assert np.allclose(ours, corrected, rtol=0, atol=1e-9 * K_CB)
            assert np.linalg.det(ours[:2, :2]) == pytest.approx(K_CB**2, rel=1e-12)
            assert np.linalg.det(printed[:2, :2]) == pytest.approx(K_CB**2 * math.cos(2 * psi), rel=1e-9, abs=1e3)
    entry = (model.dofs("rv.crank2", "theta"), model.dofs("rv.disc1", "x"))  # k_cb e sin(phi_1(t)) in our frame
    assert abs(frozen_at(model, 0.05).K_b[entry] - model.K_b[entry]) > 0.5 * K_CB * E


def test_each_pin_contact_is_the_papers_k_cr(model):
    """K_cr = k w w^T, w = (sin beta, cos beta, r_c cos beta) (Appendix), is each touching pin's block in the disc's
    eccentric frame with beta = atan2(cos varphi - K1, sin varphi) measured from y_c; gearcheck sums it over the
    17 pins per disc that touch in the static state (the paper prints one block, no pin index, no contact set)."""
    element = model.turning[-1]
    k1 = element.geometry.K1
    counted = {0: 0, 1: 0}
    for row in model.rows:
        if row.kind != "contact":
            continue
        _, d, p = row.name.split(".")
        j, i = int(d[4:]) - 1, int(p[3:]) - 1
        phi = element.eccentric_angles(0.0)[j]
        f = 2 * math.pi * i / Z_P - phi
        beta = math.atan2(math.cos(f) - k1, math.sin(f))
        w = np.array([math.sin(beta), math.cos(beta), R_C * math.cos(beta)])
        F = disc_frame(phi)
        ours = F.T @ block(row.stiffness * np.outer(row.a, row.a), model, f"rv.{d}", CENTRAL, f"rv.{d}", CENTRAL) @ F
        assert np.allclose(ours, K_PIN * np.outer(w, w), rtol=0, atol=1e-6 * K_PIN)
        counted[j] += 1
    assert counted == {0: 17, 1: 17}


# ---------------------------------------------------------------------------------------------------------------
# pin loads


@pytest.fixture(scope="module")
def loads(model):
    return pin_loads(model, span="pitch", samples=8)


def test_the_pins_hold_the_output_torque_less_the_input(model, loads):
    """At the frozen configuration the pins' torque on the discs about the pin wheel's centre is
    -T_out (1 - 1/185) = 3119.05 N m to 1e-6; each disc's torque about its own centre is Z_c / Z_p of its share
    (the arms are r_c and Z_p e), and the two discs share it equally."""
    assert loads.expected_wheel_torque == pytest.approx(3136 * (1 - 1 / 185), rel=1e-12)
    assert abs(loads.torque_balance_error[0]) < 1e-6
    assert np.allclose(np.sum(loads.disc_torque, axis=-1), -loads.wheel_torque * Z_C / Z_P, rtol=1e-12)
    assert np.allclose(loads.disc_torque[:, 0], loads.disc_torque[:, 1], rtol=1e-6)


def test_the_torque_balance_holds_at_every_frozen_time_without_the_orbit_loads(model):
    """Without the discs' centrifugal orbit loads (the rotating-frame terms off) the balance holds to 1e-9 over a
    whole eccentric turn."""
    still = build_model(model.spec, rotating_frame_terms=False)
    assert np.max(np.abs(pin_loads(still, span="turn", samples=12).torque_balance_error)) < 1e-9


def test_the_torque_balance_holds_at_every_frozen_time(model):
    assert np.max(np.abs(pin_loads(model, span="turn", samples=12).torque_balance_error)) < 1e-6


def test_about_half_the_pins_carry_load_and_the_peak_is_16_percent_over_the_classical(loads):
    """17-18 of the 40 pins per disc touch (the rigid-disc share loads 19-20: the disc's slide on its needle
    bearings unloads the pins of small arm at the leaving end and loads one past the eccentric); the peak force,
    2061-2067 N, is 1.16-1.17 times the classical 4 T / (Z_p r_c) = 1772 N and lies on the loaded side."""
    count = loads.loaded_count
    assert count.min() >= 0.4 * Z_P and count.max() <= 0.5 * Z_P
    assert np.all((loads.classical > 0).sum(axis=-1) >= 19)
    assert np.all((1.10 < loads.peak_ratio) & (loads.peak_ratio < 1.25))
    assert loads.classical_peak == pytest.approx(1772.19, abs=0.05)
    peak = np.take_along_axis(loads.arms, loads.forces.argmax(axis=-1)[..., None], axis=-1)
    assert np.all(peak < 0)


def test_the_forces_are_the_touching_rows_and_nothing_else(model):
    """The forces are k times the compression of the rows in contact; every other pin is apart (compression <= 0),
    as the cycloid stage's own pin_forces says."""
    t = 0.0037
    frozen = frozen_at(model, t)
    q = static_solution(frozen).q
    element = frozen.turning[-1]
    one = pin_loads(model, [t])
    assert np.allclose(one.forces[0], element.pin_forces(t, q, np.zeros_like(q)), rtol=0, atol=1e-9)
    delta = element.pin_deflections(t, q)
    assert np.all(delta[one.forces[0] == 0] <= 1e-15)


def test_a_full_eccentric_turn_returns_the_pattern_one_pin_on(model):
    """After one eccentric turn in the carrier frame the pins have moved on by one pitch: the forces are those of
    t = 0 shifted by one pin; a turn is Z_c pin pitches."""
    element = cycloid_element(model)
    turn, pitch = span_period(element, "turn"), span_period(element, "pitch")
    assert turn / pitch == pytest.approx(Z_P * abs(element.omega_pins - element.omega_eccentric)
                                         / abs(element.omega_eccentric), rel=1e-12)
    assert turn / pitch == pytest.approx(Z_C, rel=1e-9)
    both = pin_loads(model, [0.0, turn])
    shifted = [np.roll(both.forces[0], s, axis=-1) for s in (-1, 1)]
    assert min(np.max(np.abs(both.forces[1] - s)) for s in shifted) < 1e-3
    with pytest.raises(ValueError, match="span"):
        span_period(element, "orbit")


def test_the_figure_is_deterministic(loads):
    """Two saves of the same loads give the same PNG bytes (no software tag, no date)."""
    first, second = plots.pin_loads(loads, title="RV reducer"), plots.pin_loads(loads, title="RV reducer")
    assert first == second and first[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_model_without_a_cycloid_stage_is_refused():
    from gearcheck.train.loader import load_train

    with pytest.raises(ValueError, match="cycloid stage"):
        pin_loads(build_model(load_train("demo-3p")))
