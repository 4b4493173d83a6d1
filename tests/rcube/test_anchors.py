"""R-CUBE physics anchored outside the code: beam theory, series springs, textbook tube inertia and volume.

Every expected value here is a closed form written in the test (Roark/Timoshenko beam formulas, the
thick-walled tube's inertia and volume) or the classical actuator-stiffness mapping, never the
module's own helper.
"""

from __future__ import annotations

from dataclasses import replace
from math import inf, pi

import numpy as np
import pytest

from hapticdesign.analysis.kinematics import forward_kinematics as core_fk
from hapticdesign.analysis.kinematics import jacobian
from hapticdesign.analysis.rcube import stiffness as S
from hapticdesign.analysis.rcube.design import FINAL_DENSITY, RCubeDesign, final_design, seed_final_design
from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix
from hapticdesign.analysis.rcube.kinematics import forward_kinematics, inverse_kinematics
from hapticdesign.analysis.stiffness import vjm
from hapticdesign.analysis.stiffness.joints import JointStiffness, spring_compliance
from hapticdesign.analysis.stiffness.link import LinkDesign, link_stiffness
from hapticdesign.analysis.stiffness.materials import LinkModuli, isotropic
from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.errors import UserError
from hapticdesign.model.mechanism import Frame, JointType, Mechanism
from hapticdesign.model.rcube import chain_mechanism
from hapticdesign.model.transforms import Rx, Ry, Rz, joint, tx, ty, tz

TABLE_7_8 = [(15e-3, 11.25e-3, 0.1117), (12e-3, 9e-3, 0.0741), (7.2e-3, 5.4e-3, 0.1218)]
"""Table 7.8: outer and inner diameter and length (m) of links 1-3."""


def cantilever(L: float) -> Mechanism:
    """A link of length L along x with a six-coordinate virtual joint at its end (eq. 5.75)."""
    vj = (tx(joint(0)), ty(joint(1)), tz(joint(2)), Rx(joint(3)), Ry(joint(4)), Rz(joint(5)))
    return Mechanism(coordinates=tuple(f"t{k}" for k in range(6)),
                     joint_types=(JointType.PRISMATIC,) * 3 + (JointType.REVOLUTE,) * 3,
                     frames=(Frame("tip", None, (tx(L), *vj)),), bodies=(), end_effector="tip")


# --- bending modulus ----------------------------------------------------------------------------

def test_a_tube_bends_with_its_axial_modulus():
    """Tip deflection F L^3 / (3 E_x I), slope F L^2 / (2 E_x I); E_y only under bending="eq. 4.59"."""
    moduli = LinkModuli(E_x=60e9, E_y=150e9, G_xy=20e9)
    tube, L, F = Tube(0.015, 0.011), 0.12, 2.0
    I = pi / 64 * (0.015**4 - 0.011**4)
    J = jacobian(cantilever(L), np.zeros(6))
    for rule, E in (("E_x", 60e9), ("eq. 4.59", 150e9)):
        C = J @ np.linalg.inv(link_stiffness(moduli, tube, L, bending=rule)) @ J.T
        assert C[1, 1] * F == pytest.approx(F * L**3 / (3 * E * I), rel=1e-12)
        assert C[5, 1] * F == pytest.approx(F * L**2 / (2 * E * I), rel=1e-12)
    assert LinkDesign(tube, moduli).stiffness(L)[1, 1] == pytest.approx(12 * 60e9 * I / L**3)
    with pytest.raises(UserError):
        link_stiffness(moduli, tube, L, bending="E_z")


def test_only_the_seed_reproduction_uses_the_printed_bending_modulus():
    assert all(link.bending == "E_x" for link in final_design().links)
    assert all(link.bending == "eq. 4.59" for link in seed_final_design().links)


# --- joint and bearing compliance -----------------------------------------------------------------

def test_cantilever_on_a_compliant_root_bearing():
    """Series springs: tip deflection F L^3/(3EI) + F L^2/k_r + F/k_t, slope F L^2/(2EI) + F L/k_r,
    twist T L/(G J) + T/k_axial with the bearing's axis along the link."""
    E, G, L, F, T = 70e9, 26e9, 0.2, 3.0, 0.4
    tube = Tube(0.012, 0.008)
    I, Jp = pi / 64 * (0.012**4 - 0.008**4), pi / 32 * (0.012**4 - 0.008**4)
    kr, kt, ka = 900.0, 4e6, 350.0
    root = np.eye(4)
    root[:3, :3] = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]  # bearing frame: z (its axis) along the link's x
    J = jacobian(cantilever(L), np.zeros(6))
    springs = spring_compliance([root], np.array([L, 0.0, 0.0]), [JointStiffness(kr, kt, ka)])
    C = vjm.compliance(J, np.linalg.inv(link_stiffness(isotropic(E, G), tube, L)), springs)
    assert C[1, 1] * F == pytest.approx(F * L**3 / (3 * E * I) + F * L**2 / kr + F / kt, rel=1e-12)
    assert C[2, 2] * F == pytest.approx(F * L**3 / (3 * E * I) + F * L**2 / kr + F / kt, rel=1e-12)
    assert C[5, 1] * F == pytest.approx(F * L**2 / (2 * E * I) + F * L / kr, rel=1e-12)
    assert C[3, 3] * T == pytest.approx(T * L / (G * Jp) + T / ka, rel=1e-12)
    assert C[0, 0] * F == pytest.approx(F * L / (E * tube.area) + F / kt, rel=1e-12)


def test_drive_stiffness_maps_through_the_jacobian_when_the_links_are_rigid():
    """Rigid links and bearings, drives of torsional stiffness k: the platform's translational compliance is
    ``J diag(1/k) J^T`` with ``J = dr/dq_active`` (the classical actuator-stiffness map), rotations rigid.

    The links are made 1e12 times stiffer than the drives seen at the platform, so the link compliance
    changes the result by about 1e-9 of it; 1e-6 leaves room for the bordered inverse's round-off."""
    base = final_design()
    g = base.geometry
    stiff = LinkDesign(Tube(0.02, 0.01), isotropic(1e22))
    k = 40.0
    design = replace(base, links=(stiff,) * 3).with_joints(
        (JointStiffness(torsional=k),) + (JointStiffness(),) * 4)
    r = g.home + np.array([0.02, -0.015, 0.03])
    q = inverse_kinematics(g, r)[:, 0]
    h = 1e-7
    J = np.column_stack([(forward_kinematics(g, q + h * e) - forward_kinematics(g, q - h * e)) / (2 * h)
                         for e in np.eye(3)])
    C = np.linalg.inv(S.cartesian_stiffness(design, r))
    expected = J @ J.T / k
    assert np.allclose(C[:3, :3], expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    assert np.abs(C[3:, 3:]).max() < 1e-9 * np.abs(expected).max()


def test_rigid_joints_leave_the_seed_model_unchanged_and_compliant_joints_soften():
    d = final_design()
    r = d.geometry.home + np.array([0.01, 0.02, -0.01])
    K = S.cartesian_stiffness(d, r)
    assert np.array_equal(S.cartesian_stiffness(d.with_joints(JointStiffness()), r), K)
    soft = S.cartesian_stiffness(d.with_joints(JointStiffness(500.0, 1e6)), r)
    # springs in series: the compliance only grows, by a positive semi-definite amount
    assert np.all(np.linalg.eigvalsh(np.linalg.inv(soft) - np.linalg.inv(K)) > -1e-12 * np.abs(np.linalg.inv(K)).max())
    with pytest.raises(UserError):
        S.platform_deflection(d.with_joints(JointStiffness(500.0)), r, [1, 0, 0], method="pose")
    with pytest.raises(UserError):
        JointStiffness(rotational=-3.0)


# --- loaded mode: a tube under its own weight -----------------------------------------------------

@pytest.mark.parametrize("platform_mass", [0.0, 0.06])
def test_last_link_deflects_as_a_cantilever_under_its_weight(platform_mass):
    """Link 3's virtual joint under its own distributed weight w (per length) and a third of the
    platform's weight P at its end: w L^4/(8EI) + P L^3/(3EI), slope w L^3/(6EI) + P L^2/(2EI),
    stretch w L^2/(2 E A) + P L/(E A) (cantilever from its root, beam theory)."""
    d = replace(final_design(), platform_mass=platform_mass, gravity=(0.0, 0.0, -9.81))
    g = d.geometry
    r = g.home + np.array([0.015, -0.02, 0.025])
    q = inverse_kinematics(g, r)
    D, dd, L = TABLE_7_8[2]
    A, I = pi / 4 * (D**2 - dd**2), pi / 64 * (D**4 - dd**4)
    E = d.links[2].moduli.E_x
    for chain in range(3):
        R = core_fk(chain_mechanism(g, chain), q[chain], "link3")[:3, :3]  # x along link 3
        w = R.T @ np.array([0.0, 0.0, -9.81]) * FINAL_DENSITY * A  # weight per length, link frame
        P = R.T @ np.array([0.0, 0.0, -9.81]) * platform_mass / 3.0
        theta = S.chain_deflections(d, chain, q[chain], np.zeros(6), loaded=True)[12:18]
        bend = w * L**4 / (8 * E * I) + P * L**3 / (3 * E * I)
        slope = w * L**3 / (6 * E * I) + P * L**2 / (2 * E * I)
        scale = np.abs(bend[1:]).max()
        assert theta[0] == pytest.approx(w[0] * L**2 / (2 * E * A) + P[0] * L / (E * A), rel=1e-9, abs=1e-12 * scale)
        assert theta[1:3] == pytest.approx(bend[1:], rel=1e-9, abs=1e-12 * scale)
        assert theta[5] == pytest.approx(slope[1], rel=1e-9, abs=1e-12 * abs(slope).max())
        assert theta[4] == pytest.approx(-slope[2], rel=1e-9, abs=1e-12 * abs(slope).max())


# --- mass and inertia -----------------------------------------------------------------------------

def tube_volume(D: float, d: float, L: float) -> float:
    return pi / 4 * (D**2 - d**2) * L


def test_link_mass_is_the_tube_volumes_times_the_stated_density():
    """Table 7.8's tubes, three chains, at the stated 1790 kg/m^3 (the density 77.7 g implies)."""
    expected = 3 * sum(tube_volume(*row) for row in TABLE_7_8) * 1790.0
    assert final_design().total_link_mass() == pytest.approx(expected, rel=1e-12)
    # the seed-reproduction tubes have twice the diameters and a quarter of the density
    assert seed_final_design().total_link_mass() == pytest.approx(
        3 * sum(tube_volume(2 * D, 2 * d, L) for D, d, L in TABLE_7_8) * 1790.0 / 4, rel=1e-12)


def textbook_tube_inertia(m: float, L: float, D: float, d: float) -> np.ndarray:
    """Thick-walled cylindrical tube about its centre, axis x: m (R^2 + r^2)/2 and m (3 (R^2 + r^2) + L^2)/12."""
    s = (D / 2) ** 2 + (d / 2) ** 2
    return np.diag([m * s / 2, m * (3 * s + L**2) / 12, m * (3 * s + L**2) / 12])


def kinetic_energy(design: RCubeDesign, r: np.ndarray, v: np.ndarray, h: float = 1e-6) -> float:
    """Sum over the nine tubes of 1/2 m |v_c|^2 + 1/2 w^T I w, velocities from central differences of the
    mass-centre frames along the platform path r + t v (no Jacobians, no code inertia)."""
    g = design.geometry
    q0, qp, qm = (inverse_kinematics(g, x) for x in (r, r + h * v, r - h * v))
    total = 0.0
    for i in range(3):
        mech = chain_mechanism(g, i)
        for j, (D, d, L) in enumerate(TABLE_7_8):
            m = FINAL_DENSITY * tube_volume(D, d, L)
            H0, Hp, Hm = (core_fk(mech, q[i], f"com{j + 1}") for q in (q0, qp, qm))
            vel = (Hp[:3, 3] - Hm[:3, 3]) / (2 * h)
            W = (Hp[:3, :3] - Hm[:3, :3]) / (2 * h) @ H0[:3, :3].T
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            I = H0[:3, :3] @ textbook_tube_inertia(m, L, D, d) @ H0[:3, :3].T
            total += 0.5 * m * vel @ vel + 0.5 * w @ I @ w
    return total


def test_cartesian_mass_matrix_against_textbook_tube_inertias():
    """1/2 v^T M_C v (eq. 5.223, 5.227) is the kinetic energy of the nine tubes moving with the platform."""
    design = final_design()
    rng = np.random.default_rng(5)
    for r in [design.geometry.home] + [design.geometry.home + rng.uniform(-0.05, 0.05, 3) for _ in range(2)]:
        v = rng.normal(size=3)
        M = cartesian_mass_matrix(design, r)
        assert 0.5 * v @ M @ v == pytest.approx(kinetic_energy(design, r, v), rel=1e-7)


def test_joint_stiffness_from_a_design_file(tmp_path):
    from hapticdesign.analysis.rcube.design_io import design_from_mapping

    one = design_from_mapping({"joints": {"rotational": 800, "translational": 2e6}})
    assert one.joints == (JointStiffness(800.0, 2e6),) * 5
    each = design_from_mapping({"joints": [{"torsional": 50}, {}, {}, {}, {"rotational": 10}]})
    assert each.joints[0].axial == 50.0 and each.joints[0].rotational == inf and each.joints[4].rotational == 10.0
    for bad in ({"joints": [{}, {}]}, {"joints": {"stiff": 3}}, {"joints": {"rotational": 0}}):
        with pytest.raises(UserError):
            design_from_mapping(bad)
