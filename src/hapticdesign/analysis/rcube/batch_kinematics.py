"""Batched poses and geometric Jacobians of any mechanism frame, compiled with Numba.

The same conventions as :func:`hapticdesign.analysis.kinematics.jacobian` (linear velocity of the
frame origin, then angular velocity, both in the base frame; seed 001 eq. 5.61-5.66 and 5.87-5.92),
evaluated for many coordinate vectors at once. The R-CUBE stiffness model needs a 6 x 23 Jacobian
per chain and pose (eq. 5.93), so the elementary-transform walk runs in compiled code.
"""

from __future__ import annotations

import numba
import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.mechanism import Mechanism


@numba.njit(cache=True)
def _walk(axes, coefs, offsets, Q, poses, jac):  # pragma: no cover - compiled
    n_pose, n_dof = Q.shape
    n_node = axes.shape[0]
    u_all = np.empty((n_node, 3))
    o_all = np.empty((n_node, 3))
    for p in range(n_pose):
        R = np.eye(3)
        t = np.zeros(3)
        for k in range(n_node):
            v = offsets[k]
            for j in range(n_dof):
                v += coefs[k, j] * Q[p, j]
            ax = axes[k]
            i = ax % 3
            if ax < 3:
                a, b = (i + 1) % 3, (i + 2) % 3
                c, s = np.cos(v), np.sin(v)
                for r in range(3):
                    ra, rb = R[r, a], R[r, b]
                    R[r, a] = c * ra + s * rb
                    R[r, b] = -s * ra + c * rb
            else:
                for r in range(3):
                    t[r] += R[r, i] * v
            for r in range(3):
                u_all[k, r] = R[r, i]
                o_all[k, r] = t[r]
        for r in range(3):
            for c2 in range(3):
                poses[p, r, c2] = R[r, c2]
            poses[p, r, 3] = t[r]
        poses[p, 3, 3] = 1.0
        for k in range(n_node):
            ux, uy, uz = u_all[k, 0], u_all[k, 1], u_all[k, 2]
            if axes[k] < 3:
                dx, dy, dz = t[0] - o_all[k, 0], t[1] - o_all[k, 1], t[2] - o_all[k, 2]
                lx, ly, lz = uy * dz - uz * dy, uz * dx - ux * dz, ux * dy - uy * dx
                for j in range(n_dof):
                    cj = coefs[k, j]
                    if cj != 0.0:
                        jac[p, 0, j] += lx * cj
                        jac[p, 1, j] += ly * cj
                        jac[p, 2, j] += lz * cj
                        jac[p, 3, j] += ux * cj
                        jac[p, 4, j] += uy * cj
                        jac[p, 5, j] += uz * cj
            else:
                for j in range(n_dof):
                    cj = coefs[k, j]
                    if cj != 0.0:
                        jac[p, 0, j] += ux * cj
                        jac[p, 1, j] += uy * cj
                        jac[p, 2, j] += uz * cj


_PATHS: dict[tuple[int, str], tuple] = {}


def _path_arrays(mech: Mechanism, frame: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Axis codes, couplings and offsets of the nodes from the base to ``frame`` (cached)."""
    c = mech.compiled
    key = (id(c), frame)
    hit = _PATHS.get(key)
    if hit is not None and hit[0] is c:
        return hit[1]
    path = c.path_to(frame)
    arrays = (
        np.ascontiguousarray(c.node_axis[path], dtype=np.int64),
        np.ascontiguousarray(c.node_coef[path], dtype=float),
        np.ascontiguousarray(c.node_offset[path], dtype=float),
    )
    if len(_PATHS) > 512:
        _PATHS.clear()
    _PATHS[key] = (c, arrays)
    return arrays


def poses_and_jacobians(mech: Mechanism, Q: np.ndarray, frame: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World poses ``(..., 4, 4)`` and geometric Jacobians ``(..., 6, N)`` of ``frame`` at ``Q (..., N)``."""
    frame = frame or mech.end_effector
    Q = np.asarray(Q, dtype=float)
    if Q.shape[-1] != mech.n_dof:
        raise UserError(f"expected {mech.n_dof} coordinates per pose, got shape {Q.shape}")
    flat = np.ascontiguousarray(Q.reshape(-1, mech.n_dof))
    axes, coefs, offsets = _path_arrays(mech, frame)
    poses = np.zeros((flat.shape[0], 4, 4))
    jac = np.zeros((flat.shape[0], 6, mech.n_dof))
    _walk(axes, coefs, offsets, flat, poses, jac)
    lead = Q.shape[:-1]
    return poses.reshape(lead + (4, 4)), jac.reshape(lead + (6, mech.n_dof))
