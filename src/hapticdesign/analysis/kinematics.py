"""Forward kinematics and geometric Jacobians of any frame of a mechanism, one pose or a batch.

Positions follow seed 000 eq. 2.24-2.26, angular velocities eq. 2.20-2.23: the Jacobian
column of a variable elementary transform is its unit twist (rotation axis through the frame
origin, or translation axis) at the current pose, weighted by the coupling coefficients of
dependent coordinates. The walk itself is the compiled one of :mod:`hapticdesign.model.walk`
(seed 001 eq. 5.61-5.66 and 5.87-5.92 for the R-CUBE chains, whose stiffness model needs a 6 x 23
Jacobian per chain and pose, eq. 5.93). Closed loops (passive joints) are solved by
:mod:`hapticdesign.analysis.loops.solver`; the pose and Jacobian of a frame at the actuated
coordinates of any device (for loops ``J T``, ``qd = T qd_a``) are those of its configuration space,
:func:`hapticdesign.analysis.configuration.configuration_of`.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model import walk
from hapticdesign.model.mechanism import Mechanism


def _check_q(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (mech.n_dof,):
        raise UserError(f"expected {mech.n_dof} joint coordinates, got shape {q.shape}")
    if not np.all(np.isfinite(q)):
        raise UserError("joint coordinates must be finite numbers")
    return q


def _frame(mech: Mechanism, frame: str | None) -> str:
    frame = frame or mech.end_effector
    if frame is None:
        raise UserError("the mechanism names no end-effector frame")
    return frame


def forward_kinematics(mech: Mechanism, q: np.ndarray, frame: str | None = None) -> np.ndarray:
    """World pose (4x4) of ``frame`` (default: the end effector) at coordinates ``q``."""
    frame = _frame(mech, frame)
    return poses_and_jacobians(mech, _check_q(mech, q), frame)[0]


def jacobian(mech: Mechanism, q: np.ndarray, frame: str | None = None) -> np.ndarray:
    """Geometric Jacobian (6 x N) of ``frame``'s origin in the base frame: rows ``v`` then ``w``."""
    frame = _frame(mech, frame)
    return poses_and_jacobians(mech, _check_q(mech, q), frame)[1]


def poses_and_jacobians(mech: Mechanism, Q: np.ndarray, frame: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World poses ``(..., 4, 4)`` and geometric Jacobians ``(..., 6, N)`` of ``frame`` at ``Q (..., N)``.

    The Jacobians are those of :func:`jacobian` (base frame, rows ``v`` then ``w``), for many
    coordinate vectors at once.
    """
    Q = np.asarray(Q, dtype=float)
    if Q.shape[-1:] != (mech.n_dof,):
        raise UserError(f"expected {mech.n_dof} coordinates per pose, got shape {Q.shape}")
    compiled = mech.compiled
    node = compiled.frame_node_of(_frame(mech, frame))
    flat = np.ascontiguousarray(Q.reshape(-1, mech.n_dof))
    poses = np.empty((flat.shape[0], 4, 4))
    jac = np.empty((flat.shape[0], 6, mech.n_dof))
    walk.poses_and_jacobians(flat, *compiled.tree.arrays, node, False, poses, jac)
    lead = Q.shape[:-1]
    return poses.reshape(lead + (4, 4)), jac.reshape(lead + (6, mech.n_dof))
