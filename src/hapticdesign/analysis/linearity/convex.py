"""Convex descriptions of realizable, bounded inertial parameters (for cvxpy).

In the standard parameters ``pi = (m, h, J)`` both realizability conditions are linear matrix
inequalities:

- rigid body (Wensing, Kim & Slotine 2017): the pseudo-inertia ``[[tr(J)/2 1 - J, h], [h^T, m]]``
  is positive semi-definite; with a margin ``delta`` on its upper-left block the mass-centre
  moments meet the triangle inequality strictly;
- the seed's eq. 3.28 (positive definite inertia about the mass centre, positive mass): by a
  Schur complement, ``[[J - delta 1, S(h)^T], [S(h), m 1]] >= 0`` with ``S(h)`` the cross-product
  matrix, since ``J - S(h)^T S(h) / m`` is the inertia about the mass centre.

Bounds (eq. 3.29-3.32): mass and mass-centre bounds are linear (``lo m <= h <= hi m``); a lower
bound on a mass-centre moment is a second-order cone (``|h_yz|^2 / m <= J_xx - lo``). Upper bounds
on mass-centre moments and products are not convex; we impose the conservative ``J_xx <= hi`` and
``|J_xy| <= bound`` and check every design afterwards in the seed's variables.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np

from hapticdesign.analysis.linearity.bounds import BodyBounds
from hapticdesign.model.inertia import Realizability

# Typical magnitudes of (m, h, J) used to scale the decision variables.
SCALE = np.array([0.1, 0.01, 0.01, 0.01, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])


def bounds_scale(bounds: dict[str, BodyBounds], bodies: tuple[str, ...]) -> np.ndarray:
    """Per-parameter scale of the standard parameters from each body's bounds.

    Mass by its upper bound, first moments by ``m_hi r_max``, the inertia entries by the lower
    bound on the mass-centre moments, so that the active lower bounds (1e-7 kg m^2 for the
    gimbal links next to 0.3 kg masses) are of order one for the interior-point solver; bodies
    without bounds use :data:`SCALE`.
    """
    out = []
    for body in bodies:
        b = bounds.get(body)
        if b is None:
            out.append(SCALE)
            continue
        first = b.mass[1] * max(abs(b.centre[0]), abs(b.centre[1]), 1e-3)
        out.append(np.array([b.mass[1], first, first, first] + [max(b.moments[0], 1e-9 * b.moments[1], 1e-30)] * 6))
    return np.concatenate(out)


def _inertia(p) -> cp.Expression:
    return cp.bmat([[p[4], p[7], p[8]], [p[7], p[5], p[9]], [p[8], p[9], p[6]]])


def realizability_lmi(p, kind: Realizability, delta: float) -> cp.Expression:
    """The 4x4 (rigid body) or 6x6 (eq. 3.28) matrix that must be positive semi-definite."""
    j = _inertia(p)
    if kind is Realizability.RIGID_BODY:
        sigma = 0.5 * cp.trace(j) * np.eye(3) - j - delta * np.eye(3)
        h = cp.reshape(p[1:4], (3, 1), order="F")
        return cp.bmat([[sigma, h], [h.T, cp.reshape(p[0], (1, 1), order="F")]])
    hx, hy, hz = p[1], p[2], p[3]
    zero = cp.Constant(0.0)
    cross = cp.bmat([[zero, -hz, hy], [hz, zero, -hx], [-hy, hx, zero]])
    return cp.bmat([[j - delta * np.eye(3), cross.T], [cross, p[0] * np.eye(3)]])


def body_constraints(p, bounds: BodyBounds | None, kind: Realizability, delta: float) -> list:
    """Constraints on one body's standard parameters ``p`` (a length-10 cvxpy expression)."""
    lmi = realizability_lmi(p, kind, delta)
    out = [0.5 * (lmi + lmi.T) >> 0]
    if bounds is None:
        return out
    m, h = p[0], p[1:4]
    out += [m >= bounds.mass[0], m <= bounds.mass[1], h >= bounds.centre[0] * m, h <= bounds.centre[1] * m]
    for axis, (a, b) in enumerate(((2, 3), (1, 3), (1, 2))):
        out.append(cp.quad_over_lin(cp.hstack([p[a], p[b]]), m) <= p[4 + axis] - bounds.moments[0])
        out.append(p[4 + axis] <= bounds.moments[1])
    out.append(cp.abs(p[7:10]) <= bounds.products)
    return out


def solve(problem: cp.Problem) -> None:
    """Solve with Clarabel (interior point), falling back to SCS."""
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.SolverError:
        problem.solve(solver=cp.SCS, eps=1e-9, max_iters=200000)
