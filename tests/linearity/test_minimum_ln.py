"""Smallest LN of the 6-DOF Phantom under the practical bounds (seed 000 §3.3; new result)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from hapticdesign.analysis.linearity.bounds import practical_bounds
from hapticdesign.analysis.linearity.verdict import minimum_ln
from hapticdesign.interface.cli import app
from hapticdesign.model.inertia import SEED_FIELDS, BodyInertia, Realizability, check_body


@pytest.mark.parametrize("kind", list(Realizability))
def test_minimum_ln_design_is_inside_bounds_realizable_and_exact(phantom6, form6, kind):
    bounds = practical_bounds(phantom6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "Solution may be inaccurate"
        result = minimum_ln(phantom6, form6, bounds, kind)
    assert result.within_bounds and result.realizable
    for body, row in zip(phantom6.body_names, result.design):
        if body in bounds:
            b = bounds[body]
            assert b.mass[0] <= row[0] <= b.mass[1]
            assert np.all((b.centre[0] <= row[1:4]) & (row[1:4] <= b.centre[1]))
            assert np.all((b.moments[0] <= row[4:7]) & (row[4:7] <= b.moments[1]))
            assert np.all(np.abs(row[7:10]) <= b.products)
        report = check_body(body, BodyInertia(**dict(zip(SEED_FIELDS, row))))
        assert report.error is None
        if kind is Realizability.RIGID_BODY:
            assert report.warning is None
    assert result.ln == float(form6.ln_seed(result.design.ravel()))
    # the relaxation's minimum cannot exceed an attained value; the gap measures the solve
    assert 0 < result.lower_bound <= result.ln <= result.lower_bound * (1 + 1e-2)


def test_no_nearby_admissible_design_goes_below_the_lower_bound(phantom6, form6):
    """Mixtures (in the seed's variables, where bounds and realizability are convex) of the optimum
    with random admissible designs stay admissible; none may beat the relaxation's lower bound."""
    bounds = practical_bounds(phantom6)
    result = minimum_ln(phantom6, form6, bounds)
    rng = np.random.default_rng(13)
    for t in (1e-4, 1e-3, 1e-2, 1e-1):
        other = result.design.copy()
        for k, body in enumerate(phantom6.body_names):
            if body not in bounds:
                continue
            b = bounds[body]
            moments = rng.uniform(*b.moments, 3)
            moments[np.argmax(moments)] = min(moments.max(), moments.sum() - moments.max())
            other[k] = [rng.uniform(*b.mass), *rng.uniform(*b.centre, 3), *moments, 0, 0, 0]
        mixed = (1 - t) * result.design + t * other
        assert float(form6.ln_seed(mixed.ravel())) >= result.lower_bound


def test_linearize_six_dof_reports_a_bounded_realizable_minimum():
    result = CliRunner().invoke(app, ["linearize", "--preset", "phantom-6dof"])
    assert result.exit_code == 0, result.output
    assert "NO realizable (rigid-body) design with LN = 0" in result.stdout
    assert "design within bounds: True, realizable (rigid-body): True" in result.stdout
