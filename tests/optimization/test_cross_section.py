"""Cross-section ratio (seed 001 §6.5, §7.3): the seed's d/D = 0.768 (eq. 7.5)."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.errors import UserError
from hapticdesign.optimization.cross_section import cs1, cs2, exact_ratio, optimize_ratio

SEED_RATIO = 0.768


def test_objectives_against_the_tube_section():
    for r in (0.0, 0.3, 0.768):
        tube = Tube(1.0, r) if r > 0 else Tube(1.0, 0.0)
        assert cs1(r) == pytest.approx(1.0 / (12.0 * tube.second_moment))  # eq. 6.87 with E = l = 1
        m = tube.mass(1.0, 1.0)
        assert cs2(r) == pytest.approx(m * (1 / 3 + (0.25 + r**2 / 4) / 4 + 1 / 4))  # eq. 6.86


def test_exact_front_minimum_rms_is_the_seed_ratio():
    # every ratio is Pareto optimal (CS1 rises, CS2 falls); the minimum RMS lies at 0.7636
    r = np.linspace(0.0, 0.9, 1001)
    assert np.all(np.diff(cs1(r)) > 0) and np.all(np.diff(cs2(r)) < 0)
    assert exact_ratio() == pytest.approx(SEED_RATIO, abs=0.005)


def test_nsga2_front_and_choice():
    result = optimize_ratio(population=40, generations=30, seed=3)
    F = np.column_stack([result.CS1, result.CS2])
    dominated = [(np.all(F <= f, axis=1) & np.any(F < f, axis=1)).any() for f in F]
    assert not any(dominated)
    assert result.ratio == pytest.approx(SEED_RATIO, abs=0.015)
    again = optimize_ratio(population=40, generations=30, seed=3)
    assert np.array_equal(again.ratios, result.ratios)


def test_bad_ratio_bounds():
    with pytest.raises(UserError):
        optimize_ratio((0.8, 0.2))
    with pytest.raises(UserError):
        optimize_ratio((0.0, 1.0))
