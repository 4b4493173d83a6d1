"""The seed's differential-evolution route for design sets (seed 000 §3.2.2, eq. 3.35-3.39), reduced."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.linearity.bounds import practical_bounds
from hapticdesign.analysis.linearity.conditions import linear_conditions
from hapticdesign.analysis.linearity.design_sets import DESettings, Method, design_set
from hapticdesign.errors import UserError
from hapticdesign.model.inertia import SEED_FIELDS, BodyInertia, Realizability, check_body

REDUCED = DESettings(population=10, generations=30)


@pytest.fixture(scope="module")
def conditions3(phantom3, form3):
    return linear_conditions(phantom3, form3)


def _inside(device, design, bounds):
    """Bounds of eq. 3.35-3.38 checked directly in the seed's variables."""
    for body, row in zip(device.body_names, design.reshape(-1, 10)):
        if body not in bounds:
            continue
        b = bounds[body]
        assert b.mass[0] <= row[0] <= b.mass[1]
        assert np.all((b.centre[0] <= row[1:4]) & (row[1:4] <= b.centre[1]))
        assert np.all((b.moments[0] <= row[4:7]) & (row[4:7] <= b.moments[1]))
        assert np.all(np.abs(row[7:10]) <= b.products)


def _realizable(device, design, kind):
    for body, row in zip(device.body_names, design.reshape(-1, 10)):
        report = check_body(body, BodyInertia(**dict(zip(SEED_FIELDS, row))))
        assert report.error is None
        if kind is Realizability.RIGID_BODY:
            assert report.warning is None


@pytest.mark.parametrize("kind", list(Realizability))
def test_de_route_hits_levels_realizably_and_reproducibly(phantom3, form3, conditions3, kind):
    bounds = practical_bounds(phantom3)
    levels = (0.0, 0.01, 1.0)
    run = design_set(phantom3, form3, conditions3, bounds, levels, 1, 7, Method.DE, kind, REDUCED)
    ln = form3.ln_seed(run.designs)
    assert ln[0] < 1e-12
    for value, level in zip(ln[1:], levels[1:]):
        assert level <= value <= level * (1 + 1e-6)
    for design in run.designs:
        _inside(phantom3, design, bounds)
        _realizable(phantom3, design, kind)
    again = design_set(phantom3, form3, conditions3, bounds, levels, 1, 7, Method.DE, kind, REDUCED)
    assert np.array_equal(again.designs, run.designs)
    other = design_set(phantom3, form3, conditions3, bounds, levels, 1, 8, Method.DE, kind, REDUCED)
    assert not np.allclose(other.designs[1:], run.designs[1:])


def test_de_differs_from_the_fast_route(phantom3, form3, conditions3):
    bounds = practical_bounds(phantom3)
    de = design_set(phantom3, form3, conditions3, bounds, (0.1,), 1, 2, Method.DE, de=REDUCED)
    fast = design_set(phantom3, form3, conditions3, bounds, (0.1,), 1, 2, Method.FAST)
    assert not np.allclose(de.designs, fast.designs)


def test_de_settings_are_checked():
    with pytest.raises(UserError):
        DESettings(population=3)
    with pytest.raises(UserError):
        DESettings(generations=0)
