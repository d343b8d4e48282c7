"""The MuJoCo model's own linearisation against the lumped modal analysis, and its geometry.

The MuJoCo model is an independent derivation (bodies, joints and tendons whose
coefficients come from ``mj_jac``), so frequencies agreeing to rounding and the same
Lin & Parker mode types are evidence both are right.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

import gearcheck
from gearcheck.lumped.assembly import build_model
from gearcheck.train.loader import load_train, preset_names
from gearcheck.lumped.modal import modes
from gearcheck.train.variants import chained, edited
from gearcheck.mbd_models.elements.mesh import mesh_jacobian_row
from gearcheck.mbd_models.twin import compile_train

RELATIVE_TOLERANCE = 1e-6
RIGID_HZ = 1e-3  # below this a frequency is a rigid-body mode (0 in both)


def _compare(spec):
    lumped_modes = modes(build_model(spec))
    mj = gearcheck.modes(spec, "mujoco")
    assert mj.solver == "mujoco"
    assert len(mj) == len(lumped_modes)
    rows = []
    for i, (a, b) in enumerate(zip(lumped_modes.frequencies, mj.frequencies)):
        if a < RIGID_HZ:
            assert b < RIGID_HZ, f"mode {i + 1}: lumped rigid, MuJoCo {b} Hz"
            continue
        rel = abs(a - b) / a
        rows.append(rel)
        assert rel < RELATIVE_TOLERANCE, f"mode {i + 1}: lumped {a:.9g} Hz, MuJoCo {b:.9g} Hz"
    assert mj.types == lumped_modes.types
    assert mj.multiplicity == lumped_modes.multiplicity
    return max(rows)


@pytest.mark.parametrize("name", preset_names())
def test_frequencies_and_types_match_lumped(name):
    worst = _compare(load_train(name))
    print(f"{name}: max relative frequency difference {worst:.2e}")


def test_two_stage_chain_matches_lumped():
    """Coupling tendons between stages: the same frequencies as the lumped coupling rows."""
    worst = _compare(chained(2))
    print(f"chain-2: max relative frequency difference {worst:.2e}")


def test_free_input_has_one_rigid_mode():
    """Without an input shaft the train turns freely: exactly one zero frequency in MuJoCo's linearisation."""
    spec = edited("demo-3p", [(r"^input_shaft_(stiffness|damping).*$", "")], "free-input")
    mj = gearcheck.modes(spec, "mujoco")
    assert mj.types.count("rigid") == 1 and mj.frequencies[0] == 0.0
    _compare(spec)


def test_mjcf_is_deterministic_and_named():
    spec = load_train("demo-3p")
    xml = gearcheck.mjcf(spec)
    assert xml == gearcheck.mjcf(load_train("demo-3p"))
    assert xml.startswith("<!--") and "constant mean stiffness" in xml.split("-->")[0]
    assert '<compiler angle="radian"' in xml and 'gravity="0 0 0"' in xml
    for name in ("stage1_sun", "stage1_carrier", "stage1_planet2", "stage1_planet2_sun_mesh",
                 "stage1_planet2_ring_mesh"):
        assert f'name="{name}"' in xml
    model = mujoco.MjModel.from_xml_string(xml)
    for mid, member in spec.members.items():
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, member.label)
        assert model.body_mass[body] == member.mass
        assert model.body_inertia[body][2] == member.inertia
        if member.is_planet:  # planets ride on their carrier
            parent = model.body_parentid[body]
            assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, parent) == "stage1_carrier"
    # full precision: every number round-trips
    assert "0.06300000000000001" in xml  # the carrier radius, not a rounded 0.063


def test_mesh_coefficients_follow_the_carrier():
    """The runner's rotation of the world-frame coefficients equals a fresh mj_jac at a turned carrier."""
    spec = load_train("demo-3p")
    mb = compile_train(spec)
    m = mb.model
    d = mujoco.MjData(m)
    d.qpos[:] = 0.0
    d.qpos[mb.qadr["stage1.carrier"]["rz"]] = 0.7
    d.qpos[mb.qadr["stage1.sun"]["rz"]] = 2.1  # a gear's own angle does not change its mesh coefficients
    mujoco.mj_forward(m, d)
    mb.refresh(d.qpos)
    for mesh, t in zip(spec.meshes, mb.mesh_tendon):
        row = mesh_jacobian_row(spec, mb.kin, m, d, mesh)
        adr, n = m.tendon_adr[t], m.tendon_num[t]
        for w in range(adr, adr + n):
            dof = m.jnt_dofadr[m.wrap_objid[w]]
            assert m.wrap_prm[w] == pytest.approx(row[dof], abs=1e-12)
        assert np.count_nonzero(np.abs(row) > 1e-15) <= n  # no joint outside the tendon moves the mesh
    # and MuJoCo's own tendon Jacobian (sparse in 4.0) is that row
    mujoco.mj_forward(m, d)
    for mesh, t in zip(spec.meshes, mb.mesh_tendon):
        J = np.zeros(m.nv)
        a, n = m.ten_J_rowadr[t], m.ten_J_rownnz[t]
        J[m.ten_J_colind[a:a + n]] = d.ten_J[a:a + n]
        np.testing.assert_allclose(J, mesh_jacobian_row(spec, mb.kin, m, d, mesh), atol=1e-12)


def test_mesh_damping_from_tendon_geometry():
    """c = 2 zeta sqrt(k m_eq) with m_eq from the tendon's hinge coefficients: r_b of each gear."""
    spec = load_train("demo-3p")
    mb = compile_train(spec)
    for mesh, c in zip(spec.meshes, mb.mesh_damping):
        rb_c, rb_p = mesh.central_gear.base_radius, mesh.planet_gear.base_radius
        ic, ip = spec.members[mesh.central].inertia, spec.members[mesh.planet].inertia
        m_eq = 1.0 / (rb_c**2 / ic + rb_p**2 / ip)
        assert c == pytest.approx(2 * mesh.damping_ratio * math.sqrt(8.0e8 * m_eq), rel=1e-12)


def test_backlash_mesh_linearised_on_its_flank():
    """A dead band is closed for the linearisation: the same frequencies as without backlash."""
    with_backlash = gearcheck.modes(edited("demo-3p", [(r"^\[stages.mesh\]$", "[stages.mesh]\nbacklash_um = 30.0")],
                                        "backlash"))
    np.testing.assert_allclose(with_backlash.frequencies, gearcheck.modes(load_train("demo-3p"), "mujoco").frequencies,
                               rtol=1e-12)
