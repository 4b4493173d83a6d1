"""NSGA-II kinematic synthesis (seed 001 §7.1), hypervolume and the particle-swarm route."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.indicators.hv import HV

from hapticdesign.analysis.rcube.design import uniform_design
from hapticdesign.analysis.rcube.dynamics import cartesian_mass_matrix
from hapticdesign.errors import UserError
from hapticdesign.optimization.rcube.constraints import constraint_values, link1_length
from hapticdesign.optimization.rcube.objectives import geometry_of, objectives
from hapticdesign.optimization.rcube.swarm import weighted_sum_swarm
from hapticdesign.optimization.rcube.synthesis import Bounds, hypervolume, merge_fronts, pareto_filter, synthesize


@pytest.fixture(scope="module")
def result():
    return synthesize(population=24, generations=12, seed=1)


def test_front_is_feasible_non_dominated_and_short(result):
    f = result.front
    assert len(f) > 0
    assert np.all(constraint_values(f.X) <= 0.0)
    assert np.all(f.total_length < 0.4)
    for F in f.F:
        assert not (np.all(f.F <= F, axis=1) & np.any(f.F < F, axis=1)).any()
    assert np.all(np.diff(f.total_length) >= 0)
    # O1 and O2 of a front design recomputed from scratch (eq. 6.82-6.83)
    x = f.X[0]
    g = geometry_of(x)
    assert g.l1 == pytest.approx(0.06 / np.sin(x[0]))
    M = cartesian_mass_matrix(uniform_design(g, 0.02, 0.01, density=2000.0), g.home + np.array([0, -0.06, -0.06]))
    assert f.F[0, 0] == pytest.approx(np.tan(x[0]))
    assert f.F[0, 1] == pytest.approx(np.linalg.det(M))
    assert 0.0 < result.hypervolume <= 1.1**3


def test_same_seed_same_front(result):
    again = synthesize(population=24, generations=12, seed=1)
    assert np.array_equal(again.front.X, result.front.X) and np.array_equal(again.front.F, result.front.F)


def test_pareto_filter_and_hypervolume_on_a_toy_front():
    F = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5], [0.6, 0.6], [0.5, 0.5]])
    X = np.arange(10.0).reshape(5, 2)
    assert pareto_filter(X, F).tolist() == [0, 1, 2, 4]  # (0.6, 0.6) is dominated by (0.5, 0.5)
    # scaled to [0, 1] already; boxes to (1.1, 1.1): 1.1*0.1 + 0.1*1.1 + 0.6*0.6 - overlaps
    expected = HV(ref_point=np.array([1.1, 1.1]))(F[:3])
    assert hypervolume(F[:3]) == pytest.approx(expected)
    assert expected == pytest.approx(0.1 * 1.1 + 0.5 * 0.6 + 0.5 * 0.1)


def test_merge_keeps_the_length_limit(result):
    short = merge_fronts(list(result.per_set), length_limit=0.35)
    assert np.all(short.total_length < 0.35) and len(short) <= len(merge_fronts(list(result.per_set)))


def test_bad_bounds_and_population():
    with pytest.raises(UserError):
        Bounds((0.5, 0.001, 0.001), (0.4, 0.1, 0.1))
    with pytest.raises(UserError):
        Bounds((0.01, 0.001, 0.001), (1.5, 0.1, 0.1))
    with pytest.raises(UserError):
        synthesize(population=0)


def test_infeasible_workspace_is_reported():
    tiny = (Bounds((0.07, 0.001, 0.001), (1.5, 0.02, 0.02)),)
    with pytest.raises(UserError, match="infeasible"):
        synthesize(tiny, population=10, generations=3, seed=1)


def test_weighted_sum_swarm_against_the_front(result):
    s = weighted_sum_swarm(result.front, population=12, generations=10, seed=2)
    assert np.all(constraint_values(s.x[None]) <= 0.0)
    assert np.allclose(s.F, objectives(s.x))
    assert s.F[0] == pytest.approx(np.tan(s.x[0])) and link1_length(s.x[0]) > 0.06
    again = weighted_sum_swarm(result.front, population=12, generations=10, seed=2)
    assert np.array_equal(again.x, s.x)
