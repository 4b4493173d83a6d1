"""Joint and bearing compliance as extra springs of the virtual joint method (seed 001 §4.2, §5.2).

The seed's VJM (eq. 5.98-5.123) lumps all elasticity into the links' virtual joints and treats the
joints themselves as ideal. A real joint adds a bearing: translations and tilts of the joint's
frame resisted by finite stiffnesses, and, at the active joint, the drive's torsional stiffness
about its axis. Each is a six-coordinate spring ``(dt, dphi)`` in the joint's frame (z along the
joint axis) in series with the chain, so its compliance maps to the end point like a virtual joint's
(eq. 5.105, 5.119): ``C = J_s C_s J_s^T`` with the rigid-body Jacobian ``J_s`` of the spring, and the
chain's Cartesian compliance becomes ``J_theta K_theta^-1 J_theta^T + sum_s J_s C_s J_s^T``.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import inf, isinf, isnan

import numpy as np

from hapticdesign.errors import UserError


def _stiffness(name: str, value: float) -> float:
    value = float(value)
    if isnan(value) or value <= 0.0:
        raise UserError(f"joint {name} stiffness must be positive (inf for rigid), got {value!r}")
    return value


@dataclass(frozen=True)
class JointStiffness:
    """Bearing and drive stiffness of one joint; ``inf`` is rigid (the seed's ideal joint).

    ``rotational`` (N m/rad): tilt of the joint's frame about the two axes normal to the joint axis;
    ``translational`` (N/m): displacement of the joint's frame in any direction; ``torsional``
    (N m/rad): rotation about the joint axis, the drive and transmission at an active joint (at a
    passive joint it is in series with the free rotation and has no effect once the passive joints
    are eliminated, eq. 5.121). ``None`` takes the ``rotational`` value.
    """

    rotational: float = inf
    translational: float = inf
    torsional: float | None = None

    def __post_init__(self) -> None:
        _stiffness("rotational", self.rotational)
        _stiffness("translational", self.translational)
        if self.torsional is not None:
            _stiffness("torsional", self.torsional)

    @property
    def rigid(self) -> bool:
        return isinf(self.rotational) and isinf(self.translational) and isinf(self.axial)

    @property
    def axial(self) -> float:
        """Stiffness about the joint axis (N m/rad)."""
        return self.rotational if self.torsional is None else self.torsional

    def compliance(self) -> np.ndarray:
        """6 x 6 compliance in the joint frame, coordinates ``(tx, ty, tz, rx, ry, rz)``, z the axis."""
        kt, kr = self.translational, self.rotational
        return np.diag([1.0 / kt, 1.0 / kt, 1.0 / kt, 1.0 / kr, 1.0 / kr, 1.0 / self.axial])


RIGID = JointStiffness()


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrix ``[v]x`` of ``(..., 3)`` vectors, ``(..., 3, 3)``."""
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def spring_jacobian(frame: np.ndarray, point) -> np.ndarray:
    """Twist ``(v, w)`` at ``point`` per unit spring deflection ``(dt, dphi)`` of a spring whose frame has
    the pose ``frame (..., 4, 4)``: ``w = R dphi``, ``v = R dt + (R dphi) x (point - origin)`` (the
    rigid-body map of eq. 5.93-5.97 for a six-coordinate virtual joint)."""
    R, origin = frame[..., :3, :3], frame[..., :3, 3]
    arm = np.asarray(point, dtype=float) - origin
    J = np.zeros(R.shape[:-2] + (6, 6))
    J[..., :3, :3] = R
    J[..., :3, 3:] = -skew(arm) @ R
    J[..., 3:, 3:] = R
    return J


def spring_compliance(frames: list[np.ndarray], point, joints: list[JointStiffness]) -> np.ndarray:
    """Cartesian compliance at ``point`` of springs in series: ``sum_s J_s C_s J_s^T`` (``(..., 6, 6)``)."""
    total = 0.0
    for frame, joint in zip(frames, joints, strict=True):
        if joint.rigid:
            continue
        J = spring_jacobian(frame, point)
        total = total + J @ joint.compliance() @ np.swapaxes(J, -1, -2)
    lead = np.broadcast_shapes(*[f.shape[:-2] for f in frames], np.shape(point)[:-1])
    return np.broadcast_to(total, lead + (6, 6)).copy() if np.isscalar(total) else total
