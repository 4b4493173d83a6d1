"""Stable impedance range: the seed's linear scan, the fast search, types 1 and 2, the growth boundary."""

import numpy as np
import pytest

from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.simulation.impedance import Criteria, ImpedanceProblem, fast_search, linear_scan, true_boundary

DESIGNS = [
    {},
    {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05},
    {"Izz1": 1e-3, "Ixx2": 0.003, "Iyy2": 0.003, "Izz2": 0.004},
    {"Ixz3": 1e-3, "Ixz2": 1e-3, "r2az": 0.02},
]


@pytest.mark.parametrize("overrides", DESIGNS)
@pytest.mark.parametrize("sim_type", [1, 2])
def test_fast_search_equals_linear_scan(overrides, sim_type):
    problem = ImpedanceProblem(preset("phantom-3dof").with_params(overrides), sim_type)
    fast, linear = fast_search(problem), linear_scan(problem)
    assert fast.k_max == linear.k_max
    assert fast.first_unstable.stiffness == linear.first_unstable.stiffness == linear.k_max + 1
    assert fast.criterion == linear.criterion


def test_fast_search_on_a_wide_range_uses_fewer_runs():
    loose = Criteria(overshoot_limit=0.05, settle_tolerance=0.01, safety_limit=0.3)
    device = preset("phantom-3dof").with_params({"Izz1": 0.0})
    problem = ImpedanceProblem(device, 1, criteria=loose)
    fast, linear = fast_search(problem), linear_scan(problem, k_limit=40)
    assert fast.k_max == linear.k_max and fast.simulations < linear.simulations


def test_linear_design_gives_identical_types():
    """Seed §4.1.4.2: fully linear dynamics (LN = 0, the default design) give the same range in both types."""
    device = preset("phantom-3dof")
    one, two = ImpedanceProblem(device, 1), ImpedanceProblem(device, 2)
    for k in (3.0, 6.0, 7.0):
        a, b = one.verdict(k), two.verdict(k)
        assert a.stable == b.stable and a.peak == pytest.approx(b.peak, rel=1e-9, abs=1e-12)


def test_type_one_growth_boundary_is_b_squared_over_h11():
    """Type 1 holds joints 2, 3: joint 1 is a 1-DOF inertia H11(0) with damping b1, whose exact limit
    under full inertial compensation is b1^2 / H11 (see test_sim_boundary)."""
    device = preset("phantom-3dof").with_params({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05})
    h11 = device.H(np.zeros(3))[0, 0]
    k = true_boundary(ImpedanceProblem(device, 1), rel_tol=1e-3)
    assert k == pytest.approx(device.damping[0] ** 2 / h11, rel=0.01)


def test_bad_type_and_criteria():
    with pytest.raises(UserError, match="type must be 1 or 2"):
        ImpedanceProblem(preset("phantom-3dof"), 3)
    with pytest.raises(UserError, match="overshoot limit"):
        Criteria(overshoot_limit=0.0)
