"""R-CUBE kinematics: closed forms (seed 001 §5.1) against the elementary-transform chains."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.kinematics import forward_kinematics as core_fk
from hapticdesign.analysis.kinematics import jacobian as core_jacobian
from hapticdesign.analysis.rcube import kinematics as K
from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry, chain_mechanism, stiffness_chain_mechanism, stiffness_coordinates

GEOM = RCubeGeometry(0.1117, 0.0741, 0.1218)


def cube_points(n=7):
    return K.cube_grid(GEOM, 0.12, n).reshape(-1, 3)


def test_ik_then_fk_returns_position_over_the_workspace():
    r = cube_points()
    q = K.inverse_kinematics(GEOM, r)
    assert np.max(np.abs(K.forward_kinematics(GEOM, q[:, :, 0]) - r)) < 1e-12
    for i in range(3):
        assert np.max(np.abs(K.chain_position(GEOM, i, q[:, i, :]) - r)) < 1e-12


def test_closed_forms_match_the_elementary_transform_chains():
    r = cube_points(4)
    q = K.inverse_kinematics(GEOM, r)
    for i in range(3):
        mech = chain_mechanism(GEOM, i)
        for p in range(0, len(r), 7):
            H = core_fk(mech, q[p, i])
            assert np.allclose(H[:3, 3], r[p], atol=1e-12)
            assert np.allclose(H[:3, :3], np.eye(3), atol=1e-12)  # eq. 5.20: constant orientation
            J = core_jacobian(mech, q[p, i])
            assert np.allclose(J[:3], K.chain_jacobian(GEOM, i, q[p, i]), atol=1e-12)  # eq. 5.53-5.55
            assert np.allclose(J[3:], 0.0, atol=1e-12)  # eq. 5.68: no platform rotation
            assert np.allclose(K.extended_jacobian(GEOM, i, q[p, i]), J, atol=1e-12)


def test_virtual_chain_reduces_to_the_kinematic_chain_at_zero_deflection():
    q = K.inverse_kinematics(GEOM, GEOM.home + [0.02, -0.03, 0.01])
    for i in range(3):
        Hs = core_fk(stiffness_chain_mechanism(GEOM, i), stiffness_coordinates(q[i]))
        assert np.allclose(Hs, core_fk(chain_mechanism(GEOM, i), q[i]), atol=1e-12)


def test_jacobians_against_finite_differences():
    rng = np.random.default_rng(5)
    h = 1e-7
    for _ in range(5):
        q = rng.uniform(-1.0, 1.0, 3)
        for i in range(3):
            fd = np.stack([(K.chain_position(GEOM, i, q + h * e) - K.chain_position(GEOM, i, q - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
            assert np.allclose(K.chain_jacobian(GEOM, i, q), fd, atol=1e-8)
        fd_m = np.stack([(K.forward_kinematics(GEOM, q + h * e) - K.forward_kinematics(GEOM, q - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
        assert np.allclose(K.active_jacobian(GEOM, q), fd_m, atol=1e-8)


def test_determinant_of_chain_jacobian_eq_5_71():
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, (20, 3))
    for i in range(3):
        det = np.linalg.det(K.chain_jacobian(GEOM, i, q))
        assert np.allclose(np.abs(det), np.abs(K.chain_jacobian_determinant(GEOM, q)), rtol=1e-10, atol=1e-15)


def test_passive_rates_and_accelerations_by_differentiating_inverse_kinematics():
    r0 = GEOM.home + np.array([0.01, -0.02, 0.03])
    v, a = np.array([0.1, -0.2, 0.15]), np.array([-0.3, 0.5, 0.2])
    h = 1e-4
    path = lambda t: r0 + v * t + 0.5 * a * t * t
    q = lambda t: K.inverse_kinematics(GEOM, path(t))
    qd_fd = (q(h) - q(-h)) / (2 * h)
    qdd_fd = (q(h) - 2 * q(0.0) + q(-h)) / h**2
    assert np.allclose(K.passive_rates(GEOM, q(0.0), v), qd_fd, atol=1e-7)
    assert np.allclose(K.passive_accelerations(GEOM, q(0.0), v, a), qdd_fd, atol=1e-5)
    # eq. 5.57: q_i_dot = J_i^-1 J_m q_m_dot; the active rows equal J_m^-1 r_dot
    qm_dot = np.linalg.solve(K.active_jacobian(GEOM, q(0.0)[:, 0]), v)
    assert np.allclose(K.passive_rates(GEOM, q(0.0), v)[:, 0], qm_dot)


def test_sigma_selects_the_elbow_and_both_branches_close_the_chain():
    r = GEOM.home + [0.03, 0.02, -0.01]
    for sigma in (-1, 1):
        g = RCubeGeometry(0.1117, 0.0741, 0.1218, sigma=sigma)
        q = K.inverse_kinematics(g, r)
        assert np.all(np.sign(np.sin(q[:, 2])) == sigma)
        for i in range(3):
            assert np.allclose(K.chain_position(g, i, q[i]), r, atol=1e-12)


def test_singular_poses_eq_5_73():
    q = np.zeros((3, 3))
    q[:, 2] = -1.0
    assert not K.is_singular(GEOM, q)
    q[1, 0] = np.pi / 2
    assert K.is_singular(GEOM, q)
    q[1, 0] = 0.2
    q[2, 2] = 0.0
    assert K.is_singular(GEOM, q)
    with pytest.raises(UserError):
        K.require_regular(GEOM, q)


def test_unreachable_positions_raise():
    with pytest.raises(UserError, match="unreachable"):
        K.inverse_kinematics(GEOM, GEOM.home + [0.2, 0.0, 0.0])
    far = RCubeGeometry(0.1117, 0.02, 0.02)
    with pytest.raises(UserError, match="passive"):
        K.inverse_kinematics(far, far.home)


def test_non_positive_lengths_raise():
    with pytest.raises(UserError):
        RCubeGeometry(0.1, -0.1, 0.1)
    with pytest.raises(UserError):
        RCubeGeometry(0.0, 0.1, 0.1)


def test_workspace_and_critical_metrics_table_7_3():
    # the final design's 120 mm cube is dexterous; q_max from eq. 6.24 is Table 7.2's 32.5 degrees
    assert K.dexterous_cube(GEOM, 0.12)
    q_max = K.q_max_for_cube(GEOM, 0.12)
    assert np.degrees(q_max) == pytest.approx(32.5, abs=0.05)
    poses = K.critical_poses(GEOM, q_max)
    assert np.allclose(poses["extended"] - poses["home"], 0.06)
    assert np.allclose(poses["folded"] - poses["home"], -0.06)
    # Table 7.3, manipulability and condition number columns (eq. 6.8, 6.18), solutions 1, 20, 40
    for l1, l2, l3, mu, cv in [(111.7, 74.1, 121.8, 0.094, 1.406), (121.5, 86.3, 129.3, 0.106, 1.322),
                               (149.8, 97.4, 134.8, 0.137, 1.191)]:
        g = RCubeGeometry(l1 / 1e3, l2 / 1e3, l3 / 1e3)
        qm = K.q_max_for_cube(g)
        assert K.critical_manipulability(g, qm) == pytest.approx(mu, abs=6e-4)
        assert K.critical_condition_number(qm) == pytest.approx(cv, abs=6e-4)
