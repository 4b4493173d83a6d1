"""Cartesian (operational-space) inertia and damping of any device: the one place they are computed.

With task velocities ``v = J qd`` the kinetic energy ``1/2 qd^T H qd`` is ``1/2 v^T M_C v`` for

    M_C = J^-T H J^-1                 (square J; seed 001 eq. 4.90, 4.106, 5.223)
    M_C = (J H^-1 J^T)^-1             (J with fewer rows than columns; Khatib's operational-space inertia)

and the two agree for a square ``J``. The joints' viscous damping ``B`` is felt at the handle, on an orthonormal basis
``U`` of the directions it moves, as ``U^T J^+T B J^+ U`` (:func:`damping`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hapticdesign.errors import UserError
from hapticdesign.model.dense import lu_in_place

SINGULAR_CONDITION = 1.0 / np.finfo(float).eps
"""Condition estimate ``max|A_ij| max|(A^-1)_ij|`` (within a factor ``n^2`` of the infinity-norm
condition number) above which a matrix counts as singular to working precision."""


def _inverse(A: np.ndarray, what: str) -> np.ndarray:
    """Batched inverse of square matrices; a singular one (exactly or to working precision) is a :class:`UserError`."""
    try:
        inv = np.linalg.inv(A)
    except np.linalg.LinAlgError:
        raise UserError(f"{what} is singular: no Cartesian inertia at this pose (the Jacobian loses rank)") from None
    magnitude, inverse_magnitude = np.abs(A), np.abs(inv)
    if magnitude.max() * inverse_magnitude.max() < SINGULAR_CONDITION:  # bounds every matrix's estimate
        return inv
    condition = magnitude.max(axis=(-2, -1)) * inverse_magnitude.max(axis=(-2, -1))
    if not np.all(condition < SINGULAR_CONDITION):
        raise UserError(f"{what} is singular: no Cartesian inertia at this pose (the Jacobian loses rank)")
    return inv


def cartesian_inertia(mass_matrix, jacobian) -> np.ndarray:
    """Cartesian inertia ``M_C`` (..., m, m) of a joint-space inertia ``H`` (..., n, n) and a task
    Jacobian ``J`` (..., m, n), batched over the leading axes.

    ``J^-T H J^-1`` for a square ``J`` (seed 001 eq. 4.90, 4.106, 5.223); ``(J H^-1 J^T)^-1`` for
    ``m < n``. A ``J`` that loses rank (or ``m > n``) raises :class:`UserError`.
    """
    H = np.asarray(mass_matrix, dtype=float)
    J = np.asarray(jacobian, dtype=float)
    if H.ndim < 2 or J.ndim < 2 or H.shape[-1] != H.shape[-2] or J.shape[-1] != H.shape[-1]:
        raise UserError(f"a mass matrix (..., n, n) and a Jacobian (..., m, n) are needed, got shapes {H.shape} and {J.shape}")
    m, n = J.shape[-2:]
    if m > n:
        raise UserError(f"a task of {m} coordinates has no Cartesian inertia with {n} joints (J loses rank)")
    if m == n:
        Jinv = _inverse(J, "the Jacobian")
        return np.swapaxes(Jinv, -1, -2) @ H @ Jinv
    return _inverse(mobility(H, J), "J H^-1 J^T")


def mobility(mass_matrix: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """``J H^-1 J^T`` (..., m, m): the inverse of the Cartesian inertia of a full-row-rank ``J`` (1/kg for a
    translational task), batched over the leading axes (a compiled solve per matrix, :func:`_mobilities`); a
    singular ``H`` raises :class:`numpy.linalg.LinAlgError`."""
    H = np.asarray(mass_matrix, dtype=float)
    J = np.asarray(jacobian, dtype=float)
    stack = np.broadcast_shapes(H.shape[:-2], J.shape[:-2])
    m, n = J.shape[-2:]
    hs = np.ascontiguousarray(np.broadcast_to(H, (*stack, n, n))).reshape(-1, n, n)
    js = np.ascontiguousarray(np.broadcast_to(J, (*stack, m, n))).reshape(-1, m, n)
    out = np.empty((len(js), m, m))
    if not _mobilities(hs, js, out):
        raise np.linalg.LinAlgError("Singular matrix")
    return out.reshape(*stack, m, m)


def damping(jacobian: np.ndarray, basis: np.ndarray, joint_damping: np.ndarray) -> np.ndarray:
    """``U^T J^+T B J^+ U`` (P, k, k): the joint damping ``B`` (n, n) or (P, n, n) felt at the handle along the
    orthonormal basis ``U`` (P, 3, k) of the directions a translational Jacobian ``J`` (P, 3, n) moves it in (N s/m
    for B in N m s/rad)."""
    pinv = np.linalg.pinv(jacobian) @ basis
    return np.swapaxes(pinv, 1, 2) @ joint_damping @ pinv


@njit(cache=True)
def _mobilities(H, J, out):
    """``J_i H_i^-1 J_i^T`` into ``out[i]`` (H (P, n, n), J (P, m, n)) by Gaussian elimination with partial pivoting
    (:func:`~hapticdesign.model.dense.lu_in_place`); False when some ``H_i`` is singular."""
    n, m = H.shape[1], J.shape[1]
    lu, x = np.empty((n, n)), np.empty((n, m))
    for p in range(H.shape[0]):
        for i in range(n):
            for j in range(n):
                lu[i, j] = H[p, i, j]
            for j in range(m):
                x[i, j] = J[p, j, i]
        ratio, _ = lu_in_place(lu, x)
        if ratio == 0.0:
            return False
        for i in range(m):
            for j in range(i + 1):
                acc = 0.0
                for c in range(n):
                    acc += J[p, i, c] * x[c, j]
                out[p, i, j] = acc
                out[p, j, i] = acc
    return True
