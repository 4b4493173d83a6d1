"""Convex descriptions of realizable, bounded inertial parameters (for cvxpy).

In the standard parameters ``pi = (m, h, J)`` both realizability conditions are linear matrix
inequalities:

- rigid body (Wensing, Kim & Slotine 2017): the pseudo-inertia ``[[tr(J)/2 1 - J, h], [h^T, m]]``
  is positive semi-definite; with a margin ``delta`` on its upper-left block the mass-centre
  moments meet the triangle inequality strictly;
- the seed's eq. 3.28 (positive definite inertia about the mass centre, positive mass): by a
  Schur complement, ``[[J - delta 1, S(h)^T], [S(h), m 1]] >= 0`` with ``S(h)`` the cross-product
  matrix, since ``J - S(h)^T S(h) / m`` is the inertia about the mass centre.

Bounds (eq. 3.29-3.32, or any :class:`~.bounds.SeedBox`): mass and mass-centre bounds are linear
(``lo m <= h <= hi m``); a lower bound on a mass-centre moment is a second-order cone
(``|h_yz|^2 / m <= J_xx - lo``). Upper bounds on mass-centre moments and bounds on products are not
convex; we impose the conservative ``J_xx <= hi`` and ``-hi <= J_xy <= -lo`` (``J_xy = -Ixy - m rx
ry``) and check every design afterwards in the seed's variables. Where the mass-centre coordinates a
moment or product depends on are fixed, it is linear in ``pi`` (``Ixx = J_xx - m (ry^2 + rz^2)``,
``Ixy = -J_xy - m rx ry``, Table 2.3) and bounded exactly.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np

from hapticdesign.analysis.linearity.bounds import Bounds, as_box
from hapticdesign.errors import UserError
from hapticdesign.model.inertia import Realizability

# Typical magnitudes of (m, h, J) used to scale the decision variables.
SCALE = np.array([0.1, 0.01, 0.01, 0.01, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])


def bounds_scale(bounds: dict[str, Bounds], bodies: tuple[str, ...]) -> np.ndarray:
    """Per-parameter scale of the standard parameters from each body's bounds.

    Mass by its upper bound, first moments by ``m_hi r_max``, the inertia entries by the smallest
    positive lower bound on the mass-centre moments (a moment without one: its upper bound), so that the active lower bounds (1e-7 kg m^2 for the
    gimbal links next to 0.3 kg masses) are of order one for the interior-point solver; bodies
    without bounds use :data:`SCALE`.
    """
    out = []
    for body in bodies:
        if body not in bounds:
            out.append(SCALE)
            continue
        box = as_box(bounds[body])
        mass = box.high[0]
        first = mass * max(np.abs(box.low[1:4]).max(), np.abs(box.high[1:4]).max(), 1e-3)
        # each moment's positive lower bound, else its upper bound (a box from a study may start at or below 0)
        moments = np.where(box.low[4:7] > 0, box.low[4:7], box.high[4:7])
        out.append(np.array([mass, first, first, first] + [max(moments.min(), 1e-9 * box.high[4:7].max(), 1e-30)] * 6))
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


COUPLED = ((1, 2), (0, 2), (0, 1), (0, 1), (0, 2), (1, 2))
"""The mass-centre coordinates (0, 1, 2 = x, y, z) that each moment (Ixx, Iyy, Izz) and product (Ixy, Ixz, Iyz)
about the mass centre depends on in the standard parameters (Table 2.3's parallel-axis terms)."""


def body_constraints(p, bounds: Bounds | None, kind: Realizability, delta: float) -> list:
    """Constraints on one body's standard parameters ``p`` (a length-10 cvxpy expression)."""
    lmi = realizability_lmi(p, kind, delta)
    out = [0.5 * (lmi + lmi.T) >> 0]
    if bounds is None:
        return out
    box = as_box(bounds)
    m, h = p[0], p[1:4]
    out += [m >= box.low[0], m <= box.high[0], h >= box.low[1:4] * m, h <= box.high[1:4] * m]
    fixed = box.fixed[1:4]
    for k, (a, b) in enumerate(COUPLED):
        lo, hi = box.low[4 + k], box.high[4 + k]
        if fixed[a] and fixed[b]:
            ra, rb = box.low[1 + a], box.low[1 + b]
            # the seed variable, linear in p: Table 2.3 solved for it
            seed = p[4 + k] - m * (ra**2 + rb**2) if k < 3 else -p[4 + k] - m * ra * rb
            out += [seed >= lo, seed <= hi]
        elif k < 3:
            out.append(cp.quad_over_lin(cp.hstack([p[1 + a], p[1 + b]]), m) <= p[4 + k] - lo)
            out.append(p[4 + k] <= hi)
        elif lo != -hi:
            out += [p[4 + k] >= -hi, p[4 + k] <= -lo]
    symmetric = [k for k in range(3, 6) if not (fixed[COUPLED[k][0]] and fixed[COUPLED[k][1]])
                 and box.low[4 + k] == -box.high[4 + k]]
    if symmetric:
        out.append(cp.abs(p[[4 + k for k in symmetric]]) <= box.high[[4 + k for k in symmetric]])
    return out


def solve(problem: cp.Problem) -> None:
    """Solve with Clarabel (interior point), falling back to SCS; a one-line UserError when both fail (bounds
    so far apart that the scaled problem is not a finite one, for instance)."""
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.SolverError:
        try:
            problem.solve(solver=cp.SCS, eps=1e-9, max_iters=200000)
        except (cp.SolverError, ValueError, ArithmeticError) as exc:
            raise UserError(f"the convex solvers (Clarabel, SCS) failed on this problem ({str(exc)[:80]}); are the "
                            "bounds of a sensible size?") from None
