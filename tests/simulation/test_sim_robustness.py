"""The modelling-error study: the analytic answer equals the simulation's, and seeds reproduce."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.registry import preset
from hapticdesign.analysis.sampled_loop import compensated_limit
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


def test_over_estimated_inertia_is_one_sided_as_the_closed_form_says():
    """Type 1 is the 1-DOF loop J = H11, b1, T with a compensator share c: where the closed form has no
    stable spring (c exp(-b T / J) >= 1) the search finds k_max = 0; an under-estimated inertia (c < 1)
    never lowers k_max (the limit rises by about (1 - c) b / T)."""
    device = preset("phantom-3dof")
    cases = error_cases([("a", 0.0, device)], [0.0, 5.0], seed=11, sim_type=1, draws=8)
    base = cases[0].k_max
    h11, b1 = float(mass_matrix(device, np.zeros(3))[0, 0]), float(device.damping[0])
    over = [c for c in cases[1:] if compensated_limit(h11, b1, 1e-3, c.fraction).stiffness == 0.0]
    under = [c for c in cases[1:] if c.fraction < 1.0]
    assert over and under  # both signs occur among the draws
    assert all(c.k_max == 0.0 for c in over)
    assert all(c.k_max >= base for c in under)


def test_draws_are_seeded_and_the_summary_gives_student_t_intervals():
    cases = error_cases(_devices()[:2], [0.0, 5.0], seed=5, draws=3)
    assert [c.draw for c in cases] == [0, 0, 1, 2, 0, 0, 1, 2]
    assert len({c.fraction for c in cases if c.error_percent == 5.0}) > 1
    row = next(r for r in summarize_errors(cases) if r["level"] == 1.0 and r["error_percent"] == 5.0)
    change = np.array([abs(c.k_max - cases[4].k_max) for c in cases[5:]])
    half = stats.t.ppf(0.975, 2) * change.std(ddof=1) / np.sqrt(3)
    assert row["absolute_change_ci_low"] == pytest.approx(change.mean() - half)
    assert row["absolute_change_ci_high"] == pytest.approx(change.mean() + half)
