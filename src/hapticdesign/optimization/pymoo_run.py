"""One way to set up, run and filter pymoo's ``minimize`` (Problem, Algorithm, minimize, Result).

The searches of :mod:`~hapticdesign.optimization.rcube.synthesis`, :mod:`~hapticdesign.optimization.rcube.swarm`,
:mod:`~hapticdesign.optimization.rcube.cross_section`, :mod:`~hapticdesign.optimization.rcube.plies` and the study files'
population searches (:mod:`~hapticdesign.optimization.study_run`) all run through :func:`run`: an
:class:`AlgorithmSpec` holds the algorithm (one of pymoo's, :class:`PymooAlgorithm`: :data:`NSGA_II`,
:data:`NSGA_III`, :data:`PARTICLE_SWARM`) and its size, ``minimize`` runs it with a seed (the same seed gives the same
numbers), and the final population comes back as a plain :class:`RunResult` whose :meth:`RunResult.feasible` and
:meth:`RunResult.front` filter it.

Work that may go to a Dask cluster goes through one hook, pymoo's element-wise runner (:func:`elementwise_runner`): a
plain loop by default, or the workers of a Dask client that the caller passes (none is started here). Expensive
objectives of one design vector are a :class:`RowObjective`, pymoo's ``ElementwiseProblem``, whose rows go through it;
a study's batches of designs go through it too (:mod:`~hapticdesign.optimization.study_evaluation`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.moo.nsga3 import NSGA3
from pymoo.algorithms.soo.nonconvex.pso import PSO
from pymoo.core.algorithm import Algorithm
from pymoo.core.callback import Callback
from pymoo.core.problem import ElementwiseProblem, LoopedElementwiseEvaluation, Problem
from pymoo.core.repair import Repair
from pymoo.operators.crossover.sbx import SBX
from pymoo.operators.mutation.pm import PM
from pymoo.operators.repair.rounding import RoundingRepair
from pymoo.operators.sampling.rnd import IntegerRandomSampling
from pymoo.optimize import minimize
from pymoo.parallelization import DaskParallelization
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting
from pymoo.util.ref_dirs import get_reference_directions

from hapticdesign.errors import UserError


@dataclass(frozen=True)
class PymooAlgorithm:
    """One of pymoo's algorithms: ``name`` (in messages), ``build(spec, n_obj, options)`` makes it; ``genetic``: it
    takes sampling, crossover, mutation and repair operators (integer and discrete variables)."""

    name: str
    build: Callable[["AlgorithmSpec", int, dict], Algorithm]
    genetic: bool


NSGA_II = PymooAlgorithm("nsga2", lambda spec, n_obj, options: NSGA2(pop_size=spec.population, **options), True)
"""NSGA-II (Deb et al. 2002)."""
NSGA_III = PymooAlgorithm("nsga3", lambda spec, n_obj, options: NSGA3(
    reference_directions(n_obj, spec.population, spec.partitions), pop_size=spec.population, **options), True)
"""NSGA-III (Deb & Jain 2014): survival by the niches of Das-Dennis reference directions."""
PARTICLE_SWARM = PymooAlgorithm("pso", lambda spec, n_obj, options: PSO(pop_size=spec.population, **options), False)
"""Particle swarm optimization (Kennedy & Eberhart 1995) of one objective."""


@dataclass(frozen=True)
class AlgorithmSpec:
    """The algorithm of one run: ``algorithm`` (one of pymoo's), ``population`` and ``generations``.
    ``integer``: integer variables, genetic algorithms only (integer sampling, SBX and polynomial mutation with
    distribution index 3 and rounding repair, duplicates eliminated). ``discrete``: columns that hold whole numbers
    among real ones (the index of a discrete choice), genetic algorithms only: sampled and varied as reals and rounded
    by :class:`RoundColumns`, duplicates eliminated. ``initial``: the first population's rows; without it pymoo's
    own seeded random sampling is used. ``partitions``: NSGA-III's Das-Dennis divisions per objective axis (None:
    the most whose reference directions fit in the population)."""

    algorithm: PymooAlgorithm = NSGA_II
    population: int = 100
    generations: int = 100
    integer: bool = False
    initial: np.ndarray | None = None
    discrete: tuple[int, ...] = ()
    partitions: int | None = None

    def __post_init__(self) -> None:
        if isinstance(self.algorithm, str):  # a name of the former table ALGORITHMS, kept one release
            named = {a.name: a for a in (NSGA_II, NSGA_III, PARTICLE_SWARM)}
            if self.algorithm not in named:
                raise UserError(f"unknown optimization method {self.algorithm!r}; choose one of {', '.join(named)}")
            warnings.warn(f"AlgorithmSpec({self.algorithm!r}): a method's name is deprecated; pass pymoo's algorithm "
                          "(hapticdesign.optimization.pymoo_run.NSGA_II, NSGA_III or PARTICLE_SWARM)", FutureWarning,
                          stacklevel=3)
            object.__setattr__(self, "algorithm", named[self.algorithm])
        if (self.integer or self.discrete) and not self.algorithm.genetic:
            raise UserError("integer variables and discrete choices need a genetic algorithm, not "
                            f"{self.algorithm.name}")
        if self.population < 2:
            raise UserError(f"population must be at least 2, got {self.population}")
        if self.generations < 1:
            raise UserError(f"generations must be at least 1, got {self.generations}")


def reference_directions(n_obj: int, population: int, partitions: int | None = None) -> np.ndarray:
    """Das-Dennis reference directions of ``n_obj`` objectives with ``partitions`` divisions of each axis (None: the
    most divisions whose directions fit in ``population``); refused when they outnumber the population."""
    def count(p: int) -> int:
        return math.comb(p + n_obj - 1, n_obj - 1)

    if partitions is None:
        partitions = 1
        while n_obj > 1 and count(partitions + 1) <= population:
            partitions += 1
    if count(partitions) > population:
        raise UserError(f"method nsga3: {count(partitions)} reference directions ({partitions} partitions of "
                        f"{n_obj} objectives) need a population of at least {count(partitions)}, got {population}")
    return get_reference_directions("das-dennis", n_obj, n_partitions=partitions)


def build_algorithm(spec: AlgorithmSpec, n_obj: int) -> Algorithm:
    """The pymoo algorithm of ``spec`` for ``n_obj`` objectives."""
    options = {} if spec.initial is None else {"sampling": spec.initial}
    if spec.integer:
        options = {"sampling": IntegerRandomSampling(),
                   "crossover": SBX(prob=1.0, eta=3.0, vtype=float, repair=RoundingRepair()),
                   "mutation": PM(prob=1.0, eta=3.0, vtype=float, repair=RoundingRepair()),
                   "eliminate_duplicates": True, **options}
    elif spec.discrete:
        options = {"repair": RoundColumns(spec.discrete), "eliminate_duplicates": True, **options}
    return spec.algorithm.build(spec, n_obj, options)


class RoundColumns(Repair):
    """Round the ``columns`` of every design to the nearest whole number within the problem's bounds
    (pymoo's ``RoundingRepair`` rounds every column)."""

    def __init__(self, columns: tuple[int, ...]):
        super().__init__()
        self.columns = list(columns)

    def _do(self, problem, X, **kwargs):
        X = np.array(X, dtype=float)
        low, high = np.ceil(problem.xl[self.columns]), np.floor(problem.xu[self.columns])
        X[:, self.columns] = np.clip(np.round(X[:, self.columns]), low, high)
        return X


def initial_population(low, high, population: int, seed: int, designs: np.ndarray | None = None) -> np.ndarray:
    """``designs`` (rows within the bounds ``low``, ``high``) followed by uniform random rows drawn with ``seed``:
    ``population`` rows in all (a first population that holds chosen designs)."""
    low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    given = np.zeros((0, len(low))) if designs is None else np.atleast_2d(np.asarray(designs, dtype=float))[:population]
    rng = np.random.default_rng(seed)
    return np.vstack([given, rng.uniform(low, high, (population - len(given), len(low)))])


def pareto_filter(X: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated rows of ``F`` (minimization), duplicates of ``X`` removed."""
    if len(F) == 0:
        return np.zeros(0, dtype=int)
    _, unique = np.unique(np.round(X, 12), axis=0, return_index=True)
    unique = np.sort(unique)
    first = NonDominatedSorting().do(F[unique], only_non_dominated_front=True)
    return unique[np.sort(first)]


@dataclass(frozen=True)
class RunResult:
    """The final population of a run: designs ``X``, objectives ``F``, constraints ``G`` (``g <= 0``;
    no columns for an unconstrained problem) and pymoo's optimum ``best`` (the best feasible design
    of a single-objective run, None when there is none)."""

    X: np.ndarray
    F: np.ndarray
    G: np.ndarray
    best: np.ndarray | None

    def feasible(self) -> np.ndarray:
        """Rows that meet every constraint and have finite objectives (NaN and inf rows are dropped)."""
        return np.all(self.G <= 0.0, axis=1) & np.all(np.isfinite(self.F), axis=1)

    def front(self) -> np.ndarray:
        """Indices of the feasible, non-dominated rows, duplicates removed, in population order."""
        ok = np.flatnonzero(self.feasible())
        return ok[pareto_filter(self.X[ok].astype(float), self.F[ok])]


class _Progress(Callback):
    def __init__(self, report: Callable[[int], None]):
        super().__init__()
        self.report = report

    def notify(self, algorithm):
        self.report(algorithm.n_gen)


def run(problem: Problem, spec: AlgorithmSpec, seed: int, progress: Callable[[int], None] | None = None) -> RunResult:
    """``minimize`` ``problem`` with the algorithm of ``spec`` for ``spec.generations`` generations,
    seeded with ``seed``; ``progress(generation)`` is called after each generation."""
    options = {"callback": _Progress(progress)} if progress else {}
    result = minimize(problem, build_algorithm(spec, problem.n_obj), ("n_gen", spec.generations), seed=seed,
                      verbose=False, **options)
    pop = result.pop
    X, F = pop.get("X"), pop.get("F")
    X = np.round(X).astype(int) if spec.integer else X
    G = pop.get("G") if problem.n_ieq_constr else np.zeros((len(X), 0))
    best = None if result.X is None else np.asarray(result.X, dtype=float)
    return RunResult(X, F, G, best)


def elementwise_runner(client=None):
    """pymoo's element-wise runner: a plain loop, or the workers of the Dask ``client``
    (``dask.distributed.Client``) when one is given."""
    return LoopedElementwiseEvaluation() if client is None else DaskParallelization(client)


class RowObjective(ElementwiseProblem):
    """An expensive objective ``function(x) -> (n_obj,)`` of one design vector, as pymoo's
    ``ElementwiseProblem``: calling it on rows ``X (m, n_var)`` evaluates them through the
    element-wise runner (a loop, or the Dask ``client``'s workers) and counts them in ``evaluations``."""

    def __init__(self, function: Callable[[np.ndarray], np.ndarray], n_var: int, n_obj: int, client=None):
        super().__init__(n_var=n_var, n_obj=n_obj, elementwise_runner=elementwise_runner(client))
        self.function = function
        self.evaluations = 0

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = self.function(x)

    def __call__(self, X: np.ndarray) -> np.ndarray:
        """Objective rows ``(m, n_obj)`` of ``X``."""
        if len(X) == 0:
            return np.zeros((0, self.n_obj))
        self.evaluations += len(X)
        return self.evaluate(X)
