"""Kinematic synthesis of the R-CUBE by NSGA-II (seed 001 §6.4, §7.1, Table 7.1-7.2).

Design vector ``(q_max, l2, l3)`` (rad, m, m) within one of the bound sets of Table 7.1;
constraints 3-8 of :mod:`hapticdesign.optimization.rcube.constraints`; objectives ``O1, O2, O3`` of
:mod:`hapticdesign.optimization.rcube.objectives`. The fronts of the three bound sets are merged, reduced
to the non-dominated designs and to those with ``l1 + l2 + l3 < 400 mm`` (§7.1).

Before the runs, the shortest feasible design is found by direct constrained minimization
(:mod:`hapticdesign.optimization.rcube.shortest`) and placed in the initial population of every bound set
that holds it; the rest of each initial population is uniform random, drawn with the run's seed. The
shortest design minimizes ``O3`` on the front, so NSGA-II's elitism keeps it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial
from math import isfinite

import numpy as np
from pymoo.core.problem import Problem
from pymoo.indicators.hv import HV

from hapticdesign.errors import UserError
from hapticdesign.optimization.rcube.constraints import Q_MAX_RANGE, CubeWorkspace, constraint_values, link1_length
from hapticdesign.optimization.rcube.objectives import EvaluationLinks, objectives
from hapticdesign.optimization.pymoo_run import (NSGA_II, AlgorithmSpec, RowObjective, initial_population,
                                                 pareto_filter, run)
from hapticdesign.optimization.rcube.shortest import ConstrainedMinimum, constrained_minimum, design_summary, inside

INFEASIBLE_OBJECTIVE = 1e30
"""Objective value given to designs that break a constraint (pymoo ranks them by violation only)."""

TOTAL_LENGTH_LIMIT = 0.400
"""Kept solutions have ``l1 + l2 + l3`` below this (m), §7.1."""


@dataclass(frozen=True)
class Bounds:
    """Lower and upper bounds of ``q_max`` (rad), ``l2`` and ``l3`` (m)."""

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]

    def __post_init__(self) -> None:
        names = ("q_max", "l2", "l3")
        for name, lo, hi in zip(names, self.lower, self.upper):
            if not (isfinite(lo) and isfinite(hi)):
                raise UserError(f"bounds of {name} must be finite, got {lo!r}..{hi!r}")
            if lo > hi:
                raise UserError(f"lower bound of {name} ({lo:g}) is above its upper bound ({hi:g})")
        if self.lower[0] < Q_MAX_RANGE[0] or self.upper[0] > Q_MAX_RANGE[1]:
            raise UserError(f"q_max bounds must lie within Constraint 2, {Q_MAX_RANGE[0]}..{Q_MAX_RANGE[1]} rad (eq. 6.28)")
        if min(self.lower[1:]) <= 0.0:
            raise UserError("link-length bounds must be positive")


BOUND_SETS = (
    Bounds((0.07, 0.001, 0.001), (1.5, 0.500, 0.500)),
    Bounds((0.07, 0.001, 0.001), (1.5, 0.250, 0.250)),
    Bounds((0.07, 0.001, 0.001), (1.5, 0.100, 0.150)),
)
"""Table 7.1, sets 1-3."""


class SynthesisProblem(Problem):
    """Three objectives, seven inequality constraints. The constraints are evaluated for the whole
    population at once; the objectives, row by row (a loop, or the Dask ``client``'s workers), on
    feasible rows only."""

    def __init__(self, bounds: Bounds, workspace: CubeWorkspace, links: EvaluationLinks, client=None):
        super().__init__(n_var=3, n_obj=3, n_ieq_constr=7, xl=np.array(bounds.lower), xu=np.array(bounds.upper))
        self.workspace = workspace
        self.objective = RowObjective(partial(objectives, workspace=workspace, links=links), 3, 3, client)

    def _evaluate(self, X, out, *args, **kwargs):
        G = constraint_values(X, self.workspace)
        ok = np.all(G <= 0.0, axis=1)
        F = np.full((len(X), 3), INFEASIBLE_OBJECTIVE)
        F[ok] = self.objective(X[ok])
        out["F"] = F
        out["G"] = G


@dataclass(frozen=True)
class Front:
    """Pareto designs ``X (n, 3)`` and objectives ``F (n, 3)``, sorted by total link length."""

    X: np.ndarray
    F: np.ndarray
    workspace: CubeWorkspace = CubeWorkspace()

    @property
    def l1(self) -> np.ndarray:
        return link1_length(self.X[:, 0], self.workspace)

    @property
    def total_length(self) -> np.ndarray:
        return self.l1 + self.X[:, 1] + self.X[:, 2]

    def __len__(self) -> int:
        return len(self.X)

    def shortest(self) -> dict[str, float]:
        """The front's shortest design (the first row): ``l1, l2, l3, q_max, total_length`` (m, rad)."""
        k = int(np.argmin(self.total_length))
        return design_summary(self.X[k], self.workspace)


def run_nsga2(bounds: Bounds, population: int, generations: int, seed: int, workspace: CubeWorkspace = CubeWorkspace(),
              links: EvaluationLinks = EvaluationLinks(), progress: Callable[[int], None] | None = None,
              initial: np.ndarray | None = None, client=None) -> tuple[Front, int]:
    """One NSGA-II run (pymoo) over one bound set; returns its feasible final population and the
    number of objective evaluations. ``initial``: designs placed in the first population (see
    :func:`~hapticdesign.optimization.pymoo_run.initial_population`); without them pymoo's own seeded random sampling is used.
    ``client``: a ``dask.distributed.Client`` whose workers evaluate the objectives."""
    spec = AlgorithmSpec(NSGA_II, population, generations)
    if initial is not None:
        spec = replace(spec, initial=initial_population(bounds.lower, bounds.upper, population, seed, initial))
    problem = SynthesisProblem(bounds, workspace, links, client)
    result = run(problem, spec, seed, progress)
    ok = result.feasible()
    return Front(result.X[ok], result.F[ok], workspace), problem.objective.evaluations


def merge_fronts(fronts: list[Front], length_limit: float = TOTAL_LENGTH_LIMIT) -> Front:
    """Merge the fronts of the bound sets, keep the non-dominated designs with total length below
    ``length_limit`` (§7.1) and sort them by total length."""
    workspace = fronts[0].workspace
    X = np.concatenate([f.X for f in fronts]) if fronts else np.zeros((0, 3))
    F = np.concatenate([f.F for f in fronts]) if fronts else np.zeros((0, 3))
    keep = pareto_filter(X, F)
    merged = Front(X[keep], F[keep], workspace)
    short = merged.total_length < length_limit
    merged = Front(merged.X[short], merged.F[short], workspace)
    order = np.argsort(merged.total_length)
    return Front(merged.X[order], merged.F[order], workspace)


def hypervolume(F: np.ndarray, reference: float = 1.1) -> float:
    """Hypervolume (pymoo) of a front after scaling each objective to [0, 1] over the front itself,
    against the reference point ``(reference,) * m``; the objectives span 15 orders of magnitude."""
    if len(F) == 0:
        return 0.0
    lo, hi = F.min(axis=0), F.max(axis=0)
    scale = np.where(hi > lo, hi - lo, 1.0)
    return float(HV(ref_point=np.full(F.shape[1], reference))((F - lo) / scale))


@dataclass(frozen=True)
class SynthesisResult:
    front: Front
    per_set: tuple[Front, ...]
    evaluations: int
    hypervolume: float
    constrained_minimum: ConstrainedMinimum | None = None
    """The certified shortest feasible design (None when not computed or no start was feasible)."""


MINIMIZATION_STARTS = 32
"""Seeded starts of the direct constrained minimization of the total length."""


def synthesize(bound_sets=BOUND_SETS, population: int = 100, generations: int = 150, seed: int = 1,
               workspace: CubeWorkspace = CubeWorkspace(), links: EvaluationLinks = EvaluationLinks(),
               length_limit: float = TOTAL_LENGTH_LIMIT, progress: Callable[[int, int], None] | None = None,
               starts: int = MINIMIZATION_STARTS, client=None) -> SynthesisResult:
    """NSGA-II over each bound set (seed ``seed + k`` for set ``k``), merged as in §7.1.

    The shortest feasible design (:func:`hapticdesign.optimization.rcube.shortest.constrained_minimum`,
    ``starts`` starts drawn with ``seed``; 0 skips it) joins the initial population of every bound
    set that holds it. ``progress(set_index, generation)`` is called after each generation; ``client``
    (a ``dask.distributed.Client``, none by default) evaluates the objectives on its workers. Raises
    :class:`UserError` when no design meets the constraints (an infeasible workspace for the bounds).
    """
    minimum = constrained_minimum(bound_sets, workspace, starts, seed) if starts != 0 else None
    fronts, evaluations = [], 0
    for k, bounds in enumerate(bound_sets):
        report = (lambda gen, k=k: progress(k, gen)) if progress else None
        initial = minimum.x[None] if minimum is not None and inside(minimum.x, bounds) else None
        front, n = run_nsga2(bounds, population, generations, seed + k, workspace, links, report, initial, client)
        fronts.append(front)
        evaluations += n
    merged = merge_fronts(fronts, length_limit)
    if len(merged) == 0:
        raise UserError(
            f"no design meets Constraints 3-8 with a total link length below {length_limit * 1e3:g} mm: the "
            f"{workspace.side * 1e3:g} mm workspace is infeasible for these bounds (raise the l2, l3 upper bounds)"
        )
    return SynthesisResult(merged, tuple(fronts), evaluations, hypervolume(merged.F), minimum)
