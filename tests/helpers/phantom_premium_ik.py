"""The Phantom Premium's inverse kinematics in closed form, an oracle that does not use the toolkit: Cavusoglu &
Feygin's coordinates (x = cos q1 (l1 cos q2 + l2 sin q3), y = sin q1 (...), z = l1 sin q2 - l2 cos q3), q1 =
atan2(y, x), q2 and q3 from the triangle shoulder-elbow-handle on the elbow-down branch of home, and the joint
limits of examples/devices/phantom-premium.yaml."""

from __future__ import annotations

import math

import numpy as np

L1, L2 = 0.215, 0.170
LIMITS = np.radians([(-90, 90), (-124, 119), (-29, 214)])


def closed_form(p, l1: float = L1, l2: float = L2) -> np.ndarray | None:
    """(q1, q2, q3) putting the handle at p on home's branch, or None out of the arm's reach."""
    x, y, z = p
    rho = math.hypot(x, y)
    h = math.hypot(rho, z)
    shoulder = (l1**2 + h**2 - l2**2) / (2 * l1 * h)
    elbow = (l1**2 + l2**2 - h**2) / (2 * l1 * l2)
    if abs(shoulder) >= 1 or abs(elbow) >= 1 or rho == 0.0:
        return None
    q2 = math.atan2(z, rho) + math.acos(shoulder)
    return np.array([math.atan2(y, x), q2, q2 - math.pi / 2 + math.acos(elbow)])


def reachable(p, l1: float = L1, l2: float = L2) -> bool:
    """The handle reaches p within the joint limits."""
    q = closed_form(p, l1, l2)
    return q is not None and bool(np.all((LIMITS[:, 0] <= q) & (q <= LIMITS[:, 1])))
