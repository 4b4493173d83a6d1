"""The force a handle can exert in every direction: the force polytope's inscribed radius (issue 23, spec sheets).

With ``J_v`` the handle's translational Jacobian over the actuated coordinates, ``U`` the directions the handle
moves (the range of ``J_v``), ``A`` the motors' transmission (row k: the combination ``a_k^T q`` motor k turns
through ratio ``n_k``) and ``tau_k`` its torque limit, a handle force ``F = U f`` is held by the joint torques
``J_v^T F`` and so by the motor torques ``(A^-T J_v^T U f)_k / n_k``. The force polytope is
``{f : |g_k . f| <= n_k tau_k}`` with ``g_k`` row k of ``A^-T J_v^T U``; it is symmetric about 0, so its largest
ball is centred there and its radius, the largest force the handle exerts in every direction, is the smallest
distance to a facet, ``min_k n_k tau_k / |g_k|`` (N; gravity not included). Defined when the motors are one per
actuated coordinate (``A`` square) and each has the torque limit.
"""

from __future__ import annotations

import numpy as np

from hapticdesign.model.actuators import transmission
from hapticdesign.model.device import Device


def motor_map(device: Device) -> np.ndarray | None:
    """``A^-1`` (coordinates x motors), or None when the motors are not one per actuated coordinate."""
    if len(device.actuators) != device.n_dof:
        return None
    return np.linalg.inv(transmission(device.actuators, device.n_dof))


def torque_limits(device: Device, which: str = "continuous") -> np.ndarray | None:
    """``n_k tau_k`` per motor (N m or N at the coordinates' side) for ``which`` = ``continuous`` or ``peak``
    torques, or None when a motor lacks it."""
    torques = [getattr(a, f"torque_{which}") for a in device.actuators]
    if not torques or any(t is None for t in torques):
        return None
    return np.array([a.gear_ratio * t for a, t in zip(device.actuators, torques)])


def inscribed_force(jacobian: np.ndarray, basis: np.ndarray, inverse_map: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """The force polytope's inscribed radius (N) at poses with ``J_v`` (..., 3, n_a), ``U`` (..., 3, k), ``A^-1``
    (n_a, n_a) and ``n_k tau_k`` (n_a,), or those per pose (..., n_a, n_a), (..., n_a) (see the module docstring)."""
    g = np.swapaxes(inverse_map, -1, -2) @ np.swapaxes(jacobian, -1, -2) @ basis
    return np.min(limits / np.linalg.norm(g, axis=-1), axis=-1)
