"""Kinematic design constraints of the modified R-CUBE (seed 001 §6.1.3, eq. 6.19-6.52).

Design vector ``x = (q_max, l2, l3)`` (rad, m, m). Constraint 1 (eq. 6.24) gives
``l1 = h / sin q_max`` for a workspace cube of half edge ``h`` (60 mm). Constraints 3-7 keep the
passive elbow away from its singularity at the critical points of a larger virtual cube of half
edge ``v`` (65 mm; points C2, C3, C5, B3, B5 of eq. 6.40-6.44); Constraint 8 (eq. 6.52) keeps the
hand's side free at C1 and B1.

Points are ``(r_x, r_y)`` in the passive plane of chain 1 (eq. 6.33-6.34): ``r_x`` is the world
coordinate ``r_b`` and ``r_y = r_c - l1 cos q_a1``, which is what
:func:`hapticdesign.analysis.rcube.kinematics.passive_reach` uses, so that the closed forms here
agree with the mechanism's inverse kinematics at the corresponding platform positions. Two
readings of the printed text: eq. 6.48 prints ``+ 60 cot q_max`` where eq. 6.43 gives
``r_y = Delta_y + 65`` with ``Delta_y = l1 - l1 cos q_max`` (the printed sign makes every Table 7.2
solution infeasible); C1 and B1 (Figure 6.3 is missing) are the corners ``(l1 - v, -v)`` and
``(l1 - v, Delta_y - v)``, the points where Table 7.2's shortest solutions meet eq. 6.52.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import isfinite

import numpy as np

from hapticdesign.analysis.rcube.kinematics import arm_angles, elbow_cosine
from hapticdesign.errors import UserError

Q_MAX_RANGE = (0.07, 1.5)
"""Constraint 2 (eq. 6.28), rad."""

PASSIVE_POINTS = ("C2", "C3", "C5", "B3", "B5")
"""Points of Constraints 3-7 (eq. 6.45-6.49), in that order."""

ERGONOMIC_POINTS = ("C1", "B1")
"""Points of Constraint 8 (eq. 6.52)."""

CONSTRAINT_NAMES = tuple(f"constraint {k} ({p})" for k, p in zip(range(3, 8), PASSIVE_POINTS)) + tuple(
    f"constraint 8 ({p})" for p in ERGONOMIC_POINTS
)


@dataclass(frozen=True)
class CubeWorkspace:
    """Cube edge ``side`` (m, 120 mm in §6.1.3) and the virtual cube's edge ``virtual_side``
    (130 mm) on which the passive constraints are placed."""

    side: float = 0.120
    virtual_side: float = 0.130

    def __post_init__(self) -> None:
        if not isfinite(self.side) or self.side <= 0.0:
            raise UserError(f"workspace edge must be positive, got {self.side!r} m")
        if not isfinite(self.virtual_side) or self.virtual_side < self.side:
            raise UserError(
                f"the virtual workspace edge ({self.virtual_side!r} m) must be at least the workspace edge ({self.side!r} m)"
            )

    @property
    def half(self) -> float:
        return self.side / 2.0

    @property
    def virtual_half(self) -> float:
        return self.virtual_side / 2.0


def link1_length(q_max, workspace: CubeWorkspace = CubeWorkspace()) -> np.ndarray:
    """Constraint 1: ``l1 = h / sin q_max`` (eq. 6.24)."""
    return workspace.half / np.sin(np.asarray(q_max, dtype=float))


def critical_points(q_max, workspace: CubeWorkspace = CubeWorkspace()) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``(r_x, r_y)`` of the critical points (eq. 6.40-6.44 and C1, B1), broadcast over ``q_max``."""
    q = np.asarray(q_max, dtype=float)
    l1 = link1_length(q, workspace)
    v = workspace.virtual_half
    dy = l1 - l1 * np.cos(q)
    zero = np.zeros_like(l1)
    return {
        "C1": (l1 - v, zero - v),
        "C2": (l1 + v, zero - v),
        "C3": (l1 + v, zero + v),
        "C5": (l1 - v, zero),
        "B1": (l1 - v, dy - v),
        "B3": (l1 + v, dy + v),
        "B5": (l1 - v, dy),
    }


def distal_sine(r_x, r_y, l2, l3, sigma: int = -1) -> np.ndarray:
    """``sin(q_i2 + q_i3)`` of the passive arm at ``(r_x, r_y)`` (eq. 5.40-5.45, 6.50-6.52).

    ``r_y`` is the arm's reach along the link-1 direction and ``r_x`` the across coordinate
    ``r_b``; the elbow takes the configuration ``sigma`` (eq. 5.42). Unreachable points are
    evaluated at the nearest reachable elbow angle (their Constraints 3-7 fail anyway).
    """
    q2, q3 = arm_angles(r_x, r_y, l2, l3, sigma)
    return np.sin(q2 + q3)


def constraint_values(X, workspace: CubeWorkspace = CubeWorkspace()) -> np.ndarray:
    """Constraints 3-8 as ``g <= 0`` (pymoo's convention), shape ``(n, 7)``, for designs ``X (n, 3)``.

    Constraints 3-7: ``cos^2 q_i3 - 1 < 0`` at C2, C3, C5, B3, B5 (eq. 6.45-6.49);
    Constraint 8: ``sin(q_i2 + q_i3) <= 0`` at C1 and B1 (eq. 6.52).
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    q, l2, l3 = X[:, 0], X[:, 1], X[:, 2]
    points = critical_points(q, workspace)
    passive = [elbow_cosine(*points[p], l2, l3) ** 2 - 1.0 for p in PASSIVE_POINTS]
    ergonomic = [distal_sine(*points[p], l2, l3) for p in ERGONOMIC_POINTS]
    return np.stack(passive + ergonomic, axis=1)


def is_feasible(X, workspace: CubeWorkspace = CubeWorkspace(), tolerance: float = 0.0) -> np.ndarray:
    """Designs meeting Constraints 2-8 (``g <= tolerance``)."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    in_range = (X[:, 0] > Q_MAX_RANGE[0]) & (X[:, 0] < Q_MAX_RANGE[1])
    return in_range & np.all(constraint_values(X, workspace) <= tolerance, axis=1)


def world_point(name: str, q_max: float, l1: float, workspace: CubeWorkspace = CubeWorkspace()) -> np.ndarray:
    """The platform position (chain 1, ``S = l1``) at which chain 1's passive arm reaches point ``name``:
    ``r_a = S + l1 sin q_a1`` with ``q_a1 = 0`` (C points) or ``q_max`` (B points), ``r_b = r_x``,
    ``r_c = r_y + l1 cos q_a1`` (eq. 6.33-6.34)."""
    r_x, r_y = (float(v) for v in critical_points(q_max, workspace)[name])
    q_a = 0.0 if name.startswith("C") else q_max
    return np.array([l1 + l1 * np.sin(q_a), r_x, r_y + l1 * np.cos(q_a)])
