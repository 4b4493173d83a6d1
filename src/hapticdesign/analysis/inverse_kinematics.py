"""Inverse kinematics of the handle position: actuated coordinates that put a frame's origin at a point.

Newton's method on the position over the actuated coordinates, continued from the home pose along the
straight Cartesian segment from the home position to the target in steps of at most ``step`` metres, so
the answer stays on the home pose's branch (assembly mode of the loops and working mode of the chain).
Each Newton step solves ``J_v(q_a) dq_a = p* - p(q_a)`` in the least-squares sense, with ``J_v`` the
translational rows of the actuated Jacobian (``J T`` with loops); a device with fewer than three actuated
coordinates reaches only the points of its surface (a planar device: its plane), and a target off it
is out of reach. The passive coordinates of each waypoint are solved by the loop solver continued from the
previous waypoint (:class:`~hapticdesign.analysis.loops.solver.LoopSolver`).

This is a thin, separate function so that a general configuration solver can replace it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hapticdesign.analysis.configuration import configuration_of
from hapticdesign.analysis.kinematics import forward_kinematics, jacobian
from hapticdesign.errors import UserError
from hapticdesign.model.device import Device

STEP = 0.002
"""Largest Cartesian step of the continuation (m)."""
TOLERANCE = 1e-10
"""Position error accepted at each waypoint (m)."""
SINGULAR_RATIO = 1e-7
"""Smallest singular value of ``J_v`` relative to the largest below which the pose counts as singular."""
MAX_NEWTON = 30
MAX_JOINT_STEP = 0.2
"""Largest change of any actuated coordinate in one Newton step (rad or m)."""


@dataclass(frozen=True)
class HandlePose:
    """The answer: actuated and full coordinates and the position reached (m)."""

    q: np.ndarray
    full: np.ndarray
    passive: np.ndarray
    position: np.ndarray


class _Chain:
    """Position and translational Jacobian of a frame over the actuated coordinates, loops closed by
    continuation from the previous full pose."""

    def __init__(self, device: Device, frame: str | None):
        self.mech = device.mechanism
        self.frame = frame
        configuration = configuration_of(device)
        self.solver = None if configuration.is_tree else configuration.solver
        self.full = np.zeros(self.mech.n_dof) if self.solver is None else self.solver.home.copy()

    def close(self, q_a: np.ndarray) -> np.ndarray:
        if self.solver is None:
            return np.array(q_a, dtype=float)
        return self.solver.solve(q_a, start=self.full)

    def position_and_jacobian(self, full: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = forward_kinematics(self.mech, full, self.frame)[:3, 3]
        j = jacobian(self.mech, full, self.frame)[:3]
        return p, (j if self.solver is None else j @ self.solver.velocity_transform(full))


def home_actuated(device: Device) -> np.ndarray:
    """The file's home pose (zeros for a device without loops)."""
    return configuration_of(device).home.copy()


def handle_pose(device: Device, position, frame: str | None = None, start=None, step: float = STEP) -> HandlePose:
    """The actuated coordinates that put ``frame``'s origin (default: the end effector) at ``position`` (m),
    on the branch of the pose ``start`` (default: home); a one-line :class:`UserError` when the point is out
    of reach, behind a singularity or outside the joint limits."""
    target = np.asarray(position, dtype=float).reshape(3)
    if not np.all(np.isfinite(target)):
        raise UserError("the position must be three finite numbers (m)")
    chain = _Chain(device, frame)
    q = home_actuated(device) if start is None else np.asarray(start, dtype=float)
    chain.full = chain.close(q)
    p, _ = chain.position_and_jacobian(chain.full)
    n_steps = max(1, math.ceil(float(np.linalg.norm(target - p)) / step))
    for k in range(1, n_steps + 1):
        waypoint = p + (target - p) * k / n_steps
        q = _newton(chain, q, waypoint, target)
    names = device.mechanism.actuated_coordinates
    for name, value, span in zip(names, q, device.joint_limits()):
        if span is not None and not span[0] <= value <= span[1]:
            raise UserError(f"the position ({_text(target)}) m needs {name} = {value:.6g}, outside its limits "
                            f"[{span[0]:.6g}, {span[1]:.6g}]")
    passive = chain.full[list(device.mechanism.loops.passive)] if chain.solver is not None else np.zeros(0)
    reached, _ = chain.position_and_jacobian(chain.full)
    return HandlePose(q, chain.full.copy(), passive, reached)


def _newton(chain: _Chain, q: np.ndarray, waypoint: np.ndarray, target: np.ndarray) -> np.ndarray:
    for _ in range(MAX_NEWTON):
        p, jv = chain.position_and_jacobian(chain.full)
        error = waypoint - p
        if np.linalg.norm(error) <= TOLERANCE:
            return q
        s = np.linalg.svd(jv, compute_uv=False)
        if s[-1] <= SINGULAR_RATIO * s[0]:
            raise UserError(f"the position ({_text(target)}) m lies behind a singularity: the handle's Jacobian "
                            f"loses rank near ({_text(p)}) m on the way from home")
        dq = np.linalg.lstsq(jv, error, rcond=None)[0]
        dq *= min(1.0, MAX_JOINT_STEP / max(float(np.abs(dq).max()), 1e-300))
        try:
            full = chain.close(q + dq)
        except UserError:
            raise UserError(f"the position ({_text(target)}) m is out of reach: the loops cannot close on the way "
                            f"from home near ({_text(p)}) m") from None
        q, chain.full = q + dq, full
    p, _ = chain.position_and_jacobian(chain.full)
    raise UserError(f"the position ({_text(target)}) m is out of reach from home (the last point reached on the "
                    f"way is ({_text(p)}) m)")


def _text(v) -> str:
    return ", ".join(f"{x:.6g}" for x in v)
