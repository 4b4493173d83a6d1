"""The analytic transparency (wall joint linearized at the start pose) against the simulated loop."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hapticdesign.devices.registry import preset
from hapticdesign.errors import UserError
from hapticdesign.analysis.sampled_loop import SampledLoop
from hapticdesign.simulation.config import Compensator, Hand, LoopConfig, Wall
from hapticdesign.simulation.loop import simulate
from hapticdesign.simulation.paths import Held, Sine
from hapticdesign.simulation.transparency import transparency

NONLINEAR = {"r3y": 0.01, "Ixy2": 4e-4, "m3": 0.05}
EXACT_IN_BOTH_TYPES = {"seed": LoopConfig(), "delay2": LoopConfig(loop=SampledLoop.seed(delay=2)),
                       "no-inertial": LoopConfig(compensator=Compensator(inertial=False)),
                       "hand": LoopConfig(loop=SampledLoop.seed(hand=Hand(0.2, 2.0, 50.0)))}
MODEL_ERRORS = {"error5": LoopConfig(loop=SampledLoop.seed(error_percent=5)),
                "error10-delay2": LoopConfig(loop=SampledLoop.seed(error_percent=10, delay=2))}


def _same_estimate(device, sim_type, config):
    analytic = transparency(device, sim_type, config=config, method="analytic")
    simulated = transparency(device, sim_type, config=config)
    assert analytic.exact
    assert np.array_equal(analytic.frequency, simulated.frequency)
    assert np.abs(20 * np.log10(np.abs(analytic.g_t / simulated.g_t))).max() < 1e-6
    assert (analytic.bandwidth_hz is None) == (simulated.bandwidth_hz is None)
    if simulated.bandwidth_hz is not None:
        assert analytic.bandwidth_hz == pytest.approx(simulated.bandwidth_hz, abs=1e-6)
    return analytic


@pytest.mark.parametrize("sim_type", [1, 2])
@pytest.mark.parametrize("config", EXACT_IN_BOTH_TYPES.values(), ids=EXACT_IN_BOTH_TYPES.keys())
def test_linear_design_gives_the_simulated_estimate(config, sim_type):
    """LN = 0 (the preset): the transmitted torque is linear in the chirp in both types, so the estimate
    from the six precomputed spectra equals the simulated loop's estimate, bin by bin."""
    _same_estimate(preset("phantom-3dof"), sim_type, config)


@pytest.mark.parametrize("config", MODEL_ERRORS.values(), ids=MODEL_ERRORS.keys())
@pytest.mark.parametrize("overrides", [{}, NONLINEAR])
def test_type_one_is_exact_with_modelling_error_and_delay(overrides, config):
    """Type 1 holds joints 2 and 3 and joint 1's axis is vertical: exact for any design, with any error."""
    _same_estimate(preset("phantom-3dof").with_params(overrides), 1, config)


def test_nonlinear_design_in_type_two_is_flagged_and_close():
    device = preset("phantom-3dof").with_params(NONLINEAR)
    analytic = transparency(device, 2, method="analytic")
    simulated = transparency(device, 2)
    assert not analytic.exact
    assert analytic.bandwidth_hz == pytest.approx(simulated.bandwidth_hz, abs=0.05)  # half the 0.1 Hz bins


def _periodic_impedance(device, config, frequency, duration=5.0):
    """``tau_M / q`` at the excitation bin of a simulated sine over whole periods (type 1), recorded every
    1e-5 s plant step."""
    periods = int(round(duration * frequency))
    cfg = replace(config, duration=duration, step=1e-5, safety_limit=None, record_stride=1,
                  wall=Wall(0, 4.0, equilibrium=0.0))
    trace = simulate(device, cfg, {0: Sine(0.3, 2 * np.pi * frequency), 1: Held(0.0), 2: Held(0.0)})
    q, tau = trace.q[:-1, 0], trace.tau_c[:-1, 0]
    return np.fft.rfft(tau)[periods] / np.fft.rfft(q)[periods]


@pytest.mark.parametrize("config", [LoopConfig(), *MODEL_ERRORS.values(),
                                    LoopConfig(compensator=Compensator(inertial=False))])
def test_steady_response_equals_a_periodic_simulation(config):
    """The steady-state ``Z(jw)`` (held sequence's fundamental, delay, compensator) is what a steady sine
    through the simulated loop transmits at its own frequency (whole periods: no window edges). What
    remains is below 5e-4 here: the record samples the held torque at plant steps (``w h / 2`` of phase on
    the held part) and the delay line starts full of the first sample (2 of 5000 samples)."""
    device = preset("phantom-3dof")
    analytic = transparency(device, 1, config=config, method="analytic")
    for f in (1.0, 2.0):
        i = int(np.argmin(np.abs(analytic.frequency - f)))
        assert analytic.z_steady[i] == pytest.approx(_periodic_impedance(device, config, f), rel=5e-4)


def test_estimate_and_steady_state_differ_by_the_window_edges():
    """With a 5 % modelling error the estimate exits at 1.12 Hz and the steady state at 1.34 Hz: the chirp ends at
    full speed, and the uncompensated inertia's jump over the rectangular window swamps the first bins."""
    result = transparency(preset("phantom-3dof"), 1, config=MODEL_ERRORS["error5"], method="analytic")
    steady_db = 20 * np.log10(np.abs(result.z_steady / result.z_desired))
    estimate_db = 20 * np.log10(np.abs(result.g_t))
    assert abs(steady_db[0]) < 0.1 < abs(estimate_db[0]) and result.bandwidth_hz < result.steady_bandwidth_hz - 0.1


def test_nonlinear_parts_are_refused():
    with pytest.raises(UserError, match="quantization"):
        transparency(preset("phantom-3dof"), 1, config=LoopConfig(counts=4096),
                     method="analytic")
    with pytest.raises(UserError, match="Coulomb"):
        transparency(preset("phantom-3dof"), 1, config=LoopConfig(coulomb=(0.01, 0.0, 0.0)), method="analytic")
    with pytest.raises(UserError, match="method"):
        transparency(preset("phantom-3dof"), 1, method="exact")
