"""Cross-section ratio (seed 001 §6.5, §7.3, eq. 7.5): the minimum-RMS ratio as a function of the
search's upper limit on d/D, which the seed does not state (its 0.768 corresponds to a limit near 0.9035)."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.analysis.stiffness.sections import Tube
from hapticdesign.errors import UserError
from hapticdesign.optimization.rcube.cross_section import cs1, cs2, exact_ratio, optimize_ratio, ratio_for_upper_limit


def test_objectives_against_the_tube_section():
    for r in (0.0, 0.3, 0.75):
        tube = Tube(1.0, r) if r > 0 else Tube(1.0, 0.0)
        assert cs1(r) == pytest.approx(1.0 / (12.0 * tube.second_moment))  # eq. 6.87 with E = l = 1
        m = tube.mass(1.0, 1.0)
        assert cs2(r) == pytest.approx(m * (1 / 3 + (0.25 + r**2 / 4) / 4 + 1 / 4))  # eq. 6.86


def brute_force_ratio(upper: float, n: int = 400001) -> tuple[float, float]:
    """Grid minimum of the RMS of CS1 and CS2 normalized over the grid (eq. 7.1), and the grid step."""
    r = np.linspace(0.0, upper, n)
    a, b = cs1(r), cs2(r)
    rms = np.sqrt((((a - a.min()) / np.ptp(a)) ** 2 + ((b - b.min()) / np.ptp(b)) ** 2) / 2)
    return float(r[np.argmin(rms)]), upper / (n - 1)


def test_ratio_is_the_brute_force_minimum_for_any_upper_limit():
    # every ratio is Pareto optimal (CS1 rises, CS2 falls), so the front is the whole interval
    r = np.linspace(0.0, 0.9, 1001)
    assert np.all(np.diff(cs1(r)) > 0) and np.all(np.diff(cs2(r)) < 0)
    for upper in (0.6, 0.85, 0.9, 0.9035, 0.95):
        expected, step = brute_force_ratio(upper)
        assert abs(ratio_for_upper_limit(upper) - expected) <= step
        assert abs(exact_ratio((0.0, upper)) - expected) <= step + upper / 200000


def test_ratio_grows_with_the_upper_limit():
    limits = np.linspace(0.5, 0.98, 25)
    ratios = [ratio_for_upper_limit(u) for u in limits]
    assert np.all(np.diff(ratios) > 0) and np.all(np.asarray(ratios) < limits)


def test_nsga2_front_and_choice():
    result = optimize_ratio(population=40, generations=30, seed=3)
    F = np.column_stack([result.CS1, result.CS2])
    dominated = [(np.all(F <= f, axis=1) & np.any(F < f, axis=1)).any() for f in F]
    assert not any(dominated)
    # the choice is the minimum RMS over the front found, normalized over that front (eq. 7.1)
    a, b = cs1(result.ratios), cs2(result.ratios)
    rms = np.hypot((a - a.min()) / np.ptp(a), (b - b.min()) / np.ptp(b))
    assert result.ratio == result.ratios[np.argmin(rms)]
    again = optimize_ratio(population=40, generations=30, seed=3)
    assert np.array_equal(again.ratios, result.ratios)


def test_bad_ratio_bounds():
    with pytest.raises(UserError):
        optimize_ratio((0.8, 0.2))
    with pytest.raises(UserError):
        optimize_ratio((0.0, 1.0))
