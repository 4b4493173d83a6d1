"""The weighted-sum route (seed 001 ch. 6 introduction): one scalar objective, particle swarm.

``f = sum_k w_k (O_k - O_k,min) / (O_k,max - O_k,min)`` with the ranges of the Pareto front (the
seed does not state its scaling; the objectives differ by 15 orders of magnitude, so unscaled
weights would ignore two of them), plus a penalty for constraint violation. Solved by pymoo's PSO.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pymoo.algorithms.soo.nonconvex.pso import PSO
from pymoo.core.problem import Problem
from pymoo.optimize import minimize

from hapticdesign.errors import UserError
from hapticdesign.optimization.constraints import Workspace, constraint_values
from hapticdesign.optimization.objectives import EvaluationLinks, objectives
from hapticdesign.optimization.synthesis import BOUND_SETS, Bounds, Front

PENALTY = 1e3


class WeightedSumProblem(Problem):
    def __init__(self, bounds: Bounds, weights, low, high, workspace: Workspace, links: EvaluationLinks):
        super().__init__(n_var=3, n_obj=1, xl=np.array(bounds.lower), xu=np.array(bounds.upper))
        self.weights, self.low, self.span = np.asarray(weights, float), low, np.where(high > low, high - low, 1.0)
        self.workspace, self.links = workspace, links
        self.evaluations = 0

    def scalar(self, F: np.ndarray) -> np.ndarray:
        return ((F - self.low) / self.span) @ self.weights

    def _evaluate(self, X, out, *args, **kwargs):
        G = constraint_values(X, self.workspace)
        violation = np.clip(G, 0.0, None).sum(axis=1)
        f = 10.0 + PENALTY * violation
        for k in np.flatnonzero(violation == 0.0):
            f[k] = self.scalar(objectives(X[k], self.workspace, self.links))
            self.evaluations += 1
        out["F"] = f[:, None]


@dataclass(frozen=True)
class SwarmResult:
    x: np.ndarray
    F: np.ndarray
    value: float
    evaluations: int
    nearest: int
    """Index of the front design with the smallest weighted sum."""
    nearest_value: float
    dominated: bool
    """Whether a front design dominates the swarm's answer."""


def weighted_sum_swarm(front: Front, weights=(1 / 3, 1 / 3, 1 / 3), bounds: Bounds = BOUND_SETS[2],
                       population: int = 40, generations: int = 60, seed: int = 1,
                       workspace: Workspace = Workspace(), links: EvaluationLinks = EvaluationLinks()) -> SwarmResult:
    """Minimize the weighted sum by PSO and compare with the front's own weighted-sum optimum."""
    if len(front) == 0:
        raise UserError("the weighted-sum comparison needs a non-empty Pareto front")
    if population < 2 or generations < 1:
        raise UserError(f"population must be at least 2 and generations at least 1, got {population}, {generations}")
    w = np.asarray(weights, dtype=float)
    if w.shape != (3,) or np.any(w < 0) or w.sum() == 0:
        raise UserError(f"three non-negative weights are needed, got {weights!r}")
    problem = WeightedSumProblem(bounds, w / w.sum(), front.F.min(axis=0), front.F.max(axis=0), workspace, links)
    result = minimize(problem, PSO(pop_size=population), ("n_gen", generations), seed=seed, verbose=False)
    x = np.asarray(result.X, dtype=float)
    if np.any(constraint_values(x[None], workspace) > 0.0):
        raise UserError("the particle swarm found no feasible design; raise its population or generations")
    F = objectives(x, workspace, links)
    front_values = problem.scalar(front.F)
    nearest = int(np.argmin(front_values))
    dominated = bool(np.any(np.all(front.F <= F, axis=1) & np.any(front.F < F, axis=1)))
    return SwarmResult(x, F, float(problem.scalar(F)), problem.evaluations, nearest, float(front_values[nearest]), dominated)
