"""VJM stiffness (seed 001 §4.2, §5.2): beam theory, laminate moduli, K_C structure, deflections."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.rcube import stiffness as S
from hapticdesign.analysis.rcube.design import final_design, steel_design
from hapticdesign.analysis.rcube.kinematics import inverse_kinematics, q_max_for_cube
from hapticdesign.analysis.stiffness import vjm
from hapticdesign.analysis.stiffness.link import link_stiffness
from hapticdesign.analysis.stiffness.materials import M55J, Lamina, isotropic, laminate, micromechanics, off_axis
from hapticdesign.analysis.stiffness.sections import Tube, tube_from_plies
from hapticdesign.analysis.kinematics import jacobian
from hapticdesign.errors import UserError
from hapticdesign.model.mechanism import Frame, JointType, Mechanism
from hapticdesign.model.transforms import Rx, Ry, Rz, joint, tx, ty, tz

DESIGN = final_design()
GEOM = DESIGN.geometry


def single_link_vjm(L: float) -> Mechanism:
    """A cantilever of length L along x with one virtual joint at its end (eq. 5.75)."""
    vj = (tx(joint(0)), ty(joint(1)), tz(joint(2)), Rx(joint(3)), Ry(joint(4)), Rz(joint(5)))
    return Mechanism(
        coordinates=tuple(f"t{k}" for k in range(6)),
        joint_types=(JointType.PRISMATIC,) * 3 + (JointType.REVOLUTE,) * 3,
        frames=(Frame("tip", None, (tx(L), *vj)),),
        bodies=(),
        end_effector="tip",
    )


def test_single_link_vjm_matches_beam_theory():
    E, G, L = 70e9, 26e9, 0.25
    tube = Tube(0.012, 0.008)
    K_theta = link_stiffness(isotropic(E, G), tube, L)
    J = jacobian(single_link_vjm(L), np.zeros(6))
    compliance = J @ np.linalg.inv(K_theta) @ J.T
    I, Jp, A = tube.second_moment, tube.polar_moment, tube.area
    F, T = 3.0, 0.7
    assert compliance[1] @ [0, F, 0, 0, 0, 0] == pytest.approx(F * L**3 / (3 * E * I), rel=1e-12)
    assert compliance[2] @ [0, 0, F, 0, 0, 0] == pytest.approx(F * L**3 / (3 * E * I), rel=1e-12)
    assert compliance[3] @ [0, 0, 0, T, 0, 0] == pytest.approx(T * L / (G * Jp), rel=1e-12)
    assert compliance[0] @ [F, 0, 0, 0, 0, 0] == pytest.approx(F * L / (E * A), rel=1e-12)
    # tip slope under a tip force and tip deflection under a tip moment: F L^2 / (2 E I)
    assert compliance[5] @ [0, F, 0, 0, 0, 0] == pytest.approx(F * L**2 / (2 * E * I), rel=1e-12)
    assert compliance[1] @ [0, 0, 0, 0, 0, T] == pytest.approx(T * L**2 / (2 * E * I), rel=1e-12)


def test_tube_geometry_eq_5_162_to_5_166():
    t = Tube(0.02, 0.01)
    assert t.area == pytest.approx(np.pi * (0.01**2 - 0.005**2))
    assert t.polar_moment == pytest.approx(2 * t.second_moment)
    assert t.second_moment == pytest.approx(np.pi / 64 * (0.02**4 - 0.01**4))
    with pytest.raises(UserError):
        Tube(0.01, 0.01)
    with pytest.raises(UserError):
        Tube(-0.01, 0.0)
    with pytest.raises(UserError):
        tube_from_plies(0.01, (1, -1, 0, 0))
    # Table 7.8: 25 plies of 0.15 mm on an 11.25 mm mandrel give the printed 15 mm tube
    assert tube_from_plies(11.25e-3, (4, 7, 7, 7)).D == pytest.approx(15e-3)


def test_off_axis_moduli_eq_4_67_to_4_69():
    zero, ninety, diag = off_axis(M55J, 0.0), off_axis(M55J, 90.0), off_axis(M55J, 45.0)
    assert (zero.E_x, zero.E_y, zero.G_xy) == pytest.approx((300e9, 12e9, 5e9))
    assert (ninety.E_x, ninety.E_y, ninety.G_xy) == pytest.approx((12e9, 300e9, 5e9))
    # eq. 5.173: 1/E_45 = 1/(4 E1) + (1/(4 G12) - 2 nu/(4 E1)) + 1/(4 E2)
    assert 1 / diag.E_x == pytest.approx(1 / 1200e9 + (1 / 20e9 - 0.6 / 1200e9) + 1 / 48e9)
    # classical lamination: 1/G_45 = 1/E1 + 1/E2 + 2 nu12 / E1
    assert 1 / diag.G_xy == pytest.approx(1 / 300e9 + 1 / 12e9 + 0.6 / 300e9)
    # laminate average, eq. 5.179-5.181: a (0, 90) pair averages the two directions
    pair = laminate((1, 1, 0, 0))
    assert pair.E_x == pytest.approx(156e9) and pair.E_y == pytest.approx(156e9)


def test_micromechanics_rule_of_mixtures():
    lam = micromechanics(E_f=540e9, E_m=3.5e9, G_f=20e9, G_m=1.3e9, nu_f=0.2, nu_m=0.35, V_f=0.6)
    assert lam.E1 == pytest.approx(0.6 * 540e9 + 0.4 * 3.5e9)
    assert 1 / lam.E2 == pytest.approx(0.6 / 540e9 + 0.4 / 3.5e9)
    assert 1 / lam.G12 == pytest.approx(0.6 / 20e9 + 0.4 / 1.3e9)
    with pytest.raises(UserError):
        micromechanics(540e9, 3.5e9, 20e9, 1.3e9, 0.2, 0.35, 1.2)
    with pytest.raises(UserError):
        Lamina(-1.0, 1.0, 1.0, 0.3)


def test_passive_twists_carry_no_load_and_ranks_eq_5_120_to_5_128():
    rng = np.random.default_rng(3)
    for r in [GEOM.home] + [GEOM.home + rng.uniform(-0.05, 0.05, 3) for _ in range(3)]:
        q = inverse_kinematics(GEOM, r)
        Ks = S.chain_stiffness_matrices(DESIGN, r)
        for i in range(3):
            J = S.chain_jacobians(DESIGN, i, q[i])
            scale = np.abs(Ks[i]).max()
            assert np.allclose(Ks[i] @ J.passive, 0.0, atol=1e-9 * scale)  # eq. 5.118
            assert np.allclose(Ks[i], Ks[i].T, atol=1e-9 * scale)
            assert np.linalg.matrix_rank(Ks[i], tol=1e-8 * scale) == 2
        K_C = Ks.sum(axis=0)
        assert np.linalg.matrix_rank(K_C, tol=1e-10 * np.abs(K_C).max()) == 6
        assert np.all(np.linalg.eigvalsh(K_C) > 0)
        # eq. 5.124-5.126: chain i only loads its own axis a and the moments about b and c
        for i, rows in enumerate([(0, 4, 5), (1, 3, 5), (2, 3, 4)]):
            free = [k for k in range(6) if k not in rows]
            assert np.allclose(Ks[i][free], 0.0, atol=1e-9 * np.abs(Ks[i]).max())


def test_home_pose_structure_eq_5_128():
    K = S.cartesian_stiffness(DESIGN, GEOM.home)
    scale = np.abs(K).max()
    pattern = np.zeros((6, 6), bool)
    for a, b in [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5), (0, 5), (1, 3), (2, 4)]:
        pattern[a, b] = pattern[b, a] = True
    assert np.allclose(K[~pattern], 0.0, atol=1e-10 * scale)
    # identical chains: K_C111 = K_C222 = K_C333, K_C116 = K_C224 = K_C335, diagonal moments equal
    assert K[0, 0] == pytest.approx(K[1, 1]) == pytest.approx(K[2, 2])
    assert K[0, 5] == pytest.approx(K[1, 3]) == pytest.approx(K[2, 4])
    assert K[3, 3] == pytest.approx(K[4, 4]) == pytest.approx(K[5, 5])


def test_bordered_inverse_equals_projected_compliance():
    q = inverse_kinematics(GEOM, GEOM.home + [0.03, -0.02, 0.04])
    J = S.chain_jacobians(DESIGN, 1, q[1])
    C_theta = S.joint_compliance(DESIGN)
    K = vjm.chain_stiffness(J.theta, C_theta, J.passive)
    C = J.theta @ C_theta @ J.theta.T
    Ci = np.linalg.inv(C)
    P = J.passive
    expected = Ci - Ci @ P @ np.linalg.solve(P.T @ Ci @ P, P.T @ Ci)
    assert np.allclose(K, expected, rtol=1e-9, atol=1e-9 * np.abs(K).max())


def test_platform_deflection_direct_and_pose_equilibrium():
    q_max = q_max_for_cube(GEOM)
    r = GEOM.home + GEOM.l1 * np.sin(q_max)  # fully extended pose
    F = np.array([0.5, -0.5, 0.5, 0, 0, 0])  # small enough for the linearized iteration
    direct = S.platform_deflection(DESIGN, r, F)
    assert np.allclose(S.cartesian_stiffness(DESIGN, r) @ direct, F)
    # the pose equilibrium equals the direct solution to first order in the load: the odd part of
    # pose(F) differs from it by O(F^3), so halving the load divides the relative gap by about 4
    # (an O(F^2) gap, i.e. a first-order disagreement in the stiffness, would give 2)
    gaps = []
    for scale in (1.0, 0.5):
        lin = S.platform_deflection(DESIGN, r, scale * F)
        odd = (S.platform_deflection(DESIGN, r, scale * F, method="pose")
               - S.platform_deflection(DESIGN, r, -scale * F, method="pose")) / 2
        gaps.append(np.abs(odd - lin).max() / np.abs(lin).max())
    assert gaps[1] < gaps[0] / 3
    with pytest.raises(UserError):
        S.platform_deflection(DESIGN, r, F, method="guess")


def test_loaded_mode_reduces_to_unloaded_without_weights_and_wrench():
    from dataclasses import replace

    weightless = replace(DESIGN, gravity=(0.0, 0.0, 0.0))
    r = GEOM.home + [0.02, 0.01, -0.03]
    loaded = S.loaded_chain_stiffness_matrices(weightless, r)
    assert np.allclose(loaded, S.chain_stiffness_matrices(weightless, r))
    heavy = S.loaded_chain_stiffness_matrices(DESIGN, r, [5.0, 0, 0, 0, 0, 0], iterative=True)
    assert not np.allclose(heavy, S.chain_stiffness_matrices(DESIGN, r))
    theta = S.chain_deflections(DESIGN, 0, inverse_kinematics(GEOM, r)[0], [5.0, 0, 0, 0, 0, 0], loaded=True)
    assert theta.shape == (18,) and np.all(np.isfinite(theta))


def test_weight_jacobian_of_the_first_link_is_zero_eq_5_149():
    q = inverse_kinematics(GEOM, GEOM.home)
    Jg = S.weight_jacobians(DESIGN, 0, q[0])
    assert np.allclose(Jg[:6], 0.0)
    assert np.allclose(Jg[6:12, 6:], 0.0)  # link 2's mass centre precedes virtual joints 2 and 3


def test_steel_structure_example_has_positive_definite_sum():
    design = steel_design(GEOM, 0.010, 0.006)
    K = S.cartesian_stiffness(design, GEOM.home + [0.0, 0.03, -0.03])
    assert np.all(np.linalg.eigvalsh(K) > 0)
