"""The pymoo wrapper: seeded runs, result filtering, and the Dask runner against the plain loop."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.problem import Problem

from hapticdesign.errors import UserError
from hapticdesign.model.rcube import RCubeGeometry
from hapticdesign.optimization.rcube.objectives import objectives
from hapticdesign.optimization.rcube.plies import optimize_plies
from hapticdesign.optimization.pymoo_run import NSGA_II, PARTICLE_SWARM, AlgorithmSpec, RowObjective, RunResult, run
from hapticdesign.optimization.rcube.synthesis import BOUND_SETS, run_nsga2


class Schaffer(Problem):
    """Schaffer's problem N.1: ``f1 = x^2``, ``f2 = (x - 2)^2``; its Pareto set is ``0 <= x <= 2``."""

    def __init__(self):
        super().__init__(n_var=1, n_obj=2, xl=np.array([-10.0]), xu=np.array([10.0]))

    def _evaluate(self, X, out, *args, **kwargs):
        out["F"] = np.column_stack([X[:, 0] ** 2, (X[:, 0] - 2.0) ** 2])


def dominated(F: np.ndarray) -> np.ndarray:
    """Rows of ``F`` that another row dominates (by definition, pairwise)."""
    return np.array([np.any(np.all(F <= f, axis=1) & np.any(F < f, axis=1)) for f in F])


def test_same_seed_same_front_and_the_front_is_the_non_dominated_set():
    spec = AlgorithmSpec(NSGA_II, population=30, generations=40)
    a, b = run(Schaffer(), spec, seed=7), run(Schaffer(), spec, seed=7)
    assert np.array_equal(a.X, b.X) and np.array_equal(a.F, b.F)
    assert np.array_equal(a.front(), b.front())
    assert not np.array_equal(run(Schaffer(), spec, seed=8).X, a.X)
    _, first = np.unique(a.X, axis=0, return_index=True)
    expected = np.sort(first[~dominated(a.F[first])])
    assert len(expected) > 0 and a.front().tolist() == expected.tolist()


def test_feasible_and_front_drop_nan_infeasible_dominated_and_duplicate_rows():
    X = np.array([[0.0], [1.0], [2.0], [3.0], [4.0], [5.0], [1.0]])
    F = np.array([[0.0, 1.0], [1.0, 0.0], [np.nan, 0.0], [np.inf, 0.0], [-1.0, -1.0], [2.0, 2.0], [1.0, 0.0]])
    G = np.array([[0.0], [-1.0], [-1.0], [-1.0], [0.5], [-1.0], [-1.0]])
    result = RunResult(X, F, G, None)
    assert result.feasible().tolist() == [True, True, False, False, False, True, True]
    # row 4 dominates everything but breaks its constraint; row 5 is dominated; row 6 repeats row 1
    assert result.front().tolist() == [0, 1]


def test_spec_is_checked():
    with pytest.raises(UserError, match="population"):
        AlgorithmSpec(population=1)
    with pytest.raises(UserError, match="generations"):
        AlgorithmSpec(generations=0)
    with pytest.raises(UserError, match="method"):
        AlgorithmSpec("simplex")
    with pytest.raises(UserError, match="integer variables and discrete choices need a genetic algorithm, not pso"):
        AlgorithmSpec(PARTICLE_SWARM, integer=True)
    with pytest.raises(UserError, match="discrete choices need a genetic algorithm"):
        AlgorithmSpec(PARTICLE_SWARM, discrete=(0,))


def test_a_method_named_as_before_still_runs_for_a_release_and_says_so():
    with pytest.warns(FutureWarning, match="deprecated"):
        spec = AlgorithmSpec("pso", population=10, generations=3)
    assert spec.algorithm is PARTICLE_SWARM
    with pytest.warns(FutureWarning), pytest.raises(UserError, match="integer"):
        AlgorithmSpec("pso", integer=True)


def test_row_objective_matches_direct_evaluation():
    X = np.array([[0.6, 0.08, 0.12], [0.55, 0.075, 0.125]])
    rows = RowObjective(objectives, 3, 3)
    assert np.array_equal(rows(X), np.array([objectives(x) for x in X]))
    assert rows(X[:0]).shape == (0, 3) and rows.evaluations == 2


def test_dask_client_gives_the_numbers_of_the_loop():
    distributed = pytest.importorskip("dask.distributed")
    from hapticdesign.simulation.campaign import local_cluster

    looped_front, looped_n = run_nsga2(BOUND_SETS[1], 12, 3, seed=4)
    looped_plies = optimize_plies(RCubeGeometry(0.1117, 0.0741, 0.1218), 0.768, population=8, generations=2, seed=5)
    with local_cluster(2, processes=False) as cluster, distributed.Client(cluster) as client:
        front, n = run_nsga2(BOUND_SETS[1], 12, 3, seed=4, client=client)
        plies = optimize_plies(RCubeGeometry(0.1117, 0.0741, 0.1218), 0.768, population=8, generations=2, seed=5,
                               client=client)
    assert n == looped_n > 0
    assert np.array_equal(front.X, looped_front.X) and np.array_equal(front.F, looped_front.F)
    assert np.array_equal(plies.counts, looped_plies.counts) and np.array_equal(plies.F, looped_plies.F)
    assert plies.evaluations == looped_plies.evaluations
