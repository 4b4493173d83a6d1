"""The weighted-sum route (seed 001 ch. 6 introduction): one scalar objective, particle swarm.

``f = sum_k w_k (O_k - O_k,min) / (O_k,max - O_k,min)`` with the ranges of the Pareto front (the
seed does not state its scaling; the objectives differ by 15 orders of magnitude, so unscaled
weights would ignore two of them), plus a penalty for constraint violation. Solved by pymoo's PSO.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
from pymoo.core.problem import Problem

from hapticdesign.errors import UserError
from hapticdesign.optimization.rcube.constraints import CubeWorkspace, constraint_values
from hapticdesign.optimization.rcube.objectives import EvaluationLinks, objectives
from hapticdesign.optimization.pymoo_run import PARTICLE_SWARM, AlgorithmSpec, RowObjective, run
from hapticdesign.optimization.rcube.synthesis import BOUND_SETS, Bounds, Front

PENALTY = 1e3


class WeightedSumProblem(Problem):
    """The scaled weighted sum of ``O1, O2, O3``; constraints are evaluated for the whole population
    at once, the objectives row by row (a loop, or the Dask ``client``'s workers) on feasible rows."""

    def __init__(self, bounds: Bounds, weights, low, high, workspace: CubeWorkspace, links: EvaluationLinks, client=None):
        super().__init__(n_var=3, n_obj=1, xl=np.array(bounds.lower), xu=np.array(bounds.upper))
        self.weights, self.low, self.span = np.asarray(weights, float), low, np.where(high > low, high - low, 1.0)
        self.workspace = workspace
        self.objective = RowObjective(partial(objectives, workspace=workspace, links=links), 3, 3, client)

    def scalar(self, F: np.ndarray) -> np.ndarray:
        return ((F - self.low) / self.span) @ self.weights

    def _evaluate(self, X, out, *args, **kwargs):
        G = constraint_values(X, self.workspace)
        violation = np.clip(G, 0.0, None).sum(axis=1)
        f = 10.0 + PENALTY * violation
        ok = violation == 0.0
        f[ok] = [self.scalar(F) for F in self.objective(X[ok])]  # row by row: a matrix product may round differently
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
                       workspace: CubeWorkspace = CubeWorkspace(), links: EvaluationLinks = EvaluationLinks(),
                       client=None) -> SwarmResult:
    """Minimize the weighted sum by PSO and compare with the front's own weighted-sum optimum;
    ``client``: a ``dask.distributed.Client`` whose workers evaluate the objectives."""
    if len(front) == 0:
        raise UserError("the weighted-sum comparison needs a non-empty Pareto front")
    spec = AlgorithmSpec(PARTICLE_SWARM, population, generations)
    w = np.asarray(weights, dtype=float)
    if w.shape != (3,) or np.any(w < 0) or w.sum() == 0:
        raise UserError(f"three non-negative weights are needed, got {weights!r}")
    problem = WeightedSumProblem(bounds, w / w.sum(), front.F.min(axis=0), front.F.max(axis=0), workspace, links,
                                 client)
    x = run(problem, spec, seed).best
    if np.any(constraint_values(x[None], workspace) > 0.0):
        raise UserError("the particle swarm found no feasible design; raise its population or generations")
    F = objectives(x, workspace, links)
    front_values = problem.scalar(front.F)
    nearest = int(np.argmin(front_values))
    dominated = bool(np.any(np.all(front.F <= F, axis=1) & np.any(front.F < F, axis=1)))
    return SwarmResult(x, F, float(problem.scalar(F)), problem.objective.evaluations, nearest, float(front_values[nearest]), dominated)
