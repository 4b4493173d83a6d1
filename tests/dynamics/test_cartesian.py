"""Cartesian inertia (seed 001 eq. 4.90, 4.106, 5.223) and the kernel's mass matrix against independent constructions."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import solve

from hapticdesign.analysis.dynamics.cartesian import cartesian_inertia, mobility
from hapticdesign.analysis.dynamics.device import mass_matrix, tree_mass_matrix
from hapticdesign.errors import UserError
from hapticdesign.model.dense import symmetric_eigenvalues


def spd(rng, n: int, batch=()) -> np.ndarray:
    A = rng.normal(size=batch + (n, n))
    return A @ np.swapaxes(A, -1, -2) + n * np.eye(n)


def least_energy_inertia(H: np.ndarray, J: np.ndarray) -> np.ndarray:
    """The inertia felt at the task: 1/2 v^T M_C v is the least kinetic energy 1/2 qd^T H qd with J qd = v,
    from the KKT system [[H, J^T], [J, 0]] [qd; lambda] = [0; v] solved by SciPy, for v = e_1 .. e_m."""
    m, n = J.shape
    K = np.block([[H, J.T], [J, np.zeros((m, m))]])
    Qd = solve(K, np.vstack([np.zeros((n, m)), np.eye(m)]))[:n]
    return Qd.T @ H @ Qd


def test_square_jacobian_gives_the_kinetic_energy_of_the_task_velocity():
    rng = np.random.default_rng(0)
    H, J = spd(rng, 3, (4,)), rng.normal(size=(4, 3, 3))
    M_C = cartesian_inertia(H, J)
    for k in range(4):
        qd = rng.normal(size=3)
        v = J[k] @ qd
        assert v @ M_C[k] @ v == pytest.approx(qd @ H[k] @ qd, rel=1e-12)  # eq. 4.90
        assert np.allclose(M_C[k], least_energy_inertia(H[k], J[k]), rtol=1e-10, atol=0.0)


def test_redundant_jacobian_gives_the_least_kinetic_energy():
    """(J H^-1 J^T)^-1 for fewer task coordinates than joints (a 3-coordinate task of 5 joints)."""
    rng = np.random.default_rng(1)
    H, J = spd(rng, 5, (2, 3)), rng.normal(size=(2, 3, 3, 5))
    M_C = cartesian_inertia(H, J)
    assert M_C.shape == (2, 3, 3, 3)
    for i in range(2):
        for k in range(3):
            assert np.allclose(M_C[i, k], least_energy_inertia(H[i, k], J[i, k]), rtol=1e-10, atol=0.0)


@pytest.mark.parametrize("J", [
    np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]]),       # exactly singular
    np.array([[1.0, 2.0, 0.0], [2.0, 4.0 + 1e-17, 0.0], [0.0, 0.0, 1.0]]),  # singular to working precision
    np.array([[1.0, 2.0, 0.0, 1.0], [2.0, 4.0, 0.0, 2.0]]),              # redundant but rank 1
    np.ones((4, 3)),                                                    # more task rows than joints
])
def test_a_jacobian_that_loses_rank_is_a_user_error(J):
    with pytest.raises(UserError, match="loses rank"):
        cartesian_inertia(np.eye(J.shape[1]), J)


def test_a_batch_with_one_singular_jacobian_is_refused():
    J = np.stack([np.eye(3), np.diag([1.0, 1.0, 0.0])])
    with pytest.raises(UserError, match="singular"):
        cartesian_inertia(np.stack([np.eye(3)] * 2), J)


def test_kernel_mass_matrix_equals_the_fitted_model(phantom6):
    """H straight from the compiled kernel equals the fitted model's at any batch shape (both exact)."""
    q = np.random.default_rng(2).uniform(-np.pi, np.pi, (2, 4, 6))
    H = tree_mass_matrix(phantom6.mechanism, q, phantom6.standard_parameters())
    assert H.shape == (2, 4, 6, 6)
    assert np.allclose(H.reshape(-1, 6, 6), mass_matrix(phantom6, q.reshape(-1, 6)), rtol=1e-10, atol=1e-14)
    with pytest.raises(UserError):
        tree_mass_matrix(phantom6.mechanism, np.full(6, np.nan), phantom6.standard_parameters())


def test_mobility_matches_scipy_solves_with_broadcasting_and_refuses_a_singular_mass_matrix():
    """``J H^-1 J^T`` of the compiled solve against SciPy's solve per matrix: a stack of H with one J, one H with a
    stack of J, and an exactly singular H (LinAlgError, as NumPy's solve)."""
    rng = np.random.default_rng(4)
    H, J = spd(rng, 3, (5,)), rng.normal(size=(2, 3))
    expected = np.array([J @ solve(h, J.T) for h in H])
    assert np.allclose(mobility(H, J), expected, rtol=1e-13, atol=0)
    Js = rng.normal(size=(5, 2, 3))
    assert np.allclose(mobility(H[0], Js), [j @ solve(H[0], j.T) for j in Js], rtol=1e-13, atol=0)
    with pytest.raises(np.linalg.LinAlgError):
        mobility(np.zeros((3, 3)), J)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_symmetric_eigenvalues_match_lapack_on_near_singular_mobilities(k):
    """The compiled Jacobi eigenvalues of symmetric positive definite k x k matrices (ascending) within a few ulps of
    the largest of LAPACK's eigvalsh (the backward error both have), condition numbers up to ~1e14, ascending."""
    rng = np.random.default_rng(5)
    Q, _ = np.linalg.qr(rng.normal(size=(3000, k, k)))
    d = np.sort(rng.uniform(1e-6, 1.0, size=(3000, k)), axis=1)
    d[:1000, 0] *= 1e-8
    M = (Q * d[:, None, :]) @ np.swapaxes(Q, 1, 2)
    got, lapack = symmetric_eigenvalues(M), np.linalg.eigvalsh(M)
    eps = np.finfo(float).eps
    assert np.all(np.abs(got - lapack) <= 16 * eps * lapack[:, -1:])
    assert np.all(np.diff(got, axis=1) >= 0)
