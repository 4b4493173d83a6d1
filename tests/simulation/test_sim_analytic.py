"""The analytic impedance range (exact linear response of the sampled loop) against the simulation."""

from __future__ import annotations

import numpy as np
import pytest

from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.simulation.analytic import AnalyticProblem
from hapticdesign.simulation.config import Compensator, LoopConfig, Sensors
from hapticdesign.simulation.impedance import ImpedanceProblem, fast_search, impedance_range

NONLINEAR = {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05}
CONFIGS = [LoopConfig(), LoopConfig(compensator=Compensator(error_percent=5)),
           LoopConfig(sensors=Sensors(delay_samples=2)), LoopConfig(compensator=Compensator(inertial=False))]


@pytest.mark.parametrize("overrides", [{}, {"m2": 0.2}, NONLINEAR])
@pytest.mark.parametrize("config", CONFIGS, ids=["seed", "error5", "delay2", "no-inertial"])
def test_type_one_verdicts_equal_the_simulation(overrides, config):
    """Type 1 is exactly linear for joint 1 (vertical, cyclic axis): the analytic response equals the
    RK4 simulation to round-off, so every verdict, peak and stop time agrees."""
    device = preset("phantom-3dof").with_params(overrides)
    analytic, simulated = AnalyticProblem(device, 1, config=config), ImpedanceProblem(device, 1, config=config)
    found = fast_search(analytic)
    assert found.k_max == fast_search(simulated).k_max
    for k in (max(found.k_max - 1, 1), found.k_max, found.k_max + 1):
        a, s = analytic.verdict(k), simulated.verdict(k)
        assert (a.stable, a.criterion) == (s.stable, s.criterion)
        assert a.peak == pytest.approx(s.peak, rel=1e-9)
        assert (a.stopped_at is None) == (s.stopped_at is None)
        if a.stopped_at is not None:
            assert a.stopped_at == pytest.approx(s.stopped_at, abs=1e-9)


def test_linear_design_is_exact_in_type_two_and_others_are_flagged():
    device = preset("phantom-3dof")
    analytic = AnalyticProblem(device, 2)
    assert analytic.exact
    assert fast_search(analytic).k_max == fast_search(ImpedanceProblem(device, 2)).k_max
    assert not AnalyticProblem(device.with_params(NONLINEAR), 2).exact


def test_api_and_resolution():
    device = preset("phantom-3dof")
    result = impedance_range(device, 1, method="analytic", resolution=0.1)
    assert result.method == "analytic" and result.exact
    assert (result.k_min, result.k_max) == (impedance_range(device, 1, resolution=0.1).k_min, result.k_max)
    assert result.k_max == pytest.approx(impedance_range(device, 1, resolution=0.1).k_max)


def test_quantization_and_friction_are_not_linear():
    with pytest.raises(UserError, match="quantization"):
        AnalyticProblem(preset("phantom-3dof"), 1, config=LoopConfig(sensors=Sensors(counts_per_revolution=4096)))
    with pytest.raises(UserError, match="Coulomb"):
        AnalyticProblem(preset("phantom-3dof"), 1, config=LoopConfig(coulomb=(0.01, 0.0, 0.0)))


def test_group_errors_with_random_signs_equal_the_simulation():
    device = preset("phantom-3dof").with_params(NONLINEAR)
    config = LoopConfig(compensator=Compensator(group_errors=(("mass", 5.0), ("inertia", 5.0)), error_seed=11))
    analytic, simulated = AnalyticProblem(device, 1, config=config), ImpedanceProblem(device, 1, config=config)
    assert fast_search(analytic).k_max == fast_search(simulated).k_max
