"""Kinematic metrics (seed 001 §4.1): ellipsoids, manipulability, condition number, normalization, and the range of
the handle's translational Jacobians (:func:`handle_range_basis`).

Every function takes Jacobians ``(..., m, n)`` and broadcasts over leading pose axes; the
Euclidean norm ``||.||`` is the largest singular value.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.errors import UserError

JACOBI_SWEEPS = 40
"""Most sweeps of the one-sided Jacobi iteration of :func:`handle_range_basis` (3 rows converge quadratically, in a
handful)."""


def _square(J: np.ndarray) -> np.ndarray:
    J = np.asarray(J, dtype=float)
    if J.ndim < 2:
        raise UserError(f"expected a matrix, got shape {J.shape}")
    return J


def velocity_ellipsoid(J) -> tuple[np.ndarray, np.ndarray]:
    """Radii (sqrt of the eigenvalues of ``J J^T``, eq. 4.26) and axes (eigenvectors, columns)."""
    J = _square(J)
    w, v = np.linalg.eigh(J @ np.swapaxes(J, -1, -2))
    return np.sqrt(np.clip(w, 0.0, None)), v


def force_ellipsoid(J) -> tuple[np.ndarray, np.ndarray]:
    """Radii (sqrt of the eigenvalues of ``(J J^T)^-1``, eq. 4.27) and axes; the inverse of the velocity one."""
    radii, axes = velocity_ellipsoid(J)
    with np.errstate(divide="ignore"):
        return 1.0 / radii, axes


def manipulability(J) -> np.ndarray:
    """``mu_v = sqrt(det(J J^T))`` (eq. 4.36)."""
    J = _square(J)
    return np.sqrt(np.clip(np.linalg.det(J @ np.swapaxes(J, -1, -2)), 0.0, None))


def order_independent_manipulability(J) -> np.ndarray:
    """``mu_oi = det(J J^T)^(1/n)`` with ``n`` the order of ``J J^T`` (eq. 4.37)."""
    J = _square(J)
    n = J.shape[-2]
    return np.clip(np.linalg.det(J @ np.swapaxes(J, -1, -2)), 0.0, None) ** (1.0 / n)


def absolute_manipulability(J) -> np.ndarray:
    """``mu_av = |det J|`` for square Jacobians (eq. 4.38)."""
    return np.abs(np.linalg.det(_square(J)))


def condition_number(J) -> np.ndarray:
    """``c_v = ||J|| ||J^-1||`` (eq. 4.33; equal to ``c_f`` of eq. 4.35), infinite at a singularity."""
    return condition_of_singular_values(np.linalg.svd(_square(J), compute_uv=False))


def condition_of_singular_values(s: np.ndarray) -> np.ndarray:
    """The condition number ``sigma_max / sigma_min`` of singular values (..., k), largest first (eq. 4.33)."""
    with np.errstate(divide="ignore"):
        return s[..., 0] / s[..., -1]


def handle_range_basis(J: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The left singular vectors ``U`` (P, 3, k) and singular values (P, k), largest first, of translational Jacobians
    ``J`` (P, 3, n) with ``k = min(3, n)``: the directions the handle moves and its speeds along them; and ``U^T J``
    (P, k, n), the Jacobian on those directions.

    One-sided Jacobi (Hestenes): plane rotations of the rows of ``J`` until they are mutually orthogonal,
    ``V^T J = W``; then ``J = V W``, the singular values are the rows' norms and ``U`` the columns of ``V`` in their
    order (``W``'s rows are ``U^T J``). A row below ``eps ||J||_F`` is left as it is (rank < 3: its direction is
    rounding). ``U`` is orthonormal by construction (a product of rotations) and the singular values are as accurate
    as LAPACK's (within a few ulps of ``sigma_1``), without LAPACK's per-matrix cost on thousands of 3 x n
    matrices."""
    J = np.ascontiguousarray(J, dtype=float)
    k = min(3, J.shape[-1])
    u, s, along = np.empty((len(J), 3, k)), np.empty((len(J), k)), np.empty((len(J), k, J.shape[-1]))
    _range_bases(J, u, s, along)
    return u, s, along


@njit(cache=True)
def _range_bases(jac, u, s, along):
    """:func:`handle_range_basis` of ``jac`` (P, 3, n) into ``u`` (P, 3, k), ``s`` (P, k) and ``along`` (P, k, n)."""
    n = jac.shape[2]
    k = s.shape[1]
    eps = np.finfo(np.float64).eps
    w = np.empty((3, n))
    v = np.empty((3, 3))
    norm = np.empty(3)
    order = np.empty(3, dtype=np.int64)
    for p in range(jac.shape[0]):
        total = 0.0
        for i in range(3):
            for j in range(n):
                w[i, j] = jac[p, i, j]
                total += w[i, j] * w[i, j]
            for j in range(3):
                v[i, j] = 1.0 if i == j else 0.0
        negligible = eps * eps * total
        for _ in range(JACOBI_SWEEPS):
            rotated = False
            for a in range(2):
                for b in range(a + 1, 3):
                    alpha, beta, gamma = 0.0, 0.0, 0.0
                    for j in range(n):
                        alpha += w[a, j] * w[a, j]
                        beta += w[b, j] * w[b, j]
                        gamma += w[a, j] * w[b, j]
                    if abs(gamma) <= eps * np.sqrt(alpha * beta) or min(alpha, beta) <= negligible:
                        continue  # orthogonal, or a row below the rounding of J (rank < 3)
                    rotated = True
                    zeta = (beta - alpha) / (2.0 * gamma)
                    t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                    c = 1.0 / np.sqrt(1.0 + t * t)
                    sn = c * t
                    for j in range(n):
                        wa, wb = w[a, j], w[b, j]
                        w[a, j] = c * wa - sn * wb
                        w[b, j] = sn * wa + c * wb
                    for i in range(3):
                        va, vb = v[i, a], v[i, b]
                        v[i, a] = c * va - sn * vb
                        v[i, b] = sn * va + c * vb
            if not rotated:
                break
        for i in range(3):
            acc = 0.0
            for j in range(n):
                acc += w[i, j] * w[i, j]
            norm[i] = np.sqrt(acc)
        for r in range(3):
            order[r] = r
        for r in range(1, 3):  # insertion sort, largest first
            at = r
            while at > 0 and norm[order[at]] > norm[order[at - 1]]:
                order[at], order[at - 1] = order[at - 1], order[at]
                at -= 1
        for r in range(k):
            s[p, r] = norm[order[r]]
            for i in range(3):
                u[p, i, r] = v[i, order[r]]
            for j in range(n):
                along[p, r, j] = w[order[r], j]


def characteristic_length(desired_reach: float, actual_reach: float) -> float:
    """``L = R_d / R_a`` (eq. 4.40)."""
    if actual_reach <= 0.0 or desired_reach <= 0.0:
        raise UserError("reaches must be positive")
    return desired_reach / actual_reach


def normalized_jacobian(J, actual_reach: float, desired_reach: float = 1.0) -> np.ndarray:
    """``J_n = L J`` with ``L = R_d / R_a`` (eq. 4.41-4.44): a scale-free Jacobian."""
    return characteristic_length(desired_reach, actual_reach) * _square(J)


def positioning_resolution(J) -> np.ndarray:
    """Largest platform displacement per unit joint displacement, ``||J||`` (eq. 4.30; Fig. 7.11-7.13)."""
    return np.linalg.svd(_square(J), compute_uv=False)[..., 0]


def workspace_volume_index(volumes) -> float:
    """``W_v = max(V)`` (eq. 4.1)."""
    return float(np.max(volumes))


def workspace_reach_index(positions) -> float:
    """``W_r = max ||r_p|| - min ||r_p||`` (eq. 4.2) over sampled end-effector positions ``(..., 3)``."""
    norms = np.linalg.norm(np.asarray(positions, dtype=float).reshape(-1, np.shape(positions)[-1]), axis=1)
    return float(norms.max() - norms.min())
