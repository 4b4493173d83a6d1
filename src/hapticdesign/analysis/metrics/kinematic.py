"""Kinematic metrics (seed 001 §4.1): ellipsoids, manipulability, condition number, normalization.

Every function takes Jacobians ``(..., m, n)`` and broadcasts over leading pose axes; the
Euclidean norm ``||.||`` is the largest singular value.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.errors import UserError


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
