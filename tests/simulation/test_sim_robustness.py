"""The modelling-error study: the analytic answer equals the simulation's, and seeds reproduce."""

from __future__ import annotations

import pytest

from hapticdesign.devices.registry import preset
from hapticdesign.simulation.robustness import error_cases, summarize_errors

DESIGNS = [("a", 0.0, {}), ("b", 1.0, {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05}), ("c", 1.0, {"m2": 0.2})]


def _devices():
    base = preset("phantom-3dof")
    return [(name, level, base.with_params(params)) for name, level, params in DESIGNS]


def test_analytic_study_equals_the_simulated_one():
    analytic = error_cases(_devices(), [0.0, 5.0], seed=7, method="analytic")
    simulated = error_cases(_devices(), [0.0, 5.0], seed=7, method="fast")
    assert [c.k_max for c in analytic] == [c.k_max for c in simulated]
    assert any(a.k_max != b.k_max for a, b in zip(analytic[0::2], analytic[1::2]))  # the error is felt


def test_same_seed_same_numbers_and_summary():
    first, again = error_cases(_devices(), [0.0, 10.0], seed=3), error_cases(_devices(), [0.0, 10.0], seed=3)
    assert first == again
    other = error_cases(_devices(), [0.0, 10.0], seed=4)
    assert [c.k_max for c in other] != [c.k_max for c in first]
    rows = summarize_errors(first)
    zero = [r for r in rows if r["error_percent"] == 0.0]
    assert all(r["mean_relative_change"] == 0.0 for r in zero)
    level1 = next(r for r in rows if r["level"] == 1.0 and r["error_percent"] == 10.0)
    changes = [abs(e.k_max - z.k_max) for z, e in zip(first[0::2], first[1::2]) if z.level == 1.0]
    assert level1["mean_absolute_change"] == pytest.approx(sum(changes) / len(changes))
