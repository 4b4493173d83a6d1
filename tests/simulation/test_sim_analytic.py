"""The analytic impedance range (exact linear response of the sampled loop) against the simulation."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.analysis.dynamics.device import mass_matrix
from hapticdesign.simulation.analytic import AnalyticProblem
from hapticdesign.simulation.analytic_driven import DrivenLoop
from hapticdesign.simulation.criteria import type_paths
from hapticdesign.analysis.sampled_loop import Hand, SampledLoop
from hapticdesign.simulation.config import Compensator, LoopConfig
from hapticdesign.simulation.impedance import ImpedanceProblem, fast_search, impedance_range

NONLINEAR = {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05}
CONFIGS = [LoopConfig(), LoopConfig(loop=SampledLoop.seed(error_percent=5)),
           LoopConfig(loop=SampledLoop.seed(delay=2)), LoopConfig(compensator=Compensator(inertial=False))]


def assert_same_search(analytic, simulated, stop_times: bool = True) -> None:
    """The same k_max, and around it the same verdicts, peaks (1e-9) and whether (and, with ``stop_times``, when)
    a run stopped."""
    found = fast_search(analytic)
    assert found.k_max == fast_search(simulated).k_max
    for k in (max(found.k_max - 1, 1), found.k_max, found.k_max + 1):
        a, s = analytic.verdict(k), simulated.verdict(k)
        assert (a.stable, a.criterion) == (s.stable, s.criterion)
        assert a.peak == pytest.approx(s.peak, rel=1e-9)
        assert (a.stopped_at is None) == (s.stopped_at is None)
        if stop_times and a.stopped_at is not None:
            assert a.stopped_at == pytest.approx(s.stopped_at, abs=1e-9)


@pytest.mark.parametrize("overrides", [{}, {"m2": 0.2}, NONLINEAR])
@pytest.mark.parametrize("config", CONFIGS, ids=["seed", "error5", "delay2", "no-inertial"])
def test_type_one_verdicts_equal_the_simulation(overrides, config):
    """Type 1 is exactly linear for joint 1 (vertical, cyclic axis): the analytic response equals the
    RK4 simulation to round-off, so every verdict, peak and stop time agrees."""
    device = preset("phantom-3dof").with_params(overrides)
    assert_same_search(AnalyticProblem(device, 1, config=config), ImpedanceProblem(device, 1, config=config))


def test_linear_design_is_exact_in_type_two_and_others_are_flagged():
    device = preset("phantom-3dof")
    analytic = AnalyticProblem(device, 2)
    assert analytic.exact and analytic.driven is None
    assert fast_search(analytic).k_max == fast_search(ImpedanceProblem(device, 2)).k_max
    coupled = AnalyticProblem(device.with_params(NONLINEAR), 2)
    assert coupled.driven is not None and coupled.exact  # joint 1 is cyclic: linear time-varying, not approximate
    assert not AnalyticProblem(device.with_params(NONLINEAR), 2, wall_joint=1).exact


@pytest.mark.parametrize("config", CONFIGS, ids=["seed", "error5", "delay2", "no-inertial"])
def test_type_two_time_varying_response_equals_the_simulation(config):
    """Type 2 on a coupled design: joint 1 (cyclic) is an exactly linear time-varying loop along the
    driven motion, so the product of its transition matrices gives the nonlinear RK4 simulation's
    response to round-off: the same k_max, verdicts, peaks and stop times."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    assert_same_search(AnalyticProblem(device, 2, config=config), ImpedanceProblem(device, 2, config=config),
                       stop_times=False)


def test_type_two_on_a_gravity_loaded_joint_is_linearized_to_second_order():
    """Joint 2 (not cyclic: gravity and the driven joints' pose enter its row) in type 2: the
    linearization in q_2 leaves an O(delta^2) difference; the peaks agree to 1e-5 of the simulation's."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    analytic, simulated = AnalyticProblem(device, 2, wall_joint=1), ImpedanceProblem(device, 2, wall_joint=1)
    for k in (1.0, 5.0):
        assert analytic.verdict(k).peak == pytest.approx(simulated.verdict(k).peak, rel=1e-5)


def test_floquet_multipliers_of_a_decoupled_design_cross_the_unit_circle_at_b_squared_over_j():
    """On an LN = 0 design the homogeneous sample maps do not change along the motion, so the monodromy
    over the 2000-sample period (three motion periods of 2/3 s) is the constant map's power; it leaves
    the unit circle at the closed-form limit b^2 / H11 (x = b T / H11 < 4)."""
    device = preset("phantom-3dof")
    loop = DrivenLoop.build(device, device, 0, type_paths(2, 3, 0), np.zeros(3), float(device.damping[0]),
                            (1.0, 1.0, 1.0), 1e-3, 10, 2100, 0, 0.0, 0.01)
    assert loop.period_samples == 2000
    limit = float(device.damping[0]) ** 2 / float(mass_matrix(device, np.zeros(3))[0, 0])
    assert loop.floquet_radius(0.98 * limit) < 1.0 < loop.floquet_radius(1.02 * limit)


def test_api_and_resolution():
    device = preset("phantom-3dof")
    result = impedance_range(device, 1, method="analytic", resolution=0.1)
    assert result.method == "analytic" and result.exact
    assert (result.k_min, result.k_max) == (impedance_range(device, 1, resolution=0.1).k_min, result.k_max)
    assert result.k_max == pytest.approx(impedance_range(device, 1, resolution=0.1).k_max)


def test_quantization_and_friction_are_not_linear():
    with pytest.raises(UserError, match="quantization"):
        AnalyticProblem(preset("phantom-3dof"), 1, config=LoopConfig(counts=4096))
    with pytest.raises(UserError, match="Coulomb"):
        AnalyticProblem(preset("phantom-3dof"), 1, config=LoopConfig(coulomb=(0.01, 0.0, 0.0)))


def test_group_errors_with_random_signs_equal_the_simulation():
    device = preset("phantom-3dof").with_params(NONLINEAR)
    config = LoopConfig(compensator=Compensator(group_errors=(("mass", 5.0), ("inertia", 5.0)), error_seed=11))
    analytic, simulated = AnalyticProblem(device, 1, config=config), ImpedanceProblem(device, 1, config=config)
    assert fast_search(analytic).k_max == fast_search(simulated).k_max


@pytest.mark.parametrize("config", [LoopConfig(loop=SampledLoop.seed(hand=Hand(0.2, 1.0, 0.0))),
                                    LoopConfig(loop=SampledLoop.seed(hand=Hand(0.2, 1.0, 0.0), error_percent=5,
                                                                     delay=1))], ids=["hand", "hand-error5-delay1"])
def test_a_hand_in_type_one_equals_the_simulation(config):
    """A hand's mass and damping on the handle (``x J_v^T J_v`` on joint 1): the compensator's model has no hand, so
    it feeds its own ``H_m,11`` times the sampled acceleration of the joint with the hand; the analytic loop (the
    one-joint case of the handle loop) equals the RK4 simulation's verdicts, peaks and stop times."""
    device = preset("phantom-3dof").with_params(NONLINEAR)
    assert_same_search(AnalyticProblem(device, 1, config=config), ImpedanceProblem(device, 1, config=config))


@pytest.mark.parametrize("name, joint", [("five-bar", 1), ("delta", 0)])
def test_the_growth_boundary_of_a_closed_loop_joint_wall_is_the_simulated_one(name, joint):
    """The seed's settings on a joint wall of the example closed-loop devices (type 1): the analytic growth check,
    bisected, lands on the simulated growth boundary of the nonlinear loop (10-s runs, bisected to 1e-3). Without
    gravity's stiffness in the linearized loop (the plant's, and the compensator's on the sampled pose, which the held
    torque does not cancel within the period) the five-bar's was 0.8 % high and the delta's 2 % low."""
    from pathlib import Path

    from scipy.optimize import bisect

    from hapticdesign.devices.device_file import load_device_file
    from hapticdesign.simulation.impedance import growth_boundary

    device = load_device_file(Path(__file__).resolve().parents[2] / "examples" / "devices" / f"{name}.yaml")
    analytic = AnalyticProblem(device, 1, joint)
    simulated = growth_boundary(ImpedanceProblem(device, 1, joint, config=LoopConfig(duration=10.0)), rel_tol=1e-3)
    found = bisect(lambda k: 1.0 if analytic.grows(k) else -1.0, 0.5 * simulated, 2.0 * simulated, xtol=1e-9)
    assert found == pytest.approx(simulated, rel=2e-3)
