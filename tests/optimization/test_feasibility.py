"""A study's bounds and feasibility, judged in one place and read the same by the evaluation, the run and the records.

Oracles: the definition of a bound (a value meets ``<= b`` when it is at most ``b``, ``>= b`` when at least ``b``; a NaN
meets neither), the scaled violation written out by hand (``(value - b) / |b|``, a bound of 0 scaled by 1), and, for
a run of the planar arm, each record's constraints compared with its bounds by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hapticdesign.optimization.pymoo_run import NSGA_II
from hapticdesign.optimization.study_evaluation import StudyEvaluator, bind_study
from hapticdesign.optimization.study_file import load_study, study_from_mapping
from hapticdesign.optimization.study_run import feasibility, run_study
from tests.optimization.test_study_run import ISOTROPY, MASS, write_study

BASE = {"device": "arm.yaml", "variables": {"l1": [0.1, 0.3], "l2": [0.1, 0.3]}, "objectives": [ISOTROPY],
        "workspace": {"box": {"center": [0.1, 0.0, 0.1], "size": [0.0, 0.0, 0.0]}}}


def spec_with(*constraints: dict):
    return study_from_mapping({**BASE, "constraints": list(constraints)})


@pytest.mark.parametrize("low, high", [(None, 0.3), (0.1, None), (0.1, 0.3), (-0.2, 0.0), (0.0, 0.0)])
def test_a_bound_is_met_exactly_when_the_value_is_within_it(low, high):
    bounds = {k: v for k, v in (("<=", high), (">=", low)) if v is not None}
    constraint = spec_with({"expression": "l1 + l2", **bounds}).constraints[0]
    for value in [-1.0, -0.2, -1e-12, 0.0, 1e-12, 0.1, 0.2, 0.3, 0.30000000000000004, 1.0, math.inf, -math.inf,
                  math.nan]:
        within = (high is None or value <= high) and (low is None or value >= low)
        met = all(excess <= 0.0 for excess, _, _ in constraint.beyond(value))
        assert met == within, value


def test_the_excess_is_scaled_by_the_bound_and_the_first_miss_is_named():
    c = spec_with({"expression": "l1 + l2", ">=": 0.1, "<=": 0.3}).constraints[0]
    assert [(word, b) for _, b, word in c.beyond(0.2)] == [("<=", 0.3), (">=", 0.1)]  # <= first
    assert [e for e, _, _ in c.beyond(0.45)] == pytest.approx([(0.45 - 0.3) / 0.3, -(0.45 - 0.1) / 0.1])
    zero = spec_with({"expression": "l1 - l2", ">=": 0.0}).constraints[0]
    assert [e for e, _, _ in zero.beyond(-0.05)] == pytest.approx([0.05])  # a bound of 0 is scaled by 1
    spec = spec_with({"expression": "l1", ">=": 0.15}, {"expression": "l1 + l2", "<=": 0.3})
    assert feasibility(spec, (0.2, 0.35)) == ("", "l1 + l2 = 0.35, not <= 0.3", pytest.approx(0.05 / 0.3))
    assert feasibility(spec, (0.1, 0.35)) == ("", "l1 = 0.1, not >= 0.15", pytest.approx(0.05 / 0.15 + 0.05 / 0.3))
    assert feasibility(spec, (0.2, 0.25)) == ("", "", 0.0)
    assert feasibility(spec, (0.2, math.nan))[:2] == ("l1 + l2 is not a finite number", "")


def test_every_record_is_feasible_exactly_when_its_values_meet_the_bounds_by_hand(tmp_path):
    """A run of the planar arm with an index constraint and an expression constraint: each record is feasible exactly
    when it has values and each constrained value lies within its bounds, compared here without the study's code."""
    path = write_study(tmp_path, {"l1": [0.1, 0.3], "l2": [0.05, 0.3]}, [ISOTROPY, MASS], 8, 3,
                       constraints=[{"index": "isotropy", "reduce": "min", ">=": 0.6},
                                    {"expression": "l1 + l2", "<=": 0.4}])
    study = load_study(path)
    evaluate = StudyEvaluator(bind_study(study))
    run = run_study(study, 3, evaluate, algorithm=NSGA_II)
    bounds = [(0.6, math.inf), (-math.inf, 0.4)]
    kinds = set()
    for r in run.records:
        by_hand = all(np.isfinite(v) and low <= v <= high for v, (low, high) in zip(r.constraints, bounds))
        assert r.feasible == (by_hand and all(np.isfinite(r.objectives))), r
        kinds.add(by_hand)
    assert kinds == {True, False}  # the run holds both kinds


def test_the_bound_study_still_answers_for_a_release_and_says_so(tmp_path):
    """``bind_study(study).evaluate`` and ``.evaluate_constraints`` (docs/optimization.md before the evaluator had a
    class of its own) warn once per call and give the evaluator's answers."""
    path = write_study(tmp_path, {"l1": [0.1, 0.3], "l2": [0.05, 0.3]}, [ISOTROPY], 4, 1)
    bound = bind_study(load_study(path))
    batch = [{"l1": 0.2, "l2": 0.14}, {"l1": 0.1, "l2": 0.05}]
    with pytest.warns(FutureWarning, match="StudyEvaluator"):
        old = bound.evaluate(batch)
    with pytest.warns(FutureWarning, match="StudyEvaluator"):
        constraints = bound.evaluate_constraints(batch)
    assert old == StudyEvaluator(bound)(batch) and constraints == StudyEvaluator(bound).constraints(batch)
