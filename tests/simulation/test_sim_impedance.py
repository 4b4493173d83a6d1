"""Stable impedance range: the seed's linear scan, the fast search, types 1 and 2, the growth boundary."""

import numpy as np
import pytest

from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.devices.loading import resolve_device
from hapticdesign.analysis.sampled_loop import SampledLoop, compensated_boundary
from hapticdesign.simulation.config import Compensator, LoopConfig, Wall
from hapticdesign.simulation.impedance import (
    Criteria, ImpedanceProblem, fast_search, grid_search, impedance_range, linear_scan, growth_boundary,
)
from hapticdesign.simulation.loop import simulate

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
    under full inertial compensation is b1^2 / H11 (see test_sim_boundary): within 0.05 %."""
    device = preset("phantom-3dof").with_params({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05})
    h11 = mass_matrix(device, np.zeros(3))[0, 0]
    k = growth_boundary(ImpedanceProblem(device, 1))
    assert k == pytest.approx(device.damping[0] ** 2 / h11, rel=5e-4)


@pytest.mark.parametrize("error_percent", [1.0, 10.0])
def test_compensator_error_boundary_is_the_closed_form(error_percent):
    """A modelling error of E % scales masses, mass centres and inertias of the compensator's model
    by 1 - E/100, so its H11 is c H11 with c = H11_model / H11 (below 1 - E/100: first moments
    scale twice, m r^2 three times): the type-1 growth boundary is K*(H11, b1, T, c) of the closed
    form, far above b1^2 / H11 (each percent of c adds about b/T / 100 = 5 N m/rad)."""
    device = preset("phantom-3dof").with_params({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05})
    model = device.with_params({k: device.params.get(k, 0.0) * (1 - error_percent / 100)
                                for k in device.inertial_names()})
    h11, b = mass_matrix(device, np.zeros(3))[0, 0], device.damping[0]
    c = mass_matrix(model, np.zeros(3))[0, 0] / h11
    config = LoopConfig(loop=SampledLoop.seed(error_percent=error_percent))
    k = growth_boundary(ImpedanceProblem(device, 1, config=config))
    expected = compensated_boundary(h11, b, 1e-3, c)
    assert k == pytest.approx(expected, rel=1e-3)
    assert expected > b * b / h11 + 0.9 * (1 - c) * b / 1e-3


def _oracle(device, sim_type, stiffness, criteria=Criteria()):
    """The verdict rebuilt from a run without the excursion stop, recorded at every plant step."""
    problem = ImpedanceProblem(device, sim_type)
    config = LoopConfig(wall=Wall(0, stiffness, equilibrium=0.01), safety_limit=criteria.safety_limit,
                        stop_excursion=None, record_stride=1)
    trace = simulate(device, config, problem.paths)
    q = trace.q[:, 0]
    peak = np.max(np.abs(q - q[0]))
    samples = q[::10]
    tail = samples[trace.t[::10] >= trace.t[-1] - criteria.settle_window]
    settled = np.max(np.abs(tail - 0.01)) <= criteria.settle_tolerance
    stable = bool(np.all(np.isfinite(q)) and peak < criteria.overshoot_limit and trace.trip_time is None and settled)
    return stable, peak


@pytest.mark.parametrize("overrides, sim_type", [({"m2": 0.2}, 1), ({}, 1), ({"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05}, 2)])
def test_verdict_agrees_with_a_run_without_the_stop(overrides, sim_type):
    """A run that reaches the overshoot limit between two 1-kHz records has overshot: the verdict
    equals the criteria applied to the same run, unstopped and recorded at every plant step."""
    device = preset("phantom-3dof").with_params(overrides)
    problem = ImpedanceProblem(device, sim_type)
    for k in (4.0, 5.0, 6.0, 7.0, 8.0):
        verdict = problem.verdict(k)
        stable, peak = _oracle(device, sim_type, k)
        assert verdict.stable == stable, (k, verdict, peak)
        if verdict.stopped_at is None:
            assert verdict.peak == pytest.approx(peak, rel=1e-12)
        else:
            assert verdict.criterion == "overshoot" and verdict.peak >= 0.012 and peak >= 0.012


def test_the_issue_example_overshoots_at_seven():
    """m2 = 0.2, type 1: K = 7 peaks above 0.012 rad when run to the end; it is not stable."""
    device = preset("phantom-3dof").with_params({"m2": 0.2})
    verdict = ImpedanceProblem(device, 1).verdict(7.0)
    assert not verdict.stable and verdict.criterion == "overshoot" and verdict.stopped_at is not None
    assert _oracle(device, 1, 7.0)[1] > 0.012


def _scan(problem, resolution, n_max):
    passing = [n for n in range(1, n_max + 1) if problem.verdict(n * resolution).stable]
    if not passing:
        return 0.0, None
    top = passing[0]
    while top + 1 in passing:
        top += 1
    return top * resolution, passing[0] * resolution


@pytest.mark.parametrize("device_source, resolution, n_max", [
    ("phantom", 0.5, 16), ("examples/devices/pantograph-2dof.yaml", 0.02, 10),
    ("examples/devices/arm-3r.toml", 0.005, 12),
])
def test_grid_search_equals_a_scan_of_every_grid_value(device_source, resolution, n_max):
    device = preset("phantom-3dof") if device_source == "phantom" else resolve_device(None, device_source, None)
    problem = ImpedanceProblem(device, 1)
    result = grid_search(problem, resolution, k_limit=n_max * resolution)
    k_max, k_min = _scan(problem, resolution, n_max)
    assert result.k_max == pytest.approx(k_max)
    assert result.k_min == pytest.approx(k_min)
    assert result.simulations < n_max
    if "arm-3r" not in device_source:
        assert result.k_max > 0
        return
    # arm-3r's joint 1 at q = 0: J = H11 = 0.189 kg m^2, b = 0.05 N m s/rad, full compensation, so the wall grows
    # above b^2 / J = 0.0132 N m/rad (the closed form of seed 000 §4.1.2's 1-DOF loop, c = 1), while below it the
    # response is too slow to settle within the run: no grid value is stable, and the stiffer ones that stayed within
    # the criteria for 5 s (0.03 N m/rad and up, reported stable before the growth check) grow.
    b, j = device.damping[0], mass_matrix(device, np.zeros(3))[0, 0]
    assert result.k_max == 0
    assert problem.verdict(0.03).criterion == "oscillation grows"
    assert not problem.linear.grows(0.99 * b * b / j) and problem.linear.grows(1.01 * b * b / j)


def test_integer_resolution_agrees_with_the_seed_scan_and_the_api_takes_it():
    device = preset("phantom-3dof")
    seed = impedance_range(device, 1, method="linear")
    grid = impedance_range(device, 1, resolution=1.0)
    assert grid.k_max == seed.k_max and grid.k_min == seed.k_min == 1.0


def test_bad_type_and_criteria():
    with pytest.raises(UserError, match="type must be 1 or 2"):
        ImpedanceProblem(preset("phantom-3dof"), 3)
    with pytest.raises(UserError, match="overshoot limit"):
        Criteria(overshoot_limit=0.0)


def test_criteria_scale_with_the_step():
    """The seed's limits are 120 %, 20 % and 600 % of its 0.01-rad step (overshoot 0.012, settling 0.002, switch
    0.06): a wall with another step is judged by the same ratios, the seed's step keeps them, the window (a time)
    stays. Without the scaling a 0.64-mm Cartesian step was judged against a 12-mm overshoot and a 2-mm band."""
    from hapticdesign.simulation.criteria import Criteria

    seed = Criteria()
    assert seed.for_step(0.01) == seed
    scaled = Criteria().for_step(-0.00064)
    assert (scaled.overshoot_limit, scaled.settle_tolerance, scaled.safety_limit) == pytest.approx(
        (1.2 * 0.00064, 0.2 * 0.00064, 6 * 0.00064), rel=1e-12)
    assert scaled.settle_window == seed.settle_window
    problem = ImpedanceProblem(preset("phantom-3dof"), 1, equilibrium=0.02)
    assert problem.criteria.overshoot_limit == pytest.approx(0.024, rel=1e-12)
    with pytest.raises(UserError, match="equilibrium"):
        Criteria().for_step(0.0)
