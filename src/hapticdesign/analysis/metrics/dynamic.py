"""Dynamic metrics (seed 001 §4.3): inertia indices and the dynamic matrix.

``M`` is a joint-space inertia and ``J`` a square Jacobian, or ``M_C`` a Cartesian inertia
(:func:`hapticdesign.analysis.dynamics.cartesian.cartesian_inertia`, eq. 4.90, 4.106).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from hapticdesign.analysis.metrics.stiffness import euclidean_condition, frobenius


def inertia_volume(M_C) -> np.ndarray:
    """``I_m = det M_C`` (eq. 4.92-4.93)."""
    return np.linalg.det(np.asarray(M_C, dtype=float))


def dynamic_manipulability(M, J) -> np.ndarray:
    """``I_d = |det(J M^-1)| = |det J| / det M`` (eq. 4.97; a magnitude, like the absolute
    manipulability of eq. 4.38: the sign of det J only tells the branch, M is positive definite)."""
    return np.abs(np.linalg.det(np.asarray(J, dtype=float))) / np.linalg.det(np.asarray(M, dtype=float))


def inertia_frobenius(M_C) -> np.ndarray:
    """``I_f = sqrt(tr(M_C M_C^T))`` (eq. 4.98)."""
    return frobenius(M_C)


def inertia_uniformity(M_C) -> np.ndarray:
    """``I_e = ||M_C|| ||M_C^-1||`` (eq. 4.99)."""
    return euclidean_condition(M_C)


def acceleration_radius(M, J) -> np.ndarray:
    """Largest isotropic platform acceleration per unit joint effort: the smallest singular value
    of ``J M^-1`` (Graettinger and Krogh, seed §4.3.2, eq. 4.96)."""
    A = np.asarray(J, dtype=float) @ np.linalg.inv(np.asarray(M, dtype=float))
    return np.linalg.svd(A, compute_uv=False)[..., -1]


@dataclass(frozen=True)
class Modes:
    """Dynamic matrix ``D = M^-1 K`` (eq. 4.105; the seed's sign dropped as in eq. 7.9), its
    Frobenius norm ``omega_n`` (eq. 4.107), natural frequencies ``sqrt(eig D)`` ascending
    (rad/s, eq. 7.11-7.13) and unit modal vectors (columns)."""

    D: np.ndarray
    norm: float
    frequencies: np.ndarray
    vectors: np.ndarray


def dynamic_matrix(M, K) -> np.ndarray:
    """``D = M^-1 K`` (eq. 4.105, 7.9)."""
    return np.linalg.solve(np.asarray(M, dtype=float), np.asarray(K, dtype=float))


def natural_frequency_index(M, K) -> np.ndarray:
    """``omega_n = ||M^-1 K||_F`` (eq. 4.107)."""
    return frobenius(dynamic_matrix(M, K))


def modes(M, K) -> Modes:
    """Natural frequencies and modal vectors of ``M x'' + K x = 0`` (eq. 4.100-4.107).

    Solved as the symmetric generalized problem ``K v = w^2 M v`` (SciPy), so the frequencies are
    the square roots of the eigenvalues of ``D``.
    """
    M = np.asarray(M, dtype=float)
    K = np.asarray(K, dtype=float)
    w2, v = eigh(K, M)
    v = v / np.linalg.norm(v, axis=0)
    D = dynamic_matrix(M, K)
    return Modes(D, float(frobenius(D)), np.sqrt(np.clip(w2, 0.0, None)), v)
