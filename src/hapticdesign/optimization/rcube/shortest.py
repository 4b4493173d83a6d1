"""The shortest feasible R-CUBE design, found by direct constrained minimization and certified
(seed 001 §6.1.3, §7.1).

The kinematic synthesis keeps Table 7.2's designs sorted by total link length ``l1 + l2 + l3``
with ``l1 = h / sin q_max`` (Constraint 1, eq. 6.24). Its short end is where Constraints 3-8
(eq. 6.45-6.49, 6.52) bind. This module minimizes the total length under exactly the constraints of
:func:`hapticdesign.optimization.rcube.constraints.constraint_values` and the bounds of the synthesis
(Table 7.1, Constraint 2, eq. 6.28) with SciPy's SLSQP from many seeded starts, then certifies the
result by the Karush-Kuhn-Tucker conditions: the active constraint gradients span the design
space and their multipliers are positive, so the point is a strict local minimum (a vertex of the
feasible set), and it is the best of all starts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from hapticdesign.optimization.rcube.constraints import CONSTRAINT_NAMES, CubeWorkspace, constraint_values, is_feasible, link1_length
from hapticdesign.optimization.local_search import minimize_in_boxes

ACTIVE_TOLERANCE = 1e-7
"""A constraint with ``g > -tolerance`` at the answer counts as active."""

GRADIENT_STEP = 1e-7
"""Central-difference step (rad, m) of the KKT check."""


def total_length(x, workspace: CubeWorkspace = CubeWorkspace()) -> np.ndarray:
    """``l1 + l2 + l3`` of design vectors ``(q_max, l2, l3)`` with ``l1 = h / sin q_max`` (eq. 6.24)."""
    X = np.atleast_2d(np.asarray(x, dtype=float))
    return link1_length(X[:, 0], workspace) + X[:, 1] + X[:, 2]


def _gradient(fun, x: np.ndarray, step: float = GRADIENT_STEP) -> np.ndarray:
    """Central-difference Jacobian of a vector function of ``x`` (rows: outputs)."""
    columns = []
    for k in range(len(x)):
        e = np.zeros_like(x)
        e[k] = step
        columns.append((np.atleast_1d(fun(x + e)) - np.atleast_1d(fun(x - e))) / (2.0 * step))
    return np.stack(columns, axis=-1)


@dataclass(frozen=True)
class Certificate:
    """The KKT conditions at a candidate minimum: which Constraints 3-8 are active, their
    multipliers ``mu`` in ``grad f + sum mu_i grad g_i = 0``, the relative stationarity residual and
    the rank of the active gradients."""

    active: tuple[str, ...]
    multipliers: np.ndarray
    stationarity: float
    rank: int

    @property
    def strict_local_minimum(self) -> bool:
        """Active gradients spanning the three design variables with positive multipliers: a vertex
        of the feasible set at which the length grows along every feasible direction."""
        return self.rank == 3 and bool(np.all(self.multipliers > 0.0)) and self.stationarity < 1e-5


def certify(x, workspace: CubeWorkspace = CubeWorkspace(), tolerance: float = ACTIVE_TOLERANCE) -> Certificate:
    """KKT check of a feasible design ``x`` for the minimum total length (eq. 6.24, 6.45-6.52)."""
    x = np.asarray(x, dtype=float)
    g = constraint_values(x[None], workspace)[0]
    active = np.flatnonzero(g > -tolerance)
    grad_f = _gradient(lambda y: total_length(y, workspace), x)[0]
    if len(active) == 0:
        return Certificate((), np.zeros(0), 1.0, 0)
    grad_g = _gradient(lambda y: constraint_values(y[None], workspace)[0][active], x).reshape(len(active), 3)
    mu, *_ = np.linalg.lstsq(-grad_g.T, grad_f, rcond=None)
    residual = np.linalg.norm(grad_f + grad_g.T @ mu) / np.linalg.norm(grad_f)
    return Certificate(tuple(CONSTRAINT_NAMES[k] for k in active), mu, float(residual), int(np.linalg.matrix_rank(grad_g)))


@dataclass(frozen=True)
class ConstrainedMinimum:
    """The shortest feasible design ``x = (q_max, l2, l3)``, how many of the seeded starts reached
    it, and its KKT certificate."""

    x: np.ndarray
    certificate: Certificate
    converged: int
    starts: int
    workspace: CubeWorkspace = CubeWorkspace()

    @property
    def l1(self) -> float:
        return float(link1_length(self.x[0], self.workspace))

    @property
    def total_length(self) -> float:
        return float(total_length(self.x, self.workspace)[0])

    def summary(self) -> dict[str, float]:
        """``l1, l2, l3, q_max, total_length`` in metres and radians."""
        return design_summary(self.x, self.workspace)


def design_summary(x, workspace: CubeWorkspace = CubeWorkspace()) -> dict[str, float]:
    """``{"l1", "l2", "l3", "q_max", "total_length"}`` of a design vector (m, rad; eq. 6.24)."""
    q, l2, l3 = (float(v) for v in x)
    l1 = float(link1_length(q, workspace))
    return {"l1": l1, "l2": l2, "l3": l3, "q_max": q, "total_length": l1 + l2 + l3}


def inside(x, bounds) -> bool:
    """Whether ``x`` lies within one bound set."""
    return bool(np.all(np.asarray(bounds.lower) <= x) and np.all(x <= np.asarray(bounds.upper)))


def constrained_minimum(bound_sets: Sequence, workspace: CubeWorkspace = CubeWorkspace(), starts: int = 32,
                        seed: int = 1) -> ConstrainedMinimum | None:
    """The minimum of ``l1 + l2 + l3`` (eq. 6.24) under Constraints 2-8 (eq. 6.28, 6.45-6.52) over
    the union of ``bound_sets`` (:func:`~hapticdesign.optimization.local_search.minimize_in_boxes`); None when no start reaches a feasible design."""
    found = minimize_in_boxes([(np.array(b.lower), np.array(b.upper)) for b in bound_sets],
                              lambda x: float(total_length(x, workspace)[0]),
                              lambda x: constraint_values(x[None], workspace)[0], starts, seed,
                              lambda x: bool(is_feasible(x[None], workspace)[0]))
    if found is None:
        return None
    x, converged = found
    return ConstrainedMinimum(x, certify(x, workspace), converged, starts, workspace)
