"""Forward kinematics and geometric Jacobians of any frame of a mechanism.

Positions follow seed 000 eq. 2.24-2.26, angular velocities eq. 2.20-2.23: the Jacobian
column of a variable elementary transform is its unit twist (rotation axis through the frame
origin, or translation axis) at the current pose, weighted by the coupling coefficients of
dependent coordinates. Closed loops (passive joints) are solved by
:mod:`hapticdesign.analysis.loops.solver`; :func:`actuated_pose` and :func:`actuated_jacobian` take
the actuated coordinates of any device and, for loops, map velocities by ``qd = T qd_a``.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.errors import UserError
from hapticdesign.model.mechanism import Mechanism
from hapticdesign.model.transforms import Axis, elementary_matrix


def _check_q(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (mech.n_dof,):
        raise UserError(f"expected {mech.n_dof} joint coordinates, got shape {q.shape}")
    if not np.all(np.isfinite(q)):
        raise UserError("joint coordinates must be finite numbers")
    return q


def _node_poses(mech: Mechanism, q: np.ndarray, frame: str | None) -> tuple[list[int], list[np.ndarray]]:
    """Nodes from the base to ``frame`` (default: the end effector) and their world poses."""
    frame = frame or mech.end_effector
    if frame is None:
        raise UserError("the mechanism names no end-effector frame")
    q = _check_q(mech, q)
    c = mech.compiled
    path = c.path_to(frame)
    poses, t = [], np.eye(4)
    for n in path:
        t = t @ elementary_matrix(Axis(c.node_axis[n]), c.node_offset[n] + c.node_coef[n] @ q)
        poses.append(t)
    return path, poses


def forward_kinematics(mech: Mechanism, q: np.ndarray, frame: str | None = None) -> np.ndarray:
    """World pose (4x4) of ``frame`` (default: the end effector) at coordinates ``q``."""
    _, poses = _node_poses(mech, q, frame)
    return poses[-1] if poses else np.eye(4)


def jacobian(mech: Mechanism, q: np.ndarray, frame: str | None = None) -> np.ndarray:
    """Geometric Jacobian (6 x N) of ``frame``'s origin in the base frame: rows ``v`` then ``w``."""
    path, poses = _node_poses(mech, q, frame)
    c = mech.compiled
    p_end = poses[-1][:3, 3] if poses else np.zeros(3)
    jac = np.zeros((6, mech.n_dof))
    for n, pose in zip(path, poses):
        coef = c.node_coef[n]
        if not np.any(coef):
            continue
        axis = Axis(c.node_axis[n])
        u = pose[:3, axis.unit]
        if axis.is_rotation:
            jac[:3] += np.outer(np.cross(u, p_end - pose[:3, 3]), coef)
            jac[3:] += np.outer(u, coef)
        else:
            jac[:3] += np.outer(u, coef)
    return jac


def actuated_pose(mech: Mechanism, q_a: np.ndarray, frame: str | None = None, solver=None) -> np.ndarray:
    """World pose (4x4) of ``frame`` at actuated coordinates (passive joints solved on the assembly branch)."""
    return forward_kinematics(mech, _closed(mech, q_a, solver)[0], frame)


def actuated_jacobian(mech: Mechanism, q_a: np.ndarray, frame: str | None = None, solver=None) -> np.ndarray:
    """Geometric Jacobian (6 x N_a) of ``frame`` over the actuated coordinates: ``J(q) T`` with loops."""
    q, solver = _closed(mech, q_a, solver)
    full = jacobian(mech, q, frame)
    return full if solver is None else full @ solver.velocity_transform(q)


def _closed(mech: Mechanism, q_a: np.ndarray, solver):
    """Full coordinates of actuated ones (the identity for a tree) and the loop solver (None for a tree)."""
    if mech.loops is None:
        return np.asarray(q_a, dtype=float), None
    from hapticdesign.analysis.loops.solver import LoopSolver

    solver = solver or LoopSolver(mech)
    return solver.solve(np.asarray(q_a, dtype=float)), solver
